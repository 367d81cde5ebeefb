"""What a command may use under a memory cap (``ulimit -v`` / ``ulimit -d``): the cap in force, the
floors below which sins-fw and its commands are refused, whether a failure means that memory ran
out, and the one line that says so (docs/cli.md, "Memory limits"). Below both the launcher
(:mod:`sins_fw.launch`, which fits the process to the cap) and the command line that it starts.

This module imports the standard library and sins_fw.errors only: it is read before numpy, the
extension and Rerun.
"""

from __future__ import annotations

import errno
import resource

from sins_fw.errors import InputError

#: Messages of failures that mean "the cap was reached" (a library that could not be mapped, a
#: thread whose stack could not be).
_OUT_OF_MEMORY_TEXTS = (
    "failed to map segment",
    "cannot allocate memory",
    "can't start new thread",
    "failed to spawn background thread",
)


def memory_cap() -> int | None:
    """The smaller of the soft address-space and data-segment limits, in bytes; None without one."""
    caps = []
    for which in (resource.RLIMIT_AS, resource.RLIMIT_DATA):
        soft, _ = resource.getrlimit(which)
        if soft != resource.RLIM_INFINITY:
            caps.append(soft)
    return min(caps) if caps else None


def is_out_of_memory(e: BaseException) -> bool:
    """Whether ``e`` says that memory ran out: a MemoryError (numpy's ``_ArrayMemoryError``
    included), or a library, mapping or thread that could not be made for lack of memory."""
    if isinstance(e, MemoryError):
        return True
    if isinstance(e, OSError) and e.errno == errno.ENOMEM:
        return True
    if isinstance(e, (ImportError, OSError, RuntimeError)):
        text = str(e).lower()
        return any(t in text for t in _OUT_OF_MEMORY_TEXTS)
    return False


def out_of_memory_message(what: str, needed: str = "") -> str:
    """``not enough memory for WHAT: raise the limit or ...``, with the limit in force (and what is
    ``needed``, when known)."""
    cap = memory_cap()
    limit = (
        f" (the process's memory limit is {cap / 2**20:.0f} MiB: `ulimit -v` / `ulimit -d`)"
        if cap is not None
        else ""
    )
    return (
        f"not enough memory for {what}{limit}: raise the limit{' to ' + needed if needed else ''} "
        "or use a shorter trace or run "
        '(docs/cli.md, "Memory limits")'
    )


#: Below this cap the interpreter and numpy's start-up do not reliably get as far as Python code
#: that could report it (OpenBLAS ends the process with its own message and exit 1 under ≈ 110
#: MiB on the benchmark machine): refused before loading anything. sins-fw itself needs more
#: (docs/cli.md, "Memory limits").
STARTUP_FLOOR_MIB = 256
#: Commands whose Rust code (Rerun's writer threads) needs more than the start-up: under these caps
#: (MiB) an allocation there would fail, and Rust ends the process with SIGABRT (it cannot report
#: it as an error), so the command is refused up front. Measured with benchmarks/memory_cap.py:
#: `replay` aborted at 600 MiB and worked from 625 (docs/cli.md, "Memory limits").
COMMAND_FLOOR_MIB = {"replay": 700}
#: Set when a command ended for lack of memory (sins_fw.cli): the process then exits at once.
ran_out = False


def require_memory(command: str) -> None:
    """Refuse ``command`` (exit 2, through InputError) under a cap below its floor
    (:data:`COMMAND_FLOOR_MIB`), before any work."""
    cap, floor = memory_cap(), COMMAND_FLOOR_MIB.get(command)
    if cap is not None and floor is not None and cap < floor << 20:
        raise InputError(out_of_memory_message(f"`sins-fw {command}`", f"at least {floor} MiB"))
