/* An I2C EEPROM on I2C-A, polled with the FIFOs, in the style of TI's 2833x peripheral examples
   (Example_2833xI2C_eeprom): our own code. A page of the 24LC256 at 0x50 is written, the write cycle is
   acknowledge-polled (the address set-up of a read is NACKed until the part has finished), the page is
   read back with a repeated START, then a write to an address no part answers (0x51) shows the NACK.
   CPU timer 2, free-running at SYSCLKOUT, measures the polling. */
#include "DSP28x_Project.h"

#define EEPROM_ADDR 0x50
#define ABSENT_ADDR 0x51
#define MEM_ADDR 0x0040  /* the start of a 64-byte page */
#define NBYTES 8

Uint16 polls;          /* acknowledge-polling attempts NACKed */
Uint32 poll_cycles;    /* SYSCLKOUT cycles from the write's STOP to the ACKed attempt */
Uint16 matched;        /* bytes read back as written */
Uint16 first_read;     /* the first byte read back */
Uint16 absent_nack;    /* I2CSTR.NACK after addressing 0x51 */
Uint16 done;
Uint32 idle;

static Uint16 pattern(Uint16 k)
{
    return (0xA5 + 17 * k) & 0xFF;
}

static void i2ca_init(void)
{
    I2caRegs.I2CSAR = EEPROM_ADDR;
    I2caRegs.I2CPSC.all = 14;       /* module clock 150 MHz / 15 = 10 MHz */
    I2caRegs.I2CCLKL = 10;          /* SCL low (10 + 5) x 100 ns */
    I2caRegs.I2CCLKH = 5;           /* SCL high (5 + 5) x 100 ns: 400 kHz */
    I2caRegs.I2CIER.all = 0x0000;   /* polled */
    I2caRegs.I2CMDR.all = 0x0020;   /* out of reset */
    I2caRegs.I2CFFTX.all = 0x6000;  /* FIFO mode, TX FIFO on */
    I2caRegs.I2CFFRX.all = 0x2040;  /* RX FIFO on, RXFFINT cleared */
}

static void wait_bus_free(void)
{
    while (I2caRegs.I2CMDR.bit.STP == 1) {
    }
    while (I2caRegs.I2CSTR.bit.BB == 1) {
    }
}

static void tx_fifo_reset(void)
{
    I2caRegs.I2CFFTX.bit.TXFFRST = 0;
    I2caRegs.I2CFFTX.bit.TXFFRST = 1;
}

static void wait_stop(void)
{
    while (I2caRegs.I2CSTR.bit.SCD == 0) {
    }
    I2caRegs.I2CSTR.all = I2C_CLR_SCD_BIT;
}

static void write_page(void)
{
    Uint16 k;
    wait_bus_free();
    I2caRegs.I2CSAR = EEPROM_ADDR;
    I2caRegs.I2CCNT = NBYTES + 2;
    I2caRegs.I2CDXR = MEM_ADDR >> 8;
    I2caRegs.I2CDXR = MEM_ADDR & 0xFF;
    for (k = 0; k < NBYTES; k++) {
        I2caRegs.I2CDXR = pattern(k);
    }
    I2caRegs.I2CMDR.all = 0x6E20;   /* STT STP MST TRX IRS FREE */
    wait_stop();
}

/* The address set-up of a random read, no STOP: 1 when the part acknowledged (then the bus is held
   for the repeated START), 0 when it NACKed (a STOP ends the attempt). */
static Uint16 address_setup(void)
{
    wait_bus_free();
    tx_fifo_reset();
    I2caRegs.I2CCNT = 2;
    I2caRegs.I2CDXR = MEM_ADDR >> 8;
    I2caRegs.I2CDXR = MEM_ADDR & 0xFF;
    I2caRegs.I2CMDR.all = 0x2620;   /* STT MST TRX IRS: no STOP */
    while (I2caRegs.I2CSTR.bit.ARDY == 0) {
    }
    if (I2caRegs.I2CSTR.bit.NACK == 1) {
        I2caRegs.I2CMDR.bit.STP = 1;
        I2caRegs.I2CSTR.all = I2C_CLR_NACK_BIT | I2C_CLR_ARDY_BIT;
        wait_stop();
        return 0;
    }
    I2caRegs.I2CSTR.all = I2C_CLR_ARDY_BIT;
    return 1;
}

static void read_page(void)
{
    Uint16 k, b;
    I2caRegs.I2CCNT = NBYTES;
    I2caRegs.I2CMDR.all = 0x2C20;   /* repeated START as receiver, STOP after NBYTES */
    wait_stop();
    for (k = 0; k < NBYTES; k++) {
        b = I2caRegs.I2CDRR;
        if (k == 0) {
            first_read = b;
        }
        if (b == pattern(k)) {
            matched++;
        }
    }
}

static void write_absent(void)
{
    wait_bus_free();
    tx_fifo_reset();
    I2caRegs.I2CSAR = ABSENT_ADDR;
    I2caRegs.I2CCNT = 1;
    I2caRegs.I2CDXR = 0;
    I2caRegs.I2CMDR.all = 0x6E20;
    while (I2caRegs.I2CSTR.bit.ARDY == 0) {
    }
    absent_nack = I2caRegs.I2CSTR.bit.NACK;
    I2caRegs.I2CSTR.all = I2C_CLR_NACK_BIT | I2C_CLR_ARDY_BIT;
    wait_stop();                    /* STP was set: the STOP follows the NACK */
    tx_fifo_reset();
}

void main(void)
{
    Uint32 t0;

    InitSysCtrl();
    InitI2CGpio();
    DINT;
    InitPieCtrl();
    IER = 0x0000;
    IFR = 0x0000;
    InitPieVectTable();

    /* CPU timer 2 free-running from 0xFFFFFFFF, one count per SYSCLKOUT cycle. */
    CpuTimer2Regs.PRD.all = 0xFFFFFFFF;
    CpuTimer2Regs.TPR.all = 0;
    CpuTimer2Regs.TPRH.all = 0;
    CpuTimer2Regs.TCR.all = 0x0030; /* stop, reload */
    CpuTimer2Regs.TCR.all = 0x0000; /* run */

    i2ca_init();
    write_page();
    t0 = CpuTimer2Regs.TIM.all;
    polls = 0;
    while (address_setup() == 0) {
        polls++;
    }
    poll_cycles = t0 - CpuTimer2Regs.TIM.all;
    read_page();
    write_absent();
    done = 1;
    for (;;) {
        /* Idle: timer 2 counts on (a loop reading a register that changes, not one that never does). */
        idle = CpuTimer2Regs.TIM.all;
    }
}
