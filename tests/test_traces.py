"""Trace formats: exact round trips, streaming, atomic writes, and the bad-file corpus."""

from __future__ import annotations

import os
import re
import tracemalloc
from pathlib import Path

import numpy as np
import pytest

from conftest import ROOT, run_cli
from sins_fw import tablefile, traces
from sins_fw.errors import TraceError
from sins_fw.traces import PhysicalTrace, RawRegisterTrace

BAD = ROOT / "tests" / "data" / "bad"


def _corpus() -> list[tuple[str, str]]:
    rows = re.findall(r"^\| (\S+\.(?:csv|h5)) \| (.+) \|$", (BAD / "README.md").read_text(), flags=re.M)
    return [(name, fragment.replace("\\|", "|")) for name, fragment in rows]


def _full_trace(n: int = 1000, rate: str = "819.2") -> PhysicalTrace:
    rng = np.random.default_rng(7)
    t = np.arange(n) * 5 / 4096
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    q[[1, n // 2, n // 2 + 1]] = np.nan  # missing truth rows
    return PhysicalTrace(
        t_s=t,
        gyro_dps=rng.normal(scale=300, size=(n, 3)),
        accel_g=rng.normal(size=(n, 3)) * np.array([1e-300, 1.0, 1e300]),  # extremes of float64
        mag_gauss=rng.normal(size=(n, 3)),
        baro_mbar=rng.uniform(900, 1100, n),
        temp_c=rng.normal(25, 5, n),
        truth_q=q,
        moving=rng.uniform(size=n) > 0.5,
        metadata={"sample_rate_hz": rate, "source": "unit test", "note": "ünïcode ✓ kept"},
    )


def _assert_same(a: PhysicalTrace, b: PhysicalTrace) -> None:
    for name, col in a.columns().items():
        np.testing.assert_array_equal(b.columns()[name], col, err_msg=name, strict=True)
    assert {k: v for k, v in b.metadata.items() if k != "format"} == a.metadata
    assert b.metadata["format"] == traces.PHYSICAL_FORMAT


@pytest.mark.parametrize("ext", ["csv", "h5"])
def test_physical_round_trip_is_bit_exact(tmp_path, ext):
    trace = _full_trace()
    path = tmp_path / f"t.{ext}"
    trace.save(path)
    loaded = PhysicalTrace.load(path)
    _assert_same(trace, loaded)
    assert loaded.moving.dtype == bool and np.isnan(loaded.truth_q[500]).all()


@pytest.mark.parametrize("ext", ["csv", "h5"])
def test_minimal_physical_trace_round_trips_without_optional_columns(tmp_path, ext):
    t = np.arange(5) / 100.0
    trace = PhysicalTrace(
        t, np.zeros((5, 3)), np.tile([0.0, 0.0, 1.0], (5, 1)), metadata={"sample_rate_hz": "100"}
    )
    trace.save(tmp_path / f"m.{ext}")
    loaded = PhysicalTrace.load(tmp_path / f"m.{ext}")
    assert loaded.truth_q is None and loaded.mag_gauss is None and loaded.moving is None
    _assert_same(trace, loaded)


@pytest.mark.parametrize("ext", ["csv", "h5"])
def test_raw_register_round_trip(tmp_path, ext):
    rng = np.random.default_rng(3)
    words = rng.integers(0, 0x10000, size=(50, 15)).astype(np.uint16)
    words[0] = [0xFFFF, 0xC7A7, 0x1770, 0x2890, 0x0001, 0x3FFF, 0x1519, 0x2AE7, 0, 0, 0, 0, 0, 0, 0]
    raw = RawRegisterTrace(np.arange(50) * 0.004, words, {"sample_rate_hz": "250"})
    raw.save(tmp_path / f"r.{ext}")
    loaded = RawRegisterTrace.load(tmp_path / f"r.{ext}")
    np.testing.assert_array_equal(loaded.words, words, strict=True)
    np.testing.assert_array_equal(loaded.t_s, raw.t_s, strict=True)
    if ext == "csv":
        assert (
            "0.0,0xFFFF,0xC7A7,0x1770,0x2890,0x0001,0x3FFF,0x1519,0x2AE7," in (tmp_path / "r.csv").read_text()
        )


def test_raw_hex_words_accept_case_and_missing_prefix(tmp_path):
    header = "t_s," + ",".join(traces.RAW_WORD_COLUMNS)
    row = "0.0,ffff,0xc7a7,0X1770,7," + ",".join(["0"] * 11)
    path = tmp_path / "r.csv"
    path.write_text(f"# sample_rate_hz: 250\n{header}\n{row}\n")
    words = RawRegisterTrace.load(path).words[0]
    assert words[:5].tolist() == [0xFFFF, 0xC7A7, 0x1770, 0x0007, 0]


def test_iter_chunks_streams_in_bounded_pieces_and_checks_across_boundaries(tmp_path):
    trace = _full_trace(n=103)
    for ext in ("csv", "h5"):
        trace.save(tmp_path / f"c.{ext}")
        chunks = list(traces.iter_chunks(tmp_path / f"c.{ext}", 10))
        assert [len(c) for c in chunks] == [10] * 10 + [3]
        np.testing.assert_array_equal(np.concatenate([c.t_s for c in chunks]), trace.t_s)
    # A time step backwards exactly at a chunk boundary (row 10) is found, with its line.
    trace.t_s[10] = trace.t_s[9]
    cols = trace.columns()
    text = (tmp_path / "c.csv").read_text().splitlines()
    header_line = next(i for i, line in enumerate(text) if line.startswith("t_s,")) + 1
    text[header_line + 10] = (
        repr(float(cols["t_s"][9])) + text[header_line + 10][text[header_line + 10].index(",") :]
    )
    (tmp_path / "b.csv").write_text("\n".join(text) + "\n")
    with pytest.raises(TraceError, match=rf"line {header_line + 11} \(row 10\), column `t_s`"):
        list(traces.iter_chunks(tmp_path / "b.csv", 10))


def test_streaming_memory_does_not_grow_with_length(tmp_path):
    def peak(n: int) -> int:
        t = np.arange(n) / 100.0
        PhysicalTrace(t, np.ones((n, 3)), np.ones((n, 3)), metadata={"sample_rate_hz": "100"}).save(
            tmp_path / "s.csv"
        )
        tracemalloc.start()
        rows = sum(len(c) for c in traces.iter_chunks(tmp_path / "s.csv", 1000))
        _, top = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        assert rows == n
        return top

    small, large = peak(20_000), peak(80_000)
    # Four times the rows: the peak is set by the 1000-row chunk, not the file (a whole-file read
    # would need > 4 × 80 000 × 7 × 8 bytes ≈ 18 MB).
    assert large < 1.25 * small, (small, large)


def test_gaps_are_an_error_unless_allowed(tmp_path):
    with pytest.raises(TraceError, match=r"gap of 0\.04 s"):
        PhysicalTrace.load(BAD / "time_gap.csv")
    assert len(PhysicalTrace.load(BAD / "time_gap.csv", allow_gaps=True)) == 3
    assert len(PhysicalTrace.load(BAD / "time_gap.csv", max_gap_periods=5.0)) == 3


def test_complete_last_row_without_newline_is_accepted(tmp_path):
    path = tmp_path / "n.csv"
    header = "t_s,gyro_x_dps,gyro_y_dps,gyro_z_dps,accel_x_g,accel_y_g,accel_z_g"
    path.write_text(f"# sample_rate_hz: 100\n{header}\n0,0,0,0,0,0,1")
    assert len(PhysicalTrace.load(path)) == 1


def test_in_memory_validation_names_the_field():
    with pytest.raises(
        TraceError, match=r"PhysicalTrace.gyro_dps: expected shape \(3, 3\).*got shape \(3, 2\)"
    ):
        PhysicalTrace(
            np.arange(3.0), np.zeros((3, 2)), np.zeros((3, 3)), metadata={"sample_rate_hz": "1"}
        ).validate()
    with pytest.raises(TraceError, match="`sample_rate_hz` is missing"):
        PhysicalTrace(np.arange(3.0), np.zeros((3, 3)), np.zeros((3, 3))).validate()
    with pytest.raises(TraceError, match=r"row 1, column `gyro_x_dps`: found inf"):
        g = np.zeros((3, 3))
        g[1, 0] = np.inf
        PhysicalTrace(np.arange(3.0), g, np.zeros((3, 3)), metadata={"sample_rate_hz": "1"}).validate()


def test_save_is_atomic(tmp_path, monkeypatch):
    path = tmp_path / "a.csv"
    path.write_text("previous content")
    trace = _full_trace(n=10)

    def explode(*_args, **_kwargs):
        raise RuntimeError("disk full")

    monkeypatch.setattr(tablefile, "_format_column", explode)
    with pytest.raises(RuntimeError):
        trace.save(path)
    assert path.read_text() == "previous content"  # the old file is untouched
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.csv"]  # no temporary file left behind
    monkeypatch.undo()
    trace.save(path)
    assert oct(path.stat().st_mode & 0o777) == oct(0o666 & ~_umask())


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def test_unknown_extension_is_explained(tmp_path):
    with pytest.raises(TraceError, match=r"unknown trace extension `\.txt`; expected \.csv or \.h5"):
        _full_trace(n=5).save(tmp_path / "x.txt")


CORPUS = _corpus()


def test_corpus_table_covers_every_file():
    files = sorted(p.name for p in BAD.iterdir() if p.suffix in (".csv", ".h5"))
    assert sorted(name for name, _ in CORPUS) == files
    assert len(files) >= 30


@pytest.mark.parametrize(("name", "fragment"), CORPUS, ids=[c[0] for c in CORPUS])
def test_bad_file_gives_its_message(name, fragment):
    kind = RawRegisterTrace if name.startswith("raw_") else PhysicalTrace
    with pytest.raises(TraceError) as info:
        kind.load(BAD / name)
    message = str(info.value)
    assert message.startswith(str(BAD / name) + ":"), message
    assert fragment in message, message


@pytest.mark.parametrize(("name", "fragment"), CORPUS, ids=[c[0] for c in CORPUS])
def test_bad_file_through_the_cli(tmp_path, name, fragment):
    out = tmp_path / "out.h5"
    r = run_cli("import", "trace", str(BAD / name), "--out", str(out))
    assert r.code == 2, (r.out, r.err)
    assert "Traceback" not in r.err
    assert fragment in r.err and name in r.err, r.err
    assert list(tmp_path.iterdir()) == []  # nothing written, not even a temporary file


def test_cli_converts_between_forms(tmp_path):
    trace = _full_trace(n=200)
    trace.save(tmp_path / "a.csv")
    assert run_cli("import", "trace", str(tmp_path / "a.csv"), "--out", str(tmp_path / "b.h5")).code == 0
    r = run_cli("import", "trace", str(tmp_path / "b.h5"), "--out", str(tmp_path / "c.csv"), "--json")
    assert r.code == 0, r.err
    assert '"rows": 200' in r.out
    assert (tmp_path / "a.csv").read_bytes() == (tmp_path / "c.csv").read_bytes()


def test_cli_rejects_a_bad_output_extension_before_work(tmp_path):
    r = run_cli("synth", "static", "--out", str(tmp_path / "x.dat"))
    assert r.code == 2 and "unknown trace extension `.dat`" in r.err and "Traceback" not in r.err


def test_bad_corpus_is_reproducible(tmp_path):
    # The committed corpus is what make_corpus.py writes (text files compared byte for byte).
    import importlib.util

    spec = importlib.util.spec_from_file_location("make_corpus", BAD / "make_corpus.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.HERE = tmp_path
    module.main()
    for p in BAD.glob("*.csv"):
        if p.name != "h5_named_csv.csv":
            assert (tmp_path / p.name).read_bytes() == p.read_bytes(), p.name


def test_path_objects_and_strings_both_work(tmp_path):
    trace = _full_trace(n=5)
    trace.save(str(tmp_path / "s.h5"))
    assert len(PhysicalTrace.load(Path(tmp_path / "s.h5"))) == 5


def _h5_by_hand(path: Path, cols: dict[str, np.ndarray], attrs: dict[str, str]) -> None:
    """A trace file written without `save` (which would refuse it): what another tool could write."""
    import h5py

    with h5py.File(path, "w") as f:
        for k, v in attrs.items():
            f.attrs[k] = v
        for name, arr in cols.items():
            f.create_dataset(name, data=arr)


def _bad_in_memory(case: str) -> PhysicalTrace:
    n = 200
    t = np.arange(n) / 100.0
    q = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    meta = {"sample_rate_hz": "100"}
    if case == "truth norm 2":
        q[57] = [2.0, 0.0, 0.0, 0.0]
    elif case == "no sample rate":
        meta = {}
    elif case == "gap":
        t[120:] += 0.5
    elif case == "time backwards":
        t[90] = t[88]
    elif case == "inf gyro":
        pass
    gyro = np.zeros((n, 3))
    if case == "inf gyro":
        gyro[33, 1] = np.inf
    return PhysicalTrace(t, gyro, np.tile([0.0, 0.0, 1.0], (n, 1)), truth_q=q, metadata=meta)


def _message_body(text: str) -> str:
    """The message without the source's name (a file path, or `<physical trace in memory>`) and
    the metadata's location (`metadata (file attributes)` in a file, `metadata` in memory)."""
    return re.sub(r"^.*?: (metadata[^:]*: )?", "", str(text))


def test_a_file_without_a_rate_takes_the_times_rate_while_memory_needs_one(tmp_path):
    """A file from another tool often has no metadata: its times give the rate (issue 27, item 1). A
    trace built in code states its rate (`sample_rate_hz` missing is refused there)."""
    trace = _bad_in_memory("no sample rate")
    path = tmp_path / "bad.h5"
    _h5_by_hand(path, trace.columns(), trace.metadata)
    assert PhysicalTrace.load(path).metadata["sample_rate_hz"] == "100"
    with pytest.raises(TraceError, match="`sample_rate_hz` is missing"):
        trace.validate()


@pytest.mark.parametrize("case", ["truth norm 2", "gap", "time backwards", "inf gyro"])
def test_in_memory_traces_are_refused_like_files(tmp_path, case):
    """The file loaders and emulate() on a trace in memory (whole or in chunks) go through the same
    checks and refuse the same data with the same message (issue 24, item 5: emulate() accepted a
    truth of norm 2, a trace without a sample rate, and gaps)."""
    from sins_fw.harness import emulate

    trace = _bad_in_memory(case)
    path = tmp_path / "bad.h5"
    _h5_by_hand(path, trace.columns(), trace.metadata)
    with pytest.raises(TraceError) as from_file:
        emulate(path)
    with pytest.raises(TraceError) as loaded:
        PhysicalTrace.load(path)
    with pytest.raises(TraceError) as in_memory:
        emulate(trace)
    # Consecutive chunks (a generator) are checked across their boundaries too.
    halves = (
        PhysicalTrace.from_columns({k: v[s] for k, v in trace.columns().items()}, trace.metadata)
        for s in (slice(0, 100), slice(100, None))
    )
    with pytest.raises(TraceError) as chunked:
        emulate(halves, chunk_rows=64)
    with pytest.raises(TraceError) as validated:
        trace.validate()
    assert str(from_file.value).startswith(str(path))
    assert str(in_memory.value).startswith("<physical trace in memory>")
    body = _message_body(from_file.value)
    assert body and body != str(from_file.value)
    for other in (loaded, in_memory, chunked, validated):
        assert _message_body(other.value) == body


def test_gaps_in_memory_are_accepted_when_allowed():
    from sins_fw.harness import emulate

    run = emulate(_bad_in_memory("gap"), allow_gaps=True)
    assert run.cycles > 0
