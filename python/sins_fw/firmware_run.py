"""Run a host-built F28335 firmware (``sins-fw build-firmware``) on a trace: ``sins-fw run TRACE
--firmware fw.so [--globals globals.toml]``.

The firmware's ``main`` runs against the emulated board until the trace ends; the ADIS16407 sees the
trace (time 0 is the trace's first sample, as for the Rust model). Each time the CPU takes timer 0's
interrupt the runtime calls the ISR the firmware put in ``PieVectTable`` and then records a row: the
tick, the ISR's times, and the values of the globals named in the globals file. Those rows become
the usual parts of a run (:func:`sins_fw.harness.emulate`'s ``sink`` form), so the summary, the
budget and ``--out`` are the ones of the Rust model.

The globals file (TOML, beside the sources; ``globals.toml`` there is found by default)::

    [[global]]
    name = "rate_x"        # the C global (file scope, not static), or an array's element: "Q[0]"
    type = "float"         # int16, uint16, int32, uint32, int64, uint64, float, double (the
                           # firmware's: 32-bit when built with --float c28x)
    column = "rate_x_dps"  # the output column
    unit = "deg/s"
    description = "…"      # optional

Columns named like the run output's (``q0``…``q3``, ``roll_deg``, ``pitch_deg``, ``yaw_deg``) are the
attitude, compared with the trace's truth when all four ``q`` are given.

Globals start fresh in every run: each run loads a private copy of the library (a new file, so a
new ``dlopen`` with its own data segment), so two runs in one process give the same results.
"""

from __future__ import annotations

import ctypes
import math
import os
import re
import shutil
import subprocess
import tempfile
import tomllib
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

from sins_fw import _core, synth
from sins_fw.errors import InputError, ProfileError
from sins_fw.harness import FEED_ROWS, PS, _chunks, _TruthWindow
from sins_fw.profile import Profile
from sins_fw.run_output import RUN_SCHEMA, RunWriter
from sins_fw.tablefile import Column, Schema
from sins_fw.traces import PhysicalTrace

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
#: The run output's attitude columns a global may fill: file column → (core column, component).
ATTITUDE = {
    **{f"q{i}": ("cycle_quat", i) for i in range(4)},
    **{n: ("cycle_euler_deg", i) for i, n in enumerate(("roll_deg", "pitch_deg", "yaw_deg"))},
}
#: Basic blocks without a register access before the runtime checks for a loop that cannot end
#: (2^24 blocks: about 1 s of virtual time at 9 cycles each and 150 MHz, 0.1 s of host time).
SPIN_BLOCKS = 1 << 24

_MORE_INPUT = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p)
#: The C ABI's SinsBusRecord (rust/cabi/include/sins_fw.h), one bus-log record.
_BUS_RECORD = np.dtype(
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


class _Config(ctypes.Structure):
    _fields_ = [
        ("board", ctypes.c_void_p),
        ("read_cycles", ctypes.c_uint64),
        ("write_cycles", ctypes.c_uint64),
        ("block_cycles", ctypes.c_uint64),
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


@dataclass(frozen=True)
class Global:
    """A watched global of the firmware."""

    name: str
    type: str
    column: str
    unit: str
    description: str = ""


def load_globals(path: str | os.PathLike[str]) -> list[Global]:
    """The globals file (see the module's doc); errors name the file, the line and the field."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except OSError as e:
        raise InputError(f"{p}: cannot read the globals file: {e.strerror or e}") from None
    except UnicodeDecodeError as e:
        raise InputError(f"{p}: byte {e.start} is not UTF-8 text; expected a TOML globals file") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise InputError(f"{p}: not valid TOML: {e}") from None
    except RecursionError:
        raise InputError(f"{p}: nested too deeply to read; expected [[global]] entries") from None
    unknown = sorted(set(data) - {"global"})
    if unknown:
        raise InputError(f"{p}: unknown table `{unknown[0]}`: expected only [[global]] entries")
    entries = data.get("global")
    if not isinstance(entries, list) or not entries:
        raise InputError(f"{p}: no [[global]] entries (each: name, type, column, unit)")
    lines = [i + 1 for i, line in enumerate(text.splitlines()) if re.match(r"\s*\[\[\s*global\s*\]\]", line)]
    out: list[Global] = []
    for k, entry in enumerate(entries):
        where = f"{p}:{lines[k] if k < len(lines) else '?'}: [[global]] {k + 1}"
        fields = {"name", "type", "column", "unit", "description"}
        extra = sorted(set(entry) - fields)
        if extra:
            raise InputError(f"{where}: unknown field `{extra[0]}` (fields: {', '.join(sorted(fields))})")
        for f in ("name", "type", "column", "unit"):
            if not isinstance(entry.get(f), str) or not entry[f]:
                raise InputError(f"{where}: field `{f}` missing or not a text")
        if not re.fullmatch(r"[A-Za-z_]\w*(\[\d+\])?", entry["name"]):
            raise InputError(
                f"{where}: field `name` = {entry['name']!r}: expected a C identifier, or one element "
                "of an array (Q[0])"
            )
        if entry["type"] not in TYPES:
            raise InputError(f"{where}: field `type` = {entry['type']!r}: expected one of {', '.join(TYPES)}")
        if not re.fullmatch(r"[a-z][a-z0-9_]*", entry["column"]) or entry["column"] == "t_s":
            raise InputError(
                f"{where}: field `column` = {entry['column']!r}: expected a lower-case column name "
                "(letters, digits, _), not t_s"
            )
        if entry["column"] in {g.column for g in out}:
            raise InputError(
                f"{where}: field `column` = {entry['column']!r}: already the column of another global"
            )
        out.append(
            Global(entry["name"], entry["type"], entry["column"], entry["unit"], entry.get("description", ""))
        )
    return out


def default_globals(firmware: str | os.PathLike[str]) -> Path | None:
    """``globals.toml`` beside the firmware library, if there is one."""
    p = Path(firmware).with_name("globals.toml")
    return p if p.is_file() else None


def _costs(profile: Profile) -> dict[str, int]:
    """The cycles the runtime charges, from the profile's cost table."""
    from sins_fw.harness import cost_table_text

    text, source = cost_table_text(profile)
    t = tomllib.loads(text)
    try:
        io, irq = t["io"], t["interrupt"]
        return {
            "read_cycles": int(io["peripheral_read"]),
            "write_cycles": int(io["peripheral_write"]),
            "block_cycles": int(io["frame_loop"]),
            "isr_entry_cycles": int(irq["hw_context_save"]) + int(irq["c_prologue"]),
            "isr_exit_cycles": int(irq["c_epilogue"]) + int(irq["iret"]),
        }
    except KeyError as e:
        raise ProfileError(f"{source}: key {e} missing (the host-built firmware's costs)") from None


class _Library:
    """A private copy of the firmware library, loaded fresh (its globals at their initial values)."""

    def __init__(self, library: str | os.PathLike[str]) -> None:
        src = Path(library)
        if not src.is_file():
            raise InputError(f"{src}: no such firmware library (build it with `sins-fw build-firmware`)")
        self._dir = tempfile.TemporaryDirectory(prefix="sins-fw-run-")
        self.path = Path(self._dir.name) / src.name
        shutil.copyfile(src, self.path)
        self.source = src
        try:
            self.lib = ctypes.CDLL(str(self.path), mode=os.RTLD_LOCAL)
        except OSError as e:
            raise InputError(f"{src}: cannot load the firmware library: {e}") from None
        for name in ("sins_fw_run", "sins_fw_take_rows", "sins_fw_row_times", "sins_board_new_input"):
            if not hasattr(self.lib, name):
                raise InputError(
                    f"{src}: no symbol `{name}`: not a firmware built by `sins-fw build-firmware` (or built "
                    "by an older version: build it again)"
                )
        lib = self.lib
        lib.sins_fw_run.argtypes = [ctypes.POINTER(_Config), ctypes.c_char_p, ctypes.c_size_t]
        lib.sins_fw_take_rows.restype = ctypes.c_size_t
        lib.sins_fw_take_rows.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t]
        lib.sins_fw_rows_ready.restype = ctypes.c_size_t
        for f in ("sins_fw_accesses", "sins_fw_blocks", "sins_fw_fault_offset"):
            getattr(lib, f).restype = ctypes.c_uint64
        lib.sins_last_error.restype = ctypes.c_char_p
        #: The ISR row's times, in the runtime's order (its `sins_fw_row_times`).
        count = ctypes.c_int.in_dll(lib, "sins_fw_row_time_count").value
        self.row_times = tuple(
            (name or b"").decode() for name in (ctypes.c_char_p * count).in_dll(lib, "sins_fw_row_times")
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
        """The runtime's code of a watched global's type (see :meth:`ctype`)."""
        return TYPES["float"] if self.ctype(type_name) is ctypes.c_float else TYPES[type_name]

    def address(self, g: Global, globals_file: Path | None) -> int:
        name, _, index = g.name.partition("[")
        try:
            base = ctypes.addressof(ctypes.c_char.in_dll(self.lib, name))
            return base + int(index.rstrip("]") or 0) * ctypes.sizeof(self.ctype(g.type))
        except ValueError:
            where = f" ({globals_file})" if globals_file else ""
            raise InputError(
                f"{self.source}: no global `{g.name}`{where}: expected a file-scope, non-static variable "
                "of the "
                "firmware"
            ) from None

    def error(self) -> str:
        return (self.lib.sins_last_error() or b"").decode(errors="replace")

    def close(self) -> None:
        self._dir.cleanup()


@dataclass
class FirmwareResult:
    """What a firmware run did besides its parts: virtual time reached, register accesses and basic
    blocks run, the ISR rows, and the watched globals' values when the run ended."""

    now_s: float = 0.0
    accesses: int = 0
    blocks: int = 0
    isr_rows: int = 0
    t0_s: float = 0.0
    final: dict[str, float] = field(default_factory=dict)
    #: The SPI bus log when the run kept one (``bus_log=True``), in the keys of
    #: :attr:`sins_fw.harness.Run.bus` (``cs_t_ps``, ``cs_low``, ``frame_index``, ``frame_start_ps``,
    #: ``frame_din``, ``frame_dout``, ...), times in ps since power-on.
    bus: dict[str, np.ndarray] | None = None


def _still_trace(until_s: float) -> PhysicalTrace:
    """A board at rest, level, for ``until_s`` seconds (a run without a trace): `sins-fw synth static`
    (earth rate, normal gravity at the default site, its truth) on its 819.2 SPS grid, the last
    sample moved to ``until_s`` itself so that the input covers the whole run. (A run ends at the
    trace's last sample at or before ``until_s``: with grid samples only, a run shorter than one
    sample period, 1.22 ms, would cover no time at all and end at the firmware's first basic block.)"""
    rate = Fraction(synth.DEFAULT_RATE_HZ)
    below = math.ceil(Fraction(until_s) * rate)  # grid samples before until_s
    motion = synth.static_motion(duration_s=float((below + 2) / rate), rows=slice(0, below + 1))
    motion.t_s[-1] = until_s  # at rest: every sample reads the same, wherever it lies
    return synth.to_trace(motion, {"sample_rate_hz": synth.DEFAULT_RATE_HZ})


def run_c_firmware(
    library: str | os.PathLike[str],
    trace: PhysicalTrace | str | os.PathLike[str] | Iterable[PhysicalTrace] | None,
    profile: Profile,
    *,
    globals_file: str | os.PathLike[str] | None = None,
    sink: Callable[[dict[str, Any]], None] | None = None,
    until_s: float | None = None,
    on_chunk: Callable[[float], None] | None = None,
    bus_log: bool = False,
) -> FirmwareResult:
    """Run the firmware library on ``trace`` (None: a still board for ``until_s`` s) with the board
    of ``profile``; each part of the output (see the module's doc) goes to ``sink``. Bad input (the
    library, a symbol, the globals file) raises InputError before anything runs; an emulator error
    while the firmware runs (an unmodelled register, a loop that cannot end) raises InputError with
    the emulator's message, the loop's file and line when it names one. ``bus_log`` keeps the SPI bus
    log of the whole run (:attr:`FirmwareResult.bus`)."""
    gfile = Path(globals_file) if globals_file is not None else None
    watched = load_globals(gfile) if gfile is not None else []
    costs = _costs(profile)
    lib = _Library(library)
    board = ctypes.c_void_p()
    try:
        addrs = [lib.address(g, gfile) for g in watched]
        overrides = [o.encode() for o in profile.overrides]
        arr = (ctypes.c_char_p * max(1, len(overrides)))(*overrides)
        if (
            lib.lib.sins_board_new_input(
                str(profile.source).encode(), arr, len(overrides), ctypes.byref(board)
            )
            != 0
        ):
            raise ProfileError(f"{profile.source}: {lib.error()}")
        feeder = _Feeder(lib, board, trace, until_s, on_chunk, len(watched))
        n = len(watched)
        result = FirmwareResult()
        rows = _Rows(watched, sink)
        callback_error: list[BaseException] = []
        bus: list[np.ndarray] | None = [] if bus_log else None
        # The budget's SPI stage comes from the bus log (_Rows._spi_stage): always kept, taken piece
        # by piece.
        lib.lib.sins_set_bus_log(board, 1)

        def take_all() -> None:
            records = _take_bus_log(lib, board)
            if bus is not None:
                bus.append(records)
            rows.add(feeder.window, _take_rows(lib, n), _take_events(lib, board, feeder.t0), records)

        def more_input(_ctx: Any) -> int:
            try:
                take_all()
                feeder.push_next()
                return 0
            except BaseException as e:
                callback_error.append(e)
                return 1

        callback = _MORE_INPUT(more_input)
        cfg = _Config(
            board=board,
            spin_blocks=SPIN_BLOCKS,
            n_globals=n,
            global_addr=(ctypes.c_void_p * max(1, n))(*addrs),
            global_type=(ctypes.c_int * max(1, n))(*(lib.type_code(g.type) for g in watched)),
            more_input=callback,
            **costs,
        )
        feeder.push_next()
        message = ctypes.create_string_buffer(4096)
        rc = lib.lib.sins_fw_run(ctypes.byref(cfg), message, len(message))
        if callback_error:
            raise callback_error[0]
        if rc != 0:
            text = message.value.decode(errors="replace")
            offset = int(lib.lib.sins_fw_fault_offset())
            if offset:
                text += f" (the loop: {_source_line(lib.path, offset)})"
            ignored = [e for e in _take_events(lib, board, feeder.t0) if e["kind"] == "protected_write"]
            if ignored:
                text += f"; before it, at {ignored[0]['t_s']:.9f} s: {ignored[0]['message']}"
            raise InputError(f"{lib.source}: {text}")
        take_all()
        now = ctypes.c_uint64()
        lib.lib.sins_now_ps(board, ctypes.byref(now))
        result.now_s = now.value * PS
        result.accesses = int(lib.lib.sins_fw_accesses())
        result.blocks = int(lib.lib.sins_fw_blocks())
        result.isr_rows = rows.count
        result.t0_s = feeder.t0 or 0.0
        result.final = {
            g.name: float(lib.ctype(g.type).from_address(a).value)
            for g, a in zip(watched, addrs, strict=True)
        }
        if bus is not None:
            result.bus = _bus_columns(np.concatenate(bus))
        return result
    finally:
        if board:
            lib.lib.sins_board_free(board)
        lib.close()


#: What a bus-log comparison compares, frame by frame: the words on the wires. Times are not
#: compared: a host-built firmware's time comes from the runtime's estimates (a basic block, a
#: register access; docs/c-drivers.md), the model's from its cost table, so the two logs agree on the
#: words and their order, not on the picosecond.
BUS_WORDS = ("frame_selected", "frame_master_tx", "frame_din", "frame_dout", "frame_master_rx")


@dataclass(frozen=True)
class FrameDifference:
    """The first frame where two bus logs differ: its position (0-based, in both logs), the column
    that differs (``frames`` when one log ends first) and each log's frame there."""

    position: int
    column: str
    firmware: dict[str, int]
    model: dict[str, int]

    def __str__(self) -> str:
        def text(f: dict[str, int]) -> str:
            if not f:
                return "no frame"
            gap = f.get("gap_ps")
            gap_text = (
                "" if gap is None else f", {gap / 1e6:.3f} µs after the previous frame's last SCLK edge"
            )
            return (
                f"t = {f['start_ps'] * PS:.9f} s, DIN 0x{f['din']:04X}, DOUT 0x{f['dout']:04X}, "
                f"received 0x{f['master_rx']:04X}{gap_text}"
            )

        return (
            f"frame {self.position} ({self.column} differs): firmware {text(self.firmware)}; "
            f"model {text(self.model)}"
        )


def first_frame_difference(
    firmware: dict[str, np.ndarray], model: dict[str, np.ndarray]
) -> FrameDifference | None:
    """The first frame whose words (:data:`BUS_WORDS`) differ between a firmware run's bus log
    (:attr:`FirmwareResult.bus`) and the model's (:attr:`sins_fw.harness.Run.bus`), None when every
    frame agrees and both logs have as many."""
    n = min(len(firmware["frame_din"]), len(model["frame_din"]))
    first, column = n, "frames"
    for c in BUS_WORDS:
        bad = np.nonzero(firmware[c][:n] != model[c][:n])[0]
        if len(bad) and bad[0] < first:
            first, column = int(bad[0]), c
    if first == n and len(firmware["frame_din"]) == len(model["frame_din"]):
        return None

    def frame(log: dict[str, np.ndarray]) -> dict[str, int]:
        if first >= len(log["frame_din"]):
            return {}
        f = {k: int(log[f"frame_{k}"][first]) for k in ("start_ps", "din", "dout", "master_rx")}
        if first > 0:
            f["gap_ps"] = int(log["frame_first_edge_ps"][first]) - int(log["frame_last_edge_ps"][first - 1])
        return f

    return FrameDifference(first, column, frame(firmware), frame(model))


def _source_line(library: Path, offset: int) -> str:
    """``file:line`` of a code offset in the library (addr2line from binutils), else the offset."""
    tool = shutil.which("addr2line")
    if tool is not None:
        # The runtime reports the return address of the block's call: one byte back is inside it.
        run = subprocess.run(
            [tool, "-e", str(library), "-f", "-C", "-i", hex(offset - 1)],
            capture_output=True,
            text=True,
            check=False,
        )
        lines = run.stdout.splitlines()
        if run.returncode == 0 and len(lines) >= 2 and not lines[1].startswith("??"):
            return f"{lines[1].split(' ')[0]} in {lines[0]}"
    return f"offset 0x{offset:x} of the library"


class _Feeder:
    """Pushes the trace into the board a piece at a time, when the runtime asks for more."""

    def __init__(
        self,
        lib: _Library,
        board: ctypes.c_void_p,
        trace: Any,
        until_s: float | None,
        on_chunk: Callable[[float], None] | None,
        n_globals: int,
    ) -> None:
        self.lib, self.board, self.until_s, self.on_chunk = lib, board, until_s, on_chunk
        self.t0: float | None = None
        self.window = _TruthWindow()
        self.pieces = self._pieces(_still_trace(until_s or 1.0) if trace is None else trace)
        self.ended = False

    def _pieces(self, trace: Any) -> Iterator[tuple[PhysicalTrace, np.ndarray, slice]]:
        for chunk in _chunks(trace, FEED_ROWS):
            if not len(chunk):
                continue
            if self.t0 is None:
                self.t0 = float(chunk.t_s[0])
            t = np.ascontiguousarray(chunk.t_s - self.t0)
            stop = len(t)
            if self.until_s is not None:
                stop = int(np.searchsorted(t, self.until_s, side="right"))
            if stop:
                yield chunk, t, slice(0, stop)
            if stop < len(t):
                return

    def push_next(self) -> None:
        if self.ended:
            return
        piece = next(self.pieces, None)
        if piece is None:
            self.lib.lib.sins_end_input(self.board)
            self.ended = True
            return
        chunk, t, s = piece
        t = np.ascontiguousarray(t[s])

        def arr(a: np.ndarray | None) -> Any:
            return None if a is None else np.ascontiguousarray(a[s], dtype=np.float64)

        cols = [
            t,
            arr(chunk.gyro_dps),
            arr(chunk.accel_g),
            arr(chunk.mag_gauss),
            arr(chunk.baro_mbar),
            arr(chunk.temp_c),
        ]
        ptrs = [None if c is None else c.ctypes.data for c in cols]
        if self.lib.lib.sins_push_input(self.board, *ptrs, len(t)) != 0:
            raise InputError(f"trace: {self.lib.error()}")
        self._keep = cols  # alive until the core has copied them (it copies at once; kept for safety)
        if chunk.truth_q is not None:
            self.window.feed(t, chunk.truth_q[s], None if chunk.moving is None else chunk.moving[s])
        if self.on_chunk is not None:
            self.on_chunk(float(chunk.t_s[s][-1]))


def _take_rows(lib: _Library, n: int) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """The ISR rows ready: their times by name (the runtime's ``sins_fw_row_times``) and the `n`
    watched globals' values."""
    ready = int(lib.lib.sins_fw_rows_ready())
    times = np.zeros((ready, len(lib.row_times)), dtype=np.uint64)
    values = np.zeros((ready, n), dtype=np.float64)
    got = lib.lib.sins_fw_take_rows(times.ctypes.data, values.ctypes.data, ready)
    return {name: times[:got, i] for i, name in enumerate(lib.row_times)}, values[:got]


def _take_bus_log(lib: _Library, board: ctypes.c_void_p) -> np.ndarray:
    """The bus-log records the board has kept since the last call."""
    chunks = []
    while True:
        buf = np.zeros(1 << 14, dtype=_BUS_RECORD)
        n = ctypes.c_size_t()
        if lib.lib.sins_take_bus_log(board, buf.ctypes.data, len(buf), ctypes.byref(n)) != 0:
            raise InputError(f"bus log: {lib.error()}")
        chunks.append(buf[: n.value])
        if n.value < len(buf):
            return np.concatenate(chunks)


def _bus_columns(records: np.ndarray) -> dict[str, np.ndarray]:
    """Bus-log records as the columns of the model's bus log (sins_fw.harness.Run.bus)."""
    cs, fr = records[records["kind"] == 0], records[records["kind"] == 1]
    return {
        "cs_t_ps": cs["t_ps"].copy(),
        "cs_low": cs["cs_low"].astype(bool),
        "frame_index": fr["index"].copy(),
        "frame_start_ps": fr["t_ps"].copy(),
        "frame_end_ps": fr["end_ps"].copy(),
        "frame_first_edge_ps": fr["first_edge_ps"].copy(),
        "frame_last_edge_ps": fr["last_edge_ps"].copy(),
        "frame_sclk_period_ps": fr["sclk_period_ps"].copy(),
        "frame_bits": fr["bits"].copy(),
        "frame_selected": fr["selected"].astype(bool),
        "frame_master_tx": fr["master_tx"].copy(),
        "frame_master_rx": fr["master_rx"].copy(),
        "frame_din": fr["din"].copy(),
        "frame_dout": fr["dout"].copy(),
    }


def _take_events(lib: _Library, board: ctypes.c_void_p, t0: float | None) -> list[dict[str, Any]]:
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


class _Rows:
    """Turns the runtime's ISR rows into parts of a run (and keeps the last values)."""

    def __init__(self, watched: list[Global], sink: Callable[[dict[str, Any]], None] | None) -> None:
        self.watched, self.sink = watched, sink
        self.count = 0
        self.prev_end = 0
        #: Bus-log records not yet past the last ISR turned into a row.
        self.bus = np.zeros(0, dtype=_BUS_RECORD)
        self.has_quat = all(f"q{i}" in {g.column for g in watched} for i in range(4))

    def add(
        self,
        window: _TruthWindow,
        rows: tuple[dict[str, np.ndarray], np.ndarray],
        events: list[dict[str, Any]],
        bus: np.ndarray,
    ) -> None:
        times, values = rows
        n = len(values)
        self.bus = np.concatenate([self.bus, bus]) if len(self.bus) else bus
        if not n and not events:
            return
        self.count += n
        part = self._part(times, values, events)
        if self.has_quat and window.t is not None and n:
            window.attach(part)
        if self.sink is not None:
            self.sink(part)

    def _part(
        self, col: dict[str, np.ndarray], values: np.ndarray, events: list[dict[str, Any]]
    ) -> dict[str, Any]:
        budget = self._budget(col)
        n = len(values)
        quat = np.full((n, 4), np.nan)
        euler = np.full((n, 3), np.nan)
        for i, g in enumerate(self.watched):
            if g.column in ATTITUDE:
                core, k = ATTITUDE[g.column]
                (quat if core == "cycle_quat" else euler)[:, k] = values[:, i]
        part: dict[str, Any] = {
            "cycle_t_ps": col["tick_ps"].astype(np.uint64),
            "cycle_step": col["tick"].astype(np.uint64),
            "cycle_quat": quat,
            "cycle_euler_deg": euler,
            "cycle_vel_enu": np.full((n, 3), np.nan),
            "cycle_pos": np.full((n, 3), np.nan),
            "read_tick": np.zeros(0, np.uint64),
            "read_t_cs_ps": np.zeros(0, np.uint64),
            "read_t_start_ps": np.zeros(0, np.uint64),
            "read_t_end_ps": np.zeros(0, np.uint64),
            "read_words": np.zeros((0, 15), np.uint16),
            "read_rate": np.zeros((0, 3)),
            "read_accel": np.zeros((0, 3)),
            "read_sample_index": np.zeros(0, np.int64),
            "read_sample_ps": np.zeros(0, np.uint64),
            "read_assumed_s": np.zeros(0),
            "read_age_ps": np.zeros(0, np.uint64),
            "events": events,
            "firmware_globals": {g.column: values[:, i] for i, g in enumerate(self.watched)},
            **{f"budget_{k}": v for k, v in budget.items()},
        }
        return part

    def _spi_stage(self, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The SPI stage of ISRs whose bodies run from ``lo`` to ``hi`` (ps), as the model's budget
        bounds it: from the start of the ISR's first SPI frame to the chip select's last rise after
        its last frame (or that frame's end when CS does not rise). An ISR without a frame has an
        empty stage at ``lo``. The records up to the last ISR are dropped afterwards."""
        rec = self.bus
        frames = rec[rec["kind"] == 1]
        rises = rec[(rec["kind"] == 0) & (rec["cs_low"] == 0)]["t_ps"]
        starts, ends = frames["t_ps"], frames["end_ps"]
        start, end = lo.copy(), lo.copy()
        if len(starts):
            first = np.searchsorted(starts, lo, side="left")
            last = np.searchsorted(starts, hi, side="right") - 1
            has = (first < len(starts)) & (last >= first)
            start[has] = starts[first[has]]
            end[has] = ends[last[has]]
            if len(rises):
                rise = np.searchsorted(rises, hi, side="right") - 1
                ok = has & (rise >= 0)
                ok[ok] = rises[rise[ok]] >= end[ok]
                end[ok] = rises[rise[ok]]
        if len(hi):
            self.bus = rec[rec["t_ps"] > hi[-1]]
        return start, end

    def _budget(self, col: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """One budget row per ISR, in the Rust model's columns: the entry (context save and prologue),
        the wait for CS and the first frame (`cs_setup`), the SPI transfers and their register waits
        (`spi`, from the bus log: :meth:`_spi_stage`), the rest of the ISR's body as the `decode`
        stage (the runtime cannot tell the decode from the attitude code), the exit. (A tick whose
        interrupt was never taken is the core's `tick_lost` event.)"""
        u = {k: v.astype(np.uint64) for k, v in col.items()}
        spi_start, spi_end = self._spi_stage(u["entry_end_ps"], u["body_end_ps"])
        b = {
            "tick": u["tick"],
            "tick_ps": u["tick_ps"],
            "start_ps": u["start_ps"],
            "entry_end_ps": u["entry_end_ps"],
            "spi_start_ps": spi_start,
            "spi_end_ps": spi_end,
            "decode_end_ps": u["body_end_ps"],
            "attitude_end_ps": u["body_end_ps"],
            "euler_end_ps": u["body_end_ps"],
            "nav_end_ps": u["body_end_ps"],
            "end_ps": u["end_ps"],
            "deadline_ps": u["deadline_ps"],
            "step": np.ones(len(u["tick"]), np.uint8),
            "overrun": np.zeros(len(u["tick"]), np.uint8),
        }
        # A tick that arrived while the previous ISR was still running.
        prev_end = np.r_[self.prev_end, u["end_ps"][:-1]].astype(np.uint64)
        b["overrun"] = (u["tick_ps"] < prev_end).astype(np.uint8)
        if len(u["tick"]):
            self.prev_end = int(u["end_ps"][-1])
        return b


class FirmwareRunWriter(RunWriter):
    """``run --firmware … --out``: the run output's format and conventions (the same writer and
    metadata), with the time column, the attitude columns the globals give, and the other globals as
    columns declared by the globals file."""

    def __init__(
        self,
        path: str | os.PathLike[str],
        profile: Profile,
        t0_s: float,
        metadata: dict[str, str],
        watched: list[Global],
    ) -> None:
        super().__init__(path, profile, t0_s, metadata)
        self.watched = watched
        run_cols = {c.name: c for c in RUN_SCHEMA.columns}
        columns = [run_cols["t_s"]]
        for g in watched:
            if g.column in run_cols:
                columns.append(run_cols[g.column])
            else:
                columns.append(
                    Column(g.column, g.unit, g.description or f"firmware global `{g.name}` after the ISR")
                )
        self.schema = Schema(RUN_SCHEMA.title, RUN_SCHEMA.format, tuple(columns))

    def _columns(self, part: dict[str, Any]) -> dict[str, np.ndarray]:
        cols = {"t_s": part["cycle_t_ps"].astype(np.float64) * PS}
        cols.update(part["firmware_globals"])
        return cols


def firmware_metadata(library: str | os.PathLike[str], globals_file: Path | None) -> dict[str, str]:
    """What a run output records of the firmware."""
    meta = {"firmware": str(Path(library)), "created_by": "sins-fw run --firmware"}
    if globals_file is not None:
        meta["globals"] = str(globals_file)
    return meta


__all__ = [
    "FirmwareResult",
    "FirmwareRunWriter",
    "FrameDifference",
    "Global",
    "default_globals",
    "firmware_metadata",
    "first_frame_difference",
    "load_globals",
    "run_c_firmware",
]
