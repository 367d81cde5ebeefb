/* Host replacement of TI's DSP2833x_SysCtrl.c (see firmware_c/ti/README.md), our own code in TI's
   idioms. The board models the system control registers (rust/core/src/dsp/sysctrl.rs): the PLL
   (PLLCR, PLLSTS.DIVSEL; a new PLLCR relocks, PLLLOCKS clear meanwhile), the clock prescalers and
   enables, the watchdog (WDCR, WDKEY, SCSR), and holds the flash wait-state registers. So these
   functions do on the emulated board what TI's do on the chip:
   - DisableDog: WDCR = 0x0068 (WDDIS, WDCHK = 101); ServiceDog: WDKEY = 0x55 then 0xAA.
   - InitPll: the sequence SPRUFB0 asks for: stop if the oscillator failed (MCLKSTS), DIVSEL to /4
     before PLLCR changes, MCLKOFF while it relocks, wait for PLLLOCKS, then the divider asked for.
   - InitPeripheralClocks: HISPCP = 1, LOSPCP = 2, every peripheral clock on (TBCLKSYNC last).
   - InitFlash: the wait states for 150 MHz and the pipeline, from RAM (section ramfuncs: call it
     only after the RAM functions' copy, as on the chip). */
#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"
#include "DSP2833x_DefaultIsr.h"
#include "DSP2833x_GlobalPrototypes.h"

/* A project's own DSP2833x_Examples.h may lack TI's PLL macros: the profile's clocks then. */
#ifndef DSP28_PLLCR
#define DSP28_PLLCR SINS_FW_PLLCR
#endif
#ifndef DSP28_DIVSEL
#define DSP28_DIVSEL SINS_FW_DIVSEL
#endif

#pragma CODE_SECTION(InitFlash, "ramfuncs");

__attribute__((weak)) void DisableDog(void)
{
    EALLOW;
    SysCtrlRegs.WDCR = 0x0068;
    EDIS;
}

__attribute__((weak)) void ServiceDog(void)
{
    EALLOW;
    SysCtrlRegs.WDKEY = 0x0055;
    SysCtrlRegs.WDKEY = 0x00AA;
    EDIS;
}

__attribute__((weak)) void InitPll(Uint16 val, Uint16 divsel)
{
    /* A missing oscillator leaves the PLL in limp mode: TI stops the CPU here. */
    if (SysCtrlRegs.PLLSTS.bit.MCLKSTS != 0) {
        asm("        ESTOP0");
    }
    /* DIVSEL must be /4 while PLLCR changes. */
    if (SysCtrlRegs.PLLSTS.bit.DIVSEL != 0) {
        EALLOW;
        SysCtrlRegs.PLLSTS.bit.DIVSEL = 0;
        EDIS;
    }
    if (SysCtrlRegs.PLLCR.bit.DIV != val) {
        EALLOW;
        SysCtrlRegs.PLLSTS.bit.MCLKOFF = 1;
        SysCtrlRegs.PLLCR.bit.DIV = val;
        EDIS;
        DisableDog();
        while (SysCtrlRegs.PLLSTS.bit.PLLLOCKS != 1) {
        }
        EALLOW;
        SysCtrlRegs.PLLSTS.bit.MCLKOFF = 0;
        EDIS;
    }
    if (divsel == 1 || divsel == 2) {
        EALLOW;
        SysCtrlRegs.PLLSTS.bit.DIVSEL = divsel;
        EDIS;
    }
    if (divsel == 3) {
        EALLOW;
        SysCtrlRegs.PLLSTS.bit.DIVSEL = 2;
        DELAY_US(50L);
        SysCtrlRegs.PLLSTS.bit.DIVSEL = 3;
        EDIS;
    }
}

__attribute__((weak)) void InitFlash(void)
{
    EALLOW;
    FlashRegs.FOPT.bit.ENPIPE = 1;
    /* Wait states for 150 MHz SYSCLKOUT (TI's values). */
    FlashRegs.FBANKWAIT.bit.PAGEWAIT = 5;
    FlashRegs.FBANKWAIT.bit.RANDWAIT = 5;
    FlashRegs.FOTPWAIT.bit.OTPWAIT = 8;
    FlashRegs.FSTDBYWAIT.bit.STDBYWAIT = 0x01FF;
    FlashRegs.FACTIVEWAIT.bit.ACTIVEWAIT = 0x01FF;
    EDIS;
    /* Let the pipeline take the new wait states. */
    asm(" RPT #7 || NOP");
}

__attribute__((weak)) void InitPeripheralClocks(void)
{
    EALLOW;
    SysCtrlRegs.HISPCP.all = 0x0001;
    SysCtrlRegs.LOSPCP.all = 0x0002;
    SysCtrlRegs.PCLKCR0.bit.ADCENCLK = 1;
    SysCtrlRegs.PCLKCR0.bit.I2CAENCLK = 1;
    SysCtrlRegs.PCLKCR0.bit.SCIAENCLK = 1;
    SysCtrlRegs.PCLKCR0.bit.SCIBENCLK = 1;
    SysCtrlRegs.PCLKCR0.bit.SCICENCLK = 1;
    SysCtrlRegs.PCLKCR0.bit.SPIAENCLK = 1;
    SysCtrlRegs.PCLKCR0.bit.MCBSPAENCLK = 1;
    SysCtrlRegs.PCLKCR0.bit.MCBSPBENCLK = 1;
    SysCtrlRegs.PCLKCR0.bit.ECANAENCLK = 1;
    SysCtrlRegs.PCLKCR0.bit.ECANBENCLK = 1;
    SysCtrlRegs.PCLKCR1.all = 0xFF3F; /* ePWM1-6, eCAP1-6, eQEP1-2 */
    SysCtrlRegs.PCLKCR3.bit.CPUTIMER0ENCLK = 1;
    SysCtrlRegs.PCLKCR3.bit.CPUTIMER1ENCLK = 1;
    SysCtrlRegs.PCLKCR3.bit.CPUTIMER2ENCLK = 1;
    SysCtrlRegs.PCLKCR3.bit.DMAENCLK = 1;
    SysCtrlRegs.PCLKCR3.bit.XINTFENCLK = 1;
    SysCtrlRegs.PCLKCR3.bit.GPIOINENCLK = 1;
    SysCtrlRegs.PCLKCR0.bit.TBCLKSYNC = 1;
    EDIS;
}

__attribute__((weak)) void InitSysCtrl(void)
{
    DisableDog();
    InitPll(DSP28_PLLCR, DSP28_DIVSEL);
    InitPeripheralClocks();
}
