//! The device's own sample clock and what it samples: the [`Stimulus`] (the physical world at each
//! internal sample instant) and the [`SensorErrors`] hook applied before filtering.

use super::Physical;
use crate::error::{Error, Result};
use crate::time::{Clock, Ps};

/// SMPL_PRD[7] = 0 time base: 1638.4 Hz (0.61035 ms) = 16384/10 Hz.
const FAST_BASE: (u64, u64) = (16_384, 10);
/// SMPL_PRD[7] = 1 time base: 18.921 ms = 1e6/18921 Hz.
const SLOW_BASE: (u64, u64) = (1_000_000, 18_921);

/// The internal sample clock selected by SMPL_PRD: fs = base⁻¹/(NS + 1), skewed by `ppb`
/// (positive = fast). SMPL_PRD = 0x0001 gives exactly 819.2 SPS.
pub fn sample_clock(smpl_prd: u16, ppb: i64) -> Clock {
    let (num, den) = if smpl_prd & 0x80 != 0 { SLOW_BASE } else { FAST_BASE };
    let ns = u64::from(smpl_prd & 0x7F);
    Clock::new(num, den * (ns + 1)).skewed_ppb(ppb)
}

/// The physical world as the sensor sees it: asked once per internal sample, in order of `k`
/// (the device's sample index since power-on) at the sample instant `t`.
pub trait Stimulus {
    /// The physical quantities at sample `k`, time `t`.
    fn at(&mut self, k: u64, t: Ps) -> Physical;
}

/// The sensor error model, applied to the physical values of each sample before filtering and
/// encoding (the real model is written elsewhere; [`Ideal`] changes nothing).
pub trait SensorErrors {
    /// Corrupt `p`, the physical values of sample `k` at time `t`.
    fn apply(&mut self, k: u64, t: Ps, p: &mut Physical);
}

/// A sensor without errors.
#[derive(Debug, Clone, Copy, Default)]
pub struct Ideal;

impl SensorErrors for Ideal {
    fn apply(&mut self, _k: u64, _t: Ps, _p: &mut Physical) {}
}

/// The same physical state at every sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Constant(pub Physical);

impl Stimulus for Constant {
    fn at(&mut self, _k: u64, _t: Ps) -> Physical {
        self.0
    }
}

/// A stimulus computed by a closure of (sample index, time).
pub struct FnStimulus<F>(pub F);

impl<F: FnMut(u64, Ps) -> Physical> Stimulus for FnStimulus<F> {
    fn at(&mut self, k: u64, t: Ps) -> Physical {
        (self.0)(k, t)
    }
}

/// Samples already resampled at the device's own rate: sample `k` is `samples[k − first_index]`.
/// Outside the slice the nearest end is held and counted ([`SliceStimulus::held`]), so a trace that
/// is too short shows up in the counts instead of silently wrapping.
#[derive(Debug, Clone)]
pub struct SliceStimulus {
    samples: Vec<Physical>,
    first_index: u64,
    held: u64,
}

impl SliceStimulus {
    /// A stimulus over `samples`, the first of which is device sample `first_index`. Every value must
    /// be finite and the slice non-empty.
    pub fn new(samples: Vec<Physical>, first_index: u64) -> Result<Self> {
        if samples.is_empty() {
            return Err(Error::Input("device stimulus: no samples given".into()));
        }
        if let Some(row) = samples.iter().position(|p| !p.is_finite()) {
            return Err(Error::Input(format!("device stimulus: row {row} holds a non-finite value")));
        }
        Ok(SliceStimulus { samples, first_index, held: 0 })
    }

    /// How many samples were asked for outside the slice (and got the nearest end's value).
    pub fn held(&self) -> u64 {
        self.held
    }

    /// Number of samples in the slice.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// Always false: an empty slice is rejected by [`SliceStimulus::new`].
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }
}

impl Stimulus for SliceStimulus {
    fn at(&mut self, k: u64, _t: Ps) -> Physical {
        let last = self.samples.len() - 1;
        let i = k.saturating_sub(self.first_index);
        if k < self.first_index || i > last as u64 {
            self.held += 1;
        }
        self.samples[(i.min(last as u64)) as usize]
    }
}

/// When the samples happen: sample `epoch_k` is at `epoch_t`, sample `k ≥ epoch_k` at
/// `epoch_t + clock(k − epoch_k)`. A change of SMPL_PRD or a reset starts a new epoch.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Schedule {
    clock: Clock,
    epoch_t: Ps,
    epoch_k: u64,
    /// Index of the next sample to take.
    pub next_k: u64,
    /// Its time.
    pub next_t: Ps,
}

impl Schedule {
    /// Sample `first_k` at `first_t`, then one every clock period.
    pub fn new(clock: Clock, first_t: Ps, first_k: u64) -> Self {
        Schedule { clock, epoch_t: first_t, epoch_k: first_k, next_k: first_k, next_t: first_t }
    }

    /// The sample clock.
    pub fn clock(&self) -> Clock {
        self.clock
    }

    /// Time of sample `k` (not before the epoch).
    pub fn time_of(&self, k: u64) -> Ps {
        self.epoch_t + self.clock.cycles_to_ps(k.saturating_sub(self.epoch_k))
    }

    /// Move on to the next sample.
    pub fn step(&mut self) {
        self.next_k += 1;
        self.next_t = self.time_of(self.next_k);
    }

    /// A new epoch: the next sample is at `first_t`, then one every period of `clock`.
    pub fn restart(&mut self, clock: Clock, first_t: Ps) {
        *self = Schedule::new(clock, first_t, self.next_k);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::time::PS_PER_S;

    #[test]
    fn smpl_prd_rates() {
        assert_eq!(sample_clock(0x0001, 0), Clock::new(8192, 10));
        assert_eq!(sample_clock(0x0001, 0).hz(), 819.2);
        assert_eq!(sample_clock(0x0000, 0).hz(), 1638.4);
        assert!((sample_clock(0x0080, 0).period_s() - 18.921e-3).abs() < 1e-15);
        assert!((sample_clock(0x0083, 0).period_s() - 4.0 * 18.921e-3).abs() < 1e-15);
        assert!((sample_clock(0x007F, 0).hz() - 1638.4 / 128.0).abs() < 1e-12);
        // Bits above 7 do not matter.
        assert_eq!(sample_clock(0xFF01, 0), sample_clock(0x0001, 0));
    }

    #[test]
    fn skew_moves_samples() {
        let nominal = Schedule::new(sample_clock(1, 0), 0, 0);
        let fast = Schedule::new(sample_clock(1, 1000), 0, 0);
        // 819 200 samples take 1000 s nominally and 1000 s/(1 + 1e-6) = 1000 s − 0.999 999 000 999 ms
        // at +1 ppm, floored to the picosecond.
        assert_eq!(nominal.time_of(819_200), 1000 * PS_PER_S);
        assert_eq!(fast.time_of(819_200), 1000 * PS_PER_S - 999_999_001);
    }

    #[test]
    fn schedule_restart_keeps_the_index() {
        let mut s = Schedule::new(sample_clock(1, 0), 5_000_000, 0);
        assert_eq!(s.next_t, 5_000_000);
        s.step();
        assert_eq!((s.next_k, s.next_t), (1, 5_000_000 + 1_220_703_125));
        s.restart(sample_clock(0, 0), 2_000_000_000);
        assert_eq!((s.next_k, s.next_t), (1, 2_000_000_000));
        s.step();
        assert_eq!(s.next_t, 2_000_000_000 + 610_351_562);
    }

    #[test]
    fn slice_stimulus_holds_and_counts() {
        let mk = |v: f64| Physical { gyro_dps: [v, 0.0, 0.0], ..Physical::default() };
        let mut s = SliceStimulus::new(vec![mk(1.0), mk(2.0), mk(3.0)], 10).unwrap();
        assert_eq!(s.at(9, 0).gyro_dps[0], 1.0);
        assert_eq!(s.at(10, 0).gyro_dps[0], 1.0);
        assert_eq!(s.at(12, 0).gyro_dps[0], 3.0);
        assert_eq!(s.at(13, 0).gyro_dps[0], 3.0);
        assert_eq!(s.held(), 2);
        assert!(SliceStimulus::new(vec![], 0).is_err());
        assert!(SliceStimulus::new(vec![mk(f64::NAN)], 0).is_err());
    }

    #[test]
    fn fn_stimulus_sees_index_and_time() {
        let mut s = FnStimulus(|k: u64, t: Ps| Physical { gyro_dps: [k as f64, t as f64, 0.0], ..Physical::default() });
        assert_eq!(s.at(3, 7).gyro_dps, [3.0, 7.0, 0.0]);
    }
}
