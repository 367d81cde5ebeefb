"""CPU time of `emulate()` calls in one process, split into user and system time (page faults show
as system time): the benchmark's coning trace (240 s unless told), f64, adis16407 errors, as
`sins-fw bench`. Prints the first (cold) call, then the sum of the warm ones.

Usage: python benchmarks/warm_calls.py [CALLS [SECONDS]]   (defaults 21 calls, 240 s)
getrusage ticks in 4 ms steps on this machine, so the warm calls' times are summed.
"""

from __future__ import annotations

import resource
import sys

from sins_fw import bench
from sins_fw.harness import emulate


def main(calls: int, seconds: float) -> None:
    trace = bench.coning_trace(seconds)
    user = system = 0.0
    faults = cycles = 0
    for i in range(calls):
        r0 = resource.getrusage(resource.RUSAGE_THREAD)
        cycles = emulate(trace, overrides=bench.CASES["full_f64"], keep_truth=False).cycles
        r1 = resource.getrusage(resource.RUSAGE_THREAD)
        if i == 0:
            print(
                f"cold call of {cycles} cycles: user {(r1.ru_utime - r0.ru_utime) * 1e3:.0f} ms, "
                f"system {(r1.ru_stime - r0.ru_stime) * 1e3:.0f} ms, "
                f"{r1.ru_minflt - r0.ru_minflt} minor faults"
            )
        else:
            user += r1.ru_utime - r0.ru_utime
            system += r1.ru_stime - r0.ru_stime
            faults += r1.ru_minflt - r0.ru_minflt
    n = calls - 1
    if n:
        # getrusage counts in ticks: a short enough input can take none.
        rate = (
            f"{cycles * n / (user + system) / 1e3:.1f} k cycles/s" if user + system else "too short to time"
        )
        print(
            f"{n} warm calls of {cycles} cycles: user {user / n * 1e3:.1f} ms, "
            f"system {system / n * 1e3:.1f} ms, {faults / n:.0f} minor faults per call; {rate}"
        )


if __name__ == "__main__":
    try:
        calls = int(sys.argv[1]) if len(sys.argv) > 1 else 21
        seconds = float(sys.argv[2]) if len(sys.argv) > 2 else 240.0
    except ValueError as e:
        sys.exit(f"warm_calls.py: {e}; usage: warm_calls.py [CALLS [SECONDS]]")
    if calls < 1 or not seconds > 0:
        sys.exit("warm_calls.py: expected CALLS >= 1 and SECONDS > 0")
    main(calls, seconds)
