"""Log a :class:`~sins_fw.harness.Run` to a Rerun recording, whole arrays at a time.

Every array goes out with ``send_columns`` (one call per entity, never one call per row), so an
hour of emulation (450 000 cycles, 900 000 ticks and reads) logs in seconds. Rows carry the
emulated-time timeline (ns) and their own index: ``cycle`` for attitude steps, ``tick`` for the
per-tick budget and the per-tick reads (and for the cycle rows too, so the two can be lined up).
Paths and timeline names are in :mod:`sins_fw.viewer.paths`.
"""

from __future__ import annotations

import hashlib
import os
import uuid
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import rerun as rr
from numpy.typing import NDArray

from sins_fw import quaternion
from sins_fw.atomic import atomic_path
from sins_fw.harness import Run
from sins_fw.metrics import attitude_errors, wrap_deg
from sins_fw.report import aligned_estimate
from sins_fw.traces import RAW_WORD_COLUMNS, PhysicalTrace
from sins_fw.viewer import paths

Array = NDArray[np.float64]
PS_PER_NS = 1000
#: Board drawing, metres-free "board units": a 2:2:1 box, the ADIS16407 on top.
BOARD_HALF_SIZE = (1.0, 0.7, 0.12)
ESTIMATE_COLOR = (66, 135, 245)
TRUTH_COLOR = (200, 200, 200, 90)
AXIS_COLORS = ((230, 60, 60), (60, 200, 60), (60, 110, 240))
SEVERITY_LEVEL = {
    "info": rr.TextLogLevel.INFO,
    "warning": rr.TextLogLevel.WARN,
    "error": rr.TextLogLevel.ERROR,
}
#: The 14 output registers of a burst (the command frame's answer, word 0, is don't-care).
REGISTERS = RAW_WORD_COLUMNS[1:]


def _time(t_ps: NDArray[Any]) -> rr.TimeColumn:
    return rr.TimeColumn(
        paths.TIME, duration=(np.asarray(t_ps, dtype=np.uint64) // PS_PER_NS).astype("timedelta64[ns]")
    )


def _seq(name: str, values: NDArray[Any]) -> rr.TimeColumn:
    return rr.TimeColumn(name, sequence=np.asarray(values, dtype=np.int64))


def _send(rec: rr.RecordingStream, path: str, index: list[rr.TimeColumn], columns: Any) -> None:
    rr.send_columns(path, indexes=index, columns=columns, recording=rec)


def _series(rec: rr.RecordingStream, path: str, names: list[str], colors: list[Any] | None = None) -> None:
    """Static series styling: one named line per column."""
    rec.log(path, rr.SeriesLines(names=names, colors=colors), static=True)


def cycle_ticks(run: Run) -> NDArray[np.int64]:
    """The timer tick at which each attitude step was computed (cycle rows are stamped with it)."""
    b = run.budget
    cycle_ps = np.round(run.time_s / 1e-12).astype(np.uint64) if len(run.time_s) else np.zeros(0, np.uint64)
    i = np.clip(np.searchsorted(b["tick_ps"], cycle_ps), 0, max(len(b["tick_ps"]) - 1, 0))
    return b["tick"][i].astype(np.int64) if len(b["tick_ps"]) else np.zeros(0, np.int64)


def cycle_ps(run: Run) -> NDArray[np.uint64]:
    """Exact picoseconds of the cycle rows (the tick they were computed at)."""
    b = run.budget
    i = np.clip(np.searchsorted(b["tick"], cycle_ticks(run)), 0, max(len(b["tick"]) - 1, 0))
    return b["tick_ps"][i].astype(np.uint64) if len(b["tick"]) else np.zeros(0, np.uint64)


def event_rows(run: Run) -> dict[str, NDArray[Any]]:
    """Per event: exact time (ps), the tick whose period holds it, the cycle under way."""
    t_ps = np.array([round(e["t_s"] * 1e12) for e in run.events], dtype=np.uint64)
    tick_ps = run.budget["tick_ps"]
    if len(tick_ps):
        i = np.clip(np.searchsorted(tick_ps, t_ps, side="right") - 1, 0, len(tick_ps) - 1)
        tick = run.budget["tick"][i].astype(np.int64)
    else:
        tick = np.zeros(len(t_ps), np.int64)
    # The cycle under way: the first step computed at or after the event (one past the last step
    # for events after it).
    steps = run.step.astype(np.int64)
    j = np.searchsorted(cycle_ps(run), t_ps, side="left")
    ahead = np.append(steps, (int(steps[-1]) + 1) if len(steps) else 0)
    cycle = ahead[j]
    return {"t_ps": t_ps, "tick": tick, "cycle": cycle.astype(np.int64)}


def _log_board(rec: rr.RecordingStream, run: Run) -> None:
    rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)  # ENU: x east, y north, z up
    hx, hy, hz = BOARD_HALF_SIZE
    rec.log(
        paths.BOARD_BODY,
        rr.Boxes3D(half_sizes=[BOARD_HALF_SIZE], colors=[ESTIMATE_COLOR], labels=["estimate"]),
        static=True,
    )
    rec.log(
        paths.BOARD_AXES,
        rr.Arrows3D(
            vectors=[[1.6, 0, 0], [0, 1.3, 0], [0, 0, 0.9]],
            colors=list(AXIS_COLORS),
            labels=["x body (roll)", "y body (pitch)", "z body (yaw)"],
        ),
        static=True,
    )
    # The ADIS16407's own axis marks (sensor axes = body axes, docs/traces.md), on its package.
    top = [0.0, 0.0, hz]
    rec.log(
        paths.BOARD_ADIS,
        rr.Arrows3D(
            vectors=[[0.35, 0, 0], [0, 0.35, 0], [0, 0, 0.35]],
            origins=[top, top, top],
            colors=list(AXIS_COLORS),
            labels=["+X", "+Y", "+Z"],
        ),
        static=True,
    )
    rec.log(
        paths.BOARD_ADIS + "/package",
        rr.Boxes3D(half_sizes=[[0.25, 0.25, 0.06]], centers=[[0.0, 0.0, hz + 0.06]], colors=[(40, 40, 40)]),
        static=True,
    )
    if not run.cycles:
        return
    index = [_time(cycle_ps(run)), _seq(paths.CYCLE, run.step), _seq(paths.TICK, cycle_ticks(run))]
    xyzw = run.quat[:, [1, 2, 3, 0]]
    _send(rec, paths.BOARD, index, rr.Transform3D.columns(quaternion=xyzw))
    if run.truth_q is not None and np.isfinite(run.truth_q).all(axis=1).any():
        ok = np.isfinite(run.truth_q).all(axis=1)
        rec.log(
            paths.TRUTH_BODY,
            rr.Boxes3D(
                half_sizes=[[hx * 1.02, hy * 1.02, hz * 1.02]],
                colors=[TRUTH_COLOR],
                fill_mode=rr.components.FillMode.MajorWireframe,
                labels=["truth"],
            ),
            static=True,
        )
        truth_index = [
            _time(cycle_ps(run)[ok]),
            _seq(paths.CYCLE, run.step[ok]),
            _seq(paths.TICK, cycle_ticks(run)[ok]),
        ]
        _send(
            rec, paths.TRUTH, truth_index, rr.Transform3D.columns(quaternion=run.truth_q[ok][:, [1, 2, 3, 0]])
        )


def _log_attitude(rec: rr.RecordingStream, run: Run) -> None:
    if not run.cycles:
        return
    index = [_time(cycle_ps(run)), _seq(paths.CYCLE, run.step), _seq(paths.TICK, cycle_ticks(run))]
    for k, angle in enumerate(paths.ANGLES):
        path = paths.attitude(angle, "estimate")
        _series(rec, path, [f"{angle} estimate (°)"], [ESTIMATE_COLOR])
        _send(rec, path, index, rr.Scalars.columns(scalars=run.euler_deg[:, k]))
    if run.truth_q is None:
        return
    ok = np.isfinite(run.truth_q).all(axis=1)
    if not ok.any():
        return
    sub = [_time(cycle_ps(run)[ok]), _seq(paths.CYCLE, run.step[ok]), _seq(paths.TICK, cycle_ticks(run)[ok])]
    truth_deg = np.degrees(np.stack(quaternion.to_euler(run.truth_q[ok]), axis=1))
    err = attitude_errors(aligned_estimate(run)[0][ok], run.truth_q[ok])
    for k, angle in enumerate(paths.ANGLES):
        path = paths.attitude(angle, "truth")
        _series(rec, path, [f"{angle} truth (°)"], [TRUTH_COLOR[:3]])
        _send(rec, path, sub, rr.Scalars.columns(scalars=truth_deg[:, k]))
        path = paths.attitude_error(angle)
        _series(rec, path, [f"{angle} error (°)"], [AXIS_COLORS[k]])
        _send(rec, path, sub, rr.Scalars.columns(scalars=getattr(err, angle)))
    _series(rec, paths.attitude_error("total"), ["total attitude error (°)"], [(0, 0, 0)])
    _send(rec, paths.attitude_error("total"), sub, rr.Scalars.columns(scalars=err.total))


def physical_at_reads(run: Run, trace: PhysicalTrace) -> tuple[Array, Array]:
    """The physical rate (°/s) and acceleration (g) at the device sample each read returned, by the
    core's own resampling (linear interpolation in trace time; held at the ends)."""
    t = run.read_sample_ps.astype(np.float64) * 1e-12 + run.t0_s
    gyro = np.stack([np.interp(t, trace.t_s, trace.gyro_dps[:, k]) for k in range(3)], axis=1)
    accel = np.stack([np.interp(t, trace.t_s, trace.accel_g[:, k]) for k in range(3)], axis=1)
    return gyro, accel


def _log_reads(rec: rr.RecordingStream, run: Run, trace: PhysicalTrace | None) -> None:
    if not len(run.read_tick):
        return
    index = [_time(run.read_t_start_ps), _seq(paths.TICK, run.read_tick)]
    g = float(run.profile.get("firmware.accel_g_m_s2"))
    axes = ["x", "y", "z"]
    _series(rec, paths.RATE_DECODED, [f"{a} decoded (°/s)" for a in axes], list(AXIS_COLORS))
    _send(rec, paths.RATE_DECODED, index, rr.Scalars.columns(scalars=np.degrees(run.read_rate)))
    _series(rec, paths.ACCEL_DECODED, [f"{a} decoded (g)" for a in axes], list(AXIS_COLORS))
    _send(rec, paths.ACCEL_DECODED, index, rr.Scalars.columns(scalars=run.read_accel / g))
    if trace is not None:
        gyro, accel = physical_at_reads(run, trace)
        light = [tuple(int(c + (255 - c) * 0.55) for c in col) for col in AXIS_COLORS]
        _series(rec, paths.RATE_PHYSICAL, [f"{a} physical (°/s)" for a in axes], light)
        _send(rec, paths.RATE_PHYSICAL, index, rr.Scalars.columns(scalars=gyro))
        _series(rec, paths.ACCEL_PHYSICAL, [f"{a} physical (g)" for a in axes], light)
        _send(rec, paths.ACCEL_PHYSICAL, index, rr.Scalars.columns(scalars=accel))
    _series(rec, paths.SAMPLE_AGE, ["sample age (µs)"])
    _send(rec, paths.SAMPLE_AGE, index, rr.Scalars.columns(scalars=run.read_age_ps.astype(np.float64) * 1e-6))
    words = run.read_words[:, 1:]
    _series(rec, paths.REGISTER_WORDS, list(REGISTERS))
    _send(rec, paths.REGISTER_WORDS, index, rr.Scalars.columns(scalars=words.astype(np.float64)))
    # ND (bit 15) and EA (bit 14) of each output register, 0/1 per read.
    _series(rec, paths.REGISTER_ND, [f"{r} ND" for r in REGISTERS])
    _send(rec, paths.REGISTER_ND, index, rr.Scalars.columns(scalars=((words >> 15) & 1).astype(np.float64)))
    _series(rec, paths.REGISTER_EA, [f"{r} EA" for r in REGISTERS])
    _send(rec, paths.REGISTER_EA, index, rr.Scalars.columns(scalars=((words >> 14) & 1).astype(np.float64)))


def _log_budget(rec: rr.RecordingStream, run: Run) -> None:
    # Ticks lost or dropped by an overrun had no ISR: they are in the events, not here.
    b = {k: v[run.isr_ran] for k, v in run.budget.items()}
    if not len(b["tick"]):
        return
    index = [_time(b["tick_ps"]), _seq(paths.TICK, b["tick"])]
    us = 1e-6
    tick = b["tick_ps"].astype(np.float64)
    columns = {
        paths.BUDGET_BUSY: (
            "ISR busy (µs)",
            (b["end_ps"].astype(np.float64) - b["start_ps"]) * us,
            (66, 135, 245),
        ),
        paths.BUDGET_FINISH: ("ISR end after its tick (µs)", (b["end_ps"] - tick) * us, (245, 150, 40)),
        paths.BUDGET_DEADLINE: (
            "deadline after the tick (µs)",
            (b["deadline_ps"] - tick) * us,
            (220, 40, 40),
        ),
        paths.BUDGET_MARGIN: (
            "margin (µs, < 0: overrun)",
            (b["deadline_ps"] - b["end_ps"].astype(np.float64)) * us,
            None,
        ),
    }
    for path, (name, values, color) in columns.items():
        _series(rec, path, [name], None if color is None else [color])
        _send(rec, path, index, rr.Scalars.columns(scalars=values))


def _log_events(rec: rr.RecordingStream, run: Run) -> None:
    if not run.events:
        return
    rows = event_rows(run)
    text = [f"[{e['kind']}] {e['message']}" for e in run.events]
    level = [SEVERITY_LEVEL.get(e["severity"], rr.TextLogLevel.INFO) for e in run.events]
    index = [
        _time(rows["t_ps"]),
        _seq(paths.TICK, rows["tick"]),
        _seq(paths.CYCLE, rows["cycle"]),
        _seq(paths.EVENT, np.arange(len(text))),
    ]
    _send(rec, paths.EVENTS, index, rr.TextLog.columns(text=text, level=level))


def bus_rows(run: Run) -> dict[str, NDArray[Any]]:
    """Per frame of the bus log: the tick whose ISR clocked it; the stall before it (previous
    frame's last SCLK edge to its first edge, NaN for the first frame of the log) and the minimum
    the ADIS16407 requires there (one SCLK period inside a burst, ``device.t_stall_us`` otherwise,
    as the device model checks); and whether CS rises before the next frame (the lane goes idle)."""
    bus = run.bus or {}
    first, last = bus["frame_first_edge_ps"], bus["frame_last_edge_ps"]
    n = len(first)
    stall = np.full(n, np.nan)
    stall[1:] = first[1:].astype(np.float64) - last[:-1].astype(np.float64)
    # CS window of each frame: the number of CS falls before it.
    falls = bus["cs_t_ps"][bus["cs_low"]]
    window = np.searchsorted(falls, first)
    command = int(run.profile.get("device.burst_command"))
    in_burst = np.zeros(n, dtype=bool)
    seen: set[int] = set()
    for i, (w, din) in enumerate(zip(window.tolist(), bus["frame_din"].tolist(), strict=True)):
        in_burst[i] = w in seen
        if din == command:
            seen.add(w)
    t_stall_ps = float(run.profile.get("device.t_stall_us")) * 1e6
    required = np.where(in_burst, bus["frame_sclk_period_ps"].astype(np.float64), t_stall_ps)
    cs_rises_after = np.append(window[1:] != window[:-1], True)
    start = run.budget["start_ps"]
    i = np.clip(np.searchsorted(start, bus["frame_start_ps"], side="right") - 1, 0, len(start) - 1)
    return {
        "stall_ps": stall,
        "required_ps": required,
        "cs_rises_after": cs_rises_after,
        "tick": run.budget["tick"][i].astype(np.int64),
    }


def _log_bus(rec: rr.RecordingStream, run: Run) -> None:
    bus = run.bus
    if bus is None or not len(bus["frame_index"]):
        return
    rows = bus_rows(run)
    first, last = bus["frame_first_edge_ps"], bus["frame_last_edge_ps"]
    start = run.budget["start_ps"]
    cs_tick = run.budget["tick"][
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


def _log_parity(rec: rr.RecordingStream, run: Run, others: Mapping[str, Run]) -> None:
    for name, other in others.items():
        common, i, j = np.intersect1d(run.step, other.step, return_indices=True)
        if not len(common):
            continue
        index = [_time(cycle_ps(run)[i]), _seq(paths.CYCLE, common), _seq(paths.TICK, cycle_ticks(run)[i])]
        diff = wrap_deg(other.euler_deg[j] - run.euler_deg[i])
        _series(
            rec,
            paths.parity(name, "euler"),
            [f"{name} − this: {a} (°)" for a in paths.ANGLES],
            list(AXIS_COLORS),
        )
        _send(rec, paths.parity(name, "euler"), index, rr.Scalars.columns(scalars=diff))
        err = attitude_errors(other.quat[j], run.quat[i]).total
        _series(rec, paths.parity(name, "angle"), [f"{name} vs this: rotation between attitudes (°)"])
        _send(rec, paths.parity(name, "angle"), index, rr.Scalars.columns(scalars=err))


def log_run(
    rec: rr.RecordingStream,
    run: Run,
    *,
    trace: PhysicalTrace | None = None,
    parity: Mapping[str, Run] | None = None,
) -> None:
    """Log everything a run holds into ``rec``. ``trace`` (the physical input) adds the physical
    rates and accelerations next to the decoded ones; ``parity`` (backend name → Run of the same
    trace) adds each backend's difference from ``run``, cycle by cycle."""
    _log_board(rec, run)
    _log_attitude(rec, run)
    _log_reads(rec, run, trace)
    _log_budget(rec, run)
    _log_events(rec, run)
    _log_bus(rec, run)
    if parity:
        _log_parity(rec, run, parity)


def derived_recording_id(run: Run, name: str | None = None) -> str:
    """A recording id that is a function of the run (its profile, overrides and attitude output)
    and the recording's name: a UUID (version 5) of their SHA-256, the same on every save."""
    h = hashlib.sha256()
    for part in (run.profile.text, "\n".join(run.profile.overrides), name or ""):
        h.update(part.encode("utf-8") + b"\0")
    h.update(np.ascontiguousarray(run.time_s).tobytes())
    h.update(np.ascontiguousarray(run.quat).tobytes())
    return str(uuid.uuid5(uuid.NAMESPACE_URL, "sins-fw:" + h.hexdigest()))


def save_recording(
    run: Run,
    path: str | os.PathLike[str],
    *,
    trace: PhysicalTrace | None = None,
    parity: Mapping[str, Run] | None = None,
    name: str | None = None,
    blueprint: Any | None = None,
    recording_id: str | None = None,
) -> Path:
    """Write the recording of ``run`` to ``path`` (.rrd) with the default layout, atomically: a
    temporary file beside it is renamed over ``path`` once complete, so a failed save leaves any
    previous file untouched."""
    from sins_fw.viewer.layout import default_blueprint

    out = Path(path)
    with atomic_path(out) as tmp, tmp.open("wb") as fh:
        # No start time (send_properties=False) and an id derived from what is recorded: the same
        # run gives the same recording id (docs/traces.md, "Determinism").
        rid = recording_id if recording_id is not None else derived_recording_id(run, name)
        rec = rr.RecordingStream(
            "sins-fw", recording_id=rid, send_properties=False, batcher_config=rr.ChunkBatcherConfig.NEVER()
        )
        bp = blueprint if blueprint is not None else default_blueprint(run, parity=parity)
        # Encoded in memory and written here (not by Rerun's file-writer thread, whose failures
        # are only logged): a full disk is an OSError naming the file.
        stream = rec.binary_stream()
        # Active as well as default: a web viewer that receives the recording as it streams in
        # otherwise keeps the layout it made up from the first entities it saw.
        rec.send_blueprint(bp, make_active=True, make_default=True)
        if name:
            rec.send_recording_name(name)
        log_run(rec, run, trace=trace, parity=parity)
        fh.write(stream.read() or b"")
        rec.disconnect()
    return out
