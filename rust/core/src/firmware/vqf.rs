//! A VQF-class attitude filter (after Laidig & Seel, "VQF: Highly accurate IMU orientation estimation
//! with bias estimation and magnetic disturbance rejection", Information Fusion 91, 2023; written here
//! from the method's description, in this firmware's frames: navigation x east, y north, z up; q = C_b^n).
//!
//! The attitude is the product of three parts, q = R_z(δ) ⊗ q_acc ⊗ q_gyr:
//! 1. Strapdown: q_gyr ← q_gyr ⊗ exp(½(ω̄ − b̂)T), ω̄ the mean of the update's two rate samples, b̂ the
//!    bias estimate. q_gyr maps the body into the "almost-inertial" frame I, which drifts only with the
//!    gyro's errors.
//! 2. Inclination: the specific force in I, a_I = q_gyr ⊗ f ⊗ q_gyr*, is low-passed by a second-order
//!    Butterworth filter of cut-off √2/(2π τ_acc) (`tau_acc_s`): in I the body's rotation does not move
//!    gravity, only accelerations (which average out) and the slow drift of I do. The filtered vector,
//!    taken to the earth-fixed frame E by q_acc and normalised, is turned onto up by the smallest
//!    rotation, which is applied to q_acc (the low-pass is the gain: no other).
//! 3. Heading: the field in E (q6 = q_acc ⊗ q_gyr), if the magnetic gate (`gating.rs`) accepts it, gives
//!    the heading offset δ_m = atan2(m_E,x, m_E,y) that turns its horizontal part north; δ follows it with
//!    the first-order gain k = 1 − exp(−T/τ_mag), multiplied by `mag_recovery_gain` for as long after a
//!    rejection as the rejection lasted; while the field is rejected δ is held and heading runs on the gyro.
//! 4. Gyro bias: a Kalman filter on b̂ (3 states, covariance P, process noise from `bias_forgetting_s`)
//!    with two measurements: at rest (the gyro and the accelerometer stay within `rest_gyro_dps` /
//!    `rest_accel_m_s2` of their low-passes for `rest_min_s`) the low-passed gyro itself (σ_rest); in
//!    motion the inclination correction: a bias error δb turns E by R₆δb (R₆ = C(q6)), which the
//!    correction rate c cancels in its horizontal components, so (R₆b̂ − c̄)_xy measures (R₆b)_xy (σ_motion;
//!    c̄ the correction rate low-passed with τ_acc). b̂ is held within ± `bias_clip_dps`.
//!
//! A gyro axis at full scale (`clip_gain`, `clip_recovery_s`): the low-pass's time constant is divided by
//! `clip_gain` (its coefficients switch to the raised set, its state kept) and the motion bias
//! measurement is not used, from the first clipped update until `clip_recovery_s` after the last.
//!
//! Single precision. The low-pass's poles at 250 Hz and τ_acc = 3 s sit 1.9e-3 inside the unit circle; its
//! numerator coefficients are ≈ 1e-6. Transposed direct form II keeps the two states at the signal's
//! magnitude, so the only rounding that matters is the states' (2⁻²⁴ relative, ≈ 6e-7 m/s² at 1 g): a
//! tilt noise of ≈ 6e-8 rad. `benchmarks/broad_eval.md` measures the parity on the BROAD trials.

use super::attitude::{wrong_count, AttitudeUpdate, StepInputs};
use super::gating::{ClipGuard, ClipState, Events, MagGate, RestDetector};
use super::quat::{dcm, normalise, quat_mul};
use super::{lit, Mat3, Quat, Vec3};
use crate::numerics::{QClass, Scalar};
use crate::profile;
use crate::Result;

/// Second-order Butterworth coefficients (b0, b1, b2, a1, a2) for time constant `tau` at step `t`
/// (bilinear transform, cut-off √2/(2π τ), pre-warped).
fn butterworth(tau: f64, t: f64) -> [f64; 5] {
    let fc = std::f64::consts::SQRT_2 / (2.0 * std::f64::consts::PI * tau);
    let k = (std::f64::consts::PI * fc * t).tan();
    let norm = 1.0 / (1.0 + std::f64::consts::SQRT_2 * k + k * k);
    let b0 = k * k * norm;
    [b0, 2.0 * b0, b0, 2.0 * (k * k - 1.0) * norm, (1.0 - std::f64::consts::SQRT_2 * k + k * k) * norm]
}

/// A three-axis second-order low-pass in transposed direct form II.
#[derive(Debug, Clone)]
struct LowPass<T> {
    normal: [T; 5],
    raised: [T; 5],
    /// Per axis (s1, s2); None until the first sample (which sets the steady state).
    state: Option<[[T; 2]; 3]>,
}

impl<T: Scalar> LowPass<T> {
    fn new(tau: f64, raised_tau: f64, t: f64) -> Self {
        let c = |tau: f64| butterworth(tau, t).map(|x| T::from_f64(x, QClass::Generic));
        LowPass { normal: c(tau), raised: c(raised_tau), state: None }
    }

    fn step(&mut self, x: &Vec3<T>, raised: bool) -> Vec3<T> {
        let [b0, b1, b2, a1, a2] = if raised { self.raised } else { self.normal };
        // At the first sample, the state of a filter that has seen x for ever (output x).
        let state = self.state.get_or_insert_with(|| {
            x.map(|xi| [(xi - b0 * xi).to_class(QClass::Accel), (b2 * xi - a2 * xi).to_class(QClass::Accel)])
        });
        let mut y = *x;
        for i in 0..3 {
            let [s1, s2] = state[i];
            let yi = (b0 * x[i] + s1).to_class(QClass::Accel);
            state[i] =
                [(b1 * x[i] - a1 * yi + s2).to_class(QClass::Accel), (b2 * x[i] - a2 * yi).to_class(QClass::Accel)];
            y[i] = yi;
        }
        y
    }
}

/// The VQF-class update and its state.
#[derive(Debug, Clone)]
pub struct Vqf<T> {
    dt: T,
    /// Body → I (strapdown); None until the first update: taken from the firmware's attitude.
    q_gyr: Option<Quat<T>>,
    /// I → E (inclination correction).
    q_acc: Quat<T>,
    /// E → N: heading offset, rad.
    delta: T,
    acc_lp: LowPass<T>,
    bias: Vec3<T>,
    /// Bias covariance, (rad/s)².
    p: Mat3<T>,
    /// Process noise added to P's diagonal each update.
    q_bias: T,
    r_rest: T,
    r_motion: T,
    bias_clip: T,
    rest_bias: bool,
    motion_bias: bool,
    /// Low-passed correction rate in E (rad/s), first order, coefficient `corr_alpha`.
    corr_lp: Vec3<T>,
    corr_alpha: T,
    /// Rest detection: first-order low-passes of gyro and accelerometer, coefficient `rest_alpha`.
    rest_gyr_lp: Option<Vec3<T>>,
    rest_acc_lp: Option<Vec3<T>>,
    rest_alpha: T,
    rest_th_gyr2: T,
    rest_th_acc2: T,
    rest_steps: u32,
    rest_count: u32,
    magnetometer: bool,
    k_mag: T,
    k_mag_raised: T,
    /// Updates of raised heading gain left (after a rejection).
    mag_raised_left: u32,
    mag_gate: MagGate<T>,
    mag_rest: RestDetector<T>,
    clip: ClipGuard,
    events: Events,
}

impl<T: Scalar> Vqf<T> {
    /// The update of a `[firmware.vqf]` and a `[firmware.mag_gate]` section (`g` the firmware's g, m/s²)
    /// for updates of `step_s` seconds.
    pub fn new(p: &profile::Vqf, gate: &profile::MagGate, g: f64, step_s: f64) -> Self {
        let zero = T::from_f64(0.0, QClass::Quat);
        let sigma0 = p.bias_sigma_init_dps.to_radians();
        let z3 = [zero; 3];
        let mut p0 = [z3; 3];
        for (i, row) in p0.iter_mut().enumerate() {
            row[i] = T::from_f64(sigma0 * sigma0, QClass::Generic);
        }
        let g2 = |x: f64| T::from_f64(x * x, QClass::Generic);
        Vqf {
            dt: lit(step_s),
            q_gyr: None,
            q_acc: [lit(1.0), zero, zero, zero],
            delta: T::from_f64(0.0, QClass::Angle),
            acc_lp: LowPass::new(p.tau_acc_s, p.tau_acc_s / p.clip_gain, step_s),
            bias: z3,
            p: p0,
            q_bias: T::from_f64(sigma0 * sigma0 * step_s / p.bias_forgetting_s, QClass::Generic),
            r_rest: g2(p.bias_sigma_rest_dps.to_radians()),
            r_motion: g2(p.bias_sigma_motion_dps.to_radians()),
            bias_clip: T::from_f64(p.bias_clip_dps.to_radians(), QClass::Rate),
            rest_bias: p.rest_bias,
            motion_bias: p.motion_bias,
            corr_lp: z3,
            corr_alpha: T::from_f64(1.0 - (-step_s / p.tau_acc_s).exp(), QClass::Quat),
            rest_gyr_lp: None,
            rest_acc_lp: None,
            rest_alpha: T::from_f64(1.0 - (-step_s / p.rest_tau_s).exp(), QClass::Quat),
            rest_th_gyr2: g2(p.rest_gyro_dps.to_radians()),
            rest_th_acc2: g2(p.rest_accel_m_s2),
            rest_steps: (p.rest_min_s / step_s).round().max(1.0) as u32,
            rest_count: 0,
            magnetometer: p.magnetometer,
            k_mag: T::from_f64(1.0 - (-step_s / p.tau_mag_s).exp(), QClass::Quat),
            k_mag_raised: T::from_f64((1.0 - (-step_s / p.tau_mag_s).exp()) * p.mag_recovery_gain, QClass::Quat),
            mag_raised_left: 0,
            mag_gate: MagGate::new(gate, step_s),
            mag_rest: RestDetector::new(gate, g, step_s),
            clip: ClipGuard::new(p.clip_recovery_s, step_s),
            events: Events::new(),
        }
    }

    /// The gyro bias estimate, rad/s.
    pub fn bias(&self) -> Vec3<T> {
        self.bias
    }

    /// Whether the last update saw rest.
    pub fn at_rest(&self) -> bool {
        self.rest_count >= self.rest_steps
    }

    /// Rest detection on the raw gyro and specific force (deviation from their low-passes).
    fn rest_update(&mut self, w: &Vec3<T>, f: &Vec3<T>) -> bool {
        let a = self.rest_alpha;
        let lp = |state: &mut Option<Vec3<T>>, x: &Vec3<T>, class| -> T {
            let s = state.get_or_insert(*x);
            for i in 0..3 {
                s[i] = (s[i] + a * (x[i] - s[i])).to_class(class);
            }
            let d = [0, 1, 2].map(|i| x[i] - s[i]);
            dot(&d, &d).to_class(QClass::Generic)
        };
        let dg = lp(&mut self.rest_gyr_lp, w, QClass::Rate);
        let da = lp(&mut self.rest_acc_lp, f, QClass::Accel);
        if dg < self.rest_th_gyr2 && da < self.rest_th_acc2 {
            self.rest_count = self.rest_count.saturating_add(1);
        } else {
            self.rest_count = 0;
        }
        self.at_rest()
    }

    /// One Kalman measurement update of the bias: z ≈ H b with noise variance `r` on each row.
    fn bias_update<const M: usize>(&mut self, h: &[Vec3<T>; M], z: &[T; M], r: T) {
        let g = |x: T| x.to_class(QClass::Generic);
        // PHᵀ (3×M) and S = HPHᵀ + R (M×M, M ≤ 3; solved by Gauss–Jordan on the small matrix).
        let pht: [[T; M]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| g(dot(&self.p[i], &h[j]))));
        let mut s: [[T; M]; M] = std::array::from_fn(|i| {
            std::array::from_fn(|j| g(h[i][0] * pht[0][j] + h[i][1] * pht[1][j] + h[i][2] * pht[2][j]))
        });
        for (i, row) in s.iter_mut().enumerate() {
            row[i] = g(row[i] + r);
        }
        let innovation: [T; M] = std::array::from_fn(|i| g(z[i] - dot(&h[i], &self.bias)));
        // K = PHᵀ S⁻¹: solve Sᵀ Kᵀ = (PHᵀ)ᵀ; S is symmetric.
        let Some(s_inv) = invert(s) else { return };
        let k: [[T; M]; 3] = std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                g((0..M).fold(T::from_f64(0.0, QClass::Generic), |acc, l| acc + pht[i][l] * s_inv[l][j]))
            })
        });
        for (bias, ki) in self.bias.iter_mut().zip(&k) {
            let db = (0..M).fold(T::from_f64(0.0, QClass::Generic), |acc, j| acc + ki[j] * innovation[j]);
            let b = (*bias + db).to_class(QClass::Rate);
            *bias = if b > self.bias_clip {
                self.bias_clip
            } else if b < -self.bias_clip {
                -self.bias_clip
            } else {
                b
            };
        }
        // P ← P − K H P (H P = (P Hᵀ)ᵀ): the upper triangle, mirrored (rounding must not make P
        // asymmetric: the update assumes it symmetric, and an antisymmetric part is never damped).
        let p = self.p;
        for i in 0..3 {
            for j in i..3 {
                let khp = (0..M).fold(T::from_f64(0.0, QClass::Generic), |acc, l| acc + k[i][l] * pht[j][l]);
                self.p[i][j] = g(p[i][j] - khp);
                self.p[j][i] = self.p[i][j];
            }
        }
    }

    fn step_in_parts(
        &mut self,
        q: &mut Quat<T>,
        inputs: &StepInputs<'_, T>,
        mut mark: impl FnMut(&'static str),
    ) -> Result<()> {
        let (w0, w1) = match inputs.rates {
            [a, b] => (*a, *b),
            other => return Err(wrong_count(other.len(), 2, "VQF")),
        };
        let zero = T::from_f64(0.0, QClass::Quat);
        let one: T = lit(1.0);
        let two: T = lit(2.0);
        let half: T = lit(0.5);
        let raised = self.clip.update(inputs.clipped.gyro, &mut self.events) == ClipState::Raised;
        // 1. Strapdown.
        let w_raw: Vec3<T> = [0, 1, 2].map(|i| ((w0[i] + w1[i]) / two).to_class(QClass::Rate));
        let w: Vec3<T> = [0, 1, 2].map(|i| (w_raw[i] - self.bias[i]).to_class(QClass::Rate));
        let mut q_gyr = match self.q_gyr {
            Some(qg) => qg,
            // The first update: the firmware's attitude is all in q_gyr (E = N, I = E at the start).
            None => *q,
        };
        let angle = dot(&w, &w).sqrt().to_class(QClass::Rate);
        let phi = (angle * self.dt).to_class(QClass::Rate);
        if phi > T::from_f64(0.0, QClass::Rate) {
            let s = (phi * half).sin().to_class(QClass::Quat);
            let c = (phi * half).cos().to_class(QClass::Quat);
            let k = (s / angle).to_class(QClass::Generic);
            let dq = [
                c,
                (w[0] * k).to_class(QClass::Quat),
                (w[1] * k).to_class(QClass::Quat),
                (w[2] * k).to_class(QClass::Quat),
            ];
            q_gyr = quat_mul(&q_gyr, &dq);
            normalise(&mut q_gyr);
        }
        self.q_gyr = Some(q_gyr);
        mark("strapdown");
        // 2. Inclination from the low-passed specific force in I.
        let f_usable = inputs.specific_force.filter(|_| inputs.clipped.accel == 0);
        let mut corr_rate = [zero; 3];
        if let Some(f) = f_usable {
            let a_i = rotate(&dcm(&q_gyr), &f).map(|x| x.to_class(QClass::Accel));
            let a_lp = self.acc_lp.step(&a_i, raised);
            let a_e = rotate(&dcm(&self.q_acc), &a_lp).map(|x| x.to_class(QClass::Accel));
            let n = dot(&a_e, &a_e).sqrt().to_class(QClass::Accel);
            if n > T::from_f64(0.0, QClass::Accel) {
                let a = a_e.map(|x| x.div_to(n, QClass::Quat));
                // The smallest rotation taking a onto up: axis a × e_z = (a_y, −a_x, 0), angle acos a_z.
                let qw = ((a[2] + one) * half).to_class(QClass::Quat).sqrt().to_class(QClass::Quat);
                if qw > T::from_f64(1e-6, QClass::Quat) {
                    let k = (half / qw).to_class(QClass::Generic);
                    let corr = [qw, (a[1] * k).to_class(QClass::Quat), (-a[0] * k).to_class(QClass::Quat), zero];
                    self.q_acc = quat_mul(&corr, &self.q_acc);
                    normalise(&mut self.q_acc);
                    // The correction as a rate in E: 2·(vector part)/T.
                    corr_rate = [corr[1], corr[2], corr[3]].map(|x| (x * two / self.dt).to_class(QClass::Rate));
                }
            }
            let rest = self.rest_update(&w_raw, &f);
            mark("inclination");
            // 4. Bias.
            for i in 0..3 {
                self.p[i][i] = (self.p[i][i] + self.q_bias).to_class(QClass::Generic);
            }
            for (lp, c) in self.corr_lp.iter_mut().zip(corr_rate) {
                *lp = (*lp + self.corr_alpha * (c - *lp)).to_class(QClass::Rate);
            }
            if rest && self.rest_bias {
                let lp = self.rest_gyr_lp.unwrap_or(w_raw);
                let h = [[one, zero, zero], [zero, one, zero], [zero, zero, one]];
                self.bias_update(&h, &lp, self.r_rest);
            } else if self.motion_bias && !raised {
                let r6 = dcm(&quat_mul(&self.q_acc, &q_gyr));
                let rb = rotate(&r6, &self.bias);
                let h = [r6[0], r6[1]];
                let z = [0, 1].map(|i| (rb[i] - self.corr_lp[i]).to_class(QClass::Rate));
                self.bias_update(&h, &z, self.r_motion);
            }
            mark("bias");
        }
        // 3. Heading.
        let q6 = quat_mul(&self.q_acc, &q_gyr);
        if self.magnetometer {
            if let Some(m) = inputs.magnetic_field {
                let c6 = dcm(&q6);
                let at_rest = self.mag_rest.update(&w_raw, inputs.specific_force.as_ref());
                let was_rejected = self.mag_gate.rejected_steps();
                if self.mag_gate.check(&m, &c6[2], inputs.clipped.mag != 0, at_rest, !raised, &mut self.events) {
                    if was_rejected > 0 {
                        self.mag_raised_left = was_rejected;
                    }
                    let m_e = rotate(&c6, &m).map(|x| x.to_class(QClass::Accel));
                    let target = m_e[0].atan2(m_e[1]).to_class(QClass::Angle);
                    let err = wrap(target - self.delta);
                    let k = if self.mag_raised_left > 0 {
                        self.mag_raised_left -= 1;
                        self.k_mag_raised
                    } else {
                        self.k_mag
                    };
                    self.delta = wrap(self.delta + k * err);
                }
            }
        }
        mark("heading");
        let hd = (self.delta * half).to_class(QClass::Angle);
        let qz = [hd.cos().to_class(QClass::Quat), zero, zero, hd.sin().to_class(QClass::Quat)];
        let mut out = quat_mul(&qz, &q6);
        normalise(&mut out);
        *q = out;
        mark("quaternion");
        Ok(())
    }
}

impl<T: Scalar> AttitudeUpdate<T> for Vqf<T> {
    fn samples_per_update(&self) -> usize {
        2
    }

    fn step(&mut self, q: &mut Quat<T>, _c_bn: &Mat3<T>, inputs: &StepInputs<'_, T>) -> Result<()> {
        self.step_in_parts(q, inputs, |_| {})
    }

    fn step_marked(
        &mut self,
        q: &mut Quat<T>,
        _c_bn: &Mat3<T>,
        inputs: &StepInputs<'_, T>,
        mark: &mut dyn FnMut(&'static str),
    ) -> Result<()> {
        self.step_in_parts(q, inputs, mark)
    }

    fn restart(&mut self) {
        let zero = T::from_f64(0.0, QClass::Quat);
        self.q_gyr = None;
        self.q_acc = [lit(1.0), zero, zero, zero];
        self.delta = T::from_f64(0.0, QClass::Angle);
        self.acc_lp.state = None;
        self.corr_lp = [zero; 3];
        self.rest_gyr_lp = None;
        self.rest_acc_lp = None;
        self.rest_count = 0;
        self.mag_raised_left = 0;
        self.mag_gate.restart();
        self.mag_rest.restart();
        self.clip.restart();
    }

    fn drain_events(&mut self, sink: &mut dyn FnMut(&'static str, crate::events::Severity, String)) {
        for (kind, severity, message) in self.events.drain(..) {
            sink(kind, severity, message);
        }
    }

    fn to_costliest(&mut self) {
        // Motion bias estimation runs (not at rest, not clipped): the two-row Kalman update.
        self.rest_count = 0;
        self.clip.restart();
    }
}

fn dot<T: Scalar>(a: &Vec3<T>, b: &Vec3<T>) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// C·v.
fn rotate<T: Scalar>(c: &Mat3<T>, v: &Vec3<T>) -> Vec3<T> {
    c.map(|row| dot(&row, v))
}

/// An angle wrapped into (−π, π].
fn wrap<T: Scalar>(x: T) -> T {
    let pi: T = T::from_f64(std::f64::consts::PI, QClass::Angle);
    let two_pi: T = T::from_f64(2.0 * std::f64::consts::PI, QClass::Angle);
    let y = if x > pi {
        x - two_pi
    } else if x <= -pi {
        x + two_pi
    } else {
        x
    };
    y.to_class(QClass::Angle)
}

/// The inverse of a small symmetric positive-definite matrix (Gauss–Jordan); None when singular.
fn invert<T: Scalar, const M: usize>(mut a: [[T; M]; M]) -> Option<[[T; M]; M]> {
    let zero = T::from_f64(0.0, QClass::Generic);
    let one = T::from_f64(1.0, QClass::Generic);
    let mut inv: [[T; M]; M] = std::array::from_fn(|i| std::array::from_fn(|j| if i == j { one } else { zero }));
    for col in 0..M {
        let pivot = a[col][col];
        if pivot <= zero {
            return None;
        }
        for j in 0..M {
            a[col][j] = (a[col][j] / pivot).to_class(QClass::Generic);
            inv[col][j] = (inv[col][j] / pivot).to_class(QClass::Generic);
        }
        for row in 0..M {
            if row != col {
                let f = a[row][col];
                for j in 0..M {
                    a[row][j] = (a[row][j] - f * a[col][j]).to_class(QClass::Generic);
                    inv[row][j] = (inv[row][j] - f * inv[col][j]).to_class(QClass::Generic);
                }
            }
        }
    }
    Some(inv)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::{C28xF32Rn, Counted};

    const D: f64 = std::f64::consts::PI / 180.0;
    const DT: f64 = 0.004;
    const G: f64 = 9.80665;
    const FIELD_N: [f64; 3] = [0.0, 0.19, -0.33];

    fn run<T: Scalar>(p: &profile::Vqf, q0: Quat<f64>, bias: Vec3<f64>, secs: f64) -> (Vqf<T>, Quat<f64>) {
        let mut v = Vqf::<T>::new(p, &profile::MagGate::default(), G, DT);
        let mut q: Quat<T> = q0.map(|x| T::from_f64(x, QClass::Quat));
        let gyro = bias.map(|x| T::from_f64(x, QClass::Rate));
        let rates = [gyro, gyro];
        let f = [0.0, 0.0, G].map(|x| T::from_f64(x, QClass::Accel));
        let m = FIELD_N.map(|x| T::from_f64(x, QClass::Accel));
        for _ in 0..(secs / DT) as usize {
            let inputs =
                StepInputs { specific_force: Some(f), magnetic_field: Some(m), ..StepInputs::rates(&rates, None) };
            let c = dcm(&q);
            v.step(&mut q, &c, &inputs).unwrap();
        }
        (v, q.map(|x| x.to_f64()))
    }

    fn tilt_deg(q: &Quat<f64>) -> f64 {
        let c = dcm(q);
        c[2][2].clamp(-1.0, 1.0).acos() / D
    }

    fn heading_deg(q: &Quat<f64>) -> f64 {
        let c = dcm(q);
        c[1][0].atan2(c[0][0]) / D
    }

    /// Tilt from a 30° start: the low-pass settles within a few τ_acc (the second-order Butterworth's
    /// step response is within 1 % after ≈ 4.2 τ when the cut-off is √2/(2πτ)); the estimate is then
    /// level (the filter's output is the measured gravity).
    #[test]
    fn a_tilted_start_levels_and_the_heading_turns_north() {
        let p = profile::Vqf::default();
        let s = (15.0 * D).sin();
        let q0 = [(15.0 * D).cos(), s, 0.0, 0.0];
        let (_, q) = run::<f64>(&p, q0, [0.0; 3], 10.0);
        assert!(tilt_deg(&q) < 0.5, "tilt {}", tilt_deg(&q));
        let (_, q) = run::<f64>(&p, q0, [0.0; 3], 60.0);
        assert!(tilt_deg(&q) < 1e-3, "tilt {}", tilt_deg(&q));
        // Heading from 40° off: k = T/τ_mag, 60 s = 6.7 τ_mag: e^-6.7 · 40° = 0.05°.
        let hz = (20.0 * D).sin();
        let (_, q) = run::<f64>(&p, [(20.0 * D).cos(), 0.0, 0.0, hz], [0.0; 3], 60.0);
        assert!(heading_deg(&q).abs() < 0.1, "heading {}", heading_deg(&q));
    }

    /// A constant bias at rest: the rest measurement takes the bias out (σ_rest 0.03 °/s against an
    /// initial σ 0.5 °/s: after 1.5 s of rest the Kalman gain is near 1), so the estimate converges to
    /// it and the attitude stops drifting.
    #[test]
    fn the_bias_is_estimated_at_rest() {
        let b = [0.3 * D, -0.2 * D, 0.5 * D];
        let (v, q) = run::<f64>(&profile::Vqf::default(), [1.0, 0.0, 0.0, 0.0], b, 30.0);
        for (i, (got, want)) in v.bias().iter().zip(b).enumerate() {
            assert!((got - want).abs() < 0.01 * D, "axis {i}: {got} vs {want}");
        }
        assert!(tilt_deg(&q) < 0.05 && heading_deg(&q).abs() < 0.5, "{q:?}");
        let (v32, _) = run::<C28xF32Rn>(&profile::Vqf::default(), [1.0, 0.0, 0.0, 0.0], b, 30.0);
        for (got, want) in v32.bias().iter().zip(b) {
            assert!((got.to_f64() - want).abs() < 0.01 * D);
        }
    }

    #[test]
    fn one_step_is_counted() {
        let mut v = Vqf::<Counted>::new(&profile::Vqf::default(), &profile::MagGate::default(), G, DT);
        let mut q = [Counted(1.0), Counted(0.0), Counted(0.0), Counted(0.0)];
        let c = dcm(&q);
        let rates = [[Counted(0.1), Counted(0.2), Counted(0.3)]; 2];
        let inputs = StepInputs {
            specific_force: Some([Counted(0.1), Counted(0.0), Counted(G)]),
            magnetic_field: Some(FIELD_N.map(Counted)),
            ..StepInputs::rates(&rates, None)
        };
        v.step(&mut q, &c, &inputs).unwrap();
        let (_, ops) = crate::numerics::counter::count(|| v.step(&mut q, &c, &inputs).unwrap());
        assert!(ops.muls > 100 && ops.sqrts >= 3, "{ops:?}");
    }
}
