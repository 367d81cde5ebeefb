/* McBSP-A as an SPI master in digital loopback (SPCR1.DLB = 1), polled, in the style of TI's 2833x
   McBSP SPI loopback example: our own code. Clock-stop mode without delay (CLKSTP = 2, CLKXP = 0), the
   sample-rate generator on LSPCLK / 16, one word per frame with a data delay of 1 as an SPI master
   needs; each word written to DXR comes back in DRR, RRDY telling when. WORD_SIZE is 8, 16 (default)
   or 32 bits. With -DUSE_INTERRUPTS the receive interrupt (MRINTA, PIE INT6.5; SPCR1.RINTM = 00: on
   RRDY) takes each word instead: its ISR reads and checks it and sends the next one, and main only
   idles. */
#include "DSP28x_Project.h"

#ifndef WORD_SIZE
#define WORD_SIZE 16
#endif

Uint16 sdata1;  /* the word sent (its low 16 bits) */
Uint16 sdata2;  /* its high 16 bits (32-bit words) */
Uint16 rdata1;  /* the word received */
Uint16 rdata2;
Uint16 loops;   /* words that came back right */
Uint16 errors;  /* words that did not */
Uint16 sent;    /* words written to DXR */
Uint16 rx_isr;  /* receive ISR runs */

void mcbsp_init_spi_dlb(void);
void mcbsp_xmit(Uint16 a, Uint16 b);
void check_word(void);
void error(void);
#ifdef USE_INTERRUPTS
interrupt void mcbsp_rx_isr(void);
#endif

void main(void)
{
    InitSysCtrl();
    InitMcbspaGpio();

    DINT;
    InitPieCtrl();
    IER = 0x0000;
    IFR = 0x0000;
    InitPieVectTable();

#ifdef USE_INTERRUPTS
    EALLOW;
    PieVectTable.MRINTA = &mcbsp_rx_isr;
    EDIS;
#endif

    mcbsp_init_spi_dlb();

    sdata1 = 0x0000;
    sdata2 = 0xFFFF;
#ifdef USE_INTERRUPTS
    PieCtrlRegs.PIECTRL.bit.ENPIE = 1;
    PieCtrlRegs.PIEIER6.bit.INTx5 = 1;    /* MRINTA */
    IER |= M_INT6;
    EINT;
    mcbsp_xmit(sdata1, sdata2);           /* the first word; the ISR sends the others */
    for (;;) {
    }
#else
    for (;;) {
        mcbsp_xmit(sdata1, sdata2);
        while (McbspaRegs.SPCR1.bit.RRDY == 0) {
        }
        check_word();
    }
#endif
}

#ifdef USE_INTERRUPTS
interrupt void mcbsp_rx_isr(void)
{
    rx_isr++;
    check_word();
    mcbsp_xmit(sdata1, sdata2);
    PieCtrlRegs.PIEACK.all = PIEACK_GROUP6;
}
#endif

/* The word in DRR against the one sent; the next word to send. */
void check_word(void)
{
#if WORD_SIZE == 32
    rdata2 = McbspaRegs.DRR2.all;   /* DRR2 first: reading DRR1 ends the word */
#endif
    rdata1 = McbspaRegs.DRR1.all;
#if WORD_SIZE == 8
    if (rdata1 != (sdata1 & 0x00FF))
#elif WORD_SIZE == 32
    if (rdata1 != sdata1 || rdata2 != sdata2)
#else
    if (rdata1 != sdata1)
#endif
        error();
    else
        loops++;
    sdata1++;
    sdata2--;
}

void error(void)
{
    errors++;
}

void mcbsp_init_spi_dlb(void)
{
    McbspaRegs.SPCR2.all = 0x0000;        /* everything in reset */
    McbspaRegs.SPCR1.all = 0x0000;
    McbspaRegs.SPCR1.bit.DLB = 1;         /* digital loopback: DR is DX inside the McBSP */
    McbspaRegs.SPCR1.bit.CLKSTP = 2;      /* clock-stop (SPI) mode, no clock delay */
    McbspaRegs.PCR.bit.CLKXP = 0;         /* data out on the rising edge */
    McbspaRegs.PCR.bit.CLKRP = 0;
    McbspaRegs.PCR.bit.CLKXM = 1;         /* master: the McBSP drives CLKX */
    McbspaRegs.PCR.bit.SCLKME = 0;
    McbspaRegs.SRGR2.bit.CLKSM = 1;       /* the sample-rate generator runs on LSPCLK */
    McbspaRegs.SRGR1.bit.CLKGDV = 0x0F;   /* CLKG = LSPCLK / 16 */
    McbspaRegs.PCR.bit.FSXM = 1;          /* FSX driven by the McBSP: the chip select */
    McbspaRegs.PCR.bit.FSXP = 1;          /* active low */
    McbspaRegs.XCR2.bit.XDATDLY = 1;      /* a master needs a data delay of 1 */
    McbspaRegs.RCR2.bit.RDATDLY = 1;
#if WORD_SIZE == 8
    InitMcbspa8bit();
#elif WORD_SIZE == 32
    InitMcbspa32bit();
#else
    InitMcbspa16bit();
#endif
    McbspaRegs.SPCR2.bit.GRST = 1;        /* the sample-rate generator out of reset */
    delay_loop();                         /* two SRG clocks at least */
    McbspaRegs.SPCR2.bit.XRST = 1;
    McbspaRegs.SPCR1.bit.RRST = 1;
    McbspaRegs.SPCR2.bit.FRST = 1;
}

void mcbsp_xmit(Uint16 a, Uint16 b)
{
#if WORD_SIZE == 32
    McbspaRegs.DXR2.all = b;              /* DXR2 first: writing DXR1 starts the word */
#else
    (void)b;
#endif
    McbspaRegs.DXR1.all = a;
    sent++;
}
