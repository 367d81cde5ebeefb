/* sins-fw prelude, force-included (-include) before every source of a host-built F28335 firmware, C or
   C++: the keywords, intrinsics and types of TI's C2000 compiler that the host compiler does not know.
   Register accesses need nothing here: the build's compiler pass turns every volatile access, and every
   access to a register-file object, into a call to the emulated board (firmware_c/pass). */
#ifndef SINS_FW_PRELUDE_H
#define SINS_FW_PRELUDE_H

/* The standard headers first, with the host's own keywords: their include guards keep the firmware's
   later #includes from reading them again after the macros below. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef __cplusplus
extern "C" {
#endif
/* The runtime (firmware_c/runtime/sins_fw_runtime.cpp). */
void sins_fw_asm(const char *text);
void sins_fw_delay_us(double microseconds);
void DSP28x_usDelay(uint32_t Count);
#ifdef __cplusplus
}
#endif

/* TI's compiler keywords: an ISR is an ordinary function on the host (the runtime calls it and charges
   the interrupt entry and exit of c28x-costs.toml [interrupt]); `cregister` (IER, IFR) is dropped, the
   link places IER and IFR where the runtime reaches the emulated CPU's; `far` (the large memory model)
   means nothing on the host. TI's `#pragma CODE_SECTION/DATA_SECTION/INTERRUPT` are ignored (the build
   passes -Wno-unknown-pragmas). */
#define interrupt
#define __interrupt
#define cregister
#define far
#define __far

/* Inline assembly: the instructions TI's headers and typical firmware use are emulated (EALLOW, EDIS,
   clrc/setc INTM = EINT/DINT, clrc/setc DBGM, NOP, ESTOP0, IDLE); any other stops the run with an
   error quoting it. Nothing reaches the host's assembler. */
#define asm(text) sins_fw_asm(text)
#define __asm(text) sins_fw_asm(text)

/* TI's integer and float types with their C28x widths where the host has them (Uint16 is 16-bit, as
   `unsigned int` is on the C28x). TI's headers define them under the same guard, so theirs and ours
   agree. float64 is the host double (TI's COFF ABI makes it a 32-bit float: see --float c28x). */
#ifndef DSP28_DATA_TYPES
#define DSP28_DATA_TYPES
typedef int16_t int16;
typedef int32_t int32;
typedef int64_t int64;
typedef uint16_t Uint16;
typedef uint32_t Uint32;
typedef uint64_t Uint64;
typedef float float32;
typedef double float64;
#endif

/* TI's main may be `void main(void)`: the firmware's main is renamed and the runtime calls it. */
#define main sins_fw_user_main

#endif
