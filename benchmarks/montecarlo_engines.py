"""Monte Carlo realisations per second on the local and Dask engines, 1 and 2 workers, in one run,
and the per-task overhead of each engine (an empty job). Target: ≥ 1.8× from one worker to two.

Each configuration runs the same seeded realisations (``static`` scenario, ``errors.preset=adis16407``,
the reference profile); the trace is generated and checked once (a ``CheckedTrace``, as
``montecarlo.collect`` makes). The engines are started (and warmed with one round) before timing:
local 1 runs in this process, local 2 starts its process pool inside each timed round (as every
``sins-fw montecarlo`` does), dask N is a LocalCluster of N single-threaded worker processes bound
to 127.0.0.1, running its default batches (``montecarlo.batch_size``). Each engine is started for
its own round only and closed after it (an idle LocalCluster costs the process holding it CPU, which
would otherwise be charged to the configurations timed while it waits); its start-up and warm-up
are outside the timed part. The
configurations are timed in turns for ``--rounds`` rounds, so that a slow spell of a shared machine
falls on all of them: figures are medians. The load average before and after is recorded: on a
loaded machine two workers cannot scale by two.

    python benchmarks/montecarlo_engines.py [--duration-s 240] [--runs 32] [--rounds 3] [--output F]
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import statistics
import subprocess
import time
from pathlib import Path
from typing import Any

from sins_fw import montecarlo as mc
from sins_fw.atomic import write_text
from sins_fw.profile import load_profile
from sins_fw.traces import CheckedTrace

HERE = Path(__file__).resolve().parent
TARGET_SCALING = 1.8


def empty_job(job: mc.Job, trace: Any) -> None:
    """A job that does nothing: what is left is the engine's own cost per task."""


def cpu_timed_job(job: mc.Job, trace: Any) -> tuple[mc.Outcome, float]:
    """``run_job`` and the CPU seconds the worker's thread spent on it: what a realisation costs
    where it runs, apart from the engine around it."""
    t0 = time.thread_time()
    outcome = mc.run_job(job, trace)
    return outcome, time.thread_time() - t0


def cpu_model() -> str:
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            return line.split(":", 1)[1].strip()
    return platform.processor() or "unknown"


def commit() -> str:
    r = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, check=False)
    return r.stdout.strip() or "unknown"


def timed(engine: Any, fn: Any, jobs: list[mc.Job], traces: dict[str, Any]) -> tuple[float, float, float]:
    """Wall seconds of the round, the CPU seconds its jobs took in the workers (for
    :func:`cpu_timed_job`; 0 otherwise) and the CPU seconds of this driving process (all its
    threads: the pool's feeder, Dask's client and, for a local cluster, its scheduler)."""
    jobs_cpu = 0.0
    c0 = time.process_time()
    t0 = time.perf_counter()
    for item in engine.run(fn, jobs, traces):
        if isinstance(item, mc.Failure):
            raise RuntimeError(f"{item.key}: {item.error}")
        if isinstance(item, tuple):
            jobs_cpu += item[1]
    wall = time.perf_counter() - t0
    return wall, jobs_cpu, time.process_time() - c0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration-s", type=float, default=240.0, help="trace length per realisation")
    ap.add_argument("--runs", type=int, default=32, help="realisations per round")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--empty", type=int, default=400, help="empty jobs for the overhead")
    ap.add_argument("--output", type=Path, default=HERE / "montecarlo_engines.md")
    args = ap.parse_args()

    load_before = os.getloadavg()
    case = mc.Case("static", "static", None, (("duration_s", args.duration_s),), (0.0, 0.0, 0.0))
    traces = {case.name: CheckedTrace(case.trace())}
    profile = load_profile("reference", ["errors.preset=adis16407"])
    jobs = mc.jobs_for([case], range(1, args.runs + 1), profile)
    empties = mc.jobs_for([case], range(1, args.empty + 1), profile)
    engines: dict[str, Any] = {
        "local 1": lambda: mc.LocalEngine(1),
        "local 2": lambda: mc.LocalEngine(2),
        "dask 1": lambda: mc.DaskEngine(local_workers=1),
        "dask 2": lambda: mc.DaskEngine(local_workers=2),
    }
    walls: dict[str, list[float]] = {name: [] for name in engines}
    job_cpu: dict[str, list[float]] = {name: [] for name in engines}
    driver_cpu: dict[str, list[float]] = {name: [] for name in engines}
    batch: dict[str, int] = {}
    overhead: dict[str, tuple[float, float]] = {}

    def started(name: str) -> Any:
        """The engine, up and warmed (imports, the scattered trace, the workers' caches)."""
        engine = engines[name]()
        timed(engine, cpu_timed_job, jobs[:4], traces)
        return engine

    for _ in range(args.rounds):
        for name in engines:
            engine = started(name)
            try:
                wall, cpu, driver = timed(engine, cpu_timed_job, jobs, traces)
                if isinstance(engine, mc.DaskEngine):
                    batch[name] = engine.last_batch or 1
            finally:
                engine.close()
            walls[name].append(wall)
            job_cpu[name].append(cpu / len(jobs))
            driver_cpu[name].append(driver)
    for name, per_task in (("local 2", None), ("dask 1", None), ("dask 2", None), ("dask 2", 1)):
        engine = started(name)
        try:
            if per_task is not None:
                engine.batch = per_task
            wall, _, driver = timed(engine, empty_job, empties, traces)
            label = name if name.startswith("local") else f"{name}, {engine.last_batch} runs a task"
        finally:
            engine.close()
        overhead[label] = (wall / len(empties), driver / len(empties))
    load_after = os.getloadavg()

    rate = {name: args.runs / statistics.median(w) for name, w in walls.items()}
    scaling = {kind: rate[f"{kind} 2"] / rate[f"{kind} 1"] for kind in ("local", "dask")}
    lines = [
        "# Monte Carlo engines: realisations per second, 1 and 2 workers",
        "",
        f"`python benchmarks/montecarlo_engines.py --duration-s {args.duration_s:g} --runs {args.runs} "
        f"--rounds {args.rounds} --empty {args.empty}` at {commit()}, "
        f"{datetime.date.today().isoformat()}, on {cpu_model()} ({os.cpu_count()} cores), "
        f"Python {platform.python_version()}.",
        "",
        f"Load average (1, 5, 15 min) before: {', '.join(f'{x:.2f}' for x in load_before)}; "
        f"after: {', '.join(f'{x:.2f}' for x in load_after)}. On {os.cpu_count()} cores a load above "
        f"{os.cpu_count()} means other processes competed for them and two workers cannot double the rate.",
        "",
        f"Each realisation: `static` {args.duration_s:g} s, `errors.preset=adis16407`, reference profile; "
        f"{args.runs} realisations per round, medians of {args.rounds} rounds taken in turns.",
        "",
        "| engine | workers | runs a task | wall per round (median), s | rounds, s | realisations/s |",
        "|---|---:|---:|---:|---|---:|",
    ]
    for name, w in walls.items():
        kind, n = name.split()
        samples = ", ".join(f"{x:.2f}" for x in w)
        per_task = batch.get(name, 1)
        lines.append(
            f"| {kind} | {n} | {per_task} | {statistics.median(w):.3f} | {samples} | {rate[name]:.1f} |"
        )
    lines += [
        "",
        "| engine | scaling 1 → 2 workers | target | met |",
        "|---|---:|---:|---|",
    ]
    for kind, s in scaling.items():
        lines.append(f"| {kind} | {s:.2f}× | {TARGET_SCALING}× | {'yes' if s >= TARGET_SCALING else 'no'} |")
    cpu1 = {kind: statistics.median(job_cpu[f"{kind} 1"]) for kind in ("local", "dask")}
    cpu2 = {kind: statistics.median(job_cpu[f"{kind} 2"]) for kind in ("local", "dask")}
    lines += [
        "",
        "Where the time goes. *CPU per realisation* is the worker thread's CPU time for one `run_job`",
        "(median over rounds of the round's mean): if two workers side by side make each realisation",
        "cost more CPU than one alone, the machine itself (shared caches, memory bandwidth, the",
        "hypervisor) caps the scaling at the ratio of the two, whatever the engine does. *Driving",
        "process CPU* is this process's CPU time over a round, all threads (for local 1 it includes the",
        "realisations themselves, which run in it).",
        "",
        "| engine | workers | CPU per realisation, ms | driving process CPU per round, s |",
        "|---|---:|---:|---:|",
    ]
    for name in walls:
        kind, n = name.split()
        lines.append(
            f"| {kind} | {n} | {1e3 * statistics.median(job_cpu[name]):.1f} "
            f"| {statistics.median(driver_cpu[name]):.3f} |"
        )
    lines += [""]
    for kind in ("local", "dask"):
        ceiling = 2.0 * cpu1[kind] / cpu2[kind]
        lines.append(
            f"- {kind}: a realisation costs {cpu2[kind] / cpu1[kind]:.3f}× the CPU with two workers side by "
            f"side, so the work alone caps the scaling at {ceiling:.2f}×; the engine reaches "
            f"{scaling[kind]:.2f}× ({100 * scaling[kind] / ceiling:.0f} % of that cap)."
        )
    lines += [
        "",
        f"Overhead per run (an empty job, {args.empty} of them; wall time per job, workers sharing them,",
        "and the driving process's CPU time per job):",
        "",
        *(f"- {name}: {1e3 * t:.2f} ms wall, {1e3 * c:.2f} ms CPU" for name, (t, c) in overhead.items()),
        "",
    ]
    text = "\n".join(lines)
    print(text)
    write_text(args.output, text)


if __name__ == "__main__":
    main()
