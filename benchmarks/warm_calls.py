"""CPU time of warm `emulate()` calls in one process, split into user and system time (page faults
show as system time): the benchmark's 240 s coning trace, f64, adis16407 errors, as `sins-fw bench`.

Usage: python benchmarks/warm_calls.py [CALLS]   (default 21; the first, cold call is not counted)
getrusage ticks in 4 ms steps on this machine, so the times are summed over the calls.
"""

from __future__ import annotations

import resource
import sys

from sins_fw import bench
from sins_fw.harness import emulate


def main(calls: int) -> None:
    trace = bench.coning_trace(240.0)
    user = system = 0.0
    faults = cycles = 0
    for i in range(calls):
        r0 = resource.getrusage(resource.RUSAGE_THREAD)
        cycles = emulate(trace, overrides=bench.CASES["full_f64"], keep_truth=False).cycles
        r1 = resource.getrusage(resource.RUSAGE_THREAD)
        if i:
            user += r1.ru_utime - r0.ru_utime
            system += r1.ru_stime - r0.ru_stime
            faults += r1.ru_minflt - r0.ru_minflt
    n = calls - 1
    print(
        f"{n} warm calls of {cycles} cycles: user {user / n * 1e3:.1f} ms, system {system / n * 1e3:.1f} ms, "
        f"{faults / n:.0f} minor faults per call; {cycles * n / (user + system) / 1e3:.1f} k cycles/s"
    )


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 21)
