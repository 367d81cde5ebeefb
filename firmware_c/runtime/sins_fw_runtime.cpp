/* The runtime of a host-built F28335 firmware (sins-fw build-firmware): the register-file objects of
   the replacement headers, each register access a call to the emulated board (the sins-fw C ABI)
   charged its CPU cycles (firmware_model/c28x-costs.toml [io], passed in as SINS_FW_READ_CYCLES and
   SINS_FW_WRITE_CYCLES), and the entry point that runs the firmware's main until a virtual time.

   extern "C" int sins_fw_run(profile, overrides, n_overrides, until_s, message, message_len):
       0 when main returned or the time ran out, 2 on an emulator error (the message, naming the
       register or address, is copied into `message`). One run per loaded library: the firmware's
       globals are not reset between runs. */
#include <cstdio>
#include <cstring>
#include <string>

/* The C28x float mode (sins_fw_c28x_float.h) maps `float` and `double` onto the C28x model in the
   firmware's sources only: the runtime keeps the host's. */
#undef float
#undef double

#include "DSP2833x_Device.h"
#include "sins_fw.h"

#ifndef SINS_FW_READ_CYCLES
#error "SINS_FW_READ_CYCLES: build with sins-fw build-firmware (it takes the costs from c28x-costs.toml)"
#endif
#ifndef SINS_FW_WRITE_CYCLES
#error "SINS_FW_WRITE_CYCLES: build with sins-fw build-firmware"
#endif

volatile struct SPI_REGS SpiaRegs;
volatile struct GPIO_DATA_REGS GpioDataRegs;
volatile struct SYS_CTRL_REGS SysCtrlRegs;

void sins_fw_user_main(void);

namespace {

SinsBoard *board = nullptr;
uint64_t until_ps = 0;
uint64_t accesses = 0;

struct TimeUp {};
struct Failure {
    std::string message;
};

void check(SinsStatus status, const char *what) {
    if (status != SINS_OK) {
        throw Failure{std::string(what) + ": " + sins_last_error()};
    }
}

/* Virtual time ran out: unwind the firmware back to sins_fw_run. */
void stop_if_time_up() {
    uint64_t now = 0;
    check(sins_now_ps(board, &now), "time");
    if (now >= until_ps) {
        throw TimeUp{};
    }
}

}  // namespace

uint16_t sins_fw_read16(uint32_t address) {
    uint16_t value = 0;
    check(sins_advance_cycles(board, SINS_FW_READ_CYCLES), "read");
    check(sins_read16(board, address, &value), "read");
    accesses++;
    stop_if_time_up();
    return value;
}

void sins_fw_write16(uint32_t address, uint16_t value) {
    check(sins_advance_cycles(board, SINS_FW_WRITE_CYCLES), "write");
    check(sins_write16(board, address, value), "write");
    accesses++;
    stop_if_time_up();
}

void sins_fw_delay_us(double microseconds) {
    if (!(microseconds >= 0.0)) {
        throw Failure{"DELAY_US(" + std::to_string(microseconds) + "): expected a time >= 0"};
    }
    check(sins_advance_ps(board, static_cast<uint64_t>(microseconds * 1e6 + 0.5)), "DELAY_US");
    stop_if_time_up();
}

extern "C" int sins_fw_run(const char *profile, const char *const *overrides, size_t n_overrides, double until_s,
                           char *message, size_t message_len) {
    int rc = 0;
    std::string text;
    try {
        if (!(until_s > 0.0)) {
            throw Failure{"until_s: expected a time > 0 s"};
        }
        until_ps = static_cast<uint64_t>(until_s * 1e12 + 0.5);
        check(sins_board_new(profile, overrides, n_overrides, &board), profile);
        sins_fw_user_main();
    } catch (const TimeUp &) {
    } catch (const Failure &f) {
        rc = 2;
        text = f.message;
    }
    if (message != nullptr && message_len > 0) {
        std::snprintf(message, message_len, "%s", text.c_str());
    }
    return rc;
}

/* After a run: virtual time reached, ps, and register accesses made. */
extern "C" uint64_t sins_fw_now_ps(void) {
    uint64_t now = 0;
    if (board != nullptr && sins_now_ps(board, &now) != SINS_OK) {
        return 0;
    }
    return now;
}

extern "C" uint64_t sins_fw_accesses(void) { return accesses; }
