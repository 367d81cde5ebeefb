/* Replacement for TI's DSP2833x_I2c.h in a host build: I2C-A at 0x7900, TI's layout and field names
   (F2833x I2C reference guide SPRUG03), the emulated board's (rust/core/src/dsp/i2c.rs). */
#ifndef DSP2833x_I2C_H
#define DSP2833x_I2C_H

#ifdef __cplusplus
extern "C" {
#endif

/* I2CIER: interrupt enables (the I2CSTR flags of the same names). */
struct I2CIER_BITS {
    Uint16 ARBL:1;  /* 0 */
    Uint16 NACK:1;  /* 1 */
    Uint16 ARDY:1;  /* 2 */
    Uint16 RRDY:1;  /* 3 */
    Uint16 XRDY:1;  /* 4 */
    Uint16 SCD:1;   /* 5 */
    Uint16 AAS:1;   /* 6 */
    Uint16 rsvd:9;
};
union I2CIER_REG {
    Uint16 all;
    struct I2CIER_BITS bit;
};

/* I2CSTR: status; ARBL, NACK, ARDY, RRDY, SCD, NACKSNT are cleared by writing 1. */
struct I2CSTR_BITS {
    Uint16 ARBL:1;    /* 0 arbitration lost */
    Uint16 NACK:1;    /* 1 no acknowledge received */
    Uint16 ARDY:1;    /* 2 registers ready for access */
    Uint16 RRDY:1;    /* 3 receive data ready */
    Uint16 XRDY:1;    /* 4 transmit data ready */
    Uint16 SCD:1;     /* 5 STOP condition detected */
    Uint16 rsvd1:2;
    Uint16 AD0:1;     /* 8 */
    Uint16 AAS:1;     /* 9 addressed as slave */
    Uint16 XSMT:1;    /* 10 0 = transmit underflow */
    Uint16 RSFULL:1;  /* 11 receive overrun */
    Uint16 BB:1;      /* 12 bus busy */
    Uint16 NACKSNT:1; /* 13 */
    Uint16 SDIR:1;    /* 14 */
    Uint16 rsvd2:1;
};
union I2CSTR_REG {
    Uint16 all;
    struct I2CSTR_BITS bit;
};

/* I2CMDR: mode. */
struct I2CMDR_BITS {
    Uint16 BC:3;      /* 2:0 bit count */
    Uint16 FDF:1;     /* 3 free data format */
    Uint16 STB:1;     /* 4 START byte */
    Uint16 IRS:1;     /* 5 0 = module in reset */
    Uint16 DLB:1;     /* 6 digital loopback */
    Uint16 RM:1;      /* 7 repeat mode */
    Uint16 XA:1;      /* 8 10-bit addressing */
    Uint16 TRX:1;     /* 9 transmitter */
    Uint16 MST:1;     /* 10 master */
    Uint16 STP:1;     /* 11 STOP */
    Uint16 rsvd1:1;
    Uint16 STT:1;     /* 13 START */
    Uint16 FREE:1;    /* 14 */
    Uint16 NACKMOD:1; /* 15 */
};
union I2CMDR_REG {
    Uint16 all;
    struct I2CMDR_BITS bit;
};

/* I2CISRC: the highest-priority interrupt source pending. */
struct I2CISRC_BITS {
    Uint16 INTCODE:3;
    Uint16 rsvd1:13;
};
union I2CISRC_REG {
    Uint16 all;
    struct I2CISRC_BITS bit;
};

/* I2CPSC: module clock prescaler. */
struct I2CPSC_BITS {
    Uint16 IPSC:8;
    Uint16 rsvd1:8;
};
union I2CPSC_REG {
    Uint16 all;
    struct I2CPSC_BITS bit;
};

/* I2CFFTX: transmit FIFO. */
struct I2CFFTX_BITS {
    Uint16 TXFFIL:5;     /* 4:0 */
    Uint16 TXFFIENA:1;   /* 5 */
    Uint16 TXFFINTCLR:1; /* 6 */
    Uint16 TXFFINT:1;    /* 7 */
    Uint16 TXFFST:5;     /* 12:8 */
    Uint16 TXFFRST:1;    /* 13 */
    Uint16 I2CFFEN:1;    /* 14 */
    Uint16 rsvd1:1;
};
union I2CFFTX_REG {
    Uint16 all;
    struct I2CFFTX_BITS bit;
};

/* I2CFFRX: receive FIFO. */
struct I2CFFRX_BITS {
    Uint16 RXFFIL:5;     /* 4:0 */
    Uint16 RXFFIENA:1;   /* 5 */
    Uint16 RXFFINTCLR:1; /* 6 */
    Uint16 RXFFINT:1;    /* 7 */
    Uint16 RXFFST:5;     /* 12:8 */
    Uint16 RXFFRST:1;    /* 13 */
    Uint16 rsvd1:2;
};
union I2CFFRX_REG {
    Uint16 all;
    struct I2CFFRX_BITS bit;
};

struct I2C_REGS {
    Uint16 I2COAR;               /* +0x0 own address */
    union I2CIER_REG I2CIER;     /* +0x1 */
    union I2CSTR_REG I2CSTR;     /* +0x2 */
    Uint16 I2CCLKL;              /* +0x3 */
    Uint16 I2CCLKH;              /* +0x4 */
    Uint16 I2CCNT;               /* +0x5 */
    Uint16 I2CDRR;               /* +0x6 */
    Uint16 I2CSAR;               /* +0x7 */
    Uint16 I2CDXR;               /* +0x8 */
    union I2CMDR_REG I2CMDR;     /* +0x9 */
    union I2CISRC_REG I2CISRC;   /* +0xA */
    Uint16 I2CEMDR;              /* +0xB */
    union I2CPSC_REG I2CPSC;     /* +0xC */
    Uint16 rsvd2[19];
    union I2CFFTX_REG I2CFFTX;   /* +0x20 */
    union I2CFFRX_REG I2CFFRX;   /* +0x21 */
};

extern volatile struct I2C_REGS I2caRegs;

#ifdef __cplusplus
}
#endif

#endif
