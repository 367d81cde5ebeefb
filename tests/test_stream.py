"""Streamed trace writing (issue 24, item 11): chunk by chunk, the same values (and, where the layout
allows, the same bytes) as the whole-array writer, atomically, with memory that does not grow with
the duration."""

from __future__ import annotations

import h5py
import numpy as np
import pytest

from conftest import peak_rss_mb
from sins_fw import stream, synth
from sins_fw.errors import TraceError
from sins_fw.traces import PhysicalTrace

#: Short parameters for each scenario (a few thousand rows each; flight is fixed at 318 s).
SHORT = {
    "static": {"duration_s": 7.0, "attitude_deg": (3.0, -4.0, 5.0)},
    "indexing-table": {"angles_deg": (0.0, 10.0, -5.0), "dwell_s": 1.0},
    "turntable": {"rates_dps": (50.0, -20.0), "hold_s": 1.0, "lead_s": 0.5},
    "coning": {"duration_s": 6.0},
    "flight": {},
}


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


@pytest.mark.parametrize("name", sorted(SHORT))
def test_chunks_are_the_whole_trace_bit_for_bit(name):
    # Fails if any scenario's motion depended on the rows around it (a sum over time, a grid that
    # restarts at each chunk): the chunks' concatenation would differ from the whole trace.
    whole = synth.generate(name, **SHORT[name])
    chunks = list(synth.generate_chunks(name, rows=1000, **SHORT[name]))
    assert len(chunks) == -(-len(whole) // 1000)
    cols = [c.columns() for c in chunks]
    for key, value in whole.columns().items():
        assert _same(np.concatenate([c[key] for c in cols]), value), key
    assert all(c.metadata == whole.metadata for c in chunks)


def test_streamed_csv_is_the_whole_writers_bytes(tmp_path):
    trace = synth.generate("coning", duration_s=3.0)
    trace.save(tmp_path / "whole.csv")
    written = stream.save_chunks(
        tmp_path / "chunks.csv", synth.generate_chunks("coning", rows=700, duration_s=3.0)
    )
    assert (tmp_path / "chunks.csv").read_bytes() == (tmp_path / "whole.csv").read_bytes()
    assert written.rows == len(trace) and written.duration_s == trace.duration_s


def test_a_short_h5_is_the_whole_writers_bytes(tmp_path):
    trace = synth.generate("static", duration_s=20.0)
    trace.save(tmp_path / "whole.h5")
    stream.save_chunks(tmp_path / "chunks.h5", synth.generate_chunks("static", rows=4096, duration_s=20.0))
    assert (tmp_path / "chunks.h5").read_bytes() == (tmp_path / "whole.h5").read_bytes()


def test_a_long_h5_streams_the_same_values_chunked_alike(tmp_path, monkeypatch):
    # Scaled down: chunks of 1 000 rows, streaming from the first chunk on.
    monkeypatch.setattr(stream, "BLOCK_ROWS", 1000)
    monkeypatch.setattr(stream, "WHOLE_ROWS", 0)
    trace = synth.generate("coning", duration_s=4.0)
    stream.save_chunks(tmp_path / "s.h5", synth.generate_chunks("coning", rows=777, duration_s=4.0))
    back = PhysicalTrace.load(tmp_path / "s.h5")
    for key, value in trace.columns().items():
        assert _same(back.columns()[key], value), key
    assert back.metadata == {"format": trace.schema.format, **trace.metadata}
    with h5py.File(tmp_path / "s.h5") as f:
        assert f["t_s"].chunks == (1000,) and f["t_s"].compression == "gzip" and f["t_s"].shuffle
        assert f["moving"].dtype == np.uint8 and f["gyro_x_dps"].attrs["unit"] == "°/s"


def test_a_stream_that_fails_leaves_the_old_file(tmp_path, monkeypatch):
    monkeypatch.setattr(stream, "BLOCK_ROWS", 1000)
    monkeypatch.setattr(stream, "WHOLE_ROWS", 0)
    out = tmp_path / "t.h5"
    out.write_bytes(b"old")
    chunks = list(synth.generate_chunks("static", rows=1500, duration_s=6.0))
    bad = chunks[2]
    bad.gyro_dps[10, 1] = np.inf  # a defect in the third chunk: two chunks are already written
    with pytest.raises(TraceError, match="row 3010, column `gyro_y_dps`"):
        stream.save_chunks(out, chunks)
    assert out.read_bytes() == b"old" and [p.name for p in tmp_path.iterdir()] == ["t.h5"]


# --------------------------------------------------------------------------------- memory vs duration

#: Rows a streaming command holds at once (a trace chunk), and the bytes per row it may hold per chunk.
CHUNK = synth.CHUNK_ROWS


def test_synth_memory_does_not_grow_with_the_duration(tmp_path):
    """Peak RSS of `synth static` for 30 min minus that for 10 min, both past WHOLE_ROWS (so both
    stream the same way), must stay below one chunk's worth of what is held per chunk.

    Per chunk of C = 65 536 rows the generator holds the motion (time, attitude, rate, velocity,
    acceleration, latitude, height, transport rate: 1 + 4 + 3 × 5 + 2 = 22 doubles a row) and its
    intermediates (the sensor quantities in rad/s and m/s², the trace's 17 columns, a copy each for
    the writer's dtypes: fewer than 3 × 22 = 66 doubles a row), and the writer holds at most
    WHOLE_ROWS + C rows of 17 columns. Those are the same for 10 and 30 minutes: what differs between
    the two runs is the allocator's noise, bounded by one chunk of the whole per-chunk state,
    C × (22 + 66 + 17) × 8 B ≈ 55 MB. Before streaming the difference was the whole trace twice over
    (20 min × 819.2 SPS × (17 + 22) doubles ≈ 300 MB).
    """
    short = peak_rss_mb(["synth", "static", "--duration-s", "600", "--out", "a.h5"], tmp_path)
    long = peak_rss_mb(["synth", "static", "--duration-s", "1800", "--out", "b.h5"], tmp_path)
    margin = CHUNK * (22 + 66 + 17) * 8 / 1e6
    assert long - short < margin, (short, long, margin)
