//! Earth model and navigation (reference-design.md): navigation frame x east, y north, z up.
//!
//! - Radii (first order in the flattening e, the spec's corrected form): R_N = R_e(1 − 2e + 3e sin²φ),
//!   R_E = R_e(1 + e sin²φ).
//! - ω_ie^n = [0, ω_ie cos φ, ω_ie sin φ], ω_en^n = [−V_y/(R_N+h), V_x/(R_E+h), V_x tan φ/(R_E+h)].
//! - Gravity: WGS-84 normal gravity (Somigliana closed form) γ(φ) = γ_e (1 + k sin²φ)/√(1 − e² sin²φ)
//!   with e² = e(2 − e) from the profile's flattening and γ_e from the profile, then the first-order
//!   free-air correction γ(φ, h) = γ(φ)(1 − 2h/R_e) (−3.086e-6 s⁻² · h at the equator); g^n = [0, 0, −γ].
//! - V̇ = C_b^n f^b − (2ω_ie^n + ω_en^n) × V + g^n; λ̇ = V_x/((R_E+h) cos φ); φ̇ = V_y/(R_N+h); ḣ = V_z.
//!
//! Integration: one explicit Euler step per update period T, every derivative evaluated from the
//! state at the start of the step (velocity and position advance together from the old state).
//!
//! Fixed point (classes of `numerics::QClass`, defaults of the profile's `[iq]`): lengths (earth radius,
//! height, R + h) are `Length` (Q8: ±8.4e6 m, LSB 3.9 mm), latitude and longitude `Nav` (Q29: ±4 rad,
//! LSB 1.9e-9 rad = 1.2 cm), velocity and specific force `Accel` (Q20: ±2048 m/s, LSB 9.5e-7), rates
//! `Rate` (Q24). The quotients V/(R+h) are formed with `div_to` straight into the class of the result
//! (`_IQNdiv` with N = Q_result − Q_V + Q_R), since the coarse length Q would otherwise be the quotient's.
//! Limits that follow: ω_ie (7.29e-5 rad/s) and ω_en are held to 6e-8 rad/s (Q24, 8e-4 of ω_ie); the
//! position and height increments V·T are floored to one LSB of their class every step, which biases
//! them by up to one LSB per step: up to 1.9e-9 rad (1.2 cm) of latitude/longitude and 3.9 mm of height
//! per step, i.e. up to 1.5 m/s and 0.49 m/s of apparent motion. The fixed-point navigation serves the
//! earth-rate correction of the attitude; it is not a positioning solution.

use super::{lit, Mat3, Vec3};
use crate::numerics::counter::Work;
use crate::numerics::{QClass, Scalar};
use crate::profile::Navigation;

/// Somigliana's k = b γ_p / (a γ_e) − 1 of WGS-84 (NIMA TR8350.2, eq. 4-1).
pub const SOMIGLIANA_K: f64 = 0.001_931_852_652_41;

/// Position and velocity: latitude φ and longitude λ in rad, height in m, V in m/s (ENU).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavState<T> {
    /// Latitude φ, rad.
    pub lat: T,
    /// Longitude λ, rad.
    pub lon: T,
    /// Height h, m.
    pub height: T,
    /// Velocity east, north, up, m/s.
    pub vel: Vec3<T>,
}

impl<T: Scalar> NavState<T> {
    /// The initial state of a profile.
    pub fn from_profile(nav: &Navigation) -> Self {
        NavState {
            lat: T::from_f64(nav.latitude_deg.to_radians(), QClass::Nav),
            lon: T::from_f64(nav.longitude_deg.to_radians(), QClass::Nav),
            height: T::from_f64(nav.height_m, QClass::Length),
            vel: nav.velocity_enu.map(|v| T::from_f64(v, QClass::Accel)),
        }
    }
}

/// The earth quantities of one step, shared by the rate correction and the navigation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EarthRates<T> {
    /// ω_ie^n, rad/s.
    pub w_ie: Vec3<T>,
    /// ω_en^n, rad/s.
    pub w_en: Vec3<T>,
    /// sin φ, cos φ.
    pub sin_lat: T,
    /// cos φ.
    pub cos_lat: T,
    /// R_N + h, m.
    pub rn_h: T,
    /// R_E + h, m.
    pub re_h: T,
}

impl<T: Scalar> EarthRates<T> {
    /// ω_in^n = ω_ie^n + ω_en^n (in the C, a loop of three passes: [`Scalar::work`]).
    pub fn w_in(&self) -> Vec3<T> {
        (0..3).for_each(|_| T::work(Work::LOOP_PASS));
        [0, 1, 2].map(|i| (self.w_ie[i] + self.w_en[i]).to_class(QClass::Rate))
    }
}

/// The earth model's constants as the firmware holds them.
#[derive(Debug, Clone, Copy)]
pub struct EarthModel<T> {
    radius: T,
    flattening: T,
    earth_rate: T,
    gamma_e: T,
    k: T,
    e2: T,
    zero: T,
    one: T,
    two: T,
    three: T,
}

impl<T: Scalar> EarthModel<T> {
    /// The earth model of a profile.
    pub fn new(nav: &Navigation) -> Self {
        let f = nav.flattening;
        EarthModel {
            radius: T::from_f64(nav.earth_radius_m, QClass::Length),
            flattening: T::from_f64(f, QClass::Nav),
            earth_rate: T::from_f64(nav.earth_rate_rad_s, QClass::Rate),
            gamma_e: T::from_f64(nav.gravity_equator, QClass::Accel),
            k: lit(SOMIGLIANA_K),
            e2: lit(f * (2.0 - f)),
            zero: lit(0.0),
            one: lit(1.0),
            two: lit(2.0),
            three: lit(3.0),
        }
    }

    /// Earth rate, transport rate and radii at a state.
    pub fn rates(&self, s: &NavState<T>) -> EarthRates<T> {
        // The C's `earth_rates()` call ([`Scalar::work`]).
        T::work(Work::call(0));
        let sin_lat = s.lat.sin();
        let cos_lat = s.lat.cos();
        let s2 = sin_lat * sin_lat;
        let e = self.flattening;
        let rn = self.radius * (self.one - self.two * e + self.three * e * s2);
        let re = self.radius * (self.one + e * s2);
        let rn_h = (rn + s.height).to_class(QClass::Length);
        let re_h = (re + s.height).to_class(QClass::Length);
        // tan φ in GLOBAL_Q: the Nav Q (29) would saturate it above 76°.
        let tan_lat = sin_lat.div_to(cos_lat, QClass::Generic);
        let [vx, vy, _] = s.vel;
        let w_ie = [self.zero, self.earth_rate * cos_lat, self.earth_rate * sin_lat].map(|x| x.to_class(QClass::Rate));
        let w_en = [
            -(vy.div_to(rn_h, QClass::Rate)),
            vx.div_to(re_h, QClass::Rate),
            (vx * tan_lat).div_to(re_h, QClass::Rate),
        ]
        .map(|x| x.to_class(QClass::Rate));
        EarthRates { w_ie, w_en, sin_lat, cos_lat, rn_h, re_h }
    }

    /// Normal gravity γ(φ, h), m/s².
    pub fn gravity(&self, sin_lat: T, height: T) -> T {
        // The C's `gravity(s, h)` call ([`Scalar::work`]).
        T::work(Work::call(2));
        let s2 = sin_lat * sin_lat;
        let gamma = self.gamma_e * (self.one + self.k * s2) / (self.one - self.e2 * s2).sqrt();
        (gamma * (self.one - (self.two * height).div_to(self.radius, QClass::Generic))).to_class(QClass::Accel)
    }

    /// One navigation step of `dt` seconds with T = C_b^n and the specific force f^b (m/s²).
    pub fn step(&self, s: &mut NavState<T>, c_bn: &Mat3<T>, f_b: &Vec3<T>, dt: T) {
        self.step_with_rates(s, &self.rates(s), c_bn, f_b, dt);
    }

    /// [`EarthModel::step`] with the state's earth rates `r` (= `self.rates(s)`) already computed.
    pub fn step_with_rates(&self, s: &mut NavState<T>, r: &EarthRates<T>, c_bn: &Mat3<T>, f_b: &Vec3<T>, dt: T) {
        // The C's `navigate(f_b)` call and its two loops of three passes ([`Scalar::work`]).
        T::work(Work::call(1));
        (0..6).for_each(|_| T::work(Work::LOOP_PASS));
        let g = self.gravity(r.sin_lat, s.height);
        let f_n = [0, 1, 2].map(|i| c_bn[i][0] * f_b[0] + c_bn[i][1] * f_b[1] + c_bn[i][2] * f_b[2]);
        let a = [0, 1, 2].map(|i| self.two * r.w_ie[i] + r.w_en[i]);
        let v = s.vel;
        let coriolis = [a[1] * v[2] - a[2] * v[1], a[2] * v[0] - a[0] * v[2], a[0] * v[1] - a[1] * v[0]];
        let gravity_n = [self.zero, self.zero, -g];
        let lat_dot = v[1].div_to(r.rn_h, QClass::Nav);
        let lon_dot = v[0].div_to(r.re_h * r.cos_lat, QClass::Nav);
        for i in 0..3 {
            let v_dot = f_n[i] - coriolis[i] + gravity_n[i];
            s.vel[i] = (v[i] + v_dot * dt).to_class(QClass::Accel);
        }
        // T in the position's class, so that the product keeps its Q (a GLOBAL_Q T would floor it to Q24).
        let dt_nav = dt.to_class(QClass::Nav);
        s.lat = (s.lat + lat_dot * dt_nav).to_class(QClass::Nav);
        s.lon = (s.lon + lon_dot * dt_nav).to_class(QClass::Nav);
        s.height = (s.height + v[2] * dt).to_class(QClass::Length);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_gravity_values() {
        let m = EarthModel::<f64>::new(&Navigation::default());
        // WGS-84: γ(0) = 9.7803253359, γ(90°) = 9.8321849378 (flattening 1/298.257 vs 1/298.257223563
        // changes the pole value by < 1e-8).
        assert!((m.gravity(0.0, 0.0) - 9.780_325_335_9).abs() < 1e-10);
        assert!((m.gravity(1.0, 0.0) - 9.832_184_937_8).abs() < 1e-7);
        // Free-air gradient 2γ/R_e = 3.07e-6 s⁻² at the equator.
        let d = m.gravity(0.0, 0.0) - m.gravity(0.0, 1000.0);
        assert!((d - 2.0 * 9.780_325_335_9 * 1000.0 / 6_378_137.0).abs() < 1e-12);
    }

    #[test]
    fn radii_and_rates() {
        let nav =
            Navigation { latitude_deg: 30.0, height_m: 0.0, velocity_enu: [10.0, 20.0, 0.0], ..Default::default() };
        let m = EarthModel::<f64>::new(&nav);
        let r = m.rates(&NavState::from_profile(&nav));
        let e = nav.flattening;
        assert!((r.rn_h - 6_378_137.0 * (1.0 - 2.0 * e + 3.0 * e * 0.25)).abs() < 1e-6);
        assert!((r.re_h - 6_378_137.0 * (1.0 + e * 0.25)).abs() < 1e-6);
        // Meridian radius below the prime-vertical one everywhere except the pole.
        assert!(r.rn_h < r.re_h);
        assert!((r.w_ie[1] - 7.292115e-5 * (3f64.sqrt() / 2.0)).abs() < 1e-18);
        assert!((r.w_en[0] + 20.0 / r.rn_h).abs() < 1e-18);
        assert!((r.w_en[2] - 10.0 * (30f64.to_radians().tan()) / r.re_h).abs() < 1e-18);
    }

    #[test]
    fn constant_velocity_moves_position() {
        // Level, no specific force beyond gravity: V_x = 10 m/s east moves longitude by V/(R_E+h)/cos φ.
        let nav = Navigation { velocity_enu: [10.0, 0.0, 0.0], ..Default::default() };
        let m = EarthModel::<f64>::new(&nav);
        let mut s = NavState::from_profile(&nav);
        let r0 = m.rates(&s);
        let lon0 = s.lon;
        let eye = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let f = [0.0, 0.0, m.gravity(r0.sin_lat, s.height)];
        m.step(&mut s, &eye, &f, 0.008);
        // Tolerance: one ulp of λ ≈ 1.95 rad (2.2e-16) for the addition.
        assert!((s.lon - lon0 - 10.0 * 0.008 / (r0.re_h * r0.cos_lat)).abs() < 4.5e-16);
        // The east velocity sees −(2ω_ie + ω_en) × V: a northward Coriolis/transport term of
        // −(2ω_ie sinφ + V tanφ/(R_E+h))·V_x and an upward one of (2ω_ie cosφ + V/(R_E+h))·V_x.
        let vy_dot = -(2.0 * r0.w_ie[2] + r0.w_en[2]) * 10.0;
        assert!((s.vel[1] - vy_dot * 0.008).abs() < 1e-15);
        let vz_dot = (2.0 * r0.w_ie[1] + r0.w_en[1]) * 10.0;
        assert!((s.vel[2] - vz_dot * 0.008).abs() < 1e-15);
    }
}
