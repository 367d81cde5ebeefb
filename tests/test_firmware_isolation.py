"""The user's firmware runs in a process of its own (issue 42, item 6; issue 37, items 3 and 4): a
crash, `abort()`, `exit()`, endless recursion or a crash in a static constructor is exit 2 naming the
signal and the firmware's file and line, with the summary, the events and the rows up to there
kept; Ctrl-C and SIGTERM reach the emulator (130/143, nothing half-written) even when the firmware
ignores them; an ISR that never returns is an error event; the firmware's stdout cannot corrupt
`--json`; a watched global the variable cannot hold is refused before anything runs. Each firmware
here is built by the project's own `build-firmware` from a few lines of C."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from conftest import build_cabi
from sins_fw import synth
from sins_fw.cli import main
from sins_fw.errors import InputError
from sins_fw.firmware_build import build_firmware
from sins_fw.firmware_child import BUS_RECORD
from sins_fw.firmware_run import FirmwareStopped, _Rows, run_c_firmware
from sins_fw.harness import _TruthWindow
from sins_fw.profile import load_profile
from sins_fw.run_output import firmware_run_schema, load_run
from sins_fw.tablefile import csv_lines

ROOT = Path(__file__).resolve().parents[1]
PITCH_SWEEP = ROOT / "python" / "sins_fw" / "bundled_traces" / "pitch_sweep.h5"

#: A timer-0 firmware (a tick every 4 ms) whose ISR counts `ticks` and, at tick 100, does ACTION;
#: main does MAIN before its loop, LOOP in it.
TEMPLATE = """#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
volatile Uint32 ticks;
volatile Uint32 spins;
Uint16 small;
Uint16 burst[15];
volatile int *volatile nowhere;
int deep(int n) {
    volatile int pad[64];
    pad[n & 63] = n;
    return deep(n + 1) + pad[0];
}
interrupt void isr(void) {
    ticks++;
    if (ticks == 100) {
        ACTION
    }
    PieCtrlRegs.PIEACK.all = PIEACK_GROUP1;
}
void main(void) {
    EALLOW;
    PieVectTable.TINT0 = &isr;
    EDIS;
    PieCtrlRegs.PIECTRL.bit.ENPIE = 1;
    CpuTimer0Regs.PRD.all = 599999;
    CpuTimer0Regs.TCR.all = 0x4020;
    IER |= M_INT1;
    PieCtrlRegs.PIEIER1.bit.INTx7 = 1;
    EINT;
    MAIN
    for (;;) {
        LOOP
    }
}
"""
#: The line of ACTION in TEMPLATE.
ACTION_LINE = TEMPLATE.splitlines().index("        ACTION") + 1
GLOBALS = '[[global]]\nname = "ticks"\ntype = "uint32"\ncolumn = "ticks"\nunit = "1"\n'


@pytest.fixture(scope="module", autouse=True)
def cabi() -> None:
    build_cabi()


@pytest.fixture(scope="module")
def plain(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The template with nothing added: timer ticks counted, nothing else."""
    return _build(tmp_path_factory.mktemp("plain"))


def _build(tmp_path: Path, action: str = "", main_code: str = "", loop: str = "", extra: str = "") -> Path:
    src = tmp_path / "fw.c"
    body = TEMPLATE.replace("ACTION", action).replace("MAIN", main_code).replace("LOOP", loop)
    src.write_text(body + extra)
    (tmp_path / "globals.toml").write_text(GLOBALS)
    return build_firmware([src], tmp_path / "fw.so")


def _cli(fw: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], *extra: str) -> tuple[int, str, str]:
    argv = ["run", str(PITCH_SWEEP), "--firmware", str(fw), "--until-s", "1", "--json", *extra]
    rc = main(argv)
    captured = capsys.readouterr()
    return rc, captured.out, captured.err


@pytest.mark.parametrize(
    ("action", "signal_name", "line"),
    [
        ("*nowhere = 1;", "SIGSEGV", ACTION_LINE),
        ("abort();", "SIGABRT", ACTION_LINE),
        ("ticks += deep(0);", "SIGSEGV", None),  # endless recursion: the stack overflows in deep()
    ],
)
def test_a_crash_in_an_isr_is_exit_2_naming_the_signal_and_line_with_the_rows_kept(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], action: str, signal_name: str, line: int | None
):
    fw = _build(tmp_path, action=action)
    out = tmp_path / "run.csv"
    old = b"an old file"
    out.write_bytes(old)
    rc, stdout, err = _cli(fw, tmp_path, capsys, "--out", str(out))
    assert rc == 2, err
    assert signal_name in err, err
    if line is not None:
        assert f"fw.c:{line} in isr" in err, err
    else:
        assert "fw.c:" in err and "in deep" in err, err
    # The summary and the 99 rows before the crash are kept and written.
    summary = json.loads(stdout)
    assert summary["firmware"]["isr_runs"] == summary["cycles"] == 99
    assert signal_name in summary["firmware"]["stopped"]
    meta, cols = load_run(out)
    assert meta["created_by"] == "sins-fw run --firmware"
    assert np.array_equal(cols["ticks"], np.arange(1, 100))
    # replay and report show the rows kept as recorded (not re-emulated: the Rust model does not
    # run a C firmware); tests/test_firmware_run_files.py checks what they show.
    for command, made in (
        (["replay", str(out), "--out", str(tmp_path / "r.rrd"), "--json"], tmp_path / "r.rrd"),
        (["report", str(out), "--out", str(tmp_path / "r.png"), "--json"], tmp_path / "r.png"),
    ):
        assert main(command) == 0
        shown = json.loads(capsys.readouterr().out)
        assert shown["rows"] == 99 and shown["re_emulated"] is False and made.is_file()


def test_exit_in_main_is_exit_2_naming_the_call(tmp_path: Path, capsys: pytest.CaptureFixture[str]):
    fw = _build(tmp_path, main_code="while (ticks < 50) {\n        spins++;\n    }\n    exit(0);")
    rc, stdout, err = _cli(fw, tmp_path, capsys)
    assert rc == 2
    assert "called exit(0)" in err and "fw.c:" in err and "in main" in err, err
    assert json.loads(stdout)["firmware"]["isr_runs"] == 50


def test_a_crash_in_a_static_constructor_is_exit_2_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
):
    fw = _build(
        tmp_path, extra="__attribute__((constructor)) static void boom(void) {\n    *nowhere = 2;\n}\n"
    )
    rc, _, err = _cli(fw, tmp_path, capsys)
    assert rc == 2
    assert "SIGSEGV" in err and "static constructors" in err and "in boom" in err, err


def test_the_api_raises_firmware_stopped_with_the_result_so_far(tmp_path: Path):
    fw = _build(tmp_path, action="abort();")
    parts: list[dict] = []
    with pytest.raises(FirmwareStopped, match="SIGABRT") as e:
        run_c_firmware(fw, PITCH_SWEEP, load_profile("reference"), sink=parts.append, until_s=1.0)
    assert e.value.result.isr_rows == sum(len(p["budget_tick"]) for p in parts) == 99
    assert isinstance(e.value, InputError)


def test_an_isr_that_never_returns_is_an_error_event_and_exit_1(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
):
    fw = _build(tmp_path, action="for (;;) {\n            DELAY_US(1000);\n        }")
    rc, stdout, err = _cli(fw, tmp_path, capsys)
    assert rc == 1, err
    assert "isr_not_returned" in err and "had not returned" in err, err
    summary = json.loads(stdout)
    assert summary["firmware"]["isr_runs"] == 99
    assert summary["events"]["by_kind"]["isr_not_returned"]["severity"] == "error"


def test_a_loop_without_exit_keeps_the_summary_events_and_rows(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
):
    fw = _build(tmp_path, main_code="while (ticks < 30) {\n        spins++;\n    }\n    DINT;")
    out = tmp_path / "run.csv"
    rc, stdout, err = _cli(fw, tmp_path, capsys, "--out", str(out))
    assert rc == 2
    assert "INTM is set" in err and "fw.c:" in err, err
    assert json.loads(stdout)["firmware"]["isr_runs"] == 30
    assert len(load_run(out)[1]["ticks"]) == 30


def test_the_firmwares_stdout_goes_to_stderr_not_into_json(tmp_path: Path):
    fw = _build(tmp_path, main_code='printf("hello from the firmware\\n");\n    fflush(stdout);')
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "sins_fw",
            "run",
            str(PITCH_SWEEP),
            "--firmware",
            str(fw),
            "--until-s",
            "0.1",
            "--json",
        ],
        capture_output=True,
        text=True,
        check=False,
    )
    assert run.returncode == 0, run.stderr
    assert json.loads(run.stdout)["firmware"]["isr_runs"] == 24
    assert "hello from the firmware" in run.stderr


@pytest.mark.parametrize(
    ("entry", "expected"),
    [
        ('name = "burst[100000000000]"\ntype = "uint16"', "element 100000000000 of type uint16"),
        ('name = "burst[15]"\ntype = "uint16"', "expected an index below 15"),
        ('name = "small"\ntype = "double"', "`small` is 2 bytes in the firmware, type double is 8"),
        ('name = "burst[7]"\ntype = "uint64"', "expected an index below 3"),
    ],
)
def test_a_global_the_variable_cannot_hold_is_refused_up_front(
    plain: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], entry: str, expected: str
):
    fw = plain
    g = tmp_path / "g.toml"
    g.write_text(GLOBALS + f'\n[[global]]\n{entry}\ncolumn = "x"\nunit = "1"\n')
    out = tmp_path / "run.csv"
    rc, _, err = _cli(fw, tmp_path, capsys, "--globals", str(g), "--out", str(out))
    assert rc == 2
    assert f"{g}:7: [[global]] 2" in err and expected in err, err
    assert not out.exists()


def _long_trace(tmp_path: Path) -> Path:
    motion = synth.static_motion(duration_s=600.0)
    path = tmp_path / "still.h5"
    synth.to_trace(motion, {"sample_rate_hz": synth.DEFAULT_RATE_HZ}).save(path)
    return path


@pytest.mark.parametrize(("sig", "code"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_signals_stop_a_firmware_that_ignores_them(tmp_path: Path, sig: signal.Signals, code: int):
    """The firmware ignores SIGINT and SIGTERM and spins in main (a basic block at a time): the signal
    (to the command's whole process group, as Ctrl-C at a terminal sends it) reaches the emulator,
    which stops the firmware; nothing is written."""
    fw = _build(
        tmp_path, main_code="signal(SIGINT, SIG_IGN);\n    signal(SIGTERM, SIG_IGN);", loop="spins++;"
    )
    trace = _long_trace(tmp_path)
    out = tmp_path / "run.csv"
    cmd = [sys.executable, "-m", "sins_fw", "run", str(trace), "--firmware", str(fw), "--out", str(out)]
    proc = subprocess.Popen(
        cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True
    )
    try:
        # Once the firmware's process runs (the command's child), the run is under way.
        children = Path(f"/proc/{proc.pid}/task/{proc.pid}/children")
        deadline = time.monotonic() + 120
        while proc.poll() is None and not children.read_text().split() and time.monotonic() < deadline:
            time.sleep(0.1)
        time.sleep(1.0)
        assert proc.poll() is None, proc.communicate()
        os.killpg(proc.pid, sig)
        _, stderr = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == code, stderr
    assert "stopped at t = " in stderr and "not written" in stderr, stderr
    assert not out.exists()
    assert list(tmp_path.glob("*.tmp*")) == []


def test_bus_records_kept_stay_bounded_with_spi_outside_interrupts():
    """A firmware doing SPI in main gives bus records and no ISR row: the records kept for the
    budget's SPI stage are those after the floor the firmware's process reports (the time reached),
    so each piece's work is bounded, not the whole run's (the bus log was joined per piece, growing
    without end: quadratic)."""
    rows = _Rows([], None)
    window = _TruthWindow()
    no_rows: dict[str, np.ndarray] = {}
    kept = []
    for piece in range(200):
        bus = np.zeros(1000, BUS_RECORD)
        bus["kind"] = 1
        bus["t_ps"] = piece * 10**9 + np.arange(1000) * 10**6
        rows.add(window, no_rows, np.zeros((0, 0)), [], bus, floor_ps=(piece + 1) * 10**9 - 5 * 10**6)
        kept.append(sum(len(b) for b in rows.bus))
    assert max(kept) <= 5


def test_csv_rows_of_many_columns_cost_n_log_n_characters_not_n_squared(monkeypatch: pytest.MonkeyPatch):
    """A run output of many watched globals: each CSV line was grown one column at a time, every
    character copied once per column after it (1 000 globals: 41 s and 431 MB for 749 rows). Counted,
    not timed: the characters the joins produce for 32 and 256 columns. Joined pairwise in a balanced
    tree each character is copied once per level, 2·W·log2(n) for W characters a line: the ratio for
    8× the columns is 8 · 8/5 = 12.8 (one column at a time: W·n/2 each, a ratio of 64)."""
    produced = [0]
    add = np.strings.add

    def counting_add(a: Any, b: Any) -> Any:
        out = add(a, b)
        produced[0] += out.size * out.dtype.itemsize
        return out

    monkeypatch.setattr(np.strings, "add", counting_add)

    def cost(n: int) -> int:
        schema = firmware_run_schema([(f"g{i}", "1", "") for i in range(n)])
        cols = {"t_s": np.arange(64) * 0.004, **{f"g{i}": np.full(64, 1.0 / 3.0) for i in range(n)}}
        produced[0] = 0
        text = csv_lines(schema, cols)
        assert text.splitlines()[1] == ",".join(["0.004", *[repr(1.0 / 3.0)] * n])
        return produced[0]

    ratio = cost(256) / cost(32)
    assert ratio < 16, ratio


def test_the_text_summary_of_a_firmware_run_is_the_firmwares(
    plain: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
):
    """The summary said the profile's Rust numeric (c28x-f32), "attitude steps" and "no truth in the
    trace" (pitch_sweep has one: the globals just name no quaternion) for a C firmware run."""
    fw = plain
    rc = main(
        [
            "run",
            str(PITCH_SWEEP),
            "--firmware",
            str(fw),
            "--globals",
            str(plain.with_name("globals.toml")),
            "--until-s",
            "1",
        ]
    )
    out = capsys.readouterr().out
    assert rc == 0
    assert "numeric        the C firmware's own arithmetic: float and double of the host mode" in out, out
    assert re.search(r"^emulated       0\.99\d s of virtual time, 249 ISR runs$", out, re.MULTILINE), out
    assert "attitude error not compared: the globals file names no q0…q3" in out, out
    assert re.search(
        r"^firmware       .*: 249 ISR runs, \d+ register accesses, main ran to 0\.99\d", out, re.MULTILINE
    )
