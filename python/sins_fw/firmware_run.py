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

The firmware runs in a process of its own (:mod:`sins_fw.firmware_child`): a crash, ``abort()``,
``exit()`` or endless recursion in it ends that process, not the emulator's; the rows, events and
summary up to there are kept and the error names the signal and the firmware's file and line
(:class:`FirmwareStopped`). Its stdout is the run's stderr. Globals start fresh in every run (each
run is a new process with a new ``dlopen``), so two runs give the same results.
"""

from __future__ import annotations

import contextlib
import math
import multiprocessing
import os
import re
import shutil
import signal
import subprocess
import tempfile
import tomllib
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

from sins_fw import synth
from sins_fw._core import SEVERITIES
from sins_fw.errors import InputError, InternalError, ProfileError
from sins_fw.firmware_child import BUS_RECORD, CRASH_EVENT, CRASH_MAGIC, CRASH_RECORD, TYPES, Job, Watch
from sins_fw.firmware_child import start as start_child
from sins_fw.harness import FEED_ROWS, PS, _chunks, _TruthWindow
from sins_fw.profile import Profile, cost_table_text
from sins_fw.run_output import FIRMWARE_CREATED_BY, RunWriter, firmware_run_schema
from sins_fw.traces import PhysicalTrace

#: The run output's attitude columns a global may fill: file column → (core column, component).
ATTITUDE = {
    **{f"q{i}": ("cycle_quat", i) for i in range(4)},
    **{n: ("cycle_euler_deg", i) for i, n in enumerate(("roll_deg", "pitch_deg", "yaw_deg"))},
}
#: One function's share of one ISR (a run part's ``firmware_functions``): the tick of the ISR row, the
#: function's index in :attr:`FirmwareResult.functions`, its own C28x cycles, its calls and its
#: inclusive cycles (its own and its callees', from entry to return) in that ISR.
FUNCTION_TICKS = np.dtype(
    [
        ("tick", np.uint64),
        ("function", np.uint32),
        ("self", np.uint64),
        ("calls", np.uint64),
        ("inclusive", np.uint64),
    ]
)
#: Basic blocks without a register access before the runtime checks for a loop that cannot end
#: (2^24 blocks: about 1 s of virtual time at 9 cycles each and 150 MHz, 0.1 s of host time).
SPIN_BLOCKS = 1 << 24


@dataclass(frozen=True)
class Global:
    """A watched global of the firmware."""

    name: str
    type: str
    column: str
    unit: str
    description: str = ""
    #: Where the globals file declares it (``file:line: [[global]] k``), for messages.
    where: str = field(default="", compare=False)


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
            Global(
                entry["name"],
                entry["type"],
                entry["column"],
                entry["unit"],
                entry.get("description", ""),
                where,
            )
        )
    return out


def default_globals(firmware: str | os.PathLike[str]) -> Path | None:
    """``globals.toml`` beside the firmware library, if there is one."""
    p = Path(firmware).with_name("globals.toml")
    return p if p.is_file() else None


def _costs(profile: Profile) -> dict[str, int]:
    """The cycles the runtime charges, from the profile's cost table."""
    text, source = cost_table_text(profile)
    t = tomllib.loads(text)
    try:
        io, irq = t["io"], t["interrupt"]
        return {
            "read_cycles": int(io["peripheral_read"]),
            "write_cycles": int(io["peripheral_write"]),
            "isr_entry_cycles": int(irq["hw_context_save"]) + int(irq["c_prologue"]),
            "isr_exit_cycles": int(irq["c_epilogue"]) + int(irq["iret"]),
        }
    except KeyError as e:
        raise ProfileError(f"{source}: key {e} missing (the host-built firmware's costs)") from None


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
    #: The float mode the firmware was built with (``host`` or ``c28x``: `build-firmware --float`).
    float_mode: str = ""
    #: Whether the trace has a truth attitude (compared when the globals give q0…q3).
    truth: bool = False
    #: The SPI bus log when the run kept one (``bus_log=True``), in the keys of
    #: :attr:`sins_fw.harness.Run.bus` (``cs_t_ps``, ``cs_low``, ``frame_index``, ``frame_start_ps``,
    #: ``frame_din``, ``frame_dout``, ...), times in ps since power-on.
    bus: dict[str, np.ndarray] | None = None
    #: The names of the firmware's priced functions (the ``function`` index of the parts'
    #: ``firmware_functions`` records).
    functions: tuple[str, ...] = ()


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
    on_loaded: Callable[[str], None] | None = None,
) -> FirmwareResult:
    """Run the firmware library on ``trace`` (None: a still board for ``until_s`` s) with the board
    of ``profile``; each part of the output (see the module's doc) goes to ``sink``. The firmware runs
    in a child process (:mod:`sins_fw.firmware_child`). Bad input (the library, a symbol, the globals
    file, a global the variable cannot hold) raises InputError before anything runs. A run the
    firmware ends (an unmodelled register, a loop that cannot end, a crash, ``abort``, ``exit``)
    raises :class:`FirmwareStopped` (an InputError) with the emulator's message, the signal, and the
    firmware's file and line where the build tells; the parts up to there have gone to ``sink``, and
    the exception carries the result so far. An ISR that has not returned by its deadline when the
    input ends is an error event (``isr_not_returned``). ``bus_log`` keeps the SPI bus log of the
    whole run (:attr:`FirmwareResult.bus`). ``on_loaded`` is called with the float mode the library
    was built with once it is loaded, before any row. Ctrl-C (KeyboardInterrupt) and SIGTERM stop
    the child."""
    gfile = Path(globals_file) if globals_file is not None else None
    watched = load_globals(gfile) if gfile is not None else []
    costs = _costs(profile)
    source = Path(library)
    if not source.is_file():
        raise InputError(f"{source}: no such firmware library (build it with `sins-fw build-firmware`)")
    job = Job(
        library=str(source.resolve()),
        profile_source=str(profile.source),
        overrides=tuple(profile.overrides),
        costs=costs,
        spin_blocks=SPIN_BLOCKS,
        watched=tuple(Watch(g.name, g.type, g.where or f"{gfile}: global `{g.name}`") for g in watched),
    )
    feeder = _Feeder(trace, until_s, on_chunk)
    rows = _Rows(watched, sink)
    result = FirmwareResult()
    bus: list[np.ndarray] | None = [] if bus_log else None
    #: The first write the protection ignored (named in a stop's message: often its cause).
    ignored: list[dict[str, Any]] = []
    with _Child(job) as child:
        loaded = False
        while True:
            message = child.receive()
            if message is None:  # the child is gone without a word: a signal, exit(), _exit()
                raise child.stopped(source, loaded, result, rows, feeder)
            kind = message[0]
            if kind == "loaded":
                loaded = True
                result.float_mode = "c28x" if message[1] == 4 else "host"
                if on_loaded is not None:
                    on_loaded(result.float_mode)
                rows.row_times = message[2]
                result.functions = message[3]
                child.send(feeder.next_piece())
            elif kind == "rows":
                _, times, values, events, records, functions, floor_ps, now_ps, more = message
                result.now_s = now_ps * PS
                if bus is not None and len(records):
                    bus.append(records)
                ignored += [e for e in events if e["kind"] == "protected_write"][: 1 - len(ignored)]
                rows.add(feeder.window, rows.columns(times), values, events, records, floor_ps, functions)
                result.isr_rows = rows.count
                if more:
                    child.send(feeder.next_piece())
            elif kind == "failed":
                _, rc, text, offset, events = message
                if rc == 3:  # an ISR that never returned: an error event, the run ends as usual
                    where = f" (the ISR was at {_source_line(source, offset)})" if offset else ""
                    rows.add_events(
                        [_event(result.now_s, "isr_not_returned", f"{text}{where}")], feeder.window
                    )
                    continue
                if offset:
                    text += f" (the loop: {_source_line(source, offset)})"
                ignored += [e for e in events if e["kind"] == "protected_write"]
                if ignored:
                    text += f"; before it, at {ignored[0]['t_s']:.9f} s: {ignored[0]['message']}"
                _finish(result, rows, feeder, bus)
                raise FirmwareStopped(f"{source}: {text}", result)
            elif kind == "done":
                _, now_ps, accesses, blocks, final = message
                result.now_s = now_ps * PS
                result.accesses, result.blocks = accesses, blocks
                result.final = {g.name: v for g, v in zip(watched, final, strict=True)}
                _finish(result, rows, feeder, bus)
                return result
            elif kind == "error":
                raise message[1]
            elif kind == "internal":
                raise InternalError(f"{source}: the firmware's process failed:\n{message[1]}")


def _finish(result: FirmwareResult, rows: _Rows, feeder: _Feeder, bus: list[np.ndarray] | None) -> None:
    result.isr_rows = rows.count
    result.t0_s = feeder.t0 or 0.0
    result.truth = feeder.window.t is not None
    if bus is not None:
        result.bus = _bus_columns(np.concatenate(bus) if bus else np.zeros(0, BUS_RECORD))


def _event(t_s: float, kind: str, message: str) -> dict[str, Any]:
    return {
        "t_s": t_s,
        "kind": kind,
        "severity": "error",
        "message": message,
        "measured": None,
        "required": None,
        "frame": None,
    }


class FirmwareStopped(InputError):  # noqa: N818 (what happened to the run, as CheckFailed)
    """The firmware ended the run before the input did (a crash, ``abort``, ``exit``, a loop that can
    never end, an emulator error): exit 2. :attr:`result` holds what the run did up to there (its
    parts went to the sink)."""

    def __init__(self, message: str, result: FirmwareResult) -> None:
        super().__init__(message)
        self.result = result

    def __reduce__(self) -> tuple[Any, ...]:
        return (type(self), (str(self), self.result))


class _Child:
    """The firmware's process (:func:`sins_fw.firmware_child.start`) and the pipes to it: the parent
    kills it (SIGKILL) on the way out, whatever happened, and reaps it."""

    def __init__(self, job: Job) -> None:
        self.job = job
        self.pid = 0
        self.status: int | None = None

    def __enter__(self) -> _Child:
        ctx = multiprocessing.get_context("fork")
        self._commands_r, self._commands_w = ctx.Pipe(duplex=False)
        self._out_r, self._out_w = ctx.Pipe(duplex=False)
        # The crash report goes to an unlinked file (a pipe could fill while the parent waits).
        self._crash = tempfile.TemporaryFile(prefix="sins-fw-crash-")
        try:
            self.pid = start_child(
                self.job,
                self._commands_r,
                self._out_w,
                self._crash.fileno(),
                [self._commands_w.fileno(), self._out_r.fileno()],
            )
        finally:
            self._commands_r.close()
            self._out_w.close()
        return self

    def __exit__(self, *exc: object) -> None:
        self._reap(kill=True)
        self._commands_w.close()
        self._out_r.close()
        self._crash.close()

    def _reap(self, kill: bool) -> None:
        if self.status is not None or not self.pid:
            return
        if kill:
            with contextlib.suppress(ProcessLookupError):
                os.kill(self.pid, signal.SIGKILL)
        while True:
            try:
                _, self.status = os.waitpid(self.pid, 0)
                return
            except InterruptedError:
                continue
            except ChildProcessError:
                self.status = 0
                return

    def receive(self) -> tuple[Any, ...] | None:
        """The child's next message, None when it is gone (its end of the pipe closed)."""
        try:
            message: tuple[Any, ...] = self._out_r.recv()
        except EOFError:
            return None
        return message

    def send(self, message: tuple[Any, ...]) -> None:
        # A child gone shows at the next receive.
        with contextlib.suppress(BrokenPipeError, ConnectionResetError):
            self._commands_w.send(message)

    def stopped(
        self, source: Path, loaded: bool, result: FirmwareResult, rows: _Rows, feeder: _Feeder
    ) -> FirmwareStopped:
        """What ended the child, as the error of the run."""
        self._reap(kill=False)
        crash = _read_crash(self._crash.fileno(), len(rows.row_times))
        if crash is not None:  # what the run computed since it last handed it over
            rows.add(feeder.window, rows.columns(crash.times), crash.values, crash.events, crash.bus)
            if len(crash.times):
                end = crash.times[-1, rows.row_times.index("end_ps")]
                result.now_s = max(result.now_s, float(end) * PS)
        status = self.status or 0
        when = (
            f"at t = {result.now_s:.6f} s of the run"
            if loaded
            else "while the library loaded (its static constructors)"
        )
        where = describe_crash(source, crash)
        if os.WIFSIGNALED(status):
            sig = os.WTERMSIG(status)
            text = f"the firmware was killed by {_signal_text(sig, crash)} {when}{where}"
        else:
            code = os.WEXITSTATUS(status)
            if crash is not None and int(crash.record["signal"]) == 0:
                text = (
                    f"the firmware called exit({code}) {when}{where}: a firmware's main never returns to a "
                    "caller on the chip, and the run needs the emulator's process"
                )
            else:
                text = f"the firmware's process ended with status {code} {when}{where}"
        _finish(result, rows, feeder, None)
        return FirmwareStopped(f"{source}: {text}", result)


_SIGNAL_MEANING = {
    signal.SIGSEGV: "a bad memory access (a bad pointer, or the stack overflowed: endless recursion?)",
    signal.SIGBUS: "a bad memory access (misaligned, or a file mapping gone)",
    signal.SIGILL: "an illegal instruction",
    signal.SIGFPE: "an arithmetic fault (an integer division by zero?)",
    signal.SIGABRT: "abort(), or a failed assert()",
    signal.SIGTRAP: "a trap (__builtin_trap?)",
    signal.SIGKILL: "SIGKILL from outside (out of memory?)",
}


def _signal_text(sig: int, report: _Crash | None) -> str:
    try:
        name = signal.Signals(sig).name
    except ValueError:
        name = f"signal {sig}"
    meaning = _SIGNAL_MEANING.get(sig)
    text = f"{name} ({meaning})" if meaning else name
    if report is not None and sig in (signal.SIGSEGV, signal.SIGBUS) and int(report.record["signal"]) == sig:
        text += f", address 0x{int(report.record['fault_address']):x}"
    return text


@dataclass
class _Crash:
    """The runtime's crash report: the record, and what the run had computed and not yet handed over."""

    record: np.void
    times: np.ndarray
    values: np.ndarray
    events: list[dict[str, Any]]
    bus: np.ndarray


def _read_crash(fd: int, n_times: int) -> _Crash | None:
    """The runtime's crash report, if it wrote one (the child is gone)."""
    os.lseek(fd, 0, os.SEEK_SET)
    chunks = []
    while block := os.read(fd, 1 << 20):
        chunks.append(block)
    data = b"".join(chunks)
    if len(data) < CRASH_RECORD.itemsize:
        return None
    record = np.frombuffer(data, dtype=CRASH_RECORD, count=1)[0]
    if int(record["magic"]) != CRASH_MAGIC:
        return None
    pos = CRASH_RECORD.itemsize
    empty = _Crash(record, np.zeros((0, n_times), np.uint64), np.zeros((0, 0)), [], np.zeros(0, BUS_RECORD))

    def take(dtype: Any, count: int) -> np.ndarray | None:
        nonlocal pos
        size = np.dtype(dtype).itemsize * count
        if pos + size > len(data):
            return None
        out = np.frombuffer(data, dtype=dtype, count=count, offset=pos)
        pos += size
        return out

    head = take(np.uint64, 2)
    if head is None:
        return empty
    n, g = int(head[0]), int(head[1])
    times, values = take(np.uint64, n * n_times), take(np.float64, n * g)
    if times is None or values is None:
        return empty
    crash = _Crash(record, times.reshape(n, n_times), values.reshape(n, g), [], empty.bus)
    safe = take(np.uint64, 1)
    if safe is None or not int(safe[0]):
        return crash
    while (more := take(np.uint64, 1)) is not None and int(more[0]):
        e = take(CRASH_EVENT, 1)
        if e is None:
            return crash
        crash.events.append(
            {
                "t_s": int(e["t_ps"][0]) * PS,
                "kind": e["kind"][0].decode(errors="replace"),
                "severity": SEVERITIES[int(e["severity"][0])],
                "message": e["message"][0].decode(errors="replace"),
                "measured": None if np.isnan(e["measured"][0]) else float(e["measured"][0]),
                "required": None if np.isnan(e["required"][0]) else float(e["required"][0]),
                "frame": None if int(e["frame"][0]) < 0 else int(e["frame"][0]),
            }
        )
    bus = []
    while (k := take(np.uint64, 1)) is not None and int(k[0]):
        records = take(BUS_RECORD, int(k[0]))
        if records is None:
            break
        bus.append(records)
    crash.bus = np.concatenate(bus) if bus else empty.bus
    return crash


def describe_crash(library: Path, report: _Crash | None) -> str:
    """``, at file:line in function`` of the firmware's own code where a crash record points (the
    faulting instruction, else the innermost return address in the firmware that is not the
    runtime's), from the library's debug information (addr2line); empty without one."""
    if report is None or not int(report.record["base"]):
        return ""
    crash = report.record
    base = int(crash["base"])
    size = library.stat().st_size if library.is_file() else 0
    # The faulting instruction itself, then return addresses (one byte back lies in the call).
    candidates = [(int(crash["pc"]), 0)] if int(crash["pc"]) else []
    candidates += [(int(a), 1) for a in crash["frames"][: int(crash["n_frames"])]]
    for address, back in candidates:
        offset = address - base
        if not 0 < offset < size:
            continue
        line = _addr2line(library, offset - back)
        if line is not None and "sins_fw_runtime" not in line[0]:
            return f", at {line[0]} in {line[1]}"
    return ""


def _addr2line(library: Path, offset: int) -> tuple[str, str] | None:
    """(``file:line``, function) of a code offset in the library (addr2line from binutils)."""
    tool = shutil.which("addr2line")
    if tool is None:
        return None
    run = subprocess.run(
        [tool, "-e", str(library), "-f", "-C", "-i", hex(offset)], capture_output=True, text=True, check=False
    )
    lines = run.stdout.splitlines()
    if run.returncode != 0 or len(lines) < 2 or lines[1].startswith("??"):
        return None
    # The prelude renames the firmware's main (sins_fw_prelude.h): name it as the source does.
    function = "main" if lines[0].split("(")[0] == "sins_fw_user_main" else lines[0]
    return lines[1].split(" ")[0], function


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
    """``file:line in function`` of a code offset in the library (addr2line from binutils), else the
    offset. The runtime reports the return address of the block's call: one byte back is inside it."""
    line = _addr2line(library, offset - 1)
    return f"{line[0]} in {line[1]}" if line is not None else f"offset 0x{offset:x} of the library"


class _Feeder:
    """The trace, a piece at a time, as the firmware's process asks for more (the parent reads the
    trace: the child sees only the columns it pushes into the board)."""

    def __init__(self, trace: Any, until_s: float | None, on_chunk: Callable[[float], None] | None) -> None:
        self.until_s, self.on_chunk = until_s, on_chunk
        self.t0: float | None = None
        self.window = _TruthWindow()
        self.pieces = self._pieces(_still_trace(until_s or 1.0) if trace is None else trace)

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

    def next_piece(self) -> tuple[Any, ...]:
        """The next message for the child: ``("piece", columns)`` or ``("end",)``."""
        piece = next(self.pieces, None)
        if piece is None:
            return ("end",)
        chunk, t, s = piece

        def arr(a: np.ndarray | None) -> Any:
            return None if a is None else np.ascontiguousarray(a[s], dtype=np.float64)

        cols = [
            np.ascontiguousarray(t[s]),
            arr(chunk.gyro_dps),
            arr(chunk.accel_g),
            arr(chunk.mag_gauss),
            arr(chunk.baro_mbar),
            arr(chunk.temp_c),
        ]
        if chunk.truth_q is not None:
            self.window.feed(cols[0], chunk.truth_q[s], None if chunk.moving is None else chunk.moving[s])
        if self.on_chunk is not None:
            self.on_chunk(float(chunk.t_s[s][-1]))
        return ("piece", cols)


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


class _Rows:
    """Turns the runtime's ISR rows into parts of a run (and keeps the last values)."""

    def __init__(self, watched: list[Global], sink: Callable[[dict[str, Any]], None] | None) -> None:
        self.watched, self.sink = watched, sink
        self.count = 0
        self.prev_end = 0
        #: The tick of the last ISR row (a row's tick beyond the next: the ticks between were lost).
        self.prev_tick = 0
        #: Bus-log records that may still matter to an ISR row not yet turned into a part: those from
        #: the firmware process's floor on (the entry of the ISR running, else the time reached), in
        #: pieces joined only when rows need them. So the records kept stay those of one ISR and
        #: the work per piece of input stays bounded, SPI inside or outside an interrupt.
        self.bus: list[np.ndarray] = []
        #: The names of an ISR row's times, in the runtime's order (its ``sins_fw_row_times``, which the
        #: firmware's process reports when it has loaded the library).
        self.row_times: tuple[str, ...] = ()
        self.has_quat = all(f"q{i}" in {g.column for g in watched} for i in range(4))
        #: The watched globals' columns that are attitude components: (value column, core column, k).
        self.attitude = [(i, *ATTITUDE[g.column]) for i, g in enumerate(watched) if g.column in ATTITUDE]

    def columns(self, times: np.ndarray) -> dict[str, np.ndarray]:
        """An (n, k) array of the runtime's ISR row times as columns by name."""
        return {name: times[:, i] for i, name in enumerate(self.row_times)}

    def add(
        self,
        window: _TruthWindow,
        times: dict[str, np.ndarray],
        values: np.ndarray,
        events: list[dict[str, Any]],
        bus: np.ndarray,
        floor_ps: int = 0,
        functions: np.ndarray | None = None,
    ) -> None:
        n = len(values)
        if len(bus):
            self.bus.append(bus)
        if n or events:
            part = self._part(times, values, events)
            part["firmware_functions"] = self._functions(times, functions)
            self.count += n
            if self.has_quat and window.t is not None and n:
                window.attach(part)
            if self.sink is not None:
                self.sink(part)
        if floor_ps and self.bus:
            self._trim(floor_ps)

    def _functions(self, times: dict[str, np.ndarray], functions: np.ndarray | None) -> np.ndarray:
        """The per-function records of this part's ISR rows (the runtime's, by row index in the run)
        by the tick of their row: :data:`FUNCTION_TICKS`."""
        if functions is None or not len(functions):
            return np.zeros(0, FUNCTION_TICKS)
        local = functions["row"].astype(np.int64) - self.count
        ok = (local >= 0) & (local < len(times["tick"]))
        out = np.zeros(int(ok.sum()), FUNCTION_TICKS)
        out["tick"] = times["tick"][local[ok]]
        for k in ("function", "self", "calls", "inclusive"):
            out[k] = functions[k][ok]
        return out

    def add_events(self, events: list[dict[str, Any]], window: _TruthWindow) -> None:
        """A part of events alone (no ISR row)."""
        times = {name: np.zeros(0, np.uint64) for name in self.row_times}
        self.add(window, times, np.zeros((0, len(self.watched))), events, np.zeros(0, BUS_RECORD))

    def _records(self) -> np.ndarray:
        if len(self.bus) != 1:
            self.bus = [np.concatenate(self.bus) if self.bus else np.zeros(0, BUS_RECORD)]
        return self.bus[0]

    def _trim(self, floor_ps: int) -> None:
        """Drop the records before ``floor_ps``: no ISR row still to come starts before it."""
        last = self.bus[-1]
        if len(last) and int(last["t_ps"][-1]) < floor_ps:
            self.bus = []
            return
        rec = self._records()
        self.bus = [rec[rec["t_ps"] >= floor_ps]]

    def _part(
        self, col: dict[str, np.ndarray], values: np.ndarray, events: list[dict[str, Any]]
    ) -> dict[str, Any]:
        budget = self._budget(col)
        n = len(values)
        quat = np.full((n, 4), np.nan)
        euler = np.full((n, 3), np.nan)
        for i, core, k in self.attitude:
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
        rec = self._records()
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
            self.bus = [rec[rec["t_ps"] > hi[-1]]]
        return start, end

    def _budget(self, col: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """One budget row per ISR, in the Rust model's columns: the entry (context save and prologue),
        the wait for CS and the first frame (`cs_setup`), the SPI transfers and their register waits
        (`spi`, from the bus log: :meth:`_spi_stage`), the rest of the ISR's body as the `decode`
        stage (the runtime cannot tell the decode from the attitude code), the exit. A tick whose
        interrupt was never taken (the core's `tick_lost` event) is a skipped row, as in the model's
        budget (`BudgetRow::skipped`: every time at its arrival, flagged overrun); a tick that came
        while the previous ISR ran (the core's `overrun` event) is flagged overrun."""
        u = {k: v.astype(np.uint64) for k, v in col.items()}
        u = self._with_lost_ticks(u)
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
        # A tick that arrived while the previous ISR was still running, and a tick never run.
        skipped = u["deadline_ps"] == u["tick_ps"]
        ends = np.maximum.accumulate(np.r_[self.prev_end, u["end_ps"]].astype(np.uint64))
        b["overrun"] = ((u["tick_ps"] < ends[:-1]) | skipped).astype(np.uint8)
        b["step"] = (~skipped).astype(np.uint8)
        if len(u["tick"]):
            self.prev_end = int(ends[-1])
        return b

    def _with_lost_ticks(self, u: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """The rows with a skipped row before each for every tick lost since the row before (its
        tick number missing): at its arrival, counted back from the row's tick at the row's period."""
        ticks = u["tick"].astype(np.int64)
        prev = np.r_[self.prev_tick, ticks[:-1]]
        gaps = np.maximum(ticks - prev - 1, 0)
        if len(ticks):
            self.prev_tick = int(ticks[-1])
        if not gaps.any():
            return u
        row = np.repeat(np.arange(len(ticks)), gaps + 1)
        first = np.cumsum(gaps + 1) - (gaps + 1)
        back = (first + gaps)[row] - np.arange(len(row))  # ticks before the row's own
        period = u["deadline_ps"].astype(np.int64) - u["tick_ps"].astype(np.int64)
        lost = back > 0
        out = {k: v[row].copy() for k, v in u.items()}
        at = (u["tick_ps"].astype(np.int64)[row] - back * period[row]).astype(np.uint64)
        for k in out:
            if k.endswith("_ps"):
                out[k][lost] = at[lost]
        out["tick"][lost] = (ticks[row] - back)[lost].astype(out["tick"].dtype)
        return out


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
        self.schema = firmware_run_schema(
            [
                (g.column, g.unit, g.description or f"firmware global `{g.name}` after the ISR")
                for g in watched
            ]
        )

    def record_float_mode(self, float_mode: str) -> None:
        """Record the float mode the firmware was built with (``float_mode`` metadata): called when
        the library is loaded, before any row, so before the metadata is written."""
        if self._writer is not None:
            raise InternalError("the float mode came after the run output's metadata was written")
        self.metadata = {**self.metadata, "float_mode": float_mode}

    def _columns(self, part: dict[str, Any]) -> dict[str, np.ndarray]:
        cols = {"t_s": part["cycle_t_ps"].astype(np.float64) * PS}
        cols.update(part["firmware_globals"])
        return cols


def firmware_metadata(library: str | os.PathLike[str], globals_file: Path | None) -> dict[str, str]:
    """What a run output records of the firmware."""
    meta = {"firmware": str(Path(library)), "created_by": FIRMWARE_CREATED_BY}
    if globals_file is not None:
        meta["globals"] = str(globals_file)
    return meta


__all__ = [
    "FirmwareResult",
    "FirmwareRunWriter",
    "FirmwareStopped",
    "FrameDifference",
    "Global",
    "default_globals",
    "firmware_metadata",
    "first_frame_difference",
    "load_globals",
    "run_c_firmware",
]
