/* Host replacement of TI's DSP2833x_Sci.c (see firmware_c/ti/README.md): the pin set-up of the three
   SCIs as TI's support source does it (pull-ups on, the receive pins asynchronous, the multiplexers to
   the SCI functions: SCI-A on GPIO28/29, SCI-B on GPIO18/19, SCI-C on GPIO62/63, F2833x data sheet's
   pin table). The GPIO control registers are written as on the chip; the SCIs themselves
   (rust/core/src/dsp/sci.rs) are reached whatever the mux holds. TI's InitSci is an empty placeholder:
   firmware sets its SCI up itself. */
#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"
#include "DSP2833x_DefaultIsr.h"
#include "DSP2833x_GlobalPrototypes.h"

__attribute__((weak)) void InitSci(void)
{
}

__attribute__((weak)) void InitSciaGpio(void)
{
    EALLOW;
    GpioCtrlRegs.GPAPUD.bit.GPIO28 = 0;   /* SCIRXDA pull-up on */
    GpioCtrlRegs.GPAPUD.bit.GPIO29 = 0;   /* SCITXDA pull-up on */
    GpioCtrlRegs.GPAQSEL2.bit.GPIO28 = 3; /* asynchronous input */
    GpioCtrlRegs.GPAMUX2.bit.GPIO28 = 1;  /* SCIRXDA */
    GpioCtrlRegs.GPAMUX2.bit.GPIO29 = 1;  /* SCITXDA */
    EDIS;
}

__attribute__((weak)) void InitScibGpio(void)
{
    EALLOW;
    GpioCtrlRegs.GPAPUD.bit.GPIO18 = 0;   /* SCITXDB pull-up on */
    GpioCtrlRegs.GPAPUD.bit.GPIO19 = 0;   /* SCIRXDB pull-up on */
    GpioCtrlRegs.GPAQSEL2.bit.GPIO19 = 3; /* asynchronous input */
    GpioCtrlRegs.GPAMUX2.bit.GPIO18 = 2;  /* SCITXDB */
    GpioCtrlRegs.GPAMUX2.bit.GPIO19 = 2;  /* SCIRXDB */
    EDIS;
}

__attribute__((weak)) void InitScicGpio(void)
{
    EALLOW;
    GpioCtrlRegs.GPBPUD.bit.GPIO62 = 0;   /* SCIRXDC pull-up on */
    GpioCtrlRegs.GPBPUD.bit.GPIO63 = 0;   /* SCITXDC pull-up on */
    GpioCtrlRegs.GPBQSEL2.bit.GPIO62 = 3; /* asynchronous input */
    GpioCtrlRegs.GPBMUX2.bit.GPIO62 = 1;  /* SCIRXDC */
    GpioCtrlRegs.GPBMUX2.bit.GPIO63 = 1;  /* SCITXDC */
    EDIS;
}

__attribute__((weak)) void InitSciGpio(void)
{
    InitSciaGpio();
    InitScibGpio();
    InitScicGpio();
}
