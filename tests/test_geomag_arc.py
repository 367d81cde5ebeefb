"""The geomagnetic–gyro board on its mission: a spinning body on a drag-free ballistic arc
(`sins-fw synth spin --trajectory ballistic`, launched at 500 m/s, 45° elevation, north; spin
1000 °/s; the axis nodding ±5° at 0.2 Hz), issue 40 item 1. The firmware starts from the launch
(`geomag.launch_elevation_deg`, `launch_azimuth_deg`: the trace's `launch_*` metadata), compensates
the cross-axis gyros' lag on the spinning body (`geomag.cross_gyro_cutoff_hz`) and checks its axis
against the magnetometer (`geomag.aid_axis_gate_deg`, event `mag_aid_axis`). The aided roll error
stays within `spin_table.aided_roll_bound` (from the gains and the sensor presets) over the whole
flight; started level (the firmware before the launch keys: 11° off after 3.5 s, 21° after 20 s with
no event) the aid is held at the first update with a warning instead of steering the roll wrong.
Each emulation of the 72 s flight costs about 1 s of CPU."""

from __future__ import annotations

import json

import numpy as np
import pytest

from conftest import run_cli
from sins_fw import spin_table
from sins_fw.harness import emulate
from sins_fw.profile import load_profile
from sins_fw.traces import CheckedTrace

FIELD = spin_table.DEFAULT_FIELD
M_N = spin_table.field_enu(*FIELD)
LAUNCH = (500.0, 45.0, 0.0)


@pytest.fixture(scope="module")
def arc() -> CheckedTrace:
    return spin_table._arc_trace(1000.0, 72.0, LAUNCH, FIELD)


def _profile(unit: int, ideal: bool, extra: list[str]) -> object:
    return load_profile(
        "geomag",
        [
            f"errors.seed={unit}",
            f"geomag.ideal_sensors={'true' if ideal else 'false'}",
            "geomag.field_enu_gauss=[{}]".format(", ".join(repr(float(x)) for x in M_N)),
            "geomag.mag_cutoff_hz=0.0",
            *(spin_table.IDEAL_CALIBRATION if ideal else []),
            *extra,
        ],
    )


def test_the_trace_carries_the_launch(arc: CheckedTrace) -> None:
    meta = arc.trace.metadata
    assert (meta["launch_elevation_deg"], meta["launch_azimuth_deg"], meta["launch_speed_mps"]) == (
        "45",
        "0",
        "500",
    )
    assert spin_table.launch_overrides(meta) == [
        "geomag.launch_elevation_deg=45.0",
        "geomag.launch_azimuth_deg=0.0",
    ]
    assert spin_table.launch_overrides({}) == []


@pytest.mark.parametrize(("ideal", "units"), [(True, (0,)), (False, (0, 1, 2))])
def test_aided_roll_within_the_preset_bound_over_the_flight(
    arc: CheckedTrace, ideal: bool, units: tuple
) -> None:
    """Every update of the 72 s flight: |roll error| ≤ the bound. Ideal sensors: the bound is the
    spin gyro's group delay (2.2°, taken out by the loop), the ADC's quantisation, and the earth's and
    transport rate the firmware leaves out (a tilt (Ω + v/R)·t seen through cot α as the axis comes
    within 17° of the field at landing): 2.27 → 4.8°; measured 1.25° in the spin-up, ≤ 1.32° at the
    end. Real units (3σ unit draws, 6σ noise): 16.0 → 41°; measured ≤ 7.4° in the spin-up (δk·ω),
    ≤ 2.4° on the arc. With the cross-axis lag uncompensated the ideal run's error grows to 8.3° at
    landing, past its 4.8° bound (the second half of the test)."""
    launch = spin_table.launch_overrides(arc.trace.metadata)
    bound = None
    for unit in units:
        run = emulate(arc, _profile(unit, ideal, launch))
        assert run.truth_q is not None
        if bound is None:
            bound = spin_table.aided_roll_bound(
                run.time_s, run.truth_q, M_N, 1000.0, ideal=ideal, transport_rate=500.0 / 6.371e6
            )
        err = np.abs(spin_table.roll_errors(run.quat, run.truth_q))
        worst = int(np.argmax(err - bound))
        at, e_deg, b_deg = run.time_s[worst], np.degrees(err[worst]), np.degrees(bound[worst])
        print(f"unit {unit}: max |error| {np.degrees(err.max()):.3f}°, nearest the bound at {at:.1f} s: "
              f"{e_deg:.3f}° ≤ {b_deg:.3f}°")  # fmt: skip
        assert np.all(err <= bound), (unit, float(e_deg), float(b_deg))
        assert not run.events_by_kind().get("mag_aid_axis"), run.events
    if ideal:
        run = emulate(arc, _profile(0, True, [*launch, "geomag.cross_gyro_cutoff_hz=0"]))
        assert run.truth_q is not None
        err = np.abs(spin_table.roll_errors(run.quat, run.truth_q))
        assert bound is not None and np.any(err > bound), "the cross-axis lag must matter on the arc"


def test_a_level_start_is_not_silent(arc: CheckedTrace) -> None:
    """Without the launch keys the firmware starts level at yaw 90° (north) on a body launched at
    45°: the magnetometer's angle between axis and field is 44.9° off the attitude's, so the axis
    check holds the aid at the first update with a `mag_aid_axis` warning (before it, the aid
    steered the roll 11° off by 3.5 s, 21° by 20 s, silently)."""
    run = emulate(arc, _profile(0, True, ["firmware.initial_yaw_deg=90"]), until_s=5.0)
    axis = [e for e in run.events if e["kind"] == "mag_aid_axis"]
    assert axis and axis[0]["t_s"] < 0.01 and "held" in axis[0]["message"]
    assert axis[0]["severity"] == "warning"


def test_spin_table_along_the_arc_cli() -> None:
    """`sins-fw spin-table --trajectory ballistic`: the aided and gyro-only roll error per window
    of the flight, with the bound and the units within it (2 units, 20 s of the arc)."""
    r = run_cli(
        "spin-table", "--trajectory", "ballistic", "--runs", "2", "--duration-s", "20", "--json"
    )  # fmt: skip
    assert r.code == 0, r.err
    table = json.loads(r.out)
    block = table["blocks"][0]
    assert table["trajectory"] == "ballistic" and block["spin_dps"] == 1000.0
    assert len(block["rows"]) == len(spin_table.ARC_WINDOWS)
    for row in block["rows"]:
        assert row["within"] == 2
        assert row["aided_deg"]["max"] <= row["bound_deg"]
        assert row["aided_deg"]["max"] < row["gyro_only_deg"]["max"] or row["t_s"][0] < 4.0
    text = run_cli("spin-table", "--trajectory", "ballistic", "--runs", "2", "--duration-s", "20")
    assert text.code == 0 and "roll error along the ballistic arc" in text.out
    bad = run_cli("spin-table", "--trajectory", "ballistic", "--duration-s", "80")
    assert bad.code == 2 and "lands after 72.160 s" in bad.err
