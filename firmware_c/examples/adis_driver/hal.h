/* The few board services an Arduino-style driver needs. On the target they are the MCU's SPI and
   GPIO; on the host, host_hal.c implements them on the emulated board (the sins-fw C ABI). */
#ifndef HAL_H
#define HAL_H

#include <stdint.h>

#define HAL_LOW 0
#define HAL_HIGH 1

/* One 16-bit SPI frame: sends `out`, returns what came back; CS may rise as soon as it returns. */
uint16_t hal_transfer16(uint16_t out);
/* Drive a GPIO pin (the chip select). */
void hal_digital_write(int pin, int level);
/* Busy-wait `us` microseconds. */
void hal_delay_us(uint32_t us);

#endif
