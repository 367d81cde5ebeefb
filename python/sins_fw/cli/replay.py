"""`sins-fw replay TRACE --out FILE.rrd [--spawn]`: emulate a physical trace and write a Rerun
recording (3-D attitude, time series, budget, events, the SPI bus of a window of ticks) with its
default layout; `--spawn` opens it in the Rerun viewer when one can be shown.

TRACE is a physical trace (.h5 or .csv, docs/traces.md). Saved run outputs are not accepted yet:
the project has no run-output file format.
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
from pathlib import Path

from sins_fw.atomic import check_distinct
from sins_fw.cli.common import (
    EVENTS_CHECK,
    add_json_option,
    add_out_option,
    add_profile_options,
    check_events,
    emit,
    exit_epilog,
    profile_file,
    profile_from_args,
)
from sins_fw.errors import InputError
from sins_fw.harness import emulate
from sins_fw.run_output import RUN_FORMAT, replay_check, resolve_trace
from sins_fw.traces import PhysicalTrace, read_metadata
from sins_fw.viewer import serve

NUMERICS = ("f64", "c28x-f32", "c28x-f32-rz", "iq")


class ViewerUnavailableError(InputError):
    """The Rerun viewer cannot be shown here (no display, no viewer executable)."""


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "replay",
        help="emulate a trace and write a Rerun recording (.rrd) to replay in the Rerun viewer",
        description="Emulate a physical trace and write a Rerun recording: the board at the estimated "
        "attitude (and its truth), roll/pitch/yaw and their errors, decoded vs physical IMU data, raw "
        "register words with ND/EA, sample age, the ISR budget per tick, events, and the SPI bus "
        "(CS, frames with DIN/DOUT, stalls) for a window of ticks. Open it with `rerun FILE.rrd`.",
        epilog=exit_epilog(f"{EVENTS_CHECK}, or a saved run does not replay bit for bit"),
    )
    p.add_argument(
        "trace",
        type=Path,
        metavar="TRACE_OR_RUN",
        help="physical trace (.h5 or .csv), or a `sins-fw run --out` file: re-emulated from its recorded "
        "trace and profile and checked bit for bit against it (exit 1 on a difference)",
    )
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
        type=int,
        default=serve.WEB_PORT,
        help=f"--serve: the web viewer's HTTP port (default {serve.WEB_PORT}; 0 for a free one)",
    )
    p.add_argument(
        "--grpc-port",
        type=int,
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


def run(args: argparse.Namespace) -> int:
    if args.out is None and not args.spawn and not args.serve:
        raise InputError("nothing to do: give --out FILE.rrd, --spawn or --serve")
    if args.serve:
        # Refused before any work: a port in use or the viewer missing.
        serve.viewer_binary()
        for option, port in (("--port", args.port), ("--grpc-port", args.grpc_port)):
            if port != 0:
                serve.free_port(args.bind, port, option)
    if args.out is not None and (args.out.is_dir() or args.out.suffix != ".rrd"):
        raise InputError(f"--out {args.out}: expected a file name ending in .rrd")
    window = parse_ticks(args.bus_ticks)
    problem = viewer_problem() if args.spawn else None
    if problem is not None and args.out is None:
        # Fail before any work: nothing would be kept.
        raise ViewerUnavailableError(
            f"cannot open the Rerun viewer: {problem}; use --out FILE.rrd and open it "
            "with `rerun FILE.rrd` where a display is available"
        )
    meta = read_metadata(args.trace)
    # The trace a saved run records, found where the replay will find it (run_output.resolve_trace).
    recorded = resolve_trace(args.trace, meta) if meta.get("format") == RUN_FORMAT else None
    check_distinct(
        {"TRACE_OR_RUN": args.trace, "its recorded trace": recorded, "--profile": profile_file(args)},
        {"--out": args.out},
    )
    if meta.get("format") == RUN_FORMAT:
        # A saved run: replay it from its recorded inputs and check it before showing it.
        run_, meta = replay_check(args.trace, bus_window=window)
        profile = run_.profile
        trace = PhysicalTrace.load(resolve_trace(args.trace, meta))
    else:
        profile = profile_from_args(args)
        trace = PhysicalTrace.load(args.trace)
        run_ = emulate(trace, profile, bus_window=window)
    parity = {
        name: emulate(trace, profile, overrides=[f"firmware.numeric={name}"])
        for name in args.parity
        if name != profile.get("firmware.numeric")
    }
    from sins_fw.viewer import default_blueprint, log_run, save_recording  # rerun is a heavy import

    report = {
        "trace": str(args.trace),
        "profile": profile.source,
        "overrides": list(profile.overrides),
        "cycles": run_.cycles,
        "ticks": len(run_.budget["tick"]),
        "events": run_.events_by_kind(),
        "bus_ticks": list(window) if window else None,
        "bus_frames": 0 if run_.bus is None else len(run_.bus["frame_index"]),
        "parity": sorted(parity),
        "saved": None,
    }
    if args.out is not None:
        save_recording(run_, args.out, trace=trace, parity=parity, name=args.trace.name)
        report["saved"] = str(args.out)
    lines = [
        f"replay of {args.trace}: {run_.cycles} cycles, {report['ticks']} ticks, "
        f"{len(run_.events)} events {report['events'] or ''}".rstrip(),
        f"bus window: ticks {window[0]}…{window[1]}, {report['bus_frames']} frames"
        if window
        else "bus: not recorded",
    ]
    if args.out is not None:
        lines.append(f"saved {args.out} (open it with `rerun {args.out}`)")
    if args.spawn:
        if problem is not None:
            emit(args, report, "\n".join(lines))
            raise ViewerUnavailableError(
                f"cannot open the Rerun viewer: {problem}; the recording was saved to {args.out}"
            )
        import rerun as rr

        rec = rr.RecordingStream("sins-fw")
        try:
            rec.spawn(default_blueprint=default_blueprint(run_, parity=parity))
        except Exception as e:  # the viewer failed to start: say why, no traceback
            raise ViewerUnavailableError(f"cannot open the Rerun viewer: {e}") from None
        log_run(rec, run_, trace=trace, parity=parity)
        rec.flush()
        lines.append("sent to the Rerun viewer")
    if args.serve:
        with tempfile.TemporaryDirectory(prefix="sins-fw-serve-") as tmp:
            served = args.out
            if served is None:
                served = Path(tmp) / f"{args.trace.stem}.rrd"
                save_recording(run_, served, trace=trace, parity=parity, name=args.trace.name)
            emit(args, report, "\n".join(lines))

            def ready(url: str) -> None:
                print(f"serving {served.name} in Rerun's web viewer at {url} (Ctrl-C stops it)", flush=True)

            code = serve.serve(
                served, bind=args.bind, web_port=args.port, grpc_port=args.grpc_port, on_ready=ready
            )
        if code == 0:
            check_events(run_.events)  # the recording is shown first, whatever its events
        return code
    emit(args, report, "\n".join(lines))
    check_events(run_.events)
    return 0
