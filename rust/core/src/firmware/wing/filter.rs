//! The wing unit's error-state Kalman filter (B3, B4, C). Module docs: `wing/mod.rs`.
//!
//! Nominal state: q_wb (b → w), v^w (m/s), the gyro bias estimate ε̂ (rad/s) and the accelerometer
//! bias estimate ∇̂ (m/s²). Error state x = [φ, δv, ε, ∇] (the notes' eq. 0.15–0.17): the true
//! C_b^w = (I − [φ×]) Ĉ_b^w, v = v̂ − δv, ε = ε_true − ε̂, ∇ = ∇_true − ∇̂, so with ω̂ = ω − ε̂ and
//! f̂ = f − ∇̂ (the notes' signs):
//!
//!   φ̇ = Ĉ ε,   δv̇ = −(Ĉ f̂) × φ + Ĉ ∇,   ε̇, ∇̇ = random walks.
//!
//! Measurements (each row a scalar update; the rows have independent noise, so sequential scalar
//! updates equal the batch update and need no matrix inverse):
//! - Z₁ = (C_w^r u) × a, u = Ĉ ω̂ (the rate is along the axis): Z₁ = [a×] C_w^r [u×] φ − [a×] C_b^r ε.
//!   Its component along a is zero by construction (a row of zeros: no update).
//! - Z₂ = aᵀ C_w^r v̂ (the velocity of a point on the wing is across the axis): Z₂ = aᵀ C_w^r δv.
//! - At rest (mode C): v̂ = δv (zero velocity), ω̂ = ε (zero rate: the bias with the earth rate in it)
//!   and the level, (Ĉ f̂)_{x,y} = (φ × [0, 0, g])_{x,y} + (Ĉ ∇)_{x,y} = [g φ_y, −g φ_x] + (Ĉ ∇)_{x,y}.
//!
//! After the updates the error is put into the nominal state (q ← exp(−φ) ⊗ q, …) and reset to 0.
//! Rest detection: |ω̂| and ||f̂| − g| below their thresholds for a number of consecutive steps.

use super::super::quat::{dcm, normalise, quat_mul};
use super::super::rotvec::quat_from_rotvec;
use super::super::{lit, Mat3, Quat, Vec3};
use super::geometry::{conj, cross, dot, hinge_angle, WingZero};
use crate::numerics::{QClass, Scalar};
use crate::{Error, Result};

/// The error state's size: φ, δv, ε, ∇.
pub const STATES: usize = 12;
const PHI: usize = 0;
const DV: usize = 3;
const EPS: usize = 6;
const NAB: usize = 9;

/// Which constraints the filter uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// (B3) The rate along the axis (Z₁) only: gyro integration corrected by the axis constraint; the
    /// velocity and accelerometer-bias states are frozen (zero covariance).
    Rate,
    /// (B4) Z₁ and the velocity across the axis (Z₂).
    RateVelocity,
    /// (C) Z₁, Z₂ and recalibration at rest (zero velocity, zero rate, level).
    Full,
}

/// The filter's tuning: white noise and bias walks of the sensor, initial uncertainties, measurement
/// noise and rest detection, in SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilterConfig {
    /// Step, s.
    pub step_s: f64,
    /// Gravity, m/s² (the level measurement and the velocity integration).
    pub gravity: f64,
    /// Constraints used.
    pub mode: Mode,
    /// Gyro angle random walk, rad/√s.
    pub gyro_arw: f64,
    /// Accelerometer velocity random walk, m/s/√s.
    pub accel_vrw: f64,
    /// Gyro bias random walk, rad/s/√s.
    pub gyro_bias_walk: f64,
    /// Accelerometer bias random walk, m/s²/√s.
    pub accel_bias_walk: f64,
    /// Initial attitude uncertainty, rad (1σ per axis).
    pub attitude_sigma: f64,
    /// Initial velocity uncertainty, m/s.
    pub velocity_sigma: f64,
    /// Initial gyro-bias uncertainty after the zero acquisition, rad/s.
    pub gyro_bias_sigma: f64,
    /// Initial accelerometer-bias uncertainty, m/s².
    pub accel_bias_sigma: f64,
    /// Z₁ noise, rad/s (the gyro's per-step noise and the hinge's play).
    pub rate_constraint_sigma: f64,
    /// Z₂ noise, m/s.
    pub velocity_constraint_sigma: f64,
    /// Rest measurements' noise: rate (rad/s), velocity (m/s), specific force (m/s²).
    pub rest_rate_sigma: f64,
    /// See `rest_rate_sigma`.
    pub rest_velocity_sigma: f64,
    /// See `rest_rate_sigma`.
    pub rest_force_sigma: f64,
    /// Rest when |ω̂| < this, rad/s …
    pub rest_rate_threshold: f64,
    /// … and ||f̂| − g| < this, m/s² …
    pub rest_force_threshold: f64,
    /// … for this many consecutive steps.
    pub rest_steps: u32,
}

impl FilterConfig {
    /// A tuning for the ADIS16362 (preset `adis16362`: ARW 2 °/√h, bias stability 0.007 °/s, VRW
    /// 0.12 m/s/√h, accelerometer stability 0.1 mg) at `step_s`, gravity `gravity`. The bias walks are
    /// the stabilities spread over 100 s; the accelerometer bias's initial uncertainty is its
    /// stability (the zero holds the turn-on bias as a tilt); the thresholds are 3σ of the per-step
    /// noise plus the stability.
    pub fn adis16362(step_s: f64, gravity: f64, mode: Mode) -> Self {
        let d = std::f64::consts::PI / 180.0;
        let arw = 2.0 / 60.0 * d;
        let vrw = 0.12 / 60.0;
        let w_step = arw / step_s.sqrt();
        let f_step = vrw / step_s.sqrt();
        FilterConfig {
            step_s,
            gravity,
            mode,
            gyro_arw: arw,
            accel_vrw: vrw,
            gyro_bias_walk: 0.007 * d / 10.0,
            accel_bias_walk: 0.1e-3 * 9.80665 / 10.0,
            attitude_sigma: 0.2 * d,
            velocity_sigma: 0.01,
            gyro_bias_sigma: 0.01 * d,
            // Not the turn-on bias (4 mg): the zero takes it in as a tilt of w (one pose cannot tell a
            // bias from a tilt), and a filter that estimated it afterwards would level against a
            // reference still tilted by it: α off by b/g at every pose, α = 0 included (0.37° measured,
            // seed 1 of the `adis16362` preset on the `synth wing` steps). What is left to estimate is
            // the in-run change: the 0.1 mg stability.
            accel_bias_sigma: 0.1e-3 * 9.80665,
            rate_constraint_sigma: 3.0 * w_step + 0.05 * d,
            velocity_constraint_sigma: 0.05,
            rest_rate_sigma: w_step,
            rest_velocity_sigma: 1e-3,
            rest_force_sigma: f_step,
            rest_rate_threshold: 5.0 * w_step + 0.05 * d,
            rest_force_threshold: 5.0 * f_step + 0.02,
            rest_steps: (0.5 / step_s).ceil() as u32,
        }
    }

    /// The filter's variances: P₀'s diagonal, the process noise per step and the measurement noises.
    fn variances(&self) -> ([f64; STATES], [f64; STATES], Vec<(&'static str, f64)>) {
        let full = self.mode != Mode::Rate;
        let dt = self.step_s;
        let on = |x: f64| if full { x } else { 0.0 };
        let mut p0 = [0.0; STATES];
        let mut qd = [0.0; STATES];
        for i in 0..3 {
            p0[PHI + i] = self.attitude_sigma.powi(2);
            p0[DV + i] = on(self.velocity_sigma.powi(2));
            p0[EPS + i] = self.gyro_bias_sigma.powi(2);
            p0[NAB + i] = on(self.accel_bias_sigma.powi(2));
            qd[PHI + i] = self.gyro_arw.powi(2) * dt;
            qd[DV + i] = on(self.accel_vrw.powi(2) * dt);
            qd[EPS + i] = self.gyro_bias_walk.powi(2) * dt;
            qd[NAB + i] = on(self.accel_bias_walk.powi(2) * dt);
        }
        let mut r = vec![("Z₁ (rate along the axis)", self.rate_constraint_sigma.powi(2))];
        if full {
            r.push(("Z₂ (velocity across the axis)", self.velocity_constraint_sigma.powi(2)));
        }
        if self.mode == Mode::Full {
            r.push(("rest rate", self.rest_rate_sigma.powi(2)));
            r.push(("rest velocity", self.rest_velocity_sigma.powi(2)));
            r.push(("rest level", self.rest_force_sigma.powi(2)));
        }
        (p0, qd, r)
    }
}

/// Bits a 32-bit IQ word must hold for a set of variances: the span max/min, one sign bit, one bit of
/// headroom (a sum of two), and 8 significant bits for the smallest.
const IQ_WORD_BITS: f64 = 31.0;
const IQ_SIGNIFICANT_BITS: f64 = 8.0;

/// Under a fixed-point backend, refuse variances that no single Q format holds: log2(max/min) + 1
/// headroom + 8 significant bits must fit 31 bits (9.3 decades less 2.7). Floats pass.
pub fn check_fixed_point_span<T: Scalar>(variances: &[(&str, f64)]) -> Result<()> {
    if !T::fixed_point() {
        return Ok(());
    }
    let positive = variances.iter().filter(|(_, v)| *v > 0.0);
    let (Some(lo), Some(hi)) =
        (positive.clone().min_by(|a, b| a.1.total_cmp(&b.1)), positive.max_by(|a, b| a.1.total_cmp(&b.1)))
    else {
        return Ok(());
    };
    let bits = (hi.1 / lo.1).log2() + 1.0 + IQ_SIGNIFICANT_BITS;
    if bits > IQ_WORD_BITS {
        return Err(Error::Config(format!(
            "wing filter under firmware.numeric = \"iq\": its covariances span {:.1} decades ({} {:.2e} … {} {:.2e}); \
             one IQ format holds {:.1} decades with 8 significant bits and 1 of headroom. Run the wing filter in \
             floating point (firmware.numeric = \"c28x-f32\" or \"f64\")",
            (hi.1 / lo.1).log10(),
            lo.0,
            lo.1,
            hi.0,
            hi.1,
            (IQ_WORD_BITS - 1.0 - IQ_SIGNIFICANT_BITS) * 2f64.log10()
        )));
    }
    Ok(())
}

/// What one filter step gives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WingOutput<T> {
    /// α, rad (None while the filter has no axis).
    pub alpha: Option<T>,
    /// The axis in use (unit, r axes), if any.
    pub axis: Option<Vec3<T>>,
    /// Whether the step was detected at rest (mode C).
    pub at_rest: bool,
}

type Mat<T> = [[T; STATES]; STATES];

/// The error-state filter (module docs).
#[derive(Debug, Clone)]
pub struct WingFilter<T> {
    cfg: FilterConfig,
    q_wr: Quat<T>,
    c_wr: Mat3<T>,
    /// The hinge axis; None until one is estimated (then Z₁ and Z₂ wait: only the rest measurements run).
    axis: Option<Vec3<T>>,
    q: Quat<T>,
    v: Vec3<T>,
    eps: Vec3<T>,
    nab: Vec3<T>,
    p: Mat<T>,
    qd: [T; STATES],
    dt: T,
    g: T,
    still: u32,
    /// Held at rest whatever the inputs (the timing model's count of the costliest step).
    held_at_rest: bool,
}

fn skew<T: Scalar>(v: &Vec3<T>) -> Mat3<T> {
    let z = lit::<T>(0.0);
    [[z, -v[2], v[1]], [v[2], z, -v[0]], [-v[1], v[0], z]]
}

fn mm3<T: Scalar>(a: &Mat3<T>, b: &Mat3<T>) -> Mat3<T> {
    std::array::from_fn(|i| std::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j]))
}

fn mv3<T: Scalar>(a: &Mat3<T>, v: &Vec3<T>) -> Vec3<T> {
    std::array::from_fn(|i| dot(&a[i], v))
}

fn transpose<T: Scalar>(a: &Mat3<T>) -> Mat3<T> {
    std::array::from_fn(|i| std::array::from_fn(|j| a[j][i]))
}

impl<T: Scalar> WingFilter<T> {
    /// A filter starting at the zero pose (α = 0, at rest), with the zero's mean gyro as the bias
    /// estimate and `axis` (unit, r axes) as the hinge axis. Errors under a fixed-point backend
    /// ([`check_fixed_point_span`]).
    pub fn new(zero: &WingZero<T>, axis: Vec3<T>, cfg: FilterConfig) -> Result<Self> {
        let mut f = Self::without_axis(zero, cfg)?;
        f.axis = Some(axis);
        Ok(f)
    }

    /// [`WingFilter::new`] with no axis yet ([`WingFilter::set_axis`] gives one): until then the filter
    /// integrates the gyro and recalibrates at rest, and gives no α.
    pub fn without_axis(zero: &WingZero<T>, cfg: FilterConfig) -> Result<Self> {
        let (p0, qd, r) = cfg.variances();
        let mut all: Vec<(&str, f64)> = Vec::new();
        all.extend(p0.iter().map(|v| ("P₀", *v)));
        all.extend(qd.iter().map(|v| ("process noise per step", *v)));
        all.extend(r);
        check_fixed_point_span::<T>(&all)?;
        let z: T = lit(0.0);
        let mut p = [[z; STATES]; STATES];
        for i in 0..STATES {
            p[i][i] = T::from_f64(p0[i], QClass::Generic);
        }
        Ok(WingFilter {
            cfg,
            q_wr: zero.q_wr,
            c_wr: transpose(&dcm(&zero.q_wr)),
            axis: None,
            q: zero.q_wr,
            v: [z; 3],
            eps: zero.gyro_mean,
            nab: [z; 3],
            p,
            qd: qd.map(|x| T::from_f64(x, QClass::Generic)),
            dt: T::from_f64(cfg.step_s, QClass::Generic),
            g: T::from_f64(cfg.gravity, QClass::Accel),
            still: 0,
            held_at_rest: false,
        })
    }

    /// Use another axis estimate (B1 or B2) from now on.
    pub fn set_axis(&mut self, axis: Vec3<T>) {
        self.axis = Some(axis);
    }

    /// Whether the step detector holds the board at rest (mode C: the rest measurements run).
    pub fn at_rest(&self) -> bool {
        self.cfg.mode == Mode::Full && (self.still >= self.cfg.rest_steps || self.held_at_rest)
    }

    /// Hold the filter at rest whatever its inputs (the costliest step: the rest measurements run
    /// too). Only for the timing model's count of one step.
    pub fn hold_at_rest(&mut self) {
        self.held_at_rest = true;
    }

    /// q_wb as the filter holds it.
    pub fn attitude(&self) -> Quat<T> {
        self.q
    }

    /// q_rb = q_wr* ⊗ q_wb: the rotation from the zero (what B2 takes).
    pub fn rotation_from_zero(&self) -> Quat<T> {
        quat_mul(&conj(&self.q_wr), &self.q)
    }

    /// The gyro bias estimate (earth rate included), rad/s.
    pub fn gyro_bias(&self) -> Vec3<T> {
        self.eps
    }

    /// The accelerometer bias estimate, m/s².
    pub fn accel_bias(&self) -> Vec3<T> {
        self.nab
    }

    /// The velocity estimate in w, m/s.
    pub fn velocity(&self) -> Vec3<T> {
        self.v
    }

    /// The covariance's diagonal.
    pub fn variances(&self) -> [T; STATES] {
        std::array::from_fn(|i| self.p[i][i])
    }

    /// One step with the mean gyro ω_ib^b (rad/s) and specific force f^b (m/s²) over the step.
    pub fn step(&mut self, w: &Vec3<T>, f: &Vec3<T>) -> WingOutput<T> {
        let full = self.cfg.mode != Mode::Rate;
        let w_hat: Vec3<T> = std::array::from_fn(|i| (w[i] - self.eps[i]).to_class(QClass::Rate));
        let f_hat: Vec3<T> = std::array::from_fn(|i| (f[i] - self.nab[i]).to_class(QClass::Accel));

        // Rest detection.
        let rest_now = dot(&w_hat, &w_hat) < lit(self.cfg.rest_rate_threshold.powi(2))
            && (dot(&f_hat, &f_hat).sqrt() - self.g).abs() < lit(self.cfg.rest_force_threshold);
        self.still = if rest_now { self.still.saturating_add(1) } else { 0 };
        let at_rest = self.at_rest();

        // Nominal propagation.
        let dt = self.dt;
        self.q = quat_mul(&self.q, &quat_from_rotvec(&w_hat.map(|x| x * dt)));
        normalise(&mut self.q);
        let c = dcm(&self.q);
        let u_f = mv3(&c, &f_hat);
        if full {
            let g_w = [lit(0.0), lit(0.0), self.g];
            for ((v, uf), g) in self.v.iter_mut().zip(u_f).zip(g_w) {
                *v = (*v + (uf - g) * dt).to_class(QClass::Accel);
            }
        }

        // Covariance: P ← F P Fᵀ + Qd with F = I + A dt.
        let mut a = [[lit::<T>(0.0); STATES]; STATES];
        let neg_uf = skew(&u_f).map(|r| r.map(|x| -x));
        for i in 0..3 {
            for j in 0..3 {
                a[PHI + i][EPS + j] = c[i][j];
                if full {
                    a[DV + i][PHI + j] = neg_uf[i][j];
                    a[DV + i][NAB + j] = c[i][j];
                }
            }
        }
        self.propagate(&a);

        // Measurements.
        let mut x = [lit::<T>(0.0); STATES];
        let u_w = mv3(&c, &w_hat);
        if let Some(axis) = self.axis {
            let c_wr = self.c_wr;
            let ax = skew(&axis);
            let z1 = cross(&mv3(&c_wr, &u_w), &axis);
            let h_phi = mm3(&mm3(&ax, &c_wr), &skew(&u_w));
            let h_eps = mm3(&mm3(&ax, &c_wr), &c).map(|r| r.map(|x| -x));
            let r1 = lit(self.cfg.rate_constraint_sigma.powi(2));
            for i in 0..3 {
                let mut h = [lit::<T>(0.0); STATES];
                h[PHI..PHI + 3].copy_from_slice(&h_phi[i]);
                h[EPS..EPS + 3].copy_from_slice(&h_eps[i]);
                self.update(&mut x, &h, z1[i], r1);
            }
            if full {
                let a_w: Vec3<T> = std::array::from_fn(|j| dot(&[c_wr[0][j], c_wr[1][j], c_wr[2][j]], &axis));
                let mut h = [lit::<T>(0.0); STATES];
                h[DV..DV + 3].copy_from_slice(&a_w);
                self.update(&mut x, &h, dot(&a_w, &self.v), lit(self.cfg.velocity_constraint_sigma.powi(2)));
            }
        }
        if at_rest {
            let (rw, rv, rf) = (
                lit(self.cfg.rest_rate_sigma.powi(2)),
                lit(self.cfg.rest_velocity_sigma.powi(2)),
                lit(self.cfg.rest_force_sigma.powi(2)),
            );
            for i in 0..3 {
                let mut h = [lit::<T>(0.0); STATES];
                h[EPS + i] = lit(1.0);
                self.update(&mut x, &h, w_hat[i], rw);
                let mut h = [lit::<T>(0.0); STATES];
                h[DV + i] = lit(1.0);
                self.update(&mut x, &h, self.v[i], rv);
            }
            let g = self.g;
            for (i, phi_row) in [[lit(0.0), g, lit(0.0)], [-g, lit(0.0), lit(0.0)]].iter().enumerate() {
                let mut h = [lit::<T>(0.0); STATES];
                h[PHI..PHI + 3].copy_from_slice(phi_row);
                h[NAB..NAB + 3].copy_from_slice(&c[i]);
                self.update(&mut x, &h, u_f[i], rf);
            }
        }

        self.condition();

        // Feedback into the nominal state; the error state restarts at zero.
        let phi = [x[PHI], x[PHI + 1], x[PHI + 2]].map(|v| -v);
        self.q = quat_mul(&quat_from_rotvec(&phi), &self.q);
        normalise(&mut self.q);
        for i in 0..3 {
            self.v[i] = (self.v[i] - x[DV + i]).to_class(QClass::Accel);
            self.eps[i] = (self.eps[i] + x[EPS + i]).to_class(QClass::Rate);
            self.nab[i] = (self.nab[i] + x[NAB + i]).to_class(QClass::Accel);
        }
        WingOutput { alpha: self.axis.map(|a| hinge_angle(&self.q_wr, &a, &self.q)), axis: self.axis, at_rest }
    }

    /// P ← (I + A dt) P (I + A dt)ᵀ + Qd, as P' = P + dt·A P, then P' + dt·P' Aᵀ (A is sparse: only
    /// its non-zero entries are multiplied).
    fn propagate(&mut self, a: &Mat<T>) {
        let dt = self.dt;
        let zero = lit::<T>(0.0);
        let nz: Vec<(usize, usize, T)> = (0..STATES)
            .flat_map(|i| (0..STATES).map(move |k| (i, k)))
            .filter(|&(i, k)| a[i][k] != zero)
            .map(|(i, k)| (i, k, a[i][k] * dt))
            .collect();
        let mut p1 = self.p;
        for &(i, k, adt) in &nz {
            for (x, pk) in p1[i].iter_mut().zip(&self.p[k]) {
                *x = *x + adt * *pk;
            }
        }
        let mut p2 = p1;
        for &(j, k, adt) in &nz {
            for i in 0..STATES {
                p2[i][j] = p2[i][j] + p1[i][k] * adt;
            }
        }
        for (i, qd) in self.qd.iter().enumerate() {
            p2[i][i] = p2[i][i] + *qd;
        }
        self.p = p2;
    }

    /// Keep P a covariance in single precision: the update P − K Kᵀ s subtracts nearly equal numbers
    /// (the rest measurements' variances are 1e-6 against P's 1e-4), and in float32 its round-off left
    /// P asymmetric with negative variances, from which the filter diverged (α 60° off at rest, seed 1
    /// of the `adis16362` preset on the `synth wing` steps). Symmetrise, and floor each variance at one
    /// step's process noise (no state is known better than one step's noise after a step).
    fn condition(&mut self) {
        let half = lit::<T>(0.5);
        for i in 0..STATES {
            for j in i + 1..STATES {
                let m = (self.p[i][j] + self.p[j][i]) * half;
                self.p[i][j] = m;
                self.p[j][i] = m;
            }
            if self.p[i][i] < self.qd[i] {
                self.p[i][i] = self.qd[i];
            }
        }
    }

    /// One scalar measurement z = h·x + noise (variance r): x and P updated (P − K Kᵀ s, symmetric).
    fn update(&mut self, x: &mut [T; STATES], h: &[T; STATES], z: T, r: T) {
        let zero = lit::<T>(0.0);
        let idx: Vec<usize> = (0..STATES).filter(|&k| h[k] != zero).collect();
        if idx.is_empty() {
            return;
        }
        let ph: [T; STATES] = std::array::from_fn(|i| idx.iter().fold(zero, |s, &k| s + self.p[i][k] * h[k]));
        let s = idx.iter().fold(r, |acc, &k| acc + h[k] * ph[k]);
        let innovation = idx.iter().fold(z, |acc, &k| acc - h[k] * x[k]);
        let gain = ph.map(|v| v / s);
        for ((xi, gi), row) in x.iter_mut().zip(gain).zip(self.p.iter_mut()) {
            *xi = *xi + gi * innovation;
            for (pij, phj) in row.iter_mut().zip(&ph) {
                *pij = *pij - gi * *phj;
            }
        }
    }
}
