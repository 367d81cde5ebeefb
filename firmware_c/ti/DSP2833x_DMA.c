/* Host replacement of TI's DSP2833x_DMA.c (see firmware_c/ti/README.md), our own code: DMAInitialize
   resets the DMA (DMACTRL.HARDRESET) and lets it run free at a breakpoint (DEBUGCTRL.FREE), under EALLOW.
   The DMA is not modelled (rust/core/src/dsp/unmodelled.rs): nothing is moved. */
#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"

__attribute__((weak)) void DMAInitialize(void)
{
    EALLOW;
    DmaRegs.DMACTRL.bit.HARDRESET = 1;
    DmaRegs.DEBUGCTRL.bit.FREE = 1;
    EDIS;
}
