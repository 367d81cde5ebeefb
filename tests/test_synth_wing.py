"""The `wing` scenario (algorithms.md §3): the hinge kinematics are consistent and α truth is exact.

The rates are checked against the truth attitude with the other scenarios (test_synth.py, CASES);
here: the specific force integrates to the velocity (moving base, lever arm), the attitude relative
to the zero is a rotation by α about the fixed axis (static base), and the columns and options.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

from conftest import run_cli
from reference_integrators import assert_simpson_velocity
from sins_fw import quaternion as quat
from sins_fw import synth
from sins_fw.traces import PhysicalTrace

FINE = 20


def _fine(params):
    values = synth.resolve("wing", rate_hz=str(Fraction("819.2") * FINE), **params)
    return synth.SCENARIOS["wing"].motion(**values), 1.0 / float(Fraction("819.2") * FINE)


@pytest.mark.parametrize(
    "params",
    [
        {"flap": "sweep", "duration_s": 6.0, "rest_s": 1.0, "base_amplitude_deg": 3.0, "base_period_s": 4.0},
        {"flap": "sine", "duration_s": 5.0, "rest_s": 0.5, "period_s": 1.5, "lever_m": (0.5, -0.2, 0.3)},
    ],
)
def test_specific_force_integrates_to_the_velocity(params):
    """v̇ = C_b^n f^b − 2ω_ie × v + g, by Simpson's rule from the truth v(0) (the base may move at t = 0);
    error bound by Richardson (Simpson: order 4) plus 8 ulp of the velocity per step."""
    m, h = _fine(params)
    f_n = quat.rotate(m.q_nb, m.specific_force())
    a = f_n - np.cross(2.0 * m.w_ie_n, m.v_n) + m.gravity_n
    truth = assert_simpson_velocity(a, m.v_n, h, m.v_n[0])
    assert np.abs(truth).max() > 0.1  # the lever arm really moves


@pytest.mark.parametrize("flap", synth.FLAP_PROFILES)
@pytest.mark.parametrize("elevation", [0.0, 45.0, 80.0])
def test_the_attitude_from_the_zero_is_a_rotation_by_alpha_about_the_axis(flap, elevation):
    """Static base: q_nb(0)* ⊗ q_nb(t) = cos(α/2) + a^r sin(α/2), a^r = C_n^b(0) a^n (to rounding:
    a few products of unit quaternions, 1e-14)."""
    tr = synth.generate(
        "wing", flap=flap, axis_elevation_deg=elevation, duration_s=12.0, rest_s=1.0, angles_deg=(0, 40, -25)
    )
    beta, gamma = math.radians(elevation), math.radians(30.0)
    a_n = np.array([math.cos(beta) * math.sin(gamma), math.cos(beta) * math.cos(gamma), math.sin(beta)])
    q0 = tr.truth_q[0]
    a_r = quat.rotate(quat.conjugate(q0), a_n)
    alpha = np.radians(tr.truth_alpha_deg)
    expected = quat.from_axis_angle(a_r, alpha)
    rel = quat.multiply(quat.conjugate(q0), tr.truth_q)
    assert np.abs(rel - expected).max() < 1e-14
    assert tr.truth_alpha_deg[0] == 0.0 and np.abs(tr.truth_alpha_deg).max() > 20.0
    assert not tr.moving[0] and tr.moving.any()


def test_profiles_temperature_and_truth_column(tmp_path):
    steps = synth.generate("wing", angles_deg=(0.0, 20.0, -10.0), rest_s=2.0, temp_rate_c_per_min=3.0)
    # Each step dwells exactly at its angle (the table stops are pinned).
    for angle in (20.0, -10.0):
        assert np.isclose(steps.truth_alpha_deg, angle, rtol=0, atol=1e-12).sum() > 2.0 * 819.2 - 2
    assert steps.temp_c[0] == 25.0
    assert steps.temp_c[-1] == pytest.approx(25.0 + 3.0 * steps.t_s[-1] / 60.0, abs=1e-12)
    sweep = synth.generate("wing", flap="sweep", amplitude_deg=25.0, duration_s=30.0, rest_s=2.0)
    crossings = np.count_nonzero(np.diff(np.sign(sweep.truth_alpha_deg[sweep.t_s > 2.5])) != 0)
    assert crossings >= 4 and np.abs(sweep.truth_alpha_deg).max() == pytest.approx(25.0, abs=1e-9)
    path = tmp_path / "wing.csv"
    r = run_cli("synth", "wing", "--flap", "sine", "--duration-s", "4", "--rest-s", "1", "--out", str(path))
    assert r.code == 0, r.err
    back = PhysicalTrace.load(path)
    direct = synth.generate("wing", flap="sine", duration_s=4.0, rest_s=1.0)
    assert np.array_equal(back.truth_alpha_deg, direct.truth_alpha_deg)
    assert np.array_equal(back.temp_c, direct.temp_c)


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["--flap", "zigzag"], "expected one of steps, sine, sweep"),
        (["--axis-elevation-deg", "90"], "0 ≤ β < 90"),
        (["--lever-m", "1,2"], "expected three"),
    ],
)
def test_bad_options_exit_2(tmp_path, args, fragment):
    r = run_cli("synth", "wing", *args, "--out", str(tmp_path / "x.csv"))
    assert r.code == 2 and fragment in r.err and "Traceback" not in r.err, r.err
    assert list(tmp_path.iterdir()) == []
