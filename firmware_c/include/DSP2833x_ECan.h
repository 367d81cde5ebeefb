/* Replacement for TI's DSP2833x_ECan.h in a host build: eCAN-A/B's control registers (ECanaRegs 0x6000,
   ECanbRegs 0x6200), acceptance masks (LAM, +0x40), time stamps (MOTS +0x80, MOTO +0xC0) and 32
   mailboxes (+0x100), with TI's layout and field names (F2833x eCAN reference guide SPRUEU1). Not
   modelled: the registers read and write with their reset values (CANMC, CANBTC, CANTIOC and CANRIOC
   EALLOW-protected), CANES.CCE follows CANMC.CCR so that TI's initialisation does not wait forever, and
   the first use is reported once (`unmodelled_peripheral`); no frame is sent or received. TI's idiom of
   whole-register copies through a shadow (`struct ECAN_REGS ECanaShadow`) works as on the chip. */
#ifndef DSP2833x_ECAN_H
#define DSP2833x_ECAN_H

#ifdef __cplusplus
extern "C" {
#endif

struct CANME_BITS {
    Uint32 ME0:1;
    Uint32 ME1:1;
    Uint32 ME2:1;
    Uint32 ME3:1;
    Uint32 ME4:1;
    Uint32 ME5:1;
    Uint32 ME6:1;
    Uint32 ME7:1;
    Uint32 ME8:1;
    Uint32 ME9:1;
    Uint32 ME10:1;
    Uint32 ME11:1;
    Uint32 ME12:1;
    Uint32 ME13:1;
    Uint32 ME14:1;
    Uint32 ME15:1;
    Uint32 ME16:1;
    Uint32 ME17:1;
    Uint32 ME18:1;
    Uint32 ME19:1;
    Uint32 ME20:1;
    Uint32 ME21:1;
    Uint32 ME22:1;
    Uint32 ME23:1;
    Uint32 ME24:1;
    Uint32 ME25:1;
    Uint32 ME26:1;
    Uint32 ME27:1;
    Uint32 ME28:1;
    Uint32 ME29:1;
    Uint32 ME30:1;
    Uint32 ME31:1;
};
union CANME_REG {
    Uint32 all;
    struct CANME_BITS bit;
};

struct CANMD_BITS {
    Uint32 MD0:1;
    Uint32 MD1:1;
    Uint32 MD2:1;
    Uint32 MD3:1;
    Uint32 MD4:1;
    Uint32 MD5:1;
    Uint32 MD6:1;
    Uint32 MD7:1;
    Uint32 MD8:1;
    Uint32 MD9:1;
    Uint32 MD10:1;
    Uint32 MD11:1;
    Uint32 MD12:1;
    Uint32 MD13:1;
    Uint32 MD14:1;
    Uint32 MD15:1;
    Uint32 MD16:1;
    Uint32 MD17:1;
    Uint32 MD18:1;
    Uint32 MD19:1;
    Uint32 MD20:1;
    Uint32 MD21:1;
    Uint32 MD22:1;
    Uint32 MD23:1;
    Uint32 MD24:1;
    Uint32 MD25:1;
    Uint32 MD26:1;
    Uint32 MD27:1;
    Uint32 MD28:1;
    Uint32 MD29:1;
    Uint32 MD30:1;
    Uint32 MD31:1;
};
union CANMD_REG {
    Uint32 all;
    struct CANMD_BITS bit;
};

struct CANTRS_BITS {
    Uint32 TRS0:1;
    Uint32 TRS1:1;
    Uint32 TRS2:1;
    Uint32 TRS3:1;
    Uint32 TRS4:1;
    Uint32 TRS5:1;
    Uint32 TRS6:1;
    Uint32 TRS7:1;
    Uint32 TRS8:1;
    Uint32 TRS9:1;
    Uint32 TRS10:1;
    Uint32 TRS11:1;
    Uint32 TRS12:1;
    Uint32 TRS13:1;
    Uint32 TRS14:1;
    Uint32 TRS15:1;
    Uint32 TRS16:1;
    Uint32 TRS17:1;
    Uint32 TRS18:1;
    Uint32 TRS19:1;
    Uint32 TRS20:1;
    Uint32 TRS21:1;
    Uint32 TRS22:1;
    Uint32 TRS23:1;
    Uint32 TRS24:1;
    Uint32 TRS25:1;
    Uint32 TRS26:1;
    Uint32 TRS27:1;
    Uint32 TRS28:1;
    Uint32 TRS29:1;
    Uint32 TRS30:1;
    Uint32 TRS31:1;
};
union CANTRS_REG {
    Uint32 all;
    struct CANTRS_BITS bit;
};

struct CANTRR_BITS {
    Uint32 TRR0:1;
    Uint32 TRR1:1;
    Uint32 TRR2:1;
    Uint32 TRR3:1;
    Uint32 TRR4:1;
    Uint32 TRR5:1;
    Uint32 TRR6:1;
    Uint32 TRR7:1;
    Uint32 TRR8:1;
    Uint32 TRR9:1;
    Uint32 TRR10:1;
    Uint32 TRR11:1;
    Uint32 TRR12:1;
    Uint32 TRR13:1;
    Uint32 TRR14:1;
    Uint32 TRR15:1;
    Uint32 TRR16:1;
    Uint32 TRR17:1;
    Uint32 TRR18:1;
    Uint32 TRR19:1;
    Uint32 TRR20:1;
    Uint32 TRR21:1;
    Uint32 TRR22:1;
    Uint32 TRR23:1;
    Uint32 TRR24:1;
    Uint32 TRR25:1;
    Uint32 TRR26:1;
    Uint32 TRR27:1;
    Uint32 TRR28:1;
    Uint32 TRR29:1;
    Uint32 TRR30:1;
    Uint32 TRR31:1;
};
union CANTRR_REG {
    Uint32 all;
    struct CANTRR_BITS bit;
};

struct CANTA_BITS {
    Uint32 TA0:1;
    Uint32 TA1:1;
    Uint32 TA2:1;
    Uint32 TA3:1;
    Uint32 TA4:1;
    Uint32 TA5:1;
    Uint32 TA6:1;
    Uint32 TA7:1;
    Uint32 TA8:1;
    Uint32 TA9:1;
    Uint32 TA10:1;
    Uint32 TA11:1;
    Uint32 TA12:1;
    Uint32 TA13:1;
    Uint32 TA14:1;
    Uint32 TA15:1;
    Uint32 TA16:1;
    Uint32 TA17:1;
    Uint32 TA18:1;
    Uint32 TA19:1;
    Uint32 TA20:1;
    Uint32 TA21:1;
    Uint32 TA22:1;
    Uint32 TA23:1;
    Uint32 TA24:1;
    Uint32 TA25:1;
    Uint32 TA26:1;
    Uint32 TA27:1;
    Uint32 TA28:1;
    Uint32 TA29:1;
    Uint32 TA30:1;
    Uint32 TA31:1;
};
union CANTA_REG {
    Uint32 all;
    struct CANTA_BITS bit;
};

struct CANAA_BITS {
    Uint32 AA0:1;
    Uint32 AA1:1;
    Uint32 AA2:1;
    Uint32 AA3:1;
    Uint32 AA4:1;
    Uint32 AA5:1;
    Uint32 AA6:1;
    Uint32 AA7:1;
    Uint32 AA8:1;
    Uint32 AA9:1;
    Uint32 AA10:1;
    Uint32 AA11:1;
    Uint32 AA12:1;
    Uint32 AA13:1;
    Uint32 AA14:1;
    Uint32 AA15:1;
    Uint32 AA16:1;
    Uint32 AA17:1;
    Uint32 AA18:1;
    Uint32 AA19:1;
    Uint32 AA20:1;
    Uint32 AA21:1;
    Uint32 AA22:1;
    Uint32 AA23:1;
    Uint32 AA24:1;
    Uint32 AA25:1;
    Uint32 AA26:1;
    Uint32 AA27:1;
    Uint32 AA28:1;
    Uint32 AA29:1;
    Uint32 AA30:1;
    Uint32 AA31:1;
};
union CANAA_REG {
    Uint32 all;
    struct CANAA_BITS bit;
};

struct CANRMP_BITS {
    Uint32 RMP0:1;
    Uint32 RMP1:1;
    Uint32 RMP2:1;
    Uint32 RMP3:1;
    Uint32 RMP4:1;
    Uint32 RMP5:1;
    Uint32 RMP6:1;
    Uint32 RMP7:1;
    Uint32 RMP8:1;
    Uint32 RMP9:1;
    Uint32 RMP10:1;
    Uint32 RMP11:1;
    Uint32 RMP12:1;
    Uint32 RMP13:1;
    Uint32 RMP14:1;
    Uint32 RMP15:1;
    Uint32 RMP16:1;
    Uint32 RMP17:1;
    Uint32 RMP18:1;
    Uint32 RMP19:1;
    Uint32 RMP20:1;
    Uint32 RMP21:1;
    Uint32 RMP22:1;
    Uint32 RMP23:1;
    Uint32 RMP24:1;
    Uint32 RMP25:1;
    Uint32 RMP26:1;
    Uint32 RMP27:1;
    Uint32 RMP28:1;
    Uint32 RMP29:1;
    Uint32 RMP30:1;
    Uint32 RMP31:1;
};
union CANRMP_REG {
    Uint32 all;
    struct CANRMP_BITS bit;
};

struct CANRML_BITS {
    Uint32 RML0:1;
    Uint32 RML1:1;
    Uint32 RML2:1;
    Uint32 RML3:1;
    Uint32 RML4:1;
    Uint32 RML5:1;
    Uint32 RML6:1;
    Uint32 RML7:1;
    Uint32 RML8:1;
    Uint32 RML9:1;
    Uint32 RML10:1;
    Uint32 RML11:1;
    Uint32 RML12:1;
    Uint32 RML13:1;
    Uint32 RML14:1;
    Uint32 RML15:1;
    Uint32 RML16:1;
    Uint32 RML17:1;
    Uint32 RML18:1;
    Uint32 RML19:1;
    Uint32 RML20:1;
    Uint32 RML21:1;
    Uint32 RML22:1;
    Uint32 RML23:1;
    Uint32 RML24:1;
    Uint32 RML25:1;
    Uint32 RML26:1;
    Uint32 RML27:1;
    Uint32 RML28:1;
    Uint32 RML29:1;
    Uint32 RML30:1;
    Uint32 RML31:1;
};
union CANRML_REG {
    Uint32 all;
    struct CANRML_BITS bit;
};

struct CANRFP_BITS {
    Uint32 RFP0:1;
    Uint32 RFP1:1;
    Uint32 RFP2:1;
    Uint32 RFP3:1;
    Uint32 RFP4:1;
    Uint32 RFP5:1;
    Uint32 RFP6:1;
    Uint32 RFP7:1;
    Uint32 RFP8:1;
    Uint32 RFP9:1;
    Uint32 RFP10:1;
    Uint32 RFP11:1;
    Uint32 RFP12:1;
    Uint32 RFP13:1;
    Uint32 RFP14:1;
    Uint32 RFP15:1;
    Uint32 RFP16:1;
    Uint32 RFP17:1;
    Uint32 RFP18:1;
    Uint32 RFP19:1;
    Uint32 RFP20:1;
    Uint32 RFP21:1;
    Uint32 RFP22:1;
    Uint32 RFP23:1;
    Uint32 RFP24:1;
    Uint32 RFP25:1;
    Uint32 RFP26:1;
    Uint32 RFP27:1;
    Uint32 RFP28:1;
    Uint32 RFP29:1;
    Uint32 RFP30:1;
    Uint32 RFP31:1;
};
union CANRFP_REG {
    Uint32 all;
    struct CANRFP_BITS bit;
};

struct CANGAM_BITS {
    Uint32 GAM150:16;
    Uint32 GAM2816:13;
    Uint32 rsvd:2;
    Uint32 AMI:1;
};
union CANGAM_REG {
    Uint32 all;
    struct CANGAM_BITS bit;
};

struct CANMC_BITS {
    Uint32 MBNR:5;
    Uint32 SRES:1;
    Uint32 STM:1;
    Uint32 ABO:1;
    Uint32 CDR:1;
    Uint32 WUBA:1;
    Uint32 DBO:1;
    Uint32 PDR:1;
    Uint32 CCR:1;
    Uint32 SCB:1;
    Uint32 TCC:1;
    Uint32 MBCC:1;
    Uint32 SUSP:1;
    Uint32 rsvd:15;
};
union CANMC_REG {
    Uint32 all;
    struct CANMC_BITS bit;
};

struct CANBTC_BITS {
    Uint32 TSEG2REG:3;
    Uint32 TSEG1REG:4;
    Uint32 SAM:1;
    Uint32 SJWREG:2;
    Uint32 rsvd1:6;
    Uint32 BRPREG:8;
    Uint32 rsvd2:8;
};
union CANBTC_REG {
    Uint32 all;
    struct CANBTC_BITS bit;
};

struct CANES_BITS {
    Uint32 TM:1;
    Uint32 RM:1;
    Uint32 rsvd1:1;
    Uint32 PDA:1;
    Uint32 CCE:1;
    Uint32 SMA:1;
    Uint32 rsvd2:10;
    Uint32 EW:1;
    Uint32 EP:1;
    Uint32 BO:1;
    Uint32 ACKE:1;
    Uint32 SE:1;
    Uint32 CRCE:1;
    Uint32 SA1:1;
    Uint32 BE:1;
    Uint32 FE:1;
    Uint32 rsvd3:7;
};
union CANES_REG {
    Uint32 all;
    struct CANES_BITS bit;
};

struct CANTEC_BITS {
    Uint32 TEC:8;
    Uint32 rsvd1:24;
};
union CANTEC_REG {
    Uint32 all;
    struct CANTEC_BITS bit;
};

struct CANREC_BITS {
    Uint32 REC:8;
    Uint32 rsvd1:24;
};
union CANREC_REG {
    Uint32 all;
    struct CANREC_BITS bit;
};

struct CANGIF_BITS {
    Uint32 MIV:5;
    Uint32 rsvd1:3;
    Uint32 WLIF:1;
    Uint32 EPIF:1;
    Uint32 BOIF:1;
    Uint32 RMLIF:1;
    Uint32 WUIF:1;
    Uint32 WDIF:1;
    Uint32 AAIF:1;
    Uint32 GMIF:1;
    Uint32 TCOF:1;
    Uint32 MTOF:1;
    Uint32 rsvd2:14;
};
union CANGIF_REG {
    Uint32 all;
    struct CANGIF_BITS bit;
};

struct CANGIM_BITS {
    Uint32 I0EN:1;
    Uint32 I1EN:1;
    Uint32 GIL:1;
    Uint32 rsvd1:5;
    Uint32 WLIM:1;
    Uint32 EPIM:1;
    Uint32 BOIM:1;
    Uint32 RMLIM:1;
    Uint32 WUIM:1;
    Uint32 WDIM:1;
    Uint32 AAIM:1;
    Uint32 rsvd2:1;
    Uint32 TCOM:1;
    Uint32 MTOM:1;
    Uint32 rsvd3:14;
};
union CANGIM_REG {
    Uint32 all;
    struct CANGIM_BITS bit;
};

struct CANMIM_BITS {
    Uint32 MIM0:1;
    Uint32 MIM1:1;
    Uint32 MIM2:1;
    Uint32 MIM3:1;
    Uint32 MIM4:1;
    Uint32 MIM5:1;
    Uint32 MIM6:1;
    Uint32 MIM7:1;
    Uint32 MIM8:1;
    Uint32 MIM9:1;
    Uint32 MIM10:1;
    Uint32 MIM11:1;
    Uint32 MIM12:1;
    Uint32 MIM13:1;
    Uint32 MIM14:1;
    Uint32 MIM15:1;
    Uint32 MIM16:1;
    Uint32 MIM17:1;
    Uint32 MIM18:1;
    Uint32 MIM19:1;
    Uint32 MIM20:1;
    Uint32 MIM21:1;
    Uint32 MIM22:1;
    Uint32 MIM23:1;
    Uint32 MIM24:1;
    Uint32 MIM25:1;
    Uint32 MIM26:1;
    Uint32 MIM27:1;
    Uint32 MIM28:1;
    Uint32 MIM29:1;
    Uint32 MIM30:1;
    Uint32 MIM31:1;
};
union CANMIM_REG {
    Uint32 all;
    struct CANMIM_BITS bit;
};

struct CANMIL_BITS {
    Uint32 MIL0:1;
    Uint32 MIL1:1;
    Uint32 MIL2:1;
    Uint32 MIL3:1;
    Uint32 MIL4:1;
    Uint32 MIL5:1;
    Uint32 MIL6:1;
    Uint32 MIL7:1;
    Uint32 MIL8:1;
    Uint32 MIL9:1;
    Uint32 MIL10:1;
    Uint32 MIL11:1;
    Uint32 MIL12:1;
    Uint32 MIL13:1;
    Uint32 MIL14:1;
    Uint32 MIL15:1;
    Uint32 MIL16:1;
    Uint32 MIL17:1;
    Uint32 MIL18:1;
    Uint32 MIL19:1;
    Uint32 MIL20:1;
    Uint32 MIL21:1;
    Uint32 MIL22:1;
    Uint32 MIL23:1;
    Uint32 MIL24:1;
    Uint32 MIL25:1;
    Uint32 MIL26:1;
    Uint32 MIL27:1;
    Uint32 MIL28:1;
    Uint32 MIL29:1;
    Uint32 MIL30:1;
    Uint32 MIL31:1;
};
union CANMIL_REG {
    Uint32 all;
    struct CANMIL_BITS bit;
};

struct CANOPC_BITS {
    Uint32 OPC0:1;
    Uint32 OPC1:1;
    Uint32 OPC2:1;
    Uint32 OPC3:1;
    Uint32 OPC4:1;
    Uint32 OPC5:1;
    Uint32 OPC6:1;
    Uint32 OPC7:1;
    Uint32 OPC8:1;
    Uint32 OPC9:1;
    Uint32 OPC10:1;
    Uint32 OPC11:1;
    Uint32 OPC12:1;
    Uint32 OPC13:1;
    Uint32 OPC14:1;
    Uint32 OPC15:1;
    Uint32 OPC16:1;
    Uint32 OPC17:1;
    Uint32 OPC18:1;
    Uint32 OPC19:1;
    Uint32 OPC20:1;
    Uint32 OPC21:1;
    Uint32 OPC22:1;
    Uint32 OPC23:1;
    Uint32 OPC24:1;
    Uint32 OPC25:1;
    Uint32 OPC26:1;
    Uint32 OPC27:1;
    Uint32 OPC28:1;
    Uint32 OPC29:1;
    Uint32 OPC30:1;
    Uint32 OPC31:1;
};
union CANOPC_REG {
    Uint32 all;
    struct CANOPC_BITS bit;
};

struct CANTIOC_BITS {
    Uint32 rsvd1:3;
    Uint32 TXFUNC:1;
    Uint32 rsvd2:28;
};
union CANTIOC_REG {
    Uint32 all;
    struct CANTIOC_BITS bit;
};

struct CANRIOC_BITS {
    Uint32 rsvd1:3;
    Uint32 RXFUNC:1;
    Uint32 rsvd2:28;
};
union CANRIOC_REG {
    Uint32 all;
    struct CANRIOC_BITS bit;
};

struct CANTOC_BITS {
    Uint32 TOC0:1;
    Uint32 TOC1:1;
    Uint32 TOC2:1;
    Uint32 TOC3:1;
    Uint32 TOC4:1;
    Uint32 TOC5:1;
    Uint32 TOC6:1;
    Uint32 TOC7:1;
    Uint32 TOC8:1;
    Uint32 TOC9:1;
    Uint32 TOC10:1;
    Uint32 TOC11:1;
    Uint32 TOC12:1;
    Uint32 TOC13:1;
    Uint32 TOC14:1;
    Uint32 TOC15:1;
    Uint32 TOC16:1;
    Uint32 TOC17:1;
    Uint32 TOC18:1;
    Uint32 TOC19:1;
    Uint32 TOC20:1;
    Uint32 TOC21:1;
    Uint32 TOC22:1;
    Uint32 TOC23:1;
    Uint32 TOC24:1;
    Uint32 TOC25:1;
    Uint32 TOC26:1;
    Uint32 TOC27:1;
    Uint32 TOC28:1;
    Uint32 TOC29:1;
    Uint32 TOC30:1;
    Uint32 TOC31:1;
};
union CANTOC_REG {
    Uint32 all;
    struct CANTOC_BITS bit;
};

struct CANTOS_BITS {
    Uint32 TOS0:1;
    Uint32 TOS1:1;
    Uint32 TOS2:1;
    Uint32 TOS3:1;
    Uint32 TOS4:1;
    Uint32 TOS5:1;
    Uint32 TOS6:1;
    Uint32 TOS7:1;
    Uint32 TOS8:1;
    Uint32 TOS9:1;
    Uint32 TOS10:1;
    Uint32 TOS11:1;
    Uint32 TOS12:1;
    Uint32 TOS13:1;
    Uint32 TOS14:1;
    Uint32 TOS15:1;
    Uint32 TOS16:1;
    Uint32 TOS17:1;
    Uint32 TOS18:1;
    Uint32 TOS19:1;
    Uint32 TOS20:1;
    Uint32 TOS21:1;
    Uint32 TOS22:1;
    Uint32 TOS23:1;
    Uint32 TOS24:1;
    Uint32 TOS25:1;
    Uint32 TOS26:1;
    Uint32 TOS27:1;
    Uint32 TOS28:1;
    Uint32 TOS29:1;
    Uint32 TOS30:1;
    Uint32 TOS31:1;
};
union CANTOS_REG {
    Uint32 all;
    struct CANTOS_BITS bit;
};

struct ECAN_REGS {
    union CANME_REG CANME; /* +0x00 */
    union CANMD_REG CANMD; /* +0x02 */
    union CANTRS_REG CANTRS; /* +0x04 */
    union CANTRR_REG CANTRR; /* +0x06 */
    union CANTA_REG CANTA; /* +0x08 */
    union CANAA_REG CANAA; /* +0x0A */
    union CANRMP_REG CANRMP; /* +0x0C */
    union CANRML_REG CANRML; /* +0x0E */
    union CANRFP_REG CANRFP; /* +0x10 */
    union CANGAM_REG CANGAM; /* +0x12 */
    union CANMC_REG CANMC; /* +0x14 */
    union CANBTC_REG CANBTC; /* +0x16 */
    union CANES_REG CANES; /* +0x18 */
    union CANTEC_REG CANTEC; /* +0x1A */
    union CANREC_REG CANREC; /* +0x1C */
    union CANGIF_REG CANGIF0; /* +0x1E */
    union CANGIM_REG CANGIM; /* +0x20 */
    union CANGIF_REG CANGIF1; /* +0x22 */
    union CANMIM_REG CANMIM; /* +0x24 */
    union CANMIL_REG CANMIL; /* +0x26 */
    union CANOPC_REG CANOPC; /* +0x28 */
    union CANTIOC_REG CANTIOC; /* +0x2A */
    union CANRIOC_REG CANRIOC; /* +0x2C */
    Uint32 CANTSC; /* +0x2E */
    union CANTOC_REG CANTOC; /* +0x30 */
    union CANTOS_REG CANTOS; /* +0x32 */
};

struct CANLAM_BITS {
    Uint32 LAM_L:16;
    Uint32 LAM_H:13;
    Uint32 rsvd1:2;
    Uint32 LAMI:1;
};
union CANLAM_REG {
    Uint32 all;
    struct CANLAM_BITS bit;
};

struct LAM_REGS {
    union CANLAM_REG LAM0; /* +0x00 */
    union CANLAM_REG LAM1; /* +0x02 */
    union CANLAM_REG LAM2; /* +0x04 */
    union CANLAM_REG LAM3; /* +0x06 */
    union CANLAM_REG LAM4; /* +0x08 */
    union CANLAM_REG LAM5; /* +0x0A */
    union CANLAM_REG LAM6; /* +0x0C */
    union CANLAM_REG LAM7; /* +0x0E */
    union CANLAM_REG LAM8; /* +0x10 */
    union CANLAM_REG LAM9; /* +0x12 */
    union CANLAM_REG LAM10; /* +0x14 */
    union CANLAM_REG LAM11; /* +0x16 */
    union CANLAM_REG LAM12; /* +0x18 */
    union CANLAM_REG LAM13; /* +0x1A */
    union CANLAM_REG LAM14; /* +0x1C */
    union CANLAM_REG LAM15; /* +0x1E */
    union CANLAM_REG LAM16; /* +0x20 */
    union CANLAM_REG LAM17; /* +0x22 */
    union CANLAM_REG LAM18; /* +0x24 */
    union CANLAM_REG LAM19; /* +0x26 */
    union CANLAM_REG LAM20; /* +0x28 */
    union CANLAM_REG LAM21; /* +0x2A */
    union CANLAM_REG LAM22; /* +0x2C */
    union CANLAM_REG LAM23; /* +0x2E */
    union CANLAM_REG LAM24; /* +0x30 */
    union CANLAM_REG LAM25; /* +0x32 */
    union CANLAM_REG LAM26; /* +0x34 */
    union CANLAM_REG LAM27; /* +0x36 */
    union CANLAM_REG LAM28; /* +0x38 */
    union CANLAM_REG LAM29; /* +0x3A */
    union CANLAM_REG LAM30; /* +0x3C */
    union CANLAM_REG LAM31; /* +0x3E */
};

struct MOTS_REGS {
    Uint32 MOTS0; /* +0x00 */
    Uint32 MOTS1; /* +0x02 */
    Uint32 MOTS2; /* +0x04 */
    Uint32 MOTS3; /* +0x06 */
    Uint32 MOTS4; /* +0x08 */
    Uint32 MOTS5; /* +0x0A */
    Uint32 MOTS6; /* +0x0C */
    Uint32 MOTS7; /* +0x0E */
    Uint32 MOTS8; /* +0x10 */
    Uint32 MOTS9; /* +0x12 */
    Uint32 MOTS10; /* +0x14 */
    Uint32 MOTS11; /* +0x16 */
    Uint32 MOTS12; /* +0x18 */
    Uint32 MOTS13; /* +0x1A */
    Uint32 MOTS14; /* +0x1C */
    Uint32 MOTS15; /* +0x1E */
    Uint32 MOTS16; /* +0x20 */
    Uint32 MOTS17; /* +0x22 */
    Uint32 MOTS18; /* +0x24 */
    Uint32 MOTS19; /* +0x26 */
    Uint32 MOTS20; /* +0x28 */
    Uint32 MOTS21; /* +0x2A */
    Uint32 MOTS22; /* +0x2C */
    Uint32 MOTS23; /* +0x2E */
    Uint32 MOTS24; /* +0x30 */
    Uint32 MOTS25; /* +0x32 */
    Uint32 MOTS26; /* +0x34 */
    Uint32 MOTS27; /* +0x36 */
    Uint32 MOTS28; /* +0x38 */
    Uint32 MOTS29; /* +0x3A */
    Uint32 MOTS30; /* +0x3C */
    Uint32 MOTS31; /* +0x3E */
};

struct MOTO_REGS {
    Uint32 MOTO0; /* +0x00 */
    Uint32 MOTO1; /* +0x02 */
    Uint32 MOTO2; /* +0x04 */
    Uint32 MOTO3; /* +0x06 */
    Uint32 MOTO4; /* +0x08 */
    Uint32 MOTO5; /* +0x0A */
    Uint32 MOTO6; /* +0x0C */
    Uint32 MOTO7; /* +0x0E */
    Uint32 MOTO8; /* +0x10 */
    Uint32 MOTO9; /* +0x12 */
    Uint32 MOTO10; /* +0x14 */
    Uint32 MOTO11; /* +0x16 */
    Uint32 MOTO12; /* +0x18 */
    Uint32 MOTO13; /* +0x1A */
    Uint32 MOTO14; /* +0x1C */
    Uint32 MOTO15; /* +0x1E */
    Uint32 MOTO16; /* +0x20 */
    Uint32 MOTO17; /* +0x22 */
    Uint32 MOTO18; /* +0x24 */
    Uint32 MOTO19; /* +0x26 */
    Uint32 MOTO20; /* +0x28 */
    Uint32 MOTO21; /* +0x2A */
    Uint32 MOTO22; /* +0x2C */
    Uint32 MOTO23; /* +0x2E */
    Uint32 MOTO24; /* +0x30 */
    Uint32 MOTO25; /* +0x32 */
    Uint32 MOTO26; /* +0x34 */
    Uint32 MOTO27; /* +0x36 */
    Uint32 MOTO28; /* +0x38 */
    Uint32 MOTO29; /* +0x3A */
    Uint32 MOTO30; /* +0x3C */
    Uint32 MOTO31; /* +0x3E */
};

struct CANMSGID_BITS {
    Uint32 EXTMSGID_L:16;
    Uint32 EXTMSGID_H:2;
    Uint32 STDMSGID:11;
    Uint32 AAM:1;
    Uint32 AME:1;
    Uint32 IDE:1;
};
union CANMSGID_REG {
    Uint32 all;
    struct CANMSGID_BITS bit;
};

struct CANMSGCTRL_BITS {
    Uint32 DLC:4;
    Uint32 RTR:1;
    Uint32 rsvd1:3;
    Uint32 TPL:5;
    Uint32 rsvd2:19;
};
union CANMSGCTRL_REG {
    Uint32 all;
    struct CANMSGCTRL_BITS bit;
};

struct CANMDL_BITS {
    Uint32 LOW_WORD:16;
    Uint32 HI_WORD:16;
};
union CANMDL_REG {
    Uint32 all;
    struct CANMDL_BITS bit;
};

struct CANMDH_BITS {
    Uint32 LOW_WORD:16;
    Uint32 HI_WORD:16;
};
union CANMDH_REG {
    Uint32 all;
    struct CANMDH_BITS bit;
};

struct MBOX {
    union CANMSGID_REG MSGID; /* +0x00 */
    union CANMSGCTRL_REG MSGCTRL; /* +0x02 */
    union CANMDL_REG MDL; /* +0x04 */
    union CANMDH_REG MDH; /* +0x06 */
};

struct ECAN_MBOXES {
    struct MBOX MBOX0; /* +0x00 */
    struct MBOX MBOX1; /* +0x08 */
    struct MBOX MBOX2; /* +0x10 */
    struct MBOX MBOX3; /* +0x18 */
    struct MBOX MBOX4; /* +0x20 */
    struct MBOX MBOX5; /* +0x28 */
    struct MBOX MBOX6; /* +0x30 */
    struct MBOX MBOX7; /* +0x38 */
    struct MBOX MBOX8; /* +0x40 */
    struct MBOX MBOX9; /* +0x48 */
    struct MBOX MBOX10; /* +0x50 */
    struct MBOX MBOX11; /* +0x58 */
    struct MBOX MBOX12; /* +0x60 */
    struct MBOX MBOX13; /* +0x68 */
    struct MBOX MBOX14; /* +0x70 */
    struct MBOX MBOX15; /* +0x78 */
    struct MBOX MBOX16; /* +0x80 */
    struct MBOX MBOX17; /* +0x88 */
    struct MBOX MBOX18; /* +0x90 */
    struct MBOX MBOX19; /* +0x98 */
    struct MBOX MBOX20; /* +0xA0 */
    struct MBOX MBOX21; /* +0xA8 */
    struct MBOX MBOX22; /* +0xB0 */
    struct MBOX MBOX23; /* +0xB8 */
    struct MBOX MBOX24; /* +0xC0 */
    struct MBOX MBOX25; /* +0xC8 */
    struct MBOX MBOX26; /* +0xD0 */
    struct MBOX MBOX27; /* +0xD8 */
    struct MBOX MBOX28; /* +0xE0 */
    struct MBOX MBOX29; /* +0xE8 */
    struct MBOX MBOX30; /* +0xF0 */
    struct MBOX MBOX31; /* +0xF8 */
};

extern volatile struct ECAN_REGS ECanaRegs;
extern volatile struct ECAN_REGS ECanbRegs;
extern volatile struct ECAN_MBOXES ECanaMboxes;
extern volatile struct ECAN_MBOXES ECanbMboxes;
extern volatile struct LAM_REGS ECanaLAMRegs;
extern volatile struct LAM_REGS ECanbLAMRegs;
extern volatile struct MOTS_REGS ECanaMOTSRegs;
extern volatile struct MOTS_REGS ECanbMOTSRegs;
extern volatile struct MOTO_REGS ECanaMOTORegs;
extern volatile struct MOTO_REGS ECanbMOTORegs;

#ifdef __cplusplus
}
#endif

#endif
