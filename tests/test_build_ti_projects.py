"""`sins-fw build-firmware` on real F28335 projects as they are (issue 37, items 1-3): C compiled as C
in the dialect TI's compiler accepts, C++ as C++, register accesses through TI-layout register files
or raw addresses, TI's project layout (DSP28x_Project.h, the clock macros of DSP2833x_Examples.h, CCS
.project/.cproject, .asm files named and skipped, -I/-D), honest errors, and the interrupt-enable
check. The TI-style examples and the sensor driver are under firmware_c/examples/."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from conftest import write_globals
from sins_fw.cli import main
from sins_fw.errors import InputError
from sins_fw.firmware_build import build_firmware, read_project
from sins_fw.firmware_run import run_c_firmware
from sins_fw.profile import load_profile

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "firmware_c" / "examples"
TI_STYLE = EXAMPLES / "ti_style"
SENSOR = EXAMPLES / "c_sensor_driver"
PITCH_SWEEP = ROOT / "python" / "sins_fw" / "bundled_traces" / "pitch_sweep.h5"

#: SPI-A at LSPCLK = 150 MHz / (2·LOSPCP) = 37.5 MHz (the reference profile, TI's InitSysCtrl).
LSPCLK_HZ = 37.5e6


pytestmark = pytest.mark.usefixtures("cabi_library")


def _run(fw: Path, folder: Path, until_s: float, profile: str = "reference", **types: str):
    return run_c_firmware(
        fw, None, load_profile(profile), globals_file=write_globals(folder, **types), until_s=until_s
    )


# --- C as C, in TI's dialect ---------------------------------------------------------------------------


def test_valid_c_that_cpp_refuses_builds_and_runs(tmp_path: Path):
    """Compound literals, malloc without a cast, a function pointer of another return type, a cast to
    a union, an integer made a pointer, TI's keywords and pragmas: all build as C, and run."""
    src = tmp_path / "dialect.c"
    src.write_text(
        '#include "DSP28x_Project.h"\n'
        "#include <stdlib.h>\n"
        '#pragma CODE_SECTION(fast, "ramfuncs")\n'
        '#pragma DATA_SECTION(table, "DMARAML4")\n'
        "Uint16 table[4];\n"
        "far Uint16 farvar;\n"
        "union word { Uint16 u; int16 s; };\n"
        "struct pt { int16 x, y; };\n"
        "static int one(void) { return 1; }\n"
        "void (*hook)(void) = one;\n"
        "Uint16 sum, neg, brr, heap;\n"
        "static Uint16 fast(const struct pt *p) { return (Uint16)(p->x + p->y); }\n"
        "interrupt void never_isr(void) { PieCtrlRegs.PIEACK.all = PIEACK_GROUP1; }\n"
        "void main(void) {\n"
        "    Uint16 *p = malloc(4 * sizeof *p);\n"
        "    volatile Uint16 *spi = (volatile Uint16 *)0x7040;\n"
        "    p[0] = 7;\n"
        "    heap = p[0];\n"
        "    free(p);\n"
        "    hook();\n"
        "    sum = fast(&(struct pt){.x = 2, .y = 3});\n"
        "    neg = (Uint16)((union word)(Uint16)0xFFFE).s == 0xFFFE;\n"
        '    asm(" EALLOW");\n'
        '    __asm(" EDIS");\n'
        '    __asm(" ESTOP0");\n'
        '    asm(" RPT #7 || NOP");\n'
        "    spi[4] = 0x31;\n"
        "    brr = SpiaRegs.SPIBRR;\n"
        "    farvar = table[0];\n"
        "}\n"
    )
    fw = build_firmware([src], tmp_path / "fw.so")
    run = _run(fw, tmp_path, 1.0, sum="uint16", neg="uint16", brr="uint16", heap="uint16")
    # spi[4] is SPIBRR (0x7044: the pointer counts C28x words, as on the chip).
    assert run.final == {"sum": 5, "neg": 1, "brr": 0x31, "heap": 7}


def test_raw_addresses_reach_the_same_registers_as_the_register_files(tmp_path: Path):
    """`*(volatile Uint16 *)0x701B` is LOSPCP (segfault, rc 139, before); a 32-bit raw access is two
    words, low first; a raw address of an unmodelled register is its plain memory."""
    src = tmp_path / "raw.c"
    src.write_text(
        '#include "DSP2833x_Device.h"\n'
        "Uint16 lospcp, via_struct, pllsts, mux_lo, mux_hi;\n"
        "void main(void) {\n"
        "    EALLOW;\n"
        "    *(volatile Uint16 *)0x701B = 5;\n"
        "    *(volatile Uint32 *)0x6F86 = 0x00050004UL;\n"
        "    EDIS;\n"
        "    lospcp = *(volatile Uint16 *)0x701B;\n"
        "    via_struct = SysCtrlRegs.LOSPCP.all;\n"
        "    pllsts = *(volatile Uint16 *)0x7011;\n"
        "    mux_lo = GpioCtrlRegs.GPAMUX1.all & 0xFFFF;\n"
        "    mux_hi = GpioCtrlRegs.GPAMUX1.all >> 16;\n"
        "}\n"
    )
    fw = build_firmware([src], tmp_path / "raw.so")
    run = _run(
        fw,
        tmp_path,
        1.0,
        lospcp="uint16",
        via_struct="uint16",
        pllsts="uint16",
        mux_lo="uint16",
        mux_hi="uint16",
    )
    # PLLSTS: the profile's PLL, locked (PLLLOCKS = 1), DIVSEL = 2 (/2).
    assert run.final == {"lospcp": 5, "via_struct": 5, "pllsts": 0x0101, "mux_lo": 4, "mux_hi": 5}


def test_cpp_includes_the_headers_inside_extern_c(tmp_path: Path):
    """TI's own headers are included from C++ inside `extern "C" { }`: no template may be there."""
    src = tmp_path / "main.cpp"
    src.write_text(
        'extern "C" {\n#include "DSP28x_Project.h"\n}\n'
        "#include <vector>\n"
        "Uint16 ccr;\n"
        "static constexpr float half = 0.5f;\n"
        "int main() {\n"
        "    std::vector<Uint16> v{0x004F};\n"
        "    SpiaRegs.SPICCR.all = v[0];\n"
        "    ccr = SpiaRegs.SPICCR.all + (half > 0.25f);\n"
        "    return 0;\n"
        "}\n"
    )
    for mode in ("host", "c28x"):
        fw = build_firmware([src], tmp_path / f"cpp_{mode}.so", float_mode=mode)
        assert _run(fw, tmp_path, 1.0, ccr="uint16").final["ccr"] == 0x50


def test_c_sources_keep_the_c28x_float_mode(tmp_path: Path):
    """--float c28x on a C source: `double` is the C28x's 32-bit float and every operation the
    c28x-f32 backend's (its division is fastRTS' estimate and two Newton steps, not IEEE's)."""
    src = tmp_path / "f.c"
    src.write_text(
        "#include <math.h>\n"
        "float q, r;\n"
        "double d;\n"
        "Uint16 dbytes;\n"
        "void main(void) {\n"
        "    volatile float one = 1.0f, three = 3.0f;\n"
        "    q = one / three;\n"
        "    r = sqrt(three);\n"
        "    d = one / 10.0;\n"
        "    dbytes = sizeof(double);\n"
        "}\n"
    )
    fw = build_firmware([src], tmp_path / "f.so", float_mode="c28x")
    run = _run(fw, tmp_path, 1.0, q="float", r="float", d="double", dbytes="uint16")
    import numpy as np

    from sins_fw import _core

    assert run.final["dbytes"] == 4
    c28x = _core.c28x_f32 if hasattr(_core, "c28x_f32") else None
    assert run.final["q"] == pytest.approx(1 / 3, rel=2**-23)
    assert run.final["r"] == pytest.approx(np.sqrt(3), rel=2**-23)
    assert run.final["d"] == pytest.approx(0.1, rel=2**-23)
    del c28x


# --- TI's project layout -------------------------------------------------------------------------------


def test_the_ti_style_spi_loopback_project_builds_as_ccs_lists_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
):
    """The SPI FIFO digital loopback, polled, written as TI's examples are: its folder, its .project,
    its .cproject, or the list of its sources (with TI's .asm) build it unedited; each word comes back."""
    project = TI_STYLE / "spi_loopback"
    listed = [
        project / "spi_loopback.c",
        *(
            ROOT / "firmware_c" / "ti" / f"DSP2833x_{n}.c"
            for n in ("SysCtrl", "Spi", "PieCtrl", "PieVect", "DefaultIsr")
        ),
        TI_STYLE / "common" / "DSP2833x_usDelay.asm",
    ]
    inputs: list[list[str]] = [
        [str(project)],
        [str(project / ".project")],
        [str(project / ".cproject")],
        [*map(str, listed), "-I", str(project / "include")],
    ]
    for i, args in enumerate(inputs):
        out = tmp_path / f"loop{i}.so"
        assert main(["build-firmware", *args, "-o", str(out)]) == 0, args
        text = capsys.readouterr().out
        assert "skipped" in text and "DSP2833x_usDelay.asm: assembly: not compiled" in text
    run = _run(out, tmp_path, 0.02, loops="uint16", errors="uint16", rdata="uint16", sdata="uint16")
    # A word is 16 bits at LSPCLK / (SPIBRR + 1) = 37.5 MHz / 128: 54.6 µs; the CPU's work between words
    # (a few dozen accesses and blocks at 150 MHz, < 2 µs) adds to it.
    frame_s = 16 * 128 / LSPCLK_HZ
    assert run.final["errors"] == 0
    assert 0.02 / (frame_s + 2e-6) - 1 <= run.final["loops"] <= 0.02 / frame_s
    assert run.final["rdata"] == run.final["sdata"] - 1


def test_the_ti_style_led_blink_runs_its_timer_under_the_frequency_guard(tmp_path: Path):
    """ConfigCpuTimer under `#if (CPU_FRQ_150MHZ)` compiles in (the profile's clocks define it): the
    timer 0 interrupt comes every 0.5 s and toggles GPIO34; at 100 MHz the other guard is taken and the
    period stays 0.5 s."""
    out = tmp_path / "blink.so"
    assert main(["build-firmware", str(TI_STYLE / "led_blink"), "-o", str(out)]) == 0
    run = _run(out, tmp_path, 2.2, ticks="uint16", led="uint16")
    assert run.final == {"ticks": 4, "led": 0}  # toggled 4 times from 0
    assert run.isr_rows == 4
    slow = load_profile("reference", ["clocks.crystal_hz=20000000"])  # 20 MHz × 10 / 2 = 100 MHz
    fw = build_firmware([TI_STYLE / "led_blink"], tmp_path / "blink100.so", profile=slow)
    run = run_c_firmware(fw, None, slow, globals_file=write_globals(tmp_path, ticks="uint16"), until_s=1.2)
    assert run.final["ticks"] == 2


#: The timer 0 period of the pie_vect_copy example: ConfigCpuTimer(&CpuTimer0, 150, 1000), 1 ms.
PIE_VECT_TICK_S = 1e-3


@pytest.mark.parametrize("copy", ["uint32 words", "memcpy"])
def test_a_vector_table_copied_as_ti_copies_it_reaches_the_pie(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], copy: str
):
    """The project's own DSP2833x_PieVect.c, in TI's idiom (PieVectTableInit copied into PieVectTable
    through `Uint32 *` locals, `*to++ = *from++`, or by one memcpy), is compiled as given (not left
    out) and fills the emulated PIE's table: the TINT0 ISR the table holds (nothing sets
    PieVectTable.TINT0 itself) runs every tick, and the vectors past the first 64 read back as the
    table's, as pointers and as 32-bit words."""
    out = tmp_path / "pie.so"
    defines = ["-D", "COPY_WITH_MEMCPY"] if copy == "memcpy" else []
    assert main(["build-firmware", str(TI_STYLE / "pie_vect_copy"), *defines, "-o", str(out)]) == 0
    assert "left out" not in capsys.readouterr().out
    until_s = 0.02
    run = _run(out, tmp_path, until_s, ticks="uint16", high="uint16")
    assert run.final["high"] == 1
    # The timer starts within the first tick period of main: one tick fewer than whole periods, at most.
    whole = round(until_s / PIE_VECT_TICK_S)
    assert whole - 1 <= run.final["ticks"] == run.isr_rows <= whole


def test_tis_global_variable_defs_compiles_as_given_with_tis_headers(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
):
    """With TI's headers on the include path (a DSP2833x_Device.h of the project's: here one that
    adds an unmodelled peripheral's structure to ours), the project's DSP2833x_GlobalVariableDefs.c,
    which defines the register files under TI's DATA_SECTION pragmas, is compiled as given: its
    definitions become declarations of the objects the build places, so SpiaRegs, PieCtrlRegs and
    PieVectTable still reach the emulated board (SPI-A's loopback, the timer's ISR). With the
    replacement headers it is left out (some of the structures it defines, the external interrupts'
    XINTRUPT_REGS among them, are not declared there)."""
    inc = tmp_path / "include"
    inc.mkdir()
    (inc / "DSP2833x_Device.h").write_text(
        "#include_next <DSP2833x_Device.h>\n"
        "#ifndef PROJECT_XINTRUPT_REGS\n#define PROJECT_XINTRUPT_REGS\n"
        "struct XINTRUPT_REGS { Uint16 XINT1CR; Uint16 XINT2CR; };\n"
        "extern volatile struct XINTRUPT_REGS XIntruptRegs;\n#endif\n"
    )
    src = tmp_path / "src"
    src.mkdir()
    defs = '#include "DSP2833x_Device.h"\n'
    for name, typ in [
        ("XIntruptRegs", "volatile struct XINTRUPT_REGS"),
        ("CpuTimer0Regs", "volatile struct CPUTIMER_REGS"),
        ("PieCtrlRegs", "volatile struct PIE_CTRL_REGS"),
        ("PieVectTable", "struct PIE_VECT_TABLE"),
        ("SpiaRegs", "volatile struct SPI_REGS"),
    ]:
        defs += f'#ifdef __cplusplus\n#pragma DATA_SECTION("{name}File")\n#else\n'
        defs += f'#pragma DATA_SECTION({name},"{name}File");\n#endif\n{typ} {name};\n'
    (src / "DSP2833x_GlobalVariableDefs.c").write_text(defs)
    (src / "main.c").write_text(
        '#include "DSP2833x_Device.h"\n'
        '#include "DSP2833x_Examples.h"\n'
        "Uint16 ticks, echo, xint;\n"
        "interrupt void tick(void) { ticks++; PieCtrlRegs.PIEACK.all = PIEACK_GROUP1; }\n"
        "void main(void) {\n"
        "    InitSysCtrl();\n"
        "    DINT;\n"
        "    InitPieCtrl();\n"
        "    IER = 0; IFR = 0;\n"
        "    InitPieVectTable();\n"
        "    EALLOW; PieVectTable.TINT0 = &tick; EDIS;\n"
        "    XIntruptRegs.XINT1CR = 0x0005; xint = XIntruptRegs.XINT1CR;\n"
        "    SpiaRegs.SPICCR.all = 0x000F;\n"
        "    SpiaRegs.SPICTL.all = 0x0006;\n"
        "    SpiaRegs.SPIBRR = 0x007F;\n"
        "    SpiaRegs.SPICCR.all = 0x009F;\n"
        "    SpiaRegs.SPITXBUF = 0x1234;\n"
        "    while (SpiaRegs.SPISTS.bit.INT_FLAG != 1) {}\n"
        "    echo = SpiaRegs.SPIRXBUF;\n"
        "    InitCpuTimers();\n"
        "    ConfigCpuTimer(&CpuTimer0, 150, 1000);\n"
        "    CpuTimer0Regs.TCR.all = 0x4001;\n"
        "    IER |= M_INT1;\n"
        "    PieCtrlRegs.PIEIER1.bit.INTx7 = 1;\n"
        "    EINT;\n"
        "    for (;;) {}\n"
        "}\n"
    )
    out = tmp_path / "defs.so"
    assert main(["build-firmware", str(src), "-I", str(inc), "-o", str(out)]) == 0
    assert "left out" not in capsys.readouterr().out
    run = _run(out, tmp_path, 0.01, ticks="uint16", echo="uint16", xint="uint16")
    assert run.final["echo"] == 0x1234 and run.final["xint"] == 0x0005
    assert 9 <= run.final["ticks"] <= 10  # 1 ms ticks from a start within the first millisecond
    # Against the replacement headers, the same file is left out (and the build says so).
    (src / "main.c").write_text(
        (src / "main.c")
        .read_text()
        .replace(" XIntruptRegs.XINT1CR = 0x0005; xint = XIntruptRegs.XINT1CR;", "")
    )
    assert main(["build-firmware", str(src), "-o", str(out)]) == 0
    assert "TI's DSP2833x_GlobalVariableDefs.c left out" in capsys.readouterr().out


def test_the_ccs_project_gives_its_sources_includes_and_defines():
    project = read_project([TI_STYLE / "spi_loopback" / ".cproject"])
    names = sorted(s.name for s in project.sources)
    assert "spi_loopback.c" in names and "DSP2833x_SysCtrl.c" in names
    assert [p.name for p, _ in project.skipped] == ["DSP2833x_CodeStartBranch.asm", "DSP2833x_usDelay.asm"]
    assert TI_STYLE / "spi_loopback" / "include" in project.include
    assert project.defines == ["_DEBUG", "LARGE_MODEL"]


def test_include_and_define_options(tmp_path: Path):
    inc = tmp_path / "inc"
    inc.mkdir()
    (inc / "board.h").write_text("#define BOARD_VALUE 41\n")
    src = tmp_path / "main.c"
    src.write_text('#include "board.h"\nUint16 v;\nvoid main(void) { v = BOARD_VALUE + EXTRA; }\n')
    out = tmp_path / "fw.so"
    assert main(["build-firmware", str(src), "-I", str(inc), "-D", "EXTRA=1", "-o", str(out)]) == 0
    assert _run(out, tmp_path, 1.0, v="uint16").final["v"] == 42


# --- a third-party driver in plain C -----------------------------------------------------------------


def test_a_third_party_c_driver_builds_from_its_source(tmp_path: Path):
    """The imu164 driver (plain C: compound literals, its own frame macros, malloc, a cast to a union)
    with only the board's pin and SPI port mapping (f28335_port.c) reads the reference board's
    ADIS16407: PROD_ID 0x4017, and a sample every loop."""
    out = tmp_path / "imu.so"
    assert main(["build-firmware", str(SENSOR), "-o", str(out)]) == 0
    run = run_c_firmware(
        out, None, load_profile("reference"), globals_file=SENSOR / "globals.toml", until_s=0.05
    )
    assert run.final["product"] == 0x4017 and run.final["probed"] == 1
    # A loop: 8 frames of 16 bits at 0.75 MHz (21.3 µs each), each after a 20 µs stall, DELAY_US(1000);
    # after the 10 ms start-up and the probe, 40 ms hold at most 40 / 1.331 = 30.1 loops.
    loop_s = 8 * (16 / 0.75e6 + 20e-6) + 1e-3
    assert 0.9 * 0.04 / loop_s <= run.final["samples"] <= 0.04 / loop_s + 1


# --- bad input --------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("body", "expected"),
    [
        ("    SpiaRegs.SPIFOO.all = 1;\n", "SPIFOO"),
        ("    Uint16 x = ;\n", "expected expression"),
    ],
)
def test_a_source_that_does_not_compile_is_exit_2_with_file_and_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], body: str, expected: str
):
    src = tmp_path / "bad.c"
    src.write_text('#include "DSP2833x_Device.h"\nvoid main(void) {\n' + body + "}\n")
    out = tmp_path / "fw.so"
    out.write_bytes(b"earlier build")
    assert main(["build-firmware", str(src), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "bad.c:3" in err and expected in err and "Traceback" not in err
    assert out.read_bytes() == b"earlier build"


def test_a_gbk_source_builds_and_its_errors_are_quoted(tmp_path: Path, capsys: pytest.CaptureFixture[str]):
    """A source with GBK comments (as Chinese projects have) builds; a compile error in it is exit 2
    with the compiler's message (UnicodeDecodeError and exit 3 before)."""
    good = tmp_path / "gbk.c"
    good.write_bytes("/* 初始化 SPI */\nUint16 v;\nvoid main(void) { v = 1; }\n".encode("gbk"))
    assert main(["build-firmware", str(good), "-o", str(tmp_path / "ok.so")]) == 0
    bad = tmp_path / "gbkbad.c"
    bad.write_bytes("/* 初始化 */\nvoid main(void) {\n    undefined_thing = 1; /* 错误 */\n}\n".encode("gbk"))
    assert main(["build-firmware", str(bad), "-o", str(tmp_path / "bad.so")]) == 2
    err = capsys.readouterr().err
    assert "gbkbad.c:3" in err and "undefined_thing" in err and "Traceback" not in err


def test_a_link_error_names_the_symbol_and_where(tmp_path: Path, capsys: pytest.CaptureFixture[str]):
    src = tmp_path / "main.c"
    src.write_text("void InitAdcSomething(void);\nvoid main(void) {\n    InitAdcSomething();\n}\n")
    out = tmp_path / "fw.so"
    assert main(["build-firmware", str(src), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "undefined reference to `InitAdcSomething'" in err and "main.c:3" in err
    assert not out.exists()


def test_inputs_that_are_not_sources(tmp_path: Path):
    with pytest.raises(InputError, match="no such file"):
        read_project([tmp_path / "missing.c"])
    (tmp_path / "notes.txt").write_text("x")
    with pytest.raises(InputError, match="not a C or C\\+\\+ source"):
        read_project([tmp_path / "notes.txt"])
    with pytest.raises(InputError, match="-D 1BAD"):
        build_firmware([SENSOR], tmp_path / "x.so", defines=["1BAD"])


# --- diagnostics at enable time ---------------------------------------------------------------------


def test_enabling_an_interrupt_the_emulator_cannot_raise_is_an_event(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
):
    """An interrupt the firmware enables and no modelled peripheral raises is an
    `interrupt_never_raised` warning of the run's event stream, once per line, at the enabling
    write's time, in `run --firmware`'s summary and its parts; lines the board raises are not."""
    src = tmp_path / "irq.c"
    src.write_text(
        '#include "DSP28x_Project.h"\n'
        "Uint16 done;\n"
        "void main(void) {\n"
        "    PieCtrlRegs.PIEIER9.bit.INTx5 = 1;\n"
        "    PieCtrlRegs.PIEIER9.bit.INTx5 = 1;\n"
        "    PieCtrlRegs.PIEIER6.bit.INTx1 = 1;\n"
        "    PieCtrlRegs.PIEIER1.bit.INTx7 = 1;\n"
        "    IER |= M_INT9 | M_INT6 | M_INT1 | M_INT13;\n"
        "    IER |= M_RTOS;\n"
        "    done = 1;\n"
        "}\n"
    )
    fw = build_firmware([src], tmp_path / "irq.so")
    parts: list[dict] = []
    result = run_c_firmware(
        fw,
        None,
        load_profile("reference"),
        globals_file=write_globals(tmp_path, done="uint16"),
        until_s=0.05,
        sink=parts.append,
    )
    assert result.final["done"] == 1
    events = [e for p in parts for e in p["events"] if e["kind"] == "interrupt_never_raised"]
    # ECAN0INTA once (enabled twice), RTOSINT; SPI-A's FIFO interrupts, timer 0 through the PIE and
    # timer 1 on INT13 are the board's.
    assert [e["message"].split(",")[0] for e in events] == [
        "the firmware enables ECAN0INTA (PIE group 9",
        "the firmware enables RTOSINT (IER bit 15)",
    ]
    assert "INT9.5, vector 100" in events[0]["message"]
    assert all(e["severity"] == "warning" for e in events)
    # At the enabling writes: the first basic blocks of main, before 0.05 s of virtual time.
    assert 0 <= events[0]["t_s"] <= events[1]["t_s"] < 1e-3
    # The same in `run --firmware`'s summary (a trace of its own: run needs one).
    globals_toml = write_globals(tmp_path, done="uint16")
    rc = main(
        [
            "run",
            str(PITCH_SWEEP),
            "--firmware",
            str(fw),
            "--globals",
            str(globals_toml),
            "--until-s",
            "0.05",
            "--json",
        ]
    )
    out = capsys.readouterr()
    assert rc == 0, out.err
    summary = json.loads(out.out)
    assert summary["events"]["by_kind"]["interrupt_never_raised"]["count"] == 2
    assert "cannot raise" not in out.err


def test_a_projects_own_examples_header_takes_the_place_of_ours(tmp_path: Path):
    """A project with its own copy of TI's DSP2833x_Examples.h on its path (found before the
    replacement): its clock macros and its DELAY_US, which calls TI's DSP28x_usDelay (an assembly
    loop of 5 cycles a pass plus 9 of call and return, provided by the runtime), work as on the chip."""
    inc = tmp_path / "common" / "include"
    inc.mkdir(parents=True)
    (inc / "DSP2833x_Examples.h").write_text(
        "#ifndef PROJECT_EXAMPLES_H\n#define PROJECT_EXAMPLES_H\n"
        '#include "DSP2833x_GlobalPrototypes.h"\n'
        "#define CPU_FRQ_150MHZ 1\n#define CPU_FRQ_100MHZ 0\n#define CPU_RATE 6.667L\n"
        "/* Count for a delay of A us: A us = (5 Count + 9) cycles of CPU_RATE ns. */\n"
        "#define DELAY_US(A) \\\n"
        "    DSP28x_usDelay((Uint32)(((long double)(A) * 1000.0L / CPU_RATE - 9.0L) / 5.0L))\n"
        "#endif\n"
    )
    src = tmp_path / "main.c"
    src.write_text(
        '#include "DSP2833x_Device.h"\n#include "DSP2833x_Examples.h"\n'
        "Uint16 fast;\n"
        "void main(void) {\n"
        "#if CPU_FRQ_150MHZ\n    fast = 1;\n#endif\n"
        "    DELAY_US(1000);\n"
        "}\n"
    )
    out = tmp_path / "fw.so"
    assert main(["build-firmware", str(src), "-I", str(inc), "-o", str(out)]) == 0
    run = _run(out, tmp_path, 1.0, fast="uint16")
    assert run.final["fast"] == 1
    # Count = (1000 µs / 6.667 ns − 9) / 5 = 29 995 passes: 149 984 cycles = 999.9 µs at 150 MHz,
    # then main returns after a few accesses and blocks (< 1 µs).
    assert 999.8e-6 < run.now_s < 1001e-6


def test_polling_a_register_that_never_changes_names_the_loop(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
):
    """A wait on a register of a peripheral not modelled (plain memory: it never changes by itself)
    with interrupts off can never end: exit 2 naming the register and the loop's file:line."""
    src = tmp_path / "wait.c"
    src.write_text(
        '#include "DSP28x_Project.h"\n'
        "Uint16 state;\n"
        "void main(void) {\n"
        "    DINT;\n"
        "    while (SysCtrlRegs.PLLSTS.bit.PLLLOCKS != 0) {\n"
        "    }\n"
        "}\n"
    )
    out = tmp_path / "fw.so"
    assert main(["build-firmware", str(src), "-o", str(out)]) == 0
    with pytest.raises(InputError, match=r"polls the register at 0x7011.*wait\.c:5"):
        _run(out, tmp_path, 1.0, state="uint16")


def test_a_cproject_include_path_of_another_machine_is_the_projects_copy(tmp_path: Path):
    """A .cproject written on the user's Windows machine names TI's folders where controlSUITE was
    installed there; the project keeps a copy of them: that copy is on the path."""
    project = tmp_path / "proj"
    headers = project / "DSP2833x_headers" / "include"
    headers.mkdir(parents=True)
    (project / "main.c").write_text("void main(void) {}\n")
    (project / ".project").write_text("<projectDescription><name>p</name></projectDescription>\n")
    (project / ".cproject").write_text(
        '<cproject><configuration name="Debug"><option superClass="x.compilerID.INCLUDE_PATH">'
        '<listOptionValue value="&quot;C:\\ti\\controlSUITE\\device_support\\f2833x\\v140'
        '\\DSP2833x_headers\\include&quot;"/>'
        '<listOptionValue value="&quot;D:\\nowhere\\include&quot;"/>'
        "</option></configuration></cproject>\n"
    )
    assert read_project([project]).include == [headers]
