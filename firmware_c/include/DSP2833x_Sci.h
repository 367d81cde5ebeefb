/* Replacement for TI's DSP2833x_Sci.h in a host build: SCI-A/B/C at 0x7050/0x7750/0x7770, TI's layout
   and field names (F2833x SCI reference guide SPRUFZ5), the emulated board's (rust/core/src/dsp/sci.rs). */
#ifndef DSP2833x_SCI_H
#define DSP2833x_SCI_H

#ifdef __cplusplus
extern "C" {
#endif

/* SCICCR: character length, loopback, parity, stop bits. */
struct SCICCR_BITS {
    Uint16 SCICHAR:3;       /* 2:0 data bits - 1 */
    Uint16 ADDRIDLE_MODE:1; /* 3 */
    Uint16 LOOPBKENA:1;     /* 4 internal loopback */
    Uint16 PARITYENA:1;     /* 5 */
    Uint16 PARITY:1;        /* 6 1 = even */
    Uint16 STOPBITS:1;      /* 7 1 = two */
    Uint16 rsvd1:8;
};
union SCICCR_REG {
    Uint16 all;
    struct SCICCR_BITS bit;
};

/* SCICTL1: enables and software reset. */
struct SCICTL1_BITS {
    Uint16 RXENA:1;
    Uint16 TXENA:1;
    Uint16 SLEEP:1;
    Uint16 TXWAKE:1;
    Uint16 rsvd:1;
    Uint16 SWRESET:1;
    Uint16 RXERRINTENA:1;
    Uint16 rsvd1:9;
};
union SCICTL1_REG {
    Uint16 all;
    struct SCICTL1_BITS bit;
};

/* SCICTL2: TX/RX interrupt enables, TXEMPTY and TXRDY flags. */
struct SCICTL2_BITS {
    Uint16 TXINTENA:1;
    Uint16 RXBKINTENA:1;
    Uint16 rsvd:4;
    Uint16 TXEMPTY:1;
    Uint16 TXRDY:1;
    Uint16 rsvd1:8;
};
union SCICTL2_REG {
    Uint16 all;
    struct SCICTL2_BITS bit;
};

/* SCIRXST: receiver status. */
struct SCIRXST_BITS {
    Uint16 rsvd:1;
    Uint16 RXWAKE:1;
    Uint16 PE:1;
    Uint16 OE:1;
    Uint16 FE:1;
    Uint16 BRKDT:1;
    Uint16 RXRDY:1;
    Uint16 RXERROR:1;
    Uint16 rsvd1:8;
};
union SCIRXST_REG {
    Uint16 all;
    struct SCIRXST_BITS bit;
};

/* SCIRXBUF: the character and, in FIFO mode, its errors. */
struct SCIRXBUF_BITS {
    Uint16 RXDT:8;
    Uint16 rsvd:6;
    Uint16 SCIFFPE:1;
    Uint16 SCIFFFE:1;
};
union SCIRXBUF_REG {
    Uint16 all;
    struct SCIRXBUF_BITS bit;
};

struct SCIPRI_BITS {
    Uint16 rsvd:3;
    Uint16 FREE:1;
    Uint16 SOFT:1;
    Uint16 rsvd1:11;
};
union SCIPRI_REG {
    Uint16 all;
    struct SCIPRI_BITS bit;
};

/* SCIFFTX / SCIFFRX / SCIFFCT: the 16-word FIFOs. */
struct SCIFFTX_BITS {
    Uint16 TXFFIL:5;
    Uint16 TXFFIENA:1;
    Uint16 TXFFINTCLR:1;
    Uint16 TXFFINT:1;
    Uint16 TXFFST:5;
    Uint16 TXFIFOXRESET:1;
    Uint16 SCIFFENA:1;
    Uint16 SCIRST:1;
};
union SCIFFTX_REG {
    Uint16 all;
    struct SCIFFTX_BITS bit;
};

struct SCIFFRX_BITS {
    Uint16 RXFFIL:5;
    Uint16 RXFFIENA:1;
    Uint16 RXFFINTCLR:1;
    Uint16 RXFFINT:1;
    Uint16 RXFFST:5;
    Uint16 RXFIFORESET:1;
    Uint16 RXFFOVRCLR:1;
    Uint16 RXFFOVF:1;
};
union SCIFFRX_REG {
    Uint16 all;
    struct SCIFFRX_BITS bit;
};

struct SCIFFCT_BITS {
    Uint16 FFTXDLY:8;
    Uint16 rsvd:5;
    Uint16 CDC:1;
    Uint16 ABDCLR:1;
    Uint16 ABD:1;
};
union SCIFFCT_REG {
    Uint16 all;
    struct SCIFFCT_BITS bit;
};

struct SCI_REGS {
    union SCICCR_REG SCICCR;     /* +0x0 */
    union SCICTL1_REG SCICTL1;   /* +0x1 */
    Uint16 SCIHBAUD;             /* +0x2 */
    Uint16 SCILBAUD;             /* +0x3 */
    union SCICTL2_REG SCICTL2;   /* +0x4 */
    union SCIRXST_REG SCIRXST;   /* +0x5 */
    Uint16 SCIRXEMU;             /* +0x6 */
    union SCIRXBUF_REG SCIRXBUF; /* +0x7 */
    Uint16 rsvd1;
    Uint16 SCITXBUF;             /* +0x9 */
    union SCIFFTX_REG SCIFFTX;   /* +0xA */
    union SCIFFRX_REG SCIFFRX;   /* +0xB */
    union SCIFFCT_REG SCIFFCT;   /* +0xC */
    Uint16 rsvd2[2];
    union SCIPRI_REG SCIPRI;     /* +0xF */
};

extern volatile struct SCI_REGS SciaRegs;
extern volatile struct SCI_REGS ScibRegs;
extern volatile struct SCI_REGS ScicRegs;

#ifdef __cplusplus
}
#endif

#endif
