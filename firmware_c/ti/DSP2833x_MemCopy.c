/* Host replacement of TI's DSP2833x_MemCopy.c (see firmware_c/ti/README.md): MemCopy copies 16-bit
   words from SourceAddr up to (not including) SourceEndAddr to DestAddr, the flash-to-RAM copy of
   the ramfuncs section (the build provides RamfuncsLoadStart/LoadEnd/RunStart). */
#include "DSP2833x_Device.h"
#include "DSP2833x_GlobalPrototypes.h"

__attribute__((weak)) void MemCopy(Uint16 *SourceAddr, Uint16 *SourceEndAddr, Uint16 *DestAddr)
{
    while (SourceAddr < SourceEndAddr) {
        *DestAddr++ = *SourceAddr++;
    }
}
