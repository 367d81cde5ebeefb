//! The federated Kalman filter (thesis §3.4–3.5 with the spec's corrections): sub-filter 1
//! GFSINS/compass (18 states, 10 Hz), sub-filter 2 GFSINS/GPS (15 states, 1 Hz, loose coupling),
//! fusion at 1 Hz with β_master = 0, β₁ = β₂ = ½ and no reset. Module docs: `gfnav/mod.rs`.
//!
//! States (ENU, right-handed; the spec's correction of the thesis's mixed frames): φ (attitude error,
//! rad), δv (m/s), δp (east, north, up position error in metres: the thesis's δL, δλ, δh times
//! R_M + h, (R_N + h) cos L, 1, which keeps single precision well scaled), ε (the solved rate's drift,
//! body, rad/s), ∇ (accelerometer bias, body, m/s²); sub-filter 1 adds the compass errors φ_e (first
//! order Markov, T_ec). Error model (the standard ψ-angle equations, ENU):
//!
//!   φ̇ = −ω_in × φ + δω_in − C ε,   δv̇ = f × φ − (2ω_ie + ω_en) × δv + C ∇,   δṗ = δv,
//!
//! δω_in the rate error from δv and the north position error (eq. 3.33 in ENU). Left out: the
//! v × (2δω_ie + δω_en) terms of δv̇ (≤ 2Ω·v ≈ 3e-3 m/s² per radian-equivalent, below the 5 mg bias's
//! 4.9e-2 by far at the scenario's 22 m/s). F's lower right block is 0 (spec: 0₆ₓ₆); the compass block
//! is diag(−1/T_ec). Measurements: compass Z = φ − φ_e (H 3×18, spec), GPS Z = [δp; δv] (H 6×15).
//!
//! Covariances are held as UD factors ([`Kf`]): updates one scalar row at a time (the measurement
//! noises are independent, so sequential rows equal the batch update) by Bierman's factored update,
//! equal in exact arithmetic to the Joseph form P ← (I − k h) P (I − k h)ᵀ + k r kᵀ and, like it,
//! positive semidefinite whatever the round-off. Propagation at the compass rate with
//! Φ = I + F Δt + (F Δt)²/2 and Q_d = G Q Gᵀ Δt (Thornton).
//!
//! Fusion (eq. 3.31 with β_m = 0: the master holds no information): on the 15 common states,
//! P_f = (P₁⁻¹ + P₂⁻¹)⁻¹, x_f = P_f (P₁⁻¹ x₁ + P₂⁻¹ x₂), computed in factored form ([`fuse`]). Information sharing (eq. 3.27) happens once,
//! at the start (P_i(0) = P₀/β_i, and Q_i = Q/β_i throughout); no reset feeds x_f, P_f back. The bound
//! Q/β, P₀/β keeps block-diag(P₁, P₂) above the sub-filters' joint error covariance, so P_f is never
//! below the centralised filter's covariance (checked).

use super::super::lit;
use crate::numerics::{QClass, Scalar};

/// Full state count of sub-filter 1 (and of the centralised filter).
pub const N_COMPASS: usize = 18;
/// State count of sub-filter 2 (the states both share).
pub const N_GPS: usize = 15;
/// Offsets of the state groups.
pub const PHI: usize = 0;
/// δv.
pub const DV: usize = 3;
/// δp (metres east, north, up).
pub const DP: usize = 6;
/// ε.
pub const EPS: usize = 9;
/// ∇.
pub const NAB: usize = 12;
/// φ_e (compass).
pub const PHI_E: usize = 15;

const D: f64 = std::f64::consts::PI / 180.0;
const OMEGA: f64 = 7.292_115e-5;
const RE: f64 = 6_378_137.0;
const F_FLAT: f64 = 1.0 / 298.257_223_563;

/// The scenario and the noise figures (chapter 5, every parameter the corrections list).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scenario {
    /// Latitude, rad.
    pub lat: f64,
    /// Height, m.
    pub height: f64,
    /// Speed, m/s (straight line, level).
    pub speed: f64,
    /// Heading, rad from north, clockwise.
    pub heading: f64,
    /// Gravity, m/s².
    pub g: f64,
    /// Solved-rate drift: constant 1σ (rad/s) and white 1σ per 200 Hz sample (rad/s).
    pub drift_const: f64,
    /// See `drift_const`.
    pub drift_white: f64,
    /// Accelerometer bias: constant 1σ and white 1σ per 200 Hz sample, m/s².
    pub accel_const: f64,
    /// See `accel_const`.
    pub accel_white: f64,
    /// Sensor rate, Hz (the white figures are per sample at this rate).
    pub sensor_hz: f64,
    /// Compass white noise 1σ per axis (E, N, U), rad.
    pub compass_white: [f64; 3],
    /// Compass Markov error steady 1σ per axis (the thesis's "attitude measurement error"), rad.
    pub compass_markov: [f64; 3],
    /// Compass Markov correlation time, s [unconfirmed: not published; chosen].
    pub compass_tau: f64,
    /// Initial errors: attitude (rad per axis), velocity (m/s), position (m).
    pub init_attitude: [f64; 3],
    /// See `init_attitude`.
    pub init_velocity: f64,
    /// See `init_attitude`.
    pub init_position: f64,
    /// GPS position and velocity noise 1σ.
    pub gps_position: f64,
    /// See `gps_position`.
    pub gps_velocity: f64,
}

impl Scenario {
    /// Chapter 5: heading 30°, 80 km/h, latitude 28.20021°, height 5.13145 m; attitude errors 10′, 10′,
    /// 20′; 0.02 m/s; 1 m; drift 0.1 °/s + 0.02 °/s; accelerometers 5 mg + 1 mg; compass white 0.03°,
    /// 0.04°, 0.1° (the last unit is missing: degrees taken), measurement error 0.5°, 0.5°, 1°; GPS 10 m,
    /// 0.1 m/s. The compass's correlation time (100 s) is not published.
    pub fn chapter5() -> Self {
        let lat = 28.20021 * D;
        let s2 = lat.sin().powi(2);
        let g = 9.780_325_3 * (1.0 + 0.001_931_853 * s2) / (1.0 - 0.006_694_38 * s2).sqrt() - 3.086e-6 * 5.13145;
        Scenario {
            lat,
            height: 5.13145,
            speed: 80.0 / 3.6,
            heading: 30.0 * D,
            g,
            drift_const: 0.1 * D,
            drift_white: 0.02 * D,
            accel_const: 5e-3 * 9.80665,
            accel_white: 1e-3 * 9.80665,
            sensor_hz: 200.0,
            compass_white: [0.03 * D, 0.04 * D, 0.1 * D],
            compass_markov: [0.5 * D, 0.5 * D, 1.0 * D],
            compass_tau: 100.0,
            init_attitude: [10.0 / 60.0 * D, 10.0 / 60.0 * D, 20.0 / 60.0 * D],
            init_velocity: 0.02,
            init_position: 1.0,
            gps_position: 10.0,
            gps_velocity: 0.1,
        }
    }

    /// The error model's F (18×18) on the straight line, and G·Q·Gᵀ's diagonal (continuous, per s).
    pub fn model(&self) -> ([[f64; N_COMPASS]; N_COMPASS], [f64; N_COMPASS]) {
        let (ve, vn) = (self.speed * self.heading.sin(), self.speed * self.heading.cos());
        // Body (x right, y forward, z up) to ENU at heading ψ (clockwise from north), level.
        let (sh, ch) = (self.heading.sin(), self.heading.cos());
        let c_bn = [[ch, sh, 0.0], [-sh, ch, 0.0], [0.0, 0.0, 1.0]];
        let at =
            Linearisation { lat: self.lat, height: self.height, vel: [ve, vn, 0.0], c_bn, f_n: [0.0, 0.0, self.g] };
        error_model(&at, self)
    }

    /// P₀'s diagonal (18 states).
    pub fn p0(&self) -> [f64; N_COMPASS] {
        let mut p = [0.0; N_COMPASS];
        for i in 0..3 {
            p[PHI + i] = self.init_attitude[i].powi(2);
            p[DV + i] = self.init_velocity.powi(2);
            p[DP + i] = self.init_position.powi(2);
            p[EPS + i] = self.drift_const.powi(2);
            p[NAB + i] = self.accel_const.powi(2);
            p[PHI_E + i] = self.compass_markov[i].powi(2);
        }
        p
    }

    /// Φ = I + F Δt + (F Δt)²/2 and Q_d = diag(q) Δt (n ≤ 18 leading states).
    pub fn discrete(&self, dt: f64) -> (Vec<Vec<f64>>, Vec<f64>) {
        let (a, q) = self.model();
        let n = N_COMPASS;
        let fd: Vec<Vec<f64>> = (0..n).map(|i| (0..n).map(|j| a[i][j] * dt).collect()).collect();
        let phi = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| {
                        let sq: f64 = (0..n).map(|k| fd[i][k] * fd[k][j]).sum();
                        f64::from(u8::from(i == j)) + fd[i][j] + 0.5 * sq
                    })
                    .collect()
            })
            .collect();
        (phi, q.iter().map(|x| x * dt).collect())
    }
}

/// Where the error model is linearised: the navigation state the firmware holds (latitude in rad,
/// height in m, velocity ENU in m/s, the attitude C_b^n in whatever body axes the firmware's rates are
/// in, the specific force in ENU, m/s²).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Linearisation<T> {
    /// Latitude, rad.
    pub lat: T,
    /// Height, m.
    pub height: T,
    /// Velocity east, north, up, m/s.
    pub vel: [T; 3],
    /// C_b^n.
    pub c_bn: [[T; 3]; 3],
    /// Specific force, ENU, m/s².
    pub f_n: [T; 3],
}

/// The error model's F (18×18) at `at` and G·Q·Gᵀ's diagonal (continuous, per s) with the noise
/// figures of `s` (the module docs' equations), in the firmware's arithmetic.
#[allow(clippy::needless_range_loop)] // matrix algebra reads best indexed
pub fn error_model<T: Scalar>(at: &Linearisation<T>, s: &Scenario) -> ([[T; N_COMPASS]; N_COMPASS], [T; N_COMPASS]) {
    let zero: T = lit(0.0);
    let (sl, cl) = (at.lat.sin(), at.lat.cos());
    let (re, ff, om): (T, T, T) = (lit(RE), lit(F_FLAT), lit(OMEGA));
    let (one, two, three): (T, T, T) = (lit(1.0), lit(2.0), lit(3.0));
    let rm = re * (one - two * ff + three * ff * sl * sl) + at.height;
    let rn = re * (one + ff * sl * sl) + at.height;
    let [ve, vn, _] = at.vel;
    let w_ie = [zero, om * cl, om * sl];
    let w_en = [-vn / rm, ve / rn, ve * sl / cl / rn];
    let w_in: [T; 3] = std::array::from_fn(|i| w_ie[i] + w_en[i]);
    let c = &at.c_bn;
    let mut a = [[zero; N_COMPASS]; N_COMPASS];
    let skew = |v: &[T; 3]| [[zero, -v[2], v[1]], [v[2], zero, -v[0]], [-v[1], v[0], zero]];
    let (sw, sf) = (skew(&w_in), skew(&at.f_n));
    let coriolis: [T; 3] = std::array::from_fn(|i| two * w_ie[i] + w_en[i]);
    let sc = skew(&coriolis);
    for i in 0..3 {
        for j in 0..3 {
            a[PHI + i][PHI + j] = -sw[i][j];
            a[PHI + i][EPS + j] = -c[i][j];
            a[DV + i][PHI + j] = sf[i][j];
            a[DV + i][DV + j] = -sc[i][j];
            a[DV + i][NAB + j] = c[i][j];
        }
        a[DP + i][DV + i] = one;
        a[PHI_E + i][PHI_E + i] = lit(-1.0 / s.compass_tau);
    }
    // δω_in: from δv_N, δv_E and the north position error δN = (R_M + h) δL.
    a[PHI][DV + 1] = a[PHI][DV + 1] - one / rm;
    a[PHI + 1][DV] = a[PHI + 1][DV] + one / rn;
    a[PHI + 2][DV] = a[PHI + 2][DV] + sl / cl / rn;
    a[PHI + 1][DP + 1] = a[PHI + 1][DP + 1] - om * sl / rm;
    a[PHI + 2][DP + 1] = a[PHI + 2][DP + 1] + (om * cl + ve / (rn * cl * cl)) / rm;
    let dt_s = 1.0 / s.sensor_hz;
    let mut q = [zero; N_COMPASS];
    for i in 0..3 {
        q[PHI + i] = lit(s.drift_white.powi(2) * dt_s);
        q[DV + i] = lit(s.accel_white.powi(2) * dt_s);
        q[PHI_E + i] = lit(2.0 * s.compass_markov[i].powi(2) / s.compass_tau);
    }
    (a, q)
}

/// Φ = I + F Δt + (F Δt)²/2 and Q_d = diag(q) Δt on the leading `n` states, in the firmware's
/// arithmetic; the products run over F's nonzero elements only (what a firmware loop over the
/// model's sparse structure computes).
#[allow(clippy::needless_range_loop)] // matrix algebra reads best indexed
pub fn discretise<T: Scalar>(
    a: &[[T; N_COMPASS]; N_COMPASS],
    q: &[T; N_COMPASS],
    n: usize,
    dt: T,
) -> (Vec<Vec<T>>, Vec<T>) {
    let zero: T = lit(0.0);
    let half: T = lit(0.5);
    let nz: Vec<Vec<(usize, T)>> =
        (0..n).map(|i| (0..n).filter(|&j| a[i][j] != zero).map(|j| (j, a[i][j] * dt)).collect()).collect();
    let mut phi = vec![vec![zero; n]; n];
    for i in 0..n {
        phi[i][i] = lit(1.0);
        for &(k, fik) in &nz[i] {
            phi[i][k] = phi[i][k] + fik;
        }
    }
    for i in 0..n {
        let mut sq = vec![zero; n];
        for &(k, fik) in &nz[i] {
            for &(j, fkj) in &nz[k] {
                sq[j] = sq[j] + fik * fkj;
            }
        }
        for j in 0..n {
            if sq[j] != zero {
                phi[i][j] = phi[i][j] + half * sq[j];
            }
        }
    }
    (phi, q[..n].iter().map(|&v| v * dt).collect())
}

/// A Kalman filter of n states in the firmware's arithmetic, its covariance held as P = U D Uᵀ (U unit
/// upper triangular, D diagonal ≥ 0: Bierman–Thornton UD factors).
///
/// Why factors: each sub-filter leaves whole blocks unobserved (the compass sub-filter's δv, δp, ∇
/// grow together as ∇t, ∇t²/2; the GPS sub-filter knows the tilt and horizontal ∇ only as g·φ + ∇),
/// so P's correlation matrix has pivots near 1e-5 (`fusion_conditioning` measures them). A covariance
/// form in single precision rounds every element of ΦPΦᵀ and of the update by 2⁻²⁴ of the element,
/// 10 times a second; those errors pile up in the near-null directions until P is no longer
/// positive definite and the fusion's Cholesky fails (the C6727 float test did at first). The factors
/// carry the same information with the square root of the condition number and D ≥ 0 by
/// construction: Thornton's modified weighted Gram–Schmidt propagates them, Bierman's scalar update
/// measures. In exact arithmetic both equal the covariance form's ΦPΦᵀ + Q and the Joseph update.
#[derive(Debug, Clone)]
pub struct Kf<T> {
    /// State estimate.
    pub x: Vec<T>,
    /// Unit upper triangular factor.
    pub u: Vec<Vec<T>>,
    /// Diagonal factor.
    pub d: Vec<T>,
}

impl<T: Scalar> Kf<T> {
    /// A filter with x = 0 and diagonal P₀ scaled by 1/β.
    pub fn new(p0: &[f64], beta: f64) -> Self {
        let n = p0.len();
        let z: T = lit(0.0);
        let u = (0..n).map(|i| (0..n).map(|j| if i == j { lit(1.0) } else { z }).collect()).collect();
        Kf { x: vec![z; n], u, d: p0.iter().map(|v| T::from_f64(v / beta, QClass::Generic)).collect() }
    }

    /// The covariance U D Uᵀ (symmetric by construction: each element computed once and mirrored).
    #[allow(clippy::needless_range_loop)] // matrix algebra reads best indexed
    pub fn p(&self) -> Vec<Vec<T>> {
        let n = self.x.len();
        let zero: T = lit(0.0);
        let mut p = vec![vec![zero; n]; n];
        for i in 0..n {
            for j in i..n {
                // U is upper triangular: U[i][k] U[j][k] is zero below k = j.
                let v = (j..n).fold(zero, |s, k| s + self.u[i][k] * self.d[k] * self.u[j][k]);
                p[i][j] = v;
                p[j][i] = v;
            }
        }
        p
    }

    /// x ← Φx; P ← ΦPΦᵀ + Q_d/β (the leading n×n of Φ and Q_d), by Thornton's modified weighted
    /// Gram–Schmidt on W = [ΦU | I] with weights diag(D, Q_d/β), from the last row up.
    #[allow(clippy::needless_range_loop)] // matrix algebra reads best indexed
    pub fn predict(&mut self, phi: &[Vec<f64>], qd: &[f64], beta: f64) {
        let n = self.x.len();
        let f: Vec<Vec<T>> =
            (0..n).map(|i| (0..n).map(|j| T::from_f64(phi[i][j], QClass::Generic)).collect()).collect();
        let q: Vec<T> = qd[..n].iter().map(|q| T::from_f64(q / beta, QClass::Generic)).collect();
        self.predict_with(&f, &q);
    }

    /// [`Kf::predict`] with Φ (at least n×n) and Q_d/β (at least n) already in the firmware's arithmetic.
    ///
    /// W is one n × 2n block (row i at `w[i·2n..]`) and U, D are overwritten in place: the same
    /// operations in the same order as with a fresh matrix per row, without the allocations.
    #[allow(clippy::needless_range_loop)] // matrix algebra reads best indexed
    pub fn predict_with(&mut self, f: &[Vec<T>], qd_beta: &[T]) {
        let n = self.x.len();
        let m = 2 * n;
        let z: T = lit(0.0);
        // Φ's nonzero elements (column, value), row i at nz[start[i]..start[i + 1]].
        let mut nz: Vec<(usize, T)> = Vec::with_capacity(n * n);
        let mut start = Vec::with_capacity(n + 1);
        for r in &f[..n] {
            start.push(nz.len());
            nz.extend(r[..n].iter().copied().enumerate().filter(|(_, v)| *v != z));
        }
        start.push(nz.len());
        let row = |i: usize| &nz[start[i]..start[i + 1]];
        self.x = (0..n).map(|i| row(i).iter().fold(z, |s, &(k, v)| s + v * self.x[k])).collect();
        // W's left half ΦU (row i: Σ_k Φ[i][k] U[k][j], U[k][j] = 0 for k > j); its right half is I.
        let mut w = vec![z; n * m];
        for (i, wi) in w.chunks_exact_mut(m).enumerate() {
            for j in 0..n {
                wi[j] = row(i).iter().fold(z, |s, &(k, v)| s + v * self.u[k][j]);
            }
        }
        for i in 0..n {
            w[i * m + n + i] = lit(1.0);
        }
        let weights: Vec<T> = self.d.iter().copied().chain(qd_beta[..n].iter().copied()).collect();
        let mut dw = vec![z; m];
        for j in (0..n).rev() {
            // Rows above j are changed; row j is not changed by them.
            let (above, rest) = w.split_at_mut(j * m);
            let wj = &rest[..m];
            for ((o, &a), &b) in dw.iter_mut().zip(wj).zip(&weights) {
                *o = a * b;
            }
            let dj = wj.iter().zip(&dw).fold(z, |s, (&a, &b)| s + a * b);
            self.d[j] = dj;
            self.u[j][j] = lit(1.0);
            if dj <= z {
                // A direction without variance: U's column stays the unit vector.
                for i in 0..j {
                    self.u[i][j] = z;
                }
                continue;
            }
            for (i, wi) in above.chunks_exact_mut(m).enumerate() {
                let uij = wi.iter().zip(&dw).fold(z, |s, (&a, &b)| s + a * b) / dj;
                self.u[i][j] = uij;
                for (a, &b) in wi.iter_mut().zip(wj) {
                    *a = *a - uij * b;
                }
            }
        }
    }

    /// One scalar measurement z = h·x + v (variance r), Bierman's update of U and D.
    #[allow(clippy::needless_range_loop)] // matrix algebra reads best indexed
    pub fn update(&mut self, h: &[(usize, f64)], z: f64, r: f64) {
        let n = self.x.len();
        let zero: T = lit(0.0);
        let h: Vec<(usize, T)> = h.iter().map(|&(k, v)| (k, T::from_f64(v, QClass::Generic))).collect();
        // f = Uᵀhᵀ, v = D f.
        let f: Vec<T> = (0..n).map(|j| h.iter().fold(zero, |s, &(k, v)| s + self.u[k][j] * v)).collect();
        let v: Vec<T> = (0..n).map(|j| self.d[j] * f[j]).collect();
        let mut alpha = T::from_f64(r, QClass::Generic);
        let mut b = vec![zero; n];
        for j in 0..n {
            let before = alpha;
            alpha = alpha + f[j] * v[j];
            if f[j] == zero && v[j] == zero {
                b[j] = zero;
                continue; // column untouched by this measurement
            }
            let lambda = -f[j] / before;
            self.d[j] = self.d[j] * before / alpha;
            for i in 0..j {
                let uij = self.u[i][j];
                self.u[i][j] = uij + b[i] * lambda;
                b[i] = b[i] + uij * v[j];
            }
            b[j] = v[j];
        }
        let innov = h.iter().fold(T::from_f64(z, QClass::Generic), |acc, &(j, v)| acc - v * self.x[j]);
        for i in 0..n {
            self.x[i] = self.x[i] + b[i] / alpha * innov;
        }
    }

    /// The compass measurement Z = φ − φ_e (three rows; 18-state filters only).
    pub fn update_compass(&mut self, z: &[f64; 3], r: &[f64; 3]) {
        for i in 0..3 {
            self.update(&[(PHI + i, 1.0), (PHI_E + i, -1.0)], z[i], r[i]);
        }
    }

    /// The GPS measurement Z = [δp; δv] (six rows).
    pub fn update_gps(&mut self, z: &[f64; 6], r_pos: f64, r_vel: f64) {
        for i in 0..3 {
            self.update(&[(DP + i, 1.0)], z[i], r_pos);
            self.update(&[(DV + i, 1.0)], z[3 + i], r_vel);
        }
    }
}

/// The inverse of a symmetric positive definite matrix, None if it is not. Equilibrated first
/// (C = S A S with S = diag(1/√aᵢᵢ), so C has a unit diagonal; A⁻¹ = S C⁻¹ S): the covariances mix
/// rad² ~1e-8 with m² ~1e2, and single precision's Cholesky needs the scaling.
pub fn spd_inverse<T: Scalar>(a: &[Vec<T>]) -> Option<Vec<Vec<T>>> {
    let zero: T = lit(0.0);
    if a.iter().enumerate().any(|(i, r)| r[i] <= zero) {
        return None;
    }
    let sc: Vec<T> = a.iter().enumerate().map(|(i, r)| lit::<T>(1.0) / r[i].sqrt()).collect();
    let c: Vec<Vec<T>> =
        a.iter().enumerate().map(|(i, r)| r.iter().enumerate().map(|(j, v)| sc[i] * *v * sc[j]).collect()).collect();
    let ci = cholesky_inverse(&c)?;
    Some(ci.iter().enumerate().map(|(i, r)| r.iter().enumerate().map(|(j, v)| sc[i] * *v * sc[j]).collect()).collect())
}

#[allow(clippy::needless_range_loop)] // matrix algebra reads best indexed
fn cholesky_inverse<T: Scalar>(a: &[Vec<T>]) -> Option<Vec<Vec<T>>> {
    let n = a.len();
    let zero: T = lit(0.0);
    let mut l = vec![vec![zero; n]; n];
    for i in 0..n {
        for j in 0..=i {
            let s = (0..j).fold(a[i][j], |s, k| s - l[i][k] * l[j][k]);
            if i == j {
                if s <= zero {
                    return None;
                }
                l[i][i] = s.sqrt();
            } else {
                l[i][j] = s / l[j][j];
            }
        }
    }
    // inv(A) = inv(L)ᵀ inv(L).
    let mut li = vec![vec![zero; n]; n];
    for i in 0..n {
        li[i][i] = lit::<T>(1.0) / l[i][i];
        for j in 0..i {
            let s = (j..i).fold(zero, |s, k| s + l[i][k] * li[k][j]);
            li[i][j] = -s / l[i][i];
        }
    }
    Some((0..n).map(|i| (0..n).map(|j| (i.max(j)..n).fold(zero, |s, k| s + li[k][i] * li[k][j])).collect()).collect())
}

/// The fusion of eq. 3.31 with β_m = 0 on the first `n` states (sub-filter 2's, all of them):
/// (x_f, P_f) with P_f = (P₁⁻¹ + P₂⁻¹)⁻¹ and x_f = P_f (P₁⁻¹ x₁ + P₂⁻¹ x₂); None if a factor of
/// sub-filter 2 has D ≤ 0.
///
/// Computed in factored form, as sub-filter 2's estimate measuring sub-filter 1's state: x₂ = x + e,
/// cov e = P₂ = U₂D₂U₂ᵀ, so U₂⁻¹x₂ = U₂⁻¹x + e′ with cov e′ = D₂ diagonal: n independent scalar rows
/// (h = row i of U₂⁻¹, r = D₂ᵢ), each a Bierman update of a copy of sub-filter 1's factors. In exact
/// arithmetic this is the information form (the conditional of the common states given both); it
/// inverts no covariance. The covariance forms need (P₁ + P₂)⁻¹ or P₁⁻¹, P₂⁻¹, whose equilibrated
/// pivots fall to 1e-5 (`fusion_conditioning`): in single precision the gain then carries a
/// relative error near n·2⁻²⁴/1e-5 ≈ 9 %, and the Joseph form's excess (δK)(P₁ + P₂)(δK)ᵀ ≈ 0.09²·P₁
/// on the position (P₁ ≈ 1e5 m² in the compass sub-filter) made the f32 fused position variance
/// 576 times the f64 one; the information form failed outright (a non-positive pivot).
#[allow(clippy::needless_range_loop)] // matrix algebra reads best indexed
pub fn fuse<T: Scalar>(a: &Kf<T>, b: &Kf<T>, n: usize) -> Option<(Vec<T>, Vec<Vec<T>>)> {
    let zero: T = lit(0.0);
    if b.d[..n].iter().any(|&d| d <= zero) {
        return None;
    }
    // V = U₂⁻¹ (unit upper triangular): from U V = I, row by row from the last.
    let mut v = vec![vec![zero; n]; n];
    for i in (0..n).rev() {
        v[i][i] = lit(1.0);
        for j in i + 1..n {
            v[i][j] = -(i + 1..=j).fold(zero, |s, k| s + b.u[i][k] * v[k][j]);
        }
    }
    let mut f = a.clone();
    for (i, row) in v.iter().enumerate() {
        let z = (i..n).fold(zero, |s, j| s + row[j] * b.x[j]);
        let h: Vec<(usize, f64)> = (i..n).map(|j| (j, row[j].to_f64())).collect();
        f.update(&h, z.to_f64(), b.d[i].to_f64());
    }
    let p = f.p();
    Some((f.x[..n].to_vec(), p[..n].iter().map(|r| r[..n].to_vec()).collect()))
}

#[cfg(test)]
#[path = "federated_tests.rs"]
mod tests;
