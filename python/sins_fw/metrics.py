"""Attitude accuracy against a truth quaternion (docs/traces.md, "Metrics").

Two families, both from quaternions ``[w, x, y, z]`` that are C_b^n (navigation frame ENU):

* Euler errors: roll, pitch and yaw by the firmware's formulas (sins_fw.quaternion.to_euler), each
  estimate minus truth wrapped to (−180°, 180°]. Near pitch ±90° roll and yaw are ill-defined and so
  are their errors: prefer the BROAD errors there.
* BROAD's errors (its example code): q_err = q_est ⊗ q_truth⁻¹ (an earth-frame error), total =
  2·acos(|w|), heading = 2·atan(|z/w|), inclination = 2·acos(√(w² + z²)). RMSE over the movement
  mask, skipping rows whose truth is NaN (lost markers). Computed in float64 in the equivalent
  well-conditioned forms total = 2·atan2(|v|, |w|) (:func:`sins_fw.quaternion.rotation_angle`, the
  one "total" everywhere) and inclination = 2·atan2(√(x² + y²), √(w² + z²)): acos loses the small
  angles (and clipping |w| at 1 hides them when the estimate's norm exceeds 1).

Heading alignment (optional): a method without a magnetometer has no heading reference, so its
estimate is rotated about the navigation z axis once, by the heading error at the first valid
movement sample; reports say so.

Initial-attitude alignment (``align_initial``): firmware that starts from Q = [1, 0, 0, 0] (the
reference design) integrates relative to the body's attitude at power-on, so its estimate is
premultiplied once by the truth at that instant: all three axes, not only heading.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sins_fw import quaternion as quat
from sins_fw.errors import InputError

Array = NDArray[np.float64]


def wrap_deg(angle: ArrayLike) -> Array:
    """Wrap degrees to (−180, 180]."""
    a = np.asarray(angle, dtype=np.float64)
    wrapped = np.mod(a + 180.0, 360.0) - 180.0
    return np.where(wrapped == -180.0, 180.0, wrapped)


@dataclass(frozen=True)
class AttitudeErrors:
    """Per-sample errors in degrees (NaN where the truth is NaN)."""

    total: Array
    heading: Array
    inclination: Array
    roll: Array
    pitch: Array
    yaw: Array


def attitude_errors(q_est: ArrayLike, q_truth: ArrayLike) -> AttitudeErrors:
    """Per-sample BROAD and Euler errors of ``q_est`` against ``q_truth`` (both ``(N, 4)``)."""
    est = np.asarray(q_est, dtype=np.float64)
    truth = np.asarray(q_truth, dtype=np.float64)
    if est.shape != truth.shape or est.ndim != 2 or est.shape[1] != 4:
        raise InputError(
            f"estimate {est.shape} and truth {truth.shape}: expected two (N, 4) quaternion arrays"
        )
    err = quat.multiply(est, quat.conjugate(truth))
    w, x, y, z = np.abs(err.T)
    total = quat.rotation_angle(est, truth)
    heading = 2.0 * np.arctan2(z, w)  # = 2·atan(|z/w|), defined at w = 0 too
    # = 2·acos(√(w² + z²)) for a unit error, without acos's ill conditioning near 1 or the norm.
    inclination = 2.0 * np.arctan2(np.hypot(x, y), np.hypot(w, z))
    est_euler = quat.to_euler(est)
    truth_euler = quat.to_euler(truth)
    roll, pitch, yaw = (wrap_deg(np.degrees(e - t)) for e, t in zip(est_euler, truth_euler, strict=True))
    return AttitudeErrors(
        total=np.degrees(total),
        heading=np.degrees(heading),
        inclination=np.degrees(inclination),
        roll=roll,
        pitch=pitch,
        yaw=yaw,
    )


def valid_mask(q_truth: ArrayLike, mask: ArrayLike | None = None) -> NDArray[np.bool_]:
    """Rows that count: inside ``mask`` (all rows when None) and with a finite truth."""
    truth = np.asarray(q_truth, dtype=np.float64)
    valid = np.isfinite(truth).all(axis=1)
    if mask is not None:
        m = np.asarray(mask, dtype=bool)
        if m.shape != valid.shape:
            raise InputError(f"movement mask shape {m.shape}; expected {valid.shape}")
        valid &= m
    return valid


def align_heading(
    q_est: ArrayLike, q_truth: ArrayLike, mask: ArrayLike | None = None
) -> tuple[Array, float, int]:
    """Rotate the estimate about navigation z so its heading error is zero at the first valid sample.

    With q_err = q_h ⊗ q_i (q_h about z by δ = 2·atan2(z, w), q_i about a horizontal axis), the
    aligned estimate is R_z(−δ) ⊗ q_est. Returns (aligned estimate, δ in degrees, row used).
    """
    est = np.asarray(q_est, dtype=np.float64)
    valid = valid_mask(q_truth, mask)
    if not valid.any():
        raise InputError("heading alignment: no sample with valid truth inside the movement mask")
    k = int(np.argmax(valid))
    turn, delta_deg = heading_turn(est[k], np.asarray(q_truth, dtype=np.float64)[k])
    return quat.multiply(turn, est), delta_deg, k


def heading_turn(q_est: Array, q_truth: Array) -> tuple[Array, float]:
    """The rotation R_z(−δ) about navigation z that zeroes the heading error δ of one sample (see
    :func:`align_heading`), and δ in degrees."""
    err = quat.multiply(q_est, quat.conjugate(q_truth))
    delta = 2.0 * math.atan2(err[3], err[0])
    turn = quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), -delta)
    return turn, float(wrap_deg(math.degrees(delta)))


def alignment_record(
    method: str, row: int | None = None, *, t_s: float = 0.0, heading_deg: float = 0.0
) -> dict[str, Any]:
    """How an estimate was aligned to the truth, as every report (whole or streamed) records it: the
    method, the step row it used (None: the truth at power-on), the heading turned, a description."""
    if method == "heading":
        text = (
            f"heading: rotated about navigation z by {heading_deg:.3f}° (the heading error at step row "
            f"{row}, the first valid movement sample)"
        )
        return {"method": method, "row": row, "heading_deg": heading_deg, "description": text}
    if method == "initial":
        text = (
            "initial attitude: the firmware starts from Q = [1, 0, 0, 0], so its estimate is premultiplied "
            "by the truth at power-on (the trace's first sample)"
            if row is None
            else f"initial attitude: no truth at power-on, so the estimate is rotated to match the truth at "
            f"step row {row} (t = {t_s:.3f} s)"
        )
        return {"method": method, "row": row, "description": text}
    return {"method": "none", "row": None, "description": "none: estimate compared as is"}


def align_initial(q_est: ArrayLike, q_truth_start: ArrayLike) -> Array:
    """``q_truth_start ⊗ q_est``: an estimate that started from the identity at the instant whose
    truth is ``q_truth_start``, expressed in the truth's navigation frame."""
    start = np.asarray(q_truth_start, dtype=np.float64)
    if start.shape != (4,) or not np.isfinite(start).all():
        raise InputError(f"initial alignment: truth at the start is {start}; expected a finite quaternion")
    return quat.multiply(start, np.asarray(q_est, dtype=np.float64))


@dataclass(frozen=True)
class AccuracyReport:
    """RMSE and maximum of each error over the counted rows (degrees)."""

    rmse_total_deg: float
    rmse_heading_deg: float
    rmse_inclination_deg: float
    rmse_roll_deg: float
    rmse_pitch_deg: float
    rmse_yaw_deg: float
    max_total_deg: float
    max_heading_deg: float
    max_inclination_deg: float
    samples: int
    skipped_nan_truth: int
    heading_aligned: bool
    heading_alignment_deg: float | None
    alignment_row: int | None

    def to_dict(self) -> dict[str, Any]:
        """Plain dictionary (for JSON)."""
        return asdict(self)

    def summary(self) -> str:
        """One human-readable paragraph, stating the alignment if any."""
        text = (
            f"attitude error over {self.samples} samples ({self.skipped_nan_truth} skipped: no truth): "
            f"RMSE total {self.rmse_total_deg:.3f}°, heading {self.rmse_heading_deg:.3f}°, "
            f"inclination {self.rmse_inclination_deg:.3f}°; roll {self.rmse_roll_deg:.3f}°, "
            f"pitch {self.rmse_pitch_deg:.3f}°, yaw {self.rmse_yaw_deg:.3f}°"
        )
        if self.heading_aligned:
            text += (
                f"; heading aligned to the truth once, by {self.heading_alignment_deg:.3f}° at row "
                f"{self.alignment_row} (first valid movement sample)"
            )
        return text


def _rmse(x: Array) -> float:
    return float(np.sqrt(np.mean(x * x)))


def accuracy(
    q_est: ArrayLike, q_truth: ArrayLike, mask: ArrayLike | None = None, *, align: bool = False
) -> AccuracyReport:
    """RMSE of the errors over ``mask`` (e.g. BROAD's ``movement``), skipping NaN truth rows."""
    est = np.asarray(q_est, dtype=np.float64)
    truth = np.asarray(q_truth, dtype=np.float64)
    in_mask = np.ones(len(truth), dtype=bool) if mask is None else np.asarray(mask, dtype=bool)
    valid = valid_mask(truth, in_mask)
    if not valid.any():
        raise InputError("accuracy: no sample with valid truth inside the movement mask")
    delta: float | None = None
    row: int | None = None
    if align:
        est, delta, row = align_heading(est, truth, in_mask)
    e = attitude_errors(est[valid], truth[valid])
    return AccuracyReport(
        rmse_total_deg=_rmse(e.total),
        rmse_heading_deg=_rmse(e.heading),
        rmse_inclination_deg=_rmse(e.inclination),
        rmse_roll_deg=_rmse(e.roll),
        rmse_pitch_deg=_rmse(e.pitch),
        rmse_yaw_deg=_rmse(e.yaw),
        max_total_deg=float(e.total.max()),
        max_heading_deg=float(e.heading.max()),
        max_inclination_deg=float(e.inclination.max()),
        samples=int(valid.sum()),
        skipped_nan_truth=int((in_mask & ~np.isfinite(truth).all(axis=1)).sum()),
        heading_aligned=align,
        heading_alignment_deg=delta,
        alignment_row=row,
    )


def alpha_error_stats(error_deg: ArrayLike) -> dict[str, Any]:
    """RMS, largest |e|, 95th percentile of |e| (degrees) and the count of a set of hinge-angle errors
    (None for the figures of an empty set)."""
    e = np.abs(np.asarray(error_deg, dtype=np.float64))
    if not len(e):
        return {"steps": 0, "rms_deg": None, "max_abs_deg": None, "p95_abs_deg": None}
    return {
        "steps": len(e),
        "rms_deg": float(np.sqrt(np.mean(e * e))),
        "max_abs_deg": float(e.max()),
        "p95_abs_deg": float(np.percentile(e, 95)),
    }


def alpha_errors(alpha_deg: ArrayLike, truth_deg: ArrayLike, still: ArrayLike) -> dict[str, Any]:
    """The wing unit's α error against the trace's truth (estimate − truth, wrapped to (−180, 180]) over
    the steps with both: all of them, the static ones (the hinge still, ``still``) and the dynamic
    ones; and the steps with no α yet (the zero acquisition and the first motion)."""
    a, t = np.asarray(alpha_deg, dtype=np.float64), np.asarray(truth_deg, dtype=np.float64)
    st = np.asarray(still, dtype=bool)
    have = np.isfinite(a) & np.isfinite(t)
    e = wrap_deg(a - t)
    return {
        "steps_without_alpha": int(np.sum(~np.isfinite(a) & np.isfinite(t))),
        "all": alpha_error_stats(e[have]),
        "static": alpha_error_stats(e[have & st]),
        "dynamic": alpha_error_stats(e[have & ~st]),
        "final_error_deg": float(e[have][-1]) if have.any() else None,
    }
