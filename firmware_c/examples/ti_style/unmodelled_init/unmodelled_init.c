/* A project that only initialises the peripherals the emulator does not model (ADC, ePWM, eCAP, eCAN,
   DMA, XINTF), the way TI's 2833x examples do, with TI's support functions: our own code. It runs; each
   peripheral's first use is reported once (`unmodelled_peripheral`); the registers read back what was
   written, and their reset values before that. */
#include "DSP28x_Project.h"

Uint16 tbctl_reset;   /* EPwm1Regs.TBCTL before any write: 0x0083 */
Uint16 ecctl2_reset;  /* ECap1Regs.ECCTL2 before any write: 0x0006 */
Uint32 xtiming0_reset;/* XintfRegs.XTIMING0 before InitXintf: 0x0043FFFF */
Uint16 tbprd;         /* EPwm1Regs.TBPRD as written */
Uint16 cmpa;          /* EPwm1Regs.CMPA.half.CMPA as written */
Uint16 adctrl3;       /* AdcRegs.ADCTRL3 after InitAdc: 0x00E0 */
Uint16 canes_cce;     /* ECanaRegs.CANES.bit.CCE after InitECana: 0 */
Uint16 done;

void main(void)
{
    InitSysCtrl();
    DINT;
    InitPieCtrl();
    IER = 0x0000;
    IFR = 0x0000;
    InitPieVectTable();

    tbctl_reset = EPwm1Regs.TBCTL.all;
    ecctl2_reset = ECap1Regs.ECCTL2.all;
    xtiming0_reset = XintfRegs.XTIMING0.all;

    InitAdc();
    AdcRegs.ADCTRL1.bit.ACQ_PS = 0xF;
    AdcRegs.ADCTRL3.bit.ADCCLKPS = 0;
    AdcRegs.ADCMAXCONV.all = 0x0001;
    AdcRegs.ADCCHSELSEQ1.bit.CONV00 = 0x0;
    AdcRegs.ADCCHSELSEQ1.bit.CONV01 = 0x1;
    adctrl3 = AdcRegs.ADCTRL3.all & 0x00E0;

    InitEPwmGpio();
    EALLOW;
    SysCtrlRegs.PCLKCR0.bit.TBCLKSYNC = 0;
    EDIS;
    EPwm1Regs.TBPRD = 1500;
    EPwm1Regs.TBPHS.half.TBPHS = 0;
    EPwm1Regs.TBCTL.bit.CTRMODE = TB_COUNT_UPDOWN;
    EPwm1Regs.TBCTL.bit.PHSEN = TB_DISABLE;
    EPwm1Regs.TBCTL.bit.HSPCLKDIV = TB_DIV1;
    EPwm1Regs.TBCTL.bit.CLKDIV = TB_DIV1;
    EPwm1Regs.CMPCTL.bit.SHDWAMODE = CC_SHADOW;
    EPwm1Regs.CMPCTL.bit.LOADAMODE = CC_CTR_ZERO;
    EPwm1Regs.CMPA.half.CMPA = 750;
    EPwm1Regs.AQCTLA.bit.CAU = AQ_SET;
    EPwm1Regs.AQCTLA.bit.CAD = AQ_CLEAR;
    EPwm1Regs.ETSEL.bit.SOCAEN = 1;
    EPwm1Regs.ETSEL.bit.SOCASEL = ET_CTR_ZERO;
    EPwm1Regs.ETPS.bit.SOCAPRD = ET_1ST;
    EALLOW;
    EPwm1Regs.TZSEL.bit.OSHT1 = 1;
    SysCtrlRegs.PCLKCR0.bit.TBCLKSYNC = 1;
    EDIS;
    tbprd = EPwm1Regs.TBPRD;
    cmpa = EPwm1Regs.CMPA.half.CMPA;

    InitECap();
    ECap1Regs.ECEINT.all = 0x0000;
    ECap1Regs.ECCLR.all = 0xFFFF;
    ECap1Regs.ECCTL1.bit.CAPLDEN = 0;
    ECap1Regs.ECCTL2.bit.TSCTRSTOP = 0;
    ECap1Regs.ECCTL2.bit.CONT_ONESHT = 1;

    InitECanaGpio();
    InitECana();
    canes_cce = ECanaRegs.CANES.bit.CCE;

    DMAInitialize();
    InitXintf();

    done = 1;
    for (;;) {
        DELAY_US(1000);
    }
}
