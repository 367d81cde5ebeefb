"""Peak resident memory of each trace command on one long trace (issue 24, item 11: every command
that reads or writes a trace should stay under 300 MB on a 24-hour trace at 819.2 SPS).

    python benchmarks/peak_rss.py --duration-s 86400 --output benchmarks/peak_rss.md
    python benchmarks/peak_rss.py --trace day.h5 --commands 'run --out,report'   # an existing trace

Each command runs as its own process; its peak RSS is the child's ``ru_maxrss`` from
``resource.getrusage(RUSAGE_CHILDREN)`` read through ``os.wait4``. The trace is made by the first
command (`synth`) in a temporary folder beside the output. Memory, not time: a loaded host changes
the times, not the peaks.
"""

from __future__ import annotations

import argparse
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

LIMIT_MB = 300.0


def _peak(cmd: list[str]) -> tuple[float, float, int]:
    """(peak RSS in MB, wall time in s, exit code) of one command run to completion."""
    start = time.monotonic()
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    return usage.ru_maxrss / 1024.0, time.monotonic() - start, proc.returncode


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration-s", type=float, default=86400.0)
    ap.add_argument("--output", type=Path, default=None, help="write the results table here (.md)")
    ap.add_argument("--trace", type=Path, default=None, help="measure on this trace instead of making one")
    ap.add_argument(
        "--commands",
        default="synth,run --out,parity,replay,report,import",
        help="comma-separated commands to measure (synth always runs without --trace: it makes the trace)",
    )
    args = ap.parse_args()
    wanted = {c.strip() for c in args.commands.split(",")} | ({"synth"} if args.trace is None else set())
    sins = [sys.executable, "-m", "sins_fw"]
    with tempfile.TemporaryDirectory(dir=Path(args.output or ".").absolute().parent) as tmp:
        d = Path(tmp)
        trace = args.trace.absolute() if args.trace is not None else d / "trace.h5"
        commands = {
            "synth": [*sins, "synth", "static", "--duration-s", f"{args.duration_s:g}", "--out", str(trace)],
            "run --out": [*sins, "run", str(trace), "--out", str(d / "run.h5")],
            "parity": [*sins, "parity", str(trace), "--json"],
            "replay": [*sins, "replay", str(trace), "--out", str(d / "r.rrd")],
            "report": [*sins, "report", str(trace), "--out", str(d / "r.png")],
            "import": [*sins, "import", "trace", str(trace), "--out", str(d / "copy.h5")],
        }
        rows = []
        for name, cmd in commands.items():
            if name not in wanted:
                continue
            mb, s, code = _peak(cmd)
            rows.append(
                f"| `{name}` | {mb:.0f} MB | {s:.1f} s | {code} | {'yes' if mb < LIMIT_MB else 'NO'} |"
            )
            print(rows[-1], flush=True)
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout
    text = "\n".join(
        [
            f"# Peak RSS per command: {args.duration_s:g} s static trace at 819.2 SPS"
            if args.trace is None
            else f"# Peak RSS per command: {args.trace.name}",
            "",
            f"`python benchmarks/peak_rss.py --duration-s {args.duration_s:g} --commands '{args.commands}'`"
            if args.trace is None
            else f"`python benchmarks/peak_rss.py --trace {args.trace.name} --commands '{args.commands}'`",
            "",
            f"| command | peak RSS | wall time | exit | under {LIMIT_MB:g} MB |",
            "|---|---|---|---|---|",
            *rows,
            "",
            f"Machine: `{platform.platform()}`, Python {platform.python_version()}; "
            f"commit `{commit.strip()}` (with uncommitted changes when `git status` shows any).",
            "",
        ]
    )
    if args.output is not None:
        args.output.write_text(text, encoding="utf-8")
    else:
        print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
