/* Replacement for TI's DSP2833x_Adc.h in a host build: the ADC's registers (AdcRegs at 0x7100, the
   result mirror AdcMirror at 0x0B00) with TI's layout and field names (F2833x ADC reference guide SPRU812).
   The ADC is not modelled: its registers read and write with their reset values and its first use is
   reported once (`unmodelled_peripheral`, rust/core/src/dsp/unmodelled.rs); no conversion is made. */
#ifndef DSP2833x_ADC_H
#define DSP2833x_ADC_H

#ifdef __cplusplus
extern "C" {
#endif

struct ADCTRL1_BITS {
    Uint16 rsvd1:4;
    Uint16 SEQ_CASC:1;
    Uint16 SEQ_OVRD:1;
    Uint16 CONT_RUN:1;
    Uint16 CPS:1;
    Uint16 ACQ_PS:4;
    Uint16 SUSMOD:2;
    Uint16 RESET:1;
    Uint16 rsvd2:1;
};
union ADCTRL1_REG {
    Uint16 all;
    struct ADCTRL1_BITS bit;
};

struct ADCTRL2_BITS {
    Uint16 EPWM_SOCB_SEQ2:1;
    Uint16 rsvd1:1;
    Uint16 INT_MOD_SEQ2:1;
    Uint16 INT_ENA_SEQ2:1;
    Uint16 rsvd2:1;
    Uint16 SOC_SEQ2:1;
    Uint16 RST_SEQ2:1;
    Uint16 EXT_SOC_SEQ1:1;
    Uint16 EPWM_SOCA_SEQ1:1;
    Uint16 rsvd3:1;
    Uint16 INT_MOD_SEQ1:1;
    Uint16 INT_ENA_SEQ1:1;
    Uint16 rsvd4:1;
    Uint16 SOC_SEQ1:1;
    Uint16 RST_SEQ1:1;
    Uint16 EPWM_SOCB_SEQ:1;
};
union ADCTRL2_REG {
    Uint16 all;
    struct ADCTRL2_BITS bit;
};

struct ADCMAXCONV_BITS {
    Uint16 MAX_CONV1:4;
    Uint16 MAX_CONV2:3;
    Uint16 rsvd1:9;
};
union ADCMAXCONV_REG {
    Uint16 all;
    struct ADCMAXCONV_BITS bit;
};

struct ADCCHSELSEQ1_BITS {
    Uint16 CONV00:4;
    Uint16 CONV01:4;
    Uint16 CONV02:4;
    Uint16 CONV03:4;
};
union ADCCHSELSEQ1_REG {
    Uint16 all;
    struct ADCCHSELSEQ1_BITS bit;
};

struct ADCCHSELSEQ2_BITS {
    Uint16 CONV04:4;
    Uint16 CONV05:4;
    Uint16 CONV06:4;
    Uint16 CONV07:4;
};
union ADCCHSELSEQ2_REG {
    Uint16 all;
    struct ADCCHSELSEQ2_BITS bit;
};

struct ADCCHSELSEQ3_BITS {
    Uint16 CONV08:4;
    Uint16 CONV09:4;
    Uint16 CONV10:4;
    Uint16 CONV11:4;
};
union ADCCHSELSEQ3_REG {
    Uint16 all;
    struct ADCCHSELSEQ3_BITS bit;
};

struct ADCCHSELSEQ4_BITS {
    Uint16 CONV12:4;
    Uint16 CONV13:4;
    Uint16 CONV14:4;
    Uint16 CONV15:4;
};
union ADCCHSELSEQ4_REG {
    Uint16 all;
    struct ADCCHSELSEQ4_BITS bit;
};

struct ADCASEQSR_BITS {
    Uint16 SEQ1_STATE:4;
    Uint16 SEQ2_STATE:3;
    Uint16 rsvd1:1;
    Uint16 SEQ_CNTR:4;
    Uint16 rsvd2:4;
};
union ADCASEQSR_REG {
    Uint16 all;
    struct ADCASEQSR_BITS bit;
};

struct ADCTRL3_BITS {
    Uint16 SMODE_SEL:1;
    Uint16 ADCCLKPS:4;
    Uint16 ADCPWDN:1;
    Uint16 ADCBGRFDN:2;
    Uint16 rsvd1:8;
};
union ADCTRL3_REG {
    Uint16 all;
    struct ADCTRL3_BITS bit;
};

struct ADCST_BITS {
    Uint16 INT_SEQ1:1;
    Uint16 INT_SEQ2:1;
    Uint16 SEQ1_BSY:1;
    Uint16 SEQ2_BSY:1;
    Uint16 INT_SEQ1_CLR:1;
    Uint16 INT_SEQ2_CLR:1;
    Uint16 EOS_BUF1:1;
    Uint16 EOS_BUF2:1;
    Uint16 rsvd1:8;
};
union ADCST_REG {
    Uint16 all;
    struct ADCST_BITS bit;
};

struct ADCREFSEL_BITS {
    Uint16 rsvd1:14;
    Uint16 REF_SEL:2;
};
union ADCREFSEL_REG {
    Uint16 all;
    struct ADCREFSEL_BITS bit;
};

struct ADCOFFTRIM_BITS {
    Uint16 OFFSET_TRIM:9;
    Uint16 rsvd1:7;
};
union ADCOFFTRIM_REG {
    Uint16 all;
    struct ADCOFFTRIM_BITS bit;
};

struct ADC_REGS {
    union ADCTRL1_REG ADCTRL1; /* +0x00 */
    union ADCTRL2_REG ADCTRL2; /* +0x01 */
    union ADCMAXCONV_REG ADCMAXCONV; /* +0x02 */
    union ADCCHSELSEQ1_REG ADCCHSELSEQ1; /* +0x03 */
    union ADCCHSELSEQ2_REG ADCCHSELSEQ2; /* +0x04 */
    union ADCCHSELSEQ3_REG ADCCHSELSEQ3; /* +0x05 */
    union ADCCHSELSEQ4_REG ADCCHSELSEQ4; /* +0x06 */
    union ADCASEQSR_REG ADCASEQSR; /* +0x07 */
    Uint16 ADCRESULT0; /* +0x08 */
    Uint16 ADCRESULT1; /* +0x09 */
    Uint16 ADCRESULT2; /* +0x0A */
    Uint16 ADCRESULT3; /* +0x0B */
    Uint16 ADCRESULT4; /* +0x0C */
    Uint16 ADCRESULT5; /* +0x0D */
    Uint16 ADCRESULT6; /* +0x0E */
    Uint16 ADCRESULT7; /* +0x0F */
    Uint16 ADCRESULT8; /* +0x10 */
    Uint16 ADCRESULT9; /* +0x11 */
    Uint16 ADCRESULT10; /* +0x12 */
    Uint16 ADCRESULT11; /* +0x13 */
    Uint16 ADCRESULT12; /* +0x14 */
    Uint16 ADCRESULT13; /* +0x15 */
    Uint16 ADCRESULT14; /* +0x16 */
    Uint16 ADCRESULT15; /* +0x17 */
    union ADCTRL3_REG ADCTRL3; /* +0x18 */
    union ADCST_REG ADCST; /* +0x19 */
    Uint16 rsvd1[2];
    union ADCREFSEL_REG ADCREFSEL; /* +0x1C */
    union ADCOFFTRIM_REG ADCOFFTRIM; /* +0x1D */
};

struct ADC_RESULT_MIRROR_REGS {
    Uint16 ADCRESULT0; /* +0x00 */
    Uint16 ADCRESULT1; /* +0x01 */
    Uint16 ADCRESULT2; /* +0x02 */
    Uint16 ADCRESULT3; /* +0x03 */
    Uint16 ADCRESULT4; /* +0x04 */
    Uint16 ADCRESULT5; /* +0x05 */
    Uint16 ADCRESULT6; /* +0x06 */
    Uint16 ADCRESULT7; /* +0x07 */
    Uint16 ADCRESULT8; /* +0x08 */
    Uint16 ADCRESULT9; /* +0x09 */
    Uint16 ADCRESULT10; /* +0x0A */
    Uint16 ADCRESULT11; /* +0x0B */
    Uint16 ADCRESULT12; /* +0x0C */
    Uint16 ADCRESULT13; /* +0x0D */
    Uint16 ADCRESULT14; /* +0x0E */
    Uint16 ADCRESULT15; /* +0x0F */
};

extern volatile struct ADC_REGS AdcRegs;
extern volatile struct ADC_RESULT_MIRROR_REGS AdcMirror;

#ifdef __cplusplus
}
#endif

#endif
