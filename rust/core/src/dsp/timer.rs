//! The CPU timers. [`CpuTimer`] is timer 0 as the profile's ConfigCpuTimer sets it (the model
//! firmware's tick); [`CpuTimerRegs`] is any of timers 0–2 register by register (the host board).
//!
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

/// TCR.TSS: the timer is stopped.
pub const TCR_TSS: u16 = 1 << 4;
/// TCR.TRB: reload TIM from PRD (reads 0).
pub const TCR_TRB: u16 = 1 << 5;
/// TCR.TIE: TIF raises the timer's interrupt.
pub const TCR_TIE: u16 = 1 << 14;
/// TCR.TIF: the timer passed zero (write 1 to clear).
pub const TCR_TIF: u16 = 1 << 15;
/// TCR bits kept as written (TSS, SOFT, FREE, TIE); TRB reads 0, TIF is the flag.
const TCR_KEPT: u16 = TCR_TSS | (1 << 10) | (1 << 11) | TCR_TIE;

/// One CPU timer's registers, as `CpuTimer0Regs`…`CpuTimer2Regs` lay them out (SPRUFB0, "CPU
/// Timers": TIM at +0, PRD at +2, TCR at +4, TPR at +6, TPRH at +7), counted in SYSCLKOUT cycles of
/// the owner's cycle count (see [`super::interrupts::Interrupts`]).
///
/// The counter decrements once every TDDR+1 SYSCLKOUT cycles and, after 0, reloads from PRD and
/// sets TCR.TIF: a period is (PRD+1)(TDDR+1) cycles. Reset (SPRUFB0): TIM = PRD = 0xFFFFFFFF,
/// TCR = 0 (running, TIE = 0), TPR = TPRH = 0. TSS stops it, TRB reloads TIM from PRD, TIE lets
/// TIF raise the interrupt, writing 1 to TIF clears it. The prescaler's own counter (PSC) starts at
/// TDDR at every reload; it reads as TDDR.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CpuTimerRegs {
    prd: u32,
    tddr: u16,
    tcr: u16,
    tif: bool,
    /// Running: the cycle of the next reload (underflow). Stopped: None.
    next_reload: Option<u64>,
    /// The counter while stopped.
    held_tim: u32,
    /// Underflows since power-on, and the cycle of the last one.
    underflows: u64,
    last_underflow: Option<u64>,
    /// Its clock is gated off (PCLKCR3.CPUTIMERnENCLK = 0): the counter holds `held_tim`.
    gated: bool,
}

impl Default for CpuTimerRegs {
    fn default() -> Self {
        CpuTimerRegs::reset()
    }
}

impl CpuTimerRegs {
    /// The reset state at cycle 0: running with PRD = TIM = 0xFFFFFFFF and TIE = 0.
    pub fn reset() -> CpuTimerRegs {
        CpuTimerRegs {
            prd: u32::MAX,
            tddr: 0,
            tcr: 0,
            tif: false,
            next_reload: Some(u64::from(u32::MAX) + 1),
            held_tim: u32::MAX,
            underflows: 0,
            last_underflow: None,
            gated: false,
        }
    }

    /// Its clock (PCLKCR3.CPUTIMERnENCLK, SPRUFB0) goes off or on at cycle `c`: with it off the
    /// counter holds its value (no count, no reload, no interrupt), and goes on from that value
    /// when it is on again, if TSS = 0. (Its registers are out of reach meanwhile: the board loses
    /// the accesses.)
    pub fn set_clock(&mut self, on: bool, c: u64) {
        if !on && !self.gated {
            self.gated = true;
            if self.next_reload.is_some() {
                self.held_tim = self.tim(c);
                self.next_reload = None;
            }
        } else if on && self.gated {
            self.gated = false;
            if self.tcr & TCR_TSS == 0 {
                self.load_running(self.held_tim, c);
            }
        }
    }

    fn per_count(&self) -> u64 {
        u64::from(self.tddr) + 1
    }

    fn period(&self) -> u64 {
        (u64::from(self.prd) + 1) * self.per_count()
    }

    /// Bring the timer up to cycle `c`: every reload at or before it sets TIF. Returns whether a
    /// reload happened with TIE set (the interrupt line pulses).
    pub fn sync(&mut self, c: u64) -> bool {
        let Some(next) = self.next_reload.filter(|&n| n <= c) else { return false };
        let k = (c - next) / self.period() + 1;
        self.underflows += k;
        self.last_underflow = Some(next + (k - 1) * self.period());
        self.next_reload = Some(next + k * self.period());
        self.tif = true;
        self.tcr & TCR_TIE != 0
    }

    /// The counter at cycle `c` (synced to `c`).
    pub fn tim(&self, c: u64) -> u32 {
        match self.next_reload {
            Some(next) => next.saturating_sub(c).div_ceil(self.per_count()).saturating_sub(1) as u32,
            None => self.held_tim,
        }
    }

    /// Read the word at `offset` (0…7) at cycle `c`; None for offset 5 (reserved).
    pub fn read(&self, offset: u32, c: u64) -> Option<u16> {
        Some(match offset {
            0 => self.tim(c) as u16,
            1 => (self.tim(c) >> 16) as u16,
            2 => self.prd as u16,
            3 => (self.prd >> 16) as u16,
            4 => self.tcr | if self.tif { TCR_TIF } else { 0 },
            6 => self.tddr & 0xFF | (self.tddr & 0xFF) << 8,
            7 => self.tddr >> 8 | (self.tddr & 0xFF00),
            _ => return None,
        })
    }

    /// Write the word at `offset` at cycle `c`; false for offset 5 (reserved).
    pub fn write(&mut self, offset: u32, value: u16, c: u64) -> bool {
        match offset {
            0 | 1 => {
                let tim = self.tim(c);
                let tim = if offset == 0 {
                    (tim & 0xFFFF_0000) | u32::from(value)
                } else {
                    (tim & 0xFFFF) | u32::from(value) << 16
                };
                if self.next_reload.is_some() {
                    self.load_running(tim, c);
                } else {
                    self.held_tim = tim;
                }
            }
            2 => self.prd = (self.prd & 0xFFFF_0000) | u32::from(value),
            3 => self.prd = (self.prd & 0xFFFF) | u32::from(value) << 16,
            4 => {
                if value & TCR_TIF != 0 {
                    self.tif = false;
                }
                let was_stopped = self.next_reload.is_none();
                let tim = self.tim(c);
                self.tcr = value & TCR_KEPT;
                let tim = if value & TCR_TRB != 0 { self.prd } else { tim };
                if value & TCR_TSS != 0 {
                    self.next_reload = None;
                    self.held_tim = tim;
                } else if was_stopped || value & TCR_TRB != 0 {
                    self.load_running(tim, c);
                }
            }
            6 => self.tddr = (self.tddr & 0xFF00) | (value & 0xFF),
            7 => self.tddr = (self.tddr & 0x00FF) | (value & 0xFF) << 8,
            _ => return false,
        }
        true
    }

    fn load_running(&mut self, tim: u32, c: u64) {
        self.next_reload = Some(c + (u64::from(tim) + 1) * self.per_count());
    }

    /// The cycle of the next reload (None when stopped).
    pub fn next_reload(&self) -> Option<u64> {
        self.next_reload
    }

    /// Whether TCR.TIE is set.
    pub fn tie(&self) -> bool {
        self.tcr & TCR_TIE != 0
    }

    /// The cycles between two reloads with the PRD and TDDR written now.
    pub fn reload_period(&self) -> u64 {
        self.period()
    }

    /// Reloads since power-on and the cycle of the last one.
    pub fn underflows(&self) -> (u64, Option<u64>) {
        (self.underflows, self.last_underflow)
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
    fn a_timer_with_its_clock_off_holds_its_count() {
        let mut t = CpuTimerRegs::reset();
        t.write(2, 999, 0);
        t.write(3, 0, 0);
        t.write(4, TCR_TRB, 0); // TIM = 999: reloads at cycles 1000, 2000, …
        assert_eq!(t.tim(400), 599);
        t.set_clock(false, 400);
        assert!(!t.sync(5_000) && t.underflows().0 == 0);
        assert_eq!((t.tim(5_000), t.next_reload()), (599, None));
        t.set_clock(true, 5_000);
        assert_eq!(t.next_reload(), Some(5_600));
        t.sync(5_600);
        assert_eq!(t.underflows(), (1, Some(5_600)));
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
