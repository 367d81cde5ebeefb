"""Options and output shared by the subcommands."""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import sys
from collections import Counter
from collections.abc import Callable, Iterable, Iterator, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from sins_fw.errors import CheckFailed, InputError, ProfileError
from sins_fw.montecarlo import default_workers, make_engine
from sins_fw.profile import Profile, load_profile, resolve_profile_path
from sins_fw.run_output import FirmwareRunFile, recorded_profile
from sins_fw.traces import ReadOptions

if TYPE_CHECKING:
    from sins_fw.synth import Param

#: What exit status 1 means for a command that emulates a run (`run`, `replay`, `report`, `demo`).
EVENTS_CHECK = (
    "when the run logged any event of severity `error` (a missed deadline, a broken SPI rule, a "
    "non-finite state, ...)"
)


def exit_epilog(check: str | None) -> str:
    """The exit-status paragraph of a command's --help (the policy of the README, 'Exit codes'):
    ``check`` says when the command exits 1, None when it has no check."""
    one = (
        f"1 {check}: the output files are still written and the summary still printed"
        if check
        else "1 is not used (this command checks nothing)"
    )
    return (
        f"Exit status: 0 success; {one}; 2 bad input or usage (one message naming the file, line, "
        "key or register); 3 an internal error; 130 interrupted (Ctrl-C); 143 terminated (SIGTERM)."
    )


def check_events(events: Iterable[Mapping[str, Any]], what: str = "the run") -> None:
    """Raise CheckFailed (exit 1) when any event has severity ``error``, whatever its kind."""
    errors = [e for e in events if e.get("severity") == "error"]
    check_error_counts(Counter(str(e["kind"]) for e in errors), errors[0] if errors else None, what)


def check_error_counts(
    counts: Mapping[str, int], first: Mapping[str, Any] | None, what: str = "the run"
) -> None:
    """:func:`check_events` from the error events counted per kind (in the order each kind first
    occurred) and the first of them, as a streamed run keeps them."""
    total = sum(counts.values())
    if total and first is not None:
        kinds = ", ".join(f"{k} ×{n}" for k, n in counts.items())
        raise CheckFailed(
            f"{what} logged {total} error event{'s' if total > 1 else ''} ({kinds}); the "
            f"first at {float(first['t_s']):.6g} s: {first['message']}"
        )


# The naming scheme of every subcommand's options (docs/cli.md; tests/test_cli_scheme.py walks every
# parser and holds it to this):
#   --out FILE      the file a command writes (trace, table, run output, recording, report page)
#   --plot FILE.png a picture drawn beside the command's result (budget, montecarlo, sweep)
#   --out-dir DIR   a folder a command writes into;  --WHAT-out FILE  a second output file
#   a number with a unit ends in the unit: --duration-s, --rate-hz, --until-s, --max-gap-periods
#   --json, --debug, --profile, --set on every command that has the idea
#: Unit suffixes of number-valued options.
UNIT_SUFFIXES = (
    "-s",
    "-us",
    "-hz",
    "-deg",
    "-dps",
    "-dps2",
    "-m",
    "-mps",
    "-periods",
    "-gauss",
    "-c",
    "-c-per-min",
    "-lever-arms",
)

#: Old spellings already warned about by this process (one line each).
_warned: set[str] = set()


def deprecated(old: str, new: str) -> None:
    """Say once, on stderr (never on --json's stdout), that ``old`` is the old spelling of ``new``."""
    if old not in _warned:
        _warned.add(old)
        print(
            f"sins-fw: warning: {old} is deprecated, use {new} (the old spelling goes in the next release)",
            file=sys.stderr,
        )


class _Formerly(argparse.Action):
    """An old spelling of an option: warns (:func:`deprecated`), then does what the option does."""

    def __init__(self, option_strings: list[str], dest: str, target: argparse.Action, **kwargs: Any) -> None:
        super().__init__(option_strings, dest, **kwargs)
        self.target = target

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: Any,
        option_string: Any = None,
    ) -> None:
        deprecated(str(option_string), self.target.option_strings[0])
        self.target(parser, namespace, values, option_string)


def add_option(p: Any, name: str, *, formerly: str | None = None, **kwargs: Any) -> argparse.Action:
    """``p.add_argument(name, **kwargs)``, with ``formerly`` an old spelling that keeps working for one
    release (hidden from --help, named in the option's help, one deprecation line on stderr)."""
    if formerly is None:
        return p.add_argument(name, **kwargs)
    # A required option and its old spelling: one of the two is required.
    where = p.add_mutually_exclusive_group(required=True) if kwargs.pop("required", False) else p
    kwargs["help"] = f"{kwargs.get('help', '')} (formerly {formerly})".lstrip()
    new = where.add_argument(name, **kwargs)
    where.add_argument(
        formerly,
        action=_Formerly,
        target=new,
        dest=new.dest,
        nargs=new.nargs,
        type=new.type,
        choices=new.choices,
        metavar=new.metavar,
        default=argparse.SUPPRESS,
        help=argparse.SUPPRESS,
    )
    return new


def add_out_option(p: Any, help: str, **kwargs: Any) -> argparse.Action:
    """`--out FILE`: the file the command writes (``kwargs`` as for :func:`add_option`)."""
    return add_option(p, "--out", **{"type": Path, "metavar": "FILE", **kwargs, "help": help})


def add_plot_option(p: Any, help: str, **kwargs: Any) -> argparse.Action:
    """`--plot FILE.png`: a picture drawn beside the command's result."""
    return add_option(p, "--plot", **{"type": Path, "metavar": "FILE.png", **kwargs, "help": help})


def param_type(param: Param) -> Callable[[str], Any]:
    """An argparse ``type`` parsing a value as ``param`` does (:meth:`sins_fw.synth.Param.parse`): a
    bad value's message says what was expected; its name is the kind (``float``, ``floats``, ...)."""

    def parse(text: str) -> Any:
        try:
            return param.parse(text)
        except ValueError as e:
            raise argparse.ArgumentTypeError(str(e)) from None

    parse.__name__ = param.kind
    return parse


def add_runs_options(
    p: Any, runs: str, first_seed: str, *, default_first_seed: int = 1, **kwargs: Any
) -> None:
    """`--runs N` and `--first-seed S` (seeds S … S + N − 1): ``runs`` and ``first_seed`` say what a
    run and its seed are; ``kwargs`` go to `--first-seed` (:func:`add_option`: ``formerly``)."""
    p.add_argument("--runs", type=int, default=20, help=f"{runs} (default 20)")
    add_option(
        p,
        "--first-seed",
        type=int,
        default=default_first_seed,
        help=f"{first_seed} (default {default_first_seed})",
        **kwargs,
    )


def check_png(path: str | Path | None, option: str) -> None:
    """Refuse, before anything runs, a picture's file name that does not end in .png or is a folder."""
    if path is not None and (Path(path).suffix.lower() != ".png" or Path(path).is_dir()):
        raise InputError(f"{option} {path}: expected a file name ending in .png")


def add_debug_option(p: argparse.ArgumentParser, *, top: bool = False) -> None:
    """`--debug`, before or after the subcommand (a subcommand's copy leaves an earlier one alone)."""
    p.add_argument(
        "--debug",
        action="store_true",
        default=False if top else argparse.SUPPRESS,
        help="show a traceback on errors",
    )


def walk_parsers(
    p: argparse.ArgumentParser, name: str = "sins-fw"
) -> Iterator[tuple[str, argparse.ArgumentParser]]:
    """``p`` and every subcommand's parser below it, with the command line that reaches it."""
    yield name, p
    for action in p._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub_name, sub in action.choices.items():
                yield from walk_parsers(sub, f"{name} {sub_name}")


def add_profile_options(p: argparse.ArgumentParser) -> None:
    """`--profile P` and repeatable `--set key=value`."""
    p.add_argument("--profile", default="reference", help="profile name or path (default: reference)")
    p.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override one profile field for this run (repeatable), e.g. --set spi.spibrr=9",
    )


def add_read_options(p: argparse.ArgumentParser) -> None:
    """--units and --columns: read a trace file in other units or under other column names."""
    p.add_argument(
        "--units",
        metavar="Q=UNIT,...",
        help="the unit of each quantity's columns, whatever their names say: t=s|ms|us|ns, "
        "gyro=dps|rad/s, accel=g|m/s2, mag=gauss|mgauss|uT|nT, baro=mbar|hPa|Pa "
        "(docs/traces.md, 'Reading other files')",
    )
    p.add_argument(
        "--columns",
        metavar="COLUMN=NAME,...",
        help="read the file's column NAME as the trace's COLUMN, with or without its unit (e.g. "
        "t_ms=time,gyro_x=wx with --units gyro=rad/s); the file's columns that are no trace column are "
        "then left out",
    )


def read_options(args: argparse.Namespace) -> ReadOptions | None:
    """The --units / --columns of a command, None when neither is given."""
    read = ReadOptions(units=getattr(args, "units", None), columns=getattr(args, "columns", None))
    return read if read else None


def add_trace_or_run_argument(p: argparse.ArgumentParser) -> None:
    """The positional TRACE_OR_RUN of `replay` and `report`: a trace, or a run output replayed and checked."""
    p.add_argument(
        "trace",
        type=Path,
        metavar="TRACE_OR_RUN",
        help="physical trace (.h5 or .csv), or a `sins-fw run --out` file: re-emulated from its recorded "
        "trace and profile and checked bit for bit against it (exit 1 on a difference); a C firmware's "
        "(`run --firmware --out`) is shown as recorded, not re-emulated",
    )


def add_json_option(p: argparse.ArgumentParser) -> None:
    """`--json`: print one JSON object on stdout and nothing else."""
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout (for scripts and CI)")


def profile_from_args(args: argparse.Namespace) -> Profile:
    return load_profile(args.profile, args.overrides)


def profile_file(args: argparse.Namespace) -> Path | None:
    """The profile file the command reads (an input no output may overwrite); None when the
    profile does not resolve (loading it reports why)."""
    try:
        return resolve_profile_path(args.profile)
    except ProfileError:
        return None


def _jsonable(x: Any) -> Any:
    if isinstance(x, float) and not math.isfinite(x):
        return None
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_jsonable(v) for v in x]
    if hasattr(x, "tolist"):
        return _jsonable(x.tolist())
    return x


#: How errors name the standard output (a report printed to a full disk).
STDOUT = "standard output"

#: Whether this process has printed a command's report (so an error after it adds no second object).
_emitted = False


def emit(args: argparse.Namespace, report: dict[str, Any], text: str) -> None:
    """Print the report as JSON (with --json) or as human-readable text."""
    global _emitted
    _emitted = True
    try:
        if getattr(args, "json", False):
            print(json.dumps(_jsonable(report), indent=None, sort_keys=False, allow_nan=False))
        else:
            print(text)
    except BrokenPipeError:
        raise
    except OSError as e:  # a full disk behind `> FILE`: the error names where the report went
        raise OSError(e.errno, e.strerror, STDOUT) from None


def emit_error(args: argparse.Namespace | None, kind: str, code: int, message: str) -> None:
    """With --json and nothing printed yet, the error as one JSON object on stdout (the message also
    goes to stderr as always): ``{"error": {"kind", "exit", "message"}}``."""
    if _emitted or not getattr(args, "json", False):
        return
    print(json.dumps({"error": {"kind": kind, "exit": code, "message": message}}))


def open_firmware_run(path: Path, what: str) -> tuple[FirmwareRunFile, Profile, Any, str | None]:
    """A C firmware's run output as `report RUN` and `replay RUN` show it (as recorded, nothing
    re-emulated): the file, the profile it was run on, and the trace of its truth or, when that is
    not found, why (said on stderr: "... : ``what`` without the truth")."""
    run_file = FirmwareRunFile(path)
    profile = recorded_profile(path, run_file.metadata)
    trace, note = run_file.truth() if run_file.has_attitude else (None, None)
    if note is not None:
        print(f"{note}: {what} without the truth", file=sys.stderr)
    return run_file, profile, trace, note


def firmware_run_report(
    args: argparse.Namespace,
    run_file: FirmwareRunFile,
    profile: Profile,
    rows: int,
    truth: bool,
    note: str | None,
) -> dict[str, Any]:
    """The JSON report of `report RUN` and `replay RUN` on a C firmware's run output (the command
    adds where it wrote)."""
    m = run_file.metadata
    return {
        "trace": str(args.trace),
        "firmware": m.get("firmware"),
        "float_mode": m.get("float_mode"),
        "profile": profile.source,
        "overrides": list(profile.overrides),
        "rows": rows,
        "cycles": rows,  # as a model run's report names them: one row per ISR
        "globals": run_file.columns,
        "attitude": run_file.has_attitude,
        "truth": truth,
        "trace_found": None if run_file.trace_path is None else str(run_file.trace_path),
        "trace_missing": note,
        "re_emulated": False,
    }


def add_engine_options(p: argparse.ArgumentParser) -> None:
    """Where the runs execute: `--engine local|dask`, `--workers`, `--scheduler`, `--local-workers`,
    `--batch`."""
    g = p.add_argument_group("engine (where the runs execute; the results are the same bits on any)")
    g.add_argument(
        "--engine",
        choices=("local", "dask"),
        default="local",
        help="local: processes on this machine (default); dask: a Dask distributed cluster "
        '(needs pip install "sins-fw[dask]")',
    )
    g.add_argument(
        "--workers",
        type=int,
        default=None,
        metavar="N",
        help=f"local engine: processes (default: the cores, at most 8; here {default_workers()})",
    )
    g.add_argument(
        "--scheduler",
        default=None,
        metavar="tcp://HOST:PORT",
        help="dask engine: an existing cluster's scheduler",
    )
    g.add_argument(
        "--local-workers",
        type=int,
        default=None,
        metavar="N",
        help="dask engine: start a cluster of N worker processes on this machine (bound to 127.0.0.1)",
    )
    g.add_argument(
        "--batch",
        type=int,
        default=None,
        metavar="N",
        help="dask engine: runs per task (default: the runs ÷ (4 × the cluster's worker threads), "
        "between 1 and 32; the results are the same whatever N)",
    )


def engine_from_args(args: argparse.Namespace) -> Any:
    """The engine the options ask for (a context manager; closing it stops a cluster it started)."""
    if args.engine == "dask" and args.workers is not None:
        raise InputError(
            "--workers is the local engine's; with --engine dask the cluster's workers run the jobs"
        )
    return make_engine(
        args.engine,
        workers=args.workers,
        scheduler=args.scheduler,
        local_workers=args.local_workers,
        batch=args.batch,
    )


@contextlib.contextmanager
def run_progress(total: int, show: bool) -> Iterator[Callable[[int, int, int], None]]:
    """A progress bar on stderr (when ``show``) with completed and failed counts and an ETA; yields
    the callback the Monte Carlo collector calls. An interruption says how far the runs got."""
    from tqdm import tqdm  # as in sins_fw.progress: loaded only by a command that counts its runs

    bar = tqdm(total=total, disable=not show, unit="run", file=sys.stderr, dynamic_ncols=True)
    counts = [0, 0]

    def update(done: int, failed: int, _total: int) -> None:
        counts[:] = [done, failed]
        bar.set_postfix(completed=done, failed=failed, refresh=False)
        bar.update(done + failed - bar.n)

    try:
        yield update
    except KeyboardInterrupt as e:
        raise type(e)(
            f"{counts[0]} of {total} runs completed ({counts[1]} failed); the others were cancelled "
            "and nothing was written"
        ) from None
    finally:
        bar.close()
