//! The C28x single-precision model for a firmware's own `float`/`double` code (the C28x float mode of
//! `sins-fw build-firmware`, `firmware_c/include/sins_fw_c28x_float.h`): conversions, negation,
//! absolute value and the math library, each what `sins_core::numerics::C28xF32Rn` (the `c28x-f32`
//! backend) does. The four operations and `sqrt` are `sins_c28x_add` … `sins_c28x_sqrt` (lib.rs).
//!
//! Functions the backend has no model of (`tan`, `acos`, `exp`, `log`, `pow`) follow the backend's
//! documented rule for fastRTS' transcendental functions: evaluated in f64, rounded once to nearest
//! f32, made canonical (no NaN, no subnormal, no −0).

use sins_core::numerics::{C28xF32Rn, QClass, Scalar};

fn c28x(x: f32) -> C28xF32Rn {
    C28xF32Rn::new(x)
}

/// The rule for functions without a model: f64 result, rounded to nearest f32, canonical.
fn library(y: f64) -> f32 {
    C28xF32Rn::from_f64(y, QClass::Generic).value()
}

/// A constant or a host `double` as TI's compiler gives it a 32-bit `double`: rounded to nearest
/// f32 (whatever RND32), canonical (NaN → +∞, subnormals and −0 → +0).
#[no_mangle]
pub extern "C" fn sins_c28x_from_f64(x: f64) -> f32 {
    C28xF32Rn::from_f64(x, QClass::Generic).value()
}

/// `I32TOF32` (rounded in the mode: to nearest).
#[no_mangle]
pub extern "C" fn sins_c28x_from_i32(x: i32) -> f32 {
    C28xF32Rn::from_i32(x, QClass::Generic).value()
}

/// `UI32TOF32` (rounded to nearest; exact through f64, so one rounding).
#[no_mangle]
pub extern "C" fn sins_c28x_from_u32(x: u32) -> f32 {
    C28xF32Rn::from_f64(f64::from(x), QClass::Generic).value()
}

/// `F32TOI32`: truncated toward zero, saturated to the i32 range (the FPU saturates; C on the host
/// leaves out-of-range conversions undefined). ∞ saturates.
#[no_mangle]
pub extern "C" fn sins_c28x_to_i32(x: f32) -> i32 {
    x as i32
}

/// `F32TOUI32`: truncated toward zero, saturated to 0…2³²−1.
#[no_mangle]
pub extern "C" fn sins_c28x_to_u32(x: f32) -> u32 {
    x as u32
}

/// `NEGF32` (0 stays +0).
#[no_mangle]
pub extern "C" fn sins_c28x_neg(x: f32) -> f32 {
    (-c28x(x)).value()
}

/// `ABSF32`.
#[no_mangle]
pub extern "C" fn sins_c28x_abs(x: f32) -> f32 {
    c28x(x).abs().value()
}

/// fastRTS `sin` (the backend's model: f64 sine rounded once to nearest f32).
#[no_mangle]
pub extern "C" fn sins_c28x_sin(x: f32) -> f32 {
    c28x(x).sin().value()
}

/// fastRTS `cos` (as `sins_c28x_sin`).
#[no_mangle]
pub extern "C" fn sins_c28x_cos(x: f32) -> f32 {
    c28x(x).cos().value()
}

/// fastRTS `atan`.
#[no_mangle]
pub extern "C" fn sins_c28x_atan(x: f32) -> f32 {
    c28x(x).atan().value()
}

/// fastRTS `atan2(y, x)`.
#[no_mangle]
pub extern "C" fn sins_c28x_atan2(y: f32, x: f32) -> f32 {
    c28x(y).atan2(c28x(x)).value()
}

/// fastRTS `asin` (argument clamped to [−1, 1] as the backend does).
#[no_mangle]
pub extern "C" fn sins_c28x_asin(x: f32) -> f32 {
    c28x(x).asin().value()
}

/// `acos`: no model in the backend; f64, rounded once to nearest (argument clamped to [−1, 1]).
#[no_mangle]
pub extern "C" fn sins_c28x_acos(x: f32) -> f32 {
    library(f64::from(c28x(x).value()).clamp(-1.0, 1.0).acos())
}

/// `tan`: no model in the backend; f64, rounded once to nearest.
#[no_mangle]
pub extern "C" fn sins_c28x_tan(x: f32) -> f32 {
    library(f64::from(c28x(x).value()).tan())
}

/// `exp`: no model in the backend; f64, rounded once to nearest.
#[no_mangle]
pub extern "C" fn sins_c28x_exp(x: f32) -> f32 {
    library(f64::from(c28x(x).value()).exp())
}

/// `log`: no model in the backend; f64, rounded once to nearest (log 0 = −∞; log of x < 0, NaN in
/// IEEE, is +∞ as the FPU treats NaN).
#[no_mangle]
pub extern "C" fn sins_c28x_log(x: f32) -> f32 {
    library(f64::from(c28x(x).value()).ln())
}

/// `pow`: no model in the backend; f64, rounded once to nearest.
#[no_mangle]
pub extern "C" fn sins_c28x_pow(x: f32, y: f32) -> f32 {
    library(f64::from(c28x(x).value()).powf(f64::from(c28x(y).value())))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conversions_and_library_are_the_backend() {
        assert_eq!(sins_c28x_from_f64(1e-40), 0.0, "subnormal flushed");
        assert_eq!(sins_c28x_from_f64(-0.0).to_bits(), 0, "−0 stored as +0");
        assert_eq!(sins_c28x_from_f64(f64::NAN), f32::INFINITY);
        assert_eq!(sins_c28x_from_i32((1 << 24) + 1), 16_777_216.0, "tie to even");
        assert_eq!(sins_c28x_from_u32(u32::MAX), 4_294_967_296.0);
        assert_eq!(sins_c28x_to_i32(f32::INFINITY), i32::MAX);
        assert_eq!(sins_c28x_to_i32(-2.9), -2);
        assert_eq!(sins_c28x_neg(0.0).to_bits(), 0);
        assert_eq!(sins_c28x_abs(-2.5), 2.5);
        for x in [0.1f32, -1.3, 3.0, 1e-3] {
            let c = C28xF32Rn::new(x);
            assert_eq!(sins_c28x_sin(x), c.sin().value());
            assert_eq!(sins_c28x_cos(x), c.cos().value());
            assert_eq!(sins_c28x_atan(x), c.atan().value());
            assert_eq!(sins_c28x_atan2(x, -0.7), c.atan2(C28xF32Rn::new(-0.7)).value());
            assert_eq!(sins_c28x_asin(x), c.asin().value());
        }
        assert_eq!(sins_c28x_log(-1.0), f32::INFINITY, "NaN is ∞ on the FPU");
        assert_eq!(sins_c28x_log(0.0), f32::NEG_INFINITY);
        assert_eq!(sins_c28x_exp(-200.0), 0.0, "flushed");
    }
}
