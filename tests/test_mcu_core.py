"""The F28335 core a C firmware touches (issue 39): system control and the clock tree (the PLL, the
peripheral clock enables, the watchdog), CPU timers 0-2, the whole PIE with SPI-A's FIFO interrupts,
the flash-to-RAM copy, and the peripherals not modelled yet (registers with their reset values, one
warning each). Each firmware is written the way TI's 2833x examples are and builds with no edit."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from conftest import TIMER0_1MS, run_alone, write_globals
from sins_fw.firmware_build import build_firmware
from sins_fw.firmware_run import FirmwareStopped, run_c_firmware
from sins_fw.profile import load_profile

ROOT = Path(__file__).resolve().parents[1]
TI_STYLE = ROOT / "firmware_c" / "examples" / "ti_style"
#: OSCCLK of the reference profile, Hz.
OSCCLK_HZ = 30e6
#: The reference LSPCLK: 150 MHz / (2·LOSPCP = 4).
LSPCLK_HZ = 37.5e6


pytestmark = pytest.mark.usefixtures("cabi_library")


def _run(
    fw: Path, folder: Path, until_s: float, overrides: tuple[str, ...] = (), **types: str
) -> tuple[Any, list[dict[str, Any]]]:
    return run_alone(fw, folder, until_s, load_profile("reference", list(overrides)), **types)


def _source(folder: Path, text: str, name: str = "main.c") -> Path:
    src = folder / name
    src.write_text('#include "DSP28x_Project.h"\n' + text)
    return src


def test_cpu_timers_0_1_2_each_reach_their_isr(tmp_path: Path):
    """TINT0 through PIE group 1, TINT1 on INT13, TINT2 on INT14: periods 1, 2 and 5 ms."""
    fw = build_firmware([TI_STYLE / "cpu_timers"], tmp_path / "timers.so")
    run, events = _run(fw, tmp_path, 0.0205, count0="uint32", count1="uint32", count2="uint32")
    # Started within a few µs of power-on: 20.5 ms hold 20, 10 and 4 whole periods.
    assert run.final == {"count0": 20, "count1": 10, "count2": 4}
    assert run.isr_rows == 34
    assert not events


def test_spi_fifo_loopback_with_interrupts(tmp_path: Path):
    """SPITXINTA refills the FIFO, SPIRXINTA reads it back: every word comes back, in order."""
    fw = build_firmware([TI_STYLE / "spi_loopback_interrupts"], tmp_path / "spi.so")
    until = 0.0205
    parts: list[dict[str, Any]] = []
    run = run_c_firmware(
        fw,
        None,
        load_profile("reference"),
        globals_file=write_globals(tmp_path, tx_isr="uint16", rx_isr="uint16", errors="uint16"),
        until_s=until,
        sink=parts.append,
    )
    events = [e for p in parts for e in p["events"]]
    assert run.final["errors"] == 0
    # Two 16-bit words per receive interrupt at LSPCLK / (SPIBRR + 1) = 37.5 MHz / 100: at most
    # until / pair_s of them. From the end of the first ISR (the transmit one, which fills the FIFO)
    # the SPI never waits: the transmit interrupt comes while TXFFST ≤ 2, two words (85 µs) before the
    # FIFO runs dry, and no ISR is that long (the longest, from the rows, is checked below), so the
    # pairs follow each other back to back; the last may still be shifting when the run ends.
    pair_s = 2 * 16 * 100 / LSPCLK_HZ
    start_ps = np.concatenate([p["budget_start_ps"] for p in parts]).astype(np.int64)
    end_ps = np.concatenate([p["budget_end_ps"] for p in parts]).astype(np.int64)
    assert (end_ps - start_ps).max() * 1e-12 < pair_s
    first_end_s = end_ps[0] * 1e-12
    assert math.floor((until - first_end_s) / pair_s) - 1 <= run.final["rx_isr"] <= until / pair_s
    assert run.final["tx_isr"] - run.final["rx_isr"] in (1, 2)
    # InitSpiaGpio muxes GPIO57 to SPISTEA, so the reference board's ADIS16407 is selected around
    # the words SPI-A clocks in loopback (SPILBK ties SIMO to SOMI inside the chip; SIMO still drives
    # the pin): the part reports what it is sent, which is not its protocol (words closer than its
    # stall time are an error, as they would be on the board). Nothing else happens.
    assert {e["kind"] for e in events} <= {"spi_mode", "stall_too_short", "read_only_write"}


def test_a_flash_build_copies_its_ram_functions_before_running_them(tmp_path: Path):
    """MemCopy(&RamfuncsLoadStart, &RamfuncsLoadEnd, &RamfuncsRunStart), then InitFlash from RAM: its
    wait states land in FlashRegs, and the ISR placed in ramfuncs runs. InitFlash called before the
    copy stops the run, naming it."""
    fw = build_firmware([TI_STYLE / "flash_ramfuncs"], tmp_path / "flash.so")
    run, _ = _run(fw, tmp_path, 0.0105, ticks="uint16", bankwait="uint16")
    assert run.final == {"ticks": 10, "bankwait": 0x0505}  # PAGEWAIT = RANDWAIT = 5
    early = build_firmware([TI_STYLE / "flash_ramfuncs"], tmp_path / "early.so", defines=["INIT_FLASH_FIRST"])
    with pytest.raises(FirmwareStopped, match=r"InitFlash\(\) is placed in section ramfuncs.*before copying"):
        _run(early, tmp_path, 0.01, ticks="uint16")


def test_the_memcpy_idiom_uses_the_load_size(tmp_path: Path):
    src = _source(
        tmp_path,
        "#include <string.h>\n"
        '#pragma CODE_SECTION(fast, "ramfuncs")\n'
        "Uint16 fast(void) { return 7; }\n"
        "Uint16 got, words;\n"
        "void main(void) {\n"
        "    InitSysCtrl();\n"
        "    memcpy(&RamfuncsRunStart, &RamfuncsLoadStart, (Uint32)&RamfuncsLoadSize);\n"
        "    words = &RamfuncsLoadEnd - &RamfuncsLoadStart;\n"
        "    got = fast();\n"
        "}\n",
    )
    fw = build_firmware([src], tmp_path / "memcpy.so")
    run, _ = _run(fw, tmp_path, 0.001, got="uint16", words="uint16")
    # 8 words per function in ramfuncs: `fast` and the replacement InitFlash.
    assert run.final == {"got": 7, "words": 16}


def test_initialising_the_adc_and_epwms_runs_with_one_warning_each(tmp_path: Path):
    src = _source(
        tmp_path,
        "/* ePWM and ADC registers by address, as a project without the register files reaches them\n"
        "   (tests/test_unmodelled_init.py: by the register files, with TI's support functions). */\n"
        "#define EPWM_TBCTL(n) (*(volatile Uint16 *)(0x6800 + 0x40 * ((n) - 1)))\n"
        "#define EPWM_TBPRD(n) (*(volatile Uint16 *)(0x6805 + 0x40 * ((n) - 1)))\n"
        "#define EPWM_CMPA(n) (*(volatile Uint16 *)(0x6809 + 0x40 * ((n) - 1)))\n"
        "#define ADCTRL1 (*(volatile Uint16 *)0x7100)\n"
        "#define ADCMAXCONV (*(volatile Uint16 *)0x7102)\n"
        "#define ADCTRL3 (*(volatile Uint16 *)0x7118)\n"
        "Uint16 tbctl_reset, tbprd, adctrl3;\n"
        "void main(void) {\n"
        "    InitSysCtrl();\n"
        "    tbctl_reset = EPWM_TBCTL(2);\n"
        "    EALLOW;\n"
        "    SysCtrlRegs.PCLKCR0.bit.TBCLKSYNC = 0;\n"
        "    EDIS;\n"
        "    EPWM_TBPRD(1) = 1500;\n"
        "    EPWM_TBCTL(1) &= ~0x0003;\n"
        "    EPWM_TBPRD(2) = 3000;\n"
        "    EPWM_CMPA(2) = 750;\n"
        "    EALLOW;\n"
        "    SysCtrlRegs.PCLKCR0.bit.TBCLKSYNC = 1;\n"
        "    EDIS;\n"
        "    ADCTRL3 = 0x00E0;\n"
        "    DELAY_US(5000L);\n"
        "    ADCTRL1 = 0x0F00;\n"
        "    ADCMAXCONV = 0x0001;\n"
        "    tbprd = EPWM_TBPRD(2);\n"
        "    adctrl3 = ADCTRL3;\n"
        "}\n",
    )
    fw = build_firmware([src], tmp_path / "init.so")
    run, events = _run(fw, tmp_path, 0.01, tbctl_reset="uint16", tbprd="uint16", adctrl3="uint16")
    assert run.final == {"tbctl_reset": 0x0083, "tbprd": 3000, "adctrl3": 0x00E0}
    warned = [e for e in events if e["kind"] == "unmodelled_peripheral"]
    assert len(warned) == 2 and [e["severity"] for e in warned] == ["warning"] * 2
    assert "ePWM2 (EPwm2Regs" in warned[0]["message"] and "ADC (AdcRegs" in warned[1]["message"]
    assert {e["kind"] for e in events} == {"unmodelled_peripheral"}


#: C statements of main() that reset the PIE with the CPU's interrupts off and install ``tick`` as
#: TINT0's ISR (EALLOW left on).
_TICK_VECTOR = (
    "    DINT;\n"
    "    InitPieCtrl();\n"
    "    IER = 0; IFR = 0;\n"
    "    InitPieVectTable();\n"
    "    EALLOW;\n"
    "    PieVectTable.TINT0 = &tick;\n"
)

#: A firmware that enables the watchdog (WDPS = 0: 4.37 ms at 30 MHz) and, with SERVICE defined,
#: services it from a 1 ms timer interrupt.
WATCHDOG = (
    "interrupt void tick(void);\n"
    "Uint16 ticks;\n"
    "void main(void) {\n"
    "    InitSysCtrl();\n"
    f"{_TICK_VECTOR}"
    "    SysCtrlRegs.WDCR = 0x0028;\n"
    "    EDIS;\n"
    f"{TIMER0_1MS}"
    "    for (;;) {}\n"
    "}\n"
    "interrupt void tick(void) {\n"
    "    ticks++;\n"
    "#ifdef SERVICE\n"
    "    ServiceDog();\n"
    "#endif\n"
    "    PieCtrlRegs.PIEACK.all = PIEACK_GROUP1;\n"
    "}\n"
)


def test_a_serviced_watchdog_never_bites_and_an_unserviced_one_resets_the_chip(tmp_path: Path):
    src = _source(tmp_path, WATCHDOG)
    fed = build_firmware([src], tmp_path / "fed.so", defines=["SERVICE"])
    run, events = _run(fed, tmp_path, 0.0505, ticks="uint16")
    assert run.final["ticks"] == 50
    assert not events
    starved = build_firmware([src], tmp_path / "starved.so")
    events = []
    with pytest.raises(FirmwareStopped, match=r"the watchdog reset the chip at t = 0\.0043") as stop:
        run_alone(starved, tmp_path, 0.05, events=events, ticks="uint16")
    # WDCLK = OSCCLK / 512, 256 counts: 4.369 ms after the dog was enabled (a few µs after t = 0).
    bite_s = 512 * 256 / OSCCLK_HZ
    assert [e["kind"] for e in events] == ["watchdog_reset"]
    assert bite_s <= events[0]["t_s"] <= bite_s + 50e-6
    assert "ServiceDog" in str(stop.value)


def test_from_the_chips_reset_state_the_dog_runs_and_the_clocks_are_off(tmp_path: Path):
    """`clocks.at_main = "reset"`: a firmware that uses SPI-A without InitSysCtrl gets one
    peripheral_clock_off event (its writes lost), and the running watchdog resets it."""
    src = _source(
        tmp_path,
        "Uint16 ccr;\n"
        "void main(void) {\n"
        "    SpiaRegs.SPICCR.all = 0x000F;\n"
        "    ccr = SpiaRegs.SPICCR.all;\n"
        "    for (;;) { ccr = SpiaRegs.SPICCR.all; }\n"
        "}\n",
    )
    fw = build_firmware([src], tmp_path / "cold.so")
    parts: list[dict[str, Any]] = []
    with pytest.raises(FirmwareStopped, match="watchdog reset the chip"):
        run_c_firmware(
            fw,
            None,
            load_profile("reference", ["clocks.at_main=reset"]),
            globals_file=write_globals(tmp_path, ccr="uint16"),
            until_s=0.01,
            sink=parts.append,
        )
    kinds = [e["kind"] for p in parts for e in p["events"]]
    assert kinds == ["peripheral_clock_off", "watchdog_reset"]


def test_a_pll_setting_changes_the_timer_period(tmp_path: Path):
    """InitPll(5, 2): 30 MHz × 5 / 2 = 75 MHz once the PLL has relocked (131072 OSCCLK cycles), so
    ConfigCpuTimer(&CpuTimer0, 150, 1000) gives 2 ms periods instead of 1 ms."""
    src = _source(
        tmp_path,
        "interrupt void tick(void);\n"
        "Uint16 ticks, divsel, pll_div;\n"
        "void main(void) {\n"
        "    DisableDog();\n"
        "    InitPll(5, 2);\n"
        "    InitPeripheralClocks();\n"
        "    divsel = SysCtrlRegs.PLLSTS.bit.DIVSEL;\n"
        "    pll_div = SysCtrlRegs.PLLCR.bit.DIV;\n"
        f"{_TICK_VECTOR}"
        "    EDIS;\n"
        f"{TIMER0_1MS}"
        "    for (;;) {}\n"
        "}\n"
        "interrupt void tick(void) { ticks++; PieCtrlRegs.PIEACK.all = PIEACK_GROUP1; }\n",
    )
    fw = build_firmware([src], tmp_path / "pll.so")
    until = 0.0205
    run, _ = _run(fw, tmp_path, until, ticks="uint16", divsel="uint16", pll_div="uint16")
    lock_s = 131072 / OSCCLK_HZ
    assert (run.final["divsel"], run.final["pll_div"]) == (2, 5)
    # The timer starts a few µs after the lock: whole 2 ms periods in what is left.
    assert run.final["ticks"] == int((until - lock_s) / 2e-3) == 8


def test_the_stop_message_names_the_interrupt_involved(tmp_path: Path):
    """SPIRXINTA enabled in the PIE and in SPI-A, but IER lacks INT6: the loop that waits for it is
    named with SPIRXINTA's INT6, not timer 0's INT1."""
    src = _source(
        tmp_path,
        "Uint16 done;\n"
        "interrupt void rx(void) { done = 1; }\n"
        "void main(void) {\n"
        "    InitSysCtrl();\n"
        "    DINT;\n"
        "    InitPieCtrl();\n"
        "    InitPieVectTable();\n"
        "    EALLOW;\n"
        "    PieVectTable.SPIRXINTA = &rx;\n"
        "    EDIS;\n"
        "    SpiaRegs.SPICTL.all = 0x0017;\n"
        "    PieCtrlRegs.PIEIER6.bit.INTx1 = 1;\n"
        "    EINT;\n"
        "    for (;;) {}\n"
        "}\n",
    )
    fw = build_firmware([src], tmp_path / "ier.so")
    named = r"IER has INT6 \(M_INT6, the CPU interrupt of SPIRXINTA\) clear"
    with pytest.raises(FirmwareStopped, match=named):
        _run(fw, tmp_path, 0.01, done="uint16")


def test_a_cpu_timer_with_its_clock_gated_off_stands_still(tmp_path: Path):
    """PCLKCR3.CPUTIMER0ENCLK (bit 8) gates CPU timer 0's clock (SPRUFB0; CPU timers count SYSCLKOUT):
    with it off for 5 ms the counter holds, no tick comes, and it goes on from where it stood, so the
    run counts 5 ms of ticks fewer (1 ms periods: 20 in 20.5 ms, 15 with the gate)."""
    src = _source(
        tmp_path,
        "interrupt void tick(void);\n"
        "volatile Uint16 ticks;\n"
        "Uint16 ticks_gated;\n"
        "void main(void) {\n"
        "    InitSysCtrl();\n"
        f"{_TICK_VECTOR}"
        "    EDIS;\n"
        f"{TIMER0_1MS}"
        "    while (ticks < 3) {}\n"
        "#ifdef GATE\n"
        "    EALLOW;\n"
        "    SysCtrlRegs.PCLKCR3.bit.CPUTIMER0ENCLK = 0;\n"
        "    EDIS;\n"
        "#endif\n"
        "    DELAY_US(5000);\n"
        "    ticks_gated = ticks;\n"
        "    EALLOW;\n"
        "    SysCtrlRegs.PCLKCR3.bit.CPUTIMER0ENCLK = 1;\n"
        "    EDIS;\n"
        "    for (;;) {}\n"
        "}\n"
        "interrupt void tick(void) { ticks++; PieCtrlRegs.PIEACK.all = PIEACK_GROUP1; }\n",
    )
    until = 0.0205
    free, _ = _run(
        build_firmware([src], tmp_path / "free.so"), tmp_path, until, ticks="uint16", ticks_gated="uint16"
    )
    gated, _ = _run(
        build_firmware([src], tmp_path / "gated.so", defines=["GATE"]),
        tmp_path,
        until,
        ticks="uint16",
        ticks_gated="uint16",
    )
    assert (free.final["ticks_gated"], free.final["ticks"]) == (8, 20)
    assert (gated.final["ticks_gated"], gated.final["ticks"]) == (3, 15)
