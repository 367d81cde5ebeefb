"""`sins-fw calibrate TRACE`: twelve-position turntable calibration of the gyro-free array.

The trace holds the twelve positions of ``sins-fw synth twelve-position`` (thesis Table 3.1 order,
its earth-rate column corrected) as twelve rests separated by moves (the ``moving`` column). The mean
of each rest gives the rate meter's (the trace's gyro columns: the array's solved rate) and the centre
accelerometers' (A₇–A₉) readings; the corrected eq. 3.7–3.12 (``gfnav::calib``) give bias, scale
factor and misalignment. With ``--part adxl345`` the rate-meter terms are reported unobservable (the
earth rate reaches the array only as products Ω² ≈ 5e-9 rad²/s², far below one LSB over 2l), not
printed as numbers.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

import numpy as np

from sins_fw import _core, earth
from sins_fw.cli.common import add_json_option, emit, exit_epilog
from sins_fw.errors import ConfigError, TraceError
from sins_fw.traces import PhysicalTrace

#: ADXL345 full-resolution LSB, g (adxl345.md: 3.9 mg typical, 256 LSB/g).
ADXL345_LSB_G = 1.0 / 256.0
PARTS = ("ideal", "adxl345")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "calibrate",
        help="twelve-position turntable calibration (bias, scale factor, misalignment)",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=exit_epilog(None),
    )
    p.add_argument(
        "trace",
        type=Path,
        help="a twelve-position trace (.csv or .h5), e.g. from `sins-fw synth twelve-position`",
    )
    p.add_argument(
        "--part",
        choices=PARTS,
        default="ideal",
        help="the array's accelerometer: ideal (every term computed) or adxl345 "
        "(rate-meter terms unobservable)",
    )
    p.add_argument("--lever-m", type=float, default=0.1, help="array lever arm l, m (default 0.1)")
    p.add_argument(
        "--printed-bias-sets",
        action="store_true",
        help="the thesis's printed bias index sets (a_z0 off by g/8; plain means pick up θ·g/3)",
    )
    add_json_option(p)
    p.set_defaults(func=run)


def rest_means(trace: PhysicalTrace, where: str) -> tuple[np.ndarray, np.ndarray]:
    """The mean rate (rad/s) and specific force (m/s²) over each of the twelve rests."""
    if trace.moving is None:
        raise TraceError(f"{where}: no `moving` column; the twelve rests cannot be found")
    rest = ~np.asarray(trace.moving, dtype=bool)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], rest.astype(np.int8), [0]])))
    spans = list(zip(edges[0::2], edges[1::2], strict=True))
    if len(spans) != 12:
        raise TraceError(f"{where}: {len(spans)} rests (runs of moving = 0); expected the twelve positions")
    rate = np.array([np.radians(trace.gyro_dps[a:b].mean(axis=0)) for a, b in spans])
    force = np.array([trace.accel_g[a:b].mean(axis=0) * earth.G0 for a, b in spans])
    return rate, force


def calibrate(
    trace: PhysicalTrace, where: str, *, part: str = "ideal", lever_m: float = 0.1, printed: bool = False
) -> dict[str, Any]:
    """The calibration report of a twelve-position trace."""
    if part not in PARTS:
        raise ConfigError(f"--part {part!r}: expected one of {', '.join(PARTS)}")
    if not (math.isfinite(lever_m) and lever_m > 0):
        raise ConfigError(f"--lever-m {lever_m}: expected a positive length in metres")
    try:
        lat_deg = float(trace.metadata["latitude_deg"])
        height = float(trace.metadata.get("height_m", "0"))
    except (KeyError, ValueError):
        raise TraceError(f"{where}: metadata `latitude_deg` missing or not a number") from None
    lat = math.radians(lat_deg)
    g = float(earth.normal_gravity(lat, height))
    rate, force = rest_means(trace, where)
    cal = _core.gfnav_calibrate(rate.tolist(), force.tolist(), lat, g, printed)
    w2, res, orders = _core.gfnav_earth_rate_observability(ADXL345_LSB_G * earth.G0, lever_m)
    observable = part == "ideal"
    return {
        "trace": where,
        "latitude_deg": lat_deg,
        "gravity_m_s2": g,
        "bias_sets": "printed" if printed else "corrected",
        "accel": cal["accel"],
        "rate": cal["rate"] if observable else None,
        "earth_rate": {
            "omega_squared_rad2_s2": w2,
            "product_resolution_rad2_s2": res,
            "orders_below_resolution": orders,
            "lever_m": lever_m,
            "observable": observable,
        },
    }


def _triad_text(name: str, t: dict[str, Any], bias_unit: str, bias_scale: float) -> list[str]:
    m = t["misalignment"]
    return [
        f"{name}: bias " + ", ".join(f"{b * bias_scale:+.6g}" for b in t["bias"]) + f" {bias_unit}",
        "  scale factor error " + ", ".join(f"{k * 1e6:+.3f}" for k in t["scale"]) + " ppm",
        "  misalignment (mrad) " + ", ".join(f"θ{k} {v * 1e3:+.4f}" for k, v in m.items()),
    ]


def run(args: argparse.Namespace) -> int:
    trace = PhysicalTrace.load(args.trace)
    report = calibrate(
        trace, str(args.trace), part=args.part, lever_m=args.lever_m, printed=args.printed_bias_sets
    )
    e = report["earth_rate"]
    lines = [
        f"twelve-position calibration of {args.trace} "
        f"(latitude {report['latitude_deg']}°, {report['bias_sets']} bias sets)"
    ]
    lines += _triad_text("accelerometers (A7-A9)", report["accel"], "mg", 1e3 / earth.G0)
    if report["rate"] is not None:
        lines += _triad_text("rate meter (ideal array)", report["rate"], "°/s", math.degrees(1.0))
    else:
        lines.append(
            f"rate meter: unobservable with the ADXL345 at l = {e['lever_m']} m: the earth rate reaches "
            f"the array as Ω² = {e['omega_squared_rad2_s2']:.3g} rad²/s², one LSB over 2l is "
            f"{e['product_resolution_rad2_s2']:.3g} rad²/s² ({e['orders_below_resolution']:.1f} orders "
            "above); no number is given"
        )
    emit(args, report, "\n".join(lines))
    return 0
