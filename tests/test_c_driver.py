"""The driver-author recipe (docs/c-drivers.md): a host-built C driver for the ADIS16407, written
against a three-function HAL (firmware_c/examples/adis_driver/), linked against the C ABI crate and
run against the emulated board, reads what the Python Board reads with the same calls."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

from conftest import build_cabi
from sins_fw.board import Board

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "firmware_c" / "examples" / "adis_driver"
STALL = 40e-6  # the driver's STALL_US
BURST_STALL = 2e-6  # the driver's BURST_STALL_US


def _build(out: Path, *make_vars: str) -> Path:
    """The example built as its Makefile builds it, against this tree's C ABI library."""
    for tool in ("cargo", "make", "cc", "g++"):
        if shutil.which(tool) is None:
            pytest.fail(
                f"`{tool}` not found: the README's set-up needs a Rust toolchain and a C/C++ compiler"
            )
    build_cabi()
    libdir = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target")) / "release"
    make = ["make", "-C", str(EXAMPLE), f"OUT={out}", f"LIBDIR={libdir}", *make_vars]
    run = subprocess.run(make, capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stdout + run.stderr
    return out


@pytest.fixture(scope="module")
def demo(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return _build(tmp_path_factory.mktemp("c_driver") / "adis_demo")


def _python_side(overrides: list[str]) -> list[str]:
    """The example's main.c, line for line, with the Python Board."""
    b = Board("reference", overrides)
    b.init_spi()
    b.set_physical([10.0, -5.0, 2.5], [0.0, 0.0, 1.0])
    b.advance(0.01)
    b.set_gpio57(False)
    b.transfer(0x5600, stall_s=STALL)
    prod_id = b.transfer(0x0000, stall_s=STALL)
    b.set_gpio57(True)
    lines = [f"PROD_ID 0x{prod_id:04X}"]
    b.set_gpio57(False)
    b.transfer(0x4200, stall_s=STALL)
    lines += [f"burst {i} 0x{b.transfer(0, stall_s=BURST_STALL):04X}" for i in range(14)]
    b.set_gpio57(True)
    for e in b.take_events():
        frame = -1 if e["frame"] is None else e["frame"]
        lines.append(f"event {e['kind']} {frame} 0x{e['din'] or 0:04X}")
    return lines


@pytest.mark.parametrize("overrides", [[], ["errors.preset=adis16407"], ["spi.spibrr=9"]])
def test_the_c_driver_reads_what_the_python_board_reads(demo: Path, overrides: list[str]):
    run = subprocess.run([str(demo), "reference", *overrides], capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stderr
    lines = run.stdout.splitlines()
    assert lines == _python_side(overrides)
    if overrides == ["spi.spibrr=9"]:
        # 3.75 MHz breaks the SCLK limit: strict timing corrupts the words, and the events reach C
        # with their frames.
        assert lines[0] == "PROD_ID 0xFFFF"
        assert any(line.startswith("event sclk_too_fast ") for line in lines)
    else:
        assert lines[0] == "PROD_ID 0x4017"


def test_an_emulator_error_reaches_the_c_program_as_a_message(demo: Path):
    run = subprocess.run([str(demo), "reference", "spi.spibrr"], capture_output=True, text=True, check=False)
    assert run.returncode == 2
    assert "spi.spibrr" in run.stderr


def test_the_same_driver_builds_and_runs_as_cpp(demo: Path, tmp_path: Path):
    cpp = _build(
        tmp_path / "adis_demo_cpp", "CC=g++", "CFLAGS=-x c++ -std=c++17 -Wall -Wextra -Werror -pedantic"
    )
    runs = [
        subprocess.run([str(x), "reference"], capture_output=True, text=True, check=True) for x in (demo, cpp)
    ]
    assert runs[0].stdout == runs[1].stdout
