/* Replacement for TI's DSP2833x_Gpio.h in a host build (sins-fw build-firmware): TI's register layout
   and field names (F2833x System Control and Interrupts guide, GPIO chapter). GpioCtrlRegs at 0x6F80
   (mux, direction, pull-ups, qualification), GpioDataRegs at 0x6FC0 (GPxDAT, GPxSET, GPxCLEAR,
   GPxTOGGLE), GpioIntRegs at 0x6FE0. The data registers are the emulated board's; the control and
   interrupt-select registers are plain memory for now (issue 39). */
#ifndef DSP2833x_GPIO_H
#define DSP2833x_GPIO_H

#ifdef __cplusplus
extern "C" {
#endif

struct GPACTRL_BITS {
    Uint32 QUALPRD0:8;
    Uint32 QUALPRD1:8;
    Uint32 QUALPRD2:8;
    Uint32 QUALPRD3:8;
};
union GPACTRL_REG {
    Uint32 all;
    struct GPACTRL_BITS bit;
};

struct GPBCTRL_BITS {
    Uint32 QUALPRD0:8;
    Uint32 QUALPRD1:8;
    Uint32 QUALPRD2:8;
    Uint32 QUALPRD3:8;
};
union GPBCTRL_REG {
    Uint32 all;
    struct GPBCTRL_BITS bit;
};

struct GPA1_BITS {
    Uint32 GPIO0:2;
    Uint32 GPIO1:2;
    Uint32 GPIO2:2;
    Uint32 GPIO3:2;
    Uint32 GPIO4:2;
    Uint32 GPIO5:2;
    Uint32 GPIO6:2;
    Uint32 GPIO7:2;
    Uint32 GPIO8:2;
    Uint32 GPIO9:2;
    Uint32 GPIO10:2;
    Uint32 GPIO11:2;
    Uint32 GPIO12:2;
    Uint32 GPIO13:2;
    Uint32 GPIO14:2;
    Uint32 GPIO15:2;
};
union GPA1_REG {
    Uint32 all;
    struct GPA1_BITS bit;
};

struct GPA2_BITS {
    Uint32 GPIO16:2;
    Uint32 GPIO17:2;
    Uint32 GPIO18:2;
    Uint32 GPIO19:2;
    Uint32 GPIO20:2;
    Uint32 GPIO21:2;
    Uint32 GPIO22:2;
    Uint32 GPIO23:2;
    Uint32 GPIO24:2;
    Uint32 GPIO25:2;
    Uint32 GPIO26:2;
    Uint32 GPIO27:2;
    Uint32 GPIO28:2;
    Uint32 GPIO29:2;
    Uint32 GPIO30:2;
    Uint32 GPIO31:2;
};
union GPA2_REG {
    Uint32 all;
    struct GPA2_BITS bit;
};

struct GPB1_BITS {
    Uint32 GPIO32:2;
    Uint32 GPIO33:2;
    Uint32 GPIO34:2;
    Uint32 GPIO35:2;
    Uint32 GPIO36:2;
    Uint32 GPIO37:2;
    Uint32 GPIO38:2;
    Uint32 GPIO39:2;
    Uint32 GPIO40:2;
    Uint32 GPIO41:2;
    Uint32 GPIO42:2;
    Uint32 GPIO43:2;
    Uint32 GPIO44:2;
    Uint32 GPIO45:2;
    Uint32 GPIO46:2;
    Uint32 GPIO47:2;
};
union GPB1_REG {
    Uint32 all;
    struct GPB1_BITS bit;
};

struct GPB2_BITS {
    Uint32 GPIO48:2;
    Uint32 GPIO49:2;
    Uint32 GPIO50:2;
    Uint32 GPIO51:2;
    Uint32 GPIO52:2;
    Uint32 GPIO53:2;
    Uint32 GPIO54:2;
    Uint32 GPIO55:2;
    Uint32 GPIO56:2;
    Uint32 GPIO57:2;
    Uint32 GPIO58:2;
    Uint32 GPIO59:2;
    Uint32 GPIO60:2;
    Uint32 GPIO61:2;
    Uint32 GPIO62:2;
    Uint32 GPIO63:2;
};
union GPB2_REG {
    Uint32 all;
    struct GPB2_BITS bit;
};

struct GPC1_BITS {
    Uint32 GPIO64:2;
    Uint32 GPIO65:2;
    Uint32 GPIO66:2;
    Uint32 GPIO67:2;
    Uint32 GPIO68:2;
    Uint32 GPIO69:2;
    Uint32 GPIO70:2;
    Uint32 GPIO71:2;
    Uint32 GPIO72:2;
    Uint32 GPIO73:2;
    Uint32 GPIO74:2;
    Uint32 GPIO75:2;
    Uint32 GPIO76:2;
    Uint32 GPIO77:2;
    Uint32 GPIO78:2;
    Uint32 GPIO79:2;
};
union GPC1_REG {
    Uint32 all;
    struct GPC1_BITS bit;
};

struct GPC2_BITS {
    Uint32 GPIO80:2;
    Uint32 GPIO81:2;
    Uint32 GPIO82:2;
    Uint32 GPIO83:2;
    Uint32 GPIO84:2;
    Uint32 GPIO85:2;
    Uint32 GPIO86:2;
    Uint32 GPIO87:2;
    Uint32 rsvd1:16;
};
union GPC2_REG {
    Uint32 all;
    struct GPC2_BITS bit;
};

struct GPADAT_BITS {
    Uint32 GPIO0:1;
    Uint32 GPIO1:1;
    Uint32 GPIO2:1;
    Uint32 GPIO3:1;
    Uint32 GPIO4:1;
    Uint32 GPIO5:1;
    Uint32 GPIO6:1;
    Uint32 GPIO7:1;
    Uint32 GPIO8:1;
    Uint32 GPIO9:1;
    Uint32 GPIO10:1;
    Uint32 GPIO11:1;
    Uint32 GPIO12:1;
    Uint32 GPIO13:1;
    Uint32 GPIO14:1;
    Uint32 GPIO15:1;
    Uint32 GPIO16:1;
    Uint32 GPIO17:1;
    Uint32 GPIO18:1;
    Uint32 GPIO19:1;
    Uint32 GPIO20:1;
    Uint32 GPIO21:1;
    Uint32 GPIO22:1;
    Uint32 GPIO23:1;
    Uint32 GPIO24:1;
    Uint32 GPIO25:1;
    Uint32 GPIO26:1;
    Uint32 GPIO27:1;
    Uint32 GPIO28:1;
    Uint32 GPIO29:1;
    Uint32 GPIO30:1;
    Uint32 GPIO31:1;
};
union GPADAT_REG {
    Uint32 all;
    struct GPADAT_BITS bit;
};

struct GPBDAT_BITS {
    Uint32 GPIO32:1;
    Uint32 GPIO33:1;
    Uint32 GPIO34:1;
    Uint32 GPIO35:1;
    Uint32 GPIO36:1;
    Uint32 GPIO37:1;
    Uint32 GPIO38:1;
    Uint32 GPIO39:1;
    Uint32 GPIO40:1;
    Uint32 GPIO41:1;
    Uint32 GPIO42:1;
    Uint32 GPIO43:1;
    Uint32 GPIO44:1;
    Uint32 GPIO45:1;
    Uint32 GPIO46:1;
    Uint32 GPIO47:1;
    Uint32 GPIO48:1;
    Uint32 GPIO49:1;
    Uint32 GPIO50:1;
    Uint32 GPIO51:1;
    Uint32 GPIO52:1;
    Uint32 GPIO53:1;
    Uint32 GPIO54:1;
    Uint32 GPIO55:1;
    Uint32 GPIO56:1;
    Uint32 GPIO57:1;
    Uint32 GPIO58:1;
    Uint32 GPIO59:1;
    Uint32 GPIO60:1;
    Uint32 GPIO61:1;
    Uint32 GPIO62:1;
    Uint32 GPIO63:1;
};
union GPBDAT_REG {
    Uint32 all;
    struct GPBDAT_BITS bit;
};

struct GPCDAT_BITS {
    Uint32 GPIO64:1;
    Uint32 GPIO65:1;
    Uint32 GPIO66:1;
    Uint32 GPIO67:1;
    Uint32 GPIO68:1;
    Uint32 GPIO69:1;
    Uint32 GPIO70:1;
    Uint32 GPIO71:1;
    Uint32 GPIO72:1;
    Uint32 GPIO73:1;
    Uint32 GPIO74:1;
    Uint32 GPIO75:1;
    Uint32 GPIO76:1;
    Uint32 GPIO77:1;
    Uint32 GPIO78:1;
    Uint32 GPIO79:1;
    Uint32 GPIO80:1;
    Uint32 GPIO81:1;
    Uint32 GPIO82:1;
    Uint32 GPIO83:1;
    Uint32 GPIO84:1;
    Uint32 GPIO85:1;
    Uint32 GPIO86:1;
    Uint32 GPIO87:1;
    Uint32 rsvd1:8;
};
union GPCDAT_REG {
    Uint32 all;
    struct GPCDAT_BITS bit;
};

struct GPIOXINT_BITS {
    Uint16 GPIOSEL:5;
    Uint16 rsvd1:11;
};
union GPIOXINT_REG {
    Uint16 all;
    struct GPIOXINT_BITS bit;
};

struct GPIO_CTRL_REGS {
    union GPACTRL_REG GPACTRL;  /* 0x6F80 */
    union GPA1_REG GPAQSEL1;
    union GPA2_REG GPAQSEL2;
    union GPA1_REG GPAMUX1;     /* 0x6F86 */
    union GPA2_REG GPAMUX2;
    union GPADAT_REG GPADIR;    /* 0x6F8A */
    union GPADAT_REG GPAPUD;
    Uint32 rsvd1;
    union GPBCTRL_REG GPBCTRL;  /* 0x6F90 */
    union GPB1_REG GPBQSEL1;
    union GPB2_REG GPBQSEL2;
    union GPB1_REG GPBMUX1;     /* 0x6F96 */
    union GPB2_REG GPBMUX2;
    union GPBDAT_REG GPBDIR;    /* 0x6F9A */
    union GPBDAT_REG GPBPUD;
    Uint16 rsvd2[8];
    union GPC1_REG GPCMUX1;     /* 0x6FA6 */
    union GPC2_REG GPCMUX2;
    union GPCDAT_REG GPCDIR;
    union GPCDAT_REG GPCPUD;
};

struct GPIO_DATA_REGS {
    union GPADAT_REG GPADAT;    /* 0x6FC0 */
    union GPADAT_REG GPASET;
    union GPADAT_REG GPACLEAR;
    union GPADAT_REG GPATOGGLE;
    union GPBDAT_REG GPBDAT;    /* 0x6FC8 */
    union GPBDAT_REG GPBSET;
    union GPBDAT_REG GPBCLEAR;
    union GPBDAT_REG GPBTOGGLE;
    union GPCDAT_REG GPCDAT;    /* 0x6FD0 */
    union GPCDAT_REG GPCSET;
    union GPCDAT_REG GPCCLEAR;
    union GPCDAT_REG GPCTOGGLE;
    Uint16 rsvd1[8];
};

struct GPIO_INT_REGS {
    union GPIOXINT_REG GPIOXINT1SEL; /* 0x6FE0 */
    union GPIOXINT_REG GPIOXINT2SEL;
    union GPIOXINT_REG GPIOXNMISEL;
    union GPIOXINT_REG GPIOXINT3SEL;
    union GPIOXINT_REG GPIOXINT4SEL;
    union GPIOXINT_REG GPIOXINT5SEL;
    union GPIOXINT_REG GPIOXINT6SEL;
    union GPIOXINT_REG GPIOXINT7SEL;
    union GPADAT_REG GPIOLPMSEL;
};

extern volatile struct GPIO_CTRL_REGS GpioCtrlRegs;
extern volatile struct GPIO_DATA_REGS GpioDataRegs;
extern volatile struct GPIO_INT_REGS GpioIntRegs;

#ifdef __cplusplus
}
#endif

#endif
