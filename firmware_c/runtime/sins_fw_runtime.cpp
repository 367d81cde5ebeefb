/* The runtime of a host-built F28335 firmware (sins-fw build-firmware): the calls the build's LLVM pass
   makes of the firmware's register accesses (sins_fw_ld16/sins_fw_st16, ...: the C28x data space's
   image, the vector table, IER/IFR, or host memory), each access to a modelled register a call to the
   emulated board (the sins-fw C ABI) charged its CPU cycles, the interrupts, and the entry point that
   runs the firmware's main on a trace.

   Time. Each register access is charged its cycles (c28x-costs.toml [io] peripheral_read /
   peripheral_write). The build's LLVM pass calls sins_fw_block at every basic block of the firmware's
   own code with the block's C28x cycles, priced at compile time from its optimised IR
   (docs/c-cycles.md).
   So straight-line code and loops without any register access (the idle `for (;;) {}`) let virtual
   time pass and let interrupts in, at basic-block boundaries; DELAY_US lets them in too.

   Interrupts. When the emulated CPU takes one (timer 0 → PIE → IFR/IER/INTM, modelled in the core),
   the runtime charges the entry (hw_context_save + c_prologue), calls the function PieVectTable holds,
   charges the exit (c_epilogue + iret), IRETs, and records a row: the timer tick, the ISR's times and
   the values of the watched globals (after the ISR).

   Polling. A read of the register the previous access read, giving the same value (a polling loop),
   skips whole loop passes up to the last one before the register may change by itself
   (sins_next_change_ps) or an interrupt may come: the time reached is the one the loop would have
   reached pass by pass, as long as its passes take equal time.

   End. When the next step would pass the end of the trace, a C++ exception (TraceEnd) unwinds the
   firmware's frames back to sins_fw_run (its C is compiled with -fexceptions, so the unwinder passes
   through its frames; C++ firmware's destructors run). An emulator error unwinds the same way
   (Failure) with its message. A loop that makes no register access while nothing can interrupt it
   (INTM set, the timer or its PIE path disabled) can never end: after `spin_blocks` basic blocks
   without an access the run stops with an error naming what blocks the interrupts, and the code
   address of the loop (sins_fw_fault_offset: the harness turns it into file:line with addr2line).
   An ISR still running when the input ends (one that never returns) ends the run with status 3 and
   the code address it was at.

   Crashes. The harness runs the firmware in a child process (sins_fw.firmware_run) and passes a file
   in SINS_FW_CRASH_FD. Before any of the firmware's static constructors (this library's constructor
   of priority 101), the runtime installs handlers of the fatal signals on an alternate stack (a
   stack overflow from endless recursion is caught too) and an atexit handler: each writes a record
   (the signal, the faulting address and instruction, the return addresses of the stack, the
   library's load address) and what the run computed since the harness last took it (the ISR rows;
   the events and the bus log when the code interrupted is the firmware's own, abort() or exit())
   to the file, then the signal takes its default action; the harness keeps the rows and names the
   signal and, through addr2line, the firmware's file and line. */
#include <dlfcn.h>
#include <execinfo.h>
#include <signal.h>
#include <stdlib.h>
#include <ucontext.h>
#include <unistd.h>

#include <cctype>
#include <cstdint>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "sins_fw.h"

/* The C28x data space (22-bit word addresses), one host uint16_t per C28x word: the build places
   TI's register-file objects in it (`.set SpiaRegs, sins_fw_io + 2*0x7040` in the assembly it
   generates with these three arrays: firmware_build.placement_assembly), and the
   pass maps a raw address (`(Uint16 *)0x701B`) to it, so a pointer's arithmetic counts words as on the
   C28x. The registers of the modelled peripherals (is_modelled) are the emulated board's; every other
   word is plain memory, the registers of peripherals not modelled yet holding their reset values
   (reset_io), so that TI's support sources that initialise them run. */
constexpr uint32_t IO_WORDS = 0x400000u;
extern "C" {
extern uint16_t sins_fw_io[IO_WORDS];
/* PieVectTable: 128 host function pointers (a C28x vector is 32-bit; here it holds a host address). */
extern uint64_t sins_fw_vectors[128];
/* The CPU's cregisters IER and IFR (TI declares them `extern cregister volatile unsigned int`). */
extern uint64_t sins_fw_cregs[2];
}

/* The firmware's main: `main` is renamed by the prelude; C gives it C linkage, C++ C++ linkage. */
extern "C" void sins_fw_user_main(void) __attribute__((weak));
void sins_fw_user_main_cxx(void) __asm__("_Z17sins_fw_user_mainv") __attribute__((weak));

/* SCI-A/B/C's registers (rust/core/src/dsp/sci.rs: offsets 0-7, 9-0xC, 0xF of 0x7050/0x7750/0x7770). */
static bool is_sci(uint32_t a) {
    for (uint32_t base : {0x7050u, 0x7750u, 0x7770u}) {
        if (a >= base && a < base + 0x10u) {
            uint32_t o = a - base;
            return o != 8 && o != 0xD && o != 0xE;
        }
    }
    return false;
}

/* The modelled registers (rust/core/src/host.rs `HostBoard::read`: SPI-A, the GPIO registers,
   the system control registers (dsp/sysctrl.rs `SysCtrl::owns`), CPU timers 0-2 and the PIE
   (dsp/interrupts.rs `Interrupts::owns`), SCI-A/B/C (dsp/sci.rs), I2C-A (dsp/i2c.rs), McBSP-A/B (dsp/mcbsp.rs), and the frames of the peripherals
   not modelled yet, whose registers the board holds with their reset values and whose first use it
   reports (dsp/unmodelled.rs `FRAMES`). */
static bool is_modelled(uint32_t a) {
    if (a == 0x7011u || (a >= 0x701Au && a <= 0x701Eu) || (a >= 0x7020u && a <= 0x7023u) || a == 0x7025u ||
        a == 0x7029u) {
        return true;                                                 /* SysCtrlRegs: PLL, clocks, watchdog */
    }
    if ((a >= 0x0A80u && a < 0x0A88u) || (a >= 0x0B00u && a < 0x0B40u) || (a >= 0x1000u && a < 0x1200u) ||
        (a >= 0x6000u && a < 0x6400u) || (a >= 0x6800u && a < 0x6980u) || (a >= 0x6A00u && a < 0x6AC0u) ||
        (a >= 0x7100u && a < 0x7120u)) {
        return true;                                                 /* Flash, ADC, XINTF, DMA, eCAN, ePWM, eCAP */
    }
    if (a >= 0x7040u && a < 0x7050u) {                               /* SPI-A, its registers */
        uint32_t o = a - 0x7040u;
        return o <= 2 || (o >= 4 && o <= 0xC) || o == 0xF;
    }
    if (a >= 0x6FC0u && a < 0x6FC0u + 24) return true;               /* GPxDAT/SET/CLEAR/TOGGLE */
    if ((a >= 0x6F80u && a < 0x6F8Eu) || (a >= 0x6F90u && a < 0x6F9Eu) || (a >= 0x6FA6u && a < 0x6FAEu))
        return true;                                                 /* GpioCtrlRegs (dsp/gpio.rs) */
    if (a >= 0x0C00u && a < 0x0C18u) return a % 8 != 5;              /* CPU timers 0-2 */
    if (is_sci(a)) return true;                                      /* SCI-A/B/C (dsp/sci.rs) */
    if ((a >= 0x7900u && a <= 0x790Cu) || a == 0x7920u || a == 0x7921u) return true; /* I2C-A (dsp/i2c.rs) */
    if ((a >= 0x5000u && a < 0x5024u) || (a >= 0x5040u && a < 0x5064u)) return true; /* McBSP-A/B (dsp/mcbsp.rs) */
    return a >= 0x0CE0u && a <= 0x0CF9u;                             /* PIE control */
}

/* Reset values of registers of peripherals not modelled yet (F2833x peripheral reference guides, as
   the spec's f28335-peripherals.md §10 lists them); all others reset to 0. (The system control, flash
   and unmodelled peripherals' registers are the board's, with theirs.) */
static const struct {
    uint32_t address;
    uint16_t value;
} RESET_VALUES[] = {
    {0x7902u, 0x0410u}, /* I2CSTR: XSMT, XRDY */
};

/* The PIE lines and CPU interrupts enabled so far (the enable-time check below). */
static uint16_t pie_enabled[12];
static uint16_t ier_enabled;

static void reset_io() {
    std::memset(sins_fw_io, 0, 0x10000u * sizeof(uint16_t)); /* the peripheral frames and RAM L0-L7 */
    for (const auto &r : RESET_VALUES) {
        sins_fw_io[r.address] = r.value;
    }
    std::memset(sins_fw_vectors, 0, sizeof sins_fw_vectors);
    std::memset(pie_enabled, 0, sizeof pie_enabled);
    ier_enabled = 0;
}

extern "C" uint16_t sins_fw_read16(uint32_t address);
extern "C" void sins_fw_write16(uint32_t address, uint16_t value);

/* The PIE's 96 peripheral vectors by group and line (TI's DSP2833x_PieVect.h names, vectors 32-127). */
static const char *const PIE_NAMES[96] = {"SEQ1INT","SEQ2INT","rsvd1_3","XINT1","XINT2","ADCINT","TINT0","WAKEINT","EPWM1_TZINT","EPWM2_TZINT","EPWM3_TZINT","EPWM4_TZINT","EPWM5_TZINT","EPWM6_TZINT","rsvd2_7","rsvd2_8","EPWM1_INT","EPWM2_INT","EPWM3_INT","EPWM4_INT","EPWM5_INT","EPWM6_INT","rsvd3_7","rsvd3_8","ECAP1_INT","ECAP2_INT","ECAP3_INT","ECAP4_INT","ECAP5_INT","ECAP6_INT","rsvd4_7","rsvd4_8","EQEP1_INT","EQEP2_INT","rsvd5_3","rsvd5_4","rsvd5_5","rsvd5_6","rsvd5_7","rsvd5_8","SPIRXINTA","SPITXINTA","MRINTB","MXINTB","MRINTA","MXINTA","rsvd6_7","rsvd6_8","DINTCH1","DINTCH2","DINTCH3","DINTCH4","DINTCH5","DINTCH6","rsvd7_7","rsvd7_8","I2CINT1A","I2CINT2A","rsvd8_3","rsvd8_4","SCIRXINTC","SCITXINTC","rsvd8_7","rsvd8_8","SCIRXINTA","SCITXINTA","SCIRXINTB","SCITXINTB","ECAN0INTA","ECAN1INTA","ECAN0INTB","ECAN1INTB","rsvd10_1","rsvd10_2","rsvd10_3","rsvd10_4","rsvd10_5","rsvd10_6","rsvd10_7","rsvd10_8","rsvd11_1","rsvd11_2","rsvd11_3","rsvd11_4","rsvd11_5","rsvd11_6","rsvd11_7","rsvd11_8","XINT3","XINT4","XINT5","XINT6","XINT7","rsvd12_6","LVF","LUF"};

/* Interrupts the firmware enables that the emulator can never raise (raised: TINT0 INT1.7, WAKEINT
   INT1.8 (the watchdog), SPIRXINTA/SPITXINTA INT6.1/6.2, MRINTB/MXINTB/MRINTA/MXINTA INT6.3-6.6,
   TINT1 INT13, TINT2 INT14): each reported
   once, when it is enabled, as an `interrupt_never_raised` event of the run naming the vector, its
   PIE group and line (the board's time is the enabling write's). */
static SinsBoard *run_board();
static void warn_never_raised(const char *what) {
    SinsBoard *b = run_board();
    if (b != nullptr) {
        sins_report_never_raised(b, what);
    }
}

/* The PIE lines a modelled peripheral raises (group and line, 0-based): TINT0 and WAKEINT (1.7, 1.8),
   SPI-A's RX/TX (6.1, 6.2), the McBSPs' MRINTB/MXINTB/MRINTA/MXINTA (6.3-6.6), the SCIs' RX/TX
   (9.1-9.4, 8.5/8.6), I2C-A's I2CINT1A/I2CINT2A (8.1, 8.2). */
static bool raised_by_the_board(unsigned group, unsigned line) {
    return (group == 0 && (line == 6 || line == 7)) || (group == 5 && line <= 5) || (group == 8 && line <= 3) ||
           (group == 7 && line <= 5 && line != 2 && line != 3);
}

static void check_pie_enable(uint32_t address, uint16_t value) {
    if (address < 0x0CE2u || address > 0x0CF9u || (address - 0x0CE2u) % 2 != 0) {
        return;
    }
    unsigned group = (address - 0x0CE2u) / 2; /* 0-based */
    uint16_t fresh = static_cast<uint16_t>(value & 0xFFu & ~pie_enabled[group]);
    pie_enabled[group] |= fresh;
    for (unsigned line = 0; line < 8; line++) {
        if ((fresh >> line & 1u) && !raised_by_the_board(group, line)) {
            char what[96];
            std::snprintf(what, sizeof what, "%s (PIE group %u, INT%u.%u, vector %u)", PIE_NAMES[group * 8 + line],
                          group + 1, group + 1, line + 1, 32 + group * 8 + line);
            warn_never_raised(what);
        }
    }
}

static void check_ier_enable(uint16_t value) {
    uint16_t fresh = static_cast<uint16_t>(value & ~ier_enabled);
    ier_enabled |= fresh;
    if (fresh & 0x4000u) warn_never_raised("DLOGINT (IER bit 14)");
    if (fresh & 0x8000u) warn_never_raised("RTOSINT (IER bit 15)");
}

/* What the harness passes to sins_fw_run. */
extern "C" {
typedef int (*sins_fw_more_input)(void *ctx);
struct SinsFwConfig {
    SinsBoard *board;
    uint64_t read_cycles;
    uint64_t write_cycles;
    uint64_t isr_entry_cycles;
    uint64_t isr_exit_cycles;
    /* Basic blocks without a register access before the check for a loop that cannot end. */
    uint64_t spin_blocks;
    /* Watched globals: their addresses and type codes (0 int16, 1 uint16, 2 int32, 3 uint32,
       4 int64, 5 uint64, 6 float, 7 double). */
    size_t n_globals;
    const void *const *global_addr;
    const int *global_type;
    /* Called when the trace pushed so far is used up: push more rows or end the input; nonzero
       stops the run (the harness keeps its own error). */
    sins_fw_more_input more_input;
    void *ctx;
};
}

/* The times recorded per ISR, in this order (ps, but the first: the timer's reloads so far). */
enum { ROW_TICK, ROW_TICK_PS, ROW_START, ROW_ENTRY_END, ROW_BODY_END, ROW_END, ROW_DEADLINE, ROW_TIMES };
/* Their names, in the same order: the harness names the columns of `sins_fw_take_rows` with them
   (sins_fw.firmware_run), so this is the one list of them. */
extern "C" const char *const sins_fw_row_times[ROW_TIMES] = {
    "tick", "tick_ps", "start_ps", "entry_end_ps", "body_end_ps", "end_ps", "deadline_ps",
};
extern "C" const int sins_fw_row_time_count = ROW_TIMES;

namespace {

struct TraceEnd {};
struct Failure {
    std::string message;
};

const SinsFwConfig *cfg = nullptr;
SinsBoard *board = nullptr;
uint64_t now_ps = 0;
uint64_t pending_cycles = 0; /* basic blocks' cycles not yet passed to the board */
uint64_t flush_cycles = 0;   /* flush the blocks' cycles once this many are pending */
uint64_t irq_at = 0;         /* an interrupt may be takeable from this time (0: check at once) */
uint64_t input_until = 0;
bool input_ended = false;
uint64_t cycle_ps_ceil = 7; /* one SYSCLKOUT cycle, ps, rounded up */
uint64_t cycle_ps = 6;      /* one SYSCLKOUT cycle, ps, as the board advanced it */
uint64_t accesses = 0;
uint64_t blocks = 0;
uint64_t blocks_since_access = 0;
uint64_t fault_offset = 0;
size_t n_globals = 0;
int isr_depth = 0;
/* The outermost ISR running: its vector, the end of its entry and its deadline (the next tick; ps). */
int isr_vector = -1;
uint64_t isr_entry_end_ps = 0;
uint64_t isr_deadline_ps = UINT64_MAX;
/* The return address of the last basic block's call into the runtime (where the firmware is). */
const void *last_pc = nullptr;
/* The polling skip: the last access, when it was a read. */
bool poll_valid = false;
uint32_t poll_addr = 0;
uint16_t poll_value = 0;
uint64_t poll_t = 0;
uint64_t poll_period = 0;  /* the time between the last two reads of a polling loop */
uint64_t poll_repeats = 0; /* reads in a row of the same register giving the same value */
/* Where the firmware made its last instrumented access (the pass's call's return address). */
const void *access_pc = nullptr;

/* A polling loop is taken for one from its third identical read on (two equal periods), and for one
   that cannot end from its POLL_ENDLESS-th: reading a register twice in straight-line code is not a loop. */
constexpr uint64_t POLL_ENDLESS = 16;
/* Never destroyed (as the function records below): an exit() in the firmware runs the static
   destructors before the crash report (on_exit_call) writes these rows, and a freed vector's first
   words are the allocator's (the first row's tick read as a heap address). */
std::vector<uint64_t> &row_times = *new std::vector<uint64_t>;
std::vector<double> &row_values = *new std::vector<double>;

void check(SinsStatus status, const char *what) {
    if (status != SINS_OK) {
        throw Failure{std::string(what) + ": " + sins_last_error()};
    }
}

void refresh_input() {
    int ended = 0;
    check(sins_input_until(board, &input_until, &ended), "input");
    input_ended = ended != 0;
    if (input_until == UINT64_MAX) {
        input_until = 0;
    }
}

/* Make the input cover time `t` (asking the harness for more), or end the run there. */
void cover(uint64_t t) {
    while (t > input_until) {
        if (input_ended) {
            throw TraceEnd{};
        }
        if (cfg->more_input(cfg->ctx) != 0) {
            throw Failure{""};
        }
        refresh_input();
    }
}

void update_flush() {
    uint64_t limit = irq_at < input_until ? irq_at : input_until;
    flush_cycles = limit > now_ps ? (limit - now_ps) / cycle_ps_ceil : 0;
    if (flush_cycles > (1u << 20)) {
        flush_cycles = 1u << 20; /* keep the spin check and the event flow regular */
    }
}

void read_now() { check(sins_now_ps(board, &now_ps), "time"); }

}  // namespace

/* The board of the run in progress (null outside a run): the enable-time check reports to it. */
static SinsBoard *run_board() { return cfg != nullptr ? board : nullptr; }

namespace {

/* SYSCLKOUT may have changed (the PLL: PLLCR, PLLSTS.DIVSEL): the cycle's length again. */
void refresh_cycle() {
    check(sins_cycle_ps(board, &cycle_ps), "time");
    cycle_ps_ceil = cycle_ps + 1;
}

/* Let `cycles` SYSCLKOUT cycles pass (no register access). */
void pass_cycles(uint64_t cycles) {
    if (cycles == 0) {
        return;
    }
    cover(now_ps + (cycles + 1) * cycle_ps_ceil);
    check(sins_advance_cycles(board, cycles), "time");
    read_now();
}

void take_interrupts();

void flush_blocks() {
    uint64_t c = pending_cycles;
    pending_cycles = 0;
    pass_cycles(c);
    take_interrupts();
}

/* Let `ps` picoseconds pass, taking the interrupts that come meanwhile (DELAY_US, a polling skip). */
void pass_ps(uint64_t ps) {
    flush_blocks();
    uint64_t target = now_ps + ps;
    while (now_ps < target) {
        uint64_t step_to = irq_at > now_ps && irq_at < target ? irq_at : target;
        cover(step_to);
        check(sins_advance_to_ps(board, step_to), "time");
        now_ps = step_to;
        take_interrupts();
    }
    update_flush();
}

/* Per function, per ISR run: how many rows have been recorded (the next row's index), the clock of
   the firmware's own cycles (the blocks' cycles; ISRs' cycles are taken out again at their return, so
   a frame of main interrupted by an ISR does not count the ISR's), the shadow stack of the priced
   functions running (their counter and the clock at entry: inclusive cycles at their return), and
   the function records of the ISRs run since the harness last took them
   {row index, function index, self cycles, calls, inclusive cycles} (sins_fw_take_function_rows). */
uint64_t rows_recorded = 0;
uint64_t fn_clock = 0;
struct Frame {
    uint64_t *counter;
    uint64_t clock;
};
std::vector<Frame> &fn_stack = *new std::vector<Frame>;
std::vector<uint64_t> &fn_rows = *new std::vector<uint64_t>;
size_t function_total();
uint64_t *function_counter(size_t i);

void record_row(const uint64_t *times) {
    rows_recorded++;
    row_times.insert(row_times.end(), times, times + ROW_TIMES);
    for (size_t i = 0; i < n_globals; i++) {
        const void *p = cfg->global_addr[i];
        double v = 0;
        switch (cfg->global_type[i]) {
            case 0: v = *static_cast<const volatile int16_t *>(p); break;
            case 1: v = *static_cast<const volatile uint16_t *>(p); break;
            case 2: v = *static_cast<const volatile int32_t *>(p); break;
            case 3: v = *static_cast<const volatile uint32_t *>(p); break;
            case 4: v = static_cast<double>(*static_cast<const volatile int64_t *>(p)); break;
            case 5: v = static_cast<double>(*static_cast<const volatile uint64_t *>(p)); break;
            case 6: v = *static_cast<const volatile float *>(p); break;
            default: v = *static_cast<const volatile double *>(p); break;
        }
        row_values.push_back(v);
    }
}

/* TI's PieVectTable field name of vector `v` (the CPU timers' INT13 and INT14, the PIE's 96). */
const char *vector_name(int v) {
    if (v == 13) return "XINT13";
    if (v == 14) return "TINT2";
    if (v >= 32 && v < 128) return PIE_NAMES[v - 32];
    return "?";
}

void run_isr(int vector, uint64_t isr) {
    if (isr == 0) {
        std::string name = vector_name(vector);
        throw Failure{"the CPU took PIE vector " + std::to_string(vector) + " (" + name +
                      ") but PieVectTable holds no ISR there: set it under EALLOW (PieVectTable." + name + " = &isr;)"};
    }
    uint64_t times[ROW_TIMES] = {};
    uint64_t next = 0;
    check(sins_timer0_ticks(board, &times[ROW_TICK], &times[ROW_TICK_PS], &next), "timer 0");
    times[ROW_DEADLINE] = next == UINT64_MAX ? now_ps : next;
    times[ROW_START] = now_ps;
    poll_valid = false;
    pass_cycles(cfg->isr_entry_cycles);
    times[ROW_ENTRY_END] = now_ps;
    if (isr_depth++ == 0) {
        isr_vector = vector;
        isr_entry_end_ps = now_ps;
        isr_deadline_ps = next;
    }
    irq_at = 0;
    update_flush();
    /* The functions' counters before the ISR: its records are the differences at its return. */
    size_t nf = function_total();
    std::vector<uint64_t> before(nf * 3);
    for (size_t i = 0; i < nf; i++) {
        std::memcpy(&before[i * 3], function_counter(i), 3 * sizeof(uint64_t));
    }
    size_t stack_at = fn_stack.size();
    uint64_t clock_at = fn_clock;
    reinterpret_cast<void (*)(void)>(static_cast<uintptr_t>(isr))();
    isr_depth--;
    /* Frames left without a return (a longjmp out of them) end with the ISR. */
    while (fn_stack.size() > stack_at) {
        Frame f = fn_stack.back();
        fn_stack.pop_back();
        if (f.counter[3] > 0 && --f.counter[3] == 0) {
            f.counter[2] += fn_clock - f.clock;
        }
    }
    uint64_t c = pending_cycles;
    pending_cycles = 0;
    pass_cycles(c);
    times[ROW_BODY_END] = now_ps;
    pass_cycles(cfg->isr_exit_cycles);
    times[ROW_END] = now_ps;
    check(sins_iret(board), "IRET");
    poll_valid = false;
    for (size_t i = 0; i < nf; i++) {
        const uint64_t *k = function_counter(i);
        if (k[1] != before[i * 3 + 1] || k[0] != before[i * 3]) {
            const uint64_t r[5] = {rows_recorded, i, k[0] - before[i * 3], k[1] - before[i * 3 + 1],
                                   k[2] - before[i * 3 + 2]};
            fn_rows.insert(fn_rows.end(), r, r + 5);
        }
    }
    fn_clock = clock_at; /* the interrupted code's functions do not count the ISR's cycles */
    record_row(times);
}

/* Take every interrupt the CPU takes now (one after another: an ISR's exit may let the next in). */
void take_interrupts() {
    while (now_ps >= irq_at) {
        int vector = -1;
        uint64_t isr = 0;
        check(sins_take_interrupt(board, &vector, &isr), "interrupt");
        if (vector < 0) {
            check(sins_next_interrupt_ps(board, &irq_at, nullptr, 0), "interrupt");
            if (irq_at <= now_ps) {
                irq_at = now_ps + 1; /* due at the next step */
            }
            break;
        }
        run_isr(vector, isr);
        irq_at = 0;
    }
    update_flush();
}

/* A loop without register access: stop it if nothing can ever interrupt it. */
void spin_check(const void *pc) {
    char why[160] = {0};
    uint64_t next = 0;
    check(sins_next_interrupt_ps(board, &next, why, sizeof why), "interrupt");
    if (next != UINT64_MAX) {
        return;
    }
    Dl_info info;
    if (dladdr(pc, &info) != 0 && info.dli_fbase != nullptr) {
        fault_offset = reinterpret_cast<uintptr_t>(pc) - reinterpret_cast<uintptr_t>(info.dli_fbase);
    }
    throw Failure{"the firmware loops without any register access and nothing can interrupt the loop (" +
                  std::string(why) + "): it would never leave it (" + std::to_string(blocks_since_access) +
                  " basic blocks run since the last register access)"};
}

void before_access(uint64_t cycles) {
    blocks_since_access = 0;
    accesses++;
    cover(now_ps + (pending_cycles + cycles + 1) * cycle_ps_ceil);
}

void after_access() {
    if (now_ps >= irq_at) {
        take_interrupts();
    } else if (now_ps + flush_cycles * cycle_ps_ceil > irq_at) {
        update_flush();
    }
}

void mark_irq_state_changed() {
    irq_at = 0;
    flush_cycles = 0;
}

void set_fault_offset(const void *pc) {
    Dl_info info;
    if (pc != nullptr && dladdr(pc, &info) != 0 && info.dli_fbase != nullptr) {
        fault_offset = reinterpret_cast<uintptr_t>(pc) - reinterpret_cast<uintptr_t>(info.dli_fbase);
    }
}

/* A polling read that saw no change: skip the passes that would see none. */
void poll_skip(uint32_t address) {
    uint64_t period = now_ps - poll_t;
    bool steady = poll_repeats >= 2 && period == poll_period;
    poll_period = period;
    uint64_t change = UINT64_MAX;
    if (is_modelled(address)) {
        check(sins_next_change_ps(board, address, &change), "poll");
    }
    if (change == UINT64_MAX && irq_at == UINT64_MAX && isr_depth == 0 && poll_repeats >= POLL_ENDLESS) {
        set_fault_offset(access_pc);
        char why[160] = {0};
        uint64_t next = 0;
        check(sins_next_interrupt_ps(board, &next, why, sizeof why), "interrupt");
        char where[64];
        std::snprintf(where, sizeof where, "0x%04X", static_cast<unsigned>(address));
        throw Failure{std::string("the firmware polls the register at ") + where +
                      ", which does not change by itself, and nothing can interrupt the loop (" + why +
                      "): it would never leave it"};
    }
    uint64_t until = change < irq_at ? change : irq_at;
    if (!steady || period == 0 || until == UINT64_MAX || until <= now_ps + period) {
        poll_t = now_ps;
        return;
    }
    uint64_t passes = (until - now_ps + period - 1) / period; /* the pass that sees the change */
    uint64_t skip = (passes - 1) * period;
    poll_t = now_ps + skip;
    if (skip > 0) {
        pass_ps(skip);
        poll_t = now_ps;
    }
}

}  // namespace

extern "C" uint16_t sins_fw_read16(uint32_t address) {
    uint16_t value = 0;
    uint64_t cycles = pending_cycles + cfg->read_cycles;
    before_access(cfg->read_cycles);
    pending_cycles = 0;
    if (is_modelled(address)) {
        check(sins_cpu_read16(board, address, cycles, &value, &now_ps), "read");
    } else {
        /* Plain memory: its cycles wait with the blocks' for the next flush. */
        value = sins_fw_io[address];
        pending_cycles = cycles;
        if (pending_cycles >= flush_cycles) {
            flush_blocks();
        }
    }
    bool polling = poll_valid && poll_addr == address && poll_value == value;
    if ((address & 0xFF00u) == 0x0C00u) {
        mark_irq_state_changed();
    }
    if (address >= 0x7010u && address < 0x7030u) {
        refresh_cycle();
        mark_irq_state_changed();
    }
    after_access();
    if (polling) {
        poll_repeats++;
        poll_skip(address);
    } else {
        poll_repeats = 0;
        poll_t = now_ps;
    }
    poll_valid = true;
    poll_addr = address;
    poll_value = value;
    return value;
}

extern "C" void sins_fw_write16(uint32_t address, uint16_t value) {
    uint64_t cycles = pending_cycles + cfg->write_cycles;
    before_access(cfg->write_cycles);
    pending_cycles = 0;
    if (is_modelled(address)) {
        check(sins_cpu_write16(board, address, value, cycles, &now_ps), "write");
    } else {
        sins_fw_io[address] = value;
        pending_cycles = cycles;
        if (pending_cycles >= flush_cycles) {
            flush_blocks();
        }
    }
    check_pie_enable(address, value);
    poll_valid = false;
    if ((address & 0xFF00u) == 0x0C00u || (address >= 0x7040u && address < 0x7050u) ||
        (address >= 0x5000u && address < 0x5064u)) {
        /* the timers, the PIE, SPI-A's and the McBSPs' interrupt enables and transfers */
        mark_irq_state_changed();
    }
    if (address >= 0x7010u && address < 0x7030u) {
        refresh_cycle();
        mark_irq_state_changed();
    }
    after_access();
}

extern "C" void sins_fw_delay_us(double microseconds) {
    if (!(microseconds >= 0.0)) {
        throw Failure{"DELAY_US(" + std::to_string(microseconds) + "): expected a time >= 0"};
    }
    poll_valid = false;
    pass_ps(static_cast<uint64_t>(microseconds * 1e6 + 0.5));
}

namespace {

uint16_t creg_read(int which) {
    uint16_t v = 0;
    check(sins_creg_read(board, which, &v), which == 0 ? "IER" : "IFR");
    return v;
}

void creg_write(int which, uint16_t value) {
    check(sins_creg_write(board, which, value), which == 0 ? "IER" : "IFR");
    if (which == 0) {
        check_ier_enable(value);
    }
    mark_irq_state_changed();
    after_access();
}

/* What a host address of an instrumented access is. */
enum class Place { Io, Vector, Creg, Image, Host };

/* The vector-table images of the firmware (globals of PieVectTable's type: TI's PieVectTableInit),
   which the pass's constructors register (sins_fw_vector_image). */
struct Image {
    uintptr_t base;
    uint64_t bytes;
};
constexpr size_t MAX_IMAGES = 16;
Image images[MAX_IMAGES];
size_t n_images = 0;
const Image *image_hit = nullptr; /* the image place_of found last */

/* A C28x vector is 32 bits: a word pair of PieVectTable, or of an image, as TI's InitPieVectTable
   copies them (`Uint32 *Dest = (void *)&PieVectTable; *Dest++ = *Source++;`). A 32-bit access of
   either is the vector of its index (byte offset / 4), whose host address (64 bits) a 32-bit value
   cannot hold: it reads as a handle, HANDLE_TAG | the address's index in `code` (0 for none), and a
   handle written is the address again. */
constexpr uint32_t HANDLE_TAG = 0x80000000u;
std::vector<uint64_t> &code = *new std::vector<uint64_t>;

uint32_t handle_of(uint64_t isr) {
    if (isr == 0) {
        return 0;
    }
    for (size_t k = 0; k < code.size(); k++) {
        if (code[k] == isr) {
            return HANDLE_TAG | static_cast<uint32_t>(k);
        }
    }
    code.push_back(isr);
    return HANDLE_TAG | static_cast<uint32_t>(code.size() - 1);
}

uint64_t isr_of(uint32_t handle, const char *where, uint64_t vector) {
    if (handle == 0) {
        return 0;
    }
    if ((handle & HANDLE_TAG) != 0 && (handle & ~HANDLE_TAG) < code.size()) {
        return code[handle & ~HANDLE_TAG];
    }
    char text[240];
    std::snprintf(text, sizeof text,
                  "a 32-bit store of 0x%08X to vector %llu of %s: on the host a vector holds an ISR's address, "
                  "which a 32-bit word read from PieVectTable or PieVectTableInit stands for (or 0)",
                  static_cast<unsigned>(handle), static_cast<unsigned long long>(vector), where);
    throw Failure{text};
}

Place place_of(const volatile void *p, uint64_t *index) {
    auto a = reinterpret_cast<uintptr_t>(p);
    auto io = reinterpret_cast<uintptr_t>(sins_fw_io);
    if (a - io < sizeof sins_fw_io) {
        *index = a - io; /* bytes */
        return Place::Io;
    }
    auto vec = reinterpret_cast<uintptr_t>(sins_fw_vectors);
    if (a - vec < sizeof sins_fw_vectors) {
        *index = a - vec;
        return Place::Vector;
    }
    auto creg = reinterpret_cast<uintptr_t>(sins_fw_cregs);
    if (a - creg < sizeof sins_fw_cregs) {
        *index = (a - creg) / 8;
        return Place::Creg;
    }
    for (size_t k = 0; k < n_images; k++) {
        if (a - images[k].base < images[k].bytes) {
            *index = a - images[k].base;
            image_hit = &images[k];
            return Place::Image;
        }
    }
    return Place::Host;
}

[[noreturn]] void bad_width(const char *what, uint64_t index, unsigned bits) {
    char text[160];
    std::snprintf(text, sizeof text, "a %u-bit access at byte %llu of %s: expected whole aligned words", bits,
                  static_cast<unsigned long long>(index), what);
    throw Failure{text};
}

/* An access of `bits` (8, 16, 32, 64) at a host address: a register of the data space word by word
   (low word first, as the C28x stores a 32-bit value), a vector, IER/IFR, or host memory. */
uint64_t load(const volatile void *p, unsigned bits) {
    uint64_t index = 0;
    switch (place_of(p, &index)) {
        case Place::Io: {
            uint32_t word = static_cast<uint32_t>(index / 2);
            if (bits == 8) {
                uint16_t w = sins_fw_read16(word);
                return (index & 1) ? w >> 8 : w & 0xFFu;
            }
            if (index & 1) {
                bad_width("the C28x data space", index, bits);
            }
            uint64_t v = 0;
            for (unsigned k = 0; k < bits / 16; k++) {
                v |= static_cast<uint64_t>(sins_fw_read16(word + k)) << (16 * k);
            }
            return v;
        }
        case Place::Vector: {
            if (bits == 32 && index % 4 == 0) {
                uint64_t v = 0;
                check(sins_vector(board, static_cast<uint32_t>(index / 4), &v), "PieVectTable");
                return handle_of(v);
            }
            if (bits != 64 || index % 8 != 0) {
                bad_width("PieVectTable", index, bits);
            }
            uint64_t v = 0;
            check(sins_vector(board, static_cast<uint32_t>(index / 8), &v), "PieVectTable");
            return v;
        }
        case Place::Creg: return creg_read(static_cast<int>(index));
        case Place::Image:
            if (bits == 32 && index % 4 == 0 && 2 * index < image_hit->bytes) {
                /* Word pair index / 4: the image's element of that index (8 bytes each). */
                return handle_of(*reinterpret_cast<const volatile uint64_t *>(image_hit->base + 2 * index));
            }
            break;
        case Place::Host: break;
    }
    switch (bits) {
        case 8: return *static_cast<const volatile uint8_t *>(p);
        case 16: return *static_cast<const volatile uint16_t *>(p);
        case 32: return *static_cast<const volatile uint32_t *>(p);
        default: return *static_cast<const volatile uint64_t *>(p);
    }
}

void store(volatile void *p, uint64_t v, unsigned bits) {
    uint64_t index = 0;
    switch (place_of(p, &index)) {
        case Place::Io: {
            uint32_t word = static_cast<uint32_t>(index / 2);
            if (bits == 8) {
                uint16_t w = sins_fw_read16(word);
                w = (index & 1) ? static_cast<uint16_t>((w & 0x00FFu) | (v & 0xFFu) << 8)
                                : static_cast<uint16_t>((w & 0xFF00u) | (v & 0xFFu));
                sins_fw_write16(word, w);
                return;
            }
            if (index & 1) {
                bad_width("the C28x data space", index, bits);
            }
            for (unsigned k = 0; k < bits / 16; k++) {
                sins_fw_write16(word + k, static_cast<uint16_t>(v >> (16 * k)));
            }
            return;
        }
        case Place::Vector: {
            if (bits == 32 && index % 4 == 0) {
                uint64_t isr = isr_of(static_cast<uint32_t>(v), "PieVectTable", index / 4);
                check(sins_set_vector(board, static_cast<uint32_t>(index / 4), isr), "PieVectTable");
                sins_fw_vectors[index / 4] = isr;
                return;
            }
            if (bits != 64 || index % 8 != 0) {
                bad_width("PieVectTable", index, bits);
            }
            check(sins_set_vector(board, static_cast<uint32_t>(index / 8), v), "PieVectTable");
            sins_fw_vectors[index / 8] = v;
            return;
        }
        case Place::Creg: creg_write(static_cast<int>(index), static_cast<uint16_t>(v)); return;
        case Place::Image:
            if (bits == 32 && index % 4 == 0 && 2 * index < image_hit->bytes) {
                *reinterpret_cast<volatile uint64_t *>(image_hit->base + 2 * index) =
                    isr_of(static_cast<uint32_t>(v), "a vector table", index / 4);
                return;
            }
            break;
        case Place::Host: break;
    }
    switch (bits) {
        case 8: *static_cast<volatile uint8_t *>(p) = static_cast<uint8_t>(v); break;
        case 16: *static_cast<volatile uint16_t *>(p) = static_cast<uint16_t>(v); break;
        case 32: *static_cast<volatile uint32_t *>(p) = static_cast<uint32_t>(v); break;
        default: *static_cast<volatile uint64_t *>(p) = v; break;
    }
}

}  // namespace

/* The pass's calls (firmware_c/pass/sins_fw_pass.cpp): one per volatile or register-object access. */
extern "C" {
uint8_t sins_fw_ld8(const volatile void *p) { access_pc = __builtin_return_address(0); return static_cast<uint8_t>(load(p, 8)); }
uint16_t sins_fw_ld16(const volatile void *p) { access_pc = __builtin_return_address(0); return static_cast<uint16_t>(load(p, 16)); }
uint32_t sins_fw_ld32(const volatile void *p) { access_pc = __builtin_return_address(0); return static_cast<uint32_t>(load(p, 32)); }
uint64_t sins_fw_ld64(const volatile void *p) { access_pc = __builtin_return_address(0); return load(p, 64); }
void sins_fw_st8(volatile void *p, uint8_t v) { access_pc = __builtin_return_address(0); store(p, v, 8); }
void sins_fw_st16(volatile void *p, uint16_t v) { access_pc = __builtin_return_address(0); store(p, v, 16); }
void sins_fw_st32(volatile void *p, uint32_t v) { access_pc = __builtin_return_address(0); store(p, v, 32); }
void sins_fw_st64(volatile void *p, uint64_t v) { access_pc = __builtin_return_address(0); store(p, v, 64); }

/* A vector-table image of the firmware (the pass's constructor, at load time). */
void sins_fw_vector_image(const void *base, uint64_t bytes) {
    if (n_images < MAX_IMAGES) {
        images[n_images++] = Image{reinterpret_cast<uintptr_t>(base), bytes};
    }
}

/* A memcpy or memmove (the pass's call) one of whose ends may be a register file or a vector table:
   element by element through load/store (64-bit words when either end is PieVectTable or an image,
   16-bit words for the data space), else the C library's memmove. */
void sins_fw_memcpy(void *dst, const void *src, uint64_t n) {
    access_pc = __builtin_return_address(0);
    uint64_t i = 0;
    Place pd = place_of(dst, &i);
    Place ps = place_of(src, &i);
    if ((pd == Place::Host || pd == Place::Image) && (ps == Place::Host || ps == Place::Image)) {
        std::memmove(dst, src, n);
        return;
    }
    unsigned bits = (pd == Place::Vector || ps == Place::Vector || pd == Place::Image || ps == Place::Image) ? 64 : 16;
    unsigned unit = bits / 8;
    if (n % unit != 0) {
        bad_width(pd == Place::Host || pd == Place::Image ? "a block copy's source" : "a block copy's destination", n, bits);
    }
    auto d = reinterpret_cast<uintptr_t>(dst);
    auto s = reinterpret_cast<uintptr_t>(src);
    bool backwards = d > s && d < s + n;
    for (uint64_t k = 0; k < n; k += unit) {
        uint64_t at = backwards ? n - unit - k : k;
        store(reinterpret_cast<volatile void *>(d + at), load(reinterpret_cast<const volatile void *>(s + at), bits), bits);
    }
}

/* A memset of a register file or a vector table (the pass's call): 16-bit words of the data space. */
void sins_fw_memset(void *dst, uint8_t value, uint64_t n) {
    access_pc = __builtin_return_address(0);
    uint64_t i = 0;
    Place pd = place_of(dst, &i);
    if (pd == Place::Host || pd == Place::Image) {
        std::memset(dst, value, n);
        return;
    }
    unsigned bits = pd == Place::Vector ? 64 : 16;
    unsigned unit = bits / 8;
    if (n % unit != 0) {
        bad_width("a memset's destination", n, bits);
    }
    uint64_t word = 0;
    for (unsigned k = 0; k < unit; k++) {
        word = word << 8 | value;
    }
    auto d = reinterpret_cast<uintptr_t>(dst);
    for (uint64_t k = 0; k < n; k += unit) {
        store(reinterpret_cast<volatile void *>(d + k), word, bits);
    }
}

/* An integer made a pointer at run time (the pass's call): a C28x data address is its word of the
   runtime's image of the data space; null and host addresses stay as they are. */
void *sins_fw_ptr(uint64_t value) {
    if (value != 0 && value < IO_WORDS) {
        return sins_fw_io + value;
    }
    return reinterpret_cast<void *>(static_cast<uintptr_t>(value));
}

/* TI's DSP2833x_usDelay.asm (a loop of SUB and a taken BF, 5 cycles a pass, plus the call and return):
   TI's DELAY_US computes Count from CPU_RATE for a delay of 5·Count + 9 cycles (DSP2833x_Examples.h);
   here those cycles pass in virtual time, interrupts taken meanwhile. */
void DSP28x_usDelay(uint32_t count) {
    poll_valid = false;
    pass_ps((5ull * count + 9ull) * cycle_ps);
}

/* TI's ADC_cal (DSP2833x_ADC_cal.asm, in TI's reserved OTP): it loads the factory trims into
   ADCREFSEL and ADCOFFTRIM. The ADC is not modelled and the factory values are the part's own: the
   two registers keep their reset values. */
void ADC_cal(void) {}

/* TI's DSP2833x_DBGIER.asm: DBGIER only matters under a debugger in real-time mode. */
void SetDBGIER(uint16_t value) { (void)value; }

/* TI's flash-to-RAM copy. The build gives the linker symbols of the `ramfuncs` section
   (firmware_build.placement_assembly): RamfuncsLoadStart…RamfuncsLoadEnd, its load image (in
   "flash": words of a fixed pattern, 8 per function the sources place there with `#pragma
   CODE_SECTION(f, "ramfuncs")`), RamfuncsRunStart, its run address (in "RAM": zeros until copied),
   and RamfuncsLoadSize. The host runs the functions where they are; what the copy decides is
   whether RAM holds them when they are called: the pass calls sins_fw_ramfunc at the entry of each
   such function, and a call before the copy (MemCopy, or memcpy) stops the run, as the chip would
   run whatever RAM held. */
extern const uint16_t RamfuncsLoadStart[], RamfuncsLoadEnd[];
extern uint16_t RamfuncsRunStart[];

void sins_fw_ramfunc(const char *name) {
    size_t n = static_cast<size_t>(RamfuncsLoadEnd - RamfuncsLoadStart);
    if (cfg != nullptr && std::memcmp(RamfuncsRunStart, RamfuncsLoadStart, n * sizeof(uint16_t)) != 0) {
        throw Failure{std::string(name) +
                      "() is placed in section ramfuncs (#pragma CODE_SECTION): it runs from RAM, but the "
                      "firmware called it before copying the section there (MemCopy(&RamfuncsLoadStart, "
                      "&RamfuncsLoadEnd, &RamfuncsRunStart), or memcpy(&RamfuncsRunStart, &RamfuncsLoadStart, "
                      "(Uint32)&RamfuncsLoadSize)): on the chip it would execute whatever RAM holds"};
    }
}
}

extern "C" void sins_fw_asm(const char *text) {
    std::string op;
    for (const char *c = text; *c != '\0'; c++) {
        if (!std::isspace(static_cast<unsigned char>(*c))) {
            op += static_cast<char>(std::toupper(static_cast<unsigned char>(*c)));
        } else if (!op.empty() && op.back() != ' ') {
            op += ' ';
        }
    }
    while (!op.empty() && op.back() == ' ') {
        op.pop_back();
    }
    if (op == "EALLOW" || op == "EDIS") {
        check(sins_set_eallow(board, op == "EALLOW"), "EALLOW");
    } else if (op == "CLRC INTM" || op == "SETC INTM") {
        check(sins_set_intm(board, op == "SETC INTM"), "INTM");
        mark_irq_state_changed();
        after_access();
    } else if (op.rfind("RPT #", 0) == 0 && op.size() > 12 && op.compare(op.size() - 7, 7, " || NOP") == 0) {
        /* `RPT #N || NOP` (TI's InitFlash waits for the pipeline so): the NOP N + 1 times, and the RPT. */
        char *end = nullptr;
        unsigned long n = std::strtoul(op.c_str() + 5, &end, 0);
        if (end == op.c_str() + 5 || n > 255) {
            throw Failure{std::string("asm(\"") + text + "\"): expected RPT #0...255 || NOP"};
        }
        pending_cycles += n + 2;
    } else if (op == "CLRC DBGM" || op == "SETC DBGM" || op == "NOP" || op == "ESTOP0") {
        /* The real-time debug mode and emulation stops have no effect on the emulated board. */
    } else if (op == "IDLE") {
        /* Wait for the next interrupt: time passes up to it. */
        flush_blocks();
        if (irq_at == UINT64_MAX) {
            throw Failure{"asm(\" IDLE\"): no interrupt can wake the CPU"};
        }
        pass_ps(irq_at > now_ps ? irq_at - now_ps : 0);
    } else {
        throw Failure{std::string("asm(\"") + text + "\"): the host build emulates EALLOW, EDIS, clrc/setc INTM, " +
                      "clrc/setc DBGM, NOP, RPT #n || NOP, ESTOP0 and IDLE only"};
    }
}

/* The build's LLVM pass prices each basic block of the firmware's own code in C28x cycles from its
   optimised IR (firmware_c/pass/sins_fw_pass.cpp, SinsFwCyclePass; the prices: docs/c-cycles.md) and
   calls sins_fw_block at the block's start with them and its function's counter (sins_fw_enter at a
   function's entry block, which also counts the call) and sins_fw_leave before each return. The
   counters: {self cycles, calls, inclusive cycles, frames running}, one per function, listed by the
   pass's table {name, counter} in the section `sins_fw_functions`. Inclusive cycles are the
   function's own and its callees' (priced) cycles from its entry to its return, counted once for a
   recursive function (at its outermost frame's return); a function that has not returned has none. */
struct FunctionRow {
    const char *name;
    uint64_t *counter;
};
extern "C" {
extern const FunctionRow __start_sins_fw_functions[] __attribute__((weak));
extern const FunctionRow __stop_sins_fw_functions[] __attribute__((weak));
}

__attribute__((always_inline)) static inline void charge_block(uint32_t cycles) {
    blocks++;
    fn_clock += cycles;
    last_pc = __builtin_return_address(0);
    pending_cycles += cycles;
    if (++blocks_since_access >= cfg->spin_blocks && blocks_since_access % cfg->spin_blocks == 0) {
        spin_check(__builtin_return_address(0));
    }
    if (pending_cycles >= flush_cycles) {
        flush_blocks();
    }
}

extern "C" void sins_fw_block(uint32_t cycles, uint64_t *counter) {
    if (cfg == nullptr) {
        return; /* static constructors, before a run */
    }
    counter[0] += cycles;
    charge_block(cycles);
}

extern "C" void sins_fw_enter(uint32_t cycles, uint64_t *counter) {
    if (cfg == nullptr) {
        return;
    }
    counter[0] += cycles;
    counter[1] += 1;
    counter[3] += 1;
    fn_stack.push_back(Frame{counter, fn_clock});
    charge_block(cycles);
}

extern "C" void sins_fw_leave(uint64_t *counter) {
    if (cfg == nullptr) {
        return;
    }
    /* Frames above this function's (left by longjmp) end here too. */
    while (!fn_stack.empty()) {
        Frame f = fn_stack.back();
        fn_stack.pop_back();
        if (f.counter[3] > 0 && --f.counter[3] == 0) {
            f.counter[2] += fn_clock - f.clock;
        }
        if (f.counter == counter) {
            return;
        }
    }
}

/* The function records of the ISRs run since the last call (see fn_rows): up to `capacity` records of
   5 words into `out`; returns how many. */
extern "C" size_t sins_fw_function_rows_ready(void) { return fn_rows.size() / 5; }

extern "C" size_t sins_fw_take_function_rows(uint64_t *out, size_t capacity) {
    size_t have = fn_rows.size() / 5;
    size_t n = have < capacity ? have : capacity;
    std::memcpy(out, fn_rows.data(), n * 5 * sizeof(uint64_t));
    fn_rows.erase(fn_rows.begin(), fn_rows.begin() + static_cast<long>(n * 5));
    return n;
}

/* The functions priced: how many, and the i-th's name, self cycles and calls in this run. */
extern "C" size_t sins_fw_function_count(void) {
    return __start_sins_fw_functions == nullptr
               ? 0
               : static_cast<size_t>(__stop_sins_fw_functions - __start_sins_fw_functions);
}

extern "C" const char *sins_fw_function_at(size_t i, uint64_t *cycles, uint64_t *calls) {
    if (i >= sins_fw_function_count()) {
        return nullptr;
    }
    const FunctionRow &r = __start_sins_fw_functions[i];
    *cycles = r.counter[0];
    *calls = r.counter[1];
    return r.name;
}

namespace {
size_t function_total() { return sins_fw_function_count(); }
uint64_t *function_counter(size_t i) { return __start_sins_fw_functions[i].counter; }
}  // namespace

/* The i-th function's inclusive cycles in this run (0 past the end). */
extern "C" uint64_t sins_fw_function_inclusive(size_t i) {
    return i < sins_fw_function_count() ? __start_sins_fw_functions[i].counter[2] : 0;
}

static void reset_function_cycles() {
    for (size_t i = 0; i < sins_fw_function_count(); i++) {
        std::memset(__start_sins_fw_functions[i].counter, 0, 4 * sizeof(uint64_t));
    }
    fn_stack.clear();
    fn_rows.clear();
    fn_clock = 0;
    rows_recorded = 0;
}

/* $SINS_FW_FUNCTION_CYCLES names a file: at the end of a run the runtime writes there, one line a
   function that ran, `name<TAB>self cycles<TAB>calls` (a flat profile of the run, in C28x cycles). */
static void write_function_cycles() {
    const char *path = std::getenv("SINS_FW_FUNCTION_CYCLES");
    if (path == nullptr || *path == 0) {
        return;
    }
    FILE *f = std::fopen(path, "w");
    if (f == nullptr) {
        return;
    }
    for (size_t i = 0; i < sins_fw_function_count(); i++) {
        const FunctionRow &r = __start_sins_fw_functions[i];
        if (r.counter[1] != 0 || r.counter[0] != 0) {
            std::fprintf(f, "%s\t%llu\t%llu\n", r.name, static_cast<unsigned long long>(r.counter[0]),
                         static_cast<unsigned long long>(r.counter[1]));
        }
    }
    std::fclose(f);
}

/* Called at each pass of an empty endless loop (`for (;;) {}`: the pass calls this instead of
   sins_fw_block, with the pass's cycles). The loop does nothing, so the passes up to the next
   interrupt (or the end of the input pushed so far) are charged at once, in whole passes; with no
   interrupt possible the loop can never end: an error. */
extern "C" void sins_fw_idle(uint32_t cycles) {
    if (cfg == nullptr) {
        return;
    }
    last_pc = __builtin_return_address(0);
    if (irq_at == UINT64_MAX) {
        spin_check(last_pc);
    }
    uint64_t pass = cycles == 0 ? 1 : cycles;
    uint64_t passes = flush_cycles > pending_cycles ? (flush_cycles - pending_cycles + pass - 1) / pass : 1;
    if (passes == 0) {
        passes = 1;
    }
    blocks += passes;
    blocks_since_access += passes;
    pending_cycles += passes * pass;
    flush_blocks();
}

extern "C" int sins_fw_run(const SinsFwConfig *config, char *message, size_t message_len) {
    int rc = 0;
    std::string text;
    cfg = config;
    board = config->board;
    n_globals = config->n_globals;
    accesses = blocks = blocks_since_access = fault_offset = pending_cycles = 0;
    reset_function_cycles();
    isr_depth = 0;
    isr_vector = -1;
    last_pc = nullptr;
    poll_valid = false;
    row_times.clear();
    row_values.clear();
    try {
        if (config->spin_blocks == 0 || config->more_input == nullptr) {
            throw Failure{"sins_fw_run: spin_blocks must be > 0 and more_input set"};
        }
        /* One cycle in ps, rounded up: the time between two cycle boundaries is at most this. */
        uint64_t c0 = 0;
        read_now();
        c0 = now_ps;
        check(sins_advance_cycles(board, 1), "time");
        read_now();
        cycle_ps = now_ps - c0;
        cycle_ps_ceil = cycle_ps + 1;
        refresh_input();
        irq_at = 0;
        update_flush();
        reset_io();
        if (sins_fw_user_main != nullptr) {
            sins_fw_user_main();
        } else if (sins_fw_user_main_cxx != nullptr) {
            sins_fw_user_main_cxx();
        } else {
            throw Failure{"the firmware has no main"};
        }
    } catch (const TraceEnd &) {
        if (isr_depth > 0 && now_ps > isr_deadline_ps) {
            /* The input ended inside an ISR past its deadline (the next tick): an ISR cut by the end
               of the input within its period is not an error, one that has not returned by then is. */
            rc = 3;
            char when[320];
            std::snprintf(when, sizeof when,
                          "the ISR of PIE vector %d%s, entered at t = %.9f s, had not returned when the input "
                          "ended at t = %.9f s (its deadline, the next tick: t = %.9f s)",
                          isr_vector, (std::string(" (") + vector_name(isr_vector) + ")").c_str(), isr_entry_end_ps * 1e-12, now_ps * 1e-12,
                          isr_deadline_ps * 1e-12);
            text = when;
            Dl_info info;
            if (last_pc != nullptr && dladdr(last_pc, &info) != 0 && info.dli_fbase != nullptr) {
                fault_offset = reinterpret_cast<uintptr_t>(last_pc) - reinterpret_cast<uintptr_t>(info.dli_fbase);
            }
        }
    } catch (const Failure &f) {
        rc = 2;
        text = f.message;
    }
    cfg = nullptr;
    write_function_cycles();
    if (message != nullptr && message_len > 0) {
        std::snprintf(message, message_len, "%s", text.c_str());
    }
    return rc;
}

/* The ISR rows recorded since the last call: up to `capacity` rows (ROW_TIMES times and the watched
   globals' values each) into the arrays; returns how many. */
extern "C" size_t sins_fw_take_rows(uint64_t *times, double *values, size_t capacity) {
    size_t per = n_globals;
    size_t have = row_times.size() / ROW_TIMES;
    size_t n = have < capacity ? have : capacity;
    std::memcpy(times, row_times.data(), n * ROW_TIMES * sizeof(uint64_t));
    if (per > 0) {
        std::memcpy(values, row_values.data(), n * per * sizeof(double));
    }
    row_times.erase(row_times.begin(), row_times.begin() + static_cast<long>(n * ROW_TIMES));
    row_values.erase(row_values.begin(), row_values.begin() + static_cast<long>(n * per));
    return n;
}

/* The size of the firmware's `double`, bytes: 4 in the C28x float mode (TI's COFF ABI), else the
   host's 8. The harness reads a watched global of type "double" with it. */
#ifdef SINS_FW_C28X_FLOAT
extern "C" const int sins_fw_double_bytes = 4;
#else
extern "C" const int sins_fw_double_bytes = static_cast<int>(sizeof(double));
#endif

/* The earliest time (ps) a bus-log record may still matter to an ISR row not yet recorded: the end of
   the entry of the ISR running, else now (every later ISR starts after it). */
extern "C" uint64_t sins_fw_isr_floor_ps(void) { return isr_depth > 0 ? isr_entry_end_ps : now_ps; }

extern "C" size_t sins_fw_rows_ready(void) { return row_times.size() / ROW_TIMES; }
extern "C" uint64_t sins_fw_accesses(void) { return accesses; }
extern "C" uint64_t sins_fw_blocks(void) { return blocks; }
/* The offset in the firmware library of the loop a spin error names (0: none). */
extern "C" uint64_t sins_fw_fault_offset(void) { return fault_offset; }

/* The crash report (see the header comment): the record, then what the run had not yet handed over
   (report_pending), to a file the harness reads once the process is gone. */
namespace {

constexpr uint64_t CRASH_MAGIC = 0x53494e53465743ULL; /* "SINSFWC" */
constexpr int CRASH_FRAMES = 48;
struct CrashRecord {
    uint64_t magic;
    int64_t signal; /* 0: exit() */
    int64_t code;
    uint64_t fault_address;
    uint64_t pc;
    uint64_t base;
    uint64_t n_frames;
    uint64_t frames[CRASH_FRAMES];
};
int crash_fd = -1;
alignas(16) char crash_stack[1 << 18];
volatile sig_atomic_t crash_reported = 0;

bool write_all(const void *data, size_t n) {
    const char *p = static_cast<const char *>(data);
    while (n > 0) {
        ssize_t k = write(crash_fd, p, n);
        if (k <= 0) {
            return false;
        }
        p += k;
        n -= static_cast<size_t>(k);
    }
    return true;
}

/* One event as the crash report writes it. */
struct CrashEvent {
    uint64_t t_ps;
    int64_t frame;
    double measured;
    double required;
    uint64_t severity;
    char kind[40];
    char message[256];
};

/* What the run had computed and not yet handed to the harness: the ISR rows (always: plain memory
   of this runtime), then, when the code interrupted is the firmware's own or abort()/exit() (not
   the emulator's or the C library's, which might hold a lock), the events and the bus log. */
void report_pending(bool board_safe) {
    uint64_t head[2] = {row_times.size() / ROW_TIMES, n_globals};
    if (!write_all(head, sizeof head) || !write_all(row_times.data(), head[0] * ROW_TIMES * sizeof(uint64_t)) ||
        !write_all(row_values.data(), head[0] * n_globals * sizeof(double))) {
        return;
    }
    uint64_t safe = board_safe && board != nullptr ? 1 : 0;
    write_all(&safe, sizeof safe);
    if (!safe) {
        return;
    }
    SinsEvent ev;
    CrashEvent out;
    int got = 1;
    while (got) {
        std::memset(&out, 0, sizeof out);
        if (sins_take_event(board, &ev, out.message, sizeof out.message, &out.measured, &out.required, &got) != SINS_OK) {
            got = 0;
        }
        uint64_t more = got ? 1 : 0;
        write_all(&more, sizeof more);
        if (got) {
            out.t_ps = ev.t_ps;
            out.frame = ev.frame;
            out.severity = ev.severity;
            std::memcpy(out.kind, ev.kind, sizeof out.kind);
            write_all(&out, sizeof out);
        }
    }
    SinsBusRecord records[256];
    size_t n = 0;
    do {
        if (sins_take_bus_log(board, records, 256, &n) != SINS_OK) {
            n = 0;
        }
        uint64_t k = n;
        write_all(&k, sizeof k);
        write_all(records, n * sizeof(SinsBusRecord));
    } while (n == 256);
    uint64_t end = 0;
    write_all(&end, sizeof end);
}

void report(int sig, const siginfo_t *info, const void *context) {
    if (crash_fd < 0 || crash_reported) {
        return;
    }
    crash_reported = 1;
    CrashRecord r = {};
    r.magic = CRASH_MAGIC;
    r.signal = sig;
    if (info != nullptr) {
        r.code = info->si_code;
        r.fault_address = reinterpret_cast<uintptr_t>(info->si_addr);
    }
    if (context != nullptr) {
        const ucontext_t *uc = static_cast<const ucontext_t *>(context);
#if defined(__x86_64__)
        r.pc = static_cast<uint64_t>(uc->uc_mcontext.gregs[REG_RIP]);
#elif defined(__aarch64__)
        r.pc = uc->uc_mcontext.pc;
#else
        (void)uc;
#endif
    }
    Dl_info self;
    if (dladdr(reinterpret_cast<const void *>(&report), &self) != 0) {
        r.base = reinterpret_cast<uintptr_t>(self.dli_fbase);
    }
    void *frames[CRASH_FRAMES];
    int n = backtrace(frames, CRASH_FRAMES);
    r.n_frames = n > 0 ? static_cast<uint64_t>(n) : 0;
    for (int i = 0; i < n; i++) {
        r.frames[i] = reinterpret_cast<uintptr_t>(frames[i]);
    }
    if (!write_all(&r, sizeof r)) {
        return;
    }
    bool in_firmware = false;
    Dl_info where;
    if (r.pc != 0 && dladdr(reinterpret_cast<const void *>(static_cast<uintptr_t>(r.pc)), &where) != 0) {
        in_firmware = where.dli_fbase == self.dli_fbase;
    }
    report_pending(cfg != nullptr && (sig == 0 || sig == SIGABRT || in_firmware));
}

void on_fatal_signal(int sig, siginfo_t *info, void *context) {
    report(sig, info, context);
    /* SA_RESETHAND restored the default action: raise it again (a fault repeats at once anyway). */
    signal(sig, SIG_DFL);
    raise(sig);
}

void on_exit_call() { report(0, nullptr, nullptr); }

__attribute__((constructor(101))) void install_crash_report() {
    const char *fd = getenv("SINS_FW_CRASH_FD");
    if (fd == nullptr || *fd == '\0') {
        return;
    }
    crash_fd = atoi(fd);
    void *warm[2];
    backtrace(warm, 2); /* loads the unwinder now, not inside a signal handler */
    stack_t ss = {};
    ss.ss_sp = crash_stack;
    ss.ss_size = sizeof crash_stack;
    sigaltstack(&ss, nullptr);
    struct sigaction sa = {};
    sa.sa_sigaction = on_fatal_signal;
    sa.sa_flags = SA_SIGINFO | SA_ONSTACK | SA_RESETHAND;
    sigemptyset(&sa.sa_mask);
    for (int sig : {SIGSEGV, SIGBUS, SIGILL, SIGFPE, SIGABRT, SIGTRAP, SIGSYS}) {
        sigaction(sig, &sa, nullptr);
    }
    atexit(on_exit_call);
}

}  // namespace
