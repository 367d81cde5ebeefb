//! The error model's parameters: the terms of a triad (spreads over units, Gauss–Markov terms,
//! the flicker bank of bias instability), of the magnetometer and the barometer, the presets as
//! values ([`ErrorParams::preset`]), the profile's overrides, and their checks.

use super::*;

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

    pub(super) fn is_zero(&self) -> bool {
        self.mean == 0.0 && self.width == 0.0
    }

    pub(super) fn draw(&self, rng: &mut StreamRng) -> f64 {
        let u: f64 = match self.distribution {
            Distribution::Normal => standard_normal(rng),
            Distribution::Uniform => rng.gen_range(-1.0..1.0),
        };
        self.mean + self.width * u
    }

    pub(super) fn validate(&self, key: &str) -> Result<()> {
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

pub(super) fn flicker_intervals(tau_min_s: f64, tau_max_s: f64, terms_per_decade: u32) -> usize {
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

    pub(super) fn validate(&self, key: &str) -> Result<()> {
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

    pub(super) fn is_ideal(&self) -> bool {
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

    pub(super) fn validate(&self, key: &str) -> Result<()> {
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

pub(super) fn default_update_ratio() -> f64 {
    DEFAULT_GAUSS_MARKOV_UPDATE_RATIO
}

impl Default for ErrorParams {
    fn default() -> Self {
        ErrorParams::ideal()
    }
}

/// Gyro full scale of the default ±300 °/s range.
pub(super) const GYRO_FULL_SCALE_DPS: f64 = 300.0;
/// Accelerometer full scale, g.
pub(super) const ACCEL_FULL_SCALE_G: f64 = 18.0;

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

    pub(super) fn is_ideal(&self) -> bool {
        self.gyro.is_ideal()
            && self.accel.is_ideal()
            && self.mag.hard_iron_gauss == [0.0; 3]
            && self.mag.soft_iron == [[0.0; 3]; 3]
            && self.mag.noise_rms_gauss == 0.0
            && self.baro.noise_rms_mbar == 0.0
    }
}

pub(super) fn bad(key: &str, value: impl std::fmt::Display, expected: &str) -> Error {
    Error::Profile(format!("key `{key}` = {value}: expected {expected}"))
}

pub(super) fn check_finite(key: &str, value: f64) -> Result<()> {
    if !value.is_finite() {
        return Err(bad(key, value, "a finite number"));
    }
    Ok(())
}

pub(super) fn check_nonneg(key: &str, value: f64) -> Result<()> {
    if !(value.is_finite() && value >= 0.0) {
        return Err(bad(key, value, "a finite number ≥ 0"));
    }
    Ok(())
}

pub(super) fn check_pos(key: &str, value: f64) -> Result<()> {
    if !(value.is_finite() && value > 0.0) {
        return Err(bad(key, value, "a finite number > 0"));
    }
    Ok(())
}
