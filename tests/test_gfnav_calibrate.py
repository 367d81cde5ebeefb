"""`sins-fw calibrate` and the `twelve-position` synth scenario (issue "Gyro-free navigation", item 3).

The core's formulas are checked in Rust (`gfnav::calib` tests: exact on the linear model, second order
on the product model, the printed bias sets off by g/8 and θ·g/3). Here the whole path: a synthetic
twelve-position trace, known errors put on its columns, the rests found from the `moving` column, and
the terms coming back."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest

from conftest import run_cli
from sins_fw import earth, synth
from sins_fw.cli.calibrate import calibrate
from sins_fw.errors import TraceError

# Short dwells and moves: the formulas only need each rest's mean (the trace is noise-free).
PARAMS = {"dwell_s": 0.5, "move_s": 1.0, "rate_hz": "200"}

ACCEL_BIAS = np.array([0.012, -0.02, 0.035]) * earth.G0  # m/s²
ACCEL_SCALE = np.array([2e-3, -1.5e-3, 1e-3])
# Misalignment rows as in gfnav::calib: x (0, θxz, −θxy), y (−θyz, 0, θyx), z (θzy, −θzx, 0).
MIS = {"xy": 1e-3, "xz": -2e-3, "yx": 1.5e-3, "yz": 0.5e-3, "zx": -1e-3, "zy": 2e-3}
RATE_BIAS = np.radians([0.1, -0.05, 0.02])  # rad/s
RATE_SCALE = np.array([-1e-3, 2e-3, 5e-4])


def _matrix(scale: np.ndarray) -> np.ndarray:
    m = MIS
    dc = np.array([[0.0, m["xz"], -m["xy"]], [-m["yz"], 0.0, m["yx"]], [m["zy"], -m["zx"], 0.0]])
    return np.eye(3) + np.diag(scale) + dc


@pytest.fixture(scope="module")
def trace() -> synth.PhysicalTrace:
    return synth.generate("twelve-position", **PARAMS)


def _with_errors(tr: synth.PhysicalTrace) -> synth.PhysicalTrace:
    f = tr.accel_g * earth.G0
    w = np.radians(tr.gyro_dps)
    f_err = ACCEL_BIAS + f @ _matrix(ACCEL_SCALE).T
    w_err = RATE_BIAS + w @ _matrix(RATE_SCALE).T
    return dataclasses.replace(tr, accel_g=f_err / earth.G0, gyro_dps=np.degrees(w_err))


def test_the_trace_dwells_at_the_table_positions(trace: synth.PhysicalTrace) -> None:
    """At each rest the specific force is γ along the upward axis of Table 3.1 (1.1: z down reads −γ)."""
    g = float(earth.normal_gravity(math.radians(28.20021), 5.13145))
    rest = ~trace.moving
    f = trace.accel_g[rest] * earth.G0
    assert np.allclose(np.linalg.norm(f, axis=1), g, rtol=0, atol=1e-9)
    assert np.allclose(trace.accel_g[0] * earth.G0, [0.0, 0.0, -g], atol=1e-9)  # position 1.1: z down


def test_recovers_the_errors_put_on_the_trace(trace: synth.PhysicalTrace) -> None:
    """Linear-model errors on the columns: every term back to round-off (the rests are exact constants;
    1e-9 relative for the rate meter, whose differences of ~1e-4 rad/s readings are divided by 2Ω)."""
    r = calibrate(_with_errors(trace), "synthetic")
    np.testing.assert_allclose(r["accel"]["bias"], ACCEL_BIAS, rtol=0, atol=1e-12)
    np.testing.assert_allclose(r["accel"]["scale"], ACCEL_SCALE, rtol=0, atol=1e-12)
    for k, v in MIS.items():
        assert r["accel"]["misalignment"][k] == pytest.approx(v, abs=1e-12)
        assert r["rate"]["misalignment"][k] == pytest.approx(v, abs=1e-9)
    np.testing.assert_allclose(r["rate"]["bias"], RATE_BIAS, rtol=0, atol=1e-14)
    np.testing.assert_allclose(r["rate"]["scale"], RATE_SCALE, rtol=0, atol=1e-9)
    printed = calibrate(_with_errors(trace), "synthetic", printed=True)
    # The printed a_z0 set {1, 2, 3, 6, 7, 10, 11, 12}: off by about g/8 (spec correction).
    assert abs(printed["accel"]["bias"][2] - ACCEL_BIAS[2]) == pytest.approx(r["gravity_m_s2"] / 8, rel=0.01)


def test_cli_reports_rate_terms_unobservable_with_the_adxl345(
    tmp_path: Path, trace: synth.PhysicalTrace
) -> None:
    path = tmp_path / "twelve.h5"
    _with_errors(trace).save(path)
    res = run_cli("calibrate", str(path), "--part", "adxl345", "--json")
    assert res.code == 0, res.err
    report = json.loads(res.out)
    assert report["rate"] is None
    e = report["earth_rate"]
    assert 7.5 < e["orders_below_resolution"] < 7.7  # Ω² 5.3e-9 against 0.19 rad²/s² at l = 0.1 m
    np.testing.assert_allclose(report["accel"]["bias"], ACCEL_BIAS, atol=1e-12)
    text = run_cli("calibrate", str(path), "--part", "adxl345")
    assert text.code == 0 and "unobservable" in text.out


def test_a_trace_without_twelve_rests_is_refused(tmp_path: Path) -> None:
    static = synth.generate("static", duration_s=2.0)
    with pytest.raises(TraceError, match="1 rests"):
        calibrate(static, "static.h5")
    path = tmp_path / "static.csv"
    static.save(path)
    res = run_cli("calibrate", str(path))
    assert res.code == 2 and "expected the twelve positions" in res.err and "Traceback" not in res.err
