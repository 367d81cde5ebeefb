"""Monte Carlo over sensor-error realisations: the same scenario and board, N seeds of the error
model; the result is a distribution of attitude errors.

The work is cut into **jobs**, pure data (:class:`Job`: case, profile text, overrides, seed), and one
pure function runs a job on its case's trace (:func:`run_job`). An **engine** runs jobs and yields
their results as they complete: ``local`` (a process pool on this machine, the default) or ``dask``
(a Dask distributed cluster: one machine or many). Traces are generated once, on the client, and
handed to the workers once (the pool's initializer, Dask's scatter), never regenerated per job, and
checked once, on the client (:class:`~sins_fw.traces.CheckedTrace`), not in every job. Dask runs
jobs in batches (:class:`Batch`, :func:`batch_size`) to pay its cost per task once for several. The
engine changes nothing in a result: every result carries the :class:`Fingerprint` of the software
that computed it, results of different fingerprints are refused, and a job seen twice must give the
same result (:func:`collect`).

``published_experiment`` reproduces the reference design's indexing-table table (±30° about each
axis) and its 30 s drift after a fast rotation to yaw 25.8° as distributions, and says where each
published value falls in them.
"""

from __future__ import annotations

import contextlib
import hashlib
import logging
import os
import platform
import sys
from collections.abc import Callable, Iterator, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures import as_completed as pool_completed
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from sins_fw import _core, metrics, quaternion, synth
from sins_fw.alignment import aligned_estimate
from sins_fw.errors import InputError, InternalError, SinsError, TraceError
from sins_fw.harness import Run, emulate, has_wing
from sins_fw.profile import Profile, load_profile
from sins_fw.traces import CheckedTrace, PhysicalTrace

PERCENTILES = (5.0, 25.0, 50.0, 75.0, 95.0)
#: The attitude errors of a run, degrees, in this order (see :func:`run_job`).
ERRORS = ("pitch", "roll", "yaw", "total", "heading", "inclination")
#: The wing unit's α errors of a run, degrees (see :func:`_alpha_errors`): at the last step with α
#: and truth, and the largest |α − truth| over the still steps and over the moving ones.
ALPHA_ERRORS = ("final", "static_max", "dynamic_max")
#: Error samples kept per run for the error-over-time bands (evenly spaced steps, the last included).
SERIES_POINTS = 200
#: Below this many runs the 5th and 95th percentiles are the extremes of the sample (1/0.05 = 20).
FEW_RUNS = 20

#: The published ±30° table: true (pitch, roll, yaw) → solved (pitch, roll, yaw), degrees.
PUBLISHED_PM30: dict[tuple[float, float, float], tuple[float, float, float]] = {
    (30.0, 0.0, 0.0): (29.856, 0.713, -0.621),
    (-30.0, 0.0, 0.0): (-29.439, -0.893, 0.163),
    (0.0, 30.0, 0.0): (-0.505, 30.784, 0.735),
    (0.0, -30.0, 0.0): (0.827, -30.370, -0.765),
    (0.0, 0.0, 30.0): (0.216, 0.431, 30.196),
    (0.0, 0.0, -30.0): (0.405, 0.636, -29.796),
}
#: Published errors 30 s after a fast rotation to yaw +25.8°: pitch, roll, yaw, degrees.
PUBLISHED_YAW_HOLD = (0.814, 0.790, 1.394)


@dataclass(frozen=True)
class Case:
    """One scenario of an experiment: how to make its trace and what the truth is at the end."""

    name: str
    scenario: str
    preset: str | None
    params: tuple[tuple[str, Any], ...]
    truth_deg: tuple[float, float, float]  # pitch, roll, yaw at the end

    def trace(self) -> PhysicalTrace:
        return synth.generate(self.scenario, self.preset, **dict(self.params))


# ---------------------------------------------------------------------------------------------------
# Jobs, results and the one function that runs a job
# ---------------------------------------------------------------------------------------------------

#: What identifies a job's result: (case, grid point, seed).
JobKey = tuple[str, tuple[str, ...], int]


@dataclass(frozen=True)
class Fingerprint:
    """The software that computed a result. Results of different fingerprints are never mixed."""

    version: str  # sins-fw
    core: str  # SHA-256 (first 16 hex digits) of the compiled core extension
    platform: str  # OS and machine, Python and numpy versions

    def __str__(self) -> str:
        return f"sins-fw {self.version}, core {self.core}, {self.platform}"


_fingerprint: Fingerprint | None = None


def fingerprint() -> Fingerprint:
    """This process's fingerprint (computed once)."""
    global _fingerprint
    if _fingerprint is None:
        core = hashlib.sha256(Path(_core.__file__).read_bytes()).hexdigest()[:16]
        v = sys.version_info
        python = f"Python {v.major}.{v.minor}.{v.micro}"
        where = f"{sys.platform}-{platform.machine()}, {python}, numpy {np.__version__}"
        _fingerprint = Fingerprint(_core.__version__, core, where)
    return _fingerprint


@dataclass(frozen=True)
class Job:
    """One realisation, as pure data: the case (the name of its trace), the profile (text and
    overrides), the grid point (more overrides; empty for a plain Monte Carlo) and the error seed."""

    case: str
    seed: int
    profile_source: str
    profile_text: str
    overrides: tuple[str, ...] = ()
    point: tuple[str, ...] = ()

    @property
    def key(self) -> JobKey:
        return (self.case, self.point, self.seed)

    def profile(self) -> Profile:
        base = Profile(source=self.profile_source, text=self.profile_text)
        return base.with_overrides(*self.overrides, *self.point, f"errors.seed={self.seed}")


@dataclass(frozen=True)
class Outcome:
    """The result of one job. Errors are the estimate against the truth after the alignment every
    report uses (:func:`sins_fw.alignment.aligned_estimate`), degrees, in :data:`ERRORS` order."""

    key: JobKey
    solved_deg: tuple[float, float, float]  # the firmware's pitch, roll, yaw at the last step
    truth_deg: tuple[float, float, float]  # the truth's, same conventions (NaN without truth)
    final_error_deg: tuple[float, ...]  # at the last step with a truth
    t_s: NDArray[np.float64]  # (SERIES_POINTS,) times of the error samples
    error_deg: NDArray[np.float64]  # (SERIES_POINTS, 6)
    fingerprint: Fingerprint
    #: The wing unit's α errors (:data:`ALPHA_ERRORS`), NaN for another board or a trace without α.
    alpha_error_deg: tuple[float, float, float] = (float("nan"),) * 3
    #: The run was the wing unit's (its figures are α's, NaN when it never gave one).
    wing: bool = False

    def same_as(self, other: Outcome) -> bool:
        """Bit for bit the same result (NaN equal to NaN)."""
        return (
            self.key == other.key
            and self.fingerprint == other.fingerprint
            and all(
                np.array_equal(np.asarray(a), np.asarray(b), equal_nan=True)
                for a, b in (
                    (self.solved_deg, other.solved_deg),
                    (self.truth_deg, other.truth_deg),
                    (self.final_error_deg, other.final_error_deg),
                    (self.alpha_error_deg, other.alpha_error_deg),
                    (self.t_s, other.t_s),
                    (self.error_deg, other.error_deg),
                )
            )
        )


def _wrap180(x: NDArray[np.float64]) -> NDArray[np.float64]:
    return (x + 180.0) % 360.0 - 180.0


def _final_angles(run: Run) -> tuple[float, float, float]:
    """Pitch, roll, yaw (wrapped to ±180°) of the last step."""
    roll, pitch, yaw = run.euler_deg[-1]
    return float(pitch), float(roll), float(_wrap180(np.array(yaw)))


def _truth_angles(run: Run) -> tuple[float, float, float]:
    """Pitch, roll, yaw of the truth at the last step (the firmware's conventions)."""
    if run.truth_q is None or not np.all(np.isfinite(run.truth_q[-1])):
        return (float("nan"),) * 3
    roll, pitch, yaw = quaternion.to_euler(run.truth_q[-1])
    return float(np.degrees(pitch)), float(np.degrees(roll)), float(_wrap180(np.degrees(np.asarray(yaw))))


def _errors(est: NDArray[np.float64], truth: NDArray[np.float64]) -> NDArray[np.float64]:
    """(rows, 6) errors in ERRORS order."""
    e = metrics.attitude_errors(est, truth)
    return np.column_stack([getattr(e, name) for name in ERRORS])


def _error_series(run: Run) -> tuple[NDArray[np.float64], NDArray[np.float64], tuple[float, ...]]:
    """Times and errors at SERIES_POINTS evenly spaced steps, and the error at the last step with a
    truth (NaN where there is no truth)."""
    n = run.cycles
    rows = np.unique(np.linspace(0, n - 1, min(n, SERIES_POINTS)).round().astype(np.int64))
    series = np.full((len(rows), len(ERRORS)), np.nan)
    final = (float("nan"),) * len(ERRORS)
    if run.truth_q is not None and n:
        est, _ = aligned_estimate(run)
        valid = metrics.valid_mask(run.truth_q)
        ok = rows[valid[rows]]
        if len(ok):
            series[valid[rows]] = _errors(est[ok], run.truth_q[ok])
        if valid.any():
            last = int(np.flatnonzero(valid)[-1])
            final = tuple(float(x) for x in _errors(est[[last]], run.truth_q[[last]])[0])
    return run.time_s[rows].astype(np.float64), series, final


def _alpha_errors(run: Run) -> tuple[float, float, float]:
    """The wing unit's α against the trace's truth (:data:`ALPHA_ERRORS`, degrees): NaN where the run
    has none (another board, a trace without ``truth_alpha_deg``, no still or no moving step)."""
    alpha = run.wing.get("alpha_deg")
    if alpha is None or run.truth_alpha_deg is None or run.alpha_still is None:
        return (float("nan"),) * 3
    e = metrics.alpha_errors(alpha, run.truth_alpha_deg, run.alpha_still)

    def worst(part: dict[str, Any]) -> float:
        x = part.get("max_abs_deg")
        return float("nan") if x is None else float(x)

    final = e["final_error_deg"]
    return (float("nan") if final is None else float(final), worst(e["static"]), worst(e["dynamic"]))


def run_job(job: Job, trace: PhysicalTrace | CheckedTrace) -> Outcome:
    """Run one job on its case's trace: the pure function every engine calls. For the wing unit the
    figures are α's (:func:`_alpha_errors`); its quaternion is the wing's own frame, so the attitude
    errors are NaN."""
    run = emulate(trace, job.profile())
    if has_wing(run.profile):
        nan = float("nan")
        points = min(run.cycles, SERIES_POINTS)
        return Outcome(
            key=job.key,
            solved_deg=(nan,) * 3,
            truth_deg=(nan,) * 3,
            final_error_deg=(nan,) * len(ERRORS),
            t_s=np.zeros(points),
            error_deg=np.full((points, len(ERRORS)), nan),
            fingerprint=fingerprint(),
            alpha_error_deg=_alpha_errors(run),
            wing=True,
        )
    t_s, series, final = _error_series(run)
    return Outcome(
        key=job.key,
        solved_deg=_final_angles(run),
        truth_deg=_truth_angles(run),
        final_error_deg=final,
        t_s=t_s,
        error_deg=series,
        fingerprint=fingerprint(),
    )


# ---------------------------------------------------------------------------------------------------
# Engines: run jobs, yield results as they complete
# ---------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Failure:
    """A job that raised: its key and the error (``input_error``: a sins-fw InputError)."""

    key: Any
    error: str
    input_error: bool = False


#: The function an engine applies: (job, its trace) → result. Jobs have ``case`` and ``key``.
JobFunction = Callable[[Any, Any], Any]


def attempt(fn: JobFunction, job: Any, trace: Any) -> Any:
    """``fn(job, trace)``, or a :class:`Failure` saying why it raised."""
    try:
        return fn(job, trace)
    except SinsError as e:
        return Failure(job.key, str(e), isinstance(e, InputError))
    except Exception as e:
        return Failure(job.key, f"{type(e).__name__}: {e}")


class Engine(Protocol):
    """Runs jobs somewhere and yields each result (or Failure) as it completes, in any order.
    Closing the iterator early (an error, Ctrl-C) cancels the jobs not yet run."""

    name: str

    def run(self, fn: JobFunction, jobs: Sequence[Any], traces: Mapping[str, Any]) -> Iterator[Any]: ...

    def describe(self) -> str: ...

    def close(self) -> None: ...


@dataclass(frozen=True)
class Batch:
    """Jobs that one task of an engine runs one after the other: pure data, like a job. An engine
    that pays for each task (Dask: its scheduler and client, a few ms a task in the driving process)
    runs batches to pay once for several jobs; each job's result is still its own."""

    jobs: tuple[Any, ...]

    @property
    def cases(self) -> tuple[str, ...]:
        """The cases (trace names) its jobs need, each once."""
        return tuple(dict.fromkeys(job.case for job in self.jobs))


#: Batches per worker the default batch size aims at (:func:`batch_size`).
BATCHES_PER_WORKER = 4
#: The default batch size's upper bound: jobs per batch.
MAX_BATCH = 32


def batch_size(jobs: int, workers: int) -> int:
    """The default batch size for ``jobs`` jobs on ``workers`` parallel workers: each worker gets at
    least :data:`BATCHES_PER_WORKER` batches (so that the workers finish together, and a lost
    worker or an interruption loses little work), a batch holds at most :data:`MAX_BATCH` jobs (so
    that the progress bar keeps moving), and at least one:
    ``max(1, min(MAX_BATCH, jobs // (BATCHES_PER_WORKER * workers)))``. At 32 jobs a batch, a task
    overhead of 7 ms costs 0.2 ms a realisation of about 80 ms."""
    return max(1, min(MAX_BATCH, jobs // (BATCHES_PER_WORKER * max(1, workers))))


def batches(jobs: Sequence[Any], size: int) -> list[Batch]:
    """The jobs in order, cut into batches of ``size`` (the last may be shorter)."""
    return [Batch(tuple(jobs[i : i + size])) for i in range(0, len(jobs), size)]


def attempt_batch(fn: JobFunction, batch: Batch, traces: Mapping[str, Any]) -> list[Any]:
    """:func:`attempt` on each job of a batch, in order: a job that raises does not stop the others."""
    return [attempt(fn, job, traces[job.case]) for job in batch.jobs]


#: A pool worker's traces, installed once by the pool's initializer.
_worker_traces: Mapping[str, Any] = {}


def _install_traces(traces: Mapping[str, Any]) -> None:
    global _worker_traces
    _worker_traces = traces


def _attempt_here(fn: JobFunction, job: Any) -> Any:
    return attempt(fn, job, _worker_traces[job.case])


class LocalEngine:
    """Processes on this machine (``workers`` ≤ 1: in this process)."""

    name = "local"

    def __init__(self, workers: int = 1) -> None:
        if workers < 1:
            raise InputError(f"--workers {workers}: expected at least 1")
        self.workers = workers

    def describe(self) -> str:
        return f"local, {self.workers} process{'es' if self.workers > 1 else ''}"

    def run(self, fn: JobFunction, jobs: Sequence[Any], traces: Mapping[str, Any]) -> Iterator[Any]:
        if self.workers <= 1 or len(jobs) <= 1:
            for job in jobs:
                yield attempt(fn, job, traces[job.case])
            return
        pool = ProcessPoolExecutor(
            max_workers=min(self.workers, len(jobs)), initializer=_install_traces, initargs=(traces,)
        )
        try:
            futures = [pool.submit(_attempt_here, fn, job) for job in jobs]
            for future in pool_completed(futures):
                yield future.result()
        finally:
            pool.shutdown(wait=True, cancel_futures=True)

    def close(self) -> None:
        pass

    def __enter__(self) -> LocalEngine:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


DASK_EXTRA = 'the dask engine needs the optional extra: pip install "sins-fw[dask]"'


def import_distributed() -> ModuleType:
    """``dask.distributed``, or an InputError saying how to install it."""
    try:
        import distributed  # the optional `dask` extra: tried only for `--engine dask`
    except ImportError:
        raise InputError(DASK_EXTRA) from None
    return distributed


class DaskEngine:
    """A Dask distributed cluster: an existing scheduler (``scheduler="tcp://HOST:PORT"``) or a
    ``LocalCluster`` of ``local_workers`` single-threaded processes bound to 127.0.0.1.

    Each task runs a :class:`Batch` of ``batch`` jobs (default: :func:`batch_size` of the job count
    and the cluster's worker threads when the run starts); the results are yielded one by one as
    their batch completes. A worker lost in the middle of a batch has its batches rescheduled whole
    by Dask on the others (a batch's results come back together or not at all)."""

    name = "dask"

    def __init__(
        self, scheduler: str | None = None, local_workers: int | None = None, *, batch: int | None = None
    ) -> None:
        if (scheduler is None) == (local_workers is None):
            raise InputError("--engine dask: give either --scheduler tcp://HOST:PORT or --local-workers N")
        if local_workers is not None and local_workers < 1:
            raise InputError(f"--local-workers {local_workers}: expected at least 1")
        if batch is not None and batch < 1:
            raise InputError(f"--batch {batch}: expected at least 1 job a task")
        #: Jobs per task (None: :func:`batch_size`); the size of the last run's batches.
        self.batch = batch
        self.last_batch: int | None = None
        distributed = import_distributed()
        self._cluster: Any = None
        # A nanny sets its workers' variables (MALLOC_TRIM_THRESHOLD_, OMP_NUM_THREADS, ...) in the
        # environment of the process that starts it, and so of every later subprocess: close() puts
        # ours back.
        self._environ = dict(os.environ)
        if local_workers is not None:
            # Dask's nannies start workers with MALLOC_TRIM_THRESHOLD_=65536, which also switches off
            # glibc's adaptive mmap threshold: every array above 128 KiB is then mapped and unmapped
            # afresh, and a 240 s realisation takes 5x the minor page faults (35 k -> 181 k for 12
            # jobs) and about 40 ms more per job. Our workers keep glibc's default.
            import dask

            with dask.config.set({"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}):
                self._cluster = distributed.LocalCluster(
                    n_workers=local_workers,
                    threads_per_worker=1,
                    processes=True,
                    host="127.0.0.1",
                    dashboard_address=None,
                    silence_logs=logging.ERROR,
                )
            self.client: Any = distributed.Client(self._cluster)
        else:
            try:
                self.client = distributed.Client(scheduler, timeout="20s")
            except (OSError, TimeoutError, ValueError) as e:
                raise InputError(f"--scheduler {scheduler}: cannot connect ({e})") from None

    def _threads(self) -> int:
        """The cluster's worker threads now (tasks it runs at once)."""
        return sum(w["nthreads"] for w in self.client.scheduler_info()["workers"].values())

    def describe(self) -> str:
        workers = len(self.client.scheduler_info()["workers"])
        text = f"dask at {self.client.scheduler.address}, {workers} worker{'s' if workers != 1 else ''}"
        if self.last_batch is not None:
            text += f", {self.last_batch} run{'s' if self.last_batch != 1 else ''} a task"
        return text

    def run(self, fn: JobFunction, jobs: Sequence[Any], traces: Mapping[str, Any]) -> Iterator[Any]:
        distributed = import_distributed()
        client = self.client
        size = self.batch or batch_size(len(jobs), self._threads())
        self.last_batch = size
        # Every worker gets each trace once; a copy on every worker survives the loss of any one.
        scattered: dict[str, Any] = {}
        futures: list[Any] = []
        try:
            for name in dict.fromkeys(job.case for job in jobs):
                scattered[name] = client.scatter(traces[name], broadcast=True, hash=False)
            work = batches(jobs, size)
            futures = [
                client.submit(attempt_batch, fn, b, {c: scattered[c] for c in b.cases}, pure=False)
                for b in work
            ]
            batch_of = {future.key: b for future, b in zip(futures, work, strict=True)}
            for future in distributed.as_completed(futures):
                try:
                    results = future.result()
                except Exception as e:
                    # The scheduler gave up on the batch (e.g. it killed worker after worker).
                    results = [
                        Failure(job.key, f"{type(e).__name__}: {e}") for job in batch_of[future.key].jobs
                    ]
                yield from results
        finally:
            client.cancel([*futures, *scattered.values()])

    def close(self) -> None:
        if self._cluster is None:
            with contextlib.suppress(Exception):
                self.client.close()
            return
        # Our own scheduler logs every message it can no longer send to the departing client (after an
        # interruption, as CRITICAL with a traceback): the cluster is going away, they say nothing.
        logger = logging.getLogger("distributed")
        level = logger.level
        logger.setLevel(logging.CRITICAL + 1)
        try:
            with contextlib.suppress(Exception):
                self.client.close()
            with contextlib.suppress(Exception):
                self._cluster.close()
        finally:
            logger.setLevel(level)
            for key in set(os.environ) - set(self._environ):
                del os.environ[key]
            os.environ.update(self._environ)

    def __enter__(self) -> DaskEngine:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def make_engine(
    name: str = "local",
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    local_workers: int | None = None,
    batch: int | None = None,
) -> LocalEngine | DaskEngine:
    """An engine by name: ``local`` (``workers`` processes) or ``dask`` (``scheduler`` or
    ``local_workers``; ``batch`` jobs a task)."""
    if name == "local":
        if scheduler is not None or local_workers is not None or batch is not None:
            raise InputError("--scheduler, --local-workers and --batch go with --engine dask")
        return LocalEngine(default_workers() if workers is None else workers)
    if name == "dask":
        return DaskEngine(scheduler, local_workers, batch=batch)
    raise InputError(f"--engine {name}: expected local or dask")


# ---------------------------------------------------------------------------------------------------
# Collecting: same bits everywhere
# ---------------------------------------------------------------------------------------------------

#: Called after each result with (completed, failed, total).
Progress = Callable[[int, int, int], None]


def admit(results: dict[JobKey, Outcome], outcome: Outcome) -> None:
    """Add one result: its fingerprint must be that of the results so far, and a job already seen
    must have given the same bits."""
    if results:
        first = next(iter(results.values()))
        if outcome.fingerprint != first.fingerprint:
            raise InputError(
                f"results from different software: job {outcome.key} was computed by "
                f"[{outcome.fingerprint}], earlier ones by [{first.fingerprint}]; install the same "
                "sins-fw build on every worker"
            )
    seen = results.get(outcome.key)
    if seen is None:
        results[outcome.key] = outcome
    elif not seen.same_as(outcome):
        raise InternalError(f"job {outcome.key} gave two different results: the emulation is not repeatable")


def checked_traces(traces: Mapping[str, PhysicalTrace | CheckedTrace]) -> dict[str, CheckedTrace]:
    """Each trace checked once, here, as ``emulate`` would check it in every job (a
    :class:`~sins_fw.traces.CheckedTrace`, which the jobs then take as it is); a bad trace is the
    same TraceError, naming its case, before any job runs."""
    out = {}
    for name, trace in traces.items():
        try:
            out[name] = trace if isinstance(trace, CheckedTrace) else CheckedTrace(trace)
        except TraceError as e:
            raise TraceError(f"case `{name}`: {e}") from None
    return out


def collect(
    engine: Engine,
    jobs: Sequence[Job],
    traces: Mapping[str, PhysicalTrace | CheckedTrace],
    *,
    progress: Progress | None = None,
) -> list[Outcome]:
    """Run the jobs on the engine; the results in the order of the jobs, whatever order they
    completed in (a job listed twice gives one result). The traces are checked once, before any
    job (:func:`checked_traces`).
    Raises if any job failed (after all have run), naming it; closing early cancels the rest."""
    results: dict[JobKey, Outcome] = {}
    failures: list[Failure] = []
    checked = checked_traces(traces)
    with contextlib.closing(engine.run(run_job, jobs, checked)) as stream:
        for item in stream:
            if isinstance(item, Failure):
                failures.append(item)
            else:
                admit(results, item)
            if progress is not None:
                progress(len(results), len(failures), len(jobs))
    if failures:
        first = failures[0]
        text = f"{len(failures)} of {len(jobs)} runs failed; the first, {first.key}: {first.error}"
        raise InputError(text) if first.input_error else InternalError(text)
    return [results[k] for k in dict.fromkeys(job.key for job in jobs)]


def few_runs_warning(n: int) -> str | None:
    """The warning for percentiles that rest on n runs, or None."""
    if n >= FEW_RUNS:
        return None
    return (
        f"percentiles over {n} run{'s' if n != 1 else ''}: p5 and p95 are then the sample's extremes "
        f"and move a lot from one set of seeds to another; use at least {FEW_RUNS} runs (hundreds for "
        "stable tails)"
    )


# ---------------------------------------------------------------------------------------------------
# Monte Carlo over seeds
# ---------------------------------------------------------------------------------------------------


@dataclass
class Distribution:
    """Results of one case over the seeds."""

    case: Case
    seeds: list[int]
    solved_deg: NDArray[np.float64]  # (runs, 3): pitch, roll, yaw
    truth_deg: NDArray[np.float64]  # (runs, 3)
    final_error_deg: NDArray[np.float64]  # (runs, 6): ERRORS
    t_s: NDArray[np.float64]  # (points,)
    error_series_deg: NDArray[np.float64]  # (runs, points, 6)
    outcomes: list[Outcome]  # the results themselves, by seed

    @property
    def alpha_error_deg(self) -> NDArray[np.float64]:
        """The wing unit's α errors (runs, 3): :data:`ALPHA_ERRORS`."""
        return np.array([o.alpha_error_deg for o in self.outcomes], dtype=np.float64).reshape(-1, 3)

    @property
    def is_wing(self) -> bool:
        """The runs are the wing unit's (their figures are α's)."""
        return bool(self.outcomes) and all(o.wing for o in self.outcomes)

    @property
    def runs_without_alpha(self) -> int:
        """Wing runs that never gave an α against the truth (no axis, or no α truth)."""
        return int(np.sum(~np.isfinite(self.alpha_error_deg).any(axis=1)))

    @classmethod
    def of(cls, case: Case, outcomes: Sequence[Outcome]) -> Distribution:
        """The distribution of one case's outcomes (sorted by seed)."""
        rows = sorted((o for o in outcomes if o.key[0] == case.name), key=lambda o: o.key[2])
        return cls(
            case,
            [o.key[2] for o in rows],
            np.array([o.solved_deg for o in rows], dtype=np.float64).reshape(-1, 3),
            np.array([o.truth_deg for o in rows], dtype=np.float64).reshape(-1, 3),
            np.array([o.final_error_deg for o in rows], dtype=np.float64).reshape(-1, len(ERRORS)),
            rows[0].t_s if rows else np.zeros(0),
            np.array([o.error_deg for o in rows], dtype=np.float64),
            rows,
        )

    @property
    def error_deg(self) -> NDArray[np.float64]:
        """Pitch, roll and yaw errors at the end (runs, 3), yaw wrapped to ±180°."""
        return self.final_error_deg[:, :3]

    def errors(self, name: str) -> NDArray[np.float64]:
        """One error at the end over the runs (a name of :data:`ERRORS`)."""
        return self.final_error_deg[:, ERRORS.index(name)]

    def percentiles(self, of: str = "solved") -> dict[str, dict[str, float]]:
        """Percentiles of the solved angles (``of="solved"``: pitch, roll, yaw), of the errors at the
        end (``"error"``: every name of :data:`ERRORS`) or of the wing unit's α errors (``"alpha"``:
        the names of :data:`ALPHA_ERRORS` some run has, over the runs that have it)."""
        if of == "alpha":
            data, names = self.alpha_error_deg, ALPHA_ERRORS
            have = [i for i in range(len(names)) if np.isfinite(data[:, i]).any()]
            return {names[i]: _percentiles(data[np.isfinite(data[:, i]), i]) for i in have}
        data, names = (self.solved_deg, ERRORS[:3]) if of == "solved" else (self.final_error_deg, ERRORS)
        return {name: _percentiles(data[:, i]) for i, name in enumerate(names)}

    def rank(self, value: float, axis: int) -> float:
        """Percentile rank (0–100) of a value among the solved values of one angle: the share of runs
        below it, ties counting half."""
        col = self.solved_deg[:, axis]
        return float(100.0 * (np.sum(col < value) + 0.5 * np.sum(col == value)) / len(col))


def _percentiles(x: NDArray[np.float64]) -> dict[str, float]:
    values = np.percentile(x, PERCENTILES)
    return {f"p{p:g}": float(v) for p, v in zip(PERCENTILES, values, strict=True)}


def jobs_for(
    cases: Sequence[Case], seeds: Sequence[int], profile: Profile, points: Sequence[tuple[str, ...]] = ((),)
) -> list[Job]:
    """Every case × grid point × seed as jobs (the profile's overrides carried along)."""
    return [
        Job(c.name, seed, profile.source, profile.text, profile.overrides, point)
        for c in cases
        for point in points
        for seed in seeds
    ]


def run_cases(
    cases: Sequence[Case],
    runs: int,
    *,
    profile: Profile | str = "reference",
    overrides: Sequence[str] = (),
    workers: int = 1,
    first_seed: int = 1,
    engine: Engine | None = None,
    progress: Progress | None = None,
) -> dict[str, Distribution]:
    """Run every case with seeds first_seed … first_seed+runs−1 on ``engine`` (default: ``workers``
    local processes). The error model is the profile's (`errors.preset`); only `errors.seed` changes
    between runs."""
    prof = profile if isinstance(profile, Profile) else load_profile(profile)
    prof = prof.with_overrides(*overrides) if overrides else prof
    jobs = jobs_for(cases, range(first_seed, first_seed + runs), prof)
    traces = {c.name: c.trace() for c in cases}
    outcomes = collect(engine or LocalEngine(workers), jobs, traces, progress=progress)
    return {c.name: Distribution.of(c, outcomes) for c in cases}


def published_cases() -> list[Case]:
    """The reference design's experiments as scenarios.

    The thesis does not give the table's speed or dwell: the ±30° cases move from 0 to ±30° in the
    published 10° steps with the `sweep` preset's table (20 °/s, 40 °/s², 5 s dwell), and the solved
    angle is read at the end of the dwell at ±30°. The yaw case is the `yaw25.8` preset (a fast
    rotation, then 30 s hold)."""
    cases = []
    axis_of = {0: "y", 1: "x", 2: "z"}  # pitch, roll, yaw
    for truth in PUBLISHED_PM30:
        k = next(i for i, v in enumerate(truth) if v != 0.0)
        target = truth[k]
        steps = tuple(
            float(a) for a in np.arange(0.0, target + np.sign(target) * 10.0, np.sign(target) * 10.0)
        )
        cases.append(
            Case(
                name=f"{['pitch', 'roll', 'yaw'][k]} {target:+.0f}",
                scenario="indexing-table",
                preset="sweep",
                params=(("axis", axis_of[k]), ("angles_deg", steps)),
                truth_deg=truth,
            )
        )
    cases.append(Case("yaw 25.8 hold 30 s", "indexing-table", "yaw25.8", (), (0.0, 0.0, 25.8)))
    return cases


def published_report(dists: dict[str, Distribution]) -> list[dict[str, Any]]:
    """Per case and angle: the distribution's percentiles and the published value's rank in it."""
    rows = []
    for (truth, solved), case in zip(PUBLISHED_PM30.items(), published_cases(), strict=False):
        d = dists[case.name]
        for i, name in enumerate(("pitch", "roll", "yaw")):
            rows.append(_row(case.name, name, truth[i], solved[i], d, i))
    d = dists["yaw 25.8 hold 30 s"]
    for i, name in enumerate(("pitch", "roll", "yaw")):
        # Published as absolute errors after 30 s: compare with |solved − truth|.
        err = np.abs(d.error_deg[:, i])
        published = PUBLISHED_YAW_HOLD[i]
        values = np.percentile(err, PERCENTILES)
        rows.append(
            {
                "case": d.case.name,
                "angle": f"|{name} error|",
                "truth_deg": 0.0,
                "published_deg": published,
                "percentiles_deg": {f"p{p:g}": float(v) for p, v in zip(PERCENTILES, values, strict=True)},
                "published_rank": float(100.0 * np.mean(err < published)),
            }
        )
    return rows


def _row(case: str, angle: str, truth: float, published: float, d: Distribution, i: int) -> dict[str, Any]:
    return {
        "case": case,
        "angle": angle,
        "truth_deg": truth,
        "published_deg": published,
        "percentiles_deg": d.percentiles()[angle],
        "published_rank": d.rank(published, i),
    }


def default_workers() -> int:
    return max(1, min(len(os.sched_getaffinity(0)), 8))
