//! The nine-accelerometer array (spec `algorithms.md` §4; thesis eq. 2.7–2.13): its forward model and
//! its exact inversion. Module docs: `gfnav/mod.rs`.
//!
//! Layout (×l, body axes): u₁ = (0, 1, 0), u₂ = (0, 0, 1), u₃ = (1, 0, 0), u₄ = (0, 0, −1),
//! u₅ = (−1, 0, 0), u₆ = (0, −1, 0), u₇ = u₈ = u₉ = 0; sensing axes x, y, z, x, y, z, x, y, z.
//! Reading i is fᵢ = θᵢ·(A + ω̇×uᵢ + ω×(ω×uᵢ)), A the specific force at the origin. Written out
//! (ω×(ω×u) = ω(ω·u) − u|ω|²; no square ωᵢ² reaches a reading, because no part senses along its
//! own lever):
//!
//!   f₁ = Ax − l ω̇z + l ωxωy    f₂ = Ay − l ω̇x + l ωyωz    f₃ = Az − l ω̇y + l ωxωz
//!   f₄ = Ax − l ω̇y − l ωxωz    f₅ = Ay − l ω̇z − l ωxωy    f₆ = Az − l ω̇x − l ωyωz
//!   f₇ = Ax                    f₈ = Ay                    f₉ = Az
//!
//! Nine readings, nine unknowns (A, ω̇, the three products), and the eq. 2.11–2.13 combinations
//! invert it exactly (`inverse_is_exact_…` checks every coefficient). §2.1.3's "A₁–A₃ give the linear
//! acceleration" is A₇–A₉ (a correction of the spec).

use super::super::{lit, Vec3};
use crate::numerics::{QClass, Scalar};

/// Lever positions uᵢ/l of the nine parts (columns of eq. 2.9).
pub const POSITIONS: [[f64; 3]; 9] = [
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 0.0, 0.0],
    [0.0, 0.0, -1.0],
    [-1.0, 0.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0; 3],
    [0.0; 3],
    [0.0; 3],
];

/// Sensing axis of each part (0 = x, 1 = y, 2 = z; eq. 2.10).
pub const SENSING_AXIS: [usize; 9] = [0, 1, 2, 0, 1, 2, 0, 1, 2];

/// What the array gives at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArrayMotion<T> {
    /// Specific force at the array's origin, m/s² (A₇, A₈, A₉).
    pub accel: Vec3<T>,
    /// Angular acceleration ω̇, rad/s².
    pub ang_acc: Vec3<T>,
    /// The rate products [ωxωy, ωyωz, ωxωz], rad²/s².
    pub products: Vec3<T>,
}

/// The nine readings (m/s²) of a rigid body with specific force `accel` at the origin, angular
/// acceleration `ang_acc` and rate `rate`, parts at lever `l` (m): the forward model, in full vector
/// form (not the written-out table), so the inversion test checks the table too.
pub fn readings(accel: &Vec3<f64>, ang_acc: &Vec3<f64>, rate: &Vec3<f64>, l: f64) -> [f64; 9] {
    let cross = |a: &Vec3<f64>, b: &Vec3<f64>| -> Vec3<f64> {
        [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    };
    std::array::from_fn(|i| {
        let u = POSITIONS[i].map(|x| x * l);
        let at = cross(ang_acc, &u);
        let centripetal = cross(rate, &cross(rate, &u));
        let k = SENSING_AXIS[i];
        accel[k] + at[k] + centripetal[k]
    })
}

/// The exact inversion (eq. 2.11–2.13, A₇–A₉ for the linear part) of nine readings `a` (m/s²) at
/// lever `l` (m). Generic over the firmware's arithmetic; 1/(2l) is a constant of the firmware.
pub fn invert<T: Scalar>(a: &[T; 9], l: f64) -> ArrayMotion<T> {
    let k: T = lit(0.5 / l);
    let [a1, a2, a3, a4, a5, a6, a7, a8, a9] = *a;
    let rate = |x: T| x.to_class(QClass::Rate);
    ArrayMotion {
        accel: [a7, a8, a9],
        ang_acc: [rate((a8 + a9 - a2 - a6) * k), rate((a7 + a9 - a3 - a4) * k), rate((a7 + a8 - a1 - a5) * k)],
        products: [rate((a1 + a8 - a5 - a7) * k), rate((a2 + a9 - a6 - a8) * k), rate((a3 + a7 - a4 - a9) * k)],
    }
}

/// The rate products [ωxωy, ωyωz, ωxωz] of a rate (the order [`ArrayMotion::products`] uses).
pub fn products_of(w: &Vec3<f64>) -> Vec3<f64> {
    [w[0] * w[1], w[1] * w[2], w[0] * w[2]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::C28xF32Rn;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// Arbitrary motion: every component uniform in ±(scale), lever 0.02…0.5 m.
    fn draw(rng: &mut Xoshiro256PlusPlus) -> (Vec3<f64>, Vec3<f64>, Vec3<f64>, f64) {
        let mut v = |s: f64| -> Vec3<f64> { std::array::from_fn(|_| rng.gen_range(-s..s)) };
        let (a, dw, w) = (v(50.0), v(100.0), v(10.0));
        (a, dw, w, rng.gen_range(0.02..0.5))
    }

    /// The written-out table of the module docs is the vector forward model: each reading is linear
    /// in the nine unknowns with the coefficients listed (checked unknown by unknown).
    #[test]
    fn written_out_table_is_the_forward_model() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(23);
        for _ in 0..100 {
            let (a, dw, w, l) = draw(&mut rng);
            let (p, f) = (products_of(&w), readings(&a, &dw, &w, l));
            let table = [
                a[0] - l * dw[2] + l * p[0],
                a[1] - l * dw[0] + l * p[1],
                a[2] - l * dw[1] + l * p[2],
                a[0] - l * dw[1] - l * p[2],
                a[1] - l * dw[2] - l * p[0],
                a[2] - l * dw[0] - l * p[1],
                a[0],
                a[1],
                a[2],
            ];
            for (x, y) in f.iter().zip(table) {
                // Sums of up to four terms of magnitude ≤ 50 + 0.5·100 + 0.5·100: a few ulps of 150.
                assert!((x - y).abs() <= 8.0 * f64::EPSILON * 150.0, "{x} vs {y}");
            }
        }
    }

    /// Round trip on arbitrary motion in f64: ≤ 1e-12 relative to each quantity's scale. Derivation:
    /// each inverted quantity is (four readings ≤ 150 m/s², three roundings) × 1/(2l), so its absolute
    /// error is ≤ ~8 ulp(150)/(2l) ≤ 8·2.2e-16·150/0.04 ≈ 7e-12 rad/s² at l = 2 cm; relative to the
    /// quantities' scales (100 rad/s², 100 rad²/s²) that is ≤ 7e-14, inside 1e-12.
    #[test]
    fn inverse_is_exact_on_arbitrary_motion() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(2010);
        let mut worst: f64 = 0.0;
        for _ in 0..10_000 {
            let (a, dw, w, l) = draw(&mut rng);
            let m = invert(&readings(&a, &dw, &w, l), l);
            let p = products_of(&w);
            for i in 0..3 {
                worst = worst.max((m.accel[i] - a[i]).abs() / 50.0);
                worst = worst.max((m.ang_acc[i] - dw[i]).abs() / 100.0);
                worst = worst.max((m.products[i] - p[i]).abs() / 100.0);
            }
        }
        assert!(worst <= 1e-12, "worst relative round-trip error {worst:e}");
    }

    /// In the C6727's single precision (IEEE f32 with round to nearest; here the C28x FPU type, the
    /// same format): the round trip is exact to f32 round-off, ~1e-6 of the readings over 2l.
    #[test]
    fn inverse_in_single_precision() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(6727);
        for _ in 0..1000 {
            let (a, dw, w, l) = draw(&mut rng);
            let f = readings(&a, &dw, &w, l).map(|x| C28xF32Rn::from_f64(x, QClass::Accel));
            let m = invert(&f, l);
            let p = products_of(&w);
            // Each reading rounds by ≤ 2^-24 · 150; four of them and three sums: ≤ 8·2^-24·150/(2l).
            let tol = 8.0 * 150.0 * 2f64.powi(-24) / (2.0 * l) + 1e-6 * 100.0;
            for i in 0..3 {
                assert!((m.ang_acc[i].to_f64() - dw[i]).abs() <= tol);
                assert!((m.products[i].to_f64() - p[i]).abs() <= tol);
            }
        }
    }
}
