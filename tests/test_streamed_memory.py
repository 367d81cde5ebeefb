"""Every command that reads or writes a trace streams (issue 24, item 11): its peak memory does not
grow with the trace's duration. Each case runs the same command twice in one process (the CLI's
``main``), on a short trace and then on one ten times longer, and bounds how much the second run
raised the peak the first one set (``ru_maxrss``) by a few chunks of what the command holds per
chunk: anything kept per step instead (the smallest being a step's time and quaternion, 40 bytes)
raises it by the longer trace's worth. The first run warms the allocator, the file caches and the
imports up, so what the second adds is what the duration adds.

The 24-hour figures (the target: under 300 MB each) are in benchmarks/peak_rss.md.
"""

from __future__ import annotations

import platform
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import peaks_mb

pytestmark = pytest.mark.skipif(platform.system() != "Linux", reason="ru_maxrss in kB is Linux's")

#: The attitude update rate (8 ms) and the two durations.
STEPS_HZ = 125.0
#: The short trace is past the first file chunk (65 536 rows, 80 s) the reader caches.
SHORT_S, LONG_S = 100.0, 1000.0
#: Doubles per row of a physical trace (t, gyro, accel, mag, baro, temp, truth q, moving).
TRACE_DOUBLES = 17


@pytest.fixture(scope="module")
def traces(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A short and a ten times longer static trace (``short.h5``, ``long.h5``)."""
    d = tmp_path_factory.mktemp("streamed")
    for name, seconds in (("short", SHORT_S), ("long", LONG_S)):
        subprocess.run(
            [
                sys.executable,
                "-m",
                "sins_fw",
                "synth",
                "static",
                "--duration-s",
                f"{seconds:g}",
                "--out",
                str(d / f"{name}.h5"),
            ],
            check=True,
            capture_output=True,
        )
    return d


def per_step_growth_mb(bytes_per_step: float) -> float:
    """What keeping ``bytes_per_step`` per attitude step costs the longer trace over the short one."""
    return (LONG_S - SHORT_S) * STEPS_HZ * bytes_per_step / 1e6


PARITY = """
import json, resource, sys
from sins_fw.parity import parity
peaks = []
for path, chunk in json.loads(sys.argv[1]):
    parity(path, backends="f64,iq", chunk_rows=chunk)
    peaks.append(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0)
print(json.dumps(peaks))
"""


def test_parity_memory_does_not_grow_with_the_duration(traces):
    """Two backends side by side, read in chunks of C = 4 096 rows (5 s; the short trace is 20
    chunks, past the few chunks the queues between the backends and the comparison hold). Each
    backend holds one chunk of input (17 doubles a row, a copy or two while it is validated and
    pushed) and a few pieces of output: per backend fewer than 4 C × 17 doubles ≈ 2.2 MB, the bound
    on what differs between the two runs. Keeping the compared steps (40 bytes each, per backend)
    would add 2 × 112 500 × 40 B = 9 MB. (Before the pieces were slimmed and taken per piece, each
    queued chunk also carried every read and budget column: 4 backends on 1 200 s peaked at 325 MB,
    now 182 MB, at the default C = 65 536.)"""
    chunk = 4096
    runs = [[str(traces / "short.h5"), chunk], [str(traces / "long.h5"), chunk]]
    short, long = peaks_mb(runs, traces, PARITY)  # type: ignore[arg-type]
    bound = 2 * 4 * chunk * TRACE_DOUBLES * 8 / 1e6
    assert bound < 2 * per_step_growth_mb(40)
    assert long - short < bound, (short, long, bound)


#: Mean and deviation accumulators of the run summary (report_stream.Moments), each holding fewer
#: than one block of doubles: busy, margin, solution, utilisation, cycle utilisation, read offset,
#: interval, sample age, timestamp error; four Euler errors; three BROAD errors twice (masked, not).
SUMMARY_MOMENTS = 9 + 4 + 3 + 3


def test_run_memory_does_not_grow_with_the_duration(traces):
    """`run --out` (CSV: each block of lines is written as it comes) summarises and writes each
    part of the output as it comes. What it holds besides a chunk of input and a part of output
    (the same for either trace) is the summary's accumulators, fewer than BLOCK doubles each (all
    but empty on the short trace, full on the long one). Between the two runs the allocator's
    slack adds up to one chunk of the per-chunk input state, as for `synth` (tests/test_stream.py):
    C = 65 536 rows of 17 doubles and two copies (validated, pushed). Keeping the run instead (≈ 650
    bytes a step: its own row, two reads and two ticks) adds 73 MB; before streaming the peak rose
    by 135 MB between these two traces (89 → 111 MB now, 134 → 269 MB before)."""
    from sins_fw.report_stream import BLOCK

    runs = [["run", str(traces / f"{n}.h5"), "--out", str(traces / f"{n}.csv")] for n in ("short", "long")]
    short, long = peaks_mb(runs, traces)
    chunk = 65536 * TRACE_DOUBLES * 8 * 3 / 1e6
    bound = SUMMARY_MOMENTS * BLOCK * 8 / 1e6 + chunk
    assert bound < per_step_growth_mb(650) / 2
    assert long - short < bound, (short, long, bound)


def test_import_memory_does_not_grow_with_the_duration(traces):
    """`import trace` reads and writes a chunk (C = 65 536 rows) at a time; to CSV (each block of
    lines written as it comes; the HDF5 writer holds up to stream.WHOLE_ROWS rows by design) it
    holds a chunk of 17 doubles a row and two copies (read, validated, formatted): the bound.
    Loading the trace whole and saving it (the trace and its column copies) would add 2 × 737 280
    rows × 17 doubles = 200 MB."""
    chunk = 65536
    runs = [
        ["import", "trace", str(traces / f"{n}.h5"), "--out", str(traces / f"{n}_copy.csv")]
        for n in ("short", "long")
    ]
    short, long = peaks_mb(runs, traces)
    bound = 3 * chunk * TRACE_DOUBLES * 8 / 1e6
    assert bound < (819_200 - 81_920) * TRACE_DOUBLES * 8 / 1e6
    assert long - short < bound, (short, long, bound)


def test_report_memory_does_not_grow_with_the_duration(traces):
    """`report` gathers the page's series part by part, each at most report_page.MAX_POINTS points
    (a time and a value: 16 bytes) — 4 error or attitude lines, 3 budget lines, the late and lost
    markers — and the run summary's accumulators: the bound, with the allocator's slack of one
    chunk of input as for `run`. Keeping the run (≈ 650 bytes a step) would add 73 MB."""
    from sins_fw.report_page import MAX_POINTS
    from sins_fw.report_stream import BLOCK

    runs = [["report", str(traces / f"{n}.h5"), "--out", str(traces / f"{n}.png")] for n in ("short", "long")]
    short, long = peaks_mb(runs, traces)
    chunk = 65536 * TRACE_DOUBLES * 8 * 3 / 1e6
    bound = (3 + 4 + 3 + 2) * MAX_POINTS * 16 / 1e6 + SUMMARY_MOMENTS * BLOCK * 8 / 1e6 + chunk
    assert bound < per_step_growth_mb(650) / 2
    assert long - short < bound, (short, long, bound)


def test_replay_memory_does_not_grow_with_the_duration(traces):
    """`replay --out` logs each part of the output as it comes, and Rerun's file writer writes it
    as it is logged (viewer.recording.recording_file). What it holds besides a part of output is
    the input's chunk, with the allocator's slack of one chunk of input as for `run` (C = 65 536
    rows of 17 doubles and two copies), and the recorder's window of the trace for the physical
    rates: at most two chunks of 7 doubles a row (time, rate, acceleration), and the rows waiting to
    make a chunk of the recording (below). Keeping the run (≈ 650
    bytes a step) would add 73 MB, and the recording encoded in memory (≈ 98 kB a second of trace
    on the reference profile) 88 MB more: before streaming, 1 200 s peaked at 801 MB."""
    runs = [
        ["replay", str(traces / f"{n}.h5"), "--out", str(traces / f"{n}.rrd"), "--bus-ticks", "none"]
        for n in ("short", "long")
    ]
    short, long = peaks_mb(runs, traces)
    chunk = 65536 * TRACE_DOUBLES * 8 * 3 / 1e6
    window = 2 * 65536 * 7 * 8 / 1e6
    # Each entity's rows wait until they make a chunk of ENTITY_CHUNK_BYTES (so that Rerun's footer
    # lists few chunks), at most that and a part more, then copied into one batch; the 100 s run
    # fills few of them. The footer's manifest adds ≈ 3.5 kB a chunk: 0.2 MB on 1 000 s.
    import rerun as rr

    from sins_fw.viewer.recording import ENTITY_CHUNK_BYTES

    store = rr.chunk.RrdReader(traces / "long.rrd").store()
    entities = {c.entity_path for c in store.stream() if not c.is_static}
    waiting = len(entities) * 2 * ENTITY_CHUNK_BYTES / 1e6
    bound = chunk + window + waiting
    # Keeping the run and the encoded recording (the state before streaming) would add 161 MB.
    assert bound < per_step_growth_mb(650) + 88
    assert long - short < bound, (short, long, bound)


def test_run_allow_gaps_memory_does_not_grow_with_the_duration(traces):
    """`run --allow-gaps` notes the gaps as the chunks stream past (cli.run.GapFinder) instead of
    reading the trace whole: the bound of `run`. Reading it whole would add the longer trace's
    rows, (819 200 − 81 920) × 17 doubles = 100 MB."""
    from sins_fw.report_stream import BLOCK

    runs = [
        ["run", str(traces / f"{n}.h5"), "--allow-gaps", "--out", str(traces / f"{n}_gaps.csv")]
        for n in ("short", "long")
    ]
    short, long = peaks_mb(runs, traces)
    chunk = 65536 * TRACE_DOUBLES * 8 * 3 / 1e6
    bound = SUMMARY_MOMENTS * BLOCK * 8 / 1e6 + chunk
    assert bound < (819_200 - 81_920) * TRACE_DOUBLES * 8 / 1e6 / 2
    assert long - short < bound, (short, long, bound)
