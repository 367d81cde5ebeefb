/* A GPS's NMEA sentences on SCI-B at 9600 Bd 8N1, received through the RX FIFO, polled, and echoed on
   SCI-A at 115 200 Bd: the way a TI-style project reads a GPS (SCI-B on GPIO18/19, as TI's
   InitScibGpio muxes it). CPU timer 0, free running from reset (PRD = 0xFFFFFFFF at SYSCLKOUT), times
   the end of each sentence. Our own code. */
#include "DSP28x_Project.h"

/* LSPCLK = 37.5 MHz: BRR = LSPCLK / (baud · 8) − 1. */
#define SCIB_BRR 487 /* 9605 Bd */
#define SCIA_BRR 40  /* 114 329 Bd */

Uint16 chars;          /* characters received */
Uint16 lines;          /* sentences received (their '\n') */
Uint16 dollars;        /* sentence starts ('$') */
Uint16 rx_errors;      /* characters with SCIFFFE or SCIFFPE set */
Uint32 t_line1;        /* SYSCLKOUT cycles from reset to the first sentence's '\n' read */
Uint32 t_line2;        /* and to the second's */

static void sci_setup(volatile struct SCI_REGS *sci, Uint16 brr)
{
    sci->SCIFFTX.all = 0xE040;
    sci->SCIFFRX.all = 0x204F;
    sci->SCIFFCT.all = 0x0000;
    sci->SCICCR.all = 0x0007;      /* 8N1 */
    sci->SCICTL1.all = 0x0003;     /* TX, RX on, in reset */
    sci->SCICTL2.all = 0x0000;
    sci->SCIHBAUD = (brr >> 8) & 0x00FF;
    sci->SCILBAUD = brr & 0x00FF;
    sci->SCICTL1.all = 0x0023;     /* out of reset */
}

void main(void)
{
    Uint16 c;
    Uint16 w;

    InitSysCtrl();
    InitScibGpio();
    InitSciaGpio();
    DINT;
    InitPieCtrl();
    IER = 0x0000;
    IFR = 0x0000;
    InitPieVectTable();

    sci_setup(&ScibRegs, SCIB_BRR);
    sci_setup(&SciaRegs, SCIA_BRR);

    for (;;) {
        while (ScibRegs.SCIFFRX.bit.RXFFST == 0) {
        }
        w = ScibRegs.SCIRXBUF.all;
        if (w & 0xC000)
            rx_errors++;
        c = w & 0x00FF;
        chars++;
        if (c == '$')
            dollars++;
        while (SciaRegs.SCIFFTX.bit.TXFFST == 16) {
        }
        SciaRegs.SCITXBUF = c;
        if (c == '\n') {
            lines++;
            if (lines == 1)
                t_line1 = 0xFFFFFFFFUL - CpuTimer0Regs.TIM.all;
            else if (lines == 2)
                t_line2 = 0xFFFFFFFFUL - CpuTimer0Regs.TIM.all;
        }
    }
}
