/* Replacement for TI's DSP2833x_Device.h in a host build of F28335 firmware (sins-fw build-firmware):
   TI's type names, intrinsics and register-file objects with TI's layouts. The objects are placed by the
   link in the runtime's image of the C28x data space at their addresses (those of TI's
   DSP2833x_Headers_nonBIOS.cmd); the accesses of the modelled peripherals reach the emulated board, the
   others are plain memory with reset values (docs/c-drivers.md). A project that has TI's own headers on
   its include path uses them instead, with the same behaviour. */
#ifndef DSP2833x_DEVICE_H
#define DSP2833x_DEVICE_H

#include "sins_fw_prelude.h"

#define TARGET 1
#define DSP28_28335 TARGET
#define DSP28_28334 0
#define DSP28_28332 0

#ifdef __cplusplus
extern "C" {
#endif

/* The CPU's interrupt enable and flag registers (TI: `extern cregister volatile unsigned int IER;`). */
extern cregister volatile unsigned int IFR;
extern cregister volatile unsigned int IER;

#ifdef __cplusplus
}
#endif

#define EINT asm(" clrc INTM")
#define DINT asm(" setc INTM")
#define ERTM asm(" clrc DBGM")
#define DRTM asm(" setc DBGM")
#define EALLOW asm(" EALLOW")
#define EDIS asm(" EDIS")
#define ESTOP0 asm(" ESTOP0")

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

#include "DSP2833x_Adc.h"
#include "DSP2833x_CpuTimers.h"
#include "DSP2833x_DMA.h"
#include "DSP2833x_ECan.h"
#include "DSP2833x_ECap.h"
#include "DSP2833x_EPwm.h"
#include "DSP2833x_Gpio.h"
#include "DSP2833x_I2c.h"
#include "DSP2833x_McBSP.h"
#include "DSP2833x_PieCtrl.h"
#include "DSP2833x_PieVect.h"
#include "DSP2833x_Sci.h"
#include "DSP2833x_Spi.h"
#include "DSP2833x_SysCtrl.h"
#include "DSP2833x_Xintf.h"

#endif
