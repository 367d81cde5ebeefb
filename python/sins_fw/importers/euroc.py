"""EuRoC-style CSV (the EuRoC MAV dataset's ASL layout): ``imu0/data.csv`` with
``#timestamp [ns], w_RS_S_x [rad s^-1] … a_RS_S_z [m s^-2]`` and, when present,
``state_groundtruth_estimate0/data.csv`` with ``q_RS_w … q_RS_z`` (the sensor frame S in the ground
truth's frame R). Columns are found by name; the units are the ones in the names."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from sins_fw.errors import TraceError, utf8_text
from sins_fw.importers import PathLike, check_file, interpolate_truth, make_trace, stamp_array
from sins_fw.traces import G0, PhysicalTrace

_IMU = ("w_RS_S_x", "w_RS_S_y", "w_RS_S_z", "a_RS_S_x", "a_RS_S_y", "a_RS_S_z")
_TRUTH = ("q_RS_w", "q_RS_x", "q_RS_y", "q_RS_z")
FRAME = (
    "sensor axes = the EuRoC sensor frame S as logged (no rotation); truth C_S^R in the ground truth's "
    "frame R (z up, x and y not east and north: compare headings with --align heading or initial)"
)


def _find(path: Path) -> tuple[Path, Path | None]:
    """The IMU file and the ground-truth file (None when absent) of a folder or an IMU file."""
    if path.is_file():
        return path, None
    for root in (path, path / "mav0"):
        imu = root / "imu0" / "data.csv"
        if imu.is_file():
            gt = root / "state_groundtruth_estimate0" / "data.csv"
            return imu, gt if gt.is_file() else None
    raise TraceError(f"{path}: no imu0/data.csv here or in mav0/; expected a EuRoC-style folder or CSV")


def _text(path: Path) -> str:
    """The CSV's text: binary data and bytes that are not UTF-8 are an error naming the line."""
    data = path.read_bytes()
    nul = data.find(b"\0")
    if nul >= 0:
        line = data.count(b"\n", 0, nul) + 1
        raise TraceError(
            f"{path}: binary data (NUL byte at offset {nul}, line {line}); expected a EuRoC-style CSV "
            "text file"
        )
    return utf8_text(data, path, "a EuRoC-style CSV (ASCII numbers)", TraceError)


def _read(path: Path, names: tuple[str, ...]) -> tuple[np.ndarray, np.ndarray]:
    """The time stamps (integer ns, exact) and the named columns (float) of a EuRoC CSV."""
    text = _text(path)
    lines = text.splitlines()
    header = lines[0] if lines else ""
    columns = [c.strip().lstrip("#").split("[")[0].strip() for c in header.split(",")]
    if not columns or columns[0] != "timestamp":
        raise TraceError(
            f"{path}: line 1: first column `{columns[0] if columns else ''}`; expected `#timestamp [ns]` "
            "(a EuRoC-style CSV)"
        )
    missing = [n for n in names if n not in columns]
    if missing:
        raise TraceError(
            f"{path}: line 1: missing column `{missing[0]}`; expected {', '.join(names)} "
            f"(found {', '.join(columns)})"
        )
    if not any(line.strip() for line in lines[1:]):
        raise TraceError(f"{path}: header only, no data rows; expected one row per sample after line 1")
    try:
        table = np.loadtxt(io.StringIO(text), delimiter=",", skiprows=1, comments=None, dtype=str, ndmin=2)
        values = table[:, [columns.index(n) for n in names]].astype(np.float64)
    except (ValueError, IndexError) as e:
        raise TraceError(f"{path}: not numbers where numbers were expected ({e})") from None
    return stamp_array(list(table[:, 0]), path, "ns"), values


def import_euroc(path: PathLike, truth: PathLike | None = None) -> PhysicalTrace:
    """A EuRoC-style IMU log (a folder holding ``imu0/data.csv``, or that file) as a physical trace,
    with the ground truth (``truth``, or the folder's ``state_groundtruth_estimate0/data.csv``)."""
    p = check_file(path, "EuRoC folder or CSV")
    imu, gt = _find(p)
    if truth is not None:
        gt = check_file(truth, "ground-truth CSV")
    stamps, values = _read(imu, _IMU)
    order = np.argsort(stamps, kind="stable")
    stamps, values = stamps[order], values[order]
    keep = np.concatenate([[True], np.diff(stamps) > 0])
    stamps, values = stamps[keep], values[keep]
    t0 = int(stamps[0])
    t = (stamps - t0).astype(np.float64) * 1e-9
    truth_q = None
    if gt is not None:
        gt_stamps, q = _read(gt, _TRUTH)
        order = np.argsort(gt_stamps, kind="stable")
        truth_q = interpolate_truth(t, (gt_stamps[order] - t0).astype(np.float64) * 1e-9, q[order])
    metadata = {
        "source": f"EuRoC-style CSV {imu.name} in {imu.parent}",
        "source_file": str(imu),
        "generator": f"sins-fw import euroc {p.name}",
        "frame": FRAME,
        "units": "w_RS_S rad/s → °/s, a_RS_S m/s² → g",
        "truth": (
            f"q_RS from {gt.parent.name}/{gt.name}, interpolated (normalised linear) at the IMU times; NaN "
            "outside its span"
            if gt is not None
            else "none (no ground-truth file)"
        ),
    }
    return make_trace(
        t_abs=t,
        origin=f"t_s = 0 at the IMU's time stamp {t0} ns",
        gyro_dps=np.degrees(values[:, :3]),
        accel_g=values[:, 3:] / G0,
        mag_gauss=None,
        truth_q=truth_q,
        metadata=metadata,
        where=str(imu),
        gps="none: EuRoC-style logs hold no GPS",
    )
