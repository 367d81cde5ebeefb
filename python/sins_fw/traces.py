"""Trace files: the physical trace (what the sensor sees) and the raw-register trace (what the bus
carries). Both come as CSV with a metadata header (``.csv``) or as columnar HDF5 (``.h5``); the
format, with every column, unit and rule, is documented in docs/traces.md.

Loading validates everything and raises :class:`~sins_fw.errors.TraceError` with a message naming
the file, the line (CSV) or row, the column, and what was expected versus found. Rows are counted
from 0 (the first data row is row 0); CSV line numbers from 1.
"""

from __future__ import annotations

import contextlib
import io
import itertools
import math
import os
import re
import warnings
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import IO, Any, ClassVar, Self, TypeVar

import h5py
import numpy as np
from numpy.typing import NDArray

from sins_fw.atomic import atomic_path, kept_error_file
from sins_fw.errors import TraceError, TraceWarning

Array = NDArray[np.float64]
PathLike = str | os.PathLike[str]

PHYSICAL_FORMAT = "sins-fw-physical-trace/1"
RAW_FORMAT = "sins-fw-raw-register-trace/1"
#: Default gap limit: a time step longer than this many nominal sample periods is an error
#: (one dropped sample already makes a step of 2 periods; jitter up to 50 % is accepted).
DEFAULT_MAX_GAP_PERIODS = 1.5
#: Allowed deviation of a truth quaternion's norm from 1 (float64 data, written with full precision).
TRUTH_NORM_TOLERANCE = 1e-6
#: Rows per HDF5 chunk and per block when writing CSV.
_BLOCK_ROWS = 65536
#: Rows formatted at a time when writing CSV (the bytes do not depend on it).
_CSV_ROWS = 8192
_HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
_KEY_RE = re.compile(r"^[A-Za-z0-9_.\-]+$")
_EXTENSIONS = (".csv", ".h5")
#: Standard gravity: the unit "g" of the traces (m/s²).
G0 = 9.80665


@dataclass(frozen=True)
class Column:
    """One column of a trace format."""

    name: str
    unit: str
    description: str
    kind: str = "float"  # "float", "flag" (0/1) or "word" (16-bit register word)
    group: str = ""  # columns of one group are all present or all absent
    required: bool = True
    nan_allowed: bool = False

    @property
    def stem(self) -> str:
        """The quantity without its unit suffix (``gyro_x_dps`` → ``gyro_x``): to spot wrong units."""
        if self.kind != "float" or self.unit in ("1", ""):
            return self.name
        return self.name.rsplit("_", 1)[0]


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

#: The 15 DOUT words of one burst read, in bus order: the don't-care answer to the 0x4200 command
#: frame, then the 14 output registers 0x02…0x1C.
RAW_WORD_COLUMNS: tuple[str, ...] = (
    "frame0",
    "supply_out",
    "xgyro_out",
    "ygyro_out",
    "zgyro_out",
    "xaccl_out",
    "yaccl_out",
    "zaccl_out",
    "xmagn_out",
    "ymagn_out",
    "zmagn_out",
    "baro_out",
    "baro_outl",
    "temp_out",
    "aux_adc",
)
RAW_COLUMNS: tuple[Column, ...] = (
    Column("t_s", "s", "time of the burst's chip-select falling edge"),
    *(
        Column(n, "16-bit word", f"DOUT word {i} of the burst", kind="word")
        for i, n in enumerate(RAW_WORD_COLUMNS)
    ),
)

_ALIASES = {"time": "t_s", "timestamp": "t_s", "time_s": "t_s"}


@dataclass(frozen=True)
class _Schema:
    title: str
    format: str
    columns: tuple[Column, ...]

    def column(self, name: str) -> Column:
        return next(c for c in self.columns if c.name == name)

    def names(self) -> list[str]:
        return [c.name for c in self.columns]

    def diagnose_unknown(self, name: str) -> str:
        """Why ``name`` is not a column: a wrong or missing unit, or simply unknown."""
        lowered = name.strip().lower()
        if lowered in _ALIASES:
            c = self.column(_ALIASES[lowered])
            return f"column `{name}` has no recognised unit: expected `{c.name}` ({c.unit})"
        matches = [
            c
            for c in self.columns
            if c.stem != c.name and (lowered == c.stem or lowered.startswith(c.stem + "_"))
        ]
        if matches:
            c = max(matches, key=lambda m: len(m.stem))
            return f"column `{name}` has the wrong unit: expected `{c.name}` ({c.unit})"
        return f"unknown column `{name}`; the columns of a {self.title} are: {', '.join(self.names())}"

    def check_header(self, names: list[str], where: str) -> None:
        """Unknown, duplicated, wrong-unit and missing columns, each explained."""
        seen: set[str] = set()
        known = set(self.names())
        for n in names:
            if n in seen:
                raise TraceError(f"{where}: column `{n}` appears twice")
            seen.add(n)
            if n not in known:
                raise TraceError(f"{where}: {self.diagnose_unknown(n)}")
        for c in self.columns:
            if c.required and c.name not in seen:
                raise TraceError(f"{where}: missing column `{c.name}` ({c.description}, {c.unit})")
        groups = {c.group for c in self.columns if c.group and c.name in seen}
        for g in sorted(groups):
            missing = [c.name for c in self.columns if c.group == g and c.name not in seen]
            if missing:
                raise TraceError(
                    f"{where}: missing column `{missing[0]}`: the `{g}` columns come together "
                    f"({', '.join(c.name for c in self.columns if c.group == g)})"
                )

    def order(self, names: list[str] | set[str]) -> list[str]:
        """The present columns in canonical order."""
        return [n for n in self.names() if n in names]


PHYSICAL_SCHEMA = _Schema("physical trace", PHYSICAL_FORMAT, PHYSICAL_COLUMNS)
RAW_SCHEMA = _Schema("raw-register trace", RAW_FORMAT, RAW_COLUMNS)


# ---------------------------------------------------------------------------------------------------
# Metadata
# ---------------------------------------------------------------------------------------------------


def parse_rate(text: str, where: str = "metadata") -> Fraction:
    """A sample rate written as a decimal (``819.2``) as an exact fraction; must be positive."""
    try:
        rate = Fraction(text.strip())
    except (ValueError, ZeroDivisionError):
        rate = Fraction(0)
    if rate <= 0:
        raise TraceError(
            f"{where}: `sample_rate_hz` is `{text}`; expected a positive number of Hz (e.g. 819.2 or 2000/7)"
        )
    return rate


def _check_metadata(metadata: Mapping[str, str], schema: _Schema, where: str) -> Fraction:
    rate = _check_metadata_keys(metadata, schema, where)
    if rate is None:
        raise TraceError(f"{where}: `sample_rate_hz` is missing (the nominal sample rate, Hz)")
    return rate


def _check_metadata_keys(metadata: Mapping[str, str], schema: _Schema, where: str) -> Fraction | None:
    """The metadata's keys and format checked; the declared rate (None when there is none)."""
    for key, value in metadata.items():
        if not _KEY_RE.match(key):
            raise TraceError(f"{where}: key `{key}` must be letters, digits, `_`, `.` or `-`")
        if not isinstance(value, str) or "\n" in value or "\r" in value:
            raise TraceError(f"{where}: `{key}` must be a one-line string")
    fmt = metadata.get("format")
    if fmt is not None and fmt != schema.format:
        other = (
            "raw-register trace" if fmt == RAW_FORMAT else "physical trace" if fmt == PHYSICAL_FORMAT else fmt
        )
        raise TraceError(
            f"{where}: `format` is `{fmt}` ({other}); expected `{schema.format}` ({schema.title})"
        )
    if "sample_rate_hz" not in metadata:
        return None
    return parse_rate(metadata["sample_rate_hz"], where)


# ---------------------------------------------------------------------------------------------------
# Reading other people's files: units, column maps, the sample rate from the times, plausibility
# ---------------------------------------------------------------------------------------------------

#: The units a column may be read in, per quantity (the part of the name before the unit): the suffix
#: that names the unit in a column name (``gyro_x_rad_s``) → the factor to the trace's own unit (the
#: first one). ``units=`` / ``--units`` take the same names or the usual spellings (``rad/s``, ``m/s2``).
UNITS: dict[str, dict[str, float]] = {
    "t": {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9},
    "gyro": {"dps": 1.0, "rad_s": 180.0 / math.pi},
    "accel": {"g": 1.0, "m_s2": 1.0 / G0},
    "mag": {"gauss": 1.0, "mgauss": 1e-3, "ut": 1e-2, "nt": 1e-5},
    "baro": {"mbar": 1.0, "hpa": 1.0, "pa": 1e-2},
    "temp": {"c": 1.0},
}
_UNIT_SPELLINGS = {
    "deg/s": "dps",
    "°/s": "dps",
    "rad/s": "rad_s",
    "m/s2": "m_s2",
    "m/s^2": "m_s2",
    "m/s²": "m_s2",
    "µt": "ut",
    "μt": "ut",
}
#: Rows whose times give the sample rate (the median step) when the metadata has none, and against
#: which a declared rate is checked.
RATE_ROWS = 1024
#: A declared rate more than this far (relative) from the one the times give is refused: a nominal rate
#: is within a few per cent of the real one (an RC oscillator's tolerance; crystals are far closer), so a
#: larger difference is another rate (a decimated log) or times in another unit.
RATE_TOLERANCE = 0.05
#: Steps needed before a declared rate is checked against the times: their median is then not moved
#: by up to 4 gaps (a file of a few rows with one gap keeps its declared rate).
RATE_MIN_STEPS = 10


def _unit_name(text: str) -> str:
    t = text.strip().lower()
    return _UNIT_SPELLINGS.get(t, t.replace("/", "_"))


def _unit_text(quantity: str) -> str:
    return ", ".join(f"`{u}`" for u in UNITS[quantity])


def parse_units(units: Mapping[str, str] | str | None, where: str = "--units") -> dict[str, str]:
    """``{"gyro": "rad/s", "accel": "m/s2"}`` or ``"gyro=rad/s,accel=m/s2"`` as quantity → unit suffix
    (``{"gyro": "rad_s", "accel": "m_s2"}``), each checked against :data:`UNITS`."""
    pairs = _pairs(units, where)
    out: dict[str, str] = {}
    for q, u in pairs.items():
        if q not in UNITS:
            raise TraceError(
                f"{where}: unknown quantity `{q}`; expected one of {', '.join(UNITS)} (e.g. gyro=rad/s)"
            )
        unit = _unit_name(u)
        if unit not in UNITS[q]:
            raise TraceError(f"{where}: unknown unit `{u}` for `{q}`; expected one of {_unit_text(q)}")
        out[q] = unit
    return out


def parse_columns(columns: Mapping[str, str] | str | None, where: str = "--columns") -> dict[str, str]:
    """``{"t_s": "time", "gyro_x": "wx"}`` or ``"t_s=time,gyro_x=wx"``: trace column (with or without
    its unit) → the file's column name."""
    return _pairs(columns, where)


def _pairs(value: Mapping[str, str] | str | None, where: str) -> dict[str, str]:
    if value is None:
        return {}
    if isinstance(value, Mapping):
        return {str(k).strip(): str(v).strip() for k, v in value.items()}
    out: dict[str, str] = {}
    for item in (s for s in value.split(",") if s.strip()):
        key, sep, val = item.partition("=")
        if not sep or not key.strip() or not val.strip():
            raise TraceError(f"{where}: `{item}` is not NAME=VALUE; expected e.g. gyro=rad/s,accel=m/s2")
        if key.strip() in out:
            raise TraceError(f"{where}: `{key.strip()}` is given twice")
        out[key.strip()] = val.strip()
    return out


@dataclass(frozen=True)
class ReadOptions:
    """How to read a file that is not in the trace's own units or names: ``units`` (quantity → unit,
    e.g. ``{"gyro": "rad/s"}``: every column of the quantity is in that unit, whatever its name says)
    and ``columns`` (trace column → the file's column, e.g. ``{"t_s": "time", "gyro_x": "wx"}``: the
    file's other columns that are no trace column are then left out)."""

    units: Mapping[str, str] | str | None = None
    columns: Mapping[str, str] | str | None = None

    def __bool__(self) -> bool:
        return bool(self.units) or bool(self.columns)


@dataclass(frozen=True)
class _Field:
    """One column of the file as read: the file's name, the trace column it becomes (None: left out),
    the factor to the trace unit, and the unit it was read in."""

    source: str
    name: str | None
    factor: float = 1.0
    unit: str = ""


def _quantity(c: Column) -> str | None:
    """The quantity of a float column that has alternative units (``gyro_x_dps`` → ``gyro``)."""
    q = c.name.split("_", 1)[0]
    return q if c.kind == "float" and q in UNITS and c.stem != c.name else None


def _resolve_header(schema: _Schema, names: list[str], options: ReadOptions, where: str) -> list[_Field]:
    """The file's columns as trace columns: units from the name's suffix or ``options.units``, names
    through ``options.columns``; unknown columns, wrong units and a bad map are explained."""
    units = parse_units(options.units)
    mapping = parse_columns(options.columns)
    by_source: dict[str, str] = {}
    for key, source in mapping.items():
        if source not in names:
            raise TraceError(
                f"{where}: --columns maps `{key}` to `{source}`, which is not a column of the file "
                f"(its columns: {', '.join(names)})"
            )
        by_source[source] = key
    for q in units:
        if not any(_quantity(c) == q for c in schema.columns):
            raise TraceError(f"{where}: --units gives `{q}`, which a {schema.title} has no column of")
    fields = [_resolve(schema, n, by_source.get(n), units, bool(mapping), where) for n in names]
    seen: dict[str, str] = {}
    for f in fields:
        if f.name is None:
            continue
        if f.name in seen:
            if seen[f.name] == f.source:
                raise TraceError(f"{where}: column `{f.source}` appears twice")
            raise TraceError(
                f"{where}: columns `{seen[f.name]}` and `{f.source}` are both read as `{f.name}`; expected "
                "one column per quantity"
            )
        seen[f.name] = f.source
    schema.check_header(list(seen), where)
    return fields


def _resolve(
    schema: _Schema, source: str, key: str | None, units: dict[str, str], mapped: bool, where: str
) -> _Field:
    name = key if key is not None else source
    lowered = name.strip().lower()
    via = f" (mapped from `{source}`)" if key is not None else ""
    known = {c.name: c for c in schema.columns}
    if name in known:
        c = known[name]
        q = _quantity(c)
        unit = units.get(q, c.name.rsplit("_", 1)[1]) if q else ""
        return _Field(source, name, UNITS[q][unit] if q else 1.0, unit)
    for alias in ("timestamp", "time"):  # `time`, `time_ms`: the time column under another name
        if lowered == alias or lowered.startswith(alias + "_"):
            lowered = "t" + lowered[len(alias) :]
            break
    for c in sorted(schema.columns, key=lambda c: -len(c.stem)):
        q = _quantity(c)
        if q is None:
            continue
        if lowered == c.stem:
            if q in units:
                return _Field(source, c.name, UNITS[q][units[q]], units[q])
            raise TraceError(
                f"{where}: column `{name}`{via} has no recognised unit: expected `{c.name}` ({c.unit}); "
                f"name the unit in the column ({', '.join(f'`{c.stem}_{u}`' for u in UNITS[q])}) or give "
                f"it with --units {q}=UNIT"
            )
        if lowered.startswith(c.stem + "_"):
            unit = lowered[len(c.stem) + 1 :]
            if q in units or unit in UNITS[q]:
                u = units.get(q, unit)
                return _Field(source, c.name, UNITS[q][u], u)
            others = ", ".join(f"`{c.stem}_{u}`" for u in list(UNITS[q])[1:])
            raise TraceError(
                f"{where}: column `{name}`{via} has the wrong unit: expected `{c.name}` ({c.unit}), or "
                f"{others}; or give the unit with --units {q}=UNIT"
            )
    if mapped and key is None:
        return _Field(source, None)
    if key is not None:
        raise TraceError(f"{where}: --columns maps `{key}` to `{source}`: {schema.diagnose_unknown(key)}")
    hint = "" if schema is not PHYSICAL_SCHEMA else "; a file with other names can be read with --columns"
    raise TraceError(f"{where}: {schema.diagnose_unknown(name)}{hint}")


#: Time units tried when a rate looks wrong, with their names in messages.
_TIME_UNITS = {"s": "seconds", "ms": "milliseconds", "us": "microseconds", "ns": "nanoseconds"}
#: Sample rates an IMU trace can have (Hz): outside, the times are taken to be in another unit.
_PLAUSIBLE_RATE_HZ = (1.0, 1e5)


def _rate_of_step(step: float) -> Fraction:
    """The rate of a median step: a simple ratio when one is that close (4096/5, 2000/7, 100), else
    six significant digits."""
    rate = 1.0 / step
    simple = Fraction(rate).limit_denominator(1000)
    if simple > 0 and abs(float(simple) - rate) <= 1e-9 * rate:
        return simple
    return Fraction(f"{rate:.6g}")


def _rate_text(rate: Fraction) -> str:
    return str(rate.numerator) if rate.denominator == 1 else f"{rate.numerator}/{rate.denominator}"


def _time_hint(step: float, t: _Field, want_hz: float | None) -> str:
    """When the times' step fits ``want_hz`` (or a plausible IMU rate) in another time unit: which."""
    read_in = t.unit or "s"
    scale = UNITS["t"][read_in]
    candidates = []
    for unit, factor in UNITS["t"].items():
        rate = 1.0 / (step / scale * factor)
        if want_hz is not None:
            if unit != read_in and abs(rate / want_hz - 1) <= RATE_TOLERANCE:
                candidates.append((0.0, unit, rate))
        elif _PLAUSIBLE_RATE_HZ[0] <= rate <= _PLAUSIBLE_RATE_HZ[1]:
            candidates.append((abs(math.log10(rate / 316.0)), unit, rate))
    if not candidates:
        return ""
    _, unit, rate = min(candidates)
    if unit == read_in:
        return ""
    return (
        f"; the times look like {_TIME_UNITS[unit]} ({rate:.6g} Hz in {unit}): name the column "
        f"`t_{unit}` or give --units t={unit}"
    )


def _rate(
    metadata: dict[str, str], schema: _Schema, times: Array, t: _Field, where: str, src: str
) -> Fraction:
    """The sample rate: the declared one checked against the first rows' times (their median step),
    or, when the metadata has none, the times' own (written into ``metadata``)."""
    declared = _check_metadata_keys(metadata, schema, where)
    dt = np.diff(times)
    dt = dt[np.isfinite(dt) & (dt > 0)]
    if not len(dt):
        if declared is None:
            raise TraceError(
                f"{where}: `sample_rate_hz` is missing and fewer than two rows give it; add a line "
                "`# sample_rate_hz: RATE` (the nominal sample rate, Hz)"
            )
        return declared
    step = float(np.median(dt))
    inferred = _rate_of_step(step)
    rows = f"the median step of rows 0…{len(times) - 1}, {step:.6g} s"
    if declared is not None:
        if len(dt) >= RATE_MIN_STEPS and abs(float(declared) * step - 1) > RATE_TOLERANCE:
            fix = "; correct it, or remove it to use the times' rate"
            hint = _time_hint(step, t, float(declared)) or fix
            raise TraceError(
                f"{where}: `sample_rate_hz` is {metadata['sample_rate_hz']} Hz but the times give "
                f"{float(inferred):.6g} Hz ({rows}); expected the two within {RATE_TOLERANCE:.0%}{hint}"
            )
        return declared
    metadata["sample_rate_hz"] = _rate_text(inferred)
    if not _PLAUSIBLE_RATE_HZ[0] <= float(inferred) <= _PLAUSIBLE_RATE_HZ[1]:
        hint = _time_hint(step, t, None)
        warnings.warn(
            f"{src}: the times give a sample rate of {float(inferred):.6g} Hz ({rows} in {t.unit or 's'}), "
            f"outside {_PLAUSIBLE_RATE_HZ[0]:g}…{_PLAUSIBLE_RATE_HZ[1]:g} Hz{hint}",
            TraceWarning,
            stacklevel=2,
        )
    return inferred


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
    fields: dict[str, _Field]
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


# ---------------------------------------------------------------------------------------------------
# Value checks (vectorised; the same for every source)
# ---------------------------------------------------------------------------------------------------


@dataclass
class _Checker:
    """Checks blocks of rows as they stream in; carries the previous time across blocks."""

    schema: _Schema
    src: str
    period_s: float
    allow_gaps: bool
    max_gap_periods: float
    where: Callable[[int], str]
    prev_t: float | None = None
    rows_seen: int = 0
    #: The file's name of a column read under another name (``gyro_x_dps`` → ``wx``), for messages.
    labels: dict[str, str] = field(default_factory=dict)
    plausibility: _Plausibility | None = None
    #: How the time column was read (its unit), for the hint of a gap that is a time-unit mistake.
    time_field: _Field | None = None

    #: The trace's metadata (the GPS stream's keys are checked with its first rows).
    metadata: Mapping[str, str] = field(default_factory=dict)

    def col(self, name: str) -> str:
        """A column as the messages name it: the file's name, and the trace's when they differ."""
        return f"`{self.labels[name]}` (read as `{name}`)" if name in self.labels else f"`{name}`"

    def finish(self) -> None:
        """The end of the file: the plausibility warnings that needed all of it."""
        if self.plausibility is not None:
            self.plausibility.finish()

    def check(self, cols: dict[str, np.ndarray]) -> None:
        row0 = self.rows_seen
        for name, arr in cols.items():
            c = self.schema.column(name)
            if c.kind == "float":
                bad = ~np.isfinite(arr)
                if c.nan_allowed:
                    bad &= ~np.isnan(arr)
                if bad.any():
                    i = int(np.argmax(bad))
                    allowed = " (NaN is allowed here, infinity is not)" if c.nan_allowed else ""
                    raise TraceError(
                        f"{self.src}: {self.where(row0 + i)}, column {self.col(name)}: found {arr[i]}; "
                        f"expected a finite number{allowed}"
                    )
            elif c.kind == "flag":
                bad = (arr != 0) & (arr != 1)
                if bad.any():
                    i = int(np.argmax(bad))
                    raise TraceError(
                        f"{self.src}: {self.where(row0 + i)}, column {self.col(name)}: found {arr[i]}; "
                        "expected 0 or 1"
                    )
        if "truth_qw" in cols:
            self._check_truth(np.stack([cols[f"truth_q{c}"] for c in "wxyz"], axis=1), row0)
        if GPS_COLUMNS[0] in cols:
            if row0 == 0:
                gps_latency_s(self.metadata, f"{self.src}: metadata")
            check_gps(cols, lambda i: f"{self.src}: {self.where(row0 + i)}")
        self._check_time(cols["t_s"], row0)
        self.rows_seen += len(cols["t_s"])
        if self.plausibility is not None:
            self.plausibility.add(cols)

    def _check_truth(self, q: Array, row0: int) -> None:
        nan = np.isnan(q)
        partial = nan.any(axis=1) & ~nan.all(axis=1)
        if partial.any():
            i = int(np.argmax(partial))
            raise TraceError(
                f"{self.src}: {self.where(row0 + i)}, column `truth_q{'wxyz'[int(np.argmax(nan[i]))]}`: "
                "NaN in only some truth components; expected all four NaN (missing truth) or none"
            )
        norm = np.linalg.norm(q, axis=1)
        bad = np.abs(norm - 1.0) > TRUTH_NORM_TOLERANCE  # NaN rows compare False
        if bad.any():
            i = int(np.argmax(bad))
            raise TraceError(
                f"{self.src}: {self.where(row0 + i)}, column `truth_qw`: the truth quaternion has norm "
                f"{norm[i]:.9g}; expected a unit quaternion (|norm − 1| ≤ {TRUTH_NORM_TOLERANCE:g})"
            )

    def _check_time(self, t: Array, row0: int) -> None:
        prev = np.array([] if self.prev_t is None else [self.prev_t])
        joined = np.concatenate([prev, t])
        dt = np.diff(joined)
        offset = row0 - len(prev) + 1  # row of dt[k]'s later sample
        bad = dt <= 0
        if bad.any():
            k = int(np.argmax(bad))
            later, earlier = float(joined[k + 1]), float(joined[k])
            raise TraceError(
                f"{self.src}: {self.where(offset + k)}, column {self.col('t_s')}: time {later!r} s follows "
                f"{earlier!r} s; expected strictly increasing time"
            )
        gap = dt > self.max_gap_periods * self.period_s
        if gap.any() and not self.allow_gaps:
            k = int(np.argmax(gap))
            raise TraceError(
                f"{self.src}: {self.where(offset + k)}, column {self.col('t_s')}: gap of {dt[k]:.6g} s "
                f"({dt[k] / self.period_s:.3g} sample periods) after time {float(joined[k])!r} s; expected "
                f"at most {self.max_gap_periods:g} periods of 1/sample_rate_hz = {self.period_s:.6g} s "
                "(allow gaps with allow_gaps=True / --allow-gaps)"
                + _time_hint(
                    float(dt[k]), self.time_field or _Field("t_s", "t_s", 1.0, "s"), 1 / self.period_s
                )
            )
        if len(t):
            self.prev_t = float(t[-1])


# ---------------------------------------------------------------------------------------------------
# Reading
# ---------------------------------------------------------------------------------------------------


def _extension(path: Path) -> str:
    ext = path.suffix.lower()
    if ext in (".hdf5", ".hdf"):
        ext = ".h5"
    if ext not in _EXTENSIONS:
        raise TraceError(f"{path}: unknown trace extension `{path.suffix}`; expected .csv or .h5")
    return ext


@dataclass
class _Source:
    """An opened trace: metadata, present columns, and a generator of checked column blocks."""

    metadata: dict[str, str]
    names: list[str]
    blocks: Iterator[dict[str, np.ndarray]]


def _open(
    path: PathLike,
    schema: _Schema,
    rows: int,
    allow_gaps: bool,
    max_gap_periods: float,
    options: ReadOptions | None = None,
) -> _Source:
    p = Path(path)
    if rows < 1:
        raise TraceError(f"{p}: chunk size must be at least 1 row, got {rows}")
    ext = _extension(p)
    if not p.is_file():
        raise TraceError(f"{p}: no such trace file")
    reader = _open_csv if ext == ".csv" else _open_h5
    return reader(p, schema, rows, allow_gaps, max_gap_periods, options or ReadOptions())


def _sniff(p: Path, fh: IO[bytes]) -> None:
    head = fh.read(8192)
    fh.seek(0)
    if not head:
        raise TraceError(f"{p}: empty file; expected a CSV trace (metadata lines, a header row, data rows)")
    if head.startswith(_HDF5_SIGNATURE):
        raise TraceError(f"{p}: this is an HDF5 file, not CSV text; give it the .h5 extension")
    nul = head.find(b"\x00")
    if nul >= 0:
        raise TraceError(f"{p}: binary data (NUL byte at offset {nul}); expected a CSV text trace")


def _separator(header: str) -> str:
    """The field separator of a CSV header row: `,`, or `;` / tab in a file that has no comma there."""
    if "," in header:
        return ","
    return ";" if ";" in header else "\t" if "\t" in header else ","


def _decode(raw: bytes, p: Path, first_line: int) -> str:
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as e:
        line = first_line + raw.count(b"\n", 0, e.start)
        raise TraceError(
            f"{p}: line {line}: byte 0x{raw[e.start]:02x} is not UTF-8 text; expected a UTF-8 CSV trace"
        ) from None


def _open_csv(
    p: Path, schema: _Schema, rows: int, allow_gaps: bool, max_gap_periods: float, options: ReadOptions
) -> _Source:
    fh = p.open("rb")
    try:
        _sniff(p, fh)
        metadata: dict[str, str] = {}
        key_lines: dict[str, int] = {}
        line_no = 0
        header: str | None = None
        for raw in fh:
            line_no += 1
            text = _decode(raw, p, line_no).lstrip("\ufeff").rstrip("\r\n")
            if text.startswith("#"):
                key, sep, value = text[1:].partition(":")
                if sep and _KEY_RE.match(key.strip()):
                    if key.strip() in key_lines:
                        raise TraceError(
                            f"{p}: line {line_no}: metadata `{key.strip()}` given twice (first on line "
                            f"{key_lines[key.strip()]}); expected each key once"
                        )
                    key_lines[key.strip()] = line_no
                    metadata[key.strip()] = value.strip()
                continue
            if not text.strip():
                raise TraceError(f"{p}: line {line_no}: empty line before the header row")
            header = text
            break
        if header is None:
            raise TraceError(f"{p}: no header row; expected `# key: value` metadata lines then a header row")
        header_line = line_no
        sep = _separator(header)
        names = [n.strip() for n in header.split(sep)]
        fields = _resolve_header(schema, names, options, f"{p}: line {header_line} (header)")
        lines = "line 1" if header_line == 2 else f"lines 1–{header_line - 1}"
        head = list(itertools.islice(fh, RATE_ROWS + 1))
        if not head:
            raise TraceError(f"{p}: header only, no data rows (line {header_line} is the header)")
        t_field = next(i for i, f in enumerate(fields) if f.name == "t_s")
        times = _leading_times(head, sep, t_field, fields[t_field].factor)
        rate = _rate(metadata, schema, times, fields[t_field], f"{p}: metadata ({lines})", str(p))
    except BaseException:
        fh.close()
        raise

    def where(row: int) -> str:
        return f"line {header_line + 1 + row} (row {row})"

    checker = _checker(schema, str(p), rate, allow_gaps, max_gap_periods, where, fields, metadata)
    _note_conversions(metadata, fields)
    blocks = _csv_blocks(p, fh, head, header_line, fields, sep, rows, checker)
    return _Source(metadata, [f.name for f in fields if f.name], blocks)


def _leading_times(head: list[bytes], sep: str, index: int, factor: float) -> Array:
    """The times of the first rows, as far as they read as numbers (the rows are checked later)."""
    out: list[float] = []
    for raw in head:
        try:
            out.append(float(raw.decode("utf-8").split(sep)[index]))
        except (UnicodeDecodeError, IndexError, ValueError):
            break
    t = np.array(out, dtype=np.float64)
    return t * factor if factor != 1.0 else t


def _checker(
    schema: _Schema,
    src: str,
    rate: Fraction,
    allow_gaps: bool,
    max_gap_periods: float,
    where: Callable[[int], str],
    fields: list[_Field],
    metadata: Mapping[str, str],
) -> _Checker:
    labels = {f.name: f.source for f in fields if f.name and f.name != f.source}
    t_field = next(f for f in fields if f.name == "t_s")
    checker = _Checker(
        schema,
        src,
        float(1 / rate),
        allow_gaps,
        max_gap_periods,
        where,
        labels=labels,
        time_field=t_field,
        metadata=metadata,
    )
    if schema is PHYSICAL_SCHEMA:
        checker.plausibility = _Plausibility(src, float(1 / rate), {f.name: f for f in fields if f.name})
    return checker


def _note_conversions(metadata: dict[str, str], fields: list[_Field]) -> None:
    """Say in the metadata which columns were read under another name or unit (nothing otherwise)."""
    notes: list[str] = []
    for f in fields:
        if f.name is None:
            continue
        own = f.name.rsplit("_", 1)[1] if f.unit else ""
        if f.source != f.name or f.unit != own:
            unit = f" in {f.unit}" if f.unit != own else ""
            notes.append(f"{f.name} from `{f.source}`{unit}")
    skipped = [f.source for f in fields if f.name is None]
    if skipped:
        notes.append(f"left out: {', '.join(skipped)}")
    if notes:
        metadata["read_as"] = "; ".join(notes)


def _csv_blocks(
    p: Path,
    fh: IO[bytes],
    head: list[bytes],
    header_line: int,
    fields: list[_Field],
    sep: str,
    rows: int,
    checker: _Checker,
) -> Iterator[dict[str, np.ndarray]]:
    with fh:
        lines_iter = itertools.chain(head, fh)
        while True:
            block = list(itertools.islice(lines_iter, rows))
            if not block:
                checker.finish()
                return
            row0 = checker.rows_seen
            raw = b"".join(block)
            text = _decode(raw, p, header_line + 1 + row0)
            at_end = not raw.endswith(b"\n")
            cols = _parse_csv_block(p, text, fields, sep, checker, row0, at_end)
            checker.check(cols)
            yield cols


def _parse_csv_block(
    p: Path, text: str, fields: list[_Field], sep: str, checker: _Checker, row0: int, at_end: bool
) -> dict[str, np.ndarray]:
    schema = checker.schema
    names = [f.source for f in fields]
    kinds = [schema.column(f.name).kind if f.name else "skip" for f in fields]
    blank = _BLANK_LINE.search(text.removesuffix("\n"))
    if blank:  # loadtxt would skip it silently
        row = row0 + text.count("\n", 0, blank.start())
        raise TraceError(
            f"{p}: {checker.where(row)}: empty line; expected {len(names)} {_sep_name(sep)}-separated fields"
        )
    try:
        if all(k == "float" for k in kinds):
            table = np.loadtxt(io.StringIO(text), delimiter=sep, dtype=np.float64, ndmin=2, comments=None)
            if table.shape[1] != len(names):
                raise ValueError("field count")
            out = {f.source: table[:, i] for i, f in enumerate(fields)}
        else:
            strings = np.loadtxt(io.StringIO(text), delimiter=sep, dtype=str, ndmin=2, comments=None)
            if strings.shape[1] != len(names):
                raise ValueError("field count")
            out = {
                f.source: strings[:, i].astype(np.float64)
                for i, f in enumerate(fields)
                if kinds[i] not in ("word", "skip")
            }
    except ValueError:
        _diagnose_csv_block(p, text, names, kinds, sep, checker, row0, at_end)
        raise  # not reached: the diagnosis raises
    for i, n in enumerate(names):
        if kinds[i] != "word":
            continue
        values, bad = _parse_hex(strings[:, i])
        if bad.any():
            k = int(np.argmax(bad))
            raise TraceError(
                f"{p}: {checker.where(row0 + k)}, column `{n}`: `{strings[k, i].strip()}` is not a "
                "16-bit hexadecimal word; expected 0x0000…0xFFFF (e.g. 0xC7A7)"
            )
        out[n] = values.astype(np.uint16)
    return {f.name: out[f.source] * f.factor if f.factor != 1.0 else out[f.source] for f in fields if f.name}


def _sep_name(sep: str) -> str:
    return {",": "comma", ";": "semicolon", "\t": "tab"}[sep]


def _diagnose_csv_block(
    p: Path,
    text: str,
    names: list[str],
    kinds: list[str],
    sep: str,
    checker: _Checker,
    row0: int,
    at_end: bool,
) -> None:
    """Find the first bad line of a block that did not parse (error path only: a loop is fine)."""
    lines = text.split("\n")
    if lines and lines[-1] == "":
        lines.pop()
    what = f"{_sep_name(sep)}-separated fields"
    for k, line in enumerate(lines):
        where = checker.where(row0 + k)
        stripped = line.rstrip("\r")
        if not stripped.strip():
            raise TraceError(f"{p}: {where}: empty line; expected {len(names)} {what}")
        if stripped.lstrip().startswith("#"):
            raise TraceError(f"{p}: {where}: comment line after the header; metadata lines go before it")
        fields = stripped.split(sep)
        last = k == len(lines) - 1
        if len(fields) != len(names):
            if last and at_end and len(fields) < len(names):
                raise TraceError(
                    f"{p}: {where}: truncated last row ({len(fields)} of {len(names)} fields and no newline "
                    "at the end of the file); expected a complete row (was the file cut short?)"
                )
            hint = (
                f" (the header is {_sep_name(sep)}-separated; this row has {stripped.count(',')} commas)"
                if sep != "," and "," in stripped
                else ""
            )
            raise TraceError(
                f"{p}: {where}: {len(fields)} fields; expected {len(names)} ({', '.join(names)}){hint}"
            )
        for name, kind, token in zip(names, kinds, fields, strict=True):
            if kind in ("word", "skip"):
                continue  # word columns are checked after parsing, with their own message
            try:
                float(token)
            except ValueError:
                hint = (
                    f"; decimal commas are not read: write `{token.strip().replace(',', '.')}`"
                    if re.fullmatch(r"\s*[-+]?\d+,\d*\s*", token)
                    else ""
                )
                raise TraceError(
                    f"{p}: {where}, column `{name}`: `{token.strip()}` is not a number{hint}"
                ) from None
    raise TraceError(f"{p}: rows {row0}…{row0 + len(lines) - 1}: could not be parsed as numbers")


_BLANK_LINE = re.compile(r"(?m)^[ \t\r]*$")
_HEX_LOOKUP = np.full(128, -1, dtype=np.int64)
for _i, _ch in enumerate("0123456789abcdef"):
    _HEX_LOOKUP[ord(_ch)] = _i
    _HEX_LOOKUP[ord(_ch.upper())] = _i


def _parse_hex(tokens: NDArray[np.str_]) -> tuple[NDArray[np.int64], NDArray[np.bool_]]:
    """Vectorised parse of ``0xABCD`` / ``abcd`` tokens (1–4 hex digits); returns values and a bad mask."""
    s = np.strings.strip(tokens)
    has_prefix = np.strings.startswith(np.strings.lower(s), "0x")
    body = np.where(has_prefix, np.strings.slice(s, 2, None), s)
    length = np.strings.str_len(body)
    bad = (length < 1) | (length > 4)
    fixed = np.where(bad, "0", body).astype("<U4")
    codes = fixed.view(np.uint32).reshape(len(fixed), 4).astype(np.int64)
    valid_code = codes < 128
    digits = np.where(valid_code, _HEX_LOOKUP[np.minimum(codes, 127)], -1)
    present = np.arange(4)[None, :] < np.where(bad, 1, length)[:, None]
    bad |= (present & (digits < 0)).any(axis=1)
    weights = 16 ** (np.where(bad, 1, length)[:, None] - 1 - np.arange(4)[None, :]).clip(min=0)
    values = np.where(present, np.maximum(digits, 0) * weights, 0).sum(axis=1)
    return values, bad


def _open_h5(
    p: Path, schema: _Schema, rows: int, allow_gaps: bool, max_gap_periods: float, options: ReadOptions
) -> _Source:
    with p.open("rb") as fh:
        head = fh.read(512)
    if not head:
        raise TraceError(f"{p}: empty file; expected an HDF5 trace")
    if not head.startswith(_HDF5_SIGNATURE):
        looks_text = b"\x00" not in head and head[:1] in (b"#", b"t")
        hint = "; it looks like CSV text: give it the .csv extension" if looks_text else ""
        raise TraceError(f"{p}: not an HDF5 file (no HDF5 signature){hint}")
    try:
        f = h5py.File(p, "r")
    except OSError as e:
        raise TraceError(f"{p}: damaged or truncated HDF5 file ({e})") from None
    try:
        metadata = {str(k): _attr_text(v) for k, v in f.attrs.items()}
        names = list(f.keys())
        if not names:
            raise TraceError(
                f"{p}: no datasets; expected one dataset per column ({', '.join(schema.names())})"
            )
        fields = _resolve_header(schema, names, options, f"{p}")
        order = schema.names()
        fields = sorted((x for x in fields if x.name), key=lambda x: order.index(str(x.name)))
        length: int | None = None
        first = fields[0].source
        for x in fields:
            n = x.source
            ds = _h5_dataset(p, f, n)
            if ds.ndim != 1:
                raise TraceError(f"{p}: column `{n}`: expected a one-dimensional dataset")
            c = schema.column(str(x.name))
            kind = ds.dtype.kind
            if (c.kind == "float" and kind not in "fiu") or (c.kind != "float" and kind not in "iub"):
                raise TraceError(f"{p}: column `{n}`: dataset type {ds.dtype}; expected {_dtype_of(c)}")
            if length is None:
                length = ds.shape[0]
            elif ds.shape[0] != length:
                raise TraceError(
                    f"{p}: column `{n}` has {ds.shape[0]} rows; expected {length} like column `{first}`"
                )
        if not length:
            raise TraceError(f"{p}: header only, no data rows (every dataset is empty)")
        t_field = next(x for x in fields if x.name == "t_s")
        try:
            times = f[t_field.source][: RATE_ROWS + 1].astype(np.float64) * t_field.factor
        except (OSError, ValueError, TypeError):
            times = np.array([])  # reading the column again explains it
        rate = _rate(metadata, schema, times, t_field, f"{p}: metadata (file attributes)", str(p))
    except BaseException:
        f.close()
        raise

    def where(row: int) -> str:
        return f"row {row}"

    checker = _checker(schema, str(p), rate, allow_gaps, max_gap_periods, where, fields, metadata)
    _note_conversions(metadata, fields)
    return _Source(
        metadata, [str(x.name) for x in fields], _h5_blocks(p, f, fields, schema, int(length), rows, checker)
    )


def _h5_dataset(p: Path, f: h5py.File, name: str) -> h5py.Dataset:
    """The dataset of column ``name``, stored in this file (an external link, a dangling or looping
    soft link and a group are refused, naming the column)."""
    link = f.get(name, getlink=True)
    if isinstance(link, h5py.ExternalLink):
        raise TraceError(
            f"{p}: column `{name}` is an external link to {link.filename}:{link.path}; expected the "
            "dataset in this file"
        )
    try:
        ds = f[name]
    except (KeyError, RuntimeError, OSError) as e:
        target = f" to {link.path}" if isinstance(link, h5py.SoftLink) else ""
        raise TraceError(f"{p}: column `{name}`: the link{target} does not lead to a dataset ({e})") from None
    if not isinstance(ds, h5py.Dataset):
        raise TraceError(f"{p}: column `{name}`: expected a one-dimensional dataset, found a group")
    return ds


def _h5_blocks(
    p: Path,
    f: h5py.File,
    fields: list[_Field],
    schema: _Schema,
    length: int,
    rows: int,
    checker: _Checker,
) -> Iterator[dict[str, np.ndarray]]:
    with f:
        for start in range(0, length, rows):
            stop = min(start + rows, length)
            cols: dict[str, np.ndarray] = {}
            for x in fields:
                n, name = x.source, str(x.name)
                try:
                    block = f[n][start:stop]
                except (OSError, ValueError) as e:
                    raise TraceError(
                        f"{p}: column `{n}`, rows {start}…{stop - 1}: cannot be read ({e})"
                    ) from None
                c = schema.column(name)
                if c.kind == "word":
                    bad = (block < 0) | (block > 0xFFFF)
                    if bad.any():
                        i = int(np.argmax(bad))
                        raise TraceError(
                            f"{p}: row {start + i}, column `{n}`: {block[i]} is not a 16-bit word"
                        )
                    block = block.astype(np.uint16)
                elif c.kind == "float":
                    block = block.astype(np.float64)
                    if x.factor != 1.0:
                        block = block * x.factor
                cols[name] = block
            checker.check(cols)
            yield cols
        checker.finish()


def _attr_text(v: Any) -> str:
    if isinstance(v, bytes):
        return v.decode("utf-8", errors="replace")
    if isinstance(v, np.ndarray):
        return " ".join(str(x) for x in v.tolist())
    return str(v.item() if isinstance(v, np.generic) else v)


def _dtype_of(c: Column) -> str:
    return {"float": "float64", "flag": "uint8 (0/1)", "word": "uint16"}[c.kind]


# ---------------------------------------------------------------------------------------------------
# Writing (atomic: sins_fw.atomic)
# ---------------------------------------------------------------------------------------------------


def _format_column(c: Column, arr: np.ndarray) -> NDArray[np.str_]:
    if c.kind == "float":
        return arr.astype(np.float64).astype(str)  # shortest repr that round-trips exactly
    if c.kind == "flag":
        return arr.astype(np.uint8).astype(str)
    digits = np.array([ord(ch) for ch in "0123456789ABCDEF"], dtype=np.uint32)
    nibbles = (arr.astype(np.int64)[:, None] >> np.array([12, 8, 4, 0])) & 0xF
    return np.strings.add("0x", np.ascontiguousarray(digits[nibbles]).view("<U4").reshape(len(arr)))


def _csv_lines(schema: _Schema, cols: Mapping[str, np.ndarray]) -> str:
    """The CSV data lines of a block of rows (each line depends on its row only)."""
    names = list(cols)
    n = len(cols[names[0]])
    out = []
    # Formatted _CSV_ROWS at a time: each step makes a fixed-width UTF-32 array of whole lines
    # (≈ 700 B a row), so a block of 65 536 rows alone would take ~150 MB.
    for start in range(0, n, _CSV_ROWS):
        stop = min(start + _CSV_ROWS, n)
        line = _format_column(schema.column(names[0]), cols[names[0]][start:stop])
        for name in names[1:]:
            line = np.strings.add(
                np.strings.add(line, ","), _format_column(schema.column(name), cols[name][start:stop])
            )
        out.append("\n".join(line.tolist()) + "\n")
    return "".join(out)


def _write_csv(path: Path, schema: _Schema, metadata: Mapping[str, str], cols: dict[str, np.ndarray]) -> None:
    names = list(cols)
    n = len(cols["t_s"])
    with atomic_path(path) as tmp, tmp.open("w", encoding="utf-8", newline="\n") as out:
        out.write(f"# sins-fw {schema.title} (format described in docs/traces.md)\n")
        for k, v in metadata.items():
            out.write(f"# {k}: {v}\n")
        out.write(",".join(names) + "\n")
        for start in range(0, n, _BLOCK_ROWS):
            out.write(_csv_lines(schema, {k: a[start : start + _BLOCK_ROWS] for k, a in cols.items()}))


_H5_DTYPES = {"float": np.float64, "flag": np.uint8, "word": np.uint16}


def _h5_create(f: h5py.File, c: Column, arr: np.ndarray, chunk_rows: int) -> h5py.Dataset:
    """One column's dataset: ``arr`` as it is, or, when ``arr`` is empty, a resizable one to append
    to (gzip 9 with shuffle, chunks of ``chunk_rows``, no timestamps, the unit as an attribute)."""
    data = arr.astype(_H5_DTYPES[c.kind])
    extra: dict[str, Any] = (
        {"data": data} if len(data) else {"shape": (0,), "maxshape": (None,), "dtype": data.dtype}
    )
    ds = f.create_dataset(
        c.name,
        chunks=(chunk_rows,),
        compression="gzip",
        compression_opts=9,
        shuffle=True,
        track_times=False,
        **extra,
    )
    ds.attrs["unit"] = c.unit
    return ds


def _write_h5(
    path: Path,
    schema: _Schema,
    metadata: Mapping[str, str],
    cols: dict[str, np.ndarray],
    *,
    atomic: bool = True,
) -> None:
    n = len(cols["t_s"])
    # track_times off: the same content gives the same bytes (no timestamps); track_order keeps the
    # metadata in the order it was written (as in CSV).
    # HDF5 writes through a file that keeps the first failed write (a full disk) and raises it
    # once h5py has closed cleanly: a write failing inside HDF5 crashes the interpreter on close.
    with contextlib.ExitStack() as stack:
        tmp = stack.enter_context(atomic_path(path)) if atomic else path
        tmp_file = stack.enter_context(kept_error_file(tmp))
        f = stack.enter_context(h5py.File(tmp_file, "w", libver=("earliest", "v110"), track_order=True))
        for k, v in metadata.items():
            f.attrs[k] = v
        # Each dataset stays open until the next one exists (as the file layout has always been: HDF5
        # places the next object's metadata according to what is still open).
        ds = None
        for name, arr in cols.items():
            ds = _h5_create(f, schema.column(name), arr, min(n, _BLOCK_ROWS))
        del ds


def _write(path: PathLike, schema: _Schema, metadata: Mapping[str, str], cols: dict[str, np.ndarray]) -> None:
    p = Path(path)
    ext = _extension(p)
    meta = {"format": schema.format, **{k: v for k, v in metadata.items() if k != "format"}}
    _check_metadata(meta, schema, f"{p}: metadata")
    (_write_csv if ext == ".csv" else _write_h5)(p, schema, meta, cols)


# ---------------------------------------------------------------------------------------------------
# The trace types
# ---------------------------------------------------------------------------------------------------


class _TraceFile:
    """File I/O shared by the trace types: a subclass gives ``schema``, ``columns()`` and
    ``from_columns()``; this writes and reads it in either form, validated the same way."""

    schema: ClassVar[_Schema]
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
        _write(path, self.schema, self.metadata, self.columns())

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
            path, _BLOCK_ROWS, allow_gaps=allow_gaps, max_gap_periods=max_gap_periods, read=read
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
        src = _open(path, cls.schema, rows, allow_gaps, max_gap_periods, read)
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

    schema: ClassVar[_Schema] = PHYSICAL_SCHEMA
    _GROUPS: ClassVar[dict[str, tuple[str, ...]]] = {
        "gyro_dps": tuple(f"gyro_{a}_dps" for a in "xyz"),
        "accel_g": tuple(f"accel_{a}_g" for a in "xyz"),
        "mag_gauss": tuple(f"mag_{a}_gauss" for a in "xyz"),
        "baro_mbar": ("baro_mbar",),
        "temp_c": ("temp_c",),
        "truth_q": tuple(f"truth_q{c}" for c in "wxyz"),
        "moving": ("moving",),
        "gps": GPS_COLUMNS,
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
        for attr in ("gyro_dps", "accel_g", "mag_gauss", "baro_mbar", "temp_c", "truth_q", "gps"):
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

    schema: ClassVar[_Schema] = RAW_SCHEMA

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
    _extension(p)
    if p.is_dir():
        raise TraceError(f"{p}: is a directory; expected a trace file name ending in .csv or .h5")
    return p


def read_metadata(path: PathLike) -> dict[str, str]:
    """The metadata of a trace file without validating it (empty when unreadable: ``load`` explains)."""
    p = Path(path)
    try:
        if _extension(p) == ".h5":
            with h5py.File(p, "r") as f:
                return {str(k): _attr_text(v) for k, v in f.attrs.items()}
        metadata: dict[str, str] = {}
        with p.open("rb") as fh:
            for raw in fh:
                text = raw.decode("utf-8").lstrip("\ufeff").rstrip("\r\n")
                if not text.startswith("#"):
                    break
                key, sep, value = text[1:].partition(":")
                if sep and _KEY_RE.match(key.strip()):
                    metadata[key.strip()] = value.strip()
        return metadata
    except (OSError, UnicodeDecodeError, TraceError):
        return {}


def is_raw_register_trace(path: PathLike) -> bool:
    """Whether a trace file is a raw-register trace: its `format` metadata says so or, without it,
    its columns are the raw words (``frame0`` … ``aux_adc``). Unreadable files count as physical
    (loading them explains what is wrong)."""
    fmt = read_metadata(path).get("format")
    if fmt is not None:
        return fmt == RAW_FORMAT
    p = Path(path)
    try:
        if _extension(p) == ".h5":
            with h5py.File(p, "r") as f:
                names = set(f.keys())
        else:
            with p.open("rb") as fh:
                names = set()
                for raw in fh:
                    text = raw.decode("utf-8").lstrip("\ufeff").strip()
                    if text and not text.startswith("#"):
                        names = {n.strip() for n in text.split(_separator(text))}
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
    file's rows are on load (the same metadata check, the same :class:`_Checker`, carried across
    chunks): the one validation path for files and memory. The metadata is the first chunk's."""
    checker: _Checker | None = None
    src = ""
    for chunk in chunks:
        if checker is None:
            src = f"<{chunk.schema.title} in memory>"
            rate = _check_metadata(chunk.metadata, chunk.schema, f"{src}: metadata")
            checker = _Checker(
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
