"""The Python Board as a third-party driver author uses it (issue 20, item 6): the profile's errors and
faults, SCLK and SPI mode asked for directly, LOSPCP, absolute time, the CS hold time, checked values,
overrides as a string, events tied to their frames."""

from __future__ import annotations

import pytest

from sins_fw.board import Board
from sins_fw.errors import ConfigError, ProfileError, RegisterError, TraceError

STALL = 40e-6  # ≥ tDATARATE between normal frames
BURST_GAP = 2e-6  # > one SCLK period at 0.75 MHz inside a burst
T_SFS = 48.8e-9  # ADIS16407 last SCLK edge to CS↑ (profile device.t_sfs_ns)


def _board(*overrides: str) -> Board:
    b = Board("reference", overrides)
    b.init_spi()
    b.set_physical([0.0, 0.0, 0.0], [0.0, 0.0, 1.0])
    b.advance(0.01)
    return b


def _burst(b: Board, gap: float = BURST_GAP) -> list[int]:
    b.set_gpio57(False)
    words = [b.transfer(0x4200 if i == 0 else 0, stall_s=gap) for i in range(15)]
    b.set_gpio57(True)
    return words


def _read(b: Board, address: int) -> int:
    b.set_gpio57(False)
    b.transfer(address << 8, stall_s=STALL)
    word = b.transfer(0x0000, stall_s=STALL)
    b.set_gpio57(True)
    return word


# --- errors.* and faults.* ------------------------------------------------------------------------


def test_the_error_model_of_the_profile_reaches_the_words():
    ideal = _burst(_board())
    assert [w & 0x3FFF for w in ideal[2:5]] == [0, 0, 0]  # a still, ideal gyro reads exactly 0
    real = _burst(_board("errors.preset=adis16407"))
    assert [w & 0x3FFF for w in real[2:5]] != [0, 0, 0]
    # Same profile, same seed: the same words.
    assert _burst(_board("errors.preset=adis16407")) == real


def test_a_profile_fault_is_injected():
    fault = 'faults.list=[{kind="diag_flags", flags=8, start_s=0.005}]'
    b = _board(fault)
    words = _burst(b)
    assert all(w & 0x4000 for w in words[1:])  # EA in every output word
    assert _read(b, 0x40) & 0x8 == 0x8  # DIAG_STAT carries the flag
    assert "fault_injected" in {e["kind"] for e in b.take_events()}


def test_a_dropped_burst_fault_is_refused_with_the_reason():
    with pytest.raises(ConfigError, match=r"dropped_burst.*no firmware"):
        Board("reference", 'faults.list=[{kind="dropped_burst", start_s=0.0}]')


# --- SCLK in Hz, SPI mode, LOSPCP -----------------------------------------------------------------


def test_sclk_is_exact_or_the_nearest_below():
    b = _board()
    exact = b.configure_spi(sclk_hz=750e3)
    assert (exact["spibrr"], exact["sclk_hz"], exact["exact"]) == (49, 750e3, True)
    below = b.configure_spi(sclk_hz=1e6)  # 37.5 MHz / 38 = 986.8 kHz; /37 would be 1.0135 MHz
    assert (below["spibrr"], below["exact"]) == (37, False)
    assert below["sclk_hz"] == pytest.approx(37.5e6 / 38)
    assert b.read("SPIBRR") == 37
    assert _read(b, 0x56) == 0x4017


def test_spi_mode_sets_polarity_and_phase():
    b = _board()
    for mode, ccr_pol, ctl_phase in [(0, 0, 1), (1, 0, 0), (2, 1, 1), (3, 1, 0)]:
        assert b.configure_spi(mode=mode)["mode"] == mode
        assert (b.read("SPICCR") >> 6 & 1, b.read("SPICTL") >> 3 & 1) == (ccr_pol, ctl_phase)
        assert b.read("SPICCR") & 0x80  # released again
    with pytest.raises(ConfigError, match="SPI mode 5: expected 0…3"):
        b.configure_spi(mode=5)


def test_100_khz_needs_lospcp_and_says_so():
    b = _board()
    with pytest.raises(ConfigError, match=r"SPIBRR would have to be 374 .*raise LOSPCP \(now 2\)"):
        b.configure_spi(sclk_hz=100e3)
    b.write("LOSPCP", 6)  # 150 MHz / 12 = 12.5 MHz
    assert b.lspclk_hz == 12.5e6
    set_ = b.configure_spi(sclk_hz=100e3)
    assert (set_["spibrr"], set_["sclk_hz"], set_["exact"]) == (124, 100e3, True)
    assert _read(b, 0x56) == 0x4017
    frame = [r for r in b.take_log() if r["type"] == "frame"][-1]
    assert frame["end_s"] - frame["start_s"] == pytest.approx(16 / 100e3, abs=1e-12)


def test_lospcp_under_a_character_is_refused():
    b = _board()
    b.set_gpio57(False)
    b.write("SPITXBUF", 0x5600)
    with pytest.raises(RegisterError, match=r"LOSPCP.*character"):
        b.write("LOSPCP", 6)


# --- time -----------------------------------------------------------------------------------------


def test_advance_to_is_absolute_and_rounding_residues_are_no_step():
    b = Board("reference")
    b.advance_to(0.5)
    assert b.now_s == 0.5
    b.advance(-1e-16)  # a float rounding residue (0.0001 ps)
    b.advance_to(0.5 - 1e-13)
    assert b.now_s == 0.5
    b.advance_to(0.5 + 0.1)
    assert b.now_s == 0.6


def test_a_real_step_back_is_refused_clearly():
    b = Board("reference")
    b.advance_to(0.5)
    with pytest.raises(TraceError, match="only moves forward"):
        b.advance(-1e-6)
    with pytest.raises(TraceError, match=r"advance_to\(0.1.*at 0.5.*only moves forward"):
        b.advance_to(0.1)


@pytest.mark.parametrize("mode", [0, 1, 2, 3])
def test_transfer_returns_after_the_cs_hold_time_in_every_mode(mode):
    b = _board("device.timing_mode=lenient")
    b.configure_spi(mode=mode)
    b.set_gpio57(False)
    b.transfer(0x5600, stall_s=STALL)
    b.set_gpio57(True)  # at once, as a driver does after transfer()
    frame = [r for r in b.take_log() if r["type"] == "frame"][-1]
    if mode in (0, 2):
        # With delay, INT_FLAG comes at the last SCLK edge: returning then would break tSFS.
        assert frame["end_s"] - frame["last_edge_s"] < T_SFS
    assert "cs_hold" not in {e["kind"] for e in b.take_events()}


# --- checked values, overrides as a string --------------------------------------------------------


def test_out_of_range_values_name_register_and_value():
    b = _board()
    with pytest.raises(RegisterError, match=r"SPITXBUF = 131071 \(0x1FFFF\): expected 0…0xFFFF"):
        b.write("SPITXBUF", 0x1FFFF)
    with pytest.raises(RegisterError, match=r"SPICCR = -1 \(-0x1\)"):
        b.write("SPICCR", -1)
    with pytest.raises(RegisterError, match=r"address 256 \(0x100\): expected 0…0x7F"):
        b.peek_device(256)
    with pytest.raises(RegisterError, match=r"SPITXBUF = 65536"):
        b.transfer(0x10000)
    with pytest.raises(RegisterError, match="C28x address 0x7043: no modelled register"):
        b.read_address(0x7043)


def test_one_override_may_be_a_string():
    b = Board("reference", "spi.spibrr=9")
    assert b.profile.overrides == ("spi.spibrr=9",)
    b.init_spi()
    assert b.read("SPIBRR") == 9
    with pytest.raises(ProfileError, match="spibrr"):
        Board("reference", "spibrr")


def test_gpio57_goes_through_the_gpio_data_registers():
    b = _board()
    assert b.read("GPBDAT") >> 25 & 1 == 1
    b.write("GPBCLEAR", 1 << 25)
    assert b.read("GPBDAT") >> 25 & 1 == 0
    assert b.read("GPBCLEAR") == 0  # reads 0, as on the chip
    assert [r["low"] for r in b.take_log() if r["type"] == "cs"] == [True]


# --- events tied to frames ------------------------------------------------------------------------


def test_events_carry_their_frame_index_and_din():
    b = _board()
    _burst(b, gap=0.0)  # frames too close: stall_too_short
    frames = {r["index"]: r["din"] for r in b.take_log() if r["type"] == "frame"}
    stalls = [e for e in b.take_events() if e["kind"] == "stall_too_short"]
    assert stalls
    for e in stalls:
        assert e["frame"] in frames and e["din"] == frames[e["frame"]]
    assert stalls[0]["din"] == 0  # the first data frame after the 0x4200 command
