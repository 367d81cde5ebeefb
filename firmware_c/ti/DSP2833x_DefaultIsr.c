/* Host replacement of TI's DSP2833x_DefaultIsr.c (see firmware_c/ti/README.md): the default ISR of
   every PIE vector, as TI writes them: an emulation stop, then a loop the ISR never leaves. An
   interrupt nobody expected therefore stops the run: INTM is set inside the ISR, so the runtime
   finds a loop that nothing can interrupt and reports it with its file:line here, which names the
   vector. Weak, so that a firmware's own definition of one of them takes its place. */
#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"
#include "DSP2833x_DefaultIsr.h"
#include "DSP2833x_GlobalPrototypes.h"

__attribute__((weak)) interrupt void PIE_RESERVED(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void INT13_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void INT14_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void DATALOG_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void RTOSINT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void EMUINT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void NMI_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void ILLEGAL_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void USER1_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void USER2_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void USER3_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void USER4_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void USER5_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void USER6_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void USER7_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void USER8_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void USER9_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void USER10_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void USER11_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void USER12_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void SEQ1INT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void SEQ2INT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void rsvd_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void XINT1_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void XINT2_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void ADCINT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void TINT0_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void WAKEINT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void EPWM1_TZINT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void EPWM2_TZINT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void EPWM3_TZINT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void EPWM4_TZINT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void EPWM5_TZINT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void EPWM6_TZINT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void EPWM1_INT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void EPWM2_INT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void EPWM3_INT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void EPWM4_INT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void EPWM5_INT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void EPWM6_INT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void ECAP1_INT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void ECAP2_INT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void ECAP3_INT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void ECAP4_INT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void ECAP5_INT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void ECAP6_INT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void EQEP1_INT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void EQEP2_INT_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void SPIRXINTA_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void SPITXINTA_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void MRINTA_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void MXINTA_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void MRINTB_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void MXINTB_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void DINTCH1_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void DINTCH2_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void DINTCH3_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void DINTCH4_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void DINTCH5_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void DINTCH6_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void I2CINT1A_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void I2CINT2A_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void SCIRXINTC_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void SCITXINTC_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void SCIRXINTA_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void SCITXINTA_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void SCIRXINTB_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void SCITXINTB_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void ECAN0INTA_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void ECAN1INTA_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void ECAN0INTB_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void ECAN1INTB_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void XINT3_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void XINT4_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void XINT5_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void XINT6_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void XINT7_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void LVF_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}

__attribute__((weak)) interrupt void LUF_ISR(void)
{
    asm("      ESTOP0");
    for (;;) {
    }
}
