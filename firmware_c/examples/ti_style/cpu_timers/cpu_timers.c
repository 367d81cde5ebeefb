/* CPU timers 0, 1 and 2, each with its own ISR: timer 0 through PIE group 1 (INT1.7, TINT0), timer 1
   on the CPU's INT13 and timer 2 on INT14 (no PIE, no PIEACK). Periods 1 ms, 2 ms and 5 ms at
   150 MHz, configured with ConfigCpuTimer under TI's frequency guard. Written in the style of TI's
   2833x cpu_timer example. */
#include "DSP28x_Project.h"

interrupt void cpu_timer0_isr(void);
interrupt void cpu_timer1_isr(void);
interrupt void cpu_timer2_isr(void);

Uint32 count0, count1, count2;  /* interrupts taken, per timer */

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
    PieVectTable.XINT13 = &cpu_timer1_isr;
    PieVectTable.TINT2 = &cpu_timer2_isr;
    EDIS;

    InitCpuTimers();
#if (CPU_FRQ_150MHZ)
    ConfigCpuTimer(&CpuTimer0, 150, 1000);
    ConfigCpuTimer(&CpuTimer1, 150, 2000);
    ConfigCpuTimer(&CpuTimer2, 150, 5000);
#endif
#if (CPU_FRQ_100MHZ)
    ConfigCpuTimer(&CpuTimer0, 100, 1000);
    ConfigCpuTimer(&CpuTimer1, 100, 2000);
    ConfigCpuTimer(&CpuTimer2, 100, 5000);
#endif
    /* Start all three with their interrupts enabled (TSS = 0, TIE = 1). */
    CpuTimer0Regs.TCR.all = 0x4001;
    CpuTimer1Regs.TCR.all = 0x4001;
    CpuTimer2Regs.TCR.all = 0x4001;

    IER |= M_INT1;
    IER |= M_INT13;
    IER |= M_INT14;
    PieCtrlRegs.PIEIER1.bit.INTx7 = 1;

    EINT;
    ERTM;

    for (;;) {
    }
}

interrupt void cpu_timer0_isr(void)
{
    CpuTimer0.InterruptCount++;
    count0++;
    PieCtrlRegs.PIEACK.all = PIEACK_GROUP1;
}

interrupt void cpu_timer1_isr(void)
{
    CpuTimer1.InterruptCount++;
    count1++;
}

interrupt void cpu_timer2_isr(void)
{
    CpuTimer2.InterruptCount++;
    count2++;
}
