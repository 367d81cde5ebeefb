//! The running model: one unit's realised constants, its triads' stochastic state, and
//! [`ErrorModel`], which applies them sample by sample.

use super::*;

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
pub(super) struct GaussMarkovState {
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
pub(super) const MAX_UPDATE_SHIFT: u32 = 62;

/// log₂ of [`gauss_markov_update_interval`].
pub(super) fn update_shift(tau_s: f64, sample_period_s: f64, update_ratio: f64) -> u32 {
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
pub(super) fn gauss_markov_step(term: &GaussMarkov, dt_s: f64) -> (f64, f64) {
    let x = dt_s / term.tau_s;
    ((-x).exp(), term.sigma * (-(-2.0 * x).exp_m1()).sqrt())
}

/// The stochastic and fixed parts of one triad.
#[derive(Debug, Clone)]
pub(super) struct Triad {
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

/// The columns of `m` (rows of its transpose).
pub(super) fn transpose(m: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    std::array::from_fn(|j| std::array::from_fn(|i| m[i][j]))
}

/// Σ of the Gauss–Markov states per axis, in term order (so the sum is the same whatever the history).
pub(super) fn sum_states(terms: &[GaussMarkovState]) -> [f64; 3] {
    let mut sum = [0.0; 3];
    for term in terms {
        for (total, x) in sum.iter_mut().zip(term.state) {
            *total += x;
        }
    }
    sum
}

pub(super) fn draw_axes(spread: &Spread, rng: &mut StreamRng) -> [f64; 3] {
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

impl crate::device::SensorErrors for ErrorModel {
    fn apply(&mut self, k: u64, t: Ps, p: &mut Physical) {
        ErrorModel::apply(self, k, t, p);
    }
}

#[cfg(test)]
#[path = "tests.rs"]
mod tests;
