"""The timing budget: `sins-fw budget` and `sins_fw.budget.summarise(run)`.

Every expected number is derived in the test from the registers, the cost table or number theory;
the one tolerance that is not (±15 % on the published 0.35 ms) is the issue's acceptance criterion.
"""

from __future__ import annotations

import copy
import itertools
import json
import math
import re
from fractions import Fraction
from functools import cache

import numpy as np
import pytest

from conftest import ROOT, run_cli
from sins_fw import budget
from sins_fw.harness import emulate, profile_table
from sins_fw.profile import load_profile
from sins_fw.traces import PhysicalTrace

SYSCLK_HZ = 150e6
LSPCLK_HZ = 37.5e6
PS = 1e-12
#: Exactness of a time in the reports: virtual time is integer picoseconds, and a difference of two
#: rounded instants is off by at most 1 ps each.
TIME_EXACT_S = 2e-12
#: 15 frames of 16 bits: what one burst clocks.
BURST_BITS = 15 * 16


@cache
def cli_report(*overrides: str, seconds: str | None = None) -> tuple[int, dict]:
    args = ["budget", "--json"]
    for o in overrides:
        args += ["--set", o]
    if seconds is not None:
        args += ["--duration-s", seconds]
    r = run_cli(*args)
    assert r.code in (0, 1), r.err
    return r.code, json.loads(r.out)


def still_trace(seconds: float, gyro_dps=(0.0, 0.0, 0.0)) -> PhysicalTrace:
    t = np.linspace(0.0, seconds, 11)
    return PhysicalTrace(
        t_s=t,
        gyro_dps=np.tile(np.array(gyro_dps, dtype=float), (len(t), 1)),
        accel_g=np.tile([0.0, 0.0, 1.0], (len(t), 1)),
        # 11 samples evenly over `seconds`: the trace is validated like a file (one sample period).
        metadata={"sample_rate_hz": str(Fraction(len(t) - 1) / Fraction(str(seconds)))},
    )


def costs() -> dict:
    return profile_table("c28x-costs.toml")


# --------------------------------------------------------------------------------------- reference


def test_reference_solution_is_the_published_0_35_ms_with_the_spi_share_explained():
    code, r = cli_report()
    assert code == 0
    sol = r["solution"]
    assert sol["within_tolerance"] and abs(sol["time_s"] / 0.35e-3 - 1) <= 0.15, sol
    # SPI clocking from the registers alone: 240 bits at 37.5 MHz / (49 + 1).
    assert sol["spi_clocking_s"] == pytest.approx(BURST_BITS * 50 / LSPCLK_HZ, abs=TIME_EXACT_S)
    assert sol["spi_clocking_s"] >= 320e-6 - TIME_EXACT_S
    assert sol["parts_s"]["spi"] >= 320e-6
    # The breakdown adds up, and so does its provenance.
    assert sum(sol["parts_s"].values()) == pytest.approx(sol["time_s"], abs=5 * TIME_EXACT_S)
    assert sum(sol["provenance_s"].values()) == pytest.approx(sol["time_s"], abs=5 * TIME_EXACT_S)
    assert sol["provenance_s"]["registers"] == sol["spi_clocking_s"]
    # The arithmetic is the cycles of its stages (the emulator charges exactly these).
    comp = r["compute"]
    for stage in ("decode", "attitude", "euler"):
        assert sol["parts_s"][stage] == pytest.approx(comp[stage]["cycles"] / SYSCLK_HZ, abs=TIME_EXACT_S)


def test_reference_reports_cycle_utilisation_and_no_overruns():
    code, r = cli_report()
    s = r["summary"]
    assert code == 0 and s["overruns"]["count"] == 0 and s["overruns"]["ticks"] == []
    assert r["rules_broken"] == [] and s["violations"] == []
    assert r["tick_period_s"] == pytest.approx(4e-3, abs=TIME_EXACT_S)
    assert r["cycle_period_s"] == pytest.approx(8e-3, abs=TIME_EXACT_S)
    # Half-step: a cycle is one acquisition-only tick plus one update tick.
    acq, step = r["tick"]["acquisition"]["busy"]["worst_s"], r["tick"]["step"]["busy"]["worst_s"]
    assert r["cycle"]["busy"]["worst_s"] == pytest.approx(acq + step, abs=TIME_EXACT_S)
    assert r["cycle"]["busy"]["worst_pct"] == pytest.approx(100 * (acq + step) / 8e-3)
    assert s["cycle_utilisation"]["max"] == pytest.approx((acq + step) / 8e-3)
    assert s["utilisation"]["max"] == pytest.approx(step / 4e-3)
    # Every stage row of a tick adds up to its busy time.
    for kind in ("acquisition", "step"):
        t = r["tick"][kind]
        assert sum(t[st]["worst_s"] for st in r["stages"]) == pytest.approx(t["busy"]["worst_s"], abs=1e-11)
        assert t["busy"]["worst_s"] + t["margin"]["worst_s"] == pytest.approx(4e-3, abs=TIME_EXACT_S)


def test_text_output_shows_the_tables_and_the_calibration():
    r = run_cli("budget", "--duration-s", "0.1")
    assert r.code == 0, r.err
    for needle in (
        "one timer tick",
        "one attitude cycle",
        "attitude solution",
        "SPI clocking",
        "rules broken: none",
    ):
        assert needle in r.out


# ------------------------------------------------------------------------------------- SPI settings


def _frame_overhead_s(profile_overrides: tuple[str, ...] = ()) -> float:
    """Upper bound of the firmware's time per frame outside its 16 SCLK periods. The polling loop reads
    the flag at an iteration's start and leaves at its end, so the INT_FLAG poll ends at most two
    iterations after the flag rises, and the BUFFULL poll (the flag is already clear) takes one; then
    the register accesses, the store and loop, the chip select (charged to every frame for the bound),
    and the start latency plus up to one LSPCLK cycle to reach an LSPCLK edge."""
    p = load_profile("reference", profile_overrides)
    io = costs()["io"]
    cycles = (
        3 * p.get("timing.poll_loop_cycles")
        + io["peripheral_read"]
        + io["peripheral_write"]
        + io["store_word"]
        + io["frame_loop"]
        + io["gpio_write"]
    )
    return cycles / SYSCLK_HZ + (p.get("spi.start_latency_lspclk") + 1) / LSPCLK_HZ


def test_spibrr_127_burst_takes_about_820_us_and_the_budget_shows_it():
    _, r = cli_report("spi.spibrr=127", seconds="0.1")
    clocking = BURST_BITS * 128 / LSPCLK_HZ  # 819.2 µs at ≈ 293 kHz
    assert r["spi_baud_hz"] == pytest.approx(LSPCLK_HZ / 128)
    assert r["spi"]["burst_clocking_s"] == pytest.approx(clocking, abs=TIME_EXACT_S)
    spi = r["tick"]["step"]["spi"]["worst_s"]
    assert clocking <= spi <= clocking + 15 * _frame_overhead_s(("spi.spibrr=127",)), spi
    assert r["solution"]["spi_clocking_s"] == pytest.approx(clocking, abs=TIME_EXACT_S)
    # The longer burst is in the busy time and the utilisation.
    ref = cli_report()[1]
    assert r["tick"]["step"]["busy"]["worst_s"] - ref["tick"]["step"]["busy"]["worst_s"] == pytest.approx(
        spi - ref["tick"]["step"]["spi"]["worst_s"], abs=1e-11
    )
    assert r["summary"]["utilisation"]["max"] > 0.2


def test_reference_spi_stage_is_bounded_by_clocking_plus_polling():
    _, r = cli_report()
    spi = r["tick"]["step"]["spi"]["worst_s"]
    assert 320e-6 <= spi <= 320e-6 + 15 * _frame_overhead_s()


def test_spibrr_9_sclk_violations_in_the_budget_and_in_the_run():
    code, r = cli_report("spi.spibrr=9", seconds="0.1")
    assert code == 1
    kinds = {(v["kind"], v["source"]) for v in r["rules_broken"]}
    assert ("sclk_burst_too_fast", "registers") in kinds
    assert ("sclk_too_fast", "emulation") in kinds
    run = emulate(still_trace(0.05), overrides=["spi.spibrr=9"])
    assert any(e["kind"] == "sclk_too_fast" for e in run.events)
    v = {x["kind"]: x for x in budget.summarise(run)["violations"]}
    assert v["sclk_too_fast"]["count"] == sum(e["kind"] == "sclk_too_fast" for e in run.events)
    assert v["sclk_too_fast"]["measured"] == pytest.approx(LSPCLK_HZ / 10, rel=1e-5)


def test_bit_level_and_transaction_level_give_the_same_budget_to_the_nanosecond():
    _, a = cli_report(seconds="0.5")
    _, b = cli_report("spi.level=bit", seconds="0.5")
    assert a["overrides"] == [] and b["overrides"] == ["spi.level=bit"]
    a, b = copy.deepcopy(a), copy.deepcopy(b)
    a.pop("overrides"), b.pop("overrides")
    assert a == b


# --------------------------------------------------------------------------------------- overruns


def test_a_0_3_ms_period_overruns_and_every_overrun_is_reported_with_its_tick():
    code, r = cli_report("timer.period_us=300", seconds="0.03")
    assert code == 1
    s = r["summary"]
    # One tick's busy time (≥ the 320 µs of clocking) exceeds 300 µs: every tick after the first
    # arrives while the CPU is busy.
    assert r["tick"]["step"]["busy"]["worst_s"] > 300e-6
    assert s["overruns"]["ticks"] == list(range(2, s["ticks"] + 1))
    assert s["utilisation"]["max"] > 1.0
    assert {v["kind"] for v in r["rules_broken"]} >= {"overrun", "tick_lost"}


def test_run_summary_lists_every_overrun_tick_the_events_name():
    run = emulate(still_trace(0.03), overrides=["timer.period_us=300"])
    s = budget.summarise(run)
    named = sorted(
        int(re.match(r"tick (\d+):", e["message"]).group(1))
        for e in run.events
        if e["kind"] in ("overrun", "tick_lost")
    )
    assert s["overruns"]["ticks"] == named == list(range(2, len(run.budget["tick"]) + 1))
    lost = sorted(
        int(re.match(r"tick (\d+):", e["message"]).group(1)) for e in run.events if e["kind"] == "tick_lost"
    )
    assert s["overruns"]["skipped_ticks"] == lost
    assert s["ticks_run"] == s["ticks"] - len(lost)


def test_drop_policy_skips_the_ticks_it_reports():
    run = emulate(still_trace(0.03), overrides=["timer.period_us=300", "firmware.overrun=drop"])
    s = budget.summarise(run)
    dropped = sorted(
        int(re.match(r"tick (\d+):", e["message"]).group(1)) for e in run.events if e["kind"] == "overrun"
    )
    assert s["overruns"]["skipped_ticks"] == dropped and dropped
    # A dropped tick leaves the CPU free for the next one: they alternate.
    assert all(b - a == 2 for a, b in itertools.pairwise(dropped))


# ------------------------------------------------------------------------------- backends and options


def _explained(stage: dict, factor: float) -> int:
    scaled = sum(t["count"] * t["unit_cycles"] for t in stage["terms"] if t["scaled"])
    fixed = sum(t["count"] * t["unit_cycles"] for t in stage["terms"] if not t["scaled"])
    return math.ceil(scaled * factor) + fixed


def test_iq_and_float_compute_times_differ_and_each_is_its_op_counts_times_unit_costs():
    _, f = cli_report(seconds="0.1")
    _, q = cli_report("firmware.numeric=iq", seconds="0.1")
    table = costs()
    for r, section in ((f, "float"), (q, "iq")):
        comp = r["compute"]
        assert comp["arith_section"] == section
        for name in ("entry", "decode", "attitude", "euler", "navigation", "exit"):
            stage = comp[name]
            assert _explained(stage, comp["code_location_factor"]) == stage["cycles"], name
            for t in stage["terms"]:
                sec, key = t["key"].split(".")
                assert table[sec][key] == t["unit_cycles"], t["key"]
        # The emulator charges exactly these cycles.
        assert r["tick"]["step"]["attitude"]["worst_s"] == pytest.approx(
            comp["attitude"]["cycles"] / SYSCLK_HZ, abs=TIME_EXACT_S
        )
    # Same generic code, same counts; different unit costs, different times.
    assert f["compute"]["attitude"]["counts"] == q["compute"]["attitude"]["counts"]
    assert q["compute"]["attitude"]["cycles"] != f["compute"]["attitude"]["cycles"]
    diff = sum(
        tq["count"] * (tq["unit_cycles"] - tf["unit_cycles"])
        for tq, tf in zip(q["compute"]["attitude"]["terms"], f["compute"]["attitude"]["terms"], strict=True)
    )
    assert q["compute"]["attitude"]["cycles"] - f["compute"]["attitude"]["cycles"] == diff


@pytest.mark.parametrize(
    ("override", "row", "direction"),
    [
        ("spi.spibrr=99", "spi", +1),
        ("firmware.code_location=flash", "attitude", +1),
        ("firmware.numeric=iq", "attitude", +1),
        ("firmware.algorithm=rotation-vector", "attitude", 0),
        ("timer.period_us=5000", "margin", +1),
    ],
)
def test_profile_keys_change_the_budget(override, row, direction):
    base = budget.budget_report("reference", seconds=0.05)
    changed = budget.budget_report("reference", [override], seconds=0.05)
    a, b = base["tick"]["step"][row]["worst_s"], changed["tick"]["step"][row]["worst_s"]
    assert b != a
    if direction:
        assert (b - a) * direction > 0
    if row == "attitude":
        assert b == pytest.approx(changed["compute"]["attitude"]["cycles"] / SYSCLK_HZ, abs=TIME_EXACT_S)
    if override.startswith("firmware.algorithm"):
        assert changed["compute"]["attitude"]["counts"] != base["compute"]["attitude"]["counts"]


def test_flash_factor_scales_the_code_but_not_the_hardware_context_save():
    _, r = cli_report("firmware.code_location=flash", seconds="0.1")
    t = costs()
    factor = t["memory"]["flash_factor"]
    assert r["compute"]["code_location_factor"] == factor
    assert r["compute"]["entry"]["cycles"] == t["interrupt"]["hw_context_save"] + math.ceil(
        t["interrupt"]["c_prologue"] * factor
    )


# ------------------------------------------------------------------------------ jitter, sample age


def test_sample_age_and_jitter_match_the_analytic_expectation():
    """4 ms reads against the 1/819.2 s sample clock: gcd(4 ms, 1/819.2 s) = 1/512000 s, and 625
    consecutive reads take each age δ + j/512000 s, j = 0…624, once (δ = read offset mod 1/512000 s).
    Jitter: 600000 SYSCLKOUT cycles per tick is a multiple of the LSPCLK divisor, so none."""
    run = emulate(still_trace(2.5 + 0.002))
    assert len(run.read_tick) == 625
    ages = np.sort(run.read_age_ps.astype(np.int64))
    step_ps = 1_953_125  # 1/512000 s, exact in ps
    sample_ps = 1_220_703_125  # 1/819.2 s
    assert np.array_equal(ages - ages[0], np.arange(625) * step_ps)
    s = budget.summarise(run)["reads"]
    offset = s["offset"]["min"]
    delta = round(offset / PS) % step_ps
    assert ages[0] == delta
    assert s["sample_age_distinct"] == 625
    assert s["sample_age"]["min"] == pytest.approx(delta * PS, abs=TIME_EXACT_S)
    assert s["sample_age"]["max"] == pytest.approx((delta + 624 * step_ps) * PS, abs=TIME_EXACT_S)
    assert s["sample_age"]["mean"] == pytest.approx((delta + 312 * step_ps) * PS, abs=TIME_EXACT_S)
    assert s["sample_age"]["max"] < sample_ps * PS  # spread over [0, 1.2207 ms)
    assert s["jitter_s"] == 0.0 and s["offset"]["max"] == offset
    assert s["interval"]["min"] == s["interval"]["max"] == pytest.approx(4e-3, abs=TIME_EXACT_S)


def test_a_period_off_the_lspclk_grid_jitters_by_three_sysclk_cycles():
    """600001 cycles per tick: each ISR starts one SYSCLKOUT cycle later in the LSPCLK (= SYSCLKOUT/4)
    phase, and the first SCLK edge waits for an LSPCLK edge: four offsets, 3 cycles apart at most."""
    run = emulate(still_trace(0.1), overrides=["timer.period_us=4000.0067"])
    b = run.budget
    assert int(b["deadline_ps"][0] - b["tick_ps"][0]) == round(600001 / SYSCLK_HZ / PS)
    s = budget.summarise(run)["reads"]
    assert s["jitter_s"] == pytest.approx(3 / SYSCLK_HZ, abs=TIME_EXACT_S)
    offsets_ps = run.read_t_start_ps.astype(np.int64) - b["tick_ps"].astype(np.int64)[run.read_tick - 1]
    # In whole SYSCLKOUT cycles (each instant is rounded to the picosecond).
    assert len(np.unique(np.round(offsets_ps * PS * SYSCLK_HZ))) == 4


def test_back_to_back_reads_are_slots_not_jitter():
    run = emulate(still_trace(0.1), overrides=["firmware.schedule=back-to-back"])
    s = budget.summarise(run)["reads"]
    assert s["reads"] == 3 * len(run.budget["tick"])
    assert s["jitter_s"] == 0.0
    assert s["offset"]["max"] - s["offset"]["min"] > 320e-6  # the third burst starts two bursts later


# ------------------------------------------------------------------------------ purity, docs, plot


def test_summarise_is_a_pure_function_of_the_run():
    run = emulate(still_trace(0.1, gyro_dps=(0.5, -0.3, 1.0)))
    before = {k: v.copy() for k, v in run.budget.items()}
    a = budget.summarise(run)
    assert budget.summarise(run) == a
    assert all(np.array_equal(before[k], run.budget[k]) for k in before)
    json.dumps(a, allow_nan=False)


def test_every_cost_table_entry_names_its_source_or_is_marked_an_estimate():
    prov = budget.cost_provenance((ROOT / "firmware_model" / "c28x-costs.toml").read_text())
    table = costs()
    keys = {f"{s}.{k}" for s, sec in table.items() for k in sec}
    assert set(prov) == keys
    for key, p in prov.items():
        assert p["source"] is not None, f"{key}: {p['note']!r} names no source and is not marked an estimate"
        assert p["value"] == table[key.split(".")[0]][key.split(".")[1]]


def test_docs_describe_every_json_key():
    doc = (ROOT / "docs" / "budget.md").read_text()
    _, r = cli_report()
    for key in [*r, *r["summary"], *r["solution"], *r["summary"]["reads"], "plot"]:
        assert f"`{key}`" in doc, key


def test_plot_writes_a_png(tmp_path):
    out = tmp_path / "budget.png"
    r = run_cli("budget", "--duration-s", "0.05", "--plot", str(out))
    assert r.code == 0, r.err
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and out.stat().st_size > 10_000


def test_bad_seconds_is_a_usage_error():
    r = run_cli("budget", "--duration-s", "0")
    assert r.code == 2 and "--duration-s" in r.err and "Traceback" not in r.err
