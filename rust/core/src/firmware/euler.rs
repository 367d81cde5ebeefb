//! Euler angles from T = C_b^n (thesis eq. 2-38 and tables 2-1, 2-2), and the inverse.
//!
//! Convention, from eq. 2-7: C_b^n = Rz(ψ) · Ry(θ) · Rx(φ) with active right-handed rotations
//! (yaw ψ about z, then pitch θ about the new y, then roll φ about the new x), which gives
//! T31 = −sin θ, T32 = cos θ sin φ, T33 = cos θ cos φ, T11 = cos θ cos ψ, T21 = cos θ sin ψ. The
//! quaternion is therefore Q = q_z(ψ) ⊗ q_y(θ) ⊗ q_x(φ), q_a(x) = [cos x/2, a sin x/2].
//! Angles are radians (the firmware's `T` backends hold 2π without overflow, not 360).
//!
//! Fixed point: the tables' ratios T32/T33 and T21/T11 are formed in the angle class (`div_to`), not in
//! the elements' Q30 (which holds |ratio| < 2 only, i.e. angles below 63.4°). In Q24 a ratio saturates
//! at 128: between the `euler_zero_eps` row and |T33| = |T32|/128 the table gives ±89.55° instead of up
//! to ±90° (a limit of the published atan-of-ratio tables in GLOBAL_Q; the atan2 method has none).

use super::{lit, Mat3, Quat};
use crate::numerics::counter::Work;
use crate::numerics::{QClass, Scalar};
use crate::profile::Euler;

/// Attitude angles, radians: pitch in [−π/2, π/2], roll in (−π, π], yaw in [0, 2π).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EulerAngles<T> {
    /// θ = −asin(T31).
    pub pitch: T,
    /// φ from T32/T33.
    pub roll: T,
    /// ψ from T21/T11.
    pub yaw: T,
}

/// The Euler stage with its literals.
#[derive(Debug, Clone, Copy)]
pub struct EulerExtractor<T> {
    method: Euler,
    eps: T,
    zero: T,
    half_pi: T,
    pi: T,
    three_half_pi: T,
    two_pi: T,
}

impl<T: Scalar> EulerExtractor<T> {
    /// An extractor using `method`; |T33| or |T11| below `zero_eps` counts as "→0".
    pub fn new(method: Euler, zero_eps: f64) -> Self {
        use std::f64::consts::PI;
        EulerExtractor {
            method,
            eps: T::from_f64(zero_eps, QClass::Quat),
            zero: lit(0.0),
            half_pi: T::from_f64(PI / 2.0, QClass::Angle),
            pi: T::from_f64(PI, QClass::Angle),
            three_half_pi: T::from_f64(1.5 * PI, QClass::Angle),
            two_pi: T::from_f64(2.0 * PI, QClass::Angle),
        }
    }

    /// Roll by table 2-1: T33 → 0 gives ±90° by the sign of T32; T33 > 0 the principal value;
    /// T33 < 0 the principal value +180° (T32 ≥ 0) or −180° (T32 < 0).
    fn roll_table(&self, t32: T, t33: T) -> T {
        // The C's call of the table function with two arguments ([`Scalar::work`]).
        T::work(Work::call(2));
        if t33.abs() < self.eps {
            return if t32 >= self.zero { self.half_pi } else { -self.half_pi };
        }
        let principal = t32.div_to(t33, QClass::Angle).atan();
        if t33 > self.zero {
            principal
        } else if t32 >= self.zero {
            principal + self.pi
        } else {
            principal - self.pi
        }
    }

    /// Yaw by table 2-2: T11 → 0 gives 90° (T21 ≥ 0) or 270°; T11 > 0 the principal value, +360°
    /// when T21 < 0; T11 < 0 the principal value +180°.
    fn yaw_table(&self, t21: T, t11: T) -> T {
        // The C's call of the table function with two arguments ([`Scalar::work`]).
        T::work(Work::call(2));
        if t11.abs() < self.eps {
            return if t21 >= self.zero { self.half_pi } else { self.three_half_pi };
        }
        let principal = t21.div_to(t11, QClass::Angle).atan();
        if t11 > self.zero {
            if t21 >= self.zero {
                principal
            } else {
                principal + self.two_pi
            }
        } else {
            principal + self.pi
        }
    }

    /// Pitch, roll and yaw of T = C_b^n.
    pub fn extract(&self, t: &Mat3<T>) -> EulerAngles<T> {
        let pitch = (-t[2][0].asin()).to_class(QClass::Angle);
        let (roll, yaw) = match self.method {
            Euler::PublishedTables => (self.roll_table(t[2][1], t[2][2]), self.yaw_table(t[1][0], t[0][0])),
            Euler::Atan2 => {
                let yaw = t[1][0].atan2(t[0][0]);
                (t[2][1].atan2(t[2][2]), if yaw < self.zero { yaw + self.two_pi } else { yaw })
            }
        };
        EulerAngles { pitch, roll: roll.to_class(QClass::Angle), yaw: yaw.to_class(QClass::Angle) }
    }
}

/// Q = q_z(yaw) ⊗ q_y(pitch) ⊗ q_x(roll), the inverse of [`EulerExtractor::extract`] (radians).
pub fn euler_to_quat<T: Scalar>(yaw: T, pitch: T, roll: T) -> Quat<T> {
    let two: T = lit(2.0);
    let (sy, cy) = ((yaw / two).sin(), (yaw / two).cos());
    let (sp, cp) = ((pitch / two).sin(), (pitch / two).cos());
    let (sr, cr) = ((roll / two).sin(), (roll / two).cos());
    [cy * cp * cr + sy * sp * sr, cy * cp * sr - sy * sp * cr, cy * sp * cr + sy * cp * sr, sy * cp * cr - cy * sp * sr]
        .map(|x| x.to_class(QClass::Quat))
}

#[cfg(test)]
mod tests {
    use super::super::quat::dcm;
    use super::*;

    const D: f64 = std::f64::consts::PI / 180.0;

    fn tables() -> EulerExtractor<f64> {
        EulerExtractor::new(Euler::PublishedTables, 1e-6)
    }

    /// A T matrix with only the elements the tables read set.
    fn with(t32: f64, t33: f64, t21: f64, t11: f64) -> Mat3<f64> {
        [[t11, 0.0, 0.0], [t21, 0.0, 0.0], [0.0, t32, t33]]
    }

    #[test]
    fn roll_table_every_row() {
        let e = tables();
        let roll = |t32: f64, t33: f64| e.extract(&with(t32, t33, 0.0, 1.0)).roll / D;
        assert_eq!(roll(0.5, 1e-7), 90.0, "T33 → 0, T32 +");
        assert_eq!(roll(-0.5, -1e-7), -90.0, "T33 → 0, T32 −");
        assert!((roll(0.5, 0.5) - 45.0).abs() < 1e-12, "+ +");
        assert!((roll(-0.5, 0.5) + 45.0).abs() < 1e-12, "+ −");
        assert!((roll(0.5, -0.5) - 135.0).abs() < 1e-12, "− +");
        assert!((roll(-0.5, -0.5) + 135.0).abs() < 1e-12, "− −");
        assert!((roll(0.0, -1.0) - 180.0).abs() < 1e-12, "upside down: +180, not −180");
        // Just above the threshold the principal-value rows apply.
        assert!((roll(0.5, 2e-6) - (0.5f64 / 2e-6).atan() / D).abs() < 1e-12);
    }

    #[test]
    fn yaw_table_every_row() {
        let e = tables();
        let yaw = |t21: f64, t11: f64| e.extract(&with(0.0, 1.0, t21, t11)).yaw / D;
        assert_eq!(yaw(0.5, 1e-7), 90.0, "T11 → 0, T21 +");
        assert_eq!(yaw(-0.5, -1e-7), 270.0, "T11 → 0, T21 −");
        assert!((yaw(0.5, 0.5) - 45.0).abs() < 1e-12, "+ +");
        assert!((yaw(-0.5, 0.5) - 315.0).abs() < 1e-12, "+ −");
        assert!((yaw(0.5, -0.5) - 135.0).abs() < 1e-12, "− +");
        assert!((yaw(-0.5, -0.5) - 225.0).abs() < 1e-12, "− −");
        assert_eq!(yaw(0.0, 1.0), 0.0);
    }

    #[test]
    fn zero_threshold_differs_from_atan2() {
        // T33 = 5e-7 > 0 with T32 = 1e-6: the table says 90°, atan2 says 63.4°.
        let m = with(1e-6, 5e-7, 0.0, 1.0);
        assert_eq!(tables().extract(&m).roll / D, 90.0);
        let a = EulerExtractor::<f64>::new(Euler::Atan2, 1e-6).extract(&m).roll / D;
        assert!((a - 63.434_948_822_922_01).abs() < 1e-9);
    }

    #[test]
    fn round_trips_through_quaternion_in_every_sector() {
        let tables = tables();
        let atan2 = EulerExtractor::<f64>::new(Euler::Atan2, 1e-6);
        for yaw in (0..360).step_by(15) {
            for pitch in (-85..=85).step_by(17) {
                for roll in (-175..=180).step_by(25) {
                    let (y, p, r) = (yaw as f64 * D + 0.1, pitch as f64 * D, roll as f64 * D);
                    let q = euler_to_quat(y, p, r);
                    let t = dcm(&q);
                    for e in [&tables, &atan2] {
                        let a = e.extract(&t);
                        assert!((a.pitch - p).abs() < 1e-12, "pitch {yaw} {pitch} {roll}");
                        assert!((a.roll - r).abs() < 1e-12, "roll {yaw} {pitch} {roll}: {}", a.roll / D);
                        assert!((a.yaw - y).abs() < 1e-12, "yaw {yaw} {pitch} {roll}");
                        let back = euler_to_quat(a.yaw, a.pitch, a.roll);
                        let dot: f64 = (0..4).map(|i| back[i] * q[i]).sum();
                        assert!((dot.abs() - 1.0).abs() < 1e-14);
                    }
                }
            }
        }
    }

    #[test]
    fn zero_rows_reached_from_real_attitudes() {
        // Roll ±90° makes T33 = cos θ cos φ ≈ 6e-17 and yaw 90°/270° makes T11 ≈ 6e-17: the "→0" rows
        // return the exact table angles.
        let e = tables();
        for (roll, yaw) in [(90.0, 90.0), (-90.0, 270.0)] {
            let a = e.extract(&dcm(&euler_to_quat(yaw * D, 0.2, roll * D)));
            assert_eq!((a.roll / D, a.yaw / D), (roll, yaw));
            assert!((a.pitch - 0.2).abs() < 1e-12);
        }
    }

    #[test]
    fn iq_tables_hold_the_ratio_in_the_angle_class() {
        use crate::numerics::iq::count_overflows;
        use crate::numerics::{Iq, Scalar};
        let e = EulerExtractor::<Iq>::new(Euler::PublishedTables, 1e-6);
        let iq = |m: Mat3<f64>| m.map(|r| r.map(|x| Iq::from_f64(x, QClass::Quat)));
        // Roll 80°: T32/T33 = 5.67, beyond Q30's ±2 (which would give atan 2 = 63.4°), inside Q24's ±128.
        let (roll, ratio_roll) = (80f64.to_radians(), 89.9f64.to_radians());
        let (a, n) = count_overflows(|| e.extract(&iq(with(roll.sin(), roll.cos(), 0.0, 1.0))));
        assert_eq!(n, 0);
        // Error: T32, T33 truncated in Q30 (≤ 2⁻³⁰ each, ≈ 1e-8 rad), the ratio rounded and atan truncated
        // in Q24 (≤ 2⁻²⁴ each).
        assert!((a.roll.to_f64() - roll).abs() < 2.0 * 2f64.powi(-24), "{}", a.roll.to_f64().to_degrees());
        // 89.9°: the ratio 573 saturates at 128 → atan(128) = 89.55°, the documented limit.
        let (a, n) = count_overflows(|| e.extract(&iq(with(ratio_roll.sin(), ratio_roll.cos(), 0.0, 1.0))));
        assert_eq!(n, 1, "the ratio saturated");
        assert!((a.roll.to_f64() - 128f64.atan()).abs() < 2f64.powi(-23));
    }

    #[test]
    fn convention_matches_the_published_matrix() {
        // Eq. 2-7 element by element.
        let (y, p, r) = (0.7, -0.4, 2.1);
        let t = dcm(&euler_to_quat(y, p, r));
        let (sy, cy, sp, cp, sr, cr) = (y.sin(), y.cos(), p.sin(), p.cos(), r.sin(), r.cos());
        let expected = [
            [cp * cy, sp * cy * sr - sy * cr, sp * cy * cr + sy * sr],
            [cp * sy, sp * sy * sr + cy * cr, sp * sy * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ];
        for i in 0..3 {
            for j in 0..3 {
                assert!((t[i][j] - expected[i][j]).abs() < 1e-15, "T{}{}", i + 1, j + 1);
            }
        }
    }
}
