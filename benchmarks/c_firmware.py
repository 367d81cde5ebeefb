"""The host-built C firmware against the Rust model, on the same trace: register accesses per second
and emulated SYSCLKOUT cycles per second (virtual time × SYSCLKOUT / host CPU time) of the
`firmware_c/examples/timer0_burst` firmware (timer 0 ISR every 4 ms doing the 15-frame ADIS16407
burst; main idles in `for (;;) {}`), beside the reference profile's Rust model (the same burst every
4 ms plus the RK4 attitude update every 8 ms). Host CPU time (process time) of the run alone: the
build, the library's load and the trace's first read are outside it. Each is run ``--rounds`` times;
figures are medians.

    python benchmarks/c_firmware.py [--duration-s 60] [--rounds 3] [--output benchmarks/c_firmware.md]
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

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
    with tempfile.TemporaryDirectory() as tmp:
        fw = build_firmware([EXAMPLE], Path(tmp) / "timer0_burst.so")
        c_runs, rust_runs = [], []
        for _ in range(args.rounds):
            t = time.process_time()
            r = run_c_firmware(
                fw, trace, profile, globals_file=EXAMPLE / "globals.toml", until_s=args.duration_s
            )
            c_runs.append((time.process_time() - t, r))
            t = time.process_time()
            run = emulate(trace, profile, until_s=args.duration_s)
            rust_runs.append((time.process_time() - t, run))
    c_cpu = statistics.median(x[0] for x in c_runs)
    c = c_runs[0][1]
    rust_cpu = statistics.median(x[0] for x in rust_runs)
    rust = rust_runs[0][1]
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
        f"- trace: {TRACE.name}, first {args.duration_s:g} s; "
        f"host CPU time of the run, median of {args.rounds}",
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
        "loop's passes, "
        "charged at once up to the next interrupt). Its accesses include the polling reads left "
        "after the runtime skips the passes that see no change. The Rust model runs event by event (no "
        "idle loop to pass): its cycles per second are virtual time over CPU time, as the C firmware's.",
        "",
    ]
    text = "\n".join(lines)
    print(text)
    if args.output is not None:
        write_text(args.output, text)


if __name__ == "__main__":
    main()
