"""Smoke test of the benchmark suite: `sins-fw bench --quick --json` runs and reports every figure.
No timing is asserted (benchmarks are not tests); only that each figure was measured."""

from __future__ import annotations

import json
import math

from conftest import run_cli
from sins_fw.bench import CASES


def _positive(x: object) -> bool:
    return isinstance(x, int | float) and math.isfinite(x) and x > 0


def test_bench_quick_reports_every_figure(tmp_path):
    out = tmp_path / "results.md"
    r = run_cli("bench", "--quick", "--json", "--output", str(out))
    assert r.code == 0, r.err
    report = json.loads(r.out)
    assert set(report["pipeline"]) == set(CASES)
    for name, case in report["pipeline"].items():
        assert case["cycles"] > 1000, name
        for key in ("cycles_per_s", "best_cycles_per_s", "wall_cycles_per_s", "peak_rss_mb"):
            assert _positive(case[key]), (name, key, case[key])
    for name in ("numpy_loop", "ahrs_angular_rate"):
        assert _positive(report["baselines"][name]["cycles_per_s"]), name
    assert _positive(report["lower_bound"]["cycles_per_s"])
    long_run = report["long_run"]
    # 120 s of input is 15 000 steps of 8 ms; the first step ends at the third 4 ms tick and the
    # last tick must lie inside the input: every step went through the sink.
    assert 14_997 <= long_run["cycles"] <= 15_000, long_run["cycles"]
    assert _positive(long_run["peak_rss_mb"]) and len(long_run["last_quat"]) == 4
    for kind in ("process", "thread"):
        assert _positive(report["monte_carlo"][kind]["scaling"]), kind
    for name in ("full_vs_numpy_loop", "full_vs_ahrs", "full_vs_lower_bound", "lower_bound_vs_full"):
        assert _positive(report["ratios"][name]), name
    assert {k for k, v in report["targets"].items() if len(v) == 3} == set(report["targets"])
    m = report["machine"]
    assert m["cpu"] and m["cores"] and m["commit"] and m["date"]
    text = out.read_text()
    assert "| full_f64" in text and "lower bound" in text and "Monte Carlo" in text
