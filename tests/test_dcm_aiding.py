"""The DCM's aiding from a trace file (issue 18): the GPS stream and the magnetic field that
`sins-fw synth` writes, read back, validated and fed to the emulated firmware end to end."""

from __future__ import annotations

import math
import subprocess
from pathlib import Path

import numpy as np
import pytest

from sins_fw import _core, emulate, synth
from sins_fw.errors import ConfigError, TraceError
from sins_fw.traces import GPS_COLUMNS, PhysicalTrace

SINS_FW = Path(__file__).resolve().parents[1] / ".venv" / "bin" / "sins-fw"
V, W_DPS, GPS_HZ, LATENCY_S = 20.0, 10.0, 5.0, 0.1
#: The ADIS16407's accelerometer LSB (g): quantisation leaves each axis within half of it, so the
#: measured gravity direction, hence the tilt the DCM settles on, is within atan(√2·LSB/2) of the truth.
ACCEL_LSB_G = 3.333e-3
TILT_QUANTISATION_DEG = math.degrees(math.atan(math.sqrt(2) * ACCEL_LSB_G / 2))  # 0.135°


@pytest.fixture(scope="module")
def turn_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A level coordinated turn (20 m/s, 10 °/s) with the WMM field and a 5 Hz GPS, 100 ms late,
    long enough for the PI loop's slow mode (K_I/K_P: τ ≈ 16 s at the defaults) to settle."""
    path = tmp_path_factory.mktemp("aiding") / "turn.h5"
    trace = synth.generate(
        "turn", duration_s=240.0, mag_field="wmm", gps_rate_hz=GPS_HZ, gps_latency_s=LATENCY_S
    )
    trace.save(path)
    return path


def _settled(path: Path, *overrides: str) -> tuple[np.ndarray, np.ndarray]:
    """Inclination and heading errors (degrees, no alignment: the DCM's attitude is absolute) over
    the last quarter of the run."""
    run = emulate(path, overrides=["firmware.algorithm=dcm", "firmware.decode=correct", *overrides])
    e = run.errors("none")
    last = slice(3 * len(e.total) // 4, None)
    return e.inclination[last], e.heading[last]


def test_synth_turn_has_a_consistent_field_and_gps_stream(turn_file: Path) -> None:
    t = PhysicalTrace.load(turn_file)
    assert t.mag_gauss is not None and t.gps is not None
    m_n = np.array([float(x) for x in t.metadata["magnetic_field_enu_gauss"].split()])
    # The body field is the navigation field seen through the true attitude (|m| preserved).
    assert np.allclose(np.linalg.norm(t.mag_gauss, axis=1), np.linalg.norm(m_n), rtol=1e-12)
    fixes = ~np.isnan(t.gps[:, 0])
    assert fixes.sum() == 240 * GPS_HZ
    assert np.allclose(t.gps[fixes, 0], V)
    # Course = heading ψ(t) = ω t (right turn from north), mod 360.
    course = np.mod(W_DPS * t.t_s[fixes], 360.0)
    d = np.mod(t.gps[fixes, 1] - course + 180.0, 360.0) - 180.0
    assert np.abs(d).max() < 1e-9
    assert t.metadata["gps_latency_s"] == "0.1"


def test_dcm_with_gps_yaw_and_centripetal_compensation_converges(turn_file: Path) -> None:
    """Yaw from the GPS course: a fix reaches the firmware L = 0.1 s after its time and is held for
    1/f = 0.2 s, so the course in use lags the truth by ω(L + u), u uniform in [0, 1/f): the loop
    (time constant 1/K_P = 5 s ≫ 0.2 s) follows the mean, ω(L + 1/(2f)) = 2.0° behind. The sawtooth
    left over is 1° peak at 5 Hz through a first-order K_P/(K_P + j2πf): below 0.01°; the heading
    quantisation adds < 0.1°. Tilt: within the accelerometer quantisation (the integrator removes the
    constant earth and transport rates the firmware does not correct)."""
    incl, heading = _settled(turn_file, "firmware.dcm.yaw_reference=gps", "firmware.dcm.centripetal=true")
    lag = W_DPS * (LATENCY_S + 0.5 / GPS_HZ)
    assert np.abs(np.abs(heading) - lag).max() < 0.1, (heading.min(), heading.max(), lag)
    assert incl.max() < TILT_QUANTISATION_DEG, incl.max()


def test_dcm_without_centripetal_compensation_tilts_by_atan_v_omega_over_g(turn_file: Path) -> None:
    """In the turn the specific force is tilted from the vertical by atan(Vω/g) (19.593°); the PI loop
    settles the estimate's up on it, so the tilt error is that angle, to the quantisation (and the
    0.05 % between g0, which banks the synthetic turn, and the local gravity: 0.01°)."""
    incl, _ = _settled(turn_file, "firmware.dcm.yaw_reference=gps")
    expected = math.degrees(math.atan(V * math.radians(W_DPS) / 9.80665))
    assert abs(expected - 19.593) < 1e-3
    assert np.abs(incl - expected).max() < TILT_QUANTISATION_DEG + 0.01, (incl.min(), incl.max())


def test_dcm_with_magnetometer_yaw_converges(turn_file: Path) -> None:
    """Yaw from the magnetometer (declination from the trace's field): the horizontal field H = F cos I
    is resolved to the magnetometer's half LSB per axis, atan(√2·0.25 mG / H), and the tilt error
    enters the projected heading times tan I: bound atan(√2·2.5e-4/H) + tan I · 0.135°."""
    t = PhysicalTrace.load(turn_file, allow_gaps=False)
    m = np.array([float(x) for x in t.metadata["magnetic_field_enu_gauss"].split()])
    h = math.hypot(m[0], m[1])
    decl = math.degrees(math.atan2(m[0], m[1]))
    incl_field = math.atan2(-m[2], h)
    incl, heading = _settled(
        turn_file,
        "firmware.dcm.yaw_reference=magnetometer",
        "firmware.dcm.centripetal=true",
        f"firmware.dcm.declination_deg={decl!r}",
    )
    bound = math.degrees(math.atan(math.sqrt(2) * 2.5e-4 / h)) + math.tan(incl_field) * TILT_QUANTISATION_DEG
    assert np.abs(heading).max() < bound, (np.abs(heading).max(), bound)
    assert incl.max() < TILT_QUANTISATION_DEG


def test_gps_stream_round_trips_through_csv_and_hdf5(tmp_path: Path) -> None:
    trace = synth.generate("turn", duration_s=2.0, gps_rate_hz=1.0, mag_field="custom")
    for ext in ("csv", "h5"):
        trace.save(tmp_path / f"t.{ext}")
        back = PhysicalTrace.load(tmp_path / f"t.{ext}")
        assert back.gps is not None
        assert np.array_equal(back.gps, trace.gps, equal_nan=True)
        assert back.metadata["gps_latency_s"] == trace.metadata["gps_latency_s"]


def _csv_with(tmp_path: Path, edit: str, metadata_latency: bool = True) -> Path:
    trace = synth.generate("turn", duration_s=1.0, gps_rate_hz=1.0)
    path = tmp_path / "t.csv"
    trace.save(path)
    text = path.read_text()
    if not metadata_latency:
        text = text.replace("# gps_latency_s: 0.1\n", "")
    lines = text.splitlines(keepends=True)
    header = next(i for i, line in enumerate(lines) if line.startswith("t_s,"))
    names = lines[header].strip().split(",")
    if edit:
        column, value = edit.split("=")
        row = lines[header + 1].rstrip("\n").split(",")
        row[names.index(column)] = value
        lines[header + 1] = ",".join(row) + "\n"
    path.write_text("".join(lines))
    return path


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        ("gps_course_deg=360", "column `gps_course_deg`: found 360.0; expected 0 ≤ course < 360°"),
        ("gps_speed_mps=-1", "column `gps_speed_mps`: found -1.0; expected ≥ 0 m/s"),
        ("gps_lat_deg=nan", "column `gps_lat_deg`: NaN in only some GPS columns"),
        ("gps_lon_deg=inf", "column `gps_lon_deg`: found inf; expected a finite number"),
    ],
)
def test_bad_gps_rows_name_the_line_and_column(tmp_path: Path, edit: str, message: str) -> None:
    path = _csv_with(tmp_path, edit)
    with pytest.raises(TraceError) as e:
        PhysicalTrace.load(path)
    assert str(path) in str(e.value) and "(row 0)" in str(e.value) and message in str(e.value), e.value


def test_gps_columns_need_the_latency(tmp_path: Path) -> None:
    path = _csv_with(tmp_path, "", metadata_latency=False)
    with pytest.raises(TraceError, match="`gps_latency_s` is missing"):
        PhysicalTrace.load(path)
    assert set(GPS_COLUMNS) <= set(PhysicalTrace.load(_csv_with(tmp_path, "")).columns())


@pytest.mark.parametrize(
    ("args", "key"),
    [
        (["--gps-rate-hz", "60"], "gps_rate_hz"),
        (["--gps-latency-s", "-0.1"], "gps_latency_s"),
        (["--mag-field", "custom", "--mag-inclination-deg", "91"], "mag_inclination_deg"),
        (["--mag-field", "custom", "--mag-intensity-gauss", "0"], "mag_intensity_gauss"),
        (["--mag-declination-deg", "181"], "mag_declination_deg"),
        (["--longitude-deg", "200"], "longitude_deg"),
    ],
)
def test_synth_aiding_keys_out_of_range_exit_2(tmp_path: Path, args: list[str], key: str) -> None:
    out = tmp_path / "t.h5"
    r = subprocess.run(
        [str(SINS_FW), "synth", "static", "--duration-s", "1", *args, "--out", str(out)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert r.returncode == 2, r.stderr
    assert f"`{key}`" in r.stderr and "Traceback" not in r.stderr, r.stderr
    assert not out.exists()
    with pytest.raises(ConfigError, match=key):
        synth.resolve("static", **{key: float(args[-1])})


def test_aiding_keys_off_leave_the_generator_command_as_it_was() -> None:
    values = synth.resolve("static")
    assert "--gps" not in synth.command_line("static", values)
    assert "--mag" not in synth.command_line("static", values)


def test_dcm_correction_terms_are_output_columns_only_for_the_dcm() -> None:
    """ω_P, ω_I, the two errors and |R·Rᵀ − I| come out one row per step under the DCM (declared once
    in the core's output table), and as no rows under RK4 (its output is unchanged)."""
    names = {c["name"] for c in _core.OUTPUT_COLUMNS}
    terms = ("step", "omega_p", "omega_i", "error_rp", "error_yaw", "orthogonality")
    assert {f"dcm_{t}" for t in terms} <= names
    trace = synth.generate("static", duration_s=4.0, attitude_deg=(10.0, 0.0, 0.0))
    run = emulate(trace, overrides=["firmware.algorithm=dcm", "firmware.decode=correct"])
    assert set(run.dcm) == set(terms)
    assert np.array_equal(run.dcm["step"], run.step)
    assert run.dcm["omega_p"].shape == (len(run.step), 3)
    # Renormalisation keeps R orthonormal to ~(|dθ|²)² per step (dcm.rs); at rest far below 1e-5.
    assert run.dcm["orthogonality"].max() < 1e-5
    # The 10° roll starts as a roll–pitch error about body x: ω_P = K_P·e, K_P = 0.2, |e| = sin 10°.
    assert abs(run.dcm["omega_p"][0, 0]) == pytest.approx(0.2 * math.sin(math.radians(10.0)), rel=0.02)
    rk4 = emulate(trace)
    assert all(len(v) == 0 for v in rk4.dcm.values())


def test_a_trace_in_memory_keeps_its_gps_stream() -> None:
    """emulate() on a PhysicalTrace object slices it into pieces: the GPS columns go with them (they
    were dropped, and the GPS yaw reference then said the trace had no GPS stream)."""
    trace = synth.generate("turn", duration_s=3.0, gps_rate_hz=1.0)
    run = emulate(trace, overrides=["firmware.algorithm=dcm", "firmware.dcm.yaw_reference=gps"])
    assert len(run.dcm["error_yaw"]) == len(run.step) and np.abs(run.dcm["error_yaw"]).max() > 0
