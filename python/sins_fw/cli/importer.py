"""`sins-fw import broad FILE.hdf5 --out TRACE` and `sins-fw import trace FILE --out TRACE`.

``broad`` converts a BROAD trial into a physical trace; ``trace`` reads a physical or raw-register
trace, validates it and writes it in the form the output extension asks for (CSV ↔ .h5).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from sins_fw import progress
from sins_fw.atomic import check_distinct, check_output_folder
from sins_fw.broad import iter_broad
from sins_fw.cli.common import add_json_option, emit, exit_epilog
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
        help="convert a BROAD trial or a trace file into a sins-fw trace (.csv/.h5)",
        epilog=exit_epilog(None),
    )
    kinds = p.add_subparsers(dest="kind", metavar="KIND", required=True)
    b = kinds.add_parser(
        "broad",
        help="a BROAD trial (.hdf5) → physical trace with truth and movement mask",
        epilog=exit_epilog(None),
    )
    b.add_argument("file", type=Path, help="BROAD trial, e.g. 01_undisturbed_slow_rotation_A.hdf5")
    b.add_argument("--out", required=True, type=Path, help="output trace, .csv or .h5")
    add_json_option(b)
    b.set_defaults(func=run)
    t = kinds.add_parser(
        "trace",
        help="validate a physical or raw-register trace and write it as .csv or .h5",
        epilog=exit_epilog(None),
    )
    t.add_argument("file", type=Path, help="input trace, .csv or .h5")
    t.add_argument("--out", required=True, type=Path, help="output trace, .csv or .h5")
    t.add_argument("--allow-gaps", action="store_true", help="accept time steps longer than the gap limit")
    t.add_argument(
        "--max-gap-periods",
        type=float,
        default=DEFAULT_MAX_GAP_PERIODS,
        help=f"gap limit in nominal sample periods (default {DEFAULT_MAX_GAP_PERIODS})",
    )
    add_json_option(t)
    t.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    check_output_path(args.out)
    check_output_folder(args.out, "--out")
    check_distinct({"FILE": args.file}, {"--out": args.out})
    if args.kind == "broad":
        # Read, converted and written a chunk at a time, as `import trace` (issue 24, item 11).
        written = save_chunks(args.out, iter_broad(args.file, IMPORT_CHUNK_ROWS))
        kind_name, rows, metadata = PhysicalTrace.__name__, written.rows, written.metadata
    else:
        # Read and written a chunk at a time: memory is bounded by the chunk (issue 24, item 11).
        kind = RawRegisterTrace if read_metadata(args.file).get("format") == RAW_FORMAT else PhysicalTrace
        chunks = kind.iter_chunks(
            args.file, IMPORT_CHUNK_ROWS, allow_gaps=args.allow_gaps, max_gap_periods=args.max_gap_periods
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
