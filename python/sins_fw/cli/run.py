"""`sins-fw run TRACE`: emulate the board on a trace and summarise what the firmware did."""

from __future__ import annotations

import argparse
import contextlib
import itertools
from collections import Counter
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

import numpy as np

from sins_fw import gfsins, progress
from sins_fw.atomic import check_output_folder
from sins_fw.cli.common import (
    EVENTS_CHECK,
    add_json_option,
    add_out_option,
    add_profile_options,
    add_read_options,
    check_error_counts,
    emit,
    exit_epilog,
    profile_from_args,
    read_options,
)
from sins_fw.cli.stop import check_stop
from sins_fw.earth import earth_rate_place
from sins_fw.errors import InputError, TraceError
from sins_fw.firmware_run import (
    FirmwareRunWriter,
    FirmwareStopped,
    default_globals,
    firmware_metadata,
    load_globals,
    run_c_firmware,
)
from sins_fw.harness import CHUNK_ROWS, check_until_s, emulate
from sins_fw.profile import load_profile
from sins_fw.report import ALIGNMENTS, render
from sins_fw.report_stream import RunSummary
from sins_fw.run_output import RawWriter, RunWriter, trace_reference
from sins_fw.stream import TableWriter
from sins_fw.traces import (
    ATTITUDE_ONLY_KEY,
    ATTITUDE_ONLY_SETTING,
    DEFAULT_MAX_GAP_PERIODS,
    PhysicalTrace,
    ReadOptions,
    check_output_path,
    is_raw_register_trace,
    read_metadata,
)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "run",
        help="emulate the board on a trace: events, attitude error against the truth, time budget",
        description="Emulate the profile's board and firmware on a physical trace (.csv or .h5) and "
        "summarise: steps, virtual time, events by kind (first occurrence of each), attitude error "
        "against the trace's truth (alignment stated), ISR budget. --out writes the per-step output "
        "(docs/traces.md, 'Run output').",
        epilog=exit_epilog(EVENTS_CHECK),
    )
    p.add_argument("trace", type=Path, help="physical or raw-register trace, .csv or .h5")
    add_profile_options(p)
    add_out_option(p, "write the per-step output here (.csv or .h5)")
    p.add_argument(
        "--raw-out",
        type=Path,
        metavar="FILE",
        help="also write the words the firmware read as a raw-register trace (.csv or .h5; each "
        "burst timestamped at its CS falling edge), which `sins-fw run FILE` replays",
    )
    p.add_argument(
        "--until-s",
        type=float,
        metavar="S",
        help="emulate only the first S seconds of the trace",
    )
    p.add_argument(
        "--allow-gaps",
        action="store_true",
        help="accept time steps longer than 1.5 sample periods: the device sees the input interpolated "
        "linearly across each gap, and each gap is an `input_gap` event",
    )
    p.add_argument(
        "--align",
        choices=ALIGNMENTS,
        default="auto",
        help="frame alignment before comparing with the truth: initial (the truth at power-on, for "
        "firmware starting from Q = [1,0,0,0]), heading (about navigation z), none; auto picks initial "
        "for firmware.initial_attitude = zero, heading for level (default auto)",
    )
    p.add_argument(
        "--firmware",
        type=Path,
        metavar="FW.so",
        help="run this host-built C firmware (`sins-fw build-firmware`) instead of the profile's Rust model: "
        "its main runs until the trace ends, its ISR on CPU timer 0, in a process of its own (a crash, "
        "abort or exit there is exit 2 naming the signal and the line; its stdout goes to stderr; "
        "docs/c-drivers.md)",
    )
    p.add_argument(
        "--globals",
        type=Path,
        metavar="FILE.toml",
        help="with --firmware: the firmware's globals to read after each ISR, as output columns (default: "
        "globals.toml beside FW.so, if there)",
    )
    add_read_options(p)
    add_json_option(p)
    p.set_defaults(func=run)


class _Reached:
    """How far the emulation got: the trace time covered by the chunks emulated so far (virtual time
    0 is the trace's first sample), for the message of an interrupted run."""

    def __init__(self, span_s: float | None) -> None:
        self.span_s = span_s
        self.t: float | None = None

    def __call__(self, t: float) -> None:
        self.t = t

    def text(self, t0_s: float | None) -> str:
        if self.t is None:
            return "before the first chunk of the trace was emulated (virtual time 0 s)"
        reached = self.t - (t0_s or 0.0)
        of = f" of {self.span_s:.6g} s" if self.span_s is not None else ""
        return f"after emulating {reached:.6g} s{of} of the trace (virtual time reached)"


def _first_time(path: Path, read: ReadOptions | None = None) -> float | None:
    """The trace's first time stamp (reads only its first row); None when it cannot be read."""
    try:
        first = next(iter(PhysicalTrace.iter_chunks(path, 1, read=read)), None)
    except InputError:
        return None
    return float(first.t_s[0]) if first is not None and len(first) else None


def gap_events(
    trace: PhysicalTrace, max_gap_periods: float = DEFAULT_MAX_GAP_PERIODS
) -> list[dict[str, Any]]:
    """One `input_gap` event per time step longer than ``max_gap_periods`` sample periods, at the
    virtual time of the sample before the gap (the run's time 0 is the trace's first sample)."""
    finder = GapFinder(max_gap_periods)
    for _ in finder.follow([trace]):
        pass
    return finder.events


class GapFinder:
    """:func:`gap_events` of a trace found chunk by chunk as it streams past (:meth:`follow`), so the
    trace is never held whole: each chunk's steps, and the step from the previous chunk's last time."""

    def __init__(self, max_gap_periods: float = DEFAULT_MAX_GAP_PERIODS) -> None:
        self.max_gap_periods = max_gap_periods
        self.events: list[dict[str, Any]] = []
        self.t0: float | None = None
        self.last: np.ndarray | None = None

    def follow(self, chunks: Iterable[PhysicalTrace]) -> Iterator[PhysicalTrace]:
        for chunk in chunks:
            if len(chunk.t_s):
                self._add(chunk)
            yield chunk

    def _add(self, chunk: PhysicalTrace) -> None:
        if self.t0 is None:
            self.t0 = float(chunk.t_s[0])
        t = chunk.t_s if self.last is None else np.concatenate([self.last, chunk.t_s])
        self.last = chunk.t_s[-1:]
        period = float(1 / chunk.sample_rate_hz)
        dt = np.diff(t)
        limit = self.max_gap_periods * period
        self.events += [
            {
                "t_s": float(t[i] - self.t0),
                "kind": "input_gap",
                "severity": "warning",
                "message": f"trace gap of {dt[i]:.6g} s ({dt[i] / period:.3g} sample periods) after trace "
                f"time {float(t[i])!r} s: the device sees the input interpolated linearly across it",
                "measured": float(dt[i]),
                "required": limit,
                "frame": None,
            }
            for i in np.flatnonzero(dt > limit)
        ]


def _out_state(out: Path | None, existed: bool) -> str:
    if out is None:
        return ""
    return f"; {out} left as it was" if existed else f"; {out} not written"


def _check_paths(args: argparse.Namespace, *outputs: tuple[str, Path | None]) -> None:
    """Before any work: each output file given (option, path) a table file name in a folder that can
    take it, --until-s, the trace there."""
    for option, out in outputs:
        if out is not None:
            check_output_path(out)
            check_output_folder(out, option)
    check_until_s(args.until_s, "--until-s")
    if not args.trace.is_file():
        raise TraceError(f"{args.trace}: no such trace file")


def run(args: argparse.Namespace) -> int:
    if gfsins.has_own_schema(args.profile):
        return _run_gfsins(args)
    if args.firmware is not None:
        return _run_firmware(args)
    if args.globals is not None:
        raise InputError("--globals names the globals of a C firmware: give --firmware too")
    _check_paths(args, ("--out", args.out), ("--raw-out", args.raw_out))
    profile = profile_from_args(args)
    attitude_only = _attitude_only(args)
    if attitude_only:
        profile = load_profile(args.profile, [*args.overrides, ATTITUDE_ONLY_SETTING])
    out_existed = args.out is not None and args.out.exists()
    span = progress.trace_span_s(args.trace)
    reached = _Reached(span)
    trace: Iterable[PhysicalTrace] | Path = args.trace
    finder = GapFinder()
    replayed = is_raw_register_trace(args.trace)
    read = read_options(args)
    if read is not None and replayed:
        raise TraceError(
            f"{args.trace}: --units and --columns read physical traces; this is a raw-register trace"
        )
    if args.allow_gaps and not replayed:  # raw-register traces load with gaps allowed anyway
        # Streamed, the gaps noted as the chunks pass (issue 24, item 11).
        trace = finder.follow(PhysicalTrace.iter_chunks(args.trace, CHUNK_ROWS, allow_gaps=True, read=read))
    elif read is not None:
        trace = PhysicalTrace.iter_chunks(args.trace, CHUNK_ROWS, read=read)
    t0 = 0.0 if replayed else _first_time(args.trace, read)
    summary_acc = RunSummary(profile, align=args.align)
    with contextlib.ExitStack() as files, progress.trace_bar(progress.wanted(args), span) as bar:
        writers: list[Any] = []
        if args.out is not None:
            recorded = {**trace_reference(args.trace, args.out), **_how_read(args, read)}
            writers.append(files.enter_context(RunWriter(args.out, profile, t0 or 0.0, recorded)))
        if args.raw_out is not None:
            writers.append(files.enter_context(RawWriter(args.raw_out, _raw_metadata(args))))

        def on_chunk(t: float) -> None:
            reached(t)
            bar(t)
            check_stop()

        def sink(part: dict[str, Any]) -> None:
            summary_acc.add(part)
            for w in writers:
                w.add(part)

        try:
            # Streamed: the summary and the files take each part of the output as it comes, so
            # memory is bounded by a part whatever the trace's length (issue 24, item 11).
            result = emulate(
                trace, profile, on_chunk=on_chunk, until_s=args.until_s, allow_gaps=args.allow_gaps, sink=sink
            )
            check_stop()
            for w in writers:
                w.close()
        except KeyboardInterrupt as e:
            how_far = reached.text(_first_time(args.trace, read) if reached.t is not None else None)
            raise type(e)(f"stopped {how_far}{_out_state(args.out, out_existed)}") from None
    # Stable order: the core's events keep theirs; the gaps come after them in the counts (each
    # kind's first occurrence is the same either way: a gap is its own kind).
    summary_acc.add_events(finder.events)
    summary = summary_acc.result(trace=str(args.trace), t0_s=result.t0_s, stage_cycles=result.stage_cycles)
    summary["replayed"] = replayed
    if args.out is not None:
        summary["out"] = str(args.out)
    if args.raw_out is not None:
        summary["raw_out"] = str(args.raw_out)
    summary["earth_rate"] = earth_rate_place(profile, read_metadata(args.trace))
    text = render(summary)
    if summary["earth_rate"]["note"]:
        text += f"\nearth rate     {summary['earth_rate']['note']}"
    if replayed:
        text = "replayed       raw-register trace: recorded words, no device model\n" + text
    if attitude_only:
        summary["attitude_only"] = True
        text = (
            f"attitude only  the trace's metadata marks it attitude-only ({ATTITUDE_ONLY_KEY}): run with "
            f"{ATTITUDE_ONLY_SETTING} (--set firmware.navigation=true navigates anyway)\n" + text
        )
    if args.out is not None:
        text += f"\nwrote          {args.out} ({summary['cycles']} steps)"
    if args.raw_out is not None:
        text += f"\nwrote          {args.raw_out} ({writers[-1].rows} bursts)"
    emit(args, summary, text)
    check_error_counts(summary_acc.error_counts(), summary_acc.first_error())
    return 0


def _attitude_only(args: argparse.Namespace) -> bool:
    """Whether the trace's metadata marks it attitude-only (``sins-fw import broad``: no navigation
    aiding, so the free-inertial vertical channel would run away) and no ``--set`` chooses
    ``firmware.navigation`` itself: the run then does not navigate."""
    if any(o.split("=", 1)[0].strip() == "firmware.navigation" for o in args.overrides):
        return False
    try:
        meta = read_metadata(args.trace)
    except (TraceError, OSError):
        return False
    return meta.get(ATTITUDE_ONLY_KEY, "").strip().lower() == "true"


def _raw_metadata(args: argparse.Namespace) -> dict[str, str]:
    """Provenance of a --raw-out file: the command that reproduces it (no version or time, so the
    same command gives the same bytes)."""
    command = ["sins-fw run", args.trace.name]
    if args.profile != "reference":
        command.append(f"--profile {args.profile}")
    command += [f"--set '{o}'" for o in args.overrides]
    if args.until_s is not None:
        command.append(f"--until-s {args.until_s:g}")
    command.append(f"--raw-out {args.raw_out.name}")
    return {
        "source": f"emulated burst reads of {args.trace.name}",
        "generator": " ".join(command),
        "created_by": "sins-fw run --raw-out (no version or time recorded: regeneration is byte-identical)",
    }


def _how_read(args: argparse.Namespace, read: ReadOptions | None) -> dict[str, str]:
    """What a run output records of how its trace was read (replay and report read it, and its
    truth, the same way) and of where the run stopped."""
    out: dict[str, str] = {}
    if read is not None:
        out = {k: str(v) for k, v in (("trace_units", read.units), ("trace_columns", read.columns)) if v}
    if args.until_s is not None:
        out["until_s"] = repr(args.until_s)
    return out


def _run_firmware(args: argparse.Namespace) -> int:
    """`run TRACE --firmware FW.so`: the host-built C firmware on the trace, reported as a run of the
    Rust model is (summary, events, budget, --out in the run output's format)."""
    if args.raw_out is not None:
        raise InputError(
            "--raw-out records the Rust model's burst reads; with --firmware it is not available"
        )
    _check_paths(args, ("--out", args.out))
    if is_raw_register_trace(args.trace):
        raise TraceError(
            f"{args.trace}: a raw-register trace replays recorded words into the Rust model; a C firmware "
            "reads the device model: give a physical trace"
        )
    if not args.firmware.is_file():
        raise InputError(
            f"{args.firmware}: no such firmware library (build it with `sins-fw build-firmware`)"
        )
    globals_file = args.globals if args.globals is not None else default_globals(args.firmware)
    watched = load_globals(globals_file) if globals_file is not None else []
    profile = profile_from_args(args)
    read = read_options(args)
    trace: Any = args.trace
    if read is not None or args.allow_gaps:
        trace = PhysicalTrace.iter_chunks(args.trace, CHUNK_ROWS, allow_gaps=args.allow_gaps, read=read)
    summary_acc = RunSummary(profile, align=args.align)
    span = progress.trace_span_s(args.trace)
    out_existed = args.out is not None and args.out.exists()
    stopped: FirmwareStopped | None = None
    with contextlib.ExitStack() as files, progress.trace_bar(progress.wanted(args), span) as bar:
        writer = None
        if args.out is not None:
            meta = {
                **trace_reference(args.trace, args.out),
                **firmware_metadata(args.firmware, globals_file),
                **_how_read(args, read),
            }
            t0 = _first_time(args.trace, read) or 0.0
            writer = files.enter_context(FirmwareRunWriter(args.out, profile, t0, meta, watched))
        reached: list[float] = []

        def sink(part: dict[str, Any]) -> None:
            summary_acc.add(part)
            if writer is not None:
                writer.add(part)

        def on_chunk(t: float) -> None:
            reached[:] = [t]
            bar(t)
            check_stop()

        try:
            result = run_c_firmware(
                args.firmware,
                trace,
                profile,
                globals_file=globals_file,
                sink=sink,
                until_s=args.until_s,
                on_chunk=on_chunk,
                # Known once the library is loaded, before the file's metadata is written.
                on_loaded=None if writer is None else writer.record_float_mode,
            )
        except FirmwareStopped as e:
            # The firmware ended the run: what it computed up to there is kept (the summary, the
            # events, the rows in --out); a stop before its first row writes nothing.
            stopped, result = e, e.result
        except KeyboardInterrupt as e:
            how_far = (
                f"at t = {reached[0]:.3f} s of the trace" if reached else "before the trace's first piece"
            )
            raise type(e)(f"stopped {how_far}{_out_state(args.out, out_existed)}") from None
        if writer is not None:
            if stopped is not None and not result.isr_rows:
                raise stopped
            writer.close()
    summary = summary_acc.result(trace=str(args.trace), t0_s=result.t0_s, stage_cycles={})
    summary["firmware"] = {
        "library": str(args.firmware),
        "globals": None if globals_file is None else str(globals_file),
        "float_mode": result.float_mode,
        "truth_in_trace": result.truth,
        "attitude_globals": all(f"q{i}" in {g.column for g in watched} for i in range(4)),
        "isr_runs": result.isr_rows,
        "register_accesses": result.accesses,
        "basic_blocks": result.blocks,
        "virtual_time_s": result.now_s,
        "final_globals": result.final,
        "stopped": None if stopped is None else str(stopped),
        "stdout": "the firmware's stdout goes to stderr (it runs in a process of its own)",
    }
    summary["numeric"] = f"the C firmware's own arithmetic: float and double of the {result.float_mode} mode"
    summary["duration_s"] = result.now_s
    if args.out is not None:
        summary["out"] = str(args.out)
    text = render(summary)
    end = "the trace's end" if stopped is None else "stopped by the firmware: see the error below"
    text = (
        f"firmware       {args.firmware}: {result.isr_rows} ISR runs, {result.accesses} register accesses, "
        f"main ran to {result.now_s:.6f} s of virtual time ({end}); its stdout goes to stderr\n" + text
    )
    if args.out is not None:
        text += f"\nwrote          {args.out} ({summary['cycles']} ISR rows)"
    emit(args, summary, text)
    if stopped is not None:
        raise stopped
    check_error_counts(summary_acc.error_counts(), summary_acc.first_error())
    return 0


def _run_gfsins(args: argparse.Namespace) -> int:
    """`run TRACE --profile gfsins.toml`: the gyro-free board on a `synth vehicle` trace: the packets
    as the DSP decoded them with its tilt against the truth, the events, both processors' budget per
    rate class; --out writes one row per 5 ms cycle with the cycle's bus log."""
    for option, given in (
        ("--firmware", args.firmware),
        ("--globals", args.globals),
        ("--raw-out", args.raw_out),
    ):
        if given is not None:
            raise InputError(
                f"{option} concerns the F28335 boards (its C firmware, its ADIS16407 burst words); the "
                f"gyro-free board ({args.profile}) runs its own firmware models"
            )
    _check_paths(args, ("--out", args.out))
    prof = gfsins.load(args.profile, args.overrides)
    if is_raw_register_trace(args.trace):
        raise TraceError(
            f"{args.trace}: a raw-register trace holds ADIS16407 words; the gyro-free board needs a "
            f"physical trace with {gfsins.NEEDED} (sins-fw synth vehicle)"
        )
    read = read_options(args)
    chunks = PhysicalTrace.iter_chunks(args.trace, gfsins.CHUNK_ROWS, allow_gaps=args.allow_gaps, read=read)
    head = next(iter(chunks), None)
    if head is None or head.array_g is None or head.truth_q is None or head.gps is None:
        groups = (("truth_q*", None if head is None else head.truth_q),
                  ("array*", None if head is None else head.array_g),
                  ("gps_*", None if head is None else head.gps))  # fmt: skip
        missing = [n for n, v in groups if v is None]
        raise TraceError(
            f"{args.trace}: the gyro-free board needs {gfsins.NEEDED}; missing column group(s): "
            f"{', '.join(missing)} (make one with `sins-fw synth vehicle`)"
        )
    until = None
    if args.until_s is not None:
        until = max(0, int((args.until_s - prof.start_s) / prof.period_s + 1e-9) + 1)
    stream = gfsins.Stream(prof, until)
    nav = gfsins.NavErrors(prof.period_s)
    kinds: Counter[str] = Counter()
    first_of: dict[str, dict[str, Any]] = {}
    error_counts: Counter[str] = Counter()
    first_error: dict[str, Any] | None = None
    tilt_acc = np.zeros((2, 3))  # pitch, roll: count, sum of squares, max |error|
    totals = {"accepted": 0, "refused": 0, "gps": 0, "compass": 0, "flushes": 0}
    last_t = 0.0
    out_existed = args.out is not None and args.out.exists()

    def chunks_seen() -> Iterator[PhysicalTrace]:
        for chunk in itertools.chain([head], chunks):
            nav.add_truth(chunk, float(head.t_s[0]))
            yield chunk

    with contextlib.ExitStack() as files:
        writer = None
        if args.out is not None:
            extra = {**trace_reference(args.trace, args.out)}
            if args.until_s is not None:
                extra["until_s"] = repr(args.until_s)
            meta = gfsins.save_metadata(prof, extra)
            writer = files.enter_context(TableWriter(args.out, gfsins.RUN_SCHEMA, meta, allow_gaps=True))
        try:
            for part in stream.parts(chunks_seen()):
                check_stop()
                for e in part["events"]:
                    k = str(e["kind"])
                    kinds[k] += 1
                    first_of.setdefault(k, e)
                    if e["severity"] == "error":
                        error_counts[k] += 1
                        first_error = first_error or e
                n = part["ticks"]
                if not n:
                    continue
                t = part["t0_s"][:, 0]
                last_t = float(t[-1])
                truth = part["truth_deg"][:, 1:3]
                if writer is not None:
                    writer.write(gfsins.run_columns(part, truth))
                accepted = ~np.isnan(part["t_irq_s"][:, 0])
                err = part["tilt_deg"][accepted] - truth[accepted]
                if len(err):
                    tilt_acc[:, 0] += len(err)
                    tilt_acc[:, 1] += np.sum(err * err, axis=0)
                    tilt_acc[:, 2] = np.maximum(tilt_acc[:, 2], np.abs(err).max(axis=0))
                flags = part["flags"][:, 0].astype(int)
                totals["accepted"] += int(accepted.sum())
                totals["refused"] += int((~accepted).sum())
                totals["gps"] += int(np.count_nonzero(flags & 2))
                totals["compass"] += int(np.count_nonzero(flags & 1))
                totals["flushes"] = max(
                    totals["flushes"], int(np.nan_to_num(part["dsp_flushes"][:, 0]).max())
                )
                nav.add(part)
            ticks = stream.ticks
            if ticks == 0:
                raise TraceError(
                    f"{args.trace}: {stream.end_s:.6g} s long: the node's first tick is at "
                    f"{prof.start_s:g} s (node.start_ms)"
                )
        except KeyboardInterrupt as e:
            how = "not written" if not out_existed else "left as it was"
            where = f"; {args.out} {how}" if args.out is not None else ""
            raise type(e)(f"stopped after {stream.ticks} cycles ({last_t:.3f} s){where}") from None
        except TraceError as e:
            if str(e).startswith(str(args.trace)):
                raise
            raise TraceError(f"{args.trace}: {e}") from None
    budget = stream.budget()
    out: dict[str, Any] = budget
    tilt = {
        name: {"rms_deg": float(np.sqrt(a[1] / a[0])), "max_abs_deg": float(a[2])}
        for name, a in zip(("pitch", "roll"), tilt_acc, strict=True)
    } if tilt_acc[0, 0] else {}  # fmt: skip
    summary = {
        "trace": str(args.trace),
        "profile": prof.source,
        "overrides": list(prof.overrides),
        "board": "gfsins",
        "cycles": ticks,
        "virtual_time_s": last_t,
        "packets_accepted": totals["accepted"],
        "packets_refused": totals["refused"],
        "gps_fixes": totals["gps"],
        "compass_updates": totals["compass"],
        "tilt_error": tilt,
        "navigation_error": nav.result(),
        "denormals_flushed": totals["flushes"],
        "events": {k: {"count": n, "first": first_of[k]} for k, n in kinds.items()},
        "budget": {"period_s": out["period_s"], "classes": out["classes"], "rows": gfsins.budget_rows(out)},
    }
    lines = [
        f"trace          {args.trace}",
        f"profile        {prof.source} {' '.join(prof.overrides)}".rstrip(),
        f"cycles         {ticks} of {out['period_s'] * 1e3:g} ms, the last at {last_t:.3f} s; packets "
        f"{summary['packets_accepted']} accepted, {summary['packets_refused']} refused by the DSP; "
        f"{summary['compass_updates']} compass updates, {summary['gps_fixes']} GPS fixes",
    ]
    if tilt:
        lines.append(
            "tilt (DSP)     "
            + "; ".join(
                f"{k} error rms {v['rms_deg']:.4f}°, max {v['max_abs_deg']:.4f}°" for k, v in tilt.items()
            )
            + " (level formula on the centre part: attitude only when the vehicle does not accelerate)"
        )
    nav = summary["navigation_error"]
    if nav:
        lines.append(
            "navigation     after the first fusion: "
            + "; ".join(f"{k} rms {v['rms']:.4g}, max {v['max_abs']:.4g}" for k, v in nav.items())
            + f"; {summary['denormals_flushed']} denormals flushed"
        )
    else:
        lines.append("navigation     never fused (no compass reading and valid GPS fix reached the DSP)")
    if kinds:
        lines.append("events         " + ", ".join(f"{k} ×{n}" for k, n in kinds.items()))
        lines += [f"  first {k} at {first_of[k]['t_s']:.6f} s: {first_of[k]['message']}" for k in kinds]
    else:
        lines.append("events         none")
    lines += ["budget", *("  " + x for x in gfsins.render_budget(out))]
    if args.out is not None:
        lines.append(f"wrote          {args.out} ({ticks} cycles)")
        summary["out"] = str(args.out)
    emit(args, summary, "\n".join(lines))
    check_error_counts(error_counts, first_error)
    return 0
