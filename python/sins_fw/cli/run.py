"""`sins-fw run TRACE`: emulate the board on a trace and summarise what the firmware did. A
raw-register trace is replayed: the firmware reads the recorded words instead of the device model."""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import h5py

from sins_fw.cli.common import add_json_option, add_profile_options, emit, profile_from_args
from sins_fw.errors import InputError, TraceError
from sins_fw.harness import emulate
from sins_fw.report import ALIGNMENTS, render, summarise
from sins_fw.run_output import save_run
from sins_fw.traces import check_output_path, is_raw_register_trace


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "run",
        help="emulate the board on a trace: events, attitude error against the truth, time budget",
        description="Emulate the profile's board and firmware on a physical trace (.csv or .h5) and "
        "summarise: steps, virtual time, events by kind (first occurrence of each), attitude error "
        "against the trace's truth (alignment stated), ISR budget. --out writes the per-step output "
        "(docs/traces.md, 'Run output'). A raw-register trace is replayed: each burst read gets the "
        "next recorded burst's words, bypassing the device model.",
    )
    p.add_argument("trace", type=Path, help="physical or raw-register trace, .csv or .h5")
    add_profile_options(p)
    p.add_argument("--out", type=Path, help="write the per-step output here (.csv or .h5)")
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
    for out in (args.out, args.raw_out):
        if out is not None:
            check_output_path(out)
    if args.until_s is not None and not (math.isfinite(args.until_s) and args.until_s > 0):
        raise InputError(f"--until-s {args.until_s}: expected a number of seconds > 0")
    if not args.trace.is_file():
        raise TraceError(f"{args.trace}: no such trace file")
    profile = profile_from_args(args)
    with _progress(args) as on_chunk:
        result = emulate(args.trace, profile, on_chunk=on_chunk, until_s=args.until_s)
    summary = summarise(result, trace=str(args.trace), align=args.align)
    summary["replayed"] = is_raw_register_trace(args.trace)
    if args.out is not None:
        save_run(result, args.out, {"trace": str(args.trace)})
        summary["out"] = str(args.out)
    if args.raw_out is not None:
        raw = result.raw_register_trace(_raw_metadata(args))
        raw.save(args.raw_out, allow_gaps=True)
        summary["raw_out"] = str(args.raw_out)
    text = render(summary)
    if summary["replayed"]:
        text = "replayed       raw-register trace: recorded words, no device model\n" + text
    if args.out is not None:
        text += f"\nwrote          {args.out} ({result.cycles} steps)"
    if args.raw_out is not None:
        text += f"\nwrote          {args.raw_out} ({len(result.read_words)} bursts)"
    emit(args, summary, text)
    return 0


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
