"""ROS 1 and ROS 2 bags (read with rosbags): ``sensor_msgs/Imu`` (angular_velocity rad/s,
linear_acceleration m/s², orientation [x, y, z, w] unless its covariance is marked −1) and, when
present, ``sensor_msgs/MagneticField`` (tesla) and GPS: ``sensor_msgs/NavSatFix`` (latitude, longitude,
altitude above the WGS-84 ellipsoid; fixes with status ≥ 0) with the ground velocity of a
``geometry_msgs/TwistStamped`` topic (ENU, as a fix-velocity topic gives it: speed = hypot(x, y),
course = atan2(x_east, y_north) clockwise from north; interpolated linearly at the fix's stamp, fixes
outside its span left out). REP 103 puts the body axes FLU and the world ENU, the
trace's convention: nothing is rotated. Times are the messages' header stamps (the sensor's own)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from sins_fw import quaternion
from sins_fw.errors import TraceError
from sins_fw.importers import (
    DEFAULT_GPS_LATENCY_S,
    GAUSS_PER_TESLA,
    PathLike,
    ascending,
    check_file,
    gps_stream,
    interpolate,
    make_trace,
    need,
)
from sins_fw.traces import G0, PhysicalTrace

IMU = "sensor_msgs/msg/Imu"
MAG = "sensor_msgs/msg/MagneticField"
FIX = "sensor_msgs/msg/NavSatFix"
VEL = "geometry_msgs/msg/TwistStamped"
FRAME = (
    "body axes FLU and world ENU (REP 103), the trace's convention: rates, specific force and field "
    "copied axis for axis; orientation [x, y, z, w] reordered to [w, x, y, z]"
)


def _pick(connections: list[Any], msgtype: str, topic: str | None, p: Path, option: str) -> Any | None:
    """The connection of ``topic``, or the bag's only one of ``msgtype`` (None when it has none)."""
    found = [c for c in connections if c.msgtype == msgtype]
    topics = sorted({c.topic for c in found})
    if topic is not None:
        chosen = [c for c in found if c.topic == topic]
        if not chosen:
            raise TraceError(
                f"{p}: no {msgtype} topic `{topic}`; the bag's are: {', '.join(topics) or 'none'}"
            )
        return chosen[0]
    if len(topics) > 1:
        raise TraceError(
            f"{p}: {len(topics)} {msgtype} topics ({', '.join(topics)}); choose one with {option}"
        )
    return found[0] if found else None


def _stamp_ns(msg: Any) -> int:
    return int(msg.header.stamp.sec) * 1_000_000_000 + int(msg.header.stamp.nanosec)


def _gps(
    fixes: list[tuple[int, tuple[float, ...]]],
    vels: list[tuple[int, tuple[float, float]]],
    names: tuple[str | None, str | None],
    t_ns: np.ndarray,
    latency_s: float,
) -> Any:
    """The GPS stream (:func:`sins_fw.importers.gps_stream`) of NavSatFix positions and the ground
    velocity interpolated at their stamps, or why there is none."""
    fix_topic, vel_topic = names
    if fix_topic is None or vel_topic is None:
        what = (
            f"{fix_topic} gives position only: no {VEL} fix-velocity topic"
            if vel_topic is None and fix_topic is not None
            else f"no {FIX} topic"
            + (f" ({vel_topic} gives velocity only)" if vel_topic else f" and no {VEL}")
        )
        return f"none: {what} (speed and course need both; see --gps-topic, --gps-velocity-topic)"
    if not fixes or len(vels) < 2:
        return f"none: {fix_topic} has {len(fixes)} fixes, {vel_topic} {len(vels)} velocities (need 2)"
    tf, pos = ascending(np.array([s for s, _ in fixes], dtype=np.int64), np.array([v for _, v in fixes]))
    tv, vel = ascending(np.array([s for s, _ in vels], dtype=np.int64), np.array([v for _, v in vels]))
    inside = (tf >= tv[0]) & (tf <= tv[-1])
    v = interpolate((tf - tv[0]).astype(np.float64), (tv - tv[0]).astype(np.float64), vel)
    columns = np.column_stack([np.hypot(v[:, 0], v[:, 1]), np.degrees(np.arctan2(v[:, 0], v[:, 1])), pos])
    source = (
        f"{fix_topic} (latitude, longitude, altitude above the ellipsoid) with {vel_topic} "
        f"(ENU twist.linear x east, y north, interpolated at each fix's stamp; {int((~inside).sum())} fixes "
        "outside its span left out)"
    )
    return gps_stream(
        t_ns, tf[inside], columns[inside], ticks_per_s=1_000_000_000, latency_s=latency_s, source=source
    )


def import_rosbag(
    path: PathLike,
    imu_topic: str | None = None,
    mag_topic: str | None = None,
    gps_topic: str | None = None,
    gps_velocity_topic: str | None = None,
    gps_latency_s: float = DEFAULT_GPS_LATENCY_S,
) -> PhysicalTrace:
    """A ROS 1 bag (.bag) or ROS 2 bag (its folder, or a .db3/.mcap file in it) as a physical trace."""
    highlevel = need("rosbags.highlevel", "rosbags", "rosbag")
    typesys = need("rosbags.typesys", "rosbags", "rosbag")
    p = check_file(path, "ROS bag")
    bag = p.parent if p.is_file() and p.suffix in (".db3", ".mcap") else p
    try:
        reader = highlevel.AnyReader([bag], default_typestore=typesys.get_typestore(typesys.Stores.LATEST))
        reader.open()
    except Exception as e:  # rosbags raises its own errors on what is not a bag
        raise TraceError(f"{p}: not a readable ROS bag ({e}); expected a ROS 1 .bag or a ROS 2 bag") from None
    try:
        imu_conn = _pick(reader.connections, IMU, imu_topic, p, "--imu-topic")
        if imu_conn is None:
            found = ", ".join(sorted({f"{c.topic} ({c.msgtype})" for c in reader.connections})) or "none"
            raise TraceError(f"{p}: no {IMU} topic; expected IMU messages (the bag's topics: {found})")
        mag_conn = _pick(reader.connections, MAG, mag_topic, p, "--mag-topic")
        fix_conn = _pick(reader.connections, FIX, gps_topic, p, "--gps-topic")
        vel_conn = _pick(reader.connections, VEL, gps_velocity_topic, p, "--gps-velocity-topic")
        stamps, rates, forces, quats = [], [], [], []
        orientation = True
        for conn, _, raw in reader.messages(connections=[imu_conn]):
            msg = reader.deserialize(raw, conn.msgtype)
            stamps.append(_stamp_ns(msg))
            w, a, q = msg.angular_velocity, msg.linear_acceleration, msg.orientation
            rates.append((w.x, w.y, w.z))
            forces.append((a.x, a.y, a.z))
            quats.append((q.w, q.x, q.y, q.z))
            orientation &= bool(msg.orientation_covariance[0] != -1) and any((q.w, q.x, q.y, q.z))
        fields: list[tuple[int, tuple[float, float, float]]] = []
        if mag_conn is not None:
            for conn, _, raw in reader.messages(connections=[mag_conn]):
                msg = reader.deserialize(raw, conn.msgtype)
                m = msg.magnetic_field
                fields.append((_stamp_ns(msg), (m.x, m.y, m.z)))
        fixes: list[tuple[int, tuple[float, ...]]] = []
        vels: list[tuple[int, tuple[float, float]]] = []
        if fix_conn is not None and vel_conn is not None:
            for conn, _, raw in reader.messages(connections=[fix_conn, vel_conn]):
                msg = reader.deserialize(raw, conn.msgtype)
                if conn.msgtype == VEL:
                    vels.append((_stamp_ns(msg), (msg.twist.linear.x, msg.twist.linear.y)))
                elif msg.status.status >= 0:  # −1: no fix
                    fixes.append((_stamp_ns(msg), (msg.latitude, msg.longitude, msg.altitude)))
    except TraceError:
        raise
    except Exception as e:
        raise TraceError(f"{p}: a message cannot be read ({e})") from None
    finally:
        reader.close()
    if not stamps:
        raise TraceError(f"{p}: topic `{imu_conn.topic}` has no messages")
    t_ns, w_rad, f_ms2, q_all = ascending(
        np.array(stamps, dtype=np.int64), np.array(rates), np.array(forces), np.array(quats)
    )
    t0 = int(t_ns[0])
    t = (t_ns - t0).astype(np.float64) * 1e-9
    mag = None
    if fields:
        tm, m = ascending(
            (np.array([s for s, _ in fields], dtype=np.int64) - t0).astype(np.float64) * 1e-9,
            np.array([v for _, v in fields], dtype=np.float64),
        )
        mag = interpolate(t, tm, m) * GAUSS_PER_TESLA
    return make_trace(
        t_abs=t,
        origin=f"t_s = 0 at the header stamp {t0} ns of the first {imu_conn.topic} message",
        gyro_dps=np.degrees(w_rad),
        accel_g=f_ms2 / G0,
        mag_gauss=mag,
        truth_q=quaternion.normalize(q_all) if orientation else None,
        gps=_gps(
            fixes,
            vels,
            (fix_conn and fix_conn.topic, vel_conn and vel_conn.topic),
            t_ns,
            gps_latency_s,
        ),
        metadata={
            "source": f"ROS bag {p.name}, topic {imu_conn.topic}",
            "source_file": p.name,
            "generator": f"sins-fw import rosbag {p.name}",
            "frame": FRAME,
            "units": "angular_velocity rad/s → °/s, linear_acceleration m/s² → g, magnetic_field T → gauss",
            "magnetometer": f"{mag_conn.topic}, interpolated linearly at the IMU times"
            if mag_conn is not None and fields
            else "none (no sensor_msgs/MagneticField topic)",
            "truth": "the Imu messages' orientation: the IMU's or its driver's estimate (REP 145), not an "
            "independent truth"
            if orientation
            else "none (orientation marked unknown: covariance −1, or zero)",
        },
        where=f"{p}: {imu_conn.topic}",
    )
