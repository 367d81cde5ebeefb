"""The board driven register by register from Python (issue 3's scripting API), and the word
encoding API, against validation.md's vectors."""

from __future__ import annotations

import pytest

from sins_fw import adis16407
from sins_fw.board import Board
from sins_fw.errors import RegisterError, TraceError

STALL = 40e-6  # frames outside a burst: ≥ tDATARATE (40 µs first edge to first edge; t_STALL is 9 µs)
BURST_GAP = 2e-6  # > one SCLK period (1.333 µs at 0.75 MHz) inside a burst


@pytest.mark.parametrize(
    ("channel", "word", "value", "range_dps"),
    [
        ("gyro", 0x1770, 300.0, 300),
        ("gyro", 0x0001, 0.05, 300),
        ("gyro", 0x3FFF, -0.05, 300),
        ("gyro", 0x3FFE, -0.10, 300),
        ("gyro", 0x2890, -300.0, 300),
        ("gyro", 0xF9DA, -19.675, 75),
        ("accel", 0x1519, 18.0, 300),
        ("accel", 0x2AE7, -18.0, 300),
        ("supply", 0x0814, 5.0, 300),
        ("supply", 0x07AC, 4.75, 300),
        ("supply", 0x087B, 5.25, 300),
        ("temp", 0x0000, 25.0, 300),
    ],
)
def test_validation_vectors(channel, word, value, range_dps):
    d = adis16407.decode(channel, word, range_dps)
    assert d.value == pytest.approx(value, abs=5e-4 * max(1.0, abs(value)))
    assert adis16407.encode(channel, d.value, range_dps).word == word & 0x3FFF


def test_published_supply_frame_has_nd_and_ea():
    d = adis16407.decode("supply", 0xC7A7)
    assert d.value == pytest.approx(4.737, abs=5e-4)
    assert d.nd and d.ea


def test_saturation_is_flagged():
    assert adis16407.encode("gyro", 500.0) == (0x1FFF, True)
    assert adis16407.encode("gyro", 300.0) == (0x1770, False)


def test_bad_channel_and_range_are_input_errors():
    with pytest.raises(TraceError, match="expected one of gyro"):
        adis16407.encode("gyros", 1.0)
    with pytest.raises(TraceError, match="300, 150 or 75"):
        adis16407.decode("gyro", 0, 200)


def _board(*overrides: str) -> Board:
    b = Board("reference", overrides)
    b.init_spi()
    b.advance(0.01)  # some device samples
    return b


def test_prod_id_via_a_two_frame_read():
    b = _board()
    b.set_gpio57(False)
    b.transfer(0x5600, stall_s=STALL)  # read PROD_ID (address 0x56)
    assert b.transfer(0x0000, stall_s=STALL) == 0x4017
    b.set_gpio57(True)
    assert b.take_events() == []


def _burst(b: Board, gap: float) -> list[int]:
    b.set_gpio57(False)
    words = [b.transfer(0x4200 if i == 0 else 0, stall_s=gap) for i in range(15)]
    b.set_gpio57(True)
    return words


def test_burst_read_gives_the_published_supply_frame():
    b = _board()
    b.set_physical([10.0, 0.0, 0.0], [0.0, 0.0, 1.0], supply_v=4.737)
    b.advance(0.005)
    words = _burst(b, BURST_GAP)
    assert words[1] == 0xC7A7  # 4.737 V < 4.75 V sets a DIAG_STAT flag: EA in every word
    assert words[2] == 0xC000 | 200  # +10 °/s
    # The only event: the supply below the DIAG_STAT limit (once, at the first sample); no SPI rule broken.
    events = b.take_events()
    assert [(e["kind"], e["measured"], e["required"]) for e in events] == [
        ("supply_out_of_range", 4.737, 4.75)
    ]
    frames = [r for r in b.take_log() if r["type"] == "frame"]
    assert frames[-15]["din"] == 0x4200


def test_frames_too_close_break_the_stall_rule_and_read_corrupt_in_strict_mode():
    b = _board()
    words = _burst(b, 0.0)
    kinds = {e["kind"] for e in b.take_events()}
    assert "stall_too_short" in kinds
    assert 0xFFFF in words[2:]


@pytest.mark.parametrize(("spiccr", "spictl"), [(0x8F, 0x07), (0x8F, 0x0F), (0xCF, 0x0F)])
def test_the_other_clock_schemes_read_wrong_words_at_bit_level(spiccr, spictl):
    b = _board(f"spi.spiccr={spiccr}", f"spi.spictl={spictl}", "spi.level=bit")
    b.set_physical([10.0, 0.0, 0.0], [0.0, 0.0, 1.0], supply_v=4.737)
    b.advance(0.005)
    words = _burst(b, BURST_GAP)
    assert words[1] != 0xC7A7


def test_unknown_register_names_the_allowed_ones():
    b = _board()
    with pytest.raises(RegisterError, match="SPITXBUF"):
        b.write("SPITX", 1)
