/* Replacement for TI's DSP2833x_CpuTimers.h: CPU timer 0 at 0x0C00 (TIM, PRD, TCR, TPR, TPRH; field
   names as in TI's header), clocked from SYSCLKOUT. Timers 1 and 2 are not modelled (using one is a
   compile error naming it). TI's CPUTIMER_VARS and its Reload/Start/Stop macros are kept, so
   `CpuTimer0.RegsAddr = &CpuTimer0Regs;` and `ConfigCpuTimer`-style code build unchanged. */
#ifndef DSP2833x_CPU_TIMERS_H
#define DSP2833x_CPU_TIMERS_H

#include "sins_fw_reg.hpp"

#define SINS_TIMER0 0x0C00u

struct TIM_REG {
    SinsReg16<SINS_TIMER0 + 0> LSW;
    SinsReg16<SINS_TIMER0 + 1> MSW;
};
union TIM_GROUP {
    SinsReg32<SINS_TIMER0 + 0> all;
    struct TIM_REG half;
};

struct PRD_REG {
    SinsReg16<SINS_TIMER0 + 2> LSW;
    SinsReg16<SINS_TIMER0 + 3> MSW;
};
union PRD_GROUP {
    SinsReg32<SINS_TIMER0 + 2> all;
    struct PRD_REG half;
};

struct TCR_BITS {
    SinsField<SINS_TIMER0 + 4, 4, 1> TSS;
    SinsField<SINS_TIMER0 + 4, 5, 1> TRB;
    SinsField<SINS_TIMER0 + 4, 10, 1> SOFT;
    SinsField<SINS_TIMER0 + 4, 11, 1> FREE;
    SinsField<SINS_TIMER0 + 4, 14, 1> TIE;
    SinsField<SINS_TIMER0 + 4, 15, 1> TIF;
};
union TCR_REG {
    SinsReg16<SINS_TIMER0 + 4> all;
    struct TCR_BITS bit;
};

struct TPR_BITS {
    SinsField<SINS_TIMER0 + 6, 0, 8> TDDR;
    SinsField<SINS_TIMER0 + 6, 8, 8> PSC;
};
union TPR_REG {
    SinsReg16<SINS_TIMER0 + 6> all;
    struct TPR_BITS bit;
};

struct TPRH_BITS {
    SinsField<SINS_TIMER0 + 7, 0, 8> TDDRH;
    SinsField<SINS_TIMER0 + 7, 8, 8> PSCH;
};
union TPRH_REG {
    SinsReg16<SINS_TIMER0 + 7> all;
    struct TPRH_BITS bit;
};

struct CPUTIMER_REGS {
    union TIM_GROUP TIM;
    union PRD_GROUP PRD;
    union TCR_REG TCR;
    Uint16 rsvd1;
    union TPR_REG TPR;
    union TPRH_REG TPRH;
};

/* TI's software bookkeeping of a timer (plain memory). */
struct CPUTIMER_VARS {
    volatile struct CPUTIMER_REGS *RegsAddr;
    Uint32 InterruptCount;
    float CPUFreqInMHz;
    float PeriodInUSec;
};

extern volatile struct CPUTIMER_REGS CpuTimer0Regs;
/* TI's bookkeeping of the three timers (DSP2833x_CpuTimers.c; timers 1 and 2 have no registers here). */
extern struct CPUTIMER_VARS CpuTimer0;
extern struct CPUTIMER_VARS CpuTimer1;
extern struct CPUTIMER_VARS CpuTimer2;

#define ReloadCpuTimer0() CpuTimer0Regs.TCR.bit.TRB = 1
#define StartCpuTimer0() CpuTimer0Regs.TCR.bit.TSS = 0
#define StopCpuTimer0() CpuTimer0Regs.TCR.bit.TSS = 1
#define ReadCpuTimer0Counter() CpuTimer0Regs.TIM.all
#define ReadCpuTimer0Period() CpuTimer0Regs.PRD.all

#endif
