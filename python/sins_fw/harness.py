"""The harness: feed a physical trace to the emulated board and collect what the firmware produced.

``emulate(trace, profile)`` streams the trace into the Rust core in chunks (whole numpy arrays, never
a Python call per sample) and returns a :class:`Run` of numpy arrays: one row per attitude step, per
burst read and per timer tick, and the events. Trace time is shifted so that its first sample is the
board's power-on instant (virtual time 0); ``Run.t0_s`` keeps the shift.

A raw-register trace (:class:`RawRegisterTrace`, or a file whose metadata or columns say so) is
replayed instead: the device model is bypassed and each burst read gets the next recorded burst's 15
words, so the firmware sees exactly what was recorded (docs/traces.md, "Replaying a raw-register
trace"). Its timestamps are taken as virtual time since power-on, unshifted (``Run.t0_s`` = 0).
"""

from __future__ import annotations

import json
import math
import os
import tomllib
from collections import Counter
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sins_fw import _core
from sins_fw.alignment import ALIGNMENTS, aligned_estimate
from sins_fw.errors import InputError, ProfileError, TraceError, utf8_text
from sins_fw.metrics import AttitudeErrors, attitude_errors, valid_mask
from sins_fw.profile import MODEL_DIR, Profile, check_overrides, cost_table_text, load_profile, short
from sins_fw.tablefile import rate_text
from sins_fw.traces import (
    CheckedTrace,
    PhysicalTrace,
    RawRegisterTrace,
    gps_fixes,
    gps_latency_s,
    is_raw_register_trace,
    validated,
)

PS = 1e-12
#: Rows per chunk read from a trace (file): big enough to amortise the reading, small enough for memory.
CHUNK_ROWS = 1 << 16
#: Rows per push into the core: big enough to amortise the call (a few µs), small enough that the
#: core's copy of the input and each run's output rows stay in cache and in memory the allocator
#: reuses. Measured on the 240 s bench run: 8 500 page faults per call with 1 << 16 rows, 5 500 with
#: 1 << 13 (each 1-2 µs of system time on the benchmark VM), 5 000-6 400 with 1 << 11 … 1 << 14.
FEED_ROWS = 1 << 13

Array = NDArray[np.float64]


@dataclass
class Run:
    """What the emulated firmware produced. Times are seconds of virtual time (``*_ps`` arrays keep
    the exact integer picoseconds)."""

    profile: Profile
    t0_s: float
    # One row per attitude step.
    time_s: Array
    step: NDArray[np.uint64]
    quat: Array
    euler_deg: Array
    velocity_enu: Array
    position: Array
    # One row per burst read.
    read_tick: NDArray[np.uint64]
    #: CS falling edge of each burst (the time a raw-register trace records).
    read_t_cs_ps: NDArray[np.uint64]
    read_t_start_ps: NDArray[np.uint64]
    read_t_end_ps: NDArray[np.uint64]
    read_words: NDArray[np.uint16]
    read_rate: Array
    read_accel: Array
    read_sample_index: NDArray[np.int64]
    read_sample_ps: NDArray[np.uint64]
    read_assumed_s: Array
    read_age_ps: NDArray[np.uint64]
    # One row per timer tick (budget); keys are the core's `budget_*` columns without the prefix.
    budget: dict[str, NDArray[Any]]
    events: list[dict[str, Any]]
    stage_cycles: dict[str, int]
    truth_q: Array | None = None
    moving: NDArray[np.bool_] | None = None
    #: The truth at the trace's first sample, the board's power-on instant (None without truth).
    truth_q0: Array | None = None
    held_input_reads: int = 0
    extra: dict[str, Any] = field(default_factory=dict)
    #: The SPI bus log of the ticks ``bus_window`` asked for (see :func:`emulate`): ``cs_t_ps``,
    #: ``cs_low`` per CS edge; ``frame_*`` per frame (index, start/end, first/last SCLK edge, DIN, DOUT…).
    bus: dict[str, NDArray[Any]] | None = None
    #: The DCM's drift-cancellation terms, one row per step (the core's `dcm_*` columns without the
    #: prefix: ``step``, ``omega_p``, ``omega_i`` rad/s, ``error_rp``, ``error_yaw``, ``orthogonality``);
    #: empty for the open-loop algorithms.
    dcm: dict[str, NDArray[Any]] = field(default_factory=dict)
    #: The wing unit's rows, one per step (the core's `wing_*` columns without the prefix: ``step``,
    #: ``alpha_deg``, ``axis``, ``axis_source``, ``at_rest``); empty for the other algorithms.
    wing: dict[str, NDArray[Any]] = field(default_factory=dict)
    #: The trace's hinge angle truth at the step times, degrees, and whether it is still there
    #: (:func:`alpha_truth_at`); None when the trace has no ``truth_alpha_deg``.
    truth_alpha_deg: Array | None = None
    alpha_still: NDArray[np.bool_] | None = None

    @property
    def cycles(self) -> int:
        """Number of attitude steps."""
        return len(self.time_s)

    def events_by_kind(self) -> dict[str, int]:
        return dict(sorted(Counter(e["kind"] for e in self.events).items()))

    def errors(self, align: str = "auto") -> AttitudeErrors:
        """The attitude errors against the trace's truth, in degrees, one per step (NaN where the
        truth is unknown): ``roll``, ``pitch``, ``yaw`` (estimate − truth, wrapped to (−180, 180]),
        ``total`` (the rotation angle between them) and BROAD's ``heading`` and ``inclination``.
        The estimate is first aligned to the truth as every report aligns it (``align``: auto,
        initial, heading or none; :func:`sins_fw.alignment.aligned_estimate`). InputError when the
        trace has no truth."""
        if self.truth_q is None:
            raise InputError("Run.errors(): the trace has no truth attitude to compare with")
        if align not in ALIGNMENTS:
            raise InputError(f"Run.errors(align={align!r}): expected one of {', '.join(ALIGNMENTS)}")
        est, _ = aligned_estimate(self, align)
        valid = valid_mask(self.truth_q)
        e = attitude_errors(est[valid], self.truth_q[valid])
        out = {}
        for name in ("total", "heading", "inclination", "roll", "pitch", "yaw"):
            full = np.full(len(valid), np.nan)
            full[valid] = getattr(e, name)
            out[name] = full
        return AttitudeErrors(**out)

    @property
    def busy_s(self) -> Array:
        """ISR busy time per tick."""
        b = self.budget
        return (b["end_ps"].astype(np.float64) - b["start_ps"].astype(np.float64)) * PS

    @property
    def margin_s(self) -> Array:
        """Time left before the next tick when each ISR ended (negative: overrun)."""
        b = self.budget
        return (b["deadline_ps"].astype(np.float64) - b["end_ps"].astype(np.float64)) * PS

    @property
    def read_age_s(self) -> Array:
        return self.read_age_ps.astype(np.float64) * PS

    def raw_register_trace(self, metadata: Mapping[str, str] | None = None) -> RawRegisterTrace:
        """The words the firmware read, as a raw-register trace: one row per burst, timestamped at
        its CS falling edge (virtual time since power-on), the 15 SPIRXBUF words. Replaying it
        (``emulate(raw)``) gives the firmware exactly these words again. ``sample_rate_hz`` is the
        timer tick rate (one burst per tick; back-to-back reads three within each tick)."""
        if metadata is not None and not (
            isinstance(metadata, Mapping)
            and all(isinstance(k, str) and isinstance(v, str) for k, v in metadata.items())
        ):
            raise InputError(f"metadata = {short(metadata)}: expected a mapping of texts to texts, or None")
        ticks = self.budget["tick_ps"]
        if len(ticks) < 2:
            raise InputError("raw-register trace: the run is too short (fewer than two timer ticks)")
        rate = Fraction(10**12, int(ticks[1]) - int(ticks[0]))
        meta = {"sample_rate_hz": rate_text(rate), **(metadata or {})}
        return RawRegisterTrace(
            t_s=self.read_t_cs_ps.astype(np.float64) / 1e12,
            words=np.ascontiguousarray(self.read_words, dtype=np.uint16),
            metadata=meta,
        )

    @property
    def isr_ran(self) -> NDArray[np.bool_]:
        """Per budget row: the tick's ISR ran (False for a tick lost or dropped by an overrun, whose
        row has no ISR times)."""
        return self.budget["deadline_ps"] > self.budget["tick_ps"]


def has_dcm(profile: Profile) -> bool:
    """Whether the profile's attitude algorithm reports drift-cancellation terms (the core's `dcm_*`
    rows, :attr:`Run.dcm`): the DCM. Known before the run, so that a file or a viewer layout can
    make room for them from the start."""
    return profile.get("firmware.algorithm") == "dcm"


def has_wing(profile: Profile) -> bool:
    """Whether the profile runs the wing-angle unit (the core's `wing_*` rows, :attr:`Run.wing`)."""
    return profile.get("firmware.algorithm") == "wing"


def alpha_truth_at(t: Array, alpha_deg: Array, at: Array) -> tuple[Array, NDArray[np.bool_]]:
    """The hinge angle truth (degrees) at times ``at``, linearly interpolated (NaN outside the trace),
    and whether the hinge is still there: the trace's rows around the time and the row before them hold
    the same α (the synthetic flap profiles hold α exactly constant at rest)."""
    out = np.full(len(at), np.nan)
    still = np.zeros(len(at), dtype=bool)
    if len(t) < 3:
        return out, still
    i = np.clip(np.searchsorted(t, at, side="right") - 1, 1, len(t) - 2)
    inside = (at >= t[0]) & (at <= t[-1])
    out[inside] = np.interp(at[inside], t, alpha_deg)
    still[inside] = ((alpha_deg[i - 1] == alpha_deg[i]) & (alpha_deg[i] == alpha_deg[i + 1]))[inside]
    return out, still


#: What `emulate` accepts: a whole trace, a trace file, or an iterable of consecutive chunks (a
#: generator of PhysicalTrace, for inputs too long to hold in memory); a raw-register trace or file
#: is replayed.
TraceInput = (
    PhysicalTrace | CheckedTrace | RawRegisterTrace | str | os.PathLike[str] | Iterable[PhysicalTrace]
)


def check_until_s(value: Any, name: str = "until_s") -> float | None:
    """``until_s`` (the API's argument, ``run --until-s``, a run output's ``until_s``) as seconds:
    None, or a finite number > 0 (an int or float, numpy's included). Anything else is an
    :class:`~sins_fw.errors.InputError` naming ``name`` and what was expected."""
    if value is None:
        return None
    number = isinstance(value, int | float | np.integer | np.floating) and not isinstance(
        value, bool | np.bool_
    )
    if not (number and math.isfinite(value) and value > 0):
        raise InputError(f"{name} = {value!r}: expected a finite number of seconds > 0")
    return float(value)


def _check_trace_argument(trace: Any) -> None:
    """Refuse, before any work, a ``trace`` that is none of what :data:`TraceInput` lists."""
    if isinstance(trace, PhysicalTrace | RawRegisterTrace | str | os.PathLike):
        return
    if isinstance(trace, Iterable) and not isinstance(trace, bytes | bytearray | np.ndarray | Mapping):
        return  # chunks: each is checked as it comes (_slices)
    hint = " (wrap arrays in a PhysicalTrace)" if isinstance(trace, np.ndarray) else ""
    raise TraceError(
        f"trace = {short(trace)}: expected a PhysicalTrace, a RawRegisterTrace, a trace file path "
        f"(str or Path), or an iterable of PhysicalTrace chunks{hint}"
    )


def check_bus_window(window: Any, name: str = "bus_window") -> tuple[int, int]:
    """``(first_tick, last_tick)``: two whole numbers, 1 <= first <= last (ticks count from 1); else an
    InputError naming ``name`` and what was expected."""
    expected = "expected (first_tick, last_tick), two whole numbers with 1 <= first <= last"
    if isinstance(window, str | bytes) or not isinstance(window, Iterable):
        raise InputError(f"{name} = {short(window)}: {expected}")
    ticks = list(window)
    if len(ticks) != 2 or not all(
        isinstance(t, int | np.integer) and not isinstance(t, bool | np.bool_) for t in ticks
    ):
        raise InputError(f"{name} = {short(window)}: {expected}")
    first, last = (int(t) for t in ticks)
    if not 1 <= first <= last:
        raise InputError(f"{name} = {short(window)}: {expected} (ticks count from 1)")
    return first, last


def _check_flag(value: Any, name: str) -> bool:
    if not isinstance(value, bool | np.bool_):
        raise InputError(f"{name} = {short(value)}: expected True or False")
    return bool(value)


def _raw_chunks(trace: RawRegisterTrace | str | os.PathLike[str], rows: int) -> Iterator[RawRegisterTrace]:
    if isinstance(trace, RawRegisterTrace):
        trace.validate(allow_gaps=True)
        for i in range(0, len(trace), rows):
            yield RawRegisterTrace(t_s=trace.t_s[i : i + rows], words=trace.words[i : i + rows])
    else:
        # Gaps are a fact of a recording (a lost tick, a pause in the log), not a defect to refuse.
        yield from RawRegisterTrace.iter_chunks(trace, rows, allow_gaps=True)


def _chunks(trace: TraceInput, rows: int, allow_gaps: bool = False) -> Iterator[PhysicalTrace]:
    """The trace in chunks of at most ``rows`` rows, validated as a file is on load (a file by its
    loader, a trace or chunks in memory by :func:`sins_fw.traces.validated`, the same checks)."""
    if isinstance(trace, str | os.PathLike):
        yield from PhysicalTrace.iter_chunks(trace, rows, allow_gaps=allow_gaps)
    else:
        yield from validated(_slices(trace, rows), allow_gaps=allow_gaps)


def _slices(trace: PhysicalTrace | Iterable[PhysicalTrace], rows: int) -> Iterator[PhysicalTrace]:
    """A trace in memory (or consecutive chunks of one) as slices of at most ``rows`` rows."""
    if not isinstance(trace, PhysicalTrace):
        for i, chunk in enumerate(trace):
            if not isinstance(chunk, PhysicalTrace):
                raise TraceError(
                    f"trace chunk {i} = {short(chunk)}: expected a PhysicalTrace (an iterable of traces "
                    "is taken as consecutive chunks of one trace)"
                )
            yield from _slices(chunk, rows)
        return
    for i in range(0, len(trace), rows):
        s = slice(i, i + rows)
        yield PhysicalTrace(
            t_s=trace.t_s[s],
            gyro_dps=trace.gyro_dps[s],
            accel_g=trace.accel_g[s],
            mag_gauss=None if trace.mag_gauss is None else trace.mag_gauss[s],
            baro_mbar=None if trace.baro_mbar is None else trace.baro_mbar[s],
            temp_c=None if trace.temp_c is None else trace.temp_c[s],
            truth_q=None if trace.truth_q is None else trace.truth_q[s],
            moving=None if trace.moving is None else trace.moving[s],
            metadata=trace.metadata,
            gps=None if trace.gps is None else trace.gps[s],
            truth_alpha_deg=None if trace.truth_alpha_deg is None else trace.truth_alpha_deg[s],
        )


def new_emulator(profile: Profile, *, replay: bool = False) -> Any:
    """A fresh `_core.Emulator` for a profile (``replay=True``: reading recorded burst words)."""
    costs, costs_source = cost_table_text(profile)
    return _core.Emulator(
        profile.text, profile.source, list(profile.overrides), costs, costs_source, replay=replay
    )


def keyword_overrides(settings: Mapping[str, Any]) -> list[str]:
    """Keyword profile overrides as ``key=value`` texts: ``spi__spibrr=9`` → ``spi.spibrr=9``.

    ``__`` stands for the dot of the dotted key; values are written as TOML (strings quoted, bools
    ``true``/``false``, lists as arrays).
    """
    out = []
    for name, value in settings.items():
        if "__" not in name:
            raise ProfileError(
                f"unknown keyword argument `{name}`: profile overrides are written section__key=value "
                "(e.g. spi__spibrr=9 for spi.spibrr)"
            )
        out.append(f"{name.replace('__', '.')}={_toml_value(value, name)}")
    return out


def _toml_value(value: Any, name: str) -> str:
    if isinstance(value, bool | np.bool_):
        return "true" if value else "false"
    if isinstance(value, int | float | np.integer | np.floating):
        return repr(value.item() if isinstance(value, np.generic) else value)
    if isinstance(value, str):
        return json.dumps(value)  # a TOML basic string is a JSON string for these values
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_toml_value(v, name) for v in value) + "]"
    raise ProfileError(f"keyword override `{name}` = {value!r}: expected a number, bool, string or list")


def emulate(
    trace: TraceInput,
    profile: Profile | str = "reference",
    *,
    overrides: Iterable[str] = (),
    chunk_rows: int = CHUNK_ROWS,
    on_chunk: Callable[[float], None] | None = None,
    keep_truth: bool = True,
    bus_window: tuple[int, int] | None = None,
    sink: Callable[[dict[str, Any]], None] | None = None,
    until_s: float | None = None,
    allow_gaps: bool = False,
    **settings: Any,
) -> Run:
    """Emulate the board of ``profile`` on ``trace`` (a PhysicalTrace, a CheckedTrace, a trace file, or
    an iterable of consecutive PhysicalTrace chunks).

    Profile overrides come as ``key=value`` texts in ``overrides`` and/or as keywords with ``__`` for
    the dot, applied after them: ``emulate(trace, spi__spibrr=9, firmware__numeric="iq")`` is
    ``emulate(trace, overrides=["spi.spibrr=9", "firmware.numeric=iq"])``. ``on_chunk`` is called
    with the trace time reached after each chunk (for progress bars). ``bus_window=(first_tick,
    last_tick)`` records the SPI bus (CS edges and frames) of the ISRs of those timer ticks into
    ``Run.bus``; the log is on only around the window, so a long run stays fast and small.

    ``sink`` streams the output instead of keeping it. A Run keeps about 630 bytes per attitude
    step (its row, and the two timer ticks and two burst reads of the reference's 4 ms timer):
    measured on a 1000 s trace at 819.2 SPS, 79 MB of arrays and a peak 190 MB above the
    process's baseline, so a 24-hour trace (10.8 M steps) would keep about 6.8 GB and peak near
    16 GB. With a sink, a 24-hour `sins-fw run` peaks under 300 MB (benchmarks/peak_rss.md). It is
    called with the output of each piece of input pushed (at most FEED_ROWS rows) or
    block of ticks run, a dict of numpy arrays keyed ``cycle_*``, ``read_*``, ``budget_*`` (the
    columns of :class:`Run`, times in integer ps) plus ``events``, and, when the trace has a truth
    and ``keep_truth``, ``truth_q`` and ``moving`` at the steps' times (the values ``Run.truth_q``
    and ``Run.moving`` would hold) and ``truth_q0``; the returned Run then holds no rows (every
    array empty, no truth) and memory stays flat.

    ``until_s`` emulates only the trace's first ``until_s`` seconds (rows at most that long after the
    first one; for a raw-register trace, bursts recorded up to that virtual time).

    Accepted types, checked before any work (each refusal names the argument and what was expected):
    ``trace`` as above (a :class:`~sins_fw.errors.TraceError` otherwise, e.g. for ``None``, a list of
    numbers or a bare numpy array; the arrays of a PhysicalTrace are converted as its docstring says);
    ``profile`` a :class:`~sins_fw.profile.Profile`, a profile name or a path
    (:class:`~sins_fw.errors.ProfileError` otherwise); ``overrides`` a list (any iterable) of
    ``key=value`` texts, never one bare text (ProfileError); ``until_s`` None or a finite number > 0,
    ``chunk_rows`` a whole number >= 1, ``on_chunk`` and ``sink`` functions or None, ``bus_window``
    None or two whole numbers 1 <= first <= last, ``keep_truth`` and ``allow_gaps`` True or False
    (:class:`~sins_fw.errors.InputError`). ``until_s`` is checked by :func:`check_until_s`, as
    ``run --until-s`` and a run output's ``until_s`` are.

    A physical trace is validated as it streams in, the same way whether it is a file or in memory
    (:class:`~sins_fw.errors.TraceError` naming the row and column): ``allow_gaps`` accepts time steps
    longer than 1.5 sample periods (the device sees the input interpolated across them). A
    :class:`~sins_fw.traces.CheckedTrace` passed those checks when it was made and is not checked
    again (a trace many runs share is checked once).

    A :class:`RawRegisterTrace` or a raw-register trace file is replayed through the firmware (the
    device model is bypassed; its recorded timestamps are the reads' sample times); profile faults
    cannot apply to it (they act on the device model) and are refused.
    """
    checked = isinstance(trace, CheckedTrace)
    if checked:  # checked once where it was made, and unchangeable since (see CheckedTrace)
        trace = trace.trace
    _check_trace_argument(trace)
    until_s = check_until_s(until_s)
    if isinstance(chunk_rows, bool) or not isinstance(chunk_rows, int | np.integer) or chunk_rows < 1:
        raise InputError(f"chunk_rows = {short(chunk_rows)}: expected a whole number of rows >= 1")
    for name, fn in (("on_chunk", on_chunk), ("sink", sink)):
        if fn is not None and not callable(fn):
            raise InputError(f"{name} = {short(fn)}: expected a function or None")
    keep_truth = _check_flag(keep_truth, "keep_truth")
    allow_gaps = _check_flag(allow_gaps, "allow_gaps")
    if bus_window is not None:
        bus_window = check_bus_window(bus_window)
    every = [*check_overrides(overrides), *keyword_overrides(settings)]
    if isinstance(profile, Profile):
        prof = profile.with_overrides(*every) if every else profile
    elif isinstance(profile, str | os.PathLike):
        prof = load_profile(profile, every)  # validated once, overrides included
    else:
        raise ProfileError(
            f"profile = {short(profile)}: expected a Profile, a profile name (e.g. 'reference') or the "
            "path of a profile TOML file"
        )
    replay = isinstance(trace, RawRegisterTrace) or (
        isinstance(trace, str | os.PathLike) and is_raw_register_trace(trace)
    )
    emu = new_emulator(prof, replay=replay)
    bus = _BusWindow(emu, prof, bus_window) if bus_window is not None else None
    if replay:
        assert isinstance(trace, RawRegisterTrace | str | os.PathLike)
        return _replay(emu, prof, trace, chunk_rows, on_chunk, bus, sink, until_s)
    if isinstance(trace, PhysicalTrace) and len(trace) and sink is None and bus is None:
        # The whole trace is here and the output is taken once: the emulator sizes its output for it.
        end = float(trace.t_s[-1] - trace.t_s[0])
        emu.expect_input_until(end if until_s is None else min(end, until_s))
    parts: list[dict[str, Any]] = []
    window = _TruthWindow() if sink is not None and keep_truth else None
    truth: list[Array] = []
    moving: list[NDArray[np.bool_]] = []
    truth_t: list[Array] = []
    alphas: list[Array] = []
    t0: float | None = None
    truth_q0: Array | None = None
    chunks = _slices(trace, chunk_rows) if checked else _chunks(trace, chunk_rows, allow_gaps)
    for chunk in chunks:
        if len(chunk) == 0:
            continue
        if t0 is None:
            t0 = float(chunk.t_s[0])
        if until_s is not None and chunk.t_s[-1] - t0 > until_s:
            n = int(np.searchsorted(chunk.t_s - t0, until_s, side="right"))
            if n == 0:
                break
            chunk = next(_slices(chunk, n))
        t = np.ascontiguousarray(chunk.t_s - t0)
        fixes = gps_fixes(chunk, t)
        if fixes is not None:  # before the chunk's input: every fix is there before it is due
            emu.push_gps(fixes[0], gps_latency_s(chunk.metadata, "trace metadata"), fixes[1], fixes[2])
        for s in _pieces(t, bus):
            if window is not None and chunk.truth_q is not None:
                window.feed(
                    t[s],
                    chunk.truth_q[s],
                    None if chunk.moving is None else chunk.moving[s],
                    _alpha(chunk, s),
                )
            emu.push(
                t[s],
                np.ascontiguousarray(chunk.gyro_dps[s]),
                np.ascontiguousarray(chunk.accel_g[s]),
                None if chunk.mag_gauss is None else np.ascontiguousarray(chunk.mag_gauss[s]),
                None if chunk.baro_mbar is None else np.ascontiguousarray(chunk.baro_mbar[s]),
                None if chunk.temp_c is None else np.ascontiguousarray(chunk.temp_c[s]),
            )
            # The emulator holds the output (in columns) until `take`: one take at the end gives the
            # Run without concatenating, unless the bus window watches the ticks or a sink streams
            # (then each piece's output is taken: what a sink receives is bounded by FEED_ROWS).
            _run(emu, parts, sink, bus, window)
        if keep_truth and sink is None and chunk.truth_q is not None:
            if not truth:
                truth_q0 = chunk.truth_q[0].copy()
            truth.append(chunk.truth_q)
            truth_t.append(t)
            if chunk.moving is not None:
                moving.append(chunk.moving)
            if chunk.truth_alpha_deg is not None:
                alphas.append(chunk.truth_alpha_deg)
        if on_chunk is not None:
            on_chunk(float(chunk.t_s[-1]))
        if until_s is not None and chunk.t_s[-1] - t0 >= until_s:
            break
    run = _finish(emu, prof, t0 or 0.0, parts, sink, bus, window)
    run.truth_q0 = truth_q0
    if truth:
        tt = np.concatenate(truth_t)
        run.truth_q = _truth_at(tt, np.concatenate(truth), run.time_s)
        if moving:
            mv = np.concatenate(moving)
            idx = np.clip(np.searchsorted(tt, run.time_s, side="right") - 1, 0, len(tt) - 1)
            run.moving = mv[idx]
        if alphas:
            run.truth_alpha_deg, run.alpha_still = alpha_truth_at(tt, np.concatenate(alphas), run.time_s)
    return run


def _replay(
    emu: Any,
    prof: Profile,
    trace: RawRegisterTrace | str | os.PathLike[str],
    chunk_rows: int,
    on_chunk: Callable[[float], None] | None,
    bus: _BusWindow | None,
    sink: Callable[[dict[str, Any]], None] | None,
    until_s: float | None,
) -> Run:
    """Feed recorded bursts to a replaying emulator (see :func:`emulate`)."""
    parts: list[dict[str, Any]] = []
    for chunk in _raw_chunks(trace, chunk_rows):
        t = np.ascontiguousarray(chunk.t_s, dtype=np.float64)
        words = np.ascontiguousarray(chunk.words, dtype=np.uint16)
        if until_s is not None:
            n = int(np.searchsorted(t, until_s, side="right"))
            t, words = t[:n], words[:n]
        for s in _pieces(t, bus):
            emu.push_words(t[s], np.ascontiguousarray(words[s]))
            _run(emu, parts, sink, bus)
        if on_chunk is not None and len(t):
            on_chunk(float(t[-1]))
        if until_s is not None and len(t) < len(chunk):
            break
    return _finish(emu, prof, 0.0, parts, sink, bus)


def _pieces(t: Array, bus: _BusWindow | None) -> Iterator[slice]:
    """A chunk's rows (times ``t``) as the slices pushed into the core: at most FEED_ROWS each, and
    cut where the bus window switches the log on."""
    for lo in range(0, len(t), FEED_ROWS):
        hi = min(lo + FEED_ROWS, len(t))
        for s in bus.pieces(t[lo:hi]) if bus is not None else (slice(None),):
            yield slice(lo + (s.start or 0), hi if s.stop is None else lo + s.stop)


def _finish(
    emu: Any,
    prof: Profile,
    t0: float,
    parts: list[dict[str, Any]],
    sink: Callable[[dict[str, Any]], None] | None,
    bus: _BusWindow | None,
    window: _TruthWindow | None = None,
) -> Run:
    """End the input, run the ticks it still covers and assemble the Run (with the bus window)."""
    emu.end()
    _run(emu, parts, sink, bus, window, last=True)
    run = _assemble(prof, t0, parts, dict(emu.stage_cycles()))
    if bus is not None:
        run.bus = bus.finish()
    return run


def _run(
    emu: Any,
    parts: list[dict[str, Any]],
    sink: Callable[[dict[str, Any]], None] | None,
    bus: _BusWindow | None,
    window: _TruthWindow | None = None,
    *,
    last: bool = False,
) -> None:
    """Run the ticks the input pushed so far covers, a block at a time: a sink or the bus window
    takes each block's output as it comes, so what is held stays bounded whatever the input covers
    (a long gap, a tiny timer period); without them the Run keeps every row anyway, taken once at
    the ``last`` run. A take: the bus window sees the output, then it is kept or handed to the sink
    (with the truth at its steps when ``window`` holds the input's truth)."""
    streaming = sink is not None or bus is not None
    while True:
        full = emu.run_block() == "block_full"
        if streaming or (last and not full):
            part = emu.take()
            if bus is not None:
                bus.after(part)
            if window is not None and window.t is not None:
                window.attach(part)
            _collect(part, parts, sink)
        if not full:
            return


def _collect(
    part: dict[str, Any], parts: list[dict[str, Any]], sink: Callable[[dict[str, Any]], None] | None
) -> None:
    """Keep a chunk's output, or hand it to the sink and keep only its (empty) shape."""
    if sink is None:
        parts.append(part)
        return
    sink(part)
    if not parts:
        parts.append({k: v[:0] if hasattr(v, "shape") else [] for k, v in part.items()})


class _TruthWindow:
    """The truth of the piece of input just pushed and of the FEED_ROWS rows before it, for a
    sink's output: the truth at a step's time is interpolated between the trace's rows around it
    (:func:`_truth_at`), and a step runs once the input covers its timer period, so its rows are in
    the piece just pushed or in the FEED_ROWS rows before (10 s at 819.2 SPS, far longer than a
    timer period). Interpolating in this window gives the values the whole trace gives, bit for
    bit: the same two rows, the same arithmetic; after the trace's last row both clamp to its last
    two rows."""

    def __init__(self) -> None:
        self.t: Array | None = None
        self.q: Array = np.empty((0, 4))
        self.moving: NDArray[np.bool_] | None = None
        self.q0: Array | None = None
        self.alpha: Array | None = None

    def feed(
        self, t: Array, q: Array, moving: NDArray[np.bool_] | None, alpha_deg: Array | None = None
    ) -> None:
        if self.t is None:
            self.q0 = q[0].copy()
        keep = slice(max(len(self.q) - FEED_ROWS, 0), None)
        if alpha_deg is not None:
            self.alpha = alpha_deg if self.alpha is None else np.concatenate([self.alpha[keep], alpha_deg])
        self.t = t if self.t is None else np.concatenate([self.t[keep], t])
        self.q = np.concatenate([self.q[keep], q])
        if moving is not None:
            self.moving = moving if self.moving is None else np.concatenate([self.moving[keep], moving])

    def attach(self, part: dict[str, Any]) -> None:
        assert self.t is not None
        at = part["cycle_t_ps"].astype(np.float64) * PS
        part["truth_q"] = _truth_at(self.t, self.q, at)
        part["truth_q0"] = self.q0
        if self.moving is not None:
            idx = np.clip(np.searchsorted(self.t, at, side="right") - 1, 0, len(self.t) - 1)
            part["moving"] = self.moving[idx]
        if self.alpha is not None:
            part["truth_alpha_deg"], part["alpha_still"] = alpha_truth_at(self.t, self.alpha, at)


def _alpha(chunk: PhysicalTrace, s: slice) -> Array | None:
    return None if chunk.truth_alpha_deg is None else chunk.truth_alpha_deg[s]


def _truth_at(t: Array, q: Array, at: Array) -> Array:
    """Truth quaternion at times ``at``: normalised linear interpolation (sign-aligned), NaN where
    either neighbour is missing or outside the trace."""
    out = np.full((len(at), 4), np.nan)
    if len(t) < 2:
        return out
    i = np.clip(np.searchsorted(t, at, side="right") - 1, 0, len(t) - 2)
    a = (at - t[i]) / (t[i + 1] - t[i])
    q0, q1 = q[i], q[i + 1].copy()
    flip = np.sum(q0 * q1, axis=1) < 0
    q1[flip] *= -1
    qi = q0 + (q1 - q0) * a[:, None]
    qi /= np.linalg.norm(qi, axis=1, keepdims=True)
    inside = (at >= t[0]) & (at <= t[-1])
    out[inside] = qi[inside]
    return out


def _cat(parts: list[dict[str, Any]], key: str) -> NDArray[Any]:
    # One part (the usual case: one take at the end of a run) is used as it is, not copied.
    return parts[0][key] if len(parts) == 1 else np.concatenate([p[key] for p in parts])


def _assemble(profile: Profile, t0: float, parts: list[dict[str, Any]], stage_cycles: dict[str, int]) -> Run:
    budget_keys = [k for k in parts[0] if k.startswith("budget_")]
    return Run(
        profile=profile,
        t0_s=t0,
        time_s=_cat(parts, "cycle_t_ps").astype(np.float64) * PS,
        step=_cat(parts, "cycle_step"),
        quat=_cat(parts, "cycle_quat"),
        euler_deg=_cat(parts, "cycle_euler_deg"),
        velocity_enu=_cat(parts, "cycle_vel_enu"),
        position=_cat(parts, "cycle_pos"),
        read_tick=_cat(parts, "read_tick"),
        read_t_cs_ps=_cat(parts, "read_t_cs_ps"),
        read_t_start_ps=_cat(parts, "read_t_start_ps"),
        read_t_end_ps=_cat(parts, "read_t_end_ps"),
        read_words=_cat(parts, "read_words"),
        read_rate=_cat(parts, "read_rate"),
        read_accel=_cat(parts, "read_accel"),
        read_sample_index=_cat(parts, "read_sample_index"),
        read_sample_ps=_cat(parts, "read_sample_ps"),
        read_assumed_s=_cat(parts, "read_assumed_s"),
        read_age_ps=_cat(parts, "read_age_ps"),
        budget={k.removeprefix("budget_"): _cat(parts, k) for k in budget_keys},
        events=[e for p in parts for e in p["events"]],
        stage_cycles=stage_cycles,
        dcm={k.removeprefix("dcm_"): _cat(parts, k) for k in parts[0] if k.startswith("dcm_")},
        wing={k.removeprefix("wing_"): _cat(parts, k) for k in parts[0] if k.startswith("wing_")},
    )


def profile_table(path: str | os.PathLike[str]) -> dict[str, Any]:
    """A TOML data table of firmware_model/ (parity thresholds, costs) by name or path."""
    p = Path(path)
    if not p.is_file():
        p = MODEL_DIR / p
    try:
        data = p.read_bytes()
    except FileNotFoundError:
        raise ProfileError(f"{p}: file not found") from None
    except IsADirectoryError:
        raise ProfileError(f"{p}: is a folder; expected a TOML file") from None
    return toml_table(data, p)


def toml_table(data: bytes, where: str | os.PathLike[str]) -> dict[str, Any]:
    """A TOML file's bytes parsed, every failure a ProfileError naming ``where`` and the line: binary
    data, bytes that are not UTF-8, a syntax error, arrays or tables nested too deeply for tomllib's
    recursion."""
    nul = data.find(b"\0")
    if nul >= 0:
        raise ProfileError(f"{where}: binary data (NUL byte at offset {nul}); expected a TOML text file")
    text = utf8_text(data, where, "a TOML file (UTF-8)", ProfileError)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise ProfileError(f"{where}: {e}") from None
    except RecursionError:
        raise ProfileError(
            f"{where}: arrays or tables nested too deeply to read; expected a table of a few levels"
        ) from None


class _BusWindow:
    """Switches the core's bus log on just before the first tick of a window and off after its last.

    A tick runs once the input covers its whole period, so the input is split where the window
    starts: everything before ``(first - 1)`` periods runs with the log off. The log then keeps
    whatever ran while it was on, and :meth:`finish` keeps only the window's ISRs (first tick's
    start to the latest end among the window's ticks): the bus is idle between ISRs. The window's
    ISRs are noted from the output as it is taken (:meth:`after`), so a sink may stream it away.
    """

    def __init__(self, emu: Any, profile: Profile, window: tuple[int, int]) -> None:
        first, last = check_bus_window(window)
        self.emu, self.first, self.last = emu, first, last
        period_s = float(profile.get("timer.period_us")) * 1e-6
        # Inexact period (PRD rounding) is harmless: the cut only has to come a tick early.
        self.t_on = (first - 2) * period_s
        self.on = self.done = False
        self.records: list[dict[str, NDArray[Any]]] = []
        #: The ISRs of the window seen so far: (first start, latest end), ps.
        self.span: tuple[int, int] | None = None
        #: The first and last tick seen (for the error when the window is not in the run).
        self.ticks_seen: tuple[int, int] | None = None

    def pieces(self, t: Array) -> Iterator[slice]:
        """The chunk cut where the log must be switched on."""
        if self.on or self.done:
            yield slice(None)
            return
        cut = int(np.searchsorted(t, self.t_on, side="left"))
        if cut > 0:
            yield slice(0, cut)
        self.emu.enable_bus_log()
        self.on = True
        if cut < len(t):
            yield slice(cut, None)

    def after(self, part: dict[str, Any]) -> None:
        """Note the window's ISRs in a part of the output; stop once the window's last tick has run."""
        ticks = part["budget_tick"]
        if len(ticks):
            lo, hi = int(ticks[0]), int(ticks[-1])
            self.ticks_seen = (lo, hi) if self.ticks_seen is None else (self.ticks_seen[0], hi)
        sel = (ticks >= self.first) & (ticks <= self.last)
        if sel.any():
            start, end = int(part["budget_start_ps"][sel][0]), int(part["budget_end_ps"][sel].max())
            self.span = (start, end) if self.span is None else (self.span[0], max(self.span[1], end))
        if self.on and len(ticks) and int(ticks[-1]) >= self.last:
            self.records.append(self.emu.take_bus_log(stop=True))
            self.on, self.done = False, True

    def finish(self) -> dict[str, NDArray[Any]]:
        if self.on:
            self.records.append(self.emu.take_bus_log(stop=True))
            self.on = False
        if self.span is None:
            seen = self.ticks_seen or (0, 0)
            raise ProfileError(
                f"bus window ({self.first}, {self.last}): the run has ticks {seen[0]}…{seen[1]}"
            )
        lo, hi = self.span
        log = {k: np.concatenate([r[k] for r in self.records]) for k in self.records[0]}
        keep_cs = (log["cs_t_ps"] >= lo) & (log["cs_t_ps"] <= hi)
        keep_frame = (log["frame_start_ps"] >= lo) & (log["frame_end_ps"] <= hi)
        out = {k: v[keep_cs if k.startswith("cs_") else keep_frame] for k, v in log.items()}
        out["window_ticks"] = np.array([self.first, self.last], dtype=np.uint64)
        out["window_ps"] = np.array([lo, hi], dtype=np.uint64)
        return out
