"""I2C-A and a 24LC256 EEPROM as the user's C firmware drives them (issue 39): a TI-style polled FIFO
firmware (firmware_c/examples/ti_style/i2c_eeprom) writes a page, acknowledge-polls the write cycle,
reads the page back with a repeated START, and addresses a part that is not there. The bus's timing is
derived from the modelled clocks: SYSCLKOUT 150 MHz / (IPSC + 1 = 15) = 10 MHz, SCL low (ICCL 10 + d 5)
and high (ICCH 5 + d 5) module clocks (SPRUG03), the 24LC256's tWR = 5 ms (data sheet maximum)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from conftest import write_globals
from sins_fw.firmware_build import build_firmware
from sins_fw.firmware_run import run_c_firmware
from sins_fw.profile import load_profile

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "firmware_c" / "examples" / "ti_style" / "i2c_eeprom" / "i2c_eeprom.c"

SYSCLKOUT_HZ = 150e6
T_MOD = 15 / SYSCLKOUT_HZ  # IPSC = 14
T_LOW = (10 + 5) * T_MOD  # 1.5 µs
T_HIGH = (5 + 5) * T_MOD  # 1.0 µs
PERIOD = T_LOW + T_HIGH  # 2.5 µs: 400 kHz
T_BUF = 1.3e-6  # fast mode's bus-free time (i2c.md)
T_WR = 5e-3
#: One NACKed attempt on the bus: tBUF, START hold (a high phase), the address byte (nine periods),
#: the STOP (a low and a high phase): 27.3 µs.
ATTEMPT = T_BUF + T_HIGH + 9 * PERIOD + PERIOD
#: The part looks at the control byte at the ninth SCL rise: tBUF + high + 8 periods + low after
#: the previous STOP.
LOOK = T_BUF + T_HIGH + 8 * PERIOD + T_LOW

GLOBALS = {
    "polls": "uint16",
    "poll_cycles": "uint32",
    "matched": "uint16",
    "first_read": "uint16",
    "absent_nack": "uint16",
    "done": "uint16",
}

pytestmark = pytest.mark.usefixtures("cabi_library")


def _run(tmp_path: Path, profile: str = "i2c_eeprom") -> tuple[Any, list[dict[str, Any]]]:
    fw = build_firmware([EXAMPLE], tmp_path / "i2c.so")
    parts: list[dict[str, Any]] = []
    run = run_c_firmware(
        fw,
        None,
        load_profile(profile),
        globals_file=write_globals(tmp_path, **GLOBALS),
        until_s=0.008,
        sink=parts.append,
    )
    return run, [e for p in parts for e in p["events"]]


def test_a_page_written_acknowledge_polled_and_read_back(tmp_path: Path):
    run, events = _run(tmp_path)
    f = run.final
    assert f["done"] == 1
    assert (f["matched"], f["first_read"]) == (8, 0xA5)
    # Polls: each attempt takes at least its bus time, so no more than the write cycle holds; the
    # part answers at the first look after tWR, so the polling lasts tWR to tWR + one attempt (plus
    # the CPU's time per attempt, measured by timer 2 below).
    assert f["polls"] <= -(-(T_WR - LOOK) // ATTEMPT)  # 183
    poll_s = f["poll_cycles"] / SYSCLKOUT_HZ
    per_attempt = poll_s / (f["polls"] + 1)
    assert per_attempt >= ATTEMPT - T_BUF  # the first attempt's tBUF has passed during the write's STOP
    assert T_WR <= poll_s <= T_WR + 2 * per_attempt
    assert f["polls"] >= (T_WR - LOOK) / per_attempt - 1
    # The NACKs of a present part in its write cycle are no event; the absent address is, once.
    assert f["absent_nack"] == 1
    nacks = [e for e in events if e["kind"] == "i2c_nack"]
    assert len(nacks) == 1 and "0x51" in nacks[0]["message"], nacks
    assert not [e for e in events if e["kind"] in ("i2c_misuse", "eeprom_page_wrap")], events[:3]


def test_without_the_eeprom_in_the_profile_every_address_is_nacked(tmp_path: Path):
    """The reference profile places no part on I2C-A: the write's address is NACKed and the firmware,
    which waits for SCD after it, goes on to acknowledge polling that never ends."""
    run, events = _run(tmp_path, "reference")
    assert run.final["done"] == 0
    assert run.final["matched"] == 0
    nacks = [e for e in events if e["kind"] == "i2c_nack"]
    assert [("0x50" in e["message"]) for e in nacks] == [True]
