"""Issue 21's group-delay check through the whole geomagnetic–gyro board (firmware_model/geomag.toml: the
F28335 converting the ADS8344's eight channels over SPI every 1 ms tick, the firmware's three-sample
update every third tick): the roll bias of a steady spin, predicted from the sensors' bandwidths and from
each channel's sample instant in the SPI sequence, against `sins-fw run` (`harness.emulate`) on
`sins-fw synth spin` traces at two spin rates.

Prediction at a steady spin ω (ω_x, the x gyro's rate), each term named:
- the ADS8344 holds a channel at the 8th falling DCLK edge of its control byte (ads8344.md; SPI mode 0:
  7.5 SCLK periods after the byte's first rising edge), SCLK = LSPCLK/(SPIBRR + 1) from the profile's
  clocks; the firmware converts CH0…CH7 one after another, so channel c is held δ_c after the timer tick
  (the bytes' first edges are the emulated link's, recorded in its bus log);
- the firmware integrates each tick's rate as rate·P (P the 1 ms tick): the update labelled with tick
  n's time holds ∫ of the x rate up to t_n + δ_0 + P/2 (the midpoint rule), a lead of ω(δ_0 + P/2);
- the spin gyro's second-order low-pass (100 Hz, ζ 0.7) has lost τ_g·ω of angle for good once the
  rate has settled, τ_g = 2ζ/ω_n = 2.228 ms (`geomag.gyro_delay_s` adds it back);
- the magnetometer's y and z (the field across the spin axis) are held at δ_4 and δ_5: the measured
  across-axis angle is that of the mean instant δ_m = (δ_4 + δ_5)/2 (a skew Δ turns it by Δω·cos²γ:
  mean Δω/2 over a turn); its first-order 1 kHz low-pass lags by atan(ω/ω_c) (compensated by
  `geomag.mag_cutoff_hz` = 1000, the profile's setting), and the front end's 50 µs simulation step
  adds τ_d = h(1/(1 − e^(−ω_c h)) − ½) − 1/ω_c = 1.31 µs (device/analog: an artefact of the
  simulation, which the compensation cannot know).

So the gyro-only roll (aid gains 0) sits at ω(δ_0 + P/2 − τ_g), ω(δ_0 + P/2) with the compensation;
the aided roll, once the PI loop has settled, at the magnetometer's: ω(δ_m − τ_d) − atan(ω/ω_c) +
[atan(ω/ω_c) when compensated]. The gyro's τ_g does not enter the aided roll: at a steady spin the
gyro's output is the constant ω, which a delay does not change; what τ_g leaves (an angle) the loop
takes out like any other, and its integrator makes the steady error zero. The disagreement the aid sees,
gyro-only minus aided, is −ω(τ_g − τ_m) + ω(δ_0 + P/2 − δ_m) + O(ω³): the quantity issue 21 names,
which the aid removes rather than carries.

Set-up: ideal sensors (their bandwidths kept; the 16-bit quantisation is the only noise), the spin
axis north and level at latitude 0 (the earth's rate lies along the spin axis: the cross-axis gyros,
whose null sits exactly on code 32768, read exactly 0; elsewhere their quantisation rectifies the
earth's rate into a tilt drift of 2·LSB/π = 1.7e-4 rad/s that reaches the roll at second order), no
sway, spin-up over 0.1 s, the profile's field (custom: 0.5 gauss, 60° down: 0.433 gauss across the
axis). The rates 290 and 990 °/s advance the spin 0.87° and 2.97° per update: the magnetometer is read at
thousands of distinct roll angles, so its quantisation error averages (at 1000 °/s, 3° per update, it
would be read at only 120 angles, a fixed pattern whose mean does not shrink)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from conftest import ROOT, run_cli
from sins_fw import spin_table
from sins_fw.harness import Run, emulate
from sins_fw.profile import load_profile

PROFILE = str(ROOT / "firmware_model" / "geomag.toml")
RATES_DPS = (290.0, 990.0)
DURATION_S = 40.0
SPIN_UP_S = 0.1
#: The profile on the test's turntable: ideal sensors, the spin axis north (the trace's start), and a
#: calibration table without the presets' nominal bow and temperature coefficient (geomag.toml's
#: compensates them; the ideal sensors have none).
BASE = ("geomag.ideal_sensors=true", "firmware.initial_yaw_deg=90", *spin_table.IDEAL_CALIBRATION)
GYRO_ONLY = ("geomag.aid_kp=0", "geomag.aid_ki=0")
#: Presets (rust/core/src/device/analog/gyro.rs SPIN1200, magnetometer.rs AMR) and the front end's step.
GYRO_HZ, GYRO_ZETA, GYRO_V_PER_DPS = 100.0, 0.7, 0.0016
MAG_HZ, MAG_V_PER_GAUSS = 1000.0, 1.0
FRONT_END_STEP_S = 50e-6
TAU_G = 2.0 * GYRO_ZETA / (2.0 * math.pi * GYRO_HZ)
EARTH_RATE = 7.292115e-5  # rad/s, along the spin axis at latitude 0
#: Control bytes of CH0…CH7, single-ended, PD = 11 (ads8344.md Table I: A2A1A0 = 000, 100, 001, 101,
#: 010, 110, 011, 111): S·A2A1A0·0·1·11.
CONTROL_BYTES = [0x80 | a << 4 | 0x07 for a in (0b000, 0b100, 0b001, 0b101, 0b010, 0b110, 0b011, 0b111)]
#: Aid gains (geomag.toml) and the settled window of the aided runs.
KP, KI = 1.0, 0.25
AIDED_FROM_S = 30.0


def _lspclk_hz() -> float:
    clocks = load_profile(PROFILE).get("clocks")
    divide = {0: 4, 1: 4, 2: 2, 3: 1}[clocks["divsel"]]  # f28335.md: DIVSEL 2 → /2
    sysclk = clocks["crystal_hz"] * clocks["pllcr"] / divide
    lospcp = clocks["lospcp"]
    return sysclk / (2 * lospcp) if lospcp else sysclk


def _sclk_period_s() -> float:
    spibrr = load_profile(PROFILE).get("spi.spibrr")
    return (spibrr + 1 if spibrr >= 3 else 4) / _lspclk_hz()


@pytest.fixture(scope="module", params=RATES_DPS, ids=lambda w: f"{w:g}dps")
def spin(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> tuple[float, Path]:
    w = float(request.param)
    out = tmp_path_factory.mktemp("delay") / f"spin{w:g}.h5"
    r = run_cli(
        "synth", "spin", "--spin-dps", str(w), "--spin-up-s", str(SPIN_UP_S), "--duration-s", str(DURATION_S),
        "--pitch-amplitude-deg", "0", "--yaw-amplitude-deg", "0", "--attitude-deg", "0,0,90",
        "--latitude-deg", "0", "--mag-field", "custom", "--out", str(out),
    )  # fmt: skip
    assert r.code == 0, r.err
    return w, out


def sample_instants(trace: Path) -> np.ndarray:
    """Each channel's hold instant after its timer tick, s, from the emulated link's bus log of ticks
    3…5 (the same at every tick: the ISR reads before it computes)."""
    run = emulate(str(trace), PROFILE, overrides=BASE, bus_window=(3, 5), until_s=0.01)
    bus = run.bus
    assert bus is not None
    period = _sclk_period_s()
    assert np.all(np.abs(bus["frame_sclk_period_ps"] * 1e-12 - period) <= 1e-12)
    ticks = dict(zip(run.budget["tick"].tolist(), run.budget["tick_ps"].tolist(), strict=True))
    first = bus["frame_first_edge_ps"].astype(np.int64)
    din = bus["frame_din"].astype(np.int64)
    rows = []
    for k in (3, 4, 5):
        tick = ticks[k]
        inside = (first >= tick) & (first < tick + 1_000_000_000)
        assert inside.sum() == 32, "8 conversions of 4 characters per tick"
        control = np.flatnonzero(inside)[::4]
        assert din[control].tolist() == CONTROL_BYTES
        rows.append((first[control] - tick) * 1e-12 + 7.5 * period)
    rows_a = np.array(rows)
    assert np.all(np.abs(rows_a - rows_a[0]) < 1e-12), rows_a
    return rows_a[0]


def _roll(q: np.ndarray) -> np.ndarray:
    """Roll about body x in firmware/geomag.rs `spin_euler`'s convention."""
    q0, q1, q2, q3 = q.T
    return np.arctan2(2.0 * (q2 * q3 + q0 * q1), q0 * q0 - q1 * q1 - q2 * q2 + q3 * q3)


def _roll_error(run: Run) -> np.ndarray:
    assert run.truth_q is not None
    return np.unwrap(_roll(run.quat) - _roll(run.truth_q))


def _loop_gain(w: float) -> float:
    """|T(jw)| of the aid's closed loop T(s) = (K_p s + K_i)/(s² + K_p s + K_i)."""
    return abs((KP * 1j * w + KI) / (-(w * w) + KP * 1j * w + KI))


def gyro_only_bias(trace: Path, w: float, delay: bool) -> float:
    """The gyro-only roll error over 0.5…2.5 s, less the quantisation's drift since the rate settled:
    Q(t) = Σ (r_j − ω)·P over the ticks from t_s = 0.125 s (the spin-up's end plus 25 ms = 11 decay
    times 1/(ζω_n) of the gyro's filter), r_j the firmware's compensated x rate of tick j."""
    over = [*BASE, *GYRO_ONLY, *([f"geomag.gyro_delay_s={TAU_G!r}"] if delay else [])]
    run = emulate(str(trace), PROFILE, overrides=over, until_s=3.0)
    assert not run.events, run.events[:3]
    period = load_profile(PROFILE).get("timer.period_us") * 1e-6
    t_read = run.read_tick.astype(np.float64) * period
    q = np.cumsum(np.where(t_read >= 0.125, (run.read_rate[:, 0] - w) * period, 0.0))
    q_at = q[np.searchsorted(t_read, run.time_s + period / 2) - 1]
    window = (run.time_s >= 0.5) & (run.time_s <= 2.5)
    return float((_roll_error(run) - q_at)[window].mean())


def aided_bias(trace: Path, overrides: tuple[str, ...] = ()) -> float:
    run = emulate(str(trace), PROFILE, overrides=[*BASE, *overrides])
    assert not run.events, run.events[:3]
    e = np.angle(np.exp(1j * (_roll(run.quat) - _roll(run.truth_q))))  # type: ignore[arg-type]
    return float(e[run.time_s >= AIDED_FROM_S].mean())


def test_roll_bias_from_the_delays_and_the_sample_instants(spin: tuple[float, Path]) -> None:
    """Measured against predicted (the module's docstring), with tolerances from the quantisation (the
    only noise of ideal sensors) and the aid's gains:

    Gyro only, mean over 0.5…2.5 s: Q covers the settled ticks exactly; before t_s each read is below
    its voltage by 0…1 LSB (the firmware reads code·LSB: 0.0477 °/s, 8.3e-4 rad/s, for the spin
    gyro's 1.6 mV/°/s at VREF 5 V), so the part left out is −(0…1)·LSB·t_s, plus the earth's rate
    along the axis over t_s: centre −LSB·t_s/2 + Ω·t_s, half-width LSB·t_s/2 = 5.2e-5 rad; the f32
    firmware's rounding of the increments and the quaternion, ≤ 4·2⁻²⁴ of the angle turned (ω·2.5 s).

    Aided, mean over 30…40 s (N = 3333 updates): the magnetometer's quantisation, LSB/√12 on y and
    z across H⊥ = 0.433 gauss, σ_γ = 5.1e-5 rad per update, averages to σ_γ/√N = 8.8e-7 rad (the loop's
    DC gain is 1; 5σ); the code·LSB reading offsets y and z by −LSB/2 each, a once-per-turn ripple
    |T(jω)|·(LSB/√2)/H⊥ whose mean over the window is ≤ 2/(ωW) of it; the y–z skew's ripple at 2ω,
    |T(2jω)|·ωΔ/2, likewise; the loop's transient from the spin-up (an angle ≤ ω(τ_g + P) and the
    quantised rate's step ≤ LSB) by 30 s, (1 + ω_n t)e^(−ω_n t) and t·e^(−ω_n t), ω_n = √K_i."""
    w_dps, trace = spin
    w = math.radians(w_dps)
    delta = sample_instants(trace)
    d0, dm, skew = delta[0], (delta[4] + delta[5]) / 2.0, delta[5] - delta[4]
    period = load_profile(PROFILE).get("timer.period_us") * 1e-6
    wc = 2.0 * math.pi * MAG_HZ
    h = FRONT_END_STEP_S
    tau_d = h * (1.0 / (1.0 - math.exp(-wc * h)) - 0.5) - 1.0 / wc
    lag = math.atan(w / wc)

    lsb_rate = math.radians(5.0 / 65536 / GYRO_V_PER_DPS)
    t_s = SPIN_UP_S + 0.025
    centre = -lsb_rate * t_s / 2.0 + EARTH_RATE * t_s
    tol_gyro = lsb_rate * t_s / 2.0 + 4.0 * 2.0**-24 * w * 2.5

    lsb_gauss = 5.0 / 65536 / MAG_V_PER_GAUSS
    h_perp = 0.5 * math.cos(math.radians(30.0))  # 0.5 gauss, 60° down; the axis north: sin 60° across
    n = round((DURATION_S - AIDED_FROM_S) / (3 * period))
    window = DURATION_S - AIDED_FROM_S
    wn = math.sqrt(KI)
    tol_aided = (
        5.0 * lsb_gauss / math.sqrt(12.0) / h_perp / math.sqrt(n)
        + 2.0 / (w * window) * _loop_gain(w) * lsb_gauss / math.sqrt(2.0) / h_perp
        + 2.0 / (2.0 * w * window) * _loop_gain(2.0 * w) * w * skew / 2.0
        + w * (TAU_G + period) * (1.0 + wn * AIDED_FROM_S) * math.exp(-wn * AIDED_FROM_S)
        + lsb_rate * AIDED_FROM_S * math.exp(-wn * AIDED_FROM_S)
    )

    steady = w * (dm - tau_d)
    no_mag_cutoff = ("geomag.mag_cutoff_hz=0",)
    gyro_delay = (f"geomag.gyro_delay_s={TAU_G!r}",)
    cases = [
        ("gyro only", gyro_only_bias(trace, w, False), w * (d0 + period / 2 - TAU_G) + centre, tol_gyro),
        ("gyro only, gyro_delay_s", gyro_only_bias(trace, w, True), w * (d0 + period / 2) + centre, tol_gyro),
        ("aided", aided_bias(trace), steady, tol_aided),
        ("aided, mag_cutoff_hz 0", aided_bias(trace, no_mag_cutoff), steady - lag, tol_aided),
        ("aided, gyro_delay_s", aided_bias(trace, gyro_delay), steady, tol_aided),
    ]
    print(
        f"\n{w_dps:g} °/s: δ_0 {d0 * 1e6:.3f} µs, δ_4 {delta[4] * 1e6:.3f} µs, δ_5 {delta[5] * 1e6:.3f} µs; "
        f"τ_g {TAU_G * 1e3:.4f} ms, atan(ω/ω_c) {lag:.4e} rad, τ_d {tau_d * 1e6:.3f} µs"
    )
    for name, got, want, tol in cases:
        print(f"  {name:26} measured {got:+.6e} rad, predicted {want:+.6e} ± {tol:.1e}")
    innovation = cases[0][1] - centre - cases[3][1]
    print(
        f"  gyro-only − aided (uncompensated) {innovation:+.6e} rad; "
        f"−ω(τ_g − τ_m) {-w * (TAU_G - 1 / wc):+.6e}, "
        f"+ ω(δ_0 + P/2 − δ_m) {w * (d0 + period / 2 - dm):+.6e}"
    )
    bad = [
        f"{name}: {got:.6e} vs {want:.6e} ± {tol:.1e}"
        for name, got, want, tol in cases
        if abs(got - want) > tol
    ]
    assert not bad, bad
