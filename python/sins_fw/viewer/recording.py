"""Log a run to a Rerun recording part by part, as the emulation streams it out.

:class:`Recorder` takes each part of the output ``emulate(..., sink=...)`` hands out and logs it at
once with ``send_columns`` (one call per entity and part, never one per row), keeping only what
links one part to the next (the last tick, the events waiting for their cycle, the trace rows
around the reads, the other backends' steps not yet matched): memory is bounded by a part whatever
the run's length (issue 24, item 11). A whole :class:`~sins_fw.harness.Run` is logged as one part
(:func:`log_run`), so both go through the same code.

Rows carry the emulated-time timeline (ns) and their own index: ``cycle`` for attitude steps,
``tick`` for the per-tick budget and the per-tick reads (and for the cycle rows too, so the two can
be lined up). Paths and timeline names are in :mod:`sins_fw.viewer.paths`.

:func:`recording_file` writes a recording to a file as it is logged, atomically (a temporary file
beside the destination, renamed when complete).
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import threading
import uuid
import weakref
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import rerun as rr
from numpy.typing import NDArray

from sins_fw import quaternion
from sins_fw.atomic import atomic_path
from sins_fw.harness import CHUNK_ROWS, Run, TraceInput, _chunks, has_dcm, has_wing
from sins_fw.metrics import AttitudeErrors, attitude_errors, wrap_deg
from sins_fw.profile import Profile
from sins_fw.report_stream import _Attitude, run_part
from sins_fw.traces import RAW_WORD_COLUMNS
from sins_fw.viewer import paths
from sins_fw.viewer.layout import default_blueprint

# The recording's Arrow buffers (each entity's rows until a chunk is cut, each chunk until the
# writer has it) come and go by the megabyte: Arrow's default pool (its bundled jemalloc) kept the
# freed ones mapped, 46 MB of a one-hour `replay` (282 → 236 MB, benchmarks/peak_rss.md). The
# system allocator returns them.
pa.set_memory_pool(pa.system_memory_pool())

Array = NDArray[np.float64]
PS_PER_NS = 1000
#: Board drawing, metres-free "board units": a 2:2:1 box, the ADIS16407 on top.
BOARD_HALF_SIZE = (1.0, 0.7, 0.12)
ESTIMATE_COLOR = (66, 135, 245)
TRUTH_COLOR = (200, 200, 200, 90)
AXIS_COLORS = ((230, 60, 60), (60, 200, 60), (60, 110, 240))
LIGHT_AXIS_COLORS = [tuple(int(c + (255 - c) * 0.55) for c in col) for col in AXIS_COLORS]
SEVERITY_LEVEL = {
    "info": rr.TextLogLevel.INFO,
    "warning": rr.TextLogLevel.WARN,
    "error": rr.TextLogLevel.ERROR,
}
#: The 14 output registers of a burst (the command frame's answer, word 0, is don't-care).
REGISTERS = RAW_WORD_COLUMNS[1:]
AXES = ("x", "y", "z")
#: Parts logged between two waits for the sink: at most this many parts' encoded rows queue up in
#: Rerun's pipeline (≈ 1 MB each on the reference profile, 10 s of trace at 819.2 SPS).
FLUSH_PARTS = 8


def _time(t_ps: NDArray[Any]) -> rr.TimeColumn:
    return rr.TimeColumn(
        paths.TIME, duration=(np.asarray(t_ps, dtype=np.uint64) // PS_PER_NS).astype("timedelta64[ns]")
    )


def _seq(name: str, values: NDArray[Any]) -> rr.TimeColumn:
    return rr.TimeColumn(name, sequence=np.asarray(values, dtype=np.int64))


#: Bytes of one entity's rows (as Arrow columns) gathered into one chunk before it is written.
#: Rerun's footer keeps ≈ 3.5 kB per chunk in the writer's memory until the end of the file: one
#: chunk per entity and part made 8 694 chunks on an hour of the reference profile (30 MB held), a
#: 24-hour replay 0.7 GB. Chunks of about 1 MB hold the manifest to well under 1 % of the
#: recording's raw bytes, and what waits to ≈ 1 MB per entity (benchmarks/rerun_save.md).
ENTITY_CHUNK_BYTES = 1 << 20
#: Field metadata Rerun recomputes when a chunk is made from a record batch without it.
_SORTED = b"rerun:is_sorted"


class _Stream:
    """What this module keeps per recording stream: the next row and chunk ids and the rows of each
    entity waiting to be written as one chunk.

    Ids are Rerun's TUIDs (8 bytes of time in ns, 8 of a counter, big-endian) made a function of the
    recording id and of the order of logging, instead of the SDK's clock reading and per-process
    random counter: the same recording logged twice gets the same ids, so the same bytes. The "time"
    part is 63 bits of the recording id's SHA-256 (distinct recordings get distinct ids); the counter
    increases with every row and chunk written, so the ids keep the order in which an entity's rows
    were logged (Rerun resolves ties of latest-at queries and static rows by row id)."""

    def __init__(self, recording_id: str) -> None:
        digest = hashlib.sha256(recording_id.encode("utf-8")).digest()
        self.time_ns = int.from_bytes(digest[:8], "big") >> 1
        self.next = 1
        self.pending: dict[str, list[pa.RecordBatch]] = {}

    def take(self, n: int) -> NDArray[np.void]:
        """``n`` consecutive ids, as 16-byte values."""
        ids = np.empty(n, dtype=[("time_ns", ">u8"), ("inc", ">u8")])
        ids["time_ns"] = self.time_ns
        ids["inc"] = np.arange(self.next, self.next + n, dtype=np.uint64)
        self.next += n
        return ids.view("V16")


_STREAMS: weakref.WeakKeyDictionary[rr.RecordingStream, _Stream] = weakref.WeakKeyDictionary()


def _stream(rec: rr.RecordingStream) -> _Stream:
    state = _STREAMS.get(rec)
    if state is None:
        state = _STREAMS[rec] = _Stream(rec.get_recording_id() or "")
    return state


def _unidentified(chunk: rr.chunk.Chunk) -> pa.RecordBatch:
    """The record batch of ``chunk`` without its ids' claims: no chunk id, no sortedness flags (a
    batch joined to the next part's is checked again by Rerun)."""
    batch = chunk.to_record_batch()
    fields = [
        f.with_metadata({k: v for k, v in (f.metadata or {}).items() if k != _SORTED}) for f in batch.schema
    ]
    metadata = {k: v for k, v in (batch.schema.metadata or {}).items() if k != b"rerun:id"}
    return pa.RecordBatch.from_arrays(batch.columns, schema=pa.schema(fields, metadata=metadata))


def _write(rec: rr.RecordingStream, batches: list[pa.RecordBatch]) -> None:
    """``batches`` (one entity, one schema) as one chunk with ids of :class:`_Stream` (Rerun keeps
    the ids of a record batch that carries both: ``Chunk.from_record_batch``)."""
    batch = batches[0] if len(batches) == 1 else pa.concat_batches(batches)
    ids = _stream(rec).take(batch.num_rows + 1)
    row_at = 0
    assert (batch.schema.field(row_at).metadata or {}).get(b"rerun:kind") == b"control", batch.schema
    columns = list(batch.columns)
    columns[row_at] = pa.FixedSizeBinaryArray.from_buffers(
        pa.binary(16), batch.num_rows, [None, pa.py_buffer(ids[1:].tobytes())]
    )
    metadata = dict(batch.schema.metadata or {})
    metadata[b"rerun:id"] = b"chunk_" + ids[0].tobytes().hex().upper().encode()
    (chunk,) = rr.chunk.Chunk.from_record_batch(
        pa.RecordBatch.from_arrays(columns, schema=batch.schema.with_metadata(metadata))
    )
    rec.send_chunks(chunk)


def _send(rec: rr.RecordingStream, path: str, index: list[rr.TimeColumn], columns: Any) -> None:
    """Columns at ``path`` on the timelines of ``index`` (none: static, written at once). Temporal
    rows wait until their entity has :data:`ENTITY_CHUNK_BYTES` (or :func:`_flush`), then go out as
    one chunk."""
    batch = _unidentified(rr.chunk.Chunk.from_columns(path, index, columns))
    if not index:
        _write(rec, [batch])
        return
    state = _stream(rec)
    waiting = state.pending.setdefault(path, [])
    if waiting and not waiting[0].schema.equals(batch.schema, check_metadata=True):
        _write(rec, waiting)
        waiting.clear()
    waiting.append(batch)
    if sum(b.nbytes for b in waiting) >= ENTITY_CHUNK_BYTES:
        _write(rec, waiting)
        waiting.clear()


def _flush(rec: rr.RecordingStream) -> None:
    """Write every entity's waiting rows (in the order the entities were first logged)."""
    state = _stream(rec)
    for waiting in state.pending.values():
        if waiting:
            _write(rec, waiting)
            waiting.clear()


def _log(rec: rr.RecordingStream, path: str, archetype: Any) -> None:
    """One static row of ``archetype`` at ``path`` (``rec.log(..., static=True)`` with ids of
    :class:`_Stream`)."""
    batches = archetype.as_component_batches()
    _send(rec, path, [], [b.partition([len(b.as_arrow_array())]) for b in batches])


def _series(rec: rr.RecordingStream, path: str, names: list[str], colors: list[Any] | None = None) -> None:
    """Static series styling: one named line per column."""
    _log(rec, path, rr.SeriesLines(names=names, colors=colors))


def _log_static(rec: rr.RecordingStream) -> None:
    """The board drawing (static)."""
    _log(rec, "world", rr.ViewCoordinates.RIGHT_HAND_Z_UP)  # ENU: x east, y north, z up
    hz = BOARD_HALF_SIZE[2]
    _log(
        rec,
        paths.BOARD_BODY,
        rr.Boxes3D(half_sizes=[BOARD_HALF_SIZE], colors=[ESTIMATE_COLOR], labels=["estimate"]),
    )
    _log(
        rec,
        paths.BOARD_AXES,
        rr.Arrows3D(
            vectors=[[1.6, 0, 0], [0, 1.3, 0], [0, 0, 0.9]],
            colors=list(AXIS_COLORS),
            labels=["x body (roll)", "y body (pitch)", "z body (yaw)"],
        ),
    )
    # The ADIS16407's own axis marks (sensor axes = body axes, docs/traces.md), on its package.
    top = [0.0, 0.0, hz]
    _log(
        rec,
        paths.BOARD_ADIS,
        rr.Arrows3D(
            vectors=[[0.35, 0, 0], [0, 0.35, 0], [0, 0, 0.35]],
            origins=[top, top, top],
            colors=list(AXIS_COLORS),
            labels=["+X", "+Y", "+Z"],
        ),
    )
    _log(
        rec,
        paths.BOARD_ADIS + "/package",
        rr.Boxes3D(half_sizes=[[0.25, 0.25, 0.06]], centers=[[0.0, 0.0, hz + 0.06]], colors=[(40, 40, 40)]),
    )


def _log_truth_body(rec: rr.RecordingStream) -> None:
    hx, hy, hz = BOARD_HALF_SIZE
    _log(
        rec,
        paths.TRUTH_BODY,
        rr.Boxes3D(
            half_sizes=[[hx * 1.02, hy * 1.02, hz * 1.02]],
            colors=[TRUTH_COLOR],
            fill_mode=rr.components.FillMode.MajorWireframe,
            labels=["truth"],
        ),
    )


class _TraceWindow:
    """The rows of a physical trace around the reads of the part being logged, read chunk by chunk:
    the physical rate (°/s) and acceleration (g) at each read's device sample, by the core's own
    resampling (linear interpolation in trace time, held at the ends). ``np.interp`` over the window
    gives the values it gives over the whole trace, bit for bit: the same two rows around each time
    (the reads' sample times never go back, so the window keeps the row before the earliest)."""

    def __init__(self, trace: TraceInput) -> None:
        self.chunks = _chunks(trace, CHUNK_ROWS)
        self.t = np.empty(0)
        self.gyro = np.empty((0, 3))
        self.accel = np.empty((0, 3))
        self.t0: float | None = None
        self.ended = False
        self._read()

    def _read(self) -> None:
        chunk = next(self.chunks, None)
        if chunk is None:
            self.ended = True
            return
        if self.t0 is None and len(chunk.t_s):
            self.t0 = float(chunk.t_s[0])
        self.t = np.concatenate([self.t, chunk.t_s])
        self.gyro = np.concatenate([self.gyro, chunk.gyro_dps])
        self.accel = np.concatenate([self.accel, chunk.accel_g])

    def at(self, sample_ps: NDArray[np.uint64]) -> tuple[Array, Array]:
        t = sample_ps.astype(np.float64) * 1e-12 + (self.t0 or 0.0)
        while not self.ended and (not len(self.t) or self.t[-1] < t[-1]):
            self._read()
        keep = max(int(np.searchsorted(self.t, t[0], side="right")) - 1, 0)
        self.t, self.gyro, self.accel = self.t[keep:], self.gyro[keep:], self.accel[keep:]
        gyro = np.stack([np.interp(t, self.t, self.gyro[:, k]) for k in range(3)], axis=1)
        accel = np.stack([np.interp(t, self.t, self.accel[:, k]) for k in range(3)], axis=1)
        return gyro, accel


class _Steps:
    """Attitude steps of one run not yet matched with another backend's (parity)."""

    def __init__(self) -> None:
        self.cols: dict[str, NDArray[Any]] = {}

    def add(self, cols: Mapping[str, NDArray[Any]]) -> None:
        self.cols = {k: np.concatenate([self.cols[k], v]) if k in self.cols else v for k, v in cols.items()}

    def last(self) -> int | None:
        step = self.cols.get("step")
        return int(step[-1]) if step is not None and len(step) else None

    def take(self, upto: int | None) -> dict[str, NDArray[Any]]:
        """The rows up to step ``upto`` (all when None), removed."""
        if not self.cols:
            return {}
        n = len(self.cols["step"]) if upto is None else int(np.searchsorted(self.cols["step"], upto, "right"))
        taken = {k: v[:n] for k, v in self.cols.items()}
        self.cols = {k: v[n:] for k, v in self.cols.items()}
        return taken


class Recorder:
    """Log a run into ``rec`` part by part: :meth:`add` each part ``emulate(..., sink=...)`` hands
    out, :meth:`add_parity` each part of another backend's run of the same trace (``cycle_step``,
    ``cycle_euler_deg``, ``cycle_quat``), then :meth:`finish` with the run's bus log.

    ``trace`` (the physical input) adds the physical rates and accelerations next to the decoded
    ones; ``parity`` names the backends whose differences from this run are logged, cycle by cycle;
    ``bus_window`` is the window of ticks the run's bus log covers. Series are declared (their static
    styling) with their first rows. Each part's cycle rows come out with the rows of the ticks that
    computed them (the same ISR), which is how a cycle is stamped with its tick.
    """

    def __init__(
        self,
        rec: rr.RecordingStream,
        profile: Profile,
        *,
        trace: TraceInput | None = None,
        parity: Iterable[str] = (),
        bus_window: tuple[int, int] | None = None,
    ) -> None:
        self.rec = rec
        self.profile = profile
        self.physical = _TraceWindow(trace) if trace is not None else None
        self.attitude = _Attitude(profile, "auto")  # the one alignment every report uses
        self.attitude.listener = self._log_errors
        self.declared: set[str] = set()
        self.last_tick: tuple[int, int] | None = None  # (tick, tick_ps) of the last budget row
        self.first_tick: int | None = None
        self.last_step: int | None = None
        self.truth_logged = False
        #: Events waiting for their tick (a later tick exists) or their cycle (a later step exists).
        self.waiting: list[dict[str, Any]] = []
        self.events_logged = 0
        self.mine = {name: _Steps() for name in parity}
        self.theirs = {name: _Steps() for name in parity}
        self.window = bus_window
        self.window_budget: list[tuple[NDArray[Any], NDArray[Any]]] = []
        self.parts = 0
        g = float(profile.get("firmware.accel_g_m_s2"))
        self.g = g
        _log_static(rec)

    def _series(self, path: str, names: list[str], colors: list[Any] | None = None) -> None:
        if path not in self.declared:
            self.declared.add(path)
            _series(self.rec, path, names, colors)

    def _scalars(
        self, path: str, index: list[rr.TimeColumn], values: Any, names: list[str], colors: Any = None
    ) -> None:
        self._series(path, names, colors)
        _send(self.rec, path, index, rr.Scalars.columns(scalars=values))

    # one part -------------------------------------------------------------------------------

    def add(self, part: Mapping[str, Any]) -> None:
        """Log one part of the output (the keys ``emulate``'s sink receives)."""
        # A runaway state (±inf, an error event of the run) is recorded as it is, NaN where the
        # arithmetic on it has no value: no numpy warning per part on the console.
        with np.errstate(invalid="ignore", over="ignore"):
            self._add(part)
        # Every few parts, wait for the sink (the file writer, a viewer) to take what was logged:
        # without it parts queue up in Rerun's pipeline whenever the disk is slower than the
        # emulation; after each part it would wait far more often than needed.
        self.parts += 1
        if self.parts % FLUSH_PARTS == 0:
            self.rec.flush()

    def _add(self, part: Mapping[str, Any]) -> None:
        b = {k.removeprefix("budget_"): v for k, v in part.items() if k.startswith("budget_")}
        carry_tick = [] if self.last_tick is None else [self.last_tick[0]]
        carry_ps = [] if self.last_tick is None else [self.last_tick[1]]
        ticks = np.concatenate([np.array(carry_tick, np.uint64), b["tick"].astype(np.uint64)])
        tick_ps = np.concatenate([np.array(carry_ps, np.uint64), b["tick_ps"].astype(np.uint64)])
        if self.first_tick is None and len(ticks):
            self.first_tick = int(ticks[0])
        step = part["cycle_step"]
        if len(step):
            if "cycle_tick" in part:  # rows that carry their tick (a C firmware's run output)
                cyc_ps = np.asarray(part["cycle_t_ps"], dtype=np.uint64)
                cyc_tick = np.asarray(part["cycle_tick"], dtype=np.int64)
            else:
                # The tick whose ISR computed each step: the first at or after the step's time.
                i = np.clip(np.searchsorted(tick_ps, part["cycle_t_ps"]), 0, max(len(tick_ps) - 1, 0))
                cyc_ps, cyc_tick = tick_ps[i], ticks[i].astype(np.int64)
            self._log_cycles(part, cyc_ps, cyc_tick)
            self._log_dcm(part, cyc_ps, cyc_tick)
            self._log_wing(part, cyc_ps, cyc_tick)
            for name, mine in self.mine.items():
                mine.add(
                    {
                        "step": step,
                        "euler": part["cycle_euler_deg"],
                        "quat": part["cycle_quat"],
                        "ps": cyc_ps,
                        "tick": cyc_tick,
                    }
                )
                self._match(name)
        else:
            cyc_ps = np.zeros(0, np.uint64)
        self._log_reads(part)
        self._log_budget(b)
        self.waiting += [dict(e, t_ps=round(e["t_s"] * 1e12)) for e in part["events"]]
        if len(ticks):
            self.last_tick = (int(ticks[-1]), int(tick_ps[-1]))
        if len(step):
            self.last_step = int(step[-1])
        self._resolve_events(ticks, tick_ps, cyc_ps, step)
        if self.window is not None and len(b["tick"]):
            lo, hi = self.window
            sel = (b["tick"] >= lo - 1) & (b["tick"] <= hi + 1)
            if sel.any():
                self.window_budget.append((b["tick"][sel], b["start_ps"][sel]))

    def _log_cycles(self, part: Mapping[str, Any], cyc_ps: NDArray[Any], cyc_tick: NDArray[Any]) -> None:
        step = part["cycle_step"]
        index = [_time(cyc_ps), _seq(paths.CYCLE, step), _seq(paths.TICK, cyc_tick)]
        _send(
            self.rec,
            paths.BOARD,
            index,
            rr.Transform3D.columns(quaternion=part["cycle_quat"][:, [1, 2, 3, 0]]),
        )
        for k, angle in enumerate(paths.ANGLES):
            self._scalars(
                paths.attitude(angle, "estimate"),
                index,
                part["cycle_euler_deg"][:, k],
                [f"{angle} estimate (°)"],
                [ESTIMATE_COLOR],
            )
        truth = part.get("truth_q")
        if truth is None:
            return
        ok = np.isfinite(truth).all(axis=1)
        if ok.any():
            if not self.truth_logged:
                _log_truth_body(self.rec)
                self.truth_logged = True
            sub = [_time(cyc_ps[ok]), _seq(paths.CYCLE, step[ok]), _seq(paths.TICK, cyc_tick[ok])]
            _send(self.rec, paths.TRUTH, sub, rr.Transform3D.columns(quaternion=truth[ok][:, [1, 2, 3, 0]]))
            truth_deg = np.degrees(np.stack(quaternion.to_euler(truth[ok]), axis=1))
            for k, angle in enumerate(paths.ANGLES):
                self._scalars(
                    paths.attitude(angle, "truth"),
                    sub,
                    truth_deg[:, k],
                    [f"{angle} truth (°)"],
                    [TRUTH_COLOR[:3]],
                )
        # The errors come through the alignment (_log_errors), once it is known.
        self.attitude.add(
            {
                **part,
                "cycle_t_s": part["cycle_t_ps"].astype(np.float64) * 1e-12,
                "cycle_tick": cyc_tick,
                "cycle_index_ps": cyc_ps,
            }
        )

    def _log_dcm(self, part: Mapping[str, Any], cyc_ps: NDArray[Any], cyc_tick: NDArray[Any]) -> None:
        """The DCM's drift-cancellation terms (its ``dcm_*`` rows, none for the other algorithms),
        each row at the index of its step: ω_P and ω_I in °/s, the errors and |R·Rᵀ − I| as they are."""
        dcm_step = part.get("dcm_step")
        if dcm_step is None or not len(dcm_step):
            return
        i = np.searchsorted(part["cycle_step"], dcm_step)
        index = [_time(cyc_ps[i]), _seq(paths.CYCLE, dcm_step), _seq(paths.TICK, cyc_tick[i])]
        colors = list(AXIS_COLORS)
        for path, key, what, scale in (
            (paths.DCM_OMEGA_P, "dcm_omega_p", "ω_P {} (°/s)", np.degrees),
            (paths.DCM_OMEGA_I, "dcm_omega_i", "ω_I {} (°/s)", np.degrees),
            (paths.DCM_ERROR_RP, "dcm_error_rp", "roll–pitch error {}", np.asarray),
            (paths.DCM_ERROR_YAW, "dcm_error_yaw", "yaw error {}", np.asarray),
        ):
            self._scalars(path, index, scale(part[key]), [what.format(a) for a in AXES], colors)
        self._scalars(paths.DCM_ORTHOGONALITY, index, part["dcm_orthogonality"], ["|R·Rᵀ − I|"])

    def _log_wing(self, part: Mapping[str, Any], cyc_ps: NDArray[Any], cyc_tick: NDArray[Any]) -> None:
        """The wing unit's rows (its ``wing_*`` columns, none for the other algorithms) at the index of their
        steps: α with the trace's truth beside it and their difference (where both are known), the axis."""
        wing_step = part.get("wing_step")
        if wing_step is None or not len(wing_step):
            return
        i = np.searchsorted(part["cycle_step"], wing_step)
        index = [_time(cyc_ps[i]), _seq(paths.CYCLE, wing_step), _seq(paths.TICK, cyc_tick[i])]
        alpha = np.asarray(part["wing_alpha_deg"], dtype=np.float64)
        truth = part.get("truth_alpha_deg")
        if truth is None:
            self._scalars(paths.WING_ALPHA, index, alpha, ["α (°)"], [AXIS_COLORS[0]])
        else:
            truth = np.asarray(truth, dtype=np.float64)[i]
            both = np.stack([alpha, truth], axis=1)
            self._scalars(
                paths.WING_ALPHA, index, both, ["α (°)", "α truth (°)"], [AXIS_COLORS[0], TRUTH_COLOR[:3]]
            )
            self._scalars(paths.WING_ALPHA_ERROR, index, wrap_deg(alpha - truth), ["α − truth (°)"])
        self._scalars(
            paths.WING_AXIS, index, part["wing_axis"], [f"axis {a}" for a in AXES], list(AXIS_COLORS)
        )

    def _log_errors(self, rows: dict[str, Any], valid: NDArray[np.bool_], err: AttitudeErrors) -> None:
        index = [
            _time(rows["index_ps"][valid]),
            _seq(paths.CYCLE, rows["step"][valid]),
            _seq(paths.TICK, rows["tick"][valid]),
        ]
        for k, angle in enumerate(paths.ANGLES):
            self._scalars(
                paths.attitude_error(angle),
                index,
                getattr(err, angle),
                [f"{angle} error (°)"],
                [AXIS_COLORS[k]],
            )
        self._scalars(
            paths.attitude_error("total"), index, err.total, ["total attitude error (°)"], [(0, 0, 0)]
        )

    def _log_reads(self, part: Mapping[str, Any]) -> None:
        if not len(part["read_tick"]):
            return
        index = [_time(part["read_t_start_ps"]), _seq(paths.TICK, part["read_tick"])]
        rate = [f"{a} decoded (°/s)" for a in AXES]
        self._scalars(paths.RATE_DECODED, index, np.degrees(part["read_rate"]), rate, list(AXIS_COLORS))
        accel = [f"{a} decoded (g)" for a in AXES]
        self._scalars(paths.ACCEL_DECODED, index, part["read_accel"] / self.g, accel, list(AXIS_COLORS))
        if self.physical is not None:
            gyro, acc = self.physical.at(part["read_sample_ps"])
            rate = [f"{a} physical (°/s)" for a in AXES]
            self._scalars(paths.RATE_PHYSICAL, index, gyro, rate, LIGHT_AXIS_COLORS)
            accel = [f"{a} physical (g)" for a in AXES]
            self._scalars(paths.ACCEL_PHYSICAL, index, acc, accel, LIGHT_AXIS_COLORS)
        age = part["read_age_ps"].astype(np.float64) * 1e-6
        self._scalars(paths.SAMPLE_AGE, index, age, ["sample age (µs)"])
        words = part["read_words"][:, 1:]
        self._scalars(paths.REGISTER_WORDS, index, words.astype(np.float64), list(REGISTERS))
        # ND (bit 15) and EA (bit 14) of each output register, 0/1 per read.
        nd = ((words >> 15) & 1).astype(np.float64)
        self._scalars(paths.REGISTER_ND, index, nd, [f"{r} ND" for r in REGISTERS])
        ea = ((words >> 14) & 1).astype(np.float64)
        self._scalars(paths.REGISTER_EA, index, ea, [f"{r} EA" for r in REGISTERS])

    def _log_budget(self, budget: Mapping[str, NDArray[Any]]) -> None:
        # Ticks lost or dropped by an overrun had no ISR: they are in the events, not here.
        ran = budget["deadline_ps"] > budget["tick_ps"]
        b = {k: v[ran] for k, v in budget.items()}
        if not len(b["tick"]):
            return
        index = [_time(b["tick_ps"]), _seq(paths.TICK, b["tick"])]
        us = 1e-6
        tick = b["tick_ps"].astype(np.float64)
        busy = (b["end_ps"].astype(np.float64) - b["start_ps"]) * us
        self._scalars(paths.BUDGET_BUSY, index, busy, ["ISR busy (µs)"], [(66, 135, 245)])
        finish = (b["end_ps"] - tick) * us
        self._scalars(paths.BUDGET_FINISH, index, finish, ["ISR end after its tick (µs)"], [(245, 150, 40)])
        deadline = (b["deadline_ps"] - tick) * us
        self._scalars(
            paths.BUDGET_DEADLINE, index, deadline, ["deadline after the tick (µs)"], [(220, 40, 40)]
        )
        margin = (b["deadline_ps"] - b["end_ps"].astype(np.float64)) * us
        self._scalars(paths.BUDGET_MARGIN, index, margin, ["margin (µs, < 0: overrun)"])

    def _resolve_events(
        self, ticks: NDArray[Any], tick_ps: NDArray[Any], cyc_ps: NDArray[Any], step: NDArray[Any]
    ) -> None:
        """Give the waiting events their tick (the one whose period holds the event) and their
        cycle (the one under way: the first step computed at or after the event; one past the last
        step for events after it) once the output shows them; log those that have both."""
        for e in self.waiting:
            if "tick" not in e and len(tick_ps) and tick_ps[-1] > e["t_ps"]:
                i = int(np.searchsorted(tick_ps, e["t_ps"], side="right")) - 1
                e["tick"] = int(ticks[i]) if i >= 0 else self.first_tick
            if "cycle" not in e and len(cyc_ps) and cyc_ps[-1] >= e["t_ps"]:
                e["cycle"] = int(step[int(np.searchsorted(cyc_ps, e["t_ps"], side="left"))])
        n = 0
        while n < len(self.waiting) and "tick" in self.waiting[n] and "cycle" in self.waiting[n]:
            n += 1
        self._log_events(n)

    def _log_events(self, n: int) -> None:
        if not n:
            return
        events, self.waiting = self.waiting[:n], self.waiting[n:]
        index = [
            _time(np.array([e["t_ps"] for e in events], dtype=np.uint64)),
            _seq(paths.TICK, np.array([e["tick"] for e in events])),
            _seq(paths.CYCLE, np.array([e["cycle"] for e in events])),
            _seq(paths.EVENT, np.arange(self.events_logged, self.events_logged + n)),
        ]
        text = [f"[{e['kind']}] {e['message']}" for e in events]
        level = [SEVERITY_LEVEL.get(e["severity"], rr.TextLogLevel.INFO) for e in events]
        _send(self.rec, paths.EVENTS, index, rr.TextLog.columns(text=text, level=level))
        self.events_logged += n

    # parity -----------------------------------------------------------------------------------

    def add_parity(self, name: str, part: Mapping[str, Any]) -> None:
        """One part of backend ``name``'s run (its ``cycle_step``, ``cycle_euler_deg`` and
        ``cycle_quat``)."""
        self.theirs[name].add(
            {"step": part["cycle_step"], "euler": part["cycle_euler_deg"], "quat": part["cycle_quat"]}
        )
        self._match(name)

    def _match(self, name: str, final: bool = False) -> None:
        """Log the differences at the steps both runs have reached (all of them when ``final``)."""
        mine, theirs = self.mine[name], self.theirs[name]
        reached = [mine.last(), theirs.last()]
        if not final and None in reached:
            return
        upto = None if final else min(x for x in reached if x is not None)
        a, o = mine.take(upto), theirs.take(upto)
        if not a or not o:
            return
        common, i, j = np.intersect1d(a["step"], o["step"], return_indices=True)
        if not len(common):
            return
        index = [_time(a["ps"][i]), _seq(paths.CYCLE, common), _seq(paths.TICK, a["tick"][i])]
        diff = wrap_deg(o["euler"][j] - a["euler"][i])
        names = [f"{name} − this: {x} (°)" for x in paths.ANGLES]
        self._scalars(paths.parity(name, "euler"), index, diff, names, list(AXIS_COLORS))
        err = attitude_errors(o["quat"][j], a["quat"][i]).total
        self._scalars(
            paths.parity(name, "angle"), index, err, [f"{name} vs this: rotation between attitudes (°)"]
        )

    # the end ----------------------------------------------------------------------------------

    def finish(self, bus: dict[str, NDArray[Any]] | None = None) -> None:
        """Log what waited for later parts (events, parity rows) and the run's bus log."""
        for e in self.waiting:
            e.setdefault("tick", self.last_tick[0] if self.last_tick is not None else 0)
            e.setdefault("cycle", self.last_step + 1 if self.last_step is not None else 0)
        self._log_events(len(self.waiting))
        for name in self.mine:
            self._match(name, final=True)
        if bus is not None and self.window_budget:
            tick = np.concatenate([t for t, _ in self.window_budget])
            start = np.concatenate([s for _, s in self.window_budget])
            _log_bus(self.rec, bus, self.profile, tick, start)
        _flush(self.rec)


def bus_rows(
    bus: dict[str, NDArray[Any]], profile: Profile, tick: NDArray[Any], start: NDArray[Any]
) -> dict[str, NDArray[Any]]:
    """Per frame of the bus log: the tick whose ISR clocked it; the stall before it (previous
    frame's last SCLK edge to its first edge, NaN for the first frame of the log) and the minimum
    the ADIS16407 requires there (one SCLK period inside a burst, ``device.t_stall_us`` otherwise,
    as the device model checks); and whether CS rises before the next frame (the lane goes idle).
    ``tick`` and ``start`` are the budget's tick numbers and ISR starts, at least those of the window's
    ticks."""
    first, last = bus["frame_first_edge_ps"], bus["frame_last_edge_ps"]
    n = len(first)
    stall = np.full(n, np.nan)
    stall[1:] = first[1:].astype(np.float64) - last[:-1].astype(np.float64)
    # CS window of each frame: the number of CS falls before it.
    falls = bus["cs_t_ps"][bus["cs_low"]]
    window = np.searchsorted(falls, first)
    command = int(profile.get("device.burst_command"))
    in_burst = np.zeros(n, dtype=bool)
    seen: set[int] = set()
    for i, (w, din) in enumerate(zip(window.tolist(), bus["frame_din"].tolist(), strict=True)):
        in_burst[i] = w in seen
        if din == command:
            seen.add(w)
    t_stall_ps = float(profile.get("device.t_stall_us")) * 1e6
    required = np.where(in_burst, bus["frame_sclk_period_ps"].astype(np.float64), t_stall_ps)
    cs_rises_after = np.append(window[1:] != window[:-1], True)
    i = np.clip(np.searchsorted(start, bus["frame_start_ps"], side="right") - 1, 0, len(start) - 1)
    return {
        "stall_ps": stall,
        "required_ps": required,
        "cs_rises_after": cs_rises_after,
        "tick": tick[i].astype(np.int64),
    }


def _log_bus(
    rec: rr.RecordingStream,
    bus: dict[str, NDArray[Any]],
    profile: Profile,
    budget_tick: NDArray[Any],
    start: NDArray[Any],
) -> None:
    if not len(bus["frame_index"]):
        return
    rows = bus_rows(bus, profile, budget_tick, start)
    first, last = bus["frame_first_edge_ps"], bus["frame_last_edge_ps"]
    cs_tick = budget_tick[
        np.clip(np.searchsorted(start, bus["cs_t_ps"], side="right") - 1, 0, len(start) - 1)
    ]
    _send(
        rec,
        paths.BUS_CS,
        [_time(bus["cs_t_ps"]), _seq(paths.TICK, cs_tick)],
        rr.StateChange.columns(state=np.where(bus["cs_low"], "CS low (selected)", "CS high").tolist()),
    )
    # SCLK lane: each frame from its first to its last edge, labelled with its words; then the
    # stall up to the next frame, or idle when CS rises.
    n = len(first)
    label = [
        f"#{i} DIN {d:04X} DOUT {o:04X}"
        for i, d, o in zip(
            bus["frame_index"].tolist(), bus["frame_din"].tolist(), bus["frame_dout"].tolist(), strict=True
        )
    ]
    after = [
        "idle (CS high)" if rises else f"stall {s * 1e-6:.3f} µs"
        for s, rises in zip(np.append(rows["stall_ps"][1:], np.nan), rows["cs_rises_after"], strict=True)
    ]
    t = np.empty(2 * n, dtype=np.uint64)
    t[0::2], t[1::2] = first, last
    state = [x for pair in zip(label, after, strict=True) for x in pair]
    tick2 = np.repeat(rows["tick"], 2)
    _send(rec, paths.BUS_SCLK, [_time(t), _seq(paths.TICK, tick2)], rr.StateChange.columns(state=state))
    text = [
        f"frame {i}: DIN 0x{d:04X}  DOUT 0x{o:04X}  master read 0x{m:04X}  "
        f"edges {a} … {b} ps ({(b - a) * 1e-6:.3f} µs, {bits} bits, SCLK period {p * 1e-6:.4f} µs)"
        + ("" if np.isnan(s) else f"  stall before {s * 1e-6:.3f} µs")
        + ("" if sel else "  CS HIGH: slave not selected")
        for i, d, o, m, a, b, bits, p, s, sel in zip(
            bus["frame_index"].tolist(),
            bus["frame_din"].tolist(),
            bus["frame_dout"].tolist(),
            bus["frame_master_rx"].tolist(),
            first.tolist(),
            last.tolist(),
            bus["frame_bits"].tolist(),
            bus["frame_sclk_period_ps"].tolist(),
            rows["stall_ps"].tolist(),
            bus["frame_selected"].tolist(),
            strict=True,
        )
    ]
    index = [_time(first), _seq(paths.TICK, rows["tick"]), _seq(paths.FRAME, bus["frame_index"])]
    level = [rr.TextLogLevel.DEBUG] * n
    _send(rec, paths.BUS_FRAMES, index, rr.TextLog.columns(text=text, level=level))
    ok = ~np.isnan(rows["stall_ps"])
    if ok.any():
        _series(rec, paths.BUS_STALL, ["stall before frame (µs)"], [(66, 135, 245)])
        sub = [
            _time(first[ok]),
            _seq(paths.TICK, rows["tick"][ok]),
            _seq(paths.FRAME, bus["frame_index"][ok]),
        ]
        _send(rec, paths.BUS_STALL, sub, rr.Scalars.columns(scalars=rows["stall_ps"][ok] * 1e-6))
        _series(
            rec,
            paths.BUS_STALL_MIN,
            ["required minimum (µs): 1 SCLK period in a burst, t_stall otherwise"],
            [(220, 40, 40)],
        )
        _send(rec, paths.BUS_STALL_MIN, sub, rr.Scalars.columns(scalars=rows["required_ps"][ok] * 1e-6))


def log_run(
    rec: rr.RecordingStream,
    run: Run,
    *,
    trace: TraceInput | None = None,
    parity: Mapping[str, Run] | None = None,
) -> None:
    """Log everything a run holds into ``rec``. ``trace`` (the physical input) adds the physical
    rates and accelerations next to the decoded ones; ``parity`` (backend name → Run of the same
    trace) adds each backend's difference from ``run``, cycle by cycle."""
    recorder = Recorder(
        rec,
        run.profile,
        trace=trace,
        parity=list(parity or {}),
        bus_window=None if run.bus is None else tuple(int(x) for x in run.bus["window_ticks"]),  # type: ignore[arg-type]
    )
    recorder.add(run_part(run))
    for name, other in (parity or {}).items():
        recorder.add_parity(
            name, {"cycle_step": other.step, "cycle_euler_deg": other.euler_deg, "cycle_quat": other.quat}
        )
    recorder.finish(run.bus)


def recording_id(*parts: str | bytes) -> str:
    """A recording id that is a function of ``parts`` (what the recording is made from): a UUID
    (version 5) of their SHA-256, the same on every save."""
    h = hashlib.sha256()
    for part in parts:
        h.update((part.encode("utf-8") if isinstance(part, str) else part) + b"\0")
    return str(uuid.uuid5(uuid.NAMESPACE_URL, "sins-fw:" + h.hexdigest()))


def derived_recording_id(run: Run, name: str | None = None) -> str:
    """The recording id of a whole run: from its profile, overrides and attitude output and the
    recording's name."""
    return recording_id(
        run.profile.text,
        "\n".join(run.profile.overrides),
        name or "",
        np.ascontiguousarray(run.time_s).tobytes() + np.ascontiguousarray(run.quat).tobytes(),
    )


class _Pump:
    """A pipe whose far end Rerun's file writer opens as a file (``/dev/fd/N``), pumped by a thread
    into ``tmp`` (the temporary file of :func:`~sins_fw.atomic.atomic_path`): Rerun writes the
    recording as it is logged (memory stays flat), and every write to the disk is this module's, so
    a failure (a full disk, a file size limit) is an OSError raised here, not a line in Rerun's log.
    After a failed write the rest is read and dropped, so Rerun's writer never stops."""

    def __init__(self, tmp: Path) -> None:
        self.tmp = tmp
        self.error: OSError | None = None
        # One buffer, made here: the thread allocates nothing as it pumps, so that under a memory
        # cap (sins_fw.launch) running out is the main thread's MemoryError, never the pump's.
        self.buffer = memoryview(bytearray(1 << 20))
        self.read_end, self.write_end = os.pipe()
        self.thread = threading.Thread(target=self._pump, name="rrd-writer", daemon=True)

    def _pump(self) -> None:
        fh = self.tmp.open("wb", buffering=0)
        try:
            with open(self.read_end, "rb", buffering=0) as pipe:
                while n := pipe.readinto(self.buffer):
                    block = self.buffer[:n]
                    while block and self.error is None:  # an unbuffered write may write part of it
                        try:
                            block = block[fh.write(block) or 0 :]
                        except OSError as e:
                            self.error = e
        finally:
            # Closing can fail too (a file system that reports a full disk only then): this save's
            # error, never a thread's traceback.
            try:
                fh.close()
            except OSError as e:
                self.error = self.error or e

    def __enter__(self) -> str:
        self.thread.start()
        return f"/dev/fd/{self.write_end}"

    def __exit__(self, *exc: object) -> None:
        os.close(self.write_end)  # Rerun has closed its own copy: the pump sees the end
        self.thread.join()
        if self.error is not None and exc[0] is None:
            raise self.error


@contextlib.contextmanager
def recording_file(
    path: str | os.PathLike[str], *, recording_id: str, blueprint: Any, name: str | None = None
) -> Iterator[rr.RecordingStream]:
    """A recording stream written to ``path`` (.rrd) as it is logged, atomically: a temporary file
    beside it is renamed over ``path`` once the block ends cleanly, so a failed or interrupted save
    leaves any previous file untouched. No start time is recorded, the id is the caller's (derived
    from what is recorded) and every row and chunk id is derived from it (:class:`_Stream`):
    docs/traces.md, "Determinism".

    The file ends with Rerun's footer (its manifest of every chunk, for random access:
    ``RrdReader(path).store()``). The writer keeps that manifest until the end, ≈ 3.5 kB a chunk;
    :func:`_send` gathers an entity's rows into chunks of :data:`ENTITY_CHUNK_BYTES`, so that an
    hour of the reference profile makes 1 058 chunks (benchmarks/rerun_save.md)."""
    with atomic_path(Path(path)) as tmp, _Pump(tmp) as pipe:
        rec = rr.RecordingStream(
            "sins-fw",
            recording_id=recording_id,
            send_properties=False,
            batcher_config=rr.ChunkBatcherConfig.NEVER(),
        )
        try:
            rec.save(pipe, write_footer=True)
            # Active as well as default: a web viewer that receives the recording as it streams in
            # otherwise keeps the layout it made up from the first entities it saw.
            rec.send_blueprint(blueprint, make_active=True, make_default=True)
            if name:
                # `rec.send_recording_name(name)`, with an id of ours.
                _log(rec, "/__properties", rr.archetypes.RecordingInfo(name=name))
            yield rec
            _flush(rec)
            rec.flush()
        finally:
            rec.disconnect()


def save_recording(
    run: Run,
    path: str | os.PathLike[str],
    *,
    trace: TraceInput | None = None,
    parity: Mapping[str, Run] | None = None,
    name: str | None = None,
    blueprint: Any | None = None,
    recording_id: str | None = None,
) -> Path:
    """Write the recording of ``run`` to ``path`` (.rrd) with the default layout, atomically
    (:func:`recording_file`)."""
    rid = recording_id if recording_id is not None else derived_recording_id(run, name)
    bp = (
        blueprint
        if blueprint is not None
        else default_blueprint(
            bus=run.bus is not None, parity=parity or (), dcm=has_dcm(run.profile), wing=has_wing(run.profile)
        )
    )
    with recording_file(path, recording_id=rid, blueprint=bp, name=name) as rec:
        log_run(rec, run, trace=trace, parity=parity)
    return Path(path)
