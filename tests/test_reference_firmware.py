"""The reference firmware in C (firmware_c/examples/reference, issue 20 item 5, the arithmetic part):
the published data conversion and RK4 update as printed, plus the glue, built unmodified for the host
and fed the raw words of traces/pitch_sweep_10s_raw.csv burst by burst. Its quaternion and Euler
angles match the Rust model's bit for bit, in host f64 against the f64 backend and in the C28x float
mode against `c28x-f32`, with the reference profile's published decode, earth-rate correction and
navigation, and the published q̇2 row."""

from __future__ import annotations

import ctypes
import math
from pathlib import Path

import numpy as np
import pytest

from sins_fw import emulate
from sins_fw.firmware_build import build_firmware
from sins_fw.traces import RawRegisterTrace

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = ROOT / "firmware_c" / "examples" / "reference"
RAW = ROOT / "traces" / "pitch_sweep_10s_raw.csv"
#: The profile the C firmware implements: the reference design with the published q̇2 row.
OVERRIDES = ["firmware.quat_derivative=published"]
#: Calls the glue's per-burst entry from the test (the ISR of isr.c does it on the board).
ENTRY = """#include "reference.h"
void main(void) {}
void reference_test_burst(const Uint16 *words) { reference_process_burst(words); }
"""


pytestmark = pytest.mark.usefixtures("cabi_library")


def c_run(tmp_path: Path, float_mode: str) -> tuple[np.ndarray, np.ndarray]:
    """The C firmware's quaternion and Euler angles (roll, pitch, yaw; rad) after each update."""
    entry = tmp_path / "entry" / "entry.c"
    entry.parent.mkdir()
    entry.write_text(ENTRY)
    lib_path = build_firmware(
        [REFERENCE / "published.c", REFERENCE / "glue.c", REFERENCE / "navigation.c", entry],
        tmp_path / f"reference_{float_mode}.so",
        float_mode=float_mode,
    )
    lib = ctypes.CDLL(str(lib_path))
    # A C28x float is one IEEE single; a host double an IEEE double.
    real = ctypes.c_double if float_mode == "host" else ctypes.c_float
    words = RawRegisterTrace.load(RAW).words
    quat = (real * 4).in_dll(lib, "Q")
    euler = [real.in_dll(lib, name) for name in ("roll", "pitch", "yaw")]
    updates = ctypes.c_uint32.in_dll(lib, "updates")
    q_rows, e_rows = [], []
    burst = (ctypes.c_uint16 * 15)()
    for row in words:
        burst[:] = [int(w) for w in row]
        before = updates.value
        lib.reference_test_burst(burst)
        if updates.value != before:
            q_rows.append(list(quat))
            e_rows.append([e.value for e in euler])
    return np.array(q_rows, dtype=np.float64), np.array(e_rows, dtype=np.float64)


def first_difference(a: np.ndarray, b: np.ndarray) -> str:
    bad = np.nonzero(np.any(a.view(np.uint64) != b.view(np.uint64), axis=1))[0]
    if len(bad) == 0:
        return "none"
    i = int(bad[0])
    return f"update {i}: C {a[i].tolist()} vs Rust {b[i].tolist()}"


@pytest.fixture(scope="module")
def c_results(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """The C firmware's results per float mode, built and run once for the module."""
    return {mode: c_run(tmp_path_factory.mktemp(mode), mode) for mode in ("host", "c28x")}


@pytest.mark.parametrize(("float_mode", "numeric"), [("host", "f64"), ("c28x", "c28x-f32")])
def test_the_c_reference_firmware_matches_the_model_bit_for_bit(
    c_results: dict[str, tuple[np.ndarray, np.ndarray]], float_mode: str, numeric: str
):
    quat, euler_rad = c_results[float_mode]
    run = emulate(RAW, "reference", overrides=[*OVERRIDES, f"firmware.numeric={numeric}"])
    # 2500 bursts, an update every second one after the first: 1249 updates.
    assert len(run.quat) == len(quat) == 1249
    assert first_difference(quat, np.asarray(run.quat, dtype=np.float64)) == "none"
    # The model reports degrees: its radians × 180/π in f64 (Rust's to_degrees), done here the same way.
    euler_deg = euler_rad * (180.0 / math.pi)
    assert first_difference(euler_deg, np.asarray(run.euler_deg, dtype=np.float64)) == "none"
    # Not a trivial attitude: in its first 10 s the sweep pitches the board (about body y) by its first
    # 10° step (9.98° reached by 10 s).
    assert np.max(np.abs(euler_deg[:, 1])) > 9.9


def test_the_two_arithmetics_differ(c_results: dict[str, tuple[np.ndarray, np.ndarray]]):
    """The C28x mode is not the host's arithmetic under another name: the same C gives another
    attitude, apart by single-precision rounding (f32 ulp 6e-8, accumulated over 1249 updates)."""
    difference = np.max(np.abs(c_results["host"][0] - c_results["c28x"][0]))
    assert 0 < difference < 1e-4
