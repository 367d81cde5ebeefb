/* Replacement for TI's DSP2833x_Examples.h: TI's clock settings as the build's profile sets them
   (`sins-fw build-firmware --profile`: the build defines SINS_FW_PLLCR, SINS_FW_DIVSEL and
   SINS_FW_SYSCLK_HZ from its [clocks]), so that TI's `#if (CPU_FRQ_150MHZ)` guards compile in as on a
   150 MHz board; CPU_RATE; DELAY_US, which lets virtual time pass; the prototypes of TI's support
   functions and default ISRs. A project with TI's own DSP2833x_Examples.h on its path gets TI's
   definitions (its DELAY_US calls DSP28x_usDelay, which the runtime provides). */
#ifndef DSP2833x_EXAMPLES_H
#define DSP2833x_EXAMPLES_H

#include "DSP2833x_Device.h"
#include "DSP2833x_DefaultIsr.h"
#include "DSP2833x_GlobalPrototypes.h"
#include "DSP2833x_I2c_defines.h"

#ifndef SINS_FW_PLLCR
#define SINS_FW_PLLCR 10
#endif
#ifndef SINS_FW_DIVSEL
#define SINS_FW_DIVSEL 2
#endif
#ifndef SINS_FW_SYSCLK_HZ
#define SINS_FW_SYSCLK_HZ 150000000
#endif

#ifndef DSP28_DIVSEL
#define DSP28_DIVSEL SINS_FW_DIVSEL
#endif
#ifndef DSP28_PLLCR
#define DSP28_PLLCR SINS_FW_PLLCR
#endif

#define PARTNO_28335 0xEF
#define PARTNO_28334 0xEE
#define PARTNO_28332 0xED

#ifndef CPU_FRQ_150MHZ
#define CPU_FRQ_150MHZ (SINS_FW_SYSCLK_HZ == 150000000)
#endif
#ifndef CPU_FRQ_100MHZ
#define CPU_FRQ_100MHZ (SINS_FW_SYSCLK_HZ == 100000000)
#endif

/* ns per SYSCLKOUT cycle (TI: 6.667L at 150 MHz, 10.000L at 100 MHz). */
#define CPU_RATE (1.0e9L / SINS_FW_SYSCLK_HZ)

#define DELAY_US(A) sins_fw_delay_us((double)(A))

#endif
