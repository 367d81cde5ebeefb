//! Sensor error model: what turns the true physical quantities at one internal sample into what the
//! sensing elements report, before the device's Bartlett filter and register encoding. Quantisation
//! and saturation are not here: the register encoding does them.
//!
//! # Model
//! Per inertial triad (gyro in °/s, accelerometer in g, as in [`Physical`]), with x the true input,
//! a the true specific force (g) and ΔT = `temp_c` − 25 °C:
//!
//! ```text
//! y     = M x                                  M = I + small misalignment angles (rad)
//! y_i  ← y_i (1 + s_i + s_T,i ΔT) + q_i y_i²   scale factor, its tempco; q_i = nonlinearity_i / FS
//! out_i = y_i + b_i + c_i ΔT + (G a)_i + Σ_k g_k,i + r_i + w_i
//! ```
//!
//! b is the unit's constant (initial) bias, c the bias tempco, G the g-sensitivity (gyro), g_k the
//! first-order Gauss–Markov terms of bias instability, r the rate random walk, w white noise.
//! Magnetometer: out = (I + S) m + h + w (soft iron S, hard iron h). Barometer: out = p + w.
//!
//! # Noise conventions
//! - White noise is given by its random-walk coefficient N (the Allan, two-sided convention): the
//!   Allan deviation is N/√τ and the per-sample σ is N·√fs (integrating it gives a random walk of
//!   variance N²·t). ARW in °/√h = 60 · N[°/s/√Hz] (1 h = 3600 s, √3600 = 60); VRW in m/s/√h =
//!   60 · 9.80665 · N[g/√Hz]. A data-sheet "noise density" D (√ of the one-sided PSD) is N = D/√2:
//!   read so, the 16407's 0.5 mg/√Hz gives 0.208 m/s/√h, the sibling's 0.2 m/s/√h within 4 %, and
//!   D·√(330 Hz bandwidth) = 9.1 mg, the 16407's 9 mg rms. The model's noise is white to Nyquist, so
//!   its per-sample σ at 819.2 SPS (10.1 mg) exceeds that band-limited rms by 12 %.
//! - Gauss–Markov terms are discretised exactly: x_{k+1} = e^{−Δt/τ} x_k + σ √(1 − e^{−2Δt/τ}) w_k,
//!   started from the stationary distribution N(0, σ²), so the process is stationary from sample 0
//!   (slow terms step over several samples at once: multi-rate bank below).
//! - Bias instability is by default a bank of such terms with log-spaced τ and equal variances,
//!   which approximates flicker noise: its Allan deviation has the flat floor a data sheet's
//!   "in-run bias stability" describes (a single Gauss–Markov term only has a bump at 1.89 τ, and
//!   the curve falls again after it). See [`flicker_bank`].
//!
//! # Multi-rate bias-instability bank
//! A term of correlation time τ hardly moves in one sample (Δt = 1.22 ms against τ ≥ 1 s in the
//! preset), so it is redrawn only every m samples, m the largest power of two with m·Δt ≤ τ/R
//! ([`gauss_markov_update_interval`]; at least 1; R = [`ErrorParams::gauss_markov_update_ratio`],
//! default 100, profile key `errors.gauss_markov_update_ratio`), with the exact discretisation over
//! T = m·Δt (decay e^{−T/τ}, drive σ√(1 − e^{−2T/τ})), and held in between. Updates fall on absolute
//! sample indices k ≡ 0 (mod m): the value at sample k is the value of the update instant ⌊k/m⌋·m, so
//! it depends only on which update instants have passed; a jump of k over n of them propagates the
//! term exactly over n·T (one draw per axis). On the update instants the term is exactly the
//! stationary N(0, σ²) Gauss–Markov process sampled every T. A term with τ < 2·R·Δt keeps m = 1: the
//! per-sample process.
//!
//! What the hold changes (ε = T/τ ≤ 1/R; derivations for one term, the terms are independent):
//! - Pointwise, s after an update the held value differs from the exact process by an error of
//!   variance 2σ²(1 − e^{−s/τ}) ≤ 2σ²ε, on average over the interval ≈ σ²ε.
//! - Second-order statistics with the hold's phase uniform (what an overlapping Allan deviation
//!   over a record ≫ T sees): the structure function D(s) = E[(y(t+s) − y(t))²] of the held
//!   process is 2σ²·E[1 − e^{−N·ε}], N the number of updates in (t, t+s], ⌊s/T⌋ or ⌈s/T⌉ with mean
//!   s/T: the chord of the exact, concave 2σ²(1 − e^{−s/τ}) between multiples of T, below it by at
//!   most 2σ²·ε²/8. The Allan variance is a combination of D(s) values whose weights' magnitudes sum
//!   to 1, so it moves by at most σ²ε²/4 at every averaging time; likewise the PSD is the term's to
//!   relative O(ε²), but for notches ≈ 1/(2πτ) wide at multiples of 1/T. (For a random walk,
//!   τ → ∞, a random-phase sample-and-hold has exactly the walk's D(s).)
//! - Clusters locked to the hold grid (non-overlapping, starting at an update, length τ_A a
//!   multiple of T) see the walk sampled every T: the Allan variance gains 2σ²T²/(6ττ_A), at most
//!   σ²ε/3 at τ_A = T; below T a locked cluster pair may see no update and lose the term's
//!   2σ²τ_A/(3τ) (as large).
//!
//! Numbers for `adis16407` (R = 100, Δt = 1/819.2 s): m = 8, 64, 512, 8192, 65536, 524288 for
//! τ = 1 … 1e5 s (T = 9.8 ms … 640 s, ε = 0.0064 … 0.0100), so the bank costs 0.43 Gaussian draws
//! per sample and triad instead of 18. Gyro terms have σ = 0.0090 °/s: the hold error is ≤ 1.3e-3
//! °/s rms (mean variance ≤ 8e-7 (°/s)²), against white noise of 0.95 °/s per sample (0.91 (°/s)²,
//! 1e6 times more). The overlapping Allan variance moves by ≤ Σ σ²ε²/4 = 8.1e-9 (°/s)², 1.7e-4 of
//! the floor's 4.9e-5 (Allan deviation: < 1e-4 relative). Locked clusters: ≤ σ²ε/3 = 2.7e-7 (°/s)²
//! per term, ≤ 0.35 % of the Allan variance at its τ_A = T (0.17 % in deviation, at 80 s and 640 s
//! where the floor dominates; ≤ 0.17 % at 10 s and far less below, where white noise dominates).
//! The accelerometer's bank has the same shape, so the same relative numbers.
//!
//! # Presets
//! `ideal` (no error) and `adis16407` ([`ErrorParams::adis16407`]; per value source and flag in
//! [`preset_table`]). Interpretations: a "±x" unit-to-unit figure (initial bias, tempco) is 1σ
//! normal, as ADI's tables mean it; "in-run bias stability" is the Allan minimum (ADI's usage), so
//! the flicker floor equals it and IEEE B = floor / 0.6643; g-sensitivity is a full 3×3 matrix, each
//! element 1σ = the figure; misalignment is uniform per off-diagonal element with half the
//! axis-to-axis bound, so every axis pair stays within it; nonlinearity is a quadratic whose
//! deviation at full scale is uniform within ± the figure. Unpublished terms (scale factor, RRW,
//! accel nonlinearity, iron) are 0 and flagged.
//!
//! # Random streams
//! Every source has its own xoshiro256++ stream, so enabling, disabling or resizing one source
//! never changes another's realisation. Stream id = `sensor << 16 | source << 8 | index`, with
//! sensor 0 gyro, 1 accel, 2 magnetometer, 3 barometer; source 1 initial bias, 2 bias tempco,
//! 3 scale factor, 4 scale tempco, 5 nonlinearity, 6 misalignment, 7 g-sensitivity, 8 white noise,
//! 9 bias instability, 10 rate random walk; index the Gauss–Markov term's place in the bank
//! (source 9: every term has its own stream, numbered before zero terms are dropped), else 0. The
//! generator's state is `Xoshiro256PlusPlus::seed_from_u64(splitmix64(splitmix64(seed) ^ id))`
//! (rand_xoshiro 0.6, which fills the 256-bit state with SplitMix64 outputs), splitmix64 the
//! SplitMix64 output function: a bijection, so distinct ids of one seed never share a key, and an
//! avalanching mix, so neighbouring seeds and ids give unrelated streams. Draw order within a
//! stream: axes x, y, z; matrices row-major (misalignment: the six off-diagonal elements only);
//! a Gauss–Markov term: x, y, z of its initial state, then x, y, z at each update.
//!
//! # Time
//! The model advances by whole internal samples (`k`), with the period given at construction, so no
//! float time is accumulated. A jump of k by more than one propagates the random walk exactly over
//! the gap and each Gauss–Markov term exactly over the update instants in it; white noise is one
//! draw per call.
//!
//! # Files
//! `params.rs` the parameters, presets as values and their checks; `presets.rs` the presets as
//! rows with their sources; `streams.rs` the random streams; `model.rs` the running model
//! ([`ErrorModel`]); `ziggurat.rs` the Gaussian draws; `tests.rs` the tests.

use std::f64::consts::{LN_2, PI};

use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use serde::{Deserialize, Serialize};

use super::Physical;
use crate::error::{Error, Result};
use crate::profile::{check_update_ratio, Errors};
use crate::time::Ps;
use ziggurat::{standard_normal, Gaussian};

mod model;
mod params;
mod presets;
mod streams;
mod ziggurat;

pub use model::*;
pub use params::*;
pub use presets::*;
use streams::*;

/// Temperature at which temperature effects are zero, °C (TEMP_OUT reads 0 there).
pub const REFERENCE_TEMP_C: f64 = 25.0;
/// Standard gravity, m/s² per g (VRW conversions).
pub const STANDARD_GRAVITY: f64 = 9.80665;
/// Peak of the Allan deviation of a first-order Gauss–Markov process, as a fraction of its σ.
pub const GAUSS_MARKOV_ALLAN_PEAK: f64 = 0.617_364_283_144_441_4;
/// Averaging time of that peak, in correlation times τ.
pub const GAUSS_MARKOV_ALLAN_PEAK_AT: f64 = 1.892_617_851_020_620_6;
/// Preset names accepted by [`ErrorParams::preset`] (the profile checks `errors.preset` against them).
pub use crate::profile::{DEFAULT_GAUSS_MARKOV_UPDATE_RATIO, PRESET_NAMES};
/// Most Gauss–Markov terms per triad (each costs one Gaussian draw per axis and update).
pub const MAX_GAUSS_MARKOV_TERMS: usize = 32;
