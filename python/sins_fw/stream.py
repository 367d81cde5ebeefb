"""Streamed trace and run-output files: rows written block by block, so that memory is bounded by a
block whatever the length (issue 24, item 11).

:class:`TableWriter` writes the formats of :mod:`sins_fw.traces` (a physical or raw-register trace,
a run output) from consecutive column blocks, validated as they pass exactly as
:meth:`~sins_fw.traces.PhysicalTrace.save` validates a whole trace, atomically (a temporary file
beside the destination, renamed when complete: :mod:`sins_fw.atomic`).

Bytes: a CSV file is the same bytes as the whole-array writer wrote (each line depends on its row
only). An HDF5 file of at most :data:`WHOLE_ROWS` rows is written by the whole-array writer once
the stream has ended, so it too is the same bytes (every bundled trace and test file). A longer
HDF5 file has the same datasets, values, dtypes, chunk size, filters and attributes, resizable, but
its chunks lie interleaved in the file (each block writes one chunk of every column) where the
whole-array writer wrote one column after the other: HDF5 places a dataset's chunk index before
its chunks only when the whole column is written by one call, which a stream cannot do. Its bytes
therefore differ from that writer's; the same rows still give the same bytes.

Memory of a streamed HDF5 file: HDF5's chunk cache (8 MiB per dataset in HDF5 2.0, an entry per
chunk, uncompressed) kept the chunks written until it had to make room, so the process held up to
8 MiB per column (16 chunks of doubles): a 41-column gyro-free vehicle trace of 900 s peaked at
440 MB. The rows now go to a scratch HDF5 file beside the output with no cache (each chunk
compressed and written as it comes), and the output receives the same dataset creations,
extensions and first writes as before, and each compressed chunk copied over as it is
(``read_direct_chunk`` / ``write_direct_chunk``) at the moment HDF5's cache would have written it
(:class:`_CacheModel`: its hash slots, its byte limit, least recently used first, and the rest,
column by column, at the end): the same bytes as before, with a chunk of every column held at most.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import IO, Any

import h5py
import numpy as np

from sins_fw.atomic import atomic_path, kept_error_file, temporary_file
from sins_fw.errors import TraceError
from sins_fw.tablefile import (
    BLOCK_ROWS,
    DEFAULT_MAX_GAP_PERIODS,
    Checker,
    PathLike,
    Schema,
    check_metadata,
    csv_header,
    csv_lines,
    h5_create,
    parse_rate,
    table_extension,
    write_h5,
)
from sins_fw.traces import _TraceFile

#: Rows held before an HDF5 file is streamed: up to five chunks (6.7 min at 819.2 SPS, ≈ 45 MB for
#: the 17 columns of a physical trace) are written whole, with the whole-array writer's bytes.
WHOLE_ROWS = 5 * BLOCK_ROWS
#: …and at most these bytes of columns (the 17 columns of a physical trace over WHOLE_ROWS rows): a
#: wider table (the gyro-free vehicle's 41 columns) is held for fewer rows, so that what is held does
#: not grow with the width (a 41-column trace held 327 680 rows, ≈ 107 MB and its copies).
WHOLE_BYTES = WHOLE_ROWS * 17 * 8


class _CacheModel:
    """When HDF5's chunk cache writes a dataset's chunks (H5Dchunk.c) for writes that each fill one
    new chunk, in row order: a new chunk takes slot ``index % nslots``, writing out the chunk that
    held it; then, while the cached chunks and the new one exceed ``nbytes``, the least recently
    used is written out; at close the rest, oldest first. Only chunk indices are kept."""

    def __init__(self, nslots: int, nbytes: int, chunk_bytes: int) -> None:
        self.nslots, self.nbytes, self.chunk_bytes = nslots, nbytes, chunk_bytes
        self.entries: dict[int, None] = {}  # insertion order: least recently used first
        self.slots: dict[int, int] = {}

    def add(self, index: int) -> list[int]:
        """Chunk ``index`` written: the chunks written out to make room, in order."""
        if index in self.entries or self.chunk_bytes > self.nbytes:
            return []  # already cached (not met here), or too large to be cached: written through
        out: list[int] = []
        slot = index % self.nslots
        held = self.slots.get(slot)
        if held is not None:
            out.append(held)
            self._drop(held)
        while self.entries and (len(self.entries) + 1) * self.chunk_bytes > self.nbytes:
            first = next(iter(self.entries))
            out.append(first)
            self._drop(first)
        self.entries[index] = None
        self.slots[slot] = index
        return out

    def rest(self) -> list[int]:
        """At close: every chunk still cached, oldest first."""
        out = list(self.entries)
        self.entries.clear()
        self.slots.clear()
        return out

    def _drop(self, index: int) -> None:
        del self.entries[index]
        del self.slots[index % self.nslots]


class TableWriter:
    """Write a table file (``.csv`` or ``.h5``) from consecutive blocks of named columns.

    Use as a context manager: ``with TableWriter(path, schema, metadata) as w: w.write(cols)``. The
    file appears at ``path`` only when the block ends without an exception (else ``path`` is left as
    it was). The first block fixes the columns; every block is checked like a file's rows on load
    (finite values, flags, truth norms, increasing time, gaps unless ``allow_gaps``). An HDF5 file
    is held whole up to ``whole_rows`` rows (default :data:`WHOLE_ROWS`; the whole-array writer's
    bytes), streamed past that.
    """

    def __init__(
        self,
        path: PathLike,
        schema: Schema,
        metadata: Mapping[str, str],
        *,
        allow_gaps: bool = False,
        max_gap_periods: float = DEFAULT_MAX_GAP_PERIODS,
        whole_rows: int | None = None,
    ) -> None:
        self.path = Path(path)
        self._whole_rows = whole_rows  # None: by the width of the first block (WHOLE_ROWS, WHOLE_BYTES)
        self.schema = schema
        self._ext = table_extension(self.path)
        self.metadata = {"format": schema.format, **{k: v for k, v in metadata.items() if k != "format"}}
        rate = check_metadata(self.metadata, schema, f"{self.path}: metadata")
        src = f"<{schema.title} written to {self.path}>"
        self._checker = Checker(
            schema,
            src,
            float(1 / rate),
            allow_gaps,
            max_gap_periods,
            lambda r: f"row {r}",
            metadata=self.metadata,
        )
        self.rows = 0
        self._names: list[str] | None = None
        self._pending: list[dict[str, np.ndarray]] = []  # HDF5: rows not yet a whole chunk
        self._pending_rows = 0
        self._stack = contextlib.ExitStack()
        self._tmp: Path | None = None
        self._csv: IO[str] | None = None
        self._h5: h5py.File | None = None
        self._datasets: dict[str, Any] = {}
        # A streamed HDF5 file's rows, compressed, until they are copied into the output (see above).
        self._scratch: h5py.File | None = None
        self._scratch_sets: dict[str, Any] = {}
        self._caches: dict[str, _CacheModel] = {}

    def __enter__(self) -> TableWriter:
        self._tmp = self._stack.enter_context(atomic_path(self.path))
        return self

    def __exit__(
        self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        try:
            if kind is None:
                self._finish()
            # Closing flushes the last buffered rows: on a full disk this is where the write fails.
            self._close_files()
        except BaseException as e:
            with contextlib.suppress(OSError):
                self._close_files()  # a second failed flush: the temporary file is removed anyway
            self._stack.__exit__(type(e), e, e.__traceback__)
            raise
        self._stack.__exit__(kind, exc, tb)

    def write(self, cols: Mapping[str, np.ndarray]) -> None:
        """Append a block of rows (every column the same length; the first block's columns)."""
        block = {n: np.asarray(a) for n, a in cols.items()}
        if self._names is None:
            self.schema.check_header(list(block), f"{self.path}")
            self._names = self.schema.order(list(block))
        if self._whole_rows is None:
            self._whole_rows = min(WHOLE_ROWS, WHOLE_BYTES // (8 * max(1, len(self._names))))
        if set(block) != set(self._names):
            raise TraceError(f"{self.path}: a block has columns {sorted(block)}; expected {self._names}")
        lengths = {len(a) for a in block.values()}
        if len(lengths) != 1:
            raise TraceError(f"{self.path}: columns of one block have different lengths")
        n = lengths.pop()
        if n == 0:
            return
        block = {name: block[name] for name in self._names}
        self._checker.check(block)
        self.rows += n
        if self._ext == ".csv":
            self._write_csv(block)
            return
        self._pending.append(block)
        self._pending_rows += n
        if self._h5 is None and self._pending_rows <= (self._whole_rows or 0):
            return
        while self._pending_rows >= BLOCK_ROWS:
            self._flush_chunk(BLOCK_ROWS)

    # CSV ------------------------------------------------------------------------------------------

    def _write_csv(self, block: dict[str, np.ndarray]) -> None:
        if self._csv is None:
            assert self._tmp is not None and self._names is not None
            self._csv = self._tmp.open("w", encoding="utf-8", newline="\n")
            self._csv.write(csv_header(self.schema, self.metadata, self._names))
        self._csv.write(csv_lines(self.schema, block))

    # HDF5 -----------------------------------------------------------------------------------------

    def _take(self, rows: int) -> dict[str, np.ndarray]:
        """The first ``rows`` pending rows, as one block (the rest stays pending)."""
        assert self._names is not None
        first = self._names[0]
        taken: list[dict[str, np.ndarray]] = []
        need = rows
        while need:  # only the blocks the rows are in are joined (not every pending row)
            block = self._pending[0]
            n = len(block[first])
            if n <= need:
                taken.append(self._pending.pop(0))
                need -= n
            else:
                taken.append({k: a[:need] for k, a in block.items()})
                self._pending[0] = {k: a[need:] for k, a in block.items()}
                need = 0
        self._pending_rows -= rows
        if len(taken) == 1:
            return taken[0]
        return {n: np.concatenate([b[n] for b in taken]) for n in self._names}

    def _flush_chunk(self, rows: int) -> None:
        """Write one chunk of every column (resizable datasets of the whole-array writer's chunking)."""
        block = self._take(rows)
        if self._h5 is None:
            assert self._tmp is not None
            # Through a file that keeps a failed write (a full disk) until h5py has closed cleanly.
            tmp_file = self._stack.enter_context(kept_error_file(self._tmp))
            self._h5 = h5py.File(tmp_file, "w", libver=("earliest", "v110"), track_order=True)
            for k, v in self.metadata.items():
                self._h5.attrs[k] = v
            for name, arr in block.items():
                self._datasets[name] = h5_create(self._h5, self.schema.column(name), arr[:0], BLOCK_ROWS)
            folder = self._tmp.parent
            scratch = temporary_file(self.path, folder)
            self._stack.callback(scratch.unlink, missing_ok=True)
            scratch_tmp = self._stack.enter_context(kept_error_file(scratch))  # removed when the writer ends
            self._scratch = h5py.File(scratch_tmp, "w", rdcc_nbytes=0)  # no cache: written as it comes
            for name, arr in block.items():
                column = self.schema.column(name)
                self._scratch_sets[name] = h5_create(self._scratch, column, arr[:0], BLOCK_ROWS)
                ds = self._datasets[name]
                nslots, nbytes, _ = ds.id.get_access_plist().get_chunk_cache()
                self._caches[name] = _CacheModel(nslots, nbytes, BLOCK_ROWS * ds.dtype.itemsize)
        start = self.rows - self._pending_rows - rows
        for name, arr in block.items():
            ds = self._datasets[name]
            ds.resize((start + rows,))
            if start == 0:
                # The output's first write creates the column's chunk index where it always was;
                # HDF5 caches this one chunk until its copy replaces it.
                ds[0:1] = arr[:1]
            kept = self._scratch_sets[name]
            self._copy_chunks(name, self._caches[name].add(start // BLOCK_ROWS))
            kept.resize((start + rows,))
            kept[start : start + rows] = arr

    def _finish(self) -> None:
        if self._names is None or self.rows == 0:
            raise TraceError(f"{self.path}: no data rows to write")
        if self._ext == ".csv":
            return
        if self._h5 is None:  # short: the whole-array writer, the same bytes as ever
            assert self._tmp is not None
            write_h5(self._tmp, self.schema, self.metadata, self._take(self._pending_rows), atomic=False)
            return
        if self._pending_rows:
            self._flush_chunk(self._pending_rows)
        assert self._names is not None
        for name in self._names:  # at close HDF5 wrote each column's cached chunks in turn
            self._copy_chunks(name, self._caches[name].rest())

    def _copy_chunks(self, name: str, chunks: list[int]) -> None:
        """Chunks of column ``name`` from the scratch file into the output, compressed as they
        are, one at a time."""
        src, dst = self._scratch_sets[name].id, self._datasets[name].id
        for index in chunks:
            offset = (index * BLOCK_ROWS,)
            mask, data = src.read_direct_chunk(offset)
            dst.write_direct_chunk(offset, data, mask)

    def _close_files(self) -> None:
        csv, self._csv = self._csv, None
        h5, self._h5 = self._h5, None
        scratch, self._scratch = self._scratch, None
        try:
            if csv is not None:
                csv.close()  # closed even when its last flush fails
        finally:
            try:
                if h5 is not None:
                    h5.close()
            finally:
                if scratch is not None:
                    scratch.close()


@dataclass
class Written:
    """What :func:`save_chunks` wrote: the rows, the first chunk's metadata, the first and last time."""

    rows: int
    metadata: dict[str, str]
    t_first: float
    t_last: float

    @property
    def duration_s(self) -> float:
        """Last minus first time plus one nominal period (as ``PhysicalTrace.duration_s``)."""
        return self.t_last - self.t_first + float(1 / parse_rate(self.metadata["sample_rate_hz"]))


def save_chunks(path: PathLike, chunks: Iterable[_TraceFile], *, allow_gaps: bool = False) -> Written:
    """Write consecutive chunks of a trace (PhysicalTrace or RawRegisterTrace) to ``path`` as
    ``save`` writes the whole trace, one chunk in memory at a time; the metadata is the first chunk's."""
    writer: TableWriter | None = None
    t_first = t_last = 0.0
    with contextlib.ExitStack() as stack:
        for chunk in chunks:
            if writer is None:
                writer = stack.enter_context(
                    TableWriter(path, chunk.schema, chunk.metadata, allow_gaps=allow_gaps)
                )
                t_first = float(chunk.t_s[0]) if len(chunk.t_s) else 0.0
            writer.write(chunk.columns())
            if len(chunk.t_s):
                t_last = float(chunk.t_s[-1])
        if writer is None:
            raise TraceError(f"{path}: no data rows to write")
    return Written(writer.rows, writer.metadata, t_first, t_last)


def write_blocks(
    path: PathLike,
    schema: Schema,
    metadata: Mapping[str, str],
    blocks: Iterator[Mapping[str, np.ndarray]],
    *,
    allow_gaps: bool = False,
) -> int:
    """Write every block of ``blocks`` to ``path`` (see :class:`TableWriter`); returns the row count."""
    with TableWriter(path, schema, metadata, allow_gaps=allow_gaps) as w:
        for block in blocks:
            w.write(block)
    return w.rows
