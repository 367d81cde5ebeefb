"""A streamed HDF5 file holds a chunk, not the file (issue 42, item 5): HDF5's chunk cache kept every
chunk written until the file closed (a 900 s gyro-free vehicle trace peaked at 440 MB), and the file
keeps the bytes it had when the cache held them all."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from typing import Any

import h5py
import numpy as np
import pytest

from sins_fw import stream, synth
from sins_fw.atomic import kept_error_file
from sins_fw.tablefile import h5_create
from sins_fw.traces import PhysicalTrace


@pytest.mark.parametrize("nslots, nbytes", [(8191, 1 << 23), (7, 40_000), (3, 1 << 23)])
def test_a_streamed_h5_keeps_the_bytes_hdf5s_chunk_cache_gave(tmp_path, monkeypatch, nslots, nbytes):
    """The bytes of the writer that wrote through HDF5's chunk cache, whatever the cache: the
    default (every chunk held until the close: 6 chunks of 8 kB a column), one that holds 4 chunks
    (least recently used written first) in 7 slots, one of 3 slots (chunks 3 apart share one)."""
    monkeypatch.setattr(stream, "BLOCK_ROWS", 1000)
    monkeypatch.setattr(stream, "WHOLE_ROWS", 0)
    real = h5py.File

    def cached(*args: Any, **kwargs: Any) -> h5py.File:
        kwargs.setdefault("rdcc_nslots", nslots)
        kwargs.setdefault("rdcc_nbytes", nbytes)
        return real(*args, **kwargs)

    monkeypatch.setattr(stream.h5py, "File", cached)
    chunks = list(synth.generate_chunks("coning", rows=777, duration_s=6.5))  # a last chunk partial
    stream.save_chunks(tmp_path / "s.h5", chunks)
    # The reference: the writer's creations, extensions and writes, a chunk of rows at a time,
    # through the cache (as the writer did before it kept the rows out of it).
    cols = {k: np.concatenate([c.columns()[k] for c in chunks]) for k in chunks[0].columns()}
    schema = chunks[0].schema
    names = schema.order(list(cols))
    n = len(cols["t_s"])
    with (
        kept_error_file(tmp_path / "ref.h5") as raw,
        cached(raw, "w", libver=("earliest", "v110"), track_order=True) as f,
    ):
        for k, v in {"format": schema.format, **chunks[0].metadata}.items():
            f.attrs[k] = v
        sets = {name: h5_create(f, schema.column(name), cols[name][:0], 1000) for name in names}
        for start in range(0, n, 1000):
            stop = min(n, start + 1000)
            for name in names:
                sets[name].resize((stop,))
                sets[name][start:stop] = cols[name][start:stop]
    assert (tmp_path / "s.h5").read_bytes() == (tmp_path / "ref.h5").read_bytes()
    back = PhysicalTrace.load(tmp_path / "s.h5")
    for key, value in cols.items():
        assert back.columns()[key].tobytes() == value.tobytes(), key
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ref.h5", "s.h5"]  # no scratch file left


#: Written in its own process: a static trace's first chunk, repeated (time shifted) past the rows
#: held whole; the peak resident memory (MB) after `first` and after `last` chunks.
SCRIPT = textwrap.dedent(
    """
    import resource, sys
    from sins_fw import stream, synth
    first, last = int(sys.argv[2]), int(sys.argv[3])
    chunk = next(synth.generate_chunks("static", duration_s=100.0))
    cols = chunk.columns()
    span = len(chunk) / 819.2
    peaks = []
    with stream.TableWriter(sys.argv[1], chunk.schema, chunk.metadata) as w:
        for k in range(last):
            w.write({**cols, "t_s": cols["t_s"] + k * span})
            if k + 1 in (first, last):
                peaks.append(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)
    print(peaks[0], peaks[1])
    """
)


def test_a_streamed_h5_does_not_grow_with_its_chunks(tmp_path):
    """The peak after 20 chunks of 65 536 rows minus that after 8 (both past the 5 chunks held whole):
    the writer holds one chunk of rows and HDF5 one chunk of every column, the same for both, so
    the rise is the allocator's noise, under one chunk of the 17 columns (8.9 MB). Before, HDF5's
    cache kept each chunk written: 12 chunks × 17 columns × 0.5 MB ≈ 107 MB."""
    out = subprocess.run(
        [sys.executable, "-c", SCRIPT, str(tmp_path / "t.h5"), "8", "20"],
        capture_output=True,
        text=True,
        check=True,
    )
    first, last = (float(x) for x in out.stdout.split())
    one_chunk = stream.BLOCK_ROWS * 17 * 8 / 2**20
    assert last - first < one_chunk, (first, last, one_chunk)
    assert len(PhysicalTrace.load(tmp_path / "t.h5")) == 20 * stream.BLOCK_ROWS
