/* Run the ADIS16407 driver against the emulated board:

       adis_demo PROFILE [KEY=VALUE ...]

   PROFILE is a profile name (reference) or a .toml file; the overrides are the profile's keys, as
   for sins-fw. The board is still but for a rate of (10, -5, 2.5) deg/s and 1 g on z; after 10 ms of
   device samples the driver reads PROD_ID and one burst. Printed, one per line: PROD_ID, the 14 burst
   words (hex), then each event as "event KIND frame DIN". Exit status 2 on any emulator error. */
#include <stdio.h>

#include "adis16407.h"
#include "host_hal.h"

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: %s PROFILE [KEY=VALUE ...]\n", argv[0]);
        return 2;
    }
    SinsBoard *board = NULL;
    host_check(sins_board_new(argv[1], (const char *const *)(argv + 2), (size_t)(argc - 2), &board), argv[1]);
    host_hal_use(board);
    host_check(sins_init_spi(board), "init_spi");
    const double gyro[3] = {10.0, -5.0, 2.5}, accel[3] = {0.0, 0.0, 1.0};
    host_check(sins_set_physical(board, gyro, accel), "set_physical");
    host_check(sins_advance_ps(board, 10000000000u), "advance"); /* 10 ms */

    printf("PROD_ID 0x%04X\n", adis_read_register(ADIS_PROD_ID));
    uint16_t words[ADIS_BURST_WORDS];
    adis_burst_read(words);
    for (int i = 0; i < ADIS_BURST_WORDS; i++) {
        printf("burst %d 0x%04X\n", i, words[i]);
    }
    SinsEvent events[64];
    size_t n = 0;
    host_check(sins_take_events(board, events, 64, &n), "take_events");
    for (size_t i = 0; i < n; i++) {
        printf("event %s %lld 0x%04X\n", events[i].kind, (long long)events[i].frame, events[i].din);
    }
    sins_board_free(board);
    return 0;
}
