/* Replacement for TI's DSP2833x_EPwm.h in a host build: ePWM1-6 (EPwm1Regs at 0x6800, each next
   0x40 words on) with TI's layout and field names (F2833x ePWM reference guide SPRUG04). The ePWMs are
   not modelled: their registers read and write with their reset values (TBCTL 0x0083), the trip-zone
   registers and HRCNFG are EALLOW-protected, and the first use is reported once
   (`unmodelled_peripheral`, rust/core/src/dsp/unmodelled.rs); no output, event or interrupt is made. */
#ifndef DSP2833x_EPWM_H
#define DSP2833x_EPWM_H

#ifdef __cplusplus
extern "C" {
#endif

/* TBCTL and AQ field values (TI's DSP2833x_EPwm_defines.h names). */
#define TB_COUNT_UP 0x0
#define TB_COUNT_DOWN 0x1
#define TB_COUNT_UPDOWN 0x2
#define TB_FREEZE 0x3
#define TB_DISABLE 0x0
#define TB_ENABLE 0x1
#define TB_SHADOW 0x0
#define TB_IMMEDIATE 0x1
#define TB_SYNC_IN 0x0
#define TB_CTR_ZERO 0x1
#define TB_CTR_CMPB 0x2
#define TB_SYNC_DISABLE 0x3
#define TB_DIV1 0x0
#define TB_DIV2 0x1
#define TB_DIV4 0x2
#define CC_CTR_ZERO 0x0
#define CC_CTR_PRD 0x1
#define CC_CTR_ZERO_PRD 0x2
#define CC_SHADOW 0x0
#define CC_IMMEDIATE 0x1
#define AQ_NO_ACTION 0x0
#define AQ_CLEAR 0x1
#define AQ_SET 0x2
#define AQ_TOGGLE 0x3
#define ET_CTR_ZERO 0x1
#define ET_CTR_PRD 0x2
#define ET_CTRU_CMPA 0x4
#define ET_CTRD_CMPA 0x5
#define ET_CTRU_CMPB 0x6
#define ET_CTRD_CMPB 0x7
#define ET_1ST 0x1
#define ET_2ND 0x2
#define ET_3RD 0x3

struct TBCTL_BITS {
    Uint16 CTRMODE:2;
    Uint16 PHSEN:1;
    Uint16 PRDLD:1;
    Uint16 SYNCOSEL:2;
    Uint16 SWFSYNC:1;
    Uint16 HSPCLKDIV:3;
    Uint16 CLKDIV:3;
    Uint16 PHSDIR:1;
    Uint16 FREE_SOFT:2;
};
union TBCTL_REG {
    Uint16 all;
    struct TBCTL_BITS bit;
};

struct TBSTS_BITS {
    Uint16 CTRDIR:1;
    Uint16 SYNCI:1;
    Uint16 CTRMAX:1;
    Uint16 rsvd1:13;
};
union TBSTS_REG {
    Uint16 all;
    struct TBSTS_BITS bit;
};

struct CMPCTL_BITS {
    Uint16 LOADAMODE:2;
    Uint16 LOADBMODE:2;
    Uint16 SHDWAMODE:1;
    Uint16 rsvd1:1;
    Uint16 SHDWBMODE:1;
    Uint16 rsvd2:1;
    Uint16 SHDWAFULL:1;
    Uint16 SHDWBFULL:1;
    Uint16 rsvd3:6;
};
union CMPCTL_REG {
    Uint16 all;
    struct CMPCTL_BITS bit;
};

struct AQCTL_BITS {
    Uint16 ZRO:2;
    Uint16 PRD:2;
    Uint16 CAU:2;
    Uint16 CAD:2;
    Uint16 CBU:2;
    Uint16 CBD:2;
    Uint16 rsvd:4;
};
union AQCTL_REG {
    Uint16 all;
    struct AQCTL_BITS bit;
};

struct AQSFRC_BITS {
    Uint16 ACTSFA:2;
    Uint16 OTSFA:1;
    Uint16 ACTSFB:2;
    Uint16 OTSFB:1;
    Uint16 RLDCSF:2;
    Uint16 rsvd1:8;
};
union AQSFRC_REG {
    Uint16 all;
    struct AQSFRC_BITS bit;
};

struct AQCSFRC_BITS {
    Uint16 CSFA:2;
    Uint16 CSFB:2;
    Uint16 rsvd1:12;
};
union AQCSFRC_REG {
    Uint16 all;
    struct AQCSFRC_BITS bit;
};

struct DBCTL_BITS {
    Uint16 OUT_MODE:2;
    Uint16 POLSEL:2;
    Uint16 IN_MODE:2;
    Uint16 rsvd1:10;
};
union DBCTL_REG {
    Uint16 all;
    struct DBCTL_BITS bit;
};

struct TZSEL_BITS {
    Uint16 CBC1:1;
    Uint16 CBC2:1;
    Uint16 CBC3:1;
    Uint16 CBC4:1;
    Uint16 CBC5:1;
    Uint16 CBC6:1;
    Uint16 rsvd1:2;
    Uint16 OSHT1:1;
    Uint16 OSHT2:1;
    Uint16 OSHT3:1;
    Uint16 OSHT4:1;
    Uint16 OSHT5:1;
    Uint16 OSHT6:1;
    Uint16 rsvd2:2;
};
union TZSEL_REG {
    Uint16 all;
    struct TZSEL_BITS bit;
};

struct TZCTL_BITS {
    Uint16 TZA:2;
    Uint16 TZB:2;
    Uint16 rsvd:12;
};
union TZCTL_REG {
    Uint16 all;
    struct TZCTL_BITS bit;
};

struct TZEINT_BITS {
    Uint16 rsvd1:1;
    Uint16 CBC:1;
    Uint16 OST:1;
    Uint16 rsvd2:13;
};
union TZEINT_REG {
    Uint16 all;
    struct TZEINT_BITS bit;
};

struct TZFLG_BITS {
    Uint16 INT:1;
    Uint16 CBC:1;
    Uint16 OST:1;
    Uint16 rsvd2:13;
};
union TZFLG_REG {
    Uint16 all;
    struct TZFLG_BITS bit;
};

struct TZCLR_BITS {
    Uint16 INT:1;
    Uint16 CBC:1;
    Uint16 OST:1;
    Uint16 rsvd2:13;
};
union TZCLR_REG {
    Uint16 all;
    struct TZCLR_BITS bit;
};

struct TZFRC_BITS {
    Uint16 rsvd1:1;
    Uint16 CBC:1;
    Uint16 OST:1;
    Uint16 rsvd2:13;
};
union TZFRC_REG {
    Uint16 all;
    struct TZFRC_BITS bit;
};

struct ETSEL_BITS {
    Uint16 INTSEL:3;
    Uint16 INTEN:1;
    Uint16 rsvd1:4;
    Uint16 SOCASEL:3;
    Uint16 SOCAEN:1;
    Uint16 SOCBSEL:3;
    Uint16 SOCBEN:1;
};
union ETSEL_REG {
    Uint16 all;
    struct ETSEL_BITS bit;
};

struct ETPS_BITS {
    Uint16 INTPRD:2;
    Uint16 INTCNT:2;
    Uint16 rsvd1:4;
    Uint16 SOCAPRD:2;
    Uint16 SOCACNT:2;
    Uint16 SOCBPRD:2;
    Uint16 SOCBCNT:2;
};
union ETPS_REG {
    Uint16 all;
    struct ETPS_BITS bit;
};

struct ETFLG_BITS {
    Uint16 INT:1;
    Uint16 rsvd1:1;
    Uint16 SOCA:1;
    Uint16 SOCB:1;
    Uint16 rsvd2:12;
};
union ETFLG_REG {
    Uint16 all;
    struct ETFLG_BITS bit;
};

struct ETCLR_BITS {
    Uint16 INT:1;
    Uint16 rsvd1:1;
    Uint16 SOCA:1;
    Uint16 SOCB:1;
    Uint16 rsvd2:12;
};
union ETCLR_REG {
    Uint16 all;
    struct ETCLR_BITS bit;
};

struct ETFRC_BITS {
    Uint16 INT:1;
    Uint16 rsvd1:1;
    Uint16 SOCA:1;
    Uint16 SOCB:1;
    Uint16 rsvd2:12;
};
union ETFRC_REG {
    Uint16 all;
    struct ETFRC_BITS bit;
};

struct PCCTL_BITS {
    Uint16 CHPEN:1;
    Uint16 OSHTWTH:4;
    Uint16 CHPFREQ:3;
    Uint16 CHPDUTY:3;
    Uint16 rsvd1:5;
};
union PCCTL_REG {
    Uint16 all;
    struct PCCTL_BITS bit;
};

struct HRCNFG_BITS {
    Uint16 EDGMODE:2;
    Uint16 CTLMODE:1;
    Uint16 HRLOAD:1;
    Uint16 rsvd1:12;
};
union HRCNFG_REG {
    Uint16 all;
    struct HRCNFG_BITS bit;
};

/* TBPHS and CMPA with their high-resolution extensions: .all (32 bits) or .half.TBPHS / .half.CMPA. */
struct TBPHS_HRPWM_REG {
    Uint16 TBPHSHR; /* +0x02 */
    Uint16 TBPHS;   /* +0x03 */
};
union TBPHS_HRPWM_GROUP {
    Uint32 all;
    struct TBPHS_HRPWM_REG half;
};
struct CMPA_HRPWM_REG {
    Uint16 CMPAHR;  /* +0x08 */
    Uint16 CMPA;    /* +0x09 */
};
union CMPA_HRPWM_GROUP {
    Uint32 all;
    struct CMPA_HRPWM_REG half;
};

struct EPWM_REGS {
    union TBCTL_REG TBCTL; /* +0x00 */
    union TBSTS_REG TBSTS; /* +0x01 */
    union TBPHS_HRPWM_GROUP TBPHS; /* +0x02 */
    Uint16 TBCTR; /* +0x04 */
    Uint16 TBPRD; /* +0x05 */
    Uint16 rsvd1[1];
    union CMPCTL_REG CMPCTL; /* +0x07 */
    union CMPA_HRPWM_GROUP CMPA; /* +0x08 */
    Uint16 CMPB; /* +0x0A */
    union AQCTL_REG AQCTLA; /* +0x0B */
    union AQCTL_REG AQCTLB; /* +0x0C */
    union AQSFRC_REG AQSFRC; /* +0x0D */
    union AQCSFRC_REG AQCSFRC; /* +0x0E */
    union DBCTL_REG DBCTL; /* +0x0F */
    Uint16 DBRED; /* +0x10 */
    Uint16 DBFED; /* +0x11 */
    union TZSEL_REG TZSEL; /* +0x12 */
    Uint16 rsvd2[1];
    union TZCTL_REG TZCTL; /* +0x14 */
    union TZEINT_REG TZEINT; /* +0x15 */
    union TZFLG_REG TZFLG; /* +0x16 */
    union TZCLR_REG TZCLR; /* +0x17 */
    union TZFRC_REG TZFRC; /* +0x18 */
    union ETSEL_REG ETSEL; /* +0x19 */
    union ETPS_REG ETPS; /* +0x1A */
    union ETFLG_REG ETFLG; /* +0x1B */
    union ETCLR_REG ETCLR; /* +0x1C */
    union ETFRC_REG ETFRC; /* +0x1D */
    union PCCTL_REG PCCTL; /* +0x1E */
    Uint16 rsvd3[1];
    union HRCNFG_REG HRCNFG; /* +0x20 */
};

extern volatile struct EPWM_REGS EPwm1Regs;
extern volatile struct EPWM_REGS EPwm2Regs;
extern volatile struct EPWM_REGS EPwm3Regs;
extern volatile struct EPWM_REGS EPwm4Regs;
extern volatile struct EPWM_REGS EPwm5Regs;
extern volatile struct EPWM_REGS EPwm6Regs;

#ifdef __cplusplus
}
#endif

#endif
