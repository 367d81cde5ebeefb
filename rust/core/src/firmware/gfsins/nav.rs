//! The C6727B's navigation on every packet (issue 23): the gfnav modules run in the DSP's arithmetic.
//!
//! Per packet (200 Hz), stage by stage (each a generic function, so the timing model counts the
//! very code that runs; [`Nav::step`] runs them):
//! - **decode**: the nine counts to m/s² (`INTSP` + `MPYSP`), the compass and GPS words when new;
//! - **strapdown**: the array's exact inversion ([`Inverse`], built from the profile's layout: for
//!   the thesis's, eq. 2.11–2.13), the rate recovery ([`RateRecovery`], singular steps bridged), the attitude quaternion's RK4 step
//!   ([`Rk4`], rates ω_nb^b = ω_ib^b − C_n^b ω_in^n at the step's start, middle and end), velocity
//!   and position (explicit Euler, [`EarthModel`]'s gravity and earth rates);
//! - **compass filter** (10 Hz, on `NEW_COMPASS`): sub-filter 1 (18 states) predicted over the time
//!   since its last update with Φ from the error model at the current state
//!   ([`federated::error_model`], [`federated::discretise`]) and updated with Z = φ − φ_e, φ the
//!   attitude difference between the strapdown and the compass's heading, pitch and roll;
//! - **GPS filter** (1 Hz, on `NEW_GPS` with a valid fix): sub-filter 2 (15 states), Z = [δp; δv];
//! - **fusion** (after the GPS filter): [`federated::fuse`] with β_master = 0, β₁ = β₂ = ½, no reset.
//!
//! The navigation solution is the strapdown's corrected by the last fused error estimate (open
//! loop, as the thesis's "no reset": the strapdown is never corrected, the output is).
//!
//! Choices ([unconfirmed]: the thesis publishes no DSP code):
//! - Start: at the first packet that has both a compass reading and a valid GPS fix. Attitude from
//!   the tilt of the specific force at the array's origin (pitch atan2(f_x, √(f_y² + f_z²)), roll
//!   atan2(f_y, f_z); the centre part's A₇…A₉ in the thesis's layout) and the
//!   compass heading; velocity from the fix's speed and course (no vertical speed in NMEA: 0);
//!   position at the fix moved forward by v·`gps_age_ms` (the fix is that old); the recovered rate
//!   starts at the earth and transport rate in body axes.
//! - Position is held as metres east, north, up from the first fix: in single precision a latitude
//!   in radians has an ulp of 3e-8 rad (0.19 m), and a 5 ms step at 22 m/s moves 1.7e-8 rad north,
//!   1e-8 rad east (longitude ulp 1.2e-7 rad): integrated in radians the position would not move.
//!   Latitude for the earth model is lat₀ + N/(R_M + h₀); the GPS fix enters as the integer
//!   difference of its words from the first fix's, scaled once.
//! - The GPS fix is `gps_age_ms` old when its packet arrives (fix epoch → NMEA latency → the
//!   sentences at 19 200 baud → the node's next tick): the DSP moves the fix forward by v·age.
//! - Body axes are those of the array's positions (algorithms.md §4 layout, as `synth vehicle`
//!   places the parts: x forward, y left, z up); C_b^n from heading ψ, pitch θ, roll φ is
//!   Rz(90° − ψ)·Ry(−θ)·Rx(φ). The error model takes this C_b^n, not gfnav's straight-line one.
//! - Noise figures, P₀ and the compass's correlation time: chapter 5 ([`Scenario::chapter5`]).

use super::frame::{self, Packet};
use crate::firmware::euler::euler_to_quat;
use crate::firmware::gfnav::federated::{self, Kf, Linearisation, Scenario, N_COMPASS, N_GPS};
use crate::firmware::gfnav::{Bridge, Inverse, RateConfig, RateOutput, RateRecovery, ZNumerator};
use crate::firmware::{body_rate_nav, dcm, lit, EarthModel, Mat3, NavState, Quat, Rk4, Vec3};
use crate::numerics::{QClass, Scalar};
use crate::profile::{Navigation, QuatDerivative};

/// Standard gravity, m/s² per g (the counts' unit).
pub const G0: f64 = 9.806_65;

/// What the navigation needs from the profile.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavConfig {
    /// The packet period, s.
    pub dt: f64,
    /// The array's inversion, built from the places and channels of the parts
    /// (`array.parts`, `array.lever_arm_m`: the node reads the parts the same profile places).
    pub array: Inverse,
    /// One count, g.
    pub lsb_g: f64,
    /// Rate recovery's singular threshold |D|, rad²/s².
    pub min_denominator: f64,
    /// Age of a GPS fix when its packet reaches the DSP, s.
    pub gps_age_s: f64,
    /// The compass errors' correlation time the compass sub-filter models, s (`compass.correlation_time_s`).
    pub compass_tau_s: f64,
}

/// What the navigation has after a packet (f64 views of the DSP's values).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavOutput {
    /// The recovered rate ω_ib^b, rad/s.
    pub rate: [f64; 3],
    /// Per axis: the rate was bridged (not solved from the products).
    pub bridged: [bool; 3],
    /// Roll, pitch, heading of the solution, rad (heading clockwise from north).
    pub attitude: [f64; 3],
    /// Velocity east, north, up, m/s.
    pub vel: [f64; 3],
    /// Latitude, longitude (rad), height (m).
    pub pos: [f64; 3],
    /// The compass filter ran on this packet.
    pub compass_update: bool,
    /// The GPS filter ran on this packet.
    pub gps_update: bool,
    /// The fusion on this packet: None (not run), Some(false) refused, Some(true) done.
    pub fused: Option<bool>,
}

/// The first fix: the origin of the position in metres.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Origin {
    lat_e7: i32,
    lon_e7: i32,
    alt_cm: i32,
    /// lat₀ (rad), h₀ (m) as f64 for the output.
    lat: f64,
    lon: f64,
    height: f64,
}

/// The strapdown's state (no heap: the timing model copies it before each step).
#[derive(Debug, Clone)]
pub struct Ins<T> {
    earth: EarthModel<T>,
    rk4: Rk4<T>,
    array: Inverse,
    lat0: T,
    h0: T,
    /// 1/(R_M + h₀), 1/((R_N + h₀) cos lat₀), rad per metre.
    per_m: [T; 2],
    rate: Option<RateRecovery<T>>,
    q: Quat<T>,
    vel: Vec3<T>,
    /// East, north, up from the origin, m.
    pos: Vec3<T>,
    /// ω_nb^b of the last step (the RK4's start rate).
    w_nb: Vec3<T>,
    /// The last specific force in ENU (the error model's f).
    f_n: Vec3<T>,
    /// The rate the recovery started from.
    w_ib0: Vec3<T>,
}

/// The navigation state between packets, in the DSP's arithmetic `T`.
#[derive(Debug, Clone)]
pub struct Nav<T> {
    cfg: NavConfig,
    scenario: Scenario,
    origin: Option<Origin>,
    compass_seen: bool,
    ins: Ins<T>,
    kf1: Kf<T>,
    kf2: Kf<T>,
    /// Packet sequence of each sub-filter's last update.
    last: [u16; 2],
    /// The last fused error estimate (15 states).
    fused: Option<Vec<T>>,
    /// Steps bridged since the spell began (0: no spell).
    spell: u64,
}

/// C_b^n = Rz(90° − ψ)·Ry(−θ)·Rx(φ) as a quaternion: [`euler_to_quat`] of yaw 90° − ψ, pitch −θ.
fn euler_quat<T: Scalar>(heading: T, pitch: T, roll: T) -> Quat<T> {
    euler_to_quat(lit::<T>(std::f64::consts::FRAC_PI_2) - heading, -pitch, roll)
}

/// C_b^n from heading, pitch, roll (rad).
fn euler_dcm<T: Scalar>(heading: T, pitch: T, roll: T) -> Mat3<T> {
    dcm(&euler_quat(heading, pitch, roll))
}

/// A stage's inputs: the packet's values in the DSP's arithmetic.
#[derive(Debug, Clone, Copy)]
pub struct Decoded<T> {
    /// A₁…A₉, m/s².
    pub accel: [T; 9],
    /// Compass heading, pitch, roll, rad (when new).
    pub compass: Option<[T; 3]>,
    /// GPS speed (m/s), course (rad) (when new and valid).
    pub gps_vel: Option<[T; 2]>,
}

/// The decode stage: counts to m/s² and, when the packet says they are new, the compass's tenths of
/// a degree and the fix's speed and course to SI.
pub fn decode<T: Scalar>(p: &Packet, lsb_g: f64) -> Decoded<T> {
    let k: T = lit(lsb_g * G0);
    let tenth_deg: T = lit(0.1f64.to_radians());
    let compass = (p.flags & frame::NEW_COMPASS != 0).then(|| p.compass.map(|n| tenth_deg.mul_i32(i32::from(n))));
    let gps_vel = (p.flags & frame::NEW_GPS != 0 && p.flags & frame::GPS_VALID != 0).then(|| {
        [
            lit::<T>(0.01).mul_i32(i32::from(p.gps.speed_cm_s)),
            lit::<T>(0.01f64.to_radians()).mul_i32(i32::from(p.gps.course_cdeg)),
        ]
    });
    Decoded { accel: p.accel.map(|n| k.mul_i32(i32::from(n))), compass, gps_vel }
}

impl<T: Scalar> Ins<T> {
    /// The same state in the arithmetic `S` (values through f64).
    pub fn cast<S: Scalar>(&self) -> Ins<S> {
        let c = |x: T| S::from_f64(x.to_f64(), QClass::Generic);
        Ins {
            earth: EarthModel::new(&Navigation::default()),
            rk4: Rk4::new(self.rk4.step().to_f64(), QuatDerivative::Correct),
            array: self.array,
            lat0: c(self.lat0),
            h0: c(self.h0),
            per_m: self.per_m.map(c),
            rate: self.rate.as_ref().map(RateRecovery::cast),
            q: self.q.map(c),
            vel: self.vel.map(c),
            pos: self.pos.map(c),
            w_nb: self.w_nb.map(c),
            f_n: self.f_n.map(c),
            w_ib0: self.w_ib0.map(c),
        }
    }

    /// The earth-model state at the current position (latitude from the north offset).
    fn nav_state(&self) -> NavState<T> {
        NavState {
            lat: self.lat0 + self.pos[1] * self.per_m[0],
            lon: lit(0.0),
            height: self.h0 + self.pos[2],
            vel: self.vel,
        }
    }

    /// One step: inversion, rate recovery, attitude, velocity and position.
    pub fn step(&mut self, a: &[T; 9]) -> RateOutput<T> {
        let m = self.array.apply(a);
        let out = match self.rate.as_mut() {
            Some(r) => r.step(&m),
            None => {
                return RateOutput { rate: [lit(0.0); 3], bridged: [Bridge::Start; 3], denominators: [lit(0.0); 3] }
            }
        };
        let s = self.nav_state();
        let r = self.earth.rates(&s);
        let c_bn = dcm(&self.q);
        let w_end = body_rate_nav(&c_bn, &out.rate, &r.w_in());
        let w_mid = crate::firmware::midpoint(&self.w_nb, &w_end);
        self.rk4.step_quat(&mut self.q, &[self.w_nb, w_mid, w_end]);
        self.w_nb = w_end;
        // Velocity and position from the state at the step's start (EarthModel::step's scheme).
        let dt = self.rk4.step();
        let two: T = lit(2.0);
        let g = self.earth.gravity(r.sin_lat, s.height);
        let f_b = m.accel;
        let f_n = [0, 1, 2].map(|i| c_bn[i][0] * f_b[0] + c_bn[i][1] * f_b[1] + c_bn[i][2] * f_b[2]);
        let w = [0, 1, 2].map(|i| two * r.w_ie[i] + r.w_en[i]);
        let v = self.vel;
        let coriolis = [w[1] * v[2] - w[2] * v[1], w[2] * v[0] - w[0] * v[2], w[0] * v[1] - w[1] * v[0]];
        for i in 0..3 {
            let v_dot = f_n[i] - coriolis[i] - if i == 2 { g } else { lit(0.0) };
            self.vel[i] = v[i] + v_dot * dt;
            self.pos[i] = self.pos[i] + v[i] * dt;
        }
        self.f_n = f_n;
        out
    }
}

impl<T: Scalar> Nav<T> {
    /// The compass errors' correlation time the compass sub-filter models, s.
    pub fn compass_tau_s(&self) -> f64 {
        self.scenario.compass_tau
    }

    /// A navigation that starts at the first packet with a compass reading and a valid fix.
    pub fn new(cfg: NavConfig) -> Self {
        let scenario = Scenario { compass_tau: cfg.compass_tau_s, ..Scenario::chapter5() };
        let p0 = scenario.p0();
        let zero: T = lit(0.0);
        Nav {
            cfg,
            scenario,
            origin: None,
            compass_seen: false,
            ins: Ins {
                earth: EarthModel::new(&Navigation::default()),
                rk4: Rk4::new(cfg.dt, QuatDerivative::Correct),
                array: cfg.array,
                lat0: zero,
                h0: zero,
                per_m: [zero; 2],
                rate: None,
                q: [lit(1.0), zero, zero, zero],
                vel: [zero; 3],
                pos: [zero; 3],
                w_nb: [zero; 3],
                f_n: [zero; 3],
                w_ib0: [zero; 3],
            },
            kf1: Kf::new(&p0, 0.5),
            kf2: Kf::new(&p0[..N_GPS], 0.5),
            last: [0; 2],
            fused: None,
            spell: 0,
        }
    }

    /// The same navigation in the arithmetic `S` (values through f64: exact from a narrower float);
    /// the timing model runs such a copy in the counting type.
    pub fn cast<S: Scalar>(&self) -> Nav<S> {
        let c = |x: T| S::from_f64(x.to_f64(), QClass::Generic);
        let kf = |k: &Kf<T>| Kf {
            x: k.x.iter().map(|&v| c(v)).collect(),
            u: k.u.iter().map(|r| r.iter().map(|&v| c(v)).collect()).collect(),
            d: k.d.iter().map(|&v| c(v)).collect(),
        };
        Nav {
            cfg: self.cfg,
            scenario: self.scenario,
            origin: self.origin,
            compass_seen: self.compass_seen,
            ins: self.ins.cast(),
            kf1: kf(&self.kf1),
            kf2: kf(&self.kf2),
            last: self.last,
            fused: self.fused.as_ref().map(|x| x.iter().map(|&v| c(v)).collect()),
            spell: self.spell,
        }
    }

    /// The array's inversion (`array.parts`).
    pub fn array(&self) -> &Inverse {
        &self.cfg.array
    }

    /// Whether the navigation has started.
    pub fn started(&self) -> bool {
        self.ins.rate.is_some()
    }

    /// The rate the recovery started from (ω_ib^b at the start).
    pub fn initial_rate(&self) -> Vec3<T> {
        self.ins.w_ib0
    }

    /// The strapdown's state.
    pub fn ins(&self) -> &Ins<T> {
        &self.ins
    }

    /// The start (see the module docs): at the first packet with a compass reading and a valid fix.
    /// Returns whether the navigation runs from this packet on.
    pub fn start(&mut self, p: &Packet, d: &Decoded<T>) -> bool {
        self.compass_seen |= d.compass.is_some();
        if self.started() || !self.compass_seen || d.gps_vel.is_none() {
            return self.started();
        }
        let g = &p.gps;
        let deg = std::f64::consts::PI / 180.0;
        let (lat, lon) = (f64::from(g.lat_e7) * 1e-7 * deg, f64::from(g.lon_e7) * 1e-7 * deg);
        let height = f64::from(g.alt_cm) / 100.0;
        self.origin = Some(Origin { lat_e7: g.lat_e7, lon_e7: g.lon_e7, alt_cm: g.alt_cm, lat, lon, height });
        let ins = &mut self.ins;
        ins.lat0 = T::from_f64(lat, QClass::Nav);
        ins.h0 = T::from_f64(height, QClass::Length);
        let zero3 = [lit(0.0); 3];
        let r = ins.earth.rates(&NavState { lat: ins.lat0, lon: lit(0.0), height: ins.h0, vel: zero3 });
        let one: T = lit(1.0);
        ins.per_m = [one / r.rn_h, one / (r.re_h * r.cos_lat)];
        let tenth_deg: T = lit(0.1f64.to_radians());
        let heading = tenth_deg.mul_i32(i32::from(p.compass[0]));
        let [fx, fy, fz] = self.cfg.array.accel(&d.accel);
        let pitch = fx.atan2((fy * fy + fz * fz).sqrt());
        let roll = fy.atan2(fz);
        ins.q = euler_quat(heading, pitch, roll);
        let [speed, course] = d.gps_vel.unwrap_or([lit(0.0); 2]);
        ins.vel = [speed * course.sin(), speed * course.cos(), lit(0.0)];
        // The fix is `gps_age_s` old (as in the GPS filter's measurement): the vehicle is v·age past it.
        let age: T = lit(self.cfg.gps_age_s);
        ins.pos = [ins.vel[0] * age, ins.vel[1] * age, lit(0.0)];
        let r = ins.earth.rates(&ins.nav_state());
        // ω_ib^b = C_n^b ω_in^n at the start (ω_nb^b = 0: the vehicle does not turn).
        let w_ib = body_rate_nav(&dcm(&ins.q), &zero3, &r.w_in()).map(|x| -x);
        let rc = RateConfig {
            dt: self.cfg.dt,
            min_denominator: self.cfg.min_denominator,
            z_numerator: ZNumerator::Corrected,
        };
        ins.rate = Some(RateRecovery::new(rc, w_ib));
        ins.w_ib0 = w_ib;
        ins.w_nb = zero3;
        self.last = [p.sequence; 2];
        true
    }

    /// The strapdown stage (see [`Ins::step`]).
    pub fn strapdown(&mut self, a: &[T; 9]) -> RateOutput<T> {
        self.ins.step(a)
    }

    /// Put back a strapdown state (the timing model's copy from before a step).
    pub fn set_ins(&mut self, ins: Ins<T>) {
        self.ins = ins;
    }

    /// The error model's Φ and Q_d/β over `ticks` packets on the first `n` states at the current state.
    fn discrete(&self, n: usize, ticks: u16) -> (Vec<Vec<T>>, Vec<T>) {
        let ins = &self.ins;
        let s = ins.nav_state();
        let at = Linearisation { lat: s.lat, height: s.height, vel: ins.vel, c_bn: dcm(&ins.q), f_n: ins.f_n };
        let (a, q) = federated::error_model(&at, &self.scenario);
        let dt = lit::<T>(self.cfg.dt).mul_i32(i32::from(ticks));
        let (phi, qd) = federated::discretise(&a, &q, n, dt);
        let two: T = lit(2.0); // Q_d/β with β = ½
        (phi, qd.into_iter().map(|v| v * two).collect())
    }

    /// The compass filter stage (sub-filter 1): predict since its last update, then Z = φ − φ_e.
    pub fn compass_filter(&mut self, sequence: u16, hpr: &[T; 3]) {
        let ticks = sequence.wrapping_sub(self.last[0]);
        self.last[0] = sequence;
        let (phi, qd) = self.discrete(N_COMPASS, ticks);
        self.kf1.predict_with(&phi, &qd);
        let c_c = euler_dcm(hpr[0], hpr[1], hpr[2]);
        let c = dcm(&self.ins.q);
        // E = C Cᵀ_c ≈ I − [φ×]: φ from E's skew part.
        let e = |i: usize, j: usize| c[i][0] * c_c[j][0] + c[i][1] * c_c[j][1] + c[i][2] * c_c[j][2];
        let half: T = lit(0.5);
        let z = [(e(1, 2) - e(2, 1)) * half, (e(2, 0) - e(0, 2)) * half, (e(0, 1) - e(1, 0)) * half];
        let r = self.scenario.compass_white.map(|v| v * v);
        self.kf1.update_compass(&z.map(T::to_f64), &r);
    }

    /// The GPS filter stage (sub-filter 2): predict since its last update, then Z = [δp; δv].
    pub fn gps_filter(&mut self, sequence: u16, p: &Packet, speed_course: &[T; 2]) {
        let ticks = sequence.wrapping_sub(self.last[1]);
        self.last[1] = sequence;
        let (phi, qd) = self.discrete(N_GPS, ticks);
        self.kf2.predict_with(&phi, &qd);
        let Some(o) = self.origin else { return };
        let g = &p.gps;
        let [speed, course] = *speed_course;
        let v_gps = [speed * course.sin(), speed * course.cos(), lit(0.0)];
        let e7: T = lit(1e-7f64.to_radians());
        let age: T = lit(self.cfg.gps_age_s);
        let p_gps = [
            e7.mul_i32(g.lon_e7.wrapping_sub(o.lon_e7)) / self.ins.per_m[1] + v_gps[0] * age,
            e7.mul_i32(g.lat_e7.wrapping_sub(o.lat_e7)) / self.ins.per_m[0] + v_gps[1] * age,
            lit::<T>(0.01).mul_i32(g.alt_cm.wrapping_sub(o.alt_cm)),
        ];
        let z: [f64; 6] = std::array::from_fn(|i| {
            if i < 3 {
                (self.ins.pos[i] - p_gps[i]).to_f64()
            } else {
                (self.ins.vel[i - 3] - v_gps[i - 3]).to_f64()
            }
        });
        let s = &self.scenario;
        self.kf2.update_gps(&z, s.gps_position.powi(2), s.gps_velocity.powi(2));
    }

    /// The fusion stage: true when fused, false when refused (the last estimate is kept).
    pub fn fusion(&mut self) -> bool {
        match federated::fuse(&self.kf1, &self.kf2, N_GPS) {
            Some((x, _)) => {
                self.fused = Some(x);
                true
            }
            None => false,
        }
    }

    /// The solution: the strapdown corrected by the last fused estimate (f64 views; output only).
    pub fn solution(&self, out: &RateOutput<T>) -> NavOutput {
        let nan = [f64::NAN; 3];
        let Some(o) = self.origin else {
            return NavOutput {
                rate: nan,
                bridged: [false; 3],
                attitude: nan,
                vel: nan,
                pos: nan,
                compass_update: false,
                gps_update: false,
                fused: None,
            };
        };
        let x: Vec<f64> = self.fused.as_ref().map_or(vec![0.0; N_GPS], |x| x.iter().map(|v| v.to_f64()).collect());
        let c: [[f64; 3]; 3] = dcm(&self.ins.q).map(|r| r.map(T::to_f64));
        // C_true ≈ (I + [φ×]) C.
        let phi = [x[federated::PHI], x[federated::PHI + 1], x[federated::PHI + 2]];
        let sk = [[0.0, -phi[2], phi[1]], [phi[2], 0.0, -phi[0]], [-phi[1], phi[0], 0.0]];
        let ct: [[f64; 3]; 3] =
            std::array::from_fn(|i| std::array::from_fn(|j| c[i][j] + (0..3).map(|k| sk[i][k] * c[k][j]).sum::<f64>()));
        let heading = ct[0][0].atan2(ct[1][0]).rem_euclid(std::f64::consts::TAU);
        let pitch = ct[2][0].atan2(ct[2][1].hypot(ct[2][2]));
        let roll = ct[2][1].atan2(ct[2][2]);
        let vel: [f64; 3] = std::array::from_fn(|i| self.ins.vel[i].to_f64() - x[federated::DV + i]);
        let pm: [f64; 3] = std::array::from_fn(|i| self.ins.pos[i].to_f64() - x[federated::DP + i]);
        let pos =
            [o.lat + pm[1] * self.ins.per_m[0].to_f64(), o.lon + pm[0] * self.ins.per_m[1].to_f64(), o.height + pm[2]];
        NavOutput {
            rate: out.rate.map(T::to_f64),
            bridged: out.bridged.map(|b| b != Bridge::No),
            attitude: [roll, pitch, heading],
            vel,
            pos,
            compass_update: false,
            gps_update: false,
            fused: None,
        }
    }

    /// Count the step's bridged spell: true when a spell of bridged steps begins here (the step to
    /// report); a step solved on every axis ends the spell.
    pub fn spell(&mut self, out: &RateOutput<T>) -> bool {
        if out.bridged.iter().any(|b| *b != Bridge::No) {
            self.spell += 1;
            self.spell == 1
        } else {
            self.spell = 0;
            false
        }
    }
}
