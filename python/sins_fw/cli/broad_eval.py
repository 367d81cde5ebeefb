"""`sins-fw broad-eval`: the command line of :mod:`sins_fw.broad_eval` (the fusing firmware algorithms
on BROAD trials beside the dataset's published baselines)."""

from __future__ import annotations

import argparse
from pathlib import Path

from sins_fw import _core, broad_eval
from sins_fw.bench import machine
from sins_fw.cli.common import add_json_option, emit, exit_epilog


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "broad-eval",
        help="the DCM and the VQF-class firmware algorithms on BROAD trials beside the published baselines",
        epilog=exit_epilog(None),
    )
    p.add_argument(
        "sources", type=Path, nargs="+", help="folders of BROAD trials (*.hdf5) and/or trial files"
    )
    p.add_argument(
        "--algorithm",
        dest="algorithms",
        action="append",
        choices=broad_eval.ALGORITHMS,
        default=None,
        help="an algorithm to run (repeatable; default: all)",
    )
    p.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=None,
        help="profile key=value added after the shipped BROAD set (repeatable)",
    )
    p.add_argument(
        "--ahrs",
        action="store_true",
        help="also the `ahrs` package's Mahony and Madgwick (minutes: pure Python)",
    )
    p.add_argument(
        "--no-baselines", action="store_true", help="(kept for scripts) no `ahrs` filters: the default now"
    )
    p.add_argument("--board", action="store_true", help="also through the whole board (ADIS16407 model)")
    p.add_argument(
        "--clip-dps",
        type=float,
        default=None,
        metavar="DPS",
        help="also at algorithm level on the gyro held within ±DPS (the saturation alone; the ADIS16407's "
        "14-bit code clips at 409.55)",
    )
    p.add_argument(
        "--numeric",
        choices=tuple(_core.NUMERICS),
        default="f64",
        help="the firmware's numeric type (default f64)",
    )
    add_json_option(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    report = broad_eval.evaluate(
        list(args.sources),
        tuple(args.algorithms) if args.algorithms else broad_eval.ALGORITHMS,
        tuple(args.overrides or ()),
        ahrs=args.ahrs and not args.no_baselines,
        board=args.board,
        numeric=args.numeric,
        clip_dps=args.clip_dps,
    )
    report["machine"] = machine()  # the benchmarks' one (sins_fw.bench)
    emit(args, report, broad_eval.table(report))
    return 0
