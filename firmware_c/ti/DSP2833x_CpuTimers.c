/* Host replacement of TI's DSP2833x_CpuTimers.c (see firmware_c/ti/README.md). CPU timer 0 is
   modelled; timers 1 and 2 are plain memory for now (issue 39), set up here as TI's sets them up.

   ConfigCpuTimer follows C2000Ware's rule, PRD = MHz * us - 1: the counter runs PRD + 1 counts a
   period, so ConfigCpuTimer(&CpuTimer0, 150, 4000) gives 4 ms exactly, the period the emulator's
   firmware model realises for `timer.period_us` (firmware_model/SCHEMA.md). TI's older header-file
   releases (V1.x) write PRD = MHz * us, one count longer. */
#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"
#include "DSP2833x_DefaultIsr.h"
#include "DSP2833x_GlobalPrototypes.h"

__attribute__((weak)) struct CPUTIMER_VARS CpuTimer0;
__attribute__((weak)) struct CPUTIMER_VARS CpuTimer1;
__attribute__((weak)) struct CPUTIMER_VARS CpuTimer2;

__attribute__((weak)) void InitCpuTimers(void)
{
    CpuTimer0.RegsAddr = &CpuTimer0Regs;
    CpuTimer0Regs.PRD.all = 0xFFFFFFFF;
    CpuTimer0Regs.TPR.all = 0;
    CpuTimer0Regs.TPRH.all = 0;
    CpuTimer0Regs.TCR.bit.TSS = 1;  /* stopped */
    CpuTimer0Regs.TCR.bit.TRB = 1;  /* reload TIM from PRD */
    CpuTimer0.InterruptCount = 0;
    CpuTimer1.RegsAddr = &CpuTimer1Regs;
    CpuTimer2.RegsAddr = &CpuTimer2Regs;
    CpuTimer1Regs.PRD.all = 0xFFFFFFFF;
    CpuTimer2Regs.PRD.all = 0xFFFFFFFF;
    CpuTimer1Regs.TCR.bit.TSS = 1;
    CpuTimer2Regs.TCR.bit.TSS = 1;
    CpuTimer1Regs.TCR.bit.TRB = 1;
    CpuTimer2Regs.TCR.bit.TRB = 1;
    CpuTimer1.InterruptCount = 0;
    CpuTimer2.InterruptCount = 0;
}

__attribute__((weak)) void ConfigCpuTimer(struct CPUTIMER_VARS *Timer, float Freq, float Period)
{
    Uint32 temp;
    Timer->CPUFreqInMHz = Freq;
    Timer->PeriodInUSec = Period;
    temp = (long)(Freq * Period);
    Timer->RegsAddr->PRD.all = temp - 1;
    Timer->RegsAddr->TPR.all = 0;
    Timer->RegsAddr->TPRH.all = 0;
    Timer->RegsAddr->TCR.bit.TSS = 1;   /* stopped: the caller starts it (TSS = 0) */
    Timer->RegsAddr->TCR.bit.TRB = 1;
    Timer->RegsAddr->TCR.bit.SOFT = 0;
    Timer->RegsAddr->TCR.bit.FREE = 0;
    Timer->RegsAddr->TCR.bit.TIE = 1;
    Timer->InterruptCount = 0;
}
