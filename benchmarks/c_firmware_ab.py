"""The C firmware benchmark's main figure (`benchmarks/c_firmware.py`: the timer0_burst firmware on
the first ``--duration-s`` s of pitch_sweep.h5, the reference profile) for two builds in the same run:
A, another build of the C runtime and the C ABI library (``--base-cabi``: the folder of its
``libsins_cabi.so``; ``--base-c-dir``: its ``firmware_c``), and B, this tree's. Rounds alternate A B,
B A, A B… so that the machine's load and the order fall on both alike; each round builds nothing
(each side's firmware is built once) and counts the host CPU time of the run (the firmware's
process included). Prints the medians and the ratio B/A.

    python benchmarks/c_firmware_ab.py --base-cabi /path/to/base/target/release \\
        --base-c-dir /path/to/base/firmware_c [--duration-s 60] [--rounds 7]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: One side's measurement, in a process of its own (the C runtime's folder and the C ABI library are
#: chosen at import, from the environment): build once, then run ``rounds`` times, printing each
#: run's CPU time.
CHILD = """
import resource, sys
from pathlib import Path
from sins_fw.firmware_build import build_firmware
from sins_fw.firmware_run import run_c_firmware
from sins_fw.profile import load_profile
from sins_fw.traces import PhysicalTrace
root, out, duration = Path(sys.argv[1]), Path(sys.argv[2]), float(sys.argv[3])
example = root / "firmware_c" / "examples" / "timer0_burst"
fw = out if out.exists() else build_firmware([example], out)
trace = PhysicalTrace.load(root / "python" / "sins_fw" / "bundled_traces" / "pitch_sweep.h5")
def cpu():
    me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime
t = cpu()
g = example / "globals.toml"
r = run_c_firmware(fw, trace, load_profile("reference"), globals_file=g, until_s=duration)
print(cpu() - t, r.accesses, r.now_s)
"""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base-cabi", type=Path, required=True)
    ap.add_argument("--base-c-dir", type=Path, required=True)
    ap.add_argument("--duration-s", type=float, default=60.0)
    ap.add_argument("--rounds", type=int, default=7)
    args = ap.parse_args()
    sides = {
        "A (base)": {"SINS_FW_CABI_DIR": str(args.base_cabi), "SINS_FW_C_DIR": str(args.base_c_dir)},
        "B (this tree)": {},
    }
    cpu: dict[str, list[float]] = {name: [] for name in sides}
    accesses: dict[str, int] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(args.rounds):
            order = list(enumerate(sides.items()))
            for k, (name, env_add) in order if i % 2 == 0 else order[::-1]:
                env = {
                    key: v
                    for key, v in os.environ.items()
                    if key not in ("SINS_FW_CABI_DIR", "SINS_FW_C_DIR")
                }
                env.update(env_add)
                fw = Path(tmp) / f"fw_{k}.so"
                cmd = [sys.executable, "-c", CHILD, str(ROOT), str(fw), str(args.duration_s)]
                out = subprocess.run(cmd, env=env, check=True, capture_output=True, text=True).stdout.split()
                cpu[name].append(float(out[0]))
                accesses[name] = int(out[1])
                print(
                    f"round {i + 1} {name}: {float(out[0]):.3f} s CPU, {out[1]} accesses, {out[2]} s",
                    flush=True,
                )
    a, b = (statistics.median(v) for v in cpu.values())
    print(
        f"median CPU s: A {a:.3f}, B {b:.3f}; B/A = {b / a:.3f}; accesses A {accesses['A (base)']}, "
        f"B {accesses['B (this tree)']}"
    )


if __name__ == "__main__":
    main()
