/* SCI-A and SCI-C FIFO digital loopback with interrupts: each port's TX FIFO interrupt (TXFFIL = 2)
   writes two characters, its RX FIFO interrupt (RXFFIL = 2) reads them back and checks them. SCI-A's
   interrupts are PIE group 9 (SCIRXINTA 9.1, SCITXINTA 9.2), SCI-C's group 8 (SCIRXINTC 8.5,
   SCITXINTC 8.6). Written in the style of TI's 2833x peripheral examples (Example_2833xSci_FFDLB_int):
   our own code. */
#include "DSP28x_Project.h"

#define SCI_BRR 0x000F /* 292 969 Bd at LSPCLK 37.5 MHz */

interrupt void sciaTxFifoIsr(void);
interrupt void sciaRxFifoIsr(void);
interrupt void scicTxFifoIsr(void);
interrupt void scicRxFifoIsr(void);
void sci_fifo_init(volatile struct SCI_REGS *sci);
void error(void);

Uint16 sdataA[2];
Uint16 sdataC[2];
Uint16 rdata_pointA;
Uint16 rdata_pointC;
Uint16 rx_a, tx_a, rx_c, tx_c; /* ISR runs */
Uint16 errors;

void main(void)
{
    Uint16 i;

    InitSysCtrl();
    InitSciGpio();

    DINT;
    InitPieCtrl();
    IER = 0x0000;
    IFR = 0x0000;
    InitPieVectTable();

    EALLOW;
    PieVectTable.SCIRXINTA = &sciaRxFifoIsr;
    PieVectTable.SCITXINTA = &sciaTxFifoIsr;
    PieVectTable.SCIRXINTC = &scicRxFifoIsr;
    PieVectTable.SCITXINTC = &scicTxFifoIsr;
    EDIS;

    for (i = 0; i < 2; i++) {
        sdataA[i] = i;
        sdataC[i] = 0x80 + i;
    }
    rdata_pointA = sdataA[0];
    rdata_pointC = sdataC[0];
    sci_fifo_init(&SciaRegs);
    sci_fifo_init(&ScicRegs);

    PieCtrlRegs.PIECTRL.bit.ENPIE = 1;
    PieCtrlRegs.PIEIER9.bit.INTx1 = 1;
    PieCtrlRegs.PIEIER9.bit.INTx2 = 1;
    PieCtrlRegs.PIEIER8.bit.INTx5 = 1;
    PieCtrlRegs.PIEIER8.bit.INTx6 = 1;
    IER |= M_INT8 | M_INT9;
    EINT;

    for (;;) {
    }
}

void error(void)
{
    errors++;
    __asm("     ESTOP0");
}

interrupt void sciaTxFifoIsr(void)
{
    Uint16 i;
    for (i = 0; i < 2; i++)
        SciaRegs.SCITXBUF = sdataA[i];
    for (i = 0; i < 2; i++)
        sdataA[i] = (sdataA[i] + 1) & 0x00FF;
    tx_a++;
    SciaRegs.SCIFFTX.bit.TXFFINTCLR = 1;
    PieCtrlRegs.PIEACK.all |= PIEACK_GROUP9;
}

interrupt void sciaRxFifoIsr(void)
{
    Uint16 i, r;
    for (i = 0; i < 2; i++) {
        r = SciaRegs.SCIRXBUF.all;
        if (r != ((rdata_pointA + i) & 0x00FF))
            error();
    }
    rdata_pointA = (rdata_pointA + 1) & 0x00FF;
    rx_a++;
    SciaRegs.SCIFFRX.bit.RXFFOVRCLR = 1;
    SciaRegs.SCIFFRX.bit.RXFFINTCLR = 1;
    PieCtrlRegs.PIEACK.all |= PIEACK_GROUP9;
}

interrupt void scicTxFifoIsr(void)
{
    Uint16 i;
    for (i = 0; i < 2; i++)
        ScicRegs.SCITXBUF = sdataC[i];
    for (i = 0; i < 2; i++)
        sdataC[i] = (sdataC[i] + 1) & 0x00FF;
    tx_c++;
    ScicRegs.SCIFFTX.bit.TXFFINTCLR = 1;
    PieCtrlRegs.PIEACK.all |= PIEACK_GROUP8;
}

interrupt void scicRxFifoIsr(void)
{
    Uint16 i, r;
    for (i = 0; i < 2; i++) {
        r = ScicRegs.SCIRXBUF.all;
        if (r != ((rdata_pointC + i) & 0x00FF))
            error();
    }
    rdata_pointC = (rdata_pointC + 1) & 0x00FF;
    rx_c++;
    ScicRegs.SCIFFRX.bit.RXFFOVRCLR = 1;
    ScicRegs.SCIFFRX.bit.RXFFINTCLR = 1;
    PieCtrlRegs.PIEACK.all |= PIEACK_GROUP8;
}

void sci_fifo_init(volatile struct SCI_REGS *sci)
{
    sci->SCICCR.all = 0x0007;        /* 1 stop bit, no parity, 8 data bits */
    sci->SCICTL1.all = 0x0003;       /* TX and RX on, held in reset */
    sci->SCICTL2.bit.TXINTENA = 1;
    sci->SCICTL2.bit.RXBKINTENA = 1;
    sci->SCIHBAUD = 0x0000;
    sci->SCILBAUD = SCI_BRR;
    sci->SCICCR.bit.LOOPBKENA = 1;
    sci->SCIFFTX.all = 0xC022;       /* FIFO mode, TX interrupt at TXFFST <= 2, TX FIFO held in reset */
    sci->SCIFFRX.all = 0x0022;       /* RX interrupt at RXFFST >= 2, RX FIFO held in reset */
    sci->SCIFFCT.all = 0x00;
    sci->SCICTL1.all = 0x0023;       /* out of reset */
    sci->SCIFFTX.bit.TXFIFOXRESET = 1;
    sci->SCIFFRX.bit.RXFIFORESET = 1;
}
