/* Replacement for TI's DSP2833x_Examples.h: CPU_RATE and DELAY_US, which lets virtual time pass, and
   the prototypes of TI's support functions and default ISRs (firmware_c/ti replaces their sources). */
#ifndef DSP2833x_EXAMPLES_H
#define DSP2833x_EXAMPLES_H

#include "DSP2833x_Device.h"
#include "DSP2833x_DefaultIsr.h"
#include "DSP2833x_GlobalPrototypes.h"

#define CPU_RATE 6.667L /* ns per SYSCLKOUT cycle at 150 MHz */
#define DELAY_US(A) sins_fw_delay_us(static_cast<double>(A))

#endif
