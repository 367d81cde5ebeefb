/* A minimal user firmware, written as for the real board against TI's DSP2833x headers: InitSpi as in
   the reference design (mode 3, 16-bit, SPIBRR 49: 0.75 MHz at LSPCLK 37.5 MHz), then PROD_ID read over
   and over with polled SPI-A and GPIO57 as the chip select. Built unmodified by `sins-fw build-firmware`. */
#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"

Uint16 prod_id;
Uint16 reads;

static Uint16 spi_xmit(Uint16 a) {
    while (SpiaRegs.SPISTS.bit.BUFFULL_FLAG == 1) {
    }
    SpiaRegs.SPITXBUF = a;
    while (SpiaRegs.SPISTS.bit.INT_FLAG != 1) {
    }
    return SpiaRegs.SPIRXBUF;
}

static void init_spi(void) {
    SpiaRegs.SPICCR.bit.SPISWRESET = 0;
    SpiaRegs.SPICCR.all = 0x004F;  /* in reset, CLKPOLARITY = 1, 16-bit characters */
    SpiaRegs.SPICTL.all = 0x0006;  /* master, TALK, CLK_PHASE = 0: TI's "falling edge without delay" = mode 3 */
    SpiaRegs.SPIBRR = 49;
    SpiaRegs.SPICCR.bit.SPISWRESET = 1;
    SpiaRegs.SPIPRI.bit.FREE = 1;
}

void main(void) {
    EALLOW;
    GpioDataRegs.GPBSET.bit.GPIO57 = 1; /* CS high */
    EDIS;
    init_spi();
    DELAY_US(10000); /* let the ADIS16407 start sampling */
    for (;;) {
        GpioDataRegs.GPBCLEAR.bit.GPIO57 = 1;
        spi_xmit(0x5600);
        DELAY_US(40);
        prod_id = spi_xmit(0x0000);
        GpioDataRegs.GPBSET.bit.GPIO57 = 1;
        reads++;
        DELAY_US(1000);
    }
}
