"""The wing unit's figure is its hinge angle α (issue 40 item 3): `sins-fw run` reports α against the
trace's `truth_alpha_deg` and no attitude-error block (the unit's quaternion is q_w^b, from its zero's
level frame with yaw 0: compared with the trace's C_b^n it would show the mount and the heading, not an
error); `montecarlo` and `sweep` give α's percentiles (final, static_max, dynamic_max) instead of the
attitude errors. Short runs: a 10 s zero, then 8 s of a 30° sine flap."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from conftest import run_cli

FLAP = ("--param", "flap=sine", "--param", "rest-s=10", "--param", "duration-s=18")


@pytest.fixture(scope="module")
def flap_trace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("wing") / "flap.h5"
    r = run_cli("synth", "wing", "--flap", "sine", "--rest-s", "10", "--duration-s", "18", "--out", str(path))
    assert r.code == 0, r.err
    return path


def test_run_reports_alpha_and_no_attitude_block(flap_trace: Path) -> None:
    r = run_cli("run", str(flap_trace), "--profile", "wing", "--set", "errors.preset=adis16362")
    assert r.code == 0, r.err
    assert "hinge angle α" in r.out
    assert "attitude error not reported: the wing unit gives the hinge angle α" in r.out
    assert "BROAD RMSE" not in r.out and "alignment" not in r.out
    j = run_cli("run", str(flap_trace), "--profile", "wing", "--set", "errors.preset=adis16362", "--json")
    s = json.loads(j.out)
    assert s["attitude_error"] is None and "q_w^b" in s["attitude_error_omitted"]
    assert s["wing_alpha_error"]["dynamic"]["steps"] > 0
    # Another board keeps its attitude block.
    ref = run_cli("run", str(flap_trace), "--profile", "reference", "--until-s", "2", "--json")
    assert ref.code == 0, ref.err
    assert json.loads(ref.out)["attitude_error"] is not None


def test_montecarlo_reports_alpha_for_the_wing() -> None:
    """Three units of the ADIS16362 preset; the moving steps' largest |α − truth| is the figure (the
    flap starts after the zero, so no still step has an α: no static_max). Bound: 3 °/s of initial bias
    is taken out by the 10 s zero; 8 s of flap at its residual (ARW 2 °/√h over 10 s: 0.01 °/s 1σ) and
    the accelerometer's 4 mg bias (≤ 2 sin(α/2)·|b|/(g cos β) = 0.72° at 30°, 3σ) keep it under 1°."""
    r = run_cli(
        "montecarlo", "wing", "--profile", "wing", "--errors", "adis16362", "--runs", "3", *FLAP, "--json"
    )  # fmt: skip
    assert r.code == 0, r.err
    case = json.loads(r.out)["cases"]["wing"]
    assert set(case) == {"alpha_error_deg", "runs_without_alpha"} and case["runs_without_alpha"] == 0
    alpha = case["alpha_error_deg"]
    assert set(alpha) == {"final", "dynamic_max"}
    assert 0.0 < alpha["dynamic_max"]["p50"] < 1.0
    text = run_cli("montecarlo", "wing", "--profile", "wing", "--errors", "adis16362", "--runs", "3", *FLAP)
    assert "wing α dynamic_max error °" in text.out and "total" not in text.out


def test_sweep_reports_alpha_for_the_wing(tmp_path: Path) -> None:
    out = tmp_path / "runs.csv"
    r = run_cli(
        "sweep", "wing", "--profile", "wing", "--errors", "adis16362", "--runs", "2", *FLAP,
        "--grid", "firmware.alignment_s=5,10", "--out", str(out), "--json",
    )  # fmt: skip
    assert r.code == 0, r.err
    rows = json.loads(r.out)["percentiles"]
    assert {row["error"] for row in rows} == {"alpha_final", "alpha_dynamic_max"}
    assert len(rows) == 4
    header = out.read_text(encoding="utf-8").splitlines()
    header = next(line for line in header if not line.startswith("#"))
    assert "alpha_error_dynamic_max_deg" in header


def test_montecarlo_says_when_the_wing_gave_no_alpha() -> None:
    """A rest of 45 s before the flap with the profile's 10 s zero: the flap starts 35 s after the zero,
    outside the 30 s in which B2 takes the axis from motion, and a sine flap has no rest poses for B1:
    the unit never has an axis, so no α. The report says so (no NaN attitude lines instead)."""
    late = ("--param", "flap=sine", "--param", "rest-s=45", "--param", "duration-s=50")
    r = run_cli("montecarlo", "wing", "--profile", "wing", "--errors", "adis16362", "--runs", "2", *late)
    assert r.code == 0, r.err
    assert "wing α: 2 of 2 runs gave no α against the truth" in r.out
    assert "nan" not in r.out and "total" not in r.out
