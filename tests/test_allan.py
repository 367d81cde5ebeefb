"""Allan deviation: the estimator against a direct implementation and against theory, and the ARW and
bias-instability readers on synthetic records of known parameters (numpy only, no device model).

Statistics used for the tolerances (overlapping estimator, n rate samples, cluster size m): the
relative standard error of an Allan-deviation point is 1/√(2·edf), with edf ≈ 1.5·n/m for white
rate noise, ≈ 1.25·n/m for flicker and ≈ n/m for a random walk of the rate (Howe, Allan & Barnes,
"Properties of signal sources and measurement methods", 1981; the edf approximations of Stable32).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from sins_fw.allan import (
    FLICKER_FLOOR_FACTOR,
    bias_instability,
    cluster_sizes,
    gauss_markov_avar,
    overlapping_adev,
    per_sqrt_hour,
    random_walk,
)

# ADIS16407 preset values (rust/core/src/device/error_model.rs): gyro ARW 2.0 °/√h and in-run
# bias stability 0.007 °/s, read as the Allan minimum (ADI's convention).
ARW_COEFFICIENT = 2.0 / 60.0  # °/s/√Hz
ALLAN_FLOOR = 0.007  # °/s


def first_order_recursion(drive: np.ndarray, a: float) -> np.ndarray:
    """x_k = a·x_{k−1} + drive_k (x_{−1} = 0) by a parallel prefix scan: after the pass with shift s,
    x_k = Σ_{j<2s} a^j drive_{k−j}; log2(n) vectorised passes instead of an n-step Python loop."""
    x = drive.copy()
    shift, power = 1, a
    while shift < x.size and power > 1e-20:  # a^shift below 1e-20: further terms are below rounding
        x[shift:] += power * x[:-shift]
        shift *= 2
        power *= power
    return x


def gauss_markov(n: int, fs: float, sigma: float, tau: float, rng: np.random.Generator) -> np.ndarray:
    """A stationary first-order Gauss–Markov record, exactly discretised (as in the Rust model)."""
    dt_over_tau = 1.0 / (fs * tau)
    drive = rng.standard_normal(n) * sigma * math.sqrt(-math.expm1(-2.0 * dt_over_tau))
    drive[0] = sigma * rng.standard_normal()  # x₀ ~ N(0, σ²): stationary from the first sample
    return first_order_recursion(drive, math.exp(-dt_over_tau))


def flicker_bank(floor: float, tau_min: float, tau_max: float) -> list[tuple[float, float]]:
    """(σ, τ) of the Rust `flicker_bank` at one term per decade: equal variances B²·ln r/π."""
    intervals = max(1, round(math.log10(tau_max / tau_min)))
    ratio = (tau_max / tau_min) ** (1.0 / intervals)
    sigma = floor / FLICKER_FLOOR_FACTOR * math.sqrt(math.log(ratio) / math.pi)
    return [(sigma, tau_min * ratio**k) for k in range(intervals + 1)]


def test_cumulative_sum_estimator_equals_the_direct_definition():
    rng = np.random.default_rng(3)
    y = rng.standard_normal(500).cumsum() * 0.01 + rng.standard_normal(500) + 5.0
    fs = 4.0
    curve = overlapping_adev(y, fs, clusters=[1, 2, 7, 50, 250])
    for m, adev in zip(curve.clusters, curve.adev, strict=True):
        averages = np.convolve(y, np.ones(m) / m, mode="valid")  # all overlapping m-sample means
        direct = math.sqrt(0.5 * np.mean((averages[m:] - averages[:-m]) ** 2))
        assert adev == pytest.approx(direct, rel=1e-12)
    assert np.allclose(curve.tau, curve.clusters / fs)


def test_gauss_markov_curve_matches_theory():
    """A single Gauss–Markov term (σ = 1, T = 10 s) at τ from 0.1 T to 10 T, including its peak
    (0.6174 σ at 1.893 T). Tolerance 5 standard errors with the conservative edf = (n/m)(1 − 3m/n)
    (random-walk-of-rate case; the white and flicker cases have more degrees of freedom)."""
    fs, n, sigma, tau_c = 10.0, 2_000_000, 1.0, 10.0
    x = gauss_markov(n, fs, sigma, tau_c, np.random.default_rng(20))
    clusters = np.array([10, 100, round(1.8926 * tau_c * fs), 1000])
    curve = overlapping_adev(x, fs, clusters=clusters)
    theory = np.sqrt(gauss_markov_avar(curve.tau, sigma, tau_c))
    assert theory[2] == pytest.approx(0.6174, abs=1e-4)
    # The Taylor branch (x < 0.01) and the closed form meet.
    below, at = gauss_markov_avar([0.01 * (1.0 - 1e-12), 0.01], 1.0, 1.0)
    assert below == pytest.approx(at, rel=1e-10)
    for m, measured, expected in zip(clusters, curve.adev, theory, strict=True):
        edf = n / m * (1.0 - 3.0 * m / n)
        assert abs(measured / expected - 1.0) < 5.0 / math.sqrt(2.0 * edf), (m, measured, expected)


def test_arw_and_bias_instability_read_off_a_synthetic_record():
    """White noise of 2.0 °/√h plus a flicker bank with an Allan floor of 0.007 °/s: the readers
    must return both within 10 %.

    Why this record is a sound test (n = 4e6 samples at 2 Hz, 23 days; any seed):
    - ARW is read on τ = 0.5 … 1 s (m = 1, 2): edf ≈ 1.5 n/m ≥ 3e6, standard error < 0.05 %. The
      bank (τ 10 s … 1e6 s) adds < 0.5 % there; the test computes this systematic part from theory.
    - The floor is read on τ = 450 … 2000 s. Below, white noise lifts the curve: √(1 + T_c/τ) with
      crossover T_c = (N/floor)² = 22.7 s, ≤ 2.5 % at 450 s. Above, the record gets short: at
      2000 s, m = 4000, edf ≈ 1.25 n/m = 1250, standard error 2 %. The bank's ripple is ±1.5 %.
      The expected reading (theory, computed below) is within 3 % of the floor; the minimum of
      the window's correlated points is biased low by about one standard error; so 10 % leaves
      more than 3.5 standard errors for chance.
    """
    fs, n = 2.0, 4_000_000
    rng = np.random.default_rng(2024)
    rate = rng.standard_normal(n) * ARW_COEFFICIENT * math.sqrt(fs)
    bank = flicker_bank(ALLAN_FLOOR, 10.0, 1e6)
    for sigma, tau in bank:
        rate += gauss_markov(n, fs, sigma, tau, rng)
    curve = overlapping_adev(rate, fs)

    def theory(tau: np.ndarray) -> np.ndarray:
        avar = ARW_COEFFICIENT**2 / tau
        for sigma, tau_c in bank:
            avar = avar + gauss_markov_avar(tau, sigma, tau_c)
        return np.sqrt(avar)

    arw_window = (0.5, 1.0)
    reading = random_walk(curve, *arw_window)
    sel = (curve.tau >= arw_window[0]) & (curve.tau <= arw_window[1])
    expected_arw = math.exp(float(np.mean(np.log(theory(curve.tau[sel]) * np.sqrt(curve.tau[sel])))))
    assert abs(expected_arw / ARW_COEFFICIENT - 1.0) < 0.005
    assert abs(reading.slope + 0.5) < 0.02
    assert abs(per_sqrt_hour(reading.coefficient) / 2.0 - 1.0) < 0.10, reading

    floor_window = (450.0, 2000.0)
    floor = bias_instability(curve, *floor_window)
    sel = (curve.tau >= floor_window[0]) & (curve.tau <= floor_window[1])
    assert abs(float(theory(curve.tau[sel]).min()) / ALLAN_FLOOR - 1.0) < 0.03
    assert abs(floor.allan_minimum / ALLAN_FLOOR - 1.0) < 0.10, floor
    assert floor.bias_instability == pytest.approx(floor.allan_minimum / FLICKER_FLOOR_FACTOR)
    assert abs(floor.bias_instability / (ALLAN_FLOOR / FLICKER_FLOOR_FACTOR) - 1.0) < 0.10


def test_cluster_grid_and_input_errors():
    m = cluster_sizes(1000)
    assert m[0] == 1 and m[-1] == 100 and np.all(np.diff(m) > 0)
    assert per_sqrt_hour(ARW_COEFFICIENT) == pytest.approx(2.0)
    with pytest.raises(ValueError, match="at least 3 samples"):
        overlapping_adev([1.0, 2.0], 1.0)
    with pytest.raises(ValueError, match="NaN"):
        overlapping_adev([1.0, float("nan"), 2.0, 3.0], 1.0)
    with pytest.raises(ValueError, match="cluster sizes"):
        overlapping_adev(np.zeros(10), 1.0, clusters=[6])
    with pytest.raises(ValueError, match="fs"):
        overlapping_adev(np.zeros(10), 0.0)
    curve = overlapping_adev(np.random.default_rng(1).standard_normal(100), 1.0)
    with pytest.raises(ValueError, match="fewer than 2"):
        random_walk(curve, 50.0, 60.0)
    with pytest.raises(ValueError, match="no curve point"):
        bias_instability(curve, 1e3, 1e4)
