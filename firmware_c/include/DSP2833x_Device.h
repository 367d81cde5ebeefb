/* Replacement for TI's DSP2833x_Device.h in a host build of F28335 firmware (sins-fw build-firmware):
   the same type names and register-file objects, the registers reached through the emulated board.
   Only the peripherals the emulator models are declared (SPI-A, GPIO data, LOSPCP, CPU timer 0, the PIE); using another is a compile error naming it. */
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

/* The CPU's interrupt enable and flag registers (TI: `extern cregister volatile unsigned int IER;`). */
#include "sins_fw_reg.hpp"
extern volatile SinsCReg<0> IER;
extern volatile SinsCReg<1> IFR;

#define M_INT1 0x0001
#define M_INT2 0x0002
#define M_INT3 0x0004
#define M_INT4 0x0008
#define M_INT5 0x0010
#define M_INT6 0x0020
#define M_INT7 0x0040
#define M_INT8 0x0080
#define M_INT9 0x0100
#define M_INT10 0x0200
#define M_INT11 0x0400
#define M_INT12 0x0800
#define M_INT13 0x1000
#define M_INT14 0x2000
#define M_DLOG 0x4000
#define M_RTOS 0x8000

#define BIT0 0x0001
#define BIT1 0x0002
#define BIT2 0x0004
#define BIT3 0x0008
#define BIT4 0x0010
#define BIT5 0x0020
#define BIT6 0x0040
#define BIT7 0x0080
#define BIT8 0x0100
#define BIT9 0x0200
#define BIT10 0x0400
#define BIT11 0x0800
#define BIT12 0x1000
#define BIT13 0x2000
#define BIT14 0x4000
#define BIT15 0x8000

#include "DSP2833x_CpuTimers.h"
#include "DSP2833x_Gpio.h"
#include "DSP2833x_PieCtrl.h"
#include "DSP2833x_PieVect.h"
#include "DSP2833x_Spi.h"
#include "DSP2833x_SysCtrl.h"

#endif
