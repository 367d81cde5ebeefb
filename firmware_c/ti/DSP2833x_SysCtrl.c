/* Host replacement of TI's DSP2833x_SysCtrl.c (see firmware_c/ti/README.md). Of the system-control
   registers the emulator models LOSPCP only: SYSCLKOUT is the profile's (the reference: 30 MHz
   crystal, PLLCR = 10, DIVSEL = /2, 150 MHz), the watchdog never bites, the flash wait states and the
   peripheral clock enables are not modelled. So InitSysCtrl writes what the board models, LOSPCP =
   2 (LSPCLK = SYSCLKOUT / 4, TI's value), and the PLL, watchdog and flash functions do nothing. */
#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"
#include "DSP2833x_DefaultIsr.h"
#include "DSP2833x_GlobalPrototypes.h"

__attribute__((weak)) void DisableDog(void)
{
}

__attribute__((weak)) void ServiceDog(void)
{
}

__attribute__((weak)) void InitPll(Uint16 pllcr, Uint16 clkindiv)
{
    (void)pllcr;
    (void)clkindiv;
}

__attribute__((weak)) void InitFlash(void)
{
}

__attribute__((weak)) void InitPeripheralClocks(void)
{
    EALLOW;
    SysCtrlRegs.LOSPCP.all = 0x0002;
    EDIS;
}

__attribute__((weak)) void InitSysCtrl(void)
{
    DisableDog();
    InitPll(10, 2);
    InitPeripheralClocks();
}
