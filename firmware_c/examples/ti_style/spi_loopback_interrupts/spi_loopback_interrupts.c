/* SPI-A digital loopback (SPICCR.SPILBK = 1) through the FIFOs with interrupts: the transmit FIFO
   interrupt (SPITXINTA, PIE INT6.2) refills 2 words whenever the FIFO holds no more than TXFFIL = 2,
   the receive FIFO interrupt (SPIRXINTA, INT6.1) reads 2 words once RXFFST reaches RXFFIL = 2 and
   checks them. Written in the style of TI's 2833x spi_loopback_interrupts example. */
#include "DSP28x_Project.h"

interrupt void spiTxFifoIsr(void);
interrupt void spiRxFifoIsr(void);
void spi_fifo_init(void);

Uint16 sdata[2];    /* words sent */
Uint16 rdata[2];    /* words received */
Uint16 rdata_point; /* the first word expected back */
Uint16 tx_isr, rx_isr, errors;

void main(void)
{
    Uint16 i;

    InitSysCtrl();
    InitSpiaGpio();

    DINT;
    InitPieCtrl();
    IER = 0x0000;
    IFR = 0x0000;
    InitPieVectTable();

    EALLOW;
    PieVectTable.SPIRXINTA = &spiRxFifoIsr;
    PieVectTable.SPITXINTA = &spiTxFifoIsr;
    EDIS;

    spi_fifo_init();

    for (i = 0; i < 2; i++) {
        sdata[i] = i;
    }
    rdata_point = 0;

    PieCtrlRegs.PIECTRL.bit.ENPIE = 1;
    PieCtrlRegs.PIEIER6.bit.INTx1 = 1; /* SPIRXINTA */
    PieCtrlRegs.PIEIER6.bit.INTx2 = 1; /* SPITXINTA */
    IER = 0x20;                        /* M_INT6 */
    EINT;

    for (;;) {
    }
}

void spi_fifo_init(void)
{
    SpiaRegs.SPICCR.all = 0x001F;   /* reset, 16-bit characters, loopback */
    SpiaRegs.SPICTL.all = 0x0017;   /* interrupt enabled, master, talk, overrun interrupt */
    SpiaRegs.SPISTS.all = 0x0000;
    SpiaRegs.SPIBRR = 0x0063;       /* LSPCLK / 100 */
    SpiaRegs.SPIFFTX.all = 0xC022;  /* FIFO on, TX FIFO interrupt at TXFFIL = 2 */
    SpiaRegs.SPIFFRX.all = 0x0022;  /* RX FIFO interrupt at RXFFIL = 2 */
    SpiaRegs.SPIFFCT.all = 0x00;
    SpiaRegs.SPIPRI.all = 0x0010;
    SpiaRegs.SPICCR.bit.SPISWRESET = 1;
    SpiaRegs.SPIFFTX.bit.TXFIFO = 1;
    SpiaRegs.SPIFFRX.bit.RXFIFORESET = 1;
}

interrupt void spiTxFifoIsr(void)
{
    Uint16 i;
    for (i = 0; i < 2; i++) {
        SpiaRegs.SPITXBUF = sdata[i];
    }
    for (i = 0; i < 2; i++) {
        sdata[i] = sdata[i] + 1;
    }
    tx_isr++;
    SpiaRegs.SPIFFTX.bit.TXFFINTCLR = 1;
    PieCtrlRegs.PIEACK.all |= 0x20;
}

interrupt void spiRxFifoIsr(void)
{
    Uint16 i;
    for (i = 0; i < 2; i++) {
        rdata[i] = SpiaRegs.SPIRXBUF;
    }
    for (i = 0; i < 2; i++) {
        if (rdata[i] != rdata_point + i) {
            errors++;
        }
    }
    rdata_point++;
    rx_isr++;
    SpiaRegs.SPIFFRX.bit.RXFFOVFCLR = 1;
    SpiaRegs.SPIFFRX.bit.RXFFINTCLR = 1;
    PieCtrlRegs.PIEACK.all |= 0x20;
}
