"""SPI bit-banged on GPIO54-57 (issue 39): a TI-style firmware (firmware_c/examples/ti_style/spi_bitbang)
muxes SPI-A's pins to GPIO and clocks the ADIS16407 itself, reading PROD_ID (the part's 0x4017,
adis16407.md). The part sees the frames the pins' edges make and checks them with its own rules: at a
half period of 1 µs (SCLK 500 kHz, under its 2 MHz) nothing is broken; with no delay the clock is as
fast as the CPU's register writes, above 2 MHz, and the part says so (`sclk_too_fast`)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from conftest import run_alone
from sins_fw.firmware_build import build_firmware

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "firmware_c" / "examples" / "ti_style" / "spi_bitbang" / "spi_bitbang.c"
PROD_ID = 0x4017  # the ADIS16407's (rust/core/src/device/parts/adis16407.rs, adis16407.md)

pytestmark = pytest.mark.usefixtures("cabi_library")


def _run(tmp_path: Path, defines: tuple[str, ...] = ()) -> tuple[Any, list[dict[str, Any]]]:
    fw = build_firmware([EXAMPLE], tmp_path / "bitbang.so", defines=defines)
    return run_alone(fw, tmp_path, 0.3, prod_id="uint16", first_word="uint16", done="uint16")


def test_a_bit_banged_read_of_prod_id(tmp_path: Path):
    run, events = _run(tmp_path)
    assert run.final["done"] == 1
    assert run.final["prod_id"] == PROD_ID
    # The command frame is the window's first since power-on: the part answers it with no register.
    assert run.final["first_word"] != PROD_ID
    assert events == []


def test_a_too_fast_bit_bang_is_the_parts_sclk_event(tmp_path: Path):
    run, events = _run(tmp_path, ("HALF_PERIOD_US=0",))
    assert run.final["done"] == 1
    fast = [e for e in events if e["kind"] == "sclk_too_fast"]
    assert len(fast) == 2, [e["kind"] for e in events]  # both frames, each found by the part's rule
    assert all("exceeds the normal-mode limit 2.000000 MHz" in e["message"] for e in fast)
    # The second frame starts at the first one's SCLK period, so the part knows it too fast as it
    # loads its word: under the reference profile's strict timing its DOUT is the corrupt word.
    assert run.final["prod_id"] == 0xFFFF
