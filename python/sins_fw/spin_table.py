"""The spin-rate table of the geomagnetic–gyro board (issue 21): spin rate → roll error without and
with the magnetometer roll aid, as percentiles over a Monte Carlo of sensor units.

Each unit (seed s) is the analogue chain's presets drawn once (SPIN1200 spin gyro on x, ADXRS300 on
y and z, the AMR magnetometer: bias, scale-factor error, offsets, noise). The same units run at every
rate. Per unit and rate: the gyro-only roll error at the end (and relative to the spin angle) and the
aided run's largest |roll error|. The roll error is the x component of the body-frame error rotation
Q_true* ⊗ Q, followed through every update (whole turns count).

Two engines:
- ``board`` (the default): the whole board, ``firmware_model/geomag.toml`` through ``harness.emulate``
  (what ``sins-fw run`` does): the F28335 converting the ADS8344's eight channels over SPI every
  1 ms tick (each channel held at its own instant), the ``ads8344-geomag`` firmware in the profile's
  c28x-f32 arithmetic, on a ``sins-fw synth spin`` trace per rate (a turntable: the spin axis fixed at
  the given yaw, level, no sway; from rest by the septic ramp over ``BOARD_SPIN_UP_S``; the earth's
  rate included; latitude and height the scenario's defaults). Unit s is ``errors.seed = s`` with
  ``geomag.ideal_sensors = false``; the gyro-only run is the same unit with the aid's gains at 0
  (``geomag.aid_kp = aid_ki = 0``: it reads the same samples). The firmware's initial attitude is
  level (``firmware.initial_yaw_deg`` only), so the axis's pitch must be 0.
- ``chain``: ``_core.geomag_spin_chain``, the sensor chain and ``firmware/geomag.rs`` without the bus
  (no SPI timing; every channel of an instant read at that instant; the navigation frame inertial),
  spinning at the rate from t = 0 with the sensors settled, any pitch.

The aid's PI loop is the profile's, K_p = 1/s, K_i = 0.25/s², in both.

``trajectory = "ballistic"`` (board only): per rate a ``synth spin --trajectory ballistic`` trace (a
drag-free arc from the launch's speed, elevation and azimuth, the axis nodding ±5° at 0.2 Hz as the
scenario's defaults), the firmware started from the launch (``launch_overrides``: the trace's
``launch_*`` metadata as ``geomag.launch_*`` keys) and the table given along the arc: per window of
the flight, the largest |roll error| without and with the aid, the bound the aided error must keep
(``aided_roll_bound``, from the gains and the sensor presets) and the events.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from sins_fw import _core, earth, quaternion, synth
from sins_fw.errors import ConfigError
from sins_fw.harness import Run, emulate
from sins_fw.profile import load_profile
from sins_fw.traces import CheckedTrace

#: The issue's rates, °/s.
DEFAULT_RATES_DPS = (50.0, 100.0, 200.0, 500.0, 1000.0)
#: The earth's field at Beijing [unconfirmed: rounded IGRF 2014]: intensity (gauss), inclination
#: and declination (degrees).
DEFAULT_FIELD = (0.54, 58.5, -6.5)
PERCENTILES = (("p50", 50.0), ("p95", 95.0), ("max", 100.0))
ENGINES = ("board", "chain")
TRAJECTORIES = ("turntable", "ballistic")
#: The board's profile and the turntable's spin-up from rest, s.
BOARD_PROFILE = "geomag"
BOARD_SPIN_UP_S = 1.0
#: The group delays ``compensate`` sets: the SPIN1200's second-order 100 Hz, ζ 0.7 (τ_g = 2ζ/ω_n) and
#: the AMR magnetometer's first-order 1 kHz (device/analog).
GYRO_DELAY_S = 2.0 * 0.7 / (2.0 * math.pi * 100.0)
MAG_CUTOFF_HZ = 1000.0


def field_enu(intensity_gauss: float, inclination_deg: float, declination_deg: float) -> list[float]:
    """F·[cos I sin D, cos I cos D, −sin I] (east, north, up), I positive down."""
    i, d = math.radians(inclination_deg), math.radians(declination_deg)
    return [
        intensity_gauss * math.cos(i) * math.sin(d),
        intensity_gauss * math.cos(i) * math.cos(d),
        -intensity_gauss * math.sin(i),
    ]


def _check(
    rates_dps: Sequence[float],
    runs: int,
    seed: int,
    duration_s: float,
    field: Sequence[float],
    engine: str,
    pitch_deg: float,
    trajectory: str = "turntable",
) -> None:
    if trajectory not in TRAJECTORIES:
        raise ConfigError(f"spin-table: --trajectory {trajectory}; expected one of {', '.join(TRAJECTORIES)}")
    if trajectory == "ballistic" and engine != "board":
        raise ConfigError(
            "spin-table: --trajectory ballistic runs on the board only (expected --engine board)"
        )
    if engine not in ENGINES:
        raise ConfigError(f"spin-table: --engine {engine}; expected one of {', '.join(ENGINES)}")
    if not rates_dps:
        raise ConfigError("spin-table: --rates-dps: expected at least one rate")
    for r in rates_dps:
        if not (math.isfinite(r) and 0.0 < r <= 1000.0):
            raise ConfigError(f"spin-table: --rates-dps: {r} °/s; expected 0 < rate ≤ 1000 °/s")
    if not 1 <= runs <= 10_000:
        raise ConfigError(f"spin-table: --runs {runs}; expected 1…10000 units")
    if not 0 <= seed < 2**63:
        raise ConfigError(f"spin-table: --first-seed {seed}; expected 0 ≤ seed < 2⁶³")
    if not (math.isfinite(duration_s) and 0.01 <= duration_s <= 3600.0):
        raise ConfigError(f"spin-table: --duration-s {duration_s}; expected 0.01…3600 s")
    intensity, inclination, declination = field
    if not (math.isfinite(intensity) and 0.0 < intensity <= 1.0):
        raise ConfigError(f"spin-table: --mag-intensity-gauss {intensity}; expected 0 < F ≤ 1 gauss")
    if not (math.isfinite(inclination) and -90.0 <= inclination <= 90.0):
        raise ConfigError(f"spin-table: --mag-inclination-deg {inclination}; expected −90…90")
    if not (math.isfinite(declination) and -180.0 <= declination <= 180.0):
        raise ConfigError(f"spin-table: --mag-declination-deg {declination}; expected −180…180")
    if engine == "board" and pitch_deg != 0.0 and trajectory == "turntable":
        raise ConfigError(
            f"spin-table: --pitch-deg {pitch_deg:g}: the board's firmware starts level (geomag.toml sets "
            "firmware.initial_yaw_deg only); expected 0, or --engine chain for a pitched axis"
        )
    if engine == "board" and duration_s <= 2.0 * BOARD_SPIN_UP_S:
        raise ConfigError(
            f"spin-table: --duration-s {duration_s:g}: the board's turntable spins up over "
            f"{BOARD_SPIN_UP_S:g} s; expected more than {2.0 * BOARD_SPIN_UP_S:g} s"
        )


def _percentiles(x: np.ndarray) -> dict[str, float]:
    return {name: float(np.percentile(x, q)) for name, q in PERCENTILES}


def roll_errors(quat: np.ndarray, truth_q: np.ndarray) -> np.ndarray:
    """The x component of the body-frame error rotation Q_true* ⊗ Q (rad) per row, followed through
    every row (it moves far less than π from one update to the next), as the chain's ``errors``."""
    e = quaternion.multiply(quaternion.conjugate(truth_q), quat)
    e = np.where(e[:, :1] < 0.0, -e, e)
    v = np.linalg.norm(e[:, 1:], axis=1)
    angle = 2.0 * np.arctan2(v, e[:, 0])
    scale = np.divide(angle, v, out=np.full_like(v, 2.0), where=v > 0.0)
    return np.unwrap(e[:, 1] * scale)


def _chain_unit(
    rate: float,
    unit: int,
    duration_s: float,
    yaw_deg: float,
    pitch_deg: float,
    m_n: list[float],
    compensate: bool,
) -> tuple[float, float, float, int]:
    r = _core.geomag_spin_chain(
        spin_dps=float(rate),
        seconds=float(duration_s),
        seed=unit,
        field_enu_gauss=m_n,
        yaw_deg=float(yaw_deg),
        pitch_deg=float(pitch_deg),
        mag_cutoff_hz=MAG_CUTOFF_HZ if compensate else None,
        gyro_delay_s=GYRO_DELAY_S if compensate else None,
    )
    end = float(r["roll_gyro"][-1])
    spin_angle = math.radians(rate) * float(r["t_s"][-1])
    return end, spin_angle, float(np.abs(r["roll_aided"]).max()), 0


def _board_trace(rate: float, duration_s: float, yaw_deg: float, field: Sequence[float]) -> CheckedTrace:
    intensity, inclination, declination = field
    trace = synth.generate(
        "spin",
        spin_dps=float(rate),
        spin_up_s=BOARD_SPIN_UP_S,
        duration_s=float(duration_s),
        pitch_amplitude_deg=0.0,
        yaw_amplitude_deg=0.0,
        attitude_deg=(0.0, 0.0, float(yaw_deg)),
        mag_field="custom",
        mag_intensity_gauss=float(intensity),
        mag_inclination_deg=float(inclination),
        mag_declination_deg=float(declination),
    )
    return CheckedTrace(trace)


def _aided_and_plain(
    trace: CheckedTrace,
    unit: int,
    ideal: bool,
    keys: Sequence[str],
    m_n: list[float],
    compensate: bool,
    calibration: Sequence[str] = (),
) -> tuple[Run, Run]:
    """The geomag board's runs on ``trace`` with sensor unit ``unit`` (its seed), with the
    magnetometer aid and without it: the field ``m_n``, the group-delay compensation when
    ``compensate``, the run's own profile ``keys`` and ``calibration``."""
    profile = load_profile(
        BOARD_PROFILE,
        [
            f"errors.seed={unit}",
            f"geomag.ideal_sensors={'true' if ideal else 'false'}",
            *keys,
            "geomag.field_enu_gauss=[{}]".format(", ".join(repr(float(x)) for x in m_n)),
            f"geomag.mag_cutoff_hz={MAG_CUTOFF_HZ if compensate else 0.0!r}",
            *([f"geomag.gyro_delay_s={GYRO_DELAY_S!r}"] if compensate else []),
            *calibration,
        ],
    )
    aided = emulate(trace, profile)
    plain = emulate(trace, profile, overrides=["geomag.aid_kp=0", "geomag.aid_ki=0"])
    return aided, plain


def _board_unit(
    trace: CheckedTrace, rate: float, unit: int, yaw_deg: float, m_n: list[float], compensate: bool
) -> tuple[float, float, float, int]:
    yaw_key = f"firmware.initial_yaw_deg={float(yaw_deg)!r}"
    aided, plain = _aided_and_plain(trace, unit, False, [yaw_key], m_n, compensate)
    assert aided.truth_q is not None and plain.truth_q is not None
    end = float(roll_errors(plain.quat, plain.truth_q)[-1])
    t_end = float(plain.time_s[-1])
    spin_angle = math.radians(rate) * (t_end - BOARD_SPIN_UP_S / 2.0)
    worst = float(np.abs(roll_errors(aided.quat, aided.truth_q)).max())
    return end, spin_angle, worst, len(aided.events) + len(plain.events)


def spin_table(
    rates_dps: Sequence[float] = DEFAULT_RATES_DPS,
    *,
    runs: int = 20,
    seed: int = 0,
    duration_s: float = 60.0,
    yaw_deg: float = 90.0,
    pitch_deg: float = 0.0,
    field: Sequence[float] = DEFAULT_FIELD,
    compensate: bool = False,
    engine: str = "board",
) -> dict[str, Any]:
    """The table as a dict: the settings and, per rate, the percentiles (p50, p95, max) over ``runs``
    units (seeds ``seed`` … ``seed + runs − 1``) of the gyro-only roll error at the end (degrees and
    percent of the spin angle) and of the aided run's largest |roll error| (degrees). ``compensate``:
    the firmware's group-delay options on (the spin gyro's τ_g = 2ζ/ω_n on the x rate, the
    magnetometer's 1 kHz lag), off otherwise. ``engine``: ``board`` or ``chain`` (the module's doc)."""
    _check(rates_dps, runs, seed, duration_s, field, engine, pitch_deg)
    m_n = field_enu(*field)
    rows = []
    for rate in rates_dps:
        trace = _board_trace(rate, duration_s, yaw_deg, field) if engine == "board" else None
        gyro_only, relative, aided = [], [], []
        events = 0
        for unit in range(seed, seed + runs):
            if trace is not None:
                end, angle, worst, n = _board_unit(trace, rate, unit, yaw_deg, m_n, compensate)
            else:
                end, angle, worst, n = _chain_unit(
                    rate, unit, duration_s, yaw_deg, pitch_deg, m_n, compensate
                )
            gyro_only.append(math.degrees(abs(end)))
            relative.append(100.0 * abs(end) / angle)
            aided.append(math.degrees(worst))
            events += n
        rows.append(
            {
                "spin_dps": float(rate),
                "gyro_only_deg": _percentiles(np.array(gyro_only)),
                "gyro_only_percent": _percentiles(np.array(relative)),
                "aided_max_deg": _percentiles(np.array(aided)),
                "events": events,
            }
        )
    chain = (
        "geomag.toml on the board: F28335 SPI-A, ADS8344 16 bits at VREF 5 V, SPIN1200 (x), ADXRS300 (y, z), "
        f"AMR magnetometer, ads8344-geomag firmware (c28x-f32); spin-up {BOARD_SPIN_UP_S:g} s"
        if engine == "board"
        else "SPIN1200 (x), ADXRS300 (y, z), AMR magnetometer, ADS8344 16 bits at VREF 5 V; "
        "sensor chain and firmware/geomag.rs without the bus"
    )
    return {
        "engine": engine,
        "chain": chain,
        "units": runs,
        "seeds": [seed, seed + runs - 1],
        "duration_s": float(duration_s),
        "spin_axis_yaw_deg": float(yaw_deg),
        "spin_axis_pitch_deg": float(pitch_deg),
        "field_enu_gauss": m_n,
        "aid": {"kp_per_s": 1.0, "ki_per_s2": 0.25, "gate_gauss": 0.05},
        "compensated": compensate,
        "rows": rows,
    }


def render(table: dict[str, Any]) -> str:
    """The table as text."""

    def cells(p: dict[str, float], fmt: str) -> str:
        return " ".join(format(p[name], fmt) for name, _ in PERCENTILES)

    lines = [
        f"spin-rate table: {table['chain']}",
        f"{table['units']} units (seeds {table['seeds'][0]}…{table['seeds'][1]}), "
        f"{table['duration_s']:g} s each; "
        f"spin axis yaw {table['spin_axis_yaw_deg']:g}°, pitch {table['spin_axis_pitch_deg']:g}°; "
        f"aid K_p 1/s, K_i 0.25/s²; group-delay compensation {'on' if table['compensated'] else 'off'}",
        "percentiles over the units: p50 p95 max",
        f"{'spin °/s':>9} | {'gyro-only roll error at the end, °':>36} | {'relative, %':>26} | "
        f"{'aided max |roll error|, °':>26} | events",
    ]
    for row in table["rows"]:
        lines.append(
            f"{row['spin_dps']:9g} | {cells(row['gyro_only_deg'], '11.4f'):>36} | "
            f"{cells(row['gyro_only_percent'], '8.4f'):>26} | {cells(row['aided_max_deg'], '8.4f'):>26} | "
            f"{row['events']}"
        )
    return "\n".join(lines)


# --- The ballistic arc ------------------------------------------------------------------------------

#: The presets' 1σ figures the bound uses (rust/core/src/device/analog/{gyro,magnetometer}.rs): the
#: spin gyro (spin1200) and the cross-axis gyros (adxrs300): unit bias b (°/s), scale-factor error δk,
#: noise density N (°/s/√Hz); the AMR magnetometer: offset (gauss), noise density (gauss/√Hz), 1 kHz.
SPIN_GYRO = {"bias_dps": 1.0, "scale_error": 0.005, "noise_dps_rt_hz": 0.05}
CROSS_GYRO = {"bias_dps": 1.0, "scale_error": 0.01, "noise_dps_rt_hz": 0.1}
MAGNETOMETER = {"offset_gauss": 1e-3, "noise_gauss_rt_hz": 20e-6, "cutoff_hz": 1000.0}
#: One ADS8344 code of the spin gyro, °/s (5 V/65536 over 1.6 mV/(°/s)) and of the magnetometer,
#: gauss (5 V/65536 over 1 V/gauss): the quantisation the ideal sensors keep.
SPIN_LSB_DPS = 5.0 / 65536.0 / 1.6e-3
MAG_LSB_GAUSS = 5.0 / 65536.0
#: The attitude update period of geomag.toml (three 1 ms ticks), s.
UPDATE_S = 3e-3
#: Earth rate, rad/s.
OMEGA_IE = 7.292115e-5
#: Windows of the arc the table reports, as fractions of the flight.
ARC_WINDOWS = (0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0)


def launch_overrides(metadata: dict[str, str]) -> list[str]:
    """The ``geomag.launch_*`` overrides from a ``synth spin --trajectory ballistic`` trace's
    metadata (``launch_elevation_deg``, ``launch_azimuth_deg``); none for a trace without them."""
    if "launch_elevation_deg" not in metadata:
        return []
    out = []
    for key in ("launch_elevation_deg", "launch_azimuth_deg"):
        try:
            value = float(metadata[key])
        except (KeyError, ValueError):
            raise ConfigError(
                f"trace metadata `{key}` = {metadata.get(key)!r}: expected a number of degrees"
            ) from None
        out.append(f"geomag.{key}={value!r}")
    return out


def _axis_and_field(truth_q: np.ndarray, m_n: Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
    """The spin axis x in the navigation frame per row and the unit field's direction across it."""
    n = len(truth_q)
    axis = quaternion.rotate(truth_q, np.tile([1.0, 0.0, 0.0], (n, 1)))
    h = np.asarray(m_n, dtype=np.float64) / float(np.linalg.norm(m_n))
    across = h[None, :] - (axis @ h)[:, None] * axis
    return axis, across


def aided_roll_bound(
    t_s: np.ndarray,
    truth_q: np.ndarray,
    m_n: Sequence[float],
    spin_dps: float,
    *,
    ideal: bool,
    azimuth_deg: float = 0.0,
    kp: float = 1.0,
    ki: float = 0.25,
    gyro_delay_compensated: bool = False,
    transport_rate: float = 0.0,
) -> np.ndarray:
    """The bound (rad) the aided roll error keeps at each time ``t_s`` along an arc whose truth is
    ``truth_q``, from the loop's gains and the presets (3σ unit draws, 6σ noise); ``ideal``: the
    sensors without unit errors and noise (the ADC's quantisation kept). The loop is the PI of
    `geomag.rs` `Spin::aid`: roll error e obeys ë + K_p ė + K_i e = ḋ for a spin-axis rate error d, so
    e = h ∗ d with h(t) = (1 − at)e^(−at) for the critically damped gains (a = √K_i = K_p/2). Terms:

    (a) a rate error d growing monotonically to D (δk·ω during the spin-up, then held; b, the earth's
        rate along the axis, the ADC's half-LSB) gives e ≤ D·max(t e^(−at)) = D/(e·a);
    (b) the spin gyro's group delay (second order 100 Hz, ζ 0.7: τ_g = 2.228 ms) loses ω·τ_g of angle
        during the spin-up, a positive pulse of rate error whose answer is at most its area ω·τ_g
        (|h| ≤ 1); none with ``gyro_delay_compensated``;
    (c) magnetometer noise N√(πf_c/2) per axis over the field across the axis, |H| sin α, per update,
        through the loop's noise bandwidth (K_p + K_i/K_p)/4: 6σ; its quantisation (one code) adds
        LSB/(|H| sin α) through the same loop as a uniform error;
    (d) the spin gyro's noise through the loop: σ = N/√(8a) (∫h² = 1/(4a)), 6σ;
    (e) the magnetometer's across-axis offsets (3σ each, √2 across) turn with the body: a roll
        ripple of o√2/(|H| sin α) at the spin frequency through the loop's |T(jω)|;
    (f) a tilt ε of the propagated axis about the field's across direction turns the aid's reference
        by ε·cot α (`Spin::with_axis_gate`): ε from the cross-axis gyros' noise (6σ·N√(t/2) per
        axis, a random walk in the navigation frame), their bias turning with the spin (3σ·b/ω per
        axis), the navigation frame's own rotation the firmware leaves out (earth and transport
        rate × t), their scale error on the pitch-over Δγ(t) (3σ·δk·|Δγ|, a rotation about the
        horizontal normal of the trajectory's plane, of which only its component along the across
        direction counts) and on the nod (3σ·δk·5°). The largest ε·|cot α| so far is taken (the
        loop follows the slow reference).
    Every unit's error at time t must be within the sum. ``t_s`` are the run's update times."""
    t = np.asarray(t_s, dtype=np.float64)
    w = math.radians(spin_dps)
    a = math.sqrt(ki)
    if abs(kp - 2.0 * a) > 1e-12:
        raise ConfigError(
            f"spin-table: the bound is derived for critically damped gains (K_p = 2√K_i); got {kp}, {ki}"
        )
    axis, across = _axis_and_field(truth_q, m_n)
    field = float(np.linalg.norm(m_n))
    sin_a = np.linalg.norm(across, axis=1)
    cos_a = np.abs(axis @ (np.asarray(m_n) / field))
    three = 0.0 if ideal else 3.0
    six = 0.0 if ideal else 6.0
    d = math.radians(three * (SPIN_GYRO["scale_error"] * spin_dps + SPIN_GYRO["bias_dps"]) + SPIN_LSB_DPS)
    d += OMEGA_IE + transport_rate
    loop = d / (math.e * a)
    delay = 0.0 if gyro_delay_compensated else w * 2.0 * 0.7 / (2.0 * math.pi * 100.0)
    bandwidth = (kp + ki / kp) / 4.0
    mag_sigma = MAGNETOMETER["noise_gauss_rt_hz"] * math.sqrt(math.pi * MAGNETOMETER["cutoff_hz"] / 2.0)
    through = math.sqrt(2.0 * UPDATE_S * bandwidth)
    sin_min = np.minimum.accumulate(sin_a)
    mag = (six * mag_sigma + MAG_LSB_GAUSS) * through / (field * sin_min)
    gyro_noise = six * math.radians(SPIN_GYRO["noise_dps_rt_hz"]) / math.sqrt(8.0 * a)
    t_gain = math.hypot(kp * w, ki) / abs(complex(ki - w * w, kp * w)) if w > 0 else 1.0
    offsets = three * MAGNETOMETER["offset_gauss"] * math.sqrt(2.0) / (field * sin_min) * t_gain
    # (f): the tilt about the across direction.
    pitch = np.arcsin(np.clip(axis[:, 2], -1.0, 1.0))
    beta = math.radians(azimuth_deg)
    normal = np.array([math.cos(beta), -math.sin(beta), 0.0])  # horizontal, ⟂ the trajectory's plane
    u = across / np.maximum(sin_a, 1e-12)[:, None]
    along = np.abs(u @ normal)
    cg = CROSS_GYRO
    eps = (
        six * math.radians(cg["noise_dps_rt_hz"]) * np.sqrt(t / 2.0)
        + (three * math.radians(cg["bias_dps"]) * math.sqrt(2.0) / w if w > 0 else 0.0)
        + (OMEGA_IE + transport_rate) * t
        + three * cg["scale_error"] * (np.abs(pitch - pitch[0]) * along + math.radians(5.0))
    )
    tilt = np.maximum.accumulate(eps * cos_a / np.maximum(sin_a, 1e-12))
    return loop + delay + mag + gyro_noise + offsets + tilt


def _arc_trace(
    rate: float, duration_s: float, launch: Sequence[float], field: Sequence[float]
) -> CheckedTrace:
    speed, elevation, azimuth = launch
    intensity, inclination, declination = field
    trace = synth.generate(
        "spin",
        trajectory="ballistic",
        spin_dps=float(rate),
        spin_up_s=BOARD_SPIN_UP_S,
        duration_s=float(duration_s),
        launch_speed_mps=float(speed),
        elevation_deg=float(elevation),
        azimuth_deg=float(azimuth),
        mag_field="custom",
        mag_intensity_gauss=float(intensity),
        mag_inclination_deg=float(inclination),
        mag_declination_deg=float(declination),
    )
    return CheckedTrace(trace)


def flight_time(launch_speed_mps: float, elevation_deg: float) -> float:
    """The drag-free arc's flight 2V sin γ₀/g at the scenario's default start point, s."""
    g = float(earth.normal_gravity(math.radians(synth.DEFAULT_LATITUDE_DEG), synth.DEFAULT_HEIGHT_M))
    return 2.0 * launch_speed_mps * math.sin(math.radians(elevation_deg)) / g


def arc_table(
    rates_dps: Sequence[float] = (1000.0,),
    *,
    runs: int = 5,
    seed: int = 0,
    duration_s: float | None = None,
    launch: Sequence[float] = (500.0, 45.0, 0.0),
    field: Sequence[float] = DEFAULT_FIELD,
    compensate: bool = False,
    ideal: bool = False,
) -> dict[str, Any]:
    """The roll error along a ballistic arc on the board: per rate, per window of the flight (the
    ``ARC_WINDOWS`` fractions of it), the percentiles over the units of the largest |roll error| in
    the window, gyro-only and aided, the bound of ``aided_roll_bound`` (its largest value in the
    window), the axis's pitch and its angle to the field at the window's end, and the aided runs'
    events by kind. ``launch``: speed (m/s), elevation and azimuth (degrees); ``duration_s``: the
    flight less 0.1 s when None. ``ideal``: the sensors without unit errors and noise."""
    speed, elevation, azimuth = (float(x) for x in launch)
    flight = flight_time(speed, elevation) if speed > 0 and 0.0 < elevation < 90.0 else 0.0
    if duration_s is None:
        duration_s = math.floor((flight - 0.1) * 10.0) / 10.0
    _check(rates_dps, runs, seed, duration_s, field, "board", 0.0, "ballistic")
    m_n = field_enu(*field)
    blocks = []
    for rate in rates_dps:
        trace = _arc_trace(rate, duration_s, (speed, elevation, azimuth), field)
        launch_keys = launch_overrides(trace.trace.metadata)
        edges = [f * duration_s for f in ARC_WINDOWS]
        per_unit: list[tuple[np.ndarray, np.ndarray]] = []
        events: dict[str, int] = {}
        bound = None
        truth = None
        t = None
        for unit in range(seed, seed + runs):
            calibration = IDEAL_CALIBRATION if ideal else []
            aided, plain = _aided_and_plain(trace, unit, ideal, launch_keys, m_n, compensate, calibration)
            assert aided.truth_q is not None and plain.truth_q is not None
            if bound is None:
                t, truth = aided.time_s, aided.truth_q
                bound = aided_roll_bound(
                    t, truth, m_n, rate, ideal=ideal, azimuth_deg=azimuth, gyro_delay_compensated=compensate,
                    transport_rate=speed / 6.371e6,
                )  # fmt: skip
            per_unit.append(
                (
                    np.abs(roll_errors(plain.quat, plain.truth_q)),
                    np.abs(roll_errors(aided.quat, aided.truth_q)),
                )
            )
            for e in aided.events:
                events[e["kind"]] = events.get(e["kind"], 0) + 1
        assert t is not None and truth is not None and bound is not None
        axis, across = _axis_and_field(truth, m_n)
        unit_field = np.asarray(m_n) / float(np.linalg.norm(m_n))
        rows = []
        start = 0.0
        for end in edges:
            sel = (t > start) & (t <= end + 1e-9)
            last = int(np.nonzero(sel)[0][-1])
            rows.append(
                {
                    "t_s": [start, end],
                    "pitch_deg": math.degrees(math.asin(max(-1.0, min(1.0, float(axis[last, 2]))))),
                    "axis_field_deg": math.degrees(
                        math.atan2(float(np.linalg.norm(across[last])), float(axis[last] @ unit_field))
                    ),
                    "gyro_only_deg": _percentiles(
                        np.array([math.degrees(g[sel].max()) for g, _ in per_unit])
                    ),
                    "aided_deg": _percentiles(np.array([math.degrees(a[sel].max()) for _, a in per_unit])),
                    "bound_deg": math.degrees(float(bound[sel].max())),
                    "within": sum(bool(np.all(a[sel] <= bound[sel])) for _, a in per_unit),
                }
            )
            start = end
        blocks.append({"spin_dps": float(rate), "rows": rows, "events": events})
    return {
        "engine": "board",
        "trajectory": "ballistic",
        "chain": "geomag.toml on the board, started from the launch "
        "(geomag.launch_* from the trace's metadata)",
        "units": runs,
        "seeds": [seed, seed + runs - 1],
        "ideal_sensors": ideal,
        "duration_s": float(duration_s),
        "flight_s": flight,
        "launch": {"speed_mps": speed, "elevation_deg": elevation, "azimuth_deg": azimuth},
        "field_enu_gauss": m_n,
        "aid": {"kp_per_s": 1.0, "ki_per_s2": 0.25, "gate_gauss": 0.05},
        "compensated": compensate,
        "blocks": blocks,
    }


#: An ideal-sensor run's calibration: the presets without their nominal bow and temperature
#: coefficient (geomag.toml's table compensates them; the ideal sensors have none).
IDEAL_CALIBRATION = [
    "geomag.calibration=[{}]".format(
        ", ".join(
            "{ bias_dps = 0.0, bias_temp_dps_per_c = 0.0, ref_temp_c = 25.0, scale_error = 0.0, "
            f"nonlinearity = 0.0, full_scale_dps = {fs} }}"
            for fs in (1200.0, 300.0, 300.0)
        )
    )
]


def render_arc(table: dict[str, Any]) -> str:
    """The arc table as text."""

    def cells(p: dict[str, float]) -> str:
        return " ".join(format(p[name], "8.4f") for name, _ in PERCENTILES)

    launch = table["launch"]
    lines = [
        f"roll error along the ballistic arc: {table['chain']}",
        f"launch {launch['speed_mps']:g} m/s at elevation {launch['elevation_deg']:g}°, azimuth "
        f"{launch['azimuth_deg']:g}°; flight {table['flight_s']:.3f} s, run {table['duration_s']:g} s; "
        f"{table['units']} units (seeds {table['seeds'][0]}…{table['seeds'][1]}"
        f"{', ideal sensors' if table['ideal_sensors'] else ''}); aid K_p 1/s, K_i 0.25/s²; "
        f"group-delay compensation {'on' if table['compensated'] else 'off'}",
        "per window: largest |roll error| in it, percentiles over the units p50 p95 max; the bound "
        "(spin_table.aided_roll_bound) and the units within it",
    ]
    for block in table["blocks"]:
        lines.append(f"spin {block['spin_dps']:g} °/s")
        lines.append(
            f"{'window, s':>13} | {'pitch °':>7} | {'α °':>6} | {'gyro-only max |error|, °':>26} | "
            f"{'aided max |error|, °':>26} | {'bound °':>8} | within"
        )
        for row in block["rows"]:
            a, b = row["t_s"]
            lines.append(
                f"{a:6.1f}–{b:6.1f} | {row['pitch_deg']:7.2f} | {row['axis_field_deg']:6.2f} | "
                f"{cells(row['gyro_only_deg']):>26} | {cells(row['aided_deg']):>26} | "
                f"{row['bound_deg']:8.4f} | {row['within']}/{table['units']}"
            )
        kinds = ", ".join(f"{k} {n}" for k, n in sorted(block["events"].items())) or "none"
        lines.append(f"events of the aided runs: {kinds}")
    return "\n".join(lines)
