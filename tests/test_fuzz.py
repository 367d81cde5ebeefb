"""Property tests (hypothesis): random bytes and random mutations of a valid CSV never make the trace
loaders raise anything but TraceError, and what they accept is finite with increasing time; random
`--set key=value` overrides never make the CLI print a traceback or panic (exit 0, or 2 with one
message). Example counts are fixed so the whole file stays within its share of `make test`."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sins_fw import _core, synth
from sins_fw.cli import main
from sins_fw.errors import TraceError
from sins_fw.traces import PHYSICAL_SCHEMA, RAW_SCHEMA, PhysicalTrace, RawRegisterTrace


def fuzz(examples: int) -> settings:
    """Fixed example counts (bounded time), no deadline (a first call may import or build a lot)."""
    return settings(
        max_examples=examples,
        deadline=None,
        suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
    )


_DIR = Path(tempfile.mkdtemp(prefix="sins-fw-fuzz-"))


def _valid_csv() -> bytes:
    t = np.arange(12) / 100.0
    trace = PhysicalTrace(
        t,
        np.column_stack([np.sin(t), np.cos(t), t]),
        np.tile([0.0, 0.01, 1.0], (len(t), 1)),
        truth_q=np.tile([1.0, 0.0, 0.0, 0.0], (len(t), 1)),
        moving=np.zeros(len(t), dtype=bool),
        metadata={"sample_rate_hz": "100"},
    )
    path = _DIR / "valid.csv"
    trace.save(path)
    return path.read_bytes()


VALID = _valid_csv()
HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


def _load_checked(kind: type, path: Path) -> None:
    """Load; a TraceError is a fine answer, anything else fails. What loads must be sound."""
    try:
        trace = kind.load(path)
    except TraceError as e:
        assert str(e).startswith(str(path)), str(e)
        return
    schema = PHYSICAL_SCHEMA if kind is PhysicalTrace else RAW_SCHEMA
    cols = trace.columns()
    assert np.all(np.diff(cols["t_s"]) > 0)
    for name, arr in cols.items():
        c = schema.column(name)
        if c.kind == "float" and not c.nan_allowed:
            assert np.isfinite(arr).all(), name


@fuzz(150)
@given(data=st.binary(max_size=600), ext=st.sampled_from([".csv", ".h5"]), h5_head=st.booleans())
def test_random_bytes_are_a_trace_error_or_a_sound_trace(data, ext, h5_head):
    path = _DIR / f"random{ext}"
    path.write_bytes((HDF5_SIGNATURE if h5_head else b"") + data)
    for kind in (PhysicalTrace, RawRegisterTrace):
        _load_checked(kind, path)


# Mutations of a valid CSV: each edit is (kind, position, text).
TOKENS = st.sampled_from(
    [
        "0",
        "-1",
        "1e308",
        "1e400",
        "-1e400",
        "nan",
        "inf",
        "0x1F",
        ",",
        ",,",
        "\n",
        "\r\n",
        "#",
        " ",
        "",
        "é",
        "\x00",
    ]
)
EDIT = st.tuples(
    st.sampled_from(["insert", "delete", "replace", "duplicate_line", "drop_line", "swap_lines", "truncate"]),
    st.floats(0, 1),
    st.one_of(TOKENS, st.text(alphabet="0123456789.,-+eE#nafi \n", max_size=8)),
)


def _mutate(data: bytes, edits: list[tuple[str, float, str]]) -> bytes:
    for kind, where, text in edits:
        lines = data.split(b"\n")
        i = int(where * len(data))
        k = int(where * max(len(lines) - 1, 1))
        if kind == "insert":
            data = data[:i] + text.encode() + data[i:]
        elif kind == "delete":
            data = data[:i] + data[i + 1 + len(text) :]
        elif kind == "replace":
            data = data[:i] + text.encode() + data[i + max(len(text), 1) :]
        elif kind == "duplicate_line":
            data = b"\n".join([*lines[: k + 1], lines[k], *lines[k + 1 :]])
        elif kind == "drop_line":
            data = b"\n".join(lines[:k] + lines[k + 1 :])
        elif kind == "swap_lines" and k + 1 < len(lines):
            lines[k], lines[k + 1] = lines[k + 1], lines[k]
            data = b"\n".join(lines)
        elif kind == "truncate":
            data = data[:i]
    return data


@fuzz(250)
@given(edits=st.lists(EDIT, min_size=1, max_size=4))
def test_mutated_csv_is_a_trace_error_or_a_sound_trace(edits):
    path = _DIR / "mutated.csv"
    path.write_bytes(_mutate(VALID, edits))
    _load_checked(PhysicalTrace, path)


# Overrides: known keys (and near misses) with values of every TOML type, sane and absurd.
KEYS = _core.profile_keys()
KEY = st.one_of(
    st.sampled_from(KEYS),
    st.sampled_from(KEYS).map(lambda k: k[:-1]),
    st.text(alphabet="abcdefghijklmnopqrstuvwxyz._=", min_size=0, max_size=12),
)
VALUE = st.one_of(
    st.integers(-(2**70), 2**70).map(str),
    st.integers(0, 0xFFFF).map(hex),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.sampled_from(
        ["true", "false", '"rk4"', "level", "bit", "[0, 0]", "[1.0, 2.0, 3.0]", "{a = 1}", "", "="]
    ),
    st.text(max_size=10),
)


def _check_cli(capsys, *args: str) -> None:
    try:
        code = main(list(args))
    except SystemExit as e:  # argparse's usage errors exit from inside the parser
        code = e.code
    _, err = capsys.readouterr()
    assert "Traceback" not in err and "panicked" not in err, err
    # 1: a check failed (an error-severity event, a broken rule), said in one line after the summary.
    assert code in (0, 1, 2), (code, args, err)
    if code == 1:
        assert err.startswith("sins-fw: check failed: "), err
    if code == 2:
        assert err.startswith("sins-fw: error: ") or "usage:" in err, err


@fuzz(300)
@given(pairs=st.lists(st.tuples(KEY, VALUE), min_size=1, max_size=3))
def test_random_overrides_never_crash_board(capsys, pairs):
    sets = [a for k, v in pairs for a in ("--set", f"{k}={v}")]
    _check_cli(capsys, "board", *sets)


@pytest.fixture(scope="module")
def tiny_trace() -> Path:
    path = _DIR / "tiny.h5"
    synth.generate("static", duration_s=0.3).save(path)
    return path


@pytest.mark.filterwarnings("error::RuntimeWarning")  # a NaN or overflow in the summary: a silent NaN
@fuzz(60)
@given(pairs=st.lists(st.tuples(st.sampled_from(KEYS), VALUE), min_size=1, max_size=2))
def test_random_overrides_never_crash_run(capsys, tiny_trace, pairs):
    sets = [a for k, v in pairs for a in ("--set", f"{k}={v}")]
    _check_cli(capsys, "run", str(tiny_trace), "--json", *sets)


# HDF5 containers that are well-formed files with random content: names, shapes, types, values, metadata.
COLUMN_NAMES = st.sampled_from([*PHYSICAL_SCHEMA.names(), *RAW_SCHEMA.names(), "t_ms", "gyro_x_rads", "foo"])
DTYPES = st.sampled_from(["f8", "f4", "i8", "u1", "u2", "i2", "c8", "S4", "b1"])
H5_VALUES = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True), st.integers(-(2**31), 2**31), st.sampled_from([0.0, 1.0])
)


@st.composite
def h5_content(draw):
    n = draw(st.integers(0, 6))
    columns = {}
    for name in draw(st.lists(COLUMN_NAMES, min_size=0, max_size=9, unique=True)):
        dtype = draw(DTYPES)
        rows = draw(st.sampled_from([n, n, n, max(n - 1, 0), n + 1]))
        shape = draw(st.sampled_from([(rows,), (rows,), (rows, 2)]))
        values = draw(st.lists(H5_VALUES, min_size=int(np.prod(shape)), max_size=int(np.prod(shape))))
        with np.errstate(all="ignore"):
            columns[name] = np.array(values, dtype="f8").reshape(shape).astype(dtype)
    if "t_s" in columns and columns["t_s"].dtype.kind == "f" and draw(st.booleans()):
        columns["t_s"] = np.arange(len(columns["t_s"])) / 100.0  # often a sound time column
    rate = draw(st.sampled_from(["100", "0", "-1", "fast", "1e400", "2000/7", ""]))
    fmt = draw(st.sampled_from([None, "sins-fw-physical-trace/1", "sins-fw-raw-register-trace/1", "x"]))
    return columns, rate, fmt


@fuzz(120)
@given(content=h5_content())
def test_random_hdf5_content_is_a_trace_error_or_a_sound_trace(content):
    import h5py

    columns, rate, fmt = content
    path = _DIR / "random_content.h5"
    with h5py.File(path, "w") as f:
        if rate:
            f.attrs["sample_rate_hz"] = rate
        if fmt is not None:
            f.attrs["format"] = fmt
        for name, arr in columns.items():
            f.create_dataset(name, data=arr)
    for kind in (PhysicalTrace, RawRegisterTrace):
        _load_checked(kind, path)


# The Python API's arguments: whatever a user passes, the answer is a Run or a SinsError (never a raw
# TypeError/ValueError), and a PhysicalTrace holds native float64 of the documented shapes.
TRACE_ARGS = st.sampled_from(
    ["tiny", "tiny-chunks", "None", "numbers", "ndarray", "missing-file", "dict", "junk-chunk"]
)
PROFILE_ARGS = st.sampled_from(["reference", None, 3, "no-such-profile", ["reference"]])
OVERRIDE_ARGS = st.one_of(
    st.just(()),
    st.just("spi.spibrr=9"),
    st.lists(st.sampled_from(["spi.spibrr=9", "x=1", 9, None, "spi.spibrr=9\nspi.spibrr=1"]), max_size=2),
    st.sampled_from([None, 5]),
)
UNTIL_ARGS = st.one_of(
    st.none(),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(-5, 5),
    st.sampled_from(["1", True, [0.1]]),
)


@pytest.fixture(scope="module")
def tiny_in_memory() -> PhysicalTrace:
    return synth.generate("static", duration_s=0.05)


def _trace_arg(kind: str, tiny: PhysicalTrace):
    return {
        "tiny": tiny,
        "tiny-chunks": [tiny],
        "None": None,
        "numbers": [0.0, 1.0],
        "ndarray": np.zeros((3, 7)),
        "missing-file": str(_DIR / "no-such-trace.h5"),
        "dict": {"t_s": [0.0]},
        "junk-chunk": [tiny, "more"],
    }[kind]


@fuzz(60)
@given(trace=TRACE_ARGS, profile=PROFILE_ARGS, overrides=OVERRIDE_ARGS, until_s=UNTIL_ARGS)
def test_random_api_arguments_give_a_run_or_a_sins_error(tiny_in_memory, trace, profile, overrides, until_s):
    from sins_fw.errors import SinsError
    from sins_fw.harness import emulate

    try:
        run = emulate(_trace_arg(trace, tiny_in_memory), profile, overrides=overrides, until_s=until_s)
    except SinsError:
        return
    assert np.isfinite(run.quat).all()


ARRAY_DTYPES = st.sampled_from(
    ["f2", "f4", "f8", ">f8", "<f4", ">i4", "i1", "i8", "u2", "b1", "c8", "U3", "O"]
)


@st.composite
def trace_fields(draw):
    n = draw(st.integers(0, 4))

    def field(width: int | None):
        rows = draw(st.sampled_from([n, n, n, n + 1]))
        shape = (rows,) if width is None else draw(st.sampled_from([(rows, width), (rows, width), (rows,)]))
        values = np.array(
            draw(st.lists(st.integers(0, 100), min_size=int(np.prod(shape)), max_size=int(np.prod(shape)))),
            dtype="f8",
        ).reshape(shape)
        arr = values.astype(draw(ARRAY_DTYPES))
        return arr.tolist() if draw(st.booleans()) else arr

    return {"t_s": field(None), "gyro_dps": field(3), "accel_g": field(3), "temp_c": field(None)}


@fuzz(150)
@given(fields=trace_fields())
def test_random_trace_arrays_are_converted_exactly_or_refused_naming_the_field(fields):
    try:
        trace = PhysicalTrace(**fields, metadata={"sample_rate_hz": "100"})
    except TraceError as e:
        assert str(e).startswith("PhysicalTrace."), str(e)
        return
    n = len(trace.t_s)
    for name, width in (("t_s", None), ("gyro_dps", 3), ("accel_g", 3), ("temp_c", None)):
        arr = getattr(trace, name)
        assert arr.dtype == np.float64 and arr.dtype.isnative, name
        assert arr.shape == ((n,) if width is None else (n, width)), name
        given = np.asarray(fields[name])
        assert given.dtype.kind in "fiu", name
        assert np.array_equal(arr, given.astype(np.float64), equal_nan=True), name


# `run` with its newer options: --raw-out, --allow-gaps and --until-s, on a sound trace and on one
# with a gap; the answer is exit 0/1, or 2 with one message.
@fuzz(40)
@given(
    gap=st.booleans(),
    raw_out=st.sampled_from([None, ".csv", ".h5", ".txt"]),
    allow_gaps=st.booleans(),
    until=st.one_of(st.none(), st.sampled_from(["0.1", "1", "nan", "-1", "inf", "1e300", "abc"])),
)
def test_random_run_options_never_crash(capsys, tiny_trace, gap, raw_out, allow_gaps, until):
    from conftest import ROOT

    trace = ROOT / "tests" / "data" / "bad" / "handled" / "time_gap_2s.csv" if gap else tiny_trace
    args = ["run", str(trace), "--out", str(_DIR / "run_out.h5")]
    if raw_out is not None:
        args += ["--raw-out", str(_DIR / f"raw{raw_out}")]
    if allow_gaps:
        args.append("--allow-gaps")
    if until is not None:
        args += ["--until-s", until]
    _check_cli(capsys, *args)


# `replay` streamed (issue 24, item 11): its options and random overrides, on a sound trace and on
# one with a gap; the answer is exit 0/1, or 2 with one message, and never a half-written recording.
@pytest.mark.filterwarnings("error::RuntimeWarning")  # a NaN in the recording's arithmetic: silent
@fuzz(30)
@given(
    gap=st.booleans(),
    ticks=st.sampled_from(["none", "1:25", "3:3", "0:2", "5:1", "1:100000", "x", "2:"]),
    backends=st.lists(st.sampled_from(["f64", "c28x-f32", "c28x-f32-rz", "iq"]), max_size=3),
    suffix=st.sampled_from([".rrd", ".txt", ""]),
    pairs=st.lists(st.tuples(st.sampled_from(KEYS), VALUE), max_size=1),
)
def test_random_replay_options_never_crash(capsys, tiny_trace, gap, ticks, backends, suffix, pairs):
    from conftest import ROOT

    trace = ROOT / "tests" / "data" / "bad" / "handled" / "time_gap_2s.csv" if gap else tiny_trace
    out = _DIR / f"replay{suffix}"
    out.unlink(missing_ok=True)
    args = ["replay", str(trace), "--save", str(out), "--bus-ticks", ticks]
    args += [a for b in backends for a in ("--parity", b)]
    args += [a for k, v in pairs for a in ("--set", f"{k}={v}")]
    _check_cli(capsys, *args)
    leftovers = [p.name for p in _DIR.glob(f".replay{suffix}.*")]
    assert not leftovers, leftovers
