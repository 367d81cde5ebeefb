"""Issue 36, item 4: the user's C firmware on the geomag and the wing boards. Each example in
firmware_c/examples (`geomag`: the ADS8344's eight channels in 8-bit characters; `wing`: the
ADIS16362's burst) runs on its board's profile, unchanged, beside the Rust application of that profile
on the same trace: the same words on the bus (every frame's word out, word in and character length,
and the chip-select edges around them) and the same decoded values.

The trace holds its input constant (rates, specific force, field and temperature each a different
value on every axis, the geomag front end ideal: no noise): the two firmwares do not sample at the
same instants (their code takes different times between the timer's tick and each frame), and only an
input that does not change between those instants gives both the same words. Every channel then
carries a different code, so a word out of place, a channel read twice or a byte lost shows.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from sins_fw.firmware_build import build_firmware
from sins_fw.firmware_run import FirmwareResult, run_c_firmware
from sins_fw.harness import Run, emulate
from sins_fw.profile import load_profile
from sins_fw.traces import PhysicalTrace

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "firmware_c" / "examples"

pytestmark = pytest.mark.usefixtures("cabi_library")

#: f32's unit roundoff: each rounded operation errs by at most this fraction of its result.
U32 = 2.0**-24
#: The geomag front end's ADC reference (geomag.toml: `geomag.vref_v`), V.
VREF_V = 5.0
#: rad/s per volt of the gyro presets (spin1200 on x: 1.6 mV/°/s; adxrs300 on y, z: 5 mV/°/s).
GYRO_RAD_S_PER_V = np.radians(1.0 / np.array([0.0016, 0.005, 0.005]))
#: gauss per volt of the AMR magnetometer preset.
MAG_GAUSS_PER_V = 1.0


def _constant_trace(seconds: float) -> PhysicalTrace:
    """Every input constant, a different value on every axis, within the parts' ranges (the
    ADIS16362's ±300 °/s and ±1.7 g, the ADXRS300's ±300 °/s, the AMR's ±2 gauss)."""
    t = np.arange(0.0, seconds, 1e-3)
    n = len(t)
    return PhysicalTrace(
        t_s=t,
        gyro_dps=np.tile([37.0, -12.5, 101.0], (n, 1)),
        accel_g=np.tile([0.11, -0.27, 0.95], (n, 1)),
        mag_gauss=np.tile([0.21, -0.15, 0.33], (n, 1)),
        temp_c=np.full(n, 31.0),
        metadata={"sample_rate_hz": "1000"},
    )


def _run_c(
    example: str, profile: str, trace: PhysicalTrace, overrides: list[str], tmp_path: Path
) -> tuple[FirmwareResult, dict[str, np.ndarray], list[dict[str, Any]]]:
    folder = EXAMPLES / example
    fw = build_firmware([folder], tmp_path / f"{example}.so")
    parts: list[dict[str, Any]] = []
    run = run_c_firmware(
        fw,
        trace,
        load_profile(profile, overrides),
        globals_file=folder / "globals.toml",
        sink=parts.append,
        bus_log=True,
    )
    columns = parts[0]["firmware_globals"]
    rows = {k: np.concatenate([p["firmware_globals"][k] for p in parts]) for k in columns}
    return run, rows, [e for p in parts for e in p["events"]]


def _same_bus(c_bus: dict[str, np.ndarray], rust: Run, frames_per_tick: int, ticks: int, bits: int) -> None:
    """The C firmware's first `ticks` ticks of frames and CS edges carry what the Rust application's
    bus log of ticks 1…`ticks` carries: every frame's word out, word in, DIN the part sampled, DOUT
    it drove and character length, each frame with CS low; one CS fall and one rise per window."""
    r_bus = rust.bus
    assert r_bus is not None
    n = frames_per_tick * ticks
    assert len(r_bus["frame_master_tx"]) == n
    assert len(c_bus["frame_master_tx"]) >= n
    for key in ("master_tx", "master_rx", "din", "dout", "bits", "selected"):
        key = f"frame_{key}"
        np.testing.assert_array_equal(c_bus[key][:n], r_bus[key], err_msg=key)
    assert (r_bus["frame_bits"] == bits).all() and r_bus["frame_selected"].all()
    edges = len(r_bus["cs_low"])
    np.testing.assert_array_equal(c_bus["cs_low"][:edges], r_bus["cs_low"])
    # CS falls before its window's first frame and rises after its last, in both logs.
    for bus in (c_bus, r_bus):
        t, low = bus["cs_t_ps"][:edges], bus["cs_low"][:edges]
        falls, rises = t[low], t[~low]
        starts = bus["frame_start_ps"][:n].reshape(len(falls), -1)
        ends = bus["frame_end_ps"][:n].reshape(len(falls), -1)
        assert (falls < starts[:, 0]).all() and (rises > ends[:, -1]).all()


def test_geomag_example_reads_the_ads8344_as_the_geomag_application(tmp_path: Path) -> None:
    """firmware_c/examples/geomag on geomag.toml (its ADS8344 on SPI-A behind GPIO57, as the profile
    places it) against the `ads8344-geomag` application, 0.2 s (200 ticks of 1 ms, 32 frames each:
    four 8-bit characters per channel). The codes are equal; the decoded rates and field agree within
    what f32 arithmetic allows: each side rounds the channel's voltage twice (the code times the LSB,
    less the null: at most 2·2⁻²⁴·VREF), which the gain k (rad/s or gauss per volt) scales, and its
    ≤ 12 further operations each by 2⁻²⁴ of the result: |Δ| ≤ 2·2⁻²⁴·(2·VREF·k + 12·|x|), both sides."""
    overrides = ["geomag.ideal_sensors=true"]
    trace = _constant_trace(0.2)
    c_run, rows, events = _run_c("geomag", "geomag", trace, overrides, tmp_path)
    ticks = len(rows["conversions"])
    assert ticks >= 190, ticks
    assert not [e for e in events if e["severity"] != "info"], events[:3]
    rust = emulate(trace, "geomag", overrides=overrides, bus_window=(1, ticks))
    assert c_run.bus is not None
    _same_bus(c_run.bus, rust, 32, ticks, 8)
    # The control bytes: start bit, the channel's A2…A0 (Table I order), single-ended, PD = 11.
    control = rust.bus["frame_master_tx"][::4][:8] >> 8
    select = np.array([0, 4, 1, 5, 2, 6, 3, 7])
    np.testing.assert_array_equal(control, 0x80 | select << 4 | 0x04 | 0x03)

    r_ticks = rust.read_tick
    k = np.searchsorted(r_ticks, np.arange(1, ticks + 1))
    assert (r_ticks[k] == np.arange(1, ticks + 1)).all()
    codes = np.stack([rows[f"code{i}"] for i in range(8)], axis=1)
    np.testing.assert_array_equal(codes, rust.read_words[k, :8])
    # Eight different codes (the constant input): a channel read in another's place would show.
    assert len(np.unique(codes[-1])) == 8
    rate = np.stack([rows[f"rate_{a}"] for a in "xyz"], axis=1)
    field = np.stack([rows[f"field_{a}"] for a in "xyz"], axis=1)
    r_rate, r_field = rust.read_rate[k], rust.read_accel[k]
    tol_rate = 2 * U32 * (2 * VREF_V * GYRO_RAD_S_PER_V + 12 * np.abs(r_rate))
    tol_field = 2 * U32 * (2 * VREF_V * MAG_GAUSS_PER_V + 12 * np.abs(r_field))
    assert (np.abs(rate - r_rate) <= tol_rate).all(), np.abs(rate - r_rate).max(axis=0)
    assert (np.abs(field - r_field) <= tol_field).all(), np.abs(field - r_field).max(axis=0)
    # And they are the trace's input as the firmware compensates it: the ideal gyro has no bias
    # temperature term, the calibration table removes b_T·(31 − 25 °C) (0.02, 0.01, 0.01 °/s/°C) and
    # a bow k₂·ω|ω|/FS; within one code over the gain, plus b_T times the temperature's code (LSB
    # over 10 mV/°C) and the bow itself. The field within one code.
    lsb = VREF_V / 65536
    dps = np.array([37.0, -12.5, 101.0])
    b_t, full_scale = np.array([0.02, 0.01, 0.01]), np.array([1200.0, 300.0, 300.0])
    expected = np.radians(dps - b_t * (31.0 - 25.0))
    atol = lsb * GYRO_RAD_S_PER_V + np.radians(b_t * lsb / 0.01 + 0.001 * dps**2 / full_scale)
    assert (np.abs(rate[-1] - expected) <= atol).all(), (rate[-1], expected, atol)
    np.testing.assert_allclose(field[-1], [0.21, -0.15, 0.33], atol=lsb * MAG_GAUSS_PER_V, rtol=0)


def test_wing_example_reads_the_adis16362_as_the_wing_application(tmp_path: Path) -> None:
    """firmware_c/examples/wing on wing.toml (its ADIS16362 on SPI-A behind GPIO57) against the wing
    application, 0.3 s (75 ticks of 4 ms, a 12-frame burst each: the command 0x3E00 and the eleven
    outputs). The burst words are equal; the decoded rates (rad/s) and specific forces (m/s²) agree
    within f32's rounding: the Rust decode multiplies the code by the LSB then by π/180 (by g), the
    example by one folded constant, each side ≤ 3 roundings of 2⁻²⁴: |Δ| ≤ 6·2⁻²⁴·|x|."""
    trace = _constant_trace(0.3)
    c_run, rows, events = _run_c("wing", "wing", trace, [], tmp_path)
    ticks = len(rows["bursts"])
    assert ticks >= 70, ticks
    assert not [e for e in events if e["severity"] != "info"], events[:3]
    rust = emulate(trace, "wing", bus_window=(1, ticks))
    assert c_run.bus is not None
    _same_bus(c_run.bus, rust, 12, ticks, 16)
    assert (rust.bus["frame_master_tx"][::12] == 0x3E00).all()

    k = np.searchsorted(rust.read_tick, np.arange(1, ticks + 1))
    names = ["command", "supply_out", *(f"{a}gyro_out" for a in "xyz"), *(f"{a}accl_out" for a in "xyz")]
    names += [*(f"{a}temp_out" for a in "xyz"), "aux_adc"]
    words = np.stack([rows[n] for n in names], axis=1)
    np.testing.assert_array_equal(words, rust.read_words[k, :12])
    rate = np.stack([rows[f"rate_{a}"] for a in "xyz"], axis=1)
    accel = np.stack([rows[f"accel_{a}"] for a in "xyz"], axis=1)
    r_rate, r_accel = rust.read_rate[k], rust.read_accel[k]
    assert (np.abs(rate - r_rate) <= 6 * U32 * np.abs(r_rate)).all(), np.abs(rate - r_rate).max(axis=0)
    assert (np.abs(accel - r_accel) <= 6 * U32 * np.abs(r_accel)).all(), np.abs(accel - r_accel).max(axis=0)
    # The trace's input within one LSB (0.05 °/s, 0.333 mg).
    np.testing.assert_allclose(rate[-1], np.radians([37.0, -12.5, 101.0]), atol=np.radians(0.05), rtol=0)
    g = 9.80665
    np.testing.assert_allclose(accel[-1], np.array([0.11, -0.27, 0.95]) * g, atol=0.333e-3 * g, rtol=0)
