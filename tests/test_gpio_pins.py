"""The F28335's GPIO under the user's C firmware (issue 39, item 1; issue 36, item 4): the control
registers with their EALLOW protection (SPRUFB0), the pins' peripheral functions (GPIO57 muxed to
SPISTEA is driven by SPI-A around each character), a pin that is not a GPIO output not moving, and
the SPI parts the profile places on SPI-A each behind its own GPIO chip select."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from conftest import run_alone
from sins_fw.firmware_build import build_firmware
from sins_fw.firmware_run import FirmwareResult, run_c_firmware
from sins_fw.profile import load_profile

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "firmware_c" / "examples"
TI = ROOT / "firmware_c" / "ti"

#: The ADIS16407's PROD_ID (its data sheet: 0x4017 = 16407).
ADIS16407_PROD_ID = 0x4017


pytestmark = pytest.mark.usefixtures("cabi_library")


def _run(
    src: str,
    folder: Path,
    until_s: float,
    overrides: list[str] | None = None,
    bus_log: bool = False,
    **types: str,
) -> tuple[FirmwareResult, list[dict[str, Any]]]:
    (folder / "fw.c").write_text(src)
    fw = build_firmware([folder / "fw.c", TI / "DSP2833x_Spi.c"], folder / "fw.so")
    profile = load_profile("reference", overrides or [])
    return run_alone(fw, folder, until_s, profile, bus_log=bus_log, **types)


#: PROD_ID read over and over with polled SPI-A in mode 3 (16-bit, 0.75 MHz); `CS_DOWN`/`CS_UP` move
#: the chip select (nothing: SPISTEA does it), `SETUP` sets the pins up.
PROD_ID = """#include "DSP28x_Project.h"
Uint16 prod_id;
Uint16 mux;
static Uint16 spi_xmit(Uint16 a) {
    while (SpiaRegs.SPISTS.bit.BUFFULL_FLAG == 1) {
    }
    SpiaRegs.SPITXBUF = a;
    while (SpiaRegs.SPISTS.bit.INT_FLAG != 1) {
    }
    return SpiaRegs.SPIRXBUF;
}
void main(void) {
    SETUP;
    SpiaRegs.SPICCR.all = 0x004F;
    SpiaRegs.SPICTL.all = 0x0006;
    SpiaRegs.SPIBRR = 49;
    SpiaRegs.SPICCR.bit.SPISWRESET = 1;
    DELAY_US(10000);
    for (;;) {
        CS_DOWN;
        spi_xmit(0x5600);
        DELAY_US(40);
        prod_id = spi_xmit(0x0000);
        CS_UP;
        mux = (Uint16)GpioCtrlRegs.GPBMUX2.bit.GPIO57;
        DELAY_US(1000);
    }
}
"""


def _prod_id(setup: str, cs_down: str = "", cs_up: str = "") -> str:
    return PROD_ID.replace("SETUP", setup).replace("CS_DOWN", cs_down).replace("CS_UP", cs_up)


def test_spistea_muxed_by_init_spia_gpio_selects_the_adis16407(tmp_path: Path):
    """TI's idiom: InitSpiaGpio muxes GPIO57 to SPISTEA and SPI-A drives it around each character, so
    PROD_ID reads 0x4017 (before: the slave saw no chip select, 0xFFFF and `spi_frame_without_cs`
    warnings, exit 0). The bus log shows CS low around each frame, set up ½ SCLK before its first
    edge and released ½ SCLK after its last (the frames are 40 µs apart: a gap, so STE rises between
    them)."""
    src = _prod_id("InitSpiaGpio()", "GpioDataRegs.GPBCLEAR.bit.GPIO57 = 1")
    run, events = _run(src, tmp_path, 0.05, bus_log=True, prod_id="uint16", mux="uint16")
    assert run.final["mux"] == 1
    assert run.final["prod_id"] == ADIS16407_PROD_ID
    assert not [e for e in events if e["kind"] == "spi_frame_without_cs"], events[:3]
    # The firmware also clears GPIO57 as if it were a GPIO: the pin is SPISTEA's, it does not move
    # (reported once).
    not_driven = [e for e in events if e["kind"] == "gpio_not_driven"]
    assert len(not_driven) == 1 and "muxed to SPISTEA (its GPBMUX field = 1)" in not_driven[0]["message"]
    bus = run.bus
    assert bus is not None
    starts, ends = bus["frame_first_edge_ps"], bus["frame_last_edge_ps"]
    half = bus["frame_sclk_period_ps"][0] // 2
    falls = bus["cs_t_ps"][bus["cs_low"]]
    rises = bus["cs_t_ps"][~bus["cs_low"]]
    assert len(falls) == len(starts) > 10
    assert (falls == starts - half).all() and (rises[: len(ends)] == ends + half).all()


def test_a_protected_write_without_eallow_is_ignored_with_an_event(tmp_path: Path):
    """GPBMUX2 written without EALLOW keeps its reset value (the pin stays a GPIO, so the slave is not
    selected), and each such write is a `protected_write` warning naming the register."""
    setup = "GpioCtrlRegs.GPBMUX2.bit.GPIO57 = 1"
    run, events = _run(_prod_id(setup), tmp_path, 0.02, prod_id="uint16", mux="uint16")
    assert run.final["mux"] == 0
    protected = [e for e in events if e["kind"] == "protected_write"]
    assert protected and "GPBMUX2" in protected[0]["message"]
    assert run.final["prod_id"] != ADIS16407_PROD_ID


def test_a_chip_select_left_an_input_does_not_move(tmp_path: Path):
    """With every pin as reset leaves it (`firmware.gpio_at_start = "reset"`), GPIO57 is an input:
    GPBCLEAR moves its latch, not the pin, so the part is never selected (PROD_ID reads the floating
    0xFFFF) and a `gpio_not_driven` warning says so, once. Set up as an output, the same firmware
    reads 0x4017."""
    cs_down, cs_up = "GpioDataRegs.GPBCLEAR.bit.GPIO57 = 1", "GpioDataRegs.GPBSET.bit.GPIO57 = 1"
    reset = ["firmware.gpio_at_start=reset"]
    run, events = _run(_prod_id("", cs_down, cs_up), tmp_path, 0.02, reset, prod_id="uint16", mux="uint16")
    assert run.final["prod_id"] == 0xFFFF
    not_driven = [e for e in events if e["kind"] == "gpio_not_driven"]
    assert (
        len(not_driven) == 1 and "GPIO57, which is an input (GPBDIR bit 25 = 0)" in not_driven[0]["message"]
    )
    output = "EALLOW; GpioCtrlRegs.GPBDIR.bit.GPIO57 = 1; EDIS"
    run, events = _run(
        _prod_id(output, cs_down, cs_up), tmp_path, 0.02, reset, prod_id="uint16", mux="uint16"
    )
    assert run.final["prod_id"] == ADIS16407_PROD_ID
    assert not [e for e in events if e["kind"] in ("gpio_not_driven", "spi_frame_without_cs")]


def test_two_parts_on_spi_a_behind_two_chip_selects(tmp_path: Path):
    """Issue 36, "Must hold" (b): a profile and an example firmware, no emulator code. The ADIS16407
    on GPIO57 answers PROD_ID; the ADS8344 on GPIO60 converts its eight channels, CH7 the front
    end's VREF/2 = 2.5 V of VREF 5 V: code 2.5/5·65536 = 32768 exactly (ideal front end); CH0, the
    x gyro's 2.5 V null at rest, within one code (the still board turns at earth rate only, at most
    0.0042 °/s: 6.7 µV at the SPIN1200's 1.92 V per 1200 °/s, below one code, 5 V/65536 = 76 µV, so
    the code is 32768 or the one below it)."""
    example = EXAMPLES / "two_parts"
    fw = build_firmware([example / "main.c"], tmp_path / "fw.so")
    parts: list[dict[str, Any]] = []
    run = run_c_firmware(
        fw,
        None,
        load_profile("adis_ads8344"),
        globals_file=example / "globals.toml",
        until_s=0.05,
        sink=parts.append,
    )
    events = [e for p in parts for e in p["events"]]
    assert run.final["rounds"] > 10
    assert run.final["prod_id"] == ADIS16407_PROD_ID
    assert run.final["code7"] == 32768
    assert run.final["code0"] in (32767, 32768)
    assert not [e for e in events if e["severity"] != "info"], events[:3]
