/* The host side of hal.h: which emulated board it drives. */
#ifndef HOST_HAL_H
#define HOST_HAL_H

#include "sins_fw.h"

/* Route hal.h's calls to board `b`. */
void host_hal_use(SinsBoard *b);
/* Exit with status 2 and the emulator's message when `status` is not SINS_OK. */
void host_check(SinsStatus status, const char *what);

#endif
