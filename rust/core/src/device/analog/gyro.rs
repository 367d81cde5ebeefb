//! A 3-axis analogue MEMS gyro: per axis V = V₀ + S·LP(ω_m), with the measured rate
//! ω_m = (1 + δk)·ω + k₂·ω|ω|/FS + b + b_T·(T − 25 °C) + n, clipped to ±FS, n white of one-sided
//! density N (°/s/√Hz), through the sensor's bandwidth LP. The unit's scale-factor error δk and
//! bias b are drawn once per seed (normal, the preset's 1σ); the rest is the preset's.

use super::{stream, LowPass, LowPassState, Scene};
use rand::Rng;
use rand_distr::StandardNormal;
use rand_xoshiro::Xoshiro256PlusPlus;

/// A gyro's data-sheet figures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GyroPreset {
    /// The preset's name.
    pub name: &'static str,
    /// Where its figures come from.
    pub source: &'static str,
    /// Sensitivity S, V per °/s.
    pub volts_per_dps: f64,
    /// Output at zero rate V₀, V.
    pub null_v: f64,
    /// Full scale FS, °/s (the measured rate clips at ±FS).
    pub full_scale_dps: f64,
    /// Unit-to-unit bias b, 1σ, °/s.
    pub bias_dps: f64,
    /// Bias temperature coefficient b_T, °/s per °C.
    pub bias_temp_dps_per_c: f64,
    /// Unit-to-unit scale-factor error δk, 1σ (fraction).
    pub scale_error: f64,
    /// Nonlinearity k₂: the bow at full scale as a fraction of FS.
    pub nonlinearity: f64,
    /// Rate noise density N, °/s/√Hz.
    pub noise_dps_rt_hz: f64,
    /// The sensor's bandwidth.
    pub bandwidth: LowPass,
}

impl GyroPreset {
    /// ADXRS300-like figures (±300 °/s, 5 mV/°/s, 0.1 °/s/√Hz, 40 Hz): [unconfirmed: ADXRS300 data
    /// sheet figures as remembered, not re-read; the paper names no gyro].
    pub const ADXRS300: GyroPreset = GyroPreset {
        name: "adxrs300",
        source: "[unconfirmed] ADXRS300 data sheet (Analog Devices) as remembered: 5 mV/°/s, ±300 °/s, \
                 null 2.5 V, 0.1 °/s/√Hz, 40 Hz, nonlinearity 0.1 % FS",
        volts_per_dps: 0.005,
        null_v: 2.5,
        full_scale_dps: 300.0,
        bias_dps: 1.0,
        bias_temp_dps_per_c: 0.01,
        scale_error: 0.01,
        nonlinearity: 0.001,
        noise_dps_rt_hz: 0.1,
        bandwidth: LowPass::FirstOrder { cutoff_hz: 40.0 },
    };

    /// A spin-rated gyro for the x axis of a spinning body (±1200 °/s at 1.6 mV/°/s, second-order
    /// 100 Hz, ζ 0.7): [unconfirmed: a chosen part; the paper's turntable runs to speeds it does
    /// not state, the issue asks for 0–1000 °/s].
    pub const SPIN1200: GyroPreset = GyroPreset {
        name: "spin1200",
        source: "[unconfirmed] chosen for 0–1000 °/s spin (issue): ±1200 °/s, 1.6 mV/°/s",
        volts_per_dps: 0.0016,
        null_v: 2.5,
        full_scale_dps: 1200.0,
        bias_dps: 1.0,
        bias_temp_dps_per_c: 0.02,
        scale_error: 0.005,
        nonlinearity: 0.001,
        noise_dps_rt_hz: 0.05,
        bandwidth: LowPass::SecondOrder { natural_hz: 100.0, damping: 0.7 },
    };

    /// The preset without errors (ideal sensor with the same sensitivity, range and bandwidth).
    pub fn ideal(self) -> GyroPreset {
        GyroPreset {
            bias_dps: 0.0,
            bias_temp_dps_per_c: 0.0,
            scale_error: 0.0,
            nonlinearity: 0.0,
            noise_dps_rt_hz: 0.0,
            ..self
        }
    }
}

/// Three axes of one gyro unit (x may be a different part from y, z).
#[derive(Debug, Clone)]
pub struct Gyro {
    presets: [GyroPreset; 3],
    /// The unit's drawn bias (°/s) and scale-factor error per axis.
    pub bias_dps: [f64; 3],
    /// The unit's drawn scale-factor errors.
    pub scale_error: [f64; 3],
    filters: [LowPassState; 3],
    rng: Xoshiro256PlusPlus,
    noise_sigma: [f64; 3],
}

impl Gyro {
    /// A unit of `presets` (x, y, z) drawn from `seed`, simulated on steps of `h` s.
    pub fn new(presets: [GyroPreset; 3], seed: u64, h: f64) -> Gyro {
        let mut draw = stream(seed, 0x6779_726F);
        let n = |r: &mut Xoshiro256PlusPlus| -> f64 { r.sample(StandardNormal) };
        let bias_dps = [0, 1, 2].map(|i| presets[i].bias_dps * n(&mut draw));
        let scale_error = [0, 1, 2].map(|i| presets[i].scale_error * n(&mut draw));
        Gyro {
            presets,
            bias_dps,
            scale_error,
            filters: presets.map(|p| LowPassState::new(p.bandwidth, h, 0.0)),
            rng: stream(seed, 0x6779_6E73),
            // White noise of one-sided density N held over steps of h: σ² = N²/(2h).
            noise_sigma: presets.map(|p| p.noise_dps_rt_hz / (2.0 * h).sqrt()),
        }
    }

    /// The measured rate before the bandwidth, °/s.
    fn measured(&self, i: usize, s: &Scene) -> f64 {
        let p = &self.presets[i];
        let w = s.rate_rad_s[i].to_degrees();
        let m = (1.0 + self.scale_error[i]) * w
            + p.nonlinearity * w * w.abs() / p.full_scale_dps
            + self.bias_dps[i]
            + p.bias_temp_dps_per_c * (s.temp_c - 25.0);
        m.clamp(-p.full_scale_dps, p.full_scale_dps)
    }

    /// Start at rest in `s` (each filter at its DC output).
    pub fn settle(&mut self, s: &Scene) {
        for i in 0..3 {
            let m = self.measured(i, s);
            self.filters[i].rest_at(m);
        }
    }

    /// One step of the simulation with the body in `s`.
    pub fn step(&mut self, s: &Scene) {
        for i in 0..3 {
            let noise = if self.noise_sigma[i] > 0.0 {
                self.noise_sigma[i] * self.rng.sample::<f64, _>(StandardNormal)
            } else {
                0.0
            };
            let m = self.measured(i, s) + noise;
            self.filters[i].step(m);
        }
    }

    /// The output voltages now.
    pub fn volts(&self) -> [f64; 3] {
        [0, 1, 2].map(|i| self.presets[i].null_v + self.presets[i].volts_per_dps * self.filters[i].output())
    }
}
