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
    """A folder with a trace (t.h5, t.csv), a profile copy (also as prof.csv, a profile path of any
    name), a EuRoC-style log folder (log/), log files of the other importers (their content is never
    read: the refusal comes first), a ROS 2 bag folder, a firmware's sources with a header and a
    globals file (fw/), and a built library with the globals file beside it."""
    shutil.copy(STATIC, tmp_path / "t.h5")
    synth.generate("static", duration_s=0.2).save(tmp_path / "t.csv")
    shutil.copy(ROOT / "firmware_model" / "reference.toml", tmp_path / "p.toml")
    shutil.copy(ROOT / "firmware_model" / "reference.toml", tmp_path / "prof.csv")
    (tmp_path / "sub").mkdir()
    imu = tmp_path / "log" / "mav0" / "imu0"
    imu.mkdir(parents=True)
    (imu / "data.csv").write_text("#timestamp [ns],w_RS_S_x [rad s^-1]\n1,0\n")
    (tmp_path / "log" / "mav0" / "state_groundtruth_estimate0").mkdir()
    (tmp_path / "log" / "mav0" / "state_groundtruth_estimate0" / "data.csv").write_text("#timestamp\n")
    (tmp_path / "log" / "mav0" / "imu0" / "sensor.yaml").write_text("rate_hz: 200\n")
    (tmp_path / "gt.csv").write_text("#timestamp, q_RS_w []\n")
    (tmp_path / "flight.ulg").write_bytes(b"ULog\x01\x12\x35\x01")
    (tmp_path / "00000042.BIN").write_bytes(b"\xa3\x95\x80")
    (tmp_path / "bag").mkdir()
    (tmp_path / "bag" / "metadata.yaml").write_text("rosbag2_bagfile_information: {}\n")
    (tmp_path / "bag" / "bag_0.db3").write_bytes(b"SQLite format 3\x00")
    fw = tmp_path / "fw"
    fw.mkdir()
    (fw / "main.c").write_text('#include "filter.h"\nint main(void) { return filter_gain(); }\n')
    (fw / "filter.h").write_text("static inline int filter_gain(void) { return 2; }\n")
    (fw / "globals.toml").write_text('[[global]]\nname = "x"\ntype = "int"\n')
    (tmp_path / "lib").mkdir()
    (tmp_path / "lib" / "fw.so").write_bytes(b"\x7fELF")
    (tmp_path / "lib" / "globals.toml").write_text('[[global]]\nname = "x"\ntype = "int"\n')
    (tmp_path / "g.csv").write_text('[[global]]\nname = "x"\ntype = "int"\n')
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
    # The importers read every file of a log folder or bag (issue 42, item 1).
    "import euroc --out the folder's IMU file": lambda w: (
        ["import", "euroc", w / "log", "--out", w / "log" / "mav0" / "imu0" / "data.csv"],
        ("--out", "FILE"),
    ),
    "import euroc --out the folder's ground truth": lambda w: (
        [
            "import",
            "euroc",
            w / "log",
            "--out",
            w / "log" / "mav0" / "state_groundtruth_estimate0" / "data.csv",
        ],
        ("--out", "FILE"),
    ),
    "import euroc --out another file of the folder": lambda w: (
        [
            "import",
            "euroc",
            w / "log",
            "--out",
            _symlink(w / "y.csv", w / "log" / "mav0" / "imu0" / "sensor.yaml"),
        ],
        ("--out", "FILE"),
    ),
    "import euroc --out a hard link to the folder's IMU file": lambda w: (
        [
            "import",
            "euroc",
            w / "log",
            "--out",
            _hardlink(w / "imu.csv", w / "log" / "mav0" / "imu0" / "data.csv"),
        ],
        ("--out", "FILE"),
    ),
    "import euroc --out is --truth": lambda w: (
        ["import", "euroc", w / "log", "--truth", w / "gt.csv", "--out", w / "gt.csv"],
        ("--out", "--truth"),
    ),
    "import euroc --out the folder itself": lambda w: (
        ["import", "euroc", w / "log", "--out", w / "log"],
        ("--out", "FILE"),
    ),
    "import ulog --out a symlink to the log": lambda w: (
        ["import", "ulog", w / "flight.ulg", "--out", _symlink(w / "f.h5", w / "flight.ulg")],
        ("--out", "FILE"),
    ),
    "import dataflash --out a hard link to the log": lambda w: (
        ["import", "dataflash", w / "00000042.BIN", "--out", _hardlink(w / "d.csv", w / "00000042.BIN")],
        ("--out", "FILE"),
    ),
    "import rosbag --out a file of the bag folder": lambda w: (
        ["import", "rosbag", w / "bag", "--out", _symlink(w / "b.h5", w / "bag" / "metadata.yaml")],
        ("--out", "FILE"),
    ),
    "import rosbag --out the bag's metadata, given its .db3": lambda w: (
        [
            "import",
            "rosbag",
            w / "bag" / "bag_0.db3",
            "--out",
            _symlink(w / "b.h5", w / "bag" / "metadata.yaml"),
        ],
        ("--out", "FILE"),
    ),
    # A C firmware's inputs: its sources, the headers they include, its globals file.
    "build-firmware -o a source": lambda w: (
        ["build-firmware", w / "fw" / "main.c", "-o", w / "fw" / "main.c"],
        ("--out", "SOURCES"),
    ),
    "build-firmware -o a source of a folder given": lambda w: (
        ["build-firmware", w / "fw", "-o", w / "fw" / "main.c"],
        ("--out", "a source"),
    ),
    "build-firmware -o the folder of the sources": lambda w: (
        ["build-firmware", w / "fw" / "main.c", "-o", w / "fw"],
        ("--out", "fw/main.c"),
    ),
    "build-firmware -o a header the sources include": lambda w: (
        ["build-firmware", w / "fw" / "main.c", "-o", w / "fw" / "filter.h"],
        ("--out", "a header the sources include"),
    ),
    "build-firmware -o the globals file": lambda w: (
        ["build-firmware", w / "fw" / "main.c", "-o", w / "fw" / "globals.toml"],
        ("--out", "the globals file"),
    ),
    "run --firmware --out is --globals": lambda w: (
        [
            "run",
            w / "t.csv",
            "--firmware",
            w / "lib" / "fw.so",
            "--globals",
            w / "g.csv",
            "--out",
            w / "g.csv",
        ],
        ("--out", "--globals"),
    ),
    "run --firmware --out the globals file beside it": lambda w: (
        [
            "run",
            w / "t.csv",
            "--firmware",
            w / "lib" / "fw.so",
            "--out",
            _symlink(w / "o.csv", w / "lib" / "globals.toml"),
        ],
        ("--out", "the globals file beside --firmware"),
    ),
    "run --firmware --out is the library": lambda w: (
        [
            "run",
            w / "t.csv",
            "--firmware",
            w / "lib" / "fw.so",
            "--out",
            _symlink(w / "o.h5", w / "lib" / "fw.so"),
        ],
        ("--out", "--firmware"),
    ),
    # A Monte Carlo table is written with its CSV copy and percentile tables beside it.
    "montecarlo --out's CSV copy is the profile": lambda w: (
        ["montecarlo", "static", "--runs", "1", "--profile", w / "prof.csv", "--out", w / "prof.parquet"],
        ("--out", "--profile"),
    ),
    "montecarlo --out .h5's CSV copy is the profile": lambda w: (
        ["montecarlo", "static", "--runs", "1", "--profile", w / "prof.csv", "--out", w / "prof.h5"],
        ("--out", "--profile"),
    ),
    "montecarlo --plot a symlink to the profile": lambda w: (
        [
            "montecarlo",
            "static",
            "--runs",
            "1",
            "--profile",
            w / "p.toml",
            "--plot",
            _symlink(w / "m.png", w / "p.toml"),
        ],
        ("--plot", "--profile"),
    ),
    "sweep --out's percentile table is the profile": lambda w: (
        [
            "sweep",
            "static",
            "--runs",
            "1",
            "--profile",
            _symlink(w / "s-percentiles.csv", w / "p.toml"),
            "--out",
            w / "s.parquet",
        ],
        ("--out", "--profile"),
    ),
    "sweep --out and --plot one file through its CSV copy": lambda w: (
        ["sweep", "static", "--runs", "1", "--out", w / "s.h5", "--plot", _symlink(w / "s.png", w / "s.csv")],
        ("--plot", "--out"),
    ),
    "replay --out a symlink to the profile": lambda w: (
        ["replay", w / "t.csv", "--profile", w / "p.toml", "--out", _symlink(w / "p.rrd", w / "p.toml")],
        ("--out", "--profile"),
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


#: Options that take a file or folder are recognised by their type or metavar (FILE, DIR, FW.so, ...).
_FILE_METAVARS = ("FILE", "DIR", "TRACE", ".so", ".toml", ".png", ".rrd", "FOLDER")


def _file_options(parser) -> set[str]:
    found = set()
    for action in parser._actions:
        metavar = str(action.metavar or "")
        if (
            action.type is Path
            or any(m in metavar for m in _FILE_METAVARS)
            or action.dest in ("sources", "profile")
        ):
            found.add(action.dest)
    return found


def test_every_command_declares_the_files_it_reads_and_writes():
    """cli/files.py is the one place that knows each command's inputs and outputs: a new command or a
    new option naming a file must be declared there, or its output could overwrite an input."""
    from sins_fw.cli import build_parser
    from sins_fw.cli.common import walk_parsers
    from sins_fw.cli.files import spec_of

    leaves = {
        name.removeprefix("sins-fw "): p
        for name, p in walk_parsers(build_parser())
        if p.get_default("func") is not None
    }
    assert len(leaves) > 20
    for name, parser in leaves.items():
        spec = spec_of(name)
        assert spec is not None, f"`sins-fw {name}` has no entry in cli/files.py FILES"
        declared = {r.dest for r in (*spec.inputs, *spec.outputs)} | set(spec.folders)
        missing = _file_options(parser) - declared
        assert not missing, f"`sins-fw {name}`: options {sorted(missing)} name files: declare them in FILES"


def test_a_new_file_inside_an_input_folder_is_accepted(capsys, tmp_path):
    # The refusal is for the files the folder holds; a new file beside them destroys nothing.
    from test_importers import _euroc

    _euroc(tmp_path / "log")
    out = tmp_path / "log" / "trace.h5"
    code, _, err = _cli(capsys, "import", "euroc", tmp_path / "log", "--out", out)
    assert code == 0 and out.is_file(), err


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


# Every writer on a disk with no room left (issue 42, item 2): each command that writes a file, and the
# commands that only print (their standard output redirected there).
#: F: the full folder; L: a EuRoC log beside it. Each run is kept short (1 s scenarios, one run).
EVERY_WRITER = {
    "montecarlo --out .parquet": [
        "montecarlo",
        "static",
        "--runs",
        "1",
        "--param",
        "duration-s=1",
        "--workers",
        "1",
        "--out",
        "F/m.parquet",
    ],
    "montecarlo --out .h5": [
        "montecarlo",
        "static",
        "--runs",
        "1",
        "--param",
        "duration-s=1",
        "--workers",
        "1",
        "--out",
        "F/m.h5",
    ],
    "montecarlo --out .csv": [
        "montecarlo",
        "static",
        "--runs",
        "1",
        "--param",
        "duration-s=1",
        "--workers",
        "1",
        "--out",
        "F/m.csv",
    ],
    "montecarlo --plot": [
        "montecarlo",
        "static",
        "--runs",
        "1",
        "--param",
        "duration-s=1",
        "--workers",
        "1",
        "--plot",
        "F/m.png",
    ],
    "sweep --out .parquet": [
        "sweep",
        "static",
        "--runs",
        "1",
        "--param",
        "duration-s=1",
        "--workers",
        "1",
        "--out",
        "F/s.parquet",
    ],
    "synth --out .h5": ["synth", "static", "--duration-s", "1", "--out", "F/s.h5"],
    "synth --out .csv": ["synth", "static", "--duration-s", "1", "--out", "F/s.csv"],
    "import euroc --out .h5": ["import", "euroc", "L", "--out", "F/e.h5"],
    "report --out .png": ["report", str(ROOT / "traces" / "pitch_sweep.h5"), "--out", "F/r.png"],
    "budget --plot": ["budget", "--duration-s", "0.1", "--plot", "F/b.png"],
    "run --out .h5": ["run", str(STATIC), "--until-s", "2", "--out", "F/o.h5"],
}
#: Commands that only print: their report to a file on the full disk (`> F/out.txt`).
PRINTERS = {
    "spin-table": [
        "spin-table",
        "--engine",
        "chain",
        "--runs",
        "1",
        "--rates-dps",
        "50",
        "--duration-s",
        "2",
    ],
    "presets": ["presets"],
    "board --json": ["board", "--json"],
}


def _fill(folder: Path, room: int = 0) -> None:
    """Fill the 32 KiB tmpfs to the last byte (a filler file), then free ``room`` bytes: a write
    there fails at once, or after ``room`` bytes (mid-file, as a disk fills during a write)."""
    with open(folder / "filler", "wb", buffering=0) as f, pytest.raises(OSError):
        for _ in range(LIMIT_BYTES // 512 + 8):
            f.write(b"\0" * 512)
    if room:
        size = (folder / "filler").stat().st_size
        os.truncate(folder / "filler", size - room)


@pytest.mark.parametrize("case", sorted(EVERY_WRITER))
def test_every_writer_on_a_full_disk_is_exit_2_and_writes_nothing(full_disk, tmp_path, case):
    """One page (4 KiB) of room: the disk fills in the middle of the writing (every output here is
    larger), the hard case: a HDF5 file half-written, a table written and its CSV copy not. With no
    room at all, the write fails at its first byte (FULL_WRITES above)."""
    from sins_fw.sweep import table_files
    from test_importers import _euroc

    _euroc(tmp_path / "log")
    args = [str(tmp_path / "log") if a == "L" else a for a in EVERY_WRITER[case]]
    no_room = full_disk
    out = no_room / Path(next(a for a in args if a.startswith("F/"))).name
    out.write_bytes(b"previous")
    _fill(no_room, room=4096)
    r = _run_limited(args, no_room, None)
    assert r.returncode == 2, (r.returncode, r.stderr[-2000:])
    # A Monte Carlo table is written with the files beside it: the error names the one that failed.
    named = table_files(out) if case.startswith(("montecarlo --out", "sweep --out")) else [out]
    failed = next((p for p in named if f"sins-fw: error: {p}: " in r.stderr), None)
    assert failed is not None and "No space left on device" in r.stderr, r.stderr
    kept = "left as it was" if failed == out else "not written"
    assert f"({failed} {kept})" in r.stderr, r.stderr
    assert "Traceback" not in r.stderr and "Exception ignored" not in r.stderr, r.stderr
    assert out.read_bytes() == b"previous"
    assert sorted(p.name for p in no_room.iterdir()) == sorted(["filler", out.name]), "nothing else written"


@pytest.mark.parametrize("case", sorted(PRINTERS))
def test_a_report_printed_to_a_full_disk_is_exit_2_naming_standard_output(full_disk, case):
    (full_disk / "out.txt").touch()
    _fill(full_disk)
    with open(full_disk / "out.txt", "w") as sink:
        r = subprocess.run(
            [sys.executable, "-m", "sins_fw", *PRINTERS[case]],
            stdout=sink,
            stderr=subprocess.PIPE,
            text=True,
            timeout=600,
            check=False,
            cwd=ROOT,
        )
    assert r.returncode == 2, (r.returncode, r.stderr[-2000:])
    assert "sins-fw: error: standard output: No space left on device" in r.stderr, r.stderr
    assert "Traceback" not in r.stderr and "Exception ignored" not in r.stderr, r.stderr


@pytest.mark.parametrize(
    "args",
    [
        ["import", "trace", str(STATIC), "--out", "F/new/deeper/i.h5"],
        # Before: `report` alone refused a missing folder, where every other command creates it.
        ["report", str(ROOT / "traces" / "pitch_sweep.h5"), "--out", "F/new/deeper/r.png"],
    ],
    ids=["import", "report"],
)
def test_every_command_creates_an_outputs_missing_folders(capsys, tmp_path, args):
    argv = [a.replace("F/", f"{tmp_path}/") for a in args]
    code, _, err = _cli(capsys, *argv)
    assert code == 0, err
    assert Path(argv[-1]).is_file()
