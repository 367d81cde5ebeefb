/* Host replacement of TI's DSP2833x_PieVect.c (see firmware_c/ti/README.md), for a project that does
   not compile TI's (whose Uint32 copy of PieVectTableInit builds and runs as given, taking this one's
   place: docs/c-drivers.md, "Vectors"). It stores the same 128 vectors (TI's table, the default ISRs
   of DSP2833x_DefaultIsr.c) one by one as whole pointers (each store reaches the emulated PIE), under
   EALLOW as TI's does, then enables the PIE vector table. */
#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"
#include "DSP2833x_DefaultIsr.h"
#include "DSP2833x_GlobalPrototypes.h"

static PINT const PieVectTableInit[128] = {
    &PIE_RESERVED, /* 0 (0x0D00) */
    &PIE_RESERVED, /* 1 (0x0D02) */
    &PIE_RESERVED, /* 2 (0x0D04) */
    &PIE_RESERVED, /* 3 (0x0D06) */
    &PIE_RESERVED, /* 4 (0x0D08) */
    &PIE_RESERVED, /* 5 (0x0D0A) */
    &PIE_RESERVED, /* 6 (0x0D0C) */
    &PIE_RESERVED, /* 7 (0x0D0E) */
    &PIE_RESERVED, /* 8 (0x0D10) */
    &PIE_RESERVED, /* 9 (0x0D12) */
    &PIE_RESERVED, /* 10 (0x0D14) */
    &PIE_RESERVED, /* 11 (0x0D16) */
    &PIE_RESERVED, /* 12 (0x0D18) */
    &INT13_ISR, /* 13 (0x0D1A) */
    &INT14_ISR, /* 14 (0x0D1C) */
    &DATALOG_ISR, /* 15 (0x0D1E) */
    &RTOSINT_ISR, /* 16 (0x0D20) */
    &EMUINT_ISR, /* 17 (0x0D22) */
    &NMI_ISR, /* 18 (0x0D24) */
    &ILLEGAL_ISR, /* 19 (0x0D26) */
    &USER1_ISR, /* 20 (0x0D28) */
    &USER2_ISR, /* 21 (0x0D2A) */
    &USER3_ISR, /* 22 (0x0D2C) */
    &USER4_ISR, /* 23 (0x0D2E) */
    &USER5_ISR, /* 24 (0x0D30) */
    &USER6_ISR, /* 25 (0x0D32) */
    &USER7_ISR, /* 26 (0x0D34) */
    &USER8_ISR, /* 27 (0x0D36) */
    &USER9_ISR, /* 28 (0x0D38) */
    &USER10_ISR, /* 29 (0x0D3A) */
    &USER11_ISR, /* 30 (0x0D3C) */
    &USER12_ISR, /* 31 (0x0D3E) */
    &SEQ1INT_ISR, /* 32 (0x0D40) */
    &SEQ2INT_ISR, /* 33 (0x0D42) */
    &rsvd_ISR, /* 34 (0x0D44) */
    &XINT1_ISR, /* 35 (0x0D46) */
    &XINT2_ISR, /* 36 (0x0D48) */
    &ADCINT_ISR, /* 37 (0x0D4A) */
    &TINT0_ISR, /* 38 (0x0D4C) */
    &WAKEINT_ISR, /* 39 (0x0D4E) */
    &EPWM1_TZINT_ISR, /* 40 (0x0D50) */
    &EPWM2_TZINT_ISR, /* 41 (0x0D52) */
    &EPWM3_TZINT_ISR, /* 42 (0x0D54) */
    &EPWM4_TZINT_ISR, /* 43 (0x0D56) */
    &EPWM5_TZINT_ISR, /* 44 (0x0D58) */
    &EPWM6_TZINT_ISR, /* 45 (0x0D5A) */
    &rsvd_ISR, /* 46 (0x0D5C) */
    &rsvd_ISR, /* 47 (0x0D5E) */
    &EPWM1_INT_ISR, /* 48 (0x0D60) */
    &EPWM2_INT_ISR, /* 49 (0x0D62) */
    &EPWM3_INT_ISR, /* 50 (0x0D64) */
    &EPWM4_INT_ISR, /* 51 (0x0D66) */
    &EPWM5_INT_ISR, /* 52 (0x0D68) */
    &EPWM6_INT_ISR, /* 53 (0x0D6A) */
    &rsvd_ISR, /* 54 (0x0D6C) */
    &rsvd_ISR, /* 55 (0x0D6E) */
    &ECAP1_INT_ISR, /* 56 (0x0D70) */
    &ECAP2_INT_ISR, /* 57 (0x0D72) */
    &ECAP3_INT_ISR, /* 58 (0x0D74) */
    &ECAP4_INT_ISR, /* 59 (0x0D76) */
    &ECAP5_INT_ISR, /* 60 (0x0D78) */
    &ECAP6_INT_ISR, /* 61 (0x0D7A) */
    &rsvd_ISR, /* 62 (0x0D7C) */
    &rsvd_ISR, /* 63 (0x0D7E) */
    &EQEP1_INT_ISR, /* 64 (0x0D80) */
    &EQEP2_INT_ISR, /* 65 (0x0D82) */
    &rsvd_ISR, /* 66 (0x0D84) */
    &rsvd_ISR, /* 67 (0x0D86) */
    &rsvd_ISR, /* 68 (0x0D88) */
    &rsvd_ISR, /* 69 (0x0D8A) */
    &rsvd_ISR, /* 70 (0x0D8C) */
    &rsvd_ISR, /* 71 (0x0D8E) */
    &SPIRXINTA_ISR, /* 72 (0x0D90) */
    &SPITXINTA_ISR, /* 73 (0x0D92) */
    &MRINTA_ISR, /* 74 (0x0D94) */
    &MXINTA_ISR, /* 75 (0x0D96) */
    &MRINTB_ISR, /* 76 (0x0D98) */
    &MXINTB_ISR, /* 77 (0x0D9A) */
    &rsvd_ISR, /* 78 (0x0D9C) */
    &rsvd_ISR, /* 79 (0x0D9E) */
    &DINTCH1_ISR, /* 80 (0x0DA0) */
    &DINTCH2_ISR, /* 81 (0x0DA2) */
    &DINTCH3_ISR, /* 82 (0x0DA4) */
    &DINTCH4_ISR, /* 83 (0x0DA6) */
    &DINTCH5_ISR, /* 84 (0x0DA8) */
    &DINTCH6_ISR, /* 85 (0x0DAA) */
    &rsvd_ISR, /* 86 (0x0DAC) */
    &rsvd_ISR, /* 87 (0x0DAE) */
    &I2CINT1A_ISR, /* 88 (0x0DB0) */
    &I2CINT2A_ISR, /* 89 (0x0DB2) */
    &rsvd_ISR, /* 90 (0x0DB4) */
    &rsvd_ISR, /* 91 (0x0DB6) */
    &SCIRXINTC_ISR, /* 92 (0x0DB8) */
    &SCITXINTC_ISR, /* 93 (0x0DBA) */
    &rsvd_ISR, /* 94 (0x0DBC) */
    &rsvd_ISR, /* 95 (0x0DBE) */
    &SCIRXINTA_ISR, /* 96 (0x0DC0) */
    &SCITXINTA_ISR, /* 97 (0x0DC2) */
    &SCIRXINTB_ISR, /* 98 (0x0DC4) */
    &SCITXINTB_ISR, /* 99 (0x0DC6) */
    &ECAN0INTA_ISR, /* 100 (0x0DC8) */
    &ECAN1INTA_ISR, /* 101 (0x0DCA) */
    &ECAN0INTB_ISR, /* 102 (0x0DCC) */
    &ECAN1INTB_ISR, /* 103 (0x0DCE) */
    &rsvd_ISR, /* 104 (0x0DD0) */
    &rsvd_ISR, /* 105 (0x0DD2) */
    &rsvd_ISR, /* 106 (0x0DD4) */
    &rsvd_ISR, /* 107 (0x0DD6) */
    &rsvd_ISR, /* 108 (0x0DD8) */
    &rsvd_ISR, /* 109 (0x0DDA) */
    &rsvd_ISR, /* 110 (0x0DDC) */
    &rsvd_ISR, /* 111 (0x0DDE) */
    &rsvd_ISR, /* 112 (0x0DE0) */
    &rsvd_ISR, /* 113 (0x0DE2) */
    &rsvd_ISR, /* 114 (0x0DE4) */
    &rsvd_ISR, /* 115 (0x0DE6) */
    &rsvd_ISR, /* 116 (0x0DE8) */
    &rsvd_ISR, /* 117 (0x0DEA) */
    &rsvd_ISR, /* 118 (0x0DEC) */
    &rsvd_ISR, /* 119 (0x0DEE) */
    &XINT3_ISR, /* 120 (0x0DF0) */
    &XINT4_ISR, /* 121 (0x0DF2) */
    &XINT5_ISR, /* 122 (0x0DF4) */
    &XINT6_ISR, /* 123 (0x0DF6) */
    &XINT7_ISR, /* 124 (0x0DF8) */
    &rsvd_ISR, /* 125 (0x0DFA) */
    &LVF_ISR, /* 126 (0x0DFC) */
    &LUF_ISR, /* 127 (0x0DFE) */
};

__attribute__((weak)) void InitPieVectTable(void)
{
    unsigned i;
    EALLOW;
    for (i = 0; i < 128; i++)
        ((PINT *)&PieVectTable)[i] = PieVectTableInit[i];
    EDIS;
    PieCtrlRegs.PIECTRL.bit.ENPIE = 1;
}
