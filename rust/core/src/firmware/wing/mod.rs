//! The wing-angle unit (spec `algorithms.md` §3 with its corrections; source
//! `wing-angle-ahrs-notes.zh.txt`): a wing turns about one fixed hinge axis, and the unit measures its
//! angle α from a reference zero with an accelerometer and a gyro only (no magnetometer).
//!
//! Frames (the project's conventions: quaternions map body to reference, v^ref = q ⊗ v^b ⊗ q*,
//! Hamilton product; level frames x, y horizontal, z up):
//! - b: the IMU; r: b at the zero pose; w: a level frame, earth-fixed, = n(0) (the hinge's base is
//!   taken as static: a moving base is an error source, see `synth wing --base-*`);
//! - `q_wr` (the notes' q_w^r): r → w, from the accelerometer at the zero pose (A), yaw 0;
//! - `q_rb(t)` = cos(α/2) + a sin(α/2): b(t) → r, a rotation by α about the hinge axis a (r axes);
//! - `q_wb(t)` = q_wr ⊗ q_rb(t): b(t) → w. A level attitude q_nb(t) with any yaw differs from it by
//!   a rotation about z only, so q_wr ⊗ q_rb ⊗ q_nb* has zero x and y parts (the notes' eq. 0.4).
//!
//! The parts, each usable on its own (the tests run them so):
//! - (A) [`ZeroAcquisition`]: averages accelerometer and gyro at rest; it refuses to give a zero before
//!   (σ/target)² samples (the averaging that brings the per-sample noise σ down to the target).
//! - [`hinge_angle`]: α for a level attitude, the minimiser of J = q_x² + q_y² in closed form (exact for
//!   ideal inputs; needs the axis off vertical, β < 90°).
//! - (B1) [`static_axis`]: the axis from several rest poses by least squares. A rotation about a keeps
//!   the component of the up vector along a, so a·(u₀ − u_k) = 0 for every pose k (u the up vector in
//!   body axes, from the accelerometer): a is the direction minimising Σ (a·d_k)², d_k = u₀ − u_k.
//!   This is the notes' two equations per pose with α eliminated.
//! - (B2) [`DynamicAxis`]: the axis from gyro-integrated rotations q_rb: the vector part's direction,
//!   averaged over excursions (a rotation error δθ tilts it by atan(tan(δθ/2)/sin(α/2)), so large
//!   excursions count more: the sum of vector parts weights each by sin(α/2)).
//! - (B3, B4, C) [`WingFilter`]: the error-state Kalman filter on q_wb, v^w with states
//!   [φ, δv, ε, ∇] (12), measurements Z₁ = (C_b^r ω) × a = 0 (B3), plus Z₂ = (C_w^r v)·a = 0 (B4), plus
//!   rest recalibration (C): zero velocity, zero rate (the gyro bias, earth rate included) and the
//!   level from the accelerometer. α every step is [`hinge_angle`] of the filtered attitude.
//!
//! - On the board, [`WingUnit`] (`app.rs`, the `wing` row of the algorithm registry) runs them in
//!   order every update: the zero, then the filter, with the axis from B2 and, once two rest poses
//!   give one, from B1; its α and axis are the run's `wing_*` output rows.
//!
//! Earth rate (correction to §3: Z₁ uses ω_ib, which holds it). It is removed, not budgeted: at rest
//! the gyro reads ε + C_r^b Ω_ie^r and the zero-rate measurement puts the sum into the bias estimate.
//! A rotation about a leaves a·Ω_ie^r unchanged, so the part that integrates into α is removed exactly
//! at every pose; the part across the axis changes by at most 2 sin(α/2)·|Ω_ie| between rests (a
//! level error, the Z₁ measurement sees it as a bias).
//!
//! Fixed point: the filter's covariances span more decades than one IQ format holds (a 32-bit word
//! spans 9.3 decades; attitude variance ~1e-4 rad², gyro bias walk per step ~1e-16 rad²/s²), so under
//! `iq` the filter is refused with an error naming the span ([`check_fixed_point_span`]). A Q class
//! of its own would not help: no single Q holds both ends. The F28335 has a float unit; the wing
//! profile runs `c28x-f32`. The geometry ([`hinge_angle`], [`static_axis`], [`ZeroAcquisition`]) is
//! generic over every backend.

mod app;
mod filter;
mod geometry;
#[cfg(test)]
mod tests;

pub use app::{AxisSource, WingUnit};
pub use filter::{check_fixed_point_span, FilterConfig, Mode, WingFilter, WingOutput, STATES};
pub use geometry::{
    axis_of_rotation, hinge_angle, samples_needed, static_axis, up_vector, DynamicAxis, WingZero, ZeroAcquisition,
};
