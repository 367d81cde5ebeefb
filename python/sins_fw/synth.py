"""Synthetic scenarios with exact truth (docs/traces.md, "Synthetic scenarios").

Every scenario is an analytic trajectory: attitude C_b^n(t), body rate ω_nb^b(t), navigation-frame
velocity and acceleration, all in closed form (no numerical differentiation). The sensor quantities
follow from them:

    ω_ib^b = ω_nb^b + C_n^b (ω_ie^n + ω_en^n)
    f^b    = C_n^b (v̇^n + (2 ω_ie^n + ω_en^n) × v^n − g^n),   g^n = [0, 0, −γ(φ, h)]

with γ the WGS-84 normal gravity (sins_fw.earth). The transport rate ω_en^n is zero for the ground
scenarios (the board does not move over the earth) and included for ``flight``.

Smooth motion uses one transition shape: the septic smoothstep s(u) = 35u⁴ − 84u⁵ + 70u⁶ − 20u⁷,
whose first three derivatives vanish at both ends, so rates, angular accelerations and specific
force are continuous. A rate r ramped by Δ over T has peak derivative 2.1875 Δ/T.
"""

from __future__ import annotations

import itertools
import math
import shlex
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, replace
from fractions import Fraction
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sins_fw import _core, earth
from sins_fw import quaternion as quat
from sins_fw.errors import ConfigError, ProfileError, TraceError
from sins_fw.traces import PhysicalTrace, parse_rate

Array = NDArray[np.float64]

DEFAULT_RATE_HZ = "819.2"
#: Default site: Hohhot, where the reference design was tested (approximate; a parameter).
DEFAULT_LATITUDE_DEG = 40.8
DEFAULT_HEIGHT_M = 1050.0
#: Peak of s'(u) = 140 u³ (1 − u)³ (at u = ½): a ramp of Δ over T peaks at 2.1875 Δ/T.
SMOOTHSTEP_PEAK_SLOPE = 140.0 / 64.0
_X, _Y, _Z = np.eye(3)
_AXES = {"x": _X, "y": _Y, "z": _Z}


# ---------------------------------------------------------------------------------------------------
# Time grid and smooth profiles
# ---------------------------------------------------------------------------------------------------


def sample_times(duration_s: float, rate_hz: str | Fraction, rows: slice | None = None) -> Array:
    """t_i = i / rate for i = 0 … floor(duration·rate) − 1, each correctly rounded from the exact ratio
    (exact binary fractions for 819.2 Hz: the period 5/4096 s is a dyadic rational); ``rows`` takes
    a slice of the grid without making the rest (each t_i is the same either way)."""
    rate = parse_rate(str(rate_hz), "synth") if not isinstance(rate_hz, Fraction) else rate_hz
    n = math.floor(Fraction(str(duration_s)) * rate)
    if n < 2:
        raise ConfigError(f"duration {duration_s} s at {rate_hz} Hz gives {n} samples; expected at least 2")
    if n * rate.denominator >= 2**53:
        raise ConfigError(f"{n} samples at {rate_hz} Hz: too many for exact float64 times")
    i = np.arange(*(rows or slice(None)).indices(n), dtype=np.int64)
    return (i * rate.denominator).astype(np.float64) / float(rate.numerator)


def _smoothstep(u: Array) -> tuple[Array, Array, Array, Array]:
    """S(u) = ∫₀ᵘ s, s(u), s'(u), s''(u) of the septic smoothstep."""
    u2 = u * u
    v = 1.0 - u
    big_s = u2 * u2 * u * (7.0 - 14.0 * u + 10.0 * u2 - 2.5 * u2 * u)
    s = u2 * u2 * (35.0 - 84.0 * u + 70.0 * u2 - 20.0 * u2 * u)
    ds = 140.0 * u2 * u * v * v * v
    dds = 420.0 * u2 * v * v * (1.0 - 2.0 * u)
    return big_s, s, ds, dds


@dataclass(frozen=True)
class MotionProfile:
    """A smooth piecewise rate r(t) and its integral x(t): holds and septic ramps.

    Segment k starts at ``t0[k]``, lasts ``length[k]`` (the last one forever), ramps r from ``r0[k]``
    to ``r1[k]`` (a hold when equal) and starts at x = ``x0[k]``.
    """

    t0: Array
    length: Array
    r0: Array
    r1: Array
    x0: Array

    @staticmethod
    def build(x_start: float, r_start: float, ramps: Sequence[tuple[float, float, float]]) -> MotionProfile:
        """From ``(start time, duration, target rate)`` ramps in time order; holds fill the gaps."""
        t0: list[float] = [0.0]
        length: list[float] = []
        r0: list[float] = [r_start]
        r1: list[float] = []
        x0: list[float] = [x_start]
        t, r, x = 0.0, r_start, x_start
        for start, duration, target in ramps:
            if start < t - 1e-12 or duration <= 0:
                raise ConfigError(f"profile ramp at {start} s overlaps the previous one or has no duration")
            if start > t:  # a hold until the ramp
                length.append(start - t)
                r1.append(r)
                x += r * (start - t)
                t0.append(start)
                r0.append(r)
                x0.append(x)
            length.append(duration)
            r1.append(target)
            x += r * duration + 0.5 * (target - r) * duration
            t, r = start + duration, target
            t0.append(t)
            r0.append(r)
            x0.append(x)
        length.append(math.inf)
        r1.append(r)
        return MotionProfile(*(np.array(a, dtype=np.float64) for a in (t0, length, r0, r1, x0)))

    def pinned(self, values: dict[int, float]) -> MotionProfile:
        """The same profile with x at the start of some segments set exactly (table stops)."""
        x0 = self.x0.copy()
        for k, v in values.items():
            x0[k] = v
        return MotionProfile(self.t0, self.length, self.r0, self.r1, x0)

    @property
    def end(self) -> float:
        """Start of the final (endless) hold."""
        return float(self.t0[-1])

    def __call__(self, t: Array) -> tuple[Array, Array, Array, Array]:
        """x, r, ṙ, r̈ at times ``t``."""
        k = np.clip(np.searchsorted(self.t0, t, side="right") - 1, 0, len(self.t0) - 1)
        tau = t - self.t0[k]
        length = self.length[k]
        finite = np.isfinite(length)
        safe = np.where(finite, length, 1.0)
        u = np.where(finite, np.clip(tau / safe, 0.0, 1.0), 0.0)
        big_s, s, ds, dds = _smoothstep(u)
        d = self.r1[k] - self.r0[k]
        x = self.x0[k] + self.r0[k] * tau + d * safe * big_s
        return x, self.r0[k] + d * s, d * ds / safe, d * dds / (safe * safe)


def ramp_time(delta: float, max_slope: float) -> float:
    """Duration of a septic ramp of ``delta`` whose derivative peaks at ``max_slope``."""
    return SMOOTHSTEP_PEAK_SLOPE * abs(delta) / max_slope


# ---------------------------------------------------------------------------------------------------
# Motion → sensor quantities
# ---------------------------------------------------------------------------------------------------


@dataclass
class Motion:
    """Kinematics on the sample grid (SI units, navigation frame ENU, quaternion C_b^n)."""

    t_s: Array
    q_nb: Array
    w_nb_b: Array
    v_n: Array
    a_n: Array
    lat_rad: Array
    height_m: Array
    w_en_n: Array
    #: Displacement east of the start point, m (for the GPS longitude).
    east_m: Array
    #: The hinge angle α from the zero pose, rad (the ``wing`` scenario; None elsewhere).
    alpha_rad: Array | None = None
    #: Sensor temperature, °C (None: the trace has no temperature column).
    temp_c: Array | None = None
    #: Specific force at the gyro-free array's seven ADXL345, g, (n, 21) (the ``vehicle`` scenario).
    array_g: Array | None = None

    def rows(self, rows: slice) -> Motion:
        """These rows of the motion."""
        return Motion(**{k: None if v is None else v[rows] for k, v in vars(self).items()})

    @property
    def w_ie_n(self) -> Array:
        """Earth rate in the navigation frame (rad/s)."""
        return earth.earth_rate_n(self.lat_rad)

    @property
    def w_in_n(self) -> Array:
        """Rotation rate of the navigation frame w.r.t. inertial space: ω_ie^n + ω_en^n (rad/s)."""
        return self.w_ie_n + self.w_en_n

    @property
    def gravity_n(self) -> Array:
        """g^n = [0, 0, −γ(φ, h)] (m/s²)."""
        g = earth.normal_gravity(self.lat_rad, self.height_m)
        return np.stack([np.zeros_like(g), np.zeros_like(g), -g], axis=-1)

    def gyro_rad_s(self) -> Array:
        """ω_ib^b = ω_nb^b + C_n^b ω_in^n."""
        return self.w_nb_b + quat.rotate(quat.conjugate(self.q_nb), self.w_in_n)

    def specific_force(self) -> Array:
        """f^b = C_n^b (v̇^n + (2ω_ie^n + ω_en^n) × v^n − g^n) (m/s²)."""
        f_n = self.a_n + np.cross(2.0 * self.w_ie_n + self.w_en_n, self.v_n) - self.gravity_n
        return quat.rotate(quat.conjugate(self.q_nb), f_n)

    def moving(self) -> NDArray[np.bool_]:
        """True where the body rotates or moves relative to the navigation frame."""
        return (np.abs(self.w_nb_b).max(axis=1) > 0) | (np.abs(self.v_n).max(axis=1) > 0)


def _ground(t: Array, q: Array, w_nb: Array, latitude_deg: float, height_m: float) -> Motion:
    zeros = np.zeros((len(t), 3))
    return Motion(
        t_s=t,
        q_nb=q,
        w_nb_b=w_nb,
        v_n=zeros,
        a_n=zeros,
        lat_rad=np.full(len(t), math.radians(latitude_deg)),
        height_m=np.full(len(t), height_m),
        w_en_n=zeros,
        east_m=np.zeros(len(t)),
    )


def _attitude(attitude_deg: Sequence[float]) -> Array:
    roll, pitch, yaw = (math.radians(a) for a in attitude_deg)
    return quat.from_euler(roll, pitch, yaw)


def _axis(axis: str) -> Array:
    if axis not in _AXES:
        raise ConfigError(f"axis `{axis}`; expected x, y or z")
    return _AXES[axis]


# ---------------------------------------------------------------------------------------------------
# Scenarios
# ---------------------------------------------------------------------------------------------------


def static_motion(
    *,
    duration_s: float = 60.0,
    attitude_deg: Sequence[float] = (0.0, 0.0, 0.0),
    latitude_deg: float = DEFAULT_LATITUDE_DEG,
    height_m: float = DEFAULT_HEIGHT_M,
    rate_hz: str = DEFAULT_RATE_HZ,
    rows: slice | None = None,
) -> Motion:
    """A board at rest on the earth at a fixed attitude (roll, pitch, yaw in degrees). ``rows`` (every
    scenario has it): only those rows of the sample grid, each the same as in the whole motion."""
    t = sample_times(duration_s, rate_hz, rows)
    q = np.tile(_attitude(attitude_deg), (len(t), 1))
    return _ground(t, q, np.zeros((len(t), 3)), latitude_deg, height_m)


def _axis_motion(
    t: Array,
    motion: MotionProfile,
    axis: str,
    attitude_deg: Sequence[float],
    latitude_deg: float,
    height_m: float,
) -> Motion:
    """A rotation of a table (mounted at ``attitude_deg``) about a body axis by the angle ``motion``."""
    angle, rate, _, _ = motion(t)
    a = _axis(axis)
    q = quat.multiply(_attitude(attitude_deg), quat.from_axis_angle(a, angle))
    return _ground(t, q, rate[:, None] * a, latitude_deg, height_m)


INDEXING_PRESETS: dict[str, dict[str, Any]] = {
    # The reference design's 10° step sweeps over the published ranges (pitch −90…90, roll −180…180,
    # yaw 0…360); pass the axis: y = pitch, x = roll, z = yaw.
    "sweep": {"max_rate_dps": 20.0, "max_accel_dps2": 40.0, "dwell_s": 5.0},
    # The ±30° table: 0, +30, 0, −30, 0.
    "pm30": {
        "angles_deg": (0.0, 30.0, 0.0, -30.0, 0.0),
        "max_rate_dps": 20.0,
        "max_accel_dps2": 40.0,
        "dwell_s": 10.0,
    },
    # Fast rotation to yaw 25.8°, then hold 30 s (the published drift experiment).
    "yaw25.8": {
        "axis": "z",
        "angles_deg": (0.0, 25.8),
        "max_rate_dps": 200.0,
        "max_accel_dps2": 1000.0,
        "dwell_s": 30.0,
    },
}
_SWEEP_ANGLES = {
    "y": [*range(0, 91, 10), *range(80, -91, -10), *range(-80, 1, 10)],
    "x": [*range(0, 181, 10), *range(170, -181, -10), *range(-170, 1, 10)],
    "z": list(range(0, 361, 10)),
}


def sweep_angles(axis: str) -> tuple[float, ...]:
    """The 10° step sweep for an axis: from 0 to the top of the published range, to the bottom, back."""
    return tuple(float(a) for a in _SWEEP_ANGLES[axis])


def indexing_profile(
    angles_deg: Sequence[float], max_rate_dps: float, max_accel_dps2: float, dwell_s: float
) -> tuple[MotionProfile, float]:
    """Dwell at each table angle, moving between them with rate and acceleration limits: the angle
    profile (radians) and its total duration (the last dwell included)."""
    if len(angles_deg) < 1:
        raise ConfigError("indexing table: expected at least one angle")
    if max_rate_dps <= 0 or max_accel_dps2 <= 0 or dwell_s <= 0:
        raise ConfigError("indexing table: rate, acceleration limits and dwell must be positive")
    w_max, a_max = math.radians(max_rate_dps), math.radians(max_accel_dps2)
    angles = [math.radians(a) for a in angles_deg]
    ramps: list[tuple[float, float, float]] = []
    stops: list[tuple[float, float]] = []  # (time the table stops, its angle)
    t = dwell_s
    for prev, nxt in itertools.pairwise(angles):
        delta = nxt - prev
        if delta == 0:
            t += dwell_s
            continue
        # Without cruise a move of Δ reaches peak rate w with ramps of T = 2.1875 w/a each: Δ = w T.
        peak = min(w_max, math.sqrt(abs(delta) * a_max / SMOOTHSTEP_PEAK_SLOPE))
        t_ramp = ramp_time(peak, a_max)
        cruise = max(abs(delta) / peak - t_ramp, 0.0)
        decel = t + t_ramp + cruise
        ramps += [(t, t_ramp, math.copysign(peak, delta)), (decel, t_ramp, 0.0)]
        t = decel + t_ramp
        stops.append((t, nxt))
        t += dwell_s
    motion = MotionProfile.build(angles[0], 0.0, ramps)
    # Pin each stop to its exact table angle (the integral's rounding would leave ~1e-16 rad).
    index = {float(t0): k for k, t0 in enumerate(motion.t0)}
    return motion.pinned({index[stop]: angle for stop, angle in stops}), t


def indexing_table_motion(
    *,
    axis: str = "y",
    angles_deg: Sequence[float] = (0.0, 10.0),
    max_rate_dps: float = 20.0,
    max_accel_dps2: float = 40.0,
    dwell_s: float = 10.0,
    attitude_deg: Sequence[float] = (0.0, 0.0, 0.0),
    latitude_deg: float = DEFAULT_LATITUDE_DEG,
    height_m: float = DEFAULT_HEIGHT_M,
    rate_hz: str = DEFAULT_RATE_HZ,
    rows: slice | None = None,
) -> Motion:
    """A single-axis indexing table: dwell ``dwell_s`` at each angle (the first included), smooth moves."""
    motion, end = indexing_profile(angles_deg, max_rate_dps, max_accel_dps2, dwell_s)
    return _axis_motion(sample_times(end, rate_hz, rows), motion, axis, attitude_deg, latitude_deg, height_m)


def turntable_motion(
    *,
    axis: str = "x",
    rates_dps: Sequence[float] = (50.0, 100.0, 200.0, 300.0),
    hold_s: float = 10.0,
    max_accel_dps2: float = 100.0,
    lead_s: float = 5.0,
    attitude_deg: Sequence[float] = (0.0, 0.0, 0.0),
    latitude_deg: float = DEFAULT_LATITUDE_DEG,
    height_m: float = DEFAULT_HEIGHT_M,
    rate_hz: str = DEFAULT_RATE_HZ,
    rows: slice | None = None,
) -> Motion:
    """A rate table: at rest for ``lead_s``, then each rate held ``hold_s``, smooth changes, back to rest
    and at rest for ``lead_s`` again."""
    if max_accel_dps2 <= 0 or hold_s <= 0 or lead_s < 0:
        raise ConfigError("turntable: acceleration limit and hold must be positive, lead not negative")
    a_max = math.radians(max_accel_dps2)
    ramps: list[tuple[float, float, float]] = []
    t, r = lead_s, 0.0
    targets = [math.radians(x) for x in rates_dps]
    for k, target in enumerate([*targets, 0.0]):
        if target != r:
            dt = ramp_time(target - r, a_max)
            ramps.append((t, dt, target))
            t += dt
            r = target
        t += hold_s if k < len(targets) else lead_s
    motion = MotionProfile.build(0.0, 0.0, ramps)
    return _axis_motion(sample_times(t, rate_hz, rows), motion, axis, attitude_deg, latitude_deg, height_m)


def coning_motion(
    *,
    half_angle_deg: float = 1.0,
    frequency_hz: float = 10.0,
    duration_s: float = 120.0,
    attitude_deg: Sequence[float] = (0.0, 0.0, 0.0),
    latitude_deg: float = DEFAULT_LATITUDE_DEG,
    height_m: float = DEFAULT_HEIGHT_M,
    rate_hz: str = DEFAULT_RATE_HZ,
    rows: slice | None = None,
) -> Motion:
    """Classical coning about the mount's x axis (validation.md): relative to the mount frame R
    (at ``attitude_deg``), q_Rb(t) = [cos α/2, 0, sin α/2 cos Ωt, sin α/2 sin Ωt] and
    ω_nb^b = [−Ω(1 − cos α), −Ω sin α sin Ωt, Ω sin α cos Ωt], with q̇ = ½ q ⊗ ω (derived in
    docs/traces.md). The phase Ωt is reduced as 2π·frac(f·t) so equal phases give equal samples."""
    t = sample_times(duration_s, rate_hz, rows)
    alpha = math.radians(half_angle_deg)
    omega = 2.0 * math.pi * frequency_hz
    phase = 2.0 * math.pi * np.mod(frequency_hz * t, 1.0)
    c, s = np.cos(phase), np.sin(phase)
    q_cone = np.stack(
        [
            np.full_like(t, math.cos(alpha / 2)),
            np.zeros_like(t),
            math.sin(alpha / 2) * c,
            math.sin(alpha / 2) * s,
        ],
        axis=1,
    )
    w = np.stack(
        [
            np.full_like(t, -omega * (1.0 - math.cos(alpha))),
            -omega * math.sin(alpha) * s,
            omega * math.sin(alpha) * c,
        ],
        axis=1,
    )
    q = quat.multiply(_attitude(attitude_deg), q_cone)
    return _ground(t, q, w, latitude_deg, height_m)


#: The spin scenario's trajectories (``--trajectory``).
SPIN_TRAJECTORIES = ("turntable", "ballistic")


def spin_motion(
    *,
    trajectory: str = "turntable",
    spin_dps: float = 1000.0,
    spin_up_s: float = 2.0,
    duration_s: float = 60.0,
    pitch_amplitude_deg: float = 5.0,
    yaw_amplitude_deg: float = 5.0,
    sway_hz: float = 0.2,
    launch_speed_mps: float = 500.0,
    elevation_deg: float = 45.0,
    azimuth_deg: float = 0.0,
    attitude_deg: Sequence[float] = (0.0, 0.0, 0.0),
    latitude_deg: float = DEFAULT_LATITUDE_DEG,
    height_m: float = DEFAULT_HEIGHT_M,
    rate_hz: str = DEFAULT_RATE_HZ,
    rows: slice | None = None,
) -> Motion:
    """A body spinning about its x axis (the geomagnetic–gyro board's test, algorithms.md §1): from
    rest, a septic spin-up to ``spin_dps`` over ``spin_up_s``, held.

    ``trajectory = turntable``: on a two-axis turntable, the spin axis swings in yaw ψ(t) = A_ψ sin 2πft
    and pitch θ(t) = A_θ sin 2πft about the mount (``attitude_deg``). q = q_mount ⊗ q_z(ψ) ⊗
    q_y(θ) ⊗ q_x(φ) and, exactly, ω_nb^b = R_x(φ)ᵀ(R_y(θ)ᵀ ψ̇ e_z + θ̇ e_y) + φ̇ e_x. The spin
    angle φ is the profile's integral; the sway's phase is reduced as 2π·frac(f·t).

    ``trajectory = ballistic``: see :func:`_ballistic` (``attitude_deg`` is not used)."""
    if trajectory not in SPIN_TRAJECTORIES:
        raise ConfigError(
            f"spin: --trajectory `{trajectory}`; expected one of {', '.join(SPIN_TRAJECTORIES)}"
        )
    if not 0.0 <= spin_dps <= 1000.0:
        raise ConfigError(f"spin: --spin-dps {spin_dps}: expected 0…1000 °/s")
    if spin_up_s <= 0 or duration_s <= spin_up_s or sway_hz < 0:
        raise ConfigError("spin: spin-up must be positive and shorter than the duration, sway frequency ≥ 0")
    if trajectory == "ballistic":
        return _ballistic(
            spin_dps=spin_dps,
            spin_up_s=spin_up_s,
            duration_s=duration_s,
            pitch_amplitude_deg=pitch_amplitude_deg,
            yaw_amplitude_deg=yaw_amplitude_deg,
            sway_hz=sway_hz,
            launch_speed_mps=launch_speed_mps,
            elevation_deg=elevation_deg,
            azimuth_deg=azimuth_deg,
            latitude_deg=latitude_deg,
            height_m=height_m,
            rate_hz=rate_hz,
            rows=rows,
        )
    t = sample_times(duration_s, rate_hz, rows)
    ramps = [(0.0, spin_up_s, math.radians(spin_dps))] if spin_dps else []
    phi, phi_dot, _, _ = MotionProfile.build(0.0, 0.0, ramps)(t)
    w = 2.0 * math.pi * sway_hz
    phase = 2.0 * math.pi * np.mod(sway_hz * t, 1.0)
    a_psi, a_theta = math.radians(yaw_amplitude_deg), math.radians(pitch_amplitude_deg)
    psi, psi_dot = a_psi * np.sin(phase), a_psi * w * np.cos(phase)
    theta, theta_dot = a_theta * np.sin(phase), a_theta * w * np.cos(phase)
    q_x = quat.from_axis_angle(_AXES["x"], phi)
    q_y = quat.from_axis_angle(_AXES["y"], theta)
    q_z = quat.from_axis_angle(_AXES["z"], psi)
    q = quat.multiply(_attitude(attitude_deg), quat.multiply(q_z, quat.multiply(q_y, q_x)))
    zeros = np.zeros_like(t)
    swing = quat.rotate(quat.conjugate(q_y), np.stack([zeros, zeros, psi_dot], axis=1))
    swing[:, 1] += theta_dot
    w_b = quat.rotate(quat.conjugate(q_x), swing)
    w_b[:, 0] += phi_dot
    return _ground(t, q, w_b, latitude_deg, height_m)


def _ballistic(
    *,
    spin_dps: float,
    spin_up_s: float,
    duration_s: float,
    pitch_amplitude_deg: float,
    yaw_amplitude_deg: float,
    sway_hz: float,
    launch_speed_mps: float,
    elevation_deg: float,
    azimuth_deg: float,
    latitude_deg: float,
    height_m: float,
    rate_hz: str,
    rows: slice | None,
) -> Motion:
    """A simple ballistic arc: no drag, launched from the start point at speed V, elevation γ₀ and
    azimuth β (clockwise from north), under the start point's normal gravity g:
    v^n = [V cos γ₀ sin β, V cos γ₀ cos β, V sin γ₀ − g t], v̇^n = [0, 0, −g], the position its exact
    integral (latitude and transport rate from the start point's radii, as ``flight``). The spin
    axis (body x) follows the velocity, its flight-path angle γ(t) = atan2(V sin γ₀ − g t,
    V cos γ₀) (γ̇ = −g V cos γ₀ / |v|²), and nods about it: pitch θ(t) = γ(t) + A_θ sin 2πft, yaw
    ψ(t) = 90° − β + A_ψ sin 2πft (about up, counter-clockwise from east). q = q_z(ψ) ⊗ q_y(−θ) ⊗
    q_x(φ) and, exactly, ω_nb^b = R_x(φ)ᵀ(R_y(−θ)ᵀ ψ̇ e_z − θ̇ e_y) + φ̇ e_x. The flight must not
    outlast the landing, t = 2V sin γ₀ / g."""
    if launch_speed_mps <= 0 or not 0.0 < elevation_deg < 90.0:
        raise ConfigError("spin: the ballistic arc needs --launch-speed-mps > 0 and 0 < --elevation-deg < 90")
    g = float(earth.normal_gravity(math.radians(latitude_deg), height_m))
    gamma0 = math.radians(elevation_deg)
    v_h, v_up0 = launch_speed_mps * math.cos(gamma0), launch_speed_mps * math.sin(gamma0)
    landing = 2.0 * v_up0 / g
    if duration_s > landing:
        raise ConfigError(
            f"spin: the ballistic arc lands after {landing:.3f} s; --duration-s {_num(duration_s)} is longer"
        )
    t = sample_times(duration_s, rate_hz, rows)
    ramps = [(0.0, spin_up_s, math.radians(spin_dps))] if spin_dps else []
    phi, phi_dot, _, _ = MotionProfile.build(0.0, 0.0, ramps)(t)
    w = 2.0 * math.pi * sway_hz
    phase = 2.0 * math.pi * np.mod(sway_hz * t, 1.0)
    nod, nod_dot = np.sin(phase), w * np.cos(phase)
    v_up = v_up0 - g * t
    gamma = np.arctan2(v_up, v_h)
    gamma_dot = -g * v_h / (v_h * v_h + v_up * v_up)
    a_psi, a_theta = math.radians(yaw_amplitude_deg), math.radians(pitch_amplitude_deg)
    psi = math.radians(90.0 - azimuth_deg) + a_psi * nod
    psi_dot = a_psi * nod_dot
    theta, theta_dot = gamma + a_theta * nod, gamma_dot + a_theta * nod_dot
    q_x = quat.from_axis_angle(_X, phi)
    q_y = quat.from_axis_angle(_Y, -theta)
    q_z = quat.from_axis_angle(_Z, psi)
    q = quat.multiply(q_z, quat.multiply(q_y, q_x))
    zeros = np.zeros_like(t)
    swing = quat.rotate(quat.conjugate(q_y), np.stack([zeros, zeros, psi_dot], axis=1))
    swing[:, 1] -= theta_dot
    w_b = quat.rotate(quat.conjugate(q_x), swing)
    w_b[:, 0] += phi_dot
    beta = math.radians(azimuth_deg)
    horizontal = np.array([math.sin(beta), math.cos(beta), 0.0])
    v_n = v_h * horizontal + v_up[:, None] * _Z
    a_n = np.broadcast_to(-g * _Z, v_n.shape).copy()
    disp = v_h * t[:, None] * horizontal + (v_up0 * t - 0.5 * g * t * t)[:, None] * _Z
    lat0 = math.radians(latitude_deg)
    r_n, r_e = (float(r) for r in earth.radii(lat0))
    lat = lat0 + disp[:, 1] / (r_n + height_m)
    w_en = np.stack(
        [
            -v_n[:, 1] / (r_n + height_m),
            v_n[:, 0] / (r_e + height_m),
            v_n[:, 0] * np.tan(lat) / (r_e + height_m),
        ],
        axis=1,
    )
    return Motion(
        t_s=t,
        q_nb=q,
        w_nb_b=w_b,
        v_n=v_n,
        a_n=a_n,
        lat_rad=lat,
        height_m=height_m + disp[:, 2],
        w_en_n=w_en,
        east_m=disp[:, 0],
    )


# Gauss–Legendre nodes on [0, 1] for the position quadrature of ``flight`` (degree-7 exact).
_GL_X, _GL_W = np.polynomial.legendre.leggauss(4)
_GL_X, _GL_W = 0.5 * (_GL_X + 1.0), 0.5 * _GL_W


@dataclass(frozen=True)
class _FlightPlan:
    speed: MotionProfile  # r = V (m/s)
    gamma: MotionProfile  # r = flight-path angle γ (rad)
    heading: MotionProfile  # x = heading ψ from north, clockwise; r = ψ̇ (rad, rad/s)
    end: float

    def velocity(self, t: Array) -> tuple[Array, Array]:
        """v^n = V [cos γ sin ψ, cos γ cos ψ, sin γ] and its exact derivative v̇^n at ``t``."""
        _, v, dv, _ = self.speed(t)
        _, gam, dgam, _ = self.gamma(t)
        psi, dpsi, _, _ = self.heading(t)
        cg, sg, cp, sp = np.cos(gam), np.sin(gam), np.cos(psi), np.sin(psi)
        u = np.stack([cg * sp, cg * cp, sg], axis=-1)
        du_dpsi = np.stack([cg * cp, -cg * sp, np.zeros_like(cg)], axis=-1)
        du_dgam = np.stack([-sg * sp, -sg * cp, cg], axis=-1)
        du = dpsi[..., None] * du_dpsi + dgam[..., None] * du_dgam
        return v[..., None] * u, dv[..., None] * u + v[..., None] * du


def flight_plan(
    *, heading_deg: float, speed_mps: float, turn_rate_dps: float, climb_deg: float
) -> _FlightPlan:
    """The fixed-wing profile: 10 s at rest, take-off roll to 0.7 V, climb at γ while accelerating to V,
    level, a 90° right turn, level, a 180° left turn, level, a descent at −γ/2, level."""
    if speed_mps <= 0 or turn_rate_dps <= 0:
        raise ConfigError("flight: speed and turn rate must be positive")
    v_lof = 0.7 * speed_mps
    speed = MotionProfile.build(0.0, 0.0, [(10.0, 20.0, v_lof), (34.0, 20.0, speed_mps)])
    climb = math.radians(climb_deg)
    gamma = MotionProfile.build(
        0.0, 0.0, [(30.0, 4.0, climb), (90.0, 4.0, 0.0), (250.0, 4.0, -climb / 2), (294.0, 4.0, 0.0)]
    )
    rate = math.radians(turn_rate_dps)
    ramp = 3.0

    def turn(start: float, angle_deg: float) -> list[tuple[float, float, float]]:
        r = math.copysign(rate, angle_deg)
        hold = math.radians(abs(angle_deg)) / rate - ramp
        return [(start, ramp, r), (start + ramp + hold, ramp, 0.0)]

    heading = MotionProfile.build(math.radians(heading_deg), 0.0, [*turn(114.0, 90.0), *turn(167.0, -180.0)])
    return _FlightPlan(speed, gamma, heading, end=318.0)


def flight_motion(
    *,
    heading_deg: float = 60.0,
    speed_mps: float = 40.0,
    turn_rate_dps: float = 3.0,
    climb_deg: float = 6.0,
    latitude_deg: float = DEFAULT_LATITUDE_DEG,
    height_m: float = DEFAULT_HEIGHT_M,
    rate_hz: str = DEFAULT_RATE_HZ,
    rows: slice | None = None,
) -> Motion:
    """A fixed-wing flight (body axes x forward, y left, z up; zero angle of attack and sideslip).

    Attitude C_b^n = Rz(90° − ψ) · Ry(−γ) · Rx(μ) with bank μ = atan(V ψ̇ / g0) (a coordinated turn to
    first order). Position comes from a 4-point Gauss–Legendre quadrature of the analytic velocity per
    sample interval; latitude and transport rate use the radii of curvature of the start point
    (R_N(φ0) + h0, R_E(φ0) + h0), which keeps ω_en^n exactly the rotation rate of the local-level
    frame along the trajectory (docs/traces.md).

    The position sums the whole trajectory, so ``rows`` slices the whole motion (its length is fixed
    by the plan: 318 s).
    """
    plan = flight_plan(
        heading_deg=heading_deg, speed_mps=speed_mps, turn_rate_dps=turn_rate_dps, climb_deg=climb_deg
    )
    return _plan_motion(plan, latitude_deg, height_m, rate_hz, rows)


def turn_motion(
    *,
    speed_mps: float = 20.0,
    turn_rate_dps: float = 10.0,
    heading_deg: float = 0.0,
    duration_s: float = 120.0,
    latitude_deg: float = DEFAULT_LATITUDE_DEG,
    height_m: float = DEFAULT_HEIGHT_M,
    rate_hz: str = DEFAULT_RATE_HZ,
    rows: slice | None = None,
) -> Motion:
    """A level coordinated turn at constant speed V and turn rate ψ̇ from t = 0 (heading ``heading_deg``
    at t = 0, positive rate: a right turn): the flight's kinematics with constant V, γ = 0 and bank
    atan(V ψ̇ / g0), so the specific force has the centripetal V ψ̇ along body y besides gravity (the
    DCM's centripetal compensation removes it: ω × [V, 0, 0])."""
    if speed_mps <= 0 or turn_rate_dps == 0 or duration_s <= 0:
        raise ConfigError("turn: speed and duration must be positive, the turn rate not zero")
    plan = _FlightPlan(
        speed=MotionProfile.build(0.0, speed_mps, []),
        gamma=MotionProfile.build(0.0, 0.0, []),
        heading=MotionProfile.build(math.radians(heading_deg), math.radians(turn_rate_dps), []),
        end=duration_s,
    )
    return _plan_motion(plan, latitude_deg, height_m, rate_hz, rows)


#: The gyro-free array's parts' positions in units of the lever arm l (algorithms.md §4: u₁…u₆,
#: body axes; the seventh part at the centre): gfsins.toml's ``array.parts`` positions, in order
#: (``--array-positions-lever-arms`` places them elsewhere, as a variant profile does).
ARRAY_POSITIONS = np.array(
    [[0, 1, 0], [0, 0, 1], [1, 0, 0], [0, 0, -1], [-1, 0, 0], [0, -1, 0], [0, 0, 0]], float
)
#: The array's parts (``array1_*`` … ``array7_*``).
ARRAY_PARTS = 7
#: The thesis's chapter-5 scenario (algorithms.md §4 corrections): 80 km/h, heading 30°, its place.
VEHICLE_SPEED_MPS = 80.0 / 3.6
VEHICLE_LATITUDE_DEG = 28.20021
VEHICLE_LONGITUDE_DEG = 112.92647
VEHICLE_HEIGHT_M = 5.13145


def vehicle_motion(
    *,
    speed_mps: float = VEHICLE_SPEED_MPS,
    heading_deg: float = 30.0,
    turn_rate_dps: float = 0.0,
    duration_s: float = 60.0,
    lever_arm_m: float = 0.1,
    array_positions_lever_arms: Sequence[float] = tuple(ARRAY_POSITIONS.ravel()),
    latitude_deg: float = VEHICLE_LATITUDE_DEG,
    height_m: float = VEHICLE_HEIGHT_M,
    rate_hz: str = "1000",
    rows: slice | None = None,
) -> Motion:
    """The gyro-free vehicle board's scenario (issue 25; the thesis's chapter 5 by default): a level
    vehicle at constant speed on a straight line (``turn_rate_dps`` = 0) or a coordinated turn, with
    the specific force at each of the seven ADXL345 of the array at lever arm l: f_p = f_c + ω̇×r_p +
    ω×(ω×r_p) (rigid body, ω = ω_ib^b, r_p = l u_p in body axes, u_p the seven ``array_positions_lever_arms``
    in units of l, x y z each: a gyro-free profile's ``array.parts`` positions in order, as
    :func:`sins_fw.gfsins.vehicle_array` gives them; gravity uniform over the array).
    ω is exact; ω̇ is its second-order central difference on the sample grid, exact to O(h² ω⃛/6):
    in a turn ω_ib^b turns with the body against the earth rate (|ω̇| ≈ |ω_nb × ω_in| ≈ 1.3e-5 rad/s²
    at 10 °/s, ω⃛ ≈ 4e-7 rad/s³), so at 1 kHz the difference is off by ≈ 1e-13 rad/s², 2e-15 g at
    l = 0.2 m: a few units in the last place of f."""
    if speed_mps <= 0 or duration_s <= 0 or not 0.0 < lever_arm_m <= 1.0:
        raise ConfigError("vehicle: speed and duration must be positive, the lever arm 0 < l ≤ 1 m")
    positions = np.asarray(array_positions_lever_arms, dtype=np.float64)
    if positions.shape != (3 * ARRAY_PARTS,) or not np.all(np.abs(positions) <= 10.0):
        raise ConfigError(
            f"vehicle: array_positions_lever_arms has {positions.size} values; expected {3 * ARRAY_PARTS} "
            "(x, y, z of each part in turn, in units of the lever arm, each within ±10)"
        )
    plan = _FlightPlan(
        speed=MotionProfile.build(0.0, speed_mps, []),
        gamma=MotionProfile.build(0.0, 0.0, []),
        heading=MotionProfile.build(math.radians(heading_deg), math.radians(turn_rate_dps), []),
        end=duration_s,
    )
    # A chunk is made with two rows before it and one after (ω̇'s differences need its neighbours,
    # the end's one-sided difference two), then cut: each row's values are the whole motion's.
    n = _grid_rows(duration_s, rate_hz)
    first, stop, _ = (rows or slice(None)).indices(n)
    lo, hi = max(0, first - 2), min(n, stop + 1)
    m = _plan_motion(plan, latitude_deg, height_m, rate_hz, None if (lo, hi) == (0, n) else slice(lo, hi))
    w = m.gyro_rad_s()
    dw = np.gradient(w, m.t_s, axis=0, edge_order=2) if len(m.t_s) > 2 else np.zeros_like(w)
    f_c = m.specific_force()
    forces = []
    for u in positions.reshape(ARRAY_PARTS, 3):
        r = np.broadcast_to(lever_arm_m * u, w.shape)
        forces.append(f_c + np.cross(dw, r) + np.cross(w, np.cross(w, r)))
    m.array_g = np.concatenate(forces, axis=1) / earth.G0
    return m.rows(slice(first - lo, max(first - lo, stop - lo)))


#: The displacement at the last rows of the last chunk of a flight plan's grid made (row → value),
#: by plan, so that the next chunk (which may start a few rows back: the vehicle's halo) continues
#: the sum from there (:func:`_displacement_at`).
_CARRY: dict[tuple[Any, ...], dict[int, Array]] = {}
_CARRY_ROWS = 4


def _steps(plan: _FlightPlan, t: Array) -> Array:
    """The displacement over each interval of ``t``: exact-to-rounding Gauss–Legendre quadrature of
    the analytic velocity (each row depends on its interval's two times only)."""
    dt = np.diff(t)
    nodes = t[:-1, None] + dt[:, None] * _GL_X[None, :]
    v_nodes = plan.velocity(nodes)[0]
    return np.einsum("k,nkc->nc", _GL_W, v_nodes) * dt[:, None]


def _plan_key(plan: _FlightPlan, rate_hz: str) -> tuple[Any, ...]:
    profiles = (plan.speed, plan.gamma, plan.heading)
    return (str(rate_hz), plan.end, *(a.tobytes() for p in profiles for a in vars(p).values()))


def _displacement_at(plan: _FlightPlan, rate_hz: str, row: int) -> Array:
    """The displacement at ``row`` of the grid: the sequential sum of the steps before it, the very
    additions (in the same order) that ``np.cumsum`` over the whole grid makes, so that a chunked
    motion is the whole motion bit for bit. From the last chunk's end when that is ``row``; else
    summed from the start, a chunk of steps at a time."""
    kept = _CARRY.get(_plan_key(plan, rate_hz), {})
    at = max((r for r in kept if r <= row), default=0)
    disp = kept[at] if at in kept else np.zeros(3)
    while at < row:
        stop = min(row, at + (1 << 16))
        t = sample_times(plan.end, rate_hz, slice(at, stop + 1))
        disp = np.cumsum(np.vstack([disp[None, :], _steps(plan, t)]), axis=0)[-1]
        at = stop
    return disp


def _plan_motion(
    plan: _FlightPlan, latitude_deg: float, height_m: float, rate_hz: str, rows: slice | None
) -> Motion:
    """The motion of a flight plan (see :func:`flight_motion`), or of ``rows`` of it alone (the
    displacement carried from the previous rows: the same values as the whole motion's rows)."""
    if rows is None:
        t = sample_times(plan.end, rate_hz)
        disp0, first = np.zeros(3), 0
    else:
        first, stop, _ = rows.indices(_grid_rows(plan.end, rate_hz))
        t = sample_times(plan.end, rate_hz, slice(first, stop))
        if not len(t):
            return _empty_motion()
        disp0 = _displacement_at(plan, rate_hz, first)
    v_n, a_n = plan.velocity(t)
    _, v, dv, _ = plan.speed(t)
    _, gam, dgam, _ = plan.gamma(t)
    psi, dpsi, ddpsi, _ = plan.heading(t)
    g0 = earth.G0
    ratio = v * dpsi / g0
    bank = np.arctan(ratio)
    dbank = (dv * dpsi + v * ddpsi) / g0 / (1.0 + ratio * ratio)
    yaw, dyaw = 0.5 * math.pi - psi, -dpsi
    pitch, dpitch = -gam, -dgam
    qz = quat.from_axis_angle(_Z, yaw)
    qy = quat.from_axis_angle(_Y, pitch)
    qx = quat.from_axis_angle(_X, bank)
    q = quat.multiply(quat.multiply(qz, qy), qx)
    zeros = np.zeros_like(t)
    w_inner = quat.rotate(quat.conjugate(qy), np.stack([zeros, zeros, dyaw], axis=1)) + np.stack(
        [zeros, dpitch, zeros], axis=1
    )
    w_nb = quat.rotate(quat.conjugate(qx), w_inner) + np.stack([dbank, zeros, zeros], axis=1)

    # Position: exact-to-rounding quadrature of the analytic velocity over each sample interval,
    # summed in order from the first row (a chunk continues the sum of the rows before it).
    if rows is None:
        disp = np.vstack([np.zeros((1, 3)), np.cumsum(_steps(plan, t), axis=0)])
    else:
        disp = np.cumsum(np.vstack([disp0[None, :], _steps(plan, t)]), axis=0)
        _CARRY.clear()  # one plan streamed at a time: the carry of its last chunk
        _CARRY[_plan_key(plan, rate_hz)] = {
            first + i: disp[i].copy() for i in range(max(0, len(t) - _CARRY_ROWS), len(t))
        }
    lat0 = math.radians(latitude_deg)
    r_n, r_e = (float(r) for r in earth.radii(lat0))
    lat = lat0 + disp[:, 1] / (r_n + height_m)
    height = height_m + disp[:, 2]
    w_en = np.stack(
        [
            -v_n[:, 1] / (r_n + height_m),
            v_n[:, 0] / (r_e + height_m),
            v_n[:, 0] * np.tan(lat) / (r_e + height_m),
        ],
        axis=1,
    )
    whole = Motion(
        t_s=t,
        q_nb=q,
        w_nb_b=w_nb,
        v_n=v_n,
        a_n=a_n,
        lat_rad=lat,
        height_m=height,
        w_en_n=w_en,
        east_m=disp[:, 0],
    )
    return whole


def _grid_rows(duration_s: float, rate_hz: str) -> int:
    """Rows of the grid of ``duration_s`` at ``rate_hz`` (as :func:`sample_times` counts them)."""
    return math.floor(Fraction(str(duration_s)) * parse_rate(str(rate_hz), "synth"))


def _empty_motion() -> Motion:
    z1, z3 = np.zeros(0), np.zeros((0, 3))
    return Motion(
        t_s=z1,
        q_nb=np.zeros((0, 4)),
        w_nb_b=z3,
        v_n=z3,
        a_n=z3,
        lat_rad=z1,
        height_m=z1,
        w_en_n=z3,
        east_m=z1,
    )


# ---------------------------------------------------------------------------------------------------
# Scenario registry: parameters (for the API, the CLI and the recorded generator command)
# ---------------------------------------------------------------------------------------------------


#: The wing scenario's flap profiles (``--flap``).
FLAP_PROFILES = ("steps", "sine", "sweep")


def _flap_profile(
    t: Array,
    flap: str,
    angles_deg: Sequence[float],
    amplitude_deg: float,
    period_s: float,
    max_rate_dps: float,
    max_accel_dps2: float,
    rest_s: float,
    duration_s: float,
) -> tuple[Array, Array, Array]:
    """α, α̇, α̈ (rad, rad/s, rad/s²) of a flap profile, α = 0 at rest for ``rest_s`` first:
    - steps: to each of ``angles_deg`` with rate/acceleration-limited septic moves, ``rest_s`` at each;
    - sine: amplitude·e(t)·sin(2π(t − rest)/period), the envelope e a septic ramp 0 → 1 over one period;
    - sweep: reciprocating moves 0 → +A → −A → +A … → 0 (limited as the steps, no dwell at the ends)."""
    if flap == "sine":
        t0 = rest_s
        w = 2.0 * math.pi / period_s
        tau = np.maximum(t - t0, 0.0)
        u = np.clip(tau / period_s, 0.0, 1.0)
        _, e, de, dde = _smoothstep(u)
        de, dde = de / period_s, dde / period_s**2
        amp = math.radians(amplitude_deg)
        sn, cs = np.sin(w * tau), np.cos(w * tau)
        alpha = amp * e * sn
        rate = amp * (de * sn + e * w * cs)
        acc = amp * (dde * sn + 2.0 * de * w * cs - e * w * w * sn)
        return alpha, rate, acc
    if flap == "steps":
        profile, _ = indexing_profile(angles_deg, max_rate_dps, max_accel_dps2, rest_s)
    else:
        a = abs(amplitude_deg)
        one, _ = indexing_profile((a, -a), max_rate_dps, max_accel_dps2, 1e-3)
        cycle = 2.0 * (one.end - 1e-3)  # one +A → −A → +A cycle
        sweeps = max(1, math.floor((duration_s - 2.0 * rest_s) / cycle))
        waypoints = (0.0, *itertools.chain.from_iterable((a, -a) for _ in range(sweeps)), 0.0)
        moves, _ = indexing_profile(waypoints, max_rate_dps, max_accel_dps2, 1e-3)
        profile = MotionProfile.build(0.0, 0.0, [(t0 + rest_s, dt, r1) for t0, dt, r1 in _ramps(moves)])
    alpha, rate, acc, _ = profile(t)
    return alpha, rate, acc


def _ramps(profile: MotionProfile) -> list[tuple[float, float, float]]:
    """The ramps (start, duration, target rate) of a profile (its segments that change the rate)."""
    return [
        (float(t0), float(n), float(r1))
        for t0, n, r0, r1 in zip(profile.t0, profile.length, profile.r0, profile.r1, strict=True)
        if r0 != r1
    ]


def wing_duration(values: dict[str, Any]) -> float:
    """The wing scenario's duration: ``duration_s`` for sine and sweep; for steps the moves with a rest
    at each angle (the first included)."""
    if values["flap"] == "steps":
        _, end = indexing_profile(
            values["angles_deg"], values["max_rate_dps"], values["max_accel_dps2"], values["rest_s"]
        )
        return end
    return float(values["duration_s"])


def wing_motion(
    *,
    flap: str = "steps",
    angles_deg: Sequence[float] = (0.0, 20.0, -15.0, 35.0, 0.0),
    amplitude_deg: float = 30.0,
    period_s: float = 4.0,
    max_rate_dps: float = 60.0,
    max_accel_dps2: float = 120.0,
    rest_s: float = 10.0,
    duration_s: float = 120.0,
    axis_elevation_deg: float = 20.0,
    axis_azimuth_deg: float = 30.0,
    mount_deg: Sequence[float] = (10.0, -5.0, 70.0),
    lever_m: Sequence[float] = (0.3, 0.1, 0.0),
    base_amplitude_deg: float = 0.0,
    base_period_s: float = 20.0,
    temp_start_c: float = 25.0,
    temp_rate_c_per_min: float = 0.0,
    latitude_deg: float = DEFAULT_LATITUDE_DEG,
    height_m: float = DEFAULT_HEIGHT_M,
    rate_hz: str = DEFAULT_RATE_HZ,
    rows: slice | None = None,
) -> Motion:
    """A wing on a hinge (algorithms.md §3): the hinge axis a at elevation β above the horizontal and
    azimuth γ (its horizontal part, clockwise from north), the IMU mounted at ``mount_deg`` (roll,
    pitch, yaw of C_b^n at the zero pose) and at ``lever_m`` (ENU, m) from a point of the hinge line.
    The base pitches about east by b(t) = B sin(2πt/T) (B = 0: static). With q_h = rotation about a by
    α and q_B about east by b, C_b^n = q_B ⊗ q_h(α) ⊗ q_mount; the IMU's position is p = B·R_a(α)·ℓ, so

        ω_nb^n = ḃ e + B(α̇ a),   v = ḃ e × p + B(α̇ a × x),
        v̇ = b̈ e × p + ḃ² e × (e × p) + 2ḃ e × B(α̇ a × x) + B(α̈ a × x + α̇² a × (a × x)),  x = R_a(α) ℓ.

    Truth α is exact (the profile's closed form); the temperature is a ramp."""
    if flap not in FLAP_PROFILES:
        raise ConfigError(f"wing: flap `{flap}`; expected one of {', '.join(FLAP_PROFILES)}")
    if len(lever_m) != 3:
        raise ConfigError(f"wing: lever_m has {len(lever_m)} values; expected three (east, north, up, m)")
    if not 0.0 <= axis_elevation_deg < 90.0:
        raise ConfigError(
            f"wing: axis_elevation_deg {axis_elevation_deg}; expected 0 ≤ β < 90 (a vertical axis hides α)"
        )
    if period_s <= 0 or base_period_s <= 0 or rest_s <= 0:
        raise ConfigError("wing: period_s, base_period_s and rest_s must be positive")
    values = {"flap": flap, "angles_deg": angles_deg, "max_rate_dps": max_rate_dps}
    values |= {"max_accel_dps2": max_accel_dps2, "rest_s": rest_s, "duration_s": duration_s}
    t = sample_times(wing_duration(values), rate_hz, rows)
    alpha, rate, acc = _flap_profile(
        t, flap, angles_deg, amplitude_deg, period_s, max_rate_dps, max_accel_dps2, rest_s, duration_s
    )
    beta, gamma = math.radians(axis_elevation_deg), math.radians(axis_azimuth_deg)
    a = np.array([math.cos(beta) * math.sin(gamma), math.cos(beta) * math.cos(gamma), math.sin(beta)])
    e = _X
    wb = 2.0 * math.pi / base_period_s
    big_b = math.radians(base_amplitude_deg)
    b, db, ddb = big_b * np.sin(wb * t), big_b * wb * np.cos(wb * t), -big_b * wb * wb * np.sin(wb * t)
    q_base = quat.from_axis_angle(e, b)
    q_h = quat.from_axis_angle(a, alpha)
    q = quat.multiply(q_base, quat.multiply(q_h, _attitude(mount_deg)))
    n = len(t)
    ell = np.broadcast_to(np.asarray(lever_m, dtype=np.float64), (n, 3))
    x = quat.rotate(q_h, ell)
    ax = np.cross(a, x)
    p = quat.rotate(q_base, x)
    ep = np.cross(e, p)
    w_n = db[:, None] * e + quat.rotate(q_base, rate[:, None] * a)
    x_dot = quat.rotate(q_base, rate[:, None] * ax)
    v = db[:, None] * ep + x_dot
    acc_n = (
        ddb[:, None] * ep
        + (db * db)[:, None] * np.cross(e, ep)
        + 2.0 * db[:, None] * np.cross(e, x_dot)
        + quat.rotate(q_base, acc[:, None] * ax + (rate * rate)[:, None] * np.cross(a, ax))
    )
    motion = _ground(t, q, quat.rotate(quat.conjugate(q), w_n), latitude_deg, height_m)
    motion.v_n, motion.a_n = v, acc_n
    motion.alpha_rad = alpha
    motion.temp_c = temp_start_c + temp_rate_c_per_min / 60.0 * t
    return motion


def _quat_from_dcm(c: Array) -> Array:
    """The unit quaternion of a rotation matrix (Shepperd: from the largest of 1 + trace and
    1 + 2Cᵢᵢ − trace)."""
    t = np.trace(c)
    k = int(np.argmax([t, c[0, 0], c[1, 1], c[2, 2]]))
    if k == 0:
        r = math.sqrt(1.0 + t)
        q = [
            r / 2,
            (c[2, 1] - c[1, 2]) / (2 * r),
            (c[0, 2] - c[2, 0]) / (2 * r),
            (c[1, 0] - c[0, 1]) / (2 * r),
        ]
    else:
        i, j, m = k - 1, k % 3, (k + 1) % 3
        r = math.sqrt(1.0 + 2.0 * c[i, i] - t)
        q = [0.0] * 4
        q[0] = (c[m, j] - c[j, m]) / (2 * r)
        q[1 + i], q[1 + j], q[1 + m] = r / 2, (c[j, i] + c[i, j]) / (2 * r), (c[m, i] + c[i, m]) / (2 * r)
    return quat.normalize(np.array(q))


def twelve_position_duration(dwell_s: float, move_s: float) -> float:
    """The twelve-position scenario's duration: twelve dwells, eleven moves."""
    return 12.0 * dwell_s + 11.0 * move_s


def twelve_position_motion(
    *,
    dwell_s: float = 10.0,
    move_s: float = 4.0,
    latitude_deg: float = 28.20021,
    height_m: float = 5.13145,
    rate_hz: str = "200",
    rows: slice | None = None,
) -> Motion:
    """The twelve-position turntable calibration (algorithms.md §4, thesis Table 3.1 with its
    earth-rate column corrected): a dwell at each position in table order, smooth moves between them
    (the septic smoothstep over ``move_s``, a rotation about one body axis each). The orientations
    come from the core's table (``gfnav::calib::ORIENTATIONS``), so the trace and ``sins-fw calibrate``
    cannot disagree on them. The default place is the thesis's (chapter 5)."""
    if dwell_s <= 0 or move_s <= 0:
        raise ConfigError("twelve-position: dwell_s and move_s must be positive")
    t = sample_times(twelve_position_duration(dwell_s, move_s), rate_hz, rows)
    # C_b^n has the body axes (rows of each table entry, ENU) as its columns.
    qs = [_quat_from_dcm(np.array(axes).T) for axes in _core.gfnav_orientations()]
    q = np.empty((len(t), 4))
    w = np.zeros((len(t), 3))
    period = dwell_s + move_s
    k = np.minimum((t // period).astype(np.int64), 11)
    tau = t - k * period - dwell_s  # time into the move after dwell k (negative: dwelling)
    for i in range(12):
        at = k == i
        q[at] = qs[i]
        if i == 11:
            continue
        rel = quat.multiply(quat.conjugate(qs[i]), qs[i + 1])
        rel = rel if rel[0] >= 0 else -rel
        angle = 2.0 * math.atan2(float(np.linalg.norm(rel[1:])), float(rel[0]))
        axis = rel[1:] / np.linalg.norm(rel[1:])
        moving = at & (tau > 0)
        u = tau[moving] / move_s
        _, s, ds, _ = _smoothstep(u)
        q[moving] = quat.multiply(qs[i], quat.from_axis_angle(axis, angle * s))
        w[moving] = np.outer(angle * ds / move_s, axis)
    return _ground(t, q, w, latitude_deg, height_m)


@dataclass(frozen=True)
class Param:
    """One scenario parameter: Python name (the CLI option is ``--name-with-dashes``)."""

    name: str
    kind: str  # "float", "floats", "triple", "axis", "rate", "field", "flap", "trajectory"
    default: Any
    help: str
    #: Named in the generator command only when not at its default (the aiding keys: traces made
    #: without them stay byte-identical).
    optional: bool = False

    @property
    def option(self) -> str:
        return "--" + self.name.replace("_", "-")

    def parse(self, text: str) -> Any:
        """Parse a CLI value; raises ValueError with a message for argparse."""
        if self.kind == "float":
            return _finite(text)
        if self.kind in ("floats", "triple"):
            values = tuple(_finite(x) for x in text.split(",") if x.strip())
            if self.kind == "triple" and len(values) != 3:
                raise ValueError(f"expected three comma-separated numbers (roll,pitch,yaw), got `{text}`")
            if not values:
                raise ValueError("expected comma-separated numbers")
            return values
        if self.kind == "axis":
            if text not in _AXES:
                raise ValueError(f"expected x, y or z, got `{text}`")
            return text
        if self.kind == "trajectory":
            if text not in SPIN_TRAJECTORIES:
                raise ValueError(f"expected one of {', '.join(SPIN_TRAJECTORIES)}, got `{text}`")
            return text
        if self.kind == "flap":
            if text not in FLAP_PROFILES:
                raise ValueError(f"expected one of {', '.join(FLAP_PROFILES)}, got `{text}`")
            return text
        if self.kind == "field":
            if text not in MAG_FIELDS:
                raise ValueError(f"expected one of {', '.join(MAG_FIELDS)}, got `{text}`")
            return text
        try:
            parse_rate(text, "--rate-hz")
        except TraceError as e:
            raise ValueError(str(e).removeprefix("--rate-hz: ")) from None
        return text

    def render(self, value: Any) -> str:
        """The canonical text of a value (for the generator command line)."""
        if self.kind in ("floats", "triple"):
            return ",".join(_num(v) for v in value)
        if self.kind == "float":
            return _num(value)
        return str(value)


def _finite(text: str) -> float:
    try:
        x = float(text)
    except ValueError:
        raise ValueError(f"expected a number, got `{text}`") from None
    if not math.isfinite(x):
        raise ValueError(f"expected a finite number, got `{text}`")
    return x


def _num(x: float) -> str:
    return repr(float(x)).removesuffix(".0") if float(x).is_integer() else repr(float(x))


DEFAULT_LONGITUDE_DEG = 111.7
#: The magnetic field of ``--mag-field``: none (no magnetometer columns), wmm (the World Magnetic Model
#: 2020 of the ``ahrs`` package at the start point, epoch 2020.0), custom (the three mag_* keys).
MAG_FIELDS = ("none", "wmm", "custom")
#: The WMM's date: its epoch, so the field does not depend on the day the trace is made.
WMM_EPOCH = 2020.0
#: The aiding keys every scenario takes (magnetic field and GPS stream; docs/traces.md).
_AIDING = (
    Param("longitude_deg", "float", DEFAULT_LONGITUDE_DEG, "longitude of the start, degrees east", True),
    Param("mag_field", "field", "none", "magnetic field: none, wmm (WMM-2020 at the start) or custom", True),
    Param("mag_intensity_gauss", "float", 0.5, "custom field: total intensity F, gauss (0 < F ≤ 1)", True),
    Param("mag_inclination_deg", "float", 60.0, "custom field: inclination I, degrees down (−90…90)", True),
    Param("mag_declination_deg", "float", 0.0, "custom field: declination D, degrees east (−180…180)", True),
    Param(
        "gps_rate_hz", "float", 0.0, "GPS fix rate, Hz (0: no GPS stream; it divides the sample rate)", True
    ),
    Param("gps_latency_s", "float", 0.1, "GPS latency: a fix reaches the firmware this late, s (0…10)", True),
)
#: The vehicle scenario's aiding defaults: the thesis's longitude, a field for the compass (WMM-2020
#: at the place, rounded [unconfirmed: the thesis gives none]) and the GPS at 1 Hz.
VEHICLE_AIDING = {
    "longitude_deg": VEHICLE_LONGITUDE_DEG,
    "mag_field": "custom",
    "mag_intensity_gauss": 0.49,
    "mag_inclination_deg": 43.0,
    "mag_declination_deg": -3.0,
    "gps_rate_hz": 1.0,
}
_COMMON = (
    Param("latitude_deg", "float", DEFAULT_LATITUDE_DEG, "geodetic latitude, degrees"),
    Param("height_m", "float", DEFAULT_HEIGHT_M, "height above the ellipsoid, m"),
    Param("rate_hz", "rate", DEFAULT_RATE_HZ, "sample rate, Hz (exact decimal, e.g. 819.2)"),
    *_AIDING,
)
_ATTITUDE = Param(
    "attitude_deg", "triple", (0.0, 0.0, 0.0), "mount attitude roll,pitch,yaw, degrees (C_b^n ZYX)"
)


def _kinematic(motion: Callable[..., Motion]) -> Callable[..., Motion]:
    """A motion function taking every parameter of its scenario: the aiding keys (the trace's
    magnetic field and GPS, not the motion's) are set aside."""

    def make(**values: Any) -> Motion:
        return motion(**{k: v for k, v in values.items() if k not in _AIDING_NAMES})

    make.__doc__ = motion.__doc__
    return make


_AIDING_NAMES = frozenset(p.name for p in _AIDING)


@dataclass(frozen=True)
class Scenario:
    """A named scenario: its motion function, parameters, and description."""

    name: str
    motion: Callable[..., Motion]
    params: tuple[Param, ...]
    summary: str
    transport_rate: bool = False
    #: Whether the motion is made chunk by chunk (``rows``); else whole, once, then cut into chunks.
    chunked: bool = True
    #: The most rows made at a time (a wide scenario's chunks are shorter, so that a chunk's
    #: intermediates stay about the size of a 17-column trace's; the values do not depend on it).
    max_chunk_rows: int = 1 << 16


SCENARIOS: dict[str, Scenario] = {
    s.name: s
    for s in (
        Scenario(
            "static",
            _kinematic(static_motion),
            (Param("duration_s", "float", 60.0, "duration, s"), _ATTITUDE, *_COMMON),
            "a board at rest at a fixed attitude",
        ),
        Scenario(
            "indexing-table",
            _kinematic(indexing_table_motion),
            (
                Param("axis", "axis", "y", "body axis of the table: x (roll), y (pitch) or z (yaw)"),
                Param("angles_deg", "floats", (0.0, 10.0), "table angles in order, degrees (first = start)"),
                Param("max_rate_dps", "float", 20.0, "table rate limit, °/s"),
                Param("max_accel_dps2", "float", 40.0, "table acceleration limit, °/s²"),
                Param("dwell_s", "float", 10.0, "dwell at each angle, s"),
                _ATTITUDE,
                *_COMMON,
            ),
            "single-axis indexing table: dwell, smooth moves with rate/acceleration limits",
        ),
        Scenario(
            "turntable",
            _kinematic(turntable_motion),
            (
                Param("axis", "axis", "x", "body axis of rotation"),
                Param("rates_dps", "floats", (50.0, 100.0, 200.0, 300.0), "table rates in order, °/s"),
                Param("hold_s", "float", 10.0, "time at each rate, s"),
                Param("max_accel_dps2", "float", 100.0, "acceleration limit, °/s²"),
                Param("lead_s", "float", 5.0, "time at rest before and after, s"),
                _ATTITUDE,
                *_COMMON,
            ),
            "rate table: constant rates about a body axis with smooth changes",
        ),
        Scenario(
            "coning",
            _kinematic(coning_motion),
            (
                Param("half_angle_deg", "float", 1.0, "cone half-angle α, degrees"),
                Param("frequency_hz", "float", 10.0, "coning frequency Ω/2π, Hz"),
                Param("duration_s", "float", 120.0, "duration, s"),
                _ATTITUDE,
                *_COMMON,
            ),
            "classical coning about the mount's x axis",
        ),
        Scenario(
            "spin",
            _kinematic(spin_motion),
            (
                Param(
                    "trajectory", "trajectory", "turntable", "turntable, or ballistic (a drag-free arc)", True
                ),
                Param("spin_dps", "float", 1000.0, "spin rate about body x, °/s (0…1000)"),
                Param("spin_up_s", "float", 2.0, "spin-up time from rest, s"),
                Param("duration_s", "float", 60.0, "duration, s"),
                Param("pitch_amplitude_deg", "float", 5.0, "pitch swing of the spin axis, degrees"),
                Param("yaw_amplitude_deg", "float", 5.0, "yaw swing of the spin axis, degrees"),
                Param("sway_hz", "float", 0.2, "frequency of the pitch and yaw swing, Hz"),
                Param("launch_speed_mps", "float", 500.0, "ballistic: launch speed, m/s", True),
                Param("elevation_deg", "float", 45.0, "ballistic: launch elevation, degrees (0…90)", True),
                Param(
                    "azimuth_deg",
                    "float",
                    0.0,
                    "ballistic: launch azimuth, degrees clockwise from north",
                    True,
                ),
                _ATTITUDE,
                *_COMMON,
            ),
            "a body spinning about x on a turntable or a ballistic arc, its axis swinging in pitch and yaw",
        ),
        Scenario(
            "flight",
            _kinematic(flight_motion),
            (
                Param("heading_deg", "float", 60.0, "runway heading, degrees from north clockwise"),
                Param("speed_mps", "float", 40.0, "cruise speed, m/s"),
                Param("turn_rate_dps", "float", 3.0, "turn rate, °/s"),
                Param("climb_deg", "float", 6.0, "climb flight-path angle, degrees"),
                *_COMMON,
            ),
            "fixed-wing flight: take-off roll, climb, turns, level, descent (with transport rate)",
            transport_rate=True,
            chunked=False,  # its position sums the whole trajectory (a fixed 318 s plan)
        ),
        Scenario(
            "turn",
            _kinematic(turn_motion),
            (
                Param("speed_mps", "float", 20.0, "ground speed, m/s"),
                Param("turn_rate_dps", "float", 10.0, "turn rate, °/s (positive: right turn)"),
                Param("heading_deg", "float", 0.0, "heading at t = 0, degrees from north clockwise"),
                Param("duration_s", "float", 120.0, "duration, s"),
                *_COMMON,
            ),
            "level coordinated turn at constant speed and rate (with transport rate)",
            transport_rate=True,
        ),
        Scenario(
            "twelve-position",
            _kinematic(twelve_position_motion),
            (
                Param("dwell_s", "float", 10.0, "time at each of the twelve positions, s"),
                Param("move_s", "float", 4.0, "time of each move between positions, s"),
                Param("latitude_deg", "float", 28.20021, "geodetic latitude, degrees"),
                Param("height_m", "float", 5.13145, "height above the ellipsoid, m"),
                Param("rate_hz", "rate", "200", "sample rate, Hz (exact decimal)"),
                *_AIDING,
            ),
            "the twelve-position turntable calibration of the gyro-free array (thesis Table 3.1, corrected)",
        ),
        Scenario(
            "wing",
            _kinematic(wing_motion),
            (
                Param(
                    "flap",
                    "flap",
                    "steps",
                    "flap profile: steps (rests between), sine or sweep (reciprocating)",
                ),
                Param(
                    "angles_deg",
                    "floats",
                    (0.0, 20.0, -15.0, 35.0, 0.0),
                    "steps: hinge angles in order, degrees",
                ),
                Param("amplitude_deg", "float", 30.0, "sine and sweep: amplitude, degrees"),
                Param("period_s", "float", 4.0, "sine: period, s"),
                Param("max_rate_dps", "float", 60.0, "steps and sweep: rate limit, °/s"),
                Param("max_accel_dps2", "float", 120.0, "steps and sweep: acceleration limit, °/s²"),
                Param("rest_s", "float", 10.0, "rest at the zero first (and at each step), s"),
                Param("duration_s", "float", 120.0, "sine and sweep: duration, s"),
                Param(
                    "axis_elevation_deg",
                    "float",
                    20.0,
                    "hinge axis elevation β above the horizontal, degrees",
                ),
                Param("axis_azimuth_deg", "float", 30.0, "hinge axis azimuth, degrees from north clockwise"),
                Param(
                    "mount_deg",
                    "triple",
                    (10.0, -5.0, 70.0),
                    "IMU attitude at the zero: roll,pitch,yaw, degrees",
                ),
                Param(
                    "lever_m", "floats", (0.3, 0.1, 0.0), "IMU position from the hinge line: east,north,up, m"
                ),
                Param(
                    "base_amplitude_deg", "float", 0.0, "base pitching amplitude, degrees (0: static base)"
                ),
                Param("base_period_s", "float", 20.0, "base pitching period, s"),
                Param("temp_start_c", "float", 25.0, "sensor temperature at the start, °C"),
                Param("temp_rate_c_per_min", "float", 0.0, "temperature drift, °C/min"),
                *_COMMON,
            ),
            "a wing on a hinge of any axis, IMU at any mount: flap steps, sines or sweeps; exact α truth",
        ),
        Scenario(
            "vehicle",
            _kinematic(vehicle_motion),
            (
                Param("speed_mps", "float", VEHICLE_SPEED_MPS, "ground speed, m/s (thesis: 80 km/h)"),
                Param("heading_deg", "float", 30.0, "heading at t = 0, degrees from north clockwise"),
                Param("turn_rate_dps", "float", 0.0, "turn rate, °/s (0: straight line)"),
                Param("duration_s", "float", 60.0, "duration, s"),
                Param("lever_arm_m", "float", 0.1, "array lever arm l, m (gfsins.toml array.lever_arm_m)"),
                Param(
                    "array_positions_lever_arms",
                    "floats",
                    tuple(float(x) for x in ARRAY_POSITIONS.ravel()),
                    "the 7 parts' places x,y,z in turn, in lever arms (gfsins.toml array.parts positions)",
                    True,
                ),
                Param("latitude_deg", "float", VEHICLE_LATITUDE_DEG, "geodetic latitude, degrees"),
                Param("height_m", "float", VEHICLE_HEIGHT_M, "height above the ellipsoid, m"),
                Param("rate_hz", "rate", "1000", "sample rate, Hz (exact decimal)"),
                *(
                    replace(p, default=VEHICLE_AIDING[p.name]) if p.name in VEHICLE_AIDING else p
                    for p in _AIDING
                ),
            ),
            "gyro-free vehicle board: straight line or turn, 7 ADXL345 at lever arm l, compass field, GPS",
            transport_rate=True,
            max_chunk_rows=1 << 14,  # 41 columns and 7 force terms of 3 a row
        ),
    )
}


def resolve(name: str, preset: str | None = None, **params: Any) -> dict[str, Any]:
    """All parameters of a scenario with defaults, preset and overrides applied (the canonical set)."""
    if name not in SCENARIOS:
        raise ConfigError(f"unknown scenario `{name}`; known: {', '.join(SCENARIOS)}")
    scenario = SCENARIOS[name]
    values = {p.name: p.default for p in scenario.params}
    if preset is not None:
        if name != "indexing-table" or preset not in INDEXING_PRESETS:
            known = ", ".join(INDEXING_PRESETS) if name == "indexing-table" else "none"
            raise ConfigError(f"unknown preset `{preset}` for `{name}`; known: {known}")
        values.update(INDEXING_PRESETS[preset])
        if preset == "sweep":
            values["angles_deg"] = sweep_angles(params.get("axis", values["axis"]))
    by_name = {p.name: p for p in scenario.params}
    for key, value in params.items():
        if key not in values:
            raise ConfigError(f"scenario `{name}` has no parameter `{key}`; known: {', '.join(values)}")
        if isinstance(value, str):
            # Text (montecarlo --param key=value, a script): parsed exactly as the CLI option is.
            try:
                value = by_name[key].parse(value)
            except ValueError as e:
                raise ConfigError(f"scenario `{name}`, parameter `{key}` = {value!r}: {e}") from None
        values[key] = value
    _check_place(name, values["latitude_deg"], values["height_m"])
    _check_aiding(name, values)
    return values


def _check_aiding(name: str, values: dict[str, Any]) -> None:
    """The aiding keys' ranges (a ConfigError naming the key and the range)."""
    for key, lo, hi, allowed in (
        ("longitude_deg", -180.0, 180.0, "−180…180"),
        ("mag_intensity_gauss", 1e-6, 1.0, "0 < F ≤ 1 gauss (the earth's field is 0.22…0.67)"),
        ("mag_inclination_deg", -90.0, 90.0, "−90…90"),
        ("mag_declination_deg", -180.0, 180.0, "−180…180"),
        ("gps_rate_hz", 0.0, 50.0, "0…50 Hz"),
        ("gps_latency_s", 0.0, 10.0, "0…10 s"),
    ):
        value = values[key]
        if not (isinstance(value, int | float) and math.isfinite(value) and lo <= value <= hi):
            raise ConfigError(
                f"scenario `{name}`, parameter `{key}` (--{key.replace('_', '-')}) = {value!r}: "
                f"expected {allowed}"
            )
    if values["mag_field"] not in MAG_FIELDS:
        raise ConfigError(
            f"scenario `{name}`, parameter `mag_field` = {values['mag_field']!r}: "
            f"expected one of {', '.join(MAG_FIELDS)}"
        )


def field_n(values: dict[str, Any]) -> Array | None:
    """The earth's magnetic field at the start point, ENU, gauss (None for ``mag_field = none``):
    F·[cos I sin D, cos I cos D, −sin I], I positive down, D east of true north."""
    if values["mag_field"] == "none":
        return None
    if values["mag_field"] == "wmm":
        try:
            from ahrs.utils import WMM  # the ahrs package loads slowly: only for wmm
        except ImportError:
            raise ConfigError(
                "mag_field = wmm needs the `ahrs` package (pip install 'sins-fw[bench]'); or give the field "
                "with mag_field = custom and the mag_* keys"
            ) from None

        w = WMM(
            date=WMM_EPOCH,
            latitude=float(values["latitude_deg"]),
            longitude=float(values["longitude_deg"]),
            height=float(values["height_m"]) / 1000.0,
        )
        f, i, d = float(w.F) * 1e-5, math.radians(float(w.I)), math.radians(float(w.D))  # nT → gauss
    else:
        f = float(values["mag_intensity_gauss"])
        i, d = math.radians(values["mag_inclination_deg"]), math.radians(values["mag_declination_deg"])
    return f * np.array([math.cos(i) * math.sin(d), math.cos(i) * math.cos(d), -math.sin(i)])


def _check_place(name: str, latitude_deg: Any, height_m: Any) -> None:
    """Latitude and height through the profile's own validation of ``navigation.latitude_deg`` and
    ``navigation.height_m`` (one rule for both: the ranges where the navigation frame and the
    gravity model hold)."""
    for key, value in (("latitude_deg", latitude_deg), ("height_m", height_m)):
        try:
            _core.resolve_profile("", f"scenario `{name}`", [f"navigation.{key}={float(value)!r}"])
        except (TypeError, ValueError):
            raise ConfigError(
                f"scenario `{name}`, parameter `{key}` = {value!r}: expected a number"
            ) from None
        except ProfileError as e:
            raise ConfigError(
                f"scenario `{name}`, parameter `{key}` (--{key.replace('_', '-')}): {e}"
            ) from None


def command_line(name: str, values: dict[str, Any]) -> str:
    """The canonical ``sins-fw synth`` command that generates this trace (output option omitted)."""
    scenario = SCENARIOS[name]
    args = ["sins-fw", "synth", name]
    for p in scenario.params:
        if not (p.optional and values[p.name] == p.default):
            args += [p.option, p.render(values[p.name])]
    return shlex.join(args)


#: Rows generated at a time by :func:`generate_chunks` (the trace writer's block).
CHUNK_ROWS = 1 << 16


def _motion(scenario: Scenario, values: dict[str, Any], rows: slice | None = None) -> Motion:
    """The scenario's motion."""
    return scenario.motion(**values) if rows is None else scenario.motion(**values, rows=rows)


def generate(name: str, preset: str | None = None, **params: Any) -> PhysicalTrace:
    """A scenario as a physical trace (truth quaternion and movement mask included)."""
    values = resolve(name, preset, **params)
    return to_trace(_motion(SCENARIOS[name], values), _metadata(name, values), values)


def generate_chunks(
    name: str, preset: str | None = None, *, rows: int = CHUNK_ROWS, **params: Any
) -> Iterator[PhysicalTrace]:
    """The trace of :func:`generate` as consecutive chunks of ``rows`` rows, made one at a time (memory
    bounded by the chunk, whatever the duration); concatenated, they are that trace value for value."""
    values = resolve(name, preset, **params)
    scenario = SCENARIOS[name]
    rows = min(rows, scenario.max_chunk_rows)
    metadata = _metadata(name, values)
    whole = None if scenario.chunked else _motion(scenario, values)
    for start in itertools.count(0, rows):
        cut = slice(start, start + rows)
        motion = _motion(scenario, values, cut) if whole is None else whole.rows(cut)
        n = len(motion.t_s)
        chunk = to_trace(motion, metadata, values) if n else None
        del motion  # not held while the next chunk is made
        if chunk is not None:
            yield chunk
            del chunk
        if n < rows:
            return


def _metadata(name: str, values: dict[str, Any]) -> dict[str, str]:
    scenario = SCENARIOS[name]
    return {
        "sample_rate_hz": str(values["rate_hz"]),
        "source": f"sins-fw synth {name}",  # no preset: the generator command alone reproduces the file
        "generator": command_line(name, values),
        "created_by": "sins-fw synth (no version or time recorded: regeneration is byte-identical)",
        "frame": "sensor axes = body axes; truth C_b^n, navigation frame ENU (x east, y north, z up)",
        "g0_m_s2": repr(earth.G0),
        "gravity": "WGS-84 normal gravity with free-air correction",
        "earth_rate_rad_s": repr(earth.OMEGA_IE),
        "transport_rate": "included"
        if scenario.transport_rate or values.get("trajectory") == "ballistic"
        else "zero (the board stays at one place)",
        "latitude_deg": _num(values["latitude_deg"]),
        "height_m": _num(values["height_m"]),
        **_launch_metadata(values),
        **_aiding_metadata(values),
    }


def _launch_metadata(values: dict[str, Any]) -> dict[str, str]:
    """A ballistic arc's launch (the launcher's setting a fuze is handed before firing): elevation
    and azimuth of the spin axis at t = 0, degrees, and the launch speed (``geomag.launch_*`` keys
    take them: `sins_fw.spin_table.launch_overrides`)."""
    if values.get("trajectory") != "ballistic":
        return {}
    return {
        "launch_elevation_deg": _num(values["elevation_deg"]),
        "launch_azimuth_deg": _num(values["azimuth_deg"]),
        "launch_speed_mps": _num(values["launch_speed_mps"]),
    }


def _aiding_metadata(values: dict[str, Any]) -> dict[str, str]:
    """The metadata of the magnetic field and the GPS stream, when the trace has them."""
    out: dict[str, str] = {}
    m = field_n(values)
    if m is not None:
        source = f"WMM-2020 (ahrs), epoch {WMM_EPOCH}" if values["mag_field"] == "wmm" else "custom"
        out["magnetic_field_enu_gauss"] = " ".join(repr(float(x)) for x in m)
        out["magnetic_field_source"] = f"{source}, at the start point, constant over the trace"
    if values["gps_rate_hz"] > 0:
        out["gps_rate_hz"] = _num(values["gps_rate_hz"])
        out["gps_latency_s"] = _num(values["gps_latency_s"])
        out["longitude_deg"] = _num(values["longitude_deg"])
    return out


def to_trace(motion: Motion, metadata: dict[str, str], values: dict[str, Any] | None = None) -> PhysicalTrace:
    """Sensor quantities of a motion in trace units (°/s, g), with the magnetic field and the GPS
    stream of the aiding keys in ``values`` (none without them)."""
    m = None if values is None else field_n(values)
    gps = None if values is None or values["gps_rate_hz"] <= 0 else _gps(motion, values)
    return PhysicalTrace(
        t_s=motion.t_s,
        gyro_dps=np.degrees(motion.gyro_rad_s()),
        accel_g=motion.specific_force() / earth.G0,
        mag_gauss=None
        if m is None
        else quat.rotate(quat.conjugate(motion.q_nb), np.broadcast_to(m, motion.v_n.shape)),
        truth_q=motion.q_nb,
        truth_alpha_deg=None if motion.alpha_rad is None else np.degrees(motion.alpha_rad),
        array_g=motion.array_g,
        temp_c=motion.temp_c,
        moving=motion.moving(),
        metadata=metadata,
        gps=gps,
    )


def _gps(motion: Motion, values: dict[str, Any]) -> Array:
    """The GPS columns (n, 5): a fix (ground speed, course, latitude, longitude, height: the truth) on
    the first sample at or after each multiple of 1/gps_rate (from t = 0; exact integer arithmetic on
    the sample index, so chunks agree), NaN elsewhere. Longitude: the start's plus the east
    displacement over the start's radius of the prime vertical (as the latitude uses R_N)."""
    rate = parse_rate(str(values["rate_hz"]), "synth")
    ratio = Fraction(str(values["gps_rate_hz"])) / rate  # GPS epochs per sample
    index = np.rint(motion.t_s * float(rate)).astype(np.int64)

    def epoch(i: NDArray[np.int64]) -> NDArray[np.int64]:
        return (i * ratio.numerator) // ratio.denominator

    fix = (index == 0) | (epoch(index) != epoch(index - 1))
    v_e, v_n = motion.v_n[:, 0], motion.v_n[:, 1]
    lat0 = math.radians(float(values["latitude_deg"]))
    r_e = float(earth.radii(lat0)[1]) + float(values["height_m"])
    lon = float(values["longitude_deg"]) + np.degrees(motion.east_m / (r_e * math.cos(lat0)))
    course = np.mod(np.degrees(np.arctan2(v_e, v_n)), 360.0)
    cols = np.stack(
        [
            np.hypot(v_e, v_n),
            np.where(course >= 360.0, 0.0, course),
            np.degrees(motion.lat_rad),
            lon,
            motion.height_m,
        ],
        axis=1,
    )
    cols[~fix] = np.nan
    return cols
