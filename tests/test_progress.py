"""Issue 27, item 10: progress on the commands that can take long, and a bad output location
refused before any work.

One helper draws every bar (sins_fw.progress): on stderr, only when stderr is a terminal and the
command does not print --json, so stdout (and a pipe or a log) never carries one."""

from __future__ import annotations

import json
import os
import pty
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from conftest import BROAD, ROOT, run_cli

STATIC = ROOT / "traces" / "static_60s.h5"
#: A tqdm bar as drawn: carriage return, what it does, the percentage.
BAR = re.compile(r"\r[a-z ]+:\s+\d+%")

#: Every long command, writing into folder F.
LONG = {
    "synth": ["synth", "static", "--duration-s", "30", "--out", "F/s.h5"],
    "run": ["run", str(STATIC), "--until-s", "20", "--out", "F/o.csv"],
    "replay": ["replay", str(STATIC), "--out", "F/r.rrd", "--bus-ticks", "none"],
    "parity": ["parity", str(STATIC), "--backends", "f64,c28x-f32"],
    "import trace": ["import", "trace", str(STATIC), "--out", "F/i.csv"],
}


def _on_a_terminal(args: list[str], folder: Path) -> tuple[int, str, str]:
    """`sins-fw ARGS` with stderr on a pseudo-terminal and stdout on a pipe: (exit, stdout, what the
    terminal showed)."""
    master, slave = pty.openpty()
    argv = [a.replace("F/", f"{folder}/") for a in args]
    proc = subprocess.Popen(
        [sys.executable, "-m", "sins_fw", *argv], stdout=subprocess.PIPE, stderr=slave, cwd=ROOT, text=True
    )
    os.close(slave)
    shown = b""
    while True:
        try:
            block = os.read(master, 1 << 16)
        except OSError:  # the child has gone and closed the terminal
            break
        if not block:
            break
        shown += block
    out = proc.stdout.read() if proc.stdout else ""
    os.close(master)
    return proc.wait(), out, shown.decode("utf-8", "replace")


@pytest.mark.parametrize("case", sorted(LONG))
def test_a_long_command_shows_a_bar_on_a_terminal_only(tmp_path, case):
    code, out, shown = _on_a_terminal(LONG[case], tmp_path)
    assert code in (0, 1), shown
    assert BAR.search(shown), f"a tqdm bar on the terminal: {shown!r}"
    assert not BAR.search(out), "never on stdout"
    # The same command with stderr on a pipe (a log, CI): no bar.
    r = run_cli(*[a.replace("F/", f"{tmp_path}/") for a in LONG[case]])
    assert r.code == code and not BAR.search(r.err), r.err


@pytest.mark.parametrize("case", sorted(LONG))
def test_json_output_has_no_bar_even_on_a_terminal(tmp_path, case):
    code, out, shown = _on_a_terminal([*LONG[case], "--json"], tmp_path)
    assert code in (0, 1), shown
    assert not BAR.search(shown), shown
    json.loads(out)


# --- a bad output location, refused before any work ------------------------------------------------

#: Every command option that names an output file (FOLDER: where it goes).
OUTPUTS = {
    "run --out": ["run", str(STATIC), "--out", "FOLDER/o.csv"],
    "run --raw-out": ["run", str(STATIC), "--raw-out", "FOLDER/raw.h5"],
    "replay --out": ["replay", str(STATIC), "--out", "FOLDER/r.rrd"],
    "synth --out": ["synth", "static", "--duration-s", "5", "--out", "FOLDER/s.h5"],
    "import trace --out": ["import", "trace", str(STATIC), "--out", "FOLDER/i.h5"],
    "import broad --out": [
        "import",
        "broad",
        str(BROAD / "01_undisturbed_slow_rotation_A.hdf5"),
        "--out",
        "FOLDER/b.h5",
    ],
}


def _cannot_write(folder: Path) -> bool:
    try:
        fd, name = tempfile.mkstemp(dir=folder)
    except OSError:
        return True
    os.close(fd)
    os.unlink(name)
    return False


@pytest.fixture
def read_only(tmp_path: Path) -> Path:
    """A folder no file can be created in: a read-only one, or (as root, who writes anyway) a
    folder of the kernel's read-only /sys."""
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(0o555)
    if _cannot_write(folder):
        yield folder
    elif _cannot_write(Path("/sys/kernel")):
        yield Path("/sys/kernel")
    else:
        pytest.skip("no folder here refuses new files to this user")
    folder.chmod(0o755)


@pytest.mark.parametrize("case", sorted(OUTPUTS))
def test_an_output_in_a_folder_that_cannot_be_written_is_refused_before_any_work(read_only, case):
    """Before, the emulation (or the import) ran to its end and the write then failed: minutes lost
    on a long trace. Now exit 2 at once, naming the option, the file and the folder."""
    args = [a.replace("FOLDER", str(read_only)) for a in OUTPUTS[case]]
    if "broad" in case and not Path(args[2]).is_file():
        pytest.skip("BROAD data not available")
    out = Path(next(a for a in args if a.startswith(str(read_only))))
    r = run_cli(*args)
    option = case.split()[-1]
    assert r.code == 2, r.err
    assert f"{option} {out}: cannot create a file in {read_only}" in r.err, r.err
    assert "Traceback" not in r.err and not out.exists()


def test_an_output_through_a_file_is_refused_before_any_work(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("")
    r = run_cli("replay", str(STATIC), "--out", str(blocker / "sub" / "r.rrd"))
    assert r.code == 2 and f"--out {blocker / 'sub' / 'r.rrd'}: {blocker} is not a folder" in r.err, r.err


def test_a_missing_output_folder_is_created(tmp_path):
    """The documented rule (atomic.atomic_path): missing folders of an output are created; the check
    probes the nearest folder that exists."""
    out = tmp_path / "new" / "deeper" / "s.h5"
    r = run_cli("synth", "static", "--duration-s", "1", "--out", str(out))
    assert r.code == 0 and out.is_file(), r.err
