"""A board = 1 profile (issue 36): a gyro-free board that differs from gfsins.toml in its profile
alone (tests/data/gfsins/variant.toml: the seven ADXL345 at other places and on other SPI cores,
the triaxial part read first, l = 0.15 m; the HMC6343 at 0x1E) runs through the same commands as
the shipped profile, navigates, and addresses its compass where the profile puts it; a layout the
nine channels cannot invert is refused naming the key."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from conftest import run_cli
from sins_fw import gfsins
from sins_fw.tablefile import open_table
from sins_fw.viewer import gfsins as view

VARIANT = Path(__file__).parent / "data" / "gfsins" / "variant.toml"
SINGULAR = Path(__file__).parent / "data" / "bad" / "profiles" / "gfsins_singular_array.toml"
IDEAL = ("array.preset=ideal", "compass.errors=ideal", "gps.cep_m=0", "gps.velocity_sigma_m_s=0")
SECONDS = "20"


def _drive(out: Path, profile: str | Path) -> Path:
    """`synth vehicle` (the chapter 5 straight line) with the array placed as ``profile`` places it."""
    keys = gfsins.vehicle_array(gfsins.load(profile))
    positions = ",".join(repr(x) for x in keys["array_positions_lever_arms"])
    args = ["--lever-arm-m", repr(keys["lever_arm_m"]), "--array-positions-lever-arms", positions]
    r = run_cli("synth", "vehicle", "--duration-s", SECONDS, *args, "--out", str(out))
    assert r.code == 0, r.err
    return out


@pytest.fixture(scope="module")
def drives(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    d = tmp_path_factory.mktemp("variant")
    return {"variant": _drive(d / "variant.h5", VARIANT), "shipped": _drive(d / "shipped.h5", gfsins.PROFILE)}


def _run(trace: Path, profile: str | Path, out: Path) -> dict[str, object]:
    sets = [x for kv in IDEAL for x in ("--set", kv)]
    r = run_cli("run", str(trace), "--profile", str(profile), *sets, "--out", str(out), "--json")
    assert r.code == 0, r.err
    return dict(json.loads(r.out))


def test_the_variant_is_the_profile_and_nothing_else() -> None:
    """The variant's array and compass keys reach the board (the resolved profile), and the
    `synth vehicle` keys derived from it place the array's parts where its profile puts them."""
    prof = gfsins.load(VARIANT)
    assert int(prof.get("compass.address")) == 0x1E
    parts = prof.get("array.parts")
    assert [p["link"] for p in parts] == ["spi7", "spi2", "spi1", "spi3", "spi4", "spi5", "spi6"]
    keys = gfsins.vehicle_array(prof)
    assert keys["lever_arm_m"] == 0.15 and keys["array_positions_lever_arms"][3:6] == (0.0, 1.5, 0.5)
    shipped = gfsins.vehicle_array(gfsins.load(gfsins.PROFILE))
    assert shipped == {
        "lever_arm_m": 0.1,
        "array_positions_lever_arms": tuple(float(x) for x in gfsins_layout()),
    }


def test_synth_refuses_an_array_of_other_than_seven_places() -> None:
    from sins_fw import synth
    from sins_fw.errors import ConfigError

    with pytest.raises(ConfigError, match="array_positions_lever_arms has 20 values; expected 21"):
        synth.generate("vehicle", duration_s=1.0, array_positions_lever_arms=(0.0,) * 20)
    r = run_cli(
        "synth", "vehicle", "--duration-s", "1", "--array-positions-lever-arms", "0,1,0", "--out", "x.h5"
    )
    assert r.code == 2 and "expected 21" in r.err and "Traceback" not in r.err, r.err


def gfsins_layout() -> np.ndarray:
    from sins_fw import synth

    return synth.ARRAY_POSITIONS.ravel()


def test_the_variant_navigates_as_the_shipped_board(drives: dict[str, Path], tmp_path: Path) -> None:
    """With ideal parts on the chapter 5 straight line the variant's navigation meets the fused
    filter's chapter 5 bounds (as test_gfsins.py's shipped-profile test: position ≲ 10 m, velocity
    ≲ 0.1 m/s, level ≲ 0.5°, heading < 1.5°), and is the shipped board's navigation bit for bit:
    on a straight line the parts feel the same force to l·ω² ≈ 1e-9 g (ω the earth and transport
    rate, l ≤ 0.3 m), six orders under a count (3.9 mg), so both arrays give the same counts, and
    both inversions give A from the centre part's counts alone and exact zeros for ω̇ and the
    products (sums of equal counts with opposite signs). Its packets carry the centre part first."""
    variant = _run(drives["variant"], VARIANT, tmp_path / "variant.csv")
    shipped = _run(drives["shipped"], gfsins.PROFILE, tmp_path / "shipped.csv")
    err = variant["navigation_error"]
    assert isinstance(err, dict)
    assert err["horizontal_m"]["max_abs"] < 10.0 and err["velocity_mps"]["max_abs"] < 0.1
    assert max(err["roll_deg"]["max_abs"], err["pitch_deg"]["max_abs"]) < 0.5
    assert err["heading_deg"]["max_abs"] < 1.5
    assert err == shipped["navigation_error"]
    assert variant["compass_updates"] == shipped["compass_updates"] > 0
    assert set(variant["events"]) == {"rate_singular"}  # no i2c_nack: the compass answers at 0x1E

    def columns(path: Path) -> dict[str, np.ndarray]:
        blocks = list(open_table(path, gfsins.RUN_SCHEMA, 10_000, False, 1.5).blocks)
        return {n: np.concatenate([b[n] for b in blocks]) for n in blocks[0]}

    v, s = columns(tmp_path / "variant.csv"), columns(tmp_path / "shipped.csv")
    nav = [n for n in s if n.startswith("nav_")]
    assert nav and all(np.array_equal(v[n], s[n], equal_nan=True) for n in nav)
    # A₁…A₃ of the variant are the centre part's x, y, z: the shipped board's A₇…A₉.
    for a, b in ((1, 7), (2, 8), (3, 9)):
        assert np.array_equal(v[f"a{a}_g"], s[f"a{b}_g"])


def test_the_compass_is_addressed_where_the_profile_puts_it(drives: dict[str, Path]) -> None:
    """`board` shows I²C #1 to the HMC6343 at 0x1E and the parts on their cores; the I²C lane of the
    replay (the bus log) names 0x1E on every compass transaction."""
    r = run_cli("board", "--profile", str(VARIANT), "--json")
    assert r.code == 0, r.err
    s = json.loads(r.out)
    links = {x["name"]: x for x in s["links"]}
    assert "0x1E" in links["iic1"]["what"]
    assert "ADXL345 #1 at (0, 0, 0)·l, channels x y z" in links["spi7"]["what"]
    assert "ADXL345 #2 at (0, 1.5, 0.5)·l" in links["spi2"]["what"]
    prof = gfsins.load(VARIANT)
    from sins_fw.traces import PhysicalTrace

    trace = PhysicalTrace.load(drives["variant"])
    out = gfsins.run(trace, 400, prof)
    lanes = view.bus_lanes(out, (1, 400), int(prof.get("compass.address")))
    states = [x for x in lanes["iic1"][1] if x != "idle"]
    assert states and all(x.startswith("0x1E ") for x in states)


@pytest.mark.parametrize("command", ["board", "run"])
def test_a_singular_layout_is_exit_2_naming_the_key(command: str, drives: dict[str, Path]) -> None:
    args = [str(drives["shipped"])] if command == "run" else []
    r = run_cli(command, *args, "--profile", str(SINGULAR))
    assert r.code == 2, r.out + r.err
    assert str(SINGULAR) in r.err and "`array.parts`" in r.err and "singular" in r.err
    assert "Traceback" not in r.err
