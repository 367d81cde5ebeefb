"""`sins-fw import broad FILE.hdf5 --out TRACE`, `sins-fw import trace FILE --out TRACE` and the
importers of other logs: `sins-fw import ulog|dataflash|rosbag|euroc FILE --out TRACE`.

``broad`` converts a BROAD trial into a physical trace; ``trace`` reads a physical or raw-register
trace, validates it and writes it in the form the output extension asks for (CSV ↔ .h5); the log
importers are in :mod:`sins_fw.importers` (docs/traces.md, 'Importing logs').
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from sins_fw import progress
from sins_fw.atomic import check_output_folder
from sins_fw.broad import iter_broad
from sins_fw.cli.common import (
    add_json_option,
    add_option,
    add_out_option,
    add_read_options,
    emit,
    exit_epilog,
    read_options,
)
from sins_fw.errors import InputError, TraceError
from sins_fw.importers import DEFAULT_GPS_LATENCY_S, check_gps_latency, importer
from sins_fw.stream import save_chunks
from sins_fw.traces import (
    DEFAULT_MAX_GAP_PERIODS,
    RAW_FORMAT,
    PhysicalTrace,
    RawRegisterTrace,
    check_output_path,
    read_metadata,
)

#: Rows read and written at a time by `import trace` (the HDF5 chunk of the trace formats).
IMPORT_CHUNK_ROWS = 1 << 16


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "import",
        help="convert a BROAD trial, a PX4, ArduPilot, ROS or EuRoC log, or a trace file into a sins-fw "
        "trace (.csv/.h5)",
        epilog=exit_epilog(None),
    )
    kinds = p.add_subparsers(dest="kind", metavar="KIND", required=True)
    b = _kind(
        kinds,
        "broad",
        "a BROAD trial (.hdf5) → physical trace with truth and movement mask",
        "BROAD trial, e.g. 01_undisturbed_slow_rotation_A.hdf5",
    )
    add_json_option(b)
    b.set_defaults(func=run)
    t = _kind(
        kinds,
        "trace",
        "validate a physical or raw-register trace and write it as .csv or .h5",
        "input trace, .csv or .h5",
    )
    t.add_argument("--allow-gaps", action="store_true", help="accept time steps longer than the gap limit")
    t.add_argument(
        "--max-gap-periods",
        type=float,
        default=DEFAULT_MAX_GAP_PERIODS,
        help=f"gap limit in nominal sample periods (default {DEFAULT_MAX_GAP_PERIODS})",
    )
    add_read_options(t)
    add_json_option(t)
    t.set_defaults(func=run)
    _register_logs(kinds)


def _kind(
    kinds: argparse._SubParsersAction,
    name: str,
    help_text: str,
    file_help: str,
    description: str | None = None,
) -> argparse.ArgumentParser:
    """`sins-fw import NAME FILE --out TRACE`: the parser of one kind of input, with its FILE and --out."""
    k = kinds.add_parser(name, help=help_text, description=description, epilog=exit_epilog(None))
    k.add_argument("file", type=Path, help=file_help)
    add_out_option(k, "output trace, .csv or .h5", required=True)
    return k


_LOGS = {  # the kinds of sins_fw.importers.IMPORTERS
    "ulog": ("a PX4 ULog (.ulg) → physical trace (needs pyulog)", "PX4 log, e.g. flight.ulg"),
    "dataflash": (
        "an ArduPilot DataFlash log (.bin) → physical trace (needs pymavlink)",
        "ArduPilot log, e.g. 00000042.BIN",
    ),
    "rosbag": (
        "a ROS 1 (.bag) or ROS 2 (folder, .db3, .mcap) bag's sensor_msgs/Imu → physical trace "
        "(needs rosbags)",
        "ROS bag file or ROS 2 bag folder",
    ),
    "euroc": (
        "EuRoC-style CSV (imu0/data.csv, ground truth) → physical trace",
        "EuRoC folder (holding imu0/ or mav0/imu0/) or its imu0/data.csv",
    ),
}


def _register_logs(kinds: argparse._SubParsersAction) -> None:
    for kind, (help_text, file_help) in _LOGS.items():
        k = _kind(kinds, kind, help_text, file_help, help_text + " (docs/traces.md, 'Importing logs')")
        if kind == "euroc":
            k.add_argument(
                "--truth",
                type=Path,
                help="ground-truth CSV (default: the folder's "
                "state_groundtruth_estimate0/data.csv when present)",
            )
        if kind == "rosbag":
            k.add_argument("--imu-topic", help="the sensor_msgs/Imu topic (default: the bag's only one)")
            k.add_argument(
                "--mag-topic", help="the sensor_msgs/MagneticField topic (default: the bag's only one)"
            )
            k.add_argument(
                "--gps-topic", help="the sensor_msgs/NavSatFix topic (default: the bag's only one)"
            )
            k.add_argument(
                "--gps-velocity-topic",
                help="the geometry_msgs/TwistStamped topic of the fixes' ENU ground velocity "
                "(default: the bag's only one)",
            )
        if kind != "euroc":
            add_option(
                k,
                "--gps-latency-s",
                type=_latency,
                default=DEFAULT_GPS_LATENCY_S,
                metavar="S",
                help="the GPS receiver's latency, 0…10 s: a fix's time of validity is its logged stamp "
                f"minus this (default {DEFAULT_GPS_LATENCY_S}: the stamp is the time of validity); "
                "written as gps_latency_s",
            )
        k.add_argument(
            "--allow-gaps", action="store_true", help="accept time steps longer than the gap limit"
        )
        add_json_option(k)
        k.set_defaults(func=run)


def _latency(text: str) -> float:
    """`--gps-latency-s`: a number in 0…10 (argparse names the option on a refusal)."""
    try:
        return check_gps_latency(float(text))
    except (ValueError, InputError):
        raise argparse.ArgumentTypeError(f"{text!r}: expected the GPS receiver's latency in 0…10 s") from None


def _import_log(args: argparse.Namespace) -> PhysicalTrace:
    options: dict[str, Any] = {}
    if args.kind == "euroc":
        options["truth"] = args.truth
    if args.kind == "rosbag":
        options.update(
            imu_topic=args.imu_topic,
            mag_topic=args.mag_topic,
            gps_topic=args.gps_topic,
            gps_velocity_topic=args.gps_velocity_topic,
        )
    if args.kind != "euroc":
        options["gps_latency_s"] = args.gps_latency_s
    trace = importer(args.kind)(args.file, **options)
    try:
        trace.validate(allow_gaps=args.allow_gaps)
    except TraceError as e:
        raise TraceError(f"{args.file}: the imported trace is invalid: {e}") from None
    return trace


def run(args: argparse.Namespace) -> int:
    check_output_path(args.out)
    check_output_folder(args.out, "--out")
    if args.kind == "broad":
        # Read, converted and written a chunk at a time, as `import trace` (issue 24, item 11).
        written = save_chunks(args.out, iter_broad(args.file, IMPORT_CHUNK_ROWS))
        kind_name, rows, metadata = PhysicalTrace.__name__, written.rows, written.metadata
    elif args.kind in _LOGS:
        trace = _import_log(args)
        trace.save(args.out, allow_gaps=args.allow_gaps)
        kind_name, rows, metadata = type(trace).__name__, len(trace), trace.metadata
    else:
        # Read and written a chunk at a time: memory is bounded by the chunk (issue 24, item 11).
        kind = RawRegisterTrace if read_metadata(args.file).get("format") == RAW_FORMAT else PhysicalTrace
        chunks = kind.iter_chunks(
            args.file,
            IMPORT_CHUNK_ROWS,
            allow_gaps=args.allow_gaps,
            max_gap_periods=args.max_gap_periods,
            read=read_options(args),
        )
        span = progress.trace_span_s(args.file)
        with progress.bar(progress.wanted(args), span, desc="importing") as advance:
            written = save_chunks(args.out, progress.follow(chunks, advance), allow_gaps=args.allow_gaps)
        kind_name, rows, metadata = kind.__name__, written.rows, written.metadata
    report = {
        "in": str(args.file),
        "out": str(args.out),
        "kind": kind_name,
        "rows": rows,
        "sample_rate_hz": metadata["sample_rate_hz"],
        "source": metadata.get("source", ""),
    }
    emit(args, report, f"wrote {args.out}: {report['kind']}, {rows} rows from {args.file}")
    return 0
