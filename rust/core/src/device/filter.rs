//! The ADIS16407's Bartlett-window FIR filter: two cascaded N-tap moving averages, N = 2^M,
//! M = SENS_AVG[2:0]; |H(f)| = [sin(πNf/fs) / (N sin(πf/fs))]², group delay N − 1 samples.
//!
//! The arithmetic is exact: inputs are quantised to 2⁻²⁸ of their unit (3.7e-9 °/s, g, gauss or mbar,
//! at least 3·10⁵ times finer than any output LSB) and summed in `i64`, and the division by N² is a
//! power-of-two scaling. So the DC gain is exactly 1 (a constant input comes out as its quantisation,
//! bit for bit), running sums never drift over hours of samples, and a step costs a few integer
//! additions and two native int↔float conversions.

use super::encoding::round_half_away;
use crate::error::{Error, Result};

/// Largest M that SENS_AVG[2:0] can hold.
pub const MAX_M: u8 = 7;

/// Fraction bits of the input quantum (2⁻²⁸ of the channel's unit).
const FRACTION_BITS: i32 = 28;
/// 2²⁸.
const QUANTA_PER_UNIT: f64 = 268_435_456.0;
/// Inputs are clipped to ±2²⁰ units so that N²·2²⁸·|x| (≤ 2⁶²) fits in `i64`; anything that large
/// (10⁶ °/s, g, gauss or mbar) saturates every output field anyway.
const INPUT_LIMIT: f64 = 1_048_576.0;

/// Room for the largest window, 2^MAX_M taps: fixed arrays indexed with a mask need no bounds
/// checks on the per-sample path.
const MAX_TAPS: usize = 1 << MAX_M;

/// The Bartlett filters of `C` channels. They share the window (SENS_AVG sets one M for every
/// channel), so one position serves all and a sample updates the channels in one pass.
#[derive(Debug, Clone)]
pub struct Bartlett<const C: usize = 1> {
    m: u8,
    /// N − 1 (N = 2^M taps per stage).
    mask: usize,
    /// Last N inputs (quantised), in slots 0…N−1.
    stage1: [[i64; C]; MAX_TAPS],
    /// Last N first-stage sums, in slots 0…N−1.
    stage2: [[i64; C]; MAX_TAPS],
    pos: usize,
    sum1: [i64; C],
    sum2: [i64; C],
    primed: bool,
    /// 1/(N²·2²⁸), exact.
    out_scale: f64,
}

impl<const C: usize> Bartlett<C> {
    /// Filters with N = 2^m taps per stage, empty (the first input primes them).
    pub fn new(m: u8) -> Result<Self> {
        check_m(m)?;
        let n = 1usize << m;
        let out_scale = f64::powi(2.0, -FRACTION_BITS - 2 * i32::from(m));
        Ok(Bartlett {
            m,
            mask: n - 1,
            stage1: [[0; C]; MAX_TAPS],
            stage2: [[0; C]; MAX_TAPS],
            pos: 0,
            sum1: [0; C],
            sum2: [0; C],
            primed: false,
            out_scale,
        })
    }

    /// M (taps per stage = 2^M).
    pub fn m(&self) -> u8 {
        self.m
    }

    /// Taps per stage, N.
    pub fn taps(&self) -> usize {
        self.mask + 1
    }

    /// Change M. The history is dropped: the next input primes the filter as if it had been constant
    /// for ever (the data sheet does not say how the part refills its window).
    pub fn set_m(&mut self, m: u8) -> Result<()> {
        check_m(m)?;
        if m != self.m {
            *self = Bartlett::new(m)?;
        }
        Ok(())
    }

    /// Forget the history: the next input primes the filter.
    pub fn reset(&mut self) {
        self.primed = false;
    }

    /// Whether the filter holds a history.
    pub fn is_primed(&self) -> bool {
        self.primed
    }

    /// Feed one sample per channel and return the filter outputs at that sample. A first sample
    /// fills the whole window with its value (the part has been sampling since power-on before
    /// anyone reads it).
    pub fn push(&mut self, x: [f64; C]) -> [f64; C] {
        // A loop, not `x.map(quantize)`: the compiler may keep an array map out of line.
        let mut q = [0; C];
        for (q, x) in q.iter_mut().zip(x) {
            *q = quantize(x);
        }
        let n = self.taps();
        if !self.primed {
            self.sum1 = q.map(|q| q * n as i64);
            self.sum2 = self.sum1.map(|s| s * n as i64);
            self.stage1[..n].fill(q);
            self.stage2[..n].fill(self.sum1);
            self.pos = 0;
            self.primed = true;
        } else {
            let pos = self.pos & (MAX_TAPS - 1);
            for (c, &q) in q.iter().enumerate() {
                self.sum1[c] += q - self.stage1[pos][c];
                self.sum2[c] += self.sum1[c] - self.stage2[pos][c];
            }
            self.stage1[pos] = q;
            self.stage2[pos] = self.sum1;
            self.pos = (pos + 1) & self.mask;
        }
        // sum2 / (N² · 2²⁸): the i64 → f64 conversion is the only rounding (none for sums below 2⁵³,
        // which include every constant input); the scaling is exact.
        self.sum2.map(|s| s as f64 * self.out_scale)
    }
}

impl Bartlett {
    /// Analytic magnitude response |H| at frequency `f_hz` for sample rate `fs_hz`.
    pub fn magnitude(m: u8, f_hz: f64, fs_hz: f64) -> f64 {
        let n = f64::from(1u32 << m);
        let x = std::f64::consts::PI * f_hz / fs_hz;
        if x.sin() == 0.0 {
            return 1.0;
        }
        let h = (n * x).sin() / (n * x.sin());
        h * h
    }

    /// Group delay in samples (the triangle's centre): N − 1.
    pub fn delay_samples(m: u8) -> f64 {
        f64::from(1u32 << m) - 1.0
    }
}

/// The input quantised to 2⁻²⁸ of its unit (round to nearest), clipped to ±2²⁰ units.
pub fn quantize(x: f64) -> i64 {
    round_half_away(x.clamp(-INPUT_LIMIT, INPUT_LIMIT) * QUANTA_PER_UNIT)
}

/// The value of a quantised input.
pub fn dequantize(q: i64) -> f64 {
    q as f64 / QUANTA_PER_UNIT
}

fn check_m(m: u8) -> Result<()> {
    if m > MAX_M {
        return Err(Error::Register(format!("SENS_AVG[2:0] = {m}: expected M in 0…{MAX_M}")));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn a_bank_filters_each_channel_as_a_filter_of_its_own() {
        let mut bank = Bartlett::<3>::new(3).unwrap();
        let mut single: [Bartlett; 3] = std::array::from_fn(|_| Bartlett::new(3).unwrap());
        for k in 0..500 {
            let x = [(k as f64 * 0.37).sin() * 50.0, k as f64 * 1e-3, -((k * k) % 97) as f64];
            let y = bank.push(x);
            for c in 0..3 {
                assert_eq!(y[c].to_bits(), single[c].push([x[c]])[0].to_bits(), "sample {k}, channel {c}");
            }
        }
    }

    #[test]
    fn dc_gain_is_exactly_one() {
        for m in 0..=MAX_M {
            for x in [0.0, 1.0, -123.456_789, 299.987_654_321, 1e-3, -4.2e5, 18.000_000_000_000_004, 0.75] {
                let mut f = Bartlett::new(m).unwrap();
                let xq = dequantize(quantize(x));
                assert!((xq - x).abs() <= f64::powi(2.0, -29), "quantisation within half a quantum");
                f.push([x]);
                for _ in 0..600 {
                    assert_eq!(f.push([x])[0], xq, "M = {m}, x = {x}");
                }
            }
        }
    }

    #[test]
    fn impulse_response_is_the_triangle() {
        // h[k] = (N − |k − (N−1)|) / N² for k = 0 … 2N−2: a triangle of area 1.
        for m in 0..=4u8 {
            let n = 1usize << m;
            let mut f = Bartlett::new(m).unwrap();
            f.push([0.0]);
            let out: Vec<f64> = (0..3 * n).map(|k| f.push([if k == 0 { 1.0 } else { 0.0 }])[0]).collect();
            for (k, y) in out.iter().enumerate() {
                let tri = (n as f64 - (k as f64 - (n as f64 - 1.0)).abs()).max(0.0) / (n * n) as f64;
                assert_eq!(*y, tri, "M = {m}, k = {k}");
            }
        }
    }

    /// Least-squares fit of y = a sin ωk + b cos ωk + c; returns √(a² + b²).
    fn fitted_amplitude(y: &[f64], omega: f64, k0: usize) -> f64 {
        let mut ata = [[0.0f64; 3]; 3];
        let mut aty = [0.0f64; 3];
        for (i, &v) in y.iter().enumerate() {
            let k = (k0 + i) as f64;
            let row = [(omega * k).sin(), (omega * k).cos(), 1.0];
            for r in 0..3 {
                aty[r] += row[r] * v;
                for c in 0..3 {
                    ata[r][c] += row[r] * row[c];
                }
            }
        }
        // Gaussian elimination on the 3×3 normal equations (well conditioned over many periods).
        for p in 0..3 {
            let pivot = ata[p];
            for r in p + 1..3 {
                let f = ata[r][p] / pivot[p];
                for (x, y) in ata[r].iter_mut().zip(pivot).skip(p) {
                    *x -= f * y;
                }
                aty[r] -= f * aty[p];
            }
        }
        let mut x = [0.0f64; 3];
        for r in (0..3).rev() {
            let s: f64 = (r + 1..3).map(|c| ata[r][c] * x[c]).sum();
            x[r] = (aty[r] - s) / ata[r][r];
        }
        x[0].hypot(x[1])
    }

    #[test]
    fn amplitude_response_matches_theory() {
        let fs = 819.2;
        for m in [2u8, 4] {
            let n = 1usize << m;
            // Three frequencies inside the main lobe and side lobes of the N = 4 and N = 16 filters.
            for f in [13.7, 61.0, 150.3] {
                let mut filt = Bartlett::new(m).unwrap();
                let amp = 10.0;
                let omega = 2.0 * PI * f / fs;
                let y: Vec<f64> = (0..20_000).map(|k| filt.push([amp * (omega * k as f64 + 0.3).sin()])[0]).collect();
                // Skip the priming transient (2N − 2 samples) and fit the steady state.
                let skip = 2 * n;
                let measured = fitted_amplitude(&y[skip..], omega, skip) / amp;
                let theory = Bartlett::magnitude(m, f, fs);
                assert!((measured - theory).abs() < 1e-6, "M = {m}, f = {f}: {measured} vs {theory}");
            }
        }
    }

    #[test]
    fn running_sums_do_not_drift() {
        let mut f = Bartlett::new(3).unwrap();
        let mut direct = std::collections::VecDeque::new();
        let mut x = 0.37_f64;
        f.push([0.0]);
        for _ in 0..15 {
            direct.push_back(0.0);
        }
        for _ in 0..200_000 {
            x = (x * 3.9 * (1.0 - x)).clamp(1e-9, 1.0 - 1e-9); // chaotic, non-dyadic input
            let y = f.push([x * 100.0])[0];
            // The reference sums the same quantised inputs in floating point.
            direct.push_back(dequantize(quantize(x * 100.0)));
            if direct.len() > 15 {
                direct.pop_front();
            }
            // Direct triangle-weighted sum over the last 2N − 1 = 15 inputs, newest last.
            let d: f64 = direct.iter().enumerate().map(|(i, v)| v * (8.0 - (i as f64 - 7.0).abs()) / 64.0).sum();
            assert!((y - d).abs() < 1e-12, "{y} vs {d}");
        }
    }

    #[test]
    fn m_above_seven_is_rejected() {
        assert!(Bartlett::<1>::new(8).is_err());
        let mut f = Bartlett::<1>::new(2).unwrap();
        assert!(f.set_m(9).is_err());
        f.set_m(5).unwrap();
        assert_eq!((f.m(), f.taps()), (5, 32));
    }
}
