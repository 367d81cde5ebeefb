/* hal.h on the emulated board: each call goes to the sins-fw C ABI (include/sins_fw.h). A failing call
   prints the emulator's message (it names the register, address or value) and exits with status 2. */
#include "host_hal.h"

#include <stdio.h>
#include <stdlib.h>

#include "hal.h"

static SinsBoard *board;

void host_check(SinsStatus status, const char *what) {
    if (status != SINS_OK) {
        fprintf(stderr, "%s: %s\n", what, sins_last_error());
        exit(2);
    }
}

void host_hal_use(SinsBoard *b) { board = b; }

uint16_t hal_transfer16(uint16_t out) {
    uint16_t in = 0;
    host_check(sins_transfer16(board, out, 0, &in), "transfer16");
    return in;
}

void hal_digital_write(int pin, int level) {
    host_check(sins_set_gpio(board, (uint32_t)pin, level), "digital_write");
}

void hal_delay_us(uint32_t us) { host_check(sins_advance_ps(board, (uint64_t)us * 1000000u), "delay_us"); }
