//! A 3-axis analogue magnetometer: per axis V = V₀ + S·LP(B + o + n), B the field along the axis
//! (gauss), o the unit's offset (drawn once per seed, normal with the preset's 1σ), n white of
//! one-sided density N (gauss/√Hz), through the sensor's bandwidth LP.

use super::{stream, LowPass, LowPassState, Scene};
use rand::Rng;
use rand_distr::StandardNormal;
use rand_xoshiro::Xoshiro256PlusPlus;

/// A magnetometer's figures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MagnetometerPreset {
    /// The preset's name.
    pub name: &'static str,
    /// Where its figures come from.
    pub source: &'static str,
    /// Sensitivity S after the bridge amplifier, V per gauss.
    pub volts_per_gauss: f64,
    /// Output at zero field V₀, V.
    pub null_v: f64,
    /// Unit offset o, 1σ, gauss.
    pub offset_gauss: f64,
    /// Noise density N, gauss/√Hz.
    pub noise_gauss_rt_hz: f64,
    /// The sensor's bandwidth (with its amplifier).
    pub bandwidth: LowPass,
}

impl MagnetometerPreset {
    /// An AMR bridge (HMC1043-like) behind an amplifier giving 1 V/gauss around 2.5 V, 1 kHz
    /// first-order [unconfirmed: the paper names no magnetometer; bridge noise and amplifier are a
    /// choice].
    pub const AMR: MagnetometerPreset = MagnetometerPreset {
        name: "amr",
        source: "[unconfirmed] AMR bridge + amplifier chosen for the board: 1 V/gauss, 1 kHz, 1 mgauss offset, \
                 20 µgauss/√Hz",
        volts_per_gauss: 1.0,
        null_v: 2.5,
        offset_gauss: 1e-3,
        noise_gauss_rt_hz: 20e-6,
        bandwidth: LowPass::FirstOrder { cutoff_hz: 1000.0 },
    };

    /// The preset without errors.
    pub fn ideal(self) -> MagnetometerPreset {
        MagnetometerPreset { offset_gauss: 0.0, noise_gauss_rt_hz: 0.0, ..self }
    }
}

/// Three axes of one magnetometer unit.
#[derive(Debug, Clone)]
pub struct Magnetometer {
    preset: MagnetometerPreset,
    /// The unit's drawn offsets, gauss.
    pub offset_gauss: [f64; 3],
    filters: [LowPassState; 3],
    rng: Xoshiro256PlusPlus,
    noise_sigma: f64,
}

impl Magnetometer {
    /// A unit of `preset` drawn from `seed`, simulated on steps of `h` s.
    pub fn new(preset: MagnetometerPreset, seed: u64, h: f64) -> Magnetometer {
        let mut draw = stream(seed, 0x6D61_676F);
        let offset_gauss = [(); 3].map(|()| preset.offset_gauss * draw.sample::<f64, _>(StandardNormal));
        Magnetometer {
            preset,
            offset_gauss,
            filters: [(); 3].map(|()| LowPassState::new(preset.bandwidth, h, 0.0)),
            rng: stream(seed, 0x6D61_6E73),
            noise_sigma: preset.noise_gauss_rt_hz / (2.0 * h).sqrt(),
        }
    }

    /// Start at rest in `s`.
    pub fn settle(&mut self, s: &Scene) {
        for i in 0..3 {
            self.filters[i].rest_at(s.field_gauss[i] + self.offset_gauss[i]);
        }
    }

    /// One step with the body in `s`.
    pub fn step(&mut self, s: &Scene) {
        for i in 0..3 {
            let noise =
                if self.noise_sigma > 0.0 { self.noise_sigma * self.rng.sample::<f64, _>(StandardNormal) } else { 0.0 };
            self.filters[i].step(s.field_gauss[i] + self.offset_gauss[i] + noise);
        }
    }

    /// The output voltages now.
    pub fn volts(&self) -> [f64; 3] {
        self.filters.map(|f| self.preset.null_v + self.preset.volts_per_gauss * f.output())
    }
}
