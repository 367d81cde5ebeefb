/* Replacement for TI's DSP2833x_Xintf.h in a host build: the external interface's registers (XintfRegs
   at 0x0B20, EALLOW-protected) with TI's layout and field names (F2833x XINTF reference guide SPRU949).
   Not modelled: the registers read and write with their reset values (XTIMING0/6/7 0x0043FFFF,
   XINTCNF2 0x00010D00, XBANK 0x0038) and the first use is reported once (`unmodelled_peripheral`);
   no external memory is reached. */
#ifndef DSP2833x_XINTF_H
#define DSP2833x_XINTF_H

#ifdef __cplusplus
extern "C" {
#endif

struct XTIMING_BITS {
    Uint32 XWRTRAIL:2;
    Uint32 XWRACTIVE:3;
    Uint32 XWRLEAD:2;
    Uint32 XRDTRAIL:2;
    Uint32 XRDACTIVE:3;
    Uint32 XRDLEAD:2;
    Uint32 USEREADY:1;
    Uint32 READYMODE:1;
    Uint32 XSIZE:2;
    Uint32 rsvd1:4;
    Uint32 X2TIMING:1;
    Uint32 rsvd3:9;
};
union XTIMING_REG {
    Uint32 all;
    struct XTIMING_BITS bit;
};

struct XINTCNF2_BITS {
    Uint32 WRBUFF:2;
    Uint32 CLKMODE:1;
    Uint32 CLKOFF:1;
    Uint32 rsvd1:2;
    Uint32 WLEVEL:2;
    Uint32 rsvd2:1;
    Uint32 HOLD:1;
    Uint32 HOLDS:1;
    Uint32 HOLDAS:1;
    Uint32 rsvd3:4;
    Uint32 XTIMCLK:3;
    Uint32 rsvd4:13;
};
union XINTCNF2_REG {
    Uint32 all;
    struct XINTCNF2_BITS bit;
};

struct XBANK_BITS {
    Uint16 BANK:3;
    Uint16 BCYC:3;
    Uint16 rsvd:10;
};
union XBANK_REG {
    Uint16 all;
    struct XBANK_BITS bit;
};

struct XRESET_BITS {
    Uint16 XHARDRESET:1;
    Uint16 rsvd1:15;
};
union XRESET_REG {
    Uint16 all;
    struct XRESET_BITS bit;
};

struct XINTF_REGS {
    union XTIMING_REG XTIMING0; /* +0x00 */
    Uint16 rsvd1[10];
    union XTIMING_REG XTIMING6; /* +0x0C */
    union XTIMING_REG XTIMING7; /* +0x0E */
    Uint16 rsvd2[4];
    union XINTCNF2_REG XINTCNF2; /* +0x14 */
    Uint16 rsvd3[2];
    union XBANK_REG XBANK; /* +0x18 */
    Uint16 rsvd4[1];
    Uint16 XREVISION; /* +0x1A */
    Uint16 rsvd5[2];
    union XRESET_REG XRESET; /* +0x1D */
};

extern volatile struct XINTF_REGS XintfRegs;

#ifdef __cplusplus
}
#endif

#endif
