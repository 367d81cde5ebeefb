"""The second board profile, `firmware_model/wing.toml`: the reference's F28335 with an ADIS16362.

Every command that takes a profile accepts it. Its attitude loop is the reference's and the two parts
encode rates alike (14 bits, 0.05 °/s at ±300 °/s, the same sample clock and filter), so on the same
trace its attitude is the reference's exactly: any difference would come from the part's declaration.
"""

from __future__ import annotations

import json
from pathlib import Path

from conftest import ROOT

TRACE = str(ROOT / "traces" / "static_60s.h5")


def test_board_reports_the_adis16362_burst(cli) -> None:
    r = cli("board", "--profile", "wing", "--json")
    assert r.code == 0, r.err
    board = json.loads(r.out)
    assert board["spi_mode"] == 3 and board["mode_matches_device"]
    # The ADIS16362's burst is its command and 11 words (data sheet p. 11).
    assert abs(board["burst_clocking_s"] - 12 * board["frame_s"]) < 1e-12


def test_budget_accepts_the_wing_board(cli) -> None:
    r = cli("budget", "--profile", "wing", "--json")
    assert r.code == 0, r.err
    assert json.loads(r.out)


def test_run_on_the_wing_board_gives_the_reference_attitude(cli) -> None:
    wing = cli("run", TRACE, "--profile", "wing", "--json")
    reference = cli("run", TRACE, "--profile", "reference", "--json")
    assert wing.code == 0 and reference.code == 0, wing.err + reference.err
    w, ref = json.loads(wing.out), json.loads(reference.out)
    assert w["cycles"] == ref["cycles"]
    assert w["attitude_error"] == ref["attitude_error"]


def test_replay_accepts_the_wing_board(cli, tmp_path: Path) -> None:
    out = tmp_path / "wing.rrd"
    r = cli("replay", TRACE, "--profile", "wing", "--save", str(out), "--bus-ticks", "0:2")
    assert r.code == 0, r.err
    assert out.stat().st_size > 0
