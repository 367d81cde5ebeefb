"""Vectorised Hamilton quaternions ``[w, x, y, z]`` (arrays of shape ``(..., 4)``).

Convention (the firmware's, see docs/traces.md): ``q`` is the attitude of the body frame b in the
navigation frame n, ``v_n = q ⊗ v_b ⊗ q*`` (``to_dcm(q)`` is C_b^n), and the kinematics are
``q̇ = ½ q ⊗ [0, ω_nb^b]``. Euler angles are the firmware's: C_b^n = Rz(yaw) · Ry(pitch) · Rx(roll),
roll = atan2(T32, T33), pitch = −asin(T31), yaw = atan2(T21, T11) mod 2π.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

Array = NDArray[np.float64]


def multiply(a: ArrayLike, b: ArrayLike) -> Array:
    """Hamilton product ``a ⊗ b`` (broadcasting)."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    aw, ax, ay, az = np.moveaxis(a, -1, 0)
    bw, bx, by, bz = np.moveaxis(b, -1, 0)
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=-1,
    )


def conjugate(q: ArrayLike) -> Array:
    """``q*`` (the inverse of a unit quaternion)."""
    return np.asarray(q, dtype=np.float64) * np.array([1.0, -1.0, -1.0, -1.0])


def normalize(q: ArrayLike) -> Array:
    """``q / |q|``."""
    q = np.asarray(q, dtype=np.float64)
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def rotate(q: ArrayLike, v: ArrayLike) -> Array:
    """``q ⊗ [0, v] ⊗ q*`` for unit ``q``: a body vector expressed in the navigation frame."""
    q = np.asarray(q, dtype=np.float64)
    v = np.asarray(v, dtype=np.float64)
    w = q[..., :1]
    u = q[..., 1:]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def from_axis_angle(axis: ArrayLike, angle: ArrayLike) -> Array:
    """Rotation by ``angle`` (rad) about the unit vector ``axis``."""
    axis = np.asarray(axis, dtype=np.float64)
    half = 0.5 * np.asarray(angle, dtype=np.float64)[..., None]
    return np.concatenate([np.cos(half), np.sin(half) * axis], axis=-1)


def from_rotation_vector(rv: ArrayLike) -> Array:
    """``exp(rv / 2)``: the rotation by ``|rv|`` about ``rv / |rv|`` (exact for small ``|rv|`` too)."""
    rv = np.asarray(rv, dtype=np.float64)
    angle = np.linalg.norm(rv, axis=-1, keepdims=True)
    half = 0.5 * angle
    # sin(x)/x via np.sinc avoids the 0/0 at zero angle: sinc(y) = sin(πy)/(πy).
    scale = 0.5 * np.sinc(half / np.pi)
    return np.concatenate([np.cos(half), scale * rv], axis=-1)


def from_euler(roll: ArrayLike, pitch: ArrayLike, yaw: ArrayLike) -> Array:
    """C_b^n = Rz(yaw) · Ry(pitch) · Rx(roll) (radians), the firmware's Euler sequence."""
    x = from_axis_angle(np.array([1.0, 0.0, 0.0]), roll)
    y = from_axis_angle(np.array([0.0, 1.0, 0.0]), pitch)
    z = from_axis_angle(np.array([0.0, 0.0, 1.0]), yaw)
    return multiply(multiply(z, y), x)


def rotation_angle(q: ArrayLike, q_ref: ArrayLike) -> Array:
    """The rotation angle (radians, in [0, π]) of ``q ⊗ q_ref⁻¹``, per row, in float64:
    ``2·atan2(|v|, |w|)`` of the error quaternion ``[w, v]``.

    The one formula for every "total" attitude error (run summary, report page, BROAD metrics,
    parity). Unlike ``2·acos(|w|)`` it is well conditioned at small angles (acos has an infinite
    slope at 1: a rounding of ``w`` by ε moves it by ~2·√(2ε)) and does not depend on the
    quaternions' norms, so an un-normalised single-precision estimate (norm 1 ± 1e-7) neither shows
    a false error of 2·acos(1 − 1e-7) ≈ 0.051° nor hides a real one behind ``w`` clipped at 1.
    """
    d = multiply(q, conjugate(q_ref))  # q_ref⁻¹ = q_ref* / |q_ref|²: the scale does not change the angle
    return 2.0 * np.arctan2(np.linalg.norm(d[..., 1:], axis=-1), np.abs(d[..., 0]))


def to_dcm(q: ArrayLike) -> Array:
    """The matrix C_b^n of unit ``q`` (shape ``(..., 3, 3)``), elements T_ij of the reference design."""
    q0, q1, q2, q3 = np.moveaxis(np.asarray(q, dtype=np.float64), -1, 0)
    rows = [
        [q0 * q0 + q1 * q1 - q2 * q2 - q3 * q3, 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)],
        [2 * (q1 * q2 + q0 * q3), q0 * q0 - q1 * q1 + q2 * q2 - q3 * q3, 2 * (q2 * q3 - q0 * q1)],
        [2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), q0 * q0 - q1 * q1 - q2 * q2 + q3 * q3],
    ]
    return np.stack([np.stack(r, axis=-1) for r in rows], axis=-2)


def to_euler_deg(q: ArrayLike) -> Array:
    """Roll, pitch, yaw in degrees as one ``(..., 3)`` array, like ``Run.euler_deg``: roll in
    (−180, 180], pitch in [−90, 90], yaw in [0, 360)."""
    return np.degrees(np.stack(to_euler(q), axis=-1))


def to_euler(q: ArrayLike) -> tuple[Array, Array, Array]:
    """(roll, pitch, yaw) in radians, as a tuple of arrays: roll in (−π, π], pitch in [−π/2, π/2],
    yaw in [0, 2π). :func:`to_euler_deg` gives degrees as one array."""
    t = to_dcm(q)
    roll = np.arctan2(t[..., 2, 1], t[..., 2, 2])
    pitch = -np.arcsin(np.clip(t[..., 2, 0], -1.0, 1.0))
    yaw = np.mod(np.arctan2(t[..., 1, 0], t[..., 0, 0]), 2.0 * np.pi)
    return roll, pitch, yaw
