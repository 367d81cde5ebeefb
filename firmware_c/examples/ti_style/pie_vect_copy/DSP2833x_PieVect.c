/* The PIE vector table set up as TI's 2833x support sources set it up (our own code, in TI's
   idiom): a const table of the 128 vectors, PieVectTableInit, copied into PieVectTable through Uint32
   pointers in InitPieVectTable, a 32-bit C28x vector a word pair. Three slots of the table hold this
   project's own ISRs: TINT0 (vector 38), SPIRXINTA (72, past the first 64 vectors) and LUF (127).
   With -DCOPY_WITH_MEMCPY the table is copied by one memcpy of the whole structure instead. */
#include "DSP28x_Project.h"

interrupt void timer0_isr(void);
interrupt void spi_rx_isr(void);
interrupt void luf_isr(void);

const struct PIE_VECT_TABLE PieVectTableInit = {
    PIE_RESERVED,      /* 0 */
    PIE_RESERVED,      /* 1 */
    PIE_RESERVED,      /* 2 */
    PIE_RESERVED,      /* 3 */
    PIE_RESERVED,      /* 4 */
    PIE_RESERVED,      /* 5 */
    PIE_RESERVED,      /* 6 */
    PIE_RESERVED,      /* 7 */
    PIE_RESERVED,      /* 8 */
    PIE_RESERVED,      /* 9 */
    PIE_RESERVED,      /* 10 */
    PIE_RESERVED,      /* 11 */
    PIE_RESERVED,      /* 12 */
    INT13_ISR,         /* 13 */
    INT14_ISR,         /* 14 */
    DATALOG_ISR,       /* 15 */
    RTOSINT_ISR,       /* 16 */
    EMUINT_ISR,        /* 17 */
    NMI_ISR,           /* 18 */
    ILLEGAL_ISR,       /* 19 */
    USER1_ISR,         /* 20 */
    USER2_ISR,         /* 21 */
    USER3_ISR,         /* 22 */
    USER4_ISR,         /* 23 */
    USER5_ISR,         /* 24 */
    USER6_ISR,         /* 25 */
    USER7_ISR,         /* 26 */
    USER8_ISR,         /* 27 */
    USER9_ISR,         /* 28 */
    USER10_ISR,        /* 29 */
    USER11_ISR,        /* 30 */
    USER12_ISR,        /* 31 */
    SEQ1INT_ISR,       /* 32 */
    SEQ2INT_ISR,       /* 33 */
    rsvd_ISR,          /* 34 */
    XINT1_ISR,         /* 35 */
    XINT2_ISR,         /* 36 */
    ADCINT_ISR,        /* 37 */
    timer0_isr,        /* 38 */
    WAKEINT_ISR,       /* 39 */
    EPWM1_TZINT_ISR,   /* 40 */
    EPWM2_TZINT_ISR,   /* 41 */
    EPWM3_TZINT_ISR,   /* 42 */
    EPWM4_TZINT_ISR,   /* 43 */
    EPWM5_TZINT_ISR,   /* 44 */
    EPWM6_TZINT_ISR,   /* 45 */
    rsvd_ISR,          /* 46 */
    rsvd_ISR,          /* 47 */
    EPWM1_INT_ISR,     /* 48 */
    EPWM2_INT_ISR,     /* 49 */
    EPWM3_INT_ISR,     /* 50 */
    EPWM4_INT_ISR,     /* 51 */
    EPWM5_INT_ISR,     /* 52 */
    EPWM6_INT_ISR,     /* 53 */
    rsvd_ISR,          /* 54 */
    rsvd_ISR,          /* 55 */
    ECAP1_INT_ISR,     /* 56 */
    ECAP2_INT_ISR,     /* 57 */
    ECAP3_INT_ISR,     /* 58 */
    ECAP4_INT_ISR,     /* 59 */
    ECAP5_INT_ISR,     /* 60 */
    ECAP6_INT_ISR,     /* 61 */
    rsvd_ISR,          /* 62 */
    rsvd_ISR,          /* 63 */
    EQEP1_INT_ISR,     /* 64 */
    EQEP2_INT_ISR,     /* 65 */
    rsvd_ISR,          /* 66 */
    rsvd_ISR,          /* 67 */
    rsvd_ISR,          /* 68 */
    rsvd_ISR,          /* 69 */
    rsvd_ISR,          /* 70 */
    rsvd_ISR,          /* 71 */
    spi_rx_isr,        /* 72 */
    SPITXINTA_ISR,     /* 73 */
    MRINTA_ISR,        /* 74 */
    MXINTA_ISR,        /* 75 */
    MRINTB_ISR,        /* 76 */
    MXINTB_ISR,        /* 77 */
    rsvd_ISR,          /* 78 */
    rsvd_ISR,          /* 79 */
    DINTCH1_ISR,       /* 80 */
    DINTCH2_ISR,       /* 81 */
    DINTCH3_ISR,       /* 82 */
    DINTCH4_ISR,       /* 83 */
    DINTCH5_ISR,       /* 84 */
    DINTCH6_ISR,       /* 85 */
    rsvd_ISR,          /* 86 */
    rsvd_ISR,          /* 87 */
    I2CINT1A_ISR,      /* 88 */
    I2CINT2A_ISR,      /* 89 */
    rsvd_ISR,          /* 90 */
    rsvd_ISR,          /* 91 */
    SCIRXINTC_ISR,     /* 92 */
    SCITXINTC_ISR,     /* 93 */
    rsvd_ISR,          /* 94 */
    rsvd_ISR,          /* 95 */
    SCIRXINTA_ISR,     /* 96 */
    SCITXINTA_ISR,     /* 97 */
    SCIRXINTB_ISR,     /* 98 */
    SCITXINTB_ISR,     /* 99 */
    ECAN0INTA_ISR,     /* 100 */
    ECAN1INTA_ISR,     /* 101 */
    ECAN0INTB_ISR,     /* 102 */
    ECAN1INTB_ISR,     /* 103 */
    rsvd_ISR,          /* 104 */
    rsvd_ISR,          /* 105 */
    rsvd_ISR,          /* 106 */
    rsvd_ISR,          /* 107 */
    rsvd_ISR,          /* 108 */
    rsvd_ISR,          /* 109 */
    rsvd_ISR,          /* 110 */
    rsvd_ISR,          /* 111 */
    rsvd_ISR,          /* 112 */
    rsvd_ISR,          /* 113 */
    rsvd_ISR,          /* 114 */
    rsvd_ISR,          /* 115 */
    rsvd_ISR,          /* 116 */
    rsvd_ISR,          /* 117 */
    rsvd_ISR,          /* 118 */
    rsvd_ISR,          /* 119 */
    XINT3_ISR,         /* 120 */
    XINT4_ISR,         /* 121 */
    XINT5_ISR,         /* 122 */
    XINT6_ISR,         /* 123 */
    XINT7_ISR,         /* 124 */
    rsvd_ISR,          /* 125 */
    LVF_ISR,           /* 126 */
    luf_isr,           /* 127 */
};

void InitPieVectTable(void)
{
#ifdef COPY_WITH_MEMCPY
    EALLOW;
    memcpy(&PieVectTable, &PieVectTableInit, sizeof(PieVectTable));
    EDIS;
#else
    int16 n;
    Uint32 *from = (void *)&PieVectTableInit;
    Uint32 *to = (void *)&PieVectTable;

    EALLOW;
    for (n = 0; n < 128; n++) {
        *to++ = *from++;
    }
    EDIS;
#endif
    PieCtrlRegs.PIECTRL.bit.ENPIE = 1;
}
