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
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from sins_fw import _core, quaternion, synth
from sins_fw.errors import ConfigError
from sins_fw.harness import emulate
from sins_fw.profile import load_profile
from sins_fw.traces import CheckedTrace

#: The issue's rates, °/s.
DEFAULT_RATES_DPS = (50.0, 100.0, 200.0, 500.0, 1000.0)
#: The earth's field at Beijing [unconfirmed: rounded IGRF 2014]: intensity (gauss), inclination
#: and declination (degrees).
DEFAULT_FIELD = (0.54, 58.5, -6.5)
PERCENTILES = (("p50", 50.0), ("p95", 95.0), ("max", 100.0))
ENGINES = ("board", "chain")
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
) -> None:
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
    if engine == "board" and pitch_deg != 0.0:
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


def _board_unit(
    trace: CheckedTrace, rate: float, unit: int, yaw_deg: float, m_n: list[float], compensate: bool
) -> tuple[float, float, float, int]:
    profile = load_profile(
        BOARD_PROFILE,
        [
            f"errors.seed={unit}",
            "geomag.ideal_sensors=false",
            f"firmware.initial_yaw_deg={float(yaw_deg)!r}",
            "geomag.field_enu_gauss=[{}]".format(", ".join(repr(float(x)) for x in m_n)),
            f"geomag.mag_cutoff_hz={MAG_CUTOFF_HZ if compensate else 0.0!r}",
            *([f"geomag.gyro_delay_s={GYRO_DELAY_S!r}"] if compensate else []),
        ],
    )
    aided = emulate(trace, profile)
    plain = emulate(trace, profile, overrides=["geomag.aid_kp=0", "geomag.aid_ki=0"])
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
