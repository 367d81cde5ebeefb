"""The link-kind registry survives every build. Each link kind registers itself from its own file
under rust/core/src/bus/ (`inventory::submit!`), through linker sections that fat LTO or a cdylib
could drop; a dropped kind would make every profile placing a device on its link fail. Checked here
in the Python extension (built with the `dist` profile: fat LTO, one codegen unit) and in the C ABI
library `libsins_cabi.so` (a C program linked against it); the Rust tests check the rlib
(rust/core/tests/link_kinds.rs). The expected kinds are read from the sources, so a new kind is
expected without editing this file."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from conftest import build_cabi
from sins_fw.errors import ProfileError
from sins_fw.harness import new_emulator
from sins_fw.profile import MODEL_DIR, load_profile

ROOT = Path(__file__).resolve().parents[1]
CORE_SRC = ROOT / "rust" / "core" / "src"
#: A device on each of the non-SPI kinds (the reference board already has its SPI sensor).
I2C_AND_UART = """
[[board.devices]]
part = "HMC6343"
link = "i2c-a"
address = 0x19

[[board.devices]]
part = "GR-87"
link = "sci-a"
"""
NOWHERE = '\n[[board.devices]]\npart = "HMC6343"\nlink = "nowhere"\naddress = 0x19\n'


def _submitted_links() -> dict[str, list[str]]:
    """Kind name → its link names, from every `inventory::submit! { LinkKind { … } }` in the core's
    sources but the test-only modules (`tests*.rs`)."""
    kinds: dict[str, list[str]] = {}
    block = re.compile(
        r"inventory::submit!\s*\{\s*LinkKind\s*\{.*?name:\s*\"([^\"]+)\".*?links:\s*&\[([^\]]*)\]", re.S
    )
    for path in sorted(CORE_SRC.rglob("*.rs")):
        if path.name.startswith("tests"):
            continue
        for name, links in block.findall(path.read_text(encoding="utf-8")):
            kinds[name] = re.findall(r"\"([^\"]+)\"", links)
    assert {"spi", "i2c", "uart"} <= kinds.keys(), f"the source scan found {sorted(kinds)}"
    return kinds


def _all_links() -> list[str]:
    return sorted(link for links in _submitted_links().values() for link in links)


def _profile_file(tmp_path: Path, extra: str) -> Path:
    path = tmp_path / "board.toml"
    path.write_text((MODEL_DIR / "reference.toml").read_text(encoding="utf-8") + extra, encoding="utf-8")
    return path


def _expected_message(links: list[str]) -> str:
    return "expected one of " + ", ".join(f'"{link}"' for link in links)


def test_the_extension_registers_every_link_kind(tmp_path: Path):
    """An unknown link is refused with the registered links' names: all the sources submit."""
    with pytest.raises(ProfileError) as e:
        load_profile(_profile_file(tmp_path, NOWHERE))
    assert "board.devices[1].link" in str(e.value)
    assert _expected_message(_all_links()) in str(e.value)


def test_the_extension_builds_a_board_with_an_i2c_and_a_uart_device(tmp_path: Path):
    profile = load_profile(_profile_file(tmp_path, I2C_AND_UART))
    new_emulator(profile)  # builds every declared link through its registered kind


def _build_c(tmp_path: Path) -> Path:
    """A C program that creates a board from the profile its first argument names and prints the
    status and `sins_last_error()`, linked against this tree's libsins_cabi.so."""
    for tool in ("cargo", "cc"):
        if shutil.which(tool) is None:
            pytest.fail(f"`{tool}` not found: the README's set-up needs a Rust toolchain and a C compiler")
    build_cabi()
    libdir = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target")) / "release"
    src = tmp_path / "kinds.c"
    src.write_text(
        """#include <stdio.h>
#include "sins_fw.h"
int main(int argc, char **argv) {
    SinsBoard *b = NULL;
    int rc = (int)sins_board_new(argv[1], NULL, 0, &b);
    printf("%d %s\\n", rc, sins_last_error());
    sins_board_free(b);
    return 0;
}
""",
        encoding="utf-8",
    )
    exe = tmp_path / "kinds"
    include = ROOT / "rust" / "cabi" / "include"
    cc = ["cc", "-o", str(exe), str(src), f"-I{include}", f"-L{libdir}", "-lsins_cabi"]
    run = subprocess.run([*cc, f"-Wl,-rpath,{libdir}"], capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stderr
    return exe


def test_the_c_abi_library_registers_every_link_kind(tmp_path: Path):
    exe = _build_c(tmp_path)
    good = subprocess.run(
        [str(exe), str(_profile_file(tmp_path, I2C_AND_UART))], capture_output=True, text=True, check=True
    )
    assert good.stdout.strip() == "0", good.stdout
    bad_dir = tmp_path / "bad"
    bad_dir.mkdir()
    bad = subprocess.run(
        [str(exe), str(_profile_file(bad_dir, NOWHERE))], capture_output=True, text=True, check=True
    )
    assert bad.stdout.startswith("1 "), bad.stdout  # SINS_ERR_PROFILE
    assert _expected_message(_all_links()) in bad.stdout
