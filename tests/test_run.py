"""`sins-fw run`, the run summary and output file, `sins_fw.emulate` keyword overrides, and the
published decode's stale value seen through the whole board."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import sins_fw
from conftest import ROOT, run_cli
from sins_fw import synth
from sins_fw.errors import ProfileError
from sins_fw.report import summarise
from sins_fw.run_output import RUN_FORMAT, load_run

STATIC = "traces/static_60s.h5"


def test_run_summary_json():
    r = run_cli("run", STATIC, "--json")
    assert r.code == 0, r.err
    s = json.loads(r.out)
    assert s["cycles"] == 7499 and s["numeric"] == "c28x-f32"
    assert s["events"] == {"total": 0, "by_kind": {}}
    b = s["budget"]
    assert b["tick_period_s"] == pytest.approx(4e-3, abs=1e-12)
    assert 0 < b["utilisation_mean"] <= b["utilisation_max"] < 1
    assert b["overruns"] == b["ticks_skipped"] == b["spi_violations"] == 0
    a = s["attitude_error"]
    assert a["alignment"]["method"] == "initial" and "power-on" in a["alignment"]["description"]
    assert set(a["euler"]) == {"roll", "pitch", "yaw", "total"}


def test_run_text_states_alignment_and_budget():
    r = run_cli("run", STATIC)
    assert r.code == 0, r.err
    assert "alignment    initial attitude" in r.out
    assert "utilisation" in r.out and "SPI violations" in r.out
    assert r.err == "", "no progress bar when stderr is not a terminal"


def test_static_error_is_the_unsensed_earth_rate():
    # At rest, level, the earth rate (≤ 0.0042 °/s) is below half a gyro LSB (0.025 °/s): every gyro
    # word reads 0, and the firmware subtracts C_n^b ω_ie from that zero. Without navigation (no
    # transport rate) its attitude solves q̇ = −½ ω_ie ⊗ q, i.e. rotates by exactly ω_ie·t relative to
    # the truth while it integrates: steps × T seconds (it starts at its first read, one tick after
    # power-on). f64, RK4 on a constant rate: the error is ω_ie·steps·T to rounding (~1e-12 relative).
    run = sins_fw.emulate(STATIC, firmware__numeric="f64", firmware__navigation=False)
    assert not run.read_rate.any()
    s = summarise(run, trace=STATIC)
    total = s["attitude_error"]["euler"]["total"]
    omega_ie = run.profile.get("navigation.earth_rate_rad_s")
    integrated_s = run.cycles * 2 * s["budget"]["tick_period_s"]  # half-step: T = two ticks
    assert math.radians(total["final_deg"]) == pytest.approx(omega_ie * integrated_s, rel=1e-9)


def test_spi_violations_are_counted_with_first_occurrence():
    # SPIBRR = 9: SCLK = 37.5 MHz / 10 = 3.75 MHz, above the 1 MHz burst limit: every frame breaks it.
    r = run_cli("run", STATIC, "--set", "spi.spibrr=9", "--json")
    assert r.code == 1, r.err  # error-severity events: a failed check, the summary still printed
    s = json.loads(r.out)
    ticks = s["budget"]["ticks"]
    assert s["budget"]["spi_violations"] == 15 * ticks
    first = s["events"]["by_kind"]["sclk_too_fast"]
    assert first["count"] == 15 * ticks and first["first_t_s"] == pytest.approx(4e-3, abs=2e-4)
    assert "MHz" in first["first_message"] or "Hz" in first["first_message"]


@pytest.mark.parametrize(("ext", "trace"), [("csv", "static_60s"), ("h5", "pitch_sweep")])
def test_run_output_file_round_trips(tmp_path, ext, trace):
    out = tmp_path / f"run.{ext}"
    r = run_cli("run", f"traces/{trace}.h5", "--out", str(out))
    assert r.code == 0, r.err
    assert [p.name for p in tmp_path.iterdir()] == [out.name], "no temporary file left behind"
    meta, cols = load_run(out)
    assert meta["format"] == RUN_FORMAT and meta["sample_rate_hz"] == "125" and meta["numeric"] == "c28x-f32"
    run = sins_fw.emulate(ROOT / "traces" / f"{trace}.h5")
    # Bit-exact: shortest round-trip text in CSV, float64 datasets in HDF5.
    np.testing.assert_array_equal(cols["t_s"], run.time_s)
    np.testing.assert_array_equal(np.stack([cols[f"q{i}"] for i in range(4)], axis=1), run.quat)
    np.testing.assert_array_equal(cols["pitch_deg"], run.euler_deg[:, 1])
    np.testing.assert_array_equal(cols["vel_u_mps"], run.velocity_enu[:, 2])
    np.testing.assert_array_equal(cols["height_m"], run.position[:, 2])
    np.testing.assert_array_equal(np.stack([cols[f"truth_q{c}"] for c in "wxyz"], axis=1), run.truth_q)
    np.testing.assert_array_equal(cols["moving"], run.moving)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["run", "nope.h5"], "nope.h5: no such trace file"),
        (["run", STATIC, "--out", "x.txt"], "unknown trace extension `.txt`"),
        (["run", STATIC, "--set", "spi.nope=1"], "unknown key `spi.nope`"),
        (["run", "tests/data/bad/time_not_increasing.csv"], "expected strictly increasing time"),
        (["run", STATIC, "--align", "sideways"], "invalid choice"),
    ],
)
def test_bad_input_exits_2_without_traceback(args, message):
    r = run_cli(*args)
    assert r.code == 2, (r.code, r.err)
    assert message in r.err and "Traceback" not in r.err


def test_keyword_overrides_match_override_texts():
    trace = ROOT / "traces" / "static_60s.h5"
    by_keyword = sins_fw.emulate(
        trace, spi__spibrr=29, firmware__numeric="f64", device__timing_mode="lenient"
    )
    assert by_keyword.profile.get("spi.spibrr") == 29
    assert by_keyword.profile.get("firmware.numeric") == "f64"
    by_text = sins_fw.emulate(
        trace, overrides=["spi.spibrr=29", "firmware.numeric=f64", "device.timing_mode=lenient"]
    )
    assert by_keyword.profile.values == by_text.profile.values
    np.testing.assert_array_equal(by_keyword.quat, by_text.quat)
    with pytest.raises(ProfileError, match="section__key"):
        sins_fw.emulate(trace, spibrr=29)
    with pytest.raises(ProfileError, match=r"navigation\.velocity_enu"):
        sins_fw.emulate(trace, navigation__velocity_enu=[1.0, 2.0])


# --- the published decode through the whole board -----------------------------------------------------

RATE_0x1800_DPS = 307.2  # 0x1800 = 6144 codes × 0.05 °/s: between the two published ranges


@pytest.fixture(scope="module")
def fast_trace():
    # About body x (east, level): the earth rate has no x component, so the hold reads exactly 0x1800.
    return synth.generate(
        "turntable", axis="x", rates_dps=(RATE_0x1800_DPS,), hold_s=1.0, max_accel_dps2=3000.0, lead_s=0.2
    )


def _x_codes(run) -> np.ndarray:
    return run.read_words[:, 2] & 0x3FFF  # burst frame 2 = XGYRO_OUT, 14 valid bits


def _gap_reads(run) -> int:
    codes = _x_codes(run)
    return int(np.count_nonzero((codes > 0x1770) & (codes < 0x2890)))


def test_published_decode_keeps_previous_value_for_0x1800(fast_trace):
    run = sins_fw.emulate(fast_trace, firmware__decode="published")
    codes = _x_codes(run)
    hit = np.flatnonzero(codes == 0x1800)
    assert len(hit) > 100
    # Every read between the ranges is reported, once per read.
    assert run.events_by_kind().get("stale_decode") == _gap_reads(run) > len(hit)
    stale = [e for e in run.events if e["kind"] == "stale_decode"]
    # ND (bit 15) and EA (bit 14: 307.2 °/s is beyond the rated ±300, the overrange flag is set) + 0x1800
    assert any("XGYRO_OUT = 0xD800" in e["message"] for e in stale)
    # The value held is the last one inside the range: the read before the first out-of-range code.
    last_in_range = np.flatnonzero(codes <= 0x1770)
    held = run.read_rate[last_in_range[last_in_range < hit[0]][-1], 0]
    np.testing.assert_array_equal(run.read_rate[hit, 0], held)
    assert math.degrees(held) <= 300.0 + 1e-4


def test_correct_decode_reads_307_2_dps(fast_trace):
    run = sins_fw.emulate(fast_trace, firmware__decode="correct")
    hit = np.flatnonzero(_x_codes(run) == 0x1800)
    assert len(hit) > 100
    # c28x-f32: 6144 is exact, then × 0.05f and × (π/180)f: two rounded literals and two rounded
    # products, each ≤ 2⁻²⁴ relative.
    expected = math.radians(RATE_0x1800_DPS)
    np.testing.assert_allclose(run.read_rate[hit, 0], expected, rtol=4 * 2.0**-24)
    # The difference from the published decode is still reported.
    assert run.events_by_kind().get("stale_decode") == _gap_reads(run)


def test_nested_overruns_complete_and_are_reported():
    r = run_cli(
        "run",
        str(ROOT / "traces" / "static_60s.h5"),
        "--until-s",
        "0.2",
        "--set",
        "firmware.overrun=nest",
        "--set",
        "timer.period_us=300",
        "--json",
    )
    assert r.code == 1, r.err  # overruns are error-severity events
    kinds = json.loads(r.out)["events"]["by_kind"]
    assert "nested_interrupt" in kinds and "overrun" in kinds


def test_push_reads_any_memory_layout_in_logical_order():
    # The binding reads C-contiguous numpy buffers in place and copies anything else in row-major
    # order: a Fortran-ordered or strided column must give exactly the output of a C-ordered one.
    from sins_fw.harness import new_emulator
    from sins_fw.profile import load_profile

    profile = load_profile("reference", ["errors.preset=adis16407"])
    rng = np.random.default_rng(7)
    n = 2048  # 2.5 s at 819.2 SPS
    cols = [
        np.arange(n) / 819.2,
        rng.normal(0.0, 5.0, (n, 3)),
        rng.normal(0.0, 0.1, (n, 3)) + np.array([0.0, 0.0, 1.0]),
        rng.normal(0.3, 0.05, (n, 3)),
        1000.0 + rng.normal(0.0, 1.0, n),
        25.0 + rng.normal(0.0, 1.0, n),
    ]

    def output(columns):
        emu = new_emulator(profile)
        emu.push(*columns)
        emu.end()
        emu.run()
        out = emu.take()
        return [out[k].tobytes() for k in ("read_words", "cycle_quat", "cycle_t_ps")]

    def strided(a):
        return np.repeat(a, 2, axis=0)[::2]

    reference = output(cols)
    assert len(reference[0]) > 0
    fortran = [np.asfortranarray(c) for c in cols]
    assert not fortran[1].flags.c_contiguous
    assert output(fortran) == reference
    assert output([strided(c) for c in cols]) == reference


def test_output_size_hint_never_changes_the_output():
    # `expect_input_until` only sizes the output columns: right, too long, too short or not finite,
    # the output is the same bytes.
    from sins_fw.harness import new_emulator
    from sins_fw.profile import load_profile

    profile = load_profile("reference", ["errors.preset=adis16407"])
    trace = synth.generate("coning", duration_s=3.0)
    t = trace.t_s - trace.t_s[0]

    def output(hint):
        emu = new_emulator(profile)
        if hint is not None:
            emu.expect_input_until(hint)
        for s in (slice(0, 1000), slice(1000, None)):
            emu.push(t[s], trace.gyro_dps[s], trace.accel_g[s])
            emu.run()
        emu.end()
        emu.run()
        out = emu.take()
        return [v.tobytes() for k, v in out.items() if k != "events"] + [repr(out["events"]).encode()]

    reference = output(None)
    for hint in (float(t[-1]), 100.0, 0.5, math.nan):
        assert output(hint) == reference


def _dcm_file_columns(cols: dict[str, np.ndarray], key: str) -> np.ndarray:
    """The file columns of the core's `dcm_<key>`, as Run.dcm holds it (one column per component)."""
    from sins_fw.run_output import CORE_FILE_COLUMNS

    names = [n for n, _ in CORE_FILE_COLUMNS[f"dcm_{key}"]]
    return cols[names[0]] if len(names) == 1 else np.stack([cols[n] for n in names], axis=1)


@pytest.mark.parametrize("ext", ["csv", "h5"])
def test_dcm_run_output_carries_the_correction_terms(tmp_path, ext):
    """Issue 18, item 3: under the DCM `run --out` holds ω_P, ω_I, the two errors and |R·Rᵀ − I|
    on the row of their step, bit for bit the run's `Run.dcm` (shortest round-trip text in CSV,
    float64 datasets in HDF5), and the replay check (`replay`, `report` of the file) compares them
    like every other column. Other algorithms' files have none of them."""
    from sins_fw.errors import CheckFailed
    from sins_fw.run_output import CORE_FILE_COLUMNS, replay_check

    out = tmp_path / f"dcm.{ext}"
    r = run_cli("run", STATIC, "--set", "firmware.algorithm=dcm", "--until-s", "5", "--out", str(out))
    assert r.code == 0, r.err
    _, cols = load_run(out)
    run = sins_fw.emulate(ROOT / STATIC, overrides=["firmware.algorithm=dcm"], until_s=5.0)
    assert np.array_equal(run.dcm["step"], run.step) and run.cycles > 1000
    for key in ("omega_p", "omega_i", "error_rp", "error_yaw", "orthogonality"):
        np.testing.assert_array_equal(_dcm_file_columns(cols, key), run.dcm[key])
    assert np.any(run.dcm["omega_p"] != 0) and np.all(run.dcm["orthogonality"] > 0), "not all zero"
    replay_check(out)
    if ext == "csv":
        # One DCM value changed in the file: the replay check names it.
        lines = out.read_text(encoding="utf-8").splitlines(keepends=True)
        header = next(i for i, line in enumerate(lines) if not line.startswith("#"))
        row = lines[header + 1].rstrip("\n").split(",")
        row[-1] = repr(float(row[-1]) * 2)
        lines[header + 1] = ",".join(row) + "\n"
        out.write_text("".join(lines), encoding="utf-8")
        with pytest.raises(CheckFailed, match="row 0, column `dcm_orthogonality`"):
            replay_check(out)
    rk4 = tmp_path / f"rk4.{ext}"
    assert run_cli("run", STATIC, "--until-s", "1", "--out", str(rk4)).code == 0
    dcm_names = {n for k, v in CORE_FILE_COLUMNS.items() if k.startswith("dcm_") for n, _ in v}
    assert not dcm_names & set(load_run(rk4)[1])
