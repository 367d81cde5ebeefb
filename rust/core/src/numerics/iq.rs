//! TI IQmath fixed point: a 32-bit signed integer with Q fractional bits, one Q per quantity class.
//!
//! Each [`Iq`] carries its own Q, so values of different classes can meet in one expression as they do in
//! firmware that uses `_IQ30mpy`, `_IQ24` and friends. The Q of a class comes from the profile's
//! [`IqFormats`], held in a thread-local set by [`with_formats`]: `Scalar::from_f64(x, class)` and the
//! operators have no context argument, and the formats are fixed for a whole run, so a scoped per-thread
//! setting is the one place they can live without threading a context through every generic algorithm.
//! Without a scope the defaults of [`IqFormats`] apply.
//!
//! Semantics (spec `f28335.md`, "IQmath"). In C an `_iq30` and an `_iq24` are both `long`: mixing them
//! needs an explicit `_IQNtoIQM`. The rules below are the conversion this model applies where the generic
//! firmware code mixes classes, chosen so that it never wraps by itself; where the firmware needs the finer
//! Q (an increment added to a Q30 quaternion), the generic code converts explicitly with `to_class`
//! *before* the operation, as `_IQ24toIQ30(dk)` in C:
//! - `a ± b`: the operand with more fractional bits is shifted to the other's Q (arithmetic shift right =
//!   floor), then a 32-bit wrapping add (the C28x `ADDL` does not saturate). Result Q = the lower Q.
//! - `a * b` = `_IQNmpy` with N the larger Q: the full 64-bit product shifted right (floor) by the larger
//!   Q, so the result is in the lower Q; no rounding; the low 32 bits are kept (overflow wraps).
//! - `a / b` = `_IQNdiv`: the quotient in the lower Q, rounded to nearest (ties away from zero, i.e. within
//!   ½ LSB as TI documents the rounded result of its Newton–Raphson routine), saturated to
//!   0x7FFFFFFF / 0x80000000; a zero divisor gives 0x7FFFFFFF whatever the numerator's sign.
//!   `div_to(b, class)` is the same routine with N chosen so the quotient lands in the class's Q, and
//!   `mul_to(b, class)` is `_IQNmpy` with N = Qa + Qb − Q_class (floor, wrapping): the product in the
//!   class's Q.
//! - `from_f64_range(x, max)`: `_IQN(x)` in the finest N ≤ 30 with max < 2^(31−N).
//! - `mul_i32(n)` = `_IQmpyI32(a, n)`: the 32-bit integer product, in a's Q, wrapping.
//! - `to_class` = `_IQNtoIQM`: a plain shift (left shifts wrap, right shifts floor), as IQmath's macros.
//! - `from_f64` = `_IQN(x)`: `(long)(x·2^N)`, truncation toward zero; out-of-range values saturate to the
//!   i32 limits (the C cast is undefined there; the C28x float→int conversion saturates) and NaN gives 0.
//!   `from_i32` is `_IQN(i)` of an int, the same macro: exact in range, saturating outside.
//! - `sqrt` = `_IQsqrt` (x ≤ 0 → 0), [`Iq::isqrt`] = `_IQisqrt` (x ≤ 0 → 0, saturating). Both are the exact
//!   root truncated (floored) to the Q; TI's routines are within about 1 LSB of it.
//! - sin, cos (result in the argument's Q), atan (= `_IQatan2(x, _IQ(1))`), atan2 (Q = the lower Q of the
//!   two, at most 29 because π needs 2 integer bits; (0,0) → 0; range (−π, π]): the exact value (f64,
//!   ~2⁻⁵³ relative) truncated toward zero to the Q. IQmath's table-based routines are ≈ 29-bit accurate,
//!   so results can differ from the target by a few LSB at Q29–Q30.
//! - asin(x) is written as firmware would: `_IQatan2(x, _IQsqrt(_IQ(1) − _IQmpy(x, x)))`; |x| > 1 gives
//!   sqrt(≤ 0) = 0, hence ±π/2.
//! - abs and negation wrap (`_IQabs` is `labs`: |0x80000000| stays 0x80000000).
//! - comparisons compare real values across Qs.
//!
//! Every result that wrapped or saturated is tallied per thread ([`overflows`], [`count_overflows`]): on
//! the target it is silent, here a run can show it never happened.

use super::{pow2, QClass, Scalar};
use crate::error::Result;
use crate::profile::IqFormats;
use std::cell::Cell;
use std::cmp::Ordering;
use std::fmt;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// The largest Q of an angle result (π must fit in a signed 32-bit value).
const ANGLE_MAX_Q: u8 = 29;

/// Fractional bits per class, in [`QClass`] order.
type QTable = [u8; 7];

fn q_table(f: &IqFormats) -> QTable {
    // Validated to 1…30 before use, so the narrowing is lossless.
    [f.quat_q, f.rate_q, f.angle_q, f.accel_q, f.nav_q, f.length_q, f.global_q].map(|q| q as u8)
}

fn class_index(class: QClass) -> usize {
    match class {
        QClass::Quat => 0,
        QClass::Rate => 1,
        QClass::Angle => 2,
        QClass::Accel => 3,
        QClass::Nav => 4,
        QClass::Length => 5,
        QClass::Generic => 6,
    }
}

thread_local! {
    /// The defaults of `IqFormats` (checked by a test: `Default` is not const).
    static FORMATS: Cell<QTable> = const { Cell::new([30, 24, 24, 20, 29, 8, 24]) };
    static OVERFLOWS: Cell<u64> = const { Cell::new(0) };
}

/// Tally one result that did not fit (wrapped or saturated). Off the fast path: only called on overflow.
#[cold]
fn note_overflow() {
    OVERFLOWS.with(|c| c.set(c.get() + 1));
}

/// Results that wrapped or saturated on this thread so far (every `Iq` operation, any scope).
pub fn overflows() -> u64 {
    OVERFLOWS.with(|c| c.get())
}

/// Run `f` and return its result with the number of results that wrapped or saturated meanwhile.
pub fn count_overflows<R>(f: impl FnOnce() -> R) -> (R, u64) {
    let before = overflows();
    let r = f();
    (r, overflows() - before)
}

/// The low 32 bits of `x` (the C28x keeps them), tallying an overflow when `x` does not fit.
#[inline(always)]
fn wrap(x: i64) -> i32 {
    let low = x as i32;
    if low as i64 != x {
        note_overflow();
    }
    low
}

/// Run `f` with `formats` as this thread's Q per class; the previous formats are restored afterwards (also
/// if `f` unwinds). Errors if a Q is outside 1…30 (naming the `iq.*` key).
pub fn with_formats<R>(formats: &IqFormats, f: impl FnOnce() -> R) -> Result<R> {
    formats.validate()?;
    Ok(super::with_setting(&FORMATS, q_table(formats), f))
}

/// The Q of `class` on this thread.
pub fn q_of(class: QClass) -> u8 {
    FORMATS.with(|c| c.get()[class_index(class)])
}

/// An IQmath value: `raw / 2^q`.
#[derive(Clone, Copy)]
pub struct Iq {
    raw: i32,
    q: u8,
}

impl fmt::Debug for Iq {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}_iq{}(0x{:08X})", self.to_f64(), self.q, self.raw)
    }
}

/// `raw` shifted from `from` to `to` fractional bits: left shifts wrap, right shifts floor.
#[inline(always)]
fn shift(raw: i32, from: u8, to: u8) -> i32 {
    if to >= from {
        wrap((raw as i64) << (to - from))
    } else {
        raw >> (from - to)
    }
}

/// `raw` floored from `from` to `to` ≤ `from` fractional bits (an arithmetic shift right: never wraps).
#[inline(always)]
fn floor_to(raw: i32, from: u8, to: u8) -> i32 {
    raw >> (from - to)
}

/// The wrapped 32-bit result of an operation and whether it overflowed (tallied, see [`wrap`]).
#[inline(always)]
fn wrapped((low, overflowed): (i32, bool)) -> i32 {
    if overflowed {
        note_overflow();
    }
    low
}

/// |a·2^s / b| rounded half up (ties away from zero once the sign of a·b is applied), computed in the
/// unsigned type `$wide`, which must hold a·2^s, b·2^−s and twice the remainder. Unsigned: the division has no
/// overflow case.
macro_rules! rounded_magnitude {
    ($wide:ty, $a:expr, $b:expr, $s:expr) => {{
        let (n, d) = (($a as $wide) << $s.max(0), ($b as $wide) << (-$s).max(0));
        n / d + <$wide>::from(2 * (n % d) >= d)
    }};
}

/// [`rounded_magnitude!`] for shifts beyond ±31 (up to 2^90 / 2^60), in u128, clamped to u64.
#[cold]
#[inline(never)]
fn wide_rounded_magnitude(a: u32, b: u32, s: i32) -> u64 {
    u64::try_from(rounded_magnitude!(u128, a, b, s)).unwrap_or(u64::MAX)
}

/// floor(√n).
fn isqrt_u128(n: u128) -> u128 {
    // f64 gives the root within a few units for n < 2⁹⁶; correct it exactly.
    let mut r = (n as f64).sqrt() as u128;
    while r * r > n {
        r -= 1;
    }
    while (r + 1) * (r + 1) <= n {
        r += 1;
    }
    r
}

/// Saturate to i32 (tallying an overflow when it clamps).
#[inline(always)]
fn saturate(x: i128) -> i32 {
    let clamped = x.clamp(i32::MIN as i128, i32::MAX as i128);
    if clamped != x {
        note_overflow();
    }
    clamped as i32
}

impl Iq {
    /// A value from its raw integer and Q (1…30); errors name what was wrong.
    pub fn from_raw(raw: i32, q: u8) -> Result<Iq> {
        if !(1..=30).contains(&q) {
            return Err(crate::error::Error::Config(format!("IQ format Q{q}: expected 1…30 fractional bits")));
        }
        Ok(Iq { raw, q })
    }

    /// A raw integer in the Q of `class` on this thread.
    pub fn from_raw_in(raw: i32, class: QClass) -> Iq {
        Iq { raw, q: q_of(class) }
    }

    /// The raw 32-bit integer (what the target's memory holds).
    #[inline]
    pub fn raw(self) -> i32 {
        self.raw
    }

    /// Fractional bits.
    #[inline]
    pub fn q(self) -> u8 {
        self.q
    }

    /// `_IQtoIQN`: the same real value requantised to `q` fractional bits (left shifts wrap, right floor).
    #[inline]
    pub fn to_q(self, q: u8) -> Iq {
        Iq { raw: shift(self.raw, self.q, q), q }
    }

    /// `_IQisqrt`: 1/√x in x's Q, floored, saturated to 0x7FFFFFFF; x ≤ 0 → 0.
    pub fn isqrt(self) -> Iq {
        if self.raw <= 0 {
            return Iq { raw: 0, q: self.q };
        }
        // (1/√(raw·2^−q))·2^q = √(2^3q / raw); flooring the quotient first does not change the floored root.
        let n = (1u128 << (3 * self.q as u32)) / self.raw as u128;
        Iq { raw: saturate(isqrt_u128(n) as i128), q: self.q }
    }

    /// `_IQrmpy`: the product rounded (2^(Q−1) added before the shift), wrapping; Q as for `*`.
    pub fn rmpy(self, rhs: Iq) -> Iq {
        let (shift_by, q) = (self.q.max(rhs.q), self.q.min(rhs.q));
        let p = self.raw as i64 * rhs.raw as i64 + (1i64 << (shift_by - 1));
        Iq { raw: wrap(p >> shift_by), q }
    }

    /// `_IQrsmpy`: the product rounded and saturated to 0x7FFFFFFF / 0x80000000.
    pub fn rsmpy(self, rhs: Iq) -> Iq {
        let (shift_by, q) = (self.q.max(rhs.q), self.q.min(rhs.q));
        let p = self.raw as i64 * rhs.raw as i64 + (1i64 << (shift_by - 1));
        Iq { raw: saturate((p >> shift_by) as i128), q }
    }

    /// `_IQsat(x, pos, neg)`: clamp to [neg, pos] (real values, result in x's Q).
    pub fn sat(self, pos: Iq, neg: Iq) -> Iq {
        if self > pos {
            pos.to_q(self.q)
        } else if self < neg {
            neg.to_q(self.q)
        } else {
            self
        }
    }

    /// `_IQtoF`: to f32 truncating the mantissa (toward zero).
    pub fn to_f32(self) -> f32 {
        let exact = self.to_f64();
        let r = exact as f32;
        if (r as f64).abs() > exact.abs() {
            f32::from_bits(r.to_bits() - 1)
        } else {
            r
        }
    }

    /// An exact real value (f64, ≤ 2⁻⁵³ relative error) truncated toward zero into Q `q`, saturating.
    #[inline]
    fn truncated(value: f64, q: u8) -> Iq {
        // Scaling by 2^q is exact; `as i32` truncates toward zero, saturates and maps NaN to 0.
        let scaled = value * pow2(q as i32);
        let fits = scaled > i32::MIN as f64 - 1.0 && scaled < i32::MAX as f64 + 1.0;
        if !fits && !scaled.is_nan() {
            note_overflow();
        }
        Iq { raw: scaled as i32, q }
    }

    /// `_IQNdiv` with the quotient in Q `q`: `a·2^(q − qa + qb) / b` exact, rounded to nearest (ties away from
    /// zero), saturated; a zero divisor gives 0x7FFFFFFF.
    fn quotient(self, rhs: Iq, q: u8) -> Iq {
        if rhs.raw == 0 {
            note_overflow();
            return Iq { raw: i32::MAX, q };
        }
        let s = q as i32 - self.q as i32 + rhs.q as i32;
        let (a, b) = (self.raw.unsigned_abs(), rhs.raw.unsigned_abs());
        // With |s| ≤ 31 both operands are at most 2^62 and 2·rem below 2^63: exact in u64 (the usual case),
        // several times cheaper than in u128 (a library call, kept out of line so this path saves no registers).
        let magnitude =
            if (-31..=31).contains(&s) { rounded_magnitude!(u64, a, b, s) } else { wide_rounded_magnitude(a, b, s) };
        let negative = (self.raw < 0) != (rhs.raw < 0);
        // The i32 range: up to 2^31 below zero, 2^31 − 1 above.
        let limit = (1u64 << 31) - u64::from(!negative);
        let magnitude = if magnitude > limit {
            note_overflow();
            limit
        } else {
            magnitude
        };
        let raw = if negative { -(magnitude as i64) } else { magnitude as i64 } as i32;
        Iq { raw, q }
    }
}

impl PartialEq for Iq {
    fn eq(&self, other: &Self) -> bool {
        self.partial_cmp(other) == Some(Ordering::Equal)
    }
}

impl PartialOrd for Iq {
    /// Real values compared exactly: both raws scaled to the larger Q in 64 bits.
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        let q = self.q.max(other.q);
        let a = (self.raw as i64) << (q - self.q);
        let b = (other.raw as i64) << (q - other.q);
        Some(a.cmp(&b))
    }
}

impl Add for Iq {
    type Output = Iq;
    #[inline]
    fn add(self, rhs: Iq) -> Iq {
        // Both operands go to the lower Q: a right shift (floor) for one, none for the other.
        let q = self.q.min(rhs.q);
        Iq { raw: wrapped(floor_to(self.raw, self.q, q).overflowing_add(floor_to(rhs.raw, rhs.q, q))), q }
    }
}

impl Sub for Iq {
    type Output = Iq;
    #[inline]
    fn sub(self, rhs: Iq) -> Iq {
        let q = self.q.min(rhs.q);
        Iq { raw: wrapped(floor_to(self.raw, self.q, q).overflowing_sub(floor_to(rhs.raw, rhs.q, q))), q }
    }
}

impl Mul for Iq {
    type Output = Iq;
    #[inline]
    fn mul(self, rhs: Iq) -> Iq {
        let p = self.raw as i64 * rhs.raw as i64;
        Iq { raw: wrap(p >> self.q.max(rhs.q)), q: self.q.min(rhs.q) }
    }
}

impl Div for Iq {
    type Output = Iq;
    #[inline]
    fn div(self, rhs: Iq) -> Iq {
        self.quotient(rhs, self.q.min(rhs.q))
    }
}

impl Neg for Iq {
    type Output = Iq;
    #[inline]
    fn neg(self) -> Iq {
        Iq { raw: wrap(-(self.raw as i64)), q: self.q }
    }
}

impl Scalar for Iq {
    const NAME: &'static str = "iq";

    fn from_f64(x: f64, class: QClass) -> Self {
        Iq::truncated(x, q_of(class))
    }
    fn from_i32(x: i32, class: QClass) -> Self {
        Iq::truncated(x as f64, q_of(class))
    }
    #[inline]
    fn to_f64(self) -> f64 {
        // Exact: scaling by a power of two.
        self.raw as f64 * pow2(-(self.q as i32))
    }
    #[inline]
    fn to_class(self, class: QClass) -> Self {
        self.to_q(q_of(class))
    }
    fn fixed_point() -> bool {
        true
    }
    #[inline]
    fn mul_i32(self, n: i32) -> Self {
        Iq { raw: wrap(self.raw as i64 * n as i64), q: self.q }
    }
    #[inline]
    fn div_to(self, rhs: Self, class: QClass) -> Self {
        self.quotient(rhs, q_of(class))
    }
    #[inline]
    fn mul_to(self, rhs: Self, class: QClass) -> Self {
        let q = q_of(class);
        let p = self.raw as i128 * rhs.raw as i128;
        // N = Qa + Qb − Q; a class finer than both operands together (N < 0) is a left shift.
        let n = self.q as i32 + rhs.q as i32 - q as i32;
        let shifted = if n >= 0 { p >> n } else { p << -n };
        let raw = shifted as i32;
        if raw as i128 != shifted {
            note_overflow();
        }
        Iq { raw, q }
    }
    fn from_f64_range(x: f64, max_abs: f64) -> Self {
        // Integer bits for max_abs: the range of Q N is [−2^(31−N), 2^(31−N)).
        let int_bits = if max_abs.abs() < 1.0 { 0 } else { max_abs.abs().log2().floor() as i32 + 1 };
        Iq::truncated(x, (31 - int_bits).clamp(1, 30) as u8)
    }
    fn sqrt(self) -> Self {
        if self.raw <= 0 {
            return Iq { raw: 0, q: self.q };
        }
        // √(raw·2^−q)·2^q = √(raw·2^q) < 2^30.5: fits.
        let root = isqrt_u128((self.raw as u128) << self.q);
        Iq { raw: root as i32, q: self.q }
    }
    fn sin(self) -> Self {
        Iq::truncated(self.to_f64().sin(), self.q)
    }
    fn cos(self) -> Self {
        Iq::truncated(self.to_f64().cos(), self.q)
    }
    fn atan(self) -> Self {
        Iq::truncated(self.to_f64().atan(), self.q.min(ANGLE_MAX_Q))
    }
    fn atan2(self, x: Self) -> Self {
        let q = self.q.min(x.q).min(ANGLE_MAX_Q);
        // Integer zeros are +0, so atan2(0, x<0) = π and (0, 0) = 0 as `_IQatan2`.
        Iq::truncated(self.to_f64().atan2(x.to_f64()), q)
    }
    fn asin(self) -> Self {
        let one = Iq { raw: 1 << self.q, q: self.q };
        self.atan2((one - self * self).sqrt())
    }
    #[inline]
    fn abs(self) -> Self {
        Iq { raw: wrap((self.raw as i64).abs()), q: self.q }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn q24(x: f64) -> Iq {
        Iq::truncated(x, 24)
    }
    fn raw(raw: i32, q: u8) -> Iq {
        Iq { raw, q }
    }

    #[test]
    fn formats_are_scoped_and_validated() {
        let classes =
            [QClass::Quat, QClass::Rate, QClass::Angle, QClass::Accel, QClass::Nav, QClass::Length, QClass::Generic];
        assert_eq!(classes.map(q_of), q_table(&IqFormats::default()), "defaults without a scope");
        let custom =
            IqFormats { quat_q: 29, rate_q: 20, angle_q: 22, accel_q: 16, nav_q: 27, length_q: 6, global_q: 12 };
        let inner = with_formats(&custom, || classes.map(q_of));
        assert_eq!(inner, Ok([29, 20, 22, 16, 27, 6, 12]));
        assert_eq!(q_of(QClass::Rate), IqFormats::default().rate_q as u8, "restored");
        let bad = IqFormats { accel_q: 31, ..IqFormats::default() };
        let err = with_formats(&bad, || ()).unwrap_err().to_string();
        assert!(err.contains("iq.accel_q") && err.contains("31"), "{err}");
        assert!(Iq::from_raw(1, 0).is_err() && Iq::from_raw(1, 31).is_err());
        let v = with_formats(&custom, || Iq::from_f64(1.0, QClass::Accel)).unwrap_or(raw(0, 1));
        assert_eq!((v.raw(), v.q()), (1 << 16, 16));
    }

    #[test]
    fn from_f64_truncates_toward_zero_and_saturates() {
        assert_eq!(q24(0.1).raw, 1_677_721); // 0.1·2²⁴ = 1677721.6
        assert_eq!(q24(-0.1).raw, -1_677_721);
        assert_eq!(q24(200.0).raw, i32::MAX, "Q24 holds [−128, 128)");
        assert_eq!(q24(-1e10).raw, i32::MIN);
        assert_eq!(q24(f64::NAN).raw, 0);
        assert_eq!(Iq::from_i32(-3, QClass::Rate).raw, -3 << 24);
        assert_eq!(Iq::from_i32(1000, QClass::Rate).raw, i32::MAX);
    }

    #[test]
    fn add_floors_the_finer_operand_and_wraps() {
        // −2⁻³⁰ (Q30) + 0 (Q24): floor to Q24 gives −2⁻²⁴, truncation would give 0.
        let s = raw(-1, 30) + raw(0, 24);
        assert_eq!((s.raw, s.q), (-1, 24));
        let s = raw(1, 24) - raw(1, 30);
        assert_eq!((s.raw, s.q), (1, 24));
        // 127.5 + 1 in Q24 wraps to −127.5.
        assert_eq!((q24(127.5) + q24(1.0)).to_f64(), -127.5);
        assert_eq!((q24(-128.0) - q24(0.5)).to_f64(), 127.5);
    }

    #[test]
    fn mul_floors_and_wraps_in_the_lower_q() {
        // (−2⁻²⁴)·(2⁻²⁴) = −2⁻⁴⁸: floor → −2⁻²⁴ (truncation would give 0).
        assert_eq!((raw(-1, 24) * raw(1, 24)).raw, -1);
        assert_eq!((raw(1, 24) * raw(1, 24)).raw, 0);
        // 100·100 = 10000 ≡ 16 (mod 256, the Q24 range).
        assert_eq!((q24(100.0) * q24(100.0)).to_f64(), 16.0);
        // Mixed: 0.5 (Q30) · 3 (Q24) = 1.5 in Q24.
        let p = Iq::truncated(0.5, 30) * q24(3.0);
        assert_eq!((p.to_f64(), p.q), (1.5, 24));
        // Rounded variants: 2⁻²⁴·0.5 rounds to 2⁻²⁴ (ties up), saturating variant clamps.
        assert_eq!(raw(1, 24).rmpy(q24(0.5)).raw, 1);
        assert_eq!(q24(100.0).rsmpy(q24(100.0)).raw, i32::MAX);
        assert_eq!(q24(-100.0).rsmpy(q24(100.0)).raw, i32::MIN);
    }

    /// A xorshift stream of raw values, one in eight an extreme (i32::MIN, MIN + 1, −1, 1, i32::MAX), and Qs.
    fn raw_stream() -> impl FnMut() -> (i32, u8) {
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        let extremes = [i32::MIN, i32::MIN + 1, -1, 1, i32::MAX];
        move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let raw = if x.is_multiple_of(8) { extremes[(x / 8 % 5) as usize] } else { (x >> 16) as i32 };
            (raw, (x >> 58) as u8 % 31)
        }
    }

    #[test]
    fn the_quotient_equals_the_exact_rounded_quotient() {
        // The u64 path (|shift| ≤ 31) and the u128 one against the exact i128 formula, at every shift and at
        // the edges, with the saturation tally.
        let mut next = raw_stream();
        for n in 0..200_000 {
            let ((a, qa), (b, qb), (_, q)) = (next(), next(), next());
            if b == 0 {
                continue;
            }
            let s = q as i32 - qa as i32 + qb as i32;
            let num = (a as i128) << s.max(0);
            let den = (b as i128) << (-s).max(0);
            let (quot, rem) = (num / den, num % den);
            let away = if 2 * rem.abs() >= den.abs() { num.signum() * den.signum() } else { 0 };
            let exact = quot + away;
            let want = exact.clamp(i32::MIN as i128, i32::MAX as i128) as i32;
            let (got, overflows) = count_overflows(|| Iq { raw: a, q: qa }.quotient(Iq { raw: b, q: qb }, q));
            assert_eq!(got.raw, want, "case {n}: {a}·2^-{qa} / {b}·2^-{qb} in Q{q}");
            assert_eq!(overflows, u64::from(want as i128 != exact), "case {n}: saturation tally");
        }
    }

    #[test]
    fn add_and_sub_equal_the_wide_sum() {
        // Against the definition: both operands floored to the lower Q, summed in i64, low 32 bits kept and
        // an overflow tallied when they do not hold the sum.
        let mut next = raw_stream();
        for n in 0..200_000 {
            let ((a, qa), (b, qb)) = (next(), next());
            let (qa, qb) = (qa.max(1), qb.max(1));
            let q = qa.min(qb);
            let (x, y) = ((a >> (qa - q)) as i64, (b >> (qb - q)) as i64);
            for (exact, op) in [(x + y, "+"), (x - y, "-")] {
                let (got, overflows) = count_overflows(|| {
                    let (l, r) = (Iq { raw: a, q: qa }, Iq { raw: b, q: qb });
                    if op == "+" {
                        l + r
                    } else {
                        l - r
                    }
                });
                assert_eq!((got.raw, got.q), (exact as i32, q), "case {n}: {a}·2^-{qa} {op} {b}·2^-{qb}");
                assert_eq!(overflows, u64::from(exact as i32 as i64 != exact), "case {n}: wrap tally");
            }
        }
    }

    #[test]
    fn div_rounds_saturates_and_handles_zero() {
        assert_eq!((q24(1.0) / q24(3.0)).raw, 5_592_405); // 5592405.33
        assert_eq!((q24(2.0) / q24(3.0)).raw, 11_184_811); // 11184810.67: rounded, not truncated
        assert_eq!((q24(-2.0) / q24(3.0)).raw, -11_184_811);
        assert_eq!((q24(100.0) / q24(0.001)).raw, i32::MAX);
        assert_eq!((q24(-100.0) / q24(0.001)).raw, i32::MIN);
        for n in [5.0, -5.0, 0.0] {
            assert_eq!((q24(n) / q24(0.0)).raw, 0x7FFF_FFFF, "{n}/0");
        }
        // Mixed: 0.75 (Q30) / 0.5 (Q20) = 1.5 in Q20, and 1 (Q10) / 3 (Q30) in Q10.
        let d = Iq::truncated(0.75, 30) / Iq::truncated(0.5, 20);
        assert_eq!((d.to_f64(), d.q), (1.5, 20));
        assert_eq!((Iq::truncated(1.0, 10) / Iq::truncated(3.0, 29)).raw, 341); // 341.33
    }

    #[test]
    fn mul_i32_is_the_integer_product_in_the_value_q() {
        // _IQ24(0.05·π/180) = 14640 (14640.83 truncated); × −8192 stays in Q24, exactly.
        let lsb = Iq::from_f64(0.05f64.to_radians(), QClass::Rate);
        assert_eq!(lsb.raw, 14_640);
        let r = lsb.mul_i32(-8192);
        assert_eq!((r.raw, r.q), (14_640 * -8192, 24));
        let (r, n) = count_overflows(|| q24(100.0).mul_i32(2));
        assert_eq!((r.to_f64(), n), (-56.0, 1), "200 wraps modulo 256 (the Q24 range)");
    }

    #[test]
    fn div_to_rounds_the_quotient_into_the_class() {
        // 10 m/s (Q20) over 6378137 m (Q8): the plain quotient takes the divisor's Q8 and is 0.
        let v = Iq::truncated(10.0, 20);
        let r = Iq::truncated(6_378_137.0, 8);
        assert_eq!((v / r).raw, 0);
        let w = v.div_to(r, QClass::Rate);
        assert_eq!((w.q, w.raw), (24, (10.0 / 6_378_137.0 * 16_777_216.0f64).round() as i32));
        // Into a coarser Q than both operands, rounded (ties away from zero) and saturated.
        assert_eq!(q24(-5.0).div_to(q24(2.0), QClass::Length).to_f64(), -2.5);
        let (sat, n) = count_overflows(|| q24(100.0).div_to(q24(0.5), QClass::Quat));
        assert_eq!((sat.raw, n), (i32::MAX, 1));
    }

    #[test]
    fn mul_to_floors_the_product_into_the_class() {
        // K·T = 0.3 rad/s · 0.008 s in Q24 × Q24: the lower-Q product keeps Q24, mul_to keeps Q30.
        let (k, t) = (q24(0.3), q24(0.008));
        let exact = k.to_f64() * t.to_f64();
        assert_eq!((k * t).raw, (exact * 2f64.powi(24)).floor() as i32);
        let p = k.mul_to(t, QClass::Quat);
        assert_eq!((p.q, p.raw), (30, (exact * 2f64.powi(30)).floor() as i32));
        assert_eq!(q24(-0.5).mul_to(q24(3.0), QClass::Length).raw, -(3 << 7), "−1.5 in Q8");
        let (w, n) = count_overflows(|| q24(2.0).mul_to(q24(1.5), QClass::Quat));
        assert_eq!((w.to_f64(), n), (-1.0, 1), "3 wraps in Q30");
    }

    #[test]
    fn from_f64_range_takes_the_finest_q_that_holds_the_range() {
        // 0.05 °/s in rad/s for codes up to ±8192: 7.15 rad/s needs 3 integer bits → Q28.
        let c = Iq::from_f64_range(0.05f64.to_radians(), 8192.0 * 0.05f64.to_radians());
        assert_eq!((c.q, c.raw), (28, (0.05f64.to_radians() * 2f64.powi(28)) as i32));
        assert_eq!(Iq::from_f64_range(0.5, 0.9).q, 30);
        assert_eq!(Iq::from_f64_range(0.03, 267.8).q, 22, "±512");
        assert_eq!(Iq::from_f64_range(1.0, 256.0).q, 22, "256 itself needs 9 integer bits");
    }

    #[test]
    fn overflows_are_tallied() {
        let (_, n) = count_overflows(|| {
            let _ = q24(1.0) + q24(2.0) - q24(0.5) * q24(3.0) / q24(7.0);
            let _ = Iq::truncated(-0.5, 30).to_q(24).abs();
        });
        assert_eq!(n, 0, "nothing overflows in range");
        let (_, n) = count_overflows(|| {
            let _ = q24(127.5) + q24(1.0); // add wraps
            let _ = q24(-128.0) - q24(1.0); // sub wraps
            let _ = q24(100.0) * q24(100.0); // product wraps
            let _ = q24(3.0).to_q(30); // left shift wraps
            let _ = -raw(i32::MIN, 24); // negation of the most negative value
            let _ = Iq::from_f64(200.0, QClass::Rate); // _IQ() saturates
            let _ = q24(1.0) / q24(0.0); // zero divisor
        });
        assert_eq!(n, 7);
    }

    #[test]
    fn to_class_is_a_plain_shift() {
        let three = q24(3.0);
        assert_eq!(three.to_q(30).to_f64(), -1.0, "3·2³⁰ wraps to −2³⁰");
        assert_eq!(raw(-1, 30).to_q(24).raw, -1, "right shift floors");
        assert_eq!(Iq::truncated(0.5, 30).to_class(QClass::Rate).q, 24);
    }

    #[test]
    fn sqrt_and_isqrt() {
        assert_eq!(q24(-1.0).sqrt().raw, 0);
        assert_eq!(q24(0.0).sqrt().raw, 0);
        assert_eq!(q24(2.0).sqrt().raw, (2f64.sqrt() * 16_777_216.0).floor() as i32);
        assert_eq!(Iq::truncated(0.25, 30).sqrt().to_f64(), 0.5);
        assert_eq!(raw(i32::MAX, 30).sqrt().raw, ((i32::MAX as f64) * 2f64.powi(30)).sqrt().floor() as i32);
        assert_eq!(q24(4.0).isqrt().to_f64(), 0.5);
        assert_eq!(q24(0.0).isqrt().raw, 0);
        assert_eq!(q24(-4.0).isqrt().raw, 0);
        assert_eq!(raw(1, 24).isqrt().raw, i32::MAX, "1/√2⁻²⁴ = 4096 > Q24 range");
        assert_eq!(q24(2.0).isqrt().raw, (16_777_216.0 / 2f64.sqrt()).floor() as i32);
    }

    #[test]
    fn trig_truncates_and_atan2_range() {
        assert_eq!(q24(0.0).atan2(q24(0.0)).raw, 0);
        let pi = q24(0.0).atan2(q24(-1.0));
        assert_eq!(pi.raw, (std::f64::consts::PI * 16_777_216.0) as i32, "atan2(0, −1) = +π");
        let near_minus_pi = raw(-1, 24).atan2(q24(-1.0));
        let exact_pi = std::f64::consts::PI;
        let v = near_minus_pi.to_f64();
        // −π + atan(2⁻²⁴) ≈ −π + 2⁻²⁴, then truncated toward zero by < 1 LSB (2⁻²⁴).
        assert!(v > -exact_pi && v < -exact_pi + 2f64.powi(-23), "{v}");
        let a = Iq::truncated(0.5, 30).atan2(Iq::truncated(0.5, 30));
        assert_eq!((a.q, a.raw), (29, (std::f64::consts::FRAC_PI_4 * 2f64.powi(29)) as i32));
        assert_eq!(q24(0.5).sin().raw, (0.5f64.sin() * 16_777_216.0) as i32);
        assert_eq!(q24(-0.5).sin().raw, -q24(0.5).sin().raw, "toward zero: odd symmetry");
        assert_eq!(q24(1.0).atan().raw, (std::f64::consts::FRAC_PI_4 * 16_777_216.0) as i32);
        assert_eq!(Iq::truncated(1.0, 30).asin().raw, (std::f64::consts::FRAC_PI_2 * 2f64.powi(29)) as i32);
        assert_eq!(q24(1.5).asin().to_f64(), q24(std::f64::consts::FRAC_PI_2).to_f64(), "|x| > 1 → π/2");
        // asin through the IQ sequence stays within a few LSB of the exact value (x² floors, sqrt floors).
        let s = Iq::truncated(0.5, 30).asin().to_f64();
        assert!((s - 0.5f64.asin()).abs() < 4.0 * 2f64.powi(-29), "{s}");
    }

    #[test]
    fn comparisons_use_real_values() {
        assert_eq!(Iq::truncated(0.5, 30), q24(0.5));
        assert!(raw((1 << 29) + 1, 30) > q24(0.5));
        assert!(q24(-1.0) < Iq::truncated(-0.999, 30));
        assert_eq!(raw(i32::MIN, 24).abs().raw, i32::MIN, "labs wraps");
        assert_eq!((-raw(i32::MIN, 24)).raw, i32::MIN);
        assert_eq!(raw(-1, 24).to_f32(), -2f32.powi(-24));
        assert_eq!(raw(0x7FFF_FFFF, 24).to_f32(), 128.0 - 2f32.powi(-17), "_IQtoF truncates");
        assert_eq!(q24(5.0).sat(q24(1.0), q24(-1.0)).to_f64(), 1.0);
    }
}
