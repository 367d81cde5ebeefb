"""`sins-fw spin-table`: the geomagnetic–gyro board's spin rate → roll error table (issue 21)."""

from __future__ import annotations

import json

import pytest

from conftest import run_cli

ARGS = ("spin-table", "--rates-dps", "100,1000", "--runs", "3", "--duration-s", "20")


def test_the_table_is_reproducible_and_has_the_issue_shape():
    """The same options print the same bytes (text and JSON). Gyro only, the roll error grows as
    (δk·ω + b)·t, so relative to the spin angle it is δk + b/ω: with the presets' 1σ of δk = 0.5 %
    and b = 1 °/s, b/ω is 1 % at 100 °/s and 0.1 % at 1000 °/s, and the median unit's relative error
    falls. The aid bounds the roll (its loop answers a rate error d with at most d/(e·ω_n), ω_n =
    0.5 rad/s: 0.7° per °/s of d), far below the gyro-only error after 20 s (d·20 s)."""
    first, again = run_cli(*ARGS, "--json"), run_cli(*ARGS, "--json")
    assert first.code == 0, first.err
    assert first.out == again.out
    table = json.loads(first.out)
    slow, fast = table["rows"]
    assert (slow["spin_dps"], fast["spin_dps"]) == (100.0, 1000.0)
    assert fast["gyro_only_percent"]["p50"] < slow["gyro_only_percent"]["p50"]
    for row in table["rows"]:
        p = row["aided_max_deg"]
        assert p["p50"] <= p["p95"] <= p["max"] < row["gyro_only_deg"]["p50"]
    text = run_cli(*ARGS)
    assert text.code == 0 and text.out == run_cli(*ARGS).out
    assert "without the bus" in text.out and "p50 p95 max" in text.out


@pytest.mark.parametrize(
    ("option", "value", "message"),
    [
        ("--rates-dps", "0", "0 < rate ≤ 1000"),
        ("--rates-dps", "1200", "0 < rate ≤ 1000"),
        ("--runs", "0", "--runs 0"),
        ("--duration-s", "0", "--duration-s 0"),
        ("--mag-inclination-deg", "95", "−90…90"),
        ("--rates-dps", "fast", "--rates-dps: expected a number, got `fast`"),
        ("--duration-s", "inf", "--duration-s: expected a finite number, got `inf`"),
    ],
)
def test_bad_options_exit_2_with_a_clear_message(option, value, message):
    r = run_cli("spin-table", option, value)
    assert r.code == 2
    assert message in r.err and "Traceback" not in r.err
