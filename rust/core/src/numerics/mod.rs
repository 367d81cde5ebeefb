//! The arithmetic the firmware runs in. The attitude algorithms are written once, generic over
//! [`Scalar`], and instantiated with:
//! - `f64`: the golden reference;
//! - `c28x::C28xF32`: IEEE single precision as the C28x FPU computes it (rounding mode, flush to zero,
//!   fastRTS division and square root);
//! - `iq::Iq`: TI IQmath fixed point, a Q per quantity class;
//! - `counter::Counted`: f64 values that tally every operation, for the timing model.

use std::fmt::Debug;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// The class of quantity a value belongs to. Fixed-point backends keep one Q format per class
/// (quaternion Q30, rates Q24, …); float backends ignore it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum QClass {
    /// Quaternion components and direction-cosine elements (|x| ≤ 1).
    Quat,
    /// Angular rates in rad/s and angle increments in rad.
    Rate,
    /// Angles in rad or degrees after Euler extraction.
    Angle,
    /// Specific force and accelerations (m/s²) and velocities (m/s).
    Accel,
    /// Positions (rad of latitude/longitude, metres of height) and earth-model quantities.
    Nav,
    /// Anything else: scale factors, time steps, small constants.
    Generic,
}

/// A scalar type the firmware arithmetic can run in. Operators are the C operators of the firmware;
/// methods are its library calls (fastRTS or IQmath on the target).
pub trait Scalar:
    Copy
    + Debug
    + PartialEq
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// Backend name used in reports (`f64`, `c28x-f32`, `iq`, …).
    const NAME: &'static str;

    /// A constant or an input of class `class`, converted as the firmware's compiler or runtime
    /// would (f32: round to nearest; IQ: `_IQ()` truncation in that class's Q).
    fn from_f64(x: f64, class: QClass) -> Self;
    /// An integer converted to this type (an `I16TOF32`/`I32TOF32` or `_IQ()` of an int on target).
    fn from_i32(x: i32, class: QClass) -> Self;
    /// The value as f64 (exact for every backend).
    fn to_f64(self) -> f64;
    /// Requantise into a class (IQ: shift into that class's Q; floats: identity).
    fn to_class(self, class: QClass) -> Self;

    /// Square root (fastRTS `sqrt`, `_IQsqrt`).
    fn sqrt(self) -> Self;
    /// Sine of radians.
    fn sin(self) -> Self;
    /// Cosine of radians.
    fn cos(self) -> Self;
    /// Arc tangent, radians.
    fn atan(self) -> Self;
    /// Four-quadrant arc tangent `atan2(self, x)`, radians in (−π, π].
    fn atan2(self, x: Self) -> Self;
    /// Arc sine, radians (argument clamped to [−1, 1] as the library routines do).
    fn asin(self) -> Self;
    /// Absolute value.
    fn abs(self) -> Self;
}

impl Scalar for f64 {
    const NAME: &'static str = "f64";
    fn from_f64(x: f64, _: QClass) -> Self {
        x
    }
    fn from_i32(x: i32, _: QClass) -> Self {
        x as f64
    }
    fn to_f64(self) -> f64 {
        self
    }
    fn to_class(self, _: QClass) -> Self {
        self
    }
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    fn sin(self) -> Self {
        f64::sin(self)
    }
    fn cos(self) -> Self {
        f64::cos(self)
    }
    fn atan(self) -> Self {
        f64::atan(self)
    }
    fn atan2(self, x: Self) -> Self {
        f64::atan2(self, x)
    }
    fn asin(self) -> Self {
        f64::asin(self.clamp(-1.0, 1.0))
    }
    fn abs(self) -> Self {
        f64::abs(self)
    }
}
