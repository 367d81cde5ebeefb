/* Host replacement of TI's DSP2833x_EPwm.c (see firmware_c/ti/README.md), our own code: InitEPwm is an
   empty placeholder, as TI's; InitEPwmGpio muxes the ePWM outputs EPWM1A…EPWM6B to GPIO0-11 (GPAMUX1 = 1,
   pull-ups off, as after reset). The ePWMs are not modelled (rust/core/src/dsp/unmodelled.rs). */
#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"

__attribute__((weak)) void InitEPwm(void)
{
}

static void epwm_pins(Uint16 n)
{
    Uint32 pins = 3UL << (2 * (n - 1));           /* EPWMnA, EPWMnB: GPIO 2n-2 and 2n-1 */
    Uint32 mux = 0x5UL << (4 * (n - 1));           /* both muxed to 1 */
    EALLOW;
    GpioCtrlRegs.GPAPUD.all |= pins;
    GpioCtrlRegs.GPAMUX1.all = (GpioCtrlRegs.GPAMUX1.all & ~(0xFUL << (4 * (n - 1)))) | mux;
    EDIS;
}

__attribute__((weak)) void InitEPwm1Gpio(void) { epwm_pins(1); }
__attribute__((weak)) void InitEPwm2Gpio(void) { epwm_pins(2); }
__attribute__((weak)) void InitEPwm3Gpio(void) { epwm_pins(3); }
__attribute__((weak)) void InitEPwm4Gpio(void) { epwm_pins(4); }
__attribute__((weak)) void InitEPwm5Gpio(void) { epwm_pins(5); }
__attribute__((weak)) void InitEPwm6Gpio(void) { epwm_pins(6); }

__attribute__((weak)) void InitEPwmGpio(void)
{
    InitEPwm1Gpio();
    InitEPwm2Gpio();
    InitEPwm3Gpio();
    InitEPwm4Gpio();
    InitEPwm5Gpio();
    InitEPwm6Gpio();
}
