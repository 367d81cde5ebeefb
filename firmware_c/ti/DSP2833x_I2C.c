/* Host replacement of TI's DSP2833x_I2C.c (see firmware_c/ti/README.md): the pin set-up of I2C-A as TI's
   support source does it (pull-ups on, both pins asynchronous, the multiplexers of GPIO32/33 to SDAA/SCLA,
   GPBMUX1 = 1: F2833x data sheet's pin table). The GPIO control registers are written as on the chip;
   I2C-A itself (rust/core/src/dsp/i2c.rs) is reached whatever the mux holds. */
#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"

__attribute__((weak)) void InitI2CGpio(void)
{
    EALLOW;
    GpioCtrlRegs.GPBPUD.bit.GPIO32 = 0;   /* SDAA pull-up on */
    GpioCtrlRegs.GPBPUD.bit.GPIO33 = 0;   /* SCLA pull-up on */
    GpioCtrlRegs.GPBQSEL1.bit.GPIO32 = 3; /* asynchronous input */
    GpioCtrlRegs.GPBQSEL1.bit.GPIO33 = 3;
    GpioCtrlRegs.GPBMUX1.bit.GPIO32 = 1;  /* SDAA */
    GpioCtrlRegs.GPBMUX1.bit.GPIO33 = 1;  /* SCLA */
    EDIS;
}
