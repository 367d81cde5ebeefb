/* sins-fw 16-bit int check (`sins-fw build-firmware --diagnose-int`), force-included after the prelude
   in a syntax-only shadow compile: on the C28x `int` is 16 bits wide. Mapping the firmware's `int` to
   the host's 16-bit `short` lets the compiler's conversion warnings (-Wconversion, -Woverflow) flag
   what loses bits there: `int x = 40000;`, `int n = some_long;`, a Uint32 register value into an int.
   Not caught: a product of two ints that overflows 16 bits before it is widened (`long p = a * b;`),
   since the host promotes both to its 32-bit int first; `long` stays the host's 64 bits (32 on the
   C28x); `char` and sizeof counting 16-bit words (docs/c-arithmetic.md).

   The standard and replacement headers are read here first, with the host's int, and their include
   guards keep the firmware's own #includes from reading them again. */
#ifndef SINS_FW_INT16_H
#define SINS_FW_INT16_H

#include <assert.h>
#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"
#include "IQmathLib.h"

/* `unsigned int` and `signed int` stay valid; `long int` and `short int` do not (write `long`). */
#define int short

#endif
