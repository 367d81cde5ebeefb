//! The attitude update as a trait, and the one place the algorithms are registered.
//!
//! An algorithm says how many samples one update takes ([`AttitudeUpdate::samples_per_update`]:
//! the acquisition schedule gathers that many, see `schedule.rs`) and steps the attitude from that
//! update's inputs ([`StepInputs`]). The algorithms are registered in `algorithms.rs`.

use super::quat::{body_rate_nav, Rk4};
use super::{Mat3, Quat, Vec3};
use crate::numerics::counter::Work;
use crate::numerics::Scalar;
use crate::Result;

/// What one attitude update takes: the rates, and what the board provides of the references the
/// fusing algorithms use (the open-loop ones ignore them).
#[derive(Debug, Clone, Copy)]
pub struct StepInputs<'a, T> {
    /// ω_ib^b (rad/s) at the update's sample times t, t+T/(n−1), …, t+T (n = `samples_per_update`).
    pub rates: &'a [Vec3<T>],
    /// ω_in^n (rad/s), the navigation frame's rotation (earth and transport rate), when the firmware
    /// corrects for it (`firmware.earth_rate`).
    pub nav_rate: Option<Vec3<T>>,
    /// f^b (m/s²), the latest specific force decoded.
    pub specific_force: Option<Vec3<T>>,
    /// The latest magnetic field decoded, body axes (gauss).
    pub magnetic_field: Option<Vec3<T>>,
    /// The latest X/Y/ZTEMP_OUT decoded: each gyro axis's temperature above 25 °C (°C), when the firmware
    /// compensates the temperature (the wing unit with `firmware.wing` coefficients).
    pub temperature_c: Option<Vec3<T>>,
    /// The GPS: none on the board, a stream with no fix usable yet, or the latest fix usable.
    pub gps: GpsInput<T>,
    /// The axes whose code was at full scale (the decode's saturation flags).
    pub clipped: Clipped,
}

/// Which axes read a full-scale code: bit i is axis i (x, y, z). The gyro's over every sample of the
/// update; the accelerometer's and the magnetometer's of the sample the update takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Clipped {
    /// Gyro axes clipped in any sample of the update.
    pub gyro: u8,
    /// Accelerometer axes clipped in the latest sample.
    pub accel: u8,
    /// Magnetometer axes clipped in the latest sample.
    pub mag: u8,
}

impl<'a, T> StepInputs<'a, T> {
    /// Rates only (and the navigation frame's rate): what the open-loop algorithms take.
    pub fn rates(rates: &'a [Vec3<T>], nav_rate: Option<Vec3<T>>) -> Self {
        StepInputs {
            rates,
            nav_rate,
            specific_force: None,
            magnetic_field: None,
            temperature_c: None,
            gps: GpsInput::None,
            clipped: Clipped::default(),
        }
    }
}

/// What the firmware has of a GPS at one update.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum GpsInput<T> {
    /// The board has no GPS (the trace has no GPS stream).
    #[default]
    None,
    /// A GPS stream, but no fix is usable yet (the first one is still within its latency).
    Waiting,
    /// The latest fix usable at this update.
    Fix(GpsAiding<T>),
}

/// One GPS report as the attitude firmware uses it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GpsAiding<T> {
    /// Ground speed, m/s.
    pub ground_speed: T,
    /// Course over ground, rad, clockwise from true north.
    pub course: T,
}

/// One attitude algorithm of the firmware.
pub trait AttitudeUpdate<T: Scalar>: std::fmt::Debug + Send {
    /// Samples one update takes (at the update's sample times, both ends included).
    fn samples_per_update(&self) -> usize;
    /// One update of the attitude `q` (body to navigation), whose matrix C_b^n is `c_bn`.
    fn step(&mut self, q: &mut Quat<T>, c_bn: &Mat3<T>, inputs: &StepInputs<'_, T>) -> Result<()>;
    /// [`AttitudeUpdate::step`], calling `mark` with the name of each of its parts as the part ends
    /// (the timing model prices the parts between the marks). Algorithms with no parts call none.
    fn step_marked(
        &mut self,
        q: &mut Quat<T>,
        c_bn: &Mat3<T>,
        inputs: &StepInputs<'_, T>,
        _mark: &mut dyn FnMut(&'static str),
    ) -> Result<()> {
        self.step(q, c_bn, inputs)
    }
    /// The attitude was overwritten: forget what the update carries from step to step.
    fn restart(&mut self) {}
    /// C_b^n as the update holds it, when it carries a matrix of its own (the DCM): the firmware
    /// uses it rather than the matrix of `q`.
    fn matrix(&self) -> Option<Mat3<T>> {
        None
    }
    /// The drift-cancellation terms of the last update, when the algorithm has them.
    fn correction(&self) -> Option<Correction> {
        None
    }
    /// Push this step's rows of the algorithm's own output tables (an application's extra outputs,
    /// e.g. the wing unit's α and axis) into `out`; `step` is the cycle row's step. None by default.
    fn record(&self, _step: u64, _out: &mut crate::output::Output) {}
    /// What the update changed of the profile's request when it was built, as (event kind, message):
    /// the run reports each as a warning at its start. None by default.
    fn notices(&self) -> Vec<(&'static str, String)> {
        Vec::new()
    }
    /// Put the update in its costliest state (the timing model counts one update from there: an
    /// algorithm whose work depends on its state must fit the tick in its worst one). Nothing by default.
    fn to_costliest(&mut self) {}
    /// Hand the events the last update raised (kind, severity, message) to `sink`, and forget them
    /// (the ISR stamps them with the update's time). None by default.
    fn drain_events(&mut self, _sink: &mut dyn FnMut(&'static str, crate::events::Severity, String)) {}
}

/// The drift-cancellation terms of one update (f64 whatever the backend: a report, not firmware state).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Correction {
    /// ω_P, the proportional correction, rad/s (body axes).
    pub omega_p: [f64; 3],
    /// ω_I, the integrator, rad/s (body axes).
    pub omega_i: [f64; 3],
    /// The roll–pitch error vector (body axes).
    pub error_rp: [f64; 3],
    /// The yaw error vector (body axes).
    pub error_yaw: [f64; 3],
    /// |R·Rᵀ − I| (largest element) after renormalisation.
    pub orthogonality: f64,
}

/// RK4 on Q̇ = ½ M(ω_nb^b) Q from the rates at t, t+T/2, t+T, with ω_nb^b = ω_ib^b − C_n^b ω_in^n.
impl<T: Scalar> AttitudeUpdate<T> for Rk4<T> {
    fn samples_per_update(&self) -> usize {
        3
    }

    fn step(&mut self, q: &mut Quat<T>, c_bn: &Mat3<T>, inputs: &StepInputs<'_, T>) -> Result<()> {
        let mut w = match inputs.rates {
            [a, b, c] => [*a, *b, *c],
            other => return Err(wrong_count(other.len(), 3, "RK4")),
        };
        if let Some(w_in) = inputs.nav_rate {
            for wi in w.iter_mut() {
                // The C's loops over the samples and their three components ([`Scalar::work`]).
                (0..4).for_each(|_| T::work(Work::LOOP_PASS));
                *wi = body_rate_nav(c_bn, wi, &w_in);
            }
        }
        self.step_quat(q, &w);
        Ok(())
    }
}

/// The error of an update handed the wrong number of samples.
pub(crate) fn wrong_count(got: usize, takes: usize, name: &str) -> crate::Error {
    crate::Error::Config(format!("attitude update: {got} rate samples, the {name} update takes {takes}"))
}
