"""Reference integrators for the synthetic-scenario tests, independent of sins_fw.synth.

Attitude: C_b^n = C_i^n C_b^i, so q_nb = q_in* ⊗ q_ib with q̇_ib = ½ q_ib ⊗ ω_ib^b and
q̇_in = ½ q_in ⊗ ω_in^n (the inertial frame is the navigation frame at t = 0). Both are linear and
right-multiplicative, so one RK4 step from any q equals q ⊗ P_k with P_k the RK4 step from the
identity: every P_k is computed at once (vectorised) and the running product P_0 ⊗ … ⊗ P_k by a
parallel prefix scan (log2 N vectorised passes), not by a Python loop over steps.
"""

from __future__ import annotations

import numpy as np

from sins_fw import quaternion as quat

EPS = np.finfo(np.float64).eps


def rk4_increments(w: np.ndarray, h: float) -> np.ndarray:
    """RK4 steps of q̇ = ½ q ⊗ [0, ω] from the identity, ω sampled at t, t+h/2, t+h (rows 0, 1, 2 …:
    w has 2K+1 rows for K steps of length h)."""
    one = np.zeros((w.shape[0] // 2, 4))
    one[:, 0] = 1.0
    w1, w2, w3 = (np.concatenate([np.zeros((len(x), 1)), x], axis=1) for x in (w[0:-1:2], w[1::2], w[2::2]))
    k1 = 0.5 * quat.multiply(one, w1)
    k2 = 0.5 * quat.multiply(one + 0.5 * h * k1, w2)
    k3 = 0.5 * quat.multiply(one + 0.5 * h * k2, w2)
    k4 = 0.5 * quat.multiply(one + h * k3, w3)
    return one + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


def prefix_product(steps: np.ndarray, start: np.ndarray) -> np.ndarray:
    """[start, start⊗P0, start⊗P0⊗P1, …] by a Hillis–Steele scan."""
    acc = steps.copy()
    d = 1
    while d < len(acc):
        acc[d:] = quat.multiply(acc[:-d], acc[d:])
        d *= 2
    return np.vstack([start[None, :], quat.multiply(start, acc)])


def integrate_attitude(q0: np.ndarray, w_ib_b: np.ndarray, w_in_n: np.ndarray, h: float) -> np.ndarray:
    """q_nb at every step end (and the start) for RK4 steps of length h on the 2K+1 fine samples."""
    q_ib = prefix_product(rk4_increments(w_ib_b, h), q0)
    q_in = prefix_product(rk4_increments(w_in_n, h), np.array([1.0, 0.0, 0.0, 0.0]))
    return quat.multiply(quat.conjugate(q_in), q_ib)


def quat_distance(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """‖a − ±b‖ with the sign that makes it smallest (q and −q are the same attitude)."""
    return np.minimum(np.linalg.norm(a - b, axis=-1), np.linalg.norm(a + b, axis=-1))


def assert_simpson_velocity(
    a: np.ndarray, v_n: np.ndarray, step: float, v0: np.ndarray | float = 0.0
) -> np.ndarray:
    """The acceleration ``a`` (rows ``step`` apart) integrated from ``v0`` by Simpson's rule over
    pairs of steps, at that step and at twice it, meets the truth ``v_n`` at every other row within
    twice Richardson's bound (Simpson: order 4, so |v_h − v_2h| / 15) plus 8 ulp of the velocity per
    step. Returns the truth compared."""
    n = (len(a) - 1) // 4 * 4
    v_h = v0 + np.vstack(
        [np.zeros(3), np.cumsum(step / 3 * (a[0:n:2] + 4 * a[1:n:2] + a[2 : n + 1 : 2]), axis=0)]
    )
    v_2h = v0 + np.vstack(
        [np.zeros(3), np.cumsum(2 * step / 3 * (a[0:n:4] + 4 * a[2:n:4] + a[4 : n + 1 : 4]), axis=0)]
    )
    truth = v_n[: n + 1 : 2]
    error = np.linalg.norm(v_h - truth, axis=1)
    richardson = np.linalg.norm(v_h[::2] - v_2h, axis=1) / 15.0
    rounding = 8 * EPS * np.abs(truth).max() * np.arange(1, len(truth) + 1)
    assert (error[::2] <= 2 * richardson + rounding[::2]).all()
    return truth
