"""ArduPilot DataFlash logs (.bin, read with pymavlink's DFReader): ``IMU`` instance 0 (GyrX…Z rad/s,
AccX…Z m/s², TimeUS µs), ``MAG`` instance 0 (MagX…Z, milligauss) and ``ATT`` (Roll, Pitch, Yaw in
degrees: the autopilot's estimate) and ``GPS`` instance 0 (3D fixes, Status ≥ 3: Spd m/s, GCrs °,
Lat and Lng °, Alt m above mean sea level, taken as the height), all in ArduPilot's FRD body axes and
NED earth frame."""

from __future__ import annotations

import contextlib
import io
import os
import sys
import tempfile
from collections.abc import Iterator
from typing import Any

import numpy as np

from sins_fw import importers as imp
from sins_fw import quaternion
from sins_fw.errors import TraceError
from sins_fw.importers import DEFAULT_GPS_LATENCY_S, PathLike
from sins_fw.traces import PhysicalTrace

MILLIGAUSS = 1e-3
_FIELDS = {
    "IMU": ("GyrX", "GyrY", "GyrZ", "AccX", "AccY", "AccZ"),
    "MAG": ("MagX", "MagY", "MagZ"),
    "ATT": ("Roll", "Pitch", "Yaw"),
    "GPS": ("Status", "Spd", "GCrs", "Lat", "Lng", "Alt"),
}


class _Lines(io.TextIOBase):
    """A text sink that counts the lines written to it and keeps the first."""

    def __init__(self) -> None:
        super().__init__()
        self.count = 0
        self.first = ""
        self._partial = ""

    def writable(self) -> bool:
        return True

    def write(self, text: str) -> int:
        self._partial += text
        *lines, rest = self._partial.split("\n")
        self._partial = rest[-4096:]
        for line in lines:
            if line.strip():
                self.count += 1
                self.first = self.first or line.strip()
        return len(text)

    def said(self) -> str:
        """What pymavlink complained of, for a message: ``; N lines such as `...```."""
        if not self.count:
            return ""
        more = f" and {self.count - 1} more" if self.count > 1 else ""
        return f"; the reader said `{self.first}`{more}"


@contextlib.contextmanager
def _c_stderr_into(lines: _Lines) -> Iterator[None]:
    """The process's standard error (file descriptor 2: pymavlink's compiled indexer writes there
    directly, past Python's sys.stderr) into a temporary file for the block, then counted into
    ``lines``."""
    try:
        fd = sys.stderr.fileno()
    except (AttributeError, OSError, ValueError):
        yield  # no descriptor to take (an embedding without one): nothing is written there either
        return
    sys.stderr.flush()
    saved = os.dup(fd)
    with tempfile.TemporaryFile() as held:
        os.dup2(held.fileno(), fd)
        try:
            yield
        finally:
            os.dup2(saved, fd)
            os.close(saved)
            held.seek(0)
            for block in iter(lambda: held.read(1 << 16), b""):
                lines.write(block.decode("utf-8", "replace"))


def _instance(m: Any) -> int:
    """The sensor instance of an IMU or MAG message (logs before instances existed: 0)."""
    return int(getattr(m, "I", 0) or 0)


def import_dataflash(path: PathLike, gps_latency_s: float = DEFAULT_GPS_LATENCY_S) -> PhysicalTrace:
    """An ArduPilot DataFlash log as a physical trace."""
    dfreader = imp.need("pymavlink.DFReader", "pymavlink", "dataflash")

    p = imp.check_file(path, "DataFlash log")
    rows: dict[str, list[tuple[int, tuple[float, ...]]]] = {k: [] for k in _FIELDS}
    # pymavlink prints a line per damaged message header on stdout (tens of thousands for a file that
    # is not a log): they are counted here, and said once in the error or not at all.
    noise = _Lines()
    try:
        with _c_stderr_into(noise), contextlib.redirect_stdout(noise), contextlib.redirect_stderr(noise):  # type: ignore[type-var]
            log = dfreader.DFReader_binary(str(p), zero_time_base=False)
            try:
                while (m := log.recv_match(type=list(_FIELDS))) is not None:
                    kind = m.get_type()
                    if kind in ("IMU", "MAG", "GPS") and _instance(m):
                        continue
                    rows[kind].append((m.TimeUS, tuple(float(getattr(m, f)) for f in _FIELDS[kind])))
            finally:
                log.close()  # its file and memory map: left to the collector, a ResourceWarning later
    except Exception as e:  # pymavlink raises assorted errors on what is not a DataFlash log
        raise TraceError(
            f"{p}: not a readable DataFlash log ({e}{noise.said()}); expected an ArduPilot .bin log"
        ) from None
    if not rows["IMU"]:
        why = f" ({noise.said().removeprefix('; ')})" if noise.count else ""
        raise TraceError(f"{p}: no IMU messages (instance 0){why}; expected an ArduPilot log with IMU data")

    def arrays(kind: str) -> tuple[np.ndarray, np.ndarray]:
        t = imp.stamp_array([r[0] for r in rows[kind]], f"{p}: {kind} TimeUS", "µs")
        v = np.array([r[1] for r in rows[kind]], dtype=np.float64)
        return imp.ascending(t, v)  # type: ignore[return-value]

    t_us, imu = arrays("IMU")
    t0 = int(t_us[0])
    t = imp.seconds_since(t_us, t0)
    mag, truth = None, None
    if rows["MAG"]:
        tm, m = arrays("MAG")
        mag = imp.interpolate(t, imp.seconds_since(tm, t0), m) * MILLIGAUSS
    if rows["ATT"]:
        ta, att = arrays("ATT")
        q_ned = quaternion.from_euler(*np.radians(att).T)
        truth = imp.interpolate_truth(t, imp.seconds_since(ta, t0), q_ned)
    gps: Any = "none (no GPS messages)"
    if rows["GPS"]:
        tg = imp.stamp_array([r[0] for r in rows["GPS"]], f"{p}: GPS TimeUS", "µs")
        g = np.array([r[1] for r in rows["GPS"]], dtype=np.float64)
        fix = g[:, 0] >= 3
        source = (
            f"GPS instance 0 (Spd, GCrs, Lat, Lng; Alt above mean sea level taken as the height; "
            f"{int((~fix).sum())} messages without a 3D fix left out)"
        )
        gps = imp.gps_stream(
            t_us, tg[fix], g[fix, 1:], ticks_per_s=1_000_000, latency_s=gps_latency_s, source=source
        )
    return imp.frd_ned_trace(
        kind="dataflash",
        source="ArduPilot DataFlash log",
        path=p,
        t_abs=t,
        origin=f"t_s = 0 at the log's IMU TimeUS {t0} µs",
        gyro_rad_s=imu[:, :3],
        accel_m_s2=imu[:, 3:],
        mag_gauss=mag,
        truth_q_ned=truth,
        gps=gps,
        units="IMU Gyr rad/s → °/s, Acc m/s² → g, MAG milligauss → gauss (instance 0 of each)",
        magnetometer="MAG instance 0, interpolated linearly at the IMU times"
        if mag is not None
        else "none (no MAG messages)",
        truth="ATT Roll, Pitch, Yaw (Z-Y-X Euler angles, FRD → NED): the autopilot's estimate "
        "(EKF), not "
        "an independent truth; interpolated (normalised linear) at the IMU times, NaN outside"
        if truth is not None
        else "none (no ATT messages)",
        where=f"{p}: IMU",
    )
