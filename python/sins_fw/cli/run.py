"""`sins-fw run TRACE`: emulate the board on a trace and summarise what the firmware did."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import h5py

from sins_fw.cli.common import add_json_option, add_profile_options, emit, profile_from_args
from sins_fw.errors import TraceError
from sins_fw.harness import emulate
from sins_fw.report import ALIGNMENTS, render, summarise
from sins_fw.run_output import save_run
from sins_fw.traces import check_output_path


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "run",
        help="emulate the board on a trace: events, attitude error against the truth, time budget",
        description="Emulate the profile's board and firmware on a physical trace (.csv or .h5) and "
        "summarise: steps, virtual time, events by kind (first occurrence of each), attitude error "
        "against the trace's truth (alignment stated), ISR budget. --out writes the per-step output "
        "(docs/traces.md, 'Run output').",
    )
    p.add_argument("trace", type=Path, help="physical trace, .csv or .h5")
    add_profile_options(p)
    p.add_argument("--out", type=Path, help="write the per-step output here (.csv or .h5)")
    p.add_argument(
        "--align",
        choices=ALIGNMENTS,
        default="auto",
        help="frame alignment before comparing with the truth: initial (the truth at power-on, for "
        "firmware starting from Q = [1,0,0,0]), heading (about navigation z), none; auto picks initial "
        "for firmware.initial_attitude = zero, heading for level (default auto)",
    )
    add_json_option(p)
    p.set_defaults(func=run)


def _trace_span_s(path: Path) -> float | None:
    """The time span of an HDF5 trace without reading it (None for CSV or when unreadable: the
    emulation's own loading reports the problem)."""
    if path.suffix.lower() not in (".h5", ".hdf5"):
        return None
    try:
        with h5py.File(path, "r") as f:
            t = f["t_s"]
            return float(t[-1] - t[0]) if len(t) else None
    except (OSError, KeyError, ValueError):
        return None


@contextmanager
def _progress(args: argparse.Namespace) -> Iterator[Callable[[float], None] | None]:
    """A tqdm bar on stderr for interactive use (not with --json, not when stderr is redirected)."""
    if args.json or not sys.stderr.isatty():
        yield None
        return
    from tqdm import tqdm

    span = _trace_span_s(args.trace)
    with tqdm(total=span, unit="s", unit_scale=True, desc="emulating", file=sys.stderr, leave=False) as bar:
        start: list[float] = []

        def update(t: float) -> None:
            if not start:
                start.append(t)
            bar.update(t - start[0] - bar.n)

        yield update


def run(args: argparse.Namespace) -> int:
    if args.out is not None:
        check_output_path(args.out)
    if not args.trace.is_file():
        raise TraceError(f"{args.trace}: no such trace file")
    profile = profile_from_args(args)
    with _progress(args) as on_chunk:
        result = emulate(args.trace, profile, on_chunk=on_chunk)
    summary = summarise(result, trace=str(args.trace), align=args.align)
    if args.out is not None:
        save_run(result, args.out, {"trace": str(args.trace)})
        summary["out"] = str(args.out)
    text = render(summary)
    if args.out is not None:
        text += f"\nwrote          {args.out} ({result.cycles} steps)"
    emit(args, summary, text)
    return 0
