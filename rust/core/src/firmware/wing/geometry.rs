//! Zero acquisition (A), the hinge angle from a level attitude, the static axis (B1) and the dynamic
//! axis (B2). Module docs: `wing/mod.rs`.

use super::super::align::{level_attitude, LevelAligner};
use super::super::quat::quat_mul;
use super::super::{lit, Quat, Vec3};
use crate::numerics::{QClass, Scalar};
use crate::{Error, Result};

pub(crate) fn dot<T: Scalar>(a: &Vec3<T>, b: &Vec3<T>) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(crate) fn cross<T: Scalar>(a: &Vec3<T>, b: &Vec3<T>) -> Vec3<T> {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

pub(crate) fn conj<T: Scalar>(q: &Quat<T>) -> Quat<T> {
    [q[0], -q[1], -q[2], -q[3]]
}

fn normalised<T: Scalar>(v: &Vec3<T>) -> Vec3<T> {
    let n = dot(v, v).sqrt();
    v.map(|x| (x / n).to_class(QClass::Quat))
}

/// The unit up vector in body axes from a specific force at rest (f^b = C_n^b [0, 0, g]).
pub fn up_vector<T: Scalar>(f: &Vec3<T>) -> Vec3<T> {
    normalised(f)
}

/// Samples of white noise σ (per sample) to average down to `target`: ⌈(σ/target)²⌉, at least 1.
/// σ is the accelerometer's per-sample noise with its quantisation (LSB²/12 added in quadrature).
pub fn samples_needed(sigma: f64, target: f64) -> u32 {
    ((sigma / target).powi(2).ceil() as u32).max(1)
}

/// The zero pose: r → w (level, yaw 0), the up vector in r axes, and the mean gyro at rest (the
/// gyro bias with the earth rate in it, rad/s).
#[derive(Debug, Clone, Copy)]
pub struct WingZero<T> {
    /// q_w^r: r → w.
    pub q_wr: Quat<T>,
    /// The up vector in r (body-at-zero) axes.
    pub up_r: Vec3<T>,
    /// The mean gyro over the zero acquisition, rad/s.
    pub gyro_mean: Vec3<T>,
}

/// (A) Zero acquisition at rest: sums accelerometer and gyro samples; the zero is given only after
/// enough samples to average the accelerometer's noise to the target.
#[derive(Debug, Clone)]
pub struct ZeroAcquisition<T> {
    accel: LevelAligner<T>,
    gyro: LevelAligner<T>,
    needed: u32,
    sigma: f64,
    target: f64,
}

impl<T: Scalar> ZeroAcquisition<T> {
    /// A zero acquisition for per-sample accelerometer noise `sigma` and a target `target` (same unit,
    /// e.g. m/s²): it waits [`samples_needed`] samples.
    pub fn new(sigma: f64, target: f64) -> Result<Self> {
        if !(sigma >= 0.0 && sigma.is_finite() && target > 0.0 && target.is_finite()) {
            return Err(Error::Config(format!(
                "wing zero acquisition: accelerometer noise {sigma} and target {target}; expected noise ≥ 0 and target > 0"
            )));
        }
        let needed = samples_needed(sigma, target);
        Ok(ZeroAcquisition { accel: LevelAligner::default(), gyro: LevelAligner::default(), needed, sigma, target })
    }

    /// Add one sample at rest: gyro (rad/s) and specific force (m/s²).
    pub fn add(&mut self, w: &Vec3<T>, f: &Vec3<T>) {
        self.accel.add(f);
        self.gyro.add(w);
    }

    /// Samples the zero needs.
    pub fn needed(&self) -> u32 {
        self.needed
    }

    /// Samples added so far.
    pub fn count(&self) -> u32 {
        self.accel.count()
    }

    /// The zero; an error (saying how long it must wait) before [`ZeroAcquisition::needed`] samples.
    pub fn zero(&self) -> Result<WingZero<T>> {
        if self.count() < self.needed {
            return Err(Error::Config(format!(
                "wing zero acquisition: {} of {} samples at rest; averaging the accelerometer's per-sample \
                 noise {:.3e} down to {:.3e} takes (σ/target)² = {} samples",
                self.count(),
                self.needed,
                self.sigma,
                self.target,
                self.needed
            )));
        }
        let f = self.accel.mean()?;
        Ok(WingZero {
            q_wr: level_attitude(&f, lit(0.0)),
            up_r: up_vector(&f),
            gyro_mean: self.gyro.mean()?.map(|x| x.to_class(QClass::Rate)),
        })
    }
}

/// The hinge angle α (rad, (−π, π]) of a body whose level attitude is `q_nb` (b → a level frame, any
/// yaw), for the zero `q_wr` and the axis `axis` (unit, r axes).
///
/// q_wr ⊗ (cos(α/2) + a sin(α/2)) ⊗ q_nb* = c·P + s·S with P = q_wr ⊗ q_nb*, S = q_wr ⊗ [0, a] ⊗ q_nb*
/// (c, s of α/2); J(α) = (c·P_x + s·S_x)² + (c·P_y + s·S_y)² = A11 c² + 2 A12 c s + A22 s², whose minimum is
/// at α = atan2(−2 A12, A22 − A11): the notes' "α minimising J", in closed form. Ideal inputs make
/// J(α_true) = 0, so this is α_true up to rounding. With the axis vertical (β = 90°) J is 0 for every α.
pub fn hinge_angle<T: Scalar>(q_wr: &Quat<T>, axis: &Vec3<T>, q_nb: &Quat<T>) -> T {
    let q_bn = conj(q_nb);
    let p = quat_mul(q_wr, &q_bn);
    let s = quat_mul(&quat_mul(q_wr, &[lit(0.0), axis[0], axis[1], axis[2]]), &q_bn);
    let a11 = p[1] * p[1] + p[2] * p[2];
    let a22 = s[1] * s[1] + s[2] * s[2];
    let a12 = p[1] * s[1] + p[2] * s[2];
    (-(lit::<T>(2.0) * a12)).atan2(a22 - a11).to_class(QClass::Angle)
}

/// (B1) The hinge axis (unit, r axes) from the up vector at the zero (`up_r`) and at rest poses
/// (`poses`, body axes), by least squares: the unit a minimising Σ (a·(u₀ − u_k))², the eigenvector of
/// M = Σ d_k d_kᵀ with the smallest eigenvalue (found by power iteration on adj(M), whose largest
/// eigenvalue λ₂λ₃ belongs to it). Sign: the first pose is at a positive α (a·(u₁ × u₀) > 0).
/// Needs two poses whose differences are not parallel.
pub fn static_axis<T: Scalar>(up_r: &Vec3<T>, poses: &[Vec3<T>]) -> Result<Vec3<T>> {
    if poses.len() < 2 {
        return Err(Error::Config(format!(
            "wing static axis: {} rest pose(s) besides the zero; the least squares takes at least 2",
            poses.len()
        )));
    }
    let n: T = T::from_i32(poses.len() as i32, QClass::Generic);
    let mut m = [[lit::<T>(0.0); 3]; 3];
    for u in poses {
        let d = [0, 1, 2].map(|i| up_r[i] - u[i]);
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] = m[i][j] + d[i] * d[j] / n;
            }
        }
    }
    // adj(M) (M symmetric): the cofactors.
    let c = |r0: usize, r1: usize, c0: usize, c1: usize| m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0];
    let adj = [
        [c(1, 2, 1, 2), -c(0, 2, 1, 2), c(0, 1, 1, 2)],
        [-c(1, 2, 0, 2), c(0, 2, 0, 2), -c(0, 1, 0, 2)],
        [c(1, 2, 0, 1), -c(0, 2, 0, 1), c(0, 1, 0, 1)],
    ];
    let col = |j: usize| [adj[0][j], adj[1][j], adj[2][j]];
    let mut v = col(0);
    for j in 1..3 {
        if dot(&col(j), &col(j)) > dot(&v, &v) {
            v = col(j);
        }
    }
    let scale = dot(&v, &v);
    let trace2 = (m[0][0] + m[1][1] + m[2][2]) * (m[0][0] + m[1][1] + m[2][2]);
    // The poses span one direction only (adj(M) ≈ 0 relative to M's size): no axis.
    let limit = 1e-24 * trace2.to_f64() * trace2.to_f64();
    if !matches!(scale.to_f64().partial_cmp(&limit), Some(std::cmp::Ordering::Greater)) {
        return Err(Error::Config(
            "wing static axis: the rest poses' up vectors differ along one direction only (all poses on one \
             great circle through the zero's up vector); give poses at different angles"
                .into(),
        ));
    }
    let mut a = normalised(&v);
    for _ in 0..8 {
        let next = [0, 1, 2].map(|i| dot(&adj[i], &a));
        a = normalised(&next);
    }
    if dot(&a, &cross(&poses[0], up_r)) < lit(0.0) {
        a = a.map(|x| -x);
    }
    Ok(a)
}

/// The rotation axis of `q` (unit vector part, with q0 ≥ 0 so the angle is in [0, π]); `None` for a
/// zero vector part.
pub fn axis_of_rotation<T: Scalar>(q: &Quat<T>) -> Option<Vec3<T>> {
    let v = [q[1], q[2], q[3]];
    let v = if q[0] < lit(0.0) { v.map(|x| -x) } else { v };
    if dot(&v, &v) > lit(0.0) {
        Some(normalised(&v))
    } else {
        None
    }
}

/// (B2) The hinge axis from gyro-integrated rotations q_rb: their vector parts summed, each turned to
/// point along the running sum (or a reference axis), counted only beyond a minimum angle. The sum
/// weights each by sin(α/2), the inverse of its error's growth.
#[derive(Debug, Clone, Copy)]
pub struct DynamicAxis<T> {
    sum: Vec3<T>,
    reference: Option<Vec3<T>>,
    min_sin_half: T,
    count: u32,
}

impl<T: Scalar> DynamicAxis<T> {
    /// Count rotations beyond `min_angle` (rad); `reference` fixes the sign (else the first rotation).
    pub fn new(min_angle: f64, reference: Option<Vec3<T>>) -> Self {
        DynamicAxis { sum: [lit(0.0); 3], reference, min_sin_half: lit((min_angle / 2.0).sin()), count: 0 }
    }

    /// Add one integrated rotation b(t) → r.
    pub fn add(&mut self, q_rb: &Quat<T>) {
        let v = [q_rb[1], q_rb[2], q_rb[3]];
        let v = if q_rb[0] < lit(0.0) { v.map(|x| -x) } else { v };
        let sin_half = dot(&v, &v).sqrt();
        if sin_half < self.min_sin_half {
            return;
        }
        let toward = self.reference.unwrap_or(self.sum);
        let v = if dot(&v, &toward) < lit(0.0) { v.map(|x| -x) } else { v };
        self.sum = [0, 1, 2].map(|i| self.sum[i] + v[i]);
        self.count += 1;
    }

    /// Rotations counted.
    pub fn count(&self) -> u32 {
        self.count
    }

    /// The axis (unit, r axes), once a rotation was counted.
    pub fn axis(&self) -> Option<Vec3<T>> {
        if self.count == 0 {
            None
        } else {
            Some(normalised(&self.sum))
        }
    }
}
