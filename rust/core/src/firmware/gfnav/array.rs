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
    readings_of(&thesis_channels(), accel, ang_acc, rate, l)
}

/// [`readings`] of the array `channels`.
pub fn readings_of(
    channels: &[Channel; 9],
    accel: &Vec3<f64>,
    ang_acc: &Vec3<f64>,
    rate: &Vec3<f64>,
    l: f64,
) -> [f64; 9] {
    let cross = |a: &Vec3<f64>, b: &Vec3<f64>| -> Vec3<f64> {
        [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    };
    std::array::from_fn(|i| {
        let u = channels[i].position.map(|x| x * l);
        let at = cross(ang_acc, &u);
        let centripetal = cross(rate, &cross(rate, &u));
        let k = channels[i].axis;
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

/// The nine unknowns' names, in the order of [`Inverse`]'s rows (A, ω̇, the rate products).
pub const UNKNOWNS: [&str; 9] = ["Ax", "Ay", "Az", "ω̇x", "ω̇y", "ω̇z", "ωxωy", "ωyωz", "ωxωz"];

/// One channel of an array: its part's lever position uᵢ/l (body axes) and its sensing axis (0 = x,
/// 1 = y, 2 = z). The part's axes are the body's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Channel {
    /// uᵢ/l.
    pub position: Vec3<f64>,
    /// The body axis the channel senses along.
    pub axis: usize,
}

/// The nine channels of the thesis's layout ([`POSITIONS`], [`SENSING_AXIS`]).
pub fn thesis_channels() -> [Channel; 9] {
    std::array::from_fn(|i| Channel { position: POSITIONS[i], axis: SENSING_AXIS[i] })
}

/// Why nine channels cannot give the nine unknowns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GeometryError {
    /// Channel `.0` senses along a component of its own lever (uᵢ·θᵢ ≠ 0): its reading holds the
    /// squares ωⱼ², three more unknowns than nine readings can give.
    AlongLever(usize),
    /// The readings cannot tell unknown `.0` (an index into [`UNKNOWNS`]) from the others: the
    /// channels' matrix is singular.
    Singular(usize),
}

impl std::fmt::Display for GeometryError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            GeometryError::AlongLever(c) => write!(
                f,
                "channel A{} senses along its own lever (its position has a component on its sensing axis): \
                 its reading holds the squares of the rate, which nine channels cannot separate",
                c + 1
            ),
            GeometryError::Singular(u) => write!(
                f,
                "the nine channels cannot tell {} from the other unknowns (A, ω̇, ωxωy, ωyωz, ωxωz): \
                 the array's matrix is singular",
                UNKNOWNS[u]
            ),
        }
    }
}

/// Reading i in units of the unknowns (A, l·ω̇, l·products) for channels at uᵢ/l: row i of the
/// forward model fᵢ = θᵢ·(A + ω̇×uᵢ + ω×(ω×uᵢ)), the squares left out (checked absent).
fn model_row(c: &Channel) -> [f64; 9] {
    let [x, y, z] = c.position;
    let mut row = [0.0; 9];
    row[c.axis] = 1.0;
    // (ω̇×u)_k and the products ω_k ω_j u_j (j ≠ k) of (ω(ω·u))_k; order [ωxωy, ωyωz, ωxωz].
    let (dw, p): ([f64; 3], [f64; 3]) = match c.axis {
        0 => ([0.0, z, -y], [y, 0.0, z]),
        1 => ([-z, 0.0, x], [x, z, 0.0]),
        _ => ([y, -x, 0.0], [0.0, y, x]),
    };
    row[3..6].copy_from_slice(&dw);
    row[6..9].copy_from_slice(&p);
    row
}

/// The most terms an [`Inverse`] holds (nine unknowns of nine readings).
const TERMS: usize = 81;

/// The exact inversion of an array's nine channels, built once from its geometry: each unknown a
/// signed sum of readings, grouped by coefficient magnitude, each group's sum scaled by its
/// magnitude (a constant the firmware loads once per inversion). For the thesis's layout that is
/// eq. 2.11–2.13 term for term, in the same order ([`invert`]); `Copy`, no heap (the timing model
/// copies the strapdown's state each step).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Inverse {
    /// The distinct magnitudes other than 1, in the order of first use.
    scales: [f64; TERMS],
    n_scales: usize,
    /// Per unknown: (reading, negative, scale index or `NONE`) in evaluation order.
    terms: [[(u8, bool, u8); 9]; 9],
    len: [u8; 9],
}

/// No scale: a coefficient of magnitude 1.
const NONE: u8 = u8::MAX;

impl Inverse {
    /// The inversion of `channels` at lever `l` (m): an error when the geometry cannot give the
    /// nine unknowns.
    pub fn new(channels: &[Channel; 9], l: f64) -> Result<Inverse, GeometryError> {
        for (i, c) in channels.iter().enumerate() {
            if c.position[c.axis] != 0.0 {
                return Err(GeometryError::AlongLever(i));
            }
        }
        let m: [[f64; 9]; 9] = std::array::from_fn(|i| model_row(&channels[i]));
        let inv = invert9(&m).map_err(GeometryError::Singular)?;
        let scale_of = |r: usize| if r < 3 { 1.0 } else { l };
        let biggest = inv.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
        let mut out = Inverse { scales: [0.0; TERMS], n_scales: 0, terms: [[(0, false, NONE); 9]; 9], len: [0; 9] };
        for (r, row) in inv.iter().enumerate() {
            // Round-off of the elimination below 1e-12 of the largest coefficient is an exact zero.
            let nz: Vec<(usize, f64)> =
                row.iter().enumerate().filter(|(_, v)| v.abs() > 1e-12 * biggest).map(|(j, &v)| (j, v)).collect();
            // Groups of one magnitude, in the order of their first reading; in each, the positive
            // terms then the negative ones, each by reading.
            let mut mags: Vec<f64> = Vec::new();
            for &(_, v) in &nz {
                if !mags.contains(&v.abs()) {
                    mags.push(v.abs());
                }
            }
            let mut n = 0;
            for mag in mags {
                let scale = mag / scale_of(r);
                let s = if scale == 1.0 {
                    NONE
                } else if let Some(k) = out.scales[..out.n_scales].iter().position(|&x| x == scale) {
                    k as u8
                } else {
                    out.scales[out.n_scales] = scale;
                    out.n_scales += 1;
                    (out.n_scales - 1) as u8
                };
                for negative in [false, true] {
                    for &(j, _) in nz.iter().filter(|(_, v)| v.abs() == mag && (*v < 0.0) == negative) {
                        out.terms[r][n] = (j as u8, negative, s);
                        n += 1;
                    }
                }
            }
            out.len[r] = n as u8;
        }
        Ok(out)
    }

    /// Unknown `r` from the readings `a` with the scales `k` loaded.
    fn row<T: Scalar>(&self, r: usize, a: &[T; 9], k: &[Option<T>]) -> T {
        let terms = &self.terms[r][..usize::from(self.len[r])];
        let mut total: Option<T> = None;
        let mut i = 0;
        while i < terms.len() {
            let s = terms[i].2;
            let mut sum: Option<T> = None;
            while i < terms.len() && terms[i].2 == s {
                let (j, negative, _) = terms[i];
                let x = a[usize::from(j)];
                sum = Some(match (sum, negative) {
                    (None, false) => x,
                    (None, true) => -x,
                    (Some(y), false) => y + x,
                    (Some(y), true) => y - x,
                });
                i += 1;
            }
            let Some(sum) = sum else { break };
            // `NONE` (magnitude 1) is past the loaded scales: the sum itself.
            let g = k.get(usize::from(s)).copied().flatten().map_or(sum, |c| sum * c);
            total = Some(total.map_or(g, |t| t + g));
        }
        total.unwrap_or_else(|| lit(0.0))
    }

    /// The specific force at the array's origin alone (A): for the thesis's layout the centre
    /// part's three channels, no operation.
    pub fn accel<T: Scalar>(&self, a: &[T; 9]) -> Vec3<T> {
        // Only the scales these three rows use are loaded.
        let mut k: [Option<T>; TERMS] = [None; TERMS];
        for r in 0..3 {
            for &(_, _, s) in &self.terms[r][..usize::from(self.len[r])] {
                let s = usize::from(s);
                if s < self.n_scales && k[s].is_none() {
                    k[s] = Some(lit(self.scales[s]));
                }
            }
        }
        [0, 1, 2].map(|r| self.row(r, a, &k[..self.n_scales]))
    }

    /// The inversion of nine readings `a` (m/s²).
    pub fn apply<T: Scalar>(&self, a: &[T; 9]) -> ArrayMotion<T> {
        let mut k: [Option<T>; TERMS] = [None; TERMS];
        for (x, &s) in k.iter_mut().zip(&self.scales[..self.n_scales]) {
            *x = Some(lit(s));
        }
        let k = &k[..self.n_scales];
        let rate = |x: T| x.to_class(QClass::Rate);
        ArrayMotion {
            accel: [0, 1, 2].map(|r| self.row(r, a, k)),
            ang_acc: [3, 4, 5].map(|r| rate(self.row(r, a, k))),
            products: [6, 7, 8].map(|r| rate(self.row(r, a, k))),
        }
    }
}

/// The inverse of `m` by Gauss–Jordan elimination with partial pivoting; `Err(column)` when a column
/// has no pivot above 1e-9 of the matrix's largest entry (singular).
fn invert9(m: &[[f64; 9]; 9]) -> Result<[[f64; 9]; 9], usize> {
    let tol = 1e-9 * m.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
    let mut a = *m;
    let mut inv: [[f64; 9]; 9] = std::array::from_fn(|i| std::array::from_fn(|j| if i == j { 1.0 } else { 0.0 }));
    for c in 0..9 {
        let p = (c..9).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs())).unwrap_or(c);
        if a[p][c].abs() <= tol {
            return Err(c);
        }
        a.swap(c, p);
        inv.swap(c, p);
        let d = a[c][c];
        for j in 0..9 {
            a[c][j] /= d;
            inv[c][j] /= d;
        }
        for i in 0..9 {
            if i != c && a[i][c] != 0.0 {
                let f = a[i][c];
                for j in 0..9 {
                    a[i][j] -= f * a[c][j];
                    inv[i][j] -= f * inv[c][j];
                }
            }
        }
    }
    Ok(inv)
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

    /// The inversion built from the thesis's layout is eq. 2.11–2.13 ([`invert`]) bit for bit, in
    /// f64 and in single precision, with the same operations (the board's outputs and budget rest
    /// on it).
    #[test]
    fn the_thesis_layout_inverse_is_the_published_formula() {
        use crate::numerics::counter::count;
        use crate::numerics::Counted;
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(36);
        for _ in 0..1000 {
            let (a, dw, w, l) = draw(&mut rng);
            let inv = Inverse::new(&thesis_channels(), l).unwrap();
            let f = readings(&a, &dw, &w, l);
            assert_eq!(inv.apply(&f), invert(&f, l));
            let f32s = f.map(|x| C28xF32Rn::from_f64(x, QClass::Accel));
            assert_eq!(inv.apply(&f32s), invert(&f32s, l));
            assert_eq!(inv.accel(&f32s), invert(&f32s, l).accel);
            let fc = f.map(Counted);
            assert_eq!(count(|| inv.apply(&fc)).1, count(|| invert(&fc, l)).1);
            assert_eq!(count(|| inv.accel(&fc)).1, count(|| ()).1);
        }
    }

    /// A layout of mixed radii, a part off the axes, on any lever: the built inversion undoes the
    /// forward model (f64 round-off: each unknown is a sum of at most nine readings ≤ 150 m/s² with
    /// coefficients ≤ 1/l, a few ulps of 150·9/(2l)).
    #[test]
    fn any_regular_layout_inverts_exactly() {
        let ch = |p: [f64; 3], axis: usize| Channel { position: p, axis };
        let layout = [
            ch([0.0, 1.5, 0.5], 0),
            ch([0.0, 0.0, 1.0], 1),
            ch([1.0, 0.0, 0.0], 2),
            ch([0.0, 0.0, -2.0], 0),
            ch([-1.0, 0.0, 0.0], 1),
            ch([0.0, -1.0, 0.0], 2),
            ch([0.0; 3], 0),
            ch([0.0; 3], 1),
            ch([0.0; 3], 2),
        ];
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(37);
        for _ in 0..1000 {
            let (a, dw, w, l) = draw(&mut rng);
            let m = Inverse::new(&layout, l).unwrap().apply(&readings_of(&layout, &a, &dw, &w, l));
            let p = products_of(&w);
            let tol = 64.0 * f64::EPSILON * 150.0 * 9.0 / l;
            for i in 0..3 {
                assert!((m.accel[i] - a[i]).abs() <= tol);
                assert!((m.ang_acc[i] - dw[i]).abs() <= tol, "{} vs {}", m.ang_acc[i], dw[i]);
                assert!((m.products[i] - p[i]).abs() <= tol);
            }
        }
    }

    /// A degenerate layout is refused, naming what it cannot give: sensing axes turned so that each
    /// opposite pair sees one sum (ω̇x + ωyωz twice), and a part sensing along its own lever.
    #[test]
    fn degenerate_layouts_are_refused() {
        let mut layout = thesis_channels();
        for (c, axis) in layout.iter_mut().zip([2, 0, 1, 2, 0, 1]) {
            c.axis = axis;
        }
        layout[3].position = [0.0, -1.0, 0.0];
        layout[4].position = [0.0, 0.0, -1.0];
        layout[5].position = [-1.0, 0.0, 0.0];
        assert!(matches!(Inverse::new(&layout, 0.1), Err(GeometryError::Singular(_))));
        let mut along = thesis_channels();
        along[0].axis = 1;
        assert_eq!(Inverse::new(&along, 0.1), Err(GeometryError::AlongLever(0)));
        let e = GeometryError::Singular(3).to_string();
        assert!(e.contains("ω̇x") && e.contains("singular"), "{e}");
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
