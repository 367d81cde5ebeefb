/* Replacement for TI's DSP28x_Project.h (DSP2833x_common/include): the device header and the examples'
   header, as TI's project template includes them. */
#ifndef DSP28x_PROJECT_H
#define DSP28x_PROJECT_H

#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"

#endif
