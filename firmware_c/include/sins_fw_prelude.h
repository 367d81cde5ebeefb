/* sins-fw prelude, force-included (g++ -include) before every source of a host-built F28335 firmware:
   TI's C2000 compiler keywords and intrinsics the host compiler does not know. The sources are compiled
   as C++17 so that the replacement headers' register objects can turn each field access into a call to
   the emulated board (sins_fw_reg.hpp). */
#ifndef SINS_FW_PRELUDE_H
#define SINS_FW_PRELUDE_H

#include <stdint.h>

/* Keywords of TI's compiler: an ISR is an ordinary function on the host (the runtime calls it, and
   charges the interrupt entry and exit of c28x-costs.toml [interrupt]); `cregister` (IER, IFR) is
   dropped: the replacement DSP2833x_Device.h declares them as objects reaching the emulated CPU. */
#define interrupt
#define __interrupt
#define cregister

/* Inline assembly: the instructions TI's headers and typical firmware use are emulated (EALLOW, EDIS,
   clrc/setc INTM = EINT/DINT, clrc/setc DBGM, NOP, ESTOP0, IDLE); any other stops the run with an
   error quoting it. */
void sins_fw_asm(const char *text);
#define asm(text) sins_fw_asm(text)

/* The intrinsics of TI's DSP2833x_Device.h, as TI defines them. */
#define EINT asm(" clrc INTM")
#define DINT asm(" setc INTM")
#define ERTM asm(" clrc DBGM")
#define DRTM asm(" setc DBGM")
#define EALLOW asm(" EALLOW")
#define EDIS asm(" EDIS")
#define ESTOP0 asm(" ESTOP0")

/* TI's main may be `void main(void)`, which C++ refuses: the firmware's main is renamed and the
   runtime calls it. */
#define main sins_fw_user_main

#endif
