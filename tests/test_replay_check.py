"""`sins-fw replay RUN`: a saved run is re-emulated from its recorded trace and profile and must
match bit for bit (ArduPilot's replay-checker idea); a tampered file fails with the row and column."""

from __future__ import annotations

import h5py

from conftest import ROOT, run_cli

TRACE = str(ROOT / "traces" / "static_60s.h5")


def test_saved_run_replays_bit_for_bit_and_tampering_is_caught(tmp_path):
    out = tmp_path / "run.h5"
    assert run_cli("run", TRACE, "--set", "spi.spibrr=40", "--out", str(out)).code == 0
    r = run_cli("replay", str(out), "--save", str(tmp_path / "a.rrd"), "--json")
    assert r.code == 0, r.err
    assert (tmp_path / "a.rrd").stat().st_size > 0

    with h5py.File(out, "r+") as f:
        f["q1"][1234] = f["q1"][1234] + 1e-15
    r = run_cli("replay", str(out), "--save", str(tmp_path / "b.rrd"))
    assert r.code == 1
    assert "row 1234" in r.err and "`q1`" in r.err
    assert not (tmp_path / "b.rrd").exists()


def test_a_run_with_an_override_holding_spaces_replays(tmp_path):
    out = tmp_path / "run.csv"
    fault = 'faults.list=[{kind = "stuck_axis", channel = "gyro_z", start_s = 1.0, duration_s = 0.5}]'
    r = run_cli("run", TRACE, "--set", fault, "--until-s", "3", "--out", str(out))
    assert r.code == 0, r.err
    r = run_cli("replay", str(out), "--save", str(tmp_path / "a.rrd"))
    assert r.code == 0, r.err
