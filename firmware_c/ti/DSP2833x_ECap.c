/* Host replacement of TI's DSP2833x_ECap.c (see firmware_c/ti/README.md), our own code: InitECap is an
   empty placeholder, as TI's. The eCAPs are not modelled (rust/core/src/dsp/unmodelled.rs). */
#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"

__attribute__((weak)) void InitECap(void)
{
}
