"""Synthetic scenarios: the truth attitude is recovered by integrating the trace's own rates, and the
specific force matches gravity (and, in flight, the velocity).

Tolerances: the reference integrator is RK4 (fourth order) at step h = 1/(10·fs). Its error is
estimated by Richardson extrapolation from the same run at 2h, e_h ≈ (q_h − q_2h)/15; the test
allows twice that estimate (the asymptotic estimate's usual safety factor) plus rounding: 8 ulp per
step (a handful of roundings per quaternion product, accumulated linearly over the steps).
"""

from __future__ import annotations

import math
import shlex
from fractions import Fraction

import numpy as np
import pytest

from conftest import run_cli
from reference_integrators import EPS, assert_simpson_velocity, integrate_attitude, quat_distance
from sins_fw import earth, synth
from sins_fw import quaternion as quat
from sins_fw.traces import PhysicalTrace

FINE = 20  # fine samples per coarse sample: RK4 step = 2 fine samples = coarse period / 10

CASES = [
    ("static", "819.2", {"duration_s": 5.0, "attitude_deg": (10.0, -20.0, 135.0)}),
    ("indexing-table", "819.2", {"axis": "y", "angles_deg": (0.0, 30.0, -30.0, 0.0), "dwell_s": 1.0}),
    ("indexing-table", "819.2", {"preset": "yaw25.8", "dwell_s": 2.0}),
    ("turntable", "819.2", {"axis": "x", "rates_dps": (100.0, 300.0), "hold_s": 1.0, "lead_s": 1.0}),
    ("coning", "819.2", {"duration_s": 5.0, "half_angle_deg": 1.0, "frequency_hz": 10.0}),
    (
        "coning",
        "819.2",
        {"duration_s": 3.0, "half_angle_deg": 20.0, "frequency_hz": 2.0, "attitude_deg": (5, 5, 5)},
    ),
    ("flight", "102.4", {}),
    ("wing", "819.2", {"angles_deg": (0.0, 30.0, -20.0), "rest_s": 1.0, "mount_deg": (20.0, 80.0, -30.0)}),
    ("wing", "819.2", {"flap": "sine", "duration_s": 6.0, "period_s": 2.0, "rest_s": 1.0}),
    (
        "wing",
        "819.2",
        {"flap": "sweep", "duration_s": 8.0, "rest_s": 1.0, "base_amplitude_deg": 2.0, "base_period_s": 5.0},
    ),
    ("spin", "819.2", {"duration_s": 4.0, "spin_up_s": 1.0, "sway_hz": 1.0, "attitude_deg": (0, 10, 30)}),
    (
        "spin",
        "819.2",
        {
            "trajectory": "ballistic",
            "duration_s": 4.0,
            "spin_up_s": 1.0,
            "sway_hz": 1.0,
            "elevation_deg": 80.0,
        },
    ),
]


def _motions(name, rate, params):
    params = dict(params)
    preset = params.pop("preset", None)
    coarse = synth.SCENARIOS[name].motion(**synth.resolve(name, preset, rate_hz=rate, **params))
    fine_rate = str(Fraction(rate) * FINE)
    fine = synth.SCENARIOS[name].motion(**synth.resolve(name, preset, rate_hz=fine_rate, **params))
    return coarse, fine, 2.0 / float(Fraction(fine_rate))


@pytest.mark.parametrize(("name", "rate", "params"), CASES, ids=[f"{c[0]}-{i}" for i, c in enumerate(CASES)])
def test_rates_integrate_to_the_truth_quaternion(name, rate, params):
    coarse, fine, h = _motions(name, rate, params)
    w_ib, w_in = fine.gyro_rad_s(), fine.w_in_n
    n = min(len(w_ib) - 1, (len(coarse.t_s) - 1) * FINE) // 4 * 4
    q_h = integrate_attitude(fine.q_nb[0], w_ib[: n + 1], w_in[: n + 1], h)
    q_2h = integrate_attitude(fine.q_nb[0], w_ib[: n + 1 : 2], w_in[: n + 1 : 2], 2 * h)
    at = np.arange(0, n + 1, FINE)  # fine sample index of each coarse sample
    assert np.array_equal(fine.t_s[at], coarse.t_s[at // FINE])  # the grids share these instants exactly
    error = quat_distance(q_h[at // 2], coarse.q_nb[at // FINE])
    richardson = quat_distance(q_h[at // 2], q_2h[at // 4]) / 15.0
    tolerance = 2.0 * richardson + 8.0 * EPS * (at // 2 + 1)
    worst = int(np.argmax(error / tolerance))
    assert (error <= tolerance).all(), (
        f"t = {coarse.t_s[at[worst] // FINE]} s: {error[worst]:.3g} > {tolerance[worst]:.3g}"
    )


def test_normal_gravity_matches_published_wgs84_values():
    # NIMA TR8350.2 table 3.4: γ_e = 9.7803253359, γ_p = 9.8321849378 m/s². The pole value checks the
    # Somigliana constant k and e² (which the code holds separately) against the published γ_p.
    assert earth.normal_gravity(0.0) == pytest.approx(9.7803253359, abs=1e-10)
    assert earth.normal_gravity(math.pi / 2) == pytest.approx(9.8321849378, abs=1e-10)
    # Free-air gradient near the surface ≈ −3.086e-6 s⁻² (textbook value, 45°).
    gradient = (
        earth.normal_gravity(math.radians(45.0), 100.0) - earth.normal_gravity(math.radians(45.0))
    ) / 100.0
    assert gradient == pytest.approx(-3.086e-6, rel=2e-3)


@pytest.mark.parametrize("attitude", [(0.0, 0.0, 0.0), (30.0, -45.0, 200.0), (0.0, 90.0, 0.0)])
def test_static_specific_force_is_gravity_up_in_the_body(attitude):
    trace = synth.generate("static", duration_s=1.0, attitude_deg=attitude, latitude_deg=45.0, height_m=0.0)
    g = earth.normal_gravity(math.radians(45.0))
    f_n = quat.rotate(trace.truth_q, trace.accel_g * earth.G0)  # back to the navigation frame: up, |g|
    np.testing.assert_allclose(f_n, np.broadcast_to([0.0, 0.0, g], f_n.shape), rtol=0, atol=8 * EPS * g)
    w_n = quat.rotate(trace.truth_q, np.radians(trace.gyro_dps))  # at rest: earth rate only, north and up
    w_ie = earth.OMEGA_IE * math.sqrt(0.5)
    np.testing.assert_allclose(
        w_n, np.broadcast_to([0.0, w_ie, w_ie], w_n.shape), rtol=0, atol=8 * EPS * w_ie
    )
    assert not trace.moving.any()


def test_indexing_table_dwells_are_static_and_exact():
    m = synth.indexing_table_motion(axis="y", angles_deg=(0.0, 10.0, -30.0), dwell_s=2.0)
    still = ~m.moving()
    assert still.sum() > 0.5 * len(m.t_s)
    f = m.specific_force()[still]
    g = earth.normal_gravity(math.radians(synth.DEFAULT_LATITUDE_DEG), synth.DEFAULT_HEIGHT_M)
    np.testing.assert_allclose(np.linalg.norm(f, axis=1), g, rtol=4 * EPS)
    _, pitch, _ = quat.to_euler(m.q_nb[still])
    stops = np.unique(np.round(np.degrees(pitch), 9))
    np.testing.assert_array_equal(stops, [-30.0, 0.0, 10.0])
    # Rate and acceleration limits hold (peak of the septic ramp = the limit when the move is long enough).
    rate = np.degrees(np.abs(m.w_nb_b[:, 1]))
    assert rate.max() <= 20.0 + 1e-12
    assert rate.max() == pytest.approx(20.0, rel=1e-6)


def test_flight_specific_force_integrates_to_the_velocity():
    """v̇^n = C_b^n f^b − (2ω_ie^n + ω_en^n) × v^n + g^n, integrated by Simpson's rule over the fine grid
    (the small Coriolis term uses the truth velocity); error bound by Richardson (Simpson: order 4)."""
    _, fine, h = _motions("flight", "102.4", {})
    f_n = quat.rotate(fine.q_nb, fine.specific_force())
    a = f_n - np.cross(2.0 * fine.w_ie_n + fine.w_en_n, fine.v_n) + fine.gravity_n
    truth = assert_simpson_velocity(a, fine.v_n, h / 2)  # the fine grid: samples h/2 apart
    assert np.abs(truth).max() > 35.0  # the profile really flies


def test_flight_is_coordinated_to_first_order_and_reaches_its_profile():
    m = synth.flight_motion()
    f = m.specific_force()
    lateral = np.abs(f[:, 1]).max() / earth.G0
    assert lateral < 1e-3, lateral  # residual from Coriolis, climb and γ ≠ g0 (bank uses g0)
    heading = (90.0 - np.degrees(quat.to_euler(m.q_nb)[2])) % 360.0
    assert heading[0] == pytest.approx(60.0, abs=1e-9)
    assert heading[-1] == pytest.approx((60.0 + 90.0 - 180.0) % 360.0, abs=1e-6)
    assert m.height_m.max() - synth.DEFAULT_HEIGHT_M > 150.0
    assert not m.moving()[: int(10 * 819.2) - 1].any() and m.moving()[-1]


def test_coning_phase_repeats_exactly_at_commensurate_rates():
    m = synth.coning_motion(duration_s=1.0, frequency_hz=10.0, rate_hz="819.2")
    # 10 Hz at 819.2 Hz: 25 cycles every 2048 samples; the reduced phase gives bit-equal samples.
    longer = synth.coning_motion(duration_s=5.0, frequency_hz=10.0, rate_hz="819.2")
    np.testing.assert_array_equal(longer.w_nb_b[2048:2148], m.w_nb_b[:100])
    np.testing.assert_array_equal(longer.q_nb[2048:2148], m.q_nb[:100])


def test_sample_times_are_exact_multiples_of_the_period():
    t = synth.sample_times(10.0, "819.2")
    assert len(t) == 8192
    assert t[4096] == 5.0 and t[1] == 5 / 4096
    np.testing.assert_array_equal(np.diff(t), 5 / 4096)


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["indexing-table", "--rate-hz", "abc"], "`sample_rate_hz` is `abc`"),
        (["turntable", "--axis", "q"], "expected x, y or z"),
        (["static", "--attitude-deg", "1,2"], "expected three comma-separated numbers"),
        (["static", "--duration-s", "nan"], "expected a finite number"),
        (["coning", "--duration-s", "0.001"], "gives 0 samples"),
        (["indexing-table", "--max-rate-dps", "-1"], "must be positive"),
    ],
)
def test_cli_parameter_errors_exit_2_without_traceback(tmp_path, args, fragment):
    r = run_cli("synth", *args, "--out", str(tmp_path / "x.h5"))
    assert r.code == 2 and fragment in r.err and "Traceback" not in r.err, r.err
    assert list(tmp_path.iterdir()) == []


def test_cli_writes_what_the_api_generates(tmp_path):
    out = str(tmp_path / "a.h5")
    r = run_cli("synth", "indexing-table", "--preset", "pm30", "--dwell-s", "1", "--out", out)
    assert r.code == 0, r.err
    synth.generate("indexing-table", "pm30", dwell_s=1.0).save(tmp_path / "b.h5")
    assert (tmp_path / "a.h5").read_bytes() == (tmp_path / "b.h5").read_bytes()
    generator = PhysicalTrace.load(tmp_path / "a.h5").metadata["generator"]
    assert generator.startswith("sins-fw synth indexing-table --axis y --angles-deg 0,30,0,-30,0 ")
    # The recorded command regenerates the same file.
    again = run_cli(*shlex.split(generator)[1:], "--out", str(tmp_path / "c.h5"))
    assert again.code == 0 and (tmp_path / "c.h5").read_bytes() == (tmp_path / "a.h5").read_bytes()


def test_spin_body_x_holds_the_swinging_axis_and_the_roll_is_the_spin_angle():
    """The spin scenario's body x axis points where yaw ψ(t) and pitch θ(t) put it (the spin leaves it
    alone), and after the spin-up the spin rate is the held rate: exact up to f64 round-off."""
    m = synth.spin_motion(spin_dps=720.0, spin_up_s=1.0, duration_s=3.0, sway_hz=0.5, rate_hz="100")
    x_n = quat.rotate(m.q_nb, np.array([1.0, 0.0, 0.0]))
    phase = 2 * np.pi * np.mod(0.5 * m.t_s, 1.0)
    psi, theta = np.radians(5.0) * np.sin(phase), np.radians(5.0) * np.sin(phase)
    expected = np.stack([np.cos(psi) * np.cos(theta), np.sin(psi) * np.cos(theta), -np.sin(theta)], axis=1)
    assert np.abs(x_n - expected).max() < 1e-12
    held = m.t_s >= 1.0
    # ω_x = φ̇ + the swing's component along the spun x axis: the yaw rate's share, −sin θ·ψ̇.
    w_swing_x = -np.sin(theta) * np.radians(5.0) * np.pi * np.cos(phase)
    assert np.abs(m.w_nb_b[held, 0] - np.radians(720.0) - w_swing_x[held]).max() < 1e-12
    with pytest.raises(synth.ConfigError, match="0…1000"):
        synth.spin_motion(spin_dps=1200.0)


def test_spin_ballistic_arc_follows_the_velocity_and_falls_freely():
    """The ballistic arc without nodding: body x along v^n = [V cos γ₀ sin β, V cos γ₀ cos β,
    V sin γ₀ − g t] at every sample (f64 round-off of a few rotations: 1e-12), the flight-path angle
    falling from +γ₀ through 0 at the apex (t = V sin γ₀/g); in free fall the accelerometers read only
    gravity's change with height and the Coriolis and transport terms: f^n = [0, 0, g(h) − g(h₀)] +
    (2ω_ie + ω_en) × v (1e-12 m/s²). A flight longer than the landing time is refused."""
    v, gam, beta, lat, h0 = 300.0, math.radians(30.0), math.radians(40.0), 40.8, 1050.0
    m = synth.spin_motion(
        trajectory="ballistic",
        spin_dps=500.0,
        duration_s=25.0,
        pitch_amplitude_deg=0.0,
        yaw_amplitude_deg=0.0,
        launch_speed_mps=v,
        elevation_deg=30.0,
        azimuth_deg=40.0,
        rate_hz="100",
    )
    g = float(earth.normal_gravity(math.radians(lat), h0))
    v_n = np.stack(
        [
            np.full_like(m.t_s, v * math.cos(gam) * math.sin(beta)),
            np.full_like(m.t_s, v * math.cos(gam) * math.cos(beta)),
            v * math.sin(gam) - g * m.t_s,
        ],
        axis=1,
    )
    x_n = quat.rotate(m.q_nb, np.array([1.0, 0.0, 0.0]))
    np.testing.assert_allclose(x_n, v_n / np.linalg.norm(v_n, axis=1)[:, None], rtol=0, atol=1e-12)
    np.testing.assert_allclose(m.v_n, v_n, rtol=0, atol=1e-12 * v)
    f_n = quat.rotate(m.q_nb, m.specific_force())
    expected = np.cross(2.0 * m.w_ie_n + m.w_en_n, m.v_n)
    expected[:, 2] += earth.normal_gravity(m.lat_rad, m.height_m) - g
    np.testing.assert_allclose(f_n, expected, rtol=0, atol=1e-12)
    apex = v * math.sin(gam) / g
    assert m.height_m.max() == pytest.approx(h0 + v * math.sin(gam) * apex / 2.0, abs=0.01)
    with pytest.raises(synth.ConfigError, match=r"lands after 30\.6"):
        synth.spin_motion(trajectory="ballistic", launch_speed_mps=v, elevation_deg=30.0, duration_s=31.0)
    with pytest.raises(synth.ConfigError, match="--trajectory"):
        synth.spin_motion(trajectory="rocket")
