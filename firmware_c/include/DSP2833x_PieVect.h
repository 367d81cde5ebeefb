/* Replacement for TI's DSP2833x_PieVect.h in a host build: PieVectTable, the PIE's 128 vectors at
   0x0D00 (TI's names: vector 13, INT13, is XINT13 as in TI's header, shared by CPU timer 1 and
   XINT13; TINT0, CPU timer 0, is vector 38 at 0x0D4C). A vector holds a host function's address; each
   store to PieVectTable reaches the emulated PIE (EALLOW-protected: a write without EALLOW is ignored,
   as on the chip, and reported as a `protected_write` event). TI's InitPieVectTable copies
   PieVectTableInit through a Uint32 pointer: a 32-bit word of PieVectTable or of a table of this
   type is the vector of its index, which the runtime carries as a handle of the host address
   (docs/c-drivers.md, "Vectors"). */
#ifndef DSP2833x_PIE_VECT_H
#define DSP2833x_PIE_VECT_H

#ifdef __cplusplus
extern "C" {
#endif

typedef interrupt void (*PINT)(void);

struct PIE_VECT_TABLE {
    PINT PIE1_RESERVED; /* 0: 0x0D00 */
    PINT PIE2_RESERVED; /* 1: 0x0D02 */
    PINT PIE3_RESERVED; /* 2: 0x0D04 */
    PINT PIE4_RESERVED; /* 3: 0x0D06 */
    PINT PIE5_RESERVED; /* 4: 0x0D08 */
    PINT PIE6_RESERVED; /* 5: 0x0D0A */
    PINT PIE7_RESERVED; /* 6: 0x0D0C */
    PINT PIE8_RESERVED; /* 7: 0x0D0E */
    PINT PIE9_RESERVED; /* 8: 0x0D10 */
    PINT PIE10_RESERVED; /* 9: 0x0D12 */
    PINT PIE11_RESERVED; /* 10: 0x0D14 */
    PINT PIE12_RESERVED; /* 11: 0x0D16 */
    PINT PIE13_RESERVED; /* 12: 0x0D18 */
    PINT XINT13; /* 13: 0x0D1A */
    PINT TINT2; /* 14: 0x0D1C */
    PINT DATALOG; /* 15: 0x0D1E */
    PINT RTOSINT; /* 16: 0x0D20 */
    PINT EMUINT; /* 17: 0x0D22 */
    PINT XNMI; /* 18: 0x0D24 */
    PINT ILLEGAL; /* 19: 0x0D26 */
    PINT USER1; /* 20: 0x0D28 */
    PINT USER2; /* 21: 0x0D2A */
    PINT USER3; /* 22: 0x0D2C */
    PINT USER4; /* 23: 0x0D2E */
    PINT USER5; /* 24: 0x0D30 */
    PINT USER6; /* 25: 0x0D32 */
    PINT USER7; /* 26: 0x0D34 */
    PINT USER8; /* 27: 0x0D36 */
    PINT USER9; /* 28: 0x0D38 */
    PINT USER10; /* 29: 0x0D3A */
    PINT USER11; /* 30: 0x0D3C */
    PINT USER12; /* 31: 0x0D3E */
    PINT SEQ1INT; /* 32: 0x0D40 */
    PINT SEQ2INT; /* 33: 0x0D42 */
    PINT rsvd1_3; /* 34: 0x0D44 */
    PINT XINT1; /* 35: 0x0D46 */
    PINT XINT2; /* 36: 0x0D48 */
    PINT ADCINT; /* 37: 0x0D4A */
    PINT TINT0; /* 38: 0x0D4C */
    PINT WAKEINT; /* 39: 0x0D4E */
    PINT EPWM1_TZINT; /* 40: 0x0D50 */
    PINT EPWM2_TZINT; /* 41: 0x0D52 */
    PINT EPWM3_TZINT; /* 42: 0x0D54 */
    PINT EPWM4_TZINT; /* 43: 0x0D56 */
    PINT EPWM5_TZINT; /* 44: 0x0D58 */
    PINT EPWM6_TZINT; /* 45: 0x0D5A */
    PINT rsvd2_7; /* 46: 0x0D5C */
    PINT rsvd2_8; /* 47: 0x0D5E */
    PINT EPWM1_INT; /* 48: 0x0D60 */
    PINT EPWM2_INT; /* 49: 0x0D62 */
    PINT EPWM3_INT; /* 50: 0x0D64 */
    PINT EPWM4_INT; /* 51: 0x0D66 */
    PINT EPWM5_INT; /* 52: 0x0D68 */
    PINT EPWM6_INT; /* 53: 0x0D6A */
    PINT rsvd3_7; /* 54: 0x0D6C */
    PINT rsvd3_8; /* 55: 0x0D6E */
    PINT ECAP1_INT; /* 56: 0x0D70 */
    PINT ECAP2_INT; /* 57: 0x0D72 */
    PINT ECAP3_INT; /* 58: 0x0D74 */
    PINT ECAP4_INT; /* 59: 0x0D76 */
    PINT ECAP5_INT; /* 60: 0x0D78 */
    PINT ECAP6_INT; /* 61: 0x0D7A */
    PINT rsvd4_7; /* 62: 0x0D7C */
    PINT rsvd4_8; /* 63: 0x0D7E */
    PINT EQEP1_INT; /* 64: 0x0D80 */
    PINT EQEP2_INT; /* 65: 0x0D82 */
    PINT rsvd5_3; /* 66: 0x0D84 */
    PINT rsvd5_4; /* 67: 0x0D86 */
    PINT rsvd5_5; /* 68: 0x0D88 */
    PINT rsvd5_6; /* 69: 0x0D8A */
    PINT rsvd5_7; /* 70: 0x0D8C */
    PINT rsvd5_8; /* 71: 0x0D8E */
    PINT SPIRXINTA; /* 72: 0x0D90 */
    PINT SPITXINTA; /* 73: 0x0D92 */
    PINT MRINTB; /* 74: 0x0D94 */
    PINT MXINTB; /* 75: 0x0D96 */
    PINT MRINTA; /* 76: 0x0D98 */
    PINT MXINTA; /* 77: 0x0D9A */
    PINT rsvd6_7; /* 78: 0x0D9C */
    PINT rsvd6_8; /* 79: 0x0D9E */
    PINT DINTCH1; /* 80: 0x0DA0 */
    PINT DINTCH2; /* 81: 0x0DA2 */
    PINT DINTCH3; /* 82: 0x0DA4 */
    PINT DINTCH4; /* 83: 0x0DA6 */
    PINT DINTCH5; /* 84: 0x0DA8 */
    PINT DINTCH6; /* 85: 0x0DAA */
    PINT rsvd7_7; /* 86: 0x0DAC */
    PINT rsvd7_8; /* 87: 0x0DAE */
    PINT I2CINT1A; /* 88: 0x0DB0 */
    PINT I2CINT2A; /* 89: 0x0DB2 */
    PINT rsvd8_3; /* 90: 0x0DB4 */
    PINT rsvd8_4; /* 91: 0x0DB6 */
    PINT SCIRXINTC; /* 92: 0x0DB8 */
    PINT SCITXINTC; /* 93: 0x0DBA */
    PINT rsvd8_7; /* 94: 0x0DBC */
    PINT rsvd8_8; /* 95: 0x0DBE */
    PINT SCIRXINTA; /* 96: 0x0DC0 */
    PINT SCITXINTA; /* 97: 0x0DC2 */
    PINT SCIRXINTB; /* 98: 0x0DC4 */
    PINT SCITXINTB; /* 99: 0x0DC6 */
    PINT ECAN0INTA; /* 100: 0x0DC8 */
    PINT ECAN1INTA; /* 101: 0x0DCA */
    PINT ECAN0INTB; /* 102: 0x0DCC */
    PINT ECAN1INTB; /* 103: 0x0DCE */
    PINT rsvd10_1; /* 104: 0x0DD0 */
    PINT rsvd10_2; /* 105: 0x0DD2 */
    PINT rsvd10_3; /* 106: 0x0DD4 */
    PINT rsvd10_4; /* 107: 0x0DD6 */
    PINT rsvd10_5; /* 108: 0x0DD8 */
    PINT rsvd10_6; /* 109: 0x0DDA */
    PINT rsvd10_7; /* 110: 0x0DDC */
    PINT rsvd10_8; /* 111: 0x0DDE */
    PINT rsvd11_1; /* 112: 0x0DE0 */
    PINT rsvd11_2; /* 113: 0x0DE2 */
    PINT rsvd11_3; /* 114: 0x0DE4 */
    PINT rsvd11_4; /* 115: 0x0DE6 */
    PINT rsvd11_5; /* 116: 0x0DE8 */
    PINT rsvd11_6; /* 117: 0x0DEA */
    PINT rsvd11_7; /* 118: 0x0DEC */
    PINT rsvd11_8; /* 119: 0x0DEE */
    PINT XINT3; /* 120: 0x0DF0 */
    PINT XINT4; /* 121: 0x0DF2 */
    PINT XINT5; /* 122: 0x0DF4 */
    PINT XINT6; /* 123: 0x0DF6 */
    PINT XINT7; /* 124: 0x0DF8 */
    PINT rsvd12_6; /* 125: 0x0DFA */
    PINT LVF; /* 126: 0x0DFC */
    PINT LUF; /* 127: 0x0DFE */
};

extern struct PIE_VECT_TABLE PieVectTable;

#ifdef __cplusplus
}
#endif

#endif
