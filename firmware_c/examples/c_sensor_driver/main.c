/* The imu164 driver on the F28335 (the reference board's ADIS16407 on SPI-A, chip select GPIO57):
   set up as TI's examples set up a board, probe the part, then sample it every millisecond. */
#include "DSP28x_Project.h"
#include "imu164.h"

extern const struct imu164_bus f28335_imu_bus;

Uint16 product;
Uint16 probed;
Uint16 samples;
int16 gyro_z;
int16 accel_z;
Uint16 supply;
Uint16 *raw_base;

static int started(void)
{
    return 1;
}
/* A hook of another return type, as older C code assigns them (a warning in C, an error in C++). */
void (*start_hook)(void) = started;

static void spi_init(void)
{
    SpiaRegs.SPICCR.all = 0x004F;  /* in reset, CLKPOLARITY = 1, 16-bit characters */
    SpiaRegs.SPICTL.all = 0x0006;  /* master, TALK, CLK_PHASE = 0: mode 3 */
    SpiaRegs.SPIBRR = 49;          /* 0.75 MHz at LSPCLK 37.5 MHz */
    SpiaRegs.SPICCR.all = 0x00CF;  /* out of reset */
    SpiaRegs.SPIPRI.bit.FREE = 1;
}

void main(void)
{
    imu164_t *imu;
    InitSysCtrl();
    DINT;
    InitPieCtrl();
    IER = 0x0000;
    IFR = 0x0000;
    InitPieVectTable();
    GpioDataRegs.GPBSET.bit.GPIO57 = 1;
    spi_init();
    raw_base = (Uint16 *)0x7040; /* an integer made a pointer: SPI-A's frame */
    DELAY_US(10000);             /* the part's start-up */
    start_hook();
    imu = imu164_open(&f28335_imu_bus, &(struct imu164_config){.stall_us = 20});
    probed = imu164_probe(imu, 0x4017) == 0;
    product = imu->product;
    for (;;) {
        struct imu164_sample s = imu164_sample(imu);
        gyro_z = s.gyro[2];
        accel_z = s.accel[2];
        supply = s.supply;
        samples++;
        DELAY_US(1000);
    }
}
