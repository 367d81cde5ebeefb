"""The one-page report as a reader sees it (issue 27, item 9): the ISR panel is scaled to the work,
the margin has its own axis with the deadline at zero, missed deadlines and lost ticks are marks in a
strip (not a block over the data), long titles wrap, and `report` reads a `run --out` file. Structural
properties of the drawn figure, not pixels."""

from __future__ import annotations

import json

import numpy as np
import pytest
from matplotlib.lines import Line2D

from conftest import run_cli
from sins_fw import synth
from sins_fw.harness import emulate
from sins_fw.report_page import HEADROOM, report_figure


@pytest.fixture(scope="module")
def trace():
    return synth.generate("static", duration_s=1.0)


def _lines(ax) -> dict[str, Line2D]:
    return {ln.get_label(): ln for ln in ax.get_lines()}


def test_the_isr_axis_is_scaled_to_the_work_not_the_period(trace):
    run = emulate(trace)  # the reference board: ~340 µs of work every 4000 µs tick
    _, axes = report_figure(run)
    busy_us = run.busy_s * 1e6
    lo, hi = axes.budget.get_ylim()
    assert lo == 0 and hi == pytest.approx(busy_us.max() * (1 + HEADROOM))
    assert hi < 4000 / 4, "the axis ends near the work, far below the 4000 µs period"
    # One line for one quantity: the end after the tick lies on the busy time here, so it is not drawn.
    assert set(_lines(axes.budget)) == {"ISR busy"}
    # The margin on its own axis, the deadline at zero on it.
    margin = _lines(axes.margin)
    assert np.allclose(margin["margin to the deadline"].get_ydata(), 4000 - busy_us, atol=50)
    assert list(margin["deadline"].get_ydata()) == [0, 0]
    assert axes.margin.get_ylim()[0] <= 0 < axes.margin.get_ylim()[1]


def test_overruns_are_marks_in_a_strip_not_a_block(trace):
    run = emulate(trace, overrides=["timer.period_us=300"])  # 340 µs of work every 300 µs
    _, axes = report_figure(run)
    margin = _lines(axes.margin)
    late = next(ln for label, ln in margin.items() if label.startswith("missed deadline"))
    lost = next(ln for label, ln in margin.items() if label.startswith("tick lost"))
    for marks in (late, lost):
        assert marks.get_linestyle() == "None" and marks.get_marker() == "|"
        # In axes coordinates, above the data (the strip), not at the values.
        assert marks.get_transform() == axes.margin.get_xaxis_transform()
        assert min(marks.get_ydata()) > 0.8
    assert len(late.get_xdata()) > 0 and len(lost.get_xdata()) > 0
    # The margin goes below the deadline, and the axis shows it.
    assert min(margin["margin to the deadline"].get_ydata()) < 0
    assert axes.margin.get_ylim()[0] < min(margin["margin to the deadline"].get_ydata())
    # Queued ticks start late: the end after the tick is drawn apart from the busy time.
    assert "ISR end after its tick" in _lines(axes.budget)


def test_long_titles_wrap(trace):
    overrides = [f"timer.period_us={4000 + i}" for i in range(1)] + [
        "spi.spibrr=49",
        "firmware.numeric=f64",
        "firmware.algorithm=rotation-vector",
        "errors.preset=adis16407",
        "errors.seed=12345",
    ]
    fig, _ = report_figure(emulate(trace, overrides=overrides), title="a_rather_long_trace_name.h5")
    lines = fig._suptitle.get_text().splitlines()
    assert len(lines) >= 2 and max(map(len, lines)) <= 110


def test_report_reads_a_run_output_file(tmp_path, trace):
    path = tmp_path / "t.h5"
    trace.save(path)
    out, png = tmp_path / "run.h5", tmp_path / "r.png"
    assert run_cli("run", str(path), "--out", str(out)).code == 0
    r = run_cli("report", str(out), "--out", str(png), "--json")
    assert r.code == 0, r.err
    assert png.is_file() and json.loads(r.out)["cycles"] == 124
