"""`sins-fw spin-table`: the geomagnetic–gyro board's spin rate → roll error table (issue 21), through
the emulated board by default (firmware_model/geomag.toml: the ADS8344 over SPI and the ads8344-geomag
firmware), through the sensor chain without the bus with `--engine chain`. Short runs here (2 rates ×
3 units × 20 s: about 4 s per table on the board); benchmarks/spin_table.md has the full table."""

from __future__ import annotations

import json

import pytest

from conftest import run_cli

ARGS = ("spin-table", "--rates-dps", "100,1000", "--runs", "3", "--duration-s", "20")


def _check_shape(table: dict) -> None:
    """Gyro only, the roll error grows as (δk·ω + b)·t, so relative to the spin angle it is δk + b/ω:
    with the presets' 1σ of δk = 0.5 % and b = 1 °/s, b/ω is 1 % at 100 °/s and 0.1 % at 1000 °/s,
    and the median unit's relative error falls. The aid bounds the roll (its loop answers a rate
    error d with at most d/(e·ω_n), ω_n = 0.5 rad/s: 0.7° per °/s of d), far below the gyro-only
    error after 20 s (d·20 s)."""
    slow, fast = table["rows"]
    assert (slow["spin_dps"], fast["spin_dps"]) == (100.0, 1000.0)
    assert fast["gyro_only_percent"]["p50"] < slow["gyro_only_percent"]["p50"]
    for row in table["rows"]:
        p = row["aided_max_deg"]
        assert p["p50"] <= p["p95"] <= p["max"] < row["gyro_only_deg"]["p50"]
        assert row["events"] == 0


def test_the_board_table_is_reproducible_and_has_the_issue_shape():
    """The same options print the same bytes (JSON twice, text once against the JSON's numbers)."""
    first, again = run_cli(*ARGS, "--json"), run_cli(*ARGS, "--json")
    assert first.code == 0, first.err
    assert first.out == again.out
    table = json.loads(first.out)
    assert table["engine"] == "board" and "geomag.toml on the board" in table["chain"]
    _check_shape(table)
    text = run_cli(*ARGS)
    assert text.code == 0, text.err
    assert "geomag.toml on the board" in text.out and "p50 p95 max" in text.out
    median = table["rows"][1]["aided_max_deg"]["p50"]
    assert f"{median:8.4f}" in text.out


def test_the_chain_table_runs_without_the_bus():
    r = run_cli(*ARGS, "--engine", "chain", "--json")
    assert r.code == 0, r.err
    table = json.loads(r.out)
    assert table["engine"] == "chain" and "without the bus" in table["chain"]
    _check_shape(table)


def test_the_board_table_runs_the_board(monkeypatch: pytest.MonkeyPatch) -> None:
    """Each board unit is two emulations of geomag.toml (aided, and the aid's gains at 0) on the rate's
    synth spin trace, with the unit's seed, real sensors and the table's axis and field."""
    from sins_fw import spin_table

    calls: list[tuple[str, tuple[str, ...], tuple[str, ...]]] = []
    real = spin_table.emulate

    def spy(trace, profile, overrides=(), **kw):  # type: ignore[no-untyped-def]
        calls.append((profile.source, profile.overrides, tuple(overrides)))
        return real(trace, profile, overrides=overrides, **kw)

    monkeypatch.setattr(spin_table, "emulate", spy)
    table = spin_table.spin_table([500.0], runs=2, seed=7, duration_s=3.0)
    assert table["rows"][0]["events"] == 0
    assert len(calls) == 4
    assert all(src.endswith("geomag.toml") for src, _, _ in calls)
    seeds = [next(o for o in over if o.startswith("errors.seed=")) for _, over, _ in calls]
    assert seeds == ["errors.seed=7"] * 2 + ["errors.seed=8"] * 2
    assert all("geomag.ideal_sensors=false" in over for _, over, _ in calls)
    assert [extra for _, _, extra in calls] == [(), ("geomag.aid_kp=0", "geomag.aid_ki=0")] * 2


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
        ("--pitch-deg", "10", "the board's firmware starts level"),
        ("--duration-s", "1.5", "spins up over 1 s"),
        ("--engine", "fpga", "invalid choice"),
    ],
)
def test_bad_options_exit_2_with_a_clear_message(option, value, message):
    r = run_cli("spin-table", option, value)
    assert r.code == 2
    assert message in r.err and "Traceback" not in r.err
