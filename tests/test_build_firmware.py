"""`sins-fw build-firmware` (issue 20, item 1, its foundation): a user's F28335 C firmware written
against TI's DSP2833x headers, compiled unmodified for the host against the replacement headers, run
against the emulated board. Issue 37's C-as-C build and TI's project layout: test_build_ti_projects.py."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

from sins_fw.cli import main
from sins_fw.errors import ConfigError, InputError
from sins_fw.firmware_build import build_firmware
from sins_fw.firmware_paths import CABI_HEADER, CABI_LIBRARY, FIRMWARE_C, PACKAGE, cabi_dirs
from sins_fw.firmware_run import run_c_firmware
from sins_fw.profile import load_profile

ROOT = Path(__file__).resolve().parents[1]
PROD_ID_EXAMPLE = ROOT / "firmware_c" / "examples" / "prod_id"


pytestmark = pytest.mark.usefixtures("cabi_library")


def test_the_prod_id_firmware_reads_0x4017(tmp_path: Path, capsys: pytest.CaptureFixture[str]):
    out = tmp_path / "fw.so"
    assert main(["build-firmware", str(PROD_ID_EXAMPLE), "-o", str(out)]) == 0
    assert f"built {out}" in capsys.readouterr().out
    watched = _globals(tmp_path, "prod_id", "reads")
    run = run_c_firmware(out, None, load_profile("reference"), globals_file=watched, until_s=0.05)
    assert run.final["prod_id"] == 0x4017
    # After the 10 ms start-up delay each loop takes 1000 + 40 µs of DELAY_US plus two 16-bit frames at
    # 0.75 MHz (2 × 21.3 µs) and the polling: ≈ 1.083 ms, so 40 ms hold 36 whole loops and most of a 37th.
    assert run.final["reads"] in (36, 37)
    # The run stops before the step that would pass the input's end (a still board whose input reaches
    # until_s = 0.05 s itself), here a DELAY_US(1000).
    assert 0.05 - 1.1e-3 < run.now_s <= 0.05
    assert run.accesses > 100


def test_a_bit_field_store_is_a_read_modify_write_of_the_word(tmp_path: Path):
    src = tmp_path / "rmw.c"
    src.write_text(
        '#include "DSP2833x_Device.h"\n'
        "Uint16 ccr, ctl, lospcp;\n"
        "void main(void) {\n"
        "    SpiaRegs.SPICCR.all = 0x004F;\n"
        "    SpiaRegs.SPICCR.bit.SPISWRESET = 1;\n"
        "    ccr = SpiaRegs.SPICCR.all;\n"
        "    SpiaRegs.SPICTL.all = 0x0006;\n"
        "    SpiaRegs.SPICTL.bit.CLK_PHASE = 1;\n"
        "    SpiaRegs.SPICTL.bit.TALK = 0;\n"
        "    ctl = SpiaRegs.SPICTL.all;\n"
        "    EALLOW;\n"
        "    SysCtrlRegs.LOSPCP.bit.LSPCLK = 6;\n"
        "    EDIS;\n"
        "    lospcp = SysCtrlRegs.LOSPCP.all;\n"
        "}\n"
    )
    fw = build_firmware([src], tmp_path / "rmw.so")
    run = run_c_firmware(
        fw,
        None,
        load_profile("reference"),
        globals_file=_globals(tmp_path, "ccr", "ctl", "lospcp"),
        until_s=1.0,
    )
    assert (run.final["ccr"], run.final["ctl"], run.final["lospcp"]) == (0xCF, 0x0C, 6)
    assert run.now_s < 2e-6  # main returned: 14 accesses of 3 cycles and a few blocks at 150 MHz


def test_a_source_that_does_not_compile_names_file_and_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
):
    src = tmp_path / "bad.c"
    src.write_text(
        '#include "DSP2833x_Device.h"\nvoid main(void) {\n    CpuTimer1Regs.TCR.bit.TSSX = 1;\n}\n'
    )
    out = tmp_path / "fw.so"
    assert main(["build-firmware", str(src), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "bad.c:3" in err and "TSSX" in err
    assert not out.exists()
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(InputError, match="no C sources"):
        build_firmware([empty], tmp_path / "x.so")


def _globals(folder: Path, *names: str) -> Path:
    """A globals file watching Uint16 globals."""
    path = folder / "globals.toml"
    path.write_text(
        "".join(f'[[global]]\nname = "{n}"\ntype = "uint16"\ncolumn = "{n}"\nunit = "1"\n' for n in names)
    )
    return path


def test_the_c_abi_library_is_found_in_an_installed_package(tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    """A wheel ships libsins_cabi.so and sins_fw.h in the package's `cabi` folder; outside a source
    tree that is where build-firmware takes them from (no Rust toolchain needed)."""
    monkeypatch.delenv("SINS_FW_CABI_DIR", raising=False)
    site = tmp_path / "site-packages"
    package = site / "sins_fw"
    (package / "cabi").mkdir(parents=True)
    with pytest.raises(
        ConfigError, match=r"sins_fw/cabi/libsins_cabi\.so: the C ABI library is missing \(the installed"
    ):
        cabi_dirs(site, package)
    for name in (CABI_LIBRARY, CABI_HEADER):
        (package / "cabi" / name).write_bytes(b"")
    assert cabi_dirs(site, package) == (package / "cabi", package / "cabi")


def test_in_a_source_tree_the_c_abi_library_is_cargos(tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    """In the repository, cargo's build is taken (never a copy a wheel build left in the package), and
    SINS_FW_CABI_DIR overrides both."""
    monkeypatch.delenv("SINS_FW_CABI_DIR", raising=False)
    tree = tmp_path / "tree"
    (tree / "rust" / "cabi").mkdir(parents=True)
    (tree / "rust" / "cabi" / "Cargo.toml").write_text("")
    (tree / "python" / "sins_fw" / "cabi").mkdir(parents=True)
    (tree / "python" / "sins_fw" / "cabi" / CABI_LIBRARY).write_bytes(b"")
    target = tmp_path / "cargo-target" / "release"
    target.mkdir(parents=True)
    (target / CABI_LIBRARY).write_bytes(b"")
    monkeypatch.setenv("CARGO_TARGET_DIR", str(target.parent))
    assert cabi_dirs(tree, tree / "python" / "sins_fw") == (target, tree / "rust" / "cabi" / "include")
    own = tmp_path / "own"
    own.mkdir()
    (own / CABI_LIBRARY).write_bytes(b"")
    (own / CABI_HEADER).write_bytes(b"")
    monkeypatch.setenv("SINS_FW_CABI_DIR", str(own))
    assert cabi_dirs(tree, tree / "python" / "sins_fw") == (own, own)


def test_the_wheel_ships_what_build_firmware_needs():
    """pyproject's wheel includes name the package folders build-firmware reads (the replacement
    headers, the runtime, TI's replacements, the C ABI library and header), and the package's
    firmware_c is the repository's (a link in the source tree)."""
    include = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["maturin"]["include"]
    shipped = {Path(i["path"]).parent for i in include if i["format"] == "wheel"}
    package = Path("python") / "sins_fw"
    for folder in ("firmware_c/include", "firmware_c/runtime", "firmware_c/pass", "firmware_c/ti", "cabi"):
        assert package / folder in shipped, folder
    assert (ROOT / "firmware_c").resolve() == FIRMWARE_C and (ROOT / package).resolve() == PACKAGE
    assert (FIRMWARE_C / "runtime" / "sins_fw_runtime.cpp").is_file()
