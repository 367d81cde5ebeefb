"""Instructions a C firmware run costs, counted by valgrind's callgrind (immune to the machine's load,
unlike CPU time on a shared 2-CPU machine): one firmware example on one trace, for this tree and
optionally for another (``--base-root``: a checkout of it with its Python package importable and its
extension built; ``--base-cabi``: the folder of its ``libsins_cabi.so``).

For each side it prints the instructions of every process of the run (the harness and, from the
process isolation on, the firmware's own process, summed) and the firmware side alone: the
firmware's ``sins_fw_user_main`` and everything it calls (the runtime, the C ABI, the board) less
the harness's input callback (``cover``: the Python that feeds the trace and takes the events), with
the register accesses and the instructions per access. The firmware is built outside valgrind,
without debug information (valgrind 3.19 cannot read clang's DWARF 5). The run's process kills the
firmware's process at its end (SIGKILL, which would lose its profile): here the kill is left out and
the firmware's process ends by itself.

    python benchmarks/c_firmware_instructions.py [--example reference] \\
        [--trace traces/static_60s.h5] [--until-s 20] [--base-root DIR --base-cabi DIR]
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: One side's run, in a process of its own (the C ABI library is chosen at import).
CHILD = """
import os, signal, sys
from pathlib import Path
root, fw, mode, example, trace, until = sys.argv[1:7]
from sins_fw.firmware_build import build_firmware
ex = Path(root) / "firmware_c" / "examples" / example
if mode == "build":
    build_firmware([ex], Path(fw))
    sys.exit(0)
from sins_fw.firmware_run import run_c_firmware
from sins_fw.profile import load_profile
from sins_fw.traces import PhysicalTrace
kill = os.kill
os.kill = lambda pid, sig: None if sig == signal.SIGKILL else kill(pid, sig)
g = ex / "globals.toml"
r = run_c_firmware(Path(fw), PhysicalTrace.load(trace), load_profile("reference"),
                   globals_file=g if g.is_file() else None, until_s=float(until))
print("accesses", r.accesses)
"""


def _inclusive(profile: Path, pattern: str) -> int:
    """The inclusive instructions of the first function matching ``pattern`` (0 if none)."""
    out = subprocess.run(
        ["callgrind_annotate", "--inclusive=yes", str(profile)], capture_output=True, text=True, check=True
    ).stdout
    for line in out.splitlines():
        m = re.match(r"\s*([\d,]+) \([ \d.]+%\)\s+\S*:(.*)", line)
        if m and re.search(pattern, m.group(2)):
            return int(m.group(1).replace(",", ""))
    return 0


def _total(profile: Path) -> int:
    text = profile.read_text(errors="replace")
    m = re.search(r"^totals: (\d+)", text, re.M) or re.search(r"^summary: (\d+)", text, re.M)
    return int(m.group(1)) if m else 0


def side(name: str, root: Path, env: dict[str, str], args: argparse.Namespace, tmp: Path) -> None:
    fw = tmp / f"{name}.so"
    cmd = [sys.executable, "-c", CHILD, str(root), str(fw)]
    rest = [args.example, str(args.trace), str(args.until_s)]
    subprocess.run([*cmd, "build", *rest], env=env, check=True, cwd=root)
    subprocess.run(["strip", "--strip-debug", str(fw)], check=True)
    # A short run first, outside valgrind: Python's byte-code caches are written before counting.
    warm = [*cmd, "run", args.example, str(args.trace), "0.01"]
    subprocess.run(warm, env=env, check=True, cwd=root, stdout=subprocess.DEVNULL)
    out = tmp / f"{name}.%p.cg"
    run = subprocess.run(
        ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", *cmd, "run", *rest],
        env=env,
        cwd=root,
        capture_output=True,
        text=True,
        check=True,
    )
    accesses = int(re.search(r"accesses (\d+)", run.stdout).group(1))  # type: ignore[union-attr]
    profiles = sorted(tmp.glob(f"{name}.*.cg"))
    total = sum(_total(p) for p in profiles)
    firmware = 0
    for p in profiles:
        main = _inclusive(p, r"sins_fw_user_main")
        if main:
            firmware = main - _inclusive(p, r"namespace\)::cover\(")
    print(
        f"{name}: {total:,} instructions in {len(profiles)} process(es); firmware side {firmware:,} "
        f"for {accesses:,} register accesses ({firmware / max(accesses, 1):.0f} per access)",
        flush=True,
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--example", default="reference")
    ap.add_argument("--trace", type=Path, default=ROOT / "traces" / "static_60s.h5")
    ap.add_argument("--until-s", type=float, default=20.0)
    ap.add_argument("--base-root", type=Path)
    ap.add_argument("--base-cabi", type=Path)
    args = ap.parse_args()
    if shutil.which("valgrind") is None or shutil.which("callgrind_annotate") is None:
        sys.exit("valgrind (callgrind) is not installed")
    args.trace = args.trace.resolve()
    clean = {
        k: v for k, v in os.environ.items() if k not in ("SINS_FW_CABI_DIR", "SINS_FW_C_DIR", "PYTHONPATH")
    }
    with tempfile.TemporaryDirectory() as tmp:
        if args.base_root is not None:
            env = dict(clean, PYTHONPATH=str(args.base_root / "python"))
            if args.base_cabi is not None:
                env["SINS_FW_CABI_DIR"] = str(args.base_cabi)
            side("base", args.base_root, env, args, Path(tmp))
        side("this_tree", ROOT, clean, args, Path(tmp))


if __name__ == "__main__":
    main()
