/* The board's port of the imu164 driver: the F28335's SPI-A (master, polled, 16-bit frames) and
   GPIO57 as the chip select, as on the reference board. This is the only glue: the pin and the SPI
   port. It runs as it is on the chip and, built by `sins-fw build-firmware`, on the emulated board. */
#include "DSP28x_Project.h"
#include "imu164.h"

static uint16_t spia_transfer(void *port, uint16_t frame)
{
    (void)port;
    while (SpiaRegs.SPISTS.bit.BUFFULL_FLAG == 1) {
    }
    SpiaRegs.SPITXBUF = frame;
    while (SpiaRegs.SPISTS.bit.INT_FLAG != 1) {
    }
    return SpiaRegs.SPIRXBUF;
}

static void gpio57_select(void *port, int selected)
{
    (void)port;
    if (selected)
        GpioDataRegs.GPBCLEAR.bit.GPIO57 = 1;
    else
        GpioDataRegs.GPBSET.bit.GPIO57 = 1;
}

static void wait_us(void *port, uint32_t us)
{
    (void)port;
    DELAY_US(us);
}

const struct imu164_bus f28335_imu_bus = {
    .transfer = spia_transfer,
    .select = gpio57_select,
    .wait_us = wait_us,
    .port = 0,
};
