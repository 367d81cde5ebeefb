/* sins-fw prelude, force-included (g++ -include) before every source of a host-built F28335 firmware:
   TI's C2000 compiler keywords and intrinsics the host compiler does not know. The sources are compiled
   as C++17 so that the replacement headers' register objects can turn each field access into a call to
   the emulated board (sins_fw_reg.hpp). */
#ifndef SINS_FW_PRELUDE_H
#define SINS_FW_PRELUDE_H

#include <stdint.h>

/* Keywords of TI's compiler: an ISR is an ordinary function on the host; cregister (IER, IFR) an
   ordinary variable. */
#define interrupt
#define __interrupt
#define cregister

/* Intrinsic instructions: protection (EALLOW/EDIS: not modelled), interrupt masks (EINT/DINT: the
   host build takes no interrupts yet), the real-time debug mode and emulation stop, inline asm. */
#define EALLOW
#define EDIS
#define EINT
#define DINT
#define ERTM
#define DRTM
#define ESTOP0
#define asm(text)

/* TI's main may be `void main(void)`, which C++ refuses: the firmware's main is renamed and the
   runtime calls it. */
#define main sins_fw_user_main

#endif
