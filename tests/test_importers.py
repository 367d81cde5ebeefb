"""Importers of other logs (issue 27, item 2): each on a small log the test writes itself (with the
library's own writer, or to the format's published layout), never on downloaded data.

Every log holds one motion: a level vehicle yawing at 20 °/s about its down axis (NED/FRD logs) or
about z (EuRoC/ROS), with the magnetometer seeing a fixed field. The checks are physical: the
still accelerometer reads +1 g on the trace's z, the truth rotates it to ENU up, the truth's own
body increments q_k* ⊗ q_k+1 give the gyro's rates, heading 30° east of north puts the body's x
axis at (sin 30°, cos 30°, 0) in ENU, and the sensor's time stamps come through exactly. The GPS
fixes (10 Hz) report 20 m/s along a course of 30°, stamped 1.5 ms after an IMU sample: each lands on
the next row, NaN rows between."""

from __future__ import annotations

import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import run_cli
from sins_fw import quaternion
from sins_fw.errors import InputError
from sins_fw.traces import G0, PhysicalTrace

RATE_HZ = 250.0
N = 500
YAW_RATE = float(np.radians(20.0))
YAW0 = float(np.radians(30.0))
#: The earth's field in NED, gauss (north and down components).
MAG_NED = np.array([0.2, 0.0, 0.45])


T0_US = 1_000_000


def _attitude_ned(t_us: np.ndarray) -> np.ndarray:
    """The FRD → NED attitude of the yawing vehicle at the log times ``t_us`` (µs)."""
    yaw = YAW0 + YAW_RATE * (t_us - T0_US) * 1e-6
    return quaternion.from_axis_angle(np.array([0.0, 0.0, 1.0]), yaw)


def _ned_motion() -> dict[str, np.ndarray]:
    """Times (µs from 1 s), FRD rates (rad/s) and FRD specific force (m/s²) of the yawing vehicle."""
    t_us = T0_US + np.arange(N, dtype=np.int64) * 4000
    gyro = np.tile([0.0, 0.0, YAW_RATE], (N, 1))
    accel = np.tile([0.0, 0.0, -G0], (N, 1))
    return {"t_us": t_us, "gyro": gyro, "accel": accel}


def _field_frd(t_us: np.ndarray) -> np.ndarray:
    """The earth's field in FRD body axes at the log times ``t_us``, gauss."""
    return quaternion.rotate(quaternion.conjugate(_attitude_ned(t_us)), MAG_NED)


def _check_physics(
    trace: PhysicalTrace, float32: bool, mag_span: tuple[float, float] = (0.0, 0.0), mag_atol: float = 0.0
) -> None:
    """The trace convention: FLU body (z up), ENU navigation, rates in °/s, specific force in g."""
    tol = 1e-6 if float32 else 1e-12
    np.testing.assert_allclose(trace.accel_g, np.tile([0.0, 0.0, 1.0], (len(trace), 1)), atol=tol)
    np.testing.assert_allclose(trace.gyro_dps[:, :2], 0.0, atol=tol)
    np.testing.assert_allclose(trace.gyro_dps[:, 2], -20.0, rtol=tol)  # yaw right = turning clockwise
    q = trace.truth_q
    valid = ~np.isnan(q[:, 0])
    assert valid.sum() >= len(trace) - 2
    up = quaternion.rotate(q[valid], trace.accel_g[valid])
    np.testing.assert_allclose(up, np.tile([0.0, 0.0, 1.0], (valid.sum(), 1)), atol=10 * tol + 1e-9)
    first = np.flatnonzero(valid)[0]
    forward = quaternion.rotate(q[first], [1.0, 0.0, 0.0])
    heading = YAW0 + YAW_RATE * float(trace.t_s[first])
    np.testing.assert_allclose(forward, [np.sin(heading), np.cos(heading), 0.0], atol=1e-6)
    # The truth's body increments are the gyro's rates (the body frame is the same).
    k = np.flatnonzero(valid[:-1] & valid[1:])
    dq = quaternion.multiply(quaternion.conjugate(q[k]), q[k + 1])
    rate = 2 * dq[:, 1:] / np.diff(trace.t_s)[k, None]
    np.testing.assert_allclose(np.degrees(rate), trace.gyro_dps[k], atol=1e-3)
    if trace.mag_gauss is not None:
        inside = valid & (trace.t_s >= mag_span[0]) & (trace.t_s <= mag_span[1])
        mag_enu = quaternion.rotate(q[inside], trace.mag_gauss[inside])
        np.testing.assert_allclose(mag_enu, np.tile([0.0, 0.2, -0.45], (inside.sum(), 1)), atol=mag_atol)
    assert "gps" in trace.metadata


#: The GPS fixes: 10 Hz from 1.5 ms after the first IMU sample (µs after T0_US), 20 m/s along 30°.
GPS_DT_US = 1500 + 100_000 * np.arange(20, dtype=np.int64)
GPS_SPEED, GPS_COURSE = 20.0, 30.0
LAT0, LON0, H0 = 47.3977419, 8.5455938, 488.0
#: Rows of the fixes: the first IMU sample (every 4 ms) at or after each: 1.5 ms + 100 ms k → 25 k + 1.
GPS_ROWS = 1 + 25 * np.arange(20)


def _gps_positions(dt_us: np.ndarray) -> np.ndarray:
    """Latitude, longitude (°) and height (m) of the fixes (a sphere of 6371 km is enough: the
    importers copy positions, the test only needs known values)."""
    d = GPS_SPEED * dt_us * 1e-6
    north, east = d * np.cos(np.radians(GPS_COURSE)), d * np.sin(np.radians(GPS_COURSE))
    lat = LAT0 + np.degrees(north / 6.371e6)
    lon = LON0 + np.degrees(east / (6.371e6 * np.cos(np.radians(LAT0))))
    return np.column_stack([lat, lon, H0 + 0.5 * dt_us * 1e-6])


def _check_gps(
    trace: PhysicalTrace, deg_tol: float, m_tol: float, course_tol: float, latency_s: float
) -> None:
    """The fixes on rows GPS_ROWS, all five NaN elsewhere, values within the log format's resolution."""
    assert trace.gps is not None, trace.metadata["gps"]
    has = ~np.isnan(trace.gps[:, 0])
    np.testing.assert_array_equal(np.flatnonzero(has), GPS_ROWS)
    assert np.isnan(trace.gps[~has]).all()
    g = trace.gps[has]
    np.testing.assert_allclose(g[:, 0], GPS_SPEED, rtol=1e-7)  # float32: 6e-8 relative
    np.testing.assert_allclose(g[:, 1], GPS_COURSE, atol=course_tol)
    pos = _gps_positions(GPS_DT_US)
    np.testing.assert_allclose(g[:, 2:4], pos[:, :2], rtol=0, atol=deg_tol)
    np.testing.assert_allclose(g[:, 4], pos[:, 2], rtol=0, atol=m_tol)
    assert float(trace.metadata["gps_latency_s"]) == latency_s
    assert trace.metadata["gps_rate_hz"] == "10"
    trace.validate()  # the GPS stream's own checks (ranges, gps_latency_s)


# ---------------------------------------------------------------------------------------------------
# PX4 ULog: written to the format's published layout (pyulog reads it; it has no writer of its own
# that builds a log from nothing)
# ---------------------------------------------------------------------------------------------------


def write_ulog(
    path: Path, topics: list[tuple[str, list[tuple[str, str, int]], dict[str, np.ndarray]]]
) -> None:
    """A ULog file (version 1): the 16-byte header, the flag bits, one format and one subscription
    per topic, then the data messages in time order. Each topic: (name, [(type, field, count)],
    {field: values}); the first field is `uint64_t timestamp`."""
    out = bytearray(b"ULog\x01\x12\x35\x01" + struct.pack("<Q", 0))

    def message(kind: str, payload: bytes) -> None:
        out.extend(struct.pack("<HB", len(payload), ord(kind)) + payload)

    message("B", bytes(40))  # compat and incompat flags, no appended data
    for name, fields, _ in topics:
        message(
            "F", (name + ":" + "".join(f"{t}[{c}] {f};" if c else f"{t} {f};" for t, f, c in fields)).encode()
        )
    for i, (name, _, _) in enumerate(topics):
        message("A", struct.pack("<BH", 0, i) + name.encode())
    codes = {"uint64_t": "Q", "float": "f", "double": "d", "int32_t": "i", "uint8_t": "B"}
    rows = []
    for i, (_, fields, data) in enumerate(topics):
        for k in range(len(data["timestamp"])):
            payload = struct.pack("<H", i)
            for t, f, c in fields:
                payload += struct.pack("<" + codes[t] * (c or 1), *np.atleast_1d(data[f][k]).tolist())
            rows.append((int(data["timestamp"][k]), payload))
    for _, payload in sorted(rows, key=lambda r: r[0]):
        message("D", payload)
    path.write_bytes(bytes(out))


def _ulog_gps(version: str) -> tuple[str, list[tuple[str, str, int]], dict[str, np.ndarray]]:
    """The GPS topic: PX4 before v1.15 (vehicle_gps_position, 1e-7° and mm integers) or after
    (sensor_gps, degrees and metres as doubles). Three messages are left out: one without a fix, one
    before the first IMU sample and one after the last."""
    dt = np.concatenate([GPS_DT_US, [51_500, -50_000, 2_001_500]])
    pos = _gps_positions(dt)
    fix = np.array([3] * 20 + [0, 3, 3])
    data = {
        "timestamp": T0_US + dt,
        "vel_m_s": np.full(len(dt), GPS_SPEED),
        "cog_rad": np.full(len(dt), np.radians(GPS_COURSE) - 2 * np.pi),  # PX4's −π…π
        "fix_type": fix,
    }
    head = [
        ("uint64_t", "timestamp", 0),
        ("float", "vel_m_s", 0),
        ("float", "cog_rad", 0),
        ("uint8_t", "fix_type", 0),
    ]
    if version == "old":
        data.update(
            lat=np.rint(pos[:, 0] * 1e7).astype(np.int64),
            lon=np.rint(pos[:, 1] * 1e7).astype(np.int64),
            alt=np.rint((pos[:, 2] - 48.0) * 1e3).astype(np.int64),  # MSL: not read when alt_ellipsoid is
            alt_ellipsoid=np.rint(pos[:, 2] * 1e3).astype(np.int64),
        )
        fields = [("int32_t", n, 0) for n in ("lat", "lon", "alt", "alt_ellipsoid")]
        return "vehicle_gps_position", head + fields, data
    data.update(latitude_deg=pos[:, 0], longitude_deg=pos[:, 1], altitude_msl_m=pos[:, 2])
    fields = [("double", n, 0) for n in ("latitude_deg", "longitude_deg", "altitude_msl_m")]
    return "sensor_gps", head + fields, data


def _ulog(path: Path, gps: str | None = None) -> dict[str, np.ndarray]:
    m = _ned_motion()
    t = m["t_us"]
    write_ulog(
        path,
        ([_ulog_gps(gps)] if gps else [])
        + [
            (
                "sensor_combined",
                [("uint64_t", "timestamp", 0), ("float", "gyro_rad", 3), ("float", "accelerometer_m_s2", 3)],
                {"timestamp": t, "gyro_rad": m["gyro"], "accelerometer_m_s2": m["accel"]},
            ),
            (
                "vehicle_magnetometer",
                [("uint64_t", "timestamp", 0), ("float", "magnetometer_ga", 3)],
                {"timestamp": t[::5] + 1000, "magnetometer_ga": _field_frd(t[::5] + 1000)},
            ),
            (
                "vehicle_attitude",
                [("uint64_t", "timestamp", 0), ("float", "q", 4)],
                {"timestamp": t[::2] + 500, "q": _attitude_ned(t[::2] + 500)},
            ),
        ],
    )
    return m


@pytest.mark.parametrize("version", ["old", "new"])
def test_ulog_keeps_the_gps(tmp_path, version):
    pytest.importorskip("pyulog")
    from sins_fw.importers.ulog import import_ulog

    _ulog(tmp_path / "flight.ulg", gps=version)
    trace = import_ulog(tmp_path / "flight.ulg", gps_latency_s=0.0)
    # Old: 1e-7° integers (half a unit of rounding), mm; new: doubles. Course: float32 rad (3e-7 rad).
    deg_tol, m_tol = (0.5e-7 + 1e-12, 0.5e-3 + 1e-9) if version == "old" else (1e-12, 1e-9)
    _check_gps(trace, deg_tol, m_tol, course_tol=1e-4, latency_s=0.0)
    meta = trace.metadata["gps"]
    assert "1 messages without a 3D fix left out" in meta and "2 left out" in meta
    assert ("ellipsoid height" if version == "old" else "MSL altitude") in meta
    # A latency moves each fix's time of validity earlier: 1.5 ms + 100 ms k − 2 ms → row 25 k; the
    # fix before the first sample (k = 0, at −0.5 ms) is left out.
    late = import_ulog(tmp_path / "flight.ulg", gps_latency_s=0.002)
    assert late.gps is not None and late.metadata["gps_latency_s"] == "0.002"
    np.testing.assert_array_equal(np.flatnonzero(~np.isnan(late.gps[:, 0])), 25 * np.arange(1, 20))
    r = run_cli(
        "import",
        "ulog",
        str(tmp_path / "flight.ulg"),
        "--gps-latency-s",
        "0.1",
        "--out",
        str(tmp_path / "g.h5"),
    )
    assert r.code == 0, r.err
    saved = PhysicalTrace.load(tmp_path / "g.h5")
    assert saved.metadata["gps_latency_s"] == "0.1" and saved.gps is not None
    r = run_cli(
        "import",
        "ulog",
        str(tmp_path / "flight.ulg"),
        "--gps-latency-s",
        "11",
        "--out",
        str(tmp_path / "x.h5"),
    )
    assert (
        r.code == 2
        and "argument --gps-latency-s: '11': expected" in r.err
        and not (tmp_path / "x.h5").exists()
    )


def test_ulog_import(tmp_path):
    pytest.importorskip("pyulog")
    from sins_fw.importers.ulog import import_ulog

    m = _ulog(tmp_path / "flight.ulg")
    trace = import_ulog(tmp_path / "flight.ulg")
    np.testing.assert_array_equal(trace.t_s, (m["t_us"] - m["t_us"][0]) * 1e-6)
    assert trace.metadata["sample_rate_hz"] == "250"
    assert "1000000 µs" in trace.metadata["time_origin"]
    assert "vehicle_attitude.q" in trace.metadata["truth"] and "estimate" in trace.metadata["truth"]
    assert "FRD" in trace.metadata["frame"] and "ENU" in trace.metadata["frame"]
    assert trace.gps is None and "no vehicle_gps_position or sensor_gps" in trace.metadata["gps"]
    # The magnetometer's 50 Hz samples (from 1 ms to 1.981 s) are interpolated linearly: the yaw turns
    # by θ = 20 °/s × 20 ms between them, a chord error of at most |m_horizontal| θ²/8 (1.2e-6 gauss),
    # plus float32 rounding (6e-8 of 0.45 gauss).
    theta = YAW_RATE * 0.02
    _check_physics(
        trace, float32=True, mag_span=(0.001, 0.001 + 99 * 0.02), mag_atol=0.2 * theta**2 / 8 + 1e-7
    )


def test_ulog_through_the_cli(tmp_path):
    pytest.importorskip("pyulog")
    _ulog(tmp_path / "flight.ulg")
    r = run_cli("import", "ulog", str(tmp_path / "flight.ulg"), "--out", str(tmp_path / "f.h5"), "--json")
    assert r.code == 0, r.err
    assert '"rows": 500' in r.out
    assert PhysicalTrace.load(tmp_path / "f.h5").metadata["source"] == "PX4 ULog flight.ulg"
    (tmp_path / "bad.ulg").write_bytes(b"not a log at all")
    r = run_cli("import", "ulog", str(tmp_path / "bad.ulg"), "--out", str(tmp_path / "b.h5"))
    assert r.code == 2 and "bad.ulg: not a readable ULog file" in r.err and "Traceback" not in r.err


@pytest.mark.parametrize(
    ("kind", "package"), [("ulog", "pyulog"), ("dataflash", "pymavlink"), ("rosbag", "rosbags")]
)
def test_a_missing_library_is_named(tmp_path, monkeypatch, capsys, kind, package):
    from sins_fw.cli import main
    from sins_fw.importers import need

    monkeypatch.setitem(sys.modules, package, None)  # `import package` now raises ImportError
    with pytest.raises(InputError, match=rf"needs the `{package}` package.*pip install 'sins-fw\[import\]'"):
        need(package, package, kind)
    (tmp_path / "log").write_bytes(b"x")
    assert main(["import", kind, str(tmp_path / "log"), "--out", str(tmp_path / "o.h5")]) == 2
    assert f"pip install {package}" in capsys.readouterr().err
    assert not (tmp_path / "o.h5").exists()


# ---------------------------------------------------------------------------------------------------
# EuRoC-style CSV
# ---------------------------------------------------------------------------------------------------


def _euroc(root: Path) -> np.ndarray:
    """A EuRoC folder: the sensor yaws about its z (up) axis; the ground truth at its own times."""
    t_ns = 1403636579758555392 + np.arange(N, dtype=np.int64) * 4_000_000
    t = (t_ns - t_ns[0]) * 1e-9
    imu = root / "mav0" / "imu0"
    imu.mkdir(parents=True)
    header = "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
    header += "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n"
    rows = [f"{s},0.0,0.0,{-float(YAW_RATE)!r},0.0,0.0,{G0!r}" for s in t_ns]
    (imu / "data.csv").write_text(header + "\n".join(rows) + "\n")
    gt = root / "mav0" / "state_groundtruth_estimate0"
    gt.mkdir()
    t_gt = t_ns[::2] + 1_000_000
    yaw = np.pi / 2 - YAW0 - YAW_RATE * (t_gt - t_ns[0]) * 1e-9  # ENU yaw of heading 30° + 20 °/s t
    q = quaternion.from_axis_angle(np.array([0.0, 0.0, 1.0]), yaw)
    header = (
        "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z []\n"
    )
    rows = [f"{s},1.0,2.0,3.0," + ",".join(repr(float(x)) for x in qk) for s, qk in zip(t_gt, q, strict=True)]
    (gt / "data.csv").write_text(header + "\n".join(rows) + "\n")
    return t


def test_euroc_import(tmp_path):
    from sins_fw.importers.euroc import import_euroc

    t = _euroc(tmp_path)
    trace = import_euroc(tmp_path)
    np.testing.assert_array_equal(trace.t_s, t)
    assert "1403636579758555392 ns" in trace.metadata["time_origin"]
    assert trace.metadata["sample_rate_hz"] == "250"
    # Before the first ground-truth time (1 ms after the first IMU sample): no truth.
    assert np.isnan(trace.truth_q[0]).all() and not np.isnan(trace.truth_q[1]).any()
    _check_physics(trace, float32=False)
    assert trace.gps is None and trace.metadata["gps"] == "none: EuRoC-style logs hold no GPS"
    r = run_cli("import", "euroc", str(tmp_path), "--out", str(tmp_path / "e.csv"))
    assert r.code == 0, r.err
    np.testing.assert_array_equal(PhysicalTrace.load(tmp_path / "e.csv").t_s, t)


def test_euroc_errors_name_the_file_and_column(tmp_path):
    from sins_fw.errors import TraceError
    from sins_fw.importers.euroc import import_euroc

    with pytest.raises(TraceError, match=r"no imu0/data\.csv here or in mav0/"):
        import_euroc(tmp_path)
    (tmp_path / "imu.csv").write_text("#timestamp [ns],w_RS_S_x [rad s^-1]\n1,0\n")
    with pytest.raises(TraceError, match=r"imu.csv: line 1: missing column `w_RS_S_y`"):
        import_euroc(tmp_path / "imu.csv")


# ---------------------------------------------------------------------------------------------------
# ROS 1 and ROS 2 bags, written with rosbags' own writers
# ---------------------------------------------------------------------------------------------------


def _enu_attitude(t: np.ndarray) -> np.ndarray:
    """The FLU → ENU attitude of the yawing vehicle at the times ``t`` (s from the first sample)."""
    return quaternion.from_axis_angle(np.array([0.0, 0.0, 1.0]), np.pi / 2 - YAW0 - YAW_RATE * t)


def _write_bag(
    path: Path, ros: int, imu_topics: tuple[str, ...] = ("/imu/data",), gps: tuple[str, ...] = ()
) -> np.ndarray:
    """A bag of the yawing vehicle; ``gps`` names what GPS it holds: "fix" (NavSatFix) and "vel"
    (TwistStamped, ENU)."""
    from rosbags.rosbag1 import Writer as Writer1
    from rosbags.rosbag2 import Writer as Writer2
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS1_NOETIC if ros == 1 else Stores.ROS2_HUMBLE)
    types = store.types
    imu_t, mag_t = types["sensor_msgs/msg/Imu"], types["sensor_msgs/msg/MagneticField"]
    header_t, time_t = types["std_msgs/msg/Header"], types["builtin_interfaces/msg/Time"]
    quat_t, vec_t = types["geometry_msgs/msg/Quaternion"], types["geometry_msgs/msg/Vector3"]
    serialize = store.serialize_ros1 if ros == 1 else store.serialize_cdr
    t0_ns = 1_700_000_000_123_456_789
    t_ns = t0_ns + np.arange(N, dtype=np.int64) * 4_000_000

    def header(ns: int, k: int) -> object:
        stamp = time_t(sec=ns // 10**9, nanosec=ns % 10**9)
        return (
            header_t(seq=k, stamp=stamp, frame_id="imu")
            if ros == 1
            else header_t(stamp=stamp, frame_id="imu")
        )

    writer = Writer1(path) if ros == 1 else Writer2(path, version=9)
    with writer:
        imus = [writer.add_connection(topic, imu_t.__msgtype__, typestore=store) for topic in imu_topics]
        mag = writer.add_connection("/imu/mag", mag_t.__msgtype__, typestore=store)
        q = _enu_attitude((t_ns - t0_ns) * 1e-9)
        zeros = np.zeros(9)
        for k, ns in enumerate(t_ns):
            msg = imu_t(
                header=header(int(ns), k),
                orientation=quat_t(x=q[k, 1], y=q[k, 2], z=q[k, 3], w=q[k, 0]),
                orientation_covariance=zeros,
                angular_velocity=vec_t(x=0.0, y=0.0, z=-YAW_RATE),
                angular_velocity_covariance=zeros,
                linear_acceleration=vec_t(x=0.0, y=0.0, z=G0),
                linear_acceleration_covariance=zeros,
            )
            for conn in imus:  # recorded 2 ms after the sensor's stamp: the stamp is what counts
                writer.write(conn, int(ns) + 2_000_000, serialize(msg, imu_t.__msgtype__))
        for k, ns in enumerate(t_ns[::5] + 1_000_000):
            b = quaternion.rotate(quaternion.conjugate(_enu_attitude((ns - t0_ns) * 1e-9)), [0.0, 0.2, -0.45])
            msg = mag_t(
                header=header(int(ns), k),
                magnetic_field=vec_t(x=b[0] * 1e-4, y=b[1] * 1e-4, z=b[2] * 1e-4),
                magnetic_field_covariance=zeros,
            )
            writer.write(mag, int(ns), serialize(msg, mag_t.__msgtype__))
        _write_gps(writer, store, serialize, header, t0_ns - T0_US * 1000, gps)
    return (t_ns - t0_ns) * 1e-9


def _write_gps(
    writer: object, store: object, serialize: object, header: object, base_ns: int, gps: tuple[str, ...]
) -> None:
    """NavSatFix fixes (GPS_DT_US; one more without a fix) and the ENU ground velocity (10 Hz over
    the whole log, 0.5 ms before each fix)."""
    types = store.types  # type: ignore[attr-defined]
    fix_t, status_t = types["sensor_msgs/msg/NavSatFix"], types["sensor_msgs/msg/NavSatStatus"]
    twist_st, twist_t = types["geometry_msgs/msg/TwistStamped"], types["geometry_msgs/msg/Twist"]
    vec_t = types["geometry_msgs/msg/Vector3"]
    if "fix" in gps:
        conn = writer.add_connection("/gps/fix", fix_t.__msgtype__, typestore=store)  # type: ignore[attr-defined]
        dt = np.concatenate([GPS_DT_US, [51_500]])
        for k, ((lat, lon, h), d) in enumerate(zip(_gps_positions(dt), dt, strict=True)):
            ns = base_ns + (T0_US + int(d)) * 1000
            msg = fix_t(
                header=header(ns, k),
                status=status_t(status=-1 if k == 20 else 0, service=1),
                latitude=lat,
                longitude=lon,
                altitude=h,
                position_covariance=np.zeros(9),
                position_covariance_type=0,
            )
            writer.write(conn, ns, serialize(msg, fix_t.__msgtype__))  # type: ignore[attr-defined,operator]
    if "vel" in gps:
        conn = writer.add_connection("/gps/vel", twist_st.__msgtype__, typestore=store)  # type: ignore[attr-defined]
        c = np.radians(GPS_COURSE)
        for k in range(21):
            ns = base_ns + (T0_US + 1000 + 100_000 * k) * 1000
            v = vec_t(x=GPS_SPEED * np.sin(c), y=GPS_SPEED * np.cos(c), z=0.0)
            msg = twist_st(header=header(ns, k), twist=twist_t(linear=v, angular=vec_t(x=0.0, y=0.0, z=0.0)))
            writer.write(conn, ns, serialize(msg, twist_st.__msgtype__))  # type: ignore[attr-defined,operator]


@pytest.mark.parametrize("ros", [1, 2])
def test_rosbag_import(tmp_path, ros):
    pytest.importorskip("rosbags")
    from sins_fw.importers.rosbag import import_rosbag

    path = tmp_path / ("flight.bag" if ros == 1 else "flight")
    t = _write_bag(path, ros)
    trace = import_rosbag(path)
    np.testing.assert_array_equal(trace.t_s, t)
    assert "1700000000123456789 ns" in trace.metadata["time_origin"]
    assert "REP 103" in trace.metadata["frame"] and "estimate" in trace.metadata["truth"]
    assert trace.gps is None and "none: no sensor_msgs/msg/NavSatFix topic and no" in trace.metadata["gps"]
    # The field at 50 Hz, interpolated: the chord error of a 0.4° turn (as for the ULog).
    theta = YAW_RATE * 0.02
    _check_physics(
        trace, float32=False, mag_span=(0.001, 0.001 + 99 * 0.02), mag_atol=0.2 * theta**2 / 8 + 1e-12
    )
    r = run_cli("import", "rosbag", str(path), "--out", str(tmp_path / "r.h5"))
    assert r.code == 0, r.err


def test_rosbag_with_two_imu_topics_asks_which(tmp_path):
    pytest.importorskip("rosbags")
    from sins_fw.errors import TraceError
    from sins_fw.importers.rosbag import import_rosbag

    path = tmp_path / "two"
    _write_bag(path, 2, imu_topics=("/imu/a", "/imu/b"))
    with pytest.raises(
        TraceError, match=r"2 sensor_msgs/msg/Imu topics \(/imu/a, /imu/b\); choose one with --imu-topic"
    ):
        import_rosbag(path)
    assert len(import_rosbag(path, imu_topic="/imu/b")) == N
    r = run_cli("import", "rosbag", str(tmp_path / "nothing"), "--out", str(tmp_path / "o.h5"))
    assert r.code == 2 and "no such ROS bag" in r.err


# ---------------------------------------------------------------------------------------------------
# ArduPilot DataFlash: built to the format's layout (FMT messages describe the others), read by
# pymavlink's DFReader
# ---------------------------------------------------------------------------------------------------


def _df_format(type_id: int, name: str, fmt: str, columns: str) -> bytes:
    """An FMT message: the type, the message length (3-byte header included), name, format, columns."""
    sizes = {"Q": 8, "B": 1, "f": 4, "n": 4, "N": 16, "Z": 64, "L": 4, "e": 4, "I": 4, "H": 2, "c": 2}
    length = 3 + sum(sizes[c] for c in fmt)
    payload = struct.pack("<BB4s16s64s", type_id, length, name.encode(), fmt.encode(), columns.encode())
    return b"\xa3\x95\x80" + payload


def _df_message(type_id: int, fmt: str, *values: float) -> bytes:
    return b"\xa3\x95" + bytes([type_id]) + struct.pack("<" + fmt, *values)


def _dataflash(path: Path, gps: bool = False) -> dict[str, np.ndarray]:
    m = _ned_motion()
    out = bytearray(_df_format(128, "FMT", "BBnNZ", "Type,Length,Name,Format,Columns"))
    out += _df_format(129, "IMU", "QBffffff", "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ")
    out += _df_format(130, "MAG", "QBfff", "TimeUS,I,MagX,MagY,MagZ")
    out += _df_format(131, "ATT", "Qfff", "TimeUS,Roll,Pitch,Yaw")
    if gps:  # ArduPilot's GPS layout: Lat/Lng 1e-7° integers, Alt cm integers (MSL), GPS week and ms
        out += _df_format(
            132, "GPS", "QBBIHBcLLeffffB", "TimeUS,I,Status,GMS,GWk,NSats,HDop,Lat,Lng,Alt,Spd,GCrs,VZ,Yaw,U"
        )

        def gps_message(
            t_us: int, instance: int, status: int, ints: tuple[int, int, int], spd: float
        ) -> bytes:
            gms = 300_000_000 + (t_us - T0_US) // 1000
            values = (t_us, instance, status, gms, 2300, 12, 80, *ints, spd, GPS_COURSE, 0.0, 0.0, 1)
            return _df_message(132, "QBBIHBhiiiffffB", *values)

        for dt, (lat, lon, h) in zip(GPS_DT_US, _gps_positions(GPS_DT_US), strict=True):
            ints = (round(lat * 1e7), round(lon * 1e7), round(h * 100))
            out += gps_message(T0_US + int(dt), 0, 3, ints, GPS_SPEED)
            out += gps_message(T0_US + int(dt), 1, 3, (0, 0, 0), 1.0)  # a second receiver: left out
        out += gps_message(T0_US + 51_500, 0, 1, (0, 0, 0), 0.0)  # no fix: left out
        out += gps_message(T0_US - 50_000, 0, 3, (473977419, 85455938, 48800), GPS_SPEED)  # too early
    for k, t in enumerate(m["t_us"]):
        out += _df_message(129, "QBffffff", t, 0, *m["gyro"][k], *m["accel"][k])
        out += _df_message(129, "QBffffff", t, 1, 9.0, 9.0, 9.0, 9.0, 9.0, 9.0)  # a second IMU: left out
        if k % 5 == 0:
            mag = _field_frd(np.array([t + 1000]))[0] * 1000  # milligauss
            out += _df_message(130, "QBfff", t + 1000, 0, *mag)
        if k % 2 == 0:
            yaw = np.degrees(YAW0 + YAW_RATE * (t + 500 - T0_US) * 1e-6) % 360
            out += _df_message(131, "Qfff", t + 500, 0.0, 0.0, yaw)
    path.write_bytes(bytes(out))
    return m


def test_dataflash_import(tmp_path):
    pytest.importorskip("pymavlink")
    from sins_fw.importers.dataflash import import_dataflash

    m = _dataflash(tmp_path / "00000001.BIN")
    trace = import_dataflash(tmp_path / "00000001.BIN")
    np.testing.assert_array_equal(trace.t_s, (m["t_us"] - m["t_us"][0]) * 1e-6)
    assert "ATT" in trace.metadata["truth"] and "estimate" in trace.metadata["truth"]
    theta = YAW_RATE * 0.02
    # ATT's yaw in float32 degrees: 3e-6° of rounding at 360° (5e-8 rad), far below the checks' 1e-6.
    _check_physics(
        trace, float32=True, mag_span=(0.001, 0.001 + 99 * 0.02), mag_atol=0.2 * theta**2 / 8 + 1e-7
    )
    r = run_cli("import", "dataflash", str(tmp_path / "00000001.BIN"), "--out", str(tmp_path / "d.csv"))
    assert r.code == 0, r.err
    (tmp_path / "empty.BIN").write_bytes(_df_format(128, "FMT", "BBnNZ", "Type,Length,Name,Format,Columns"))
    r = run_cli("import", "dataflash", str(tmp_path / "empty.BIN"), "--out", str(tmp_path / "e.csv"))
    assert r.code == 2 and "no IMU messages (instance 0)" in r.err and "Traceback" not in r.err


def test_dataflash_keeps_the_gps(tmp_path):
    pytest.importorskip("pymavlink")
    from sins_fw.importers.dataflash import import_dataflash

    _dataflash(tmp_path / "gps.BIN", gps=True)
    trace = import_dataflash(tmp_path / "gps.BIN")
    # Lat/Lng: half a 1e-7° unit; Alt: half a cm; GCrs float32 degrees.
    _check_gps(trace, 0.5e-7 + 1e-12, 0.005 + 1e-9, course_tol=1e-5, latency_s=0.0)
    meta = trace.metadata["gps"]
    assert (
        "1 messages without a 3D fix left out" in meta and "1 left out" in meta and "mean sea level" in meta
    )
    _dataflash(tmp_path / "no_gps.BIN")
    assert import_dataflash(tmp_path / "no_gps.BIN").metadata["gps"] == "none (no GPS messages)"


@pytest.mark.parametrize("ros", [1, 2])
def test_rosbag_keeps_the_gps(tmp_path, ros):
    pytest.importorskip("rosbags")
    from sins_fw.importers.rosbag import import_rosbag

    path = tmp_path / ("gps.bag" if ros == 1 else "gps")
    _write_bag(path, ros, gps=("fix", "vel"))
    trace = import_rosbag(path)
    # Positions are doubles; speed and course from the float64 velocity: rounding only.
    _check_gps(trace, 1e-12, 1e-9, course_tol=1e-9, latency_s=0.0)
    assert "/gps/fix" in trace.metadata["gps"] and "/gps/vel" in trace.metadata["gps"]
    only = tmp_path / ("fix.bag" if ros == 1 else "fix")
    _write_bag(only, ros, gps=("fix",))
    trace = import_rosbag(only)
    assert trace.gps is None
    assert "/gps/fix gives position only" in trace.metadata["gps"]
    assert "no geometry_msgs/msg/TwistStamped" in trace.metadata["gps"]
    r = run_cli("import", "rosbag", str(only), "--out", str(tmp_path / "o.h5"))
    assert r.code == 0, r.err


def test_two_fixes_on_one_row_keep_the_later():
    from sins_fw.importers import gps_stream

    t_imu = np.arange(5, dtype=np.int64) * 4000  # µs
    fixes = np.array([[1.0, 10.0, 1.0, 2.0, 3.0], [2.0, -10.0, 1.0, 2.0, 3.0], [3.0, 370.0, 1.0, 2.0, 3.0]])
    gps = gps_stream(
        t_imu, np.array([5000, 6000, 12000]), fixes, ticks_per_s=10**6, latency_s=0.0, source="s"
    )
    assert not isinstance(gps, str)
    # 5 ms and 6 ms both go on the 8 ms row: the later (course −10° → 350°) stays; 12 ms is on its row.
    np.testing.assert_array_equal(gps.columns[2:4, :2], [[2.0, 350.0], [3.0, 10.0]])
    assert np.isnan(gps.columns[[0, 1, 4]]).all()
    assert "2 fixes" in gps.metadata["gps"] and "1 replaced by a later fix" in gps.metadata["gps"]


# ---------------------------------------------------------------------------------------------------
# Malformed logs and options (issue 42, item 3): exit 2 naming the file and what was expected, one
# message, never a traceback or a library's noise
# ---------------------------------------------------------------------------------------------------


def _euroc_csv(tmp_path: Path, body: bytes) -> Path:
    path = tmp_path / "imu.csv"
    header = b"#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
    header += b"a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n"
    path.write_bytes(header + body)
    return path


_ROW = b"0.0,0.0,0.1,0.0,0.0,9.8\n"


@pytest.mark.parametrize(
    ("body", "fragment"),
    [
        # Before: OverflowError (exit 3).
        (b"1," + _ROW + b"99999999999999999999," + _ROW, "time stamp 99999999999999999999 out of range"),
        (b"1," + _ROW + b"-9223372036854775807," + _ROW, "time stamp -9223372036854775807 out of range"),
        # Before: UnicodeDecodeError (exit 3).
        (
            b"1," + _ROW + "2,0.0,0.0,0.1,0.0,0.0,9.8 caf\u00e9\n".encode("latin-1"),
            "line 3: byte 0xe9 is not UTF-8",
        ),
        (b"1," + _ROW + b"\x00\x01\x02\xff" * 8, "binary data (NUL byte at offset"),
        # Before: numpy's UserWarning on stderr, then an IndexError (exit 3).
        (b"", "header only, no data rows"),
        (b"\n\n", "header only, no data rows"),
    ],
    ids=["overflow", "overflow-negative", "latin-1", "binary", "header-only", "blank-lines"],
)
def test_a_malformed_euroc_csv_is_exit_2_naming_the_file(tmp_path, body, fragment):
    path = _euroc_csv(tmp_path, body)
    r = run_cli("import", "euroc", str(path), "--out", str(tmp_path / "o.h5"))
    assert r.code == 2, r.err
    assert f"sins-fw: error: {path}: " in r.err and fragment in r.err, r.err
    assert r.err.count("\n") == 1 and "Traceback" not in r.err and "Warning" not in r.err, r.err
    assert not (tmp_path / "o.h5").exists()


def test_euroc_ground_truth_that_is_latin_1_is_named(tmp_path):
    _euroc(tmp_path)
    gt = tmp_path / "mav0" / "state_groundtruth_estimate0" / "data.csv"
    gt.write_bytes(gt.read_bytes().replace(b"p_RS_R_x", "p_RS_R_\u00e9".encode("latin-1")))
    r = run_cli("import", "euroc", str(tmp_path), "--out", str(tmp_path / "o.h5"))
    assert r.code == 2 and f"{gt}: line 1: byte 0xe9 is not UTF-8" in r.err, r.err


def test_dataflash_time_stamps_that_overflow_are_exit_2(tmp_path):
    pytest.importorskip("pymavlink")
    _dataflash(tmp_path / "log.bin")
    data = bytearray((tmp_path / "log.bin").read_bytes())
    # The last IMU message's TimeUS (uint64) set to 2^64 - 1: before, OverflowError (exit 3).
    head = _df_message(129, "QBffffff", T0_US, 0, *([0.0] * 6))[:3]
    at = len(data)
    while True:  # the last IMU message of instance 0 (the instance byte follows the 8-byte TimeUS)
        at = data.rfind(head, 0, at)
        if data[at + 11] == 0:
            break
    data[at + 3 : at + 11] = struct.pack("<Q", 2**64 - 1)
    (tmp_path / "log.bin").write_bytes(bytes(data))
    r = run_cli("import", "dataflash", str(tmp_path / "log.bin"), "--out", str(tmp_path / "o.h5"))
    # (pymavlink hands TimeUS over as a float: 2^64 − 1 arrives rounded to 2^64.)
    assert r.code == 2 and "IMU TimeUS: time stamp 18446744073709551616 out of range" in r.err, r.err
    assert "Traceback" not in r.err


def test_a_file_that_is_not_a_dataflash_log_is_one_message_not_the_readers_noise(tmp_path):
    pytest.importorskip("pymavlink")
    rng = np.random.default_rng(42)
    bad = tmp_path / "random.bin"
    bad.write_bytes(rng.integers(0, 256, 200_000, dtype=np.uint8).tobytes())
    r = run_cli("import", "dataflash", str(bad), "--out", str(tmp_path / "o.h5"))
    # Before: pymavlink printed a "bad header" line per damaged header (tens of thousands) on stdout.
    assert r.code == 2 and r.out == "", r.out[:500]
    assert r.err.count("\n") == 1 and f"sins-fw: error: {bad}: " in r.err, r.err[:2000]
    assert "expected an ArduPilot" in r.err


def test_ulog_time_stamps_beyond_the_range_are_exit_2(tmp_path):
    pytest.importorskip("pyulog")
    m = _ned_motion()
    t = m["t_us"].astype(np.uint64)
    t[-1] = 2**63 + 5  # a uint64 beyond int64: before, a silent wrap to a negative time
    write_ulog(
        tmp_path / "f.ulg",
        [
            (
                "sensor_combined",
                [("uint64_t", "timestamp", 0), ("float", "gyro_rad", 3), ("float", "accelerometer_m_s2", 3)],
                {"timestamp": t, "gyro_rad": m["gyro"], "accelerometer_m_s2": m["accel"]},
            )
        ],
    )
    r = run_cli("import", "ulog", str(tmp_path / "f.ulg"), "--out", str(tmp_path / "o.h5"))
    assert r.code == 2 and f"time stamp {2**63 + 5} out of range" in r.err, r.err


def test_a_ulog_whose_name_is_not_utf8_imports_with_the_name_escaped(tmp_path):
    pytest.importorskip("pyulog")
    import os

    name = os.fsdecode(b"vol_caf\xe9.ulg")  # Latin-1 bytes in a file name
    _ulog(tmp_path / name)
    out = tmp_path / "o.h5"
    r = subprocess.run(
        [sys.executable, "-m", "sins_fw", "import", "ulog", tmp_path / name, "--out", out],
        capture_output=True,
        check=False,
    )
    # Before: UnicodeEncodeError writing the metadata (exit 3).
    assert r.returncode == 0, r.stderr
    assert PhysicalTrace.load(out).metadata["source"] == "PX4 ULog vol_caf\\xe9.ulg"
    assert b"vol_caf\xe9.ulg" in r.stdout  # the report names the file by its own bytes, as ls does


@pytest.mark.parametrize("value", ["nan", "inf", "-1", "11", "abc"])
def test_gps_latency_that_is_not_0_to_10_s_is_refused_before_reading(tmp_path, value):
    # Before: nan was accepted silently when the log had no GPS (the check compared with nan).
    (tmp_path / "log.ulg").write_bytes(b"not read")
    r = run_cli(
        "import", "ulog", str(tmp_path / "log.ulg"), "--gps-latency-s", value, "--out", str(tmp_path / "o.h5")
    )
    assert r.code == 2 and "--gps-latency-s" in r.err and "0…10 s" in r.err, r.err
    from sins_fw.importers import importer

    with pytest.raises(InputError, match="gps_latency_s"):
        importer("ulog")(tmp_path / "log.ulg", gps_latency_s=float(value) if value != "abc" else value)
