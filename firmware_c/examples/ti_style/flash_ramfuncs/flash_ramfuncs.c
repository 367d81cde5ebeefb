/* A flash build's start-up: the functions of section ramfuncs (TI's InitFlash among them, and our
   own timer ISR here) are copied from their load address in flash to RAM before any of them runs,
   then InitFlash sets the flash wait states. Written in the style of TI's 2833x flash example. */
#include "DSP28x_Project.h"

#pragma CODE_SECTION(cpu_timer0_isr, "ramfuncs");
interrupt void cpu_timer0_isr(void);

Uint16 ticks;      /* timer interrupts taken */
Uint16 bankwait;   /* FBANKWAIT after InitFlash */

void main(void)
{
    InitSysCtrl();

    DINT;
    InitPieCtrl();
    IER = 0x0000;
    IFR = 0x0000;
    InitPieVectTable();

    EALLOW;
    PieVectTable.TINT0 = &cpu_timer0_isr;
    EDIS;

    /* Copy the time-critical code and the flash set-up to RAM, then set up the flash from RAM. */
#ifndef INIT_FLASH_FIRST
    MemCopy(&RamfuncsLoadStart, &RamfuncsLoadEnd, &RamfuncsRunStart);
#endif
    InitFlash();
    bankwait = FlashRegs.FBANKWAIT.all;

    InitCpuTimers();
    ConfigCpuTimer(&CpuTimer0, 150, 1000);
    CpuTimer0Regs.TCR.all = 0x4001;
    IER |= M_INT1;
    PieCtrlRegs.PIEIER1.bit.INTx7 = 1;
    EINT;
    ERTM;

    for (;;) {
    }
}

interrupt void cpu_timer0_isr(void)
{
    ticks++;
    PieCtrlRegs.PIEACK.all = PIEACK_GROUP1;
}
