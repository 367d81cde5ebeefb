//! Compass tilt compensation (thesis eq. 2.38–2.40) and the 24-point deviation least squares (eq.
//! 3.13–3.18), with the spec's corrections. Module docs: `gfnav/mod.rs`.
//!
//! Tilt: Hx* = Hx cos γ + Hy sin θ sin γ − Hz cos θ sin γ, Hy* = Hy cos θ + Hz sin θ, as printed. These are
//! the first two rows of C_b^h = R_y(−γ)·R_x(−θ) (R the active rotation matrices), so they level the
//! field exactly in the compass's own axes x forward, y right, z down (the HMC6343's): θ the angle about
//! the forward axis, γ about the right axis (the test builds the field that way at any tilt and gets
//! the heading back). β = (−atan2(Hy*, Hx*)) mod 360°: the printed arctan(Hx*/Hy*) contradicts the
//! thesis's own quadrant rules, which also miss Hx* < 0, Hy* > 0; atan2 covers all four (spec).
//!
//! Deviation: Δβ = A + B sin β + C cos β + D sin 2β + E cos 2β of the raw heading β, fitted over 24
//! headings 0°, 15°, …, 345° (the printed last point 360° repeats 0°: corrected), the observation being
//! βₖ − refₖ wrapped to (−180°, 180°]; compensated heading β − Δβ(β).

use super::super::lit;
use crate::numerics::{QClass, Scalar};
use crate::{Error, Result};

/// The horizontal field (Hx*, Hy*) of body field `h` at angles θ, γ (rad), eq. 2.38–2.39.
pub fn tilt_compensate<T: Scalar>(h: &[T; 3], theta: T, gamma: T) -> (T, T) {
    let (st, ct, sg, cg) = (theta.sin(), theta.cos(), gamma.sin(), gamma.cos());
    (h[0] * cg + h[1] * st * sg - h[2] * ct * sg, h[1] * ct + h[2] * st)
}

/// The magnetic heading β in [0, 2π) from the horizontal field: (−atan2(Hy*, Hx*)) mod 2π.
pub fn heading<T: Scalar>(hx: T, hy: T) -> T {
    let b = -hy.atan2(hx);
    let two_pi: T = lit(std::f64::consts::TAU);
    let b = if b < lit(0.0) { b + two_pi } else { b };
    (if b >= two_pi { b - two_pi } else { b }).to_class(QClass::Angle)
}

/// The 24 reference headings, degrees: 0, 15, …, 345.
pub fn reference_headings_deg() -> [f64; 24] {
    std::array::from_fn(|k| 15.0 * k as f64)
}

/// Deviation coefficients [A, B, C, D, E] (A and the result in the unit of the observations).
pub type Deviation = [f64; 5];

fn regressors(beta_rad: f64) -> [f64; 5] {
    [1.0, beta_rad.sin(), beta_rad.cos(), (2.0 * beta_rad).sin(), (2.0 * beta_rad).cos()]
}

/// Δβ(β) for raw heading β (degrees), in degrees.
pub fn deviation_at(m: &Deviation, beta_deg: f64) -> f64 {
    regressors(beta_deg.to_radians()).iter().zip(m).map(|(u, c)| u * c).sum()
}

/// The compensated heading β − Δβ(β), degrees in [0, 360).
pub fn compensate(m: &Deviation, beta_deg: f64) -> f64 {
    (beta_deg - deviation_at(m, beta_deg)).rem_euclid(360.0)
}

/// Least squares M = (UᵀU)⁻¹UᵀH (eq. 3.18) from raw headings `beta_deg` at the 24 reference headings
/// ([`reference_headings_deg`]), degrees. Errors if the normal matrix is singular (headings that do
/// not spread around the circle).
pub fn fit_deviation(beta_deg: &[f64; 24]) -> Result<Deviation> {
    fit_deviation_against(beta_deg, &reference_headings_deg())
}

/// The fit against any 24 reference headings (degrees): the printed H (its last row β₂₄ − 360) is
/// this with 360 as the last reference, kept to show what it costs.
pub fn fit_deviation_against(beta_deg: &[f64; 24], refs: &[f64; 24]) -> Result<Deviation> {
    let mut n = [[0.0; 5]; 5];
    let mut r = [0.0; 5];
    for (b, rf) in beta_deg.iter().zip(refs) {
        let u = regressors(b.to_radians());
        let h = (b - rf + 180.0).rem_euclid(360.0) - 180.0;
        for i in 0..5 {
            r[i] += u[i] * h;
            for j in 0..5 {
                n[i][j] += u[i] * u[j];
            }
        }
    }
    solve5(n, r).ok_or_else(|| {
        Error::Config("compass deviation fit: UᵀU is singular (the 24 headings do not spread around the circle)".into())
    })
}

/// Gaussian elimination with partial pivoting (a 5×5 symmetric positive definite system).
#[allow(clippy::needless_range_loop)] // matrix algebra reads best indexed
fn solve5(mut a: [[f64; 5]; 5], mut b: [f64; 5]) -> Option<[f64; 5]> {
    let scale = a.iter().map(|r| r.iter().map(|x| x.abs()).fold(0.0, f64::max)).fold(0.0, f64::max);
    for k in 0..5 {
        let p = (k..5).max_by(|&i, &j| a[i][k].abs().total_cmp(&a[j][k].abs()))?;
        if a[p][k].abs() <= 1e-12 * scale {
            return None;
        }
        a.swap(k, p);
        b.swap(k, p);
        for i in k + 1..5 {
            let f = a[i][k] / a[k][k];
            for j in k..5 {
                a[i][j] -= f * a[k][j];
            }
            b[i] -= f * b[k];
        }
    }
    let mut x = [0.0; 5];
    for k in (0..5).rev() {
        x[k] = (b[k] - (k + 1..5).map(|j| a[k][j] * x[j]).sum::<f64>()) / a[k][k];
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::C28xF32Rn;

    fn rx(a: f64) -> [[f64; 3]; 3] {
        [[1.0, 0.0, 0.0], [0.0, a.cos(), -a.sin()], [0.0, a.sin(), a.cos()]]
    }
    fn ry(a: f64) -> [[f64; 3]; 3] {
        [[a.cos(), 0.0, a.sin()], [0.0, 1.0, 0.0], [-a.sin(), 0.0, a.cos()]]
    }
    fn mul(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
        std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
    }

    /// The field of a board at heading ψ tilted by θ, γ (C_b^h = R_y(−γ)R_x(−θ), axes x forward, y right,
    /// z down; field inclination 45°): the printed formulas level it exactly and β = ψ in all four
    /// quadrants, for tilts up to the HMC6343's ±80°; in f64 to 1e-12 rad, in single precision to 1e-5.
    #[test]
    fn tilt_compensation_returns_the_heading_in_every_quadrant() {
        let inc = 45f64.to_radians();
        for psi_deg in (0..360).step_by(5) {
            let psi = (psi_deg as f64 + 0.5).to_radians();
            let h_h = [inc.cos() * psi.cos(), -inc.cos() * psi.sin(), inc.sin()];
            for (theta_deg, gamma_deg) in [(0.0, 0.0), (30.0, -20.0), (-80.0, 45.0), (60.0, 80.0), (-10.0, -75.0)] {
                let (th, ga) = (f64::to_radians(theta_deg), f64::to_radians(gamma_deg));
                let c_bh = mul(&ry(-ga), &rx(-th));
                // H_b = C_h^b H_h = (C_b^h)ᵀ H_h.
                let h_b: [f64; 3] = std::array::from_fn(|i| (0..3).map(|k| c_bh[k][i] * h_h[k]).sum());
                let (hx, hy) = tilt_compensate(&h_b, th, ga);
                assert!((hx - h_h[0]).abs() < 1e-12 && (hy - h_h[1]).abs() < 1e-12);
                let err = (heading(hx, hy) - psi + 3.0 * std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                    - std::f64::consts::PI;
                assert!(err.abs() < 1e-12, "ψ {psi_deg} θ {theta_deg} γ {gamma_deg}: {err}");
                let s = |x: f64| C28xF32Rn::from_f64(x, QClass::Generic);
                let (fx, fy) = tilt_compensate(&h_b.map(s), s(th), s(ga));
                let e32 = (heading(fx, fy).to_f64() - psi + 3.0 * std::f64::consts::PI)
                    .rem_euclid(std::f64::consts::TAU)
                    - std::f64::consts::PI;
                assert!(e32.abs() < 1e-5, "{e32}");
            }
        }
    }

    /// A synthetic deviation [A..E] = [1.5°, −2.0°, 3.0°, 0.7°, −0.4°]: the raw heading βₖ at reference
    /// refₖ solves βₖ = refₖ + Δβ(βₖ) (fixed point; |dΔβ/dβ| ≤ Σ|coef|·2 rad/rad < 1 contracts). The fit
    /// returns the five coefficients to 1e-12° (the data are exactly in the model, so the residual is
    /// round-off), and compensation returns every reference heading. With the printed last point (360°
    /// for the 24th raw heading at 345°+Δβ) the fit is off by degrees: the corrected point matters.
    #[test]
    fn deviation_fit_recovers_the_coefficients_exactly() {
        let m: Deviation = [1.5, -2.0, 3.0, 0.7, -0.4];
        let refs = reference_headings_deg();
        let beta: [f64; 24] = refs.map(|r| {
            let mut b = r;
            for _ in 0..200 {
                b = r + deviation_at(&m, b);
            }
            b.rem_euclid(360.0)
        });
        let fit = fit_deviation(&beta).unwrap();
        for (a, b) in fit.iter().zip(m) {
            assert!((a - b).abs() < 1e-12, "{fit:?}");
        }
        for (b, r) in beta.iter().zip(refs) {
            let d = (compensate(&fit, *b) - r + 180.0).rem_euclid(360.0) - 180.0;
            assert!(d.abs() < 1e-10);
        }
        // The printed H's last row is β₂₄ − 360 with β₂₄ near 345: a 15° outlier among 24 points.
        let mut printed_refs = refs;
        printed_refs[23] = 360.0;
        let off = fit_deviation_against(&beta, &printed_refs).unwrap();
        assert!(off.iter().zip(m).any(|(a, b)| (a - b).abs() > 0.3), "{off:?}");
    }

    #[test]
    fn clustered_headings_are_refused() {
        assert!(fit_deviation(&[10.0; 24]).is_err());
    }
}
