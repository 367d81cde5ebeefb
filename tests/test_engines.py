"""The Monte Carlo engines and sweeps: the same bits on the local pool and on Dask distributed (a
LocalCluster of two workers bound to 127.0.0.1, never another address) whatever the batch size, a
worker killed in the middle of a run (of single jobs or of batches), mixed software refused, the
optional extra missing, Ctrl-C, a trace checked once, and the sweep tables."""

from __future__ import annotations

import contextlib
import csv
import json
import os
import pickle
import signal
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from conftest import ROOT, run_cli
from sins_fw import harness, sweep
from sins_fw import montecarlo as mc
from sins_fw.errors import InputError, InternalError, TraceError
from sins_fw.harness import emulate
from sins_fw.profile import load_profile
from sins_fw.traces import CheckedTrace

STATIC = mc.Case("static 3 s", "static", None, (("duration_s", 3.0),), (0.0, 0.0, 0.0))
TURN = mc.Case(
    "turn", "indexing-table", None, (("axis", "z"), ("angles_deg", (0.0, 20.0)), ("dwell_s", 1.0)), (0, 0, 20)
)
PROFILE = load_profile("reference", ["errors.preset=adis16407"])
# Two cases × two grid points × three seeds: twelve jobs.
JOBS = mc.jobs_for([STATIC, TURN], [1, 2, 3], PROFILE, [(), ("timer.period_us=2000",)])


def _traces() -> dict:
    return {c.name: c.trace() for c in (STATIC, TURN)}


def _same(a: list[mc.Outcome], b: list[mc.Outcome]) -> bool:
    return len(a) == len(b) and all(x.same_as(y) for x, y in zip(a, b, strict=True))


@pytest.fixture(scope="module")
def reference() -> list[mc.Outcome]:
    """The jobs on the local engine with two processes (run before any cluster starts)."""
    with mc.LocalEngine(2) as engine:
        return mc.collect(engine, JOBS, _traces())


@pytest.fixture(scope="module")
def dask_engine(reference):
    pytest.importorskip("distributed")
    environ = dict(os.environ)
    with mc.DaskEngine(local_workers=2) as engine:
        yield engine
    # The nannies' variables (MALLOC_TRIM_THRESHOLD_ ...) do not stay behind for later subprocesses.
    assert dict(os.environ) == environ


@contextlib.contextmanager
def _batch(engine: mc.DaskEngine, size: int | None):
    """The engine running ``size`` jobs a task for the duration (None: the default rule)."""
    before, engine.batch = engine.batch, size
    try:
        yield
    finally:
        engine.batch = before


def _workers(engine: mc.DaskEngine) -> dict[str, int]:
    """Worker address → process id."""
    return engine.client.run(os.getpid)


def test_local_results_are_ordered_and_distinct(reference):
    assert [o.key for o in reference] == [j.key for j in JOBS]
    # Different seeds and grid points are different realisations; one process gives the same bits.
    assert len({o.final_error_deg for o in reference}) == len(JOBS)
    with mc.LocalEngine(1) as engine:
        assert _same(mc.collect(engine, JOBS, _traces()), reference)


def test_cluster_binds_to_loopback_only(dask_engine):
    assert dask_engine.client.scheduler.address.startswith("tcp://127.0.0.1:")
    workers = _workers(dask_engine)
    assert len(workers) == 2 and all(a.startswith("tcp://127.0.0.1:") for a in workers)


def _trim_threshold() -> str | None:
    return os.environ.get("MALLOC_TRIM_THRESHOLD_")


def test_local_workers_keep_glibcs_adaptive_mmap_threshold(dask_engine):
    # Dask's default sets MALLOC_TRIM_THRESHOLD_=65536 in its workers, which pins glibc's mmap
    # threshold: every large numpy array is then mapped afresh (5x the page faults per realisation).
    assert set(dask_engine.client.run(_trim_threshold).values()) == {None}


@pytest.mark.parametrize("size", [None, 1, 5, 12])
def test_dask_gives_the_local_arrays_whatever_the_batch(dask_engine, reference, size):
    # None: the default rule (12 jobs on 2 workers: 1 a task); 5: batches of 5, 5 and 2; 12: one task.
    seen: list[tuple[int, int, int]] = []
    with _batch(dask_engine, size):
        got = mc.collect(dask_engine, JOBS, _traces(), progress=lambda *counts: seen.append(counts))
    assert dask_engine.last_batch == (size or 1)
    assert dask_engine.describe().endswith(f", {size or 1} run{'s' if (size or 1) > 1 else ''} a task")
    assert _same(got, reference)
    assert np.array_equal(
        np.array([o.error_deg for o in got]), np.array([o.error_deg for o in reference]), equal_nan=True
    )
    # The progress bar still counts realisations, one by one, whatever the batch.
    assert seen == [(k, 0, len(JOBS)) for k in range(1, len(JOBS) + 1)]


def test_batch_size_rule():
    # At least 4 batches a worker, at most 32 jobs a batch, at least 1.
    assert mc.batch_size(128, 2) == 16 and mc.batch_size(128, 1) == 32
    assert mc.batch_size(10_000, 8) == mc.MAX_BATCH == 32
    assert mc.batch_size(12, 2) == 1 and mc.batch_size(0, 2) == 1 and mc.batch_size(5, 0) == 1
    cut = mc.batches(JOBS, 5)
    assert [len(b.jobs) for b in cut] == [5, 5, 2]
    assert [j for b in cut for j in b.jobs] == JOBS
    assert cut[0].cases == (STATIC.name,) and cut[1].cases == (STATIC.name, TURN.name)


@pytest.mark.parametrize("size", [1, 3])
def test_a_worker_killed_mid_run_gives_the_identical_result_set(dask_engine, size):
    # Runs of about 0.1 s each, so that both workers still have runs queued after the first result
    # (with batches of 3, the first result comes with two others, and the lost batch is run again whole).
    dask_engine.client.wait_for_workers(2, timeout=120)  # the one killed before is back
    long = mc.Case("static 300 s", "static", None, (("duration_s", 300.0),), (0.0, 0.0, 0.0))
    jobs = mc.jobs_for([long], range(1, 13), PROFILE)
    traces = {long.name: long.trace()}
    with mc.LocalEngine(1) as engine:
        reference = mc.collect(engine, jobs, traces)
    killed: list[int] = []

    def kill_one_busy_worker(done: int, failed: int, total: int) -> None:
        if killed or done < 1:
            return
        busy = {w for w, tasks in dask_engine.client.processing().items() if tasks}
        pids = _workers(dask_engine)
        victim = next(w for w in pids if w in busy)
        os.kill(pids[victim], signal.SIGKILL)
        killed.append(pids[victim])

    with _batch(dask_engine, size):
        got = mc.collect(dask_engine, jobs, traces, progress=kill_one_busy_worker)
    assert killed, "no worker was busy after the first result"
    assert _same(got, reference)
    # The nanny restarted the worker: two again, neither the one killed.
    deadline = time.monotonic() + 60
    while len(pids := _workers(dask_engine)) < 2 and time.monotonic() < deadline:
        time.sleep(0.2)
    assert killed[0] not in pids.values()


def test_results_from_different_software_are_refused(dask_engine):
    dask_engine.client.wait_for_workers(2, timeout=120)  # the one killed above is back
    workers = list(_workers(dask_engine))
    fake = "import sins_fw.montecarlo as m; m._fingerprint = m.Fingerprint('0.0.0', 'other', 'elsewhere')"
    dask_engine.client.run(exec, fake, workers=workers[:1])
    try:
        with pytest.raises(InputError, match="results from different software"):
            mc.collect(dask_engine, JOBS, _traces())
    finally:
        dask_engine.client.run(exec, "import sins_fw.montecarlo as m; m._fingerprint = None")


def test_an_interruption_cancels_the_outstanding_dask_tasks(dask_engine):
    def interrupt(done: int, failed: int, total: int) -> None:
        raise KeyboardInterrupt

    with _batch(dask_engine, 4), pytest.raises(KeyboardInterrupt):
        mc.collect(dask_engine, JOBS, _traces(), progress=interrupt)

    def tasks(dask_scheduler) -> int:
        return len(dask_scheduler.tasks)

    # The scheduler forgets every job and the scattered traces (none left queued, running or held).
    deadline = time.monotonic() + 30
    while (left := dask_engine.client.run_on_scheduler(tasks)) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert left == 0


def test_admit_checks_fingerprint_and_repeats(reference):
    results: dict = {}
    first = reference[0]
    mc.admit(results, first)
    mc.admit(results, first)  # the same job seen twice with the same bits: kept once
    assert list(results) == [first.key]
    with pytest.raises(InternalError, match="two different results"):
        mc.admit(results, replace(first, final_error_deg=(0.0,) * 6))
    other = replace(reference[1], fingerprint=mc.Fingerprint("0.0.0", "other", "elsewhere"))
    with pytest.raises(InputError, match="different software"):
        mc.admit(results, other)


def test_missing_extra_exits_2():
    code = (
        "import sys; sys.modules['distributed'] = None\n"
        "from sins_fw.cli import main\n"
        "sys.exit(main(['montecarlo', 'static', '--param', 'duration-s=1', '--runs', '1', "
        "'--engine', 'dask', '--local-workers', '1']))"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=False)
    assert r.returncode == 2, r.stderr
    assert 'pip install "sins-fw[dask]"' in r.stderr and "Traceback" not in r.stderr


def test_a_bad_trace_is_refused_once_with_emulates_message(monkeypatch):
    bad = STATIC.trace()
    bad.gyro_dps[7, 1] = np.nan
    with pytest.raises(TraceError) as in_emulate:
        emulate(bad, PROFILE)
    with mc.LocalEngine(2) as engine, pytest.raises(TraceError) as in_collect:
        mc.collect(engine, JOBS, {STATIC.name: bad, TURN.name: TURN.trace()})
    # The same message, naming the case, before any job ran (no "12 of 12 runs failed").
    assert str(in_collect.value) == f"case `{STATIC.name}`: {in_emulate.value}"


def test_a_checked_trace_is_checked_once_and_cannot_change(monkeypatch):
    trace = STATIC.trace()
    checked = CheckedTrace(trace)
    trace.gyro_dps[:] = np.nan  # the caller's arrays are not the checked ones
    for copy in (checked, pickle.loads(pickle.dumps(checked))):
        view = copy.trace
        assert view is not copy.trace and np.isfinite(view.gyro_dps).all()
        with pytest.raises(ValueError, match="read-only"):
            view.gyro_dps[0, 0] = 1.0
        view.metadata["sample_rate_hz"] = "1"  # a copy: the checked trace keeps its own
        assert copy.trace.metadata["sample_rate_hz"] != "1"
    # The jobs take it as it is: no check in any job (none can fail here), and the same bits.
    reference = mc.run_job(JOBS[0], STATIC.trace())

    def no_check(*args, **kwargs):
        raise AssertionError("a checked trace was checked again")

    monkeypatch.setattr(harness, "validated", no_check)
    with mc.LocalEngine(1) as engine:
        got = mc.collect(engine, JOBS[:1], {STATIC.name: checked})
    assert got[0].same_as(reference)
    with pytest.raises(TraceError, match="expected a PhysicalTrace"):
        CheckedTrace("trace.csv")  # type: ignore[arg-type]


def test_engine_options_are_checked():
    r = run_cli("montecarlo", "static", "--runs", "1", "--engine", "dask")
    assert r.code == 2 and "--scheduler" in r.err and "--local-workers" in r.err
    r = run_cli("montecarlo", "static", "--runs", "1", "--scheduler", "tcp://127.0.0.1:1")
    assert r.code == 2 and "--engine dask" in r.err
    r = run_cli("montecarlo", "static", "--runs", "1", "--out", "x.txt")
    assert r.code == 2 and ".parquet" in r.err
    r = run_cli("montecarlo", "static", "--runs", "1", "--batch", "4")
    assert r.code == 2 and "--batch" in r.err and "--engine dask" in r.err
    r = run_cli(
        "montecarlo", "static", "--runs", "1", "--engine", "dask", "--local-workers", "1", "--batch", "0"
    )
    assert r.code == 2 and "--batch 0: expected at least 1" in r.err


def test_montecarlo_cli_on_dask_in_batches_gives_the_local_report():
    pytest.importorskip("distributed")
    common = ["montecarlo", "static", "--param", "duration-s=2", "--runs", "4", "--json"]
    local = run_cli(*common, "--workers", "1")
    dask = run_cli(*common, "--engine", "dask", "--local-workers", "1", "--batch", "3")
    assert local.code == 0 and dask.code == 0, dask.err
    a, b = json.loads(local.out), json.loads(dask.out)
    assert b["engine"].endswith(", 1 worker, 3 runs a task")  # batches of 3 and 1
    assert a["cases"] == b["cases"]


def _pool_started(pid: int) -> bool:
    cmdline = Path(f"/proc/{pid}/cmdline").read_bytes()
    for child in Path(f"/proc/{pid}/task/{pid}/children").read_text().split():
        with contextlib.suppress(OSError):
            if Path(f"/proc/{child}/cmdline").read_bytes() == cmdline:
                return True
    return False


def test_ctrl_c_cancels_writes_nothing_and_exits_130(tmp_path):
    out = tmp_path / "runs.csv"
    args = ["montecarlo", "static", "--param", "duration-s=300", "--runs", "400", "--workers", "2"]
    proc = subprocess.Popen(
        [sys.executable, "-m", "sins_fw", *args, "--out", str(out)],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    # The runs have started once the pool's worker processes exist (about 20 s of work remain): forked
    # children with the same command line (not a helper some import may run, such as `uname`).
    deadline = time.monotonic() + 60
    while not _pool_started(proc.pid) and time.monotonic() < deadline:
        time.sleep(0.1)
    time.sleep(0.5)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert "runs completed" in err and "nothing was written" in err and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []


def test_sweep_writes_one_tidy_table_with_percentiles(tmp_path):
    out = tmp_path / "sweep.parquet"
    r = run_cli(
        "sweep", "static", "--param", "duration-s=2", "--grid", "spi.spibrr=9,49", "--grid",
        "errors.seed=1..3", "--workers", "1", "--out", str(out), "--plot", str(tmp_path / "s.png"), "--json",
    )  # fmt: skip
    assert r.code == 0, r.err
    assert "p5 and p95 are then the sample's extremes" in r.err  # three runs per point
    rep = json.loads(r.out)
    assert rep["points"] == ["spi.spibrr=9", "spi.spibrr=49"] and rep["seeds"] == [1, 2, 3]
    import pyarrow.parquet as pq

    runs = pq.read_table(out).to_pydict()
    assert runs["spi.spibrr"] == ["9"] * 3 + ["49"] * 3 and runs["seed"] == [1, 2, 3] * 2
    with open(tmp_path / "sweep.csv", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    # The CSV copy reads back as the same floats.
    assert [float(x["error_total_deg"]) for x in rows] == runs["error_total_deg"]
    pct = pq.read_table(tmp_path / "sweep-percentiles.parquet").to_pydict()
    assert len(pct["error"]) == 2 * len(mc.ERRORS) and set(pct["runs"]) == {3}
    i = pct["point"].index("spi.spibrr=9") + mc.ERRORS.index("total")
    assert pct["p50_deg"][i] == float(np.percentile(runs["error_total_deg"][:3], 50))
    assert (tmp_path / "s.png").stat().st_size > 10_000
    assert (tmp_path / "sweep-percentiles.csv").is_file()


def test_sweep_hdf5_and_bad_grids(tmp_path):
    import h5py

    out = tmp_path / "s.h5"
    r = run_cli(
        "sweep", "static", "--param", "duration-s=1", "--point", "spi.spibrr=9", "--runs", "2", "--workers",
        "1", "--out", str(out),
    )  # fmt: skip
    assert r.code == 0, r.err
    with h5py.File(out) as f:
        assert f["runs/seed"][()].tolist() == [1, 2]
        assert [s.decode() for s in f["percentiles/error"][()]] == list(mc.ERRORS)
    for grid, said in (
        ("spi.nosuch=1", "nosuch"),
        ("errors.seed=1..x", "two integers"),
        ("spi.spibrr", "KEY="),
    ):
        r = run_cli("sweep", "static", "--grid", grid, "--runs", "1")
        assert r.code == 2 and said in r.err and "Traceback" not in r.err, r.err


def test_grid_values():
    assert sweep.parse_values("1..3,7", "g") == ["1", "2", "3", "7"]
    with pytest.raises(InputError, match="empty"):
        sweep.parse_values("5..3", "g")
    points = sweep.grid_points(
        PROFILE, {"spi.spibrr": ["9", "49"], "errors.seed": ["1"]}, [("timer.period_us=4000",)]
    )
    assert points == [("timer.period_us=4000", "spi.spibrr=9"), ("timer.period_us=4000", "spi.spibrr=49")]
