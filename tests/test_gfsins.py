"""The gyro-free vehicle board (issue 25 items 4–6): `synth vehicle`'s array, compass and GPS truth,
and the board model (acquisition node + C6727) over it through the binding."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sins_fw import _core, earth, gfsins, quaternion, synth
from sins_fw.errors import ConfigError, ProfileError, TraceError


@pytest.fixture(scope="module")
def turn() -> synth.PhysicalTrace:
    return synth.generate("vehicle", duration_s=4.0, turn_rate_dps=10.0, lever_arm_m=0.2)


def test_array_is_the_rigid_body_formula(turn: synth.PhysicalTrace) -> None:
    """f_p = f_c + ω̇×r_p + ω×(ω×r_p) against an independent ω̇: in a steady level turn ω_nb^b is
    constant, so ω̇_ib^b = −ω_nb^b × (C_n^b ω_in^n) + C_n^b ω̇_in^n, with ω̇_in^n from the motion's
    exact v̇^n: ω̇_en^n = [−v̇_N/R_N', v̇_E/R_E', v̇_E tan L/R_E'] and ω̇_ie^n = Ω L̇ [0, −sin L, cos L]
    (R' = R + h, L̇ = v_N/R_N'). Left out: v_E L̇ sec²L/R_E' ≈ 1.2e-11 rad/s², 2.5e-13 g at
    l = 0.2 m, under the 1e-12 g tolerance. The centripetal term (≈ 0.6 mg at 10 °/s) and
    ω̇×r (≈ 2.6e-7 g: the body turning against the earth rate) both show."""
    values = synth.resolve("vehicle", duration_s=4.0, turn_rate_dps=10.0, lever_arm_m=0.2)
    m = synth.SCENARIOS["vehicle"].motion(**{k: values[k] for k in values if k not in synth._AIDING_NAMES})
    lat0 = math.radians(values["latitude_deg"])
    r_n, r_e = (float(r) + values["height_m"] for r in earth.radii(lat0))
    lat, a = m.lat_rad, m.a_n
    lat_rate = m.v_n[:, 1] / r_n
    dw_en = np.stack([-a[:, 1] / r_n, a[:, 0] / r_e, a[:, 0] * np.tan(lat) / r_e], axis=1)
    dw_ie = earth.OMEGA_IE * lat_rate[:, None] * np.stack([0 * lat, -np.sin(lat), np.cos(lat)], axis=1)
    to_b = quaternion.conjugate(m.q_nb)
    w_in_b = quaternion.rotate(to_b, m.w_in_n)
    w = m.w_nb_b + w_in_b
    dw = -np.cross(m.w_nb_b, w_in_b) + quaternion.rotate(to_b, dw_en + dw_ie)
    assert turn.array_g is not None
    np.testing.assert_array_equal(turn.gyro_dps, np.degrees(w))
    centre = turn.array_g[:, 18:21]
    np.testing.assert_array_equal(centre, turn.accel_g)
    for p, u in enumerate(synth.ARRAY_POSITIONS[:6]):
        r = np.broadcast_to(0.2 * u, w.shape)
        expected = centre + (np.cross(dw, r) + np.cross(w, np.cross(w, r))) / earth.G0
        np.testing.assert_allclose(turn.array_g[:, 3 * p : 3 * p + 3], expected, rtol=0, atol=1e-12)
    # Part 3 at +l x̂ (forward): the centripetal −ω_z² l along x, with ω_z ≈ 10 °/s · cos(bank).
    d = turn.array_g[:, 6] - centre[:, 0]
    assert d.mean() == pytest.approx(-(w[:, 1] ** 2 + w[:, 2] ** 2).mean() * 0.2 / earth.G0, rel=1e-6)


def test_vehicle_defaults_are_the_thesis_scenario() -> None:
    values = synth.resolve("vehicle")
    assert values["speed_mps"] == pytest.approx(80 / 3.6) and values["heading_deg"] == 30.0
    assert (values["latitude_deg"], values["longitude_deg"], values["height_m"]) == (
        28.20021,
        112.92647,
        5.13145,
    )
    assert values["gps_rate_hz"] == 1.0 and values["mag_field"] == "custom"
    with pytest.raises(ConfigError, match="lever arm"):
        synth.generate("vehicle", duration_s=1.0, lever_arm_m=0.0)


def test_board_runs_on_the_vehicle_trace(turn: synth.PhysicalTrace) -> None:
    """The straight-line scenario through the board: the DSP sees heading 30° from the compass,
    the GPS fixes near the trace's, a tilt near level; the budget has both processors' three rate
    classes; with the shipped profile the only events are the navigation's spells of bridged rate
    steps (the array's noise makes the products' change cross the singular threshold now and then)."""
    trace = synth.generate("vehicle", duration_s=3.0)
    out = gfsins.run(trace, ticks=400)
    assert {e["kind"] for e in out["events"]} <= {"rate_singular"}
    flags = out["flags"][:, 0].astype(int)
    compass = out["compass_deg"][flags & 1 == 1]
    assert len(compass) > 0
    assert np.abs(compass[:, 0] - 30.0).max() < 5.0  # ±1° (1σ) Markov error of the preset, plus rounding
    fixes = out["gps"][flags & 2 == 2]
    assert len(fixes) == 3  # epochs 0 (at the first tick, 0.6 s), 1 and 2 (≈ 0.3 s after each second)
    lat = trace.gps[~np.isnan(trace.gps[:, 0]), 2]
    assert np.abs(fixes[:, 0] - lat[:3]).max() < 1e-3  # 5 m CEP ≈ 5e-5°
    assert np.abs(out["tilt_deg"]).max() < 10.0  # offsets of the adxl345 preset (≤ 3σ of 40/80 mg)
    for proc in ("node", "dsp"):
        classes = out["budget"][proc]
        assert all(classes[c]["ticks"] > 0 for c in ("200 Hz", "10 Hz", "1 Hz"))
        assert classes["1 Hz"]["peak_s"] >= classes["200 Hz"]["peak_s"]
        assert classes["1 Hz"]["peak_fraction"] < 0.2  # the DSP's filter stages: 12.5 % (nav_tests.rs)


def test_board_input_errors(turn: synth.PhysicalTrace) -> None:
    with pytest.raises(ProfileError, match=r"node\.adxl_sck_ratio"):
        from sins_fw import _core

        _core.gfsins_run(
            "[node]\nadxl_sck_ratio = 3\n",
            "bad.toml",
            [],
            turn.t_s,
            turn.array_g,
            gfsins.compass_truth(turn),
            gfsins.held_gps(turn),
            1,
        )
    with pytest.raises(TraceError, match="array columns"):
        gfsins.run(synth.generate("static", duration_s=1.0), ticks=1)


def test_navigation_columns_follow_the_vehicle() -> None:
    """With ideal parts on the straight line (chapter 5's 80 km/h, heading 30°), the C6727's
    navigation columns follow the vehicle within the fused filter's chapter 5 bounds (docs/gfnav.md,
    federated_tests.rs: position ≲ 10 m, velocity ≲ 0.1 m/s, level ≲ 0.5°, heading < 1.5°) after
    its first fusion; the recovered rate is the earth and transport rate (≤ 1e-4 rad/s), bridged on
    every axis (a constant rate: one reported spell); every column of _core.GFSINS_COLUMNS is in the
    run output."""
    trace = synth.generate("vehicle", duration_s=20.0)
    ideal = ("array.preset=ideal", "compass.errors=ideal", "gps.cep_m=0", "gps.velocity_sigma_m_s=0")
    prof = gfsins.load(gfsins.PROFILE, ideal)
    out = gfsins.run(trace, gfsins.ticks_in(trace, prof), prof)
    err = gfsins.nav_errors(trace, out)
    assert err["horizontal_m"]["max_abs"] < 10.0 and err["velocity_mps"]["max_abs"] < 0.1
    assert max(err["roll_deg"]["max_abs"], err["pitch_deg"]["max_abs"]) < 0.5
    assert err["heading_deg"]["max_abs"] < 1.5
    started = ~np.isnan(out["nav_rate"][:, 0])
    assert started.sum() > 3000
    assert np.abs(out["nav_rate"][started]).max() < 1e-4
    assert set(out["nav_bridged"][started, 0]) == {7.0}
    assert [e["kind"] for e in out["events"]] == ["rate_singular"]
    names = {n for c in _core.GFSINS_COLUMNS for n, _ in c["file"]}
    assert names <= {c.name for c in gfsins.RUN_COLUMNS}
