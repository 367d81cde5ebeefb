//! Initial attitude `level`: at rest the accelerometer measures f^b = C_n^b [0, 0, γ], i.e.
//! γ·[T31, T32, T33], so with T31 = −sin θ, T32 = cos θ sin φ, T33 = cos θ cos φ:
//! θ = atan2(−f_x, √(f_y² + f_z²)), φ = atan2(f_y, f_z) (no division by γ, exact at any tilt);
//! yaw comes from the profile (`initial_yaw_deg`), since a level accelerometer cannot see it.

use super::euler::euler_to_quat;
use super::{lit, Quat, Vec3};
use crate::numerics::{QClass, Scalar};
use crate::{Error, Result};

/// Q from an averaged specific force (m/s², body axes) and a yaw (rad).
pub fn level_attitude<T: Scalar>(f_mean: &Vec3<T>, yaw: T) -> Quat<T> {
    let [fx, fy, fz] = *f_mean;
    let pitch = (-fx).atan2((fy * fy + fz * fz).sqrt()).to_class(QClass::Angle);
    let roll = fy.atan2(fz).to_class(QClass::Angle);
    euler_to_quat(yaw, pitch, roll)
}

/// Accumulates accelerometer samples over the still period, then averages them (sum, then one
/// division by the count per axis, as a firmware loop would).
#[derive(Debug, Clone, Copy)]
pub struct LevelAligner<T> {
    sum: Vec3<T>,
    count: u32,
}

impl<T: Scalar> Default for LevelAligner<T> {
    fn default() -> Self {
        LevelAligner { sum: [lit(0.0); 3], count: 0 }
    }
}

impl<T: Scalar> LevelAligner<T> {
    /// Add one specific-force sample.
    pub fn add(&mut self, f_b: &Vec3<T>) {
        for (s, f) in self.sum.iter_mut().zip(f_b) {
            *s = (*s + *f).to_class(QClass::Accel);
        }
        self.count += 1;
    }

    /// Samples accumulated so far.
    pub fn count(&self) -> u32 {
        self.count
    }

    /// The average specific force; an error before the first sample.
    pub fn mean(&self) -> Result<Vec3<T>> {
        if self.count == 0 {
            return Err(Error::Config(
                "level alignment: no accelerometer sample in the still period (firmware.alignment_s too short)".into(),
            ));
        }
        let n = T::from_i32(self.count as i32, QClass::Generic);
        Ok(self.sum.map(|s| (s / n).to_class(QClass::Accel)))
    }
}

#[cfg(test)]
mod tests {
    use super::super::euler::EulerExtractor;
    use super::super::quat::dcm;
    use super::*;
    use crate::profile::Euler;

    #[test]
    fn level_recovers_pitch_and_roll_at_any_tilt() {
        let e = EulerExtractor::<f64>::new(Euler::Atan2, 1e-6);
        for (p, r) in [(0.0, 0.0), (0.3, -0.2), (-1.2, 2.5), (1.4, -3.0)] {
            let t = dcm(&euler_to_quat(0.7, p, r));
            let g = 9.8;
            // f^b = C_n^b [0, 0, g] = g·(third row of T).
            let f = [t[2][0] * g, t[2][1] * g, t[2][2] * g];
            let mut al = LevelAligner::default();
            for _ in 0..125 {
                al.add(&f);
            }
            let q = level_attitude(&al.mean().unwrap(), 1.1);
            let a = e.extract(&dcm(&q));
            assert!((a.pitch - p).abs() < 1e-12 && (a.roll - r).abs() < 1e-12 && (a.yaw - 1.1).abs() < 1e-12);
        }
        assert!(LevelAligner::<f64>::default().mean().is_err());
    }
}
