"""Numeric parity against f64 (thresholds in firmware_model/parity.toml), golden output hashes, and
bit-identical reruns."""

from __future__ import annotations

import json
import math
import os
import shutil
from pathlib import Path

import numpy as np
import pytest

from conftest import ROOT, run_cli
from sins_fw import golden, synth
from sins_fw import quaternion as quat
from sins_fw.errors import InputError, ProfileError
from sins_fw.harness import emulate
from sins_fw.parity import (
    REFERENCE,
    Threshold,
    attitude_difference_deg,
    compare,
    drift_rate_deg_per_h,
    load_thresholds,
    run_backends,
)
from sins_fw.traces import PhysicalTrace

TRACES = ("static_60s", "pitch_sweep", "coning_10hz")
THRESHOLDS = load_thresholds()
CHECKED = [REFERENCE, *THRESHOLDS]


@pytest.fixture(scope="module")
def bundled_runs() -> dict[str, dict]:
    """Every checked backend on every bundled trace (shared by the parity and golden tests)."""
    return {t: run_backends(ROOT / "traces" / f"{t}.h5", backends=CHECKED) for t in TRACES}


def test_thresholds_cover_every_backend():
    assert {"c28x-f32", "c28x-f32-rz", "iq"} <= set(THRESHOLDS)


@pytest.mark.parametrize("trace", TRACES)
def test_bundled_trace_within_parity_thresholds(bundled_runs, trace):
    runs = bundled_runs[trace]
    for backend, limit in THRESHOLDS.items():
        d = compare(runs[backend], runs[REFERENCE], backend, limit)
        assert d.steps > 1000
        assert d.max_deg > 0, f"{backend} identical to f64: the backend was not selected"
        assert d.passed, f"{trace}: {backend} exceeds {d.exceeded}"


def test_fast_rotation_within_parity_thresholds(tmp_path):
    # 280 °/s about body x (mount 10/20/30°), 11.2 s: the fastest rate inside the published decode's range.
    path = tmp_path / "fast.h5"
    synth.generate(
        "turntable",
        axis="x",
        rates_dps=(280.0,),
        hold_s=8.0,
        max_accel_dps2=1000.0,
        lead_s=1.0,
        attitude_deg=(10.0, 20.0, 30.0),
    ).save(path)
    runs = run_backends(path, backends=CHECKED)
    assert not runs[REFERENCE].events, "the trace stays inside every rule and range"
    for backend, limit in THRESHOLDS.items():
        d = compare(runs[backend], runs[REFERENCE], backend, limit)
        assert d.passed, f"{backend} exceeds {d.exceeded}"


def test_difference_is_the_rotation_angle_even_when_tiny():
    rng = np.random.default_rng(7)
    q_ref = quat.normalize(rng.normal(size=(5, 4)))
    axes = quat.normalize(rng.normal(size=(5, 3)))
    angles = np.array([1e-12, 1e-9, 1e-3, 1.0, math.pi - 1e-6])
    q = quat.multiply(quat.from_axis_angle(axes, angles), q_ref)
    got = np.radians(attitude_difference_deg(q, q_ref))
    # q's components are rounded to ~1.1e-16 (half an ulp of numbers ≤ 1), which moves the angle by a
    # few 1e-16 rad: the atan2 form recovers every size to that (2·acos(|w|) is off by up to ~2e-8 rad
    # at 1e-9, where w is within one ulp of 1).
    np.testing.assert_allclose(got, angles, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(np.radians(attitude_difference_deg(-q, q_ref)), angles, rtol=1e-12, atol=1e-15)
    naive = 2.0 * np.arccos(np.clip(np.abs(quat.multiply(q, quat.conjugate(q_ref))[:, 0]), 0, 1))
    assert abs(naive[1] - 1e-9) > 1e-10, "the naive form would not have passed"
    with pytest.raises(InputError):
        attitude_difference_deg(q[:, :3], q_ref[:, :3])


def test_drift_rate_is_the_least_squares_slope():
    t = np.linspace(0.0, 600.0, 75001)
    assert drift_rate_deg_per_h(t, 1e-3 + 2.5e-6 * t) == pytest.approx(2.5e-6 * 3600, rel=1e-9)
    # A symmetric bump has no trend.
    assert abs(drift_rate_deg_per_h(t, np.sin(np.pi * t / 600.0))) < 1e-9
    assert drift_rate_deg_per_h(t[:1], t[:1]) == 0.0


def test_exceeding_a_threshold_is_reported(bundled_runs):
    runs = bundled_runs["static_60s"]
    tight = Threshold(max_deg=1e-9, rms_deg=1.0, drift_deg_per_h=1.0)
    d = compare(runs["c28x-f32"], runs[REFERENCE], "c28x-f32", tight)
    assert not d.passed and d.exceeded[0].startswith("max_deg:")


def _model_dir_with(tmp_path: Path, parity_toml: str) -> Path:
    model = tmp_path / "model"
    model.mkdir()
    for name in ("reference.toml", "c28x-costs.toml"):
        shutil.copy(ROOT / "firmware_model" / name, model / name)
    (model / "parity.toml").write_text(parity_toml, encoding="utf-8")
    return model


def test_cli_exits_1_when_a_backend_exceeds(tmp_path, monkeypatch):
    strict = "[backends.c28x-f32]\nmax_deg = 1e-9\nrms_deg = 1e-9\ndrift_deg_per_h = 1e-9\n"
    monkeypatch.setenv("SINS_FW_MODEL_DIR", str(_model_dir_with(tmp_path, strict)))
    r = run_cli("parity", "traces/static_60s.h5")
    assert r.code == 1, r.err
    assert "EXCEEDS max_deg" in r.out and "threshold" in r.err


def test_cli_parity_json():
    r = run_cli("parity", "traces/static_60s.h5", "--backends", "c28x-f32", "--json")
    assert r.code == 0, r.err
    report = json.loads(r.out)
    (trace,) = report["traces"]
    assert [b["backend"] for b in trace["backends"]] == ["c28x-f32"]
    assert trace["backends"][0]["checked"] and trace["passed"]


def test_bad_threshold_files_and_backends(tmp_path):
    bad = tmp_path / "p.toml"
    bad.write_text("[backends.c28x-f32]\nmax_deg = -1\nrms_deg = 1\ndrift_deg_per_h = 1\n")
    with pytest.raises(ProfileError, match=r"backends\.c28x-f32\.max_deg"):
        load_thresholds(bad)
    bad.write_text("[backends.f16]\nmax_deg = 1\nrms_deg = 1\ndrift_deg_per_h = 1\n")
    with pytest.raises(ProfileError, match="unknown backend"):
        load_thresholds(bad)
    r = run_cli("parity", "traces/static_60s.h5", "--backends", "f32")
    assert r.code == 2 and "backend `f32`" in r.err and "Traceback" not in r.err


# --- golden outputs ----------------------------------------------------------------------------------


@pytest.mark.parametrize("trace", TRACES)
def test_golden_hashes(bundled_runs, trace):
    expected = golden.load()
    assert trace in expected, "tests/golden/hashes.toml lacks this trace: run `make golden`"
    # The parity fixture's f64 run is the golden run: profile reference with firmware.numeric = f64.
    run = bundled_runs[trace][REFERENCE]
    assert run.profile.overrides == golden.OVERRIDES
    got = golden.run_hashes(run)
    changed = [k for k in expected[trace] if got[k] != expected[trace][k]]
    assert not changed, f"{trace}: {changed} differ from tests/golden/hashes.toml (intended? `make golden`)"


def test_golden_regeneration_reports_changes(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(golden, "TRACES", ("static_60s",))
    path = tmp_path / "hashes.toml"
    golden.main([str(path)])
    assert "→ static_60s.quat: (none) →" in capsys.readouterr().out
    first = path.read_bytes()
    golden.main([str(path)])
    assert "0 value(s) changed" in capsys.readouterr().out
    assert path.read_bytes() == first
    assert golden.load(path)["static_60s"] == golden.load()["static_60s"]


# --- determinism ---------------------------------------------------------------------------------------


def _all_bytes(run) -> list[bytes]:
    arrays = [
        run.time_s,
        run.quat,
        run.euler_deg,
        run.velocity_enu,
        run.position,
        run.read_words,
        run.read_rate,
        run.read_accel,
        run.read_t_start_ps,
        run.read_age_ps,
        *(run.budget[k] for k in sorted(run.budget)),
    ]
    return [np.ascontiguousarray(a).tobytes() for a in arrays] + [repr(run.events).encode()]


@pytest.mark.parametrize("numeric", ["f64", "c28x-f32", "iq"])
def test_same_input_gives_identical_bytes(numeric):
    trace = PhysicalTrace.load(ROOT / "traces" / "static_60s.h5")
    profile = ["errors.preset=adis16407", f"firmware.numeric={numeric}"]  # noise: a seeded stream
    first = emulate(trace, overrides=profile)
    again = emulate(trace, overrides=profile)
    # The chunking of the input must not matter either (the emulator streams).
    chunked = emulate(trace, overrides=profile, chunk_rows=4093)
    assert _all_bytes(first) == _all_bytes(again) == _all_bytes(chunked)


_DRIFT_SCRIPT = """
import numpy as np
from sins_fw.parity import drift_rate_deg_per_h
rng = np.random.default_rng(3)
t = np.arange(2_000_000) * 0.008
a = np.cumsum(rng.normal(scale=1e-6, size=t.size)) + 1e-9 * t
print(repr(drift_rate_deg_per_h(t, a)))
"""


def test_drift_rate_does_not_depend_on_the_blas_thread_count():
    """Issue 24, item 12: `parity --json` differed in its last digits between OMP_NUM_THREADS=1 and
    2. The drift's sums were BLAS dot products, which OpenBLAS splits between its threads for long
    vectors (a different summation order per thread count); numpy's pairwise sum has one order."""
    import subprocess
    import sys

    outs = []
    for threads in ("1", "2"):
        env = {k: v for k, v in os.environ.items() if not k.endswith("_NUM_THREADS")}
        env["OMP_NUM_THREADS"] = threads
        proc = subprocess.run(
            [sys.executable, "-c", _DRIFT_SCRIPT], capture_output=True, text=True, env=env, check=True
        )
        outs.append(proc.stdout)
    assert outs[0] == outs[1]
