"""The `sins-fw` command line. Each subcommand is a module of this package with `register(sub)`.

Exit codes: 0 success, 1 a check failed (parity, deadline), 2 bad input or usage, 130 interrupted.
User errors print one message on stderr, never a traceback (``--debug`` shows one).
"""

from __future__ import annotations

import argparse
import os
import sys
import traceback
from collections.abc import Sequence

from sins_fw import __version__
from sins_fw.cli import (
    bench,
    board,
    budget,
    demo,
    importer,
    montecarlo,
    parity,
    presets,
    replay,
    report,
    run,
    synth,
)
from sins_fw.errors import CheckFailed, InputError, InternalError, SinsError

#: The subcommands, in the order `--help` lists them.
COMMANDS = (demo, run, board, budget, parity, replay, report, synth, importer, presets, montecarlo, bench)

EXIT_OK, EXIT_CHECK_FAILED, EXIT_USAGE, EXIT_INTERRUPTED = 0, 1, 2, 130


class _Parser(argparse.ArgumentParser):
    """argparse that reports usage errors with our exit code and no traceback."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.print_usage(sys.stderr)
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="sins-fw",
        description="Firmware-in-the-loop emulator of a TMS320F28335 + ADIS16407 strapdown attitude board.",
    )
    parser.add_argument("--version", action="version", version=f"sins-fw {__version__}")
    parser.add_argument("--debug", action="store_true", help="show a traceback on errors")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for command in COMMANDS:
        command.register(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of `sins-fw`; returns the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return EXIT_USAGE
    try:
        return int(args.func(args))
    except CheckFailed as e:
        return _fail(args, e, EXIT_CHECK_FAILED)
    except InputError as e:
        return _fail(args, e, EXIT_USAGE)
    except BrokenPipeError:
        # The reader went away (`sins-fw ... | head`): not an error of ours; silence the final flush.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_OK
    except KeyboardInterrupt:
        print("sins-fw: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except (InternalError, SinsError) as e:
        return _fail(args, e, EXIT_USAGE if not isinstance(e, InternalError) else 3)
    except BaseException as e:
        # A Rust panic surfaces as pyo3's PanicException (a BaseException): report it as a bug.
        if type(e).__name__ == "PanicException":
            return _fail(args, InternalError(str(e)), 3)
        raise


def _fail(args: argparse.Namespace, e: BaseException, code: int) -> int:
    if getattr(args, "debug", False):
        traceback.print_exception(e)
    print(f"sins-fw: error: {e}", file=sys.stderr)
    return code


def entry() -> None:
    """Console-script entry point (`sins-fw`)."""
    sys.exit(main())
