"""The wing unit's thermal calibration: the gyro bias temperature coefficients its firmware compensates
(`firmware.wing.gyro_bias_tempco_dps_per_c`, `rust/core/src/firmware/wing/app.rs`).

The source (`wing-angle-ahrs-notes.zh.txt`) says the ADIS16362's 0.01 °/s/°C makes 0.3° over 30 s
"barely" reachable with the temperature compensated, and gives no procedure. Here: the unit at rest on a
temperature ramp, through the whole board; each gyro axis's decoded rate is fitted against the part's own
X/Y/ZTEMP_OUT reading of the same burst (least squares, rate = b + k·ΔT): k is the coefficient the
firmware subtracts. At rest the rate also holds the earth rate and the bias instability; the fit's slope
error is that instability's part correlated with the ramp, and the white noise's
σ_ARW·√(12)/(√T_s·ΔT_span) (T_s the ramp's duration).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from sins_fw import synth
from sins_fw.harness import Run, emulate

#: X/Y/ZTEMP_OUT in a burst read's words: after the command's frame, SUPPLY_OUT, three gyros and three
#: accelerometers (the ADIS16362's 11-word burst, adis16362.md).
TEMP_WORDS = slice(8, 11)
#: TEMP_OUT: 12-bit two's complement, 0.136 °C per LSB, code 0 = 25 °C (data sheet p. 11).
TEMP_LSB_C = 0.136

#: The calibration ramp: 25 → 65 °C at 10 °C/min, at rest at the zero pose.
RAMP_START_C = 25.0
RAMP_C_PER_MIN = 10.0
RAMP_S = 240.0


def temperature_above_25_c(words: np.ndarray) -> np.ndarray:
    """Each read's X/Y/ZTEMP_OUT (rows of burst words) decoded: °C above 25 °C, (reads, 3)."""
    code = (np.asarray(words, dtype=np.int32)[:, TEMP_WORDS]) & 0x0FFF
    return np.where(code >= 0x800, code - 0x1000, code) * TEMP_LSB_C


def fit_tempco(run: Run) -> tuple[float, float, float]:
    """The gyro bias temperature coefficients of a run at rest, °/s per °C (x, y, z): each axis's decoded
    rate against its own TEMP_OUT reading, least squares with an intercept."""
    dt = temperature_above_25_c(run.read_words)
    rate_dps = np.degrees(np.asarray(run.read_rate, dtype=np.float64))
    k = []
    for i in range(3):
        design = np.column_stack([np.ones(len(dt)), dt[:, i]])
        (_, slope), *_ = np.linalg.lstsq(design, rate_dps[:, i], rcond=None)
        k.append(float(slope))
    return (k[0], k[1], k[2])


def calibration_trace() -> synth.PhysicalTrace:
    """The unit at rest at the zero pose while the temperature ramps (:data:`RAMP_S`)."""
    return synth.generate(
        "wing",
        flap="sine",
        amplitude_deg=0.0,
        rest_s=RAMP_S,
        duration_s=RAMP_S,
        temp_start_c=RAMP_START_C,
        temp_rate_c_per_min=RAMP_C_PER_MIN,
    )


def calibrate(
    overrides: Sequence[str], trace: synth.PhysicalTrace | None = None
) -> tuple[float, float, float]:
    """The coefficients of the unit ``overrides`` select on the wing board (e.g. ``errors.preset=adis16362``,
    ``errors.seed=7``), from a rest on :func:`calibration_trace`."""
    run = emulate(calibration_trace() if trace is None else trace, "wing", overrides=list(overrides))
    return fit_tempco(run)


def compensation_override(k: Sequence[float]) -> str:
    """The profile override that makes the firmware compensate with coefficients ``k``."""
    return "firmware.wing.gyro_bias_tempco_dps_per_c=[" + ", ".join(f"{x:.9g}" for x in k) + "]"
