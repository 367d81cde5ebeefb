/* Replacement for TI's DSP2833x_I2c_defines.h in a host build: the names TI's I2C examples use (the
   status masks written to I2CSTR to clear a flag, the I2CISRC codes, the message structure of TI's EEPROM
   example with its status and error codes), with the values of SPRUG03's register tables. */
#ifndef DSP2833x_I2C_DEFINES_H
#define DSP2833x_I2C_DEFINES_H

/* Defaults TI's EEPROM example compiles with (a project may define its own first). */
#ifndef I2C_SLAVE_ADDR
#define I2C_SLAVE_ADDR 0x50
#endif
#ifndef I2C_NUMBYTES
#define I2C_NUMBYTES 4
#endif
#ifndef I2C_EEPROM_HIGH_ADDR
#define I2C_EEPROM_HIGH_ADDR 0x00
#endif
#ifndef I2C_EEPROM_LOW_ADDR
#define I2C_EEPROM_LOW_ADDR 0x30
#endif

/* I2CSTR flags, written as 1 to clear them. */
#define I2C_CLR_AL_BIT 0x0001
#define I2C_CLR_NACK_BIT 0x0002
#define I2C_CLR_ARDY_BIT 0x0004
#define I2C_CLR_RRDY_BIT 0x0008
#define I2C_CLR_SCD_BIT 0x0020

/* I2CISRC.INTCODE values. */
#define I2C_NO_ISRC 0x0000
#define I2C_ARB_ISRC 0x0001
#define I2C_NACK_ISRC 0x0002
#define I2C_ARDY_ISRC 0x0003
#define I2C_RX_ISRC 0x0004
#define I2C_TX_ISRC 0x0005
#define I2C_SCD_ISRC 0x0006
#define I2C_AAS_ISRC 0x0007

/* I2CMSG.MsgStatus. */
#define I2C_MSGSTAT_INACTIVE 0x0000
#define I2C_MSGSTAT_SEND_WITHSTOP 0x0010
#define I2C_MSGSTAT_WRITE_BUSY 0x0011
#define I2C_MSGSTAT_SEND_NOSTOP 0x0020
#define I2C_MSGSTAT_SEND_NOSTOP_BUSY 0x0021
#define I2C_MSGSTAT_RESTART 0x0022
#define I2C_MSGSTAT_READ_BUSY 0x0023

/* Function return codes. */
#define I2C_SUCCESS 0x0000
#define I2C_ERROR 0xFFFF
#define I2C_ARB_LOST_ERROR 0x0001
#define I2C_NACK_ERROR 0x0002
#define I2C_BUS_BUSY_ERROR 0x1000
#define I2C_STP_NOT_READY_ERROR 0x5555
#define I2C_NO_FLAGS 0xAAAA
#define I2C_SUCCESS_FLAG 0x0000

/* Buffer size of I2CMSG. */
#define I2C_MAX_BUFFER_SIZE 16

/* One message of TI's EEPROM example. */
struct I2CMSG {
    Uint16 MsgStatus;
    Uint16 SlaveAddress;
    Uint16 NumOfBytes;
    Uint16 MemoryHighAddr;
    Uint16 MemoryLowAddr;
    Uint16 MsgBuffer[I2C_MAX_BUFFER_SIZE];
};

#endif
