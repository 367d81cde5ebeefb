"""Shared fixtures: paths to the repository, the shared data, and a CLI runner."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

from sins_fw.firmware_run import run_c_firmware
from sins_fw.profile import Profile, load_profile

ROOT = Path(__file__).resolve().parents[1]
# The shared data sits beside the repository (../shared); from a git worktree one level deeper too.
SHARED = next(
    (p for p in (ROOT.parent / "shared", ROOT.parent.parent / "shared") if p.is_dir()), ROOT.parent / "shared"
)
BROAD = SHARED / "data" / "broad"


@dataclass
class CliResult:
    code: int
    out: str
    err: str


def run_cli(*args: str, cwd: Path | None = None, timeout: float = 600) -> CliResult:
    """Run `sins-fw` as a user would (a separate process, the installed entry point's module)."""
    env = dict(os.environ)
    proc = subprocess.run(
        [sys.executable, "-m", "sins_fw", *args],
        capture_output=True,
        text=True,
        cwd=cwd or ROOT,
        env=env,
        timeout=timeout,
        check=False,
    )
    return CliResult(proc.returncode, proc.stdout, proc.stderr)


@pytest.fixture
def cli() -> type:
    return run_cli


def build_cabi() -> None:
    """Build (or find up to date) the C ABI library `sins-fw build-firmware` links a firmware against,
    where it looks for it, as `make test` builds it: with the Rust tests (`make cabi CABI_WITH_TESTS=1`,
    Makefile), whose build of the core it shares. (`cargo build -p sins-cabi` resolved the core's
    dependencies' features for sins-cabi alone and compiled the core a second time.)"""
    env = {k: v for k, v in os.environ.items() if k not in ("MAKEFLAGS", "MFLAGS", "MAKELEVEL")}
    make = ["make", "-s", "--no-print-directory", "cabi", "CABI_WITH_TESTS=1"]
    built = subprocess.run(make, cwd=ROOT, env=env, capture_output=True, text=True, check=False)
    assert built.returncode == 0, built.stdout + built.stderr


@pytest.fixture(scope="module")
def cabi_library() -> None:
    """The C ABI library (:func:`build_cabi`), built (or found up to date) once for a module that
    builds C firmware (`pytestmark = pytest.mark.usefixtures(...)`)."""
    build_cabi()


def peak_rss_mb(args: list[str], cwd: Path) -> float:
    """Peak resident memory (MB) of ``python -m sins_fw ARGS`` run to completion in its own process."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "sins_fw", *args], cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE
    )
    _, status, usage = os.wait4(proc.pid, 0)
    assert os.waitstatus_to_exitcode(status) == 0, proc.stderr.read().decode() if proc.stderr else ""
    return usage.ru_maxrss / 1024.0


#: A script that runs each command line of the JSON list ``argv[1]`` in one process (the CLI's
#: ``main``) and prints the process's peak RSS (MB) after each; ``{setup}``: Python run first.
PEAKS_SCRIPT = """
import json, resource, sys
{setup}
from sins_fw.cli import main
peaks = []
for argv in json.loads(sys.argv[1]):
    code = main(argv)
    assert code in (0, 1), (argv, code)
    peaks.append(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0)
print(json.dumps(peaks))
"""


def peaks_mb(runs: list[list[str]], cwd: Path, script: str = PEAKS_SCRIPT.format(setup="")) -> list[float]:
    """The process's peak RSS (MB) after each run of ``runs``, run in that order in one process
    (``script``: :data:`PEAKS_SCRIPT` or one like it)."""
    out = subprocess.run(
        [sys.executable, "-c", script, json.dumps(runs)], cwd=cwd, capture_output=True, text=True
    )
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout.splitlines()[-1])


def signal_once_started(
    args: list[str], started: Callable[[], bool], settle_s: float, sig: int
) -> tuple[float, int, str]:
    """Start ``python -m sins_fw ARGS`` (from the repository), wait (up to 120 s) until `started()`,
    let it run `settle_s` more, send `sig`: the seconds from the signal to its exit, its exit code
    and its standard error."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "sins_fw", *args],
        cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    deadline = time.monotonic() + 120
    while not started() and time.monotonic() < deadline:
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.05)
    time.sleep(settle_s)
    assert proc.poll() is None, proc.communicate()
    sent = time.monotonic()
    proc.send_signal(sig)
    try:
        _, err = proc.communicate(timeout=30)
    finally:
        proc.kill()
    return time.monotonic() - sent, proc.returncode, err


def write_globals(folder: Path, **types: str) -> Path:
    """A C firmware's globals file in `folder` watching each named global with its type, in a column of
    its own name."""
    path = folder / "globals.toml"
    path.write_text(
        "".join(
            f'[[global]]\nname = "{n}"\ntype = "{t}"\ncolumn = "{n}"\nunit = "1"\n' for n, t in types.items()
        )
    )
    return path


def run_alone(
    fw: Path,
    folder: Path,
    until_s: float,
    profile: Profile | None = None,
    events: list[dict[str, Any]] | None = None,
    bus_log: bool = False,
    **types: str,
) -> tuple[Any, list[dict[str, Any]]]:
    """A C firmware's run without a trace on ``profile`` (the reference board's), watching the named
    globals (:func:`write_globals` in ``folder``), and its events, gathered into ``events`` when given
    (where the run stops with an error they are all the test sees)."""
    events = [] if events is None else events
    run = run_c_firmware(
        fw,
        None,
        profile or load_profile("reference"),
        globals_file=write_globals(folder, **types),
        until_s=until_s,
        sink=lambda part: events.extend(part["events"]),
        bus_log=bus_log,
    )
    return run, events


#: C statements of a test firmware's main() that enable CPU timer 0's interrupt (TINT0: PIE group 1,
#: line 7; CPU INT1) and the CPU's.
TINT0_ENABLE = "    IER |= M_INT1;\n    PieCtrlRegs.PIEIER1.bit.INTx7 = 1;\n    EINT;\n"
#: The same after starting CPU timer 0 with a 1 ms period at 150 MHz, as TI's examples do.
TIMER0_1MS = (
    "    InitCpuTimers();\n"
    "    ConfigCpuTimer(&CpuTimer0, 150, 1000);\n"
    "    CpuTimer0Regs.TCR.all = 0x4001;\n"
    f"{TINT0_ENABLE}"
)


#: Modules whose tests start what is sized for the whole machine (a process pool and a Dask cluster of
#: two workers each; a web server and headless Chromium drawing WebGL in software) and wait on it with
#: deadlines. `make test` runs the rest on two pytest-xdist workers, then these alone (marker `alone`).
ALONE = frozenset({"test_engines.py", "test_serve.py"})


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "alone: run after the parallel part, one test at a time (make test)")


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        if item.path.name in ALONE:
            item.add_marker(pytest.mark.alone)
