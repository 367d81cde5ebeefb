//! The published quaternion update (appendix 1 of the thesis): RK4 on Q̇ = ½ M(ω) Q with three rate
//! samples, normalisation with one sqrt and four divisions, then the T matrix. The operation order
//! is the published code's, because every backend rounds each operation and the timing model counts
//! them.

use super::{lit, Mat3, Quat, Vec3};
use crate::numerics::{QClass, Scalar};
use crate::profile::QuatDerivative;

/// The RK4 quaternion step with its literals (`T1`, `2`, `6`) converted once.
#[derive(Debug, Clone, Copy)]
pub struct Rk4<T> {
    t1: T,
    two: T,
    six: T,
    form: QuatDerivative,
}

impl<T: Scalar> Rk4<T> {
    /// A step of `step_s` seconds (the firmware's `T1`) with the given derivative rows.
    pub fn new(step_s: f64, form: QuatDerivative) -> Self {
        // T1 in Q30 on a fixed-point target (0.008 s: 7e-8 relative truncation; GLOBAL_Q would be 5.4e-6).
        Rk4 { t1: T::from_f64(step_s, QClass::Quat), two: lit(2.0), six: lit(6.0), form }
    }

    /// The step length `T1` as the firmware holds it.
    pub fn step(&self) -> T {
        self.t1
    }

    /// K = ½ M(ω) X, written as the published lines `K[i] = ( … )/2`. The K are rates (|K| ≤ |ω|/2).
    fn derivative(&self, w: &Vec3<T>, x: &Quat<T>) -> Quat<T> {
        let [wx, wy, wz] = *w;
        let [x0, x1, x2, x3] = *x;
        let two = self.two;
        let k0 = (-wx * x1 - wy * x2 - wz * x3) / two;
        let k1 = (wx * x0 + wz * x2 - wy * x3) / two;
        let k2 = match self.form {
            QuatDerivative::Correct => (wy * x0 - wz * x1 + wx * x3) / two,
            QuatDerivative::Published => (wy * x0 - wz * x1 - wx * x3) / two,
        };
        let k3 = (wz * x0 + wy * x1 - wx * x2) / two;
        [k0, k1, k2, k3].map(|k| k.to_class(QClass::Rate))
    }

    /// One update of `q` with the rates ω_nb^b at t, t+T/2, t+T (`Wnbb[0..3]`), then normalisation.
    /// `Wnbb[1]` serves both K2 and K3, as published.
    ///
    /// Fixed point: K (up to |ω|/2, beyond Q30's ±2) is in the rate class, but the increments K·T/2,
    /// K·T and ΣK·T/6 (≤ 0.03 at 409.6 °/s) are formed straight in the quaternion's Q30 (`_IQNmpy`,
    /// `_IQNdiv` with N chosen for a Q30 result, [`Scalar::mul_to`], [`Scalar::div_to`]) and added to Q
    /// in Q30. Formed in the rate class's Q24 they would be quantised to 6e-8: an earth-rate increment
    /// (≈ 3e-7 per step) only ~5 LSB, a 10 % error.
    pub fn step_quat(&self, q: &mut Quat<T>, w: &[Vec3<T>; 3]) {
        let (two, t1) = (self.two, self.t1);
        let at = |k: &Quat<T>, half: bool| -> Quat<T> {
            let mut a = *q;
            for i in 0..4 {
                let kt = k[i].mul_to(t1, QClass::Quat);
                let dk = if half { kt.div_to(two, QClass::Quat) } else { kt };
                a[i] = (q[i] + dk).to_class(QClass::Quat);
            }
            a
        };
        let k1 = self.derivative(&w[0], q);
        let a = at(&k1, true);
        let k2 = self.derivative(&w[1], &a);
        let b = at(&k2, true);
        let k3 = self.derivative(&w[1], &b);
        let c1 = at(&k3, false);
        let k4 = self.derivative(&w[2], &c1);
        for i in 0..4 {
            let dq =
                (k1[i] + two * k2[i] + two * k3[i] + k4[i]).mul_to(t1, QClass::Quat).div_to(self.six, QClass::Quat);
            q[i] = (q[i] + dq).to_class(QClass::Quat);
        }
        normalise(q);
    }
}

/// `mo = sqrt(Q0² + Q1² + Q2² + Q3²); Qi = Qi / mo` as published (one sqrt, four divisions).
pub fn normalise<T: Scalar>(q: &mut Quat<T>) {
    let mo = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    for x in q.iter_mut() {
        *x = (*x / mo).to_class(QClass::Quat);
    }
}

/// The attitude matrix T = C_b^n from Q, element by element as published (`( … )*2`).
pub fn dcm<T: Scalar>(q: &Quat<T>) -> Mat3<T> {
    let [q0, q1, q2, q3] = *q;
    let two: T = lit(2.0);
    let m = [
        [q0 * q0 + q1 * q1 - q2 * q2 - q3 * q3, (q1 * q2 - q0 * q3) * two, (q1 * q3 + q0 * q2) * two],
        [(q1 * q2 + q0 * q3) * two, q0 * q0 - q1 * q1 + q2 * q2 - q3 * q3, (q2 * q3 - q0 * q1) * two],
        [(q1 * q3 - q0 * q2) * two, (q2 * q3 + q0 * q1) * two, q0 * q0 - q1 * q1 - q2 * q2 + q3 * q3],
    ];
    m.map(|row| row.map(|x| x.to_class(QClass::Quat)))
}

/// ω_nb^b = ω_ib^b − C_n^b ω_in^n with C_n^b = Tᵀ (so element i is Σ_j T_ji ω_in,j).
pub fn body_rate_nav<T: Scalar>(c_bn: &Mat3<T>, w_ib: &Vec3<T>, w_in_n: &Vec3<T>) -> Vec3<T> {
    let mut w = *w_ib;
    for (i, wi) in w.iter_mut().enumerate() {
        let proj = c_bn[0][i] * w_in_n[0] + c_bn[1][i] * w_in_n[1] + c_bn[2][i] * w_in_n[2];
        *wi = (*wi - proj).to_class(QClass::Rate);
    }
    w
}

/// The midpoint rate a one-read-per-step schedule uses for t+T/2: (ω(t) + ω(t+T)) / 2.
pub fn midpoint<T: Scalar>(w0: &Vec3<T>, w2: &Vec3<T>) -> Vec3<T> {
    let two: T = lit(2.0);
    [0, 1, 2].map(|i| ((w0[i] + w2[i]) / two).to_class(QClass::Rate))
}

/// Hamilton product a ⊗ b.
pub fn quat_mul<T: Scalar>(a: &Quat<T>, b: &Quat<T>) -> Quat<T> {
    let [a0, a1, a2, a3] = *a;
    let [b0, b1, b2, b3] = *b;
    [
        a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
        a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
        a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
        a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0,
    ]
    .map(|x| x.to_class(QClass::Quat))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// exp(½ [0, v]) for a rotation vector v (f64 reference).
    pub(crate) fn rotvec_quat(v: [f64; 3]) -> Quat<f64> {
        let a = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if a == 0.0 {
            return [1.0, 0.0, 0.0, 0.0];
        }
        let s = (a / 2.0).sin() / a;
        [(a / 2.0).cos(), v[0] * s, v[1] * s, v[2] * s]
    }

    /// Angle of the rotation between two attitudes (rad).
    pub(crate) fn angle_between(a: &Quat<f64>, b: &Quat<f64>) -> f64 {
        let conj = [a[0], -a[1], -a[2], -a[3]];
        let d = quat_mul(&conj, b);
        let v = (d[1] * d[1] + d[2] * d[2] + d[3] * d[3]).sqrt();
        2.0 * v.atan2(d[0].abs())
    }

    #[test]
    fn constant_rate_matches_closed_form_for_60_s() {
        let w = [0.3, -0.5, 0.7];
        let step = 0.008;
        let rk4 = Rk4::<f64>::new(step, QuatDerivative::Correct);
        let mut q = [1.0, 0.0, 0.0, 0.0];
        let n = 7500; // 60 s
        for _ in 0..n {
            rk4.step_quat(&mut q, &[w, w, w]);
        }
        let t = n as f64 * step;
        let truth = rotvec_quat(w.map(|x| x * t));
        let err = angle_between(&truth, &q);
        // RK4 truncates exp(½ΩT) after the 4th-order term: |ω|T/2 = 3.6e-3, (|ω|T/2)^5/120 = 5e-15 per
        // step → ≤ 4e-11 rad over 7500 steps, plus f64 round-off.
        assert!(err < 1e-9, "error {err:e} rad");
        assert!(err < 1e-10, "error {err:e} rad larger than the RK4 truncation bound");
    }

    #[test]
    fn published_row_breaks_multi_axis_kinematics() {
        // Two different q̇2 rows: identical when q3 or ωx is zero, different otherwise.
        let correct = Rk4::<f64>::new(0.008, QuatDerivative::Correct);
        let published = Rk4::<f64>::new(0.008, QuatDerivative::Published);
        let (mut a, mut b) = ([1.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]);
        let w = [0.0, 0.4, 0.0];
        for _ in 0..100 {
            correct.step_quat(&mut a, &[w; 3]);
            published.step_quat(&mut b, &[w; 3]);
        }
        assert_eq!(a, b);
        let w = [0.5, 0.0, 0.5];
        for _ in 0..100 {
            correct.step_quat(&mut a, &[w; 3]);
            published.step_quat(&mut b, &[w; 3]);
        }
        assert!(angle_between(&a, &b) > 1e-3);
    }

    #[test]
    fn dcm_is_orthonormal_and_matches_rotation() {
        let q = rotvec_quat([0.4, -1.1, 2.0]);
        let m = dcm(&q);
        for i in 0..3 {
            for j in 0..3 {
                let d: f64 = (0..3).map(|k| m[i][k] * m[j][k]).sum();
                assert!((d - if i == j { 1.0 } else { 0.0 }).abs() < 1e-15);
            }
        }
        // T·v equals Q ⊗ v ⊗ Q*.
        let v = [0.3, 0.2, -0.9];
        let qv = quat_mul(&quat_mul(&q, &[0.0, v[0], v[1], v[2]]), &[q[0], -q[1], -q[2], -q[3]]);
        for i in 0..3 {
            let mv: f64 = (0..3).map(|k| m[i][k] * v[k]).sum();
            assert!((mv - qv[i + 1]).abs() < 1e-15);
        }
    }

    #[test]
    fn body_rate_subtracts_transformed_nav_rate() {
        let q = rotvec_quat([0.2, 0.5, -0.3]);
        let m = dcm(&q);
        let w_in = [1e-5, 5e-5, 4e-5];
        // A body rate equal to C_n^b ω_in leaves nothing.
        let w_ib = [0, 1, 2].map(|i| (0..3).map(|j| m[j][i] * w_in[j]).sum::<f64>());
        let w = body_rate_nav(&m, &w_ib, &w_in);
        assert!(w.iter().all(|x| x.abs() < 1e-20));
    }
}
