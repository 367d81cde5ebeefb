//! IEEE single precision as the TMS320C67x+ (the C6727B's CPU) computes it, for the gyro-free board's
//! navigation (spec `c6727.md`, "Floating point").
//!
//! Semantics ([unconfirmed]: c6727.md's recollection of SPRU733, which was not read; each point is
//! what that note says, kept in one place so a measurement can change it):
//! - `+ − ×` round to nearest even: compiled code runs with FADCR/FMCR/FAUCR at their reset value
//!   00 (c6727.md: "compiled code assumes round-to-nearest"); on normal operands and normal results
//!   they equal Rust's f32 bit for bit.
//! - **denormals**: a denormal operand is read as a zero of its sign, and a denormal result is
//!   flushed to a zero of its sign (the FPU's status flags record it; here a per-thread count,
//!   [`flushes`], so a run can report how many it met). The tininess point (before or after
//!   rounding) is not published: a result is flushed when it is subnormal after rounding to nearest.
//!   The sign of the flushed zero is kept [unconfirmed].
//! - **NaN**: an invalid operation (0·∞, ∞ − ∞, 0/0, √x for x < 0) returns 0x7FFF_FFFF, with no
//!   quiet/signalling distinction; the model stores that one pattern for every NaN, so a NaN that
//!   reaches a value is always the canonical one.
//! - **division and square root**: the C67x+ has no divide or square-root instruction; the RTS
//!   (`__c6xabi_divf`, `sqrtf`) refines RCPSP/RSQRSP estimates by Newton–Raphson steps. The model
//!   gives the correctly rounded IEEE quotient and root [unconfirmed: TI documents the RTS's
//!   routines as IEEE-accurate for normal operands; their last-bit behaviour is not modelled].
//! - sin, cos, atan, atan2, asin: evaluated in f64 and rounded once (the RTS's last bit is not
//!   modelled), then flushed like any result.
//!
//! Every stored value is canonical: a normal number, a signed zero, ±∞ or the canonical NaN.

use super::{QClass, Scalar};
use std::cell::Cell;
use std::fmt;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// The C67x's NaN result, 0x7FFF_FFFF.
pub const NAN_BITS: u32 = 0x7FFF_FFFF;

thread_local! {
    /// Denormal operands and results flushed to zero on this thread since the last [`take_flushes`].
    static FLUSHES: Cell<u64> = const { Cell::new(0) };
}

/// Flushes counted on this thread since the last [`take_flushes`] (or the thread's start).
pub fn flushes() -> u64 {
    FLUSHES.with(Cell::get)
}

/// The flushes counted on this thread, resetting the count.
pub fn take_flushes() -> u64 {
    FLUSHES.with(|c| c.replace(0))
}

#[cold]
#[inline(never)]
fn unusual(r: f32) -> f32 {
    if r.is_nan() {
        f32::from_bits(NAN_BITS)
    } else {
        // Subnormal: a zero of its sign.
        FLUSHES.with(|c| c.set(c.get() + 1));
        0.0f32.copysign(r)
    }
}

/// The largest subnormal f32: `|r| > MAX_SUBNORMAL` is `|r| ≥ f32::MIN_POSITIVE` (no f32 lies
/// between), written so that the compiler keeps it a float compare (the `≥ MIN_POSITIVE` form is
/// turned into an integer classification of the bits, twice the instructions on every operation).
const MAX_SUBNORMAL: f32 = f32::from_bits(0x007F_FFFF);

/// A result as the C67x stores it: normals, ±∞ and zeros pass (`|r| > MAX_SUBNORMAL` is false only
/// for NaN, zeros and subnormals); a subnormal is flushed (and counted), a NaN becomes 0x7FFF_FFFF.
#[inline(always)]
fn canonical(r: f32) -> f32 {
    if r.abs() > MAX_SUBNORMAL || r == 0.0 {
        r
    } else {
        unusual(r)
    }
}

/// An f32 as the C67x+ holds it (always canonical: see the module docs).
#[derive(Clone, Copy, PartialEq, PartialOrd, Default)]
#[repr(transparent)]
pub struct C67xF32(f32);

impl fmt::Debug for C67xF32 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:?}_c67x", self.0)
    }
}

impl C67xF32 {
    /// An f32 as the CPU would read it as an operand: a subnormal is read as a zero of its sign
    /// (counted as a flush), a NaN as 0x7FFF_FFFF.
    #[inline]
    pub fn new(x: f32) -> Self {
        C67xF32(canonical(x))
    }

    f32_target!(bits);
}

macro_rules! binop {
    ($trait:ident, $method:ident, $op:tt) => {
        impl $trait for C67xF32 {
            type Output = Self;
            #[inline]
            fn $method(self, rhs: Self) -> Self {
                C67xF32(canonical(self.0 $op rhs.0))
            }
        }
    };
}

binop!(Add, add, +);
binop!(Sub, sub, -);
binop!(Mul, mul, *);
binop!(Div, div, /);

impl Neg for C67xF32 {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        // NaN stays the canonical pattern (the sign bit of 0x7FFF_FFFF is clear).
        C67xF32(canonical(-self.0))
    }
}

/// A library result computed in f64, rounded to nearest once, stored as the CPU stores results.
#[inline]
fn from_library(y: f64) -> C67xF32 {
    C67xF32(canonical(y as f32))
}

impl Scalar for C67xF32 {
    const NAME: &'static str = "c67x-f32";

    /// The compiler rounds constants to nearest; a constant that rounds to a subnormal is read as zero.
    #[inline]
    fn from_f64(x: f64, _: QClass) -> Self {
        C67xF32::new(x as f32)
    }
    /// `INTSP` rounds to nearest.
    #[inline]
    fn from_i32(x: i32, _: QClass) -> Self {
        C67xF32(x as f32)
    }
    #[inline]
    fn to_f64(self) -> f64 {
        self.0 as f64
    }
    #[inline]
    fn sqrt(self) -> Self {
        C67xF32(canonical(self.0.sqrt()))
    }
    f32_target!(library);
    #[inline]
    fn abs(self) -> Self {
        C67xF32(canonical(self.0.abs()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    fn c(x: f32) -> C67xF32 {
        C67xF32::new(x)
    }

    /// On normal operands whose exact result is normal, + − × ÷ √ are IEEE f32's, bit for bit
    /// (random operands over a wide exponent range; the results stay normal by construction).
    #[test]
    fn normal_arithmetic_is_f32_bit_for_bit() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(6727);
        let draw = |rng: &mut Xoshiro256PlusPlus| {
            let m: f32 = rng.gen_range(1.0f32..2.0);
            let e: i32 = rng.gen_range(-40..=40);
            let s = if rng.gen::<bool>() { -1.0 } else { 1.0 };
            s * m * 2f32.powi(e)
        };
        take_flushes();
        for _ in 0..100_000 {
            let (a, b) = (draw(&mut rng), draw(&mut rng));
            assert_eq!((c(a) + c(b)).to_bits(), (a + b).to_bits());
            assert_eq!((c(a) - c(b)).to_bits(), (a - b).to_bits());
            assert_eq!((c(a) * c(b)).to_bits(), (a * b).to_bits());
            assert_eq!((c(a) / c(b)).to_bits(), (a / b).to_bits());
            assert_eq!(c(a.abs()).sqrt().to_bits(), a.abs().sqrt().to_bits());
            assert_eq!((-c(a)).to_bits(), (-a).to_bits());
        }
        assert_eq!(take_flushes(), 0, "no normal operation flushes");
    }

    /// A denormal operand is read as a signed zero, a denormal result is flushed to a signed zero,
    /// and each flush is counted.
    #[test]
    fn denormals_flush_to_zero_and_are_counted() {
        take_flushes();
        // 2⁻¹²⁶, the smallest normal; 2⁻¹²⁶ · 0.5 = 2⁻¹²⁷ is below the normal range (IEEE: subnormal).
        let tiny = f32::MIN_POSITIVE;
        let r = c(tiny) * c(0.5);
        assert_eq!(r.to_bits(), 0, "flushed to +0");
        assert_eq!(flushes(), 1);
        let r = c(-tiny) * c(0.5);
        assert_eq!(r.to_bits(), 0x8000_0000, "flushed to −0");
        // A difference of two close normals that IEEE gives as a subnormal.
        let r = c(tiny * 1.5) - c(tiny);
        assert_eq!(r.value(), 0.0);
        assert_eq!(flushes(), 3);
        // A subnormal operand (from memory) is read as zero.
        let d = C67xF32::from_bits(0x0000_0001);
        assert_eq!(d.value(), 0.0);
        assert_eq!((d + c(1.0)).value(), 1.0);
        assert_eq!(take_flushes(), 4);
        // The boundaries: the largest subnormal (either sign) flushes, the smallest normal, zeros
        // and infinities pass.
        assert_eq!(C67xF32::new(f32::from_bits(0x007F_FFFF)).to_bits(), 0);
        assert_eq!(C67xF32::new(f32::from_bits(0x807F_FFFF)).to_bits(), 0x8000_0000);
        assert_eq!(take_flushes(), 2);
        for x in [tiny, -tiny, 0.0, -0.0, f32::INFINITY, f32::NEG_INFINITY, f32::MAX] {
            assert_eq!(C67xF32::new(x).to_bits(), x.to_bits());
        }
        assert_eq!(flushes(), 0);
        // IEEE f32 keeps them: the flush is what differs.
        assert!((tiny * 0.5).is_subnormal());
        assert_eq!(flushes(), 0);
    }

    /// Invalid operations give 0x7FFF_FFFF; infinities follow IEEE.
    #[test]
    fn nan_is_the_one_pattern() {
        let inf = c(f32::INFINITY);
        for r in [inf - inf, c(0.0) * inf, c(0.0) / c(0.0), c(-1.0).sqrt(), -(c(0.0) / c(0.0))] {
            assert_eq!(r.to_bits(), NAN_BITS);
        }
        assert_eq!((c(1.0) / c(0.0)).value(), f32::INFINITY);
        assert_eq!((c(-1.0) / c(0.0)).value(), f32::NEG_INFINITY);
        assert_eq!(C67xF32::from_f64(f64::NAN, QClass::Generic).to_bits(), NAN_BITS);
    }
}
