"""The Python API refuses what it cannot take with a documented sins_fw.errors exception naming the
argument or field and what was expected, and converts exactly what a user would expect it to take
(float32, integer and big-endian arrays, lists of numbers: native float64)."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from sins_fw import synth
from sins_fw.cli import main
from sins_fw.errors import InputError, ProfileError, SinsError, TraceError
from sins_fw.harness import check_until_s, emulate
from sins_fw.traces import PhysicalTrace, RawRegisterTrace


@pytest.fixture(scope="module")
def trace() -> PhysicalTrace:
    # 0.3 s at 819.2 SPS: a few dozen attitude steps, quick to emulate.
    return synth.generate("static", duration_s=0.3)


@pytest.fixture(scope="module")
def reference(trace):
    return emulate(trace)


def _same_run(a, b) -> None:
    assert a.time_s.tobytes() == b.time_s.tobytes()
    assert a.quat.tobytes() == b.quat.tobytes()
    assert a.read_words.tobytes() == b.read_words.tobytes()
    assert len(a.time_s) > 10


# ---------------------------------------------------------------------------------------------------
# emulate's arguments
# ---------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("value", "kind", "fragment"),
    [
        (None, TraceError, "trace = None: expected a PhysicalTrace, a RawRegisterTrace, a trace file path"),
        (
            [1.0, 2.0, 3.0],
            TraceError,
            "trace chunk 0 = 1.0: expected a PhysicalTrace (an iterable of traces is taken as consecutive",
        ),
        (42, TraceError, "trace = 42: expected a PhysicalTrace"),
        (np.zeros((4, 7)), TraceError, "(wrap arrays in a PhysicalTrace)"),
        ({"t_s": [0.0]}, TraceError, "trace = {'t_s': [0.0]}: expected a PhysicalTrace"),
    ],
    ids=["None", "list-of-numbers", "int", "ndarray", "dict"],
)
def test_a_trace_argument_that_is_not_a_trace_is_a_trace_error(value, kind, fragment):
    # Before: TypeError ('NoneType' / 'float' object is not iterable), or a dict's keys iterated.
    with pytest.raises(kind) as e:
        emulate(value)
    assert fragment in str(e.value)


@pytest.mark.parametrize(
    ("profile", "fragment"),
    [
        (None, "profile = None: expected a Profile, a profile name (e.g. 'reference') or the path"),
        (3, "profile = 3: expected a Profile"),
    ],
)
def test_a_profile_that_is_not_a_profile_is_a_profile_error(trace, profile, fragment):
    # Before: TypeError from pathlib (expected str, bytes or os.PathLike object, not NoneType).
    with pytest.raises(ProfileError) as e:
        emulate(trace, profile=profile)
    assert fragment in str(e.value)


def test_overrides_as_one_text_is_refused_not_iterated_by_character(trace):
    # Before: "spi.spibrr=9" was taken as the overrides "s", "p", "i", ... (the core refused "s").
    with pytest.raises(ProfileError) as e:
        emulate(trace, overrides="spi.spibrr=9")
    assert str(e.value) == (
        "overrides = 'spi.spibrr=9': expected a list of 'key=value' texts (write overrides=['spi.spibrr=9'])"
    )
    with pytest.raises(ProfileError, match=r"overrides\[1\] = 9: expected a 'key=value' text"):
        emulate(trace, overrides=["spi.spibrr=9", 9])
    with pytest.raises(ProfileError, match="overrides = 5: expected a list"):
        emulate(trace, overrides=5)
    # Any iterable of texts is fine (a tuple, a generator).
    emulate(trace, overrides=(o for o in ["spi.spibrr=9"]), until_s=0.05)


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf, 0.0, -1.0, "5", True, [1.0]])
def test_until_s_that_is_not_a_positive_finite_number_is_an_input_error(trace, value):
    # Before: nan was accepted (the run emulated the whole trace: every comparison with nan is False).
    with pytest.raises(InputError) as e:
        emulate(trace, until_s=value)
    assert str(e.value) == f"until_s = {value!r}: expected a finite number of seconds > 0"


def test_until_s_is_checked_by_one_function_for_the_api_the_cli_and_a_run_output(capsys, tmp_path, trace):
    assert check_until_s(None) is None
    assert check_until_s(np.float32(0.25)) == 0.25 and check_until_s(2) == 2.0
    path = tmp_path / "t.h5"
    trace.save(path)
    assert main(["run", str(path), "--until-s", "nan"]) == 2
    assert (
        "sins-fw: error: --until-s = nan: expected a finite number of seconds > 0" in capsys.readouterr().err
    )
    # A numpy number is a number: the same run as with the float.
    _same_run(emulate(trace, until_s=np.float64(0.2)), emulate(trace, until_s=0.2))


# ---------------------------------------------------------------------------------------------------
# PhysicalTrace's arrays: converted exactly, or refused naming the field and the shape expected
# ---------------------------------------------------------------------------------------------------


def _fields(trace: PhysicalTrace, convert) -> dict:
    return {
        "t_s": convert(trace.t_s),
        "gyro_dps": convert(trace.gyro_dps),
        "accel_g": convert(trace.accel_g),
        "metadata": trace.metadata,
    }


def _as_float32(trace: PhysicalTrace) -> PhysicalTrace:
    """The trace with every value rounded to float32 (held as float64): what a float32 input means."""
    return PhysicalTrace(**_fields(trace, lambda a: a.astype(np.float32).astype(np.float64)))


CONVERSIONS = {
    "float32": lambda a: a.astype(np.float32),
    "big-endian": lambda a: a.astype(">f8"),
    "list": lambda a: a.tolist(),
    "non-contiguous": lambda a: np.asfortranarray(a),
}


@pytest.mark.parametrize("name", sorted(CONVERSIONS))
def test_numeric_arrays_of_other_dtypes_and_lists_are_converted_exactly(trace, reference, name):
    # Before: the core refused them with "type mismatch:" and no detail (float32, big-endian), or a
    # list failed with a raw TypeError/AttributeError.
    convert = CONVERSIONS[name]
    given = PhysicalTrace(**_fields(trace, convert))
    for field in ("t_s", "gyro_dps", "accel_g"):
        arr = getattr(given, field)
        assert arr.dtype == np.float64 and arr.dtype.isnative, field
    expected = emulate(_as_float32(trace)) if name == "float32" else reference
    _same_run(emulate(given), expected)


def test_integer_arrays_are_converted_exactly():
    # A board at rest, level: whole numbers throughout (t in ms steps of a 1 kHz trace, as ints of ms
    # are not seconds: 1 Hz instead). Int64 gyro/accel must give the run of the float64 trace.
    n = 40
    ints = PhysicalTrace(
        t_s=np.arange(n),
        gyro_dps=np.zeros((n, 3), dtype=np.int32),
        accel_g=np.tile(np.array([0, 0, 1], dtype=np.int64), (n, 1)),
        metadata={"sample_rate_hz": 1},
    )
    floats = PhysicalTrace(
        t_s=np.arange(n, dtype=float),
        gyro_dps=np.zeros((n, 3)),
        accel_g=np.tile([0.0, 0.0, 1.0], (n, 1)),
        metadata={"sample_rate_hz": "1"},
    )
    assert ints.metadata == {"sample_rate_hz": "1"} and ints.accel_g.dtype == np.float64
    _same_run(emulate(ints, until_s=20), emulate(floats, until_s=20))
    with pytest.raises(
        TraceError, match=r"PhysicalTrace.t_s: .* element \(1,\) = 9007199254740993 is beyond 2\^53"
    ):
        PhysicalTrace(np.array([0, 2**53 + 1]), np.zeros((2, 3)), np.zeros((2, 3)))


@pytest.mark.parametrize(
    ("field", "value", "fragment"),
    [
        (
            "gyro_dps",
            [["a", "b", "c"]] * 3,
            "PhysicalTrace.gyro_dps: expected shape (3, 3) (gyro_x_dps, gyro_y_dps, ",
        ),
        ("gyro_dps", np.zeros(3), "PhysicalTrace.gyro_dps: expected shape (3, 3)"),
        ("accel_g", np.zeros((3, 4)), "PhysicalTrace.accel_g: expected shape (3, 3)"),
        (
            "accel_g",
            None,
            "PhysicalTrace.accel_g: expected shape (3, 3) (accel_x_g, accel_y_g, accel_z_g; n = len(t_s)) "
            "of numbers (float or integer); got None",
        ),
        ("t_s", "0 0.01 0.02", "PhysicalTrace.t_s: expected shape (n,) (times, s) of numbers"),
        (
            "t_s",
            np.zeros((3, 1)),
            "PhysicalTrace.t_s: expected shape (n,) (times, s) of numbers (float or integer); "
            "got shape (3, 1)",
        ),
        (
            "truth_q",
            np.zeros((3, 3)),
            "PhysicalTrace.truth_q: expected shape (3, 4) (truth_qw, truth_qx, truth_qy",
        ),
        (
            "temp_c",
            np.zeros(3, dtype=complex),
            "PhysicalTrace.temp_c: expected shape (3,) (temp_c; n = len(t_s)) of numbers (float or "
            "integer); got ndarray of dtype complex128",
        ),
        ("gyro_dps", [[0, 0], [0, 0, 0], [0, 0, 0]], "PhysicalTrace.gyro_dps: expected shape (3, 3)"),
        (
            "moving",
            [0, 1, 2],
            "PhysicalTrace.moving: element 2 = 2; expected shape (3,) (moving; n = len(t_s)) of bools or 0/1",
        ),
        (
            "metadata",
            [("sample_rate_hz", "100")],
            "PhysicalTrace.metadata: expected a dict of text keys and values; got list",
        ),
        (
            "metadata",
            {"sample_rate_hz": None},
            "PhysicalTrace.metadata: `sample_rate_hz` = None is NoneType; expected text or a number",
        ),
    ],
    ids=lambda v: v if isinstance(v, str) and len(v) < 20 else None,
)
def test_a_field_that_cannot_be_converted_is_refused_naming_it_and_the_shape(field, value, fragment):
    # Before: accepted at construction; then a raw TypeError/UFuncTypeError in validation or the
    # core's "type mismatch:", or (shape) a TraceError only once the trace was validated.
    fields = {
        "t_s": np.array([0.0, 0.01, 0.02]),
        "gyro_dps": np.zeros((3, 3)),
        "accel_g": np.zeros((3, 3)),
        "metadata": {"sample_rate_hz": "100"},
        field: value,
    }
    with pytest.raises(TraceError) as e:
        PhysicalTrace(**fields)
    assert fragment in str(e.value)


def test_moving_as_numbers_0_or_1_is_converted_to_bools():
    t = PhysicalTrace(
        [0.0, 0.01], [[0, 0, 0]] * 2, [[0, 0, 1]] * 2, moving=np.array([0.0, 1.0], dtype=">f4"), metadata={}
    )
    assert t.moving.dtype == bool and t.moving.tolist() == [False, True]


def test_raw_register_trace_converts_words_and_refuses_what_is_not_a_word(tmp_path):
    ok = RawRegisterTrace([0.0, 0.004], [[0] * 15, [0xFFFF] * 15], metadata={"sample_rate_hz": 250})
    assert (
        ok.words.dtype == np.uint16 and ok.t_s.dtype == np.float64 and ok.metadata["sample_rate_hz"] == "250"
    )
    with pytest.raises(
        TraceError, match=r"RawRegisterTrace.words: element \(1, 3\) = 65536; expected shape \(2, 15\)"
    ):
        RawRegisterTrace([0.0, 0.004], [[0] * 15, [0, 0, 0, 0x10000] + [0] * 11])
    with pytest.raises(
        TraceError, match=r"RawRegisterTrace.words: expected shape \(2, 15\) of 16-bit words .*dtype float64"
    ):
        RawRegisterTrace([0.0, 0.004], np.zeros((2, 15)))


def test_every_refusal_is_a_sins_error_never_a_raw_python_error(trace):
    """The cases above in one sweep, as a user would try them: only SinsError subclasses come out."""
    attempts = [
        lambda: emulate([trace, "more"]),
        lambda: emulate(b"bytes"),
        lambda: emulate(trace, profile=None),
        lambda: emulate(trace, overrides="x"),
        lambda: emulate(trace, until_s=math.nan),
        lambda: PhysicalTrace(None, None, None),
        lambda: PhysicalTrace([0.0, "x"], [[0, 0, 0]] * 2, [[0, 0, 0]] * 2),
        lambda: PhysicalTrace([0.0, 1.0], [[0, 0, 0]] * 2, [[0, 0, 0]] * 2, metadata=None),
    ]
    for attempt in attempts:
        with pytest.raises(SinsError):
            attempt()


# ---------------------------------------------------------------------------------------------------
# Issue 42, item 4: every public function names the argument that is not what it expects
# ---------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kw", "fragment"),
    [
        # Before: ValueError from int() ('1:5'), TypeError (None, 3 is not iterable).
        ({"bus_window": "1:5"}, "bus_window = '1:5': expected (first_tick, last_tick)"),
        ({"bus_window": 3}, "bus_window = 3: expected (first_tick, last_tick)"),
        ({"bus_window": (1, 2, 3)}, "bus_window = (1, 2, 3): expected (first_tick, last_tick)"),
        ({"bus_window": (1.5, 3)}, "bus_window = (1.5, 3): expected (first_tick, last_tick), two whole"),
        ({"bus_window": (0, 3)}, "bus_window = (0, 3): expected"),
        ({"keep_truth": "no"}, "keep_truth = 'no': expected True or False"),
        ({"allow_gaps": 1}, "allow_gaps = 1: expected True or False"),
        # Before: chunk_rows=0 raised ValueError (range() arg 3 must not be zero), 2.5 a TypeError; a
        # sink that is not a function a TypeError at the first chunk.
        ({"chunk_rows": 0}, "chunk_rows = 0: expected a whole number of rows >= 1"),
        ({"chunk_rows": 2.5}, "chunk_rows = 2.5: expected a whole number"),
        ({"sink": "out.h5"}, "sink = 'out.h5': expected a function or None"),
        ({"on_chunk": 1}, "on_chunk = 1: expected a function or None"),
    ],
)
def test_emulate_names_a_bad_keyword(trace, kw, fragment):
    with pytest.raises(InputError) as e:
        emulate(trace, **kw)
    assert fragment in str(e.value)


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        # Before: TypeError from pathlib.
        ((None,), "name_or_path = None: expected a profile name"),
        ((3.5,), "name_or_path = 3.5: expected a profile name"),
        # Before: read character by character ("override `s`: expected key=value").
        (("reference", "spi.spibrr=9"), "overrides = 'spi.spibrr=9': expected a list of 'key=value' texts"),
        (("reference", [9]), "overrides[0] = 9: expected a 'key=value' text"),
        (("reference", None), "overrides = None: expected a list"),
    ],
)
def test_load_profile_names_a_bad_argument(args, fragment):
    from sins_fw import load_profile

    with pytest.raises(ProfileError) as e:
        load_profile(*args)
    assert fragment in str(e.value)


def test_profile_methods_name_a_bad_argument():
    from sins_fw import load_profile

    profile = load_profile("reference")
    with pytest.raises(ProfileError, match="dotted = None: expected a dotted key text"):
        profile.get(None)
    with pytest.raises(ProfileError, match=re.escape("overrides[0] = ['spi.spibrr=9']")):
        profile.with_overrides(["spi.spibrr=9"])
    assert profile.with_overrides("spi.spibrr=9").get("spi.spibrr") == 9


def test_a_gyro_free_profile_is_checked_the_same_way():
    from sins_fw import gfsins

    with pytest.raises(ProfileError, match="name_or_path = None"):
        gfsins.load(None)
    with pytest.raises(ProfileError, match=re.escape("overrides = 'node.start_ms=5'")):
        gfsins.load(gfsins.PROFILE, "node.start_ms=5")


def test_run_raw_register_trace_metadata_is_checked(reference):
    with pytest.raises(InputError, match="metadata = 'x': expected a mapping of texts to texts"):
        reference.raw_register_trace("x")
