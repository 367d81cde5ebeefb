"""Robustness: bad input fails clearly (exit code 2, one message naming the file and key, never a
traceback), what a run must report is reported as an event, an interrupted run loses nothing and
says how far it got, every output file is written atomically, and outputs are byte-reproducible."""

from __future__ import annotations

import json
import os
import pty
import re
import select
import signal
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import numpy as np
import pytest

from conftest import ROOT, run_cli
from sins_fw import atomic, synth
from sins_fw.cli import main
from sins_fw.run_output import load_run
from sins_fw.tablefile import write_csv
from sins_fw.traces import PHYSICAL_SCHEMA

BAD = ROOT / "tests" / "data" / "bad"
PROFILES = BAD / "profiles"
HANDLED = BAD / "handled"
STATIC = ROOT / "traces" / "static_60s.h5"


def _cli(capsys, *args: str) -> tuple[int, str, str]:
    """`sins-fw ARGS` in this process (the same code as the console script, without its start-up)."""
    code = main(list(args))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


# ---------------------------------------------------------------------------------------------------
# Bad profiles
# ---------------------------------------------------------------------------------------------------

PROFILE_CASES = sorted(tomllib.loads((PROFILES / "cases.toml").read_text(encoding="utf-8"))["cases"].items())


def test_profile_corpus_table_covers_every_file():
    files = sorted(p.name for p in PROFILES.glob("*.toml") if p.name != "cases.toml")
    assert [name for name, _ in PROFILE_CASES] == files
    assert len(files) >= 30


@pytest.mark.parametrize(("name", "fragment"), PROFILE_CASES, ids=[c[0] for c in PROFILE_CASES])
def test_bad_profile_is_refused_by_board_and_run(capsys, tmp_path, name, fragment):
    path = str(PROFILES / name)
    for args in (
        ["board", "--profile", path],
        ["run", str(STATIC), "--profile", path, "--out", str(tmp_path / "o.h5")],
    ):
        code, out, err = _cli(capsys, *args)
        assert code == 2, (args, out, err)
        assert fragment in err, err
        assert "Traceback" not in err and "panicked" not in err
        assert out == ""
    assert list(tmp_path.iterdir()) == []


def test_bad_profile_through_the_console_script():
    # The same as above in a separate process, as a user runs it.
    r = run_cli("board", "--profile", str(PROFILES / "sens_avg_75_with_m2.toml"))
    assert r.code == 2 and "so write 0x0104" in r.err and "Traceback" not in r.err, r.err
    r = run_cli(
        "run", str(STATIC), "--set", "firmware.initial_attitude=level", "--set", "firmware.alignment_s=0"
    )
    assert r.code == 2 and '`firmware.initial_attitude` = "level"' in r.err, r.err


# ---------------------------------------------------------------------------------------------------
# Bad traces through `sins-fw run` (test_traces.py takes them through the loader and `import`)
# ---------------------------------------------------------------------------------------------------


def _trace_corpus() -> list[tuple[str, str]]:
    rows = re.findall(
        r"^\| (\S+\.(?:csv|h5)) \| (.+) \|$", (BAD / "README.md").read_text(encoding="utf-8"), re.M
    )
    return [(name, fragment.replace("\\|", "|")) for name, fragment in rows]


TRACE_CASES = _trace_corpus()


@pytest.mark.parametrize(("name", "fragment"), TRACE_CASES, ids=[c[0] for c in TRACE_CASES])
def test_bad_trace_through_run(capsys, tmp_path, name, fragment):
    code, out, err = _cli(capsys, "run", str(BAD / name), "--out", str(tmp_path / "o.csv"))
    assert code == 2, (out, err)
    assert "Traceback" not in err and "panicked" not in err
    assert str(BAD / name) in err, err
    # `run` replays raw-register traces, so a bad one gets the raw reader's documented message too.
    assert fragment in err, err
    assert list(tmp_path.iterdir()) == []  # no output, not even a temporary file


def test_far_beyond_range_saturates_with_events(capsys, tmp_path):
    out = tmp_path / "o.csv"
    code, text, err = _cli(capsys, "run", str(HANDLED / "far_beyond_range.csv"), "--out", str(out), "--json")
    assert code == 0, err
    by_kind = json.loads(text)["events"]["by_kind"]
    # x gyro (1e6 °/s), y gyro (-1e300 °/s) and z accel (1000 g) clip at every read.
    reads = json.loads(text)["budget"]["ticks"]
    assert by_kind["saturated_reading"]["count"] == 3 * reads
    assert "code at the 14-bit limit" in by_kind["saturated_reading"]["first_message"]
    _, cols = load_run(out)
    assert all(np.isfinite(v).all() for v in cols.values()), "no NaN or infinity in the output"


def test_gap_is_an_error_or_with_allow_gaps_an_event(capsys, tmp_path):
    trace = str(HANDLED / "time_gap_2s.csv")
    code, _, err = _cli(capsys, "run", trace)
    assert (
        code == 2 and "gap of 0.51 s (51 sample periods) after time 0.99 s" in err and "--allow-gaps" in err
    )
    out = tmp_path / "o.h5"
    code, text, err = _cli(capsys, "run", trace, "--allow-gaps", "--json", "--out", str(out))
    assert code == 0, err
    gap = json.loads(text)["events"]["by_kind"]["input_gap"]
    assert gap["count"] == 1 and gap["first_t_s"] == pytest.approx(0.99)
    assert "interpolated linearly" in gap["first_message"]
    _, cols = load_run(out)
    assert all(np.isfinite(v).all() for v in cols.values())


@pytest.mark.parametrize(("name", "fragment"), TRACE_CASES[::4], ids=[c[0] for c in TRACE_CASES[::4]])
def test_an_output_aliasing_a_corpus_input_is_refused_before_the_input_is_read(
    capsys, tmp_path, name, fragment
):
    """The aliasing refusal comes first, whatever the input holds: the file itself, a symlink, a hard
    link and a `..` path to it as --out or --raw-out; the corpus file is left byte for byte."""
    trace = tmp_path / name
    trace.write_bytes((BAD / name).read_bytes())
    (tmp_path / "sub").mkdir()
    (tmp_path / f"sym{trace.suffix}").symlink_to(trace)
    os.link(trace, tmp_path / f"hard{trace.suffix}")
    for option, alias in [
        ("--out", trace),
        ("--out", tmp_path / f"sym{trace.suffix}"),
        ("--raw-out", tmp_path / f"hard{trace.suffix}"),
        ("--raw-out", tmp_path / "sub" / ".." / name),
    ]:
        code, _, err = _cli(capsys, "run", str(trace), option, str(alias))
        assert code == 2 and option in err and "TRACE" in err and "Traceback" not in err, (option, err)
        assert trace.read_bytes() == (BAD / name).read_bytes()


#: Hostile commands beyond one bad file: (arguments, the fragment of the one error line).
HOSTILE_COMMANDS = {
    "synth latitude 95": (["synth", "static", "--latitude-deg", "95"], "latitude"),
    "synth latitude 1e6": (["synth", "static", "--latitude-deg", "1e6"], "latitude"),
    "synth height 1e9": (["synth", "static", "--height-m", "1e9"], "height"),
    "override over a line break": (["board", "--set", "spi.spibrr=49\nspi.spibrr=9"], "line break"),
    "run --until-s nan": (
        ["run", str(STATIC), "--until-s", "nan"],
        "--until-s = nan: expected a finite number",
    ),
    "run --until-s -1": (
        ["run", str(STATIC), "--until-s", "-1"],
        "--until-s = -1.0: expected a finite number",
    ),
    "montecarlo --param abc": (["montecarlo", "static", "--param", "duration-s=abc"], "duration_s"),
}


@pytest.mark.parametrize("case", sorted(HOSTILE_COMMANDS))
def test_hostile_command_is_exit_2_with_one_message(capsys, tmp_path, case):
    args, fragment = HOSTILE_COMMANDS[case]
    if args[0] == "synth":
        args = [*args, "--out", str(tmp_path / "s.h5")]
    code, out, err = _cli(capsys, *args)
    assert code == 2, (out, err)
    assert err.startswith("sins-fw: error: ") and fragment in err and "Traceback" not in err, err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("until", ["abc", "nan", "inf", "-1", "0"])
def test_a_run_output_with_a_bad_until_s_is_exit_2_naming_it(capsys, tmp_path, until):
    import h5py

    trace, out = tmp_path / "t.csv", tmp_path / "o.h5"
    synth.generate("static", duration_s=0.3).save(trace)
    assert _cli(capsys, "run", str(trace), "--out", str(out), "--until-s", "0.2")[0] == 0
    with h5py.File(out, "r+") as f:
        f.attrs["until_s"] = until
    code, _, err = _cli(capsys, "replay", str(out), "--out", str(tmp_path / "r.rrd"))
    assert (
        code == 2
        and f"{out}: metadata `until_s` = " in err
        and "expected a finite number of seconds > 0" in err
    ), err


# ---------------------------------------------------------------------------------------------------
# Interrupted runs
# ---------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def long_trace(tmp_path_factory) -> Path:
    """A 30-minute static trace (1.47 M samples): long enough to interrupt mid-run."""
    path = tmp_path_factory.mktemp("long") / "static_30min.h5"
    synth.generate("static", duration_s=1800.0).save(path)
    return path


#: The progress bar once it has counted emulated seconds (`emulating:   4% 81.0/1.80k …`).
PROGRESS = re.compile(rb"emulating:\s+\d+%\S*\s*[|\s]*[^|]*?\b[1-9][0-9.]*k?/")


def _interrupt(long_trace: Path, out: Path, sig: signal.Signals) -> tuple[int, str]:
    """Run `sins-fw run` with stderr on a pseudo-terminal (so it shows its progress bar), send
    ``sig`` once the bar shows emulated time, and return the exit code and what stderr showed."""
    master, slave = pty.openpty()
    proc = subprocess.Popen(
        [sys.executable, "-m", "sins_fw", "run", str(long_trace), "--out", str(out)],
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=slave,
        cwd=ROOT,
        # A shell may start test runs with SIGINT ignored; the user's terminal would not.
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    os.close(slave)
    shown, sent = b"", False
    deadline = time.monotonic() + 300
    try:
        while time.monotonic() < deadline:
            ready, _, _ = select.select([master], [], [], 0.5)
            if ready:
                try:
                    chunk = os.read(master, 4096)
                except OSError:  # the child closed the terminal
                    break
                if not chunk:
                    break
                shown += chunk
                if not sent and PROGRESS.search(shown):
                    proc.send_signal(sig)
                    sent = True
            elif proc.poll() is not None:
                break
        code = proc.wait(timeout=60)
    finally:
        os.close(master)
        if proc.poll() is None:
            proc.kill()
    assert sent, f"the run never showed progress: {shown[-500:]!r}"
    return code, shown.decode("utf-8", "replace").replace("\r", "\n")


@pytest.mark.parametrize(
    ("sig", "code", "word"), [(signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated")]
)
def test_interrupted_run_keeps_the_previous_output_and_says_how_far_it_got(
    long_trace, tmp_path, sig, code, word
):
    out = tmp_path / "run.csv"
    out.write_text("the previous run's output\n", encoding="utf-8")
    got, shown = _interrupt(long_trace, out, sig)
    assert got == code, shown
    assert "Traceback" not in shown and "panicked" not in shown, shown
    message = next(line for line in shown.splitlines() if line.startswith("sins-fw:"))
    # Interrupted while emulating (the usual case) or, on a fast machine, while writing the file.
    emulated = re.search(r"after emulating ([0-9.e+]+) s of 1800 s of the trace", message)
    writing = re.search(r"while writing \S+ after emulating all ([0-9.e+]+) s", message)
    assert message.startswith(f"sins-fw: {word}: stopped ") and (emulated or writing), message
    assert 0 < float((emulated or writing).group(1)) <= 1800
    assert message.endswith(f"{out} left as it was"), message
    assert out.read_text(encoding="utf-8") == "the previous run's output\n"
    assert [p.name for p in tmp_path.iterdir()] == [out.name], "no temporary file left behind"


# ---------------------------------------------------------------------------------------------------
# Atomic writes
# ---------------------------------------------------------------------------------------------------

#: Low-level writes in the package: each must write a temporary path from sins_fw.atomic.
WRITE_CALL = re.compile(
    r"\.write_text\(|\.write_bytes\(|savefig\(|\.save\(str\("  # text, bytes, figures, Rerun recordings
    r"|\bopen\([^)]*[\"'][wa]b?[\"']|File\([^)]*[\"']w[\"']"  # open(..., "w"), h5py.File(..., "w")
)


def test_every_writer_in_the_package_writes_a_temporary_path():
    offenders = []
    for path in sorted((ROOT / "python" / "sins_fw").rglob("*.py")):
        if path.name == "atomic.py":
            continue
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            if WRITE_CALL.search(line) and "tmp" not in line and "atomic.write_" not in line:
                offenders.append(f"{path.relative_to(ROOT)}:{n}: {line.strip()}")
    assert not offenders, "write through sins_fw.atomic.atomic_path:\n" + "\n".join(offenders)


@pytest.fixture(scope="module")
def short_run():
    from sins_fw.harness import emulate

    return emulate(synth.generate("static", duration_s=0.5))


def _writers(short_run):
    from sins_fw import budget, golden
    from sins_fw.report_page import save_report
    from sins_fw.run_output import save_run
    from sins_fw.viewer import save_recording

    trace = synth.generate("static", duration_s=0.1)
    return {
        "run.csv": lambda p: save_run(short_run, p),
        "run.h5": lambda p: save_run(short_run, p),
        "trace.csv": trace.save,
        "trace.h5": trace.save,
        "report.png": lambda p: save_report(short_run, p),
        "budget.png": lambda p: budget.plot_report(budget.budget_report(short_run.profile, seconds=0.1), p),
        "recording.rrd": lambda p: save_recording(short_run, p),
        "hashes.toml": lambda p: atomic.write_text(p, golden.render(golden.load(golden.GOLDEN_FILE))),
    }


WRITTEN = (
    "run.csv",
    "run.h5",
    "trace.csv",
    "trace.h5",
    "report.png",
    "budget.png",
    "recording.rrd",
    "hashes.toml",
)


@pytest.mark.parametrize("name", WRITTEN)
def test_a_write_interrupted_at_the_last_moment_leaves_the_previous_file(
    tmp_path, monkeypatch, short_run, name
):
    write = _writers(short_run)[name]
    path = tmp_path / name
    path.write_bytes(b"previous")

    def interrupted(*_args, **_kwargs):
        raise KeyboardInterrupt

    # Everything is written; the interrupt comes just before the rename.
    monkeypatch.setattr(atomic.os, "replace", interrupted)
    with pytest.raises(KeyboardInterrupt):
        write(path)
    assert path.read_bytes() == b"previous"
    assert [p.name for p in tmp_path.iterdir()] == [name], "no temporary file left behind"
    monkeypatch.undo()
    write(path)
    assert path.read_bytes() != b"previous" and path.stat().st_size > 0
    assert [p.name for p in tmp_path.iterdir()] == [name]


# ---------------------------------------------------------------------------------------------------
# Determinism of the run output
# ---------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def moving_trace(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("moving") / "coning_20s.h5"
    synth.generate("coning", duration_s=20.0).save(path)
    return path


def _without_overrides_line(text: str) -> str:
    return "\n".join(line for line in text.splitlines() if not line.startswith("# overrides:"))


def test_run_output_is_byte_identical_across_runs_and_bus_levels(capsys, tmp_path, moving_trace):
    noise = ["--set", "errors.preset=adis16407", "--set", "errors.seed=7"]  # a seeded noise stream
    files = {}
    for name, extra in [("a", []), ("b", []), ("bit", ["--set", "spi.level=bit"])]:
        for ext in ("csv", "h5"):
            out = tmp_path / f"{name}.{ext}"
            code, _, err = _cli(capsys, "run", str(moving_trace), *noise, *extra, "--out", str(out))
            assert code == 0, err
            files[name, ext] = out.read_bytes()
    assert files["a", "csv"] == files["b", "csv"]
    assert files["a", "h5"] == files["b", "h5"]
    # The bit-level run records its override in the metadata; everything else is the same bytes.
    a, bit = files["a", "csv"].decode(), files["bit", "csv"].decode()
    assert '# overrides: ["errors.preset=adis16407", "errors.seed=7", "spi.level=bit"]' in bit
    assert _without_overrides_line(a) == _without_overrides_line(bit)
    _, cols_a = load_run(tmp_path / "a.h5")
    _, cols_bit = load_run(tmp_path / "bit.h5")
    assert cols_a.keys() == cols_bit.keys()
    for k in cols_a:
        assert cols_a[k].tobytes() == cols_bit[k].tobytes(), k


# ---------------------------------------------------------------------------------------------------
# Errors that are not the input's: the file system, and bugs
# ---------------------------------------------------------------------------------------------------


def test_an_output_path_through_a_file_is_exit_2_naming_it(capsys, tmp_path):
    blocker = tmp_path / "not_a_folder"
    blocker.write_text("")
    code, _, err = _cli(capsys, "run", str(STATIC), "--out", str(blocker / "run.csv"))
    assert code == 2 and f"{blocker / 'run.csv'}: {blocker} is not a folder" in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["not_a_folder"]


def test_a_bug_is_one_line_with_exit_3_and_a_traceback_only_with_debug(capsys, monkeypatch):
    from sins_fw.cli import board

    def broken(args):
        raise RuntimeError("a bug")

    monkeypatch.setattr(board, "run", broken)
    code, _, err = _cli(capsys, "board")
    assert (
        code == 3
        and err
        == "sins-fw: error: internal error (please report; --debug shows where): RuntimeError('a bug')\n"
    )
    code, _, err = _cli(capsys, "--debug", "board")
    assert code == 3 and "Traceback" in err and 'raise RuntimeError("a bug")' in err


_FINALISER_SCRIPT = """
import os, signal
from sins_fw.cli import stop

class Finalised:
    def __del__(self):
        os.kill(os.getpid(), signal.SIGINT)
        for _ in range(10_000):  # the handler runs here, inside the finaliser
            pass

with stop.handling():
    Finalised()  # dropped at once: the KeyboardInterrupt is raised and swallowed in __del__
    try:
        stop.check_stop()
        print("not raised")
    except KeyboardInterrupt:
        print("raised at the check")
"""


def test_an_interrupt_dropped_inside_a_finaliser_is_raised_at_the_next_check() -> None:
    """Python drops an exception raised in a finaliser ("Exception ignored in ..." and a traceback): a
    signal landing there must still stop the command at the next chunk, and print no traceback (both
    seen once the emulator got fast). A subprocess: pytest replaces the hook that prints."""
    done = subprocess.run(
        [sys.executable, "-c", _FINALISER_SCRIPT], capture_output=True, text=True, timeout=60
    )
    assert done.stdout.strip() == "raised at the check", (done.stdout, done.stderr)
    assert "Traceback" not in done.stderr and "Exception ignored" not in done.stderr, done.stderr


# ---------------------------------------------------------------------------------------------------
# The streamed writers (issue 24, item 11): bad input found part-way through leaves nothing behind
# ---------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("name", "fragment"), TRACE_CASES, ids=[c[0] for c in TRACE_CASES])
def test_bad_trace_through_replay_and_run_allow_gaps(capsys, tmp_path, name, fragment):
    """`replay` and `run --allow-gaps` read the trace as they write (they loaded it whole before):
    the corpus still gets exit 2 naming the file, and no recording or output, not even a temporary
    file."""
    commands = [["replay", str(BAD / name), "--out", str(tmp_path / "r.rrd")]]
    if "gap" not in name:  # a gap is what --allow-gaps accepts
        commands.append(["run", str(BAD / name), "--allow-gaps", "--out", str(tmp_path / "o.csv")])
    for args in commands:
        code, out, err = _cli(capsys, *args)
        assert code == 2, (args, out, err)
        assert "Traceback" not in err and "panicked" not in err
        assert str(BAD / name) in err, err
        assert list(tmp_path.iterdir()) == [], args


@pytest.fixture(scope="module")
def late_nan(tmp_path_factory) -> Path:
    """A 150 s static trace whose gyro is NaN at row 120 000 (146 s): in the second file chunk, long
    after every streamed writer has written its first rows."""
    trace = synth.generate("static", duration_s=150.0)
    cols = trace.columns()
    cols["gyro_y_dps"] = cols["gyro_y_dps"].copy()
    cols["gyro_y_dps"][120_000] = np.nan
    path = tmp_path_factory.mktemp("late") / "late_nan.csv"
    # Written as another tool would (no validation on the way out).
    write_csv(path, PHYSICAL_SCHEMA, {"format": PHYSICAL_SCHEMA.format, **trace.metadata}, cols)
    return path


LATE = {
    "replay --out": ["replay", "TRACE", "--out", "OUT/r.rrd", "--bus-ticks", "none"],
    "replay --out --parity": ["replay", "TRACE", "--out", "OUT/r.rrd", "--parity", "f64"],
    "run --out .h5": ["run", "TRACE", "--out", "OUT/o.h5"],
    "run --allow-gaps --out": ["run", "TRACE", "--allow-gaps", "--out", "OUT/o.csv"],
    "run --raw-out": ["run", "TRACE", "--raw-out", "OUT/raw.csv"],
    "import trace": ["import", "trace", "TRACE", "--out", "OUT/i.h5"],
}


@pytest.mark.parametrize("case", sorted(LATE))
def test_bad_row_found_late_leaves_the_previous_output(capsys, tmp_path, late_nan, case):
    """Each streamed writer meets the bad row after writing for a while: exit 2 naming the file,
    row and column; the previous output kept byte for byte, no temporary file."""
    out = tmp_path / "out"
    out.mkdir()
    args = [a.replace("TRACE", str(late_nan)).replace("OUT", str(out)) for a in LATE[case]]
    target = Path(next(a for a in args if a.startswith(str(out))))
    target.write_bytes(b"previous")
    code, _, err = _cli(capsys, *args)
    assert code == 2, err
    assert str(late_nan) in err and "row 120000" in err and "gyro_y_dps" in err, err
    assert "Traceback" not in err
    assert target.read_bytes() == b"previous"
    assert sorted(p.name for p in out.iterdir()) == [target.name]
