"""The benchmark suite (`sins-fw bench`, `make bench`): emulated 8 ms cycles per second and peak memory
of the full pipeline, against what a user would write instead and against the bare RK4 step.

Every figure is measured in one run on the same input (a coning trace at 819.2 SPS from
:mod:`sins_fw.synth`). Rates are emulated cycles per second of CPU time of the measuring thread
(`time.thread_time`: the machine may be shared, CPU time is what one core delivers), the median of
repeated runs; wall-clock rates are reported beside them. Each pipeline case runs in a fresh process
so that its peak RSS (`ru_maxrss`) is its own.
"""

from __future__ import annotations

import concurrent.futures as cf
import datetime
import functools
import math
import os
import platform
import resource
import statistics
import subprocess
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np

from sins_fw import _core, synth
from sins_fw.harness import emulate
from sins_fw.profile import load_profile
from sins_fw.traces import PhysicalTrace

#: The firmware's attitude step, s (two 4 ms reads per step).
STEP_S = 0.008
#: The pipeline cases: name → profile overrides (reference profile: published decode, RK4, Euler,
#: navigation, budget recording; transaction-level SPI unless set).
ADIS = "errors.preset=adis16407"
CASES: dict[str, tuple[str, ...]] = {
    "full_f64": ('firmware.numeric="f64"', ADIS),
    "c28x_f32": ('firmware.numeric="c28x-f32"', ADIS),
    "iq": ('firmware.numeric="iq"', ADIS),
    "bit_level_f64": ('firmware.numeric="f64"', ADIS, 'spi.level="bit"'),
    "full_f64_ideal_sensor": ('firmware.numeric="f64"',),
}
#: Targets of issue 8.
TARGET_CYCLES_PER_S = 1_000_000
TARGET_BIT_LEVEL_CYCLES_PER_S = 200_000
TARGET_VS_BASELINE = 100.0
TARGET_VS_LOWER_BOUND = 4.0
TARGET_LONG_RSS_MB = 300.0
TARGET_SCALING = 1.8


@functools.lru_cache(maxsize=2)
def coning_trace(duration_s: float) -> PhysicalTrace:
    """The common input: classical coning (1°, 10 Hz) at 819.2 SPS."""
    return synth.generate("coning", duration_s=duration_s)


def _rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _timed(f: Callable[[], Any]) -> tuple[Any, float, float]:
    """(result, CPU s of this thread, wall s)."""
    c0, w0 = time.thread_time(), time.perf_counter()
    r = f()
    return r, time.thread_time() - c0, time.perf_counter() - w0


def pipeline_case(overrides: tuple[str, ...], duration_s: float, repeats: int) -> dict[str, Any]:
    """Emulate the coning trace `repeats` times (in this process): the CPU and wall time of each
    run and the peak RSS."""
    trace = coning_trace(duration_s)
    rss_before = _rss_mb()
    cpu, wall, cycles = [], [], 0
    for _ in range(repeats):
        run, c, w = _timed(lambda: emulate(trace, overrides=overrides, keep_truth=False))
        cycles = run.cycles
        cpu.append(c)
        wall.append(w)
        del run
    return {
        "overrides": list(overrides),
        "cycles": cycles,
        "cpu_samples_s": cpu,
        "wall_samples_s": wall,
        "peak_rss_mb": _rss_mb(),
        "rss_before_mb": rss_before,
    }


def pooled(rounds: list[dict[str, Any]]) -> dict[str, Any]:
    """One case measured in several rounds (each a fresh process): medians over every repeat of
    every round, the largest peak RSS."""
    cpu = [c for r in rounds for c in r["cpu_samples_s"]]
    wall = [w for r in rounds for w in r["wall_samples_s"]]
    c, w, cycles = statistics.median(cpu), statistics.median(wall), rounds[0]["cycles"]
    return {
        "overrides": rounds[0]["overrides"],
        "cycles": cycles,
        "cpu_s": c,
        "wall_s": w,
        "cycles_per_s": cycles / c,
        "best_cycles_per_s": cycles / min(cpu),
        "wall_cycles_per_s": cycles / w,
        "peak_rss_mb": max(r["peak_rss_mb"] for r in rounds),
        "rss_before_mb": rounds[0]["rss_before_mb"],
        "repeats": len(cpu),
        "rounds": len(rounds),
    }


def _in_child(f: Callable[..., dict[str, Any]], *args: Any) -> dict[str, Any]:
    """Run `f(*args)` in a fresh process (its own peak RSS)."""
    with cf.ProcessPoolExecutor(max_workers=1, mp_context=_spawn()) as pool:
        return pool.submit(f, *args).result()


def _spawn() -> Any:
    import multiprocessing  # only the benchmark that spawns workers needs it

    return multiprocessing.get_context("spawn")


# ---------------------------------------------------------------------------------------------------
# What a user would write instead
# ---------------------------------------------------------------------------------------------------


def numpy_loop(gyro_words: np.ndarray, steps: int) -> np.ndarray:
    """A straightforward NumPy/Python version of the firmware's loop: per 8 ms step decode the three
    14-bit gyro words of the half-step samples, RK4 on Q̇ = ½ Ω(ω) Q, normalise, extract Euler angles.
    `gyro_words` is (n, 3) uint16 (X/Y/Z GYRO_OUT, one row per 4 ms read). Returns the last quaternion
    and Euler angles (so nothing is skipped)."""
    lsb = math.radians(0.05)

    def decode(w: np.ndarray) -> np.ndarray:
        code = (w & 0x3FFF).astype(np.int64)
        code = np.where(code >= 0x2000, code - 0x4000, code)
        return code * lsb

    def omega(w: np.ndarray) -> np.ndarray:
        x, y, z = w
        return 0.5 * np.array([[0, -x, -y, -z], [x, 0, z, -y], [y, -z, 0, x], [z, y, -x, 0]])

    q = np.array([1.0, 0.0, 0.0, 0.0])
    euler = np.zeros(3)
    for k in range(steps):
        w0, w1, w2 = (decode(gyro_words[2 * k + i]) for i in range(3))
        m0, m1, m2 = omega(w0), omega(w1), omega(w2)
        k1 = m0 @ q
        k2 = m1 @ (q + 0.5 * STEP_S * k1)
        k3 = m1 @ (q + 0.5 * STEP_S * k2)
        k4 = m2 @ (q + STEP_S * k3)
        q = q + STEP_S / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        q = q / np.linalg.norm(q)
        q0, q1, q2, q3 = q
        euler = np.array(
            [
                np.arctan2(2 * (q2 * q3 + q0 * q1), q0 * q0 - q1 * q1 - q2 * q2 + q3 * q3),
                np.arcsin(np.clip(2 * (q0 * q2 - q1 * q3), -1.0, 1.0)),
                np.arctan2(2 * (q1 * q2 + q0 * q3), q0 * q0 + q1 * q1 - q2 * q2 - q3 * q3),
            ]
        )
    return np.concatenate([q, euler])


def ahrs_loop(rates: np.ndarray) -> np.ndarray:
    """`ahrs.filters.AngularRate` driven sample by sample on the decoded rates (rad/s, one row per
    4 ms read): two updates per 8 ms cycle, the same samples the firmware integrates."""
    from ahrs.filters import AngularRate  # the optional `bench` extra: only this comparison needs it

    f = AngularRate(frequency=1.0 / (STEP_S / 2))
    q = np.array([1.0, 0.0, 0.0, 0.0])
    for w in rates:
        q = f.update(q, w, method="closed", order=1, dt=STEP_S / 2)
    return q


def lower_bound(rates: np.ndarray, min_cpu_s: float) -> dict[str, Any]:
    """The firmware's RK4 step alone in Rust (f64) on pre-decoded rates, repeated until `min_cpu_s`."""
    rates = np.ascontiguousarray(rates, dtype=np.float64)
    cpu: list[float] = []
    steps = 0
    while sum(cpu) < min_cpu_s or len(cpu) < 3:
        (steps, _q), c, _ = _timed(lambda: _core.bench_rk4_lower_bound(rates, STEP_S))
        cpu.append(c)
    c = statistics.median(cpu)
    return {"cycles": steps, "cpu_s": c, "cycles_per_s": steps / c, "repeats": len(cpu)}


def firmware_stages(overrides: tuple[str, ...], reads: np.ndarray, min_cpu_s: float) -> dict[str, Any]:
    """The firmware's stages alone in Rust (f64: decode, RK4, Euler, navigation) on the burst words
    the board read (n×6 uint16), repeated until `min_cpu_s`: the firmware's own share of a cycle."""
    profile = load_profile("reference", overrides)
    reads = np.ascontiguousarray(reads, dtype=np.uint16)
    cpu: list[float] = []
    steps = 0
    while sum(cpu) < min_cpu_s or len(cpu) < 3:
        (steps, _q), c, _ = _timed(
            lambda: _core.bench_firmware_stages(profile.text, profile.source, list(profile.overrides), reads)
        )
        cpu.append(c)
    c = statistics.median(cpu)
    return {"cycles": steps, "cpu_s": c, "cycles_per_s": steps / c, "repeats": len(cpu)}


def baseline(f: Callable[[], Any], cycles: int, repeats: int) -> dict[str, Any]:
    cpu = [_timed(f)[1] for _ in range(repeats)]
    c = statistics.median(cpu)
    return {"cycles": cycles, "cpu_s": c, "cycles_per_s": cycles / c, "repeats": repeats}


# ---------------------------------------------------------------------------------------------------
# Long run (memory) and Monte Carlo (scaling)
# ---------------------------------------------------------------------------------------------------


def long_trace(duration_s: float, rows: int = 1 << 16) -> Iterator[PhysicalTrace]:
    """A trace of `duration_s` at 819.2 SPS generated chunk by chunk (never held whole): a board
    coning at 10 Hz about x with a slow yaw, 1 g up."""
    n = int(duration_s * 819.2)
    for i in range(0, n, rows):
        t = np.arange(i, min(i + rows, n)) / 819.2
        w = 2 * np.pi * 10.0
        a = math.radians(1.0)
        gyro = np.stack([np.full_like(t, 0.0), -a * w * np.sin(w * t), a * w * np.cos(w * t) + 0.1], axis=1)
        accel = np.zeros((len(t), 3))
        accel[:, 2] = 1.0
        yield PhysicalTrace(
            t_s=t, gyro_dps=np.degrees(gyro), accel_g=accel, metadata={"sample_rate_hz": "819.2"}
        )


def long_run(overrides: tuple[str, ...], duration_s: float) -> dict[str, Any]:
    """Stream `duration_s` of input through the emulator with the output streamed to a sink that
    keeps counts and the last attitude; peak RSS of this process."""
    kept = {"cycles": 0, "events": 0}
    last: dict[str, Any] = {}

    def sink(part: dict[str, Any]) -> None:
        kept["cycles"] += len(part["cycle_t_ps"])
        kept["events"] += len(part["events"])
        if len(part["cycle_quat"]):
            last["quat"] = part["cycle_quat"][-1].tolist()

    _, c, w = _timed(lambda: emulate(long_trace(duration_s), overrides=overrides, sink=sink))
    return {
        "duration_s": duration_s,
        "cycles": kept["cycles"],
        "events": kept["events"],
        "last_quat": last.get("quat"),
        "cpu_s": c,
        "wall_s": w,
        "cycles_per_s": kept["cycles"] / c,
        "peak_rss_mb": _rss_mb(),
    }


def _seeded_run(args: tuple[tuple[str, ...], float, int]) -> int:
    overrides, duration_s, seed = args
    return emulate(
        coning_trace(duration_s), overrides=(*overrides, f"errors.seed={seed}"), keep_truth=False
    ).cycles


def monte_carlo(overrides: tuple[str, ...], duration_s: float, runs: int, rounds: int) -> dict[str, Any]:
    """Wall time of `runs` seeded runs on 1 and 2 workers, processes and threads (the emulator
    releases the GIL in `run()`). Both pools of a kind are warmed up (imports, trace) before they are
    timed, then timed in turns for `rounds` rounds, so that a slow spell of a shared machine falls on
    both: the scaling is the ratio of the medians."""
    jobs = [(overrides, duration_s, seed) for seed in range(1, runs + 1)]
    out: dict[str, Any] = {"runs": runs, "duration_s": duration_s, "rounds": rounds}
    for kind in ("process", "thread"):
        pools: dict[int, cf.Executor] = {}
        walls: dict[int, list[float]] = {1: [], 2: []}
        cycles = 0
        try:
            for workers in (1, 2):
                if kind == "process":
                    pools[workers] = cf.ProcessPoolExecutor(max_workers=workers, mp_context=_spawn())
                else:
                    pools[workers] = cf.ThreadPoolExecutor(max_workers=workers)
                list(pools[workers].map(_seeded_run, [(overrides, duration_s, 0)] * workers))
            for _ in range(rounds):
                for workers in (1, 2):
                    t0 = time.perf_counter()
                    cycles = sum(pools[workers].map(_seeded_run, jobs))
                    walls[workers].append(time.perf_counter() - t0)
        finally:
            for pool in pools.values():
                pool.shutdown()
        wall_1, wall_2 = statistics.median(walls[1]), statistics.median(walls[2])
        out[kind] = {
            "wall_1_s": wall_1,
            "wall_2_s": wall_2,
            "wall_1_samples_s": walls[1],
            "wall_2_samples_s": walls[2],
            "cycles": cycles,
            "scaling": wall_1 / wall_2,
        }
    return out


# ---------------------------------------------------------------------------------------------------
# The suite
# ---------------------------------------------------------------------------------------------------


def machine() -> dict[str, Any]:
    cpu = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    try:
        commit = subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, check=False
        ).stdout.strip()
        # The results file a previous run wrote does not make the code dirty.
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--", ".", ":!benchmarks/results.md"],
            capture_output=True,
            text=True,
            check=False,
        ).stdout
        commit = (commit + ("+dirty" if dirty.strip() else "")) or "unknown"
    except OSError:
        commit = "unknown"
    return {
        "uname": " ".join(platform.uname()),
        "cpu": cpu,
        "cores": os.cpu_count(),
        "load_average": list(os.getloadavg()),
        "commit": commit,
        "date": datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "python": platform.python_version(),
        "numpy": np.__version__,
    }


def machine_line() -> str:
    """One line naming the machine, the commit and the date, for benchmark result files."""
    m = machine()
    return f"{m['uname']}; CPU: {m['cpu']} ({m['cores']} cores); commit {m['commit']}; {m['date']}"


def run_suite(quick: bool = False, progress: Callable[[str], None] | None = None) -> dict[str, Any]:
    """Measure every figure. `quick` shortens every input (for the smoke test), the figures are then
    rough."""
    say = progress or (lambda _m: None)
    duration = 20.0 if quick else 240.0
    # Every case runs in `rounds` rounds of `repeats`, the cases taking turns, so that a slow spell
    # of a shared machine falls on all of them rather than on one.
    rounds, repeats = (1, 1) if quick else (3, 3)
    long_s = 120.0 if quick else 86_400.0
    report: dict[str, Any] = {
        "quick": quick,
        "machine": machine(),
        "input": f"coning 1° 10 Hz, {duration:g} s",
    }
    measured: dict[str, list[dict[str, Any]]] = {name: [] for name in CASES}
    for r in range(rounds):
        for name, overrides in CASES.items():
            say(f"pipeline {name}, round {r + 1} of {rounds} …")
            measured[name].append(_in_child(pipeline_case, overrides, duration, repeats))
    pipeline = {name: pooled(parts) for name, parts in measured.items()}
    report["pipeline"] = pipeline

    say("same input, decoded: reads of the f64 run …")
    run = emulate(coning_trace(duration), overrides=CASES["full_f64"], keep_truth=False)
    words = np.ascontiguousarray(run.read_words[:, 2:5])
    rates = np.ascontiguousarray(run.read_rate)
    cycles = (len(rates) - 1) // 2
    n_py = min(cycles, 2_000 if quick else 20_000)
    say("NumPy/Python loop …")
    base = {"numpy_loop": baseline(lambda: numpy_loop(words, n_py), n_py, 1 if quick else 3)}
    say("ahrs AngularRate …")
    base["ahrs_angular_rate"] = baseline(lambda: ahrs_loop(rates[: 2 * n_py]), n_py, 1 if quick else 3)
    report["baselines"] = base
    say("RK4 lower bound …")
    report["lower_bound"] = lower_bound(rates, 0.05 if quick else 0.5)
    say("firmware stages alone …")
    reads = run.read_words[:, 2:8]
    report["firmware_stages"] = firmware_stages(CASES["full_f64"], reads, 0.05 if quick else 0.5)

    say(f"long run, {long_s:g} s streamed …")
    report["long_run"] = _in_child(long_run, CASES["full_f64"], long_s)
    say("Monte Carlo scaling …")
    report["monte_carlo"] = monte_carlo(CASES["full_f64"], duration, 4 if quick else 16, 1 if quick else 3)
    report["machine"]["load_average_after"] = list(os.getloadavg())

    ours = pipeline["full_f64"]["cycles_per_s"]
    report["ratios"] = {
        "full_vs_numpy_loop": ours / base["numpy_loop"]["cycles_per_s"],
        "full_vs_ahrs": ours / base["ahrs_angular_rate"]["cycles_per_s"],
        "full_vs_lower_bound": ours / report["lower_bound"]["cycles_per_s"],
        "lower_bound_vs_full": report["lower_bound"]["cycles_per_s"] / ours,
        # Context for the targets, not targets: the firmware's own work against the same figures.
        "firmware_stages_vs_numpy_loop": report["firmware_stages"]["cycles_per_s"]
        / base["numpy_loop"]["cycles_per_s"],
        "lower_bound_vs_firmware_stages": report["lower_bound"]["cycles_per_s"]
        / report["firmware_stages"]["cycles_per_s"],
    }
    long_rss = report["long_run"]["peak_rss_mb"]
    report["targets"] = {
        "full_cycles_per_s": [ours, TARGET_CYCLES_PER_S, ours >= TARGET_CYCLES_PER_S],
        "bit_level_cycles_per_s": [
            pipeline["bit_level_f64"]["cycles_per_s"],
            TARGET_BIT_LEVEL_CYCLES_PER_S,
            pipeline["bit_level_f64"]["cycles_per_s"] >= TARGET_BIT_LEVEL_CYCLES_PER_S,
        ],
        "vs_numpy_loop": [report["ratios"]["full_vs_numpy_loop"], TARGET_VS_BASELINE, None],
        "vs_ahrs": [report["ratios"]["full_vs_ahrs"], TARGET_VS_BASELINE, None],
        "lower_bound_vs_full": [report["ratios"]["lower_bound_vs_full"], TARGET_VS_LOWER_BOUND, None],
        "long_run_peak_rss_mb": [long_rss, TARGET_LONG_RSS_MB, long_rss < TARGET_LONG_RSS_MB],
        "monte_carlo_scaling": [report["monte_carlo"]["process"]["scaling"], TARGET_SCALING, None],
    }
    t = report["targets"]
    t["vs_numpy_loop"][2] = t["vs_numpy_loop"][0] >= TARGET_VS_BASELINE
    t["vs_ahrs"][2] = t["vs_ahrs"][0] >= TARGET_VS_BASELINE
    t["lower_bound_vs_full"][2] = t["lower_bound_vs_full"][0] <= TARGET_VS_LOWER_BOUND
    t["monte_carlo_scaling"][2] = t["monte_carlo_scaling"][0] >= TARGET_SCALING
    return report


def _k(x: float) -> str:
    return f"{x:,.0f}"


def render(report: dict[str, Any]) -> str:
    """The report as Markdown (benchmarks/results.md)."""
    m = report["machine"]
    lines = [
        "# Benchmarks",
        "",
        f"- date: {m['date']}; commit: `{m['commit']}`"
        + (" (quick run: rough figures)" if report["quick"] else ""),
        f"- machine: `{m['uname']}`; CPU: {m['cpu']}; cores: {m['cores']}",
        f"- load average before / after: {' '.join(f'{x:.2f}' for x in m['load_average'])} / "
        f"{' '.join(f'{x:.2f}' for x in m.get('load_average_after', []))} (a shared machine: rates are per "
        "CPU second of the measuring thread, wall-clock rates beside them)",
        f"- input: {report['input']} at 819.2 SPS; medians of repeated runs (the targets use them); "
        "one emulated cycle = one 8 ms step",
        "- on a shared virtual machine even CPU time moves with the neighbours' load (the host's steal "
        "counts as run time): the best run is what the code does on an unshared core, and "
        "`benchmarks/instructions_per_cycle.sh` gives a load-independent figure",
        "",
        "| case | cycles | cycles/s (CPU, median) | best run | cycles/s (wall) | × real time | peak RSS MB |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    for name, r in report["pipeline"].items():
        lines.append(
            f"| {name} (`{' '.join(r['overrides'])}`) | {r['cycles']} | {_k(r['cycles_per_s'])} | "
            f"{_k(r['best_cycles_per_s'])} | {_k(r['wall_cycles_per_s'])} | "
            f"{r['cycles_per_s'] * STEP_S:,.0f} | {r['peak_rss_mb']:.0f} |"
        )
    b, lb, fs = report["baselines"], report["lower_bound"], report["firmware_stages"]
    lines += [
        f"| NumPy/Python loop (decode + RK4 + Euler) | {b['numpy_loop']['cycles']} | "
        f"{_k(b['numpy_loop']['cycles_per_s'])} | | | | |",
        f"| ahrs 0.4.0 AngularRate, per sample | {b['ahrs_angular_rate']['cycles']} | "
        f"{_k(b['ahrs_angular_rate']['cycles_per_s'])} | | | | |",
        f"| lower bound: bare Rust RK4 step, f64 | {lb['cycles']} | {_k(lb['cycles_per_s'])} | | | | |",
        f"| firmware stages alone (decode + RK4 + Euler + navigation, Rust f64, the board's words) | "
        f"{fs['cycles']} | {_k(fs['cycles_per_s'])} | | | | |",
        "",
    ]
    ra = report["ratios"]
    lines += [
        "The firmware stages alone are the firmware's own work in each emulated cycle, without the board "
        "(device, SPI, timing, output rows): "
        f"{ra['firmware_stages_vs_numpy_loop']:,.1f}× the NumPy/Python loop, and the bare RK4 step runs "
        f"{ra['lower_bound_vs_firmware_stages']:,.2f}× faster than they do.",
        "",
    ]
    lr = report["long_run"]
    lines += [
        f"Long run: {lr['duration_s'] / 3600:g} h streamed in and out (`emulate(..., sink=...)`), "
        f"{lr['cycles']} cycles, {_k(lr['cycles_per_s'])} cycles/s, peak RSS {lr['peak_rss_mb']:.0f} MB.",
        "",
    ]
    mc = report["monte_carlo"]
    lines.append(
        f"Monte Carlo, {mc['runs']} seeded runs of {mc['duration_s']:g} s, medians of {mc['rounds']} rounds: "
        + "; ".join(
            f"{k} pool: 1 worker {mc[k]['wall_1_s']:.2f} s, 2 workers {mc[k]['wall_2_s']:.2f} s, "
            f"scaling {mc[k]['scaling']:.2f}×"
            for k in ("process", "thread")
        )
        + "."
    )
    lines += ["", "| target | measured | required | met |", "|---|---:|---:|---|"]
    for name, (got, want, ok) in report["targets"].items():
        lines.append(f"| {name} | {got:,.2f} | {want:,.2f} | {'yes' if ok else 'NO'} |")
    lines.append("")
    return "\n".join(lines)
