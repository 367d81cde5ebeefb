/* imu164: a portable driver for ADIS164xx-family IMUs (16-bit SPI frames, mode 3), written the way
   third-party sensor drivers are: plain C99 with GNU extensions, no vendor headers, its own frame
   macros, a bus described by function pointers that the board's port fills in. It knows nothing of
   the F28335: see f28335_port.c for the pin and SPI port mapping. */
#ifndef IMU164_H
#define IMU164_H

#include <stdint.h>

/* A register read is one frame with the address in bits 14:8; its answer comes in the next frame. */
#define IMU164_FRAME_READ(reg) ((uint16_t)(((uint16_t)(reg) & 0x7Fu) << 8))
/* A register write is one frame per byte: bit 15 set, address, data byte. */
#define IMU164_FRAME_WRITE(reg, byte) ((uint16_t)(0x8000u | (((uint16_t)(reg) & 0x7Fu) << 8) | ((byte) & 0xFFu)))
/* Output registers: 14-bit two's complement in bits 13:0, bit 15 ND (new data), bit 14 EA (error). */
#define IMU164_SIGN14(word) ((int16_t)((int16_t)((word) << 2) >> 2))
#define IMU164_ND(word) (((word) >> 15) & 1u)

enum imu164_reg {
    IMU164_SUPPLY_OUT = 0x02,
    IMU164_XGYRO_OUT = 0x04,
    IMU164_YGYRO_OUT = 0x06,
    IMU164_ZGYRO_OUT = 0x08,
    IMU164_XACCL_OUT = 0x0A,
    IMU164_YACCL_OUT = 0x0C,
    IMU164_ZACCL_OUT = 0x0E,
    IMU164_PROD_ID = 0x56,
};

struct imu164_bus {
    uint16_t (*transfer)(void *port, uint16_t frame); /* one 16-bit frame, full duplex */
    void (*select)(void *port, int selected);         /* the chip select, active low on the wire */
    void (*wait_us)(void *port, uint32_t us);         /* a stall between frames */
    void *port;
};

struct imu164_config {
    uint16_t stall_us; /* between frames: the part's tSTALL (9 us), and tDATARATE (40 us) from frame start to frame start */
};

typedef struct imu164 {
    struct imu164_bus bus;
    struct imu164_config config;
    uint16_t product;
} imu164_t;

union imu164_word {
    uint16_t u;
    int16_t s;
};

struct imu164_sample {
    int16_t gyro[3];
    int16_t accel[3];
    uint16_t supply;
    uint16_t fresh; /* ND of all six */
};

imu164_t *imu164_open(const struct imu164_bus *bus, const struct imu164_config *config);
int imu164_probe(imu164_t *dev, uint16_t expected_product);
uint16_t imu164_read(imu164_t *dev, enum imu164_reg reg);
struct imu164_sample imu164_sample(imu164_t *dev);

#endif
