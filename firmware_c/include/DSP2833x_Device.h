/* Replacement for TI's DSP2833x_Device.h in a host build of F28335 firmware (sins-fw build-firmware):
   the same type names and register-file objects, the registers reached through the emulated board.
   Only the peripherals the emulator models are declared; using another is a compile error naming it. */
#ifndef DSP2833x_DEVICE_H
#define DSP2833x_DEVICE_H

#include "sins_fw_prelude.h"

#define TARGET 1
#define DSP28_28335 TARGET
#define DSP28_28334 0
#define DSP28_28332 0

/* TI's integer and float types with their C28x widths where the host has them (int16 and Uint16 are
   16-bit, as `int` is on the C28x; float64 is the 32-bit double of TI's COFF ABI only in name). */
typedef int16_t int16;
typedef int32_t int32;
typedef int64_t int64;
typedef uint16_t Uint16;
typedef uint32_t Uint32;
typedef uint64_t Uint64;
typedef float float32;
typedef double float64;

#include "DSP2833x_Gpio.h"
#include "DSP2833x_Spi.h"
#include "DSP2833x_SysCtrl.h"

#endif
