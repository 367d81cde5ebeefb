/* A small ADIS16407 driver written against hal.h only, as it would be for the real board. */
#ifndef ADIS16407_H
#define ADIS16407_H

#include <stdint.h>

#define ADIS_CS_PIN 57         /* GPIO57 on the reference board */
#define ADIS_PROD_ID 0x56      /* reads 0x4017 (16407) */
#define ADIS_BURST_WORDS 14    /* SUPPLY_OUT ... AUX_ADC */

/* Read one 16-bit register: the address in one frame, the value in the next. */
uint16_t adis_read_register(uint8_t address);
/* Burst read: 0x4200, then the 14 output words into `words`. */
void adis_burst_read(uint16_t words[ADIS_BURST_WORDS]);

#endif
