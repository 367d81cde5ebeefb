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

use std::f64::consts::{LN_2, PI};

use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use serde::{Deserialize, Serialize};

use super::Physical;
use crate::error::{Error, Result};
use crate::profile::{check_update_ratio, Errors};
use crate::time::Ps;
use ziggurat::{standard_normal, Gaussian};

mod ziggurat;

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

/// Allan-deviation floor of flicker noise per unit of IEEE-952 bias instability B: √(2 ln 2 / π) ≈ 0.6643.
pub fn flicker_floor_factor() -> f64 {
    (2.0 * LN_2 / PI).sqrt()
}

/// Theoretical Allan variance at averaging time `t_s` of a first-order Gauss–Markov process of
/// stationary standard deviation `sigma` and correlation time `tau_s`:
/// σ_A² = (2σ²/x)·[1 − (3 − 4e^{−x} + e^{−2x})/(2x)], x = t/τ.
pub fn gauss_markov_avar(sigma: f64, tau_s: f64, t_s: f64) -> f64 {
    let x = t_s / tau_s;
    // The closed form cancels catastrophically for small x; there its Taylor series (coefficients
    // −(−1)ⁿ(2ⁿ − 4)/n! of x^{n−2}) is used, truncated after x⁵ (next term x⁶/160: < 1e-12 relative).
    let shape = if x < 1e-2 {
        x * (2.0 / 3.0 + x * (-1.0 / 2.0 + x * (7.0 / 30.0 + x * (-1.0 / 12.0 + x * 31.0 / 1260.0))))
    } else {
        let bracket = -4.0 * (-x).exp_m1() + (-2.0 * x).exp_m1();
        (2.0 / x) * (1.0 - bracket / (2.0 * x))
    };
    sigma * sigma * shape
}

/// Shape of a unit-to-unit distribution.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Distribution {
    /// Gaussian; [`Spread::width`] is 1σ.
    Normal,
    /// Uniform; [`Spread::width`] is the half-width.
    Uniform,
}

/// A constant of one unit (one sensor part), drawn once per seed: `mean + width·u` with
/// u ~ N(0, 1) or U(−1, 1). A zero width gives the fixed value `mean`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Spread {
    /// Centre of the distribution (the value every unit shares).
    pub mean: f64,
    /// 1σ (normal) or half-width (uniform).
    pub width: f64,
    /// Shape of the distribution.
    pub distribution: Distribution,
}

impl Spread {
    /// No error.
    pub const ZERO: Spread = Spread::fixed(0.0);

    /// The same value for every unit.
    pub const fn fixed(value: f64) -> Self {
        Spread { mean: value, width: 0.0, distribution: Distribution::Normal }
    }

    /// Zero-mean Gaussian of standard deviation `sigma`.
    pub const fn normal(sigma: f64) -> Self {
        Spread { mean: 0.0, width: sigma, distribution: Distribution::Normal }
    }

    /// Zero-mean uniform on ±`half_width`.
    pub const fn uniform(half_width: f64) -> Self {
        Spread { mean: 0.0, width: half_width, distribution: Distribution::Uniform }
    }

    fn is_zero(&self) -> bool {
        self.mean == 0.0 && self.width == 0.0
    }

    fn draw(&self, rng: &mut StreamRng) -> f64 {
        let u: f64 = match self.distribution {
            Distribution::Normal => standard_normal(rng),
            Distribution::Uniform => rng.gen_range(-1.0..1.0),
        };
        self.mean + self.width * u
    }

    fn validate(&self, key: &str) -> Result<()> {
        check_finite(&format!("{key}.mean"), self.mean)?;
        check_nonneg(&format!("{key}.width"), self.width)
    }
}

/// One first-order Gauss–Markov process (per axis).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GaussMarkov {
    /// Stationary standard deviation, output units.
    pub sigma: f64,
    /// Correlation time, s.
    pub tau_s: f64,
}

/// The single Gauss–Markov process whose Allan-deviation peak (at 1.89 τ) equals `allan_peak`:
/// σ = `allan_peak` / 0.6174.
pub fn gauss_markov_for_allan_peak(allan_peak: f64, tau_s: f64) -> GaussMarkov {
    GaussMarkov { sigma: allan_peak / GAUSS_MARKOV_ALLAN_PEAK, tau_s }
}

/// A bank of Gauss–Markov terms approximating flicker noise whose Allan-deviation floor is
/// `allan_floor`. The n + 1 correlation times are log-spaced from `tau_min_s` to `tau_max_s` with
/// n = round(decades · `terms_per_decade`), ratio r = (τ_max/τ_min)^{1/n}; every term has the
/// variance σ² = B² ln r / π, B = floor / 0.6643, because Σ_k 2σ²τ_k/(1 + (2πfτ_k)²) integrated
/// over ln τ is B²/(2πf), the two-sided flicker PSD of bias instability B. At one term per decade
/// the Allan deviation stays within ±1.5 % of the floor for 20 τ_min ≤ T ≤ τ_max / 5 (tested).
pub fn flicker_bank(allan_floor: f64, tau_min_s: f64, tau_max_s: f64, terms_per_decade: u32) -> Vec<GaussMarkov> {
    let intervals = flicker_intervals(tau_min_s, tau_max_s, terms_per_decade);
    let ratio = (tau_max_s / tau_min_s).powf(1.0 / intervals as f64);
    let b = allan_floor / flicker_floor_factor();
    let sigma = b * (ratio.ln() / PI).sqrt();
    (0..=intervals).map(|k| GaussMarkov { sigma, tau_s: tau_min_s * ratio.powi(k as i32) }).collect()
}

fn flicker_intervals(tau_min_s: f64, tau_max_s: f64, terms_per_decade: u32) -> usize {
    ((tau_max_s / tau_min_s).log10() * terms_per_decade as f64).round().max(1.0) as usize
}

/// How bias instability is described.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum BiasInstability {
    /// No bias instability.
    None,
    /// Flicker noise of the given Allan-deviation floor, realised by [`flicker_bank`].
    Flicker {
        /// Flat bottom of the Allan deviation, output units (= 0.6643 × IEEE-952 B).
        allan_floor: f64,
        /// Shortest correlation time of the bank, s.
        tau_min_s: f64,
        /// Longest correlation time of the bank, s.
        tau_max_s: f64,
        /// Terms per decade of τ (1 gives ±1.5 % ripple).
        terms_per_decade: u32,
    },
    /// Explicit Gauss–Markov terms (one term: the classic first-order model).
    GaussMarkov {
        /// The terms, summed.
        terms: Vec<GaussMarkov>,
    },
}

impl BiasInstability {
    /// The Gauss–Markov terms this description expands to.
    pub fn terms(&self) -> Vec<GaussMarkov> {
        match self {
            BiasInstability::None => Vec::new(),
            BiasInstability::Flicker { allan_floor, tau_min_s, tau_max_s, terms_per_decade } => {
                flicker_bank(*allan_floor, *tau_min_s, *tau_max_s, *terms_per_decade)
            }
            BiasInstability::GaussMarkov { terms } => terms.clone(),
        }
    }

    fn validate(&self, key: &str) -> Result<()> {
        match self {
            BiasInstability::None => Ok(()),
            BiasInstability::Flicker { allan_floor, tau_min_s, tau_max_s, terms_per_decade } => {
                check_nonneg(&format!("{key}.allan_floor"), *allan_floor)?;
                check_pos(&format!("{key}.tau_min_s"), *tau_min_s)?;
                check_pos(&format!("{key}.tau_max_s"), *tau_max_s)?;
                if tau_max_s <= tau_min_s {
                    return Err(bad(&format!("{key}.tau_max_s"), tau_max_s, "a value > tau_min_s"));
                }
                if *terms_per_decade == 0 {
                    return Err(bad(&format!("{key}.terms_per_decade"), terms_per_decade, "an integer ≥ 1"));
                }
                let count = flicker_intervals(*tau_min_s, *tau_max_s, *terms_per_decade) + 1;
                if count > MAX_GAUSS_MARKOV_TERMS {
                    return Err(bad(
                        &format!("{key}.terms_per_decade"),
                        terms_per_decade,
                        &format!("at most {MAX_GAUSS_MARKOV_TERMS} terms in all (this range gives {count})"),
                    ));
                }
                Ok(())
            }
            BiasInstability::GaussMarkov { terms } => {
                if terms.len() > MAX_GAUSS_MARKOV_TERMS {
                    return Err(bad(
                        &format!("{key}.terms"),
                        terms.len(),
                        &format!("at most {MAX_GAUSS_MARKOV_TERMS} terms"),
                    ));
                }
                for (i, term) in terms.iter().enumerate() {
                    check_nonneg(&format!("{key}.terms[{i}].sigma"), term.sigma)?;
                    check_pos(&format!("{key}.terms[{i}].tau_s"), term.tau_s)?;
                }
                Ok(())
            }
        }
    }
}

/// Error parameters of one inertial triad (gyro: output units °/s; accelerometer: g).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InertialErrors {
    /// Full scale the nonlinearity is referred to, output units (the selected range).
    pub full_scale: f64,
    /// Constant bias of the unit (initial bias), output units.
    pub initial_bias: Spread,
    /// Bias temperature coefficient, output units per °C.
    pub bias_tempco: Spread,
    /// Scale-factor error, fraction (1e-6 = 1 ppm).
    pub scale_factor: Spread,
    /// Scale-factor temperature coefficient, fraction per °C.
    pub scale_tempco: Spread,
    /// Quadratic nonlinearity: deviation at full scale as a fraction of full scale.
    pub nonlinearity: Spread,
    /// Each off-diagonal element of the misalignment matrix, degrees. The angle between two sensing
    /// axes differs from 90° by the sum of the two elements of that pair.
    pub misalignment_deg: Spread,
    /// Each element of the g-sensitivity matrix, output units per g (row: output, column: force).
    pub g_sensitivity: Spread,
    /// White-noise random-walk coefficient N, output units/√Hz (module docs: conventions).
    pub noise_density: f64,
    /// Bias instability.
    pub bias_instability: BiasInstability,
    /// Rate random walk K, output units/√s (the bias wanders by K·√Δt per step; σ_A = K·√(τ/3)).
    pub rate_random_walk: f64,
}

impl InertialErrors {
    /// An error-free triad of the given full scale.
    pub fn ideal(full_scale: f64) -> Self {
        InertialErrors {
            full_scale,
            initial_bias: Spread::ZERO,
            bias_tempco: Spread::ZERO,
            scale_factor: Spread::ZERO,
            scale_tempco: Spread::ZERO,
            nonlinearity: Spread::ZERO,
            misalignment_deg: Spread::ZERO,
            g_sensitivity: Spread::ZERO,
            noise_density: 0.0,
            bias_instability: BiasInstability::None,
            rate_random_walk: 0.0,
        }
    }

    fn is_ideal(&self) -> bool {
        [
            self.initial_bias,
            self.bias_tempco,
            self.scale_factor,
            self.scale_tempco,
            self.nonlinearity,
            self.misalignment_deg,
            self.g_sensitivity,
        ]
        .iter()
        .all(Spread::is_zero)
            && self.noise_density == 0.0
            && self.rate_random_walk == 0.0
            && self.bias_instability.terms().iter().all(|t| t.sigma == 0.0)
    }

    fn validate(&self, key: &str) -> Result<()> {
        check_pos(&format!("{key}.full_scale"), self.full_scale)?;
        for (name, spread) in [
            ("initial_bias", &self.initial_bias),
            ("bias_tempco", &self.bias_tempco),
            ("scale_factor", &self.scale_factor),
            ("scale_tempco", &self.scale_tempco),
            ("nonlinearity", &self.nonlinearity),
            ("misalignment_deg", &self.misalignment_deg),
            ("g_sensitivity", &self.g_sensitivity),
        ] {
            spread.validate(&format!("{key}.{name}"))?;
        }
        check_nonneg(&format!("{key}.noise_density"), self.noise_density)?;
        check_nonneg(&format!("{key}.rate_random_walk"), self.rate_random_walk)?;
        self.bias_instability.validate(&format!("{key}.bias_instability"))
    }
}

/// Magnetometer errors (gauss).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MagErrors {
    /// Hard iron: a field offset fixed to the board, gauss.
    pub hard_iron_gauss: [f64; 3],
    /// Soft iron: the deviation S of the field map from identity (out = (I + S)·m), row-major.
    pub soft_iron: [[f64; 3]; 3],
    /// White noise, σ per internal sample, gauss.
    pub noise_rms_gauss: f64,
}

/// Barometer errors (mbar).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BaroErrors {
    /// White noise, σ per internal sample, mbar.
    pub noise_rms_mbar: f64,
}

/// All error parameters of the sensor. Printable as a table with [`preset_table`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ErrorParams {
    /// Gyroscopes, °/s.
    pub gyro: InertialErrors,
    /// Accelerometers, g.
    pub accel: InertialErrors,
    /// Magnetometers, gauss.
    pub mag: MagErrors,
    /// Barometer, mbar.
    pub baro: BaroErrors,
    /// R ≥ 1: every Gauss–Markov term of correlation time τ is redrawn every m samples, m the largest
    /// power of two with m·Δt ≤ τ/R, and held in between (module docs: multi-rate bank). A huge R
    /// (1e12) redraws every term every sample.
    #[serde(default = "default_update_ratio")]
    pub gauss_markov_update_ratio: f64,
}

fn default_update_ratio() -> f64 {
    DEFAULT_GAUSS_MARKOV_UPDATE_RATIO
}

impl Default for ErrorParams {
    fn default() -> Self {
        ErrorParams::ideal()
    }
}

/// Gyro full scale of the default ±300 °/s range.
const GYRO_FULL_SCALE_DPS: f64 = 300.0;
/// Accelerometer full scale, g.
const ACCEL_FULL_SCALE_G: f64 = 18.0;

impl ErrorParams {
    /// The error-free sensor: [`ErrorModel::apply`] is the identity.
    pub fn ideal() -> Self {
        ErrorParams {
            gyro: InertialErrors::ideal(GYRO_FULL_SCALE_DPS),
            accel: InertialErrors::ideal(ACCEL_FULL_SCALE_G),
            mag: MagErrors { hard_iron_gauss: [0.0; 3], soft_iron: [[0.0; 3]; 3], noise_rms_gauss: 0.0 },
            baro: BaroErrors { noise_rms_mbar: 0.0 },
            gauss_markov_update_ratio: DEFAULT_GAUSS_MARKOV_UPDATE_RATIO,
        }
    }

    /// The ADIS16407 as specified in `spec/adis16407.md`; sources and interpretations per value are
    /// in [`preset_table`].
    pub fn adis16407() -> Self {
        // Bias-instability bank: 1 s … 1e5 s, one term per decade: the floor is flat within ±1.5 %
        // from 20 s (the gyro's white/floor crossover is (N/floor)² ≈ 23 s) to 5.5 h.
        let bank =
            |allan_floor| BiasInstability::Flicker { allan_floor, tau_min_s: 1.0, tau_max_s: 1e5, terms_per_decade: 1 };
        ErrorParams {
            gyro: InertialErrors {
                full_scale: GYRO_FULL_SCALE_DPS,
                initial_bias: Spread::normal(3.0),
                bias_tempco: Spread::normal(0.01),
                scale_factor: Spread::ZERO,
                scale_tempco: Spread::ZERO,
                nonlinearity: Spread::uniform(0.001),
                misalignment_deg: Spread::uniform(0.025),
                g_sensitivity: Spread::normal(0.05),
                noise_density: 2.0 / 60.0,
                bias_instability: bank(0.007),
                rate_random_walk: 0.0,
            },
            accel: InertialErrors {
                full_scale: ACCEL_FULL_SCALE_G,
                initial_bias: Spread::normal(0.050),
                bias_tempco: Spread::normal(0.3e-3),
                scale_factor: Spread::ZERO,
                scale_tempco: Spread::ZERO,
                nonlinearity: Spread::ZERO,
                misalignment_deg: Spread::uniform(0.025),
                g_sensitivity: Spread::ZERO,
                noise_density: 0.5e-3 / std::f64::consts::SQRT_2,
                bias_instability: bank(0.2e-3),
                rate_random_walk: 0.0,
            },
            mag: MagErrors { hard_iron_gauss: [0.0; 3], soft_iron: [[0.0; 3]; 3], noise_rms_gauss: 1.15e-3 },
            baro: BaroErrors { noise_rms_mbar: 0.027 },
            gauss_markov_update_ratio: DEFAULT_GAUSS_MARKOV_UPDATE_RATIO,
        }
    }

    /// `adis16407` with the gyro's initial (turn-on) bias removed, as an autonull (GLOB_CMD bit 0) or
    /// a bias calibration at start-up leaves it: everything else (in-run instability, noise, tempco,
    /// g-sensitivity, the accelerometer's errors) is kept. The reference design's published 30 s drifts
    /// (< 1.4°) are impossible with the data sheet's ±3 °/s turn-on bias left in (90° in 30 s).
    pub fn adis16407_nulled() -> Self {
        let mut p = ErrorParams::adis16407();
        p.gyro.initial_bias = Spread::ZERO;
        p
    }

    /// The ADIS16362 (`adis16362.md`): the gyro figures the wing-angle notes quote from its data sheet
    /// (initial bias 3 °/s, in-run stability 0.007 °/s, tempco 0.01 °/s/°C, the ADIS16407's) and the
    /// rest of the ADIS16407's gyro; the accelerometer's are placeholders [unconfirmed, recollection of
    /// Table 1]: initial bias ±4 mg, in-run stability 0.1 mg, VRW 0.12 m/s/√hr, tempco as the 16407's.
    pub fn adis16362() -> Self {
        let mut p = ErrorParams::adis16407();
        let a = &mut p.accel;
        a.full_scale = 1.7;
        a.initial_bias = Spread::normal(4e-3);
        a.noise_density = 0.12 / 60.0 / 9.80665;
        if let BiasInstability::Flicker { allan_floor, .. } = &mut a.bias_instability {
            *allan_floor = 0.1e-3;
        }
        // No magnetometer and no barometer on this part.
        p.mag.noise_rms_gauss = 0.0;
        p.baro.noise_rms_mbar = 0.0;
        p
    }

    /// A preset by name (one of [`PRESET_NAMES`]).
    pub fn preset(name: &str) -> Result<Self> {
        match name {
            "ideal" => Ok(ErrorParams::ideal()),
            "adis16407" => Ok(ErrorParams::adis16407()),
            "adis16407-nulled" => Ok(ErrorParams::adis16407_nulled()),
            "adis16362" => Ok(ErrorParams::adis16362()),
            _ => Err(bad("errors.preset", name, "one of `ideal`, `adis16407`, `adis16407-nulled`, `adis16362`")),
        }
    }

    /// Check every value; messages name the key (`errors.gyro.noise_density`, …).
    pub fn validate(&self) -> Result<()> {
        self.gyro.validate("errors.gyro")?;
        self.accel.validate("errors.accel")?;
        for (i, v) in self.mag.hard_iron_gauss.iter().enumerate() {
            check_finite(&format!("errors.mag.hard_iron_gauss[{i}]"), *v)?;
        }
        for (i, row) in self.mag.soft_iron.iter().enumerate() {
            for (j, v) in row.iter().enumerate() {
                check_finite(&format!("errors.mag.soft_iron[{i}][{j}]"), *v)?;
            }
        }
        check_nonneg("errors.mag.noise_rms_gauss", self.mag.noise_rms_gauss)?;
        check_nonneg("errors.baro.noise_rms_mbar", self.baro.noise_rms_mbar)?;
        check_update_ratio(self.gauss_markov_update_ratio)
    }

    fn is_ideal(&self) -> bool {
        self.gyro.is_ideal()
            && self.accel.is_ideal()
            && self.mag.hard_iron_gauss == [0.0; 3]
            && self.mag.soft_iron == [[0.0; 3]; 3]
            && self.mag.noise_rms_gauss == 0.0
            && self.baro.noise_rms_mbar == 0.0
    }
}

/// One row of a preset table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PresetRow {
    /// What the value is (including how it is distributed over units).
    pub quantity: &'static str,
    /// The value, in `unit`.
    pub value: f64,
    /// Unit of `value`.
    pub unit: &'static str,
    /// Where the value comes from and how it was interpreted.
    pub source: &'static str,
    /// True where the spec marks the value unconfirmed for the ADIS16407, or it is a model choice.
    pub unconfirmed: bool,
}

const SRC_16407: &str = "ADIS16407 data sheet (spec adis16407.md)";
const SRC_16405: &str = "ADIS16405 sibling (spec adis16407.md), unconfirmed for the 16407";
const SRC_16405_1SIGMA: &str =
    "ADIS16405 sibling, unconfirmed; ± read as 1σ normal (ADI tables give typical values as 1σ, ez.analog.com DOC-16082)";
const SRC_NOT_IN_SPEC: &str = "not in the spec: 0 assumed";

/// The preset `name` as printable rows (every number read from [`ErrorParams::preset`]).
pub fn preset_table(name: &str) -> Result<Vec<PresetRow>> {
    let p = ErrorParams::preset(name)?;
    let annotated = name != "ideal";
    let g = &p.gyro;
    let a = &p.accel;
    let floor = |e: &InertialErrors| match &e.bias_instability {
        BiasInstability::Flicker { allan_floor, tau_min_s, tau_max_s, terms_per_decade } => {
            [*allan_floor, *tau_min_s, *tau_max_s, *terms_per_decade as f64]
        }
        _ => [0.0; 4],
    };
    let [g_floor, g_tmin, g_tmax, g_terms] = floor(g);
    let [a_floor, a_tmin, a_tmax, a_terms] = floor(a);
    let model_choice = "model choice: flicker bank (module docs), 1 term/decade";
    let rows: Vec<(&'static str, f64, &'static str, &'static str, bool)> = vec![
        ("gyro full scale (range ±300)", g.full_scale, "°/s", SRC_16407, false),
        ("gyro initial bias, 1σ", g.initial_bias.width, "°/s", SRC_16405_1SIGMA, true),
        ("gyro bias tempco, 1σ", g.bias_tempco.width, "°/s/°C", SRC_16405_1SIGMA, true),
        ("gyro scale-factor error, 1σ", g.scale_factor.width * 1e6, "ppm", SRC_NOT_IN_SPEC, true),
        ("gyro scale-factor tempco, 1σ", g.scale_tempco.width * 1e6, "ppm/°C", SRC_NOT_IN_SPEC, true),
        (
            "gyro nonlinearity (quadratic, uniform ±)",
            g.nonlinearity.width * 100.0,
            "% FS",
            "ADIS16405 sibling 0.1 % FS, unconfirmed; |deviation at full scale| ≤ it",
            true,
        ),
        (
            "gyro misalignment per element (uniform ±)",
            g.misalignment_deg.width,
            "°",
            "ADIS16407 axis-to-axis < 0.05°: two elements per pair, so pairs stay within ±0.05°",
            false,
        ),
        (
            "gyro g-sensitivity per matrix element, 1σ",
            g.g_sensitivity.width,
            "°/s/g",
            "ADIS16405 sibling (value given with MSC_CTRL[7] compensation on), unconfirmed",
            true,
        ),
        ("gyro angle random walk", g.noise_density * 60.0, "°/√h", SRC_16405, true),
        (
            "gyro per-sample noise at 819.2 SPS (derived)",
            g.noise_density * 819.2f64.sqrt(),
            "°/s",
            "N·√fs; sibling quotes ≈ 0.8 °/s rms unfiltered",
            true,
        ),
        (
            "gyro in-run bias stability (Allan floor)",
            g_floor,
            "°/s",
            "ADIS16405 sibling 0.007 °/s, unconfirmed; ADI's figure is the Allan minimum (DOC-16082)",
            true,
        ),
        ("gyro bias-instability τ min", g_tmin, "s", model_choice, true),
        ("gyro bias-instability τ max", g_tmax, "s", model_choice, true),
        ("gyro bias-instability terms per decade", g_terms, "", model_choice, true),
        ("gyro rate random walk", g.rate_random_walk, "°/s/√s", SRC_NOT_IN_SPEC, true),
        ("accel full scale", a.full_scale, "g", SRC_16407, false),
        ("accel initial bias, 1σ", a.initial_bias.width * 1e3, "mg", SRC_16405_1SIGMA, true),
        ("accel bias tempco, 1σ", a.bias_tempco.width * 1e3, "mg/°C", SRC_16405_1SIGMA, true),
        ("accel scale-factor error, 1σ", a.scale_factor.width * 1e6, "ppm", SRC_NOT_IN_SPEC, true),
        ("accel scale-factor tempco, 1σ", a.scale_tempco.width * 1e6, "ppm/°C", SRC_NOT_IN_SPEC, true),
        ("accel nonlinearity (uniform ±)", a.nonlinearity.width * 100.0, "% FS", SRC_NOT_IN_SPEC, true),
        (
            "accel misalignment per element (uniform ±)",
            a.misalignment_deg.width,
            "°",
            "assumed equal to the gyro's (spec gives no accel alignment)",
            true,
        ),
        (
            "accel noise density (one-sided, data-sheet convention)",
            a.noise_density * std::f64::consts::SQRT_2 * 1e3,
            "mg/√Hz",
            "ADIS16407 data sheet 0.5 mg/√Hz; model N = D/√2",
            false,
        ),
        (
            "accel velocity random walk (derived)",
            a.noise_density * STANDARD_GRAVITY * 60.0,
            "m/s/√h",
            "from the 16407 density; ADIS16405 sibling quotes 0.2 m/s/√h",
            false,
        ),
        (
            "accel per-sample noise at 819.2 SPS (derived)",
            a.noise_density * 819.2f64.sqrt() * 1e3,
            "mg",
            "N·√fs, white to Nyquist; the 16407's 9 mg rms is D·√(330 Hz bandwidth)",
            false,
        ),
        (
            "accel in-run bias stability (Allan floor)",
            a_floor * 1e3,
            "mg",
            "ADIS16405 sibling 0.2 mg, unconfirmed; read as the Allan minimum (DOC-16082)",
            true,
        ),
        ("accel bias-instability τ min", a_tmin, "s", model_choice, true),
        ("accel bias-instability τ max", a_tmax, "s", model_choice, true),
        ("accel bias-instability terms per decade", a_terms, "", model_choice, true),
        ("accel rate random walk", a.rate_random_walk * 1e3, "mg/√s", SRC_NOT_IN_SPEC, true),
        ("magnetometer noise per sample", p.mag.noise_rms_gauss * 1e3, "mgauss", SRC_16405, true),
        (
            "magnetometer hard iron, largest |component|",
            p.mag.hard_iron_gauss.iter().fold(0.0f64, |m, v| m.max(v.abs())) * 1e3,
            "mgauss",
            "installation-dependent: none by default",
            false,
        ),
        (
            "magnetometer soft iron, largest |S element|",
            p.mag.soft_iron.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs())),
            "",
            "installation-dependent: none by default",
            false,
        ),
        ("barometer noise per sample", p.baro.noise_rms_mbar, "mbar", SRC_16405, true),
    ];
    Ok(rows
        .into_iter()
        .map(|(quantity, value, unit, source, unconfirmed)| {
            let (source, unconfirmed) = match name {
                "adis16362" => adis16362_source(quantity).unwrap_or((source, unconfirmed)),
                _ => (source, unconfirmed),
            };
            PresetRow {
                quantity,
                value,
                unit,
                source: if annotated { source } else { "ideal preset: no error" },
                unconfirmed: annotated && unconfirmed,
            }
        })
        .collect())
}

const SRC_WING_NOTES: &str =
    "ADIS16362 data sheet as the wing-angle notes quote it (spec adis16362.md, algorithms.md §3 corrections)";
const SRC_16362_RECOLLECTION: &str = "ADIS16362 Table 1 by recollection, not re-read (spec adis16362.md): unconfirmed";

/// Where each value of the `adis16362` preset comes from, where it differs from the ADIS16407's
/// annotation (the rows not named keep it: model choices and values not in the spec). The preset is
/// [`ErrorParams::adis16362`].
fn adis16362_source(quantity: &str) -> Option<(&'static str, bool)> {
    let row = match quantity {
        "gyro full scale (range ±300)" => ("ADIS16362 data sheet p. 11 Table 9: ±300 °/s (spec adis16362.md)", false),
        "gyro initial bias, 1σ" => (SRC_WING_NOTES, false),
        "gyro bias tempco, 1σ" => (SRC_WING_NOTES, false),
        "gyro in-run bias stability (Allan floor)" => (SRC_WING_NOTES, false),
        "gyro angle random walk" => ("ADIS16362 Table 1 by recollection (2.0 °/√h), not re-read: unconfirmed", true),
        "gyro per-sample noise at 819.2 SPS (derived)" => {
            ("N·√fs from the ARW; the recollected 0.8 °/s rms unfiltered is unconfirmed", true)
        }
        "gyro nonlinearity (quadratic, uniform ±)" => (SRC_16362_RECOLLECTION, true),
        "gyro misalignment per element (uniform ±)" => ("axis-to-axis 0.05° by recollection: unconfirmed", true),
        "gyro g-sensitivity per matrix element, 1σ" => (SRC_16362_RECOLLECTION, true),
        "accel full scale" => ("rated ±1.7 g by recollection (spec adis16362.md): unconfirmed", true),
        "accel initial bias, 1σ" => ("±4 mg by recollection, read as 1σ (spec adis16362.md): unconfirmed", true),
        "accel bias tempco, 1σ" => ("the ADIS16407's 0.3 mg/°C: not in the ADIS16362 spec, unconfirmed", true),
        "accel noise density (one-sided, data-sheet convention)" => {
            ("derived from the VRW 0.12 m/s/√h (recollection, unconfirmed), N·√2", true)
        }
        "accel velocity random walk (derived)" => (SRC_16362_RECOLLECTION, true),
        "accel per-sample noise at 819.2 SPS (derived)" => (
            "N·√fs from the VRW: 5.8 mg, against a recollected ≈ 1.5 mg rms unfiltered — the two recollected \
             figures disagree by 4×; unconfirmed",
            true,
        ),
        "accel in-run bias stability (Allan floor)" => {
            ("0.1 mg by recollection (spec adis16362.md): unconfirmed", true)
        }
        "accel misalignment per element (uniform ±)" => ("assumed equal to the gyro's: unconfirmed", true),
        "magnetometer noise per sample" | "barometer noise per sample" => {
            ("no magnetometer or barometer on the ADIS16362 (spec adis16362.md)", false)
        }
        _ => return None,
    };
    Some(row)
}

/// The realised constants of one inertial triad (one unit, one seed).
#[derive(Debug, Clone, PartialEq)]
pub struct InertialUnit {
    /// Constant bias per axis, output units.
    pub bias: [f64; 3],
    /// Bias temperature coefficient per axis, output units per °C.
    pub bias_tempco: [f64; 3],
    /// Scale-factor error per axis, fraction.
    pub scale_factor: [f64; 3],
    /// Scale-factor temperature coefficient per axis, fraction per °C.
    pub scale_tempco: [f64; 3],
    /// Quadratic coefficient per axis, 1/output unit (nonlinearity fraction / full scale).
    pub quadratic: [f64; 3],
    /// Sensing axes as rows, in the sensor frame: I + misalignment angles (rad).
    pub axes: [[f64; 3]; 3],
    /// Output per g of specific force (row: output axis, column: force axis).
    pub g_sensitivity: [[f64; 3]; 3],
}

/// One Gauss–Markov term of one triad, redrawn every m = 2^`shift` samples (module docs: multi-rate
/// bank) from its own stream.
#[derive(Debug, Clone)]
struct GaussMarkovState {
    params: GaussMarkov,
    /// log₂ of the update interval m: the term is redrawn at samples k with k % m == 0.
    shift: u32,
    /// Coefficients of one update, over m·Δt.
    decay: f64,
    drive: f64,
    state: [f64; 3],
    rng: StreamRng,
}

/// Largest log₂ of an update interval: 2^62 samples are 1.8e8 years at 819.2 SPS, and the next
/// update instant of any sample index stays representable in u64.
const MAX_UPDATE_SHIFT: u32 = 62;

/// log₂ of [`gauss_markov_update_interval`].
fn update_shift(tau_s: f64, sample_period_s: f64, update_ratio: f64) -> u32 {
    let limit_s = tau_s / update_ratio;
    let mut shift = 0;
    while shift < MAX_UPDATE_SHIFT && (1u64 << (shift + 1)) as f64 * sample_period_s <= limit_s {
        shift += 1;
    }
    shift
}

/// Samples between two updates of a Gauss–Markov term of correlation time `tau_s`: the largest power
/// of two m with m·`sample_period_s` ≤ `tau_s` / `update_ratio`, at least 1 (module docs: multi-rate
/// bank).
pub fn gauss_markov_update_interval(tau_s: f64, sample_period_s: f64, update_ratio: f64) -> u64 {
    1 << update_shift(tau_s, sample_period_s, update_ratio)
}

/// Exact discretisation over `dt_s`: (e^{−Δt/τ}, σ√(1 − e^{−2Δt/τ})); expm1 keeps the drive exact
/// when Δt ≪ τ (1.2 ms against 1e5 s).
fn gauss_markov_step(term: &GaussMarkov, dt_s: f64) -> (f64, f64) {
    let x = dt_s / term.tau_s;
    ((-x).exp(), term.sigma * (-(-2.0 * x).exp_m1()).sqrt())
}

/// The stochastic and fixed parts of one triad.
#[derive(Debug, Clone)]
struct Triad {
    gaussian: Gaussian,
    unit: InertialUnit,
    white_sigma: f64,
    /// `white_sigma > 0`, decided once (a flag test is cheaper than a float comparison per sample).
    has_white_noise: bool,
    white_rng: StreamRng,
    gauss_markov: Vec<GaussMarkovState>,
    /// Σ of the terms' states per axis, refreshed when a term updates (most samples update none).
    gauss_markov_sum: [f64; 3],
    /// First sample index at which some term updates (0: not known yet, check every term).
    next_update: u64,
    /// log₂ of the bank's shortest update interval (None: no term).
    shortest_shift: Option<u32>,
    /// True when the terms' shifts never decrease in bank order (the flicker bank's: τ ascending):
    /// the due terms of a move are then a prefix of the bank.
    shifts_ascending: bool,
    rate_random_walk: f64,
    rate_walk_step: f64,
    rate_walk: [f64; 3],
    rate_walk_rng: StreamRng,
    /// False when the g-sensitivity matrix is zero (the accelerometer's): its products are skipped.
    has_g_sensitivity: bool,
    /// `unit.axes` and `unit.g_sensitivity` by column: a column's three elements side by side let
    /// the compiler compute two axes in one instruction (each axis's sum in the same order).
    axes_by_column: [[f64; 3]; 3],
    g_sensitivity_by_column: [[f64; 3]; 3],
    /// ΔT (bits) that `gain` and `fixed_bias` were computed for; temperature changes slowly, so
    /// they are recomputed only when it changes.
    cached_delta_temp: u64,
    /// 1 + s_i + s_T,i ΔT per axis.
    gain: [f64; 3],
    /// b_i + c_i ΔT per axis.
    fixed_bias: [f64; 3],
    /// fixed_bias + gauss_markov_sum + rate_walk per axis, in that order: its parts change only at a
    /// temperature change, a Gauss–Markov update or a walk step, which refresh it
    /// ([`Triad::refresh_slow_bias`]).
    slow_bias: [f64; 3],
}

const SOURCE_INITIAL_BIAS: u64 = 1;
const SOURCE_BIAS_TEMPCO: u64 = 2;
const SOURCE_SCALE_FACTOR: u64 = 3;
const SOURCE_SCALE_TEMPCO: u64 = 4;
const SOURCE_NONLINEARITY: u64 = 5;
const SOURCE_MISALIGNMENT: u64 = 6;
const SOURCE_G_SENSITIVITY: u64 = 7;
const SOURCE_WHITE_NOISE: u64 = 8;
const SOURCE_BIAS_INSTABILITY: u64 = 9;
const SOURCE_RATE_RANDOM_WALK: u64 = 10;
const SENSOR_GYRO: u64 = 0;
const SENSOR_ACCEL: u64 = 1;
const SENSOR_MAG: u64 = 2;
const SENSOR_BARO: u64 = 3;

/// The generator of every stream: xoshiro256++ (Blackman & Vigna), 2^256 − 1 period, passes
/// BigCrush and PractRand; a few ns per Gaussian draw against ≈ 12 ns for ChaCha20. Nothing here
/// needs a cryptographic generator, only independent, reproducible streams.
type StreamRng = Xoshiro256PlusPlus;

/// The SplitMix64 output function (Steele, Lea & Flood 2014): a bijection of u64 whose outputs of
/// nearby inputs are uncorrelated, so it separates streams whose keys differ in a few bits.
fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The random stream of one source of one sensor; `index` numbers the Gauss–Markov terms of bias
/// instability, 0 for every other source (module docs: derivation).
fn stream(seed: u64, sensor: u64, source: u64, index: u64) -> StreamRng {
    let id = sensor << 16 | source << 8 | index;
    StreamRng::seed_from_u64(splitmix64(splitmix64(seed) ^ id))
}

/// The columns of `m` (rows of its transpose).
fn transpose(m: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    std::array::from_fn(|j| std::array::from_fn(|i| m[i][j]))
}

/// Σ of the Gauss–Markov states per axis, in term order (so the sum is the same whatever the history).
fn sum_states(terms: &[GaussMarkovState]) -> [f64; 3] {
    let mut sum = [0.0; 3];
    for term in terms {
        for (total, x) in sum.iter_mut().zip(term.state) {
            *total += x;
        }
    }
    sum
}

fn draw_axes(spread: &Spread, rng: &mut StreamRng) -> [f64; 3] {
    [spread.draw(rng), spread.draw(rng), spread.draw(rng)]
}

impl Triad {
    fn new(e: &InertialErrors, seed: u64, sensor: u64, dt_s: f64, update_ratio: f64) -> Self {
        let s = |source| stream(seed, sensor, source, 0);
        let quadratic = draw_axes(&e.nonlinearity, &mut s(SOURCE_NONLINEARITY)).map(|n| n / e.full_scale);
        let mut axes = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let mut rng = s(SOURCE_MISALIGNMENT);
        for (i, row) in axes.iter_mut().enumerate() {
            for (j, element) in row.iter_mut().enumerate() {
                if i != j {
                    *element = e.misalignment_deg.draw(&mut rng).to_radians();
                }
            }
        }
        let mut g_sensitivity = [[0.0; 3]; 3];
        let mut rng = s(SOURCE_G_SENSITIVITY);
        for element in g_sensitivity.iter_mut().flatten() {
            *element = e.g_sensitivity.draw(&mut rng);
        }
        let unit = InertialUnit {
            bias: draw_axes(&e.initial_bias, &mut s(SOURCE_INITIAL_BIAS)),
            bias_tempco: draw_axes(&e.bias_tempco, &mut s(SOURCE_BIAS_TEMPCO)),
            scale_factor: draw_axes(&e.scale_factor, &mut s(SOURCE_SCALE_FACTOR)),
            scale_tempco: draw_axes(&e.scale_tempco, &mut s(SOURCE_SCALE_TEMPCO)),
            quadratic,
            axes,
            g_sensitivity,
        };
        let gauss_markov: Vec<GaussMarkovState> = e
            .bias_instability
            .terms()
            .into_iter()
            .enumerate()
            .filter(|(_, t)| t.sigma > 0.0)
            .map(|(index, params)| {
                // The stream is numbered by the term's place in the bank, so a zero term changes no other.
                let mut rng = stream(seed, sensor, SOURCE_BIAS_INSTABILITY, index as u64);
                let shift = update_shift(params.tau_s, dt_s, update_ratio);
                let (decay, drive) = gauss_markov_step(&params, dt_s * (1u64 << shift) as f64);
                // Start stationary: x₀ ~ N(0, σ²).
                let state = [(); 3].map(|()| params.sigma * standard_normal(&mut rng));
                GaussMarkovState { params, shift, decay, drive, state, rng }
            })
            .collect();
        let white_sigma = e.noise_density / dt_s.sqrt();
        let mut triad = Triad {
            gaussian: Gaussian::new(),
            has_g_sensitivity: unit.g_sensitivity.iter().flatten().any(|g| *g != 0.0),
            axes_by_column: transpose(&unit.axes),
            g_sensitivity_by_column: transpose(&unit.g_sensitivity),
            cached_delta_temp: 0,
            gain: [0.0; 3],
            fixed_bias: [0.0; 3],
            slow_bias: [0.0; 3],
            unit,
            white_sigma,
            has_white_noise: white_sigma > 0.0,
            white_rng: s(SOURCE_WHITE_NOISE),
            gauss_markov_sum: sum_states(&gauss_markov),
            shortest_shift: gauss_markov.iter().map(|term| term.shift).min(),
            shifts_ascending: gauss_markov.windows(2).all(|pair| pair[0].shift <= pair[1].shift),
            gauss_markov,
            next_update: 0,
            rate_random_walk: e.rate_random_walk,
            rate_walk_step: e.rate_random_walk * dt_s.sqrt(),
            rate_walk: [0.0; 3],
            rate_walk_rng: s(SOURCE_RATE_RANDOM_WALK),
        };
        triad.set_temperature(0.0);
        triad
    }

    /// Recompute the temperature-dependent gain and bias for ΔT = `delta_temp_c`.
    fn set_temperature(&mut self, delta_temp_c: f64) {
        let u = &self.unit;
        self.cached_delta_temp = delta_temp_c.to_bits();
        self.gain = std::array::from_fn(|i| 1.0 + u.scale_factor[i] + u.scale_tempco[i] * delta_temp_c);
        self.fixed_bias = std::array::from_fn(|i| u.bias[i] + u.bias_tempco[i] * delta_temp_c);
        self.refresh_slow_bias();
    }

    /// Recompute `slow_bias` from its parts.
    fn refresh_slow_bias(&mut self) {
        self.slow_bias = std::array::from_fn(|i| self.fixed_bias[i] + self.gauss_markov_sum[i] + self.rate_walk[i]);
    }

    /// Move the bias processes on from sample `from` to sample `to` > `from` (samples of `dt_s`):
    /// each Gauss–Markov term exactly over the update instants (multiples of its interval) the move
    /// passes, the rate random walk exactly over the whole move.
    #[inline]
    fn advance(&mut self, from: u64, to: u64, dt_s: f64) {
        if to >= self.next_update {
            self.update_gauss_markov(from, to, dt_s);
        }
        if self.rate_random_walk > 0.0 {
            self.walk(from, to, dt_s);
        }
    }

    /// The Gauss–Markov part of [`Triad::advance`], when some term is due.
    #[inline(never)]
    fn update_gauss_markov(&mut self, from: u64, to: u64, dt_s: f64) {
        let mut updated = false;
        // The move passes a multiple of 2^shift exactly when `from` and `to` (from < to) differ in a
        // bit at or above `shift`, i.e. when shift ≤ the highest bit in which they differ.
        let highest_changed_bit = u64::BITS - 1 - (from ^ to).leading_zeros();
        for term in &mut self.gauss_markov {
            if term.shift > highest_changed_bit {
                if self.shifts_ascending {
                    break; // every later term has a shift at least as large: none is due
                }
                continue;
            }
            let updates = (to >> term.shift) - (from >> term.shift);
            let (decay, drive) = if updates == 1 {
                (term.decay, term.drive)
            } else {
                gauss_markov_step(&term.params, dt_s * updates as f64 * (1u64 << term.shift) as f64)
            };
            let w = self.gaussian.draw3(&mut term.rng);
            for (x, w) in term.state.iter_mut().zip(w) {
                *x = decay * *x + drive * w;
            }
            updated = true;
        }
        // Every term's update instants are multiples of the shortest interval, so the next one of
        // those is the bank's next update.
        self.next_update = self.shortest_shift.map_or(u64::MAX, |s| ((to >> s) + 1).saturating_mul(1 << s));
        if updated {
            self.gauss_markov_sum = sum_states(&self.gauss_markov);
            self.refresh_slow_bias();
        }
    }

    /// The rate random walk part of [`Triad::advance`].
    #[inline(never)]
    fn walk(&mut self, from: u64, to: u64, dt_s: f64) {
        let steps = to - from;
        let step = if steps == 1 { self.rate_walk_step } else { self.rate_random_walk * (dt_s * steps as f64).sqrt() };
        let w = self.gaussian.draw3(&mut self.rate_walk_rng);
        for (r, w) in self.rate_walk.iter_mut().zip(w) {
            *r += step * w;
        }
        self.refresh_slow_bias();
    }

    /// Corrupt the true values `x` of the triad's three axes (`force_g`: the true specific force).
    /// Always inline: it runs twice per sample, and a call's register saves cost as much as the bias
    /// sum it wraps.
    #[inline(always)]
    fn apply(&mut self, force_g: &[f64; 3], delta_temp_c: f64, x: &mut [f64; 3]) {
        if delta_temp_c.to_bits() != self.cached_delta_temp {
            self.set_temperature(delta_temp_c);
        }
        let white = if self.has_white_noise {
            let [a, b, c] = self.gaussian.draw3(&mut self.white_rng);
            [self.white_sigma * a, self.white_sigma * b, self.white_sigma * c]
        } else {
            [0.0; 3]
        };
        // Step by step for the three axes together (the compiler pairs axes); per axis the operations
        // and their order are the model's formula (module docs).
        let truth = *x;
        let (a, q) = (&self.axes_by_column, &self.unit.quadratic);
        let mut y: [f64; 3] = std::array::from_fn(|i| a[0][i] * truth[0] + a[1][i] * truth[1] + a[2][i] * truth[2]);
        y = std::array::from_fn(|i| y[i] * self.gain[i] + q[i] * y[i] * y[i]);
        let mut bias = self.slow_bias;
        if self.has_g_sensitivity {
            let g = &self.g_sensitivity_by_column;
            for (i, bias) in bias.iter_mut().enumerate() {
                *bias += g[0][i] * force_g[0] + g[1][i] * force_g[1] + g[2][i] * force_g[2];
            }
        }
        *x = std::array::from_fn(|i| y[i] + (bias[i] + white[i]));
    }
}

/// The seeded, reproducible sensor error model of one ADIS16407 unit.
#[derive(Debug, Clone)]
pub struct ErrorModel {
    identity: bool,
    sample_period_s: f64,
    last_sample: Option<u64>,
    /// First sample index at which a triad's bias processes move: the earlier of the triads' next
    /// Gauss–Markov updates, or 0 (every sample) when a triad has a rate random walk.
    next_bias_move: u64,
    gyro: Triad,
    accel: Triad,
    /// The magnetometer's map I + S, by column (see `Triad::axes_by_column`).
    mag_map_by_column: [[f64; 3]; 3],
    mag_hard_iron: [f64; 3],
    mag_sigma: f64,
    /// `mag_sigma > 0` and `baro_sigma > 0`, decided once.
    has_mag_noise: bool,
    has_baro_noise: bool,
    mag_rng: StreamRng,
    baro_sigma: f64,
    baro_rng: StreamRng,
    gaussian: Gaussian,
}

impl ErrorModel {
    /// A model of one unit: `params` realised with `seed`, advancing `sample_period_s` per sample.
    pub fn new(params: &ErrorParams, seed: u64, sample_period_s: f64) -> Result<Self> {
        params.validate()?;
        if !(sample_period_s.is_finite() && sample_period_s > 0.0) {
            return Err(Error::Config(format!(
                "error model: device sample period {sample_period_s} s: expected a finite number > 0"
            )));
        }
        let dt = sample_period_s;
        let mut mag_map = params.mag.soft_iron;
        for (i, row) in mag_map.iter_mut().enumerate() {
            row[i] += 1.0;
        }
        Ok(ErrorModel {
            identity: params.is_ideal(),
            sample_period_s: dt,
            last_sample: None,
            next_bias_move: 0,
            gyro: Triad::new(&params.gyro, seed, SENSOR_GYRO, dt, params.gauss_markov_update_ratio),
            accel: Triad::new(&params.accel, seed, SENSOR_ACCEL, dt, params.gauss_markov_update_ratio),
            mag_map_by_column: transpose(&mag_map),
            mag_hard_iron: params.mag.hard_iron_gauss,
            mag_sigma: params.mag.noise_rms_gauss,
            has_mag_noise: params.mag.noise_rms_gauss > 0.0,
            has_baro_noise: params.baro.noise_rms_mbar > 0.0,
            mag_rng: stream(seed, SENSOR_MAG, SOURCE_WHITE_NOISE, 0),
            baro_sigma: params.baro.noise_rms_mbar,
            baro_rng: stream(seed, SENSOR_BARO, SOURCE_WHITE_NOISE, 0),
            gaussian: Gaussian::new(),
        })
    }

    /// The model of the profile's `[errors]` section (preset, seed, update ratio).
    pub fn from_profile(errors: &Errors, sample_period_s: f64) -> Result<Self> {
        let mut params = ErrorParams::preset(&errors.preset)?;
        params.gauss_markov_update_ratio = errors.gauss_markov_update_ratio;
        ErrorModel::new(&params, errors.seed, sample_period_s)
    }

    /// True when the model changes nothing (the `ideal` preset).
    pub fn is_identity(&self) -> bool {
        self.identity
    }

    /// The realised constants of the gyro triad.
    pub fn gyro_unit(&self) -> &InertialUnit {
        &self.gyro.unit
    }

    /// The realised constants of the accelerometer triad.
    pub fn accel_unit(&self) -> &InertialUnit {
        &self.accel.unit
    }

    /// Move both triads' bias processes from sample `from` to sample `to` > `from`.
    #[inline(never)]
    fn move_biases(&mut self, from: u64, to: u64) {
        self.gyro.advance(from, to, self.sample_period_s);
        self.accel.advance(from, to, self.sample_period_s);
        let walks = self.gyro.rate_random_walk > 0.0 || self.accel.rate_random_walk > 0.0;
        self.next_bias_move = if walks { 0 } else { self.gyro.next_update.min(self.accel.next_update) };
    }

    /// Apply the errors to internal sample `k` (taken at `_t`; the model's time is `k` times the
    /// sample period, so no float time accumulates). Samples must come in non-decreasing `k`; a gap
    /// propagates the bias processes exactly, a repeated `k` only draws new white noise.
    pub fn apply(&mut self, k: u64, _t: Ps, p: &mut Physical) {
        if self.identity {
            return;
        }
        match self.last_sample {
            // Most samples move no bias process: one test for both triads, the moves out of line.
            Some(last) if k > last && k >= self.next_bias_move => self.move_biases(last, k),
            // Out of contract (k went back): hold the processes, and find the next update afresh.
            Some(last) if k < last => {
                self.gyro.next_update = 0;
                self.accel.next_update = 0;
                self.next_bias_move = 0;
            }
            _ => {}
        }
        self.last_sample = Some(k);
        let delta_temp_c = p.temp_c - REFERENCE_TEMP_C;
        // The gyro sees the true specific force, so it goes before the accelerometer's own errors.
        let force = p.accel_g;
        self.gyro.apply(&force, delta_temp_c, &mut p.gyro_dps);
        self.accel.apply(&force, delta_temp_c, &mut p.accel_g);
        // As in `Triad::apply`: step by step for the three axes together.
        let (m, c, h) = (p.mag_gauss, &self.mag_map_by_column, &self.mag_hard_iron);
        p.mag_gauss = std::array::from_fn(|i| c[0][i] * m[0] + c[1][i] * m[1] + c[2][i] * m[2] + h[i]);
        if self.has_mag_noise {
            let w = self.gaussian.draw3(&mut self.mag_rng);
            for (out, w) in p.mag_gauss.iter_mut().zip(w) {
                *out += self.mag_sigma * w;
            }
        }
        if self.has_baro_noise {
            let w = self.gaussian.draw(&mut self.baro_rng);
            p.baro_mbar += self.baro_sigma * w;
        }
    }
}

fn bad(key: &str, value: impl std::fmt::Display, expected: &str) -> Error {
    Error::Profile(format!("key `{key}` = {value}: expected {expected}"))
}

fn check_finite(key: &str, value: f64) -> Result<()> {
    if !value.is_finite() {
        return Err(bad(key, value, "a finite number"));
    }
    Ok(())
}

fn check_nonneg(key: &str, value: f64) -> Result<()> {
    if !(value.is_finite() && value >= 0.0) {
        return Err(bad(key, value, "a finite number ≥ 0"));
    }
    Ok(())
}

fn check_pos(key: &str, value: f64) -> Result<()> {
    if !(value.is_finite() && value > 0.0) {
        return Err(bad(key, value, "a finite number > 0"));
    }
    Ok(())
}

impl super::SensorErrors for ErrorModel {
    fn apply(&mut self, k: u64, t: Ps, p: &mut Physical) {
        ErrorModel::apply(self, k, t, p);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_distr::StandardNormal;

    /// The default internal sample period, 1/819.2 s.
    const DT: f64 = 1.0 / 819.2;

    /// A physical input that changes every sample (rates, forces, field, temperature).
    fn moving_input(k: u64) -> Physical {
        let s = k as f64 * DT;
        Physical {
            gyro_dps: [10.0 * (3.0 * s).sin(), -5.0 + s, 120.0 * (0.5 * s).cos()],
            accel_g: [0.1 * s.sin(), -0.2, -1.0 + 0.01 * s],
            mag_gauss: [0.3, -0.05 * s.cos(), 0.4],
            baro_mbar: 1013.25 - 0.01 * s,
            temp_c: 25.0 + 20.0 * (0.1 * s).sin(),
            supply_v: 5.0,
            aux_v: 1.0,
        }
    }

    fn run(model: &mut ErrorModel, n: u64) -> Vec<Physical> {
        (0..n)
            .map(|k| {
                let mut p = moving_input(k);
                model.apply(k, 0, &mut p);
                p
            })
            .collect()
    }

    fn bits(p: &Physical) -> Vec<u64> {
        let mut v: Vec<u64> = p.gyro_dps.iter().chain(&p.accel_g).chain(&p.mag_gauss).map(|x| x.to_bits()).collect();
        v.extend([p.baro_mbar, p.temp_c, p.supply_v, p.aux_v].map(f64::to_bits));
        v
    }

    fn model(params: &ErrorParams, seed: u64) -> ErrorModel {
        ErrorModel::new(params, seed, DT).unwrap()
    }

    #[test]
    fn same_seed_is_bit_identical_and_other_seeds_differ() {
        let params = ErrorParams::adis16407();
        let a = run(&mut model(&params, 7), 5000);
        let b = run(&mut model(&params, 7), 5000);
        assert!(a.iter().zip(&b).all(|(x, y)| bits(x) == bits(y)));
        let c = run(&mut model(&params, 8), 5000);
        // Every gyro/accel/mag/baro value carries independent white noise: all must differ.
        let differing =
            a.iter().zip(&c).filter(|(x, y)| x.gyro_dps != y.gyro_dps && x.baro_mbar != y.baro_mbar).count();
        assert_eq!(differing, 5000);
    }

    #[test]
    fn ideal_is_the_identity() {
        let mut m = ErrorModel::from_profile(&Errors::default(), DT).unwrap();
        assert!(m.is_identity());
        for k in 0..1000 {
            let mut p = moving_input(k);
            p.gyro_dps[0] = f64::INFINITY;
            p.accel_g[1] = -0.0;
            let before = bits(&p);
            m.apply(k, 0, &mut p);
            assert_eq!(bits(&p), before);
        }
        // A flicker bank of zero floor is still ideal.
        let mut params = ErrorParams::ideal();
        params.gyro.bias_instability =
            BiasInstability::Flicker { allan_floor: 0.0, tau_min_s: 1.0, tau_max_s: 10.0, terms_per_decade: 1 };
        assert!(model(&params, 1).is_identity());
        assert!(!model(&ErrorParams::adis16407(), 1).is_identity());
    }

    /// Per-axis white noise of the gyro only, with zero input: returns the output samples per axis.
    fn gyro_samples(params: &ErrorParams, seed: u64, n: usize, k_step: u64) -> [Vec<f64>; 3] {
        let mut m = model(params, seed);
        let mut out: [Vec<f64>; 3] = Default::default();
        for i in 0..n as u64 {
            let mut p = Physical { temp_c: REFERENCE_TEMP_C, ..Physical::default() };
            m.apply(i * k_step, 0, &mut p);
            for (axis, v) in out.iter_mut().zip(p.gyro_dps) {
                axis.push(v);
            }
        }
        out
    }

    #[test]
    fn white_noise_sigma_is_density_times_root_fs() {
        let mut params = ErrorParams::ideal();
        params.gyro.noise_density = 2.0 / 60.0; // 2 °/√h
        let sigma = params.gyro.noise_density * (1.0 / DT).sqrt();
        assert!((sigma - 0.954).abs() < 1e-3);
        let n = 200_000;
        // Known zero mean: n·s²/σ² ~ χ²(n), so s/σ has std 1/√(2n) = 0.0016; the mean has std σ/√n.
        for axis in gyro_samples(&params, 3, n, 1) {
            let mean = axis.iter().sum::<f64>() / n as f64;
            let rms = (axis.iter().map(|x| x * x).sum::<f64>() / n as f64).sqrt();
            assert!((rms / sigma - 1.0).abs() < 5.0 / (2.0 * n as f64).sqrt(), "rms {rms} vs σ {sigma}");
            assert!(mean.abs() < 5.0 * sigma / (n as f64).sqrt(), "mean {mean}");
        }
    }

    #[test]
    fn gauss_markov_variance_and_lag_one_correlation_match_theory() {
        let term = GaussMarkov { sigma: 0.5, tau_s: 10.0 * DT };
        let mut params = ErrorParams::ideal();
        params.gyro.bias_instability = BiasInstability::GaussMarkov { terms: vec![term] };
        let n = 400_000;
        // k_step > 1 exercises the exact propagation over gaps: the lag-1 correlation becomes a^step.
        for k_step in [1u64, 3] {
            let a = (-(k_step as f64) * DT / term.tau_s).exp();
            for axis in gyro_samples(&params, 11, n, k_step) {
                assert_ar1(&axis, term.sigma, a, &format!("step {k_step}"));
            }
        }
    }

    /// `x` (n values) is a stationary AR(1) of standard deviation `sigma` and lag-1 correlation `a`:
    /// var(s²)/σ⁴ = (2/n)(1 + a²)/(1 − a²) and var(r̂₁) = (1 − a²)/n by theory; bounds are 5σ.
    fn assert_ar1(x: &[f64], sigma: f64, a: f64, what: &str) {
        let n = x.len() as f64;
        let var_tol = 5.0 * (2.0 / n * (1.0 + a * a) / (1.0 - a * a)).sqrt();
        let rho_tol = 5.0 * ((1.0 - a * a) / n).sqrt();
        let power = x.iter().map(|v| v * v).sum::<f64>();
        let variance = power / n;
        let rho = x.windows(2).map(|w| w[0] * w[1]).sum::<f64>() / power;
        let s2 = sigma * sigma;
        assert!((variance / s2 - 1.0).abs() < var_tol, "{what}: variance {variance} vs {s2}");
        assert!((rho - a).abs() < rho_tol, "{what}: lag-1 {rho} vs {a}");
    }

    #[test]
    fn update_interval_is_the_largest_power_of_two_within_tau_over_r() {
        let r = DEFAULT_GAUSS_MARKOV_UPDATE_RATIO;
        let intervals: Vec<u64> =
            flicker_bank(0.007, 1.0, 1e5, 1).iter().map(|t| gauss_markov_update_interval(t.tau_s, DT, r)).collect();
        // τ/(R·Δt) = 8.2, 82, 819, 8192, 81920, 819200 samples (module docs numbers).
        assert_eq!(intervals, [8, 64, 512, 8192, 65536, 524288]);
        for m in [1u64, 2, 64, 1 << 20] {
            // Exactly on the bound m is allowed; a hair below it, m/2 (and never below 1).
            let tau = r * m as f64 * DT;
            assert_eq!(gauss_markov_update_interval(tau, DT, r), m);
            assert_eq!(gauss_markov_update_interval(tau * (1.0 - 1e-9), DT, r), (m / 2).max(1));
        }
        assert_eq!(gauss_markov_update_interval(1e-9, DT, r), 1);
        assert_eq!(gauss_markov_update_interval(1e300, DT, r), 1 << MAX_UPDATE_SHIFT);
        // A huge R is the per-sample process for every τ of the preset.
        assert_eq!(gauss_markov_update_interval(1e5, DT, 1e12), 1);
    }

    #[test]
    fn hold_moves_the_structure_function_by_at_most_the_documented_bound() {
        // Module docs: with a random hold phase, D_held(s) = 2σ²·E[1 − a^N] (N = n or n + 1 updates
        // in s = (n + f)·T, P(N = n + 1) = f) is the chord of D(s) = 2σ²(1 − e^{−s/τ}), at most
        // σ²ε²/4 below it; summed over the adis16407 gyro bank that is 8.1e-9 (°/s)², 1.7e-4 of the
        // floor's Allan variance. Checked here on a dense grid of s, not from the formula.
        let floor = 0.007;
        let mut total = 0.0;
        for term in flicker_bank(floor, 1.0, 1e5, 1) {
            let m = gauss_markov_update_interval(term.tau_s, DT, DEFAULT_GAUSS_MARKOV_UPDATE_RATIO);
            let period = m as f64 * DT;
            let eps = period / term.tau_s;
            let s2 = term.sigma * term.sigma;
            let mut largest = 0.0f64;
            for i in 0..20_000 {
                let s = i as f64 * period / 997.0; // 20 intervals, 997 points each
                let (n, f) = ((s / period).floor(), (s / period).fract());
                let held = 2.0 * s2 * ((1.0 - f) * -(-n * eps).exp_m1() + f * -(-(n + 1.0) * eps).exp_m1());
                let exact = 2.0 * s2 * -(-s / term.tau_s).exp_m1();
                assert!(held <= exact * (1.0 + 1e-12), "τ {}: chord above the curve at s = {s}", term.tau_s);
                largest = largest.max(exact - held);
            }
            let bound = s2 * eps * eps / 4.0;
            // The bound is reached to within 1 % (mid-interval of the first one) and never exceeded.
            assert!(largest <= bound && largest > 0.99 * bound, "τ {}: {largest} vs {bound}", term.tau_s);
            total += bound;
        }
        assert!((total / 8.15e-9 - 1.0).abs() < 0.01, "{total}");
        assert!(total / (floor * floor) < 1.7e-4);
    }

    /// Gyro of an otherwise ideal sensor with the given Gauss–Markov terms and update ratio.
    fn gauss_markov_only(terms: Vec<GaussMarkov>, update_ratio: f64) -> ErrorParams {
        let mut params = ErrorParams::ideal();
        params.gyro.bias_instability = BiasInstability::GaussMarkov { terms };
        params.gauss_markov_update_ratio = update_ratio;
        params
    }

    #[test]
    fn a_fast_term_keeps_the_per_sample_process_exactly() {
        // τ = 10 Δt < 2·R·Δt: m = 1. The model's output is then today's recursion bit for bit,
        // from the term's own stream, including the exact propagation over gaps.
        let term = GaussMarkov { sigma: 0.3, tau_s: 10.0 * DT };
        assert_eq!(gauss_markov_update_interval(term.tau_s, DT, DEFAULT_GAUSS_MARKOV_UPDATE_RATIO), 1);
        let mut m = model(&gauss_markov_only(vec![term], DEFAULT_GAUSS_MARKOV_UPDATE_RATIO), 9);
        let mut rng = stream(9, SENSOR_GYRO, SOURCE_BIAS_INSTABILITY, 0);
        let mut x = [(); 3].map(|()| term.sigma * rng.sample::<f64, _>(StandardNormal));
        let mut last = 0;
        for k in (0..3000u64).map(|i| i + i / 7 * 3) {
            if k > last {
                let (decay, drive) = gauss_markov_step(&term, (k - last) as f64 * DT);
                x = x.map(|x| decay * x + drive * rng.sample::<f64, _>(StandardNormal));
            }
            last = k;
            let mut p = Physical { temp_c: REFERENCE_TEMP_C, ..Physical::default() };
            m.apply(k, 0, &mut p);
            assert_eq!(p.gyro_dps.map(f64::to_bits), x.map(f64::to_bits), "sample {k}");
        }
    }

    #[test]
    fn multi_rate_terms_are_stationary_and_held_between_updates() {
        // R = 1 holds each term as long as allowed (m·Δt ≤ τ), so a = e^{−mΔt/τ} = e^{−0.8} is far
        // from 1 and the AR(1) bounds are tight. The term sits at bank index 1 behind a zero term.
        for (tau_samples, m, updates) in [(5.0, 4u64, 200_000u64), (20.0, 16, 100_000)] {
            let term = GaussMarkov { sigma: 0.2, tau_s: tau_samples * DT };
            assert_eq!(gauss_markov_update_interval(term.tau_s, DT, 1.0), m);
            let params = gauss_markov_only(vec![GaussMarkov { sigma: 0.0, tau_s: 1.0 }, term], 1.0);
            let a = (-(m as f64) * DT / term.tau_s).exp();
            // Calls every sample (one update per interval), then every 3m samples (three updates
            // per call, propagated exactly in one step: the lag-1 correlation becomes a³).
            for calls_per_update in [m, 1] {
                let k_step = if calls_per_update == m { 1 } else { 3 * m };
                let a_step = if k_step == 1 { a } else { a.powi(3) };
                let n = updates as usize;
                let per_axis = gyro_samples(&params, 17, n * calls_per_update as usize, k_step);
                for axis in per_axis {
                    // Held: every sample of an interval repeats the value of its update instant.
                    let at_updates: Vec<f64> = axis.iter().step_by(calls_per_update as usize).copied().collect();
                    for (i, v) in axis.iter().enumerate() {
                        assert_eq!(v.to_bits(), at_updates[i / calls_per_update as usize].to_bits());
                    }
                    // AR(1) theory at the update instants, as in the per-sample test.
                    assert_ar1(&at_updates, term.sigma, a_step, &format!("m {m} step {k_step}"));
                }
            }
        }
    }

    #[test]
    fn gaps_within_update_intervals_keep_the_realisation() {
        // The adis16407 bank alone (fastest term m = 8). Visiting only k % 8 ∈ {0, 3, 5} still
        // passes every update instant one at a time, so the values at the visited samples are
        // those of the contiguous run, bit for bit.
        let mut params = ErrorParams::ideal();
        params.gyro.bias_instability = ErrorParams::adis16407().gyro.bias_instability;
        params.accel.bias_instability = ErrorParams::adis16407().accel.bias_instability;
        let sample = |m: &mut ErrorModel, k: u64| {
            let mut p = Physical { temp_c: REFERENCE_TEMP_C, ..Physical::default() };
            m.apply(k, 0, &mut p);
            (p.gyro_dps.map(f64::to_bits), p.accel_g.map(f64::to_bits))
        };
        let mut contiguous = model(&params, 4);
        let mut gapped = model(&params, 4);
        let n = 1 << 17; // two updates of the m = 65536 term
        let mut changes = 0;
        let mut previous = sample(&mut gapped, 0);
        let _ = sample(&mut contiguous, 0);
        for k in 1..n {
            let want = sample(&mut contiguous, k);
            if [0, 3, 5].contains(&(k % 8)) {
                let got = sample(&mut gapped, k);
                assert_eq!(got, want, "sample {k}");
                changes += usize::from(got != previous);
                previous = got;
            }
        }
        // The bank moves at every update of its fastest term (k % 8 == 0), and only then.
        assert_eq!(changes, (n as usize - 1) / 8);
    }

    #[test]
    fn the_slow_bias_is_its_parts_sum_after_every_change() {
        // A gyro whose slow parts move (Gauss–Markov bank, a tempco and a temperature that changes
        // every 7th sample; with and without a rate random walk, which moves at every sample and would
        // hide the others), moved by single samples and gaps: after each sample the cached sum must be
        // the sum of the parts now, bit for bit.
        for rate_random_walk in [0.0, 0.01] {
            let mut params = ErrorParams::adis16407();
            params.gyro.rate_random_walk = rate_random_walk;
            let mut model = ErrorModel::new(&params, 5, DT).unwrap();
            let (mut k, mut moves) = (0, 0);
            for n in 0..5000u64 {
                k += if n % 97 == 0 { 1000 } else { 1 };
                let mut p = Physical { temp_c: 25.0 + (n / 7) as f64 * 0.01, ..Physical::powered_idle() };
                let before = model.gyro.slow_bias;
                model.apply(k, 0, &mut p);
                let g = &model.gyro;
                let parts: [f64; 3] = std::array::from_fn(|i| g.fixed_bias[i] + g.gauss_markov_sum[i] + g.rate_walk[i]);
                assert_eq!(
                    g.slow_bias.map(f64::to_bits),
                    parts.map(f64::to_bits),
                    "walk {rate_random_walk}, sample {k}"
                );
                moves += usize::from(g.slow_bias != before);
            }
            // Without the walk: a temperature change every 7 samples, an update every 8.
            assert!(moves > 1200, "walk {rate_random_walk}: the slow bias moved at only {moves} samples");
        }
    }

    /// The bank's update by the definition: every term, due when the move passes a multiple of its
    /// interval, then the sum afresh (the reference for the due-term shortcut).
    fn update_every_term(triad: &mut Triad, from: u64, to: u64) {
        for term in &mut triad.gauss_markov {
            let updates = (to >> term.shift) - (from >> term.shift);
            if updates > 0 {
                let (decay, drive) = gauss_markov_step(&term.params, DT * updates as f64 * (1u64 << term.shift) as f64);
                let w = [(); 3].map(|()| standard_normal(&mut term.rng));
                for (x, w) in term.state.iter_mut().zip(w) {
                    *x = decay * *x + drive * w;
                }
            }
        }
        triad.gauss_markov_sum = sum_states(&triad.gauss_markov);
    }

    #[test]
    fn due_terms_are_those_of_the_plain_loop_over_every_term() {
        // Banks: the adis16407 flicker bank (shifts ascending: the loop stops at the first term not
        // due) and a shuffled one with repeated shifts (not ascending: every term is looked at).
        // Moves: mostly single samples, gaps of up to 1000 samples, jumps of up to 2^21 (past
        // every interval), and restarts (k goes back, as `ErrorModel::apply` allows).
        let flicker = ErrorParams::adis16407().gyro.bias_instability;
        let shuffled = BiasInstability::GaussMarkov {
            terms: [1e3, 0.1, 50.0, 0.1, 1e5, 2e-3, 50.0]
                .map(|tau_s: f64| GaussMarkov { sigma: 0.01 * tau_s.sqrt(), tau_s })
                .to_vec(),
        };
        for (bank, ascending) in [(flicker, true), (shuffled, false)] {
            let mut errors = InertialErrors::ideal(300.0);
            errors.bias_instability = bank;
            for update_ratio in [DEFAULT_GAUSS_MARKOV_UPDATE_RATIO, 1.0] {
                let mut fast = Triad::new(&errors, 11, SENSOR_GYRO, DT, update_ratio);
                assert_eq!(fast.shifts_ascending, ascending);
                let mut plain = fast.clone();
                let mut steps = Xoshiro256PlusPlus::seed_from_u64(5);
                let (mut last, mut restarts, mut multi_updates) = (0u64, 0, 0);
                for _ in 0..200_000 {
                    let k = match steps.gen_range(0..1000) {
                        0..=979 => last + 1,
                        980..=994 => last + steps.gen_range(2..1000),
                        995..=997 => last + steps.gen_range(1000..1 << 21),
                        _ => {
                            restarts += 1;
                            fast.next_update = 0;
                            steps.gen_range(0..=last)
                        }
                    };
                    if k > last {
                        multi_updates += usize::from(
                            (k >> fast.shortest_shift.unwrap_or(0)) - (last >> fast.shortest_shift.unwrap_or(0)) > 1,
                        );
                        fast.advance(last, k, DT);
                        update_every_term(&mut plain, last, k);
                        let states = |t: &Triad| {
                            t.gauss_markov.iter().flat_map(|g| g.state.map(f64::to_bits)).collect::<Vec<_>>()
                        };
                        assert_eq!(states(&fast), states(&plain), "move {last} -> {k}");
                        assert_eq!(fast.gauss_markov_sum.map(f64::to_bits), plain.gauss_markov_sum.map(f64::to_bits));
                    }
                    last = k;
                }
                assert!(
                    restarts > 100 && multi_updates > 1000,
                    "{restarts} restarts, {multi_updates} multi-update moves"
                );
            }
        }
    }

    #[test]
    fn each_triad_moves_as_if_it_were_alone() {
        // The model moves both triads when either is due (`next_bias_move`): a triad's output must
        // not depend on the other's schedule. Gyro: the flicker bank (shortest interval 8 samples);
        // accelerometer: terms of intervals 2 and 32 samples, then also a rate random walk (due every
        // sample). Each is compared with a model where the other triad is ideal, over single samples,
        // gaps, jumps and restarts.
        let mut params = ErrorParams::ideal();
        params.gyro.bias_instability = ErrorParams::adis16407().gyro.bias_instability;
        let accel_terms = [3.0, 40.0].map(|m: f64| GaussMarkov { sigma: 1e-3, tau_s: m * DT * 100.0 }).to_vec();
        params.accel.bias_instability = BiasInstability::GaussMarkov { terms: accel_terms };
        let mut walking = params.clone();
        walking.accel.rate_random_walk = 1e-4;
        for params in [params, walking] {
            let mut gyro_alone = params.clone();
            gyro_alone.accel = ErrorParams::ideal().accel;
            let mut accel_alone = params.clone();
            accel_alone.gyro = ErrorParams::ideal().gyro;
            let mut models = [&params, &gyro_alone, &accel_alone].map(|p| model(p, 3));
            let mut steps = Xoshiro256PlusPlus::seed_from_u64(8);
            let (mut k, mut last_accel) = (0u64, [0u64; 3]);
            for _ in 0..100_000 {
                let moved = match steps.gen_range(0..1000) {
                    0..=979 => 1,
                    980..=994 => steps.gen_range(2..1000),
                    995..=997 => steps.gen_range(1000..1 << 21),
                    _ => 0,
                };
                k = if moved == 0 { steps.gen_range(0..=k) } else { k + moved };
                let [both, gyro, accel] = models.each_mut().map(|m| {
                    let mut p = Physical { temp_c: REFERENCE_TEMP_C, ..Physical::default() };
                    m.apply(k, 0, &mut p);
                    (p.gyro_dps.map(f64::to_bits), p.accel_g.map(f64::to_bits))
                });
                assert_eq!(both.0, gyro.0, "gyro at sample {k}");
                assert_eq!(both.1, accel.1, "accelerometer at sample {k}");
                if params.accel.rate_random_walk > 0.0 && moved > 0 {
                    assert_ne!(accel.1, last_accel, "the walk stood still at sample {k}");
                }
                last_accel = accel.1;
            }
        }
    }

    #[test]
    fn update_ratio_is_checked_and_reaches_the_model_from_the_profile() {
        for bad_ratio in [0.5, f64::NAN, f64::INFINITY] {
            let errors = Errors { gauss_markov_update_ratio: bad_ratio, ..Errors::default() };
            let err = errors.validate().unwrap_err().to_string();
            assert!(err.contains("errors.gauss_markov_update_ratio"), "{err}");
            assert!(ErrorModel::from_profile(&errors, DT).is_err());
        }
        // R = 1e12 from the profile is the per-sample bank: the same realisation as ErrorModel::new
        // with that ratio, and another one than the default R.
        let errors = Errors { preset: "adis16407".into(), seed: 3, gauss_markov_update_ratio: 1e12 };
        let mut params = ErrorParams::adis16407();
        params.gauss_markov_update_ratio = 1e12;
        let per_sample = run(&mut ErrorModel::from_profile(&errors, DT).unwrap(), 200);
        assert_eq!(
            per_sample.iter().map(bits).collect::<Vec<_>>(),
            run(&mut model(&params, 3), 200).iter().map(bits).collect::<Vec<_>>()
        );
        let default = run(&mut model(&ErrorParams::adis16407(), 3), 200);
        assert_ne!(per_sample.iter().map(bits).collect::<Vec<_>>(), default.iter().map(bits).collect::<Vec<_>>());
    }

    #[test]
    fn sources_have_independent_streams() {
        // white only (A), white + bias processes + constants (B), bias processes + constants (C):
        // B − C must be A's noise, so adding sources did not change the white-noise realisation.
        let mut white = ErrorParams::ideal();
        white.gyro.noise_density = 0.03;
        let mut rest = ErrorParams::ideal();
        rest.gyro.initial_bias = Spread::normal(3.0);
        rest.gyro.bias_instability =
            BiasInstability::GaussMarkov { terms: vec![GaussMarkov { sigma: 0.1, tau_s: 0.5 }] };
        rest.gyro.rate_random_walk = 0.01;
        let mut both = rest.clone();
        both.gyro.noise_density = white.gyro.noise_density;
        let zero = || Physical { temp_c: 25.0, ..Physical::default() };
        let (mut a, mut b, mut c) = (model(&white, 5), model(&both, 5), model(&rest, 5));
        for k in 0..2000 {
            let (mut pa, mut pb, mut pc) = (zero(), zero(), zero());
            a.apply(k, 0, &mut pa);
            b.apply(k, 0, &mut pb);
            c.apply(k, 0, &mut pc);
            for i in 0..3 {
                assert!((pb.gyro_dps[i] - pc.gyro_dps[i] - pa.gyro_dps[i]).abs() < 1e-12);
            }
        }
        assert_eq!(b.gyro_unit().bias, c.gyro_unit().bias);
    }

    #[test]
    fn misalignment_is_a_small_angle_matrix_within_the_axis_to_axis_bound() {
        let params = ErrorParams::adis16407();
        let bound = 0.05f64.to_radians();
        let element = params.gyro.misalignment_deg.width.to_radians();
        let mut largest = 0.0f64;
        for seed in 0..200 {
            let mut only_misalignment = ErrorParams::ideal();
            only_misalignment.gyro.misalignment_deg = params.gyro.misalignment_deg;
            let mut m = model(&only_misalignment, seed);
            // Column j of M is the response to a unit rate about axis j.
            let columns: Vec<[f64; 3]> = (0..3)
                .map(|j| {
                    let mut p = Physical { temp_c: 25.0, ..Physical::default() };
                    p.gyro_dps[j] = 1.0;
                    m.apply(j as u64, 0, &mut p);
                    p.gyro_dps
                })
                .collect();
            let measured: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| columns[j][i]));
            assert_eq!(measured, m.gyro_unit().axes);
            for i in 0..3 {
                assert_eq!(measured[i][i], 1.0);
                for j in (0..3).filter(|&j| j != i) {
                    assert!(measured[i][j].abs() <= element);
                    // Angle between sensing axes i and j: 90° − (m_ij + m_ji) to second order.
                    let (ri, rj) = (measured[i], measured[j]);
                    let dot: f64 = (0..3).map(|c| ri[c] * rj[c]).sum();
                    let norm = |r: [f64; 3]| r.iter().map(|x| x * x).sum::<f64>().sqrt();
                    let deviation = PI / 2.0 - (dot / (norm(ri) * norm(rj))).acos();
                    assert!((deviation - (measured[i][j] + measured[j][i])).abs() < 3.0 * element * element);
                    assert!(deviation.abs() <= bound + 3.0 * element * element);
                    largest = largest.max(deviation.abs());
                }
            }
        }
        // The pair sum is triangular on ±0.05°: P(|sum| > 0.03°) = 0.16 per pair, 600 pairs seen.
        assert!(largest > 0.03f64.to_radians(), "largest axis-pair deviation {largest} rad");
    }

    #[test]
    fn g_sensitivity_and_temperature_effects_are_exactly_linear() {
        let mut params = ErrorParams::ideal();
        params.gyro.g_sensitivity = Spread::normal(0.05);
        params.gyro.bias_tempco = Spread::normal(0.01);
        params.accel.bias_tempco = Spread::normal(0.3e-3);
        let mut m = model(&params, 21);
        let g = m.gyro_unit().g_sensitivity;
        let c_gyro = m.gyro_unit().bias_tempco;
        let c_accel = m.accel_unit().bias_tempco;
        assert!(g.iter().flatten().all(|x| *x != 0.0));
        for (k, (force, temp)) in
            [([0.0, 0.0, -1.0], 25.0), ([0.3, -0.7, 2.5], 25.0), ([0.6, -1.4, 5.0], 40.0)].into_iter().enumerate()
        {
            let mut p = Physical { accel_g: force, temp_c: temp, ..Physical::default() };
            m.apply(k as u64, 0, &mut p);
            let dt = temp - REFERENCE_TEMP_C;
            for i in 0..3 {
                let expected = c_gyro[i] * dt + (g[i][0] * force[0] + g[i][1] * force[1] + g[i][2] * force[2]);
                assert_eq!(p.gyro_dps[i], expected, "gyro axis {i}");
                assert_eq!(p.accel_g[i], force[i] + c_accel[i] * dt, "accel axis {i}");
            }
        }
        // Doubling the force doubles the g-sensitivity output, bit for bit.
        let respond = |m: &mut ErrorModel, f: [f64; 3]| {
            let mut p = Physical { accel_g: f, temp_c: 25.0, ..Physical::default() };
            m.apply(0, 0, &mut p);
            p.gyro_dps
        };
        let once = respond(&mut m, [0.3, -0.7, 2.5]);
        let twice = respond(&mut m, [0.6, -1.4, 5.0]);
        assert_eq!(twice, once.map(|x| 2.0 * x));
    }

    #[test]
    fn nonlinearity_is_its_fraction_of_full_scale_at_full_scale() {
        let mut params = ErrorParams::ideal();
        params.gyro.nonlinearity = Spread::fixed(0.001);
        let mut m = model(&params, 1);
        let mut p = Physical { gyro_dps: [300.0, -300.0, 150.0], temp_c: 25.0, ..Physical::default() };
        m.apply(0, 0, &mut p);
        assert!((p.gyro_dps[0] - 300.3).abs() < 1e-12);
        assert!((p.gyro_dps[1] - (-299.7)).abs() < 1e-12);
        assert!((p.gyro_dps[2] - 150.075).abs() < 1e-12);
    }

    #[test]
    fn magnetometer_iron_and_barometer_noise() {
        let mut params = ErrorParams::ideal();
        params.mag.hard_iron_gauss = [0.01, -0.02, 0.03];
        params.mag.soft_iron = [[0.1, 0.0, 0.0], [0.0, 0.0, 0.05], [0.0, 0.0, 0.0]];
        let mut m = model(&params, 1);
        let mut p = Physical { mag_gauss: [0.2, 0.4, -0.6], ..Physical::default() };
        m.apply(0, 0, &mut p);
        let expected = [0.2 * 1.1 + 0.01, 0.4 - 0.6 * 0.05 - 0.02, -0.6 + 0.03];
        for (out, want) in p.mag_gauss.iter().zip(expected) {
            assert!((out - want).abs() < 1e-15);
        }
        let mut params = ErrorParams::ideal();
        params.baro.noise_rms_mbar = 0.027;
        let mut m = model(&params, 2);
        let n = 100_000;
        let power: f64 = (0..n)
            .map(|k| {
                let mut p = Physical { baro_mbar: 1000.0, ..Physical::default() };
                m.apply(k, 0, &mut p);
                (p.baro_mbar - 1000.0).powi(2)
            })
            .sum();
        let rms = (power / n as f64).sqrt();
        // 1000 mbar carries ~1e-13 mbar rounding, far below the 5σ bound 0.027·5/√(2n).
        assert!((rms / 0.027 - 1.0).abs() < 5.0 / (2.0 * n as f64).sqrt(), "baro rms {rms}");
        // Magnetometer white noise, per axis, with the same 5σ bound on the relative rms.
        let mut params = ErrorParams::ideal();
        params.mag.noise_rms_gauss = 1.15e-3;
        let mut m = model(&params, 3);
        let truth = [0.2, 0.4, -0.6];
        let mut power = [0.0; 3];
        for k in 0..n {
            let mut p = Physical { mag_gauss: truth, ..Physical::default() };
            m.apply(k, 0, &mut p);
            for axis in 0..3 {
                power[axis] += (p.mag_gauss[axis] - truth[axis]).powi(2);
            }
        }
        for power in power {
            let rms = (power / n as f64).sqrt();
            assert!((rms / 1.15e-3 - 1.0).abs() < 5.0 / (2.0 * n as f64).sqrt(), "magnetometer rms {rms}");
        }
    }

    #[test]
    fn gauss_markov_allan_peak_constants() {
        let (mut best, mut at) = (0.0, 0.0);
        for i in 0..200_000 {
            let x = 1.0 + i as f64 * 1e-5;
            let v = gauss_markov_avar(1.0, 1.0, x).sqrt();
            if v > best {
                (best, at) = (v, x);
            }
        }
        assert!((best - GAUSS_MARKOV_ALLAN_PEAK).abs() < 1e-9);
        assert!((at - GAUSS_MARKOV_ALLAN_PEAK_AT).abs() < 1e-4);
        // Series and closed form meet at the switch-over x = 0.01.
        let below = gauss_markov_avar(1.0, 1.0, 0.01 * (1.0 - 1e-12));
        let closed = gauss_markov_avar(1.0, 1.0, 0.01);
        assert!((below / closed - 1.0).abs() < 1e-10);
        let gm = gauss_markov_for_allan_peak(0.007, 100.0);
        assert!(
            (gauss_markov_avar(gm.sigma, gm.tau_s, GAUSS_MARKOV_ALLAN_PEAK_AT * 100.0).sqrt() - 0.007).abs() < 1e-12
        );
    }

    #[test]
    fn flicker_bank_has_a_flat_allan_floor() {
        let floor = 0.007;
        let bank = flicker_bank(floor, 1.0, 1e5, 1);
        assert_eq!(bank.len(), 6);
        assert!((bank[5].tau_s - 1e5).abs() < 1e-6);
        // Documented accuracy: within ±1.5 % for 20 τ_min ≤ T ≤ τ_max / 5.
        for i in 0..=60 {
            let t = 20.0 * 10f64.powf(i as f64 * 3.0 / 60.0);
            let adev = bank.iter().map(|g| gauss_markov_avar(g.sigma, g.tau_s, t)).sum::<f64>().sqrt();
            assert!((adev / floor - 1.0).abs() < 0.015, "T = {t} s: {adev}");
        }
    }

    #[test]
    fn presets_and_table() {
        assert!(ErrorParams::preset("adis16407").unwrap().validate().is_ok());
        let err = ErrorParams::preset("adis16405").unwrap_err().to_string();
        assert!(err.contains("errors.preset") && err.contains("adis16407"), "{err}");
        let rows = preset_table("adis16407").unwrap();
        let row = |q: &str| rows.iter().find(|r| r.quantity.starts_with(q)).unwrap();
        assert!((row("gyro angle random walk").value - 2.0).abs() < 1e-12);
        assert!(row("gyro angle random walk").unconfirmed);
        assert!((row("accel noise density").value - 0.5).abs() < 1e-12);
        assert!(!row("accel noise density").unconfirmed);
        // 0.5 mg/√Hz one-sided is 0.208 m/s/√h, the sibling's 0.2 m/s/√h within 4 %.
        assert!((row("accel velocity random walk").value - 0.208).abs() < 1e-3);
        assert!((row("gyro in-run bias stability").value - 0.007).abs() < 1e-15);
        assert!((row("accel in-run bias stability").value - 0.2).abs() < 1e-12);
        assert!((row("magnetometer noise").value - 1.15).abs() < 1e-12);
        assert!(rows.iter().all(|r| r.value.is_finite() && !r.source.is_empty()));
        let ideal = preset_table("ideal").unwrap();
        assert_eq!(ideal.len(), rows.len());
        assert!(ideal.iter().all(|r| !r.unconfirmed && (r.value == 0.0 || r.quantity.contains("full scale"))));
    }

    #[test]
    fn the_adis16362_table_names_its_own_sources() {
        let rows = preset_table("adis16362").unwrap();
        let row = |q: &str| rows.iter().find(|r| r.quantity.starts_with(q)).unwrap();
        // The notes' figures, confirmed by the wing-angle notes (the issue's numbers).
        for (q, v) in [("gyro initial bias", 3.0), ("gyro in-run bias stability", 0.007), ("gyro bias tempco", 0.01)] {
            assert!((row(q).value - v).abs() < 1e-15 && !row(q).unconfirmed && row(q).source.contains("notes"), "{q}");
        }
        assert!((row("accel velocity random walk").value - 0.12).abs() < 1e-12);
        assert!((row("accel in-run bias stability").value - 0.1).abs() < 1e-12);
        assert!((row("accel initial bias").value - 4.0).abs() < 1e-12);
        assert!((row("accel full scale").value - 1.7).abs() < 1e-15);
        assert_eq!(row("magnetometer noise").value, 0.0);
        // No row of the 16362 cites the 16407's data sheet as its own: each names the 16362's source,
        // a sibling marked unconfirmed, or a model choice.
        for r in &rows {
            assert!(!r.source.starts_with("ADIS16407 data sheet") || r.unconfirmed, "{}: {}", r.quantity, r.source);
            assert!(!r.source.contains("for the 16407"), "{}: {}", r.quantity, r.source);
        }
        assert!(rows.iter().filter(|r| r.source.to_lowercase().contains("adis16362")).count() >= 14);
    }

    #[test]
    fn invalid_parameters_name_their_key() {
        let mut params = ErrorParams::adis16407();
        params.accel.initial_bias.width = -1.0;
        let err = ErrorModel::new(&params, 1, DT).unwrap_err().to_string();
        assert!(err.contains("errors.accel.initial_bias.width"), "{err}");
        let mut params = ErrorParams::ideal();
        params.gyro.bias_instability =
            BiasInstability::Flicker { allan_floor: 0.007, tau_min_s: 10.0, tau_max_s: 1.0, terms_per_decade: 1 };
        let err = ErrorModel::new(&params, 1, DT).unwrap_err().to_string();
        assert!(err.contains("errors.gyro.bias_instability.tau_max_s"), "{err}");
        assert!(ErrorModel::new(&ErrorParams::ideal(), 1, 0.0).is_err());
    }

    #[test]
    fn params_round_trip_through_toml() {
        let params = ErrorParams::adis16407();
        let text = toml::to_string(&params).unwrap();
        let back: ErrorParams = toml::from_str(&text).unwrap();
        assert_eq!(back, params);
    }
}
