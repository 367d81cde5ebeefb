"""What the ADIS16407 model does to a coning motion, against the analytic prediction.

validation.md asks for the coning benchmark through the full device model and the difference from
ideal samples. On the bundled 10 Hz, α = 1° cone the firmware's attitude drifts about the cone axis
at ≈ 35 °/h, a hundred times the RK4 algorithm error (0.26 °/h): the device explains it exactly.
"""

from __future__ import annotations

import numpy as np
import pytest

from conftest import ROOT
from sins_fw import quaternion as q
from sins_fw.harness import emulate


def test_coning_drift_through_the_device_is_the_bartlett_filter_plus_quantisation():
    run = emulate(ROOT / "traces" / "coning_10hz.h5", overrides=["firmware.numeric=f64"])
    # Body-frame error rotation truth⁻¹ ⊗ estimate; its x component is the drift about the cone axis.
    err = q.multiply(q.conjugate(run.truth_q), run.quat)
    x = 2.0 * err[:, 1] * np.sign(err[:, 0])
    measured = np.polyfit(run.time_s, x, 1)[0]

    omega, alpha, fs, n_taps, lsb = 2 * np.pi * 10.0, np.radians(1.0), 819.2, 4, np.radians(0.05)
    # Bartlett gain at 10 Hz (two 4-tap moving averages): the cone the gyros report is smaller,
    # sin α' = |H| sin α, while the constant x rate −Ω(1 − cos α) passes at gain 1. The firmware
    # integrates the true x rate against the smaller cone's: drift −Ω(cos α' − cos α).
    u = np.pi * 10.0 / fs
    gain = (np.sin(n_taps * u) / (n_taps * np.sin(u))) ** 2
    alpha_seen = np.arcsin(gain * np.sin(alpha))
    filter_drift = -omega * (np.cos(alpha_seen) - np.cos(alpha))
    # The x rate is quantised to the 0.05 °/s LSB (a constant: it never dithers).
    wx = -omega * (1 - np.cos(alpha))
    quantisation_drift = np.round(wx / lsb) * lsb - wx
    predicted = filter_drift + quantisation_drift
    # Left out of the prediction: RK4's own coning error (0.26 °/h = 7e-5 °/s, 0.7 % of the total)
    # and the residual earth-rate compensation error; 3 % bounds them.
    assert abs(measured - predicted) < 0.03 * abs(predicted), (np.degrees(measured), np.degrees(predicted))
    assert abs(np.degrees(measured) * 3600) > 30.0  # ≈ 35 °/h: the device, not the algorithm, dominates


def _drift_about_the_cone_axis(run) -> float:  # type: ignore[no-untyped-def]
    err = q.multiply(q.conjugate(run.truth_q), run.quat)
    x = 2.0 * err[:, 1] * np.sign(err[:, 0])
    return float(np.polyfit(run.time_s, x, 1)[0])


@pytest.mark.parametrize("coning_samples", [1, 2, 3])
def test_rotation_vector_coning_drift_on_the_board_is_predicted_for_each_order(coning_samples: int):
    """The rotation vector with N coning samples on the bundled cone (α = 1°, 10 Hz), half-step
    schedule: a read every 4 ms tick is the next sample, an update every N ticks (T = N × 4 ms).

    Theory (algorithms.md §1, validation.md): the update turns the body by Φ per step; its x part is
    Σ Δθx (the constant x rate, −Ω(1 − cos α)·T) plus the coning correction, which depends only on the
    transverse increments. Those are the transverse increments of a smaller cone:
    - the Bartlett filter (two 4-tap averages at 819.2 Hz) passes the transverse rate at gain |H(Ω)|;
      its phase is linear (a pure delay common to every sample), which a cone does not notice;
    - the firmware's trapezoid increments (ωᵢ₋₁ + ωᵢ)·h/2 of a vector turning at Ω have the exact
      increment's direction and x·cot x of its length, x = Ωh/2 (the exact one is 2 sin(Ωh/2)/Ω·|ω⊥|).
    So sin α' = |H| · x cot x · sin α, and the drift is the algorithm's own coning error for the
    α' cone, e_N, plus the x rate the correction does not balance, −Ω(cos α' − cos α), plus the x
    rate's quantisation (as for RK4 above). e_N from the classical N-sample error with the previous
    interval's term for N = 1 (rotvec.rs): −α²Ω(ΩT)⁴/60, −α²Ω(ΩT)⁴/960, −α²Ω(ΩT)⁶/204120 (sign:
    the update lags the true coning rotation, as the x rate does); all three are below 0.3 °/h here.
    """
    n = coning_samples
    run = emulate(
        ROOT / "traces" / "coning_10hz.h5",
        overrides=[
            "firmware.numeric=f64",
            "firmware.algorithm=rotation-vector",
            f"firmware.coning_samples={n}",
        ],
    )
    measured = _drift_about_the_cone_axis(run)

    omega, alpha, fs, n_taps, lsb = 2 * np.pi * 10.0, np.radians(1.0), 819.2, 4, np.radians(0.05)
    h = 0.004  # the timer period: one sample per tick
    t_step = n * h
    u = np.pi * 10.0 / fs
    bartlett = (np.sin(n_taps * u) / (n_taps * np.sin(u))) ** 2
    x = omega * h / 2
    trapezoid = x / np.tan(x)
    alpha_seen = np.arcsin(bartlett * trapezoid * np.sin(alpha))
    cone_drift = -omega * (np.cos(alpha_seen) - np.cos(alpha))
    wx = -omega * (1 - np.cos(alpha))
    quantisation_drift = np.round(wx / lsb) * lsb - wx
    a2w, wt = alpha_seen**2 * omega, omega * t_step
    algorithm_drift = -{1: a2w * wt**4 / 60, 2: a2w * wt**4 / 960, 3: a2w * wt**6 / 204120}[n]
    predicted = cone_drift + quantisation_drift + algorithm_drift
    # Left out, as for RK4 above: the residual earth-rate compensation error and the sample-and-hold
    # jitter (the read takes the latest 819.2 Hz sample, 0-1.22 ms old, as at the tick: its second
    # order shortens the increments by ≈ Ω²·E[(δᵢ − δᵢ₋₁)²]/8 = 1.5e-4, ≈ 1 % of the drift); 3 %
    # bounds them.
    assert abs(measured - predicted) < 0.03 * abs(predicted), (
        n,
        np.degrees(measured) * 3600,
        np.degrees(predicted) * 3600,
    )
