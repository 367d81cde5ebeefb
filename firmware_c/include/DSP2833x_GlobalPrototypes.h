/* Replacement for TI's DSP2833x_GlobalPrototypes.h: the support functions of TI's DSP2833x_common
   sources, as far as the host build provides them (firmware_c/ti: the host replacements of those
   sources, linked into every firmware; a firmware's own definition of one of these functions takes
   its place). */
#ifndef DSP2833x_GLOBALPROTOTYPES_H
#define DSP2833x_GLOBALPROTOTYPES_H

#include "DSP2833x_CpuTimers.h"

/* DSP2833x_SysCtrl.c */
void InitSysCtrl(void);
void InitPll(Uint16 pllcr, Uint16 clkindiv);
void InitPeripheralClocks(void);
void DisableDog(void);
void ServiceDog(void);
void InitFlash(void);

/* DSP2833x_PieCtrl.c, DSP2833x_PieVect.c */
void InitPieCtrl(void);
void EnableInterrupts(void);
void InitPieVectTable(void);

/* DSP2833x_CpuTimers.c */
void InitCpuTimers(void);
void ConfigCpuTimer(struct CPUTIMER_VARS *Timer, float Freq, float Period);

/* DSP2833x_Spi.c (TI's empty InitSpi is left out: firmware sets SPI-A up itself) */
void InitSpiGpio(void);
void InitSpiaGpio(void);

#endif
