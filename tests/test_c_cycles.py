"""The C28x cycle model of host-built firmware (issue 38): the build's LLVM pass prices every basic
block of the optimised IR at compile time (firmware_c/pass/sins_fw_pass.cpp, SinsFwCyclePass) from
firmware_model/c28x-c-costs.toml and the profile's c28x-costs.toml, and the runtime charges it and
counts each function's own cycles (docs/c-cycles.md)."""

from __future__ import annotations

import os
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest

from conftest import build_cabi
from sins_fw.firmware_build import CLANG, block_costs, build_firmware, pass_plugin
from sins_fw.firmware_run import run_c_firmware
from sins_fw.profile import load_profile

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = ROOT / "firmware_c" / "examples" / "reference"
STATIC = ROOT / "traces" / "static_60s.h5"

SOURCE = """
float g;
float f(float a, float b) { return a * b + g / b; }
void idle(void) { for (;;) {} }
"""


def _ir(tmp_path: Path, float_mode: str) -> str:
    src = tmp_path / "t.c"
    src.write_text(SOURCE, encoding="utf-8")
    env = {
        **os.environ,
        "SINS_FW_PASS_C28X_FLOAT": "1" if float_mode == "c28x" else "0",
        "SINS_FW_PASS_COSTS": ",".join(f"{k}={v}" for k, v in block_costs(None).items()),
    }
    run = subprocess.run(
        [
            CLANG,
            "-O1",
            "-ffp-contract=off",
            f"-fpass-plugin={pass_plugin()}",
            "-S",
            "-emit-llvm",
            str(src),
            "-o",
            "-",
        ],
        capture_output=True,
        text=True,
        env=env,
        check=True,
    )
    return run.stdout


@pytest.mark.parametrize("float_mode", ["host", "c28x"])
def test_a_block_is_priced_from_the_two_tables(tmp_path: Path, float_mode: str):
    """f's one block: a load of g, a division, a multiplication, an addition and the return, at the
    cost table's float prices and the C table's load and return: the same sum in both float modes
    (the c28x mode's calls to the c28x-f32 backend are priced as the operations they stand for)."""
    p = block_costs(None)
    ir = _ir(tmp_path, float_mode)
    want = p["load"] + p["data_wait"] + p["float.div"] + p["float.mul"] + p["float.add"] + p["ret"]
    m = re.search(r"define [^@]*@f\(.*?\n\s*call void @sins_fw_enter\(i32 (\d+),", ir)
    assert m is not None, ir
    assert int(m.group(1)) == want == 1 + 0 + 24 + 3 + 3 + 8
    # The empty endless loop calls sins_fw_idle with its pass: one unconditional branch.
    assert f"call void @sins_fw_idle(i32 {p['branch']})" in ir


def test_a_price_that_is_not_cycles_is_named(tmp_path: Path):
    from sins_fw.errors import ProfileError

    table = (
        (ROOT / "firmware_model" / "c28x-costs.toml")
        .read_text(encoding="utf-8")
        .replace("div = 24", "div = 2.5")
    )
    (tmp_path / "costs.toml").write_text(table, encoding="utf-8")
    prof = load_profile(
        "reference", overrides=[f"timing.costs={str(tmp_path / 'costs.toml')!r}".replace("'", '"')]
    )
    with pytest.raises(ProfileError, match=r"costs.toml: key `float.div` = 2.5"):
        block_costs(prof)


def _run(fw: Path, out: Path) -> tuple[str, list[int]]:
    """The firmware's per-function cycles and its ISRs' end times over 0.2 s of the static trace."""
    os.environ["SINS_FW_FUNCTION_CYCLES"] = str(out)
    parts: list[dict] = []
    try:
        run_c_firmware(
            fw,
            STATIC,
            load_profile(
                "reference", overrides=["firmware.quat_derivative=published", "device.timing_mode=lenient"]
            ),
            globals_file=REFERENCE / "globals.toml",
            sink=parts.append,
            until_s=0.2,
        )
    finally:
        del os.environ["SINS_FW_FUNCTION_CYCLES"]
    return out.read_text(encoding="utf-8"), [int(t) for p in parts for t in p["budget_end_ps"]]


def test_same_input_same_library_same_counts(tmp_path: Path):
    """Built twice from the same sources and run: the same cycles per function and the same ISR
    times, and so again for a second run of the same library. The attitude update is charged its
    float operations (over a thousand cycles a call)."""
    build_cabi()
    a = build_firmware([REFERENCE], tmp_path / "a.so", float_mode="c28x")
    b = build_firmware([REFERENCE], tmp_path / "b.so", float_mode="c28x")
    first = _run(a, tmp_path / "1.tsv")
    assert _run(a, tmp_path / "2.tsv") == first
    assert _run(b, tmp_path / "3.tsv") == first
    rows = {line.split("\t")[0]: line.split("\t")[1:] for line in first[0].splitlines()}
    cycles, calls = (int(x) for x in rows["updateQ"])
    assert calls > 0 and cycles / calls > 1000


def test_the_reference_isr_takes_the_models_time(tmp_path: Path):
    """Calibration (issue 38): the reference C firmware (the published algorithm) and the Rust model on
    the static trace, c28x float in both, each ISR's time from entry to IRET. The issue's bounds: the
    whole ISR within ±10 % of the model's, and an update tick's (the attitude solution's) within ±15 %
    of the published 0.35 ms. Measured (2 s): 349.5 µs against the model's 347.7 µs on update ticks,
    329.0 against 334.5 on the others; the attitude update (updateQ) within ±15 % of the model's."""
    from sins_fw import emulate

    build_cabi()
    fw = build_firmware([REFERENCE], tmp_path / "ref.so", float_mode="c28x")
    overrides = [
        "firmware.quat_derivative=published",
        "firmware.numeric=c28x-f32",
        "device.timing_mode=lenient",
    ]
    parts: list[dict] = []
    os.environ["SINS_FW_FUNCTION_CYCLES"] = str(tmp_path / "fn.tsv")
    try:
        run_c_firmware(
            fw,
            STATIC,
            load_profile("reference", overrides=overrides),
            globals_file=REFERENCE / "globals.toml",
            sink=parts.append,
            until_s=0.2,
        )
    finally:
        del os.environ["SINS_FW_FUNCTION_CYCLES"]
    functions = {
        line.split("\t")[0]: [int(x) for x in line.split("\t")[1:]]
        for line in (tmp_path / "fn.tsv").read_text(encoding="utf-8").splitlines()
    }
    c_isr = (
        np.concatenate([p["budget_end_ps"].astype(np.int64) - p["budget_start_ps"] for p in parts]) * 1e-12
    )
    updates = np.concatenate([p["firmware_globals"]["updates"] for p in parts])
    c_update = np.diff(np.r_[0, updates]) > 0
    model = emulate(STATIC, "reference", overrides=overrides, until_s=0.2)
    b = model.budget
    m_isr = (b["end_ps"].astype(np.int64) - b["start_ps"].astype(np.int64)) * 1e-12
    m_update = (b["nav_end_ps"].astype(np.int64) - b["euler_end_ps"].astype(np.int64)) > 0
    assert c_update.sum() > 20 and m_update.sum() > 20 and (~c_update).sum() > 20
    for c, m in ((c_isr[c_update], m_isr[m_update]), (c_isr[~c_update], m_isr[~m_update])):
        assert abs(c.mean() / m.mean() - 1) <= 0.10
    assert abs(c_isr[c_update].mean() / 0.35e-3 - 1) <= 0.15
    # The attitude update: updateQ's own cycles a call against the model's attitude stage, ±15 %
    # (measured: 1347 cycles, 8.98 µs, against 8.25 µs).
    cycles, calls = functions["updateQ"]
    m_attitude = (b["attitude_end_ps"].astype(np.int64) - b["decode_end_ps"].astype(np.int64))[
        m_update
    ] * 1e-12
    assert abs(cycles / calls / 150e6 / m_attitude.mean() - 1) <= 0.15
