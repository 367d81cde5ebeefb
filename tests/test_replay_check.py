"""`sins-fw replay RUN`: a saved run is re-emulated from its recorded trace and profile and must
match bit for bit (ArduPilot's replay-checker idea); a tampered file fails with the row and column."""

from __future__ import annotations

import h5py

from conftest import ROOT, run_cli

TRACE = str(ROOT / "traces" / "static_60s.h5")


def test_saved_run_replays_bit_for_bit_and_tampering_is_caught(tmp_path):
    out = tmp_path / "run.h5"
    assert run_cli("run", TRACE, "--set", "spi.spibrr=40", "--out", str(out)).code == 0
    r = run_cli("replay", str(out), "--out", str(tmp_path / "a.rrd"), "--json")
    assert r.code == 0, r.err
    assert (tmp_path / "a.rrd").stat().st_size > 0

    with h5py.File(out, "r+") as f:
        f["q1"][1234] = f["q1"][1234] + 1e-15
    r = run_cli("replay", str(out), "--out", str(tmp_path / "b.rrd"))
    assert r.code == 1
    assert "row 1234" in r.err and "`q1`" in r.err
    assert not (tmp_path / "b.rrd").exists()


def test_a_run_with_an_override_holding_spaces_replays(tmp_path):
    out = tmp_path / "run.csv"
    fault = 'faults.list=[{kind = "stuck_axis", channel = "gyro_z", start_s = 1.0, duration_s = 0.5}]'
    r = run_cli("run", TRACE, "--set", fault, "--until-s", "3", "--out", str(out))
    assert r.code == 0, r.err
    r = run_cli("replay", str(out), "--out", str(tmp_path / "a.rrd"))
    assert r.code == 0, r.err


def test_a_saved_run_replays_from_any_working_directory(tmp_path):
    """Issue 24, item 12: the run output recorded the trace path as typed (relative to the working
    directory of `run`), so `replay` from elsewhere could not find it. It records the path relative
    to the output, the absolute path and the content hash (docs/traces.md, "Run output")."""
    import shutil

    data, other, moved = tmp_path / "data", tmp_path / "other", tmp_path / "moved"
    for d in (data, other, moved):
        d.mkdir()
    shutil.copy(TRACE, data / "t.h5")
    r = run_cli("run", "t.h5", "--until-s", "4", "--out", "../out/run.h5", cwd=data)
    assert r.code == 0, r.err
    out = tmp_path / "out" / "run.h5"
    with h5py.File(out, "r") as f:
        assert f.attrs["trace"] == "../data/t.h5"
        assert f.attrs["trace_abs"] == str(data / "t.h5")
    r = run_cli("replay", "../out/run.h5", "--out", "a.rrd", cwd=other)
    assert r.code == 0, r.err
    # The output moved alone: found at the absolute path.
    shutil.move(out, moved / "run.h5")
    r = run_cli("replay", str(moved / "run.h5"), "--out", "b.rrd", cwd=other)
    assert r.code == 0, r.err
    # Another file where the trace was: refused, naming what was tried.
    shutil.copy(ROOT / "traces" / "coning_10hz.h5", data / "t.h5")
    r = run_cli("replay", str(moved / "run.h5"), "--out", "c.rrd", cwd=other)
    assert r.code == 2, r.err
    assert "SHA-256" in r.err and "t.h5" in r.err
    assert not (other / "c.rrd").exists()
