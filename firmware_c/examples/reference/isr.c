/* The reference firmware's start-up, CPU timer 0 interrupt and burst read, written as a user would
   against TI's DSP2833x headers (the thesis publishes the per-frame SPI code of section 4.4.2, not
   this glue). Every 4 ms CPU timer 0 interrupts; the ISR reads one 15-word burst of the ADIS16407
   (0x4200, then SUPPLY_OUT ... AUX_ADC) over SPI-A with GPIO57 as the chip select, and hands the
   words to the attitude code (glue.c). main initialises SPI-A as the reference profile's InitSpi
   (SPICCR 0x004F, SPICTL, SPIBRR, SPICCR 0x00CF, SPIPRI), the timer and the PIE, then idles.

   It needs the host build's CPU timer 0 and PIE (issue 20, item 3) to build; published.c, glue.c and
   navigation.c build and run without it (tests/test_reference_firmware.py calls
   reference_process_burst). */
#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"
#include "reference.h"

#define BURST_WORDS 15
#ifndef TIMER_PERIOD_US /* the published 4 ms; a build may define another (-DTIMER_PERIOD_US=300) */
#define TIMER_PERIOD_US 4000
#endif

interrupt void cpu_timer0_isr(void);

Uint16 rdata[BURST_WORDS];
Uint32 bursts;

/* Section 4.4.2, as printed: ready to send when the transmit buffer is not full ... */
unsigned int Spi_TxReady(void)
{
    unsigned int n;
    if (SpiaRegs.SPISTS.bit.BUFFULL_FLAG == 1)
        { n = 0; }
    else
        { n = 1; }
    return (n);
}

/* ... and a word received when INT_FLAG is set. */
unsigned int Spi_RxReady(void)
{
    unsigned int m;
    if (SpiaRegs.SPISTS.bit.INT_FLAG == 1)
        { m = 1; }
    else
        { m = 0; }
    return (m);
}

static void InitSpi(void)
{
    SpiaRegs.SPICCR.all = 0x004F;  /* in reset, CLKPOLARITY = 1, 16-bit characters */
    SpiaRegs.SPICTL.all = 0x0007;  /* master, TALK, SPI interrupt enable; CLK_PHASE = 0: mode 3 */
    SpiaRegs.SPIBRR = 49;          /* LSPCLK 37.5 MHz / 50 = 0.75 MHz */
    SpiaRegs.SPICCR.all = 0x00CF;  /* out of reset */
    SpiaRegs.SPIPRI.all = 0x0020;  /* SOFT */
}

void main(void)
{
    InitSysCtrl();  /* 150 MHz; LSPCLK = SYSCLKOUT / 4 */
    DINT;
    InitPieCtrl();
    IER = 0x0000;
    IFR = 0x0000;
    InitPieVectTable();
    EALLOW;
    PieVectTable.TINT0 = &cpu_timer0_isr;
    EDIS;

    EALLOW;
    GpioDataRegs.GPBSET.bit.GPIO57 = 1;  /* CS high */
    EDIS;
    InitSpi();

    InitCpuTimers();
    ConfigCpuTimer(&CpuTimer0, 150, TIMER_PERIOD_US);
    CpuTimer0Regs.TCR.all = 0x4001;  /* TIE = 1, TSS = 0: start */

    IER |= M_INT1;
    PieCtrlRegs.PIEIER1.bit.INTx7 = 1;  /* TINT0 */
    EINT;
    ERTM;
    for (;;) {
    }
}

/* One burst read per tick: per frame, wait until the transmit buffer is free, send (0x4200 first,
   then zeros), wait for the received word, read it (reference-design.md's reading of the listing, and
   the emulator's model); then the attitude code. The thesis prints the per-frame steps in another
   order, `if (Spi_RxReady() == 1) { rdata = SpiaRegs.SPIRXBUF; } while (Spi_RxReady() != 1) { }`
   after the write: taken literally, each frame would read the word of the frame before (INT_FLAG is
   still set from it), shifting the burst by one word. */
interrupt void cpu_timer0_isr(void)
{
    Uint16 i, sdata;
    GpioDataRegs.GPBDAT.bit.GPIO57 = 0;  /* CS low */
    for (i = 0; i < BURST_WORDS; i++) {
        sdata = (i == 0) ? 0x4200 : 0x0000;
        while (Spi_TxReady() != 1) { }
        SpiaRegs.SPITXBUF = sdata;
        while (Spi_RxReady() != 1) { }
        rdata[i] = SpiaRegs.SPIRXBUF;
    }
    GpioDataRegs.GPBDAT.bit.GPIO57 = 1;  /* CS high */
    bursts++;
    reference_process_burst(rdata);
    PieCtrlRegs.PIEACK.all = PIEACK_GROUP1;
}
