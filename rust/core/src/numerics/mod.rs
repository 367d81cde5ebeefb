//! The arithmetic the firmware runs in. The attitude algorithms are written once, generic over
//! [`Scalar`], and instantiated with:
//! - `f64`: the golden reference;
//! - `c28x::C28xF32`: IEEE single precision as the C28x FPU computes it (rounding mode, flush to zero,
//!   fastRTS division and square root);
//! - `iq::Iq`: TI IQmath fixed point, a Q per quantity class;
//! - `c67x::C67xF32`: IEEE single precision as the C67x+ (the gyro-free board's C6727B) computes it
//!   (denormals flushed and counted, one NaN pattern); run by that board's DSP, not a `Numeric`;
//! - `counter::Counted`: f64 values that tally every operation, for the timing model.
//!
//! `profile::Numeric` selects one of the first four for a run; [`dispatch_numeric!`](crate::dispatch_numeric) turns that runtime
//! choice into a monomorphised call of a generic function. `Counted` is not a `Numeric`: the timing model
//! runs the same generic code with it to count operations per stage.

/// What the single-precision targets (`c28x`, `c67x`), newtypes over their stored `f32`, have in
/// common, written once: the raw bits (`value`, `to_bits`, `from_bits` through the type's own `new`,
/// which canonicalises as the CPU reads an operand) with `f32_target!(bits)` in an inherent `impl`,
/// and the library functions (sine, cosine, arc tangents, arc sine: evaluated in f64 on the stored
/// value, rounded into the target by the module's `from_library`) with `f32_target!(library)` in
/// the `impl Scalar`.
macro_rules! f32_target {
    (library) => {
        fn sin(self) -> Self {
            from_library((self.0 as f64).sin())
        }
        fn cos(self) -> Self {
            from_library((self.0 as f64).cos())
        }
        fn atan(self) -> Self {
            from_library((self.0 as f64).atan())
        }
        fn atan2(self, x: Self) -> Self {
            from_library((self.0 as f64).atan2(x.0 as f64))
        }
        fn asin(self) -> Self {
            from_library((self.0 as f64).clamp(-1.0, 1.0).asin())
        }
    };
    (bits) => {
        /// The stored f32 (canonical).
        #[inline]
        pub fn value(self) -> f32 {
            self.0
        }

        /// The raw IEEE bits (what a memory dump of the target shows).
        #[inline]
        pub fn to_bits(self) -> u32 {
            self.0.to_bits()
        }

        /// A value from raw IEEE bits, read as an operand: canonicalised as the CPU uses a value it
        /// loads (`new`).
        #[inline]
        pub fn from_bits(bits: u32) -> Self {
            Self::new(f32::from_bits(bits))
        }
    };
}

pub mod c28x;
pub mod c67x;
pub mod counter;
pub mod iq;

pub use c28x::{C28xF32, C28xF32Rn, C28xF32Rz, EstimateModel};
pub use c67x::C67xF32;
pub use counter::{Counted, OpCounts};
pub use iq::Iq;

use std::cell::Cell;
use std::thread::LocalKey;

/// Run `f` with the thread-local setting `key` set to `value`; the previous value is restored
/// afterwards, also when `f` unwinds. The backends' per-run settings (C28x estimate model, IQ formats,
/// the counter's float/fixed choice) are thread-locals because operators have no context argument.
pub(crate) fn with_setting<T: Copy, R>(key: &'static LocalKey<Cell<T>>, value: T, f: impl FnOnce() -> R) -> R {
    struct Restore<T: Copy + 'static>(&'static LocalKey<Cell<T>>, T);
    impl<T: Copy + 'static> Drop for Restore<T> {
        fn drop(&mut self) {
            self.0.with(|c| c.set(self.1));
        }
    }
    let _restore = Restore(key, key.with(|c| c.replace(value)));
    f()
}

/// 2^k as f64 for |k| ≤ 1022, from its bits (a few integer instructions; no conversion or library call).
#[inline(always)]
pub(crate) fn pow2(k: i32) -> f64 {
    f64::from_bits(((k + 1023) as u64) << 52)
}

/// Instantiate generic firmware code for the backend a profile selects.
///
/// `dispatch_numeric!(numeric, T => expr)` evaluates `expr` with the type alias `T` bound to the backend of
/// `numeric` (a [`crate::profile::Numeric`]): `f64`, [`C28xF32Rn`], [`C28xF32Rz`] or [`Iq`]; every arm must
/// have the same type. With IQ, the Q formats are those in force on the thread; the form
/// `dispatch_numeric!(numeric, iq_formats = &formats, T => expr)` sets them for the IQ arm (via
/// [`iq::with_formats`]) and yields `Result<_>` in every arm (an error only for invalid formats).
///
/// ```
/// use sins_core::dispatch_numeric;
/// use sins_core::numerics::{QClass, Scalar};
/// use sins_core::profile::{IqFormats, Numeric};
///
/// fn half_norm<T: Scalar>(x: f64, y: f64) -> f64 {
///     let (x, y) = (T::from_f64(x, QClass::Generic), T::from_f64(y, QClass::Generic));
///     ((x * x + y * y).sqrt() * T::from_f64(0.5, QClass::Generic)).to_f64()
/// }
/// let f = dispatch_numeric!(Numeric::C28xF32, T => half_norm::<T>(3.0, 4.0));
/// assert_eq!(f, 2.499_999_761_581_421); // fastRTS sqrt(25) is 1 ulp below 5
/// assert_eq!(dispatch_numeric!(Numeric::F64, T => half_norm::<T>(3.0, 4.0)), 2.5);
/// let q = dispatch_numeric!(Numeric::Iq, iq_formats = &IqFormats::default(), T => half_norm::<T>(3.0, 4.0));
/// assert_eq!(q, Ok(2.5));
/// ```
#[macro_export]
macro_rules! dispatch_numeric {
    ($numeric:expr, iq_formats = $formats:expr, $t:ident => $body:expr) => {
        match $numeric {
            $crate::profile::Numeric::Iq => {
                #[allow(dead_code)]
                type $t = $crate::numerics::Iq;
                $crate::numerics::iq::with_formats($formats, || $body)
            }
            other => ::std::result::Result::<_, $crate::Error>::Ok($crate::dispatch_numeric!(other, $t => $body)),
        }
    };
    ($numeric:expr, $t:ident => $body:expr) => {
        match $numeric {
            $crate::profile::Numeric::F64 => {
                type $t = f64;
                $body
            }
            $crate::profile::Numeric::C28xF32 => {
                type $t = $crate::numerics::C28xF32Rn;
                $body
            }
            $crate::profile::Numeric::C28xF32Rz => {
                type $t = $crate::numerics::C28xF32Rz;
                $body
            }
            $crate::profile::Numeric::Iq => {
                type $t = $crate::numerics::Iq;
                $body
            }
        }
    };
}

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
    /// Latitude and longitude (rad) and small earth-model quantities (flattening).
    Nav,
    /// Lengths in metres: the earth radius, R_N + h, R_E + h and the height (6.4e6 m needs ≥ 23
    /// integer bits, so a fixed-point backend gives lengths a Q of its own).
    Length,
    /// Anything else: scale factors, time steps, small constants.
    Generic,
}

/// A scalar type the firmware arithmetic can run in. Operators are the C operators of the firmware;
/// methods are its library calls (fastRTS or IQmath on the target). The provided methods are what a
/// floating-point backend does (classes are no concern of a float); fixed point overrides them.
pub trait Scalar:
    Copy
    + Send
    + 'static
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
    /// A constant for products of magnitude up to `max_abs` (an LSB times the largest code): floats as
    /// `from_f64`; IQ `_IQN(x)` in the finest Q (≤ 30) whose range holds `max_abs`, so that the integer
    /// product keeps every bit the 32-bit word allows before the firmware shifts it to its class.
    #[inline]
    fn from_f64_range(x: f64, max_abs: f64) -> Self {
        let _ = max_abs;
        Self::from_f64(x, QClass::Generic)
    }
    /// An integer converted to this type (an `I16TOF32`/`I32TOF32` or `_IQ()` of an int on target).
    fn from_i32(x: i32, class: QClass) -> Self;
    /// The integer, memory and control work the firmware's C does here beside its arithmetic in
    /// this type: tallied by the counting type for the timing model, nothing for every other backend.
    #[inline(always)]
    fn work(w: counter::Work) {
        let _ = w;
    }
    /// The value as f64 (exact for every backend).
    fn to_f64(self) -> f64;
    /// Requantise into a class (IQ: shift into that class's Q; floats: identity).
    #[inline]
    fn to_class(self, class: QClass) -> Self {
        let _ = class;
        self
    }
    /// True for a fixed-point backend (and for the counting type while it counts one): its firmware
    /// scales integer inputs with one constant folded into the firmware unit, because intermediate
    /// units (°/s up to 409.6, g) may not fit the class's Q. The float firmware keeps the published
    /// two-step conversion, so its results stay bit-identical to the published code.
    fn fixed_point() -> bool {
        false
    }

    /// `self · n` for an integer `n` (a raw sensor code): floats convert `n` (`I32TOF32`) and
    /// multiply, `(float)n * self`; IQ is `_IQmpyI32(self, n)`, the 32-bit integer product in
    /// `self`'s Q, wrapping on overflow (IQmathLib.h: `#define _IQmpyI32(A,B) ((A)*(B))`).
    #[inline]
    fn mul_i32(self, n: i32) -> Self {
        Self::from_i32(n, QClass::Generic) * self
    }
    /// `self / rhs` with the quotient in `class` (floats: the plain division). IQ: `_IQNdiv` with N
    /// chosen so the quotient of the two operands' Qs lands in the class's Q (N = Q_class − Q_self +
    /// Q_rhs), rounded and saturated as `/`; for quotients of operands whose Q does not suit the result,
    /// such as V/(R+h) (m/s over metres in a coarse length Q, giving rad/s).
    #[inline]
    fn div_to(self, rhs: Self, class: QClass) -> Self {
        let _ = class;
        self / rhs
    }
    /// `self * rhs` with the product in `class` (floats: the plain product). IQ: `_IQNmpy` with N chosen
    /// so the product of the two operands' Qs lands in the class's Q (N = Q_self + Q_rhs − Q_class),
    /// floored, wrapping as `*`; for small products of coarse operands, such as K·T (rate × step) added
    /// to a Q30 quaternion.
    #[inline]
    fn mul_to(self, rhs: Self, class: QClass) -> Self {
        let _ = class;
        self * rhs
    }

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::{IqFormats, Numeric};

    fn one_third<T: Scalar>() -> (&'static str, f64) {
        let x = T::from_f64(1.0, QClass::Rate) / T::from_i32(3, QClass::Rate);
        (T::NAME, x.to_f64())
    }

    #[test]
    fn dispatch_picks_each_backend() {
        let third = |n: Numeric| dispatch_numeric!(n, T => one_third::<T>());
        assert_eq!(third(Numeric::F64), ("f64", 1.0 / 3.0));
        assert_eq!(third(Numeric::C28xF32).0, "c28x-f32");
        assert_eq!(third(Numeric::C28xF32Rz).0, "c28x-f32-rz");
        // IQ: rates are Q24 by default; the quotient is rounded (5592405.33 → 5592405).
        assert_eq!(third(Numeric::Iq), ("iq", 5_592_405.0 / (1u64 << 24) as f64));
        let formats = IqFormats { rate_q: 16, ..IqFormats::default() };
        let scoped = dispatch_numeric!(Numeric::Iq, iq_formats = &formats, T => one_third::<T>());
        assert_eq!(scoped, Ok(("iq", 21_845.0 / 65_536.0)));
        let float = dispatch_numeric!(Numeric::F64, iq_formats = &formats, T => one_third::<T>());
        assert_eq!(float, Ok(("f64", 1.0 / 3.0)));
        let bad = IqFormats { rate_q: 0, ..IqFormats::default() };
        assert!(dispatch_numeric!(Numeric::Iq, iq_formats = &bad, T => one_third::<T>()).is_err());
    }
}
