"""The geomagnetic–gyro board (firmware_model/geomag.toml: an F28335 reading the ADS8344 over SPI,
`firmware.application = "ads8344-geomag"`): `sins-fw board`, `budget`, `run` and `replay` accept it
on a `sins-fw synth spin` trace; its roll follows the trace's truth within a bound derived from the
sensor presets; a profile reading the ADS8344 in 16-bit characters is refused naming the key and what
the data sheet expects."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from conftest import ROOT, run_cli
from sins_fw.harness import emulate

PROFILE = str(ROOT / "firmware_model" / "geomag.toml")
SPIN_DPS = 500.0
DURATION_S = 20.0


@pytest.fixture(scope="module")
def spin_trace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """500 °/s about x after a 2 s spin-up, the axis swinging ±5° in pitch and yaw, the custom field
    (0.5 gauss, 60° down, declination 0) that geomag.toml's `field_enu_gauss` states."""
    out = tmp_path_factory.mktemp("geomag") / "spin.h5"
    r = run_cli(
        "synth", "spin", "--spin-dps", str(SPIN_DPS), "--duration-s", str(DURATION_S),
        "--mag-field", "custom", "--out", str(out),
    )  # fmt: skip
    assert r.code == 0, r.err
    return out


def test_board_budget_run_replay_accept_the_profile(spin_trace: Path, tmp_path: Path) -> None:
    board = run_cli("board", "--profile", PROFILE)
    assert board.code == 0, board.err
    assert "the ADS8344 needs mode 0 or 3: matches" in board.out
    assert "8 bits" in board.out and "rules broken:  none" in board.out
    budget = run_cli("budget", "--profile", PROFILE, "--duration-s", "0.1")
    assert budget.code == 0, budget.err
    assert "rules broken: none" in budget.out
    run = run_cli("run", str(spin_trace), "--profile", PROFILE, "--out", str(tmp_path / "run.h5"))
    assert run.code == 0, run.err
    assert "6666 attitude steps" in run.out and (tmp_path / "run.h5").is_file()
    replay = run_cli("replay", str(spin_trace), "--profile", PROFILE, "--out", str(tmp_path / "r.rrd"))
    assert replay.code == 0, replay.err
    assert (tmp_path / "r.rrd").is_file()


def test_16_bit_characters_are_refused_naming_the_key() -> None:
    r = run_cli("board", "--profile", PROFILE, "--set", "spi.spiccr=0x00CF")
    assert r.code == 2, r.out
    assert "key `spi.spiccr`" in r.err and "SPICHAR = 15: 16-bit characters" in r.err
    assert "for the ADS8344 on GPIO57: SPICHAR = 7 (8-bit characters" in r.err
    assert "D15…D9 fall in the command's character" in r.err


def _spin_roll(q: np.ndarray) -> np.ndarray:
    """Roll about body x in firmware/geomag.rs `spin_euler`'s convention: atan2(C₃₂, C₃₃)."""
    q0, q1, q2, q3 = q.T
    return np.arctan2(2.0 * (q2 * q3 + q0 * q1), q0 * q0 - q1 * q1 - q2 * q2 + q3 * q3)


def test_roll_follows_the_truth_within_the_preset_bound(spin_trace: Path) -> None:
    """Roll error after the loop's transient (t ≥ 12 s), seed 1, against a bound from the presets
    (geomag.toml: spin1200 on x, adxrs300 on y and z, amr; aid K_p = 1/s, K_i = 0.25/s²: critically
    damped, ω_n = 0.5 rad/s; update T = 3 ms):
    (a) the x gyro's rate error d = δk·ω + b + k₂ω²/FS + Ω_earth at 3σ of the unit draws
        (δk 3·0.5 %, b 3·1 °/s, k₂ 0.1 %): 10.7 °/s; the loop answers a rate step with d·t·e^(−ω_n t),
        5.6e-3 rad at 12 s (the aid runs from t = 0);
    (b) magnetometer noise N·√(πf_c/2) = 20 µgauss/√Hz·√(π·1 kHz/2) = 7.9e-4 gauss over the 0.5 gauss
        across the spin axis: σ_γ = 1.6e-3 rad per update, through the loop's noise bandwidth
        (K_p + K_i/K_p)/4 = 0.3125 Hz: σ = σ_γ·√(2TB) = 6.9e-5 rad, 6σ = 4.1e-4 rad;
    (c) the cross-axis gyros' bias (3σ 3 °/s) rotating with the spin tilts the axis by ≤ b/ω = 6e-3 rad,
        seen in the spin-body roll through the ±5° pitch (× tan 5°) and through the field along the
        axis (≤ 0.022 of 0.5 gauss): 5.3e-4 + 2.6e-4 rad;
    (d) the x gyro's group delay 2ζ/ω_n = 2.23 ms leaves a roll step ω·τ = 0.0195 rad at the end of
        the spin-up, which the loop removes as (1 + ω_n t)e^(−ω_n t): 7.9e-4 rad 10 s later;
    (e) the magnetometer's 1 kHz lag, compensated: ≤ 2e-6 rad.
    Sum 7.6e-3 rad (0.44°). A broken chain (a result shifted by a bit, an uncompensated gyro, no aid)
    is off by degrees to 180°."""
    run = emulate(str(spin_trace), PROFILE)
    assert not run.events_by_kind().get("mag_aid_gated"), "the aid must stay on: 0.5 gauss across the axis"
    t = run.time_s
    truth = run.truth_q
    err = np.angle(np.exp(1j * (_spin_roll(run.quat) - _spin_roll(truth))))
    late = t >= 12.0
    assert late.sum() > 2000
    d = math.radians(0.015 * SPIN_DPS + 3.0 + 0.001 * SPIN_DPS**2 / 1200.0 + 0.0042)
    bound = (
        d * 12.0 * math.exp(-0.5 * 12.0)
        + 4.1e-4
        + 5.3e-4
        + 2.6e-4
        + 0.0195 * (1 + 0.5 * 10.0) * math.exp(-0.5 * 10.0)
        + 2e-6
    )
    worst = float(np.abs(err[late]).max())
    assert worst <= bound, f"roll error {worst:.2e} rad > {bound:.2e} rad"


def test_spi_modes_0_and_3_read_the_same_codes_without_events(spin_trace: Path) -> None:
    """geomag.toml reads the ADS8344 in SPI mode 0 (the data sheet's drawing: SPICCR 0x87, CLKPOLARITY 0;
    SPICTL 0x0F, CLK_PHASE 1, TI's "rising edge with delay"); mode 3 (SPICCR 0xC7, SPICTL 0x07) is set
    by an override. Either way the run has no event and CH7, wired to VREF/2 = 2.5 V of VREF 5 V, reads
    32768 on every read (mode 0 read 16384 when the link shifted the part's answer a second time).
    The other channels agree within 1 LSB: the two modes hold each input half an SCLK period (213 ns)
    apart, and the fastest input, the 0.5 gauss across the axis turning at 500 °/s through 1 V/gauss,
    moves 0.5 V · 8.7 rad/s · 213 ns = 0.012 LSB in that time (a code may still cross one step). The
    roll in mode 0 is checked against the truth by the test above."""
    words = {}
    for mode, overrides in [(0, ()), (3, ("spi.spiccr=0x00C7", "spi.spictl=0x0007"))]:
        run = emulate(str(spin_trace), PROFILE, overrides=overrides, until_s=4.0)
        assert run.events == [], (mode, run.events[:3])
        words[mode] = run.read_words[:, :8].astype(np.int64)
        assert len(words[mode]) > 3000, mode
        assert np.all(words[mode][:, 7] == 32768), (mode, np.unique(words[mode][:, 7]))
    assert words[0].shape == words[3].shape
    assert int(np.abs(words[0] - words[3]).max()) <= 1
