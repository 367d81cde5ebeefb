/* Host replacement of TI's DSP2833x_Spi.c (see firmware_c/ti/README.md), written for sins-fw. The GPIO
   is modelled (rust/core/src/dsp/gpio.rs): InitSpiaGpio gives SPI-A its alternate pins as TI's
   support source does (SPRUFB0, GPIO chapter; pin functions as /work spec f28335-peripherals.md §3):
   GPIO54..57 muxed to SPISIMOA, SPISOMIA, SPICLKA and SPISTEA (GPBMUX2 = 1), their pull-ups on and
   their inputs asynchronous (GPBQSEL2 = 3), under EALLOW. With GPIO57 muxed to SPISTEA, SPI-A drives
   the chip select around each character. TI's InitSpi is an empty placeholder and is left out:
   firmware sets SPI-A up itself. */
#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"
#include "DSP2833x_DefaultIsr.h"
#include "DSP2833x_GlobalPrototypes.h"

__attribute__((weak)) void InitSpiaGpio(void)
{
    EALLOW;
    /* Pull-ups on (PUD bit 0). */
    GpioCtrlRegs.GPBPUD.bit.GPIO54 = 0;
    GpioCtrlRegs.GPBPUD.bit.GPIO55 = 0;
    GpioCtrlRegs.GPBPUD.bit.GPIO56 = 0;
    GpioCtrlRegs.GPBPUD.bit.GPIO57 = 0;
    /* Asynchronous inputs: the SPI samples its own pins. */
    GpioCtrlRegs.GPBQSEL2.bit.GPIO54 = 3;
    GpioCtrlRegs.GPBQSEL2.bit.GPIO55 = 3;
    GpioCtrlRegs.GPBQSEL2.bit.GPIO56 = 3;
    GpioCtrlRegs.GPBQSEL2.bit.GPIO57 = 3;
    /* SPI-A's functions. */
    GpioCtrlRegs.GPBMUX2.bit.GPIO54 = 1; /* SPISIMOA */
    GpioCtrlRegs.GPBMUX2.bit.GPIO55 = 1; /* SPISOMIA */
    GpioCtrlRegs.GPBMUX2.bit.GPIO56 = 1; /* SPICLKA */
    GpioCtrlRegs.GPBMUX2.bit.GPIO57 = 1; /* SPISTEA */
    EDIS;
}

__attribute__((weak)) void InitSpiGpio(void)
{
    InitSpiaGpio();
}
