/* Replacement for TI's DSP2833x_GlobalPrototypes.h: the support functions of TI's DSP2833x_common
   sources (a project's own copies of TI's sources, or the host replacements of firmware_c/ti, which are
   linked into every firmware and give way to a project's own definitions), the functions of TI's
   assembly files that the runtime provides, and the flash-to-RAM copy's linker symbols. */
#ifndef DSP2833x_GLOBALPROTOTYPES_H
#define DSP2833x_GLOBALPROTOTYPES_H

#ifdef __cplusplus
extern "C" {
#endif

/* DSP2833x_SysCtrl.c */
void InitSysCtrl(void);
void InitPll(Uint16 pllcr, Uint16 clkindiv);
void InitPeripheralClocks(void);
void DisableDog(void);
void ServiceDog(void);
void InitFlash(void);
Uint16 CsmUnlock(void);

/* DSP2833x_Gpio.c, DSP2833x_Spi.c (TI's InitSpi, an empty placeholder, is left out: firmware often
   defines its own, static) */
void InitGpio(void);
void InitSpiGpio(void);
void InitSpiaGpio(void);

/* DSP2833x_Adc.c, DSP2833x_EPwm.c, DSP2833x_ECap.c, DSP2833x_ECan.c, DSP2833x_DMA.c, DSP2833x_Xintf.c:
   the peripherals not modelled (their registers hold what is written; each first use is reported) */
void InitAdc(void);
void InitEPwm(void);
void InitEPwmGpio(void);
void InitEPwm1Gpio(void);
void InitEPwm2Gpio(void);
void InitEPwm3Gpio(void);
void InitEPwm4Gpio(void);
void InitEPwm5Gpio(void);
void InitEPwm6Gpio(void);
void InitECap(void);
void InitECan(void);
void InitECana(void);
void InitECanb(void);
void InitECanGpio(void);
void InitECanaGpio(void);
void DMAInitialize(void);
void InitXintf(void);

/* DSP2833x_McBSP.c */
void InitMcbsp(void);
void InitMcbspa(void);
void InitMcbspb(void);
void InitMcbspGpio(void);
void InitMcbspaGpio(void);
void InitMcbspbGpio(void);
void InitMcbspa8bit(void);
void InitMcbspa12bit(void);
void InitMcbspa16bit(void);
void InitMcbspa20bit(void);
void InitMcbspa24bit(void);
void InitMcbspa32bit(void);
void InitMcbspb8bit(void);
void InitMcbspb12bit(void);
void InitMcbspb16bit(void);
void InitMcbspb20bit(void);
void InitMcbspb24bit(void);
void InitMcbspb32bit(void);
void delay_loop(void);
void clkg_delay_loop(void);
/* DSP2833x_Sci.c */
void InitI2CGpio(void);
void InitSci(void);
void InitSciGpio(void);
void InitSciaGpio(void);
void InitScibGpio(void);
void InitScicGpio(void);

/* DSP2833x_PieCtrl.c, DSP2833x_PieVect.c */
void InitPieCtrl(void);
void EnableInterrupts(void);
void InitPieVectTable(void);

/* DSP2833x_MemCopy.c */
void MemCopy(Uint16 *SourceAddr, Uint16 *SourceEndAddr, Uint16 *DestAddr);

/* TI's assembly files, provided by the runtime: DSP2833x_usDelay.asm, DSP2833x_ADC_cal.asm,
   DSP2833x_DBGIER.asm. */
void DSP28x_usDelay(Uint32 Count);
void ADC_cal(void);
void SetDBGIER(Uint16 dbgier);

/* The linker command file's symbols of the RAM functions' copy (the build provides them: the load
   image of section ramfuncs and its place in RAM; RamfuncsLoadSize's address is its size, in bytes
   on the host, whose memcpy counts bytes where the C28x's counts 16-bit words). */
extern Uint16 RamfuncsLoadStart;
extern Uint16 RamfuncsLoadEnd;
extern Uint16 RamfuncsRunStart;
extern Uint16 RamfuncsLoadSize;

#ifdef __cplusplus
}
#endif

#endif
