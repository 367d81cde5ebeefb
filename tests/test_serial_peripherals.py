"""SCI-A/B/C as the user's C firmware drives them (issue 39): TI-style FIFO digital loopback, polled and
with interrupts (PIE groups 9 and 8), a GPS's NMEA file received on SCI-B at 9600 Bd with the line's
timing, what a port transmits captured with its prefix, and the errors (a bad file named, a wrong baud
read as framing errors). The firmwares are under firmware_c/examples/ti_style/sci_*."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from conftest import run_alone, write_globals
from sins_fw.errors import InputError
from sins_fw.firmware_build import build_firmware
from sins_fw.firmware_run import run_c_firmware
from sins_fw.profile import load_profile

ROOT = Path(__file__).resolve().parents[1]
TI_STYLE = ROOT / "firmware_c" / "examples" / "ti_style"

#: LSPCLK = SYSCLKOUT / 4 = 37.5 MHz (InitSysCtrl: LOSPCP = 2) in the reference profile.
LSPCLK_HZ = 37.5e6
SYSCLKOUT_HZ = 150e6


pytestmark = pytest.mark.usefixtures("cabi_library")


#: A register access's cycles (c28x-costs.toml [io] peripheral_read / peripheral_write: 1 + the
#: peripheral frame's 2 wait states).
ACCESS_CYCLES = 3


def _pass_s(fn_cycles: Path, accesses: int, passes: int) -> float:
    """An upper bound of the CPU's time for one pass of the firmware's main loop, s: every cycle the
    run charged main's own blocks (the runtime's per-function counters, SINS_FW_FUNCTION_CYCLES:
    docs/c-cycles.md) and every register access, over the passes. The waits inside the pass (the
    polling loops) are in it too, so it bounds the time the code adds between two characters."""
    rows = dict(line.split("\t", 1) for line in fn_cycles.read_text(encoding="utf-8").splitlines())
    main = int(rows["sins_fw_user_main"].split("\t")[0])
    return (main + ACCESS_CYCLES * accesses) / passes / SYSCLKOUT_HZ


def _char_s(brr: int, bits: int = 10) -> float:
    """A character's time on the line: `bits` bits at LSPCLK / ((BRR + 1) · 8) (SPRUFZ5)."""
    return bits * (brr + 1) * 8 / LSPCLK_HZ


def test_sci_fifo_loopback_polled_returns_each_character_at_the_baud(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
):
    fw = build_firmware([TI_STYLE / "sci_loopback" / "sci_loopback.c"], tmp_path / "poll.so")
    until = 0.02
    monkeypatch.setenv("SINS_FW_FUNCTION_CYCLES", str(tmp_path / "fn.tsv"))
    run = run_c_firmware(
        fw,
        None,
        load_profile("reference"),
        globals_file=write_globals(tmp_path, loops="uint16", errors="uint16", rdata="uint16", sdata="uint16"),
        until_s=until,
    )
    char = _char_s(0x0F)  # 34.1 µs
    assert run.final["errors"] == 0
    assert run.final["rdata"] == (run.final["sdata"] - 1) % 256
    # One character per pass; the CPU's pass between characters adds to the line's time, at most
    # one pass of the loop (measured: 60 cycles of main's blocks and 6.2 accesses a pass, 0.53 µs).
    code = _pass_s(tmp_path / "fn.tsv", run.accesses, int(run.final["loops"]))
    assert code < char / 10
    assert until / (char + code) - 1 <= run.final["loops"] <= until / char


INT_GLOBALS = ("rx_a", "tx_a", "rx_c", "tx_c", "errors")


def test_sci_fifo_loopback_with_interrupts_on_groups_9_and_8(tmp_path: Path):
    fw = build_firmware([TI_STYLE / "sci_loopback_int" / "sci_loopback_int.c"], tmp_path / "int.so")
    until = 0.01
    run = run_c_firmware(
        fw,
        None,
        load_profile("reference"),
        globals_file=write_globals(tmp_path, **dict.fromkeys(INT_GLOBALS, "uint16")),
        until_s=until,
    )
    f = run.final
    assert f["errors"] == 0
    # Each RX interrupt takes two characters back to back: 2 · 34.1 µs on the line.
    pairs = until / (2 * _char_s(0x0F))
    for port in ("a", "c"):
        assert pairs - 2 <= f[f"rx_{port}"] <= pairs
        # The TX interrupt runs whenever TXFFST ≤ 2: at most two pairs ahead of the receiver.
        assert 0 <= f[f"tx_{port}"] - f[f"rx_{port}"] <= 2
    assert run.isr_rows == sum(f[k] for k in ("rx_a", "tx_a", "rx_c", "tx_c"))


NMEA = b"$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47\r\n$GPRMC,1*00\r\n"
GPS_GLOBALS = {
    "chars": "uint16",
    "lines": "uint16",
    "dollars": "uint16",
    "rx_errors": "uint16",
    "t_line1": "uint32",
    "t_line2": "uint32",
}


def _gps_run(tmp_path: Path, *overrides: str) -> tuple[Any, list[dict[str, Any]]]:
    """The GPS firmware's run (main's cycles in ``tmp_path/fn.tsv``) and its events."""
    nmea = tmp_path / "gps.nmea"
    nmea.write_bytes(NMEA)
    fw = build_firmware([TI_STYLE / "sci_gps" / "sci_gps.c"], tmp_path / "gps.so")
    profile = load_profile(
        "reference",
        [
            f"serial.sci_b.rx_file={nmea}",
            "serial.sci_b.rx_baud=9600",
            "serial.sci_b.rx_start_s=0.1",
            "serial.sci_b.rx_line_period_s=1.0",
            *overrides,
        ],
    )
    with pytest.MonkeyPatch.context() as env:
        env.setenv("SINS_FW_FUNCTION_CYCLES", str(tmp_path / "fn.tsv"))
        return run_alone(fw, tmp_path, 1.5, profile, **GPS_GLOBALS)


def test_scib_receives_an_nmea_file_at_9600_baud_with_the_line_timing(tmp_path: Path):
    run, events = _gps_run(tmp_path)
    f = run.final
    line1 = NMEA.index(b"\n") + 1
    assert f["chars"] == len(NMEA) and f["lines"] == 2 and f["dollars"] == 2 and f["rx_errors"] == 0
    # The first sentence's '\n' ends line1 characters (10 bits each at 9600 Bd) after its start at
    # 0.1 s; the second sentence starts 1 s after the first. The polling loop reads it within one pass
    # of the main loop (the bound from the run's own counts: :func:`_pass_s`, one pass a character;
    # measured 1.21 µs).
    char = 10 / 9600
    end1 = 0.1 + line1 * char
    end2 = 1.1 + (len(NMEA) - line1) * char
    code = _pass_s(tmp_path / "fn.tsv", run.accesses, len(NMEA))
    assert code < char / 10
    assert 0 <= f["t_line1"] / SYSCLKOUT_HZ - end1 < code
    assert 0 <= f["t_line2"] / SYSCLKOUT_HZ - end2 < code
    # The echo on SCI-A is captured per line, with the port's prefix, when its stop bit ends.
    lines = [e for e in events if e["kind"] == "sci_tx_line"]
    sent = [s.decode().replace("\r", "\\r").replace("\n", "\\n") for s in NMEA.splitlines(keepends=True)]
    assert [e["message"] for e in lines] == [f"SCI-A> {s}" for s in sent]
    echo_char = _char_s(40)
    assert 0 < lines[0]["t_s"] - end1 < echo_char + code


def test_a_wrong_baud_reads_framing_errors_reported_once(tmp_path: Path):
    """SCI-B at 19 200 Bd against the GPS's 9600 Bd: every character with SCIFFFE, one event."""
    nmea = tmp_path / "gps.nmea"
    nmea.write_bytes(NMEA)
    run, events = _gps_run(tmp_path, "serial.sci_b.rx_baud=19200")
    assert run.final["rx_errors"] == len(NMEA)
    framing = [e for e in events if e["kind"] == "uart_framing_error"]
    assert len(framing) == 1
    assert "19200 Bd" in framing[0]["message"] and "SCI-B" in framing[0]["message"]


def test_a_missing_receive_file_is_named(tmp_path: Path):
    missing = tmp_path / "nope.nmea"
    with pytest.raises(InputError) as e:
        load_profile("reference", [f"serial.sci_b.rx_file={missing}"])
    assert "serial.sci_b.rx_file" in str(e.value) and str(missing) in str(e.value)
    with pytest.raises(InputError, match=r"serial\.sci_c\.rx_baud"):
        load_profile("reference", ["serial.sci_c.rx_baud=10"])
    with pytest.raises(InputError, match="did you mean"):
        load_profile("reference", ["serial.sci_b.rx_fil=x"])


def test_sci_misuse_is_an_event(tmp_path: Path):
    """A character written with the SCI held in reset, and SCIRXBUF read with the FIFO empty."""
    src = tmp_path / "misuse.c"
    src.write_text(
        '#include "DSP28x_Project.h"\n'
        "Uint16 r;\n"
        "void main(void) {\n"
        "    SciaRegs.SCITXBUF = 0x41;\n"
        "    SciaRegs.SCIFFTX.all = 0xE040;\n"
        "    SciaRegs.SCICTL1.all = 0x0023;\n"
        "    r = SciaRegs.SCIRXBUF.all;\n"
        "    for (;;) {}\n"
        "}\n"
    )
    fw = build_firmware([src], tmp_path / "misuse.so")
    events: list[dict[str, Any]] = []
    with pytest.raises(InputError):  # the idle loop with nothing to interrupt it
        run_alone(fw, tmp_path, 0.01, events=events, r="uint16")
    misuse = [e["message"] for e in events if e["kind"] == "sci_misuse"]
    assert len(misuse) == 2, events
    assert "held in reset" in misuse[0] and "RX FIFO empty" in misuse[1]
