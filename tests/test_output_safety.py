"""Nothing lost: no command writes over one of its inputs or writes two outputs to one file (however
the path is spelled: `..`, a symlink, a hard link), and a full disk is a clean exit 2 that names the
file and leaves the previous one intact."""

from __future__ import annotations

import os
import resource
import shutil
import signal
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest

from conftest import ROOT
from sins_fw import synth
from sins_fw.cli import main

STATIC = ROOT / "traces" / "static_60s.h5"


def _cli(capsys, *args: str) -> tuple[int, str, str]:
    code = main([str(a) for a in args])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def _snapshot(folder: Path) -> dict[str, bytes | str]:
    """Every entry of a folder: a symlink by its target, a file by its bytes."""
    out: dict[str, bytes | str] = {}
    for p in sorted(folder.rglob("*")):
        key = str(p.relative_to(folder))
        if p.is_symlink():
            out[key] = "-> " + os.readlink(p)
        elif p.is_file():
            out[key] = p.read_bytes()
    return out


@pytest.fixture
def ws(tmp_path: Path) -> Path:
    """A folder with a trace (t.h5, t.csv), a profile copy and a BROAD-like file."""
    shutil.copy(STATIC, tmp_path / "t.h5")
    synth.generate("static", duration_s=0.2).save(tmp_path / "t.csv")
    shutil.copy(ROOT / "firmware_model" / "reference.toml", tmp_path / "p.toml")
    (tmp_path / "sub").mkdir()
    return tmp_path


def _symlink(link: Path, target: Path) -> Path:
    link.symlink_to(target)
    return link


def _hardlink(link: Path, target: Path) -> Path:
    os.link(target, link)
    return link


#: name → (arguments built in the work folder, the two paths the message must name).
CASES: dict[str, Callable[[Path], tuple[list[object], tuple[str, str]]]] = {
    "run --out is the trace": lambda w: (["run", w / "t.h5", "--out", w / "t.h5"], ("--out", "TRACE")),
    "run --raw-out is the trace": lambda w: (
        ["run", w / "t.csv", "--raw-out", w / "t.csv"],
        ("--raw-out", "TRACE"),
    ),
    "run --out through ..": lambda w: (
        ["run", w / "t.csv", "--out", w / "sub" / ".." / "t.csv"],
        ("--out", "TRACE"),
    ),
    "run --out and --raw-out one file": lambda w: (
        ["run", w / "t.csv", "--out", w / "x.csv", "--raw-out", w / "x.csv"],
        ("--raw-out", "--out"),
    ),
    "run --out a symlink to the trace": lambda w: (
        ["run", w / "t.h5", "--out", _symlink(w / "link.h5", w / "t.h5")],
        ("--out", "TRACE"),
    ),
    "run --out a hard link to the trace": lambda w: (
        ["run", w / "t.h5", "--out", _hardlink(w / "hard.h5", w / "t.h5")],
        ("--out", "TRACE"),
    ),
    "run --out a dangling symlink to --raw-out": lambda w: (
        ["run", w / "t.csv", "--out", _symlink(w / "a.csv", w / "b.csv"), "--raw-out", w / "b.csv"],
        ("--raw-out", "--out"),
    ),
    "run --out a symlink to the profile": lambda w: (
        ["run", w / "t.csv", "--profile", w / "p.toml", "--out", _symlink(w / "p.csv", w / "p.toml")],
        ("--out", "--profile"),
    ),
    "import trace --out is the input": lambda w: (
        ["import", "trace", w / "t.h5", "--out", w / "sub" / ".." / "t.h5"],
        ("--out", "FILE"),
    ),
    "import broad --out a symlink to the input": lambda w: (
        [
            "import",
            "broad",
            _symlink(w / "trial.hdf5", w / "t.h5"),
            "--out",
            _symlink(w / "o.h5", w / "t.h5"),
        ],
        ("--out", "FILE"),
    ),
    "report --out a symlink to the trace": lambda w: (
        ["report", w / "t.csv", "--out", _symlink(w / "r.png", w / "t.csv")],
        ("--out", "TRACE"),
    ),
    "replay --out a hard link to the trace": lambda w: (
        ["replay", w / "t.csv", "--out", _hardlink(w / "r.rrd", w / "t.csv")],
        ("--out", "TRACE_OR_RUN"),
    ),
    "budget --plot a symlink to the profile": lambda w: (
        [
            "budget",
            "--profile",
            w / "p.toml",
            "--duration-s",
            "0.1",
            "--plot",
            _symlink(w / "b.png", w / "p.toml"),
        ],
        ("--plot", "--profile"),
    ),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_an_output_that_is_an_input_or_another_output_is_refused_before_the_run(capsys, ws, case):
    args, (first, second) = CASES[case](ws)
    before = _snapshot(ws)
    code, out, err = _cli(capsys, *args)
    assert code == 2, (out, err)
    assert out == "" and "Traceback" not in err
    assert first in err and second in err, err
    assert _snapshot(ws) == before, "nothing written, nothing replaced"


def test_replay_refuses_to_save_over_the_trace_a_run_output_records(capsys, ws):
    run_out = ws / "o.h5"
    code, _, err = _cli(capsys, "run", ws / "t.csv", "--out", run_out)
    assert code == 0, err
    before = _snapshot(ws)
    code, _, err = _cli(capsys, "replay", run_out, "--out", _symlink(ws / "r.rrd", ws / "t.csv"))
    assert code == 2 and "--out" in err and "recorded trace" in err, err
    before["r.rrd"] = "-> " + str(ws / "t.csv")
    assert _snapshot(ws) == before


def test_demo_refuses_a_recording_path_that_is_a_bundled_trace(capsys, tmp_path):
    _symlink(tmp_path / "pitch_sweep.rrd", ROOT / "traces" / "pitch_sweep.h5")
    before = (ROOT / "traces" / "pitch_sweep.h5").read_bytes()
    code, _, err = _cli(capsys, "demo", "--out-dir", tmp_path)
    assert code == 2 and "pitch_sweep.h5" in err, err
    assert (tmp_path / "pitch_sweep.rrd").is_symlink()
    assert (ROOT / "traces" / "pitch_sweep.h5").read_bytes() == before


def test_distinct_outputs_beside_the_input_are_accepted(capsys, ws):
    code, _, err = _cli(capsys, "run", ws / "t.csv", "--out", ws / "o.csv", "--raw-out", ws / "sub" / "r.csv")
    assert code == 0, err
    assert (ws / "o.csv").is_file() and (ws / "sub" / "r.csv").is_file()


# ---------------------------------------------------------------------------------------------------
# A full disk (or a file size limit): exit 2 naming the file, the previous file intact
# ---------------------------------------------------------------------------------------------------

#: Commands writing each kind of file the CLI writes, into folder F (TRACE: the 60 s bundled trace).
FULL_WRITES = {
    "run --out .h5": ["run", str(STATIC), "--out", "F/o.h5"],
    "run --out .csv": ["run", str(STATIC), "--out", "F/o.csv"],
    "import trace --out .h5": ["import", "trace", str(STATIC), "--out", "F/i.h5"],
    "replay --out .rrd": ["replay", str(STATIC), "--out", "F/o.rrd", "--bus-ticks", "none"],
    # Streamed writers (issue 24, item 11): the recording with the other backends' threads running,
    # and a run reading its trace as it writes.
    "replay --out .rrd --parity": ["replay", str(STATIC), "--out", "F/o.rrd", "--parity", "f64"],
    "run --allow-gaps --out .csv": ["run", str(STATIC), "--allow-gaps", "--out", "F/o.csv"],
}
#: Room for the previous files and not much more (each output above is larger).
LIMIT_BYTES = 32 * 1024


def _run_limited(args: list[str], folder: Path, fsize: int | None) -> subprocess.CompletedProcess[str]:
    """`sins-fw ARGS` (F → folder) in a child process: a crash must not take the test runner down."""

    def limit() -> None:
        if fsize is not None:
            # Writes past the limit fail with EFBIG at the same point a full disk fails with ENOSPC.
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
            resource.setrlimit(resource.RLIMIT_FSIZE, (fsize, fsize))

    argv = [a.replace("F/", f"{folder}/") for a in args]
    return subprocess.run(
        [sys.executable, "-m", "sins_fw", *argv],
        capture_output=True,
        text=True,
        timeout=600,
        preexec_fn=limit,
        check=False,
        cwd=ROOT,
    )


def _check_refused_cleanly(r: subprocess.CompletedProcess[str], out: Path, why: str) -> None:
    assert r.returncode == 2, (r.returncode, r.stderr[-2000:])
    assert f"sins-fw: error: {out}: {why}" in r.stderr and f"{out} left as it was" in r.stderr, r.stderr
    assert "Traceback" not in r.stderr and "\x1b[" not in r.stderr and "ERROR" not in r.stderr, r.stderr
    assert out.read_bytes() == b"previous"
    assert sorted(p.name for p in out.parent.iterdir()) == [out.name], "no temporary file left"


@pytest.mark.parametrize("case", sorted(FULL_WRITES))
def test_a_file_size_limit_is_exit_2_naming_the_file_and_keeping_the_old_one(tmp_path, case):
    args = FULL_WRITES[case]
    out = tmp_path / Path(next(a for a in args if a.startswith("F/"))).name
    out.write_bytes(b"previous")
    r = _run_limited(args, tmp_path, LIMIT_BYTES)
    _check_refused_cleanly(r, out, "File too large")


@pytest.fixture
def full_disk(tmp_path: Path):
    """A real 32 KiB tmpfs (needs root and a kernel that lets this process mount)."""
    folder = tmp_path / "full"
    folder.mkdir()
    if os.geteuid() != 0 or shutil.which("mount") is None:
        pytest.skip(
            "mounting a small tmpfs needs root and mount(8); the file-size-limit test covers the path"
        )
    r = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", f"size={LIMIT_BYTES}", "tmpfs", str(folder)],
        capture_output=True,
        text=True,
        check=False,
    )
    if r.returncode != 0:
        pytest.skip(
            f"cannot mount a tmpfs here ({r.stderr.strip()}); the file-size-limit test covers the path"
        )
    try:
        yield folder
    finally:
        subprocess.run(["umount", str(folder)], check=False)


@pytest.mark.parametrize("case", sorted(FULL_WRITES))
def test_a_full_disk_is_exit_2_naming_the_file_and_keeping_the_old_one(full_disk, case):
    args = FULL_WRITES[case]
    out = full_disk / Path(next(a for a in args if a.startswith("F/"))).name
    out.write_bytes(b"previous")
    r = _run_limited(args, full_disk, None)
    _check_refused_cleanly(r, out, "No space left on device")


def test_an_rrd_whose_last_bytes_fail_at_close_is_an_error_not_a_thread_traceback(tmp_path, monkeypatch):
    """The recording's pump writes through a buffered file: on a nearly full disk every write can fit
    the buffer and only the flush at close fail. Before, that OSError escaped the pump's thread as a
    traceback on stderr and the save went on as if complete (a truncated .rrd renamed into place);
    now it is the save's error, raised when the pump ends."""
    import errno
    import threading

    from sins_fw.viewer import recording

    class FailsAtClose:
        def __init__(self) -> None:
            self.held = 0

        def write(self, block: bytes) -> int:
            self.held += len(block)
            return len(block)

        def close(self) -> None:
            raise OSError(errno.ENOSPC, "No space left on device")

    escaped: list[BaseException] = []
    monkeypatch.setattr(threading, "excepthook", lambda args: escaped.append(args.exc_value))
    monkeypatch.setattr(Path, "open", lambda self, *a, **k: FailsAtClose())
    pump = recording._Pump(tmp_path / "r.rrd.tmp")
    with pytest.raises(OSError, match="No space left on device"), pump as fd:
        os.write(int(fd.rsplit("/", 1)[1]), b"x" * 1000)
    assert escaped == []
