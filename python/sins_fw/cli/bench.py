"""`sins-fw bench`: the benchmark suite (throughput, memory, scaling; see sins_fw.bench)."""

from __future__ import annotations

import argparse
import sys

from sins_fw import atomic
from sins_fw.bench import render, run_suite
from sins_fw.cli.common import add_json_option, add_out_option, emit, exit_epilog


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "bench",
        help="measure emulated cycles per second and memory against baselines",
        epilog=exit_epilog(None),
    )
    p.add_argument(
        "--quick", action="store_true", help="short inputs (seconds, rough figures; for the smoke test)"
    )
    add_out_option(p, "also write the report as Markdown to FILE", formerly="--output")
    add_json_option(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    quiet = args.json
    if args.out is not None:
        atomic.check_output_folder(args.out, "--out")  # before the suite's minutes of work
    report = run_suite(quick=args.quick, progress=None if quiet else lambda m: print(m, file=sys.stderr))
    text = render(report)
    if args.out is not None:
        atomic.write_text(args.out, text)
    emit(args, report, text)
    return 0
