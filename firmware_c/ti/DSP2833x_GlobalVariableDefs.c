/* Host replacement of TI's DSP2833x_GlobalVariableDefs.c (see firmware_c/ti/README.md). TI's file
   defines the register-file objects and places them at their addresses with DATA_SECTION pragmas; on
   the host the objects of the modelled peripherals are defined by the runtime
   (firmware_c/runtime/sins_fw_runtime.cpp), each access reaching the emulated board at its address
   through the object's type. Nothing is left to define here. */
#include "DSP2833x_Device.h"
