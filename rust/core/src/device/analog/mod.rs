//! Analogue sensors feeding the ADS8344's channels on the geomagnetic–gyro board: a 3-axis MEMS
//! gyro ([`gyro`]) and a 3-axis magnetometer ([`magnetometer`]), each an output voltage per axis
//! through its own bandwidth ([`LowPass`]), and the board's front end ([`FrontEnd`]) that maps them
//! onto the converter's inputs (`ads8344::AnalogInputs`).
//!
//! The sensors are simulated on a fixed internal step (`FrontEnd::STEP_S`, 20 kHz: ≥ 200× the gyros'
//! bandwidths, 20× the magnetometer's 1 kHz; each low-pass is discretised exactly for a step-held
//! input, held at the step's middle, which leaves a first-order low-pass ω_c h²/12 more delay than
//! 1/ω_c: 1.3 µs on the magnetometer's 159 µs, 0.8 %, measured in `geomag_chain`); a voltage asked
//! for between two steps is interpolated linearly (error ≤ h²·|v̈|/8: 2e-9 of the amplitude for a
//! 2.8 Hz signal). Every random draw comes from the seed: the same seed gives the same voltages.

pub mod gyro;
pub mod magnetometer;

pub use gyro::{Gyro, GyroPreset};
pub use magnetometer::{Magnetometer, MagnetometerPreset};

use super::ads8344::AnalogInputs;
use crate::time::{ps_to_s, Ps};
use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

/// A sensor's bandwidth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LowPass {
    /// H(s) = 1/(1 + s/ω_c), ω_c = 2π·`cutoff_hz`.
    FirstOrder {
        /// −3 dB frequency, Hz.
        cutoff_hz: f64,
    },
    /// H(s) = ω_n²/(s² + 2ζω_n s + ω_n²), ω_n = 2π·`natural_hz`.
    SecondOrder {
        /// Natural frequency, Hz.
        natural_hz: f64,
        /// Damping ratio.
        damping: f64,
    },
}

impl LowPass {
    /// The phase lag at `f_hz`, rad: atan(f/f_c) (first order), atan2(2ζ r, 1 − r²), r = f/f_n
    /// (second order).
    pub fn phase_lag(&self, f_hz: f64) -> f64 {
        match *self {
            LowPass::FirstOrder { cutoff_hz } => (f_hz / cutoff_hz).atan(),
            LowPass::SecondOrder { natural_hz, damping } => {
                let r = f_hz / natural_hz;
                (2.0 * damping * r).atan2(1.0 - r * r)
            }
        }
    }

    /// The gain at `f_hz`.
    pub fn gain(&self, f_hz: f64) -> f64 {
        match *self {
            LowPass::FirstOrder { cutoff_hz } => 1.0 / (1.0 + (f_hz / cutoff_hz).powi(2)).sqrt(),
            LowPass::SecondOrder { natural_hz, damping } => {
                let r = f_hz / natural_hz;
                1.0 / ((1.0 - r * r).powi(2) + (2.0 * damping * r).powi(2)).sqrt()
            }
        }
    }

    /// The group delay at DC, τ_g = −H'(0), s: 1/ω_c (first order), 2ζ/ω_n (second order). A ramp
    /// input comes out exactly τ_g late once the transient has gone; the phase lag at a frequency ω
    /// is ω·τ_g + O(ω³).
    pub fn group_delay_s(&self) -> f64 {
        let tau = std::f64::consts::TAU;
        match *self {
            LowPass::FirstOrder { cutoff_hz } => 1.0 / (tau * cutoff_hz),
            LowPass::SecondOrder { natural_hz, damping } => 2.0 * damping / (tau * natural_hz),
        }
    }

    /// The equivalent noise bandwidth, Hz (white noise of one-sided density N through the filter has
    /// variance N²·B): π f_c / 2 (first order), π f_n / (4ζ) (second order).
    pub fn noise_bandwidth_hz(&self) -> f64 {
        match *self {
            LowPass::FirstOrder { cutoff_hz } => std::f64::consts::PI * cutoff_hz / 2.0,
            LowPass::SecondOrder { natural_hz, damping } => std::f64::consts::PI * natural_hz / (4.0 * damping),
        }
    }
}

/// A low-pass filter's state, discretised exactly for an input held over each step `h` (zero-order
/// hold): first order y ← y + (1 − e^(−h ω_c))(u − y); second order through the matrix exponential
/// of its companion form (worked out once).
#[derive(Debug, Clone, Copy)]
pub struct LowPassState {
    /// x ← A x + B u, y = x[0].
    a: [[f64; 2]; 2],
    b: [f64; 2],
    x: [f64; 2],
}

impl LowPassState {
    /// The filter at rest at output `y0` (its DC state for input `y0`).
    pub fn new(lp: LowPass, h: f64, y0: f64) -> LowPassState {
        let tau = std::f64::consts::TAU;
        let (a, b) = match lp {
            LowPass::FirstOrder { cutoff_hz } => {
                let e = (-h * tau * cutoff_hz).exp();
                ([[e, 0.0], [0.0, 0.0]], [1.0 - e, 0.0])
            }
            LowPass::SecondOrder { natural_hz, damping } => {
                // ẋ = [[0, 1], [−ω², −2ζω]] x + [0, ω²] u; A = e^(Mh) by scaling and squaring of
                // its Taylor series, B = M⁻¹(A − I)·[0, ω²] = (I − A)·[1, 0] (DC gain 1).
                let w = tau * natural_hz;
                let m = [[0.0, 1.0], [-w * w, -2.0 * damping * w]];
                let a = expm2(m, h);
                ([[a[0][0], a[0][1]], [a[1][0], a[1][1]]], [1.0 - a[0][0], -a[1][0]])
            }
        };
        LowPassState { a, b, x: [y0, 0.0] }
    }

    /// At rest at output `y0`.
    pub fn rest_at(&mut self, y0: f64) {
        self.x = [y0, 0.0];
    }

    /// The output now.
    pub fn output(&self) -> f64 {
        self.x[0]
    }

    /// One step with input `u` held over it; returns the output at the step's end.
    pub fn step(&mut self, u: f64) -> f64 {
        let [x0, x1] = self.x;
        self.x = [
            self.a[0][0] * x0 + self.a[0][1] * x1 + self.b[0] * u,
            self.a[1][0] * x0 + self.a[1][1] * x1 + self.b[1] * u,
        ];
        self.x[0]
    }
}

/// e^(M h) of a 2×2 matrix: scaling and squaring of a 12-term Taylor series.
fn expm2(m: [[f64; 2]; 2], h: f64) -> [[f64; 2]; 2] {
    let mul = |p: [[f64; 2]; 2], q: [[f64; 2]; 2]| {
        [
            [p[0][0] * q[0][0] + p[0][1] * q[1][0], p[0][0] * q[0][1] + p[0][1] * q[1][1]],
            [p[1][0] * q[0][0] + p[1][1] * q[1][0], p[1][0] * q[0][1] + p[1][1] * q[1][1]],
        ]
    };
    let norm = m.iter().flatten().map(|x| (x * h).abs()).sum::<f64>();
    let squarings = norm.log2().ceil().max(0.0) as i32 + 4;
    let s = h / f64::powi(2.0, squarings);
    let ms = m.map(|r| r.map(|x| x * s));
    let mut term = [[1.0, 0.0], [0.0, 1.0]];
    let mut sum = term;
    for k in 1..=12 {
        term = mul(term, ms).map(|r| r.map(|x| x / k as f64));
        for i in 0..2 {
            for j in 0..2 {
                sum[i][j] += term[i][j];
            }
        }
    }
    for _ in 0..squarings {
        sum = mul(sum, sum);
    }
    sum
}

/// The generator of one random stream of a sensor: seed and stream id mixed (SplitMix64).
pub(crate) fn stream(seed: u64, id: u64) -> Xoshiro256PlusPlus {
    let mix = |mut z: u64| {
        z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    };
    Xoshiro256PlusPlus::seed_from_u64(mix(mix(seed) ^ id))
}

/// What the board's sensors see at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Scene {
    /// Angular rate of the body about its x, y, z axes, rad/s.
    pub rate_rad_s: [f64; 3],
    /// The magnetic field along the body's axes, gauss.
    pub field_gauss: [f64; 3],
    /// The board's temperature, °C.
    pub temp_c: f64,
}

/// The board's front end: the gyro on CH0–CH2, the magnetometer on CH3–CH5, a temperature sensor
/// on CH6 (0.5 V + 10 mV/°C [unconfirmed: a TMP36-like part; the paper's board is not published]),
/// VREF/2 on CH7 (a ratiometric check).
pub struct FrontEnd<F> {
    scene: F,
    gyro: Gyro,
    mag: Magnetometer,
    vref_v: f64,
    /// Internal step index of `now` and the outputs at steps k−1 and k (CH0–CH6).
    k: u64,
    prev: [f64; 7],
    now: [f64; 7],
}

impl<F: FnMut(f64) -> Scene> FrontEnd<F> {
    /// The internal simulation step, s (20 kHz).
    pub const STEP_S: f64 = 50e-6;

    /// The board's sensors seeing `scene(t_s)`, the ADC's reference `vref_v`.
    pub fn new(mut scene: F, gyro: Gyro, mag: Magnetometer, vref_v: f64) -> FrontEnd<F> {
        let s = scene(0.0);
        let mut fe = FrontEnd { scene, gyro, mag, vref_v, k: 0, prev: [0.0; 7], now: [0.0; 7] };
        fe.gyro.settle(&s);
        fe.mag.settle(&s);
        fe.now = fe.outputs(&s);
        fe.prev = fe.now;
        fe
    }

    fn outputs(&self, s: &Scene) -> [f64; 7] {
        let g = self.gyro.volts();
        let m = self.mag.volts();
        [g[0], g[1], g[2], m[0], m[1], m[2], 0.5 + 0.01 * s.temp_c]
    }

    /// Run the sensors to the step at or after `t_s`.
    fn advance(&mut self, t_s: f64) {
        while (self.k as f64) * Self::STEP_S < t_s {
            // The input over step k → k+1 is held at its value at the step's middle.
            let s = (self.scene)((self.k as f64 + 0.5) * Self::STEP_S);
            self.gyro.step(&s);
            self.mag.step(&s);
            self.prev = self.now;
            self.now = self.outputs(&s);
            self.k += 1;
        }
    }
}

impl<F: FnMut(f64) -> Scene> AnalogInputs for FrontEnd<F> {
    fn volts(&mut self, channel: usize, t: Ps) -> f64 {
        if channel == 7 {
            return self.vref_v / 2.0;
        }
        let t_s = ps_to_s(t);
        self.advance(t_s);
        // Between steps k−1 and k (a time before step k−1 holds the earliest kept value).
        let frac = ((t_s / Self::STEP_S) - (self.k as f64 - 1.0)).clamp(0.0, 1.0);
        self.prev[channel] + frac * (self.now[channel] - self.prev[channel])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The discretised filters follow their continuous step responses exactly (ZOH input is exact
    /// for a step): first order 1 − e^(−t ω_c); second order (ζ < 1) 1 − e^(−ζωt)(cos ω_d t +
    /// ζω/ω_d sin ω_d t).
    #[test]
    fn low_pass_step_responses_are_exact() {
        let h = 50e-6;
        let mut f1 = LowPassState::new(LowPass::FirstOrder { cutoff_hz: 40.0 }, h, 0.0);
        let (fnat, z) = (80.0, 0.6);
        let mut f2 = LowPassState::new(LowPass::SecondOrder { natural_hz: fnat, damping: z }, h, 0.0);
        let w = std::f64::consts::TAU * fnat;
        let wd = w * (1.0 - z * z).sqrt();
        for k in 1..=2000 {
            let t = k as f64 * h;
            let y1 = f1.step(1.0);
            let y2 = f2.step(1.0);
            let e1 = 1.0 - (-t * std::f64::consts::TAU * 40.0).exp();
            let e2 = 1.0 - (-z * w * t).exp() * ((wd * t).cos() + z * w / wd * (wd * t).sin());
            assert!((y1 - e1).abs() < 1e-12 && (y2 - e2).abs() < 1e-10, "{k}: {y1} {e1} {y2} {e2}");
        }
    }

    /// Phase lag and gain formulas against the filters driven by a sine (steady state, 2.78 Hz).
    #[test]
    fn phase_and_gain_of_a_sine() {
        let h = 50e-6;
        let f = 1.0 / 0.36; // 1000 °/s of spin
        for lp in [LowPass::FirstOrder { cutoff_hz: 40.0 }, LowPass::SecondOrder { natural_hz: 60.0, damping: 0.7 }] {
            let mut s = LowPassState::new(lp, h, 0.0);
            let (mut c, mut q) = (0.0, 0.0);
            let n = 144_000; // 20 periods of 7200 steps exactly; the last 10 demodulated
            let w = std::f64::consts::TAU * f;
            for k in 0..n {
                // The input held over a step is the sine at its middle (the front end's rule): a
                // staircase centred on the sine, no delay, gain sinc(ωh/2) = 1 − 8e-9. The output
                // at the step's end is compared with the sine there.
                let y = s.step((w * (k as f64 + 0.5) * h).sin());
                if k >= n / 2 {
                    let t = (k as f64 + 1.0) * h;
                    c += y * (w * t).cos();
                    q += y * (w * t).sin();
                }
            }
            let m = (n - n / 2) as f64 / 2.0;
            let (gain, lag) = ((c * c + q * q).sqrt() / m, -(c.atan2(q)));
            // Whole periods demodulate exactly; what is left is the start transient (decayed by
            // e^(−ω_c·3.6 s)) and the staircase's 8e-9: 1e-6 bounds both.
            assert!((gain - lp.gain(f)).abs() < 1e-6, "{lp:?} gain {gain}");
            assert!((lag - lp.phase_lag(f)).abs() < 1e-6, "{lp:?} lag {lag} vs {}", lp.phase_lag(f));
        }
    }

    fn spinning(rate_dps: f64) -> impl FnMut(f64) -> Scene {
        move |t| {
            let w = rate_dps.to_radians();
            let (s, c) = (w * t).sin_cos();
            // 0.5 gauss across the spin axis, 0.2 gauss along it.
            Scene { rate_rad_s: [w, 0.0, 0.0], field_gauss: [0.2, 0.5 * c, -0.5 * s], temp_c: 25.0 }
        }
    }

    /// Ideal sensors: the gyro's x output is V₀ + S·ω; the magnetometer's y, z follow the rotating
    /// field through the 1 kHz bandwidth (gain 1 − 4e-6, lag 2.8e-3 rad at 2.78 Hz: the bound
    /// 1e-5·0.5 V + 0.5 V·2.8e-3); CH6 the temperature, CH7 VREF/2. The same seed gives the same
    /// voltages, another seed others.
    #[test]
    fn front_end_voltages() {
        let ideal = |seed| {
            FrontEnd::new(
                spinning(1000.0),
                Gyro::new(
                    [GyroPreset::SPIN1200.ideal(), GyroPreset::ADXRS300.ideal(), GyroPreset::ADXRS300.ideal()],
                    seed,
                    50e-6,
                ),
                Magnetometer::new(MagnetometerPreset::AMR.ideal(), seed, 50e-6),
                5.0,
            )
        };
        let mut fe = ideal(1);
        let t = 1_000_000_000_000; // 1 s
        assert!((fe.volts(0, t) - (2.5 + 1.6)).abs() < 1e-12);
        assert!((fe.volts(1, t) - 2.5).abs() < 1e-15);
        let c = (1000f64.to_radians() * 1.0).cos();
        assert!((fe.volts(4, t) - (2.5 + 0.5 * c)).abs() < 0.5 * (1e-5 + 2.8e-3));
        assert!((fe.volts(6, t) - 0.75).abs() < 1e-15 && fe.volts(7, t) == 2.5);
        let real = |seed| {
            let mut fe = FrontEnd::new(
                spinning(500.0),
                Gyro::new([GyroPreset::SPIN1200; 3], seed, 50e-6),
                Magnetometer::new(MagnetometerPreset::AMR, seed, 50e-6),
                5.0,
            );
            (0..200).map(|k| fe.volts(k % 7, k as u64 * 1_000_000_000)).collect::<Vec<f64>>()
        };
        assert_eq!(real(7), real(7));
        assert_ne!(real(7), real(8));
    }

    /// Noise: a gyro with only its noise, at rest, sampled every 20 ms (5 correlation times of the
    /// 40 Hz low-pass: independent samples), has σ = N·√B, B = π·40/2 Hz the noise bandwidth. With
    /// n = 20 000 samples the estimate's relative 1σ is 1/√(2n) = 0.5 %: the test allows 2.5 % (5σ).
    #[test]
    fn gyro_noise_through_its_bandwidth() {
        let p = GyroPreset { noise_dps_rt_hz: 0.1, ..GyroPreset::ADXRS300.ideal() };
        let mut fe = FrontEnd::new(
            spinning(0.0),
            Gyro::new([p; 3], 3, 50e-6),
            Magnetometer::new(MagnetometerPreset::AMR.ideal(), 3, 50e-6),
            5.0,
        );
        let n = 20_000;
        let x: Vec<f64> = (1..=n).map(|k| (fe.volts(2, k * 20_000_000_000) - 2.5) / 0.005).collect();
        let var = x.iter().map(|v| v * v).sum::<f64>() / n as f64;
        let expected = 0.1 * p.bandwidth.noise_bandwidth_hz().sqrt();
        assert!((var.sqrt() / expected - 1.0).abs() < 0.025, "{} vs {expected}", var.sqrt());
    }
}
