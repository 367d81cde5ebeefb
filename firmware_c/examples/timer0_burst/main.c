/* A user firmware written as for the real board against TI's DSP2833x headers, built unmodified by
   `sins-fw build-firmware` and run by `sins-fw run TRACE --firmware fw.so`: the set-up of TI's
   examples (InitSysCtrl, InitPieCtrl, the PIE vector, InitCpuTimers, ConfigCpuTimer: TI's support
   functions, from their host replacements in firmware_c/ti), CPU timer 0 at the reference period
   (4 ms), and an ISR that reads the ADIS16407's burst over SPI-A with GPIO57 as the chip select and
   stores the decoded rates in globals (globals.toml names them for the run's output). main then idles in `for (;;) {}`, as TI's examples do. */
#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"

#define BURST_WORDS 15 /* the command frame and SUPPLY_OUT … AUX_ADC */
#define GYRO_LSB_DPS 0.05

interrupt void cpu_timer0_isr(void);

Uint16 burst[BURST_WORDS];
Uint16 xgyro_word, ygyro_word, zgyro_word;
float64 rate_x, rate_y, rate_z; /* °/s */
Uint32 isr_count;

/* The reference design's InitSpi: mode 3, 16-bit, 0.75 MHz at LSPCLK 37.5 MHz. */
static void InitSpi(void) {
    SpiaRegs.SPICCR.all = 0x004F;
    SpiaRegs.SPICTL.all = 0x0006;
    SpiaRegs.SPIBRR = 49;
    SpiaRegs.SPICCR.all = 0x00CF;
    SpiaRegs.SPIPRI.all = 0x0020;
}

static Uint16 spi_xmit(Uint16 a) {
    while (SpiaRegs.SPISTS.bit.BUFFULL_FLAG == 1) {
    }
    SpiaRegs.SPITXBUF = a;
    while (SpiaRegs.SPISTS.bit.INT_FLAG != 1) {
    }
    return SpiaRegs.SPIRXBUF;
}

/* A gyro word: 14-bit two's complement. */
static float64 gyro_dps(Uint16 word) {
    int16 code = (int16)(word << 2) >> 2;
    return code * GYRO_LSB_DPS;
}

void main(void) {
    InitSysCtrl();
    DINT;
    InitPieCtrl();
    IER = 0x0000;
    IFR = 0x0000;
    EALLOW;
    PieVectTable.TINT0 = &cpu_timer0_isr;
    EDIS;
    PieCtrlRegs.PIECTRL.bit.ENPIE = 1;

    GpioDataRegs.GPBSET.bit.GPIO57 = 1; /* CS high */
    InitSpi();

    InitCpuTimers();
    ConfigCpuTimer(&CpuTimer0, 150, 4000);
    CpuTimer0Regs.TCR.all = 0x4001; /* TSS = 0: start, TIE = 1 */

    IER |= M_INT1;
    PieCtrlRegs.PIEIER1.bit.INTx7 = 1;
    EINT;
    ERTM;
    for (;;) {
    }
}

interrupt void cpu_timer0_isr(void) {
    Uint16 i;
    CpuTimer0.InterruptCount++;
    GpioDataRegs.GPBCLEAR.bit.GPIO57 = 1;
    for (i = 0; i < BURST_WORDS; i++) {
        if (i > 0) {
            DELAY_US(0.5); /* inside a burst the ADIS16407 wants one SCLK period (1.33 µs) between frames */
        }
        burst[i] = spi_xmit(i == 0 ? 0x4200 : 0x0000);
    }
    GpioDataRegs.GPBSET.bit.GPIO57 = 1;
    xgyro_word = burst[2];
    ygyro_word = burst[3];
    zgyro_word = burst[4];
    rate_x = gyro_dps(xgyro_word);
    rate_y = gyro_dps(ygyro_word);
    rate_z = gyro_dps(zgyro_word);
    isr_count = CpuTimer0.InterruptCount;
    PieCtrlRegs.PIEACK.all = PIEACK_GROUP1;
}
