/* SPI bit-banged on GPIO54-57, in the style of TI's 2833x peripheral examples: our own code. SPI-A's
   pins are muxed to GPIO and moved by the CPU as a master without the SPI peripheral: GPIO56 SCLK
   (idling high: SPI mode 3, the ADIS16407's), GPIO54 MOSI, GPIO55 MISO (an input), GPIO57 the part's
   chip select. After the part's start-up, PROD_ID (register 0x56) is read: a command frame 0x5600,
   then a second frame whose 16 bits come back on MISO, each sampled after SCLK's rising edge.

   HALF_PERIOD_US is half an SCLK period (default 1 us: SCLK 500 kHz at most, under the part's 2 MHz);
   built with HALF_PERIOD_US=0 the clock runs as fast as the CPU moves the pins. */
#include "DSP28x_Project.h"

#ifndef HALF_PERIOD_US
#define HALF_PERIOD_US 1
#endif

#define PROD_ID_READ 0x5600   /* read command: bit 15 = 0, the register's address in bits 14:8 */
#define STALL_US 20           /* CS high between frames: more than the part's 9 us stall */

Uint16 prod_id;     /* the word the second frame read */
Uint16 first_word;  /* the word the command frame read (the part's answer to the frame before it) */
Uint16 done;
Uint32 idle;

static void half_period(void)
{
#if HALF_PERIOD_US > 0
    DELAY_US(HALF_PERIOD_US);
#endif
}

static void init_bitbang_gpio(void)
{
    EALLOW;
    GpioCtrlRegs.GPBMUX2.bit.GPIO54 = 0;     /* GPIO, not SPISIMOA */
    GpioCtrlRegs.GPBMUX2.bit.GPIO55 = 0;     /* GPIO, not SPISOMIA */
    GpioCtrlRegs.GPBMUX2.bit.GPIO56 = 0;     /* GPIO, not SPICLKA */
    GpioCtrlRegs.GPBMUX2.bit.GPIO57 = 0;     /* GPIO, not SPISTEA */
    GpioCtrlRegs.GPBPUD.bit.GPIO55 = 0;      /* pull-up on MISO */
    GpioCtrlRegs.GPBDIR.bit.GPIO54 = 1;
    GpioCtrlRegs.GPBDIR.bit.GPIO55 = 0;
    GpioCtrlRegs.GPBDIR.bit.GPIO56 = 1;
    GpioCtrlRegs.GPBDIR.bit.GPIO57 = 1;
    EDIS;
    GpioDataRegs.GPBSET.bit.GPIO57 = 1;      /* CS high */
    GpioDataRegs.GPBSET.bit.GPIO56 = 1;      /* SCLK idles high (CPOL = 1) */
    GpioDataRegs.GPBCLEAR.bit.GPIO54 = 1;
}

/* One 16-bit frame in mode 3, MSB first: SCLK falls (the part shifts its next bit out, the master
   sets MOSI), then rises (both sides sample). */
static Uint16 xfer16(Uint16 out)
{
    Uint16 in = 0;
    int16 i;
    for (i = 15; i >= 0; i--) {
        GpioDataRegs.GPBCLEAR.bit.GPIO56 = 1;
        if (out & (1u << i))
            GpioDataRegs.GPBSET.bit.GPIO54 = 1;
        else
            GpioDataRegs.GPBCLEAR.bit.GPIO54 = 1;
        half_period();
        GpioDataRegs.GPBSET.bit.GPIO56 = 1;
        in = (in << 1) | GpioDataRegs.GPBDAT.bit.GPIO55;
        half_period();
    }
    return in;
}

static Uint16 frame(Uint16 out)
{
    Uint16 in;
    GpioDataRegs.GPBCLEAR.bit.GPIO57 = 1;    /* CS low */
    DELAY_US(1);                             /* CS set-up */
    in = xfer16(out);
    DELAY_US(1);                             /* CS hold */
    GpioDataRegs.GPBSET.bit.GPIO57 = 1;      /* CS high */
    DELAY_US(STALL_US);
    return in;
}

void main(void)
{
    InitSysCtrl();
    init_bitbang_gpio();

    DINT;
    InitPieCtrl();
    IER = 0x0000;
    IFR = 0x0000;
    InitPieVectTable();

    /* CPU timer 2 free-running, for the idle loop below. */
    CpuTimer2Regs.PRD.all = 0xFFFFFFFF;
    CpuTimer2Regs.TCR.all = 0x0030;
    CpuTimer2Regs.TCR.all = 0x0000;

    DELAY_US(250000L);                       /* the ADIS16407's 210 ms start-up */
    first_word = frame(PROD_ID_READ);
    prod_id = frame(0x0000);
    done = 1;
    for (;;) {
        idle = CpuTimer2Regs.TIM.all;
    }
}
