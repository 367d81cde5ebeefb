"""Accuracy metrics on constructed quaternions with known errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sins_fw import quaternion as quat
from sins_fw.metrics import accuracy, align_heading, attitude_errors, wrap_deg

Z = np.array([0.0, 0.0, 1.0])
TOL = 1e-9  # degrees: float64 trigonometry on O(1) values, far below any real error


def _random_attitudes(n: int, seed: int = 1) -> np.ndarray:
    q = np.random.default_rng(seed).normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def _rot(axis, deg):
    axis = np.asarray(axis, dtype=float)
    return quat.from_axis_angle(axis / np.linalg.norm(axis), math.radians(deg))


def test_broad_errors_of_known_heading_and_inclination_errors():
    truth = _random_attitudes(200)
    heading, tilt = 3.0, 4.0
    error = quat.multiply(
        _rot(Z, heading), _rot([1.0, 2.0, 0.0], tilt)
    )  # earth-frame error, z then horizontal
    est = quat.multiply(error, truth)
    e = attitude_errors(est, truth)
    np.testing.assert_allclose(e.heading, heading, atol=TOL)
    np.testing.assert_allclose(e.inclination, tilt, atol=TOL)
    total = 2 * math.degrees(
        math.acos(math.cos(math.radians(heading / 2)) * math.cos(math.radians(tilt / 2)))
    )
    np.testing.assert_allclose(e.total, total, atol=TOL)
    # The sign of q does not matter (q and −q are one attitude).
    np.testing.assert_allclose(attitude_errors(-est, truth).total, total, atol=TOL)


def test_euler_errors_are_wrapped_differences():
    truth = quat.from_euler(*np.radians([10.0, 20.0, 359.5]))[None, :]
    est = quat.from_euler(*np.radians([11.0, 19.5, 0.5]))[None, :]
    e = attitude_errors(est, truth)
    assert e.roll[0] == pytest.approx(1.0, abs=TOL)
    assert e.pitch[0] == pytest.approx(-0.5, abs=TOL)
    assert e.yaw[0] == pytest.approx(1.0, abs=TOL)  # 0.5 − 359.5 wraps to +1
    np.testing.assert_array_equal(wrap_deg([180.0, -180.0, 540.0, -190.0]), [180.0, 180.0, 180.0, 170.0])


def test_rmse_uses_the_mask_and_skips_nan_truth():
    truth = np.tile([1.0, 0.0, 0.0, 0.0], (5, 1))
    angles = [1.0, 2.0, 7.0, 3.0, 9.0]
    est = np.stack([_rot([1.0, 0.0, 0.0], a) for a in angles])
    truth[2] = np.nan  # lost truth: skipped
    mask = np.array([True, True, True, True, False])  # the last row is outside the movement phase
    report = accuracy(est, truth, mask)
    assert report.samples == 3 and report.skipped_nan_truth == 1
    assert report.rmse_total_deg == pytest.approx(math.sqrt((1 + 4 + 9) / 3), abs=TOL)
    assert report.rmse_heading_deg == pytest.approx(0.0, abs=TOL)
    assert report.max_inclination_deg == pytest.approx(3.0, abs=TOL)
    assert not report.heading_aligned and "aligned" not in report.summary()


def test_heading_alignment_removes_a_constant_heading_offset_once():
    truth = _random_attitudes(100, seed=5)
    truth[:3] = np.nan  # the first valid movement sample is row 4 (row 3 is outside the mask)
    mask = np.ones(100, dtype=bool)
    mask[3] = False
    est = quat.multiply(
        _rot(Z, 25.0), quat.multiply(_rot([0.0, 1.0, 0.0], 2.0), np.nan_to_num(truth, nan=0.5))
    )
    aligned, delta, row = align_heading(est, truth, mask)
    assert row == 4
    assert delta == pytest.approx(25.0, abs=TOL)
    e = attitude_errors(aligned[4:], truth[4:])
    np.testing.assert_allclose(e.heading, 0.0, atol=TOL)
    np.testing.assert_allclose(e.inclination, 2.0, atol=TOL)
    report = accuracy(est, truth, mask, align=True)
    assert report.heading_aligned and report.alignment_row == 4
    assert report.heading_alignment_deg == pytest.approx(25.0, abs=TOL)
    assert report.rmse_total_deg == pytest.approx(2.0, abs=TOL)
    assert "heading aligned to the truth once, by 25.000° at row 4" in report.summary()
    assert accuracy(est, truth, mask).rmse_heading_deg == pytest.approx(25.0, abs=TOL)


def test_total_error_is_well_conditioned_on_unnormalised_single_precision_estimates():
    """Issue 24, item 6. A firmware estimate in single precision has norm 1 ± a few 1e-8 (one ulp
    of 1 in f32 is 1.19e-7). With the truth at the identity and the estimate (1 − δ)·identity, the
    true error is 0 but 2·acos(|w|) gives 2·acos(1 − δ) ≈ 2·√(2δ): 0.0512° for δ = 1e-7. With the
    estimate (1 + δ)·R_x(0.01°), w = (1 + δ)·cos(0.005°) = (1 + 1e-7)(1 − 3.81e-9) > 1 is clipped to
    1 and 2·acos gives 0 where the error is 0.01°. The atan2 form gives 0 and 0.01° (to rounding,
    a few 1e-16 relative: the norm divides out)."""
    delta = 1e-7
    truth = np.array([[1.0, 0.0, 0.0, 0.0]] * 2)
    est = np.stack([(1 - delta) * truth[0], (1 + delta) * _rot([1.0, 0.0, 0.0], 0.01)])
    old = np.degrees(2.0 * np.arccos(np.clip(np.abs(quat.multiply(est, quat.conjugate(truth))[:, 0]), 0, 1)))
    assert old[0] == pytest.approx(math.degrees(2 * math.acos(1 - delta)), rel=1e-6)  # 0.0512°
    assert old[0] > 0.05 and old[1] == 0.0, "the old formula is wrong by the derived amounts"
    e = attitude_errors(est, truth)
    assert e.total[0] == 0.0
    assert e.total[1] == pytest.approx(0.01, rel=1e-12)
    assert e.inclination[1] == pytest.approx(0.01, rel=1e-12)
    # The float32 estimate the firmware holds, converted exactly: same answer.
    e32 = attitude_errors(est.astype(np.float32), truth)
    assert e32.total[0] < 1e-6 and e32.total[1] == pytest.approx(0.01, rel=1e-5)
    assert accuracy(est, truth).max_total_deg == pytest.approx(0.01, rel=1e-12)


def test_every_total_error_is_the_one_function(monkeypatch):
    """The run summary, the report page, the BROAD metrics and parity all take the total rotation
    angle from sins_fw.quaternion.rotation_angle (and nothing else computes one)."""
    import matplotlib

    matplotlib.use("Agg")
    from sins_fw import parity, report, report_page, synth
    from sins_fw.harness import emulate

    run = emulate(synth.generate("static", duration_s=2.0))
    calls: list[str] = []
    real = quat.rotation_angle

    def counted(q, q_ref):
        calls.append("called")
        return real(q, q_ref)

    monkeypatch.setattr(quat, "rotation_angle", counted)
    for name, use in {
        "run summary": lambda: report.summarise(run),
        "report page": lambda: report_page.report_figure(run),
        "BROAD metrics": lambda: accuracy(run.quat, run.quat),
        "parity": lambda: parity.attitude_difference_deg(run.quat, run.quat),
    }.items():
        calls.clear()
        use()
        assert calls, f"{name} does not use quaternion.rotation_angle"
