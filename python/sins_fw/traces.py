"""Trace files: the physical trace (what the sensor sees) and the raw-register trace (what the bus
carries). Both come as CSV with a metadata header (``.csv``) or as columnar HDF5 (``.h5``); the
format, with every column, unit and rule, is documented in docs/traces.md. This module declares the
two formats (their :class:`~sins_fw.tablefile.Schema` and their own checks: truth quaternion, GPS
stream, plausibility of units) and the trace types; the file engine is :mod:`sins_fw.tablefile`.

Loading validates everything and raises :class:`~sins_fw.errors.TraceError` with a message naming
the file, the line (CSV) or row, the column, and what was expected versus found. Rows are counted
from 0 (the first data row is row 0); CSV line numbers from 1.
"""

from __future__ import annotations

import hashlib
import math
import warnings
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass, field, fields, replace
from fractions import Fraction
from pathlib import Path
from typing import Any, ClassVar, Self, TypeVar

import h5py
import numpy as np
from numpy.typing import NDArray

from sins_fw import _core
from sins_fw.errors import TraceError, TraceWarning
from sins_fw.tablefile import (
    BLOCK_ROWS,
    DEFAULT_MAX_GAP_PERIODS,
    G0,
    Array,
    Checker,
    Column,
    Field,
    PathLike,
    ReadOptions,
    Schema,
    check_metadata,
    csv_separator,
    open_table,
    parse_rate,
    read_metadata,
    table_extension,
    write_table,
)

PHYSICAL_FORMAT = "sins-fw-physical-trace/1"
RAW_FORMAT = "sins-fw-raw-register-trace/1"
#: The metadata key that marks a physical trace attitude-only (``true``: a recording with no
#: navigation aiding and a truth of attitude only, as ``sins-fw import broad`` writes): ``sins-fw run``
#: then runs it with :data:`ATTITUDE_ONLY_SETTING` unless ``--set firmware.navigation=…`` is given
#: (the free-inertial vertical channel would run away: a `state_out_of_range` error).
ATTITUDE_ONLY_KEY = "attitude_only"
#: The setting of an attitude-only run.
ATTITUDE_ONLY_SETTING = "firmware.navigation=false"
#: Allowed deviation of a truth quaternion's norm from 1 (float64 data, written with full precision).
TRUTH_NORM_TOLERANCE = 1e-6


def _index(i: Any) -> int | tuple[int, ...]:
    """A numpy index as plain integers, for messages: (1, 3), not (np.int64(1), np.int64(3))."""
    return tuple(int(k) for k in i) if isinstance(i, tuple) else int(i)


def _axes(prefix: str, suffix: str, unit: str, what: str, required: bool) -> list[Column]:
    return [
        Column(f"{prefix}_{a}_{suffix}", unit, f"{what}, sensor {a} axis", group=prefix, required=required)
        for a in "xyz"
    ]


PHYSICAL_COLUMNS: tuple[Column, ...] = (
    Column("t_s", "s", "sample time"),
    *_axes("gyro", "dps", "°/s", "angular rate ω_ib", True),
    *_axes("accel", "g", "g (9.80665 m/s²)", "specific force", True),
    *_axes("mag", "gauss", "gauss", "magnetic field", False),
    Column("baro_mbar", "mbar", "barometric pressure", group="baro", required=False),
    Column("temp_c", "°C", "sensor temperature", group="temp", required=False),
    *(
        Column(
            f"truth_q{c}",
            "1",
            f"truth quaternion component {c} (C_b^n, ENU)",
            group="truth",
            required=False,
            nan_allowed=True,
        )
        for c in "wxyz"
    ),
    Column(
        "moving", "0/1", "1 where the body moves relative to the navigation frame", "flag", "moving", False
    ),
    Column(
        "truth_alpha_deg",
        "°",
        "truth hinge angle α from the zero pose (wing scenario)",
        group="truth_alpha",
        required=False,
        nan_allowed=True,
    ),
    *(
        Column(
            name,
            unit,
            f"{what}; a row of five NaN: no fix at this sample",
            group="gps",
            required=False,
            nan_allowed=True,
        )
        for name, unit, what in (
            ("gps_speed_mps", "m/s", "GPS ground speed"),
            ("gps_course_deg", "°", "GPS course over ground, clockwise from true north (0 ≤ c < 360)"),
            ("gps_lat_deg", "°", "GPS latitude, WGS-84"),
            ("gps_lon_deg", "°", "GPS longitude, WGS-84"),
            ("gps_height_m", "m", "GPS height above the WGS-84 ellipsoid"),
        )
    ),
    *(
        Column(
            f"array{p}_{a}_g",
            "g (9.80665 m/s²)",
            f"specific force at the gyro-free array's ADXL345 #{p} ({'centre' if p == 7 else 'outer'}), "
            f"part {a} axis = body {a} axis (vehicle scenario)",
            group="array",
            required=False,
        )
        for p in range(1, 8)
        for a in "xyz"
    ),
)
#: The GPS stream's columns (:func:`check_gps`).
GPS_COLUMNS: tuple[str, ...] = (
    "gps_speed_mps",
    "gps_course_deg",
    "gps_lat_deg",
    "gps_lon_deg",
    "gps_height_m",
)
#: Each GPS column's allowed range (closed, except the course's upper end).
_GPS_RANGES: dict[str, tuple[float, float, str]] = {
    "gps_speed_mps": (0.0, math.inf, "≥ 0 m/s"),
    "gps_course_deg": (0.0, 360.0, "0 ≤ course < 360°"),
    "gps_lat_deg": (-90.0, 90.0, "−90…90°"),
    "gps_lon_deg": (-180.0, 180.0, "−180…180°"),
    "gps_height_m": (-1.0e4, 1.0e5, "−10 000…100 000 m"),
}

#: The part whose burst read a raw-register trace records: the format is the ADIS16407's burst
#: (its command answer and 14 output registers, docs/traces.md "Raw-register trace"), whatever part
#: a profile declares.
RAW_PART = "ADIS16407"
#: The 15 DOUT words of one burst read, in bus order: the don't-care answer to the burst command
#: frame (0x4200), then the registers :data:`RAW_PART`'s declaration in the Rust core lists for its
#: burst (`_core.PARTS`), named in lower case (0x02…0x1C: ``supply_out`` … ``aux_adc``).
RAW_WORD_COLUMNS: tuple[str, ...] = ("frame0", *(name.lower() for name in _core.PARTS[RAW_PART]["burst"]))
RAW_COLUMNS: tuple[Column, ...] = (
    Column("t_s", "s", "time of the burst's chip-select falling edge"),
    *(
        Column(n, "16-bit word", f"DOUT word {i} of the burst", kind="word")
        for i, n in enumerate(RAW_WORD_COLUMNS)
    ),
)

# ---------------------------------------------------------------------------------------------------
# Plausibility of a physical trace read from another program's file (docs/traces.md)
# ---------------------------------------------------------------------------------------------------

#: Rows over which the specific force's median magnitude is taken.
ACCEL_ROWS = 4096
#: A factor around a unit's ratio inside which a value "looks like" the other unit: the geometric
#: middle between the right unit (1) and the wrong one (9.81 for g/m/s², 57.3 for °/s / rad/s) is
#: √9.81 ≈ 3.1 and √57.3 ≈ 7.6; 1.5 stays well inside both.
_LOOKS_LIKE = 1.5
#: The largest full scale of MEMS gyros (°/s): a rate above it read as rad/s is °/s.
GYRO_MAX_DPS = 2000.0
#: Length of the segments whose mean specific-force directions are compared with the gyro's turning.
_SEGMENT_S = 0.5
#: The accelerometer must turn through at least this much (°) before the gyro is judged by it.
_MIN_TURN_DEG = 10.0


@dataclass
class _Plausibility:
    """Warnings for units that read but look wrong (docs/traces.md, 'Reading other files'): 9.8 g at
    rest (m/s² in `_g` columns) and 0.1 g (g in `_m_s2` columns); a gyro that turns far less than the
    accelerometer's direction does (rad/s in `_dps` columns) or faster than any MEMS gyro (°/s in
    `_rad_s` columns)."""

    src: str
    period_s: float
    fields: dict[str, Field]
    accel: list[Array] = field(default_factory=list)
    accel_rows: int = 0
    accel_done: bool = False
    seg_acc: list[Array] = field(default_factory=list)
    seg_gyro: list[Array] = field(default_factory=list)
    last_dir: Array | None = None
    last_bound_deg: float = 0.0
    turn_deg: float = 0.0
    bound_deg: float = 0.0
    peak_dps: float = 0.0
    warned: set[str] = field(default_factory=set)

    def add(self, cols: Mapping[str, np.ndarray]) -> None:
        with np.errstate(over="ignore", invalid="ignore"):  # values near the float limit: inf is fine
            self._add(cols)

    def _add(self, cols: Mapping[str, np.ndarray]) -> None:
        f = np.stack([cols[f"accel_{a}_g"] for a in "xyz"], axis=1)
        w = np.stack([cols[f"gyro_{a}_dps"] for a in "xyz"], axis=1)
        if not self.accel_done:
            self.accel.append(np.linalg.norm(f, axis=1))
            self.accel_rows += len(f)
            if self.accel_rows >= ACCEL_ROWS:
                self._check_accel()
        if len(w):
            self.peak_dps = max(self.peak_dps, float(np.max(np.linalg.norm(w, axis=1))))
        self.seg_acc.append(f)
        self.seg_gyro.append(np.linalg.norm(w, axis=1))
        self._segments(final=False)

    def finish(self) -> None:
        with np.errstate(over="ignore", invalid="ignore"):
            if not self.accel_done:
                self._check_accel()
            self._segments(final=True)
        gyro = self.fields.get("gyro_x_dps")
        if gyro is None:
            return
        if gyro.unit != "dps" and self.peak_dps > GYRO_MAX_DPS:
            self._warn(
                "gyro",
                f"a rate of {self.peak_dps:.4g} °/s (read in {gyro.unit}) is beyond any MEMS gyro's range "
                f"(±{GYRO_MAX_DPS:g} °/s): the gyro columns look like °/s; name them `gyro_x_dps` … or "
                "give --units gyro=dps",
            )
        ratio = math.sqrt(180.0 / math.pi)
        if gyro.unit == "dps" and self.turn_deg > _MIN_TURN_DEG and self.turn_deg > ratio * self.bound_deg:
            self._warn(
                "gyro",
                f"the specific force turned through {self.turn_deg:.4g}° in all while the gyro rates (read "
                f"in °/s) allow at most {self.bound_deg:.4g}°: the gyro columns look like rad/s; name them "
                "`gyro_x_rad_s` … or give --units gyro=rad/s",
            )

    def _check_accel(self) -> None:
        self.accel_done = True
        if not self.accel:
            return
        norms = np.concatenate(self.accel)[:ACCEL_ROWS]
        self.accel = []
        accel = self.fields.get("accel_x_g")
        if accel is None or not len(norms):
            return
        m = float(np.median(norms))
        rows = f"the median magnitude of the specific force over rows 0…{len(norms) - 1}"
        if accel.unit == "g" and G0 / _LOOKS_LIKE <= m <= G0 * _LOOKS_LIKE:
            self._warn(
                "accel",
                f"{rows} is {m:.4g} g, where at rest or in ordinary motion it is about 1 g: the accel "
                "columns look like m/s²; name them `accel_x_m_s2` … or give --units accel=m/s2",
            )
        elif accel.unit != "g" and 1 / (G0 * _LOOKS_LIKE) <= m <= _LOOKS_LIKE / G0:
            self._warn(
                "accel",
                f"{rows} is {m * G0:.4g} m/s² (read in {accel.unit}), where at rest or in ordinary motion "
                "it is about 9.81 m/s²: the accel columns look like g; name them `accel_x_g` … or give "
                "--units accel=g",
            )

    def _segments(self, final: bool) -> None:
        """Compare the turning of the mean specific force from one segment to the next with the gyro's
        bound on the turning over the two segments (∫|ω| dt; a rotation turns a vector by at most it)."""
        n = max(2, round(_SEGMENT_S / self.period_s))
        acc = np.concatenate(self.seg_acc) if self.seg_acc else np.zeros((0, 3))
        gyro = np.concatenate(self.seg_gyro) if self.seg_gyro else np.zeros(0)
        k = len(acc) // n
        self.seg_acc = [acc[k * n :]] if not final else []
        self.seg_gyro = [gyro[k * n :]] if not final else []
        if not k:
            return
        means = acc[: k * n].reshape(k, n, 3).mean(axis=1)
        bounds = gyro[: k * n].reshape(k, n).sum(axis=1) * self.period_s
        norms = np.linalg.norm(means, axis=1)
        dirs = means / np.where(norms > 0, norms, 1.0)[:, None]
        if self.last_dir is not None:
            dirs = np.vstack([self.last_dir, dirs])
            bounds = np.concatenate([[self.last_bound_deg], bounds])
        if len(dirs) > 1:
            cos = np.einsum("ij,ij->i", dirs[:-1], dirs[1:])
            sin = np.linalg.norm(np.cross(dirs[:-1], dirs[1:]), axis=1)
            self.turn_deg += float(np.degrees(np.arctan2(sin, cos)).sum())
            self.bound_deg += float((bounds[:-1] + bounds[1:]).sum())
        self.last_dir = dirs[-1]
        self.last_bound_deg = float(bounds[-1])

    def _warn(self, key: str, text: str) -> None:
        if key not in self.warned:
            self.warned.add(key)
            warnings.warn(f"{self.src}: {text}", TraceWarning, stacklevel=4)


def check_truth(checker: Checker, cols: Mapping[str, np.ndarray], row0: int) -> None:
    """The truth quaternion of a block of rows (one of :attr:`Schema.checks` of the tables with truth
    columns): all four components NaN (missing truth) or none, and unit norm."""
    if "truth_qw" not in cols:
        return
    q = np.stack([cols[f"truth_q{c}"] for c in "wxyz"], axis=1)
    nan = np.isnan(q)
    partial = nan.any(axis=1) & ~nan.all(axis=1)
    if partial.any():
        i = int(np.argmax(partial))
        raise TraceError(
            f"{checker.src}: {checker.where(row0 + i)}, "
            f"column `truth_q{'wxyz'[int(np.argmax(nan[i]))]}`: "
            "NaN in only some truth components; expected all four NaN (missing truth) or none"
        )
    norm = np.linalg.norm(q, axis=1)
    bad = np.abs(norm - 1.0) > TRUTH_NORM_TOLERANCE  # NaN rows compare False
    if bad.any():
        i = int(np.argmax(bad))
        raise TraceError(
            f"{checker.src}: {checker.where(row0 + i)}, column `truth_qw`: "
            "the truth quaternion has norm "
            f"{norm[i]:.9g}; expected a unit quaternion (|norm − 1| ≤ {TRUTH_NORM_TOLERANCE:g})"
        )


def _check_gps_rows(checker: Checker, cols: Mapping[str, np.ndarray], row0: int) -> None:
    """The GPS stream of a block of rows, and its metadata keys with the first block."""
    if GPS_COLUMNS[0] not in cols:
        return
    if row0 == 0:
        gps_latency_s(checker.metadata, f"{checker.src}: metadata")
    check_gps(cols, lambda i: f"{checker.src}: {checker.where(row0 + i)}")


PHYSICAL_SCHEMA = Schema(
    "physical trace",
    PHYSICAL_FORMAT,
    PHYSICAL_COLUMNS,
    checks=(check_truth, _check_gps_rows),
    plausibility=_Plausibility,
    unknown_hint="; a file with other names can be read with --columns",
)
RAW_SCHEMA = Schema("raw-register trace", RAW_FORMAT, RAW_COLUMNS)


# ---------------------------------------------------------------------------------------------------
# The trace types
# ---------------------------------------------------------------------------------------------------


class _TraceFile:
    """File I/O shared by the trace types: a subclass gives ``schema``, ``columns()`` and
    ``from_columns()``; this writes and reads it in either form, validated the same way."""

    schema: ClassVar[Schema]
    metadata: dict[str, str]

    def columns(self) -> dict[str, np.ndarray]:
        raise NotImplementedError

    @classmethod
    def from_columns(cls, cols: Mapping[str, np.ndarray], metadata: Mapping[str, str]) -> Self:
        raise NotImplementedError

    def validate(self, *, allow_gaps: bool = False, max_gap_periods: float = DEFAULT_MAX_GAP_PERIODS) -> None:
        """The checks a file gets on load, for a trace built in memory."""
        for _ in validated([self], allow_gaps=allow_gaps, max_gap_periods=max_gap_periods):
            pass

    def save(self, path: PathLike, *, allow_gaps: bool = False) -> None:
        """Write as CSV (``.csv``; raw words as ``0xABCD``) or HDF5 (``.h5``), validated, atomically."""
        self.validate(allow_gaps=allow_gaps)
        write_table(path, self.schema, self.metadata, self.columns())

    @classmethod
    def load(
        cls,
        path: PathLike,
        *,
        allow_gaps: bool = False,
        max_gap_periods: float = DEFAULT_MAX_GAP_PERIODS,
        read: ReadOptions | None = None,
    ) -> Self:
        """Read and validate a whole trace (``read``: other units or column names, :class:`ReadOptions`)."""
        chunks = cls.iter_chunks(
            path, BLOCK_ROWS, allow_gaps=allow_gaps, max_gap_periods=max_gap_periods, read=read
        )
        return _concat(cls, chunks)

    @classmethod
    def iter_chunks(
        cls,
        path: PathLike,
        rows: int,
        *,
        allow_gaps: bool = False,
        max_gap_periods: float = DEFAULT_MAX_GAP_PERIODS,
        read: ReadOptions | None = None,
    ) -> Iterator[Self]:
        """Stream a trace in validated chunks of at most ``rows`` rows (memory does not grow with length)."""
        src = open_table(path, cls.schema, rows, allow_gaps, max_gap_periods, read)
        for block in src.blocks:
            yield cls.from_columns(block, src.metadata)


def _number_array(value: Any, name: str, shape: tuple[int, ...], expected: str, kinds: str) -> np.ndarray:
    """``value`` (an array of any real dtype and byte order, or a (nested) list of numbers) as an array
    of ``shape`` (-1: any length), or a TraceError naming the field and what was expected. ``kinds`` are the
    accepted numpy dtype kinds (``"fiu"``: float, signed, unsigned integers)."""
    where = f"{name}: expected {expected}"
    try:
        arr = np.asarray(value)
    except (ValueError, TypeError) as e:  # a ragged list, an object numpy cannot take
        raise TraceError(f"{where}; got {type(value).__name__} ({e})") from None
    if arr.dtype.kind not in kinds:
        got = "" if arr.dtype.kind == "O" else f" of dtype {arr.dtype}"
        raise TraceError(f"{where}; got {'None' if value is None else type(value).__name__}{got}")
    if len(arr.shape) != len(shape) or any(g != e and e != -1 for g, e in zip(arr.shape, shape, strict=True)):
        raise TraceError(f"{where}; got shape {arr.shape}")
    if arr.dtype.kind in "iu" and arr.size and "f" in kinds:
        # float64 holds every integer up to 2^53 exactly; beyond that the conversion would round.
        big = (arr > 2**53) | (arr < -(2**53))
        if big.any():
            i = np.unravel_index(int(np.argmax(big)), arr.shape)
            raise TraceError(f"{where}; element {_index(i)} = {arr[i]} is beyond 2^53, not exact as float64")
    return arr


def _float_field(value: Any, name: str, shape: tuple[int, ...], expected: str) -> Array:
    """A float64 field in native byte order (float32, integers, big-endian, lists converted exactly)."""
    arr = _number_array(value, name, shape, f"{expected} of numbers (float or integer)", "fiu")
    return arr if arr.dtype == np.float64 and arr.dtype.isnative else arr.astype(np.float64)


def _shape_text(shape: tuple[int, ...]) -> str:
    return f"shape ({shape[0]},)" if len(shape) == 1 else f"shape {shape}"


def _metadata(value: Any, owner: str) -> dict[str, str]:
    """Trace metadata as ``{str: str}``: numbers (``100``, ``819.2``, a Fraction) are written as text
    exactly (a float by its shortest round-trip repr); anything else is a TraceError."""
    if not isinstance(value, Mapping):
        raise TraceError(
            f"{owner}.metadata: expected a dict of text keys and values; got {type(value).__name__}"
        )
    out: dict[str, str] = {}
    for k, v in value.items():
        if not isinstance(k, str):
            raise TraceError(f"{owner}.metadata: key {k!r} is {type(k).__name__}; expected text")
        if isinstance(v, str):
            out[k] = v
        elif isinstance(v, int | float | Fraction | np.integer | np.floating) and not isinstance(v, bool):
            out[k] = (
                repr(v.item() if isinstance(v, np.generic) else v) if not isinstance(v, Fraction) else str(v)
            )
        else:
            raise TraceError(
                f"{owner}.metadata: `{k}` = {v!r} is {type(v).__name__}; expected text or a number"
            )
    return out


@dataclass
class PhysicalTrace(_TraceFile):
    """What the sensor sees, sample by sample (units and frames: docs/traces.md).

    ``gyro_dps`` is ω_ib in the sensor frame (°/s), ``accel_g`` the specific force (g = 9.80665 m/s²),
    ``truth_q`` the attitude C_b^n as a unit quaternion ``[w, x, y, z]`` (navigation frame ENU), NaN
    rows where the truth is missing. Optional fields are ``None`` when absent.

    Shapes for n samples: ``t_s``, ``baro_mbar``, ``temp_c`` and ``moving`` (n,); ``gyro_dps``,
    ``accel_g`` and ``mag_gauss`` (n, 3); ``truth_q`` (n, 4). The numeric fields take numpy arrays of
    any float or integer dtype and either byte order, or (nested) lists of numbers, and hold them as
    native float64 (an exact conversion; integers beyond 2^53 are refused); ``moving`` takes bools,
    or numbers 0/1. ``metadata`` maps text keys to text (numbers are written as text exactly). Anything
    else (text, a wrong shape, complex numbers, …) is a :class:`~sins_fw.errors.TraceError` naming
    the field and what was expected. The values themselves (finite, increasing time, unit truth) are
    checked by :meth:`validate`, and by ``emulate`` as the trace streams in.
    """

    t_s: Array
    gyro_dps: Array
    accel_g: Array
    mag_gauss: Array | None = None
    baro_mbar: Array | None = None
    temp_c: Array | None = None
    truth_q: Array | None = None
    moving: NDArray[np.bool_] | None = None
    metadata: dict[str, str] = field(default_factory=dict)
    gps: Array | None = None
    truth_alpha_deg: Array | None = None
    array_g: Array | None = None

    schema: ClassVar[Schema] = PHYSICAL_SCHEMA
    _GROUPS: ClassVar[dict[str, tuple[str, ...]]] = {
        "gyro_dps": tuple(f"gyro_{a}_dps" for a in "xyz"),
        "accel_g": tuple(f"accel_{a}_g" for a in "xyz"),
        "mag_gauss": tuple(f"mag_{a}_gauss" for a in "xyz"),
        "baro_mbar": ("baro_mbar",),
        "temp_c": ("temp_c",),
        "truth_q": tuple(f"truth_q{c}" for c in "wxyz"),
        "moving": ("moving",),
        "gps": GPS_COLUMNS,
        "truth_alpha_deg": ("truth_alpha_deg",),
        "array_g": tuple(f"array{p}_{a}_g" for p in range(1, 8) for a in "xyz"),
    }

    def __post_init__(self) -> None:
        self.t_s = _float_field(self.t_s, "PhysicalTrace.t_s", (-1,), "shape (n,) (times, s)")
        n = len(self.t_s)
        for attr, names in self._GROUPS.items():
            value = getattr(self, attr)
            if value is None and attr not in ("gyro_dps", "accel_g"):
                continue
            shape = (n, len(names)) if len(names) > 1 else (n,)
            name = f"PhysicalTrace.{attr}"
            expected = f"{_shape_text(shape)} ({', '.join(names)}; n = len(t_s))"
            if attr == "moving":
                arr = _number_array(value, name, shape, f"{expected} of bools or 0/1", "biuf")
                if arr.dtype.kind != "b":
                    bad = (arr != 0) & (arr != 1)
                    if bad.any():
                        i = int(np.argmax(bad))
                        raise TraceError(
                            f"{name}: element {_index(i)} = {arr[i]}; expected {expected} of bools or 0/1"
                        )
                    arr = arr.astype(bool)
                setattr(self, attr, arr)
            else:
                setattr(self, attr, _float_field(value, name, shape, expected))
        self.metadata = _metadata(self.metadata, "PhysicalTrace")

    def __len__(self) -> int:
        return len(self.t_s)

    @property
    def sample_rate_hz(self) -> Fraction:
        """The nominal sample rate from the metadata, as an exact fraction."""
        return parse_rate(self.metadata.get("sample_rate_hz", "0"), "trace metadata")

    @property
    def duration_s(self) -> float:
        """Time span covered: last minus first sample time plus one nominal period."""
        return float(self.t_s[-1] - self.t_s[0] + 1 / self.sample_rate_hz) if len(self) else 0.0

    def columns(self) -> dict[str, np.ndarray]:
        """The trace as named one-dimensional columns, in canonical order."""
        n = len(self.t_s)
        cols: dict[str, np.ndarray] = {"t_s": np.asarray(self.t_s, dtype=np.float64)}
        for attr, names in self._GROUPS.items():
            value = getattr(self, attr)
            if value is None:
                continue
            arr = np.asarray(value)
            shape = (n, len(names)) if len(names) > 1 else (n,)
            if arr.shape != shape:
                raise TraceError(
                    f"PhysicalTrace.{attr}: shape {arr.shape}; expected {shape} ({', '.join(names)})"
                )
            for i, name in enumerate(names):
                cols[name] = arr[:, i] if len(names) > 1 else arr
        if "moving" in cols:
            cols["moving"] = cols["moving"].astype(np.uint8)
        return cols

    @classmethod
    def from_columns(cls, cols: Mapping[str, np.ndarray], metadata: Mapping[str, str]) -> Self:
        """Build from named columns (as read from a file)."""
        fields: dict[str, Any] = {}
        for attr, names in cls._GROUPS.items():
            if names[0] in cols:
                arrays = [np.asarray(cols[n]) for n in names]
                fields[attr] = np.stack(arrays, axis=1) if len(names) > 1 else arrays[0]
        if "moving" in fields:
            fields["moving"] = fields["moving"].astype(bool)
        for attr in (
            "gyro_dps",
            "accel_g",
            "mag_gauss",
            "baro_mbar",
            "temp_c",
            "truth_q",
            "gps",
            "truth_alpha_deg",
            "array_g",
        ):
            if attr in fields:
                fields[attr] = fields[attr].astype(np.float64)
        return cls(t_s=np.asarray(cols["t_s"], dtype=np.float64), metadata=dict(metadata), **fields)


@dataclass
class RawRegisterTrace(_TraceFile):
    """Per burst read: the time of the chip-select falling edge (s) and the 15 DOUT words
    (``words[:, 0]`` answers the 0x4200 command frame and is don't care; ``words[:, 1:]`` are
    SUPPLY_OUT … AUX_ADC, see :data:`RAW_WORD_COLUMNS`)."""

    t_s: Array
    words: NDArray[np.uint16]
    metadata: dict[str, str] = field(default_factory=dict)

    schema: ClassVar[Schema] = RAW_SCHEMA

    def __post_init__(self) -> None:
        # The same conversions as PhysicalTrace: t_s any real numbers, words any integers in 0…0xFFFF.
        self.t_s = _float_field(self.t_s, "RawRegisterTrace.t_s", (-1,), "shape (n,) (times, s)")
        shape = (len(self.t_s), len(RAW_WORD_COLUMNS))
        expected = f"shape {shape} of 16-bit words (0…0xFFFF; n = len(t_s))"
        words = _number_array(self.words, "RawRegisterTrace.words", shape, expected, "iu")
        bad = (words < 0) | (words > 0xFFFF)
        if bad.any():
            i = np.unravel_index(int(np.argmax(bad)), shape)
            raise TraceError(f"RawRegisterTrace.words: element {_index(i)} = {words[i]}; expected {expected}")
        self.words = words.astype(np.uint16, copy=False)
        self.metadata = _metadata(self.metadata, "RawRegisterTrace")

    def __len__(self) -> int:
        return len(self.t_s)

    def columns(self) -> dict[str, np.ndarray]:
        """The trace as named columns."""
        words = np.asarray(self.words)
        if words.shape != (len(self.t_s), len(RAW_WORD_COLUMNS)):
            raise TraceError(
                f"RawRegisterTrace.words: shape {words.shape}; "
                f"expected ({len(self.t_s)}, {len(RAW_WORD_COLUMNS)})"
            )
        if words.dtype.kind not in "iu" or (words.size and (words.min() < 0 or words.max() > 0xFFFF)):
            raise TraceError("RawRegisterTrace.words: expected 16-bit words (0…0xFFFF)")
        cols: dict[str, np.ndarray] = {"t_s": np.asarray(self.t_s, dtype=np.float64)}
        for i, n in enumerate(RAW_WORD_COLUMNS):
            cols[n] = words[:, i].astype(np.uint16)
        return cols

    @classmethod
    def from_columns(cls, cols: Mapping[str, np.ndarray], metadata: Mapping[str, str]) -> Self:
        """Build from named columns."""
        words = np.stack([np.asarray(cols[n], dtype=np.uint16) for n in RAW_WORD_COLUMNS], axis=1)
        return cls(t_s=np.asarray(cols["t_s"], dtype=np.float64), words=words, metadata=dict(metadata))


def check_output_path(path: PathLike) -> Path:
    """Fail early (before any work) on an output path that cannot take a trace."""
    p = Path(path)
    table_extension(p)
    if p.is_dir():
        raise TraceError(f"{p}: is a directory; expected a trace file name ending in .csv or .h5")
    return p


def file_sha256(path: PathLike) -> str:
    """The SHA-256 of a file's bytes (hex), read in blocks."""
    with open(path, "rb") as fh:
        return hashlib.file_digest(fh, "sha256").hexdigest()


def is_raw_register_trace(path: PathLike) -> bool:
    """Whether a trace file is a raw-register trace: its `format` metadata says so or, without it,
    its columns are the raw words (``frame0`` … ``aux_adc``). Unreadable files count as physical
    (loading them explains what is wrong)."""
    fmt = read_metadata(path).get("format")
    if fmt is not None:
        return fmt == RAW_FORMAT
    p = Path(path)
    try:
        if table_extension(p) == ".h5":
            with h5py.File(p, "r") as f:
                names = set(f.keys())
        else:
            with p.open("rb") as fh:
                names = set()
                for raw in fh:
                    text = raw.decode("utf-8").lstrip("\ufeff").strip()
                    if text and not text.startswith("#"):
                        names = {n.strip() for n in text.split(csv_separator(text))}
                        break
    except (OSError, UnicodeDecodeError, TraceError):
        return False
    return bool(names & set(RAW_WORD_COLUMNS))


def iter_chunks(
    path: PathLike,
    rows: int,
    *,
    allow_gaps: bool = False,
    max_gap_periods: float = DEFAULT_MAX_GAP_PERIODS,
    read: ReadOptions | None = None,
) -> Iterator[PhysicalTrace]:
    """Stream a physical trace in validated chunks of at most ``rows`` rows."""
    return PhysicalTrace.iter_chunks(
        path, rows, allow_gaps=allow_gaps, max_gap_periods=max_gap_periods, read=read
    )


_C = TypeVar("_C", bound=_TraceFile)


def validated(
    chunks: Iterable[_C], *, allow_gaps: bool = False, max_gap_periods: float = DEFAULT_MAX_GAP_PERIODS
) -> Iterator[_C]:
    """The consecutive chunks of a trace built in memory, each checked as it passes exactly as a
    file's rows are on load (the same metadata check, the same :class:`Checker`, carried across
    chunks): the one validation path for files and memory. The metadata is the first chunk's."""
    checker: Checker | None = None
    src = ""
    for chunk in chunks:
        if checker is None:
            src = f"<{chunk.schema.title} in memory>"
            rate = check_metadata(chunk.metadata, chunk.schema, f"{src}: metadata")
            checker = Checker(
                chunk.schema,
                src,
                float(1 / rate),
                allow_gaps,
                max_gap_periods,
                lambda r: f"row {r}",
                metadata=chunk.metadata,
            )
        cols = chunk.columns()
        lengths = {n: len(a) for n, a in cols.items()}
        if len(set(lengths.values())) > 1:
            raise TraceError(f"{src}: columns have different lengths: {lengths}")
        checker.check(cols)
        yield chunk
    if checker is None or checker.rows_seen == 0:
        raise TraceError(f"{src or '<trace in memory>'}: no data rows")


class CheckedTrace:
    """A :class:`PhysicalTrace` that passed every check ``emulate`` makes on a trace in memory, with
    gaps not allowed (:meth:`PhysicalTrace.validate`), and that cannot change afterwards: the check
    runs on read-only copies of the arrays, and the checked trace is never handed out (:attr:`trace`
    is a new PhysicalTrace over the same read-only arrays each time, so that changing it changes
    nothing here). ``emulate`` takes it without checking it again: a trace many runs share (a Monte
    Carlo's) is checked once, where it is made.

    A copy (pickle, ``copy``) carries the checked arrays and makes them read-only again without a new
    check: it holds the same values that passed. This is how a trace scattered to a cluster's
    workers is trusted there (a pickle is code to whoever unpickles it: who can forge one can run
    anything on the worker already)."""

    __slots__ = ("_trace",)

    def __init__(self, trace: PhysicalTrace) -> None:
        if not isinstance(trace, PhysicalTrace):
            raise TraceError(f"CheckedTrace: expected a PhysicalTrace; got {type(trace).__name__}")
        arrays = {f.name: getattr(trace, f.name) for f in fields(trace) if f.name != "metadata"}
        copied = {k: None if v is None else np.array(v, copy=True) for k, v in arrays.items()}
        frozen = PhysicalTrace(**copied, metadata=dict(trace.metadata))
        _freeze(frozen)
        frozen.validate()
        self._trace = frozen

    @property
    def trace(self) -> PhysicalTrace:
        """The checked trace: a new PhysicalTrace over its read-only arrays (and a copy of its metadata)."""
        return replace(self._trace)

    def __len__(self) -> int:
        return len(self._trace)

    def __getstate__(self) -> PhysicalTrace:
        return self._trace

    def __setstate__(self, trace: PhysicalTrace) -> None:
        _freeze(trace)
        self._trace = trace


def _freeze(trace: PhysicalTrace) -> None:
    """Make a trace's arrays read-only."""
    for f in fields(trace):
        value = getattr(trace, f.name)
        if isinstance(value, np.ndarray):
            value.setflags(write=False)


_T = TypeVar("_T", PhysicalTrace, RawRegisterTrace)


def _concat(cls: type[_T], chunks: Iterator[_T]) -> _T:
    traces = list(chunks)
    parts = [t.columns() for t in traces]
    cols = {n: np.concatenate([p[n] for p in parts]) for n in parts[0]}
    return cls.from_columns(cols, traces[0].metadata)


# ---------------------------------------------------------------------------------------------------
# The optional GPS stream of a physical trace (docs/traces.md, "GPS stream")
# ---------------------------------------------------------------------------------------------------


def gps_latency_s(metadata: Mapping[str, str], where: str) -> float:
    """The GPS stream's latency from the metadata key ``gps_latency_s`` (required with the GPS columns):
    a fix reaches the firmware that many seconds after its time of validity (its row's ``t_s``)."""
    text = metadata.get("gps_latency_s")
    if text is None:
        raise TraceError(
            f"{where}: `gps_latency_s` is missing; expected the GPS receiver's latency in s (e.g. 0.1) "
            "with the gps_* columns"
        )
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and 0.0 <= value <= 10.0):
        raise TraceError(f"{where}: `gps_latency_s` is `{text}`; expected a number of seconds in 0…10")
    if "gps_rate_hz" in metadata:
        parse_rate(metadata["gps_rate_hz"], where)
    return value


def check_gps(cols: Mapping[str, np.ndarray], where: Callable[[int], str]) -> None:
    """The GPS columns of a block of rows: a row holds a fix (five numbers in range) or none (five
    NaN); ``where(i)`` names row i of the block."""
    block = np.stack([cols[n] for n in GPS_COLUMNS], axis=1)
    nan = np.isnan(block)
    partial = nan.any(axis=1) & ~nan.all(axis=1)
    if partial.any():
        i = int(np.argmax(partial))
        name = GPS_COLUMNS[int(np.argmax(nan[i]))]
        raise TraceError(
            f"{where(i)}, column `{name}`: NaN in only some GPS columns; expected all five NaN (no fix "
            "at this sample) or none"
        )
    for k, name in enumerate(GPS_COLUMNS):
        lo, hi, allowed = _GPS_RANGES[name]
        x = block[:, k]
        with np.errstate(invalid="ignore"):
            bad = (x < lo) | (x >= hi if name == "gps_course_deg" else x > hi)
        if bad.any():
            i = int(np.argmax(bad))
            raise TraceError(f"{where(i)}, column `{name}`: found {float(x[i])!r}; expected {allowed}")


def gps_fixes(trace: PhysicalTrace, t_s: Array) -> tuple[Array, Array, Array] | None:
    """The GPS fixes of a (validated) trace or chunk: the times ``t_s`` of its rows holding a fix (the
    trace's times as the emulator takes them), their ground speed (m/s) and course (degrees); None
    without a GPS stream."""
    if trace.gps is None:
        return None
    has = ~np.isnan(trace.gps[:, 0])
    return (
        np.ascontiguousarray(t_s[has]),
        np.ascontiguousarray(trace.gps[has, 0]),
        np.ascontiguousarray(trace.gps[has, 1]),
    )
