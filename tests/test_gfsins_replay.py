"""`replay TRACE --profile gfsins` streams (issue 42, item 7): the board runs block by block over the
trace read a chunk at a time, as `run` does, each block logged as it comes, so that memory holds a
block whatever the trace's length and Ctrl-C or SIGTERM stop it within a second with nothing
written; the recording holds what the whole run's recording held."""

from __future__ import annotations

import json
import platform
import signal
from pathlib import Path

import pytest

from conftest import peak_rss_mb, run_cli, signal_once_started
from sins_fw import gfsins
from sins_fw.traces import PhysicalTrace, file_sha256


def _content(path: Path) -> dict[tuple[str, tuple[str, ...]], object]:
    """Every entity's rows of a recording, per entity and set of columns (row ids left out: they
    number the chunks, which a block boundary may place differently)."""
    import pyarrow as pa
    import rerun as rr

    by: dict[tuple[str, tuple[str, ...]], list[pa.Table]] = {}
    for chunk in rr.chunk.RrdReader(path).stream():
        batch = chunk.to_record_batch()
        keep = tuple(n for n in batch.schema.names if "rowid" not in n.lower().replace("_", ""))
        by.setdefault((chunk.entity_path, keep), []).append(pa.Table.from_batches([batch.select(list(keep))]))
    return {k: pa.concat_tables(v).combine_chunks() for k, v in by.items()}


def test_the_streamed_replay_records_what_the_whole_run_records(tmp_path):
    # 12 s: 2 280 ticks, two blocks of the core (gfsins.BLOCK_TICKS = 2 000); the bus window
    # spans the blocks' boundary.
    from sins_fw.viewer import gfsins as view
    from sins_fw.viewer import recording

    trace = tmp_path / "v.h5"
    assert run_cli("synth", "vehicle", "--duration-s", "12", "--out", str(trace)).code == 0
    out = tmp_path / "s.rrd"
    r = run_cli(
        "replay", str(trace), "--profile", "gfsins", "--out", str(out), "--bus-ticks", "1900:2100", "--json"
    )
    assert r.code == 0, r.err
    report = json.loads(r.out)
    assert report["cycles"] > gfsins.BLOCK_TICKS
    # The whole run logged at once, with the id the command derives from the same inputs.
    window = (1900, 2100)
    prof = gfsins.load(gfsins.PROFILE)
    whole_trace = PhysicalTrace.load(trace)
    whole = gfsins.run(whole_trace, gfsins.ticks_in(whole_trace, prof), prof)
    truth = gfsins.truth_tilt_deg(whole_trace, whole["t0_s"][:, 0])
    rid = recording.recording_id(prof.text, "", trace.name, bytes.fromhex(file_sha256(trace)), repr(window))
    bp = view.blueprint(bus=True)
    with recording.recording_file(tmp_path / "w.rrd", recording_id=rid, blueprint=bp, name=trace.name) as rec:
        logged = view.record(rec, whole, truth, window, int(prof.get("compass.address")))
    assert report["cycles"] == len(whole["sequence"]) and report["bus_transactions"] == logged > 0
    streamed, reference = _content(out), _content(tmp_path / "w.rrd")
    assert sorted(streamed) == sorted(reference)
    for key, table in reference.items():
        assert streamed[key].equals(table), key


@pytest.mark.parametrize("sig, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_long_gyro_free_replay_stops_within_a_second_with_nothing_written(tmp_path, sig, code):
    """With the costliest accepted access (a whole period per PLB access) the board takes dozens of
    periods per tick; the core returns every ≈ 0.25 s, the replay checks for a stop between blocks.
    (The whole run was one call into the core: the signal waited for its end.)"""
    trace = tmp_path / "long.h5"
    assert run_cli("synth", "vehicle", "--duration-s", "60", "--out", str(trace)).code == 0
    out = tmp_path / "r.rrd"
    # Started: the recording's temporary file is there (the board runs once it is open).
    args = [
        "replay",
        str(trace),
        "--profile",
        "gfsins",
        "--set",
        "node.plb_access_cycles=375000",
        "--out",
        str(out),
    ]
    took, returncode, err = signal_once_started(args, lambda: len(list(tmp_path.iterdir())) >= 2, 1.0, sig)
    # The stop itself comes within a second; the margin is the interpreter's exit on a loaded machine.
    assert took < 5.0
    assert returncode == code, err
    assert "stopped" in err and "not written" in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["long.h5"], "nothing half-written"


@pytest.mark.skipif(platform.system() != "Linux", reason="ru_maxrss in kB is Linux's")
def test_the_gyro_free_replay_streams_in_bounded_memory(tmp_path):
    """Peak RSS of the replay of 360 s minus that of 120 s. Both have filled Rerun's per-entity
    buffers (≈ 1 MB each, reached within the first two minutes) and hold a chunk of the trace
    (16 384 rows × 41 columns, 5.4 MB, and the inputs made from it: three times that) and a block
    of cycles: the rise is the allocator's noise, under that 16 MB. The whole run held the trace
    and every cycle: 240 s more of them is ≈ 300 MB (measured 30 s → 150 s: 189 → 355 MB)."""
    peaks = []
    for seconds in (120, 360):
        trace = tmp_path / f"v{seconds}.h5"
        assert run_cli("synth", "vehicle", "--duration-s", str(seconds), "--out", str(trace)).code == 0
        peaks.append(
            peak_rss_mb(["replay", str(trace), "--profile", "gfsins", "--out", f"r{seconds}.rrd"], tmp_path)
        )
    assert peaks[1] - peaks[0] < 16.0, peaks
