/* Replacement for TI's DSP2833x_McBSP.h in a host build: McBSP-A/B at 0x5000/0x5040, TI's layout and
   field names (F2833x McBSP reference guide SPRUFB7), the emulated board's in SPI (clock-stop) mode
   (rust/core/src/dsp/mcbsp.rs). */
#ifndef DSP2833x_MCBSP_H
#define DSP2833x_MCBSP_H

#ifdef __cplusplus
extern "C" {
#endif

/* A data or channel-enable register: 16 bits. */
struct MCBSP_WORD_BITS {
    Uint16 LO:8;
    Uint16 HI:8;
};
union DRR2_REG { Uint16 all; struct MCBSP_WORD_BITS bit; };
union DRR1_REG { Uint16 all; struct MCBSP_WORD_BITS bit; };
union DXR2_REG { Uint16 all; struct MCBSP_WORD_BITS bit; };
union DXR1_REG { Uint16 all; struct MCBSP_WORD_BITS bit; };

/* SPCR2: transmitter, sample-rate and frame-sync generator resets, XRDY/XEMPTY. */
struct SPCR2_BITS {
    Uint16 XRST:1;      /* 0 transmitter out of reset */
    Uint16 XRDY:1;      /* 1 DXR ready (read-only) */
    Uint16 XEMPTY:1;    /* 2 0 = XSR empty (read-only) */
    Uint16 XSYNCERR:1;  /* 3 */
    Uint16 XINTM:2;     /* 5:4 */
    Uint16 GRST:1;      /* 6 sample-rate generator out of reset */
    Uint16 FRST:1;      /* 7 frame-sync generator out of reset */
    Uint16 SOFT:1;      /* 8 */
    Uint16 FREE:1;      /* 9 */
    Uint16 rsvd:6;
};
union SPCR2_REG { Uint16 all; struct SPCR2_BITS bit; };

/* SPCR1: receiver reset, RRDY/RFULL, clock-stop (SPI) mode, digital loopback. */
struct SPCR1_BITS {
    Uint16 RRST:1;      /* 0 receiver out of reset */
    Uint16 RRDY:1;      /* 1 DRR ready (read-only) */
    Uint16 RFULL:1;     /* 2 overrun (read-only) */
    Uint16 RSYNCERR:1;  /* 3 */
    Uint16 RINTM:2;     /* 5:4 */
    Uint16 rsvd1:1;     /* 6 */
    Uint16 DXENA:1;     /* 7 */
    Uint16 rsvd2:3;     /* 10:8 */
    Uint16 CLKSTP:2;    /* 12:11 2 or 3: SPI mode */
    Uint16 RJUST:2;     /* 14:13 */
    Uint16 DLB:1;       /* 15 digital loopback */
};
union SPCR1_REG { Uint16 all; struct SPCR1_BITS bit; };

/* RCR2/RCR1, XCR2/XCR1: phases, frame lengths, word lengths (0-5: 8, 12, 16, 20, 24, 32 bits), delay. */
struct RCR2_BITS {
    Uint16 RDATDLY:2;   /* 1:0 */
    Uint16 RFIG:1;      /* 2 */
    Uint16 RCOMPAND:2;  /* 4:3 */
    Uint16 RWDLEN2:3;   /* 7:5 */
    Uint16 RFRLEN2:7;   /* 14:8 */
    Uint16 RPHASE:1;    /* 15 */
};
union RCR2_REG { Uint16 all; struct RCR2_BITS bit; };
struct RCR1_BITS {
    Uint16 rsvd1:5;
    Uint16 RWDLEN1:3;   /* 7:5 */
    Uint16 RFRLEN1:7;   /* 14:8 */
    Uint16 rsvd2:1;
};
union RCR1_REG { Uint16 all; struct RCR1_BITS bit; };
struct XCR2_BITS {
    Uint16 XDATDLY:2;
    Uint16 XFIG:1;
    Uint16 XCOMPAND:2;
    Uint16 XWDLEN2:3;
    Uint16 XFRLEN2:7;
    Uint16 XPHASE:1;
};
union XCR2_REG { Uint16 all; struct XCR2_BITS bit; };
struct XCR1_BITS {
    Uint16 rsvd1:5;
    Uint16 XWDLEN1:3;
    Uint16 XFRLEN1:7;
    Uint16 rsvd2:1;
};
union XCR1_REG { Uint16 all; struct XCR1_BITS bit; };

/* SRGR2/SRGR1: the sample-rate generator (CLKG = LSPCLK / (CLKGDV + 1) with CLKSM = 1). */
struct SRGR2_BITS {
    Uint16 FPER:12;     /* 11:0 */
    Uint16 FSGM:1;      /* 12 */
    Uint16 CLKSM:1;     /* 13 */
    Uint16 rsvd:1;      /* 14 */
    Uint16 GSYNC:1;     /* 15 */
};
union SRGR2_REG { Uint16 all; struct SRGR2_BITS bit; };
struct SRGR1_BITS {
    Uint16 CLKGDV:8;    /* 7:0 */
    Uint16 FWID:8;      /* 15:8 */
};
union SRGR1_REG { Uint16 all; struct SRGR1_BITS bit; };

/* MCR2/MCR1: multichannel selection. */
struct MCR2_BITS {
    Uint16 XMCM:2;
    Uint16 XCBLK:3;
    Uint16 XPABLK:2;
    Uint16 XPBBLK:2;
    Uint16 XMCME:1;
    Uint16 rsvd:6;
};
union MCR2_REG { Uint16 all; struct MCR2_BITS bit; };
struct MCR1_BITS {
    Uint16 RMCM:1;
    Uint16 rsvd1:1;
    Uint16 RCBLK:3;
    Uint16 RPABLK:2;
    Uint16 RPBBLK:2;
    Uint16 RMCME:1;
    Uint16 rsvd2:6;
};
union MCR1_REG { Uint16 all; struct MCR1_BITS bit; };

/* Channel enables (RCERA-XCERH): one bit per channel. */
union MCBSP_CER_REG { Uint16 all; struct MCBSP_WORD_BITS bit; };

/* PCR: pin control (clock and frame-sync polarities and sources). */
struct PCR_BITS {
    Uint16 CLKRP:1;     /* 0 */
    Uint16 CLKXP:1;     /* 1 */
    Uint16 FSRP:1;      /* 2 */
    Uint16 FSXP:1;      /* 3 */
    Uint16 DR_STAT:1;   /* 4 */
    Uint16 DX_STAT:1;   /* 5 */
    Uint16 CLKS_STAT:1; /* 6 */
    Uint16 SCLKME:1;    /* 7 */
    Uint16 CLKRM:1;     /* 8 */
    Uint16 CLKXM:1;     /* 9 */
    Uint16 FSRM:1;      /* 10 */
    Uint16 FSXM:1;      /* 11 */
    Uint16 rsvd:4;
};
union PCR_REG { Uint16 all; struct PCR_BITS bit; };

/* MFFINT: the McBSP's interrupt enables. */
struct MFFINT_BITS {
    Uint16 XINT:1;      /* 0 */
    Uint16 rsvd1:1;
    Uint16 RINT:1;      /* 2 */
    Uint16 rsvd2:13;
};
union MFFINT_REG { Uint16 all; struct MFFINT_BITS bit; };

struct MCBSP_REGS {
    union DRR2_REG DRR2;        /* +0x00 */
    union DRR1_REG DRR1;        /* +0x01 */
    union DXR2_REG DXR2;        /* +0x02 */
    union DXR1_REG DXR1;        /* +0x03 */
    union SPCR2_REG SPCR2;      /* +0x04 */
    union SPCR1_REG SPCR1;      /* +0x05 */
    union RCR2_REG RCR2;        /* +0x06 */
    union RCR1_REG RCR1;        /* +0x07 */
    union XCR2_REG XCR2;        /* +0x08 */
    union XCR1_REG XCR1;        /* +0x09 */
    union SRGR2_REG SRGR2;      /* +0x0A */
    union SRGR1_REG SRGR1;      /* +0x0B */
    union MCR2_REG MCR2;        /* +0x0C */
    union MCR1_REG MCR1;        /* +0x0D */
    union MCBSP_CER_REG RCERA;  /* +0x0E */
    union MCBSP_CER_REG RCERB;  /* +0x0F */
    union MCBSP_CER_REG XCERA;  /* +0x10 */
    union MCBSP_CER_REG XCERB;  /* +0x11 */
    union PCR_REG PCR;          /* +0x12 */
    union MCBSP_CER_REG RCERC;  /* +0x13 */
    union MCBSP_CER_REG RCERD;  /* +0x14 */
    union MCBSP_CER_REG XCERC;  /* +0x15 */
    union MCBSP_CER_REG XCERD;  /* +0x16 */
    union MCBSP_CER_REG RCERE;  /* +0x17 */
    union MCBSP_CER_REG RCERF;  /* +0x18 */
    union MCBSP_CER_REG XCERE;  /* +0x19 */
    union MCBSP_CER_REG XCERF;  /* +0x1A */
    union MCBSP_CER_REG RCERG;  /* +0x1B */
    union MCBSP_CER_REG RCERH;  /* +0x1C */
    union MCBSP_CER_REG XCERG;  /* +0x1D */
    union MCBSP_CER_REG XCERH;  /* +0x1E */
    Uint16 rsvd1[4];            /* +0x1F */
    union MFFINT_REG MFFINT;    /* +0x23 */
};

extern volatile struct MCBSP_REGS McbspaRegs;
extern volatile struct MCBSP_REGS McbspbRegs;

#ifdef __cplusplus
}
#endif

#endif
