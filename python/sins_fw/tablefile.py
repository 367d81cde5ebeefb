"""The table-file engine: the files of :mod:`sins_fw.traces` (physical and raw-register traces)
and of :mod:`sins_fw.run_output` (`sins-fw run --out`). A format is a :class:`Schema` (its columns,
each a :class:`Column`, and its own checks); this module reads it from CSV with a ``# key: value``
metadata header (``.csv``) or from columnar HDF5 (``.h5``) in validated blocks (:func:`open_table`;
other units and column names through :class:`ReadOptions`, the sample rate from the times when the
metadata has none) and writes it byte-reproducibly and atomically (:func:`write_table`; the streamed
writer is :class:`sins_fw.stream.TableWriter`). The files' conventions are in docs/traces.md.

Reading validates everything and raises :class:`~sins_fw.errors.TraceError` with a message naming
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
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from decimal import Decimal
from fractions import Fraction
from pathlib import Path
from typing import IO, Any, Protocol

import h5py
import numpy as np
from numpy.typing import NDArray

from sins_fw.atomic import atomic_path, kept_error_file
from sins_fw.errors import TraceError, TraceWarning, utf8_text

Array = NDArray[np.float64]
PathLike = str | os.PathLike[str]

#: Default gap limit: a time step longer than this many nominal sample periods is an error
#: (one dropped sample already makes a step of 2 periods; jitter up to 50 % is accepted).
DEFAULT_MAX_GAP_PERIODS = 1.5
#: Rows per HDF5 chunk and per block when writing CSV.
BLOCK_ROWS = 65536
#: Rows formatted at a time when writing CSV (the bytes do not depend on it), and cells: fewer rows
#: a step for a table of more than 32 columns.
_CSV_ROWS = 8192
_CSV_CELLS = _CSV_ROWS * 32
_HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
_KEY_RE = re.compile(r"^[A-Za-z0-9_.\-]+$")
_EXTENSIONS = (".csv", ".h5")
#: Standard gravity: the unit "g" of the traces (m/s²).
G0 = 9.80665


@dataclass(frozen=True)
class Column:
    """One column of a table format (a trace, the run output)."""

    name: str
    unit: str
    description: str
    kind: str = "float"  # "float", "flag" (0/1) or "word" (16-bit register word)
    group: str = ""  # columns of one group are all present or all absent
    required: bool = True
    nan_allowed: bool = False
    #: Any value, ±inf and NaN included: a computed state written as it was once it left its range
    #: (the run output's state columns: the run's events say where it left it).
    nonfinite_allowed: bool = False

    @property
    def stem(self) -> str:
        """The quantity without its unit suffix (``gyro_x_dps`` → ``gyro_x``): to spot wrong units."""
        if self.kind != "float" or self.unit in ("1", ""):
            return self.name
        return self.name.rsplit("_", 1)[0]


#: Other names of the time column (the message on them asks for `t_s`).
_ALIASES = {"time": "t_s", "timestamp": "t_s", "time_s": "t_s"}


#: A check of a block of rows beyond each column's own rule (:attr:`Schema.checks`): it gets the
#: checker (its ``src``, ``where`` and ``metadata`` name the place in messages), the block's columns
#: and the block's first row, and raises TraceError.
BlockCheck = Callable[["Checker", dict[str, np.ndarray], int], None]
#: Every schema's title by its format (the message on a file of another format names it).
_TITLES: dict[str, str] = {}


class Plausibility(Protocol):
    """Watches the rows read from a file for values that read but look wrong (warnings only):
    :attr:`Schema.plausibility` makes one per file."""

    def add(self, cols: Mapping[str, np.ndarray]) -> None: ...

    def finish(self) -> None: ...


@dataclass(frozen=True)
class Schema:
    """A table format: its title (in messages), its ``format`` metadata value and its columns in file
    order, and what this kind of table checks beyond each column's rule: ``checks`` run on each block
    of rows (after the column checks, before the time check), ``plausibility`` makes the watcher of a
    file's rows (src, sample period, the columns as read), ``unknown_hint`` ends the message on an
    unknown column."""

    title: str
    format: str
    columns: tuple[Column, ...]
    checks: tuple[BlockCheck, ...] = ()
    plausibility: Callable[[str, float, dict[str, Field]], Plausibility] | None = None
    unknown_hint: str = ""

    def __post_init__(self) -> None:
        _TITLES[self.format] = self.title
        # The columns by name (the first of a name), for :meth:`column`: a table of a thousand
        # columns (a firmware's watched globals) looks each up once per block.
        by_name: dict[str, Column] = {}
        for c in self.columns:
            by_name.setdefault(c.name, c)
        object.__setattr__(self, "_by_name", by_name)

    def column(self, name: str) -> Column:
        by_name: dict[str, Column] = self.__dict__["_by_name"]
        return by_name[name]

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


def check_metadata(metadata: Mapping[str, str], schema: Schema, where: str) -> Fraction:
    """The metadata of a table of ``schema`` checked (keys, one-line values, ``format``); its
    ``sample_rate_hz``, which must be there."""
    rate = _check_metadata_keys(metadata, schema, where)
    if rate is None:
        raise TraceError(f"{where}: `sample_rate_hz` is missing (the nominal sample rate, Hz)")
    return rate


def _check_metadata_keys(metadata: Mapping[str, str], schema: Schema, where: str) -> Fraction | None:
    """The metadata's keys and format checked; the declared rate (None when there is none)."""
    for key, value in metadata.items():
        if not _KEY_RE.match(key):
            raise TraceError(f"{where}: key `{key}` must be letters, digits, `_`, `.` or `-`")
        if not isinstance(value, str) or "\n" in value or "\r" in value:
            raise TraceError(f"{where}: `{key}` must be a one-line string")
    fmt = metadata.get("format")
    if fmt is not None and fmt != schema.format:
        other = _TITLES.get(fmt, fmt)
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
class Field:
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


def _resolve_header(schema: Schema, names: list[str], options: ReadOptions, where: str) -> list[Field]:
    """The file's columns as trace columns: units from the name's suffix or ``options.units``, names
    through ``options.columns``; unknown columns, wrong units and a bad map are explained."""
    units = parse_units(options.units)
    mapping = parse_columns(options.columns)
    by_source: dict[str, str] = {}
    known = {c.name for c in schema.columns}
    for key, source in mapping.items():
        if source not in names:
            raise TraceError(
                f"{where}: --columns maps `{key}` to `{source}`, which is not a column of the file "
                f"(its columns: {', '.join(names)})"
            )
        if source in by_source:
            raise TraceError(
                f"{where}: --columns maps both `{by_source[source]}` and `{key}` to `{source}`; expected "
                "one trace column per column of the file"
            )
        # A column whose own name is a trace column (with its unit) is that quantity: read as another
        # (a gyro column as the time) it is a slip of the map, not a file's odd naming.
        quantity, target = source.split("_", 1)[0], key.split("_", 1)[0].lower()
        target = "t" if target in ("time", "timestamp") else target
        if source in known and quantity != target:
            raise TraceError(
                f"{where}: --columns maps `{key}` to `{source}`, which is a `{quantity}` column by its name; "
                f"expected a column of the same quantity for `{key}` (axes may be swapped, quantities not)"
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
    schema: Schema, source: str, key: str | None, units: dict[str, str], mapped: bool, where: str
) -> Field:
    name = key if key is not None else source
    lowered = name.strip().lower()
    via = f" (mapped from `{source}`)" if key is not None else ""
    known = {c.name: c for c in schema.columns}
    if name in known:
        c = known[name]
        q = _quantity(c)
        unit = units.get(q, c.name.rsplit("_", 1)[1]) if q else ""
        return Field(source, name, UNITS[q][unit] if q else 1.0, unit)
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
                return Field(source, c.name, UNITS[q][units[q]], units[q])
            raise TraceError(
                f"{where}: column `{name}`{via} has no recognised unit: expected `{c.name}` ({c.unit}); "
                f"name the unit in the column ({', '.join(f'`{c.stem}_{u}`' for u in UNITS[q])}) or give "
                f"it with --units {q}=UNIT"
            )
        if lowered.startswith(c.stem + "_"):
            unit = lowered[len(c.stem) + 1 :]
            if q in units or unit in UNITS[q]:
                u = units.get(q, unit)
                return Field(source, c.name, UNITS[q][u], u)
            others = ", ".join(f"`{c.stem}_{u}`" for u in list(UNITS[q])[1:])
            raise TraceError(
                f"{where}: column `{name}`{via} has the wrong unit: expected `{c.name}` ({c.unit}), or "
                f"{others}; or give the unit with --units {q}=UNIT"
            )
    if mapped and key is None:
        return Field(source, None)
    if key is not None:
        raise TraceError(f"{where}: --columns maps `{key}` to `{source}`: {schema.diagnose_unknown(key)}")
    raise TraceError(f"{where}: {schema.diagnose_unknown(name)}{schema.unknown_hint}")


#: Time units tried when a rate looks wrong, with their names in messages.
_TIME_UNITS = {"s": "seconds", "ms": "milliseconds", "us": "microseconds", "ns": "nanoseconds"}
#: Sample rates an IMU trace can have (Hz): outside, the times are taken to be in another unit.
_PLAUSIBLE_RATE_HZ = (1.0, 1e5)


def rate_of_step(step: float) -> Fraction:
    """The rate of a median step: a simple ratio when one is that close (4096/5, 2000/7, 100), else
    six significant digits."""
    rate = 1.0 / step
    simple = Fraction(rate).limit_denominator(1000)
    if simple > 0 and abs(float(simple) - rate) <= 1e-9 * rate:
        return simple
    return Fraction(f"{rate:.6g}")


def rate_text(rate: Fraction) -> str:
    """A rate as the metadata writes it, exact: a decimal when it has one (``250``, ``819.2``), else
    ``num/den`` (``2000/7``)."""
    den = rate.denominator
    while den % 2 == 0:
        den //= 2
    while den % 5 == 0:
        den //= 5
    if den != 1:
        return f"{rate.numerator}/{rate.denominator}"
    text = f"{Decimal(rate.numerator) / Decimal(rate.denominator):f}"
    return text.rstrip("0").rstrip(".") if "." in text else text


def _time_hint(step: float, t: Field, want_hz: float | None) -> str:
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


def _rate(metadata: dict[str, str], schema: Schema, times: Array, t: Field, where: str, src: str) -> Fraction:
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
    inferred = rate_of_step(step)
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
    metadata["sample_rate_hz"] = rate_text(inferred)
    if not _PLAUSIBLE_RATE_HZ[0] <= float(inferred) <= _PLAUSIBLE_RATE_HZ[1]:
        hint = _time_hint(step, t, None)
        warnings.warn(
            f"{src}: the times give a sample rate of {float(inferred):.6g} Hz ({rows} in {t.unit or 's'}), "
            f"outside {_PLAUSIBLE_RATE_HZ[0]:g}…{_PLAUSIBLE_RATE_HZ[1]:g} Hz{hint}",
            TraceWarning,
            stacklevel=2,
        )
    return inferred


# ---------------------------------------------------------------------------------------------------
# Value checks (vectorised; the same for every source)
# ---------------------------------------------------------------------------------------------------


@dataclass
class Checker:
    """Checks blocks of rows as they stream in; carries the previous time across blocks."""

    schema: Schema
    src: str
    period_s: float
    allow_gaps: bool
    max_gap_periods: float
    where: Callable[[int], str]
    prev_t: float | None = None
    rows_seen: int = 0
    #: The file's name of a column read under another name (``gyro_x_dps`` → ``wx``), for messages.
    labels: dict[str, str] = field(default_factory=dict)
    plausibility: Plausibility | None = None
    #: How the time column was read (its unit), for the hint of a gap that is a time-unit mistake.
    time_field: Field | None = None

    #: The table's metadata (for the schema's ``checks``: a GPS stream's keys, for example).
    metadata: Mapping[str, str] = field(default_factory=dict)

    def col(self, name: str) -> str:
        """A column as the messages name it: the file's name, and the trace's when they differ."""
        return f"`{self.labels[name]}` (read as `{name}`)" if name in self.labels else f"`{name}`"

    def finish(self) -> None:
        """The end of the file: the plausibility warnings that needed all of it."""
        if self.plausibility is not None:
            self.plausibility.finish()

    def check(self, cols: dict[str, np.ndarray]) -> None:
        """Check the next block of rows (raises TraceError naming the first bad value)."""
        row0 = self.rows_seen
        for name, arr in cols.items():
            c = self.schema.column(name)
            if c.kind == "float" and not c.nonfinite_allowed:
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
        for extra in self.schema.checks:
            extra(self, cols, row0)
        self._check_time(cols["t_s"], row0)
        self.rows_seen += len(cols["t_s"])
        if self.plausibility is not None:
            self.plausibility.add(cols)

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
                    float(dt[k]), self.time_field or Field("t_s", "t_s", 1.0, "s"), 1 / self.period_s
                )
            )
        if len(t):
            self.prev_t = float(t[-1])


# ---------------------------------------------------------------------------------------------------
# Reading
# ---------------------------------------------------------------------------------------------------


def table_extension(path: Path) -> str:
    """The file form by extension: ``.csv`` or ``.h5`` (``.hdf5``/``.hdf`` count as ``.h5``)."""
    ext = path.suffix.lower()
    if ext in (".hdf5", ".hdf"):
        ext = ".h5"
    if ext not in _EXTENSIONS:
        raise TraceError(f"{path}: unknown trace extension `{path.suffix}`; expected .csv or .h5")
    return ext


@dataclass
class OpenedTable:
    """An opened trace: metadata, present columns, and a generator of checked column blocks."""

    metadata: dict[str, str]
    names: list[str]
    blocks: Iterator[dict[str, np.ndarray]]


def open_table(
    path: PathLike,
    schema: Schema,
    rows: int,
    allow_gaps: bool,
    max_gap_periods: float,
    options: ReadOptions | None = None,
) -> OpenedTable:
    """Open a table file of ``schema`` (CSV or HDF5 by extension): its metadata and header are
    checked now, its rows as the blocks of at most ``rows`` rows are taken from
    :attr:`OpenedTable.blocks` (each validated: values, the schema's checks, times and gaps)."""
    p = Path(path)
    if rows < 1:
        raise TraceError(f"{p}: chunk size must be at least 1 row, got {rows}")
    ext = table_extension(p)
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


def csv_separator(header: str) -> str:
    """The field separator of a CSV header row: `,`, or `;` / tab in a file that has no comma there."""
    if "," in header:
        return ","
    return ";" if ";" in header else "\t" if "\t" in header else ","


def _decode(raw: bytes, p: Path, first_line: int) -> str:
    return utf8_text(raw, p, "a UTF-8 CSV trace", TraceError, first_line)


def _open_csv(
    p: Path, schema: Schema, rows: int, allow_gaps: bool, max_gap_periods: float, options: ReadOptions
) -> OpenedTable:
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
        sep = csv_separator(header)
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

    checker = _checker(schema, str(p), rate, allow_gaps, max_gap_periods, header_line + 1, fields, metadata)
    blocks = _csv_blocks(p, fh, head, header_line, fields, sep, rows, checker)
    return OpenedTable(metadata, [f.name for f in fields if f.name], blocks)


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
    schema: Schema,
    src: str,
    rate: Fraction,
    allow_gaps: bool,
    max_gap_periods: float,
    first_line: int | None,
    fields: list[Field],
    metadata: dict[str, str],
) -> Checker:
    """The checker of a table's rows, which names a row by its number and, in a file of lines (CSV),
    by its line (``first_line``: row 0's); the conversions of ``fields`` noted in ``metadata``."""

    def where(row: int) -> str:
        return f"row {row}" if first_line is None else f"line {first_line + row} (row {row})"

    labels = {f.name: f.source for f in fields if f.name and f.name != f.source}
    t_field = next(f for f in fields if f.name == "t_s")
    checker = Checker(
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
    if schema.plausibility is not None:
        checker.plausibility = schema.plausibility(
            src, float(1 / rate), {f.name: f for f in fields if f.name}
        )
    _note_conversions(metadata, fields)
    return checker


def _note_conversions(metadata: dict[str, str], fields: list[Field]) -> None:
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
    fields: list[Field],
    sep: str,
    rows: int,
    checker: Checker,
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
    p: Path, text: str, fields: list[Field], sep: str, checker: Checker, row0: int, at_end: bool
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
    checker: Checker,
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
    p: Path, schema: Schema, rows: int, allow_gaps: bool, max_gap_periods: float, options: ReadOptions
) -> OpenedTable:
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

    checker = _checker(schema, str(p), rate, allow_gaps, max_gap_periods, None, fields, metadata)
    return OpenedTable(
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
    fields: list[Field],
    schema: Schema,
    length: int,
    rows: int,
    checker: Checker,
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


def csv_header(schema: Schema, metadata: Mapping[str, str], names: list[str]) -> str:
    """A CSV table's head: the title line, the metadata as ``# key: value`` lines, the column names."""
    title = f"# sins-fw {schema.title} (format described in docs/traces.md)"
    return "\n".join([title, *(f"# {k}: {v}" for k, v in metadata.items()), ",".join(names)]) + "\n"


def csv_lines(schema: Schema, cols: Mapping[str, np.ndarray]) -> str:
    """The CSV data lines of a block of rows (each line depends on its row only)."""
    names = list(cols)
    n = len(cols[names[0]])
    columns = {c.name: c for c in schema.columns}
    out = []
    # Formatted a few rows at a time: each step makes fixed-width UTF-32 arrays of whole lines
    # (≈ 700 B a row of a run output), so a block of 65 536 rows alone would take ~150 MB; a table
    # of many columns (a firmware's watched globals) takes fewer rows a step, as many cells.
    step = max(1, min(_CSV_ROWS, _CSV_CELLS // len(names)))
    for start in range(0, n, step):
        stop = min(start + step, n)
        parts = [_format_column(columns[name], cols[name][start:stop]) for name in names]
        out.append("\n".join(_join_columns(parts).tolist()) + "\n")
    return "".join(out)


def _join_columns(parts: list[NDArray[np.str_]]) -> NDArray[np.str_]:
    """The columns' texts joined by commas, row by row: pairwise, in a balanced tree, so that each
    character is copied once per level (log2 of the columns), not once per column after it (a
    line grown one column at a time costs the square of the columns)."""
    while len(parts) > 1:
        joined = [
            np.strings.add(np.strings.add(a, ","), b) for a, b in zip(parts[::2], parts[1::2], strict=False)
        ]
        if len(parts) % 2:
            joined.append(parts[-1])
        parts = joined
    return parts[0]


def write_csv(path: Path, schema: Schema, metadata: Mapping[str, str], cols: dict[str, np.ndarray]) -> None:
    """Write a table as CSV with its metadata header, atomically (no validation: :func:`write_table`)."""
    n = len(cols["t_s"])
    with atomic_path(path) as tmp, tmp.open("w", encoding="utf-8", newline="\n") as out:
        out.write(csv_header(schema, metadata, list(cols)))
        for start in range(0, n, BLOCK_ROWS):
            out.write(csv_lines(schema, {k: a[start : start + BLOCK_ROWS] for k, a in cols.items()}))


_H5_DTYPES = {"float": np.float64, "flag": np.uint8, "word": np.uint16}


def h5_create(f: h5py.File, c: Column, arr: np.ndarray, chunk_rows: int) -> h5py.Dataset:
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


def write_h5(
    path: Path,
    schema: Schema,
    metadata: Mapping[str, str],
    cols: dict[str, np.ndarray],
    *,
    atomic: bool = True,
) -> None:
    """Write a table as HDF5 (one gzip dataset per column, metadata as file attributes, no
    timestamps: the same content gives the same bytes), atomically unless ``atomic`` is false
    (no validation: :func:`write_table`)."""
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
            ds = h5_create(f, schema.column(name), arr, min(n, BLOCK_ROWS))
        del ds


def write_table(
    path: PathLike, schema: Schema, metadata: Mapping[str, str], cols: dict[str, np.ndarray]
) -> None:
    """Write a table of ``schema`` as CSV or HDF5 by extension, atomically; the metadata gets the
    schema's ``format`` and is checked first (the rows are not: validate them before)."""
    p = Path(path)
    ext = table_extension(p)
    meta = {"format": schema.format, **{k: v for k, v in metadata.items() if k != "format"}}
    check_metadata(meta, schema, f"{p}: metadata")
    (write_csv if ext == ".csv" else write_h5)(p, schema, meta, cols)


def read_metadata(path: PathLike) -> dict[str, str]:
    """The metadata of a trace file without validating it (empty when unreadable: ``load`` explains)."""
    p = Path(path)
    try:
        if table_extension(p) == ".h5":
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
