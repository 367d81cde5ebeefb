/* Host replacement of TI's DSP2833x_Xintf.c (see firmware_c/ti/README.md), our own code: InitXintf sets
   the external interface's clocks (XINTCNF2: XTIMCLK = SYSCLKOUT/2, CLKMODE /2, write buffer 3) and the
   zone timings of zones 0, 6 and 7 (lead 3, active 7, trail 3 XTIMCLK cycles, 16-bit, XREADY ignored),
   then the bank switching, under EALLOW. XINTF is not modelled (rust/core/src/dsp/unmodelled.rs): no
   external memory is reached. */
#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"

static void zone_timing(volatile union XTIMING_REG *x)
{
    x->bit.X2TIMING = 0;
    x->bit.XWRLEAD = 3;
    x->bit.XWRACTIVE = 7;
    x->bit.XWRTRAIL = 3;
    x->bit.XRDLEAD = 3;
    x->bit.XRDACTIVE = 7;
    x->bit.XRDTRAIL = 3;
    x->bit.USEREADY = 0;
    x->bit.XSIZE = 3;
}

__attribute__((weak)) void InitXintf(void)
{
    EALLOW;
    XintfRegs.XINTCNF2.bit.XTIMCLK = 1;
    XintfRegs.XINTCNF2.bit.WRBUFF = 3;
    XintfRegs.XINTCNF2.bit.CLKOFF = 0;
    XintfRegs.XINTCNF2.bit.CLKMODE = 1;
    zone_timing(&XintfRegs.XTIMING0);
    zone_timing(&XintfRegs.XTIMING6);
    zone_timing(&XintfRegs.XTIMING7);
    XintfRegs.XBANK.bit.BANK = 7;
    XintfRegs.XBANK.bit.BCYC = 7;
    EDIS;
}
