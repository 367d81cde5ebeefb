"""The `sins-fw` command line. Each subcommand is a module of this package with `register(sub)`.

Exit codes: 0 success, 1 a check the command performs failed (the outputs are still written and the
summary printed: an event of severity error in a run, a rule broken, a parity threshold exceeded;
README "Exit codes", each command's --help), 2 bad input or usage, 3 a bug in sins-fw
(reported in one line; ``--debug`` shows the traceback), 130 interrupted (Ctrl-C, SIGINT), 143
terminated (SIGTERM). User errors print one message on stderr, never a traceback (``--debug`` shows
one). An interrupted command leaves every output file either as it was or complete (sins_fw.atomic)
and says how far it got.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import signal
import sys
import traceback
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import TextIO

from sins_fw import __version__, memory
from sins_fw.cli import (
    bench,
    board,
    broad_eval,
    budget,
    build_firmware,
    calibrate,
    demo,
    files,
    importer,
    montecarlo,
    parity,
    presets,
    replay,
    report,
    run,
    spin_table,
    stop,
    sweep,
    synth,
)
from sins_fw.cli.common import STDOUT, add_debug_option, emit_error, walk_parsers
from sins_fw.errors import CheckFailed, InputError, InternalError, SinsError, Terminated, TraceWarning

#: The subcommands, in the order `--help` lists them.
COMMANDS = (
    demo,
    run,
    board,
    budget,
    parity,
    replay,
    report,
    synth,
    importer,
    presets,
    montecarlo,
    sweep,
    spin_table,
    bench,
    broad_eval,
    build_firmware,
    calibrate,
)

EXIT_OK, EXIT_CHECK_FAILED, EXIT_USAGE, EXIT_BUG = 0, 1, 2, 3
#: 128 + the signal number, as a shell reports a process its signal ended.
EXIT_INTERRUPTED, EXIT_TERMINATED = 128 + signal.SIGINT, 128 + signal.SIGTERM


class _Parser(argparse.ArgumentParser):
    """argparse that reports usage errors with our exit code and no traceback."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.print_usage(sys.stderr)
        if "--json" in sys.argv[1:]:
            emit_error(argparse.Namespace(json=True), "usage", EXIT_USAGE, f"{self.prog}: {message}")
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="sins-fw",
        description="Firmware-in-the-loop emulator of a TMS320F28335 + ADIS16407 strapdown attitude board.",
    )
    parser.add_argument("--version", action="version", version=f"sins-fw {__version__}")
    add_debug_option(parser, top=True)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for command in COMMANDS:
        command.register(sub)
    for name, p in list(walk_parsers(parser))[1:]:
        add_debug_option(p)  # `sins-fw run --debug ...` as well as `sins-fw --debug run ...`
        # Which command ran (cli/files.py: the files it reads and writes); the leaf's default wins.
        p.set_defaults(command_line=name.removeprefix("sins-fw "))
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of `sins-fw`; returns the exit code."""
    # A file name that is not UTF-8 (Python holds its bytes as lone surrogates) is printed as the
    # bytes it is, as `ls` does, instead of failing the report after the work is done.
    with contextlib.suppress(AttributeError, ValueError):
        sys.stdout.reconfigure(errors="surrogateescape")  # type: ignore[union-attr]
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return EXIT_USAGE
    # SIGINT and SIGTERM unwind (temporary files removed, progress reported) instead of killing the
    # process where it stands. A trace that reads but looks wrong is one line on stderr.
    with stop.handling(), warnings.catch_warnings():
        warnings.showwarning = _show_warning
        return _run(args)


def _show_warning(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    file: TextIO | None = None,
    line: str | None = None,
) -> None:
    """Every warning as one line on stderr: sins-fw's own as `sins-fw: warning: ...`; a library's
    (numpy's RuntimeWarning, ...) with its kind and where it was raised, never with a source line."""
    if issubclass(category, TraceWarning):
        print(f"sins-fw: warning: {message}", file=sys.stderr)
    else:
        where = f"{Path(filename).name}:{lineno}"
        text = " ".join(str(message).split())
        print(f"sins-fw: warning: {category.__name__} ({where}): {text}", file=sys.stderr)


def _run(args: argparse.Namespace) -> int:
    """The command of `args`, its errors turned into a line and an exit code."""
    try:
        memory.require_memory(args.command)
        # Before any work: no output may be one of the command's inputs (cli/files.py).
        files.check(args.command_line, args)
        code = int(args.func(args))
        # A signal whose exception was dropped where it landed still ends the command as interrupted.
        stop.check_stop()
        _flush_stdout()
        return code
    except CheckFailed as e:
        return _fail(args, e, EXIT_CHECK_FAILED)
    except InputError as e:
        return _fail(args, e, EXIT_USAGE)
    except BrokenPipeError:
        # The reader went away (`sins-fw ... | head`): not an error of ours; silence the final flush.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_OK
    except KeyboardInterrupt as e:
        # Terminated is a KeyboardInterrupt; the message (if any) says how far the command got.
        what = "terminated" if isinstance(e, Terminated) else "interrupted"
        detail = f": {e}" if str(e) else ""
        code = EXIT_TERMINATED if isinstance(e, Terminated) else EXIT_INTERRUPTED
        emit_error(args, what, code, f"{what}{detail}")
        print(f"sins-fw: {what}{detail}", file=sys.stderr)
        return code
    except InternalError as e:
        return _fail(args, e, EXIT_BUG)
    except SinsError as e:
        return _fail(args, e, EXIT_USAGE)
    except OSError as e:
        if memory.is_out_of_memory(e):
            return _out_of_memory(args, e)
        # The file system said no (permissions, a full disk, a missing folder): the user's to fix.
        # A write that names no file was a print to standard output (a full disk behind `>`).
        name = e.filename or (STDOUT if _stdout_failing() else None)
        where = f"{name}: " if name else ""
        return _fail(args, InputError(f"{where}{e.strerror or e}"), EXIT_USAGE, e)
    except Exception as e:
        if memory.is_out_of_memory(e):  # MemoryError, numpy's _ArrayMemoryError, a library or thread
            return _out_of_memory(args, e)
        # A bug of ours: one line naming it (the traceback with --debug), never a raw traceback.
        return _fail(
            args, InternalError(f"internal error (please report; --debug shows where): {e!r}"), EXIT_BUG, e
        )
    except BaseException as e:
        # A Rust panic surfaces as pyo3's PanicException (a BaseException): report it as a bug.
        if type(e).__name__ == "PanicException":
            return _fail(args, InternalError(str(e)), EXIT_BUG)
        raise


def _flush_stdout() -> None:
    """Write out what the command printed: a failure (a full disk behind a redirection) is the
    command's error naming standard output, and what is left unwritten is dropped (not retried, with
    a second error, when the interpreter exits)."""
    try:
        sys.stdout.flush()
    except BrokenPipeError:
        raise
    except OSError as e:
        _drop_stdout()
        raise OSError(e.errno, e.strerror, STDOUT) from None


def _stdout_failing() -> bool:
    """Whether writing standard output fails (then what it holds is dropped: see _flush_stdout)."""
    try:
        sys.stdout.flush()
    except (OSError, ValueError):
        _drop_stdout()
        return True
    return False


def _drop_stdout() -> None:
    with contextlib.suppress(OSError, ValueError, io.UnsupportedOperation):
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())


def _out_of_memory(args: argparse.Namespace, e: BaseException) -> int:
    """The memory cap or the machine's memory ran out: the user's to fix, one line, exit 2."""
    memory.ran_out = True
    return _fail(args, InputError(memory.out_of_memory_message(f"`sins-fw {args.command}`")), EXIT_USAGE, e)


def _fail(args: argparse.Namespace, e: BaseException, code: int, cause: BaseException | None = None) -> int:
    if getattr(args, "debug", False):
        traceback.print_exception(cause or e)
    what = "check failed" if code == EXIT_CHECK_FAILED else "error"
    kind = {EXIT_CHECK_FAILED: "check_failed", EXIT_USAGE: "input", EXIT_BUG: "internal"}[code]
    emit_error(args, kind, code, str(e))
    print(f"sins-fw: {what}: {e}", file=sys.stderr)
    return code
