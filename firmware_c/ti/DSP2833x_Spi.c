/* Host replacement of TI's DSP2833x_Spi.c (see firmware_c/ti/README.md). The GPIO multiplexers are not
   modelled: SPI-A's pins (GPIO54..57 on the reference board, GPIO57 driven as the chip select) are
   always connected, so the pin set-up has nothing to do. TI's InitSpi is an empty placeholder and is
   left out: firmware sets SPI-A up itself. */
#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"
#include "DSP2833x_DefaultIsr.h"
#include "DSP2833x_GlobalPrototypes.h"

__attribute__((weak)) void InitSpiaGpio(void)
{
}

__attribute__((weak)) void InitSpiGpio(void)
{
    InitSpiaGpio();
}
