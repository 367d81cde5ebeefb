/* Replacement for TI's DSP2833x_Examples.h: CPU_RATE and DELAY_US, which lets virtual time pass. */
#ifndef DSP2833x_EXAMPLES_H
#define DSP2833x_EXAMPLES_H

#include "DSP2833x_Device.h"

#define CPU_RATE 6.667L /* ns per SYSCLKOUT cycle at 150 MHz */
#define DELAY_US(A) sins_fw_delay_us(static_cast<double>(A))

#endif
