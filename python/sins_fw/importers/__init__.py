"""Importers for the logs users have (docs/traces.md, 'Importing logs'): PX4 ULog, ArduPilot
DataFlash, ROS 1/2 bags and EuRoC-style CSV, each into a physical trace.

Each keeps the sensor's own time stamps (shifted so that the log's first IMU sample is t = 0, the
origin in the metadata), converts units to the trace's (°/s, g, gauss) and frames to its convention
(body axes with z up when level, navigation frame ENU) and says what it did in the metadata
(``frame``, ``truth``, ``time_origin``). Magnetometer samples are interpolated linearly onto the IMU
times; an attitude found in the log becomes the truth (interpolated, normalised; NaN outside its
span). GPS fixes found in the log become the trace's GPS stream (:func:`gps_stream`).

The libraries (pyulog, pymavlink, rosbags) are the optional extra ``sins-fw[import]``; without them
the command says which package to install.
"""

from __future__ import annotations

import importlib
import math
import os
from collections.abc import Callable
from fractions import Fraction
from pathlib import Path
from types import ModuleType
from typing import Any, NamedTuple, cast

import numpy as np
from numpy.typing import NDArray

from sins_fw import quaternion
from sins_fw.errors import InputError, TraceError
from sins_fw.tablefile import rate_of_step, rate_text
from sins_fw.traces import G0, GPS_COLUMNS, PhysicalTrace

Array = NDArray[np.float64]
PathLike = str | os.PathLike[str]

#: FRD (x forward, y right, z down) → FLU (x forward, y left, z up): a half turn about x.
FLU_FROM_FRD = np.array([1.0, -1.0, -1.0])
#: The half turn about x as a quaternion (C_FLU^FRD = C_FRD^FLU).
Q_FRD_FLU = np.array([0.0, 1.0, 0.0, 0.0])
#: C_NED^ENU: a half turn about (1, 1, 0)/√2 (x_E = y_N, y_N = x_E, z_U = −z_D).
Q_ENU_NED = np.array([0.0, 1.0, 1.0, 0.0]) / np.sqrt(2.0)
FRAME_FRD_NED = (
    "body axes FLU (x forward, y left, z up) from the log's FRD: (x, −y, −z) for rates, specific "
    "force and field; truth C_b^n with n = ENU from the log's FRD→NED attitude q: q_ENU,FLU = "
    "q_ENU,NED ⊗ q ⊗ q_FRD,FLU (q_ENU,NED = [0, 1, 1, 0]/√2, q_FRD,FLU = [0, 1, 0, 0])"
)
GAUSS_PER_TESLA = 1e4
#: Truth samples further apart than this many of their own median steps are a gap: NaN truth there.
TRUTH_GAP_STEPS = 2.0


def need(module: str, package: str, kind: str) -> ModuleType:
    """Import an optional library, or an InputError (exit 2) saying which package to install."""
    try:
        return importlib.import_module(module)
    except ImportError:
        raise InputError(
            f"`sins-fw import {kind}` needs the `{package}` package, which is not installed: "
            f"pip install 'sins-fw[import]' (or pip install {package})"
        ) from None


def printable(text: str) -> str:
    """Text for the trace's metadata (UTF-8): a file name's bytes that are not UTF-8 (which Python holds
    as lone surrogates) written as ``\\xNN`` escapes."""
    try:
        return text.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")
    except UnicodeEncodeError:  # a surrogate no file name holds
        return text.encode("utf-8", "backslashreplace").decode("utf-8")


def check_file(path: PathLike, what: str) -> Path:
    p = Path(path)
    if not p.exists():
        raise TraceError(f"{p}: no such {what}")
    return p


#: Time stamps are integer ticks within ±2^62 (146 years in ns): differences between any two, and a
#: stamp shifted by a GPS latency, then stay exact in int64. A log's stamps beyond are damaged.
MAX_STAMP = 2**62


def stamp_array(values: Any, where: PathLike, unit: str) -> NDArray[np.int64]:
    """Integer time stamps (ints, numpy integers or their text) as int64, each within ±:data:`MAX_STAMP`
    ticks; else a TraceError naming the stamp and what was expected."""
    expected = f"expected integer time stamps in {unit} within ±2^62"
    try:
        array = np.asarray(values)
        if array.dtype.kind in "iu":
            if len(array) and (int(array.max()) > MAX_STAMP or int(array.min()) < -MAX_STAMP):
                bad = array[np.argmax((array > MAX_STAMP) | (array < -MAX_STAMP))]
                raise TraceError(f"{where}: time stamp {int(bad)} out of range; {expected}")
            return array.astype(np.int64)
        stamps = [int(v) for v in array.tolist()]
    except (ValueError, TypeError, OverflowError):
        bad = next((v for v in np.asarray(values).tolist() if not _is_int(v)), None)
        raise TraceError(f"{where}: time stamp `{bad}` is not an integer; {expected}") from None
    bad = next((v for v in stamps if not -MAX_STAMP <= v <= MAX_STAMP), None)
    if bad is not None:
        raise TraceError(f"{where}: time stamp {bad} out of range; {expected}")
    return np.array(stamps, dtype=np.int64)


def _is_int(v: Any) -> bool:
    try:
        int(v)
    except (ValueError, TypeError, OverflowError):
        return False
    return True


def truth_from_ned(q_ned_frd: Array) -> Array:
    """An FRD→NED attitude (Hamilton [w, x, y, z]) as the trace's C_b^n: FLU body, ENU navigation."""
    return quaternion.multiply(quaternion.multiply(Q_ENU_NED, q_ned_frd), Q_FRD_FLU)


def interpolate_truth(t: Array, t_q: Array, q: Array) -> Array:
    """Unit quaternions ``q`` (at times ``t_q``) at the times ``t``: normalised linear interpolation
    between the neighbours (signs aligned: q and −q are one attitude); NaN before the first, after
    the last, and inside gaps longer than :data:`TRUTH_GAP_STEPS` median steps."""
    out = np.full((len(t), 4), np.nan)
    if len(t_q) < 2:
        return out
    q = quaternion.normalize(np.asarray(q, dtype=np.float64))
    q = q.copy()
    for k in range(1, len(q)):  # one hemisphere, so that neighbours interpolate the short way
        if np.dot(q[k], q[k - 1]) < 0:
            q[k] = -q[k]
    i = np.searchsorted(t_q, t, side="right") - 1
    inside = (i >= 0) & (i < len(t_q) - 1)
    exact_end = t == t_q[-1]
    i = np.clip(i, 0, len(t_q) - 2)
    step = np.diff(t_q)
    gap = step[i] > TRUTH_GAP_STEPS * float(np.median(step))
    ok = (inside & ~gap) | exact_end
    u = ((t - t_q[i]) / step[i])[:, None]
    blend = quaternion.normalize((1 - u) * q[i] + u * q[i + 1])
    out[ok] = blend[ok]
    return out


def interpolate(t: Array, t_src: Array, values: Array) -> Array:
    """``values`` (n, k) at the times ``t``: linear interpolation, the first and last value held
    beyond the ends (the trace's columns other than truth take no NaN)."""
    return np.stack([np.interp(t, t_src, values[:, j]) for j in range(values.shape[1])], axis=1)


def rate_from_times(t: Array, where: str) -> Fraction:
    dt = np.diff(t)
    dt = dt[dt > 0]
    if not len(dt):
        raise TraceError(f"{where}: fewer than two IMU samples with increasing times; expected a log")
    return rate_of_step(float(np.median(dt)))


def ascending(t: Array, *arrays: Array) -> tuple[Array, ...]:
    """Samples in time order, a repeated time stamp kept once (the first): logs can repeat one when
    a topic is written twice."""
    order = np.argsort(t, kind="stable")
    t = t[order]
    keep = np.concatenate([[True], np.diff(t) > 0]) if len(t) else np.zeros(0, dtype=bool)
    return (t[keep], *(a[order][keep] for a in arrays))


def make_trace(
    *,
    t_abs: Array,
    origin: str,
    gyro_dps: Array,
    accel_g: Array,
    mag_gauss: Array | None,
    truth_q: Array | None,
    metadata: dict[str, str],
    where: str,
    gps: GpsStream | str | None = None,
) -> PhysicalTrace:
    """The physical trace of an import: times from the log's first IMU sample, the rate from the
    times, the provenance and conversions in the metadata."""
    t = t_abs - t_abs[0]
    meta = {
        "sample_rate_hz": rate_text(rate_from_times(t, where)),
        **metadata,
        "time_origin": origin,
        "g0_m_s2": repr(G0),
    }
    if gps is None or isinstance(gps, str):
        meta["gps"] = gps or "none"
    else:
        meta.update(gps.metadata)
    meta = {k: printable(v) for k, v in meta.items()}
    return PhysicalTrace(
        t_s=t,
        gyro_dps=gyro_dps,
        accel_g=accel_g,
        mag_gauss=mag_gauss,
        truth_q=truth_q,
        metadata=meta,
        gps=None if gps is None or isinstance(gps, str) else gps.columns,
    )


def seconds_since(t_us: Array, t0_us: int) -> NDArray[np.float64]:
    """Microsecond time stamps as seconds since ``t0_us``."""
    return (t_us - t0_us).astype(np.float64) * 1e-6


def frd_ned_trace(
    *,
    kind: str,
    source: str,
    path: Path,
    t_abs: Array,
    origin: str,
    gyro_rad_s: Array,
    accel_m_s2: Array,
    mag_gauss: Array | None,
    truth_q_ned: Array | None,
    gps: GpsStream | str | None,
    units: str,
    magnetometer: str,
    truth: str,
    where: str,
) -> PhysicalTrace:
    """The physical trace of an autopilot's log (`sins-fw import KIND`) in its FRD body and NED earth
    frames (:data:`FRAME_FRD_NED`): rates (rad/s), specific force (m/s²) and field (gauss) turned to
    FLU °/s, g and gauss, the FRD→NED attitude ``truth_q_ned`` to the trace's C_b^n."""
    return make_trace(
        t_abs=t_abs,
        origin=origin,
        gyro_dps=np.degrees(gyro_rad_s) * FLU_FROM_FRD,
        accel_g=accel_m_s2 / G0 * FLU_FROM_FRD,
        mag_gauss=None if mag_gauss is None else mag_gauss * FLU_FROM_FRD,
        truth_q=None if truth_q_ned is None else truth_from_ned(truth_q_ned),
        gps=gps,
        metadata={
            "source": f"{source} {path.name}",
            "source_file": path.name,
            "generator": f"sins-fw import {kind} {path.name}",
            "frame": FRAME_FRD_NED,
            "units": units,
            "magnetometer": magnetometer,
            "truth": truth,
        },
        where=where,
    )


#: The GPS latency an import writes unless told (`--gps-latency-s`): the log's stamp of a fix is taken
#: as its time of validity.
DEFAULT_GPS_LATENCY_S = 0.0


def check_gps_latency(latency_s: object, option: str = "--gps-latency-s") -> float:
    """The GPS latency as a float in 0…10 s, else an InputError naming ``option`` (a NaN included)."""
    try:
        value = float(latency_s)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        value = math.nan
    if isinstance(latency_s, bool) or not 0.0 <= value <= 10.0:
        raise InputError(f"{option} {latency_s!r}: expected the GPS receiver's latency in 0…10 s")
    return value


class GpsStream(NamedTuple):
    """The GPS columns of an import (n, 5; NaN on rows without a fix) and their metadata keys."""

    columns: Array
    metadata: dict[str, str]


def gps_stream(
    t_imu: NDArray[np.int64],
    t_fix: NDArray[np.int64],
    fixes: Array,
    *,
    ticks_per_s: int,
    latency_s: float,
    source: str,
) -> GpsStream | str:
    """Fixes (n, 5: speed m/s, course ° clockwise from north, latitude °, longitude °, height m) logged
    at the integer stamps ``t_fix`` as the GPS columns of the rows at the IMU stamps ``t_imu`` (same
    clock, ``ticks_per_s`` ticks a second). A logged stamp is the time the fix reached the autopilot;
    its time of validity is ``latency_s`` earlier (rounded to a tick), and the fix goes on the first
    row at or after that time (as synth places its fixes; two on one row: the later kept). Fixes
    before the first or after the last row, or with a non-finite value, are left out and counted.
    Returns a text saying why there is no GPS stream when no fix is left."""
    check_gps_latency(latency_s)
    fixes = np.array(fixes, dtype=np.float64).reshape(-1, len(GPS_COLUMNS))
    fixes[:, 1] = np.mod(fixes[:, 1], 360.0)
    fixes[fixes[:, 1] >= 360.0, 1] = 0.0  # a tiny negative course rounds to 360
    valid = t_fix - round(latency_s * ticks_per_s)
    row = np.searchsorted(t_imu, valid, side="left")
    keep = np.isfinite(fixes).all(axis=1) & (valid >= t_imu[0]) & (row < len(t_imu))
    left_out = int((~keep).sum())
    order = np.argsort(valid[keep], kind="stable")
    rows, values = row[keep][order], fixes[keep][order]
    if not len(rows):
        return f"none: {source} holds no fix inside the IMU's span"
    cols = np.full((len(t_imu), len(GPS_COLUMNS)), np.nan)
    cols[rows] = values  # numpy assigns in order: on a row taking two fixes the later stays
    shared = len(rows) - len(np.unique(rows))
    step = np.diff(np.unique(valid[keep]))
    meta = {
        "gps": f"{source}; {len(rows) - shared} fixes, each on the first row at or after its time of "
        f"validity (the log's stamp minus gps_latency_s); {left_out} left out (outside the IMU's span or "
        f"not finite), {shared} replaced by a later fix on the same row",
        "gps_latency_s": repr(float(latency_s)),
    }
    if len(step):
        meta["gps_rate_hz"] = rate_text(rate_of_step(float(np.median(step)) / ticks_per_s))
    return GpsStream(cols, meta)


Importer = Callable[..., PhysicalTrace]
#: `sins-fw import KIND`: the module and function of each importer (imported when used).
IMPORTERS = {
    "ulog": ("ulog", "import_ulog"),
    "dataflash": ("dataflash", "import_dataflash"),
    "rosbag": ("rosbag", "import_rosbag"),
    "euroc": ("euroc", "import_euroc"),
}


def importer(kind: str) -> Importer:
    """The importer `sins-fw import KIND` runs."""
    module, function = IMPORTERS[kind]
    imported: Any = importlib.import_module(f"sins_fw.importers.{module}")
    run = cast(Importer, getattr(imported, function))

    def checked(path: PathLike, **options: Any) -> PhysicalTrace:
        # The options are checked before the log is read (a long read must not end in a refusal of
        # what was known at the start).
        if "gps_latency_s" in options:
            options["gps_latency_s"] = check_gps_latency(options["gps_latency_s"], "gps_latency_s")
        return run(path, **options)

    return checked
