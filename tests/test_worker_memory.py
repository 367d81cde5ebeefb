"""The package's worker processes keep freed memory: a warm emulation in such a process takes
(almost) no minor page faults, where a plain process faults in every page of its fresh output."""

from __future__ import annotations

import json
import platform
import subprocess
import sys

import pytest

SCRIPT = """
import json, resource, sys
from sins_fw import synth
from sins_fw.harness import emulate
from sins_fw.worker_memory import keep_freed_memory
kept = keep_freed_memory() if sys.argv[1] == "keep" else None
trace = synth.generate("coning", duration_s=240.0)
faults, pages = [], 0
for _ in range(3):
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    run = emulate(trace, keep_truth=False)
    faults.append(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
    pages = sum(v.nbytes for v in vars(run).values() if hasattr(v, "nbytes")) // 4096
    del run
print(json.dumps({"kept": kept, "warm_faults": faults[1:], "output_pages": pages}))
"""


def _faults(mode: str) -> dict:
    out = subprocess.run([sys.executable, "-c", SCRIPT, mode], capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


@pytest.mark.skipif(platform.libc_ver()[0] != "glibc", reason="mallopt is glibc's")
def test_a_worker_keeps_freed_memory_and_stops_faulting():
    plain, keep = _faults("plain"), _faults("keep")
    assert keep["kept"] is True
    pages = plain["output_pages"]
    # Without it each warm run faults in most pages of its fresh output (measured: 4 372 faults for
    # ≈ 4 400 pages); with it the heap is reused and at most a tenth of that remains.
    assert all(f > pages // 2 for f in plain["warm_faults"]), (plain, pages)
    assert all(f < pages // 10 for f in keep["warm_faults"]), (keep, pages)


def test_monte_carlo_workers_keep_freed_memory(monkeypatch):
    """`run_cases` starts its worker processes with `keep_freed_memory`, and the results are those
    of one process."""
    from concurrent.futures import ProcessPoolExecutor

    import numpy as np

    from sins_fw import montecarlo
    from sins_fw.worker_memory import keep_freed_memory

    seen: dict = {}

    def pool(**kwargs: object) -> ProcessPoolExecutor:
        seen.update(kwargs)
        return ProcessPoolExecutor(**kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(montecarlo, "ProcessPoolExecutor", pool)
    case = montecarlo.Case("static 2 s", "static", None, (("duration_s", 2.0),), (0.0, 0.0, 0.0))
    two = montecarlo.run_cases([case], 2, overrides=["errors.preset=adis16407"], workers=2)
    assert seen["initializer"] is keep_freed_memory
    one = montecarlo.run_cases([case], 2, overrides=["errors.preset=adis16407"], workers=1)
    assert np.array_equal(one[case.name].solved_deg, two[case.name].solved_deg)
