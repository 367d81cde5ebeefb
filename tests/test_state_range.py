"""A firmware state out of range is an error event at its first step, never silent: a free-inertial
vertical channel runs away (on a 12 207 s static trace in c28x-f32-rz the height, then quaternion,
velocity and position became ±inf from 9 279 s with "events none"). The ranges are documented in
firmware_model/SCHEMA.md ("Firmware state checked at every step")."""

from __future__ import annotations

import numpy as np

from conftest import ROOT, run_cli
from sins_fw.harness import emulate

STATIC = ROOT / "traces" / "static_60s.h5"
#: The firmware's g → m/s² factor at its limit: the 1 g at rest reads as 100 m/s², so the vertical
#: channel accelerates at ≈ 90 m/s² and the height leaves its range (1e5 m, from 1 050 m) after
#: √(2 · 99 000 / 90) ≈ 47 s: a runaway in seconds instead of half an hour.
RUNAWAY = ["firmware.accel_g_m_s2=100"]


def test_a_runaway_vertical_channel_is_an_error_event_at_its_first_step():
    run = emulate(STATIC, overrides=[*RUNAWAY, "firmware.numeric=c28x-f32-rz"])
    height = run.position[:, 2]
    out = np.flatnonzero(height > 1e5)
    assert len(out) and out[0] > 0
    first = out[0]
    # Every step before is in range (the velocity stays within ±1e4 m/s over the run).
    assert np.all(np.abs(run.velocity_enu) <= 1e4) and np.all(height[:first] <= 1e5)
    bad = [e for e in run.events if e["kind"] == "state_out_of_range"]
    assert len(bad) == 1, run.events_by_kind()
    e = bad[0]
    assert e["severity"] == "error"
    assert abs(e["t_s"] - run.time_s[first]) < 1e-9
    assert f"step {int(run.step[first])} " in e["message"] and "height = " in e["message"]
    assert e["measured"] == height[first] and e["required"] == 1e5


def test_the_run_summary_names_the_state_out_of_range():
    r = run_cli("run", str(STATIC), "--until-s", "50", *(a for o in RUNAWAY for a in ("--set", o)))
    assert "state_out_of_range" in r.out and "height = " in r.out, r.out + r.err


def test_the_reference_run_stays_in_range():
    # The bundled static trace (60 s) on the reference profile: nothing out of range.
    run = emulate(STATIC)
    assert "state_out_of_range" not in run.events_by_kind()
