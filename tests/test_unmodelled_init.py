"""The peripherals the emulator does not model, initialised the way TI's 2833x examples do (issue 39):
a TI-style firmware (firmware_c/examples/ti_style/unmodelled_init) calls InitAdc, InitEPwmGpio,
InitECap, InitECana, DMAInitialize and InitXintf and sets up ePWM1, eCAP1 and the ADC through the
register files of firmware_c/include (DSP2833x_Adc.h, _EPwm.h, _ECap.h, _ECan.h, _DMA.h, _Xintf.h).
It runs to its end; the registers hold their reset values until written (the guides' values,
rust/core/src/dsp/unmodelled.rs) and what is written after; each peripheral kind is reported once, as
a warning."""

from __future__ import annotations

from pathlib import Path

import pytest

from conftest import run_alone
from sins_fw.firmware_build import build_firmware

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "firmware_c" / "examples" / "ti_style" / "unmodelled_init" / "unmodelled_init.c"

pytestmark = pytest.mark.usefixtures("cabi_library")


def test_a_project_initialising_the_unmodelled_peripherals_runs_with_one_warning_each(tmp_path: Path):
    fw = build_firmware([EXAMPLE], tmp_path / "init.so")
    run, events = run_alone(
        fw,
        tmp_path,
        0.02,
        tbctl_reset="uint16",
        ecctl2_reset="uint16",
        xtiming0_reset="uint32",
        tbprd="uint16",
        cmpa="uint16",
        adctrl3="uint16",
        canes_cce="uint16",
        done="uint16",
    )
    assert run.final == {
        "tbctl_reset": 0x0083,  # SPRUG04: counter frozen, HSPCLKDIV /2
        "ecctl2_reset": 0x0006,  # SPRUFG4: STOP_WRAP = 3
        "xtiming0_reset": 0x0043FFFF,  # SPRU949
        "tbprd": 1500,
        "cmpa": 750,
        "adctrl3": 0x00E0,
        "canes_cce": 0,  # CCE follows CCR, cleared again by InitECana
        "done": 1,
    }
    warned = [e for e in events if e["kind"] == "unmodelled_peripheral"]
    used = [e["message"].split("(")[0].removeprefix("the firmware uses the ").strip() for e in warned]
    assert used == ["ePWM1", "eCAP1", "XINTF", "ADC", "eCAN-A", "DMA"], used
    assert {e["severity"] for e in warned} == {"warning"}
    assert {e["kind"] for e in events} == {"unmodelled_peripheral"}, events[:3]
