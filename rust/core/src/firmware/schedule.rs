//! The acquisition schedule: how the ISR's reads become the rate samples of an attitude update.
//!
//! An update takes n samples at t, t+T/(n−1), …, t+T (n from the algorithm: 3 for RK4, N+1 for the
//! rotation vector with N coning samples). The profile's `firmware.schedule` gathers them:
//! - `half-step`: a burst every timer tick, each the next sample; an update every n−1 ticks
//!   (T = (n−1) × the timer period), its last sample the next update's first;
//! - `endpoint`: a burst and an update every tick, the samples between the two ends linearly
//!   interpolated (the midpoint for RK4);
//! - `back-to-back`: n bursts in a row every tick, treated as the update's n sample times.

use super::{lit, Vec3};
use crate::numerics::{QClass, Scalar};
use crate::profile::Schedule;

/// Most samples an update of a registered algorithm takes (the 3-sample rotation vector).
pub const MAX_SAMPLES: usize = 4;

/// The samples of the update being gathered.
#[derive(Debug, Clone)]
pub struct RateSchedule<T> {
    kind: Schedule,
    /// Samples per update, n.
    n: usize,
    rates: [Vec3<T>; MAX_SAMPLES],
    have: usize,
}

impl<T: Scalar> RateSchedule<T> {
    /// The schedule `kind` for updates of `n` samples (2 ≤ n ≤ [`MAX_SAMPLES`]).
    pub fn new(kind: Schedule, n: usize) -> crate::Result<Self> {
        if !(2..=MAX_SAMPLES).contains(&n) {
            return Err(crate::Error::Config(format!(
                "acquisition schedule: an update of {n} samples, expected 2 to {MAX_SAMPLES}"
            )));
        }
        Ok(RateSchedule { kind, n, rates: [[lit(0.0); 3]; MAX_SAMPLES], have: 0 })
    }

    /// Bursts the ISR reads every tick.
    pub fn bursts_per_tick(&self) -> usize {
        match self.kind {
            Schedule::BackToBack => self.n,
            Schedule::HalfStep | Schedule::Endpoint => 1,
        }
    }

    /// The time the firmware takes burst `burst` of tick `tick` to stand for (s; timer period `period_s`).
    pub fn assumed_s(&self, tick: u64, burst: usize, period_s: f64) -> f64 {
        match self.kind {
            Schedule::HalfStep | Schedule::Endpoint => tick as f64 * period_s,
            // n bursts treated as t, t+T/(n−1), …, t+T of the update ending at this tick.
            Schedule::BackToBack => (tick as f64 - 1.0 + burst as f64 / (self.n - 1) as f64) * period_s,
        }
    }

    /// Add this tick's decoded rates (one per burst); true when an update's samples are complete
    /// ([`RateSchedule::rates`]), then [`RateSchedule::advance`] after the update. The second value
    /// is whether the firmware interpolated (the `endpoint` schedule's extra stage).
    pub fn add(&mut self, decoded: &[Vec3<T>]) -> (bool, bool) {
        let n = self.n;
        match self.kind {
            Schedule::HalfStep => {
                self.rates[self.have] = decoded[0];
                self.have += 1;
                if self.have == n {
                    self.have = 1; // the update's last sample is the next update's first
                    return (true, false);
                }
                (false, false)
            }
            Schedule::Endpoint => {
                if self.have == 0 {
                    self.rates[0] = decoded[0];
                    self.have = 1;
                    return (false, false);
                }
                let (a, b) = (self.rates[0], decoded[0]);
                interpolate(&a, &b, &mut self.rates[1..n - 1]);
                self.rates[n - 1] = b;
                (true, n > 2)
            }
            Schedule::BackToBack => {
                self.rates[..n].copy_from_slice(&decoded[..n]);
                (true, false)
            }
        }
    }

    /// The update's samples.
    pub fn rates(&self) -> &[Vec3<T>] {
        &self.rates[..self.n]
    }

    /// After an update: its last sample becomes the next update's first.
    pub fn advance(&mut self) {
        self.rates[0] = self.rates[self.n - 1];
    }
}

/// The samples between `a` (at t) and `b` (at t+T), equally spaced, into `out` (the interior
/// points of an update of `out.len() + 2` samples): the midpoint (a + b)·½ for RK4, a + (b − a)·i/(n−1)
/// otherwise.
pub fn interpolate<T: Scalar>(a: &Vec3<T>, b: &Vec3<T>, out: &mut [Vec3<T>]) {
    let intervals = out.len() + 1;
    for (k, o) in out.iter_mut().enumerate() {
        let i = k + 1;
        *o = if 2 * i == intervals {
            let half = T::from_f64(0.5, QClass::Generic);
            std::array::from_fn(|j| ((a[j] + b[j]) * half).to_class(QClass::Rate))
        } else {
            let w = T::from_f64(i as f64 / intervals as f64, QClass::Generic);
            std::array::from_fn(|j| (a[j] + (b[j] - a[j]) * w).to_class(QClass::Rate))
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_step_gathers_n_samples_over_n_minus_1_ticks() {
        for n in 2..=MAX_SAMPLES {
            let mut s = RateSchedule::<f64>::new(Schedule::HalfStep, n).unwrap();
            let mut updates = 0;
            for k in 0..(3 * (n - 1) + 1) {
                let (ready, interpolated) = s.add(&[[k as f64; 3]]);
                assert!(!interpolated);
                if ready {
                    updates += 1;
                    let want: Vec<f64> = (0..n).map(|i| (k + 1 - n + i) as f64).collect();
                    assert_eq!(s.rates().iter().map(|r| r[0]).collect::<Vec<_>>(), want, "n {n}");
                    s.advance();
                }
            }
            assert_eq!(updates, 3, "n {n}");
        }
    }

    #[test]
    fn endpoint_interpolates_equally_spaced_samples() {
        let mut s = RateSchedule::<f64>::new(Schedule::Endpoint, 4).unwrap();
        assert_eq!(s.add(&[[0.0; 3]]), (false, false));
        assert_eq!(s.add(&[[3.0; 3]]), (true, true));
        assert_eq!(s.rates().iter().map(|r| r[1]).collect::<Vec<_>>(), [0.0, 1.0, 2.0, 3.0]);
        s.advance();
        let mut s2 = RateSchedule::<f64>::new(Schedule::Endpoint, 2).unwrap();
        s2.add(&[[1.0; 3]]);
        assert_eq!(s2.add(&[[5.0; 3]]), (true, false));
        assert_eq!(s2.rates(), &[[1.0; 3], [5.0; 3]]);
    }

    #[test]
    fn back_to_back_reads_n_bursts_standing_for_the_sample_times() {
        let s = RateSchedule::<f64>::new(Schedule::BackToBack, 4).unwrap();
        assert_eq!(s.bursts_per_tick(), 4);
        let t: Vec<f64> = (0..4).map(|b| s.assumed_s(10, b, 0.006)).collect();
        for (b, x) in t.iter().enumerate() {
            assert!((x - (0.054 + 0.002 * b as f64)).abs() < 1e-15, "{t:?}");
        }
        assert!(RateSchedule::<f64>::new(Schedule::BackToBack, 5).is_err());
    }
}
