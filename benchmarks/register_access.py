"""The cost of one register access of a host-built firmware against the cost of a function call, by
the mechanism issue 37 chose (compiler-instrumented volatile accesses: the build's LLVM pass makes each
a call into the runtime) and by the fallback it rejected (register structs in trapped pages: a
SIGSEGV, the page unprotected, a single step, a SIGTRAP, the page protected again).

A firmware built by ``build_firmware`` times, with the host's clock, ``--n`` passes of: a call to a
non-inlined function (the unit), a volatile read of a firmware global (the pass's call, host memory),
reads of registers of a peripheral not modelled (SysCtrlRegs.PCLKCR0 and PCLKCR1 in turn: the
runtime's image of the data space, their cycles charged to the board), and reads of modelled registers
(SpiaRegs.SPIBRR and SPICCR in turn, so that no read looks like a polling loop: the emulated SPI-A),
and the same reads by a direct call of the runtime's sins_fw_read16 (what the C++ register proxies
called before: the difference is the mechanism's own cost). A small C program times the trapped
page the same way. Medians of ``--rounds`` (each the fastest of 7 passes inside the firmware); ns
per access and as a multiple of the call. Each loop pass also carries the coverage call of its basic
block, in all rows alike.

    python benchmarks/register_access.py [--n 200000] [--rounds 5] \
        [--output benchmarks/register_access.md]
"""

from __future__ import annotations

import argparse
import datetime
import platform
import statistics
import subprocess
import tempfile
from pathlib import Path

from sins_fw.atomic import write_text
from sins_fw.firmware_build import CLANG, build_firmware
from sins_fw.firmware_run import run_c_firmware
from sins_fw.profile import load_profile

FIRMWARE = r"""
#include "DSP28x_Project.h"
#include <time.h>
float call_ns, host_ns, plain_reg_ns, model_reg_ns, direct_ns;
Uint16 sins_fw_read16(Uint32 address);
volatile Uint16 flag;
__attribute__((noinline)) Uint16 unit(volatile Uint16 *p) {
    __asm__ volatile("" ::: "memory");
    return 1;
}
static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1e9 + t.tv_nsec;
}
static float lowest(float a, double b) { return a == 0 || b < a ? (float)b : a; }
void main(void) {
    long i, r, n = N;
    Uint32 s = 0;
    for (r = 0; r < 7; r++) { /* the fastest of 7 passes of each: the host's other load left out */
        double t0 = now();
        for (i = 0; i < n; i++) s += unit(&flag);
        double t1 = now();
        for (i = 0; i < n; i++) s += flag;
        double t2 = now();
        for (i = 0; i < n; i++) s += SysCtrlRegs.PCLKCR0.all + SysCtrlRegs.PCLKCR1.all;
        double t3 = now();
        for (i = 0; i < n; i++) s += SpiaRegs.SPIBRR + SpiaRegs.SPICCR.all;
        double t4 = now();
        for (i = 0; i < n; i++) s += sins_fw_read16(0x7044) + sins_fw_read16(0x7040);
        double t5 = now();
        call_ns = lowest(call_ns, (t1 - t0) / n);
        host_ns = lowest(host_ns, (t2 - t1) / n);
        plain_reg_ns = lowest(plain_reg_ns, (t3 - t2) / (2 * n));
        model_reg_ns = lowest(model_reg_ns, (t4 - t3) / (2 * n));
        direct_ns = lowest(direct_ns, (t5 - t4) / (2 * n));
    }
    flag = (Uint16)s;
}
"""

TRAP = r"""
#define _GNU_SOURCE
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <sys/mman.h>
#include <time.h>
#include <ucontext.h>
static volatile uint16_t *page;
static void on_segv(int sig, siginfo_t *si, void *c) {
    (void)sig; (void)si;
    mprotect((void *)page, 4096, PROT_READ | PROT_WRITE);
    ((ucontext_t *)c)->uc_mcontext.gregs[REG_EFL] |= 0x100;
}
static void on_trap(int sig, siginfo_t *si, void *c) {
    (void)sig; (void)si;
    mprotect((void *)page, 4096, PROT_NONE);
    ((ucontext_t *)c)->uc_mcontext.gregs[REG_EFL] &= ~0x100;
}
static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1e9 + t.tv_nsec;
}
int main(int argc, char **argv) {
    int n = argc > 1 ? atoi(argv[1]) : 10000;
    uint32_t s = 0;
    page = mmap(0, 4096, PROT_NONE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    struct sigaction a = {0};
    a.sa_flags = SA_SIGINFO; a.sa_sigaction = on_segv; sigaction(SIGSEGV, &a, 0);
    a.sa_sigaction = on_trap; sigaction(SIGTRAP, &a, 0);
    double t0 = now();
    for (int i = 0; i < n; i++) s += page[i & 7];
    printf("%f %u\n", (now() - t0) / n, s);
    return 0;
}
"""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=200_000)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--output", type=Path)
    args = ap.parse_args()
    names = ("call_ns", "host_ns", "plain_reg_ns", "model_reg_ns", "direct_ns")
    with tempfile.TemporaryDirectory() as work:
        folder = Path(work)
        src = folder / "bench.c"
        src.write_text(FIRMWARE.replace("N;", f"{args.n};"))
        fw = build_firmware([src], folder / "bench.so")
        gfile = folder / "globals.toml"
        gfile.write_text(
            "".join(f'[[global]]\nname = "{n}"\ntype = "float"\ncolumn = "{n}"\nunit = "ns"\n' for n in names)
        )
        runs = [
            run_c_firmware(fw, None, load_profile("reference"), globals_file=gfile, until_s=3600).final
            for _ in range(args.rounds)
        ]
        (folder / "trap.c").write_text(
            TRAP.replace("#include <stdio.h>", "#include <stdio.h>\n#include <stdlib.h>")
        )
        subprocess.run([CLANG, "-O2", str(folder / "trap.c"), "-o", str(folder / "trap")], check=True)
        traps = [
            float(
                subprocess.run(
                    [str(folder / "trap"), "2000"], capture_output=True, text=True, check=True
                ).stdout.split()[0]
            )
            for _ in range(args.rounds)
        ]
    med = {n: statistics.median(r[n] for r in runs) for n in names}
    med["trap_ns"] = statistics.median(traps)
    unit = med["call_ns"]
    rows = [
        ("a call to a non-inlined function (the unit)", "call_ns"),
        ("a volatile read of a firmware global (the pass's call, host memory)", "host_ns"),
        (
            "a read of a register not modelled (SysCtrlRegs.PCLKCR0/1: plain memory, cycles charged)",
            "plain_reg_ns",
        ),
        ("a read of a modelled register (SpiaRegs.SPIBRR/SPICCR: the emulated SPI-A)", "model_reg_ns"),
        (
            "the same reads by a direct call of the runtime (the path of the former C++ register proxies)",
            "direct_ns",
        ),
        ("a read in a trapped page (SIGSEGV, single step, SIGTRAP: the rejected fallback)", "trap_ns"),
    ]
    text = [
        "# The cost of a register access (benchmarks/register_access.py)",
        "",
        f"{datetime.date.today()}, {platform.machine()}, {platform.python_version()}; "
        f"`python benchmarks/register_access.py --n {args.n} --rounds {args.rounds}`; medians of "
        f"{args.rounds} runs, the host's wall clock inside the firmware.",
        "",
        "| access | ns | × a call |",
        "|---|---:|---:|",
        *(f"| {label} | {med[key]:.1f} | {med[key] / unit:.1f} |" for label, key in rows),
        "",
    ]
    print("\n".join(text))
    if args.output:
        write_text(args.output, "\n".join(text))


if __name__ == "__main__":
    main()
