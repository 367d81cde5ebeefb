"""The C28x cycle model of host-built firmware (issue 38): the build's LLVM pass prices every basic
block of the optimised IR at compile time (firmware_c/pass/sins_fw_pass.cpp, SinsFwCyclePass) from
the profile's c28x-costs.toml ([instructions], [float], [iq]), and the runtime charges it and
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
float half(float a) { return a / 2.0f - a / 3.0f; }
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
    cost table's float prices and the C table's return: the same sum in both float modes (the c28x
    mode's calls to the c28x-f32 backend are priced as the operations they stand for). The load of
    the float g is the operand move the table's float prices include (c28x-costs.toml): 0."""
    p = block_costs(None)
    ir = _ir(tmp_path, float_mode)
    want = p["float.div"] + p["float.mul"] + p["float.add"] + p["ret"]
    m = re.search(r"define [^@]*@f\(.*?\n\s*call void @sins_fw_enter\(i32 (\d+),", ir)
    assert m is not None, ir
    assert int(m.group(1)) == want == 24 + 3 + 3 + 8
    # The empty endless loop calls sins_fw_idle with its pass: one unconditional branch.
    assert f"call void @sins_fw_idle(i32 {p['branch']})" in ir


@pytest.mark.parametrize("float_mode", ["host", "c28x"])
def test_a_division_by_a_power_of_two_is_priced_as_the_multiplication(tmp_path: Path, float_mode: str):
    """`a / 2.0f` is `a * 0.5f` to the bit, and cl2000 -O2 emits MPYF32 for it: priced `float.mul`
    in both float modes (clang makes the multiplication for host float; the C28x mode's backend call
    hides it); `a / 3.0f` stays a division."""
    p = block_costs(None)
    ir = _ir(tmp_path, float_mode)
    m = re.search(r"define [^@]*@half\(.*?\n\s*call void @sins_fw_enter\(i32 (\d+),", ir)
    assert m is not None, ir
    assert int(m.group(1)) == p["float.mul"] + p["float.div"] + p["float.add"] + p["ret"] == 3 + 24 + 3 + 8


LOOP = """
unsigned short d[6], m[6];
void mask(void) { int i; for (i = 0; i < 6; i++) m[i] = d[i] & 0x3FFF; }
"""


def test_a_loop_is_priced_as_the_c28x_runs_it(tmp_path: Path):
    """The published decode's first loop: the entry block's branch into the loop falls through (0),
    the loop's block is its two indexings, load, AND, store, the counter's increment and compare (the
    host's 64-bit index is a 32-bit one on the C28x: one cycle each) and the conditional branch back;
    the exit block its return."""
    p = block_costs(None)
    src = tmp_path / "loop.c"
    src.write_text(LOOP, encoding="utf-8")
    env = {**os.environ, "SINS_FW_PASS_COSTS": ",".join(f"{k}={v}" for k, v in p.items())}
    ir = subprocess.run(
        [CLANG, "-O1", f"-fpass-plugin={pass_plugin()}", "-S", "-emit-llvm", str(src), "-o", "-"],
        capture_output=True,
        text=True,
        env=env,
        check=True,
    ).stdout
    prices = [int(x) for x in re.findall(r"call void @sins_fw_(?:enter|block)\(i32 (\d+),", ir)]
    loop = 2 * p["int"] + p["load"] + p["data_wait"] + p["int"] + p["store"] + 2 * p["int"] + p["cond_branch"]
    assert prices == [0, loop, p["ret"]] == [0, 13, 8], ir


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
    float operations."""
    build_cabi()
    a = build_firmware([REFERENCE], tmp_path / "a.so", float_mode="c28x")
    b = build_firmware([REFERENCE], tmp_path / "b.so", float_mode="c28x")
    first = _run(a, tmp_path / "1.tsv")
    assert _run(a, tmp_path / "2.tsv") == first
    assert _run(b, tmp_path / "3.tsv") == first
    rows = {line.split("\t")[0]: line.split("\t")[1:] for line in first[0].splitlines()}
    cycles, calls = (int(x) for x in rows["updateQ"])
    # At least the RK4's float operations the model counts (without the earth-rate correction: 49
    # additions, 29 subtractions, 134 multiplications at 3 cycles, 4 divisions at 24): 732 cycles.
    assert calls > 0 and cycles / calls >= (49 + 29 + 134) * 3 + 4 * 24


def test_the_reference_isr_takes_the_models_time(tmp_path: Path):
    """Calibration (issue 38): the reference C firmware (the published algorithm) and the Rust model on
    the static trace, c28x float in both, each ISR's time from entry to IRET. The issue's bounds: the
    whole ISR within ±10 % of the model's, and an update tick's (the attitude solution's) within ±15 %
    of the published 0.35 ms. Measured (0.2 s): 343.8 µs against the model's 351.0 µs on update
    ticks, 328.1 against 335.9 on the others (the C's SPI gaps are 0.56 µs shorter: its polls are
    optimised, docs/c-cycles.md); the attitude update (updateQ) within ±15 % of the model's."""
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
    # The attitude update: updateQ (the RK4 and the normalisation, its own cycles a call) against
    # the model's attitude stage without the earth-rate correction (`firmware.earth_rate=false`:
    # the same RK4 and normalisation; with it, the stage also holds what the C's body_rates does),
    # ±15 %. Measured: 812 cycles (5.41 µs; its 24 divisions by 2 priced as the multiplications by
    # 0.5 cl2000 makes of them, its float loads and stores in the operand moves of the float prices)
    # against 777 cycles (5.18 µs: the arithmetic and the call).
    cycles, calls = functions["updateQ"]
    rk4 = emulate(STATIC, "reference", overrides=[*overrides, "firmware.earth_rate=false"], until_s=0.2)
    b4 = rk4.budget
    m_rk4 = (b4["attitude_end_ps"].astype(np.int64) - b4["decode_end_ps"].astype(np.int64)) * 1e-12
    m_attitude = m_rk4[m_rk4 > 0]
    assert len(m_attitude) > 20
    assert abs(cycles / calls / 150e6 / m_attitude.mean() - 1) <= 0.15


def test_each_stage_of_the_reference_c_firmware_takes_the_models_counted_cycles(tmp_path: Path):
    """Calibration stage by stage (issue 38): the reference C firmware's functions (inclusive cycles
    per call, `sins-fw budget --firmware`) against the model's counted stage cycles (`sins-fw
    budget`), the same input, c28x float, within ±15 % each: decode (`convert_data`), the body rates
    (`body_rates` with its `earth_rates`; the model's attitude stage less its RK4 alone), the RK4 and
    normalisation (`updateQ`; the model with `firmware.earth_rate=false`), Euler (`update_euler`,
    kept out of line as cl2000 -O2 keeps a function: it inlines automatically only at -O3) and the
    navigation (`navigate` with its `earth_rates`). Both count the same arithmetic at the same
    [float] prices and the same integer, memory and control work at the same [instructions] prices,
    the model as its generic code declares the C's, the C as its optimised IR has it. Measured:
    270/265, 586/618, 812/777, 289/265, 628/604 cycles. The bound is the issue's; what is left
    between them is named in docs/c-cycles.md."""
    from sins_fw.budget import budget_report
    from sins_fw.firmware_budget import firmware_budget_report

    build_cabi()
    project = tmp_path / "reference"
    project.mkdir()
    for f in REFERENCE.iterdir():
        text = f.read_text(encoding="utf-8")
        if f.name == "glue.c":
            text = text.replace(
                "static void update_euler(void)", "static __attribute__((noinline)) void update_euler(void)"
            )
            assert "noinline" in text
        (project / f.name).write_text(text, encoding="utf-8")
    fw = build_firmware([project], tmp_path / "ref.so", float_mode="c28x")
    overrides = ["firmware.numeric=c28x-f32", "device.timing_mode=lenient"]
    c = firmware_budget_report(fw, load_profile("reference", overrides=overrides), seconds=0.5)
    fns = {f["function"]: f["inclusive_cycles"] / f["calls"] for f in c["functions"]}
    model = budget_report("reference", overrides, seconds=0.5)["compute"]
    rk4 = budget_report("reference", [*overrides, "firmware.earth_rate=false"], seconds=0.5)["compute"]
    pairs = {
        "decode": (fns["convert_data"], model["decode"]["cycles"]),
        "body rates": (fns["body_rates"], model["attitude"]["cycles"] - rk4["attitude"]["cycles"]),
        "rk4": (fns["updateQ"], rk4["attitude"]["cycles"]),
        "euler": (fns["update_euler"], model["euler"]["cycles"]),
        "navigation": (fns["navigate"], model["navigation"]["cycles"]),
    }
    for name, (c_cycles, model_cycles) in pairs.items():
        assert abs(c_cycles / model_cycles - 1) <= 0.15, (name, c_cycles, model_cycles)


def test_the_budget_splits_a_c_isr_by_its_functions(tmp_path: Path, cli):
    """`sins-fw budget --firmware` on the reference C firmware (issue 38, item 2): the tick's stages
    (entry, CS set-up, SPI from the bus log, compute, exit) in the model's table shape, and the
    compute by the firmware's own functions with their calls, self and inclusive cycles. Every figure
    checked comes from the run: the ISR calls each of its helpers as the sources say (the attitude
    update on every second ISR: its `schedule_div`; the navigation's `earth_rates` twice per
    update), the functions' own cycles add up to the ISR's inclusive cycles (everything the ISR runs
    is called from it), and the compute stage after the SPI holds `reference_process_burst`
    (called after the burst) plus at most the ISR's own code."""
    import json

    from sins_fw.firmware_budget import firmware_budget_report

    build_cabi()
    fw = build_firmware([REFERENCE], tmp_path / "ref.so", float_mode="c28x")
    prof = load_profile("reference", overrides=["firmware.numeric=c28x-f32", "device.timing_mode=lenient"])
    r = firmware_budget_report(fw, prof, seconds=0.5)
    fns = {f["function"]: f for f in r["functions"]}
    isrs = r["isrs"]
    assert isrs == r["summary"]["ticks"] > 100
    assert fns["cpu_timer0_isr"]["calls"] == isrs
    assert fns["convert_data"]["calls"] == isrs
    updates = fns["updateQ"]["calls"]
    assert abs(updates - isrs / 2) <= 1
    assert fns["navigate"]["calls"] == updates and fns["earth_rates"]["calls"] == 2 * updates
    total_self = sum(f["self_cycles"] for f in r["functions"])
    assert total_self == fns["cpu_timer0_isr"]["inclusive_cycles"]
    for f in r["functions"]:
        assert f["self_cycles"] <= f["inclusive_cycles"]
        assert f["inclusive_s"]["max"] * 1e6 == pytest.approx(f["inclusive_pct"]["max"] * 40.0)
    # The compute stage (after the SPI) holds the processing of the burst and the ISR's last blocks.
    worst = r["tick"]["compute"]["worst_s"]
    burst = fns["reference_process_burst"]["inclusive_s"]["max"]
    assert 0 <= worst - burst <= fns["cpu_timer0_isr"]["self_s"]["max"]
    # The SPI stage: 15 frames of 16 bits at the profile's 0.75 MHz SCLK at least.
    assert r["tick"]["spi"]["typical_s"] >= 15 * 16 / 0.75e6
    # The CLI: the same report, the table in text, the rule the lenient device reports: exit 1.
    res = cli("budget", "--firmware", str(fw), "--set", "firmware.numeric=c28x-f32",
              "--set", "device.timing_mode=lenient", "--duration-s", "0.5", "--json")  # fmt: skip
    assert res.code == 1, res.err
    out = json.loads(res.out)
    assert [f["function"] for f in out["functions"]] == [f["function"] for f in r["functions"]]
    assert out["tick"] == r["tick"]
    text = cli("budget", "--firmware", str(fw), "--duration-s", "0.5", "--set", "device.timing_mode=lenient")
    assert "updateQ" in text.out and "reference_process_burst" in text.out and "spi" in text.out


def _event_ticks(events: list[dict], kind: str, message: str) -> list[int]:
    """The ticks the events of ``kind`` name, in order: each message matches ``message``, whose group
    is the tick."""
    return sorted(int(re.match(message, e["message"]).group(1)) for e in events if e["kind"] == kind)


def _scheduling(run_budget: dict, events: list[dict], until_ps: int) -> dict:
    """The scheduling figures of a run: its ticks, ISRs run, ticks skipped and flagged overrun (budget
    rows up to ``until_ps``), its `overrun` and `tick_lost` events there, and the mean ISR time."""
    tick_ps = run_budget["tick_ps"].astype(np.int64)
    keep = tick_ps <= until_ps
    b = {k: np.asarray(v)[keep] for k, v in run_budget.items()}
    skipped = b["deadline_ps"] == b["tick_ps"]
    overrun = b["overrun"].astype(bool)
    inside = [e for e in events if e["t_s"] <= until_ps * 1e-12]
    busy = (b["end_ps"].astype(np.int64) - b["start_ps"].astype(np.int64))[~skipped]
    return {
        "ticks": len(b["tick"]),
        "run": int((~skipped).sum()),
        "skipped": [int(t) for t in b["tick"][skipped]],
        "late": [int(t) for t in b["tick"][overrun & ~skipped]],
        "lost_events": _event_ticks(
            inside, "tick_lost", r"tick (\d+): TINT0 arrived while the previous one was still pending: lost$"
        ),
        "overrun_events": _event_ticks(
            inside, "overrun", r"tick (\d+): the previous ISR ran [\d.]+ µs past this tick \(Queue\)$"
        ),
        "kinds": {e["kind"] for e in inside if e["source"] == "emulator"},
        "busy_mean_ps": float(busy.mean()),
    }


def test_an_overrun_is_the_same_event_for_c_and_the_model(tmp_path: Path):
    """One accounting of time (issue 38, item 3): the reference C firmware built with a 300 µs timer
    (`-DTIMER_PERIOD_US=300`) and the model with `timer.period_us=300` both take longer than a tick
    on every ISR (≈ 340 µs: the SPI burst alone clocks 320 µs), so every tick after the first comes
    while an ISR runs. In both, each tick is either run late (an `overrun` event at its arrival, its
    budget row flagged) or lost while the previous one was pending (a `tick_lost` event, a skipped
    budget row, flagged): the same kinds, the same messages, and the rows and events name the same
    ticks. The CPU is never idle, so the ISRs run back to back: over T, T / mean ISR time of them,
    and the other ticks are lost, the lost share 1 − P / mean ISR time in each (±2 ticks: a partial
    ISR at each end); the C's and the model's ISR times differ by 2.1 % (335.9 against 343.1 µs: the
    optimised C's polls make its SPI gaps 0.56 µs shorter, docs/c-cycles.md), within the calibration's
    ±10 % on the whole ISR, so their lost shares agree to 1 − P/L differences of that size."""
    from sins_fw._core import EVENT_KINDS

    from sins_fw import emulate

    source = {k["name"]: k["source"] for k in EVENT_KINDS}
    build_cabi()
    fw = build_firmware([REFERENCE], tmp_path / "fast.so", float_mode="c28x", defines=["TIMER_PERIOD_US=300"])
    overrides = ["firmware.numeric=c28x-f32", "device.timing_mode=lenient", "timer.period_us=300"]
    parts: list[dict] = []
    until = 0.3
    run_c_firmware(
        fw, STATIC, load_profile("reference", overrides=overrides), sink=parts.append, until_s=until
    )
    c_budget = {
        k.removeprefix("budget_"): np.concatenate([p[k] for p in parts])
        for k in parts[0]
        if k.startswith("budget_")
    }
    c_events = [{**e, "source": source.get(e["kind"])} for p in parts for e in p["events"]]
    model = emulate(STATIC, "reference", overrides=overrides, until_s=until)
    m_events = [{**e, "source": source.get(e["kind"])} for e in model.events]
    # Both up to the C's last ISR row (the input's end cuts the ISR running then).
    end_ps = int(c_budget["tick_ps"][-1]) - 1
    c = _scheduling(c_budget, c_events, end_ps)
    m = _scheduling(model.budget, m_events, end_ps)
    for s in (c, m):
        assert s["kinds"] == {"overrun", "tick_lost"}
        assert s["lost_events"] == s["skipped"] and len(s["skipped"]) > 50
        assert s["overrun_events"] == s["late"] and len(s["late"]) > 500
        assert s["run"] + len(s["skipped"]) == s["ticks"]
        # Back to back: the ISRs run fill the time from the first to the last.
        period_ps = 300e6
        span_ps = s["ticks"] * period_ps
        assert abs(s["run"] - span_ps / s["busy_mean_ps"]) <= 2
        assert abs(len(s["skipped"]) / s["ticks"] - (1 - period_ps / s["busy_mean_ps"])) <= 2 / s["ticks"]
    assert abs(c["busy_mean_ps"] / m["busy_mean_ps"] - 1) <= 0.10
    share = abs(len(c["skipped"]) - len(m["skipped"])) / c["ticks"]
    assert share <= abs(300e6 / c["busy_mean_ps"] - 300e6 / m["busy_mean_ps"]) + 4 / c["ticks"]


def test_built_unoptimised_the_published_spi_loop_meets_the_burst_stall(tmp_path: Path):
    """The strict-timing question (issue 38): the reference C firmware built as a CCS Debug
    configuration builds it (`opt_level="off"`, clang -O0: every variable in memory, the polls
    `Spi_TxReady()`/`Spi_RxReady()` real calls) runs the reference profile as it is, strict device
    timing, with no device-timing event and the model's words: its frames are at least the
    ADIS16407's one-SCLK burst stall (1.333 µs at 0.75 MHz) apart, as the model's, whose polling pass
    (`timing.poll_loop_cycles` = 39) is this build's: the -O0 pass's blocks price 38 cycles (docs/
    c-cycles.md). The optimised build's frames are under the stall (tests/test_reference_chain.py)."""
    from sins_fw._core import EVENT_KINDS

    from sins_fw import emulate
    from sins_fw.firmware_run import first_frame_difference

    source = {k["name"]: k["source"] for k in EVENT_KINDS}
    build_cabi()
    fw = build_firmware([REFERENCE], tmp_path / "debug.so", float_mode="c28x", opt_level="off")
    overrides = ["firmware.quat_derivative=published", "firmware.numeric=c28x-f32"]
    parts: list[dict] = []
    result = run_c_firmware(
        fw,
        STATIC,
        load_profile("reference", overrides=overrides),
        globals_file=REFERENCE / "globals.toml",
        sink=parts.append,
        until_s=0.2,
        bus_log=True,
    )
    events = [e for p in parts for e in p["events"]]
    assert not [e for e in events if source.get(e["kind"]) == "device"], events[:3]
    model = emulate(STATIC, "reference", overrides=overrides, until_s=0.2, bus_window=(1, result.isr_rows))
    assert result.bus is not None and model.bus is not None
    assert result.isr_rows > 40 and first_frame_difference(result.bus, model.bus) is None
    first = result.bus["frame_first_edge_ps"].astype(np.int64).reshape(-1, 15)
    last = result.bus["frame_last_edge_ps"].astype(np.int64).reshape(-1, 15)
    gaps = first[:, 1:] - last[:, :-1]
    assert gaps.min() >= 1_333_333
