"""The gyro-free vehicle board (issue 25) from Python: a ``synth vehicle`` trace through the board
model of ``firmware_model/gfsins.toml`` (``_core.gfsins_run``), the DSP's decoded packets, both
processors' budget per rate class and the events.

The compass's truth comes from the trace: heading (clockwise from north), pitch (nose up) and roll
(right side down) of the body's x (forward) axis from ``truth_q`` (C_b^n, ENU; the synth flight
kinematics' x forward, y left, z up), its specific force from the centre part (``array7_*``), its
field from ``mag_*``. The GPS rows are held from fix to fix (the receiver samples the truth at its
own epochs)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from sins_fw import _core
from sins_fw.errors import TraceError
from sins_fw.traces import PhysicalTrace

#: The shipped profile.
PROFILE = Path(__file__).parent / "firmware_model" / "gfsins.toml"


def compass_truth(trace: PhysicalTrace) -> np.ndarray:
    """(n, 9): heading, pitch, roll (°), specific force (g), field (gauss) at the compass."""
    if trace.truth_q is None or trace.array_g is None:
        raise TraceError("gfsins: the trace needs truth_q and the array columns (sins-fw synth vehicle)")
    w, x, y, z = trace.truth_q.T
    # Columns of C_b^n: the body x axis in ENU, and the up components of y and z.
    xe, xn, xu = 1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y)
    yu, zu = 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)
    heading = np.mod(np.degrees(np.arctan2(xe, xn)), 360.0)
    pitch = np.degrees(np.arctan2(xu, np.hypot(yu, zu)))
    roll = np.degrees(np.arctan2(yu, zu))
    mag = trace.mag_gauss if trace.mag_gauss is not None else np.zeros((len(trace), 3))
    return np.column_stack([heading, pitch, roll, trace.array_g[:, 18:21], mag])


def held_gps(trace: PhysicalTrace) -> np.ndarray:
    """(n, 5): the trace's GPS rows, each fix held until the next."""
    if trace.gps is None or np.isnan(trace.gps[0, 0]):
        raise TraceError("gfsins: the trace needs a GPS stream with a fix on its first row (--gps-rate-hz)")
    has = ~np.isnan(trace.gps[:, 0])
    index = np.maximum.accumulate(np.where(has, np.arange(len(trace)), 0))
    return np.ascontiguousarray(trace.gps[index])


def run(trace: PhysicalTrace, ticks: int, profile: Path = PROFILE) -> dict[str, Any]:
    """Run the board over ``trace`` for ``ticks`` 5 ms cycles (see ``_core.gfsins_run``)."""
    compass = compass_truth(trace)  # checks that the trace has the array columns
    assert trace.array_g is not None
    return dict(
        _core.gfsins_run(
            profile.read_text(encoding="utf-8"),
            str(profile),
            np.ascontiguousarray(trace.t_s),
            np.ascontiguousarray(trace.array_g),
            compass,
            held_gps(trace),
            int(ticks),
        )
    )
