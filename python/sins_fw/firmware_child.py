"""The process a host-built firmware runs in (:func:`sins_fw.firmware_run.run_c_firmware`).

The user's firmware is C and C++ code of unknown quality: it may dereference a bad pointer, recurse
without end, call ``abort()`` or ``exit()``, crash in a static constructor, print on stdout or
install its own signal handlers. It therefore never runs in the emulator's own process: the harness
forks a child (:func:`start`) that loads the library (a fresh ``dlopen``: the globals at their
initial values in every run), runs ``main`` and streams back, whenever the runtime asks for more
input, the ISR rows, the events and the bus-log records taken since the last time, as whole numpy
arrays (one message per piece of input, never per sample). The parent owns the trace, the output
files, the summary and the signals: Ctrl-C and SIGTERM reach it (the child is in its own process
group and ignores SIGINT), and it kills the child (SIGKILL, which no firmware can catch). The child
dies with the parent (``PR_SET_PDEATHSIG``).

The child's standard output is its standard error (a firmware's ``printf`` cannot mix with ``--json``
on stdout); its standard input is ``/dev/null``. The runtime reports a fatal signal or an ``exit()``
on a pipe of its own (``SINS_FW_CRASH_FD``; firmware_c/runtime/sins_fw_runtime.cpp): the parent names
the signal and the firmware's file and line (:func:`sins_fw.firmware_run.describe_crash`).

Fork, not spawn: measured on the 2-core machine of benchmarks/c_firmware.md, a fork of the harness
costs a few milliseconds, a fresh interpreter importing numpy and the package a few hundred, which
is several times the whole run of a minute of trace.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import signal
import sys
import traceback
from dataclasses import dataclass
from multiprocessing.connection import Connection
from typing import Any

import numpy as np

from sins_fw import _core
from sins_fw.errors import InputError, ProfileError
from sins_fw.harness import PS

#: The C ABI's SinsBusRecord (rust/cabi/include/sins_fw.h), one bus-log record.
BUS_RECORD = np.dtype(
    [
        ("kind", np.uint8),
        ("cs_low", np.uint8),
        ("selected", np.uint8),
        ("bits", np.uint8),
        ("master_tx", np.uint16),
        ("master_rx", np.uint16),
        ("din", np.uint16),
        ("dout", np.uint16),
        ("t_ps", np.uint64),
        ("end_ps", np.uint64),
        ("first_edge_ps", np.uint64),
        ("last_edge_ps", np.uint64),
        ("sclk_period_ps", np.uint64),
        ("index", np.uint64),
    ],
    align=True,
)
#: C type names of a watched global and the runtime's codes for them.
TYPES = {"int16": 0, "uint16": 1, "int32": 2, "uint32": 3, "int64": 4, "uint64": 5, "float": 6, "double": 7}
_CTYPES: dict[str, Any] = {
    "int16": ctypes.c_int16,
    "uint16": ctypes.c_uint16,
    "int32": ctypes.c_int32,
    "uint32": ctypes.c_uint32,
    "int64": ctypes.c_int64,
    "uint64": ctypes.c_uint64,
    "float": ctypes.c_float,
    "double": ctypes.c_double,
}
#: The runtime's crash record (sins_fw_runtime.cpp, CrashRecord): 7 words and 48 return addresses.
CRASH_MAGIC = 0x53494E53465743
CRASH_FRAMES = 48
CRASH_RECORD = np.dtype(
    [
        ("magic", np.uint64),
        ("signal", np.int64),
        ("code", np.int64),
        ("fault_address", np.uint64),
        ("pc", np.uint64),
        ("base", np.uint64),
        ("n_frames", np.uint64),
        ("frames", np.uint64, (CRASH_FRAMES,)),
    ]
)

#: An event as the crash report writes it (sins_fw_runtime.cpp, CrashEvent).
CRASH_EVENT = np.dtype(
    [
        ("t_ps", np.uint64),
        ("frame", np.int64),
        ("measured", np.float64),
        ("required", np.float64),
        ("severity", np.uint64),
        ("kind", "S40"),
        ("message", "S256"),
    ]
)

_MORE_INPUT = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p)


class _Config(ctypes.Structure):
    _fields_ = [
        ("board", ctypes.c_void_p),
        ("read_cycles", ctypes.c_uint64),
        ("write_cycles", ctypes.c_uint64),
        ("isr_entry_cycles", ctypes.c_uint64),
        ("isr_exit_cycles", ctypes.c_uint64),
        ("spin_blocks", ctypes.c_uint64),
        ("n_globals", ctypes.c_size_t),
        ("global_addr", ctypes.POINTER(ctypes.c_void_p)),
        ("global_type", ctypes.POINTER(ctypes.c_int)),
        ("more_input", _MORE_INPUT),
        ("ctx", ctypes.c_void_p),
    ]


class _Event(ctypes.Structure):
    _fields_ = [
        ("t_ps", ctypes.c_uint64),
        ("frame", ctypes.c_int64),
        ("din", ctypes.c_uint16),
        ("severity", ctypes.c_uint8),
        ("kind", ctypes.c_char * 40),
    ]


class _DlInfo(ctypes.Structure):
    _fields_ = [
        ("dli_fname", ctypes.c_char_p),
        ("dli_fbase", ctypes.c_void_p),
        ("dli_sname", ctypes.c_char_p),
        ("dli_saddr", ctypes.c_void_p),
    ]


class _ElfSym(ctypes.Structure):
    """ElfW(Sym) of a 64-bit ELF (<elf.h>, Elf64_Sym)."""

    _fields_ = [
        ("st_name", ctypes.c_uint32),
        ("st_info", ctypes.c_ubyte),
        ("st_other", ctypes.c_ubyte),
        ("st_shndx", ctypes.c_uint16),
        ("st_value", ctypes.c_uint64),
        ("st_size", ctypes.c_uint64),
    ]


#: dladdr1's flag asking for the symbol's ELF entry (<dlfcn.h>).
_RTLD_DL_SYMENT = 1


@dataclass(frozen=True)
class Watch:
    """What the child needs of a watched global: its C name (``x`` or ``x[3]``), type and where the
    globals file declares it (for messages)."""

    name: str
    type: str
    where: str


@dataclass(frozen=True)
class Job:
    """A run, as the child gets it (by fork: nothing is pickled)."""

    library: str
    profile_source: str
    overrides: tuple[str, ...]
    costs: dict[str, int]
    spin_blocks: int
    watched: tuple[Watch, ...]


class Library:
    """The firmware library loaded in this (child) process."""

    def __init__(self, path: str) -> None:
        self.source = path
        try:
            self.lib = ctypes.CDLL(path, mode=os.RTLD_LOCAL)
        except OSError as e:
            raise InputError(f"{path}: cannot load the firmware library: {e}") from None
        for name in ("sins_fw_run", "sins_fw_take_rows", "sins_fw_row_times", "sins_board_new_input"):
            if not hasattr(self.lib, name):
                raise InputError(
                    f"{path}: no symbol `{name}`: not a firmware built by `sins-fw build-firmware` (or built "
                    "by an older version: build it again)"
                )
        lib = self.lib
        lib.sins_fw_run.argtypes = [ctypes.POINTER(_Config), ctypes.c_char_p, ctypes.c_size_t]
        lib.sins_fw_take_rows.restype = ctypes.c_size_t
        lib.sins_fw_take_rows.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t]
        lib.sins_fw_rows_ready.restype = ctypes.c_size_t
        for f in ("sins_fw_accesses", "sins_fw_blocks", "sins_fw_fault_offset"):
            getattr(lib, f).restype = ctypes.c_uint64
        #: The earliest time a bus record may still matter to a row (absent in older builds).
        self.floor = getattr(lib, "sins_fw_isr_floor_ps", None)
        if self.floor is not None:
            self.floor.restype = ctypes.c_uint64
        lib.sins_last_error.restype = ctypes.c_char_p
        count = ctypes.c_int.in_dll(lib, "sins_fw_row_time_count").value
        self.row_times = tuple(
            (name or b"").decode() for name in (ctypes.c_char_p * count).in_dll(lib, "sins_fw_row_times")
        )
        #: The priced functions' names, in the runtime's order (`sins_fw_function_at`; none in a build
        #: without the cycle model's per-ISR records).
        self.functions: tuple[str, ...] = ()
        self.take_functions = getattr(lib, "sins_fw_take_function_rows", None)
        if self.take_functions is not None:
            lib.sins_fw_function_count.restype = ctypes.c_size_t
            lib.sins_fw_function_at.restype = ctypes.c_char_p
            lib.sins_fw_function_at.argtypes = [ctypes.c_size_t, ctypes.c_void_p, ctypes.c_void_p]
            lib.sins_fw_function_rows_ready.restype = ctypes.c_size_t
            self.take_functions.restype = ctypes.c_size_t
            self.take_functions.argtypes = [ctypes.c_void_p, ctypes.c_size_t]
            word = ctypes.c_uint64()
            self.functions = tuple(
                (lib.sins_fw_function_at(i, ctypes.byref(word), ctypes.byref(word)) or b"").decode(
                    errors="replace"
                )
                for i in range(int(lib.sins_fw_function_count()))
            )
        try:
            self.double_bytes = ctypes.c_int.in_dll(lib, "sins_fw_double_bytes").value
        except ValueError:
            self.double_bytes = 8
        lib.sins_board_new_input.argtypes = [
            ctypes.c_char_p,
            ctypes.POINTER(ctypes.c_char_p),
            ctypes.c_size_t,
            ctypes.POINTER(ctypes.c_void_p),
        ]
        lib.sins_push_input.argtypes = [ctypes.c_void_p, *([ctypes.c_void_p] * 6), ctypes.c_size_t]
        lib.sins_end_input.argtypes = [ctypes.c_void_p]
        lib.sins_set_bus_log.argtypes = [ctypes.c_void_p, ctypes.c_int]
        lib.sins_take_bus_log.argtypes = [
            ctypes.c_void_p,
            ctypes.c_void_p,
            ctypes.c_size_t,
            ctypes.POINTER(ctypes.c_size_t),
        ]
        lib.sins_board_free.argtypes = [ctypes.c_void_p]
        lib.sins_now_ps.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_uint64)]
        lib.sins_take_event.argtypes = [
            ctypes.c_void_p,
            ctypes.POINTER(_Event),
            ctypes.c_char_p,
            ctypes.c_size_t,
            ctypes.POINTER(ctypes.c_double),
            ctypes.POINTER(ctypes.c_double),
            ctypes.POINTER(ctypes.c_int),
        ]

    def ctype(self, type_name: str) -> Any:
        """The ctypes type of a watched global's type: ``double`` is the firmware's (32-bit in the
        C28x float mode, ``sins_fw_double_bytes``)."""
        if type_name == "double" and self.double_bytes == 4:
            return ctypes.c_float
        return _CTYPES[type_name]

    def type_code(self, type_name: str) -> int:
        return TYPES["float"] if self.ctype(type_name) is ctypes.c_float else TYPES[type_name]

    def address(self, g: Watch) -> int:
        """The address of the watched global, refused when the variable (its size in the library's
        dynamic symbol table) does not hold the element of that type: nothing is ever read outside it."""
        name, _, index = g.name.partition("[")
        try:
            base = ctypes.addressof(ctypes.c_char.in_dll(self.lib, name))
        except ValueError:
            raise InputError(
                f"{g.where}: no global `{g.name}` in {self.source}: expected a file-scope, non-static "
                "variable of the firmware"
            ) from None
        width = ctypes.sizeof(self.ctype(g.type))
        k = int(index.rstrip("]") or 0)
        size = symbol_size(base)
        if size is None:
            raise InputError(f"{g.where}: `{name}` in {self.source} is not a variable of known size")
        if (k + 1) * width > size:
            if index:
                fits = size // width
                expected = f"an index below {fits}" if fits else f"a type of at most {size} bytes"
                raise InputError(
                    f"{g.where}: `{g.name}`: the firmware's `{name}` is {size} bytes, element {k} of type "
                    f"{g.type} ({width} bytes) lies outside it: expected {expected}"
                )
            raise InputError(
                f"{g.where}: `{g.name}` is {size} bytes in the firmware, type {g.type} is {width}: "
                "expected the variable's own type (or a narrower one)"
            )
        return base + k * width

    def error(self) -> str:
        return (self.lib.sins_last_error() or b"").decode(errors="replace")


def symbol_size(address: int) -> int | None:
    """The size (bytes) of the object the dynamic symbol at ``address`` names (glibc's dladdr1),
    None when no symbol starts there."""
    libc = ctypes.CDLL(None)
    dladdr1 = getattr(libc, "dladdr1", None)
    if dladdr1 is None:  # glibc before 2.34: in libdl
        dladdr1 = ctypes.CDLL("libdl.so.2").dladdr1
    dladdr1.argtypes = [
        ctypes.c_void_p,
        ctypes.POINTER(_DlInfo),
        ctypes.POINTER(ctypes.c_void_p),
        ctypes.c_int,
    ]
    info, extra = _DlInfo(), ctypes.c_void_p()
    if not dladdr1(address, ctypes.byref(info), ctypes.byref(extra), _RTLD_DL_SYMENT) or not extra.value:
        return None
    if info.dli_saddr != address:
        return None
    return int(ctypes.cast(extra, ctypes.POINTER(_ElfSym)).contents.st_size)


def take_rows(lib: Library, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The ISR rows ready: their times (one column per name of the runtime's ``sins_fw_row_times``)
    and the ``n`` watched globals' values."""
    ready = int(lib.lib.sins_fw_rows_ready())
    times = np.zeros((ready, len(lib.row_times)), dtype=np.uint64)
    values = np.zeros((ready, n), dtype=np.float64)
    got = lib.lib.sins_fw_take_rows(times.ctypes.data, values.ctypes.data, ready)
    return times[:got], values[:got]


#: One function's share of one ISR run (the runtime's sins_fw_take_function_rows): the row's index in
#: the run, the function's index in :attr:`Library.functions`, its own cycles, calls and inclusive
#: cycles in that ISR.
FUNCTION_RECORD = np.dtype(
    [
        ("row", np.uint64),
        ("function", np.uint64),
        ("self", np.uint64),
        ("calls", np.uint64),
        ("inclusive", np.uint64),
    ]
)


def take_function_rows(lib: Library) -> np.ndarray:
    """The per-function records of the ISRs run since the last call."""
    if lib.take_functions is None:
        return np.zeros(0, FUNCTION_RECORD)
    ready = int(lib.lib.sins_fw_function_rows_ready())
    out = np.zeros(ready, FUNCTION_RECORD)
    got = lib.take_functions(out.ctypes.data, ready)
    return out[:got]


def take_bus_log(lib: Library, board: ctypes.c_void_p) -> np.ndarray:
    """The bus-log records the board has kept since the last call."""
    chunks = []
    while True:
        buf = np.zeros(1 << 14, dtype=BUS_RECORD)
        n = ctypes.c_size_t()
        if lib.lib.sins_take_bus_log(board, buf.ctypes.data, len(buf), ctypes.byref(n)) != 0:
            raise InputError(f"bus log: {lib.error()}")
        chunks.append(buf[: n.value])
        if n.value < len(buf):
            return chunks[0] if len(chunks) == 1 else np.concatenate(chunks)


def take_events(lib: Library, board: ctypes.c_void_p) -> list[dict[str, Any]]:
    out = []
    ev, measured, required, got = _Event(), ctypes.c_double(), ctypes.c_double(), ctypes.c_int()
    message = ctypes.create_string_buffer(1024)
    while True:
        if (
            lib.lib.sins_take_event(board, ctypes.byref(ev), message, len(message), measured, required, got)
            != 0
        ):
            raise InputError(f"events: {lib.error()}")
        if not got.value:
            return out
        m, r = measured.value, required.value
        out.append(
            {
                "t_s": ev.t_ps * PS,
                "kind": ev.kind.decode(),
                "severity": _core.SEVERITIES[ev.severity],
                "message": message.value.decode(errors="replace"),
                "measured": None if np.isnan(m) else m,
                "required": None if np.isnan(r) else r,
                "frame": None if ev.frame < 0 else int(ev.frame),
            }
        )


def serve(job: Job, commands: Connection, out: Connection) -> None:
    """The child's work: load, check the globals, run ``main``, streaming to ``out``; the pieces of
    input come from ``commands``. Messages (tuples, first the kind):

    - ``("loaded", double_bytes, row_times, functions)``: the library's static constructors ran (its
      ``double``'s size, the names of an ISR row's times: the runtime's ``sins_fw_row_times``, the
      priced functions' names);
    - ``("rows", times, values, events, bus, functions, floor_ps, now_ps, more)``: the rows, events,
      bus-log records and per-function records (:data:`FUNCTION_RECORD`) since the last message;
      with ``more`` (a request for input) the child then waits for
      ``("piece", columns)`` or ``("end",)``;
    - ``("failed", rc, message, fault_offset, events)``: the runtime stopped the run (rows sent first);
    - ``("done", now_ps, accesses, blocks, final)``;
    - ``("error", exception)``: bad input (an InputError), before or while running."""
    lib = Library(job.library)
    out.send(("loaded", lib.double_bytes, lib.row_times, lib.functions))
    addrs = [lib.address(g) for g in job.watched]
    n = len(addrs)
    board = ctypes.c_void_p()
    overrides = [o.encode() for o in job.overrides]
    arr = (ctypes.c_char_p * max(1, len(overrides)))(*overrides)
    if (
        lib.lib.sins_board_new_input(job.profile_source.encode(), arr, len(overrides), ctypes.byref(board))
        != 0
    ):
        raise ProfileError(f"{job.profile_source}: {lib.error()}")
    # The budget's SPI stage comes from the bus log: always kept, taken piece by piece.
    lib.lib.sins_set_bus_log(board, 1)
    now = ctypes.c_uint64()
    callback_error: list[BaseException] = []
    kept: list[Any] = []

    def send_rows(more: bool) -> None:
        times, values = take_rows(lib, n)
        functions = take_function_rows(lib)
        events = take_events(lib, board)
        bus = take_bus_log(lib, board)
        floor = int(lib.floor()) if lib.floor is not None else 0
        lib.lib.sins_now_ps(board, ctypes.byref(now))
        out.send(("rows", times, values, events, bus, functions, floor, int(now.value), more))

    def push(message: tuple[Any, ...]) -> None:
        if message[0] == "end":
            lib.lib.sins_end_input(board)
            return
        cols = message[1]
        ptrs = [None if c is None else c.ctypes.data for c in cols]
        if lib.lib.sins_push_input(board, *ptrs, len(cols[0])) != 0:
            raise InputError(f"trace: {lib.error()}")
        kept[:] = cols  # alive until the core has copied them (it copies at once; kept for safety)

    def more_input(_ctx: Any) -> int:
        try:
            send_rows(True)
            push(commands.recv())
            return 0
        except BaseException as e:
            callback_error.append(e)
            return 1

    callback = _MORE_INPUT(more_input)
    cfg = _Config(
        board=board,
        spin_blocks=job.spin_blocks,
        n_globals=n,
        global_addr=(ctypes.c_void_p * max(1, n))(*addrs),
        global_type=(ctypes.c_int * max(1, n))(*(lib.type_code(g.type) for g in job.watched)),
        more_input=callback,
        **job.costs,
    )
    push(commands.recv())  # the first piece
    message = ctypes.create_string_buffer(4096)
    rc = lib.lib.sins_fw_run(ctypes.byref(cfg), message, len(message))
    if callback_error:
        raise callback_error[0]
    send_rows(False)
    if rc != 0:
        out.send(
            (
                "failed",
                int(rc),
                message.value.decode(errors="replace"),
                int(lib.lib.sins_fw_fault_offset()),
                take_events(lib, board),
            )
        )
    final = [float(lib.ctype(g.type).from_address(a).value) for g, a in zip(job.watched, addrs, strict=True)]
    out.send(("done", int(now.value), int(lib.lib.sins_fw_accesses()), int(lib.lib.sins_fw_blocks()), final))


def _die_with_parent() -> None:
    """PR_SET_PDEATHSIG(SIGKILL): the child ends when the process that forked it does."""
    # Not Linux: the parent's kill on the way out remains.
    with contextlib.suppress(AttributeError, OSError):
        ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGKILL), 0, 0, 0)


def start(job: Job, commands: Connection, out: Connection, crash_fd: int, close: list[int]) -> int:
    """Fork the child; returns its pid (in the parent). ``close``: the parent's ends of the pipes,
    closed in the child."""
    for stream in (sys.stdout, sys.stderr):
        stream.flush()
    parent = os.getpid()
    pid = os.fork()
    if pid != 0:
        return pid
    code = 0
    try:
        os.setpgid(0, 0)  # out of the terminal's foreground group: Ctrl-C reaches the parent alone
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        _die_with_parent()
        if os.getppid() != parent:
            os._exit(1)
        for fd in close:
            os.close(fd)
        null = os.open(os.devnull, os.O_RDONLY)
        os.dup2(null, 0)
        os.close(null)
        os.dup2(2, 1)  # the firmware's stdout is the run's stderr
        os.environ["SINS_FW_CRASH_FD"] = str(crash_fd)
        try:
            serve(job, commands, out)
        except InputError as e:
            out.send(("error", e))
        except BaseException:
            out.send(("internal", traceback.format_exc()))
    except BaseException:
        code = 3
    finally:
        os._exit(code)
    return 0  # not reached


__all__ = [
    "BUS_RECORD",
    "CRASH_EVENT",
    "CRASH_RECORD",
    "TYPES",
    "Job",
    "Library",
    "Watch",
    "serve",
    "start",
    "symbol_size",
]
