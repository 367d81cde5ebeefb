/* Host replacement of TI's DSP2833x_Mcbsp.c (see firmware_c/ti/README.md): McBSP-A/B's pins and a
   plain initialisation, our own code in the support source's names. McBSP-A's pins: MDXA/MDRA/MCLKXA/
   MFSXA on GPIO20-23 (GPAMUX2 = 2), MCLKRA/MFSRA on GPIO58/59 (GPBMUX2 = 1); McBSP-B's: GPIO24-27
   (GPAMUX2 = 3), MCLKRB/MFSRB on GPIO60/61 (GPBMUX2 = 1) (F2833x data sheet's pin table, spec
   f28335-peripherals.md §3). The McBSPs themselves (rust/core/src/dsp/mcbsp.rs) are reached whatever
   the mux holds. InitMcbspa/b: every part in reset, internal clock and frame sync, the sample-rate
   generator on LSPCLK / 2, 8-bit words, then out of reset; InitMcbspxNNbit set the word length. */
#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"

/* At least two sample-rate generator clocks at any CLKGDV the examples use (LSPCLK / 2 at 37.5 MHz:
   53 ns; CLKGDV up to 255: 13.7 us). */
__attribute__((weak)) void delay_loop(void)
{
    DELAY_US(14);
}

__attribute__((weak)) void clkg_delay_loop(void)
{
    DELAY_US(14);
}

static void init_mcbsp(volatile struct MCBSP_REGS *m)
{
    m->SPCR2.all = 0x0000;          /* transmitter, sample-rate and frame-sync generators in reset */
    m->SPCR1.all = 0x0000;          /* receiver in reset, right-justified */
    m->MFFINT.all = 0x0000;         /* no interrupts */
    m->RCR2.all = 0x0000;           /* one phase, one word per frame */
    m->RCR1.all = 0x0000;
    m->XCR2.all = 0x0000;
    m->XCR1.all = 0x0000;
    m->PCR.bit.FSXM = 1;            /* frame sync and clock generated inside */
    m->PCR.bit.CLKXM = 1;
    m->SRGR2.bit.CLKSM = 1;         /* the sample-rate generator runs on LSPCLK */
    m->SRGR2.bit.FPER = 31;
    m->SRGR1.bit.FWID = 0;
    m->SRGR1.bit.CLKGDV = 1;        /* CLKG = LSPCLK / 2 */
    delay_loop();
    m->SPCR2.bit.GRST = 1;
    delay_loop();
    m->SPCR2.bit.XRST = 1;
    m->SPCR1.bit.RRST = 1;
    m->SPCR2.bit.FRST = 1;
}

__attribute__((weak)) void InitMcbspa(void)
{
    init_mcbsp(&McbspaRegs);
}

__attribute__((weak)) void InitMcbspb(void)
{
    init_mcbsp(&McbspbRegs);
}

__attribute__((weak)) void InitMcbsp(void)
{
    InitMcbspa();
    InitMcbspb();
}

static void word_length(volatile struct MCBSP_REGS *m, Uint16 code)
{
    m->RCR1.bit.RWDLEN1 = code;
    m->XCR1.bit.XWDLEN1 = code;
}

__attribute__((weak)) void InitMcbspa8bit(void) { word_length(&McbspaRegs, 0); }
__attribute__((weak)) void InitMcbspa12bit(void) { word_length(&McbspaRegs, 1); }
__attribute__((weak)) void InitMcbspa16bit(void) { word_length(&McbspaRegs, 2); }
__attribute__((weak)) void InitMcbspa20bit(void) { word_length(&McbspaRegs, 3); }
__attribute__((weak)) void InitMcbspa24bit(void) { word_length(&McbspaRegs, 4); }
__attribute__((weak)) void InitMcbspa32bit(void) { word_length(&McbspaRegs, 5); }
__attribute__((weak)) void InitMcbspb8bit(void) { word_length(&McbspbRegs, 0); }
__attribute__((weak)) void InitMcbspb12bit(void) { word_length(&McbspbRegs, 1); }
__attribute__((weak)) void InitMcbspb16bit(void) { word_length(&McbspbRegs, 2); }
__attribute__((weak)) void InitMcbspb20bit(void) { word_length(&McbspbRegs, 3); }
__attribute__((weak)) void InitMcbspb24bit(void) { word_length(&McbspbRegs, 4); }
__attribute__((weak)) void InitMcbspb32bit(void) { word_length(&McbspbRegs, 5); }

__attribute__((weak)) void InitMcbspaGpio(void)
{
    EALLOW;
    GpioCtrlRegs.GPAMUX2.bit.GPIO20 = 2;  /* MDXA */
    GpioCtrlRegs.GPAMUX2.bit.GPIO21 = 2;  /* MDRA */
    GpioCtrlRegs.GPAMUX2.bit.GPIO22 = 2;  /* MCLKXA */
    GpioCtrlRegs.GPAMUX2.bit.GPIO23 = 2;  /* MFSXA */
    GpioCtrlRegs.GPBMUX2.bit.GPIO58 = 1;  /* MCLKRA */
    GpioCtrlRegs.GPBMUX2.bit.GPIO59 = 1;  /* MFSRA */
    GpioCtrlRegs.GPAPUD.bit.GPIO21 = 0;   /* pull-ups on the inputs */
    GpioCtrlRegs.GPAPUD.bit.GPIO22 = 0;
    GpioCtrlRegs.GPAPUD.bit.GPIO23 = 0;
    GpioCtrlRegs.GPBPUD.bit.GPIO58 = 0;
    GpioCtrlRegs.GPBPUD.bit.GPIO59 = 0;
    GpioCtrlRegs.GPAQSEL2.bit.GPIO21 = 3; /* asynchronous inputs */
    GpioCtrlRegs.GPAQSEL2.bit.GPIO22 = 3;
    GpioCtrlRegs.GPAQSEL2.bit.GPIO23 = 3;
    GpioCtrlRegs.GPBQSEL2.bit.GPIO58 = 3;
    GpioCtrlRegs.GPBQSEL2.bit.GPIO59 = 3;
    EDIS;
}

__attribute__((weak)) void InitMcbspbGpio(void)
{
    EALLOW;
    GpioCtrlRegs.GPAMUX2.bit.GPIO24 = 3;  /* MDXB */
    GpioCtrlRegs.GPAMUX2.bit.GPIO25 = 3;  /* MDRB */
    GpioCtrlRegs.GPAMUX2.bit.GPIO26 = 3;  /* MCLKXB */
    GpioCtrlRegs.GPAMUX2.bit.GPIO27 = 3;  /* MFSXB */
    GpioCtrlRegs.GPBMUX2.bit.GPIO60 = 1;  /* MCLKRB */
    GpioCtrlRegs.GPBMUX2.bit.GPIO61 = 1;  /* MFSRB */
    GpioCtrlRegs.GPAPUD.bit.GPIO25 = 0;
    GpioCtrlRegs.GPAPUD.bit.GPIO26 = 0;
    GpioCtrlRegs.GPAPUD.bit.GPIO27 = 0;
    GpioCtrlRegs.GPBPUD.bit.GPIO60 = 0;
    GpioCtrlRegs.GPBPUD.bit.GPIO61 = 0;
    GpioCtrlRegs.GPAQSEL2.bit.GPIO25 = 3;
    GpioCtrlRegs.GPAQSEL2.bit.GPIO26 = 3;
    GpioCtrlRegs.GPAQSEL2.bit.GPIO27 = 3;
    GpioCtrlRegs.GPBQSEL2.bit.GPIO60 = 3;
    GpioCtrlRegs.GPBQSEL2.bit.GPIO61 = 3;
    EDIS;
}

__attribute__((weak)) void InitMcbspGpio(void)
{
    InitMcbspaGpio();
    InitMcbspbGpio();
}
