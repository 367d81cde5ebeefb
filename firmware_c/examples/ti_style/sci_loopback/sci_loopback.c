/* SCI-A FIFO digital loopback, polled: a character written to SCITXBUF goes round the internal
   loopback (SCICCR.LOOPBKENA = 1, no pins involved) and comes back through the receive FIFO after its
   time on the line (10 bits at the baud). Written in the style of TI's 2833x peripheral examples
   (Example_2833xSci_FFDLB): our own code. */
#include "DSP28x_Project.h"

/* LSPCLK = 37.5 MHz (InitSysCtrl: LOSPCP = 2); BRR = 15: 37.5 MHz / (16 · 8) = 292 969 Bd. */
#define SCI_BRR 0x000F

void scia_loopback_init(void);
void scia_fifo_init(void);
void scia_xmit(int a);
void error(void);

Uint16 sdata;   /* the character sent */
Uint16 rdata;   /* the character received */
Uint16 loops;   /* characters that came back right */
Uint16 errors;  /* characters that did not */

void main(void)
{
    InitSysCtrl();
    InitSciaGpio();

    DINT;
    InitPieCtrl();
    IER = 0x0000;
    IFR = 0x0000;
    InitPieVectTable();

    loops = 0;
    errors = 0;
    scia_fifo_init();
    scia_loopback_init();

    sdata = 0x0000;
    for (;;) {
        scia_xmit(sdata);
        /* Wait until the character is back in the receive FIFO. */
        while (SciaRegs.SCIFFRX.bit.RXFFST != 1) {
        }
        rdata = SciaRegs.SCIRXBUF.all;
        if (rdata != sdata)
            error();
        else
            loops++;
        sdata++;
        sdata &= 0x00FF;
    }
}

void error(void)
{
    errors++;
    __asm("     ESTOP0");
}

void scia_loopback_init(void)
{
    SciaRegs.SCICCR.all = 0x0007;    /* 1 stop bit, no parity, 8 data bits, no loopback yet */
    SciaRegs.SCICTL1.all = 0x0003;   /* TX and RX on, held in reset */
    SciaRegs.SCICTL2.all = 0x0003;
    SciaRegs.SCICTL2.bit.TXINTENA = 1;
    SciaRegs.SCICTL2.bit.RXBKINTENA = 1;
    SciaRegs.SCIHBAUD = 0x0000;
    SciaRegs.SCILBAUD = SCI_BRR;
    SciaRegs.SCICCR.bit.LOOPBKENA = 1;
    SciaRegs.SCICTL1.all = 0x0023;   /* out of reset */
}

void scia_xmit(int a)
{
    SciaRegs.SCITXBUF = a;
}

void scia_fifo_init(void)
{
    SciaRegs.SCIFFTX.all = 0xE040;   /* SCIRST, FIFO enhancements, TX FIFO out of reset, clear TXFFINT */
    SciaRegs.SCIFFRX.all = 0x204F;   /* RX FIFO out of reset, clear RXFFINT, RXFFIL = 15 */
    SciaRegs.SCIFFCT.all = 0x0000;
}
