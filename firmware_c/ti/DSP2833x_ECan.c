/* Host replacement of TI's DSP2833x_ECan.c (see firmware_c/ti/README.md), our own code in TI's idiom
   (whole-register copies through a shadow): InitECana/InitECanb route the CAN pins to the module
   (CANTIOC.TXFUNC, CANRIOC.RXFUNC), select eCAN mode (CANMC.SCB), clear the flags, then ask for the
   configuration mode (CANMC.CCR, waiting for CANES.CCE), set the bit timing of 1 Mbit/s at 150 MHz
   (BRPREG 9, TSEG2REG 2, TSEG1REG 10: SYSCLKOUT/2/(BRP+1)/(TSEG1+TSEG2+3) [unconfirmed]) and leave it
   again, and disable every mailbox. eCAN is not modelled (rust/core/src/dsp/unmodelled.rs): CANES.CCE
   follows CANMC.CCR so that the waits end; no frame is sent or received. */
#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"

static void init_ecan(volatile struct ECAN_REGS *regs, volatile struct ECAN_MBOXES *boxes)
{
    struct ECAN_REGS shadow;
    EALLOW;
    shadow.CANTIOC.all = regs->CANTIOC.all;
    shadow.CANTIOC.bit.TXFUNC = 1;
    regs->CANTIOC.all = shadow.CANTIOC.all;
    shadow.CANRIOC.all = regs->CANRIOC.all;
    shadow.CANRIOC.bit.RXFUNC = 1;
    regs->CANRIOC.all = shadow.CANRIOC.all;
    shadow.CANMC.all = regs->CANMC.all;
    shadow.CANMC.bit.SCB = 1;
    regs->CANMC.all = shadow.CANMC.all;
    boxes->MBOX0.MSGCTRL.all = 0;
    regs->CANTA.all = 0xFFFFFFFF;
    regs->CANRMP.all = 0xFFFFFFFF;
    regs->CANGIF0.all = 0xFFFFFFFF;
    regs->CANGIF1.all = 0xFFFFFFFF;
    shadow.CANMC.all = regs->CANMC.all;
    shadow.CANMC.bit.CCR = 1;
    regs->CANMC.all = shadow.CANMC.all;
    do {
        shadow.CANES.all = regs->CANES.all;
    } while (shadow.CANES.bit.CCE != 1);
    shadow.CANBTC.all = 0;
    shadow.CANBTC.bit.BRPREG = 9;
    shadow.CANBTC.bit.TSEG2REG = 2;
    shadow.CANBTC.bit.TSEG1REG = 10;
    shadow.CANBTC.bit.SAM = 1;
    regs->CANBTC.all = shadow.CANBTC.all;
    shadow.CANMC.all = regs->CANMC.all;
    shadow.CANMC.bit.CCR = 0;
    regs->CANMC.all = shadow.CANMC.all;
    do {
        shadow.CANES.all = regs->CANES.all;
    } while (shadow.CANES.bit.CCE != 0);
    regs->CANME.all = 0;
    EDIS;
}

__attribute__((weak)) void InitECana(void)
{
    init_ecan(&ECanaRegs, &ECanaMboxes);
}

__attribute__((weak)) void InitECanb(void)
{
    init_ecan(&ECanbRegs, &ECanbMboxes);
}

__attribute__((weak)) void InitECan(void)
{
    InitECana();
    InitECanb();
}

__attribute__((weak)) void InitECanaGpio(void)
{
    EALLOW;
    GpioCtrlRegs.GPAPUD.bit.GPIO30 = 0;     /* CANRXA pull-up on */
    GpioCtrlRegs.GPAPUD.bit.GPIO31 = 0;     /* CANTXA */
    GpioCtrlRegs.GPAQSEL2.bit.GPIO30 = 3;   /* asynchronous input */
    GpioCtrlRegs.GPAMUX2.bit.GPIO30 = 1;    /* CANRXA */
    GpioCtrlRegs.GPAMUX2.bit.GPIO31 = 1;    /* CANTXA */
    EDIS;
}

__attribute__((weak)) void InitECanGpio(void)
{
    InitECanaGpio();
}
