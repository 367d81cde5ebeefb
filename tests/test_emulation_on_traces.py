"""The reference firmware on real and synthetic traces: BROAD recordings end to end, and the
indexing-table experiment with ideal sensors (algorithm and quantisation only)."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import BROAD
from sins_fw import report, synth
from sins_fw.broad import import_broad
from sins_fw.harness import emulate

TRIALS = sorted(BROAD.glob("*.hdf5")) if BROAD.is_dir() else []


@pytest.mark.skipif(not TRIALS, reason=f"BROAD recordings not found in {BROAD}")
@pytest.mark.parametrize("path", TRIALS, ids=lambda p: p.stem)
def test_broad_trial_runs_with_saturation_events_and_metrics(path):
    trace = import_broad(path)
    run = emulate(trace)
    assert run.cycles > 0
    s = report.summarise(run, trace=str(path))
    broad = s["attitude_error"]["broad"]
    # The reference firmware only integrates the gyro: its error grows, but it is a finite number.
    rmse = [broad["rmse_total_deg"], broad["rmse_heading_deg"], broad["rmse_inclination_deg"]]
    assert np.isfinite(rmse).all()
    # A rate beyond the rated ±300 °/s (or a force beyond ±18 g) reaches the device: it flags the
    # overrange (an event per episode). Within the range the published decode never goes stale.
    over = np.abs(trace.gyro_dps).max() > 300.0 or np.abs(trace.accel_g).max() > 18.0
    kinds = run.events_by_kind()
    assert ("sensor_overrange" in kinds) == over, (np.abs(trace.gyro_dps).max(), kinds)
    if not over:
        assert "stale_decode" not in kinds


def _held_angles(run, trace, axis_index):
    """Firmware angle and truth at the end of each dwell (the last step before the table moves)."""
    truth = run.truth_q
    moving = run.moving.astype(bool)
    ends = np.flatnonzero(~moving[:-1] & moving[1:])  # last still step before each move
    ends = np.append(ends, len(moving) - 1)
    est = run.euler_deg[ends][:, axis_index]
    from sins_fw import quaternion as q

    roll, pitch, yaw = q.to_euler(truth[ends])
    true = np.degrees([roll, pitch, yaw][axis_index])
    return est, true


def test_indexing_table_ideal_sensors_no_earth_rate_within_005_deg():
    """The ±30° table about each axis, ideal sensors, earth-rate compensation off: every held angle is
    within 0.05° of truth. What is left is the algorithm and the 0.05 °/s quantisation of the table's
    rates (a 30° move at 20 °/s ≈ 2 s: a rate error below half an LSB gives < 0.05°)."""
    for axis, k in (("x", 0), ("y", 1), ("z", 2)):
        trace = synth.generate("indexing-table", "pm30", axis=axis)
        run = emulate(trace, overrides=["firmware.earth_rate=false"])
        est, true = _held_angles(run, trace, k)
        err = (est - true + 180.0) % 360.0 - 180.0
        assert np.abs(err).max() < 0.05, (axis, err)


def test_earth_rate_compensation_with_a_quantised_gyro_drifts_at_the_earth_rate():
    """One gyro LSB (0.05 °/s) is twelve times the earth rate (0.0042 °/s): with ideal sensors and no
    noise to dither it, a still ADIS16407 reads exactly zero, and the firmware subtracts an earth rate
    the gyro never saw. The attitude then drifts at the earth rate itself, 15.04 °/h projected on the
    navigation axes: over 60 s the drift angle is ω_ie·60 s = 0.2507°."""
    trace = synth.generate("static", duration_s=60.0)
    on = emulate(trace, overrides=["firmware.numeric=f64"])
    off = emulate(trace, overrides=["firmware.numeric=f64", "firmware.earth_rate=false"])
    assert np.all(on.read_rate == 0.0), "a still, noise-free ADIS16407 reads zero"
    err_on = report.attitude_summary(on)["euler"]["total"]["final_deg"]
    err_off = report.attitude_summary(off)["euler"]["total"]["final_deg"]
    omega_ie_deg_s = np.degrees(7.292115e-5)
    expected = omega_ie_deg_s * on.time_s[-1]
    assert err_on == pytest.approx(expected, rel=1e-3), (err_on, expected)
    # Without compensation the firmware holds still, and so does the truth in the local-level frame:
    # the quantised gyro hides the earth rate, so there is nothing to compensate.
    assert err_off == 0.0
