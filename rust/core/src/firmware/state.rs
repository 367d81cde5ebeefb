//! The firmware's state and its stages. One method per stage (decode, attitude update, Euler
//! extraction, navigation, alignment) so the acquisition model can drive them in the firmware's
//! order and the timing model can run each with the counting type. Plain data in and out; nothing
//! allocates.

use super::algorithms::{attitude_update, samples_per_update};
use super::align::{level_attitude, LevelAligner};
use super::attitude::{AttitudeUpdate, Clipped, Correction, GpsAiding, GpsInput, StepInputs};
use super::decode::{Decoded, Decoder};
use super::euler::{euler_to_quat, EulerAngles, EulerExtractor};
use super::nav::{EarthModel, EarthRates, NavState};
use super::quat::dcm;
use super::{lit, Mat3, Quat, Vec3};
use crate::numerics::counter::Work;
use crate::numerics::{QClass, Scalar};
use crate::profile::{InitialAttitude, Profile, Schedule};
use crate::{Error, Result};

/// The attitude update period T of a profile, s: for `half-step` one timer tick per interval between
/// the update's samples (a read every tick; RK4's t, t+T/2, t+T span two ticks), one tick otherwise.
pub fn update_period_s(profile: &Profile) -> Result<f64> {
    let tick = profile.timer.period_us * 1e-6;
    match profile.firmware.schedule {
        Schedule::HalfStep => Ok((samples_per_update(&profile.firmware)? - 1) as f64 * tick),
        Schedule::Endpoint | Schedule::BackToBack => Ok(tick),
    }
}

/// The firmware's variables and constants in the numeric type `T`.
#[derive(Debug)]
pub struct Firmware<T: Scalar> {
    /// The attitude update of `firmware.algorithm`.
    attitude: Box<dyn AttitudeUpdate<T>>,
    earth_rate: bool,
    navigation: bool,
    initial_attitude: InitialAttitude,
    step_s: f64,
    t1: T,
    decoder: Decoder<T>,
    euler: EulerExtractor<T>,
    earth: EarthModel<T>,
    initial_yaw: T,
    q: Quat<T>,
    c_bn: Mat3<T>,
    nav: NavState<T>,
    aligner: LevelAligner<T>,
    /// The latest specific force decoded (the DCM's roll–pitch reference).
    last_accel: Option<Vec3<T>>,
    /// The algorithm takes the magnetic field (the DCM with `yaw_reference = "magnetometer"`).
    uses_magnetometer: bool,
    /// The latest magnetic field decoded, gauss.
    last_mag: Option<Vec3<T>>,
    /// The algorithm compensates the gyro's temperature drift (the wing unit with `firmware.wing`
    /// coefficients): the ISR decodes X/Y/ZTEMP_OUT.
    uses_temperature: bool,
    /// The latest X/Y/ZTEMP_OUT decoded, °C above 25 °C.
    last_temp: Option<Vec3<T>>,
    /// Axes at full scale: the gyro's over the reads since the last update, the accelerometer's and
    /// the magnetometer's of the latest read.
    clipped: Clipped,
    /// Fixes of the GPS stream not usable yet (in time order); None: the board has no GPS.
    gps_pending: Option<std::collections::VecDeque<GpsFix>>,
    /// The latest fix usable at the last update.
    gps: GpsInput<T>,
    /// When the latest fix taken reached the firmware, s.
    gps_last_available: Option<f64>,
    /// Fixes given so far (to name them in errors).
    gps_given: u64,
    /// The earth rates the attitude update computed from the current navigation state, which the
    /// navigation step of the same update takes instead of computing them again (they are a pure
    /// function of that state, and only the navigation step changes it). An emulation shortcut,
    /// not the target's code: the timing model counts the navigation stage computing them itself
    /// (see `timing::stages`).
    earth_rates_of_state: Option<EarthRates<T>>,
}

/// One fix of a GPS stream as the trace gives it (what the firmware takes of a GPS report).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GpsFix {
    /// Time of validity, s (the trace's time, as the physical input's).
    pub t_s: f64,
    /// The receiver's latency, s: the fix reaches the firmware at `t_s + latency_s`.
    pub latency_s: f64,
    /// Ground speed, m/s.
    pub ground_speed_mps: f64,
    /// Course over ground, degrees clockwise from true north.
    pub course_deg: f64,
}

impl GpsFix {
    /// When the fix reaches the firmware, s.
    pub fn available_s(&self) -> f64 {
        self.t_s + self.latency_s
    }
}

impl<T: Scalar> Firmware<T> {
    /// The firmware of a (validated) profile, at its initial state: Q = [1, 0, 0, 0] (also for
    /// `level`, until [`Firmware::finish_alignment`]), V and position from `navigation`.
    pub fn new(profile: &Profile) -> Result<Self> {
        let fw = &profile.firmware;
        if !(1..=3).contains(&fw.coning_samples) {
            return Err(Error::Profile(format!(
                "key `firmware.coning_samples` = {}: expected 1, 2 or 3",
                fw.coning_samples
            )));
        }
        let step_s = update_period_s(profile)?;
        if !(step_s.is_finite() && step_s > 0.0) {
            return Err(Error::Profile(format!("key `timer.period_us` = {}: expected > 0", profile.timer.period_us)));
        }
        let q: Quat<T> = [lit(1.0), lit(0.0), lit(0.0), lit(0.0)];
        let uses_magnetometer = (fw.algorithm == "dcm"
            && fw.dcm.yaw_reference == crate::profile::YawReference::Magnetometer)
            || (fw.algorithm == "vqf" && fw.vqf.magnetometer);
        let uses_temperature = fw.algorithm == "wing" && fw.wing.compensates();
        Ok(Firmware {
            attitude: attitude_update(fw, step_s)?,
            earth_rate: fw.earth_rate,
            navigation: fw.navigation,
            initial_attitude: fw.initial_attitude,
            step_s,
            t1: lit(step_s),
            decoder: Decoder::new(&profile.device, fw)?,
            euler: EulerExtractor::new(fw.euler, fw.euler_zero_eps),
            earth: EarthModel::new(&profile.navigation),
            initial_yaw: T::from_f64(fw.initial_yaw_deg.to_radians(), QClass::Angle),
            q,
            c_bn: dcm(&q),
            nav: NavState::from_profile(&profile.navigation),
            aligner: LevelAligner::default(),
            last_accel: None,
            uses_magnetometer,
            // The firmware's field variable before the first read: zero, as a C global starts.
            last_mag: uses_magnetometer.then_some([lit(0.0); 3]),
            uses_temperature,
            // Likewise the temperature variables: 0 (25 °C) before the first read.
            last_temp: uses_temperature.then_some([lit(0.0); 3]),
            clipped: Clipped::default(),
            gps_pending: None,
            gps: GpsInput::None,
            gps_last_available: None,
            gps_given: 0,
            earth_rates_of_state: None,
        })
    }

    /// The update period T, s.
    pub fn step_s(&self) -> f64 {
        self.step_s
    }

    /// Rate samples one attitude update takes: 3 for RK4 (t, t+T/2, t+T), N+1 for the rotation
    /// vector with N coning samples (the sub-interval boundaries t, t+T/N, …, t+T).
    pub fn rates_per_update(&self) -> usize {
        self.attitude.samples_per_update()
    }

    /// Stage 1: decode X/Y/Z GYRO_OUT and X/Y/Z ACCL_OUT.
    pub fn decode(&mut self, words: &[u16; 6]) -> Decoded<T> {
        let d = self.decoder.decode(words);
        self.last_accel = Some(d.accel);
        self.clipped.gyro |= d.report.saturated & 0b111;
        self.clipped.accel = d.report.saturated >> 3;
        d
    }

    /// Whether the attitude algorithm takes the magnetic field (then the ISR decodes X/Y/Z MAGN_OUT).
    pub fn uses_magnetometer(&self) -> bool {
        self.uses_magnetometer
    }

    /// Decode X/Y/Z MAGN_OUT for the attitude update.
    pub fn decode_magnetometer(&mut self, words: &[u16; 3]) -> Vec3<T> {
        let m = self.decoder.decode_magnetometer(words);
        self.last_mag = Some(m);
        self.clipped.mag = super::decode::saturated_magnetometer(words);
        m
    }

    /// Whether the attitude algorithm takes the temperature (then the ISR decodes X/Y/ZTEMP_OUT).
    pub fn uses_temperature(&self) -> bool {
        self.uses_temperature
    }

    /// Decode X/Y/ZTEMP_OUT for the attitude update.
    pub fn decode_temperature(&mut self, words: &[u16; 3]) -> Vec3<T> {
        let t = super::decode::decode_temperature(words);
        self.last_temp = Some(t);
        t
    }

    /// Fixes of the board's GPS stream (in order of their arrival time `t_s + latency_s`, strictly
    /// increasing; each value finite, speed ≥ 0, latency ≥ 0): from the first call on, the board has a
    /// GPS. Errors name the fix (counted from the first fix ever given) and the field.
    pub fn push_gps(&mut self, fixes: &[GpsFix]) -> Result<()> {
        let pending = self.gps_pending.get_or_insert_with(Default::default);
        if self.gps == GpsInput::None {
            self.gps = GpsInput::Waiting;
        }
        for f in fixes {
            let i = self.gps_given;
            let bad = |field: &str, value: f64, expected: &str| {
                Err(Error::Input(format!("GPS fix {i}: field `{field}` = {value}; expected {expected}")))
            };
            if !f.t_s.is_finite() {
                return bad("t_s", f.t_s, "a finite time");
            }
            if !(f.latency_s.is_finite() && f.latency_s >= 0.0) {
                return bad("latency_s", f.latency_s, "a finite number ≥ 0");
            }
            if !(f.ground_speed_mps.is_finite() && f.ground_speed_mps >= 0.0) {
                return bad("ground_speed_mps", f.ground_speed_mps, "a finite number ≥ 0");
            }
            if !f.course_deg.is_finite() {
                return bad("course_deg", f.course_deg, "a finite number of degrees");
            }
            if let Some(last) = pending.back().map(GpsFix::available_s).or(self.gps_last_available) {
                if f.available_s() <= last {
                    return bad("t_s", f.t_s, "a fix arriving (t_s + latency_s) after the previous one");
                }
            }
            pending.push_back(*f);
            self.gps_given += 1;
        }
        Ok(())
    }

    /// The latest GPS fix that has reached the firmware by `t_s` (the board's time, s): every fix with
    /// `t_s + latency_s ≤ t_s` is taken in order, the last one kept.
    pub fn receive_gps(&mut self, t_s: f64) {
        let Some(pending) = &mut self.gps_pending else { return };
        while let Some(fix) = pending.front().filter(|f| f.available_s() <= t_s).copied() {
            pending.pop_front();
            self.gps_last_available = Some(fix.available_s());
            self.gps = GpsInput::Fix(GpsAiding {
                ground_speed: T::from_f64(fix.ground_speed_mps, QClass::Accel),
                course: T::from_f64(fix.course_deg.to_radians(), QClass::Angle),
            });
        }
    }

    /// Earth and transport rates at the current navigation state.
    pub fn earth_rates(&self) -> EarthRates<T> {
        self.earth.rates(&self.nav)
    }

    /// [`Firmware::earth_rates`], kept for the navigation step of this update.
    fn earth_rates_kept(&mut self) -> EarthRates<T> {
        let r = self.earth_rates_of_state.unwrap_or_else(|| self.earth.rates(&self.nav));
        self.earth_rates_of_state = Some(r);
        r
    }

    /// Forget the kept earth rates, so that the next navigation step computes them (the timing
    /// model counts the navigation stage as the target runs it).
    pub(crate) fn forget_earth_rates(&mut self) {
        self.earth_rates_of_state = None;
    }

    /// Stage 2: attitude update from `rates_per_update()` samples of ω_ib^b (rad/s), with the
    /// navigation frame's rate when the profile corrects for it.
    pub fn update_attitude(&mut self, rates: &[Vec3<T>]) -> Result<()> {
        self.update_attitude_marked(rates, None)
    }

    /// [`Firmware::update_attitude`] calling `mark` as each part of the algorithm ends (the timing
    /// model's breakdown; see [`AttitudeUpdate::step_marked`]).
    pub fn update_attitude_marked(
        &mut self,
        rates: &[Vec3<T>],
        mark: Option<&mut dyn FnMut(&'static str)>,
    ) -> Result<()> {
        // The C calls the update (`updateQ()`), and before it, with the navigation frame's rate, the
        // body rates (`body_rates(w_ib)`) ([`Scalar::work`]).
        T::work(Work::call(0));
        let nav_rate = if self.earth_rate {
            T::work(Work::call(1));
            Some(self.earth_rates_kept().w_in())
        } else {
            None
        };
        let inputs = StepInputs {
            specific_force: self.last_accel,
            magnetic_field: self.last_mag,
            temperature_c: self.last_temp,
            gps: self.gps,
            clipped: self.clipped,
            ..StepInputs::rates(rates, nav_rate)
        };
        match mark {
            None => self.attitude.step(&mut self.q, &self.c_bn, &inputs)?,
            Some(mark) => self.attitude.step_marked(&mut self.q, &self.c_bn, &inputs, mark)?,
        }
        self.clipped.gyro = 0;
        self.c_bn = self.attitude.matrix().unwrap_or_else(|| dcm(&self.q));
        Ok(())
    }

    /// Hand the attitude algorithm's events of the last update to `sink` (see
    /// [`AttitudeUpdate::drain_events`]).
    pub fn drain_attitude_events(&mut self, sink: &mut dyn FnMut(&'static str, crate::events::Severity, String)) {
        self.attitude.drain_events(sink);
    }

    /// The drift-cancellation terms of the last attitude update (DCM), None for the open-loop ones.
    pub fn correction(&self) -> Option<Correction> {
        self.attitude.correction()
    }

    /// Push the attitude algorithm's own rows of this step (see [`AttitudeUpdate::record`]).
    pub fn record_outputs(&self, step: u64, out: &mut crate::output::Output) {
        self.attitude.record(step, out);
    }

    /// What the attitude algorithm changed of the profile's request (see [`AttitudeUpdate::notices`]).
    pub fn attitude_notices(&self) -> Vec<(&'static str, String)> {
        self.attitude.notices()
    }

    /// Put the attitude algorithm in its costliest state (the timing model's count; see
    /// [`AttitudeUpdate::to_costliest`]).
    pub(crate) fn attitude_to_costliest(&mut self) {
        self.attitude.to_costliest();
    }

    /// Stage 3: Euler angles of the current attitude (radians).
    pub fn euler(&self) -> EulerAngles<T> {
        // The C's `update_euler()` call ([`Scalar::work`]).
        T::work(Work::call(0));
        self.euler.extract(&self.c_bn)
    }

    /// Stage 4: one navigation step with the specific force f^b (m/s²); nothing when the profile
    /// turns navigation off.
    pub fn navigate(&mut self, f_b: &Vec3<T>) {
        if self.navigation {
            let rates = self.earth_rates_of_state.take().unwrap_or_else(|| self.earth.rates(&self.nav));
            self.earth.step_with_rates(&mut self.nav, &rates, &self.c_bn, f_b, self.t1);
        }
    }

    /// Alignment (`level`): add one still accelerometer sample.
    pub fn add_alignment_sample(&mut self, f_b: &Vec3<T>) {
        self.aligner.add(f_b);
        self.clipped.gyro = 0;
    }

    /// End of the still period: for `level`, Q from the averaged accelerometer and the profile's
    /// yaw; for `zero`, Q = [1, 0, 0, 0].
    pub fn finish_alignment(&mut self) -> Result<()> {
        let q = match self.initial_attitude {
            InitialAttitude::Level => level_attitude(&self.aligner.mean()?, self.initial_yaw),
            InitialAttitude::Zero => euler_to_quat(lit(0.0), lit(0.0), lit(0.0)),
        };
        self.set_attitude(q);
        Ok(())
    }

    /// Overwrite the attitude (tests, restarts).
    pub fn set_attitude(&mut self, q: Quat<T>) {
        self.q = q;
        self.c_bn = dcm(&q);
        self.attitude.restart();
    }

    /// The quaternion Q (body to navigation).
    pub fn quat(&self) -> &Quat<T> {
        &self.q
    }

    /// T = C_b^n as of the last update.
    pub fn dcm(&self) -> &Mat3<T> {
        &self.c_bn
    }

    /// Velocity and position.
    pub fn nav_state(&self) -> &NavState<T> {
        &self.nav
    }

    /// The decode stage (previous values of the published decode).
    pub fn decoder(&self) -> &Decoder<T> {
        &self.decoder
    }

    /// The earth model.
    pub fn earth(&self) -> &EarthModel<T> {
        &self.earth
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::Decode;

    fn dcm_with(yaw: crate::profile::YawReference) -> Profile {
        let mut p = Profile::default();
        p.firmware.algorithm = "dcm".into();
        p.firmware.dcm.yaw_reference = yaw;
        p
    }

    fn fix(t_s: f64, latency_s: f64, course_deg: f64) -> GpsFix {
        GpsFix { t_s, latency_s, ground_speed_mps: 20.0, course_deg }
    }

    /// A fix reaches the firmware at its time plus its latency, the latest one that has wins, and the
    /// GPS yaw reference waits (no error, no yaw correction) until the first fix is there; without a
    /// stream at all it names the key.
    #[test]
    fn gps_fixes_arrive_after_their_latency() {
        let p = dcm_with(crate::profile::YawReference::Gps);
        let rates = [[0.0; 3]; 2];
        let mut fw = Firmware::<f64>::new(&p).unwrap();
        let e = fw.update_attitude(&rates).unwrap_err().to_string();
        assert!(e.contains("firmware.dcm.yaw_reference") && e.contains("GPS stream"), "{e}");
        let mut fw = Firmware::<f64>::new(&p).unwrap();
        fw.push_gps(&[fix(1.0, 0.1, 90.0), fix(1.2, 0.1, 180.0), fix(1.4, 0.1, 270.0)]).unwrap();
        fw.receive_gps(1.0999);
        assert_eq!(fw.gps, GpsInput::Waiting);
        fw.update_attitude(&rates).unwrap();
        assert_eq!(fw.correction().unwrap().error_yaw, [0.0; 3], "no yaw error before the first fix");
        fw.receive_gps(1.1);
        let course = |fw: &Firmware<f64>| match fw.gps {
            GpsInput::Fix(f) => f.course.to_degrees(),
            other => panic!("{other:?}"),
        };
        assert_eq!(course(&fw), 90.0);
        fw.receive_gps(1.45);
        assert!((course(&fw) - 180.0).abs() < 1e-12, "the latest fix arrived, not the one still in flight");
        fw.update_attitude(&rates).unwrap();
        // Level, nose east (R = I), course south: the yaw error turns the nose about up.
        assert!(fw.correction().unwrap().error_yaw[2].abs() > 0.5);
        fw.receive_gps(10.0);
        assert!((course(&fw) - 270.0).abs() < 1e-12);
    }

    #[test]
    fn bad_gps_fixes_name_the_fix_and_field() {
        let mut fw = Firmware::<f64>::new(&dcm_with(crate::profile::YawReference::Gps)).unwrap();
        fw.push_gps(&[fix(1.0, 0.1, 0.0)]).unwrap();
        for (bad, field) in [
            (GpsFix { ground_speed_mps: -1.0, ..fix(2.0, 0.1, 0.0) }, "ground_speed_mps"),
            (fix(2.0, -0.1, 0.0), "latency_s"),
            (fix(2.0, 0.1, f64::NAN), "course_deg"),
            (fix(f64::INFINITY, 0.1, 0.0), "t_s"),
            (fix(0.9, 0.1, 0.0), "t_s"),
        ] {
            let e = fw.push_gps(&[bad]).unwrap_err().to_string();
            assert!(e.contains("GPS fix 1") && e.contains(&format!("`{field}`")), "{e}");
        }
    }

    #[test]
    fn update_period_follows_the_schedule() {
        let mut p = Profile::default();
        assert_eq!(update_period_s(&p).unwrap(), 0.008);
        p.firmware.schedule = Schedule::Endpoint;
        assert_eq!(update_period_s(&p).unwrap(), 0.004);
    }

    /// The navigation step that takes the attitude update's earth rates ends where one computing
    /// them itself does, bit for bit, in every backend (moving north-east, with the earth-rate correction).
    #[test]
    fn kept_earth_rates_equal_fresh_ones() {
        fn run<T: Scalar>(p: &Profile, forget: bool) -> Vec<f64> {
            let mut fw = Firmware::<T>::new(p).unwrap();
            let words = [0x0014, 0x3FF6, 0x0008, 0x0003, 0x3FFD, 0x012C];
            for _ in 0..50 {
                let d = fw.decode(&words);
                fw.update_attitude(&[d.rate; 3]).unwrap();
                if forget {
                    fw.forget_earth_rates();
                }
                fw.navigate(&d.accel);
            }
            let n = fw.nav_state();
            [n.lat, n.lon, n.height, n.vel[0], n.vel[1], n.vel[2]].iter().chain(fw.quat()).map(|x| x.to_f64()).collect()
        }
        let mut p = Profile::default();
        p.navigation.velocity_enu = [30.0, 40.0, 1.0];
        p.navigation.latitude_deg = 45.0;
        for (kept, fresh) in [
            (run::<f64>(&p, false), run::<f64>(&p, true)),
            (run::<crate::numerics::C28xF32Rn>(&p, false), run::<crate::numerics::C28xF32Rn>(&p, true)),
            (run::<crate::numerics::Iq>(&p, false), run::<crate::numerics::Iq>(&p, true)),
        ] {
            assert_eq!(
                kept.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                fresh.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
            );
        }
    }

    #[test]
    fn wrong_sample_counts_are_errors() {
        let mut p = Profile::default();
        let mut fw = Firmware::<f64>::new(&p).unwrap();
        let e = fw.update_attitude(&[[0.0; 3]; 2]).unwrap_err();
        assert!(e.to_string().contains("takes 3"), "{e}");
        p.firmware.algorithm = "rotation-vector".into();
        p.firmware.coning_samples = 3;
        let mut fw = Firmware::<f64>::new(&p).unwrap();
        assert_eq!(fw.rates_per_update(), 4);
        assert!(fw.update_attitude(&[[0.0; 3]; 4]).is_ok());
        let mut rv =
            super::super::rotvec::RotationVector::<f64>::new(3, crate::profile::IncrementRule::Trapezoid, 0.008);
        assert!(rv.step_increments(&mut [1.0, 0.0, 0.0, 0.0], &[[0.0; 3]; 2], None).is_err());
        p.firmware.coning_samples = 1;
        let mut fw = Firmware::<f64>::new(&p).unwrap();
        assert_eq!(fw.rates_per_update(), 2);
        let e = fw.update_attitude(&[[0.0; 3]; 3]).unwrap_err();
        assert!(e.to_string().contains("3 rate samples, the RotationVector update takes 2"), "{e}");
    }

    #[test]
    fn iq_firmware_at_full_scale_stays_in_range_and_tracks_f64() {
        use super::super::quat::tests::angle_between;
        use crate::numerics::iq::{count_overflows, with_formats};
        use crate::numerics::Iq;
        // The correct decode at the 14-bit limits: 409.55 °/s about x, −409.6 °/s about z, 27.3 g on y,
        // 1 g on z (0x012C ≈ 0.9999 g), with navigation and the earth-rate correction on, for 2 s. (The
        // Euler tables are left out: their ratio saturates by design near ±90°, see euler.rs.)
        let mut p = Profile::default();
        p.firmware.decode = Decode::Correct;
        let words = [0x1FFF, 0x0000, 0x2000, 0x0000, 0x1FFF, 0x012C];
        let mut f = Firmware::<f64>::new(&p).unwrap();
        for _ in 0..250 {
            let d = f.decode(&words);
            f.update_attitude(&[d.rate; 3]).unwrap();
            f.navigate(&d.accel);
        }
        let want = *f.quat();
        let (got, overflows) = with_formats(&p.iq, || {
            count_overflows(|| {
                let mut fw = Firmware::<Iq>::new(&p).unwrap();
                for _ in 0..250 {
                    let d = fw.decode(&words);
                    fw.update_attitude(&[d.rate; 3]).unwrap();
                    fw.navigate(&d.accel);
                }
                fw.quat().map(|x| x.to_f64())
            })
        })
        .unwrap();
        assert_eq!(overflows, 0, "no IQ value wrapped or saturated");
        // The constant rate turns the board by |ω|·2 s = 20.2 rad; the IQ firmware's gyro constant (Q28) and
        // T1 (Q30) are truncated by `_IQ()`, so it turns that much less by their relative shortfalls.
        let shortfall = |x: f64, q: i32| (x - (x * 2f64.powi(q)).trunc() / 2f64.powi(q)) / x;
        let lsb = 0.05f64.to_radians();
        let turned = (8191f64.powi(2) + 8192f64.powi(2)).sqrt() * lsb * 2.0;
        let predicted = (shortfall(lsb, 28) + shortfall(0.008, 30)) * turned; // 1.23e-5 rad
                                                                              // Left over: the floors to Q24 rad/s of the decode (< 6e-8 rad/s per axis) and of the earth-rate
                                                                              // correction (a few 6e-8 rad/s) over 2 s, and the Q30 RK4 increments (≈ 1e-9 per step): < 1e-6 rad.
        let err = angle_between(&want, &got);
        assert!((err - predicted).abs() < 1e-6, "{err:e} rad, predicted {predicted:e}");
        assert!(err > 0.0, "the IQ backend was not used");
    }

    #[test]
    fn level_alignment_then_decode_and_euler() {
        let mut p = Profile::default();
        p.firmware.initial_attitude = InitialAttitude::Level;
        p.firmware.initial_yaw_deg = 200.0;
        p.firmware.decode = Decode::Correct;
        let mut fw = Firmware::<f64>::new(&p).unwrap();
        assert!(fw.finish_alignment().is_err(), "no sample yet");
        // Board pitched by θ: f^b = γ·(T31, T32, T33) = γ·(−sin θ, 0, cos θ); as words of 3.333 mg.
        let theta = 10f64.to_radians();
        let code = |g: f64| ((g / 3.333e-3).round() as i32 as u16) & 0x3FFF;
        let words = [0, 0, 0, code(-theta.sin()), 0, code(theta.cos())];
        for _ in 0..125 {
            let d = fw.decode(&words);
            fw.add_alignment_sample(&d.accel);
        }
        fw.finish_alignment().unwrap();
        let a = fw.euler();
        // Quantisation: one LSB (3.333 mg) of f_x moves θ by ≤ 3.333e-3/cos θ rad.
        assert!((a.pitch - theta).abs() < 3.333e-3 / theta.cos(), "{}", a.pitch.to_degrees());
        assert!(a.roll.abs() < 1e-15);
        assert!((a.yaw.to_degrees() - 200.0).abs() < 1e-12);
    }
}
