/* A small ADIS16407 driver written against hal.h only (nothing here knows about the emulator). Timing
   from the data sheet: >= 9 us stall between normal frames (16 us used, as ADI's evaluation tool does
   at 1 MHz; the frames are also >= 40 us apart, tDATARATE), one SCLK period inside a burst (2 us). */
#include "adis16407.h"

#include "hal.h"

#define STALL_US 40u
#define BURST_STALL_US 2u

uint16_t adis_read_register(uint8_t address) {
    hal_digital_write(ADIS_CS_PIN, HAL_LOW);
    hal_delay_us(STALL_US);
    (void)hal_transfer16((uint16_t)((address & 0x7Fu) << 8)); /* DOUT here is the previous read's */
    hal_delay_us(STALL_US);
    uint16_t value = hal_transfer16(0x0000);
    hal_digital_write(ADIS_CS_PIN, HAL_HIGH);
    return value;
}

void adis_burst_read(uint16_t words[ADIS_BURST_WORDS]) {
    hal_digital_write(ADIS_CS_PIN, HAL_LOW);
    hal_delay_us(STALL_US);
    (void)hal_transfer16(0x4200);
    for (int i = 0; i < ADIS_BURST_WORDS; i++) {
        hal_delay_us(BURST_STALL_US);
        words[i] = hal_transfer16(0x0000);
    }
    hal_digital_write(ADIS_CS_PIN, HAL_HIGH);
}
