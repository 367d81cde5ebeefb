"""Peak memory and time of `sins-fw replay` and `sins-fw report` of a C firmware's run output (`run
--firmware --out`), which they read a block at a time (issue 37, item 3): the same file format at two
lengths, 10× apart; the peak should not follow the length.

The files are made here in the run output's format (run_output.firmware_run_schema, metadata as
`run --firmware` writes it): 4 ms ISR rows holding a quaternion rolling ±17° and two other globals;
their recorded trace does not exist (a long trace with truth would take the shared machine minutes
to make), so the attitude is shown without truth. Each command runs in its own process
(`python -m sins_fw`), its peak resident memory from wait4. Writes benchmarks/firmware_run_files.md.

    python benchmarks/firmware_run_files.py [--rows 100000 1000000]
"""

from __future__ import annotations

import argparse
import datetime
import os
import subprocess
import sys
import tempfile
import time
from fractions import Fraction
from pathlib import Path

import numpy as np

from sins_fw.atomic import write_text
from sins_fw.profile import load_profile
from sins_fw.run_output import FIRMWARE_CREATED_BY, _run_metadata, firmware_run_schema
from sins_fw.tablefile import write_table

HERE = Path(__file__).resolve().parent


def make(path: Path, rows: int) -> None:
    t = (np.arange(1, rows + 1, dtype=np.int64) * 4_000_000_000 + 4_016_000).astype(np.float64) * 1e-12
    angle = 0.3 * np.sin(t / 7.0)
    cols = {
        "t_s": t,
        "q0": np.cos(angle / 2),
        "q1": np.sin(angle / 2),
        "q2": np.zeros(rows),
        "q3": np.zeros(rows),
        "updates": np.arange(rows) // 2.0,
        "temp_c": 25 + np.sin(t),
    }
    schema = firmware_run_schema(
        [
            ("q0", "1", ""),
            ("q1", "1", ""),
            ("q2", "1", ""),
            ("q3", "1", ""),
            ("updates", "1", ""),
            ("temp_c", "°C", ""),
        ]
    )
    extra = {
        "trace": "absent.h5",
        "created_by": FIRMWARE_CREATED_BY,
        "firmware": "fw.so",
        "float_mode": "host",
    }
    write_table(path, schema, _run_metadata(load_profile("reference"), Fraction(1, 250), 0.0, extra), cols)


def measure(args: list[str], cwd: Path) -> tuple[float, float]:
    """(wall seconds, peak RSS in MB) of `python -m sins_fw ARGS`."""
    start = time.perf_counter()
    proc = subprocess.Popen(
        [sys.executable, "-m", "sins_fw", *args],
        cwd=cwd,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    _, status, usage = os.wait4(proc.pid, 0)
    assert os.waitstatus_to_exitcode(status) == 0, args
    return time.perf_counter() - start, usage.ru_maxrss / 1024.0


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--rows", type=int, nargs="+", default=[100_000, 1_000_000])
    p.add_argument("--make", nargs=2, metavar=("FILE", "ROWS"), help=argparse.SUPPRESS)
    a = p.parse_args()
    if a.make:
        make(Path(a.make[0]), int(a.make[1]))
        return
    lines = [
        "# `replay` and `report` of a C firmware's run output: memory against length",
        "",
        f"`python benchmarks/firmware_run_files.py --rows {' '.join(map(str, a.rows))}`, "
        f"{datetime.date.today().isoformat()}, {os.cpu_count()} CPUs shared with other work (times are wall "
        "clock, start-up included). Each file: 4 ms ISR rows, q0…q3 and two globals, its trace absent.",
        "",
        "| rows (virtual time) | file | command | wall s | peak RSS MB |",
        "|---|---|---|---|---|",
    ]
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        for rows in a.rows:
            f = d / f"run_{rows}.h5"
            # Made in a process of its own: a child forked from this one would start with this
            # process's memory in its peak (ru_maxrss counts the pages shared until exec).
            subprocess.run([sys.executable, __file__, "--make", str(f), str(rows)], check=True)
            size = f.stat().st_size / 1e6
            for command, out in (("replay", "r.rrd"), ("report", "p.png")):
                wall, rss = measure([command, str(f), "--out", str(d / out)], d)
                lines.append(
                    f"| {rows} ({rows * 0.004:.0f} s) | {size:.1f} MB | {command} | {wall:.1f} | {rss:.0f} |"
                )
                print(lines[-1], flush=True)
    lines += [
        "",
        "Each is read a block at a time (run_output.FIRMWARE_BLOCK_ROWS rows); what grows with the length is",
        "`replay`'s Rerun footer manifest (≈ 3.5 kB per chunk, benchmarks/rerun_save.md) and `report`'s",
        "nothing: its series hold at most report_page.MAX_POINTS points.",
    ]
    write_text(HERE / "firmware_run_files.md", "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
