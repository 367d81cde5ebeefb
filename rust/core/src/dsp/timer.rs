//! CPU timer 0: the counter decrements once every TDDR+1 SYSCLKOUT cycles and reloads from PRD
//! when it passes zero, so one interrupt period is (PRD+1)(TDDR+1) SYSCLKOUT cycles. Tick `k`
//! (the k-th TINT0) happens exactly k periods after the timer starts, in integer picoseconds.

use crate::error::{Error, Result};
use crate::profile;
use crate::time::{Clock, Ps};

/// How the firmware's ConfigCpuTimer turns a period in µs into PRD.
///
/// TI's C2000Ware code writes `PRD = MHz·µs − 1` ("counter decrements PRD+1 times each period");
/// the DSP2833x header-file releases of the thesis' era (v1.x) wrote `PRD = MHz·µs`, which makes
/// every period one SYSCLKOUT cycle longer than asked (4000.0067 µs instead of 4000 µs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PrdRule {
    /// `PRD = SYSCLKOUT_MHz·µs/(TDDR+1) − 1`: the period is exactly what was asked (C2000Ware).
    MinusOne,
    /// `PRD = SYSCLKOUT_MHz·µs/(TDDR+1)`: one prescaled count longer (DSP2833x headers v1.x).
    Legacy,
}

/// CPU timer 0 configured as the firmware configures it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CpuTimer {
    sysclkout: Clock,
    /// Period register.
    pub prd: u32,
    /// Prescaler TDDRH:TDDR.
    pub tddr: u32,
    /// SYSCLKOUT cycle at which the timer was started (TSS cleared).
    pub start_cycle: u64,
}

impl CpuTimer {
    /// Timer 0 as the profile's ConfigCpuTimer call sets it (TI's current rule, `PRD = MHz·µs − 1`).
    pub fn from_profile(timer: &profile::Timer, sysclkout: Clock) -> Result<CpuTimer> {
        CpuTimer::with_rule(timer, sysclkout, PrdRule::MinusOne)
    }

    /// Timer 0 with an explicit PRD rule. The requested cycles are truncated like TI's
    /// `(long)(Freq * Period)`.
    pub fn with_rule(timer: &profile::Timer, sysclkout: Clock, rule: PrdRule) -> Result<CpuTimer> {
        if !(timer.period_us.is_finite() && timer.period_us > 0.0) {
            return Err(Error::Config(format!("timer.period_us = {}: expected a finite period > 0", timer.period_us)));
        }
        if timer.tddr > 0xFFFF {
            return Err(Error::Config(format!("timer.tddr = {}: TDDRH:TDDR is 16 bits (0…65535)", timer.tddr)));
        }
        // The period in whole picoseconds (exact for any period given to 1e-6 µs), then the whole
        // SYSCLKOUT cycles it spans: MHz·µs, truncated.
        let period_ps = (timer.period_us * 1e6).round();
        if period_ps >= u64::MAX as f64 {
            return Err(Error::Config(format!("timer.period_us = {}: too long for the timer", timer.period_us)));
        }
        let cycles = sysclkout.ps_to_cycles(period_ps as Ps);
        let per_count = timer.tddr as u64 + 1;
        let counts = cycles / per_count;
        let prd = match rule {
            PrdRule::MinusOne => counts.checked_sub(1),
            PrdRule::Legacy => Some(counts),
        };
        match prd {
            Some(prd) if (1..=u32::MAX as u64).contains(&prd) => {
                Ok(CpuTimer { sysclkout, prd: prd as u32, tddr: timer.tddr, start_cycle: 0 })
            }
            _ => Err(Error::Config(format!(
                "timer.period_us = {}: gives PRD = {} with TDDR = {} at {} Hz SYSCLKOUT; PRD must be 1…{}",
                timer.period_us,
                prd.map_or_else(|| "-1".to_string(), |p| p.to_string()),
                timer.tddr,
                sysclkout.hz(),
                u32::MAX
            ))),
        }
    }

    /// SYSCLKOUT cycles of one interrupt period: (PRD+1)(TDDR+1).
    pub fn period_cycles(&self) -> u64 {
        (self.prd as u64 + 1) * (self.tddr as u64 + 1)
    }

    /// Time of the `k`-th interrupt (k ≥ 1; k = 0 is the start), exact to the picosecond.
    pub fn tick_ps(&self, k: u64) -> Ps {
        self.sysclkout.cycles_to_ps(self.start_cycle + k * self.period_cycles())
    }

    /// Index of the last tick at or before `t` (0 before the first interrupt).
    pub fn ticks_by(&self, t: Ps) -> u64 {
        self.sysclkout.ps_to_cycles(t).saturating_sub(self.start_cycle) / self.period_cycles()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::time::PS_PER_S;

    fn sys() -> Clock {
        Clock::from_hz(150_000_000)
    }

    #[test]
    fn reference_period_is_4_ms_exactly() {
        let t = CpuTimer::from_profile(&profile::Timer::default(), sys()).unwrap();
        assert_eq!((t.prd, t.tddr), (599_999, 0));
        assert_eq!(t.period_cycles(), 600_000);
        assert_eq!(t.tick_ps(1), 4_000_000_000);
        // 250 ticks are one second exactly; tick k is k periods, never an accumulated sum.
        assert_eq!(t.tick_ps(250), PS_PER_S);
        assert_eq!(t.tick_ps(900_000), 3600 * PS_PER_S);
        assert_eq!(t.ticks_by(PS_PER_S), 250);
        assert_eq!(t.ticks_by(PS_PER_S - 1), 249);
    }

    #[test]
    fn legacy_rule_is_one_cycle_longer() {
        let t = CpuTimer::with_rule(&profile::Timer::default(), sys(), PrdRule::Legacy).unwrap();
        assert_eq!(t.prd, 600_000);
        assert_eq!(t.tick_ps(1), 4_000_006_666);
        assert_eq!(t.tick_ps(3), 12_000_020_000);
    }

    #[test]
    fn prescaler_divides_prd() {
        let t = CpuTimer::from_profile(&profile::Timer { period_us: 4000.0, tddr: 9 }, sys()).unwrap();
        assert_eq!(t.prd, 59_999);
        assert_eq!(t.period_cycles(), 600_000);
        // A non-integer µs period at a rational clock: 1/3 µs = 50 cycles.
        let c = Clock::new(100_000_000, 1);
        let t = CpuTimer::from_profile(&profile::Timer { period_us: 10.0 / 3.0, tddr: 0 }, c).unwrap();
        assert_eq!(t.period_cycles(), 333);
    }

    #[test]
    fn unreachable_periods_name_the_key() {
        // 150 MHz × 0.01 µs = 1.5 cycles → PRD = 0: rejected.
        let e = CpuTimer::from_profile(&profile::Timer { period_us: 0.01, tddr: 0 }, sys()).unwrap_err();
        assert!(matches!(e, Error::Config(ref m) if m.contains("timer.period_us") && m.contains("PRD = 0")), "{e}");
        // 40 s at 150 MHz is 6e9 counts: beyond u32.
        let e = CpuTimer::from_profile(&profile::Timer { period_us: 40e6, tddr: 0 }, sys()).unwrap_err();
        assert!(matches!(e, Error::Config(ref m) if m.contains("timer.period_us")), "{e}");
        // The prescaler makes it reachable.
        let t = CpuTimer::from_profile(&profile::Timer { period_us: 40e6, tddr: 1 }, sys()).unwrap();
        assert_eq!(t.tick_ps(1), 40 * PS_PER_S);
    }
}
