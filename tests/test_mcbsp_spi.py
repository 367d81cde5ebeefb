"""McBSP-A in SPI (clock-stop) mode with digital loopback (issue 39): a TI-style polled firmware
(firmware_c/examples/ti_style/mcbsp_spi_loopback) sends words of 8, 16 and 32 bits, each coming back
in DRR with RRDY. The word's time is derived from the modelled clocks (rust/core/src/dsp/mcbsp.rs):
LSPCLK = 150 MHz / 4, CLKG = LSPCLK / (CLKGDV + 1 = 16), a word is XDATDLY (1) + its bits CLKG periods,
started at the next CLKG edge after the DXR1 write."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from conftest import run_alone
from sins_fw.firmware_build import build_firmware

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "firmware_c" / "examples" / "ti_style" / "mcbsp_spi_loopback" / "mcbsp_spi_loopback.c"
CLKG_S = 16 / 37.5e6
UNTIL_S = 0.01
#: The CPU's time per loop, at most: the loop's register accesses and compare are a few tens of
#: SYSCLKOUT cycles; 2 µs (300 cycles) bounds it.
CPU_S = 2e-6

pytestmark = pytest.mark.usefixtures("cabi_library")


def _run(tmp_path: Path, size: int, *defines: str) -> tuple[Any, list[dict[str, Any]]]:
    fw = build_firmware([EXAMPLE], tmp_path / f"mcbsp{size}.so", defines=[f"WORD_SIZE={size}", *defines])
    return run_alone(
        fw,
        tmp_path,
        UNTIL_S,
        loops="uint16",
        errors="uint16",
        sdata1="uint16",
        rdata1="uint16",
        rdata2="uint16",
        sent="uint16",
        rx_isr="uint16",
    )


@pytest.mark.parametrize("size", [8, 16, 32])
def test_words_come_back_through_the_loopback_at_the_clocks_rate(tmp_path: Path, size: int):
    run, events = _run(tmp_path, size)
    f = run.final
    assert f["errors"] == 0
    word_s = (1 + size) * CLKG_S
    # Each loop waits for its word (one more CLKG period at most for the edge it starts on).
    assert UNTIL_S / (word_s + CLKG_S + CPU_S) - 1 <= f["loops"] <= UNTIL_S / word_s
    last = (int(f["sdata1"]) - 1) & 0xFFFF
    assert f["rdata1"] == (last & 0xFF if size == 8 else last)
    if size == 32:
        assert f["rdata2"] == (0xFFFF - last) & 0xFFFF
    assert not [e for e in events if e["severity"] == "error"], events[:3]


@pytest.mark.parametrize("size", [8, 16, 32])
def test_the_receive_interrupt_takes_every_word(tmp_path: Path, size: int):
    """With -DUSE_INTERRUPTS MRINTA (INT6.5, raised when RRDY rises) runs once per word: its ISR reads
    and checks the word and sends the next, main only idles. A word ends (1 + size) CLKG periods after
    the CLKG edge that follows the ISR's DXR1 write (at most one CLKG period and the ISR's CPU time,
    entry included, after the previous word's end), so the ISR runs between UNTIL/(word + CLKG + CPU)
    − 1 and UNTIL/word times; every word sent but the one in flight came back to it."""
    run, events = _run(tmp_path, size, "USE_INTERRUPTS")
    f = run.final
    word_s = (1 + size) * CLKG_S
    assert f["errors"] == 0
    assert UNTIL_S / (word_s + CLKG_S + CPU_S) - 1 <= f["rx_isr"] <= UNTIL_S / word_s
    assert f["loops"] == f["rx_isr"], "each ISR run took one word, right"
    assert f["sent"] - f["rx_isr"] in (0, 1), "no word lost: only the one in flight is not yet received"
    assert not [e for e in events if e["kind"] == "interrupt_never_raised"], events[:3]
    assert not [e for e in events if e["severity"] == "error"], events[:3]
