"""Smoke test of the benchmark suite: `sins-fw bench --quick --json` runs and reports every figure.
No timing is asserted (benchmarks are not tests); only that each figure was measured."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from conftest import run_cli
from sins_fw import _core
from sins_fw.bench import CASES
from sins_fw.errors import ConfigError, TraceError
from sins_fw.profile import load_profile


def _positive(x: object) -> bool:
    return isinstance(x, int | float) and math.isfinite(x) and x > 0


def test_bench_quick_reports_every_figure(tmp_path):
    out = tmp_path / "results.md"
    r = run_cli("bench", "--quick", "--json", "--out", str(out))
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
    # The stages ran every update of the reads: 20 s of input, one step per two 4 ms reads.
    stages = report["firmware_stages"]
    assert _positive(stages["cycles_per_s"]) and 2_490 <= stages["cycles"] <= 2_500, stages
    long_run = report["long_run"]
    # 120 s of input is 15 000 steps of 8 ms; the first step ends at the third 4 ms tick and the
    # last tick must lie inside the input: every step went through the sink.
    assert 14_997 <= long_run["cycles"] <= 15_000, long_run["cycles"]
    assert _positive(long_run["peak_rss_mb"]) and len(long_run["last_quat"]) == 4
    for kind in ("process", "thread"):
        assert _positive(report["monte_carlo"][kind]["scaling"]), kind
    for name in (
        "full_vs_numpy_loop",
        "full_vs_ahrs",
        "full_vs_lower_bound",
        "lower_bound_vs_full",
        "firmware_stages_vs_numpy_loop",
        "lower_bound_vs_firmware_stages",
    ):
        assert _positive(report["ratios"][name]), name
    assert {k for k, v in report["targets"].items() if len(v) == 3} == set(report["targets"])
    m = report["machine"]
    assert m["cpu"] and m["cores"] and m["commit"] and m["date"]
    text = out.read_text()
    for part in ("| full_f64", "lower bound", "firmware stages alone", "Monte Carlo"):
        assert part in text, part


def test_bench_entry_points_refuse_bad_input():
    """The two Rust figures refuse arrays of the wrong shape with an error naming it, and the
    stages a firmware they do not model."""
    with pytest.raises(TraceError, match=r"rates: shape \[4, 2\], expected \(n, 3\)"):
        _core.bench_rk4_lower_bound(np.zeros((4, 2)), 0.008)
    p = load_profile("reference")
    with pytest.raises(TraceError, match=r"reads: shape \[4, 5\], expected \(n, 6\)"):
        _core.bench_firmware_stages(p.text, p.source, [], np.zeros((4, 5), dtype=np.uint16))
    with pytest.raises(ConfigError, match=r"firmware\.algorithm"):
        _core.bench_firmware_stages(
            p.text, p.source, ['firmware.algorithm="rotation-vector"'], np.zeros((5, 6), dtype=np.uint16)
        )
