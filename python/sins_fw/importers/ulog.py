"""PX4 ULog (read with pyulog): ``sensor_combined`` (gyro_rad, rad/s; accelerometer_m_s2, m/s²; FRD
body axes; time stamps in µs), the magnetometer from ``vehicle_magnetometer`` (magnetometer_ga) or
``sensor_mag`` (x, y, z), gauss, FRD; the attitude from ``vehicle_attitude_groundtruth`` (a
simulation's truth) or ``vehicle_attitude`` (the autopilot's estimate), q = FRD → NED, [w, x, y, z].
GPS from ``vehicle_gps_position`` or else ``sensor_gps`` (instance 0; 3D fixes, fix_type ≥ 3):
vel_m_s, cog_rad, and lat/lon (1e-7° integers) with alt_ellipsoid/alt (mm) or, in newer PX4,
latitude_deg/longitude_deg with altitude_ellipsoid_m/altitude_msl_m; at the message's timestamp.
Both IMU vectors take sensor_combined's ``timestamp`` (the gyro's sample time; the accelerometer's
``accelerometer_timestamp_relative``, normally 0, is not applied)."""

from __future__ import annotations

from typing import Any

import numpy as np

from sins_fw.errors import TraceError
from sins_fw.importers import (
    DEFAULT_GPS_LATENCY_S,
    PathLike,
    ascending,
    check_file,
    frd_ned_trace,
    gps_stream,
    interpolate,
    interpolate_truth,
    need,
    seconds_since,
    stamp_array,
)
from sins_fw.traces import PhysicalTrace

_TOPICS = (
    "sensor_combined",
    "vehicle_magnetometer",
    "sensor_mag",
    "vehicle_attitude_groundtruth",
    "vehicle_attitude",
    "vehicle_gps_position",
    "sensor_gps",
)
_MAGS = (("vehicle_magnetometer", "magnetometer_ga[{}]"), ("sensor_mag", "{}"))
_ATTITUDES = (
    ("vehicle_attitude_groundtruth", "the simulation's true attitude"),
    ("vehicle_attitude", "the autopilot's estimate (EKF), not an independent truth"),
)


def _vectors(data: dict[str, Any], pattern: str, axes: tuple[str, ...], where: str) -> np.ndarray:
    names = [pattern.format(a) for a in axes]
    missing = [n for n in names if n not in data]
    if missing:
        raise TraceError(f"{where}: field `{missing[0]}` is missing; expected {', '.join(names)}")
    return np.stack([np.asarray(data[n], dtype=np.float64) for n in names], axis=1)


#: (latitude, longitude, ellipsoid height, MSL altitude): the field names and their scale to °, ° and m.
_GPS_POSITIONS = (
    (("latitude_deg", 1.0), ("longitude_deg", 1.0), ("altitude_ellipsoid_m", 1.0), ("altitude_msl_m", 1.0)),
    (("lat", 1e-7), ("lon", 1e-7), ("alt_ellipsoid", 1e-3), ("alt", 1e-3)),
)


def _gps(topics: dict[tuple[str, int], dict[str, Any]], t_us: np.ndarray, latency_s: float, p: Any) -> Any:
    """The GPS stream of the log (see :func:`sins_fw.importers.gps_stream`) or why there is none."""
    for topic in ("vehicle_gps_position", "sensor_gps"):
        data = topics.get((topic, 0))
        if data is None:
            continue
        lat, lon, ell, msl = next((f for f in _GPS_POSITIONS if f[0][0] in data), _GPS_POSITIONS[1])
        height, note = (ell, "ellipsoid height") if ell[0] in data else (msl, "MSL altitude as the height")
        names = ["vel_m_s", "cog_rad", lat[0], lon[0], height[0]]
        v = _vectors(data, "{}", tuple(names), f"{p}: {topic}")
        v *= [1.0, np.degrees(1.0), lat[1], lon[1], height[1]]
        fix = np.asarray(data.get("fix_type", np.full(len(v), 3)))
        t_fix = stamp_array(data["timestamp"], f"{p}: {topic}.timestamp", "µs")
        source = (
            f"{topic} ({', '.join(names)}; {note}; {int((fix < 3).sum())} messages without a 3D fix left out)"
        )
        return gps_stream(
            t_us, t_fix[fix >= 3], v[fix >= 3], ticks_per_s=1_000_000, latency_s=latency_s, source=source
        )
    return "none (no vehicle_gps_position or sensor_gps topic)"


def import_ulog(path: PathLike, gps_latency_s: float = DEFAULT_GPS_LATENCY_S) -> PhysicalTrace:
    """A PX4 ULog file as a physical trace (instance 0 of each topic)."""
    pyulog = need("pyulog", "pyulog", "ulog")
    p = check_file(path, "ULog file")
    try:
        log = pyulog.ULog(str(p), list(_TOPICS))
    except Exception as e:  # pyulog raises its own and struct errors on a file that is not ULog
        raise TraceError(f"{p}: not a readable ULog file ({e}); expected a PX4 .ulg log") from None
    topics = {(d.name, d.multi_id): d.data for d in log.data_list}
    imu = topics.get(("sensor_combined", 0))
    if imu is None:
        found = ", ".join(sorted({n for n, _ in topics})) or "none of the topics read"
        raise TraceError(f"{p}: no `sensor_combined` topic; expected a PX4 log with IMU data (found {found})")
    where = f"{p}: sensor_combined"
    t_us = stamp_array(imu["timestamp"], f"{where}.timestamp", "µs")
    gyro = _vectors(imu, "gyro_rad[{}]", ("0", "1", "2"), where)
    accel = _vectors(imu, "accelerometer_m_s2[{}]", ("0", "1", "2"), where)
    t_us, gyro, accel = ascending(t_us, gyro, accel)
    t0 = int(t_us[0])
    t = seconds_since(t_us, t0)
    mag, mag_note = None, "none (no vehicle_magnetometer or sensor_mag topic)"
    for topic, pattern in _MAGS:
        data = topics.get((topic, 0))
        if data is not None:
            tm = seconds_since(stamp_array(data["timestamp"], f"{p}: {topic}.timestamp", "µs"), t0)
            axes = ("0", "1", "2") if "[" in pattern else ("x", "y", "z")
            tm, m = ascending(tm, _vectors(data, pattern, axes, f"{p}: {topic}"))
            mag = interpolate(t, tm, m)
            mag_note = f"{topic} (gauss), interpolated linearly at the IMU times"
            break
    truth, truth_note = None, "none (no vehicle_attitude topic)"
    for topic, what in _ATTITUDES:
        data = topics.get((topic, 0))
        if data is not None:
            tq = seconds_since(stamp_array(data["timestamp"], f"{p}: {topic}.timestamp", "µs"), t0)
            tq, q = ascending(tq, _vectors(data, "q[{}]", ("0", "1", "2", "3"), f"{p}: {topic}"))
            truth = interpolate_truth(t, tq, q)
            truth_note = f"{topic}.q: {what}; interpolated (normalised linear) at the IMU times, NaN outside"
            break
    return frd_ned_trace(
        kind="ulog",
        source="PX4 ULog",
        path=p,
        t_abs=t,
        origin=f"t_s = 0 at the log's sensor_combined time stamp {t0} µs",
        gyro_rad_s=gyro,
        accel_m_s2=accel,
        mag_gauss=mag,
        truth_q_ned=truth,
        gps=_gps(topics, t_us, gps_latency_s, p),
        units="gyro_rad rad/s → °/s, accelerometer_m_s2 m/s² → g, magnetometer gauss",
        magnetometer=mag_note,
        truth=truth_note,
        where=where,
    )
