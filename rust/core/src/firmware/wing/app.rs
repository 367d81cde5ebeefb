//! The wing unit's firmware on the board: the `wing` row of the algorithm registry
//! (`firmware/algorithms.rs`). Module docs: `wing/mod.rs`. Every update, with the update's mean gyro
//! and the latest specific force:
//!
//! 1. (A) Zero: the unit is powered at the zero pose and held still; it averages for
//!    `firmware.alignment_s`, and at least the (σ/0.5 mg)² samples that bring the ADIS16362's
//!    per-sample accelerometer noise σ to 0.5 mg ([`super::samples_needed`]): a shorter `alignment_s` is
//!    lengthened to that, and the row's α stays NaN until then. The attitude output is Q = 1 meanwhile.
//! 2. Then the 12-state filter (C: Z₁, Z₂ and rest recalibration) runs every update, with no axis at
//!    first (it integrates and recalibrates at rest, and gives no α).
//! 3. The axis: (B2) from a gyro-only integration of q_rb (the zero's mean gyro removed), kept apart from
//!    the filter so the axis constraint does not confirm itself; its rotations beyond 10° are averaged
//!    during the first 30 s after the zero (the integration horizon: later the gyro drift
//!    outgrows the estimate). (B1) from the rest poses the filter detects, each beyond 5° from the
//!    zero, up to the last eight: once two give an axis, it replaces B2 (a body-fixed accelerometer
//!    bias cancels in the up-vector differences B1 uses; B2's error grows with the gyro's).
//!    Sign: a·up ≥ 0 (the axis points out of the horizontal; for β = 0 the sign is that of the first
//!    estimate).
//! 4. α = the filter's [`hinge_angle`] about that axis; the attitude output is the filter's q_wb
//!    (w: level, yaw 0 at the zero).
//!
//! Temperature (the source: the gyro's 0.01 °/s/°C makes 0.3° over 30 s "barely" reachable, with the
//! temperature compensated; it gives no method). With `firmware.wing.gyro_bias_tempco_dps_per_c` k (a
//! unit's thermal calibration, °/s per °C) the update's mean gyro loses k_i·ΔT_i on each axis before
//! anything else takes it, ΔT_i the axis's X/Y/ZTEMP_OUT above 25 °C (the register's zero) [unconfirmed:
//! the law is the error model's linear one; the reference temperature does not matter, the zero and the
//! rest recalibration take the constant part]. Left uncompensated, a ramp of r °C/s after the zero turns
//! α by ½·(k·a)·r·t² (a the hinge axis): 0.75° in 30 s at 0.01 °/s/°C along the axis and 10 °C/min.
//!
//! The earth rate is not taken from the board's `firmware.earth_rate` correction: the zero's mean gyro
//! and the rest recalibration hold it (module docs), so the wing profile turns that correction off.

use super::filter::{FilterConfig, Mode, WingFilter, WingOutput};
use super::geometry::{dot, static_axis, up_vector, DynamicAxis, WingZero, ZeroAcquisition};
use crate::firmware::align::level_attitude;
use crate::firmware::attitude::{wrong_count, AttitudeUpdate, StepInputs};
use crate::firmware::quat::{normalise, quat_mul};
use crate::firmware::rotvec::quat_from_rotvec;
use crate::firmware::{lit, Mat3, Quat, Vec3};
use crate::numerics::{QClass, Scalar};
use crate::output::{Output, WingRow};
use crate::{Error, Result};

/// Rest poses B1 keeps (the latest).
const POSES: usize = 8;
/// A rest pose counts for B1 beyond this angle from the zero, degrees.
const MIN_POSE_DEG: f64 = 5.0;
/// B2 counts integrated rotations beyond this angle, degrees.
const MIN_DYNAMIC_DEG: f64 = 10.0;
/// B2 counts rotations during this long after the zero, s.
const DYNAMIC_WINDOW_S: f64 = 30.0;
/// The zero's accelerometer target, g (the source's 0.5 mg for 0.1° static).
const ZERO_TARGET_G: f64 = 0.5e-3;
/// The ADIS16362's accelerometer velocity random walk, m/s/√s (0.12 m/s/√h; the `adis16362` preset),
/// its sample rate (819.2 SPS) and its LSB (0.333 mg): the per-sample noise the zero averages.
const ADIS16362_VRW: f64 = 0.12 / 60.0;
const ADIS16362_SPS: f64 = 819.2;
const ADIS16362_ACCEL_LSB_G: f64 = 0.333e-3;

/// Where the axis in use comes from (the output's `wing_axis_source`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AxisSource {
    /// No axis yet.
    None = 0,
    /// B2: integrated motion.
    Dynamic = 1,
    /// B1: rest poses.
    Static = 2,
}

/// The wing unit's firmware (module docs).
#[derive(Debug, Clone)]
pub struct WingUnit<T: Scalar> {
    cfg: FilterConfig,
    zero_steps: u32,
    /// `firmware.alignment_s` as the profile gave it, and the update period (for the notice).
    asked: (f64, f64),
    acquisition: ZeroAcquisition<T>,
    filter: Option<WingFilter<T>>,
    up_r: Vec3<T>,
    gyro_mean: Vec3<T>,
    /// B2's gyro-only q_rb.
    free: Quat<T>,
    dynamic: DynamicAxis<T>,
    dynamic_steps: u32,
    steps_since_zero: u32,
    poses: [Vec3<T>; POSES],
    pose_count: usize,
    /// The specific force summed over the rest going on, and its samples.
    open_pose: (Vec3<T>, u32),
    axis: Option<Vec3<T>>,
    source: AxisSource,
    last: Option<WingOutput<T>>,
    /// The gyro bias temperature coefficients, rad/s per °C (None: no compensation).
    tempco: Option<Vec3<T>>,
}

impl<T: Scalar> WingUnit<T> {
    /// The unit for an update period of `step_s` s, gravity `gravity` m/s² (the firmware's g), and a zero
    /// of `zero_s` s at least.
    pub fn new(step_s: f64, gravity: f64, zero_s: f64) -> Result<Self> {
        let sigma =
            ((ADIS16362_VRW * ADIS16362_SPS.sqrt()).powi(2) + (ADIS16362_ACCEL_LSB_G * gravity).powi(2) / 12.0).sqrt();
        let acquisition = ZeroAcquisition::new(sigma, ZERO_TARGET_G * gravity)?;
        if !(zero_s.is_finite() && zero_s >= 0.0) {
            return Err(Error::Profile(format!(
                "key `firmware.alignment_s` = {zero_s}: the wing unit's zero acquisition time; expected ≥ 0 s"
            )));
        }
        let zero_steps = ((zero_s / step_s).ceil() as u32).max(acquisition.needed());
        let z = lit::<T>(0.0);
        Ok(WingUnit {
            cfg: FilterConfig::adis16362(step_s, gravity, Mode::Full),
            zero_steps,
            asked: (zero_s, step_s),
            acquisition,
            filter: None,
            up_r: [z; 3],
            gyro_mean: [z; 3],
            free: [lit(1.0), z, z, z],
            dynamic: DynamicAxis::new(MIN_DYNAMIC_DEG.to_radians(), None),
            dynamic_steps: (DYNAMIC_WINDOW_S / step_s).round() as u32,
            steps_since_zero: 0,
            poses: [[z; 3]; POSES],
            pose_count: 0,
            open_pose: ([z; 3], 0),
            axis: None,
            source: AxisSource::None,
            last: None,
            tempco: None,
        })
    }

    /// The unit compensating the gyro's temperature drift with coefficients `dps_per_c` (x, y, z; °/s per
    /// °C; all zero: none): module docs.
    pub fn with_temperature_compensation(mut self, dps_per_c: [f64; 3]) -> Self {
        self.tempco =
            dps_per_c.iter().any(|&k| k != 0.0).then(|| dps_per_c.map(|k| T::from_f64(k.to_radians(), QClass::Rate)));
        self
    }

    /// Updates the zero acquisition takes.
    pub fn zero_steps(&self) -> u32 {
        self.zero_steps
    }

    /// The axis turned so that a·up ≥ 0.
    fn upward(&self, a: Vec3<T>) -> Vec3<T> {
        if dot(&a, &self.up_r) < lit(0.0) {
            a.map(|x| -x)
        } else {
            a
        }
    }

    /// Start tracking from a zero.
    fn start(&mut self, zero: &WingZero<T>) -> Result<()> {
        self.up_r = zero.up_r;
        self.gyro_mean = zero.gyro_mean;
        self.filter = Some(WingFilter::without_axis(zero, self.cfg)?);
        Ok(())
    }

    /// One update with the mean gyro `w` (rad/s) and specific force `f` (m/s²); the attitude q_wb.
    fn update(&mut self, w: &Vec3<T>, f: &Vec3<T>, mark: &mut dyn FnMut(&'static str)) -> Result<Option<Quat<T>>> {
        if self.filter.is_none() {
            self.acquisition.add(w, f);
            if self.acquisition.count() >= self.zero_steps {
                let zero = self.acquisition.zero()?;
                self.start(&zero)?;
            }
            mark("zero");
            return Ok(None);
        }
        // B2: the gyro-only rotation from the zero, during the window.
        if self.steps_since_zero < self.dynamic_steps {
            self.steps_since_zero += 1;
            let dt = lit::<T>(self.cfg.step_s);
            let phi: Vec3<T> = std::array::from_fn(|i| ((w[i] - self.gyro_mean[i]) * dt).to_class(QClass::Angle));
            self.free = quat_mul(&self.free, &quat_from_rotvec(&phi));
            normalise(&mut self.free);
            self.dynamic.add(&self.free);
            if self.source != AxisSource::Static {
                if let Some(a) = self.dynamic.axis() {
                    self.set_axis(self.upward(a), AxisSource::Dynamic);
                }
            }
        }
        mark("axis");
        let Some(filter) = self.filter.as_mut() else { unreachable!("the filter started above") };
        let out = filter.step(w, f);
        let q = filter.attitude();
        mark("filter");
        // B1: the rest poses.
        if out.at_rest {
            let (sum, n) = &mut self.open_pose;
            *sum = std::array::from_fn(|i| sum[i] + f[i]);
            *n += 1;
        } else if self.open_pose.1 > 0 {
            self.close_pose()?;
        }
        self.last = Some(out);
        Ok(Some(q))
    }

    /// The rest that was going on has ended: keep its up vector if it is far enough from the zero,
    /// and take the static axis when the poses give one.
    fn close_pose(&mut self) -> Result<()> {
        let (sum, _) = std::mem::replace(&mut self.open_pose, ([lit(0.0); 3], 0));
        let u = up_vector(&sum);
        let d: Vec3<T> = std::array::from_fn(|i| u[i] - self.up_r[i]);
        let chord = 2.0 * (MIN_POSE_DEG.to_radians() / 2.0).sin();
        if dot(&d, &d) < lit(chord * chord) {
            return Ok(());
        }
        self.poses[self.pose_count % POSES] = u;
        self.pose_count += 1;
        let kept = &self.poses[..self.pose_count.min(POSES)];
        if kept.len() >= 2 {
            // Poses on one great circle through the zero give no axis: keep the one in use.
            if let Ok(a) = static_axis(&self.up_r, kept) {
                self.set_axis(self.upward(a), AxisSource::Static);
            }
        }
        Ok(())
    }

    fn set_axis(&mut self, a: Vec3<T>, source: AxisSource) {
        self.axis = Some(a);
        self.source = source;
        if let Some(filter) = self.filter.as_mut() {
            filter.set_axis(a);
        }
    }
}

impl<T: Scalar> AttitudeUpdate<T> for WingUnit<T> {
    /// Two: the update's ends (the half-step schedule reads one burst a tick and updates every tick).
    fn samples_per_update(&self) -> usize {
        2
    }

    fn step(&mut self, q: &mut Quat<T>, c_bn: &Mat3<T>, inputs: &StepInputs<'_, T>) -> Result<()> {
        self.step_marked(q, c_bn, inputs, &mut |_| {})
    }

    /// Parts: `zero` (during the acquisition), else `axis` (B2) and `filter` (the 12-state filter with α),
    /// the rest-pose bookkeeping after it.
    fn step_marked(
        &mut self,
        q: &mut Quat<T>,
        _c_bn: &Mat3<T>,
        inputs: &StepInputs<'_, T>,
        mark: &mut dyn FnMut(&'static str),
    ) -> Result<()> {
        let [a, b] = inputs.rates else { return Err(wrong_count(inputs.rates.len(), 2, "wing")) };
        let half = lit::<T>(0.5);
        let mut w: Vec3<T> = std::array::from_fn(|i| ((a[i] + b[i]) * half).to_class(QClass::Rate));
        if let Some(k) = &self.tempco {
            let Some(dt) = inputs.temperature_c else {
                return Err(Error::Config("wing unit: temperature compensation without a temperature decoded".into()));
            };
            w = std::array::from_fn(|i| (w[i] - k[i] * dt[i]).to_class(QClass::Rate));
        }
        let Some(f) = inputs.specific_force else {
            return Err(Error::Config("wing unit: no specific force decoded before the update".into()));
        };
        if let Some(q_wb) = self.update(&w, &f, mark)? {
            *q = q_wb;
        }
        Ok(())
    }

    fn notices(&self) -> Vec<(&'static str, String)> {
        let (asked_s, step_s) = self.asked;
        if ((asked_s / step_s).ceil() as u32) >= self.zero_steps {
            return Vec::new();
        }
        vec![(
            "wing_zero_lengthened",
            format!(
                "key `firmware.alignment_s` = {asked_s} s: the zero averages {} updates ({:.3} s) to bring the \
                 accelerometer noise to {} mg; α stays NaN until then",
                self.zero_steps,
                f64::from(self.zero_steps) * step_s,
                ZERO_TARGET_G * 1e3
            ),
        )]
    }

    fn record(&self, step: u64, out: &mut Output) {
        let nan = f64::NAN;
        let (alpha_deg, axis, at_rest) = match &self.last {
            Some(o) => (
                o.alpha.map_or(nan, |a| a.to_f64().to_degrees()),
                o.axis.map_or([nan; 3], |a| a.map(|x| x.to_f64())),
                o.at_rest,
            ),
            None => (nan, [nan; 3], false),
        };
        let source = if self.last.and_then(|o| o.axis).is_some() { self.source } else { AxisSource::None };
        out.wing.push(WingRow { step, alpha_deg, axis, axis_source: source as u64, at_rest });
    }

    /// Tracking at rest with a static axis (the rest measurements, B2 and the pose bookkeeping all run).
    fn to_costliest(&mut self) {
        let g = self.cfg.gravity;
        let f: Vec3<T> = [0.1, -0.2, (g * g - 0.05).sqrt()].map(|x| T::from_f64(x, QClass::Accel));
        let zero = WingZero {
            q_wr: level_attitude(&f, lit(0.0)),
            up_r: up_vector(&f),
            gyro_mean: [0.01, -0.005, 0.02].map(|x| T::from_f64(x, QClass::Rate)),
        };
        if self.start(&zero).is_ok() {
            let a = [0.3, 0.9, 0.3].map(|x: f64| T::from_f64(x / 0.99f64.sqrt(), QClass::Quat));
            self.set_axis(a, AxisSource::Static);
            if let Some(filter) = self.filter.as_mut() {
                filter.hold_at_rest();
            }
            self.open_pose = (f, 1);
        }
    }
}
