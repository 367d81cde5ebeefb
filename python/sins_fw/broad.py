"""Import a BROAD trial (Laidig et al., "BROAD — A Benchmark for Robust Inertial Orientation
Estimation", Data 6(7), 2021, CC BY 4.0) as a physical trace.

Conversions: ``imu_gyr`` rad/s → °/s, ``imu_acc`` m/s² → g (g0 = 9.80665 m/s²), ``imu_mag`` µT →
gauss (1 gauss = 100 µT). ``opt_quat`` is the IMU frame's orientation w.r.t. the optical ENU frame as
a Hamilton quaternion with v_ENU = q ⊗ v_IMU ⊗ q*: that is C_b^n with n = ENU, the firmware's
convention, so it is copied unchanged (docs/traces.md shows how this was checked against the data:
q rotates the still accelerometer reading to +z, and q_k* ⊗ q_k+1 matches the body-frame gyro).
Rows where the markers were lost keep their IMU samples and get NaN truth. ``movement`` becomes
``moving``. The sample rate, 285.714… Hz in the file, is the exact ratio 2000/7 Hz.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from fractions import Fraction
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from sins_fw import earth
from sins_fw.errors import TraceError
from sins_fw.traces import ATTITUDE_ONLY_KEY, PhysicalTrace, _concat, file_sha256, validated

_DATASETS = {"imu_gyr": 3, "imu_acc": 3, "imu_mag": 3, "opt_quat": 4, "movement": 0}
#: Largest denominator accepted when recovering the exact sample rate from the stored float.
_RATE_DENOMINATOR = 1000
MICROTESLA_PER_GAUSS = 100.0


def exact_rate(rate: float, where: str) -> Fraction:
    """The simple fraction a stored float sample rate stands for (2000/7 for 285.7142857142857)."""
    if not np.isfinite(rate) or rate <= 0:
        raise TraceError(f"{where}: attribute `sampling_rate` is {rate}; expected a positive rate in Hz")
    frac = Fraction(rate).limit_denominator(_RATE_DENOMINATOR)
    if abs(float(frac) - rate) > 1e-12 * rate:
        frac = Fraction(rate)  # no simple ratio: keep the float's exact value
    return frac


def import_broad(path: str | os.PathLike[str]) -> PhysicalTrace:
    """Read one BROAD ``.hdf5`` trial and return it as a physical trace (validated)."""
    return _concat(PhysicalTrace, iter_broad(path, rows=None))


def iter_broad(path: str | os.PathLike[str], rows: int | None = 1 << 16) -> Iterator[PhysicalTrace]:
    """One BROAD ``.hdf5`` trial as consecutive physical-trace chunks of at most ``rows`` rows (all
    of them in one when None), read from the file a chunk at a time and validated as they pass: the
    chunks of :func:`import_broad`'s trace, value for value. The file's structure (datasets, shapes,
    lengths, sampling rate) is checked before the first chunk."""
    p = Path(path)
    if not p.is_file():
        raise TraceError(f"{p}: no such BROAD file")
    try:
        f = h5py.File(p, "r")
    except OSError as e:
        raise TraceError(f"{p}: not a readable HDF5 file ({e}); expected a BROAD trial (.hdf5)") from None
    with f:
        datasets = {}
        for name, width in _DATASETS.items():
            if name not in f:
                raise TraceError(
                    f"{p}: dataset `{name}` is missing; expected a BROAD trial ({', '.join(_DATASETS)})"
                )
            ds = f[name]
            shape = ds.shape
            shape_ok = len(shape) == 1 if width == 0 else len(shape) == 2 and shape[1] == width
            if not shape_ok:
                want = "(N,)" if width == 0 else f"(N, {width})"
                raise TraceError(f"{p}: dataset `{name}` has shape {shape}; expected {want}")
            datasets[name] = ds
        n = datasets["imu_gyr"].shape[0]
        for name, ds in datasets.items():
            if ds.shape[0] != n:
                raise TraceError(f"{p}: dataset `{name}` has {ds.shape[0]} rows; expected {n} like `imu_gyr`")
        if "sampling_rate" not in f.attrs:
            raise TraceError(f"{p}: attribute `sampling_rate` is missing")
        rate = exact_rate(float(f.attrs["sampling_rate"]), str(p))
        info = f.attrs.get("info", "")
        info = info.decode() if isinstance(info, bytes) else str(info)
        trial = next(
            (line.split(":", 1)[1].strip() for line in info.splitlines() if line.startswith("Trial:")), p.stem
        )
        metadata = {
            "sample_rate_hz": f"{rate.numerator}/{rate.denominator}"
            if rate.denominator != 1
            else str(rate.numerator),
            "source": f"BROAD trial {trial} (Laidig et al. 2021, doi:10.3390/data6070072, CC BY 4.0)",
            "source_file": p.name,
            "source_sha256": file_sha256(p),
            "generator": f"sins-fw import broad {p.name}",
            "frame": "sensor axes = IMU axes (myon aktos-t); truth C_b^n w.r.t. the optical ENU frame",
            "g0_m_s2": repr(earth.G0),
            "truth": "opt_quat unchanged (Hamilton, v_ENU = q v_IMU q*); NaN rows: markers lost",
            # Attitude only: no position truth or aiding; `run` does not navigate it by default.
            ATTITUDE_ONLY_KEY: "true",
        }
        step = max(n, 1) if rows is None else rows
        chunks = (_chunk(p, datasets, lo, min(lo + step, n), rate, metadata) for lo in range(0, n, step))
        try:
            yield from validated(chunks)
        except TraceError as e:
            if str(e).startswith(f"{p}:"):
                raise
            raise TraceError(f"{p}: the imported trace is invalid: {e}") from None


def _chunk(
    p: Path, datasets: dict[str, Any], lo: int, hi: int, rate: Fraction, metadata: dict[str, str]
) -> PhysicalTrace:
    """Rows ``lo``..``hi`` of a BROAD trial, converted (see the module doc)."""
    arrays = {name: ds[lo:hi] for name, ds in datasets.items()}
    for name in ("imu_gyr", "imu_acc", "imu_mag"):
        bad = ~np.isfinite(arrays[name])
        if bad.any():
            row, col = np.argwhere(bad)[0]
            raise TraceError(
                f"{p}: dataset `{name}`, row {lo + row}, column {col}: {arrays[name][row, col]}; expected "
                "finite"
            )
    truth = np.array(arrays["opt_quat"], dtype=np.float64)
    truth[np.isnan(truth).any(axis=1)] = np.nan  # a lost marker loses the whole attitude
    i = np.arange(lo, hi, dtype=np.int64)
    return PhysicalTrace(
        t_s=(i * rate.denominator).astype(np.float64) / float(rate.numerator),
        gyro_dps=np.degrees(arrays["imu_gyr"].astype(np.float64)),
        accel_g=arrays["imu_acc"].astype(np.float64) / earth.G0,
        mag_gauss=arrays["imu_mag"].astype(np.float64) / MICROTESLA_PER_GAUSS,
        truth_q=truth,
        moving=arrays["movement"].astype(bool),
        metadata=metadata,
    )
