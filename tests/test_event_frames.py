"""Per-frame events name their bus frame: an event's ``frame`` is the index the bus log gives the
frame it is about (``frame_index``), None for an event not tied to one frame."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sins_fw.harness import emulate

ROOT = Path(__file__).resolve().parents[1]
STATIC = ROOT / "python" / "sins_fw" / "bundled_traces" / "static_60s.h5"
#: SPI mode 2: CLKPOLARITY 1 (SPICCR 0xCF) with CLK_PHASE 1 (SPICTL 0x0F), "falling edge with
#: delay" in TI's terms (f28335.md); the ADIS16407 takes mode 3 (SPICTL 0x07, without delay).
MODE_2 = ["spi.spiccr=0xCF", "spi.spictl=0x0F"]
UNTIL_S = 0.4
TICKS = 99  # the ticks of 0.4 s at 4 ms (the first at 4 ms)


def test_a_mode_2_run_reports_each_frame_with_its_bus_index():
    run = emulate(STATIC, "reference", overrides=MODE_2, until_s=UNTIL_S, bus_window=(1, TICKS))
    assert run.bus is not None
    mode = [e for e in run.events if e["kind"] == "spi_mode"]
    index, first_edge = run.bus["frame_index"], run.bus["frame_first_edge_ps"]
    # Every frame the part took part in, one event each: 15 a burst, one burst a tick.
    assert len(mode) == np.count_nonzero(run.bus["frame_selected"]) == 15 * TICKS
    row = {int(i): k for k, i in enumerate(index)}
    for e in mode:
        k = row[e["frame"]]  # a row of the bus log
        assert round(e["t_s"] / 1e-12) == int(first_edge[k]), e
    assert len({e["frame"] for e in mode}) == len(mode)


def test_an_event_of_no_frame_names_none():
    """An ISR overrun is the timer's and the firmware's, not a frame's."""
    run = emulate(STATIC, "reference", overrides=["timer.period_us=300.0"], until_s=0.1)
    overruns = [e for e in run.events if e["kind"] == "overrun"]
    assert overruns and all(e["frame"] is None for e in overruns)
