/* Replacement for TI's DSP2833x_DefaultIsr.h: the default ISRs of TI's DSP2833x_DefaultIsr.c (host
   replacement in firmware_c/ti), which InitPieVectTable puts in every vector. */
#ifndef DSP2833x_DEFAULT_ISR_H
#define DSP2833x_DEFAULT_ISR_H

#ifdef __cplusplus
extern "C" {
#endif

interrupt void PIE_RESERVED(void);
interrupt void INT13_ISR(void);
interrupt void INT14_ISR(void);
interrupt void DATALOG_ISR(void);
interrupt void RTOSINT_ISR(void);
interrupt void EMUINT_ISR(void);
interrupt void NMI_ISR(void);
interrupt void ILLEGAL_ISR(void);
interrupt void USER1_ISR(void);
interrupt void USER2_ISR(void);
interrupt void USER3_ISR(void);
interrupt void USER4_ISR(void);
interrupt void USER5_ISR(void);
interrupt void USER6_ISR(void);
interrupt void USER7_ISR(void);
interrupt void USER8_ISR(void);
interrupt void USER9_ISR(void);
interrupt void USER10_ISR(void);
interrupt void USER11_ISR(void);
interrupt void USER12_ISR(void);
interrupt void SEQ1INT_ISR(void);
interrupt void SEQ2INT_ISR(void);
interrupt void rsvd_ISR(void);
interrupt void XINT1_ISR(void);
interrupt void XINT2_ISR(void);
interrupt void ADCINT_ISR(void);
interrupt void TINT0_ISR(void);
interrupt void WAKEINT_ISR(void);
interrupt void EPWM1_TZINT_ISR(void);
interrupt void EPWM2_TZINT_ISR(void);
interrupt void EPWM3_TZINT_ISR(void);
interrupt void EPWM4_TZINT_ISR(void);
interrupt void EPWM5_TZINT_ISR(void);
interrupt void EPWM6_TZINT_ISR(void);
interrupt void EPWM1_INT_ISR(void);
interrupt void EPWM2_INT_ISR(void);
interrupt void EPWM3_INT_ISR(void);
interrupt void EPWM4_INT_ISR(void);
interrupt void EPWM5_INT_ISR(void);
interrupt void EPWM6_INT_ISR(void);
interrupt void ECAP1_INT_ISR(void);
interrupt void ECAP2_INT_ISR(void);
interrupt void ECAP3_INT_ISR(void);
interrupt void ECAP4_INT_ISR(void);
interrupt void ECAP5_INT_ISR(void);
interrupt void ECAP6_INT_ISR(void);
interrupt void EQEP1_INT_ISR(void);
interrupt void EQEP2_INT_ISR(void);
interrupt void SPIRXINTA_ISR(void);
interrupt void SPITXINTA_ISR(void);
interrupt void MRINTA_ISR(void);
interrupt void MXINTA_ISR(void);
interrupt void MRINTB_ISR(void);
interrupt void MXINTB_ISR(void);
interrupt void DINTCH1_ISR(void);
interrupt void DINTCH2_ISR(void);
interrupt void DINTCH3_ISR(void);
interrupt void DINTCH4_ISR(void);
interrupt void DINTCH5_ISR(void);
interrupt void DINTCH6_ISR(void);
interrupt void I2CINT1A_ISR(void);
interrupt void I2CINT2A_ISR(void);
interrupt void SCIRXINTC_ISR(void);
interrupt void SCITXINTC_ISR(void);
interrupt void SCIRXINTA_ISR(void);
interrupt void SCITXINTA_ISR(void);
interrupt void SCIRXINTB_ISR(void);
interrupt void SCITXINTB_ISR(void);
interrupt void ECAN0INTA_ISR(void);
interrupt void ECAN1INTA_ISR(void);
interrupt void ECAN0INTB_ISR(void);
interrupt void ECAN1INTB_ISR(void);
interrupt void XINT3_ISR(void);
interrupt void XINT4_ISR(void);
interrupt void XINT5_ISR(void);
interrupt void XINT6_ISR(void);
interrupt void XINT7_ISR(void);
interrupt void LVF_ISR(void);
interrupt void LUF_ISR(void);

#ifdef __cplusplus
}
#endif

#endif
