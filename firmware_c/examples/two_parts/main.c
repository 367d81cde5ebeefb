/* Two SPI parts on SPI-A behind two GPIO chip selects (firmware_model/adis_ads8344.toml): the ADIS16407
   on GPIO57 (SPI mode 3, 16-bit characters, 0.75 MHz) and the ADS8344 on GPIO60 (mode 0, 8-bit
   characters, 2.34 MHz, the geomag board's set-up). Every millisecond the firmware reads the
   ADIS16407's PROD_ID and SUPPLY_OUT, then converts the ADS8344's eight channels, single-ended,
   external clock: the control byte and three read bytes per channel, the code the 16 bits after the
   null bit. SPI-A is set up again for each part (the two need different modes and character lengths).
   Written against TI's DSP2833x headers; built unmodified by `sins-fw build-firmware`. */
#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"

#define ADIS_CS 57
#define ADC_CS 60

Uint16 prod_id;    /* the ADIS16407's PROD_ID (0x4017) */
Uint16 supply;     /* its SUPPLY_OUT word */
Uint16 codes[8];   /* the ADS8344's codes, channel 0..7 */
Uint16 code7;      /* channel 7 (VREF/2 on the geomag front end) */
Uint16 code0;      /* channel 0 */
Uint32 rounds;     /* read rounds done */

static Uint16 spi_xmit(Uint16 a) {
    while (SpiaRegs.SPISTS.bit.BUFFULL_FLAG == 1) {
    }
    SpiaRegs.SPITXBUF = a;
    while (SpiaRegs.SPISTS.bit.INT_FLAG != 1) {
    }
    return SpiaRegs.SPIRXBUF;
}

/* SPI-A in reset, then the character length, clock scheme and baud rate, then released. */
static void spi_setup(Uint16 spiccr, Uint16 spictl, Uint16 spibrr) {
    SpiaRegs.SPICCR.bit.SPISWRESET = 0;
    SpiaRegs.SPICCR.all = spiccr;
    SpiaRegs.SPICTL.all = spictl;
    SpiaRegs.SPIBRR = spibrr;
    SpiaRegs.SPICCR.bit.SPISWRESET = 1;
    SpiaRegs.SPIPRI.bit.FREE = 1;
}

/* Both chip selects GPIO outputs, high (the SPI data pins are left to the board). */
static void init_chip_selects(void) {
    GpioDataRegs.GPBSET.bit.GPIO57 = 1;
    GpioDataRegs.GPBSET.bit.GPIO60 = 1;
    EALLOW;
    GpioCtrlRegs.GPBMUX2.bit.GPIO57 = 0;
    GpioCtrlRegs.GPBMUX2.bit.GPIO60 = 0;
    GpioCtrlRegs.GPBDIR.bit.GPIO57 = 1;
    GpioCtrlRegs.GPBDIR.bit.GPIO60 = 1;
    EDIS;
}

static void read_adis(void) {
    /* Mode 3 (CLKPOLARITY = 1, CLK_PHASE = 0), 16-bit, master, TALK; SPIBRR 49: 0.75 MHz. */
    spi_setup(0x004F, 0x0006, 49);
    GpioDataRegs.GPBCLEAR.bit.GPIO57 = 1;
    spi_xmit(0x5600); /* PROD_ID */
    DELAY_US(40);
    prod_id = spi_xmit(0x0200); /* SUPPLY_OUT next */
    DELAY_US(40);
    supply = spi_xmit(0x0000);
    GpioDataRegs.GPBSET.bit.GPIO57 = 1;
}

static void read_adc(void) {
    /* Mode 0 (CLKPOLARITY = 0, CLK_PHASE = 1), 8-bit, master, TALK; SPIBRR 15: 2.34 MHz. */
    static const Uint16 select[8] = {0, 4, 1, 5, 2, 6, 3, 7}; /* A2..A0 of channel n, single-ended */
    Uint16 ch;
    spi_setup(0x0007, 0x000E, 15);
    for (ch = 0; ch < 8; ch++) {
        Uint32 b1, b2, b3;
        Uint16 control = (Uint16)(0x80u | select[ch] << 4 | 0x04u | 0x03u);
        GpioDataRegs.GPBCLEAR.bit.GPIO60 = 1;
        spi_xmit((Uint16)(control << 8)); /* 8-bit characters go out from SPITXBUF's top byte */
        b1 = spi_xmit(0) & 0xFFu;
        b2 = spi_xmit(0) & 0xFFu;
        b3 = spi_xmit(0) & 0xFFu;
        GpioDataRegs.GPBSET.bit.GPIO60 = 1;
        codes[ch] = (Uint16)(((b1 << 16) | (b2 << 8) | b3) >> 7);
    }
    code0 = codes[0];
    code7 = codes[7];
}

void main(void) {
    init_chip_selects();
    DELAY_US(10000); /* let the ADIS16407 start sampling */
    for (;;) {
        read_adis();
        read_adc();
        rounds++;
        DELAY_US(1000);
    }
}
