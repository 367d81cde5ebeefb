"""The summary `sins-fw run` prints, accumulated chunk by chunk as the run streams (issue 24, item
11): the same figures, bit for bit, as the summary of the whole run, and as the whole-array
functions (numpy over every row) for runs of up to one block of values."""

from __future__ import annotations

import math
from typing import Any

import pytest

from conftest import ROOT, run_cli
from sins_fw import report_stream
from sins_fw.harness import emulate
from sins_fw.report import attitude_summary, budget_summary, events_summary, summarise
from sins_fw.run_output import save_run

TRACES = ROOT / "traces"
CASES = [
    ("static_60s.h5", [], "auto"),
    ("pitch_sweep.h5", [], "auto"),
    ("pitch_sweep.h5", [], "none"),
    # Overruns (66 665 ticks dropped), error events, and the heading alignment.
    ("coning_10hz.h5", ["timer.period_us=300"], "heading"),
]


def same(a: Any, b: Any, path: str = "") -> None:
    """Equal values of equal types, NaN equal to NaN, recursively."""
    if isinstance(a, dict):
        assert a.keys() == b.keys(), path
        for k in a:
            same(a[k], b[k], f"{path}.{k}")
    elif isinstance(a, list):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            same(x, y, f"{path}[{i}]")
    elif isinstance(a, float) and math.isnan(a):
        assert isinstance(b, float) and math.isnan(b), path
    else:
        assert a == b and type(a) is type(b), (path, a, b)


@pytest.mark.parametrize("name, overrides, align", CASES)
def test_the_streamed_summary_is_the_whole_runs_bit_for_bit(monkeypatch, name, overrides, align):
    """20 s of each case (2 500 steps, up to 66 667 ticks) with blocks of 1 000 values, so that every
    mean and deviation merges blocks; the streamed parts (a sink's, a few thousand ticks each) cut
    the run elsewhere than the blocks do."""
    monkeypatch.setattr(report_stream, "BLOCK", 1000)
    run = emulate(TRACES / name, overrides=overrides, until_s=20.0)
    whole = summarise(run, align=align)
    acc = report_stream.RunSummary(run.profile, align=align)
    parts: list[int] = []

    def sink(part: dict[str, Any]) -> None:
        parts.append(len(part["budget_tick"]))
        acc.add(part)

    streamed_run = emulate(TRACES / name, overrides=overrides, until_s=20.0, sink=sink)
    streamed = acc.result(t0_s=streamed_run.t0_s, stage_cycles=streamed_run.stage_cycles)
    assert len(parts) > 2 and whole["budget"]["ticks"] > 2 * report_stream.BLOCK
    same(whole, streamed)


@pytest.mark.parametrize("name, overrides, align", CASES)
def test_up_to_a_block_the_summary_is_numpys_over_the_whole_arrays(name, overrides, align):
    """Within one block (16 384 values) every figure is the whole-array one: the functions the
    summary was computed with before it streamed."""
    run = emulate(TRACES / name, overrides=overrides, until_s=4.0)
    assert len(run.budget["tick"]) <= report_stream.BLOCK
    s = summarise(run, align=align)
    same(s["events"], events_summary(run))
    same(s["attitude_error"], attitude_summary(run, align))
    same(s["budget"], budget_summary(run))


@pytest.mark.parametrize("ext", [".csv", ".h5"])
@pytest.mark.parametrize("overrides", [[], ["firmware.algorithm=dcm"]])
def test_run_out_streamed_is_the_whole_writers_file(tmp_path, ext, overrides):
    """`run --out` writes as the run streams: the bytes `save_run` writes of the whole run (the
    metadata the CLI records added), the DCM's columns included."""
    trace = TRACES / "pitch_sweep.h5"
    out = tmp_path / f"o{ext}"
    sets = [x for o in overrides for x in ("--set", o)]
    r = run_cli("run", str(trace), *sets, "--out", str(out), "--until-s", "30")
    assert r.code == 0, r.err
    from sins_fw.run_output import trace_reference

    meta = {**trace_reference(trace, out), "until_s": repr(30.0)}
    save_run(emulate(trace, overrides=overrides, until_s=30.0), tmp_path / f"w{ext}", meta)
    assert out.read_bytes() == (tmp_path / f"w{ext}").read_bytes()


def test_a_long_series_is_plotted_as_its_envelope_in_at_most_max_points():
    """Past MAX_POINTS rows a page series keeps, per time bin, its smallest and largest value at
    their own times: at most MAX_POINTS points, every extreme kept (here a spike and a dip)."""
    import numpy as np

    from sins_fw.report_page import MAX_POINTS, Series

    t = np.arange(1_000_000) * 1e-3
    v = np.sin(t)
    v[123_457], v[876_543] = 50.0, -40.0
    s = Series()
    for i in range(0, len(t), 8192):
        s.add(t[i : i + 8192], v[i : i + 8192])
    pt, pv = s.points()
    assert len(pt) <= MAX_POINTS and np.all(np.diff(pt) >= 0)
    assert pv.max() == 50.0 and pt[np.argmax(pv)] == t[123_457]
    assert pv.min() == -40.0 and pt[np.argmin(pv)] == t[876_543]
    short = Series()
    short.add(t[:1000], v[:1000])
    assert np.array_equal(short.points()[1], v[:1000])  # short: the rows themselves


def test_run_allow_gaps_streams_and_writes_what_the_whole_trace_gave(tmp_path):
    """Issue 24, item 11: `run --allow-gaps` read the whole trace into memory to list its gaps. Now
    the gaps are noted as the chunks stream past (one across the first chunk boundary, row 65 536):
    the same `input_gap` events, and the --out bytes `save_run` writes of the run on the whole
    trace (the memory bound: tests/test_streamed_memory.py)."""
    import json

    import numpy as np

    from sins_fw import synth
    from sins_fw.run_output import trace_reference
    from sins_fw.traces import PhysicalTrace

    whole = synth.generate("static", duration_s=100.0)
    keep = np.ones(len(whole), dtype=bool)
    for lo, hi in ((1000, 1600), (65530, 65600), (80000, 80003)):
        keep[lo:hi] = False
    cols = {k: v[keep] for k, v in whole.columns().items()}
    gappy = PhysicalTrace.from_columns(cols, whole.metadata)
    trace = tmp_path / "gappy.h5"
    gappy.save(trace, allow_gaps=True)
    out = tmp_path / "o.csv"
    r = run_cli("run", str(trace), "--allow-gaps", "--out", str(out), "--json")
    assert r.code == 0, r.err
    gaps = json.loads(r.out)["events"]["by_kind"]["input_gap"]
    period = 1 / float(gappy.sample_rate_hz)
    dt = np.diff(gappy.t_s)
    assert gaps["count"] == int(np.sum(dt > 1.5 * period)) == 3
    first = int(np.argmax(dt > 1.5 * period))
    assert gaps["first_t_s"] == float(gappy.t_s[first] - gappy.t_s[0])
    save_run(
        emulate(PhysicalTrace.load(trace, allow_gaps=True), allow_gaps=True),
        tmp_path / "w.csv",
        trace_reference(trace, out),
    )
    assert out.read_bytes() == (tmp_path / "w.csv").read_bytes()
