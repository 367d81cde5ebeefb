//! The firmware model: decode of the IMU's output words, attitude update (RK4 as published, or the
//! rotation-vector family), Euler extraction, navigation and initial attitude. Everything is generic
//! over [`Scalar`] so the same code runs in f64 (golden), C28x f32, IQmath and the counting type.
//!
//! Conventions (the reference design's): Q = [q0 q1 q2 q3] is the body-to-navigation quaternion
//! (Hamilton product, v^n = Q ⊗ v^b ⊗ Q*), its matrix `T = C_b^n`; the navigation frame is x east,
//! y north, z up. Angles inside the firmware are radians. Each stage is a method of [`Firmware`], so
//! the acquisition model and the timing model can run the stages separately. Variables are
//! requantised (`to_class`) where the firmware assigns them, so fixed-point backends see the same Q
//! per variable the target code would use.

#[cfg(test)]
mod acceptance;
pub mod algorithms;
mod align;
pub mod application;
pub mod attitude;
mod dcm;
mod decode;
mod euler;
pub mod gating;
pub mod geomag;
pub mod geomag_app;
pub mod geomag_chain;
pub mod gfnav;
pub mod gfsins;
pub mod isr;
mod nav;
mod quat;
mod rotvec;
pub mod schedule;
mod state;
pub mod state_check;
pub mod vqf;
pub mod wing;

pub use algorithms::{attitude_update, run_samples as attitude_run_samples, samples_per_update};
pub use align::{level_attitude, LevelAligner};
pub use attitude::{AttitudeUpdate, Clipped, Correction, GpsAiding, GpsInput, StepInputs};
pub use dcm::{attitude_from_acc_mag, Dcm};
pub use decode::{gyro_lsb_dps, DecodeReport, Decoded, Decoder, ACCEL_LSB_G, PUBLISHED_GYRO_LSB_DPS};
pub use euler::{euler_to_quat, EulerAngles, EulerExtractor};
pub use nav::{EarthModel, EarthRates, NavState, SOMIGLIANA_K};
pub use quat::{body_rate_nav, dcm, midpoint, normalise, quat_mul, Rk4};
pub use rotvec::{coning_vector, increments, quat_from_rotvec, RotationVector};
pub use state::{update_period_s, Firmware, GpsFix};

use crate::numerics::{QClass, Scalar};

/// A 3-vector (rates, increments, specific force, velocity).
pub type Vec3<T> = [T; 3];
/// A quaternion [q0 q1 q2 q3], scalar first.
pub type Quat<T> = [T; 4];
/// A 3×3 matrix, row-major (`m[row][col]`, T_ij = `m[i-1][j-1]`).
pub type Mat3<T> = [[T; 3]; 3];

/// A literal of the firmware code (a compile-time constant on target): converted once.
pub(crate) fn lit<T: Scalar>(x: f64) -> T {
    T::from_f64(x, QClass::Generic)
}
