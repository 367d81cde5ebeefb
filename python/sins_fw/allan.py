"""Allan deviation of a rate record and the two numbers read off it: the random-walk coefficient
(angle random walk for a gyro, velocity random walk for an accelerometer) and bias instability.

Conventions (IEEE Std 952; the same as the Rust error model, ``device::error_model``):

- White rate noise of coefficient N gives σ_A(τ) = N/√τ; N is "the value at τ = 1 s on the −1/2
  line", in output units/√Hz (°/s/√Hz = °/√s). ARW in °/√h is 60·N (:func:`per_sqrt_hour`).
- Flicker (bias-instability) noise of IEEE coefficient B gives a flat floor σ_A = 0.6643·B
  (:data:`FLICKER_FLOOR_FACTOR` = √(2 ln 2/π)). ADI quotes "in-run bias stability" as the Allan
  minimum itself, so compare a data-sheet figure with :attr:`BiasInstabilityReading.allan_minimum`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

FLICKER_FLOOR_FACTOR: float = math.sqrt(2.0 * math.log(2.0) / math.pi)
"""Allan-deviation floor per unit of flicker bias instability B: √(2 ln 2/π) ≈ 0.6643."""


@dataclass(frozen=True)
class AllanCurve:
    """An overlapping Allan-deviation curve."""

    tau: NDArray[np.float64]
    """Averaging times, s."""
    adev: NDArray[np.float64]
    """Allan deviation at each τ, in the units of the rate record."""
    clusters: NDArray[np.int64]
    """Cluster sizes m (τ = m / fs)."""
    samples: int
    """Number of rate samples the curve was computed from."""


@dataclass(frozen=True)
class RandomWalkReading:
    """The white-noise coefficient read off a curve."""

    coefficient: float
    """N: the value at τ = 1 s of the −1/2 line fitted in the window, units/√Hz."""
    slope: float
    """Free least-squares log-log slope in the window (−0.5 when white noise dominates there)."""
    tau_range: tuple[float, float]
    """Smallest and largest τ used, s."""


@dataclass(frozen=True)
class BiasInstabilityReading:
    """The floor of a curve."""

    allan_minimum: float
    """Smallest Allan deviation in the window (ADI's "in-run bias stability")."""
    tau_at_minimum: float
    """τ of that minimum, s."""
    bias_instability: float
    """allan_minimum / floor factor (IEEE-952 B with the default factor)."""


def cluster_sizes(samples: int, per_decade: int = 10, max_fraction: float = 0.1) -> NDArray[np.int64]:
    """Log-spaced unique cluster sizes from 1 to ``max_fraction · samples``.

    The default stops at a tenth of the record: beyond it a point rests on fewer than about ten
    independent differences and the curve is too noisy to read a minimum from.
    """
    if samples < 3:
        raise ValueError(f"an Allan curve needs at least 3 samples, got {samples}")
    if per_decade < 1:
        raise ValueError(f"per_decade must be ≥ 1, got {per_decade}")
    if not 0.0 < max_fraction <= 0.5:
        raise ValueError(f"max_fraction must be in (0, 0.5], got {max_fraction}")
    largest = max(1, math.floor(max_fraction * samples))
    decades = math.log10(largest)
    grid = np.logspace(0.0, decades, num=max(2, math.ceil(decades * per_decade) + 1))
    return np.unique(np.floor(grid).astype(np.int64))


def overlapping_adev(rate: ArrayLike, fs: float, clusters: ArrayLike | None = None) -> AllanCurve:
    """Overlapping Allan deviation of a rate record sampled at ``fs`` Hz.

    The record is integrated once (cumulative sum, mean removed: a constant rate is a linear trend
    the second difference cancels anyway, and removing it keeps the integral small and exact);
    then for each cluster size m, with θ the N + 1 integral points and τ = m/fs,
    σ²(τ) = Σ_k (θ_{k+2m} − 2θ_{k+m} + θ_k)² / (2τ²(N + 1 − 2m)).
    """
    if not (math.isfinite(fs) and fs > 0.0):
        raise ValueError(f"fs must be a finite number > 0, got {fs}")
    y = np.asarray(rate, dtype=np.float64)
    if y.ndim != 1:
        raise ValueError(f"rate must be one-dimensional, got shape {y.shape}")
    if not np.all(np.isfinite(y)):
        raise ValueError("rate contains NaN or infinite values")
    n = y.size
    m = cluster_sizes(n) if clusters is None else np.asarray(clusters, dtype=np.int64)
    if m.ndim != 1 or m.size == 0 or np.any(m < 1) or np.any(2 * m > n):
        raise ValueError(f"cluster sizes must be 1 … {n // 2} for {n} samples")
    theta = np.empty(n + 1)
    theta[0] = 0.0
    np.cumsum(y - y.mean(), out=theta[1:])
    theta /= fs
    tau = m / fs
    adev = np.empty(m.size)
    for i, (size, t) in enumerate(zip(m.tolist(), tau.tolist(), strict=True)):
        d = theta[2 * size :] - 2.0 * theta[size:-size] + theta[: -2 * size]
        adev[i] = math.sqrt(float(np.sum(d * d)) / (2.0 * t * t * d.size))  # not np.dot: BLAS threads
    return AllanCurve(tau=tau, adev=adev, clusters=m, samples=n)


def _window(curve: AllanCurve, tau_min: float | None, tau_max: float | None) -> NDArray[np.bool_]:
    lo = curve.tau[0] if tau_min is None else tau_min
    hi = curve.tau[-1] if tau_max is None else tau_max
    return (curve.tau >= lo) & (curve.tau <= hi)


def random_walk(
    curve: AllanCurve, tau_min: float | None = None, tau_max: float | None = 1.0
) -> RandomWalkReading:
    """Fit the −1/2 line σ = N/√τ in ``[tau_min, tau_max]`` (default: shortest τ … 1 s).

    N is the geometric mean of σ·√τ over the window (the least-squares intercept in log-log with
    the slope fixed at −1/2), i.e. the line's value at τ = 1 s. Choose the window where white noise
    dominates: above the device filter (≥ 10 filter lengths) and well below the crossover with the
    floor, (N/floor)² (≈ 23 s for the ADIS16407 gyro, ≈ 3 s for its accelerometer).
    """
    sel = _window(curve, tau_min, tau_max)
    if np.count_nonzero(sel) < 2:
        raise ValueError(f"fewer than 2 curve points in the τ window [{tau_min}, {tau_max}] s")
    log_tau = np.log(curve.tau[sel])
    log_adev = np.log(curve.adev[sel])
    coefficient = math.exp(float(np.mean(log_adev + 0.5 * log_tau)))
    slope = float(np.polyfit(log_tau, log_adev, 1)[0])
    return RandomWalkReading(
        coefficient=coefficient,
        slope=slope,
        tau_range=(float(curve.tau[sel][0]), float(curve.tau[sel][-1])),
    )


def bias_instability(
    curve: AllanCurve,
    tau_min: float | None = None,
    tau_max: float | None = None,
    floor_factor: float = FLICKER_FLOOR_FACTOR,
) -> BiasInstabilityReading:
    """The minimum of the curve in ``[tau_min, tau_max]`` and B = minimum / ``floor_factor``.

    The minimum of a noisy curve is biased low by roughly one standard error of the points near
    it: restrict the window to τ where the record holds enough independent differences.
    """
    if not (math.isfinite(floor_factor) and floor_factor > 0.0):
        raise ValueError(f"floor_factor must be a finite number > 0, got {floor_factor}")
    sel = _window(curve, tau_min, tau_max)
    if not np.any(sel):
        raise ValueError(f"no curve point in the τ window [{tau_min}, {tau_max}] s")
    i = int(np.argmin(np.where(sel, curve.adev, np.inf)))
    minimum = float(curve.adev[i])
    return BiasInstabilityReading(
        allan_minimum=minimum,
        tau_at_minimum=float(curve.tau[i]),
        bias_instability=minimum / floor_factor,
    )


def per_sqrt_hour(coefficient: float) -> float:
    """A random-walk coefficient in units/√Hz (= units·√s / s) as units/√h: × √3600 = × 60."""
    return 60.0 * coefficient


def gauss_markov_avar(tau: ArrayLike, sigma: float, correlation_time: float) -> NDArray[np.float64]:
    """Theoretical Allan variance of a first-order Gauss–Markov process of stationary standard
    deviation ``sigma`` and correlation time ``correlation_time``:
    σ²(τ) = (2σ²/x)·[1 − (3 − 4e^{−x} + e^{−2x})/(2x)], x = τ/T. Its deviation peaks at
    0.6174·σ for τ = 1.893·T.
    """
    x = np.asarray(tau, dtype=np.float64) / correlation_time
    small = x < 1e-2
    xs = np.where(small, 1.0, x)  # placeholder where the series applies (avoids 0-division)
    # Taylor series where the closed form cancels (truncation < 1e-12 relative).
    series = x * (2.0 / 3.0 + x * (-0.5 + x * (7.0 / 30.0 + x * (-1.0 / 12.0 + x * 31.0 / 1260.0))))
    bracket = -4.0 * np.expm1(-xs) + np.expm1(-2.0 * xs)
    closed = (2.0 / xs) * (1.0 - bracket / (2.0 * xs))
    return sigma * sigma * np.where(small, series, closed)
