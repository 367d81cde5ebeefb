//! Twelve-position turntable calibration (thesis §3.2, Table 3.1, eq. 3.7–3.12, with the spec's
//! corrections). Module docs: `gfnav/mod.rs`.
//!
//! The array's solved rate (a "rate meter", the thesis treats it as a gyro triad) and the centre
//! accelerometer triad (A₇–A₉) each follow the linear model (eq. 2.32)
//!
//!   y = b + (I + K + ΔC) x,   rows of ΔC: x (0, θxz, −θxy), y (−θyz, 0, θyx), z (θzy, −θzx, 0),
//!
//! θᵢⱼ the small rotation of sensing axis i about axis j (the sign that makes the thesis's
//! formulas (3.9) and (3.11) come out as printed — checked formula by formula). x is the earth rate
//! (rad/s) or the specific force (m/s²) of the position.
//!
//! Positions (Table 3.1 order, numbered 1–12): about z down (1.1–1.4), about y west (2.1–2.4), about x
//! west (3.1–3.4). The thesis's table gives gravity (down positive); here the reference is the
//! specific force, its negative, so the accelerometer formulas below are the thesis's with each
//! difference reversed. The earth-rate column is recomputed from the printed axis directions (rows
//! 1.4 and 2.1–2.4 are misprinted in the thesis; [`PRINTED_EARTH_RATE`] keeps them).
//!
//! Corrections applied (spec §4 corrections; derivations in the tests):
//! - (3.9): θ_gxy's second bracket +(ω_x¹² − ω_x¹⁰) cos L; line 5 (θ_gyz) +(ω_y⁸ − ω_y⁶) cos L. The
//!   printed labels of lines 3–5 are shuffled too (as printed they read θ_gxx, θ_gzy, θ_gzx; by what
//!   they measure they are θ_gzy, θ_gzx, θ_gyz), and line 6's "θ_gxx" is θ_gyx.
//! - (3.10): every accelerometer bias over {1, 2, 5, 6, 7, 10, 11, 12}, whose specific forces sum to
//!   zero on every axis (as printed a_z0 takes {1, 2, 3, 6, 7, 10, 11, 12}: off by g/8; the plain means
//!   of a_x0, a_y0 pick up θ·g/3).
//! - (3.7): the rate biases over {5, …, 12}, whose earth rates sum to zero on every axis. As printed
//!   (plain means, and {1, 2, 5, 6, 7, 10, 11, 12} for z) they pick up θ·Ω sin L/3 and θ·Ω cos L/4:
//!   second order, kept as [`BiasSets::Printed`].
//! - (3.11): "θ_axx" is θ_azx.
//!
//! Every formula is exact on the linear model; with the product model (I + K)(I + ΔC) the results
//! are off by products k·θ (second order).
//!
//! Observability: through the array the earth rate reaches the rate meter only as products ωᵢωⱼ ~
//! Ω² ≈ 5.3e-9 rad²/s², against the products' resolution of one ADXL345 LSB over 2l (0.19 rad²/s² at
//! l = 0.1 m): ~7.6 orders below. The rate-meter terms round-trip on ideal data only
//! ([`earth_rate_observability`] reports the ratio; `sins-fw calibrate` prints it instead of numbers).

use super::super::Vec3;

/// Earth rate, rad/s (WGS-84).
pub const OMEGA_IE: f64 = 7.292_115e-5;

/// Body axes of each position in local-level terms: for each body axis, its direction as
/// (east, north, up) components (rows: x, y, z). Table 3.1's orientation columns.
pub const ORIENTATIONS: [[[f64; 3]; 3]; 12] = {
    const E: [f64; 3] = [1.0, 0.0, 0.0];
    const W: [f64; 3] = [-1.0, 0.0, 0.0];
    const N: [f64; 3] = [0.0, 1.0, 0.0];
    const S: [f64; 3] = [0.0, -1.0, 0.0];
    const U: [f64; 3] = [0.0, 0.0, 1.0];
    const D: [f64; 3] = [0.0, 0.0, -1.0];
    [
        [W, N, D],
        [N, E, D],
        [E, S, D],
        [S, W, D],
        [D, W, N],
        [N, W, U],
        [U, W, S],
        [S, W, D],
        [W, N, D],
        [W, U, N],
        [W, S, U],
        [W, D, S],
    ]
};

/// Table 3.1's earth-rate column as printed, in units of (Ω cos L, Ω sin L): each entry (a, b) is
/// a·Ω cos L + b·Ω sin L. Rows 1.4 and 2.1–2.4 are wrong ([`reference`] recomputes them).
pub const PRINTED_EARTH_RATE: [[(f64, f64); 3]; 12] = [
    [(0.0, 0.0), (1.0, 0.0), (0.0, -1.0)],
    [(1.0, 0.0), (0.0, 0.0), (0.0, -1.0)],
    [(0.0, 0.0), (-1.0, 0.0), (0.0, -1.0)],
    [(0.0, 0.0), (1.0, 0.0), (0.0, -1.0)],
    [(-1.0, 0.0), (0.0, 0.0), (0.0, -1.0)],
    [(0.0, -1.0), (0.0, 0.0), (1.0, 0.0)],
    [(1.0, 0.0), (0.0, 0.0), (0.0, -1.0)],
    [(1.0, 0.0), (0.0, 0.0), (0.0, -1.0)],
    [(0.0, 0.0), (1.0, 0.0), (0.0, -1.0)],
    [(0.0, 0.0), (0.0, 1.0), (1.0, 0.0)],
    [(0.0, 0.0), (-1.0, 0.0), (0.0, 1.0)],
    [(0.0, 0.0), (0.0, -1.0), (-1.0, 0.0)],
];

/// What an error-free rate meter and accelerometer triad read at a position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reference {
    /// Earth rate in body axes, rad/s.
    pub rate: Vec3<f64>,
    /// Specific force in body axes, m/s² (+g on the upward axis).
    pub force: Vec3<f64>,
}

/// The twelve positions' references at latitude `lat` (rad), gravity `g` (m/s²): body components of
/// Ω_ie = Ω(0, cos L, sin L) ENU and of f = (0, 0, g) ENU.
pub fn reference(lat: f64, g: f64) -> [Reference; 12] {
    let w = [0.0, OMEGA_IE * lat.cos(), OMEGA_IE * lat.sin()];
    let f = [0.0, 0.0, g];
    let dot = |a: &[f64; 3], b: &[f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    ORIENTATIONS.map(|axes| Reference { rate: axes.map(|a| dot(&a, &w)), force: axes.map(|a| dot(&a, &f)) })
}

/// Small-angle misalignments θᵢⱼ (rad): sensing axis i rotated about axis j.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Misalignment {
    /// x about y.
    pub xy: f64,
    /// x about z.
    pub xz: f64,
    /// y about x.
    pub yx: f64,
    /// y about z.
    pub yz: f64,
    /// z about x.
    pub zx: f64,
    /// z about y.
    pub zy: f64,
}

/// A triad's errors: y = bias + (I + K + ΔC) x.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TriadErrors {
    /// Bias, in the triad's unit (rad/s or m/s²).
    pub bias: Vec3<f64>,
    /// Scale-factor errors k (relative).
    pub scale: Vec3<f64>,
    /// Misalignments, rad.
    pub misalignment: Misalignment,
}

impl TriadErrors {
    /// ΔC (the misalignment matrix of the module docs).
    pub fn delta_c(&self) -> [[f64; 3]; 3] {
        let m = &self.misalignment;
        [[0.0, m.xz, -m.xy], [-m.yz, 0.0, m.yx], [m.zy, -m.zx, 0.0]]
    }

    /// The reading of input `x` under the linear model (eq. 2.32).
    pub fn apply_linear(&self, x: &Vec3<f64>) -> Vec3<f64> {
        let dc = self.delta_c();
        std::array::from_fn(|i| {
            self.bias[i] + (1.0 + self.scale[i]) * x[i] + (0..3).map(|j| dc[i][j] * x[j]).sum::<f64>()
        })
    }

    /// The reading under the product model (I + K)(I + ΔC) (eq. 2.31, before dropping second order).
    pub fn apply_product(&self, x: &Vec3<f64>) -> Vec3<f64> {
        let dc = self.delta_c();
        let c: Vec3<f64> = std::array::from_fn(|i| x[i] + (0..3).map(|j| dc[i][j] * x[j]).sum::<f64>());
        std::array::from_fn(|i| self.bias[i] + (1.0 + self.scale[i]) * c[i])
    }
}

/// Which bias index sets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BiasSets {
    /// Reference sums zero on every axis: rates {5…12}, accelerometers {1, 2, 5, 6, 7, 10, 11, 12}.
    Corrected,
    /// As printed: plain means for x and y; z over {1, 2, 5, 6, 7, 10, 11, 12} (rates) and
    /// {1, 2, 3, 6, 7, 10, 11, 12} (accelerometers).
    Printed,
}

/// The calibration's result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Calibration {
    /// The rate meter (the array's solved rate).
    pub rate: TriadErrors,
    /// The centre accelerometer triad (A₇–A₉).
    pub accel: TriadErrors,
}

fn mean(sets: &[usize], y: &[Vec3<f64>; 12], axis: usize) -> f64 {
    sets.iter().map(|&i| y[i - 1][axis]).sum::<f64>() / sets.len() as f64
}

/// The calibration from the twelve positions' mean readings: `rate` (rad/s) and `force` (m/s²), in
/// Table 3.1 order, at latitude `lat` (rad) with gravity `g` (m/s²).
pub fn calibrate(rate: &[Vec3<f64>; 12], force: &[Vec3<f64>; 12], lat: f64, g: f64, sets: BiasSets) -> Calibration {
    let (c, s, o) = (lat.cos(), lat.sin(), OMEGA_IE);
    let w = |i: usize, a: usize| rate[i - 1][a];
    let f = |i: usize, a: usize| force[i - 1][a];
    let (x, y, z) = (0, 1, 2);
    let all: Vec<usize> = (1..=12).collect();
    let (rb, ab): ([Vec<usize>; 3], [Vec<usize>; 3]) = match sets {
        BiasSets::Corrected => {
            let r: Vec<usize> = (5..=12).collect();
            let a = vec![1, 2, 5, 6, 7, 10, 11, 12];
            ([r.clone(), r.clone(), r], [a.clone(), a.clone(), a])
        }
        BiasSets::Printed => (
            [all.clone(), all.clone(), vec![1, 2, 5, 6, 7, 10, 11, 12]],
            [all.clone(), all.clone(), vec![1, 2, 3, 6, 7, 10, 11, 12]],
        ),
    };
    let rate_errors = TriadErrors {
        bias: std::array::from_fn(|a| mean(&rb[a], rate, a)),
        scale: [
            ((w(6, x) - w(8, x)) * c + (w(7, x) - w(5, x)) * s) / (2.0 * o) - 1.0,
            ((w(9, y) - w(11, y)) * c + (w(10, y) - w(12, y)) * s) / (2.0 * o) - 1.0,
            ((w(5, z) - w(7, z)) * c + (w(6, z) - w(8, z)) * s + (w(11, z) - w(9, z)) * s + (w(10, z) - w(12, z)) * c)
                / (4.0 * o)
                - 1.0,
        ],
        misalignment: Misalignment {
            xy: ((w(7, x) - w(5, x)) * c - (w(6, x) - w(8, x)) * s
                + (w(9, x) - w(11, x)) * s
                + (w(12, x) - w(10, x)) * c)
                / (4.0 * o),
            xz: ((w(9, x) - w(11, x)) * c - (w(12, x) - w(10, x)) * s) / (2.0 * o),
            zy: (w(2, z) - w(4, z)) / (2.0 * o * c),
            zx: (w(3, z) - w(1, z)) / (2.0 * o * c),
            yz: ((w(5, y) - w(7, y)) * s + (w(8, y) - w(6, y)) * c) / (2.0 * o),
            yx: ((w(5, y) - w(7, y)) * c - (w(8, y) - w(6, y)) * s + (w(10, y) - w(12, y)) * c
                - (w(9, y) - w(11, y)) * s)
                / (4.0 * o),
        },
    };
    let accel_errors = TriadErrors {
        bias: std::array::from_fn(|a| mean(&ab[a], force, a)),
        scale: [
            (f(7, x) - f(5, x)) / (2.0 * g) - 1.0,
            (f(10, y) - f(12, y)) / (2.0 * g) - 1.0,
            (f(6, z) - f(8, z) + f(11, z) - f(9, z)) / (4.0 * g) - 1.0,
        ],
        misalignment: Misalignment {
            xy: (f(8, x) - f(6, x) + f(9, x) - f(11, x)) / (4.0 * g),
            xz: (f(10, x) - f(12, x)) / (2.0 * g),
            yz: (f(5, y) - f(7, y)) / (2.0 * g),
            zy: (f(7, z) - f(5, z)) / (2.0 * g),
            zx: (f(12, z) - f(10, z)) / (2.0 * g),
            yx: (f(6, y) - f(8, y) + f(11, y) - f(9, y)) / (4.0 * g),
        },
    };
    Calibration { rate: rate_errors, accel: accel_errors }
}

/// How far the earth rate is below what the array resolves: (Ω², product resolution, orders). The
/// product resolution is one reading's LSB `lsb_m_s2` over 2l (a one-LSB change of one reading moves
/// a product by that much); `orders` = log10(resolution/Ω²).
pub fn earth_rate_observability(lsb_m_s2: f64, lever_m: f64) -> (f64, f64, f64) {
    let w2 = OMEGA_IE * OMEGA_IE;
    let res = lsb_m_s2 / (2.0 * lever_m);
    (w2, res, (res / w2).log10())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::device::adxl345;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    const G: f64 = 9.791;
    const LAT: f64 = 28.20021 * std::f64::consts::PI / 180.0;

    fn draw(rng: &mut Xoshiro256PlusPlus, bias: f64, small: f64) -> TriadErrors {
        let mut r = |s: f64| rng.gen_range(-s..s);
        TriadErrors {
            bias: [r(bias), r(bias), r(bias)],
            scale: [r(small), r(small), r(small)],
            misalignment: Misalignment {
                xy: r(small),
                xz: r(small),
                yx: r(small),
                yz: r(small),
                zx: r(small),
                zy: r(small),
            },
        }
    }

    fn readings(rate: &TriadErrors, accel: &TriadErrors, product: bool) -> ([Vec3<f64>; 12], [Vec3<f64>; 12]) {
        let refs = reference(LAT, G);
        let ap = |e: &TriadErrors, x: &Vec3<f64>| if product { e.apply_product(x) } else { e.apply_linear(x) };
        (refs.map(|r| ap(rate, &r.rate)), refs.map(|r| ap(accel, &r.force)))
    }

    fn worst(a: &TriadErrors, b: &TriadErrors) -> (f64, f64) {
        let (ma, mb) = (a.misalignment, b.misalignment);
        let small = [
            a.scale[0] - b.scale[0],
            a.scale[1] - b.scale[1],
            a.scale[2] - b.scale[2],
            ma.xy - mb.xy,
            ma.xz - mb.xz,
            ma.yx - mb.yx,
            ma.yz - mb.yz,
            ma.zx - mb.zx,
            ma.zy - mb.zy,
        ];
        let bias = (0..3).map(|i| (a.bias[i] - b.bias[i]).abs()).fold(0.0, f64::max);
        (bias, small.iter().map(|x| x.abs()).fold(0.0, f64::max))
    }

    /// The recomputed table agrees with the printed one except in rows 1.4 and 2.1–2.4 (spec); the
    /// gravity column (specific force negated) agrees everywhere (checked against the printed g column).
    #[test]
    #[allow(clippy::needless_range_loop)]
    fn table_rows_misprinted_are_exactly_the_listed_ones() {
        let refs = reference(LAT, G);
        let printed_gravity = [
            [0.0, 0.0, 1.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 0.0],
            [0.0, 0.0, -1.0],
            [-1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, 1.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, -1.0],
            [0.0, 1.0, 0.0],
        ];
        let (c, s) = (OMEGA_IE * LAT.cos(), OMEGA_IE * LAT.sin());
        let mut wrong = Vec::new();
        for (i, r) in refs.iter().enumerate() {
            for a in 0..3 {
                assert_eq!(r.force[a], -G * printed_gravity[i][a]);
            }
            let printed: Vec3<f64> = PRINTED_EARTH_RATE[i].map(|(p, q)| p * c + q * s);
            if (0..3).any(|a| (printed[a] - r.rate[a]).abs() > 1e-12) {
                wrong.push(i + 1);
            }
        }
        assert_eq!(wrong, vec![4, 5, 6, 7, 8]); // 1.4, 2.1, 2.2, 2.3, 2.4
    }

    /// On the linear model every term comes back to round-off (the formulas are exact): biases to
    /// 1e-15 of the references, scale factors and misalignments to 1e-9 (the rate meter's divide a
    /// difference of 1e-4 rad/s readings holding ~1e-12 of absolute round-off by 2Ω).
    #[test]
    fn exact_on_the_linear_model() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(12);
        for _ in 0..200 {
            let (re, ae) = (draw(&mut rng, 1e-3, 1e-2), draw(&mut rng, 0.5, 1e-2));
            let (w, f) = readings(&re, &ae, false);
            let cal = calibrate(&w, &f, LAT, G, BiasSets::Corrected);
            let (rb, rs) = worst(&cal.rate, &re);
            let (ab, as_) = worst(&cal.accel, &ae);
            assert!(rb < 1e-15 && rs < 1e-9, "{rb:e} {rs:e}");
            assert!(ab < 1e-14 && as_ < 1e-14, "{ab:e} {as_:e}");
        }
    }

    /// On the product model (I + K)(I + ΔC) the error is second order: every recovered term within
    /// 4·k·θ of the truth (each formula's residual is a sum of at most four products kᵢθⱼ over its
    /// divisor; here |k|, |θ| ≤ 1e-3: ≤ 4e-6, and the bias, free of scale, stays exact), while the first
    /// order terms themselves are ~1e-3.
    #[test]
    fn second_order_on_the_product_model() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(345);
        let small = 1e-3;
        for _ in 0..200 {
            let (re, ae) = (draw(&mut rng, 1e-3, small), draw(&mut rng, 0.5, small));
            let (w, f) = readings(&re, &ae, true);
            let cal = calibrate(&w, &f, LAT, G, BiasSets::Corrected);
            for (got, want, bias_tol) in [(&cal.rate, &re, 1e-15), (&cal.accel, &ae, 1e-12)] {
                let (b, s) = worst(got, want);
                assert!(b < bias_tol + 4.0 * small * small * G, "bias {b:e}");
                assert!(s <= 4.0 * small * small, "{s:e}");
            }
        }
    }

    /// The printed bias sets: a_z0 off by exactly g/8·(1 + k_z) − θ terms (here with no other error: g/8),
    /// a_x0 by θ_xy·g/3 (the plain mean: the specific forces of the twelve positions sum to −4g on z).
    #[test]
    fn printed_bias_sets_are_off_as_the_spec_says() {
        let mut ae = TriadErrors::default();
        let (w, f) = readings(&TriadErrors::default(), &ae, false);
        let cal = calibrate(&w, &f, LAT, G, BiasSets::Printed);
        assert!((cal.accel.bias[2] - (-G / 8.0)).abs() < 1e-14, "{}", cal.accel.bias[2]);
        ae.misalignment.xy = 1e-3;
        let (w, f) = readings(&TriadErrors::default(), &ae, false);
        let cal = calibrate(&w, &f, LAT, G, BiasSets::Printed);
        // x reads −θxy·f_z; Σ f_z over the twelve = −4g: mean = θxy·4g/12 = θxy·g/3.
        assert!((cal.accel.bias[0] - 1e-3 * G / 3.0).abs() < 1e-15);
        let corrected = calibrate(&w, &f, LAT, G, BiasSets::Corrected);
        assert!(corrected.accel.bias[0].abs() < 1e-15);
    }

    /// ADXL345 at l = 0.1 m: Ω² = 5.3e-9 rad²/s² against a product resolution of 3.9 mg·g₀/0.2 m =
    /// 0.19 rad²/s²: 7.6 orders (the spec's "≈ 8 orders").
    #[test]
    fn earth_rate_is_unobservable_with_the_adxl345() {
        let (w2, res, orders) = earth_rate_observability(adxl345::LSB_G * 9.80665, 0.1);
        assert!((w2 - 5.318e-9).abs() < 1e-12);
        assert!((res - 0.1915).abs() < 1e-3, "{res}");
        assert!((7.5..7.7).contains(&orders), "{orders}");
    }
}
