"""The ``sins-fw`` console script: fit the process to a memory cap, then start the command line.

Under a limit on the address space (``ulimit -v``, RLIMIT_AS: CI containers, batch schedulers) or on
the data segment (``ulimit -d``, RLIMIT_DATA), what the libraries sins-fw imports reserve at start
counts against it as if it were used: Rerun's allocator (mimalloc) reserves a 1 GiB arena,
pyarrow's jemalloc starts a background purging thread, glibc gives each thread that allocates a
64 MB heap, OpenBLAS starts a thread per core with its buffers. Under a cap of 1.5 GB that was
enough for ``sins-fw --version`` to end in a segfault (pyarrow's "<jemalloc>: arena 0 background
thread creation failed") or in a traceback (a library that no longer fits: "failed to map segment
from shared object"). :func:`fit_to_memory_cap` asks each for less, before any of them is loaded,
and only when there is a cap (without one, reserving costs nothing). What still does not fit is the
one line of :func:`out_of_memory_message` and exit 2 (docs/cli.md, "Memory limits").

Rust code cannot report a failed allocation: it prints ``memory allocation of N bytes failed`` and
aborts the process (SIGABRT), which no Python code in that process survives to report. So under a
cap the command runs in a child process and this one, holding nothing but the interpreter, waits
for it (:func:`_supervise`): a child ended by SIGABRT, SIGSEGV or SIGBUS is the out-of-memory line
and exit 2, and the temporary files it was writing (:data:`sins_fw.atomic.LEDGER_ENV`) are removed,
so that nothing half-written is left.

This module imports nothing heavy (sins_fw.atomic and sins_fw.memory need the standard library
only): it must run before numpy, the extension and Rerun are loaded.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import signal
import sys
import tempfile

from sins_fw import memory
from sins_fw.atomic import LEDGER_ENV
from sins_fw.memory import STARTUP_FLOOR_MIB, is_out_of_memory, memory_cap, out_of_memory_message

#: glibc's mallopt parameter M_ARENA_MAX (malloc.h).
_M_ARENA_MAX = -8
#: What sins-fw asks of the libraries under a cap: environment variables they read when they load.
CAPPED_ENVIRONMENT = {
    # Rerun's mimalloc: reserve arenas of 32 MiB as needed instead of one of 1 GiB up front.
    "MIMALLOC_ARENA_RESERVE": "32MiB",
    # pyarrow's allocations through the system allocator: no jemalloc, no background thread.
    "ARROW_DEFAULT_MEMORY_POOL": "system",
    # pyarrow's bundled jemalloc still starts (and under a cap fails to start, printing a line) its
    # background purging thread unless told not to: its settings variable (prefix je_arrow_).
    "JE_ARROW_MALLOC_CONF": "background_thread:false",
    # numpy's OpenBLAS: one thread (sins-fw's reductions are numpy's own sums: docs/traces.md).
    "OPENBLAS_NUM_THREADS": "1",
}
#: glibc malloc arenas under a cap (each a 64 MB reservation; the default is 8 per core).
CAPPED_MALLOC_ARENAS = 2


def fit_to_memory_cap() -> None:
    """Under a memory cap, ask the libraries for less at start (module docstring). A variable the
    user has set wins."""
    if memory_cap() is None:
        return
    for key, value in CAPPED_ENVIRONMENT.items():
        os.environ.setdefault(key, value)
    if sys.platform.startswith("linux") and "MALLOC_ARENA_MAX" not in os.environ:
        try:
            libc = ctypes.CDLL(None)
            mallopt = libc.mallopt
        except (OSError, AttributeError):  # not glibc (musl has no per-thread arenas)
            return
        mallopt(_M_ARENA_MAX, CAPPED_MALLOC_ARENAS)


def entry() -> None:
    """Console-script entry point (``sins-fw``)."""
    cap = memory_cap()
    if cap is not None and cap < STARTUP_FLOOR_MIB << 20:
        print(f"sins-fw: error: {out_of_memory_message('sins-fw to start')}", file=sys.stderr)
        _exit_now(2)
    fit_to_memory_cap()
    if cap is not None and LEDGER_ENV not in os.environ:
        _supervise(sys.argv[1:])  # returns in the child only
    try:
        from sins_fw.cli import main  # after fit_to_memory_cap: the libraries load under the fitted settings

        code = main()
    except BaseException as e:  # what the command's own handling could not reach: imports, arguments
        if not is_out_of_memory(e):
            raise
        print(f"sins-fw: error: {out_of_memory_message('sins-fw')}", file=sys.stderr)
        memory.ran_out = True
        code = 2
    if memory.ran_out:
        _exit_now(code)
    sys.exit(code)


def _exit_now(code: int) -> None:
    """Exit without the interpreter's finalisation: with memory exhausted, the threads and
    allocators of half-loaded libraries may not survive being torn down (a segfault after the
    message)."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(OSError, ValueError):
            stream.flush()
    os._exit(code)


#: Signals that end a process whose memory ran out in code that cannot report it: Rust's abort on a
#: failed allocation (SIGABRT), and a library that used the null pointer a failed allocation gave
#: it (SIGSEGV, SIGBUS).
_ALLOCATION_FAILURE_SIGNALS = {signal.SIGABRT, signal.SIGSEGV, signal.SIGBUS}
#: Signals the supervisor passes on to the command when another process sent them to it (`kill`,
#: a batch scheduler, `timeout`). The terminal's Ctrl-C and hang-up reach the whole foreground
#: process group, the command included, and are not passed on a second time.
_FORWARDED_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP, signal.SIGQUIT)


def _supervise(argv: list[str]) -> None:
    """Run the command in a child process and end this one with the child's exit code (module
    docstring). Returns in the child only, with the signal mask it had and the ledger's descriptor
    in :data:`LEDGER_ENV`."""
    waited = {*_FORWARDED_SIGNALS, signal.SIGCHLD}
    # Blocked before the fork, so that a signal that comes before the loop below waits for it.
    old_mask = signal.pthread_sigmask(signal.SIG_BLOCK, waited)
    ledger, name = tempfile.mkstemp(prefix="sins-fw-ledger-")
    os.unlink(name)  # no name: the file goes with the last descriptor, the parent's or the child's
    try:
        pid = os.fork()
    except OSError:  # no memory even for a copy of this small process: run unsupervised
        os.close(ledger)
        signal.pthread_sigmask(signal.SIG_SETMASK, old_mask)
        return
    if pid == 0:
        st = os.fstat(ledger)
        # With the file's identity: a program this one starts (a compiler, a worker interpreter)
        # inherits the variable but not the descriptor, whose number may then be another file's.
        os.environ[LEDGER_ENV] = f"{ledger}:{st.st_dev}:{st.st_ino}"
        signal.pthread_sigmask(signal.SIG_SETMASK, old_mask)
        return
    status = 0
    while True:
        info = signal.sigwaitinfo(waited)
        if info.si_signo == signal.SIGCHLD:
            done, status = os.waitpid(pid, os.WNOHANG)
            if done == pid:
                break
        elif info.si_code <= 0:  # sent by a process (SI_USER, SI_QUEUE, SI_TKILL), not the terminal
            os.kill(pid, info.si_signo)
    # Whatever the command left in the ledger is an orphan now, however it ended: a signal it could
    # not handle, or one it handled but that came between the temporary file's creation and the
    # code that would have removed it (sins_fw.atomic.atomic_path).
    _remove_temporaries(_read_all(ledger))
    if os.WIFEXITED(status):
        _exit_now(os.WEXITSTATUS(status))
    signum = os.WTERMSIG(status)
    if signum in _ALLOCATION_FAILURE_SIGNALS:
        command = next((a for a in argv if not a.startswith("-")), None)
        what = f"`sins-fw {command}`" if command else "sins-fw"
        ended = f"it ended with {signal.Signals(signum).name}"
        print(f"sins-fw: error: {out_of_memory_message(what)}; {ended}", file=sys.stderr)
        _exit_now(2)
    _exit_now(128 + signum)


def _read_all(fd: int) -> bytes:
    """The whole of the file open as ``fd``."""
    os.lseek(fd, 0, os.SEEK_SET)
    parts = []
    while block := os.read(fd, 1 << 16):
        parts.append(block)
    return b"".join(parts)


def _remove_temporaries(ledger: bytes) -> None:
    """Remove the temporary files a command that was killed had created and not yet renamed or
    removed (``\\0``-separated paths; those already gone are skipped)."""
    for path in ledger.split(b"\0"):
        if path:
            with contextlib.suppress(OSError):
                os.unlink(path)
