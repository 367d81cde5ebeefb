"""The spin-rate table of the geomagnetic–gyro board (issue 21): spin rate → roll error without and
with the magnetometer roll aid, as percentiles over a Monte Carlo of sensor units.

Each unit (seed s) is the analogue chain's presets drawn once (SPIN1200 spin gyro on x, ADXRS300 on
y and z, the AMR magnetometer: bias, scale-factor error, offsets, noise), read through the
ADS8344's 16 bits at VREF 5 V, compensated with the nominal calibration and run through
``firmware/geomag.rs`` (three-sample rotation vector; the aid's PI loop, K_p = 1/s, K_i = 0.25/s²)
on a turntable spinning at a constant rate, by ``_core.geomag_spin_chain``: the sensor chain and the
firmware without the bus (no SPI timing; every channel of an instant read at that instant). The
same units run at every rate. Per unit and rate: the gyro-only roll error at the end (and relative
to the spin angle) and the aided run's largest |roll error|.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from sins_fw import _core
from sins_fw.errors import ConfigError

#: The issue's rates, °/s.
DEFAULT_RATES_DPS = (50.0, 100.0, 200.0, 500.0, 1000.0)
#: The earth's field at Beijing [unconfirmed: rounded IGRF 2014]: intensity (gauss), inclination
#: and declination (degrees).
DEFAULT_FIELD = (0.54, 58.5, -6.5)
PERCENTILES = (("p50", 50.0), ("p95", 95.0), ("max", 100.0))


def field_enu(intensity_gauss: float, inclination_deg: float, declination_deg: float) -> list[float]:
    """F·[cos I sin D, cos I cos D, −sin I] (east, north, up), I positive down."""
    i, d = math.radians(inclination_deg), math.radians(declination_deg)
    return [
        intensity_gauss * math.cos(i) * math.sin(d),
        intensity_gauss * math.cos(i) * math.cos(d),
        -intensity_gauss * math.sin(i),
    ]


def _check(
    rates_dps: Sequence[float], runs: int, seed: int, duration_s: float, field: Sequence[float]
) -> None:
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


def _percentiles(x: np.ndarray) -> dict[str, float]:
    return {name: float(np.percentile(x, q)) for name, q in PERCENTILES}


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
) -> dict[str, Any]:
    """The table as a dict: the settings and, per rate, the percentiles (p50, p95, max) over ``runs``
    units (seeds ``seed`` … ``seed + runs − 1``) of the gyro-only roll error at the end (degrees and
    percent of the spin angle) and of the aided run's largest |roll error| (degrees). ``compensate``:
    the firmware's group-delay options on (the spin gyro's τ_g = 2ζ/ω_n, the magnetometer's 1 kHz)."""
    _check(rates_dps, runs, seed, duration_s, field)
    m_n = field_enu(*field)
    tau_g = 2.0 * 0.7 / (2.0 * math.pi * 100.0)  # SPIN1200: second order, 100 Hz, ζ 0.7
    rows = []
    for rate in rates_dps:
        gyro_only, relative, aided = [], [], []
        for unit in range(seed, seed + runs):
            r = _core.geomag_spin_chain(
                spin_dps=float(rate),
                seconds=float(duration_s),
                seed=unit,
                field_enu_gauss=m_n,
                yaw_deg=float(yaw_deg),
                pitch_deg=float(pitch_deg),
                mag_cutoff_hz=1000.0 if compensate else None,
                gyro_delay_s=tau_g if compensate else None,
            )
            end = abs(float(r["roll_gyro"][-1]))
            gyro_only.append(math.degrees(end))
            relative.append(100.0 * end / (math.radians(rate) * float(r["t_s"][-1])))
            aided.append(math.degrees(float(np.abs(r["roll_aided"]).max())))
        rows.append(
            {
                "spin_dps": float(rate),
                "gyro_only_deg": _percentiles(np.array(gyro_only)),
                "gyro_only_percent": _percentiles(np.array(relative)),
                "aided_max_deg": _percentiles(np.array(aided)),
            }
        )
    return {
        "chain": "SPIN1200 (x), ADXRS300 (y, z), AMR magnetometer, ADS8344 16 bits at VREF 5 V; "
        "sensor chain and firmware/geomag.rs without the bus",
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
        f"{'aided max |roll error|, °':>26}",
    ]
    for row in table["rows"]:
        lines.append(
            f"{row['spin_dps']:9g} | {cells(row['gyro_only_deg'], '11.4f'):>36} | "
            f"{cells(row['gyro_only_percent'], '8.4f'):>26} | {cells(row['aided_max_deg'], '8.4f'):>26}"
        )
    return "\n".join(lines)
