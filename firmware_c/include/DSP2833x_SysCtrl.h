/* Replacement for TI's DSP2833x_SysCtrl.h in a host build: the system control registers at 0x7010
   (TI's layout and field names, F2833x System Control and Interrupts guide). LOSPCP (0x701B: LSPCLK =
   SYSCLKOUT / (2·LOSPCP)) is the emulated board's; the PLL, clock enables, watchdog and low-power
   registers are plain memory holding their reset values for now (issue 39: PLLSTS reads locked).
   FlashRegs (0x0A80) and CsmRegs (0x0AE0), which TI's InitFlash and CsmUnlock write, likewise. */
#ifndef DSP2833x_SYSCTRL_H
#define DSP2833x_SYSCTRL_H

#ifdef __cplusplus
extern "C" {
#endif

struct PLLSTS_BITS {
    Uint16 PLLLOCKS:1;
    Uint16 rsvd1:1;
    Uint16 PLLOFF:1;
    Uint16 MCLKSTS:1;
    Uint16 MCLKCLR:1;
    Uint16 OSCOFF:1;
    Uint16 MCLKOFF:1;
    Uint16 DIVSEL:2;
    Uint16 rsvd2:7;
};
union PLLSTS_REG {
    Uint16 all;
    struct PLLSTS_BITS bit;
};

struct HISPCP_BITS {
    Uint16 HSPCLK:3;
    Uint16 rsvd1:13;
};
union HISPCP_REG {
    Uint16 all;
    struct HISPCP_BITS bit;
};

struct LOSPCP_BITS {
    Uint16 LSPCLK:3;
    Uint16 rsvd1:13;
};
union LOSPCP_REG {
    Uint16 all;
    struct LOSPCP_BITS bit;
};

struct PCLKCR0_BITS {
    Uint16 rsvd1:2;
    Uint16 TBCLKSYNC:1;
    Uint16 ADCENCLK:1;
    Uint16 I2CAENCLK:1;
    Uint16 SCICENCLK:1;
    Uint16 rsvd2:2;
    Uint16 SPIAENCLK:1;
    Uint16 rsvd3:1;
    Uint16 SCIAENCLK:1;
    Uint16 SCIBENCLK:1;
    Uint16 MCBSPAENCLK:1;
    Uint16 MCBSPBENCLK:1;
    Uint16 ECANAENCLK:1;
    Uint16 ECANBENCLK:1;
};
union PCLKCR0_REG {
    Uint16 all;
    struct PCLKCR0_BITS bit;
};

struct PCLKCR1_BITS {
    Uint16 EPWM1ENCLK:1;
    Uint16 EPWM2ENCLK:1;
    Uint16 EPWM3ENCLK:1;
    Uint16 EPWM4ENCLK:1;
    Uint16 EPWM5ENCLK:1;
    Uint16 EPWM6ENCLK:1;
    Uint16 rsvd1:2;
    Uint16 ECAP1ENCLK:1;
    Uint16 ECAP2ENCLK:1;
    Uint16 ECAP3ENCLK:1;
    Uint16 ECAP4ENCLK:1;
    Uint16 ECAP5ENCLK:1;
    Uint16 ECAP6ENCLK:1;
    Uint16 EQEP1ENCLK:1;
    Uint16 EQEP2ENCLK:1;
};
union PCLKCR1_REG {
    Uint16 all;
    struct PCLKCR1_BITS bit;
};

struct PCLKCR3_BITS {
    Uint16 rsvd1:8;
    Uint16 CPUTIMER0ENCLK:1;
    Uint16 CPUTIMER1ENCLK:1;
    Uint16 CPUTIMER2ENCLK:1;
    Uint16 DMAENCLK:1;
    Uint16 XINTFENCLK:1;
    Uint16 GPIOINENCLK:1;
    Uint16 rsvd2:2;
};
union PCLKCR3_REG {
    Uint16 all;
    struct PCLKCR3_BITS bit;
};

struct LPMCR0_BITS {
    Uint16 LPM:2;
    Uint16 QUALSTDBY:6;
    Uint16 rsvd1:7;
    Uint16 WDINTE:1;
};
union LPMCR0_REG {
    Uint16 all;
    struct LPMCR0_BITS bit;
};

struct PLLCR_BITS {
    Uint16 DIV:4;
    Uint16 rsvd1:12;
};
union PLLCR_REG {
    Uint16 all;
    struct PLLCR_BITS bit;
};

struct SYS_CTRL_REGS {
    Uint16 rsvd7;                 /* 0x7010 */
    union PLLSTS_REG PLLSTS;      /* 0x7011 */
    Uint16 rsvd1[8];
    union HISPCP_REG HISPCP;      /* 0x701A */
    union LOSPCP_REG LOSPCP;      /* 0x701B */
    union PCLKCR0_REG PCLKCR0;    /* 0x701C */
    union PCLKCR1_REG PCLKCR1;    /* 0x701D */
    union LPMCR0_REG LPMCR0;      /* 0x701E */
    Uint16 rsvd2;
    union PCLKCR3_REG PCLKCR3;    /* 0x7020 */
    union PLLCR_REG PLLCR;        /* 0x7021 */
    Uint16 SCSR;                  /* 0x7022 */
    Uint16 WDCNTR;                /* 0x7023 */
    Uint16 rsvd4;
    Uint16 WDKEY;                 /* 0x7025 */
    Uint16 rsvd5[3];
    Uint16 WDCR;                  /* 0x7029 */
    Uint16 rsvd6[4];
    Uint16 MAPCNF;                /* 0x702E */
    Uint16 rsvd8;
};

struct FOPT_BITS {
    Uint16 ENPIPE:1;
    Uint16 rsvd1:15;
};
union FOPT_REG {
    Uint16 all;
    struct FOPT_BITS bit;
};

struct FPWR_BITS {
    Uint16 PWR:2;
    Uint16 rsvd1:14;
};
union FPWR_REG {
    Uint16 all;
    struct FPWR_BITS bit;
};

struct FSTATUS_BITS {
    Uint16 PWRS:2;
    Uint16 STDBYWAITS:1;
    Uint16 ACTIVEWAITS:1;
    Uint16 rsvd1:4;
    Uint16 V3STAT:1;
    Uint16 rsvd2:7;
};
union FSTATUS_REG {
    Uint16 all;
    struct FSTATUS_BITS bit;
};

struct FSTDBYWAIT_BITS {
    Uint16 STDBYWAIT:9;
    Uint16 rsvd1:7;
};
union FSTDBYWAIT_REG {
    Uint16 all;
    struct FSTDBYWAIT_BITS bit;
};

struct FACTIVEWAIT_BITS {
    Uint16 ACTIVEWAIT:9;
    Uint16 rsvd1:7;
};
union FACTIVEWAIT_REG {
    Uint16 all;
    struct FACTIVEWAIT_BITS bit;
};

struct FBANKWAIT_BITS {
    Uint16 RANDWAIT:4;
    Uint16 rsvd1:4;
    Uint16 PAGEWAIT:4;
    Uint16 rsvd2:4;
};
union FBANKWAIT_REG {
    Uint16 all;
    struct FBANKWAIT_BITS bit;
};

struct FOTPWAIT_BITS {
    Uint16 OTPWAIT:5;
    Uint16 rsvd1:11;
};
union FOTPWAIT_REG {
    Uint16 all;
    struct FOTPWAIT_BITS bit;
};

struct FLASH_REGS {
    union FOPT_REG FOPT;               /* 0x0A80 */
    Uint16 rsvd1;
    union FPWR_REG FPWR;
    union FSTATUS_REG FSTATUS;
    union FSTDBYWAIT_REG FSTDBYWAIT;
    union FACTIVEWAIT_REG FACTIVEWAIT;
    union FBANKWAIT_REG FBANKWAIT;     /* 0x0A86 */
    union FOTPWAIT_REG FOTPWAIT;       /* 0x0A87 */
};

struct CSMSCR_BITS {
    Uint16 SECURE:1;
    Uint16 rsvd1:14;
    Uint16 FORCESEC:1;
};
union CSMSCR_REG {
    Uint16 all;
    struct CSMSCR_BITS bit;
};

struct CSM_REGS {
    Uint16 KEY0;                       /* 0x0AE0 */
    Uint16 KEY1;
    Uint16 KEY2;
    Uint16 KEY3;
    Uint16 KEY4;
    Uint16 KEY5;
    Uint16 KEY6;
    Uint16 KEY7;
    Uint16 rsvd1[7];
    union CSMSCR_REG CSMSCR;           /* 0x0AEF */
};

struct CSM_PWL {
    Uint16 PSWD0;                      /* 0x33FFF8 */
    Uint16 PSWD1;
    Uint16 PSWD2;
    Uint16 PSWD3;
    Uint16 PSWD4;
    Uint16 PSWD5;
    Uint16 PSWD6;
    Uint16 PSWD7;
};

extern volatile struct SYS_CTRL_REGS SysCtrlRegs;
extern volatile struct FLASH_REGS FlashRegs;
extern volatile struct CSM_REGS CsmRegs;
extern volatile struct CSM_PWL CsmPwl;

#ifdef __cplusplus
}
#endif

#endif
