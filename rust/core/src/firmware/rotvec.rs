//! The rotation-vector update with 1-, 2- or 3-sample coning correction (algorithms.md §1).
//!
//! Angle increments Δθᵢ over N sub-intervals h = T/N come from the rate samples at the sub-interval
//! boundaries by the profile's rule: trapezoid Δθᵢ = (ωᵢ₋₁ + ωᵢ)·h/2, or rectangle Δθᵢ = ωᵢ·h (end
//! rate). The rotation vector is
//! - 1 sample: Φ = Δθ + (1/12) Δθₖ₋₁ × Δθ (previous-interval correction; none on the first step),
//! - 2 samples: Φ = Δθ₁ + Δθ₂ + (2/3) Δθ₁ × Δθ₂,
//! - 3 samples: Φ = ΣΔθᵢ + (9/20) Δθ₁ × Δθ₃ + (27/40) Δθ₂ × (Δθ₃ − Δθ₁),
//!
//! and Q ← Q ⊗ q(Φ), q(Φ) = [cos(φ/2), (Φ/φ) sin(φ/2)].

use super::attitude::{wrong_count, AttitudeUpdate, StepInputs};
use super::quat::{normalise, quat_mul};
use super::{lit, Mat3, Quat, Vec3};
use crate::numerics::{QClass, Scalar};
use crate::profile::IncrementRule;
use crate::{Error, Result};

/// The rotation-vector update with N coning samples over a step of T seconds: N+1 rate samples
/// t, t+T/N, …, t+T per update.
#[derive(Debug, Clone)]
pub struct RotationVector<T> {
    coning_samples: usize,
    increment_rule: IncrementRule,
    /// The step T as the firmware holds it (the earth-rate correction's ζ = ω_in·T).
    t1: T,
    /// The sub-interval h = T/N.
    sub_interval: T,
    /// Δθₖ₋₁, the previous step's last increment (the 1-sample correction).
    previous_increment: Option<Vec3<T>>,
}

impl<T: Scalar> RotationVector<T> {
    /// The update with `coning_samples` (1, 2 or 3) sub-intervals of a `step_s` step.
    pub fn new(coning_samples: usize, increment_rule: IncrementRule, step_s: f64) -> Self {
        RotationVector {
            coning_samples,
            increment_rule,
            t1: lit(step_s),
            sub_interval: lit(step_s / coning_samples as f64),
            previous_increment: None,
        }
    }

    /// The update from angle increments (rad) over the N sub-intervals: Q ← q(−ζ) ⊗ Q ⊗ q(Φ). The
    /// earth-rate correction is the navigation frame's own rotation over the step, ζ = ω_in^n·T,
    /// applied on the navigation side (C_{n(k)}^{n(k+1)} ≈ I − [ζ×]).
    pub fn step_increments(&mut self, q: &mut Quat<T>, dtheta: &[Vec3<T>], nav_rate: Option<Vec3<T>>) -> Result<()> {
        if dtheta.len() != self.coning_samples {
            return Err(Error::Config(format!(
                "rotation vector: {} angle increments, firmware.coning_samples = {}",
                dtheta.len(),
                self.coning_samples
            )));
        }
        let previous = if self.coning_samples == 1 { self.previous_increment.as_ref() } else { None };
        let phi = coning_vector(dtheta, previous)?;
        self.previous_increment = Some(dtheta[dtheta.len() - 1]);
        let mut next = quat_mul(q, &quat_from_rotvec(&phi));
        if let Some(w_in) = nav_rate {
            let zeta = w_in.map(|w| (-(w * self.t1)).to_class(QClass::Rate));
            next = quat_mul(&quat_from_rotvec(&zeta), &next);
        }
        normalise(&mut next);
        *q = next;
        Ok(())
    }
}

impl<T: Scalar> AttitudeUpdate<T> for RotationVector<T> {
    fn samples_per_update(&self) -> usize {
        self.coning_samples + 1
    }

    fn step(&mut self, q: &mut Quat<T>, _c_bn: &Mat3<T>, inputs: &StepInputs<'_, T>) -> Result<()> {
        let takes = self.samples_per_update();
        if inputs.rates.len() != takes {
            return Err(wrong_count(inputs.rates.len(), takes, "RotationVector"));
        }
        let mut d = [[lit::<T>(0.0); 3]; 3];
        increments(self.increment_rule, inputs.rates, self.sub_interval, &mut d)?;
        self.step_increments(q, &d[..self.coning_samples], inputs.nav_rate)
    }

    fn restart(&mut self) {
        self.previous_increment = None;
    }
}

/// Below this φ² (rad²) q(Φ) uses its series (cos φ/2 = 1 − φ²/8 + φ⁴/384, sin(φ/2)/φ =
/// ½ − φ²/48 + φ⁴/3840; truncation ≤ φ⁶/46080 = 2e-23 here), which avoids 0/0 and a sqrt.
const SERIES_BELOW_PHI2: f64 = 1e-6;

fn cross<T: Scalar>(a: &Vec3<T>, b: &Vec3<T>) -> Vec3<T> {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// Angle increments from `rates` (N+1 samples at the sub-interval boundaries, t … t+T) over
/// sub-intervals of `h` seconds, written to `out[..N]`. Rectangle ignores `rates[0]`.
pub fn increments<T: Scalar>(rule: IncrementRule, rates: &[Vec3<T>], h: T, out: &mut [Vec3<T>]) -> Result<()> {
    let n = rates.len().saturating_sub(1);
    if n == 0 || out.len() < n {
        return Err(Error::Config(format!(
            "angle increments: {} rate samples for {} increments, expected N+1 samples for N ≤ {} increments",
            rates.len(),
            out.len(),
            out.len()
        )));
    }
    let two: T = lit(2.0);
    for i in 0..n {
        for k in 0..3 {
            let d = match rule {
                IncrementRule::Trapezoid => (rates[i][k] + rates[i + 1][k]) * h / two,
                IncrementRule::Rectangle => rates[i + 1][k] * h,
            };
            out[i][k] = d.to_class(QClass::Rate);
        }
    }
    Ok(())
}

/// The rotation vector from 1, 2 or 3 increments (`previous` = Δθₖ₋₁ for the 1-sample correction).
pub fn coning_vector<T: Scalar>(dtheta: &[Vec3<T>], previous: Option<&Vec3<T>>) -> Result<Vec3<T>> {
    let add = |a: Vec3<T>, b: Vec3<T>| [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
    let scale = |c: T, a: Vec3<T>| [c * a[0], c * a[1], c * a[2]];
    let phi = match dtheta {
        [d] => match previous {
            Some(p) => add(*d, scale(lit(1.0 / 12.0), cross(p, d))),
            None => *d,
        },
        [d1, d2] => add(add(*d1, *d2), scale(lit(2.0 / 3.0), cross(d1, d2))),
        [d1, d2, d3] => {
            let sum = add(add(*d1, *d2), *d3);
            let diff = [d3[0] - d1[0], d3[1] - d1[1], d3[2] - d1[2]];
            add(add(sum, scale(lit(9.0 / 20.0), cross(d1, d3))), scale(lit(27.0 / 40.0), cross(d2, &diff)))
        }
        _ => {
            return Err(Error::Config(format!(
                "rotation vector: {} angle increments, expected 1, 2 or 3 (firmware.coning_samples)",
                dtheta.len()
            )))
        }
    };
    Ok(phi.map(|x| x.to_class(QClass::Rate)))
}

/// q(Φ) = [cos(φ/2), (Φ/φ) sin(φ/2)], by series for small φ.
pub fn quat_from_rotvec<T: Scalar>(phi: &Vec3<T>) -> Quat<T> {
    let phi2 = phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2];
    let (c, s) = if phi2 < lit(SERIES_BELOW_PHI2) {
        let phi4 = phi2 * phi2;
        let c = lit::<T>(1.0) - phi2 / lit(8.0) + phi4 / lit(384.0);
        let s = lit::<T>(0.5) - phi2 / lit(48.0) + phi4 / lit(3840.0);
        (c, s)
    } else {
        let angle = phi2.sqrt();
        let half = angle / lit(2.0);
        (half.cos(), half.sin() / angle)
    };
    [c, phi[0] * s, phi[1] * s, phi[2] * s].map(|x| x.to_class(QClass::Quat))
}

#[cfg(test)]
mod tests {
    use super::super::quat::tests::{angle_between, rotvec_quat};
    use super::*;

    #[test]
    fn series_and_closed_form_agree_at_the_switch() {
        for a in [0.99e-3, 1.01e-3, 1e-6, 0.3] {
            let v = [a * 0.6, -a * 0.8, 0.0];
            let q = quat_from_rotvec(&v);
            let r = rotvec_quat(v);
            for i in 0..4 {
                assert!((q[i] - r[i]).abs() < 1e-17 + 1e-16 * r[i].abs(), "{a} {i}");
            }
        }
        assert_eq!(quat_from_rotvec(&[0.0; 3]), [1.0, 0.0, 0.0, 0.0]);
    }

    #[test]
    fn increments_rules() {
        let rates = [[0.0, 1.0, 2.0], [2.0, 3.0, 4.0], [4.0, 5.0, 6.0]];
        let mut out = [[0.0; 3]; 3];
        increments(IncrementRule::Trapezoid, &rates, 0.5, &mut out).unwrap();
        assert_eq!(&out[..2], &[[0.5, 1.0, 1.5], [1.5, 2.0, 2.5]]);
        increments(IncrementRule::Rectangle, &rates, 0.5, &mut out).unwrap();
        assert_eq!(&out[..2], &[[1.0, 1.5, 2.0], [2.0, 2.5, 3.0]]);
        assert!(increments(IncrementRule::Rectangle, &rates[..1], 0.5, &mut out).is_err());
        assert!(coning_vector::<f64>(&[[0.0; 3]; 4], None).is_err());
    }

    #[test]
    fn constant_rate_is_exact() {
        // No coning: every correction term vanishes and Q ⊗ q(Φ) is the exact rotation.
        let w = [0.3, -0.5, 0.7];
        let mut q = [1.0, 0.0, 0.0, 0.0];
        let h = 0.004;
        for _ in 0..7500 {
            let d = w.map(|x| x * h);
            let phi = coning_vector(&[d, d], None).unwrap();
            q = super::super::quat::quat_mul(&q, &quat_from_rotvec(&phi));
        }
        let truth = rotvec_quat(w.map(|x| x * 60.0));
        assert!(angle_between(&truth, &q) < 1e-9);
    }
}
