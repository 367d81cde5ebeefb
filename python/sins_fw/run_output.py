"""The per-step output of a run as a file (`sins-fw run --out FILE`): CSV with a metadata header or
HDF5, by extension, with the conventions of the trace formats (docs/traces.md, "Run output"):
shortest round-trip float text, one dataset per column, written atomically and byte-reproducibly.
"""

from __future__ import annotations

import contextlib
import json
import os
import tomllib
from collections.abc import Iterator
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

from sins_fw import _core, quaternion
from sins_fw.errors import CheckFailed, InputError
from sins_fw.harness import CHUNK_ROWS, PS, Run, _chunks, _truth_at, check_until_s, emulate, has_dcm, has_wing
from sins_fw.profile import Profile, load_profile
from sins_fw.stream import TableWriter
from sins_fw.tablefile import (
    BLOCK_ROWS,
    Column,
    ReadOptions,
    Schema,
    csv_separator,
    open_table,
    parse_rate,
    rate_text,
    read_metadata,
    table_extension,
    write_table,
)
from sins_fw.traces import PhysicalTrace, RawRegisterTrace, check_truth, file_sha256

RUN_FORMAT = "sins-fw-run-output/1"

#: The core's output columns that the file holds (`_core.OUTPUT_COLUMNS`, the ones with file
#: columns): core column name → its file columns, one per component. The per-step (`cycle_`) ones
#: are in every file; the DCM's (`dcm_`, one row per step, the step's row) only in the DCM's, the wing
#: unit's (`wing_`, likewise) only in the wing unit's.
CORE_FILE_COLUMNS: dict[str, list[tuple[str, str]]] = {
    c["name"]: c["file"] for c in _core.OUTPUT_COLUMNS if c["file"]
}


#: The state columns (core names): written as computed, ±inf and NaN included, once the state has
#: left its range (the run's `state_out_of_range` event says at which step), so that nothing
#: computed is lost.
STATE_COLUMNS = frozenset({"cycle_quat", "cycle_euler_deg", "cycle_vel_enu", "cycle_pos"})


def _core_file_columns(prefix: str, **kind: Any) -> list[Column]:
    return [
        Column(
            name,
            unit,
            c["meaning"] if len(c["file"]) == 1 else f"{c['meaning']}: component {i}",
            **({"nonfinite_allowed": True} if c["name"] in STATE_COLUMNS else {}),
            **kind,
        )
        for c in _core.OUTPUT_COLUMNS
        if c["name"].startswith(prefix)
        for i, (name, unit) in enumerate(c["file"])
    ]


RUN_COLUMNS: tuple[Column, ...] = (
    *_core_file_columns("cycle_"),
    *(
        Column(
            f"truth_q{c}",
            "1",
            f"truth quaternion component {c} at the step time (C_b^n, ENU)",
            group="truth",
            required=False,
            nan_allowed=True,
        )
        for c in "wxyz"
    ),
    Column("moving", "0/1", "the trace's movement mask at the step time", "flag", "moving", False),
    *_core_file_columns("dcm_", group="dcm", required=False, nonfinite_allowed=True),
    *_core_file_columns("wing_", group="wing", required=False, nan_allowed=True, nonfinite_allowed=True),
    Column(
        "truth_alpha_deg",
        "°",
        "the trace's hinge angle truth at the step time (wing unit, trace with truth_alpha_deg)",
        group="truth_alpha",
        required=False,
        nan_allowed=True,
    ),
)
RUN_SCHEMA = Schema("run output", RUN_FORMAT, RUN_COLUMNS, checks=(check_truth,))


def run_columns(run: Run) -> dict[str, np.ndarray]:
    """The per-step columns of a run, in file order."""
    values = {
        "cycle_t_ps": run.time_s[:, None],
        "cycle_quat": run.quat,
        "cycle_euler_deg": run.euler_deg,
        "cycle_vel_enu": run.velocity_enu,
        "cycle_pos": run.position,
    }
    cols = _file_columns(values, "cycle_")
    if run.truth_q is not None:
        for i, c in enumerate("wxyz"):
            cols[f"truth_q{c}"] = run.truth_q[:, i]
        if run.moving is not None:
            cols["moving"] = run.moving.astype(np.uint8)
    if has_dcm(run.profile):
        cols |= _group_columns(run.step, {f"dcm_{k}": v for k, v in run.dcm.items()}, "dcm_")
    if has_wing(run.profile):
        cols |= _group_columns(run.step, {f"wing_{k}": v for k, v in run.wing.items()}, "wing_")
        if run.truth_alpha_deg is not None:
            cols["truth_alpha_deg"] = run.truth_alpha_deg
    return cols


def _file_columns(values: dict[str, np.ndarray], prefix: str) -> dict[str, np.ndarray]:
    """The file columns of the core columns ``values`` (those named ``prefix``…), one per component."""
    cols: dict[str, np.ndarray] = {}
    for core_name, file_columns in CORE_FILE_COLUMNS.items():
        if core_name.startswith(prefix):
            v = values[core_name]
            for i, (name, _unit) in enumerate(file_columns):
                cols[name] = v if v.ndim == 1 else v[:, i]
    return cols


def _group_columns(step: np.ndarray, values: dict[str, np.ndarray], prefix: str) -> dict[str, np.ndarray]:
    """An algorithm's own file columns (the DCM's `dcm_`, the wing unit's `wing_`), on the rows of their
    steps (the core gives one row per step)."""
    if not np.array_equal(values[f"{prefix}step"], step):
        raise CheckFailed(f"run output: the `{prefix}` rows are not one per attitude step")
    cols = _file_columns(values, prefix)
    return {k: v.astype(np.uint8) if v.dtype == bool else v for k, v in cols.items()}


def save_run(run: Run, path: str | os.PathLike[str], metadata: dict[str, str] | None = None) -> None:
    """Write the per-step output (``.csv`` or ``.h5``) atomically. ``metadata`` adds one-line
    ``key: value`` entries to the ones recorded always (trace, profile, overrides, numeric, rate)."""
    meta = _run_metadata(run.profile, _step_s(run), run.t0_s, metadata or {})
    write_table(path, RUN_SCHEMA, meta, run_columns(run))


def _run_metadata(profile: Profile, step_s: Fraction, t0_s: float, extra: dict[str, str]) -> dict[str, str]:
    return {
        "format": RUN_FORMAT,
        "sample_rate_hz": str(1 / step_s),
        "profile": profile.source,
        # JSON: an override may hold spaces (`faults.list=[{kind = "spike", …}]`).
        "overrides": json.dumps(list(profile.overrides), ensure_ascii=False),
        "numeric": str(profile.get("firmware.numeric")),
        "trace_t0_s": repr(t0_s),
        "created_by": "sins-fw run",
        **extra,
    }


def _step_columns(part: dict[str, Any], dcm: bool, wing: bool = False) -> dict[str, np.ndarray]:
    """The file columns of one part of streamed output (as :func:`run_columns` of a whole run;
    ``dcm``, ``wing``: the DCM's or the wing unit's columns too)."""
    values = {
        "cycle_t_ps": (part["cycle_t_ps"].astype(np.float64) * PS)[:, None],
        "cycle_quat": part["cycle_quat"],
        "cycle_euler_deg": part["cycle_euler_deg"],
        "cycle_vel_enu": part["cycle_vel_enu"],
        "cycle_pos": part["cycle_pos"],
    }
    cols = _file_columns(values, "cycle_")
    if "truth_q" in part:
        for i, c in enumerate("wxyz"):
            cols[f"truth_q{c}"] = part["truth_q"][:, i]
        if "moving" in part:
            cols["moving"] = part["moving"].astype(np.uint8)
    if dcm:
        cols |= _group_columns(part["cycle_step"], part, "dcm_")
    if wing:
        cols |= _group_columns(part["cycle_step"], part, "wing_")
        if "truth_alpha_deg" in part:
            cols["truth_alpha_deg"] = part["truth_alpha_deg"]
    return cols


class _Deferred:
    """A streamed table whose metadata needs the first ticks of the run (the update or tick
    period): the parts are held until they tell, then written as they come (:class:`TableWriter`,
    atomic: nothing appears at the path unless :meth:`close` completes)."""

    def __init__(self, path: str | os.PathLike[str]) -> None:
        self.path = Path(path)
        self.rows = 0
        self._held: list[dict[str, Any]] = []
        self._writer: TableWriter | None = None
        self._stack = contextlib.ExitStack()
        self._ticks: list[int] = []  # the first two tick times (ps)
        self._steps: list[int] = []  # the first two step-tick times (ps)

    def __enter__(self) -> _Deferred:
        return self

    def __exit__(self, kind: Any, exc: Any, tb: Any) -> None:
        self._stack.__exit__(kind, exc, tb)

    def add(self, part: dict[str, Any]) -> None:
        b_ps, b_step = part["budget_tick_ps"], part["budget_step"].astype(bool)
        if len(self._ticks) < 2:
            self._ticks += [int(t) for t in b_ps[: 2 - len(self._ticks)]]
        if len(self._steps) < 2:
            self._steps += [int(t) for t in b_ps[b_step][: 2 - len(self._steps)]]
        if self._writer is None:
            self._held.append(part)
            if self._ready(final=False):
                self._open()
            return
        self._write(part)

    def close(self) -> None:
        """Write what is held and complete the file (the rename happens when the block ends)."""
        if self._writer is None:
            self._ready(final=True)
            self._open()

    def _open(self) -> None:
        schema, meta = self._header()
        self._writer = self._stack.enter_context(
            TableWriter(self.path, schema, meta, allow_gaps=self._gaps, whole_rows=self._whole_rows)
        )
        held, self._held = self._held, []
        for p in held:
            self._write(p)

    def _write(self, part: dict[str, Any]) -> None:
        assert self._writer is not None
        cols = self._columns(part)
        self._writer.write(cols)
        self.rows = self._writer.rows

    _gaps = False
    #: Rows an HDF5 output is held whole before it streams: one chunk (a run's output may be any
    #: length; the memory it holds stays one chunk's, ≈ 13 MB for the 24 columns of a run output).
    _whole_rows = BLOCK_ROWS

    def _ready(self, final: bool) -> bool:
        raise NotImplementedError

    def _header(self) -> tuple[Schema, dict[str, str]]:
        raise NotImplementedError

    def _columns(self, part: dict[str, Any]) -> dict[str, np.ndarray]:
        raise NotImplementedError


class RunWriter(_Deferred):
    """`run --out` written as the run streams (the file :func:`save_run` writes of the whole run:
    the same bytes for CSV and for HDF5 files of up to ``tablefile.BLOCK_ROWS`` steps). Steps may be
    missing (an overrun drops one): gaps are allowed, as :func:`load_run` allows them."""

    _gaps = True
    #: The columns written (a firmware run's writer declares its own).
    schema = RUN_SCHEMA

    def __init__(
        self, path: str | os.PathLike[str], profile: Profile, t0_s: float, metadata: dict[str, str]
    ) -> None:
        super().__init__(path)
        self.profile, self.t0_s, self.metadata = profile, t0_s, metadata

    def _ready(self, final: bool) -> bool:
        if len(self._steps) >= 2:
            return True
        if final and len(self._ticks) < 2:
            raise InputError(
                "run output: the run is too short to have an update period (fewer than two ticks)"
            )
        return final

    def _header(self) -> tuple[Schema, dict[str, str]]:
        ticks = self._steps if len(self._steps) >= 2 else self._ticks
        step_s = Fraction(ticks[1] - ticks[0], 10**12)
        return self.schema, _run_metadata(self.profile, step_s, self.t0_s, self.metadata)

    def _columns(self, part: dict[str, Any]) -> dict[str, np.ndarray]:
        return _step_columns(part, has_dcm(self.profile), has_wing(self.profile))


class RawWriter(_Deferred):
    """`run --raw-out` written as the run streams (:meth:`Run.raw_register_trace` saved)."""

    _gaps = True

    def __init__(self, path: str | os.PathLike[str], metadata: dict[str, str]) -> None:
        super().__init__(path)
        self.metadata = metadata

    def _ready(self, final: bool) -> bool:
        if len(self._ticks) >= 2:
            return True
        if final:
            raise InputError("raw-register trace: the run is too short (fewer than two timer ticks)")
        return False

    def _header(self) -> tuple[Schema, dict[str, str]]:
        rate = Fraction(10**12, self._ticks[1] - self._ticks[0])
        meta = {"sample_rate_hz": rate_text(rate), **self.metadata}
        empty = RawRegisterTrace(
            t_s=np.zeros(0), words=np.zeros((0, _core.READ_WORDS), np.uint16), metadata=meta
        )
        self._meta = empty.metadata
        return RawRegisterTrace.schema, self._meta

    def _columns(self, part: dict[str, Any]) -> dict[str, np.ndarray]:
        raw = RawRegisterTrace(
            t_s=part["read_t_cs_ps"].astype(np.float64) / 1e12,
            words=np.ascontiguousarray(part["read_words"], dtype=np.uint16),
            metadata=self._meta,
        )
        return raw.columns()


def trace_reference(trace: str | os.PathLike[str], out: str | os.PathLike[str]) -> dict[str, str]:
    """How a run output records its trace so that it is found again from any working directory
    (docs/traces.md, "Run output"): ``trace``, the path relative to the output's folder (POSIX
    separators; it survives moving the two together), ``trace_abs``, the absolute path (it survives
    moving the output alone), and ``trace_sha256``, the trace file's content hash, which tells the
    right file from another one at either place."""
    t = Path(trace).absolute()
    folder = Path(out).absolute().parent
    return {
        "trace": Path(os.path.relpath(t, folder)).as_posix(),
        "trace_abs": str(t),
        "trace_sha256": file_sha256(t),
    }


def resolve_trace(path: str | os.PathLike[str], meta: dict[str, str]) -> Path:
    """The trace a run output was made from, found in order: relative to the output's folder
    (``trace``), at its absolute path (``trace_abs``), then as written relative to the working
    directory (outputs written before the absolute path and hash were recorded). With a recorded
    ``trace_sha256`` the first candidate with that content is taken; none: an InputError naming
    every place tried."""
    out = Path(path)
    written = meta.get("trace")
    if not written:
        raise InputError(f"{path}: run output without a `trace` entry in its metadata: cannot replay it")
    candidates = [out.absolute().parent / written]
    if meta.get("trace_abs"):
        candidates.append(Path(meta["trace_abs"]))
    candidates.append(Path(written))
    want = meta.get("trace_sha256")
    tried: list[str] = []
    for c in dict.fromkeys(candidates):
        if not c.is_file():
            tried.append(f"{c} (no such file)")
        elif want and file_sha256(c) != want:
            tried.append(f"{c} (another file: its SHA-256 is not the recorded {want[:12]}…)")
        else:
            return c
    raise InputError(f"{path}: cannot find its trace `{written}`; tried {'; '.join(tried)}")


def _step_s(run: Run) -> Fraction:
    """The attitude update period T in exact seconds: the spacing of the first two ticks that
    completed a step (integer picoseconds); the tick period when the run has fewer steps."""
    b = run.budget
    ticks = b["tick_ps"][b["step"].astype(bool)]
    if len(ticks) < 2:
        ticks = b["tick_ps"]
    if len(ticks) < 2:
        raise InputError("run output: the run is too short to have an update period (fewer than two ticks)")
    return Fraction(int(ticks[1]) - int(ticks[0]), 10**12)


#: The ``created_by`` of a C firmware's run output (`run --firmware --out`: sins_fw.firmware_run).
FIRMWARE_CREATED_BY = "sins-fw run --firmware"


def firmware_run_schema(columns: list[tuple[str, str, str]]) -> Schema:
    """The schema of a C firmware's run output: the time, then its columns (name, unit, description):
    the run output's own where the name is one (q0…q3, the Euler angles), else a firmware global's."""
    run_cols = {c.name: c for c in RUN_SCHEMA.columns}
    cols = [run_cols["t_s"]]
    for name, unit, description in columns:
        cols.append(run_cols[name] if name in run_cols else Column(name, unit, description))
    return Schema(RUN_SCHEMA.title, RUN_SCHEMA.format, tuple(cols))


def _header_names(path: Path) -> list[str]:
    """The column names of a table file (its header row, or its HDF5 datasets)."""
    if table_extension(path) == ".h5":
        import h5py  # a heavy import: only for an HDF5 file

        with h5py.File(path, "r") as f:
            return list(f.keys())
    with path.open("rb") as fh:
        for raw in fh:
            text = raw.decode("utf-8", errors="replace").lstrip("\ufeff").rstrip("\r\n")
            if text.startswith("#") or not text.strip():
                continue
            return [n.strip() for n in text.split(csv_separator(text))]
    return []


def load_run(path: str | os.PathLike[str]) -> tuple[dict[str, str], dict[str, np.ndarray]]:
    """Read a run-output file back: (metadata, columns), validated as on write. A C firmware's run
    output (`run --firmware --out`) is read with its own columns: the time and the globals it watched."""
    schema = RUN_SCHEMA
    if Path(path).is_file():
        try:
            firmware = read_metadata(path).get("created_by") == FIRMWARE_CREATED_BY
        except InputError:
            firmware = False  # open_table names what is wrong
        if firmware:
            names = [n for n in _header_names(Path(path)) if n != "t_s"]
            schema = firmware_run_schema([(n, "", "firmware global after the ISR") for n in names])
    src = open_table(path, schema, 1 << 16, True, 1.5)
    blocks = list(src.blocks)
    cols: dict[str, Any] = {n: np.concatenate([b[n] for b in blocks]) for n in blocks[0]} if blocks else {}
    return src.metadata, cols


def _until_s(path: str | os.PathLike[str], text: str | None) -> float | None:
    """The `until_s` a run output records (None when absent), checked as `run --until-s` checks it."""
    if not text:
        return None
    try:
        until: Any = float(text)
    except ValueError:
        until = text  # refused below, as text
    return check_until_s(until, f"{path}: metadata `until_s`")


def recorded_trace(path: str | os.PathLike[str], meta: dict[str, str]) -> Path | PhysicalTrace:
    """The trace a run output was made from (:func:`resolve_trace`), read as the run read it: a run
    whose trace needed ``--units`` / ``--columns`` records them (``trace_units``, ``trace_columns``),
    and that trace is loaded with them; any other is returned as its path, to be streamed."""
    trace = resolve_trace(path, meta)
    read = ReadOptions(units=meta.get("trace_units"), columns=meta.get("trace_columns"))
    return PhysicalTrace.load(trace, read=read) if read else trace


def recorded_profile(path: str | os.PathLike[str], meta: dict[str, str]) -> Profile:
    """The profile a run output records (``profile``, ``overrides``), loaded."""
    try:
        overrides = [str(o) for o in json.loads(meta.get("overrides") or "[]")]
    except (json.JSONDecodeError, TypeError):
        raise InputError(f"{path}: metadata `overrides` is not a JSON list of key=value texts") from None
    return load_profile(meta.get("profile", "reference"), overrides)


def replay_check(
    path: str | os.PathLike[str], bus_window: tuple[int, int] | None = None
) -> tuple[Run, dict[str, str]]:
    """Re-emulate a saved run from what its metadata records (trace, profile, overrides) and check
    that every per-step value comes out bit for bit the same, like ArduPilot's replay checker. Returns
    the new Run and the metadata (``trace`` is where the trace was found: :func:`resolve_trace`);
    raises CheckFailed naming the first differing column and row. A C firmware's run output is
    refused (InputError): its rows are the firmware's, which the Rust model does not re-emulate
    (`sins-fw replay` and `report` show it as recorded: :class:`FirmwareRunFile`)."""
    meta, saved = load_run(path)
    if meta.get("created_by") == FIRMWARE_CREATED_BY:
        raise InputError(
            f"{path}: a run of the C firmware {meta.get('firmware', '(its `firmware` metadata)')}: its rows "
            "are the firmware's globals, which the Rust model does not re-emulate; `sins-fw replay` and "
            "`sins-fw report` show it as recorded, sins_fw.load_run reads it, and `sins-fw run TRACE "
            "--firmware FW.so` runs the firmware again"
        )
    meta = {**meta, "trace": str(resolve_trace(path, meta))}  # the trace as found
    trace = recorded_trace(path, meta)
    until = _until_s(path, meta.get("until_s"))
    profile = recorded_profile(path, meta)
    run = emulate(trace, profile, bus_window=bus_window, until_s=until)
    fresh = run_columns(run)
    for name, column in saved.items():
        if name not in fresh:
            raise CheckFailed(f"{path}: column `{name}` is not produced by the replay")
        a, b = np.asarray(column), np.asarray(fresh[name])
        if a.shape != b.shape:
            raise CheckFailed(f"{path}: column `{name}` has {len(a)} rows, the replay {len(b)}")
        same = (a == b) | (np.isnan(a) & np.isnan(b)) if a.dtype.kind == "f" else a == b
        if not same.all():
            row = int(np.argmin(same))
            raise CheckFailed(
                f"{path}: replay differs at row {row}, column `{name}`: saved {a[row]!r}, now {b[row]!r}"
            )
    return run, meta


# A C firmware's run output read back (`replay` and `report` of a `run --firmware --out` file) --------

#: The run output's attitude columns a firmware's globals may fill: the quaternion (all four) and the
#: Euler angles (all three, degrees).
FIRMWARE_QUAT = ("q0", "q1", "q2", "q3")
FIRMWARE_EULER = ("roll_deg", "pitch_deg", "yaw_deg")
#: Rows of a firmware's run output read at a time (a block and the trace rows it spans are what
#: memory holds, whatever the run's length).
FIRMWARE_BLOCK_ROWS = 1 << 13


def is_firmware_run(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` is a C firmware's run output (`run --firmware --out`; False when unreadable)."""
    if not Path(path).is_file():
        return False
    meta = read_metadata(path)
    return meta.get("format") == RUN_FORMAT and meta.get("created_by") == FIRMWARE_CREATED_BY


def _file_units(path: Path, meta: dict[str, str], names: list[str]) -> dict[str, str]:
    """The unit of each column where it is known: an HDF5 dataset's ``unit`` attribute; else the
    globals file the run recorded (when it is still there and names the column); else the run
    output's own unit of an attitude column."""
    units: dict[str, str] = {}
    if table_extension(path) == ".h5":
        import h5py  # a heavy import: only for an HDF5 file

        with h5py.File(path, "r") as f:
            for n in names:
                unit = f[n].attrs.get("unit")
                if unit is not None:
                    units[n] = unit.decode() if isinstance(unit, bytes) else str(unit)
    elif meta.get("globals") and Path(meta["globals"]).is_file():
        # Read for the units alone, leniently (sins_fw.firmware_run.load_globals checks the file
        # when a run reads it; it may have changed since): a file that does not read gives none.
        with contextlib.suppress(OSError, UnicodeDecodeError, tomllib.TOMLDecodeError, RecursionError):
            entries = tomllib.loads(Path(meta["globals"]).read_text(encoding="utf-8")).get("global")
            for e in entries if isinstance(entries, list) else []:
                column, unit = (e.get("column"), e.get("unit")) if isinstance(e, dict) else (None, None)
                if column in names and isinstance(unit, str):
                    units[column] = unit
    run_cols = {c.name: c for c in RUN_SCHEMA.columns}
    for n in names:
        if not units.get(n) and n in run_cols:
            units[n] = run_cols[n].unit
    return units


#: A firmware run's file holds no burst reads and no budget rows: a part's are empty.
_NO_READS: dict[str, np.ndarray] = {
    **{
        f"read_{k}": np.zeros(0, np.uint64)
        for k in ("tick", "t_cs_ps", "t_start_ps", "t_end_ps", "sample_ps", "age_ps")
    },
    "read_words": np.zeros((0, _core.READ_WORDS), np.uint16),
    "read_rate": np.zeros((0, 3)),
    "read_accel": np.zeros((0, 3)),
    "read_sample_index": np.zeros(0, np.int64),
    "read_assumed_s": np.zeros(0),
}
_NO_BUDGET: dict[str, np.ndarray] = {
    **{
        f"budget_{k}": np.zeros(0, np.uint64)
        for k in (
            "tick",
            "tick_ps",
            "start_ps",
            "entry_end_ps",
            "spi_start_ps",
            "spi_end_ps",
            "decode_end_ps",
            "attitude_end_ps",
            "euler_end_ps",
            "nav_end_ps",
            "end_ps",
            "deadline_ps",
        )
    },
    "budget_step": np.zeros(0, np.uint8),
    "budget_overrun": np.zeros(0, np.uint8),
}


class FirmwareRunFile:
    """A C firmware's run output opened for `replay` and `report`, shown as recorded (the Rust
    model does not re-emulate a C firmware): its metadata, its columns (name and unit, when known)
    and their rows read a block at a time (:meth:`parts`: the parts a firmware run hands its sink,
    with the trace's truth where the trace is found)."""

    def __init__(self, path: str | os.PathLike[str]) -> None:
        self.path = Path(path)
        self.metadata = read_metadata(self.path)
        names = [n for n in _header_names(self.path) if n != "t_s"]
        self.schema = firmware_run_schema([(n, "", "firmware global after the ISR") for n in names])
        self.units = _file_units(self.path, self.metadata, names)
        #: The watched globals' columns, in file order.
        self.columns = names
        self.has_quat = all(n in names for n in FIRMWARE_QUAT)
        self.has_euler = all(n in names for n in FIRMWARE_EULER)
        self.rate = parse_rate(
            self.metadata.get("sample_rate_hz", ""), f"{self.path}: metadata `sample_rate_hz`"
        )
        #: Where :meth:`truth` found the recorded trace.
        self.trace_path: Path | None = None

    @property
    def has_attitude(self) -> bool:
        """Whether the firmware's columns give its attitude (q0…q3 and/or the Euler angles)."""
        return self.has_quat or self.has_euler

    def label(self, column: str) -> str:
        """``column (unit)``, or the column alone when its unit is unknown or dimensionless."""
        unit = self.units.get(column, "")
        return f"{column} ({unit})" if unit not in ("", "1") else column

    def truth(self) -> tuple[Path | Iterator[PhysicalTrace] | None, str | None]:
        """The trace the run recorded (:func:`resolve_trace`; :attr:`trace_path` is where it was
        found), to be read as the run read it (its ``--units`` / ``--columns``, streamed), or None
        and why not (one line)."""
        try:
            found = resolve_trace(self.path, self.metadata)
        except InputError as e:
            return None, str(e)
        self.trace_path = found
        read = ReadOptions(units=self.metadata.get("trace_units"), columns=self.metadata.get("trace_columns"))
        if read:
            return PhysicalTrace.iter_chunks(found, CHUNK_ROWS, allow_gaps=True, read=read), None
        return found, None

    def blocks(self) -> Iterator[dict[str, np.ndarray]]:
        """The file's rows, :data:`FIRMWARE_BLOCK_ROWS` at a time, validated as :func:`load_run` does."""
        src = open_table(self.path, self.schema, FIRMWARE_BLOCK_ROWS, True, 1.5)
        yield from src.blocks

    def parts(self, trace: Path | Iterator[PhysicalTrace] | None = None) -> Iterator[dict[str, Any]]:
        """The rows as parts of a run (the keys :func:`sins_fw.harness.emulate` hands a sink; no
        budget, bus reads or events: the file holds none), each row stamped with its tick
        (``cycle_tick``: its time over the tick period). The attitude is the firmware's quaternion, or
        its Euler angles made one (``q = from_euler``) when it has no quaternion; its Euler angles
        those of its columns, or its quaternion's (:func:`sins_fw.quaternion.to_euler`). With
        ``trace`` (the recorded trace, :meth:`truth`) a part carries the truth at each row's time
        and the movement mask, as `run --firmware` attached them."""
        until = _until_s(self.path, self.metadata.get("until_s"))
        window = _TruthReader(trace, until) if trace is not None and self.has_attitude else None
        step_s = 1 / self.rate
        for block in self.blocks():
            t_s = block["t_s"]
            n = len(t_s)
            t_ps = np.rint(t_s * 1e12).astype(np.uint64)
            tick = np.rint(t_s / float(step_s)).astype(np.int64)
            quat, euler = np.full((n, 4), np.nan), np.full((n, 3), np.nan)
            if self.has_quat:
                quat = np.stack([block[c] for c in FIRMWARE_QUAT], axis=1).astype(np.float64)
            if self.has_euler:
                euler = np.stack([block[c] for c in FIRMWARE_EULER], axis=1).astype(np.float64)
                if not self.has_quat:
                    quat = quaternion.from_euler(*np.radians(euler).T)
            elif self.has_quat:
                with np.errstate(invalid="ignore"):
                    euler = quaternion.to_euler_deg(quat)
            part: dict[str, Any] = {
                "cycle_t_ps": t_ps,
                "cycle_step": tick.astype(np.uint64),
                "cycle_tick": tick,
                "cycle_quat": quat,
                "cycle_euler_deg": euler,
                "cycle_vel_enu": np.full((n, 3), np.nan),
                "cycle_pos": np.full((n, 3), np.nan),
                **_NO_READS,
                "events": [],
                "firmware_t_s": t_s,
                "firmware_globals": {c: block[c] for c in self.columns},
                **_NO_BUDGET,
            }
            if window is not None and n:
                t, q, moving, q0 = window.covering(float(t_s[-1]))
                if len(t):
                    part["truth_q"] = _truth_at(t, q, t_s)
                    part["truth_q0"] = q0
                    if moving is not None:
                        idx = np.clip(np.searchsorted(t, t_s, side="right") - 1, 0, len(t) - 1)
                        part["moving"] = moving[idx]
            yield part


class _TruthReader:
    """The truth of the recorded trace around the rows being read, a chunk at a time (times from
    the trace's first sample, as the firmware run counted them): the rows from the one before the
    block's first time on, so that the truth at a row is interpolated between the same two trace
    rows as over the whole trace (:func:`sins_fw.harness._truth_at`), bit for bit."""

    def __init__(self, trace: Path | Iterator[PhysicalTrace], until_s: float | None = None) -> None:
        # Gaps allowed: the truth is only read here (a run with --allow-gaps recorded such a trace).
        self.chunks = _chunks(trace, CHUNK_ROWS, allow_gaps=True)
        self.t0: float | None = None
        self.t = np.empty(0)
        self.q = np.empty((0, 4))
        self.moving: np.ndarray | None = None
        self.q0: np.ndarray | None = None
        self.ended = False
        #: The run's `--until-s`: its input, so its truth, ended there.
        self.until_s = until_s

    def covering(self, until_s: float) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, np.ndarray | None]:
        """The truth rows read so far from the last one at or before the previous call's end, read
        on until one is past ``until_s`` (or the trace ends). Empty when the trace has no truth."""
        while not self.ended and (not len(self.t) or self.t[-1] <= until_s):
            chunk = next(self.chunks, None)
            if chunk is None:
                self.ended = True
                break
            if not len(chunk):
                continue
            if self.t0 is None:
                self.t0 = float(chunk.t_s[0])
            if chunk.truth_q is None:  # a trace without truth: nothing to compare with
                self.ended = True
                break
            if self.q0 is None:
                self.q0 = np.asarray(chunk.truth_q[0], dtype=np.float64).copy()
            t = chunk.t_s - self.t0
            stop = len(t) if self.until_s is None else int(np.searchsorted(t, self.until_s, side="right"))
            self.t = np.concatenate([self.t, t[:stop]])
            self.q = np.concatenate([self.q, chunk.truth_q[:stop]])
            if chunk.moving is not None:
                moving = chunk.moving[:stop]
                self.moving = moving if self.moving is None else np.concatenate([self.moving, moving])
            if stop < len(t):
                self.ended = True
        out = (self.t, self.q, self.moving, self.q0)
        # Keep the row before the end for the next block (its first rows may fall before it).
        keep = max(int(np.searchsorted(self.t, until_s, side="right")) - 1, 0)
        self.t, self.q = self.t[keep:], self.q[keep:]
        if self.moving is not None:
            self.moving = self.moving[keep:]
        return out
