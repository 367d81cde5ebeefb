"""The host-built C firmware against the Rust model, on the same trace: register accesses per second
and emulated SYSCLKOUT cycles per second (virtual time × SYSCLKOUT / host CPU time) of the
`firmware_c/examples/timer0_burst` firmware (timer 0 ISR every 4 ms doing the 15-frame ADIS16407
burst; main idles in `for (;;) {}`), beside the reference profile's Rust model (the same burst every
4 ms plus the RK4 attitude update every 8 ms). Host CPU time of the run alone, the firmware's
process included (it runs in a child process: sins_fw.firmware_child; its CPU time is counted once
it is reaped, at the run's end): the build and the trace's first read are outside it. Each is run
``--rounds`` times; figures are medians.

Also measured (each in the same way):

- the isolation's fixed cost: a run of 10 ms of trace (the fork, the library's load, the pipes),
  beside what a fresh interpreter costs to import the harness (the price of a spawned runner);
- SPI outside an interrupt (the burst polled in main back to back, no ISR): 2.5, 5 and 10 s of
  trace, which must cost time in proportion (issue 37, item 4: it was quadratic);
- watched globals: 100, 1 000 and 3 000 globals, `sins-fw run --firmware … --out run.csv` in a
  process of its own (CPU time and peak resident memory of the command and of the firmware's
  process it forks, which shares its pages at the fork), which must cost time in proportion to the
  globals (issue 42, item 7: it was quadratic).

    python benchmarks/c_firmware.py [--duration-s 60] [--rounds 3] [--output benchmarks/c_firmware.md]
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from sins_fw.atomic import write_text
from sins_fw.firmware_build import build_firmware
from sins_fw.firmware_run import run_c_firmware
from sins_fw.harness import emulate
from sins_fw.profile import load_profile
from sins_fw.traces import PhysicalTrace

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "firmware_c" / "examples" / "timer0_burst"
TRACE = ROOT / "python" / "sins_fw" / "bundled_traces" / "pitch_sweep.h5"
SYSCLKOUT_HZ = 150e6

#: The timer0_burst firmware's burst, polled in main back to back (a frame every ~23 µs, each raising
#: the device's `stall_too_short`: no wait between frames), no interrupt at all.
SPI_IN_MAIN = """#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"
Uint16 burst[15];
Uint32 bursts;
static Uint16 spi_xmit(Uint16 a) {
    while (SpiaRegs.SPISTS.bit.BUFFULL_FLAG == 1) {
    }
    SpiaRegs.SPITXBUF = a;
    while (SpiaRegs.SPISTS.bit.INT_FLAG != 1) {
    }
    return SpiaRegs.SPIRXBUF;
}
void main(void) {
    Uint16 i;
    InitSysCtrl();
    DINT;
    GpioDataRegs.GPBSET.bit.GPIO57 = 1;
    SpiaRegs.SPICCR.all = 0x004F;
    SpiaRegs.SPICTL.all = 0x0006;
    SpiaRegs.SPIBRR = 49;
    SpiaRegs.SPICCR.all = 0x00CF;
    SpiaRegs.SPIPRI.all = 0x0020;
    for (;;) {
        GpioDataRegs.GPBCLEAR.bit.GPIO57 = 1;
        for (i = 0; i < 15; i++) {
            if (i > 0) {
                DELAY_US(0.5);
            }
            burst[i] = spi_xmit(i == 0 ? 0x4200 : 0x0000);
        }
        GpioDataRegs.GPBSET.bit.GPIO57 = 1;
        bursts++;
    }
}
"""


#: Runs the command given and prints its CPU time (s) and the largest resident set of it and the
#: firmware's process (KiB; RUSAGE_CHILDREN's ru_maxrss is the largest of the children reaped).
_WRAPPER = (
    "import resource, subprocess, sys\n"
    "subprocess.run(sys.argv[1:], check=True, stdout=subprocess.DEVNULL)\n"
    "r = resource.getrusage(resource.RUSAGE_CHILDREN)\n"
    "print(r.ru_utime + r.ru_stime, r.ru_maxrss)\n"
)


def _cpu() -> float:
    """CPU time of this process and of its reaped children, s."""
    me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime


def _timed(fn: Callable[[], Any], rounds: int) -> tuple[float, Any]:
    runs = []
    for _ in range(rounds):
        t = _cpu()
        r = fn()
        runs.append((_cpu() - t, r))
    return statistics.median(x[0] for x in runs), runs[0][1]


def _globals_firmware(tmp: Path, n: int) -> tuple[Path, Path]:
    """timer0_burst with ``n`` more globals, each set by the ISR, and a globals file watching them."""
    src = (EXAMPLE / "main.c").read_text(encoding="utf-8")
    decl = f"float64 watched[{n}];\n"
    body = "    for (i = 0; i < " + str(n) + "; i++) {\n        watched[i] = rate_x + i;\n    }\n"
    src = src.replace("Uint32 isr_count;\n", "Uint32 isr_count;\n" + decl)
    src = src.replace(
        "    isr_count = CpuTimer0.InterruptCount;\n", "    isr_count = CpuTimer0.InterruptCount;\n" + body
    )
    folder = tmp / f"globals_{n}"
    folder.mkdir()
    (folder / "main.c").write_text(src, encoding="utf-8")
    fw = build_firmware([folder / "main.c"], folder / "fw.so")
    g = folder / "globals.toml"
    g.write_text(
        "".join(
            f'[[global]]\nname = "watched[{i}]"\ntype = "double"\ncolumn = "w{i}"\nunit = "1"\n\n'
            for i in range(n)
        ),
        encoding="utf-8",
    )
    return fw, g


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration-s", type=float, default=60.0)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--output", type=Path)
    args = ap.parse_args()
    profile = load_profile("reference")
    trace = PhysicalTrace.load(TRACE)
    subprocess.run(
        ["cargo", "build", "--release", "-p", "sins-cabi"], cwd=ROOT, check=True, capture_output=True
    )
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        fw = build_firmware([EXAMPLE], tmp / "timer0_burst.so")
        c_cpu, c = _timed(
            lambda: run_c_firmware(
                fw, trace, profile, globals_file=EXAMPLE / "globals.toml", until_s=args.duration_s
            ),
            args.rounds,
        )
        rust_cpu, rust = _timed(lambda: emulate(trace, profile, until_s=args.duration_s), args.rounds)
        fixed_cpu, _ = _timed(
            lambda: run_c_firmware(fw, trace, profile, globals_file=EXAMPLE / "globals.toml", until_s=0.01),
            args.rounds,
        )
        spawn_cpu, _ = _timed(
            lambda: subprocess.run([sys.executable, "-c", "import sins_fw.firmware_run"], check=True),
            args.rounds,
        )
        (tmp / "spi_main.c").write_text(SPI_IN_MAIN, encoding="utf-8")
        spi_fw = build_firmware([tmp / "spi_main.c"], tmp / "spi_main.so")
        spi = []
        for seconds in (2.5, 5.0, 10.0):
            cpu, r = _timed(lambda s=seconds: run_c_firmware(spi_fw, trace, profile, until_s=s), args.rounds)
            spi.append((seconds, cpu, r))
        watched = []
        for n in (100, 1000, 3000):
            gfw, gfile = _globals_firmware(tmp, n)
            cmd = [
                sys.executable,
                "-m",
                "sins_fw",
                "run",
                str(TRACE),
                "--firmware",
                str(gfw),
                "--globals",
                str(gfile),
            ]
            cmd += ["--until-s", "3", "--out", str(tmp / f"run_{n}.csv")]
            # Run under a small wrapper process whose only children are the command and the
            # firmware's process it forks: their CPU time and largest resident set are the command's.
            wall = time.perf_counter()
            measured = subprocess.run(
                [sys.executable, "-c", _WRAPPER, *cmd], check=True, capture_output=True, text=True
            )
            wall = time.perf_counter() - wall
            cpu, rss_kib = (float(x) for x in measured.stdout.split())
            watched.append((n, cpu, wall, rss_kib / 1024))
    rust_virtual = float(rust.budget["tick_ps"][-1]) * 1e-12
    load = os.getloadavg()
    lines = [
        "# Host-built C firmware vs the Rust model (benchmarks/c_firmware.py)",
        "",
        f"- date: {datetime.datetime.now(datetime.UTC).strftime('%Y-%m-%d %H:%M UTC')}",
        f"- machine: {platform.machine()}, {os.cpu_count()} CPUs, {platform.platform()}, "
        f"Python {platform.python_version()}; load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}",
        "- command: `python benchmarks/c_firmware.py "
        f"--duration-s {args.duration_s:g} --rounds {args.rounds}`",
        f"- trace: {TRACE.name}, first {args.duration_s:g} s; host CPU time of the run (the firmware's "
        f"process included), median of {args.rounds}",
        "",
        "| emulator | virtual s | ISRs | register accesses | host CPU s | accesses/s | emulated cycles/s "
        "| × real time |",
        "|---|---|---|---|---|---|---|---|",
        f"| C firmware (timer0_burst) | {c.now_s:.3f} | {c.isr_rows} | {c.accesses} | {c_cpu:.3f} | "
        f"{c.accesses / c_cpu:.3g} | {c.now_s * SYSCLKOUT_HZ / c_cpu:.3g} | {c.now_s / c_cpu:.1f} |",
        f"| Rust model (reference) | {rust_virtual:.3f} | {len(rust.budget['tick'])} | not counted "
        f"| {rust_cpu:.3f} | – | {rust_virtual * SYSCLKOUT_HZ / rust_cpu:.3g} "
        f"| {rust_virtual / rust_cpu:.1f} |",
        "",
        f"The C firmware passed {c.blocks} basic blocks (each a call into the runtime, but the idle "
        "loop's passes, charged at once up to the next interrupt). Its accesses include the polling reads "
        "left after the runtime skips the passes that see no change. The Rust model runs event by event (no "
        "idle loop to pass): its cycles per second are virtual time over CPU time, as the C firmware's.",
        "",
        "## The isolation's fixed cost",
        "",
        f"- a run of 10 ms of trace (fork, the library's load and static constructors, the pipes, the "
        f"child reaped): {fixed_cpu * 1e3:.1f} ms of CPU",
        f"- a fresh interpreter importing the harness (`python -c 'import sins_fw.firmware_run'`, what "
        f"a spawned runner would pay before any work): {spawn_cpu * 1e3:.1f} ms of CPU",
        "",
        "## SPI outside an interrupt (the burst polled in main back to back, an event every frame)",
        "",
        "| trace s | virtual s reached | register accesses | host CPU s | CPU s per trace s |",
        "|---|---|---|---|---|",
        *(f"| {s:g} | {r.now_s:.3f} | {r.accesses} | {cpu:.3f} | {cpu / s:.4f} |" for s, cpu, r in spi),
        "",
        "## Watched globals (`sins-fw run --firmware … --until-s 3 --out run.csv`, the whole command)",
        "",
        "| globals | host CPU s | wall s | peak RSS, MB |",
        "|---|---|---|---|",
        *(f"| {n} | {cpu:.2f} | {wall:.2f} | {rss:.0f} |" for n, cpu, wall, rss in watched),
        "",
    ]
    text = "\n".join(lines)
    print(text)
    if args.output is not None:
        write_text(args.output, text)


if __name__ == "__main__":
    main()
