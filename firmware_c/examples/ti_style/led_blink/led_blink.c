/* An LED on GPIO34 blinked by the CPU timer 0 interrupt: the timer set up with ConfigCpuTimer under
   TI's CPU frequency guard, its interrupt through PIE group 1 (INT1.7) to an ISR that toggles the pin
   and acknowledges the group. Written in the style of TI's 2833x peripheral examples. */
#include "DSP28x_Project.h"

interrupt void cpu_timer0_isr(void);

Uint16 ticks;  /* timer interrupts taken */
Uint16 led;    /* GPIO34 as read back after each toggle */

void main(void)
{
    InitSysCtrl();

    DINT;
    InitPieCtrl();
    IER = 0x0000;
    IFR = 0x0000;
    InitPieVectTable();

    /* Our ISR in the TINT0 vector (the vector table is EALLOW-protected). */
    EALLOW;
    PieVectTable.TINT0 = &cpu_timer0_isr;
    EDIS;

    InitCpuTimers();
#if (CPU_FRQ_150MHZ)
    /* 150 MHz SYSCLKOUT: a 0.5 s period. */
    ConfigCpuTimer(&CpuTimer0, 150, 500000);
#endif
#if (CPU_FRQ_100MHZ)
    ConfigCpuTimer(&CpuTimer0, 100, 500000);
#endif
    /* Start the timer with its interrupt enabled: TIE = 1, TSS = 0, one write. */
    CpuTimer0Regs.TCR.all = 0x4001;

    /* GPIO34 an output. */
    EALLOW;
    GpioCtrlRegs.GPBMUX1.bit.GPIO34 = 0;
    GpioCtrlRegs.GPBDIR.bit.GPIO34 = 1;
    EDIS;

    /* CPU INT1 (PIE group 1), TINT0 in it (INTx7), then interrupts on. */
    IER |= M_INT1;
    PieCtrlRegs.PIEIER1.bit.INTx7 = 1;
    EINT;
    ERTM;

    for (;;) {
    }
}

interrupt void cpu_timer0_isr(void)
{
    CpuTimer0.InterruptCount++;
    ticks++;
    GpioDataRegs.GPBTOGGLE.bit.GPIO34 = 1;
    led = GpioDataRegs.GPBDAT.bit.GPIO34;
    PieCtrlRegs.PIEACK.all = PIEACK_GROUP1;
}
