"""`sins-fw board`, `budget`, `run` and `replay` on the gyro-free board's profile (gfsins.toml, its own
schema, dispatched on `meta.board`): what each shows, the files `run` writes, the Rerun bus lanes of
every link, exit codes, and errors that name the file and key."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from conftest import run_cli
from sins_fw import gfsins, synth
from sins_fw.tablefile import open_table, read_metadata

PROFILE = str(gfsins.PROFILE)


@pytest.fixture(scope="module")
def vehicle(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """3 s of the chapter 5 drive (synth vehicle), as `sins-fw synth vehicle` writes it: samples at
    0 … 2.999 s, so the node's ticks at 0.6 + 0.005 k s are 480."""
    path = tmp_path_factory.mktemp("gfsins") / "vehicle.h5"
    r = run_cli("synth", "vehicle", "--duration-s", "3", "--out", str(path))
    assert r.code == 0, r.err
    return path


def test_board_shows_both_processors_links_parts_and_rules() -> None:
    r = run_cli("board", "--profile", PROFILE, "--json")
    assert r.code == 0, r.err
    s = json.loads(r.out)
    assert [p["name"] for p in s["processors"]] == ["node", "dsp"]
    links = {x["name"]: x for x in s["links"]}
    assert list(links) == ["spi1", "spi2", "spi3", "spi4", "spi5", "spi6", "spi7", "iic1", "uart", "spi8"]
    for i in range(1, 8):  # 75 MHz / 54
        assert links[f"spi{i}"]["rate_hz"] == pytest.approx(75e6 / 54, rel=1e-6)
    assert links["iic1"]["rate_hz"] == pytest.approx(100e3)
    assert links["uart"]["rate_hz"] == 19200 and "8N1" in links["uart"]["what"]
    # 8 PLB cycles of 13⅓ ns: the model's SCK period is whole picoseconds (106 666 ps).
    assert links["spi8"]["rate_hz"] == pytest.approx(1e12 / 106_666, rel=1e-12)
    assert {p["part"] for p in s["parts"]} == {"ADXL345 ×7", "HMC6343", "GR-87 GPS"}
    assert len(s["rules"]) >= 5 and all(x["ok"] for x in s["rules"])
    assert {e["kind"] for e in s["emulated"]["events"]} <= {"rate_singular"}
    text = run_cli("board", "--profile", PROFILE).out
    assert "1388.889 kHz" in text and "19200 baud" in text and "TMS320C6727B" in text
    assert "rules checked" in text and "none broken" in text


def test_board_exit_1_on_a_broken_rule() -> None:
    """SPI #1–#7 at 75 MHz / 8 = 9.4 MHz: above the ADXL345's 5 MHz, in the settings and at the parts."""
    r = run_cli("board", "--profile", PROFILE, "--set", "node.adxl_sck_ratio=8")
    assert r.code == 1, r.err
    assert "BROKEN SPI #1–#7 SCLK" in r.out and "sclk_too_fast" in r.out
    r = run_cli("board", "--profile", PROFILE, "--set", "gps.baud=4800")
    assert r.code == 1 and "uart_framing_error" in r.out


@pytest.mark.parametrize("command", ["board", "budget", "run", "replay"])
def test_a_bad_profile_key_is_exit_2_naming_the_key(command: str, tmp_path: Path, vehicle: Path) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text(gfsins.PROFILE.read_text(encoding="utf-8").replace("[node]", "[node]\nsck_ratio = 54"))
    args = {
        "board": [],
        "budget": [],
        "run": [str(vehicle)],
        "replay": [str(vehicle), "--out", str(tmp_path / "x.rrd")],
    }
    r = run_cli(command, *args[command], "--profile", str(bad))
    assert r.code == 2, r.out + r.err
    assert str(bad) in r.err and "node.sck_ratio" in r.err and "Traceback" not in r.err
    r = run_cli(command, *args[command], "--profile", PROFILE, "--set", "array.lever_arm_m=2")
    assert r.code == 2 and "array.lever_arm_m" in r.err and "Traceback" not in r.err
    assert not (tmp_path / "x.rrd").exists()


def test_budget_shows_both_processors_stages_per_rate_class() -> None:
    r = run_cli("budget", "--profile", PROFILE, "--json")
    assert r.code == 0, r.err
    b = json.loads(r.out)
    assert b["classes"] == ["200 Hz", "10 Hz", "1 Hz"]
    rows = b["stages"]
    for proc in ("node", "dsp"):
        mine = [x for x in rows if x["processor"] == proc]
        assert len(mine) >= 2 and mine[-1]["stage"] == "total"
        for c in b["classes"]:
            total = mine[-1][c]
            assert total["ticks"] > 0 and total == b["processors"][proc][c]
            # Every stage row is one the Rust budget gave, each at most its processor's peak.
            assert all(x[c]["peak_s"] <= total["peak_s"] for x in mine)
    node = b["processors"]["node"]
    assert node["1 Hz"]["peak_s"] > node["10 Hz"]["peak_s"] > node["200 Hz"]["peak_s"]
    text = run_cli("budget", "--profile", PROFILE).out
    assert "200 Hz peak" in text and "10 Hz peak" in text and "1 Hz peak" in text
    assert "node" in text and "dsp" in text and "accelerometers" in text


def test_budget_exit_1_on_an_overrun() -> None:
    r = run_cli("budget", "--profile", PROFILE, "--set", "node.adxl_sck_ratio=8192", "--duration-s", "0.1")
    assert r.code == 1 and "overrun" in r.err, r.err


def test_run_writes_the_packets_and_bus_log(tmp_path: Path, vehicle: Path) -> None:
    for ext in (".csv", ".h5"):
        out = tmp_path / f"run{ext}"
        r = run_cli("run", str(vehicle), "--profile", PROFILE, "--out", str(out), "--json")
        assert r.code == 0, r.err
        s = json.loads(r.out)
        assert s["cycles"] == 480 and s["packets_refused"] == 0 and s["gps_fixes"] == 3
        assert set(s["events"]) <= {"rate_singular"} and s["tilt_error"]["pitch"]["rms_deg"] < 10
        meta = read_metadata(out)
        assert meta["format"] == gfsins.RUN_FORMAT and meta["sample_rate_hz"] == "200"
        # Read back through the table reader, every row checked against the schema.
        table = open_table(out, gfsins.RUN_SCHEMA, 10_000, False, 1.5)
        blocks = list(table.blocks)
        t = np.concatenate([b["t_s"] for b in blocks])
        assert len(t) == 480 and t[0] == 0.6 and np.allclose(np.diff(t), 0.005, rtol=0, atol=1e-12)
        spi8 = np.concatenate([b["spi8_end_s"] for b in blocks])
        assert np.all(spi8 > t) and np.all(spi8 < t + 0.005)  # each packet inside its cycle
    again = tmp_path / "again.csv"
    run_cli("run", str(vehicle), "--profile", PROFILE, "--out", str(again))
    assert again.read_bytes() == (tmp_path / "run.csv").read_bytes()  # byte-identical
    lines = (tmp_path / "run.csv").read_text(encoding="utf-8").splitlines()
    header = next(x for x in lines if not x.startswith("#")).split(",")
    assert header[:3] == ["t_s", "sequence", "flags"] and "spi8_end_s" in header and "iic_start_s" in header
    text = run_cli("run", str(vehicle), "--profile", PROFILE).out
    assert "packets 480 accepted" in text and "1 Hz peak" in text


def test_run_input_errors_name_the_file(tmp_path: Path) -> None:
    static = tmp_path / "static.csv"
    synth.generate("static", duration_s=2.0).save(static)
    r = run_cli("run", str(static), "--profile", PROFILE)
    assert r.code == 2 and str(static) in r.err and "array*" in r.err, r.err
    short = tmp_path / "short.h5"
    run_cli("synth", "vehicle", "--duration-s", "0.2", "--out", str(short))
    r = run_cli("run", str(short), "--profile", PROFILE)
    assert r.code == 2 and "node.start_ms" in r.err, r.err
    r = run_cli("run", str(short), "--profile", PROFILE, "--raw-out", str(tmp_path / "raw.csv"))
    assert r.code == 2 and "--raw-out" in r.err


def test_replay_has_a_bus_lane_for_every_link(tmp_path: Path, vehicle: Path) -> None:
    import rerun as rr

    out = tmp_path / "v.rrd"
    r = run_cli(
        "replay", str(vehicle), "--profile", PROFILE, "--out", str(out), "--bus-ticks", "1:250", "--json"
    )
    assert r.code == 0, r.err
    rep = json.loads(r.out)
    assert rep["cycles"] == 480 and rep["bus_links"] == list(gfsins_links())
    entities = set(rr.chunk.RrdReader(out).stream().collect().schema().entity_paths())
    for link in gfsins_links():
        assert f"/bus/{link}" in entities, link
    # Every link carried something in 250 ticks (the compass polls from 1.1 s, a GPS burst by 1.3 s).
    assert rep["bus_transactions"] >= 250 * 8


def gfsins_links() -> tuple[str, ...]:
    from sins_fw.viewer import paths

    return paths.GFSINS_LINKS
