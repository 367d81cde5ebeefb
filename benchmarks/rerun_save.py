"""How long a Rerun recording of a 1-hour run takes to save (target: < 30 s for 450 000 cycles).

Generates a 1-hour coning trace (truth included, so every entity is logged), emulates it on the
reference profile with a 50-tick bus window, then times ``save_recording`` alone (best of
``--repeat``). Writes benchmarks/rerun_save.md with the machine, commit and date.

    python benchmarks/rerun_save.py [--duration-s 3600] [--repeat 2]
"""

from __future__ import annotations

import argparse
import datetime
import platform
import subprocess
import tempfile
import time
from pathlib import Path

from sins_fw import synth
from sins_fw.atomic import write_text
from sins_fw.harness import emulate
from sins_fw.viewer import save_recording

HERE = Path(__file__).resolve().parent


def cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def commit() -> str:
    try:
        return subprocess.run(
            ["git", "-C", str(HERE), "rev-parse", "--short", "HEAD"],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration-s", type=float, default=3600.0)
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--out", type=Path, default=HERE / "rerun_save.md")
    args = ap.parse_args()

    t = time.perf_counter()
    trace = synth.generate("coning", duration_s=args.duration_s)
    t_synth = time.perf_counter() - t
    t = time.perf_counter()
    run = emulate(trace, bus_window=(1000, 1049))
    t_emulate = time.perf_counter() - t
    saves = []
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "run.rrd"
        for _ in range(args.repeat):
            t = time.perf_counter()
            save_recording(run, path, trace=trace)
            saves.append(time.perf_counter() - t)
        size = path.stat().st_size
    best = min(saves)
    all_saves = ", ".join(f"{s:.1f}" for s in saves)
    verdict = "under" if best < 30 else "OVER"
    text = f"""# Rerun recording: save time of a long run

`python benchmarks/rerun_save.py --duration-s {args.duration_s:g} --repeat {args.repeat}`

| what | value |
|---|---|
| emulated time | {args.duration_s:g} s (coning 10 Hz, 1°, truth included) |
| attitude cycles | {run.cycles} |
| timer ticks / burst reads | {len(run.budget["tick"])} / {len(run.read_tick)} |
| bus window | ticks 1000…1049 ({len(run.bus["frame_index"]) if run.bus else 0} frames) |
| synthesise the trace | {t_synth:.1f} s |
| emulate (reference profile) | {t_emulate:.1f} s |
| **save the recording** (best of {args.repeat}: {all_saves} s) | **{best:.1f} s** ({verdict} 30 s) |
| .rrd size | {size / 1e6:.0f} MB |

Machine: `{platform.uname().system} {platform.uname().release} {platform.uname().machine}`, CPU
`{cpu_model()}`, Python {platform.python_version()}, rerun-sdk {__import__("rerun").__version__}.
Commit `{commit()}`, {datetime.date.today().isoformat()}. The machine is shared (2 cores): other jobs may
have been running; the best of the repeats is the figure.
"""
    write_text(args.out, text)
    print(text)


if __name__ == "__main__":
    main()
