"""The lowest address-space cap (RLIMIT_AS, `ulimit -v`) under which each command works, and what
it does below (issue 42, item 2): exit 0/1, or exit 2 with "not enough memory for …", never a
signal or a traceback. Each command runs as its own process under the cap, caps in MiB.

    python benchmarks/memory_cap.py                       # the commands of docs/cli.md
    python benchmarks/memory_cap.py --caps 500,550,600 --commands board
"""

from __future__ import annotations

import argparse
import platform
import resource
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
STATIC = ROOT / "traces" / "static_60s.h5"
COMMANDS = {
    "--version": ["--version"],
    "board": ["board"],
    "budget": ["budget"],
    "run": ["run", str(STATIC)],
    "replay": ["replay", str(STATIC), "--out", "{tmp}/r.rrd"],
}


def outcome(args: list[str], cap_mib: int) -> str:
    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (cap_mib << 20, cap_mib << 20))

    code = "import sys; from sins_fw.launch import entry; sys.argv[0] = 'sins-fw'; entry()"
    r = subprocess.run([sys.executable, "-c", code, *args], preexec_fn=limit, capture_output=True, text=True)
    if r.returncode < 0:
        return f"signal {-r.returncode}"
    if "Traceback" in r.stderr:
        return f"traceback, exit {r.returncode}"
    if r.returncode == 2 and "not enough memory for" in r.stderr:
        return "exit 2, not enough memory"
    return f"exit {r.returncode}"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--caps", default="300,450,500,525,550,575,600,650,700,750,1000,1500,2000")
    ap.add_argument("--commands", default=",".join(COMMANDS))
    a = ap.parse_args()
    caps = [int(x) for x in a.caps.split(",")]
    names = a.commands.split(",")
    print(f"Machine: {platform.platform()}, {platform.processor() or platform.machine()}")
    print("| cap (MiB) | " + " | ".join(f"`{n}`" for n in names) + " |")
    print("|---" * (len(names) + 1) + "|")
    with tempfile.TemporaryDirectory() as tmp:
        for cap in caps:
            cells = [outcome([x.format(tmp=tmp) for x in COMMANDS[n]], cap) for n in names]
            print(f"| {cap} | " + " | ".join(cells) + " |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
