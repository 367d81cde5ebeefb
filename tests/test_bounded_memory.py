"""Memory is bounded by the block of ticks the core runs per call, whatever one chunk of input covers:
a long gap between two rows (an in-memory trace whose times are far apart, e.g. nanoseconds taken
as seconds, or `--allow-gaps` over a gap) and a timer period far below the ISR's length (every tick
but a few lost, an event each) once made the core hold every row of the chunk at once (an abort at
"memory allocation of 872415232 bytes failed": 2^23 budget rows of 104 bytes) or the harness hold
them until the end of the chunk. With a sink, the output goes out a block at a time."""

from __future__ import annotations

import json
import platform
import subprocess
import sys

import pytest

from sins_fw import _core

# One process per case: ru_maxrss is the process's peak. The same input is run for `short` and then
# `long` virtual seconds, both many blocks long; bounded memory means the longer run does not raise
# the peak the shorter one set by more than one block's output (the derived bound, from the bytes per
# tick of the columns and events the sink received). Unbounded, the peak grows with every block: by
# (long - short) / short times the short run's whole output.
SCRIPT = """
import json, resource, sys
import numpy as np
from sins_fw import _core
from sins_fw.traces import PhysicalTrace
from sins_fw.harness import emulate

case, short, long = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
overrides = ["timer.period_us=1"] if case == "fast_timer" else []

def trace(seconds):
    # Two rows: the whole run is one gap (the fast timer's ticks need no more input either).
    t = np.array([0.0, seconds])
    return PhysicalTrace(t_s=t, gyro_dps=np.zeros((2, 3)), accel_g=np.tile([0.0, 0.0, 1.0], (2, 1)),
                         metadata={"sample_rate_hz": "819.2"})

def run(seconds):
    seen = {"ticks": 0, "bytes": 0, "parts": 0}
    def sink(part):
        seen["ticks"] += len(part["budget_tick"])
        seen["parts"] += 1
        seen["bytes"] += sum(v.nbytes for v in part.values() if hasattr(v, "nbytes"))
        seen["bytes"] += sum(sys.getsizeof(e) + sum(sys.getsizeof(v) for v in e.values())
                             for e in part["events"])
    emulate(trace(seconds), sink=sink, overrides=overrides, allow_gaps=True)
    return seen, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024

a, peak_short = run(short)
b, peak_long = run(long)
print(json.dumps({"short": a, "long": b, "peak_short": peak_short, "peak_long": peak_long}))
"""


@pytest.mark.skipif(platform.system() != "Linux", reason="ru_maxrss in kB is Linux's")
@pytest.mark.parametrize(
    "case, short_s, long_s",
    [
        # 4 ms ticks: 8 and 24 blocks of 2^15 ticks.
        ("gap", 8 * 131.072, 24 * 131.072),
        # 1 µs ticks (all but one in ~350 lost, an event each): 3 and 12 blocks.
        ("fast_timer", 3 * 0.032768, 12 * 0.032768),
    ],
)
def test_a_sink_keeps_memory_bounded_by_the_block_whatever_the_input_covers(case, short_s, long_s):
    out = subprocess.run(
        [sys.executable, "-c", SCRIPT, case, str(short_s), str(long_s)],
        capture_output=True,
        text=True,
        check=True,
    )
    r = json.loads(out.stdout)
    block = _core.BLOCK_TICKS
    short, long = r["short"], r["long"]
    # The runs are many blocks long, and every tick came out through the sink.
    assert short["ticks"] >= 3 * block - 2 and long["ticks"] >= 12 * block - 2, r
    # One block's output, from what the sink received per tick.
    block_bytes = block * long["bytes"] / long["ticks"]
    assert r["peak_long"] - r["peak_short"] <= block_bytes, r
    assert long["parts"] >= long["ticks"] // block, r
