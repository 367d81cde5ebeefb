"""Numeric parity: the same board, profile and input run in several arithmetic backends, each
compared step by step with the f64 golden reference.

Only ``firmware.numeric`` differs between the runs, so every difference in the attitude is the
arithmetic's. Per step the difference is the rotation angle of ``q_backend ⊗ q_f64⁻¹``,
``2·atan2(|v|, |w|)`` (:func:`sins_fw.quaternion.rotation_angle`; not ``2·acos(|w|)``, which loses
every digit below ~1e-8 rad because ``w`` is within 1e-16 of 1 there; the atan2 form is also
insensitive to the quaternion's norm). Reported per
backend: the maximum, the RMS and the final difference (degrees) and the drift rate, the
least-squares slope of the difference over time (degrees per hour).

Thresholds per backend live in ``firmware_model/parity.toml`` (``max_deg``, ``rms_deg``,
``drift_deg_per_h``; ``max_deg_per_h`` and ``rms_deg_per_h`` for limits that grow with the run's
duration); the file records how they were measured. ``sins-fw parity --thresholds FILE`` reads
another table of the same form (a CI's own).
"""

from __future__ import annotations

import contextlib
import math
import os
import queue
import threading
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sins_fw import _core
from sins_fw import quaternion as quat
from sins_fw.errors import InputError, ProfileError
from sins_fw.harness import CHUNK_ROWS, Run, emulate, profile_table
from sins_fw.profile import MODEL_DIR, Profile, load_profile
from sins_fw.traces import PhysicalTrace

Array = NDArray[np.float64]

#: The golden backend every other one is compared with.
REFERENCE = "f64"
#: The backends `sins-fw parity` runs by default (the values `firmware.numeric` takes: the core's
#: `profile::Numeric::ALL`).
BACKENDS: tuple[str, ...] = tuple(_core.NUMERICS)
#: The threshold table (in firmware_model/).
THRESHOLDS_FILE = "parity.toml"
_LIMITS = ("max_deg", "rms_deg", "drift_deg_per_h")
#: The keys of a threshold table: the limits, and the maximum's and RMS's growth per hour of run.
_KEYS = (*_LIMITS, "max_deg_per_h", "rms_deg_per_h")
_SECONDS_PER_HOUR = 3600.0


def attitude_difference_deg(q: ArrayLike, q_ref: ArrayLike) -> Array:
    """Per-row rotation angle (degrees, in [0, 180]) of ``q ⊗ q_ref⁻¹``; both ``(N, 4)``."""
    a = np.asarray(q, dtype=np.float64)
    b = np.asarray(q_ref, dtype=np.float64)
    if a.shape != b.shape or a.ndim != 2 or a.shape[1] != 4:
        raise InputError(f"quaternions {a.shape} and {b.shape}: expected two (N, 4) arrays")
    return np.degrees(quat.rotation_angle(a, b))


def drift_rate_deg_per_h(t_s: ArrayLike, angle_deg: ArrayLike) -> float:
    """Least-squares slope of ``angle_deg`` against ``t_s``, in degrees per hour (0 for < 2 rows)."""
    t = np.asarray(t_s, dtype=np.float64)
    a = np.asarray(angle_deg, dtype=np.float64)
    if len(t) < 2:
        return 0.0
    tc = t - t.mean()
    # np.sum, not np.dot: a BLAS dot splits the sum between its threads (OMP_NUM_THREADS changes
    # the last digits); numpy's own pairwise summation has one fixed order.
    denom = float(np.sum(tc * tc))
    if denom == 0.0:
        return 0.0
    return float(np.sum(tc * (a - a.mean())) / denom) * _SECONDS_PER_HOUR


@dataclass(frozen=True)
class Threshold:
    """The largest allowed difference of one backend from f64. The maximum and the RMS may also grow
    with the run's duration T, where a rate is the right measure (rounding errors accumulate): the
    limit is then ``max_deg + max_deg_per_h · T`` (T in hours), likewise for the RMS."""

    max_deg: float = 0.0
    rms_deg: float = 0.0
    drift_deg_per_h: float = 0.0
    max_deg_per_h: float = 0.0
    rms_deg_per_h: float = 0.0

    def limits(self, duration_s: float) -> dict[str, float]:
        """The limits for a run of ``duration_s`` seconds, by measured quantity."""
        hours = duration_s / _SECONDS_PER_HOUR
        return {
            "max_deg": self.max_deg + self.max_deg_per_h * hours,
            "rms_deg": self.rms_deg + self.rms_deg_per_h * hours,
            "drift_deg_per_h": self.drift_deg_per_h,
        }

    def describe(self) -> str:
        def part(deg: float, per_h: float) -> str:
            terms = [f"{deg:g}°"] * bool(deg) + [f"{per_h:g}°/h × T"] * bool(per_h)
            return " + ".join(terms)

        return (
            f"max {part(self.max_deg, self.max_deg_per_h)}, RMS {part(self.rms_deg, self.rms_deg_per_h)}, "
            f"drift {self.drift_deg_per_h:g}°/h"
        )


def load_thresholds(path: str | os.PathLike[str] | None = None) -> dict[str, Threshold]:
    """The per-backend thresholds of ``firmware_model/parity.toml`` (or ``path``, e.g. a CI's own).

    Per backend `[backends.NAME]`: ``drift_deg_per_h``, and for the maximum and the RMS an absolute
    limit (``max_deg``, ``rms_deg``), one that grows with the run's duration (``max_deg_per_h``,
    ``rms_deg_per_h``), or both (added). Every value a positive number."""
    source = Path(path) if path is not None else MODEL_DIR / THRESHOLDS_FILE
    table = profile_table(source)
    backends = table.get("backends")
    unknown_top = sorted(set(table) - {"backends"})
    if unknown_top:
        raise ProfileError(
            f"{source}: unknown key(s) {', '.join(unknown_top)}; expected [backends.NAME] tables"
        )
    if not isinstance(backends, dict):
        raise ProfileError(f"{source}: expected a [backends.NAME] table per backend")
    out: dict[str, Threshold] = {}
    allowed = ", ".join(b for b in BACKENDS if b != REFERENCE)
    bad = sorted(name for name in backends if name not in BACKENDS or name == REFERENCE)
    if bad:
        raise ProfileError(f"{source}: [backends.{bad[0]}]: unknown backend; expected one of {allowed}")
    for name, limits in backends.items():
        if not isinstance(limits, dict):
            raise ProfileError(f"{source}: [backends.{name}]: expected a table")
        unknown = sorted(set(limits) - set(_KEYS))
        if unknown:
            keys = ", ".join(f"`backends.{name}.{k}`" for k in unknown)
            raise ProfileError(f"{source}: unknown key(s) {keys}; expected {', '.join(_KEYS)}")
        for key, v in limits.items():
            if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v) or v <= 0:
                raise ProfileError(
                    f"{source}: key `backends.{name}.{key}` = {v!r}: expected a positive number"
                )
        for needed in (("max_deg", "max_deg_per_h"), ("rms_deg", "rms_deg_per_h"), ("drift_deg_per_h",)):
            if not any(k in limits for k in needed):
                raise ProfileError(f"{source}: [backends.{name}]: missing `{'` or `'.join(needed)}`")
        out[name] = Threshold(**{k: float(v) for k, v in limits.items()})
    return out


@dataclass
class BackendDiff:
    """One backend against the reference on one trace."""

    backend: str
    steps: int
    max_deg: float
    max_at_s: float
    rms_deg: float
    final_deg: float
    drift_deg_per_h: float
    threshold: Threshold | None = None
    #: The limits exceeded, as ``name: measured > limit`` texts (empty: within every limit).
    exceeded: list[str] = field(default_factory=list)
    #: The first step (its time, s) at which the difference was not finite (either run's quaternion
    #: had left the finite numbers: its state ran away, e.g. the free-inertial vertical channel
    #: overflowing single precision); None if every step was finite. The statistics above are those
    #: of the finite steps before it, and the backend fails.
    nonfinite_from_s: float | None = None

    @property
    def checked(self) -> bool:
        """A threshold was given (a backend without one is measured only)."""
        return self.threshold is not None

    @property
    def passed(self) -> bool:
        return not self.exceeded

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["checked"] = self.checked
        d["passed"] = self.passed
        return d


def compare(run: Run, reference: Run, backend: str, threshold: Threshold | None = None) -> BackendDiff:
    """The attitude difference of ``run`` from ``reference`` (same steps), checked against a threshold."""
    if run.cycles != reference.cycles or not np.array_equal(run.time_s, reference.time_s):
        raise InputError(
            f"backend {backend}: {run.cycles} attitude steps, reference {reference.cycles}; the runs must "
            "produce the same steps at the same times to be compared"
        )
    if run.cycles == 0:
        raise InputError("no attitude step to compare: the trace is shorter than one update period")
    st = _Stats()
    st.add(run.time_s, attitude_difference_deg(run.quat, reference.quat))
    return st.diff(backend, threshold, float(run.time_s[-1]))


@dataclass
class TraceParity:
    """Every backend against the reference on one trace."""

    trace: str
    profile: str
    overrides: tuple[str, ...]
    duration_s: float
    steps: int
    backends: list[BackendDiff]

    @property
    def passed(self) -> bool:
        return all(b.passed for b in self.backends)

    def to_dict(self) -> dict[str, Any]:
        return {
            "trace": self.trace,
            "profile": self.profile,
            "overrides": list(self.overrides),
            "reference": REFERENCE,
            "duration_s": self.duration_s,
            "steps": self.steps,
            "passed": self.passed,
            "backends": [b.to_dict() for b in self.backends],
        }


def parse_backends(text: str | Sequence[str]) -> list[str]:
    """A backend list (``"f64,iq"`` or a sequence); f64 first whether given or not, no repeats."""
    names = [s.strip() for s in (text.split(",") if isinstance(text, str) else text) if s.strip()]
    for n in names:
        if n not in BACKENDS:
            raise InputError(f"backend `{n}`: unknown; expected some of {', '.join(BACKENDS)}")
    return [REFERENCE, *dict.fromkeys(n for n in names if n != REFERENCE)]


def run_backends(
    trace: PhysicalTrace | str | os.PathLike[str],
    profile: Profile | str = "reference",
    *,
    overrides: Iterable[str] = (),
    backends: Sequence[str] = BACKENDS,
    on_chunk: Callable[[str, float], None] | None = None,
) -> dict[str, Run]:
    """Emulate ``trace`` once per backend: the profile with only ``firmware.numeric`` changed."""
    prof = profile if isinstance(profile, Profile) else load_profile(profile)
    prof = prof.with_overrides(*overrides)
    if isinstance(trace, str | os.PathLike):
        trace = PhysicalTrace.load(trace)  # read once, run several times
    runs: dict[str, Run] = {}
    for name in parse_backends(backends):
        report = None if on_chunk is None else (lambda t, n=name: on_chunk(n, t))
        runs[name] = emulate(trace, prof.with_overrides(f"firmware.numeric={name}"), on_chunk=report)
    return runs


@dataclass
class _Stats:
    """Running statistics of one backend's difference, merged chunk by chunk in a fixed order (so
    the result does not depend on how the work was scheduled): count, sum of squares, maximum and
    where, the last value, and the least-squares line of the angle against time (Chan et al.'s
    pairwise update of the means, the sum of squares of t and the co-moment of t and the angle).

    Only the steps before the first non-finite difference count (one NaN would make every figure
    NaN: a 24-hour run whose single-precision navigation overflowed reported nothing but NaN); the
    first non-finite step's time is kept (:attr:`BackendDiff.nonfinite_from_s`)."""

    total: int = 0
    nonfinite_from_s: float | None = None
    n: int = 0
    sum_sq: float = 0.0
    max_deg: float = -math.inf
    max_at_s: float = math.nan
    final_deg: float = math.nan
    mean_t: float = 0.0
    mean_a: float = 0.0
    m2_t: float = 0.0
    c_ta: float = 0.0

    def add(self, t: Array, angle: Array) -> None:
        self.total += len(t)
        if self.nonfinite_from_s is not None:
            return
        bad = ~np.isfinite(angle)
        if bad.any():
            i = int(np.argmax(bad))
            self.nonfinite_from_s = float(t[i])
            t, angle = t[:i], angle[:i]
        if not len(t):
            return
        k = int(np.argmax(angle))
        if not angle[k] <= self.max_deg:  # NaN counts as the largest, as np.argmax does
            self.max_deg, self.max_at_s = float(angle[k]), float(t[k])
        self.final_deg = float(angle[-1])
        self.sum_sq += float(np.sum(angle * angle))
        nb, mt, ma = len(t), float(np.mean(t)), float(np.mean(angle))
        tc = t - mt
        m2, c = float(np.sum(tc * tc)), float(np.sum(tc * (angle - ma)))
        n = self.n + nb
        dt, da = mt - self.mean_t, ma - self.mean_a
        w = self.n * nb / n
        self.mean_t += dt * nb / n
        self.mean_a += da * nb / n
        self.m2_t += m2 + dt * dt * w
        self.c_ta += c + dt * da * w
        self.n = n

    def diff(self, backend: str, threshold: Threshold | None, duration_s: float) -> BackendDiff:
        drift = self.c_ta / self.m2_t * _SECONDS_PER_HOUR if self.n >= 2 and self.m2_t > 0 else 0.0
        diff = _checked(
            BackendDiff(
                backend=backend,
                steps=self.total,
                max_deg=self.max_deg if self.n else math.nan,
                max_at_s=self.max_at_s,
                rms_deg=math.sqrt(self.sum_sq / self.n) if self.n else math.nan,
                final_deg=self.final_deg,
                drift_deg_per_h=drift,
                threshold=threshold,
                nonfinite_from_s=self.nonfinite_from_s,
            ),
            # The limits that grow with the duration: for the span the figures cover.
            duration_s if self.nonfinite_from_s is None else self.nonfinite_from_s,
        )
        if self.nonfinite_from_s is not None:
            diff.exceeded.insert(
                0,
                f"attitude not finite from {self.nonfinite_from_s:.6g} s on (the state left its range; the "
                f"figures are those of the {self.n} finite steps before)",
            )
        return diff


def _checked(diff: BackendDiff, duration_s: float) -> BackendDiff:
    """``diff`` with the limits it exceeds listed (the duration-scaled ones for ``duration_s``)."""
    if diff.threshold is not None:
        measured = {
            "max_deg": diff.max_deg,
            "rms_deg": diff.rms_deg,
            "drift_deg_per_h": abs(diff.drift_deg_per_h),
        }
        for key, limit in diff.threshold.limits(duration_s).items():
            # NaN compares False: count it as exceeded explicitly.
            if not measured[key] <= limit:
                per_h = getattr(diff.threshold, f"{key}_per_h", 0.0)
                how = f" (for {duration_s:.4g} s at {per_h:g}°/h)" if per_h else ""
                diff.exceeded.append(f"{key}: {measured[key]:.3g} > {limit:.3g}{how}")
    return diff


_DONE = object()
#: The output columns a backend's thread hands over: the steps' times and quaternions, and the ticks'
#: times (the reference's last one is the duration).
_KEPT = ("cycle_t_ps", "cycle_quat", "budget_tick_ps")


def streamed(
    trace: PhysicalTrace | str | os.PathLike[str],
    profiles: dict[str, Profile],
    on_chunk: Callable[[str, float], None] | None,
    chunk_rows: int,
    keep: tuple[str, ...] = _KEPT,
) -> Iterator[dict[str, dict[str, Any] | None]]:
    """Emulate every backend at once, each in a thread streaming its output (``emulate(...,
    sink=...)``) through a queue of a few chunks: memory is bounded by the chunk, not the trace.
    Yields one output chunk per backend per round (None for a backend that has finished): only what
    the comparison reads (``keep``, by default :data:`_KEPT`), not the chunk's read and budget
    columns, which would otherwise be the bulk of every queued chunk (≈ 5 MB each instead of 0.4 MB
    at 10 000 steps)."""
    queues: dict[str, queue.Queue[Any]] = {n: queue.Queue(maxsize=2) for n in profiles}
    stop = threading.Event()

    def work(name: str) -> None:
        q = queues[name]

        def put(item: Any) -> None:
            while not stop.is_set():
                try:
                    q.put(item, timeout=0.1)
                    return
                except queue.Full:
                    continue
            raise _StoppedError

        def slim(part: dict[str, Any]) -> None:
            put({k: part[k] for k in keep})

        try:
            report = None if on_chunk is None else (lambda t: on_chunk(name, t))
            emulate(trace, profiles[name], on_chunk=report, sink=slim, chunk_rows=chunk_rows)
            put(_DONE)
        except _StoppedError:
            pass
        except BaseException as e:  # handed to the main thread, which raises it
            with contextlib.suppress(_StoppedError):
                put(e)

    threads = [threading.Thread(target=work, args=(n,), daemon=True) for n in profiles]
    for th in threads:
        th.start()
    done: set[str] = set()
    try:
        while len(done) < len(profiles):
            row: dict[str, dict[str, Any] | None] = {}
            for name, q in queues.items():
                item = None if name in done else q.get()
                if item is _DONE:
                    done.add(name)
                    item = None
                elif isinstance(item, BaseException):
                    raise item
                row[name] = item
            yield row
    finally:
        stop.set()
        for th in threads:
            th.join()


class _StoppedError(Exception):
    """The consumer has gone: a backend's thread stops."""


def parity(
    trace: PhysicalTrace | str | os.PathLike[str],
    profile: Profile | str = "reference",
    *,
    overrides: Iterable[str] = (),
    backends: Sequence[str] = BACKENDS,
    thresholds: dict[str, Threshold] | None = None,
    on_chunk: Callable[[str, float], None] | None = None,
    chunk_rows: int = CHUNK_ROWS,
) -> TraceParity:
    """Run every backend on ``trace`` and compare each with f64 against ``thresholds`` (default: the
    table in firmware_model/parity.toml). A backend without a threshold is measured, not checked.

    The backends run side by side and are compared chunk by chunk as their output streams out, so
    memory does not grow with the trace's length (a trace file is read by each backend, in chunks of
    ``chunk_rows`` rows; each backend holds about one chunk of input and a few pieces of output)."""
    limits = load_thresholds() if thresholds is None else thresholds
    names = parse_backends(backends)
    if len(names) < 2:
        raise InputError(
            f"backends {backends!r}: nothing to compare; name at least one backend besides the "
            f"reference {REFERENCE} (known: {', '.join(b for b in BACKENDS if b != REFERENCE)})"
        )
    prof = profile if isinstance(profile, Profile) else load_profile(profile)
    prof = prof.with_overrides(*overrides)
    profiles = {n: prof.with_overrides(f"firmware.numeric={n}") for n in names}
    stats = {n: _Stats() for n in names if n != REFERENCE}
    pending: dict[str, tuple[Array, Array]] = {n: (np.empty(0, np.uint64), np.empty((0, 4))) for n in names}
    last_tick_ps: int | None = None
    for row in streamed(trace, profiles, on_chunk, chunk_rows):
        for n, part in row.items():
            if part is None:
                continue
            t, q = pending[n]
            pending[n] = (np.concatenate([t, part["cycle_t_ps"]]), np.concatenate([q, part["cycle_quat"]]))
            if n == REFERENCE and len(part["budget_tick_ps"]):
                last_tick_ps = int(part["budget_tick_ps"][-1])
        common = min(len(t) for t, _ in pending.values())
        ref_t, ref_q = pending[REFERENCE]
        for n, st in stats.items():
            t, q = pending[n]
            if not np.array_equal(t[:common], ref_t[:common]):
                raise InputError(
                    f"backend {n}: its attitude steps are not at the reference's times; the runs must "
                    "produce the same steps at the same times to be compared"
                )
            st.add(
                ref_t[:common].astype(np.float64) * 1e-12, attitude_difference_deg(q[:common], ref_q[:common])
            )
        pending = {n: (t[common:], q[common:]) for n, (t, q) in pending.items()}
    counts = {n: len(t) for n, (t, _) in pending.items()}
    if any(counts.values()):
        raise InputError(
            f"backends produced different numbers of attitude steps (left over: {counts}); the runs must "
            "produce the same steps at the same times to be compared"
        )
    steps = next(iter(stats.values())).total if stats else 0
    if stats and steps == 0:
        raise InputError("no attitude step to compare: the trace is shorter than one update period")
    duration_s = last_tick_ps * 1e-12 if last_tick_ps is not None else 0.0
    return TraceParity(
        trace=str(trace) if not isinstance(trace, PhysicalTrace) else trace.metadata.get("source", "<trace>"),
        profile=prof.source,
        overrides=prof.overrides,
        duration_s=duration_s,
        steps=steps,
        backends=[st.diff(n, limits.get(n), duration_s) for n, st in stats.items()],
    )
