//! Standard normal draws, the same values as `rand_distr::StandardNormal` but with its common case
//! inlined into the caller.
//!
//! Why: the error model draws about eleven Gaussians per device sample. `rand_distr`'s sampler is one
//! function holding both the ziggurat's fast path and its rare rejection paths (with `exp`, `ln`),
//! so it is never inlined: every draw pays a call that saves six registers and reloads and stores the
//! generator's state, about as much as the draw itself. Here the fast path (one `next_u64`, one table
//! look-up, one comparison; taken by 98.5 % of draws) is inlined, and every other draw goes to
//! `rand_distr` itself from the generator's state before the draw, so it repeats the same first step
//! and takes the same rejection path: values and stream positions are those of
//! `rng.sample(StandardNormal)`, bit for bit (tested against it below).

use std::sync::LazyLock;

use rand::{Rng, RngCore};
use rand_distr::StandardNormal;

/// One draw of N(0, 1) from `rng`: exactly `rng.sample::<f64, _>(StandardNormal)` (for set-up; the
/// per-sample paths hold a [`Gaussian`]).
pub(super) fn standard_normal<R: RngCore + Clone>(rng: &mut R) -> f64 {
    Gaussian::new().draw(rng)
}

/// The sampler of N(0, 1) with the layer table at hand: a model keeps one, so its per-sample draws
/// skip the once-only initialisation check of the table (≈ 5 instructions a draw, measured).
#[derive(Debug, Clone, Copy)]
pub(super) struct Gaussian(&'static [f64; 257]);

impl Gaussian {
    /// The sampler (computes the table on first use in the process).
    pub(super) fn new() -> Gaussian {
        Gaussian(&ZIG_NORM_X)
    }

    /// One draw of N(0, 1) from `rng`: exactly `rng.sample::<f64, _>(StandardNormal)`.
    #[inline(always)]
    pub(super) fn draw<R: RngCore + Clone>(self, rng: &mut R) -> f64 {
        let mut ahead = rng.clone();
        match self.first_step(&mut ahead) {
            Some(x) => {
                *rng = ahead;
                x
            }
            None => rejected_first_step(rng),
        }
    }

    /// Three draws: exactly `[self.draw(rng), self.draw(rng), self.draw(rng)]`, but when all three
    /// take the fast path (95 % of triples) the generator's state is stored once, not three times.
    #[inline(always)]
    pub(super) fn draw3<R: RngCore + Clone>(self, rng: &mut R) -> [f64; 3] {
        let mut ahead = rng.clone();
        let mut out = [0.0; 3];
        for x in &mut out {
            match self.first_step(&mut ahead) {
                Some(v) => *x = v,
                None => return three_draws(self, rng),
            }
        }
        *rng = ahead;
        out
    }

    /// rand_distr 0.4's ziggurat (`utils::ziggurat`, symmetric case), first step: the low 8 bits of
    /// one `next_u64` pick the layer, the high 52 make u uniform on [−1, 1); x = u·X[i] is accepted
    /// if |x| < X[i + 1]. `None`: rejected, `rng` has moved on by one word.
    #[inline(always)]
    fn first_step<R: RngCore>(self, rng: &mut R) -> Option<f64> {
        let edges = self.0;
        let bits = rng.next_u64();
        let layer = (bits & 0xff) as usize;
        let u = f64::from_bits(bits >> 12 | EXPONENT_OF_2) - 3.0;
        let x = u * edges[layer];
        (x.abs() < edges[layer + 1]).then_some(x)
    }
}

/// The ziggurat's tail and wedge cases (1.5 % of draws): `rand_distr` from the state before the draw.
#[cold]
#[inline(never)]
fn rejected_first_step<R: RngCore>(rng: &mut R) -> f64 {
    rng.sample(StandardNormal)
}

/// [`Gaussian::draw3`] when one of the three leaves the fast path: the three draws one by one from
/// the state before them.
#[cold]
#[inline(never)]
fn three_draws<R: RngCore + Clone>(gaussian: Gaussian, rng: &mut R) -> [f64; 3] {
    [gaussian.draw(rng), gaussian.draw(rng), gaussian.draw(rng)]
}

/// Exponent bits of 2.0: with 52 random mantissa bits, a float uniform on [2, 4).
const EXPONENT_OF_2: u64 = 0x4000_0000_0000_0000;

/// The layer edges X₀ … X₂₅₆ of the 256-layer ziggurat for N(0, 1) (Marsaglia & Tsang, "The
/// ziggurat method for generating random variables", 2000), computed once from the method's two
/// constants: the tail's start R and the area V of every layer. With f(x) = e^(−x²/2):
/// X₁ = R, X₀ = V/f(R) (the base layer, tail included, as a rectangle of area V),
/// X_{i+1} = √(−2 ln(V/X_i + f(X_i))) (each layer of area V), X₂₅₆ = 0.
/// In f64 with this machine's libm these are the doubles `rand_distr` 0.4 tabulates: the test below
/// holds 4 × 10⁶ draws equal to its sampler, which a differing edge would break in its layer.
static ZIG_NORM_X: LazyLock<[f64; 257]> = LazyLock::new(|| {
    const R: f64 = 3.654_152_885_361_009;
    const V: f64 = 0.004_928_673_233_99;
    let f = |x: f64| (-x * x / 2.0).exp();
    let mut x = [0.0; 257];
    x[0] = V / f(R);
    x[1] = R;
    for i in 1..255 {
        x[i + 1] = (-2.0 * (V / x[i] + f(x[i])).ln()).sqrt();
    }
    x
});

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_xoshiro::Xoshiro256PlusPlus;

    #[test]
    fn draws_are_rand_distr_standard_normal_bit_for_bit() {
        // 4 × 10⁶ draws reach every layer ≈ 15 000 times, the wedges (1.5 % of draws) ≈ 60 000 times
        // and layer 0's tail (0.03 %) ≈ 1 000 times; the generators must also stay in step.
        let mut rejected = 0u64;
        for seed in 0..4 {
            let mut ours = Xoshiro256PlusPlus::seed_from_u64(seed);
            let mut theirs = ours.clone();
            for n in 0..1_000_000 {
                let before = ours.clone();
                let want: f64 = theirs.sample(StandardNormal);
                let got = standard_normal(&mut ours);
                assert_eq!(got.to_bits(), want.to_bits(), "seed {seed}, draw {n}");
                assert_eq!(ours, theirs, "seed {seed}, draw {n}: stream positions differ");
                let mut one_step = before;
                one_step.next_u64();
                rejected += u64::from(ours != one_step);
            }
        }
        assert!(rejected > 10_000, "only {rejected} draws left the fast path: the test covers too little");
    }

    #[test]
    fn a_triple_is_three_draws_bit_for_bit() {
        // 10⁶ triples: ≈ 4.5 % of them (45 000) leave the fast path somewhere and take the fallback.
        let gaussian = Gaussian::new();
        for seed in 0..4 {
            let mut triples = Xoshiro256PlusPlus::seed_from_u64(seed);
            let mut singles = triples.clone();
            for n in 0..250_000 {
                let got = gaussian.draw3(&mut triples);
                let want = [gaussian.draw(&mut singles), gaussian.draw(&mut singles), gaussian.draw(&mut singles)];
                assert_eq!(got.map(f64::to_bits), want.map(f64::to_bits), "seed {seed}, triple {n}");
                assert_eq!(triples, singles, "seed {seed}, triple {n}: stream positions differ");
            }
        }
    }
}
