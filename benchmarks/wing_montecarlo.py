"""Monte Carlo of the wing unit on its board (`firmware_model/wing.toml`, the ADIS16362 `adis16362`
error preset, one unit per seed): the static and the 30 s dynamic α error against the source's 0.1° and
0.3° targets, and the axis error against the pose count, the pose spread and the flap amplitude.

Every run is the whole board (`emulate`: SPI bursts, decode, the wing firmware in c28x-f32) on a
`synth wing` trace; only the error model's seed changes between runs of a case.
- Static: the default steps (0 → 20° → −15° → 35° → 0, 10 s rests); |α − truth| at the last step of each
  rest away from the zero (three per run).
- Dynamic: 10 s (the profile's zero) or 60 s (`firmware.alignment_s=60`) at the zero, then a 30° sine
  flap (4 s period) for 30 s; |α − truth| at its end.
- Axis: the angle between the final axis and the truth (the hinge axis in the IMU's axes at the zero,
  from the trace's truth at power-on): B1 (rest poses) for steps of 2, 3 and 5 poses and of ±8°, ±15°,
  ±35° spread; B2 (integrated motion) for sine flaps of 10°, 30° and 60°.

Run: .venv/bin/python benchmarks/wing_montecarlo.py [RUNS]  (writes benchmarks/wing_montecarlo.md)
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from sins_fw import atomic, synth
from sins_fw import quaternion as q
from sins_fw.bench import machine_line
from sins_fw.harness import emulate
from sins_fw.metrics import wrap_deg
from sins_fw.profile import load_profile

BETA_DEG, AZIMUTH_DEG = 20.0, 30.0  # the synth default hinge axis


def truth_axis(q0: np.ndarray) -> np.ndarray:
    """The hinge axis in the IMU's axes at the zero (the firmware's r axes): C_n^b(0) a."""
    b, g = math.radians(BETA_DEG), math.radians(AZIMUTH_DEG)
    a = np.array([math.cos(b) * math.sin(g), math.cos(b) * math.cos(g), math.sin(b)])
    return q.rotate(q.conjugate(q0[None, :]), a[None, :])[0]


def run(trace: Any, seed: int, *extra: str) -> Any:
    profile = load_profile("wing", ["errors.preset=adis16362", f"errors.seed={seed}", *extra])
    return emulate(trace, profile)


def axis_error_deg(r: Any) -> float:
    est = r.wing["axis"][-1]
    c = float(np.clip(np.dot(est, truth_axis(r.truth_q0)), -1.0, 1.0))
    return math.degrees(math.acos(c))


def static_errors(r: Any) -> list[float]:
    """|α − truth| at the last step of each rest away from the zero."""
    still, truth = r.alpha_still, r.truth_alpha_deg
    err = np.abs(wrap_deg(r.wing["alpha_deg"] - truth))
    ends = np.flatnonzero(still[:-1] & ~still[1:])  # the last still step before a move
    return [float(err[i]) for i in ends if abs(truth[i]) > 1.0 and np.isfinite(err[i])]


def pct(x: list[float]) -> str:
    p50, p95 = np.percentile(x, [50, 95])
    return f"{p50:.3f} | {p95:.3f} | {max(x):.3f}"


def main() -> None:
    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 20
    t0 = time.perf_counter()
    lines = [
        "# Wing unit Monte Carlo (ADIS16362 preset, whole board)",
        "",
        f"Machine: {machine_line()}",
        f"Command: `.venv/bin/python benchmarks/wing_montecarlo.py {runs}`",
        "",
    ]
    steps = synth.generate("wing")
    static: list[float] = []
    for s in range(1, runs + 1):
        static += static_errors(run(steps, s))
    within = sum(e <= 0.1 for e in static) / len(static)
    lines += [
        f"## Static α, {runs} units × 3 poses (20°, −15°, 35°; β = 20°), |α − truth| at the end of each rest",
        "",
        "| p50 ° | p95 ° | max ° | within 0.1° |",
        "|---:|---:|---:|---:|",
        f"| {pct(static)} | {100 * within:.0f} % |",
        "",
    ]
    lines += [
        f"## Dynamic α after 30 s of a 30° sine flap (4 s period), {runs} units",
        "",
        "| zero (rest at α = 0 first) | p50 ° | p95 ° | max ° | within 0.3° |",
        "|---|---:|---:|---:|---:|",
    ]
    for zero_s in (10.0, 60.0):
        sine = synth.generate(
            "wing", flap="sine", amplitude_deg=30.0, period_s=4.0, rest_s=zero_s, duration_s=zero_s + 30.0
        )
        dynamic = []
        for s in range(1, runs + 1):
            r = run(sine, s, f"firmware.alignment_s={zero_s:g}")
            dynamic.append(float(abs(wrap_deg(r.wing["alpha_deg"][-1] - r.truth_alpha_deg[-1]))))
        within = sum(e <= 0.3 for e in dynamic) / len(dynamic)
        lines.append(f"| {zero_s:g} s | {pct(dynamic)} | {100 * within:.0f} % |")
    lines.append("")
    axis_runs = max(runs // 3, 3)
    cases = [
        ("poses", "2 (20°, −15°)", {"angles_deg": (0.0, 20.0, -15.0, 0.0)}),
        ("poses", "3 (20°, −15°, 35°)", {}),
        ("poses", "5 (20°, −15°, 35°, −30°, 10°)", {"angles_deg": (0, 20, -15, 35, -30, 10, 0)}),
        ("spread", "±8°", {"angles_deg": (0.0, 8.0, -8.0, 0.0)}),
        ("spread", "±15°", {"angles_deg": (0.0, 15.0, -15.0, 0.0)}),
        ("spread", "±35°", {"angles_deg": (0.0, 35.0, -35.0, 0.0)}),
        *(
            ("flap amplitude (B2)", f"{a:g}°", {"flap": "sine", "amplitude_deg": a, "duration_s": 40.0})
            for a in (10.0, 30.0, 60.0)
        ),
    ]
    lines += [
        f"## Axis error at the end of the run, {axis_runs} units per case",
        "",
        "| varied | case | source | p50 ° | p95 ° | max ° |",
        "|---|---|---|---:|---:|---:|",
    ]
    for varied, name, params in cases:
        trace = synth.generate("wing", **params)
        errs, sources = [], set()
        for s in range(1, axis_runs + 1):
            r = run(trace, s)
            errs.append(axis_error_deg(r))
            sources.add({1: "B2", 2: "B1"}.get(int(r.wing["axis_source"][-1]), "none"))
        lines.append(f"| {varied} | {name} | {'/'.join(sorted(sources))} | {pct(errs)} |")
    lines += ["", f"Wall time {time.perf_counter() - t0:.0f} s.", ""]
    atomic.write_text(Path(__file__).with_suffix(".md"), "\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
