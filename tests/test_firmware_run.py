"""`sins-fw run TRACE --firmware fw.so` (issue 20, items 3 and 5's runner): a user's F28335 C firmware,
built unmodified, on a trace: CPU timer 0 → PIE → IER/IFR/INTM → the ISR in PieVectTable, the globals
read after each ISR, the usual summary, budget and --out."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from conftest import TIMER0_1MS, TINT0_ENABLE, build_cabi
from sins_fw import adis16407
from sins_fw.cli import main
from sins_fw.errors import InputError
from sins_fw.firmware_build import build_firmware
from sins_fw.firmware_run import load_globals, run_c_firmware
from sins_fw.profile import load_profile
from sins_fw.tablefile import open_table

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "firmware_c" / "examples" / "timer0_burst"
PITCH_SWEEP = ROOT / "python" / "sins_fw" / "bundled_traces" / "pitch_sweep.h5"
#: The pitch sweep is still for its first 6.03 s; 8 s hold 2 s of sweep (gyro y up to ~23 °/s).
UNTIL_S = "8"


@pytest.fixture(scope="module")
def firmware(tmp_path_factory: pytest.TempPathFactory) -> Path:
    build_cabi()
    return build_firmware([EXAMPLE], tmp_path_factory.mktemp("fw") / "timer0_burst.so")


def _run(firmware: Path, out: Path, capsys: pytest.CaptureFixture[str], *extra: str) -> tuple[int, dict, str]:
    argv = ["run", str(PITCH_SWEEP), "--firmware", str(firmware), "--globals", str(EXAMPLE / "globals.toml")]
    rc = main([*argv, "--until-s", UNTIL_S, "--out", str(out), "--json", *extra])
    captured = capsys.readouterr()
    return rc, json.loads(captured.out) if rc == 0 else {}, captured.err


def test_the_timer0_isr_runs_every_4_ms_and_decodes_the_burst(
    firmware: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
):
    out = tmp_path / "run.csv"
    rc, summary, err = _run(firmware, out, capsys)
    assert rc == 0, err
    # The reference period: PRD = 150·4000 − 1, so a tick every 600 000 SYSCLKOUT cycles = 4 ms exactly.
    budget = summary["budget"]
    assert budget["tick_period_s"] == 0.004
    assert summary["events"]["total"] == 0
    fw = summary["firmware"]
    # Ticks from the timer's start (a few µs into main) to 8 s: 1999 whole periods.
    assert fw["isr_runs"] == summary["cycles"] == 1999
    # The ISR: entry (14 + 16 cycles), 15 frames of 16 bits at 0.75 MHz (320 µs), 14 × 0.5 µs of
    # DELAY_US, the polling, the decode, exit (16 + 8): between 327 and 400 µs.
    busy = budget["detail"]["busy"]
    assert 327e-6 < busy["min"] <= busy["max"] == budget["isr_max_s"] < 400e-6
    meta, cols = open_table_all(out)
    assert meta["firmware"] == str(firmware) and meta["sample_rate_hz"] == "250"
    t = cols["t_s"]
    assert np.all(np.diff(np.round(t * 1e12).astype(np.int64)) == 4_000_000_000)
    assert np.array_equal(cols["isr_count"], np.arange(1, len(t) + 1))
    # The rates the C ISR decoded are the Rust model's decode of the same words, bit for bit.
    for axis in "xyz":
        words = cols[f"{axis}gyro_word"].astype(int)
        model = np.array([adis16407.decode("gyro", w).value for w in words])
        assert np.array_equal(cols[f"rate_{axis}_dps"], model)
    # And they follow the trace: still before 6.03 s, pitching (y) after it.
    still = t < 6.0
    assert np.all(cols["rate_y_dps"][still] == 0.0)
    assert cols["rate_y_dps"][~still].max() > 10.0


def open_table_all(path: Path) -> tuple[dict[str, str], dict[str, np.ndarray]]:
    watched = load_globals(EXAMPLE / "globals.toml")
    from sins_fw.firmware_run import FirmwareRunWriter

    schema = FirmwareRunWriter(path, load_profile("reference"), 0.0, {}, watched).schema
    src = open_table(path, schema, 1 << 16, True, 1.5)
    blocks = list(src.blocks)
    return src.metadata, {n: np.concatenate([b[n] for b in blocks]) for n in blocks[0]}


def test_two_runs_in_one_process_give_the_same_rows(firmware: Path):
    """Each run loads a fresh copy of the library: the globals (isr_count, CpuTimer0's bookkeeping) start
    from their initial values again, so the second run's rows equal the first's."""
    profile = load_profile("reference")

    def rows() -> list[dict]:
        parts: list[dict] = []
        run_c_firmware(
            firmware,
            PITCH_SWEEP,
            profile,
            globals_file=EXAMPLE / "globals.toml",
            sink=parts.append,
            until_s=0.5,
        )
        return parts

    a, b = rows(), rows()
    assert len(a) == len(b) and sum(len(p["budget_tick"]) for p in a) == 124
    for pa, pb in zip(a, b, strict=True):
        for key in ("budget_tick_ps", "budget_start_ps", "budget_end_ps"):
            assert np.array_equal(pa[key], pb[key])
        assert np.array_equal(pa["firmware_globals"]["isr_count"], pb["firmware_globals"]["isr_count"])
    assert a[0]["firmware_globals"]["isr_count"][0] == 1


def _firmware(tmp_path: Path, body: str, name: str = "fw") -> Path:
    src = tmp_path / f"{name}.c"
    src.write_text(body)
    return build_firmware([src], tmp_path / f"{name}.so")


def test_an_idle_loop_no_interrupt_can_leave_is_an_error_naming_its_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
):
    fw = _firmware(
        tmp_path,
        '#include "DSP2833x_Device.h"\nvoid main(void) {\n    DINT;\n    for (;;) {\n    }\n}\n',
    )
    out = tmp_path / "run.csv"
    rc = main(["run", str(PITCH_SWEEP), "--firmware", str(fw), "--until-s", "1", "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2
    assert "INTM is set" in err and "fw.c:4" in err, err
    assert not out.exists()


def test_a_busy_loop_without_register_access_and_no_interrupt_is_an_error_naming_its_line(tmp_path: Path):
    """Not an empty loop: its blocks are instrumented; after 2^24 blocks without an access, with
    nothing able to interrupt it (the timer never started), the run stops."""
    fw = _firmware(
        tmp_path,
        '#include "DSP2833x_Device.h"\n'
        "Uint16 flag, spins;\n"
        "void main(void) {\n"
        "    EINT;\n"
        "    while (flag == 0) {\n"
        "        spins++;\n"
        "    }\n"
        "}\n",
    )
    with pytest.raises(InputError, match=r"IER has INT1 .* \(the loop: .*fw\.c:[56]"):
        run_c_firmware(fw, PITCH_SWEEP, load_profile("reference"), until_s=5.0)


def test_a_vector_set_without_eallow_is_ignored_and_reported(tmp_path: Path):
    fw = _firmware(
        tmp_path,
        '#include "DSP2833x_Device.h"\n'
        "interrupt void isr(void) { PieCtrlRegs.PIEACK.all = PIEACK_GROUP1; }\n"
        "void main(void) {\n"
        "    PieVectTable.TINT0 = &isr;\n"
        "    PieCtrlRegs.PIECTRL.bit.ENPIE = 1;\n"
        "    CpuTimer0Regs.PRD.all = 149999;\n"
        "    CpuTimer0Regs.TCR.all = 0x4020;\n"
        f"{TINT0_ENABLE}"
        "    for (;;) {\n"
        "    }\n"
        "}\n",
    )
    with pytest.raises(InputError, match=r"PIE vector 38 \(TINT0\) but PieVectTable holds no ISR") as e:
        run_c_firmware(fw, PITCH_SWEEP, load_profile("reference"), until_s=1.0)
    assert "vector 38 (0x0D4C) written without EALLOW: the write is ignored" in str(e.value)


def test_bad_input_exits_2_and_writes_nothing(
    firmware: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
):
    out = tmp_path / "run.csv"
    base = ["run", str(PITCH_SWEEP), "--until-s", "0.1", "--out", str(out)]
    assert main([*base, "--firmware", str(tmp_path / "missing.so")]) == 2
    assert "missing.so: no such firmware library" in capsys.readouterr().err
    bad = tmp_path / "globals.toml"
    bad.write_text('[[global]]\nname = "rate_x"\ntype = "double"\ncolumn = "a"\nunit = "1"\n\n'
                   '[[global]]\nname = "rate_y"\ntype = "real"\ncolumn = "b"\nunit = "1"\n')  # fmt: skip
    assert main([*base, "--firmware", str(firmware), "--globals", str(bad)]) == 2
    assert f"{bad}:7: [[global]] 2: field `type` = 'real'" in capsys.readouterr().err
    bad.write_text('[[global]]\nname = "no_such_global"\ntype = "double"\ncolumn = "a"\nunit = "1"\n')
    assert main([*base, "--firmware", str(firmware), "--globals", str(bad)]) == 2
    assert "no global `no_such_global`" in capsys.readouterr().err
    bad.write_text("[[global]\n")
    assert main([*base, "--firmware", str(firmware), "--globals", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "not valid TOML" in err and "line 1" in err
    (tmp_path / "other").mkdir()
    not_fw = tmp_path / "other" / "libother.so"
    not_fw.write_bytes((ROOT / "target" / "release" / "libsins_cabi.so").read_bytes())
    assert main([*base, "--firmware", str(not_fw)]) == 2
    assert "no symbol `sins_fw_run`" in capsys.readouterr().err
    assert not out.exists()


def test_load_globals_names_line_and_field(tmp_path: Path):
    g = tmp_path / "g.toml"
    g.write_text(
        '# comment\n[[global]]\nname = "x"\ntype = "float"\ncolumn = "x"\nunit = "1"\ncolour = "red"\n'
    )
    with pytest.raises(InputError, match=r"g\.toml:2: \[\[global\]\] 1: unknown field `colour`"):
        load_globals(g)


def test_a_tick_that_comes_while_the_last_is_pending_is_lost(tmp_path: Path):
    """An ISR of 9 ms on a 4 ms timer: the tick during it waits (INTM is set), the next one finds the
    flag still set: lost, a `tick_lost` event from the core, the ISR of the tick after it late: an
    `overrun` event; the budget has a row per tick, a skipped one for a lost tick (as the model's)."""
    fw = _firmware(
        tmp_path,
        '#include "DSP2833x_Device.h"\n'
        '#include "DSP2833x_Examples.h"\n'
        "Uint16 runs;\n"
        "interrupt void isr(void) {\n"
        "    runs++;\n"
        "    DELAY_US(9000);\n"
        "    PieCtrlRegs.PIEACK.all = PIEACK_GROUP1;\n"
        "}\n"
        "void main(void) {\n"
        "    EALLOW;\n"
        "    PieVectTable.TINT0 = &isr;\n"
        "    EDIS;\n"
        "    PieCtrlRegs.PIECTRL.bit.ENPIE = 1;\n"
        "    CpuTimer0Regs.PRD.all = 599999;\n"
        "    CpuTimer0Regs.TCR.all = 0x4020;\n"
        f"{TINT0_ENABLE}"
        "    for (;;) {\n"
        "    }\n"
        "}\n",
    )
    parts: list[dict] = []
    r = run_c_firmware(fw, PITCH_SWEEP, load_profile("reference"), sink=parts.append, until_s=0.1)
    events = [e for p in parts for e in p["events"]]
    assert {e["kind"] for e in events} == {"tick_lost", "overrun"}
    # Ticks every 4 ms, an ISR of 9 ms + entry and exit: tick 1's ISR runs from 4 to 13 ms, ticks 2
    # (8 ms) and 3 (12 ms) come meanwhile: 2 is lost, the ISR runs for 3 at 13 ms (an overrun,
    # 1 ms late) until 22 ms, for 5 (tick 4 lost) at 22 ms, … as the model accounts them: the
    # budget has a row for every tick, a lost one skipped (no deadline) and flagged overrun.
    ticks = np.concatenate([p["budget_tick"] for p in parts])
    assert list(ticks[:5]) == [1, 2, 3, 4, 5]
    skipped = np.concatenate([p["budget_deadline_ps"] == p["budget_tick_ps"] for p in parts])
    assert list(skipped[:5]) == [False, True, False, True, False]
    assert r.isr_rows == (~skipped).sum()
    overrun = np.concatenate([p["budget_overrun"] for p in parts])
    assert list(overrun[:5]) == [0, 1, 1, 1, 1]
    tick_ps = np.concatenate([p["budget_tick_ps"] for p in parts]).astype(np.int64)
    assert list(np.diff(tick_ps[:5])) == [4_000_000_000] * 4
    lost = [e for e in events if e["kind"] == "tick_lost"]
    late = [e for e in events if e["kind"] == "overrun"]
    assert lost[0]["message"] == "tick 2: TINT0 arrived while the previous one was still pending: lost"
    assert lost[0]["t_s"] == tick_ps[1] * 1e-12
    assert late[0]["message"].startswith("tick 3: the previous ISR ran 1")
    assert late[0]["t_s"] == tick_ps[2] * 1e-12 and late[0]["measured"] > 1e-3
    # Each event has its row, up to the last ISR run: the ISR the input's end cut has no row (its
    # tick's overrun and the tick lost before it have their events).
    end = tick_ps[-1] * 1e-12
    assert len([e for e in lost if e["t_s"] <= end]) == skipped.sum()
    assert len([e for e in late if e["t_s"] <= end]) == (overrun.astype(bool) & ~skipped).sum()


def test_tis_support_sources_link_from_their_host_replacements(tmp_path: Path):
    """A TI-style project: main calls TI's InitSysCtrl, InitPieCtrl, InitPieVectTable, InitCpuTimers
    and ConfigCpuTimer, and its folder holds a copy of DSP2833x_PieVect.c in TI's form (the default
    vectors' table copied through Uint32 pointers): it is compiled as given, the host replacements
    of the other support sources link. The firmware never sets its own TINT0 vector, so the table's
    default TINT0_ISR takes the tick and, as on the chip, never returns: the run stops naming it in
    DSP2833x_DefaultIsr.c."""
    project = tmp_path / "project"
    project.mkdir()
    # The default vectors, as the host replacement of DSP2833x_PieVect.c lists them.
    replacement = (ROOT / "firmware_c" / "ti" / "DSP2833x_PieVect.c").read_text()
    defaults = re.findall(r"^\s*&(\w+), /\* \d+ ", replacement, re.M)
    assert len(defaults) == 128
    (project / "DSP2833x_PieVect.c").write_text(
        '#include "DSP2833x_Device.h"\n'
        '#include "DSP2833x_Examples.h"\n'
        "const struct PIE_VECT_TABLE PieVectTableInit = {" + ", ".join(defaults) + "};\n"
        "void InitPieVectTable(void) {\n"
        "    Uint32 *Source = (void *)&PieVectTableInit;\n"
        "    Uint32 *Dest = (void *)&PieVectTable;\n"
        "    EALLOW;\n"
        "    for (int16 i = 0; i < 128; i++) *Dest++ = *Source++;\n"
        "    EDIS;\n"
        "    PieCtrlRegs.PIECTRL.bit.ENPIE = 1;\n"
        "}\n"
    )
    (project / "main.c").write_text(
        '#include "DSP2833x_Device.h"\n'
        '#include "DSP2833x_Examples.h"\n'
        "void main(void) {\n"
        "    InitSysCtrl();\n"
        "    InitPieCtrl();\n"
        "    IER = 0x0000;\n"
        "    IFR = 0x0000;\n"
        "    InitPieVectTable();\n"
        f"{TIMER0_1MS}"
        "    for (;;) {\n"
        "    }\n"
        "}\n"
    )
    fw = build_firmware([project], tmp_path / "fw.so")
    with pytest.raises(
        InputError, match=r"INTM is set .*the loop: .*DSP2833x_DefaultIsr\.c:\d+ in TINT0_ISR"
    ):
        run_c_firmware(fw, PITCH_SWEEP, load_profile("reference"), until_s=0.1)


def test_a_firmwares_own_definition_takes_the_place_of_the_replacement(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
):
    """The replacements are weak: the firmware's own TINT0_ISR (as in its copy of TI's
    DSP2833x_DefaultIsr.c) is the one InitPieVectTable installs; the CLI names the TI copy it left
    out."""
    (tmp_path / "DSP2833x_GlobalVariableDefs.c").write_text('#pragma DATA_SECTION(AdcRegs, "AdcRegsFile");\n')
    (tmp_path / "main.c").write_text(
        '#include "DSP2833x_Device.h"\n'
        '#include "DSP2833x_Examples.h"\n'
        "Uint32 ticks;\n"
        "interrupt void TINT0_ISR(void) {\n"
        "    ticks++;\n"
        "    PieCtrlRegs.PIEACK.all = PIEACK_GROUP1;\n"
        "}\n"
        "void main(void) {\n"
        "    InitSysCtrl();\n"
        "    InitPieCtrl();\n"
        "    InitPieVectTable();\n"
        f"{TIMER0_1MS}"
        "    for (;;) {\n"
        "    }\n"
        "}\n"
    )
    out = tmp_path / "fw.so"
    assert main(["build-firmware", str(tmp_path), "-o", str(out)]) == 0
    assert "TI's DSP2833x_GlobalVariableDefs.c left out" in capsys.readouterr().out
    globals_file = tmp_path / "globals.toml"
    globals_file.write_text('[[global]]\nname = "ticks"\ntype = "uint32"\ncolumn = "ticks"\nunit = "1"\n')
    result = run_c_firmware(
        out, PITCH_SWEEP, load_profile("reference"), globals_file=globals_file, until_s=0.05
    )
    # 1 ms ticks from a start a few µs into main, to the last sample at or before 50 ms (48.8 ms at
    # 819.2 SPS): 48.
    assert result.isr_rows == 48 and result.final["ticks"] == 48


def test_a_run_shorter_than_one_sample_period_still_runs_main(tmp_path: Path):
    """A run without a trace reads a still board; its input used to end at the last 819.2-SPS sample
    at or before until_s, so a 1 ms run covered no time at all and ended at main's first basic block,
    its globals unset. The still board's input now reaches until_s itself."""
    fw = _firmware(
        tmp_path, '#include "DSP2833x_Device.h"\nUint16 started;\nvoid main(void) {\n    started = 1;\n}\n'
    )
    globals_file = tmp_path / "globals.toml"
    globals_file.write_text('[[global]]\nname = "started"\ntype = "uint16"\ncolumn = "started"\nunit = "1"\n')
    result = run_c_firmware(fw, None, load_profile("reference"), globals_file=globals_file, until_s=0.001)
    assert result.final["started"] == 1
