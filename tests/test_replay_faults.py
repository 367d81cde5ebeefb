"""Raw-register traces replayed through the firmware (the recorded words, no device model) and
device-side faults injected from the profile, through the API and the CLI."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from conftest import ROOT, run_cli
from sins_fw.errors import ConfigError
from sins_fw.harness import Run, emulate
from sins_fw.traces import RawRegisterTrace, is_raw_register_trace

PITCH = ROOT / "traces" / "pitch_sweep.h5"
RAW = ROOT / "traces" / "pitch_sweep_10s_raw.csv"


def _same_outputs(a: Run, b: Run) -> None:
    """Everything the firmware computed, bit for bit, and the same ISRs at the same times."""
    for name in ("time_s", "quat", "euler_deg", "velocity_enu", "position", "read_words", "read_rate"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert all(np.array_equal(a.budget[k], b.budget[k]) for k in a.budget)


@pytest.mark.parametrize("numeric", ["f64", "c28x-f32"])
@pytest.mark.parametrize("suffix", [".csv", ".h5"])
def test_a_recorded_run_replays_bit_for_bit(tmp_path: Path, numeric: str, suffix: str) -> None:
    # Noisy words (the ADIS16407 error model) of the sweep's first 8 s: rest, then the first step.
    settings = {"firmware__numeric": numeric, "errors__preset": "adis16407"}
    original = emulate(PITCH, until_s=8.0, **settings)
    path = tmp_path / f"raw{suffix}"
    original.raw_register_trace({"source": "test"}).save(path)
    assert is_raw_register_trace(path)
    replayed = emulate(path, **settings)
    _same_outputs(replayed, original)
    # The replay's reads carry the recorded burst: its row and its timestamp (the CS falling edge).
    assert np.array_equal(replayed.read_sample_index, np.arange(len(original.read_words)))
    assert np.array_equal(replayed.read_sample_ps, original.read_t_cs_ps)
    assert replayed.t0_s == 0.0 and replayed.truth_q is None
    assert not any(e["kind"].startswith("replay_") for e in replayed.events)


def test_the_bundled_raw_trace_is_the_reference_run_of_the_sweep() -> None:
    raw = RawRegisterTrace.load(RAW)
    original = emulate(PITCH, until_s=10.0)
    assert np.array_equal(raw.words, original.read_words)
    _same_outputs(emulate(RAW), original)


def test_cli_runs_a_raw_trace_and_writes_one(tmp_path: Path) -> None:
    r = run_cli("run", str(RAW), "--json")
    assert r.code == 0, r.err
    report = json.loads(r.out)
    assert report["replayed"] and report["cycles"] == 1249 and report["attitude_error"] is None
    out = tmp_path / "again.csv"
    r = run_cli("run", str(RAW), "--raw-out", str(out))
    assert r.code == 0, r.err
    assert "replayed" in r.out and "2500 bursts" in r.out
    # Replaying gives the same words back: the re-recorded trace holds the same words and times.
    again, first = RawRegisterTrace.load(out), RawRegisterTrace.load(RAW)
    assert np.array_equal(again.words, first.words) and np.array_equal(again.t_s, first.t_s)


def test_cli_rejects_a_malformed_raw_trace(tmp_path: Path) -> None:
    good = RAW.read_text().splitlines()
    header = next(i for i, line in enumerate(good) if line.startswith("t_s,"))
    bad_word = tmp_path / "bad_word.csv"
    fields = good[header + 3].split(",")
    fields[4] = "0xZZZZ"
    bad_word.write_text("\n".join([*good[: header + 3], ",".join(fields), *good[header + 4 :]]) + "\n")
    r = run_cli("run", str(bad_word))
    assert r.code == 2, r.err
    assert "line" in r.err and "column `ygyro_out`" in r.err and "16-bit hexadecimal" in r.err
    assert "Traceback" not in r.err
    # Without its format line the words still mark it raw; a missing column is named.
    no_column = tmp_path / "no_column.csv"
    lines = [line for line in good if not line.startswith("# format")]
    lines = [",".join(line.split(",")[:-1]) if not line.startswith("#") else line for line in lines]
    no_column.write_text("\n".join(lines) + "\n")
    assert is_raw_register_trace(no_column)
    r = run_cli("run", str(no_column))
    assert r.code == 2 and "missing column `aux_adc`" in r.err, r.err


def test_a_replay_refuses_faults() -> None:
    with pytest.raises(ConfigError, match=r"faults\.list.*bypasses the device model"):
        emulate(RAW, overrides=['faults.list=[{kind="sensor_reset", start_s=1.0}]'])


def _faulted(*sets: str) -> dict[str, Any]:
    args = ["run", str(ROOT / "traces" / "static_60s.h5"), "--until-s", "3", "--json"]
    for s in sets:
        args += ["--set", s]
    r = run_cli(*args)
    by_kind = json.loads(r.out)["events"]["by_kind"]
    # Exit 1 exactly when an event of severity error was logged (the summary is printed either way).
    assert r.code == (1 if any(k["severity"] == "error" for k in by_kind.values()) else 0), r.err
    return by_kind


def test_cli_stuck_axis_from_set() -> None:
    events = _faulted('faults.list=[{kind="stuck_axis", channel="gyro_x", start_s=2.0, duration_s=1.0}]')
    injected = events["fault_injected"]
    assert injected["count"] == 1 and injected["first_t_s"] == 2.0
    assert injected["first_message"].startswith("stuck_axis at 2 s for 1 s, channel gyro_x")


def test_cli_sensor_reset_and_supply_fault_from_set() -> None:
    faults = (
        '[{kind="sensor_reset", start_s=1.0}, '
        '{kind="supply_out_of_range", start_s=2.0, duration_s=0.5, volts=5.5}]'
    )
    events = _faulted(f"faults.list={faults}")
    assert events["fault_injected"]["count"] == 2
    assert events["software_reset"]["first_t_s"] == 1.0
    # 130 ms of reset: the bursts of ticks 250…282 read corrupt words, every frame flagged.
    assert events["device_busy"]["count"] == 33 * 15
    supply = events["supply_out_of_range"]
    assert supply["count"] == 1 and "5.500 V above the 5.25 V limit" in supply["first_message"]


def test_cli_names_the_bad_fault_key() -> None:
    r = run_cli("run", str(RAW), "--set", 'faults.list=[{kind="spike", channel="gyro_x", start_s=1.0}]')
    assert r.code == 2 and "faults.list[0].magnitude" in r.err, r.err
