//! TI IQmathLib for a firmware's own code (`firmware_c/include/IQmathLib.h`): every `_iq` value is a
//! raw 32-bit integer and its Q (1…30, given by the header's macro: `GLOBAL_Q` or the N of `_IQN…`),
//! and each function is what `sins_core::numerics::Iq` (the `iq` backend) does with those two.
//!
//! A Q outside 1…30 is refused by the header at compile time; should one reach a function, it returns
//! 0 and `sins_last_error()` names it.

use sins_core::numerics::iq::with_formats;
use sins_core::numerics::{Iq, QClass, Scalar};
use sins_core::profile::IqFormats;

/// The value `raw / 2^q`, or None (the thread's last error set) for a Q outside 1…30.
fn iq(raw: i32, q: u8) -> Option<Iq> {
    match Iq::from_raw(raw, q) {
        Ok(v) => Some(v),
        Err(e) => {
            crate::set_error(e.to_string());
            None
        }
    }
}

/// `f(a, b)` on two values of Q `q`, raw result (0 for a bad Q).
fn binary(a: i32, b: i32, q: u8, f: impl FnOnce(Iq, Iq) -> Iq) -> i32 {
    match (iq(a, q), iq(b, q)) {
        (Some(a), Some(b)) => f(a, b).raw(),
        _ => 0,
    }
}

/// `f(a)` on a value of Q `q`, raw result (0 for a bad Q).
fn unary(a: i32, q: u8, f: impl FnOnce(Iq) -> Iq) -> i32 {
    iq(a, q).map_or(0, |a| f(a).raw())
}

/// `_IQN(x)`: `x·2^q` truncated toward zero, saturated to the 32-bit range (NaN → 0).
#[no_mangle]
pub extern "C" fn sins_iq_from_f64(x: f64, q: u8) -> i32 {
    let formats = IqFormats { global_q: u32::from(q), ..IqFormats::default() };
    match with_formats(&formats, || Iq::from_f64(x, QClass::Generic)) {
        Ok(v) => v.raw(),
        Err(e) => {
            crate::set_error(e.to_string());
            0
        }
    }
}

/// `_IQNtoF(a)`: to f32, the mantissa truncated.
#[no_mangle]
pub extern "C" fn sins_iq_to_f32(a: i32, q: u8) -> f32 {
    iq(a, q).map_or(0.0, Iq::to_f32)
}

/// `_IQNtoIQM`: from Q `from` to Q `to` (left shifts wrap, right shifts floor).
#[no_mangle]
pub extern "C" fn sins_iq_to_q(a: i32, from: u8, to: u8) -> i32 {
    match (iq(a, from), iq(0, to)) {
        (Some(a), Some(_)) => a.to_q(to).raw(),
        _ => 0,
    }
}

/// `_IQNmpy(a, b)`: the 64-bit product shifted right by N (floor), low 32 bits.
#[no_mangle]
pub extern "C" fn sins_iq_mpy(a: i32, b: i32, q: u8) -> i32 {
    binary(a, b, q, |a, b| a * b)
}

/// `_IQNrmpy(a, b)`: the product rounded, wrapping.
#[no_mangle]
pub extern "C" fn sins_iq_rmpy(a: i32, b: i32, q: u8) -> i32 {
    binary(a, b, q, Iq::rmpy)
}

/// `_IQNrsmpy(a, b)`: the product rounded and saturated.
#[no_mangle]
pub extern "C" fn sins_iq_rsmpy(a: i32, b: i32, q: u8) -> i32 {
    binary(a, b, q, Iq::rsmpy)
}

/// `_IQNdiv(a, b)`: the quotient rounded to nearest (ties away from zero), saturated; b = 0 gives
/// 0x7FFFFFFF.
#[no_mangle]
pub extern "C" fn sins_iq_div(a: i32, b: i32, q: u8) -> i32 {
    binary(a, b, q, |a, b| a / b)
}

/// `_IQmpyI32(a, n)`: the 32-bit integer product, wrapping.
#[no_mangle]
pub extern "C" fn sins_iq_mpy_i32(a: i32, n: i32, q: u8) -> i32 {
    unary(a, q, |a| a.mul_i32(n))
}

/// `_IQNsqrt(a)`: the root floored to Q N; a ≤ 0 gives 0.
#[no_mangle]
pub extern "C" fn sins_iq_sqrt(a: i32, q: u8) -> i32 {
    unary(a, q, Iq::sqrt)
}

/// `_IQNisqrt(a)`: 1/√a floored, saturated; a ≤ 0 gives 0.
#[no_mangle]
pub extern "C" fn sins_iq_isqrt(a: i32, q: u8) -> i32 {
    unary(a, q, Iq::isqrt)
}

/// `_IQNsin(a)` (radians), in Q N, truncated toward zero.
#[no_mangle]
pub extern "C" fn sins_iq_sin(a: i32, q: u8) -> i32 {
    unary(a, q, Iq::sin)
}

/// `_IQNcos(a)` (radians), in Q N.
#[no_mangle]
pub extern "C" fn sins_iq_cos(a: i32, q: u8) -> i32 {
    unary(a, q, Iq::cos)
}

/// `_IQNatan(a)`, radians, in Q min(N, 29) (π needs two integer bits). The raw result is in that Q:
/// `IQmathLib.h` shifts it back to N.
#[no_mangle]
pub extern "C" fn sins_iq_atan(a: i32, q: u8) -> i32 {
    unary(a, q, |a| a.atan().to_q(q))
}

/// `_IQNatan2(y, x)`, radians in (−π, π] (see `sins_iq_atan` for the Q); (0, 0) gives 0.
#[no_mangle]
pub extern "C" fn sins_iq_atan2(y: i32, x: i32, q: u8) -> i32 {
    binary(y, x, q, |y, x| y.atan2(x).to_q(q))
}

/// `_IQNasin(a)`, as firmware writes it: `_IQatan2(a, _IQsqrt(_IQ(1) − _IQmpy(a, a)))`.
#[no_mangle]
pub extern "C" fn sins_iq_asin(a: i32, q: u8) -> i32 {
    unary(a, q, |a| a.asin().to_q(q))
}

/// `_IQabs(a)` (wraps: |0x80000000| stays 0x80000000).
#[no_mangle]
pub extern "C" fn sins_iq_abs(a: i32, q: u8) -> i32 {
    unary(a, q, Iq::abs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_functions_are_the_backend() {
        let q24 = |x: f64| sins_iq_from_f64(x, 24);
        assert_eq!(q24(0.5), 1 << 23);
        assert_eq!(q24(-1e-9), 0, "truncated toward zero");
        assert_eq!(q24(1e6), i32::MAX, "saturated");
        assert_eq!(sins_iq_mpy(q24(1.5), q24(-2.0), 24), q24(-3.0));
        assert_eq!(sins_iq_mpy(-1, 1, 24), -1, "floor: −2⁻⁴⁸ → −1 LSB");
        assert_eq!(sins_iq_div(q24(1.0), q24(3.0), 24), 5_592_405);
        assert_eq!(sins_iq_div(q24(1.0), 0, 24), i32::MAX);
        assert_eq!(sins_iq_sqrt(q24(2.0), 24), (2f64.sqrt() * 16_777_216.0).floor() as i32);
        assert_eq!(sins_iq_to_f32(q24(0.25), 24), 0.25);
        assert_eq!(sins_iq_to_q(q24(1.0), 24, 30), 1 << 30);
        assert_eq!(sins_iq_to_q(q24(3.0), 24, 30), (3i64 << 30) as i32, "wraps");
        let x = Iq::from_raw(q24(0.3), 24).unwrap();
        assert_eq!(sins_iq_sin(x.raw(), 24), x.sin().raw());
        assert_eq!(sins_iq_cos(x.raw(), 24), x.cos().raw());
        assert_eq!(sins_iq_atan2(x.raw(), q24(-0.7), 24), x.atan2(Iq::from_raw(q24(-0.7), 24).unwrap()).raw());
        let y = Iq::from_raw(sins_iq_from_f64(0.3, 30), 30).unwrap();
        assert_eq!(sins_iq_atan(y.raw(), 30), y.atan().raw() << 1, "Q29 result back in Q30");
        assert_eq!(sins_iq_abs(i32::MIN, 24), i32::MIN);
        assert_eq!(sins_iq_from_f64(1.0, 31), 0, "bad Q");
        assert_eq!(sins_iq_mpy(1, 1, 0), 0, "bad Q");
    }
}
