/* Host replacement of TI's DSP2833x_Adc.c (see firmware_c/ti/README.md), our own code: InitAdc powers
   the ADC up as the ADC reference guide (SPRU812) asks, band gap and reference first, then the analog
   core, each followed by its settling delay. The ADC is not modelled (rust/core/src/dsp/unmodelled.rs):
   its registers hold what is written, its first use is reported once (`unmodelled_peripheral`), and no
   conversion is made. ADC_cal (TI's assembly routine loading the factory trims) is the runtime's. */
#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"

#define ADC_USDELAY 5000L

__attribute__((weak)) void InitAdc(void)
{
    EALLOW;
    SysCtrlRegs.PCLKCR0.bit.ADCENCLK = 1;
    ADC_cal();
    EDIS;
    AdcRegs.ADCTRL3.all = 0x00E0;   /* ADCBGRFDN = 3 (band gap, reference), ADCPWDN = 1 (analog core) */
    DELAY_US(ADC_USDELAY);
}
