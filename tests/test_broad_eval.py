"""`sins-fw broad-eval` on the ten BROAD trials in ../shared/data/broad (skipped when they are absent).

The DCM alone here (the ahrs baselines take minutes in pure Python: `benchmarks/broad_eval.md` has the
side-by-side run). The target is the dataset's published Mahony on these ten, mean inclination RMSE
≤ 3.75° (measured 2.98° with the tuned set); the magnet trials degrade heading, never to NaN.
"""

from __future__ import annotations

import json

import pytest

from conftest import BROAD, run_cli
from sins_fw.broad_eval import evaluate

pytestmark = pytest.mark.skipif(
    len(list(BROAD.glob("*.hdf5"))) != 10, reason=f"the ten BROAD trials are not in {BROAD}"
)


def test_dcm_meets_the_published_mahony_inclination():
    r = evaluate(BROAD, baselines=False)
    assert len(r["trials"]) == 10
    assert r["mean"]["dcm"]["inclination"] <= 3.75, r["mean"]
    by_name = {t["trial"]: t["dcm"] for t in r["trials"]}
    for name, e in by_name.items():
        assert all(v == v and v < 90 for v in e.values()), (name, e)  # finite (NaN != NaN)
    # The attached magnet (trial 32) turns the projected field: heading suffers, inclination much less.
    magnet = by_name["32_disturbed_attached_magnet_1cm"]
    assert magnet["heading"] > 2 * magnet["inclination"], magnet


def test_cli_json_and_bad_folder(tmp_path):
    r = run_cli("broad-eval", str(BROAD), "--no-baselines", "--json")
    assert r.code == 0, r.err
    report = json.loads(r.out)
    assert report["machine"]["commit"] and set(report["mean"]) == {"dcm"}
    bad = run_cli("broad-eval", str(tmp_path))
    assert bad.code == 2 and "expected the ten" in bad.err and "Traceback" not in bad.err


def test_the_board_keeps_a_slow_trial_close_to_the_algorithm():
    # Trial 01 stays inside the ADIS16407's ±300 °/s: through the whole board (its filter, quantisation,
    # the 4 ms update, the magnetometer words) the inclination RMSE was 0.86° against 0.72° at algorithm
    # level; the fast trials lose to gyro saturation instead (benchmarks/broad_eval.md).
    from sins_fw.broad_eval import board_errors

    e = board_errors(BROAD / "01_undisturbed_slow_rotation_A.hdf5")
    assert e["inclination"] < 1.0 and e["heading"] < 2.5, e
