/* SPI-A FIFO digital loopback, polled: a word written to SPITXBUF goes round the internal loopback
   (SPICCR.SPILBK = 1, no pins involved) and comes back through the receive FIFO. Written in the style
   of TI's 2833x peripheral examples. */
#include "DSP28x_Project.h"
#include "spi_loopback.h"

Uint16 sdata;   /* the word sent */
Uint16 rdata;   /* the word received */
Uint16 loops;   /* words that came back right */
Uint16 errors;  /* words that did not */

void main(void)
{
    /* System: PLL, watchdog, peripheral clocks (DSP2833x_SysCtrl.c). */
    InitSysCtrl();
    /* SPI-A's pins (DSP2833x_Spi.c): loopback needs none, TI's examples set them anyway. */
    InitSpiaGpio();

    /* Interrupts off and the PIE at its defaults, as every TI example starts. */
    DINT;
    InitPieCtrl();
    IER = 0x0000;
    IFR = 0x0000;
    InitPieVectTable();

    spi_fifo_init();
    spi_init();

    sdata = 0x0000;
    for (;;) {
        spi_xmit(sdata);
        /* Wait until the word is back in the receive FIFO. */
        while (SpiaRegs.SPIFFRX.bit.RXFFST != 1) {
        }
        rdata = SpiaRegs.SPIRXBUF;
        if (rdata != sdata)
            error();
        else
            loops++;
        sdata++;
    }
}

void error(void)
{
    errors++;
    __asm("     ESTOP0"); /* a breakpoint under the debugger */
}

void spi_init(void)
{
    SpiaRegs.SPICCR.all = 0x000F;          /* in reset, 16-bit characters */
    SpiaRegs.SPICTL.all = 0x0006;          /* master, TALK, no SPI interrupt */
    SpiaRegs.SPIBRR = LOOPBACK_BRR;
    SpiaRegs.SPICCR.bit.SPILBK = 1;        /* internal loopback */
    SpiaRegs.SPICCR.bit.SPISWRESET = 1;    /* out of reset */
    SpiaRegs.SPIPRI.bit.FREE = 1;          /* free run at a breakpoint */
}

void spi_xmit(Uint16 word)
{
    SpiaRegs.SPITXBUF = word;
}

void spi_fifo_init(void)
{
    SpiaRegs.SPIFFTX.all = 0xE040;  /* SPIRST, FIFO enhancements, TX FIFO out of reset, clear TXFFINT */
    SpiaRegs.SPIFFRX.all = 0x204F;  /* RX FIFO out of reset, clear RXFFINT, RXFFIL = 15 */
    SpiaRegs.SPIFFCT.all = 0x0000;  /* no transmit delay */
}
