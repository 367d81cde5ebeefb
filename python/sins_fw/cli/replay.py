"""`sins-fw replay TRACE --out FILE.rrd [--spawn]`: emulate a physical trace and write a Rerun
recording (3-D attitude, time series, budget, events, the SPI bus of a window of ticks) with its
default layout; `--spawn` opens it in the Rerun viewer when one can be shown.

TRACE is a physical trace (.h5 or .csv, docs/traces.md) or a run output (`sins-fw run --out`): a
run of the Rust model is re-emulated and checked bit for bit before it is shown; a C firmware's
(`run --firmware --out`) is shown as recorded (:mod:`sins_fw.viewer.firmware`).
"""

from __future__ import annotations

import argparse
import contextlib
import os
import shutil
import sys
import tempfile
from collections import Counter
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

from sins_fw import _core, gfsins, parity, progress
from sins_fw.atomic import check_output_folder
from sins_fw.cli.common import (
    EVENTS_CHECK,
    add_json_option,
    add_out_option,
    add_profile_options,
    add_trace_or_run_argument,
    check_error_counts,
    emit,
    exit_epilog,
    firmware_run_report,
    open_firmware_run,
    profile_from_args,
)
from sins_fw.cli.stop import check_stop
from sins_fw.errors import InputError, TraceError
from sins_fw.harness import CHUNK_ROWS, Run, emulate, has_dcm, has_wing
from sins_fw.profile import Profile
from sins_fw.run_output import (
    FIRMWARE_CREATED_BY,
    RUN_FORMAT,
    recorded_trace,
    replay_check,
    resolve_trace,
)
from sins_fw.traces import PhysicalTrace, file_sha256, read_metadata
from sins_fw.viewer import serve

if TYPE_CHECKING:
    from sins_fw.viewer.recording import Recorder

NUMERICS: tuple[str, ...] = tuple(_core.NUMERICS)


class ViewerUnavailableError(InputError):
    """The Rerun viewer cannot be shown here (no display, no viewer executable)."""


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "replay",
        help="emulate a trace and write a Rerun recording (.rrd) to replay in the Rerun viewer",
        description="Emulate a physical trace and write a Rerun recording: the board at the estimated "
        "attitude (and its truth), roll/pitch/yaw and their errors, decoded vs physical IMU data, raw "
        "register words with ND/EA, sample age, the ISR budget per tick, events, and the SPI bus "
        "(CS, frames with DIN/DOUT, stalls) for a window of ticks. Open it with `rerun FILE.rrd`. A C "
        "firmware's run output (`run --firmware --out`) is shown as recorded, not re-emulated: its "
        "globals as time series and, when they give the attitude, the board, the Euler angles and the "
        "error against the recorded trace's truth.",
        epilog=exit_epilog(f"{EVENTS_CHECK}, or a saved run does not replay bit for bit"),
    )
    add_trace_or_run_argument(p)
    add_profile_options(p)
    add_out_option(p, "write the recording to this file (.rrd)", metavar="FILE.rrd", formerly="--save")
    p.add_argument(
        "--spawn", action="store_true", help="open the recording in the Rerun viewer (needs a display)"
    )
    p.add_argument(
        "--serve",
        action="store_true",
        help="serve the recording in Rerun's web viewer (no display needed) and print its address; "
        "Ctrl-C stops it",
    )
    p.add_argument(
        "--bind",
        default="127.0.0.1",
        metavar="ADDRESS",
        help="address --serve listens on (default 127.0.0.1, this machine only: Rerun's servers have no "
        "authentication)",
    )
    p.add_argument(
        "--port",
        type=port_number,
        default=serve.WEB_PORT,
        help=f"--serve: the web viewer's HTTP port (default {serve.WEB_PORT}; 0 for a free one)",
    )
    p.add_argument(
        "--grpc-port",
        type=port_number,
        default=serve.GRPC_PORT,
        help=f"--serve: the port the viewer fetches the recording from (default {serve.GRPC_PORT}; 0 for a "
        "free one)",
    )
    p.add_argument(
        "--bus-ticks",
        default="1:25",
        metavar="FIRST:LAST",
        help="timer ticks whose SPI traffic is recorded, inclusive (default 1:25; `none` for no bus view)",
    )
    p.add_argument(
        "--parity",
        action="append",
        default=[],
        choices=NUMERICS,
        metavar="NUMERIC",
        help=f"also run this numeric backend ({', '.join(NUMERICS)}) and log its difference (repeatable)",
    )
    add_json_option(p)
    p.set_defaults(func=run)


def port_number(text: str) -> int:
    """A TCP port, 0…65535 (0: a free one); argparse names the option on a refusal (exit 2)."""
    try:
        port = int(text, 10)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: expected a TCP port number, 0…65535") from None
    if not 0 <= port <= 65535:
        raise argparse.ArgumentTypeError(f"{port}: expected a TCP port number, 0…65535 (0: a free one)")
    return port


def parse_ticks(text: str) -> tuple[int, int] | None:
    """`FIRST:LAST` → (first, last); `none` → None."""
    if text.strip().lower() == "none":
        return None
    try:
        first, last = (int(x) for x in text.split(":"))
    except ValueError:
        raise InputError(
            f"--bus-ticks {text!r}: expected FIRST:LAST (timer ticks, from 1) or `none`"
        ) from None
    if not 1 <= first <= last:
        raise InputError(f"--bus-ticks {text!r}: expected 1 <= FIRST <= LAST")
    return first, last


def viewer_problem() -> str | None:
    """Why the Rerun viewer cannot be opened here, or None when it can."""
    has_viewer = shutil.which("rerun") is not None or _bundled_viewer()
    if not has_viewer:
        return "no Rerun viewer executable (`rerun`) is installed"
    if sys.platform.startswith("linux") and not (
        os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
    ):
        return "no display (DISPLAY and WAYLAND_DISPLAY are unset)"
    return None


def _bundled_viewer() -> bool:
    try:
        import rerun_cli  # noqa: F401  (the viewer shipped with rerun-sdk)
    except ImportError:
        return False
    return True


class _Tally:
    """What the replay's report says of the run, counted part by part."""

    def __init__(self) -> None:
        self.cycles = 0
        self.ticks = 0
        self.kinds: Counter[str] = Counter()
        self.errors: Counter[str] = Counter()  # in the order each kind first occurred
        self.first_error: dict[str, Any] | None = None
        self.last_step: int | None = None

    def add(self, part: dict[str, Any]) -> None:
        self.cycles += len(part["cycle_step"])
        self.ticks += len(part["budget_tick"])
        if len(part["cycle_step"]):
            self.last_step = int(part["cycle_step"][-1])
        for e in part["events"]:
            self.kinds[e["kind"]] += 1
            if e["severity"] == "error":
                self.errors[e["kind"]] += 1
                self.first_error = self.first_error or e


class _Parity:
    """The other backends' runs, side by side with the replayed one (``parity.streamed``: each in a
    thread, a few parts queued), handed to the recorders as far as the replayed run has got."""

    KEEP = ("cycle_step", "cycle_euler_deg", "cycle_quat")

    def __init__(
        self, trace: Path | PhysicalTrace, profile: Profile, names: list[str], recorders: list[Recorder]
    ) -> None:
        profiles = {n: profile.with_overrides(f"firmware.numeric={n}") for n in names}
        self.rows = parity.streamed(trace, profiles, None, CHUNK_ROWS, keep=self.KEEP) if names else iter(())
        self.reached: dict[str, int | None] = dict.fromkeys(names)
        self.done: set[str] = set()
        self.recorders = recorders

    def _pull(self) -> bool:
        row = next(self.rows, None)
        if row is None:
            self.done |= set(self.reached)
            return False
        for name, part in row.items():
            if part is None:
                self.done.add(name)
                continue
            if len(part["cycle_step"]):
                self.reached[name] = int(part["cycle_step"][-1])
            for r in self.recorders:
                r.add_parity(name, part)
        return True

    def upto(self, step: int | None) -> None:
        """Pull the backends' parts until each has reached ``step`` (or ended)."""
        if step is None:
            return
        while any(n not in self.done and (s is None or s < step) for n, s in self.reached.items()):
            if not self._pull():
                return

    def finish(self) -> None:
        while self._pull():
            pass

    def close(self) -> None:
        close = getattr(self.rows, "close", None)
        if close is not None:
            close()  # stops the threads of backends still running (an error in the replayed run)


def run(args: argparse.Namespace) -> int:
    if args.out is None and not args.spawn and not args.serve:
        raise InputError("nothing to do: give --out FILE.rrd, --spawn or --serve")
    if args.serve:
        # Refused before any work: a port in use (or the same for both) or the viewer missing.
        wanted = (("--port", args.port), ("--grpc-port", args.grpc_port))
        serve.free_ports(args.bind, *((port, option) for option, port in wanted if port != 0))
        serve.viewer_binary()
    if args.out is not None and (args.out.is_dir() or args.out.suffix != ".rrd"):
        raise InputError(f"--out {args.out}: expected a file name ending in .rrd")
    if args.out is not None:
        check_output_folder(args.out, "--out")
    window = parse_ticks(args.bus_ticks)
    problem = viewer_problem() if args.spawn else None
    if problem is not None and args.out is None:
        # Fail before any work: nothing would be kept.
        raise ViewerUnavailableError(
            f"cannot open the Rerun viewer: {problem}; use --out FILE.rrd and open it "
            "with `rerun FILE.rrd` where a display is available"
        )
    meta = read_metadata(args.trace)
    if meta.get("format") == gfsins.RUN_FORMAT:
        raise InputError(
            f"{args.trace}: a saved run of the gyro-free board; replay the trace it records "
            f"({meta.get('trace', 'its `trace` metadata')}) with --profile {meta.get('profile', 'gfsins')}"
        )
    if meta.get("format") == RUN_FORMAT and meta.get("created_by") == FIRMWARE_CREATED_BY:
        return _replay_firmware(args, problem)
    if gfsins.has_own_schema(args.profile) and meta.get("format") != RUN_FORMAT:
        return _replay_gfsins(args, window, problem)
    saved_run: Run | None = None
    source: Path | PhysicalTrace | None = None
    if meta.get("format") == RUN_FORMAT:
        # A saved run: replay it from its recorded inputs and check it before showing it (whole).
        saved_run, meta = replay_check(args.trace, bus_window=window)
        profile = saved_run.profile
        trace = resolve_trace(args.trace, meta)
        source = recorded_trace(args.trace, meta)  # read as the run read it (--units, --columns)
    else:
        profile = profile_from_args(args)
        trace = args.trace
        if not trace.is_file():
            raise TraceError(f"{trace}: no such trace file")
    names = [n for n in dict.fromkeys(args.parity) if n != profile.get("firmware.numeric")]
    with contextlib.ExitStack() as keep:
        served = _served(args, keep)
        tally, bus_frames = _record(
            args, trace, profile, saved_run, window, names, served, problem is None, source
        )
        report = {
            "trace": str(args.trace),
            "profile": profile.source,
            "overrides": list(profile.overrides),
            "cycles": tally.cycles,
            "ticks": tally.ticks,
            "events": dict(sorted(tally.kinds.items())),
            "bus_ticks": list(window) if window else None,
            "bus_frames": bus_frames,
            "parity": sorted(names),
            "saved": None if args.out is None else str(args.out),
        }
        lines = [
            f"replay of {args.trace}: {tally.cycles} cycles, {tally.ticks} ticks, "
            f"{sum(tally.kinds.values())} events {report['events'] or ''}".rstrip(),
            f"bus window: ticks {window[0]}…{window[1]}, {bus_frames} frames"
            if window
            else "bus: not recorded",
        ]
        code = _report_and_serve(args, report, lines, problem, served)
        if code != 0:
            return code
    # The recording is shown first, whatever its events.
    check_error_counts(dict(tally.errors), tally.first_error)
    return 0


def _record(
    args: argparse.Namespace,
    trace: Path,
    profile: Profile,
    saved_run: Run | None,
    window: tuple[int, int] | None,
    names: list[str],
    served: Path | None,
    spawn: bool,
    source: Path | PhysicalTrace | None = None,
) -> tuple[_Tally, int]:
    """Emulate ``trace`` (or take ``saved_run``) and log it, part by part as it streams out, to the
    file ``served`` and/or a spawned viewer; the other backends ``names`` side by side. Returns what
    the report says and the number of bus frames. ``source``: the trace as the saved run read it,
    when that differs from the file ``trace`` (see :func:`sins_fw.run_output.recorded_trace`)."""
    from sins_fw.viewer import recording  # rerun is a heavy import
    from sins_fw.viewer.layout import default_blueprint  # as recording: Rerun

    blueprint = default_blueprint(
        bus=window is not None, parity=names, dcm=has_dcm(profile), wing=has_wing(profile)
    )
    # The id is derived from what the recording is made of (docs/traces.md, "Determinism").
    rid = recording.recording_id(
        profile.text,
        "\n".join(profile.overrides),
        args.trace.name,
        bytes.fromhex(file_sha256(trace)),
        repr(window),
        ",".join(names),
    )
    tally = _Tally()
    with contextlib.ExitStack() as stack:
        streams = stack.enter_context(_recording_streams(args, served, rid, blueprint, spawn))
        recorders = [
            recording.Recorder(r, profile, trace=source or trace, parity=names, bus_window=window)
            for r in streams
        ]
        others = _Parity(source or trace, profile, names, recorders)
        stack.callback(others.close)

        def sink(part: dict[str, Any]) -> None:
            tally.add(part)
            for r in recorders:
                r.add(part)
            others.upto(tally.last_step)

        if saved_run is not None:
            sink(recording.run_part(saved_run))
            bus = saved_run.bus
        else:
            with progress.trace_bar(
                progress.wanted(args), progress.trace_span_s(trace), desc="replaying"
            ) as reached:
                bus = emulate(trace, profile, bus_window=window, sink=sink, on_chunk=reached).bus
        others.finish()
        for r in recorders:
            r.finish(bus)
    return tally, 0 if bus is None else len(bus["frame_index"])


def _replay_gfsins(args: argparse.Namespace, window: tuple[int, int] | None, problem: str | None) -> int:
    """`replay TRACE --profile gfsins.toml`: the gyro-free board's run as a Rerun recording with a
    bus lane per link (sins_fw.viewer.gfsins)."""
    from sins_fw.viewer import gfsins as view  # rerun is a heavy import: only for a replay
    from sins_fw.viewer import recording  # as above

    if args.parity:
        raise InputError(
            "--parity runs the F28335 firmware's other numeric backends; the gyro-free board has none"
        )
    if not args.trace.is_file():
        raise TraceError(f"{args.trace}: no such trace file")
    prof = gfsins.load(args.profile, args.overrides)
    # The board runs block by block over the trace read a chunk at a time (as `run` does): memory
    # holds a chunk and a block whatever the trace's length, and a stop is seen between blocks.
    chunks = PhysicalTrace.iter_chunks(args.trace, gfsins.CHUNK_ROWS)
    stream = gfsins.Stream(prof)
    kinds: Counter[str] = Counter()
    errors: Counter[str] = Counter()
    first_error: dict[str, Any] | None = None
    trace_hash = bytes.fromhex(file_sha256(args.trace))
    overrides = "\n".join(prof.overrides)
    rid = recording.recording_id(prof.text, overrides, args.trace.name, trace_hash, repr(window))
    bp = view.blueprint(bus=window is not None)
    with contextlib.ExitStack() as keep:
        served = _served(args, keep)
        logged = 0
        with _recording_streams(args, served, rid, bp, problem is None) as streams:
            address = int(prof.get("compass.address"))
            recorders = [view.Recorder(r, window, address) for r in streams]
            try:
                for part in stream.parts(chunks):
                    check_stop()
                    for e in part["events"]:
                        kinds[str(e["kind"])] += 1
                        if e["severity"] == "error":
                            errors[str(e["kind"])] += 1
                            first_error = first_error or e
                    for recorder in recorders:
                        recorder.add(part, part["truth_deg"][:, 1:3])
            except KeyboardInterrupt as e:
                where = f"; {args.out} not written" if args.out is not None else ""
                raise type(e)(f"stopped after {stream.ticks} cycles{where}") from None
            except TraceError as e:
                if str(e).startswith(str(args.trace)):
                    raise
                raise TraceError(f"{args.trace}: {e}") from None
            for recorder in recorders:
                logged = recorder.finish()
        ticks = stream.ticks
        report = {
            "trace": str(args.trace),
            "profile": prof.source,
            "overrides": list(prof.overrides),
            "board": "gfsins",
            "cycles": ticks,
            "ticks": ticks,
            "events": dict(sorted(kinds.items())),
            "bus_ticks": list(window) if window else None,
            "bus_links": list(view.paths.GFSINS_LINKS) if window else [],
            "bus_transactions": logged,
            "parity": [],
            "saved": None if args.out is None else str(args.out),
        }
        lines = [
            f"replay of {args.trace} on the gyro-free board: {ticks} cycles, {sum(kinds.values())} events "
            f"{report['events'] or ''}".rstrip(),
            f"bus window: ticks {window[0]}…{window[1]}, {logged} transactions on "
            f"{', '.join(view.paths.GFSINS_LINKS)}"
            if window
            else "bus: not recorded",
        ]
        code = _report_and_serve(args, report, lines, problem, served)
        if code != 0:
            return code
    check_error_counts(errors, first_error)
    return 0


def _replay_firmware(args: argparse.Namespace, problem: str | None) -> int:
    """`replay RUN` of a C firmware's run output: the recording made from the file as recorded, a
    block at a time (:mod:`sins_fw.viewer.firmware`); nothing is re-emulated."""
    from sins_fw.viewer import firmware as view  # rerun is a heavy import: only for a replay
    from sins_fw.viewer import recording  # as above

    if args.parity:
        raise InputError(
            f"{args.trace}: --parity re-runs the Rust model's numeric backends; a C firmware's run output "
            "is shown as recorded"
        )
    run_file, profile, trace, note = open_firmware_run(args.trace, "recorded")
    rid = recording.recording_id(
        "sins-fw run --firmware",
        profile.text,
        "\n".join(profile.overrides),
        args.trace.name,
        bytes.fromhex(file_sha256(args.trace)),
    )
    bp = view.blueprint(run_file)
    with contextlib.ExitStack() as keep:
        served = _served(args, keep)
        with _recording_streams(args, served, rid, bp, problem is None) as streams:
            recorders = [view.FirmwareRecorder(r, run_file, profile) for r in streams]
            rows, truth = 0, False
            for part in run_file.parts(trace):
                check_stop()
                rows += len(part["cycle_step"])
                truth |= "truth_q" in part
                for recorder in recorders:
                    recorder.add(part)
            for recorder in recorders:
                recorder.finish()
        m = run_file.metadata
        report = firmware_run_report(args, run_file, profile, rows, truth, note)
        report["saved"] = None if args.out is None else str(args.out)
        if not run_file.has_attitude:
            attitude = "no attitude columns (q0…q3, roll_deg/pitch_deg/yaw_deg)"
        elif truth:
            attitude = "its attitude against the trace's truth"
        else:
            attitude = "its attitude, no truth (" + (
                "the trace has none)" if trace is not None else "trace not found)"
            )
        lines = [
            f"replay of {args.trace}, a run of the C firmware {m.get('firmware', '?')} shown as recorded "
            f"(not re-emulated): {rows} ISR rows, {len(run_file.columns)} globals, {attitude}",
        ]
        code = _report_and_serve(args, report, lines, problem, served)
        if code != 0:
            return code
    return 0


def _served(args: argparse.Namespace, keep: contextlib.ExitStack) -> Path | None:
    """The file the replay's recording is written to: ``--out``, or for ``--serve`` alone a
    temporary one (removed when ``keep`` closes); None when only a viewer is spawned."""
    if args.out is None and args.serve:
        tmp = keep.enter_context(tempfile.TemporaryDirectory(prefix="sins-fw-serve-"))
        return Path(tmp) / f"{args.trace.stem}.rrd"
    return args.out


@contextlib.contextmanager
def _recording_streams(
    args: argparse.Namespace, served: Path | None, rid: str, blueprint: Any, spawn: bool
) -> Iterator[list[Any]]:
    """Where a replay logs: the recording file ``served`` (complete once the block ends cleanly:
    :func:`sins_fw.viewer.recording.recording_file`) and/or, with ``--spawn`` (and ``spawn``), a
    Rerun viewer started for the recording ``rid``, flushed at the end."""
    from sins_fw.viewer import recording  # rerun is a heavy import

    with contextlib.ExitStack() as files:
        streams: list[Any] = []
        if served is not None:
            name = args.trace.name
            out = recording.recording_file(served, recording_id=rid, blueprint=blueprint, name=name)
            streams.append(files.enter_context(out))
        viewer = None
        if args.spawn and spawn:
            import rerun as rr  # as above

            viewer = rr.RecordingStream("sins-fw", recording_id=rid)
            try:
                viewer.spawn(default_blueprint=blueprint)
            except Exception as e:  # the viewer failed to start: say why, no traceback
                raise ViewerUnavailableError(f"cannot open the Rerun viewer: {e}") from None
            streams.append(viewer)
        yield streams
        if viewer is not None:
            viewer.flush()


def _report_and_serve(
    args: argparse.Namespace,
    report: dict[str, Any],
    lines: list[str],
    problem: str | None,
    served: Path | None,
) -> int:
    """Say where the recording went (saved, sent to the viewer), print the report, then serve the
    recording when `--serve` asks: the exit code of the server, 0 without one."""
    if args.out is not None:
        lines.append(f"saved {args.out} (open it with `rerun {args.out}`)")
    if args.spawn:
        if problem is not None:
            emit(args, report, "\n".join(lines))
            raise ViewerUnavailableError(
                f"cannot open the Rerun viewer: {problem}; the recording was saved to {args.out}"
            )
        lines.append("sent to the Rerun viewer")
    emit(args, report, "\n".join(lines))
    if not args.serve:
        return 0
    assert served is not None

    def ready(url: str) -> None:
        print(f"serving {served.name} in Rerun's web viewer at {url} (Ctrl-C stops it)", flush=True)

    return serve.serve(served, bind=args.bind, web_port=args.port, grpc_port=args.grpc_port, on_ready=ready)
