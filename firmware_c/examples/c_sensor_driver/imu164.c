/* imu164: see imu164.h. */
#include "imu164.h"

#include <stdlib.h>

typedef void (*imu164_hook)(void);

/* Read `n` registers in a pipeline: the frame reading register k+1 carries register k's answer. Every
   frame, the first too, comes a stall after the one before. */
static void read_chain(imu164_t *dev, const uint8_t *regs, int n, uint16_t *out)
{
    int i;
    dev->bus.wait_us(dev->bus.port, dev->config.stall_us);
    dev->bus.select(dev->bus.port, 1);
    dev->bus.transfer(dev->bus.port, IMU164_FRAME_READ(regs[0]));
    dev->bus.select(dev->bus.port, 0);
    for (i = 0; i < n; i++) {
        dev->bus.wait_us(dev->bus.port, dev->config.stall_us);
        dev->bus.select(dev->bus.port, 1);
        out[i] = dev->bus.transfer(dev->bus.port, i + 1 < n ? IMU164_FRAME_READ(regs[i + 1]) : 0x0000);
        dev->bus.select(dev->bus.port, 0);
    }
}

imu164_t *imu164_open(const struct imu164_bus *bus, const struct imu164_config *config)
{
    imu164_t *dev = malloc(sizeof *dev); /* C: no cast */
    if (dev == NULL)
        return NULL;
    *dev = (imu164_t){
        .bus = *bus,
        .config = config ? *config : (struct imu164_config){.stall_us = 20},
        .product = 0,
    };
    return dev;
}

uint16_t imu164_read(imu164_t *dev, enum imu164_reg reg)
{
    uint16_t word = 0;
    read_chain(dev, (const uint8_t[]){(uint8_t)reg}, 1, &word);
    return word;
}

int imu164_probe(imu164_t *dev, uint16_t expected_product)
{
    dev->product = imu164_read(dev, IMU164_PROD_ID);
    return dev->product == expected_product ? 0 : -1;
}

struct imu164_sample imu164_sample(imu164_t *dev)
{
    uint16_t w[7];
    int k;
    struct imu164_sample s;
    read_chain(dev,
               (const uint8_t[]){IMU164_XGYRO_OUT, IMU164_YGYRO_OUT, IMU164_ZGYRO_OUT, IMU164_XACCL_OUT,
                                 IMU164_YACCL_OUT, IMU164_ZACCL_OUT, IMU164_SUPPLY_OUT},
               7, w);
    s.fresh = 1;
    for (k = 0; k < 3; k++) {
        s.gyro[k] = ((union imu164_word)(uint16_t)IMU164_SIGN14(w[k])).s; /* GNU C: a cast to a union */
        s.accel[k] = IMU164_SIGN14(w[k + 3]);
        s.fresh &= IMU164_ND(w[k]) & IMU164_ND(w[k + 3]);
    }
    s.supply = w[6] & 0x3FFFu;
    return s;
}
