/* Replacement for TI's DSP2833x_SysCtrl.h, as far as the emulator models it: LOSPCP (0x701B), whose
   bits 2:0 set LSPCLK = SYSCLKOUT / (2·LOSPCP). The other system-control registers are not modelled
   yet (using one is a compile error naming it). */
#ifndef DSP2833x_SYSCTRL_H
#define DSP2833x_SYSCTRL_H

#include "sins_fw_reg.hpp"

struct LOSPCP_BITS {
    SinsField<0x701Bu, 0, 3> LSPCLK;
};
union LOSPCP_REG {
    SinsReg16<0x701Bu> all;
    struct LOSPCP_BITS bit;
};

struct SYS_CTRL_REGS {
    union LOSPCP_REG LOSPCP;
};

extern volatile struct SYS_CTRL_REGS SysCtrlRegs;

#endif
