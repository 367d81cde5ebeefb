//! The one checker of the SPI timing rules every SPI part declares ([`SpiTiming`]: SCLK limit,
//! CS set-up and hold, CS-high minimum, modes, frame length): the ADIS16xxx family's slave
//! (`slave.rs`), the ADXL345 and the ADS8344 ask it which rules a frame or a chip-select edge
//! breaks, and report each broken rule in their own words (their events' kinds and messages are
//! the part's). The figures are turned once into whole-ps bounds ([`MinPs`]), so that a frame's
//! check is a few integer comparisons.

use super::frame::{MinPs, Violations};
use super::spi_timing::SpiTiming;
use crate::bus::FrameTiming;
use crate::time::Ps;

/// A part's SPI rules as whole-ps bounds, built once from its [`SpiTiming`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct SpiRules {
    sclk: MinPs,
    cs_setup: MinPs,
    cs_hold: Option<MinPs>,
    cs_high: Option<MinPs>,
    /// Bit `m` set: SPI mode `m` (0…3) is the part's.
    modes: u8,
    frame_bits: Option<u8>,
}

impl SpiRules {
    /// The bounds of `timing`'s rules.
    pub fn new(timing: &SpiTiming) -> SpiRules {
        let bound = |ps: f64| MinPs::with_slack(ps, timing.slack_ps);
        SpiRules {
            sclk: MinPs::with_slack(timing.min_sclk_period_ps(), timing.slack_ps),
            cs_setup: bound(timing.cs_setup_ps),
            cs_hold: timing.cs_hold_ps.map(bound),
            cs_high: timing.cs_high_min_ps.map(bound),
            modes: timing.modes.iter().filter(|&&m| m < 4).fold(0, |acc, &m| acc | 1 << m),
            frame_bits: timing.frame_bits,
        }
    }

    /// The rules a frame breaks by its shape (length, SPI mode, SCLK period against the part's
    /// limit): the same for every frame of one character shape.
    #[inline(always)]
    pub fn shape(&self, timing: &FrameTiming) -> Violations {
        self.shape_against(timing, self.sclk)
    }

    /// [`SpiRules::shape`] with the SCLK period held to `sclk` (a limit of the part's other than
    /// its declared one: the ADIS16xxx burst limit).
    #[inline(always)]
    pub fn shape_against(&self, timing: &FrameTiming, sclk: MinPs) -> Violations {
        let mut found = Violations::default();
        if self.frame_bits.is_some_and(|bits| bits != timing.bits) {
            found.insert(Violations::FRAME_LENGTH);
        }
        if timing.mode >= 4 || self.modes & (1 << timing.mode) == 0 {
            found.insert(Violations::SPI_MODE);
        }
        if sclk.short(timing.sclk_period) {
            found.insert(Violations::SCLK_TOO_FAST);
        }
        found
    }

    /// The first SCLK edge of a chip-select window at `first_edge`, CS having fallen at `cs_fall`:
    /// whether that is sooner than the CS set-up time.
    #[inline(always)]
    pub fn setup_short(&self, cs_fall: Ps, first_edge: Ps) -> bool {
        self.cs_setup.short(first_edge.saturating_sub(cs_fall))
    }

    /// CS rising at `cs_rise` after the last SCLK edge at `last_edge`: whether that is sooner than
    /// the CS hold time (never, for a part without the rule).
    #[inline(always)]
    pub fn hold_short(&self, last_edge: Ps, cs_rise: Ps) -> bool {
        self.cs_hold.is_some_and(|bound| bound.short(cs_rise.saturating_sub(last_edge)))
    }

    /// CS falling at `cs_fall` after it rose at `cs_rise`: whether it stayed high less than the
    /// part's minimum (never, for a part without the rule).
    #[inline(always)]
    pub fn high_short(&self, cs_rise: Ps, cs_fall: Ps) -> bool {
        self.cs_high.is_some_and(|bound| bound.short(cs_fall.saturating_sub(cs_rise)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn timing() -> SpiTiming {
        SpiTiming {
            sclk_max_hz: 2.4e6,
            cs_setup_ps: 50_000.0,
            cs_hold_ps: Some(5_000.0),
            cs_high_min_ps: Some(150_000.0),
            modes: &[0, 3],
            frame_bits: Some(8),
            char_bits: &[8],
            slack_ps: 0.0,
        }
    }

    fn frame(period: Ps, bits: u8, mode: u8) -> FrameTiming {
        FrameTiming { index: 0, first_edge: 0, last_edge: 0, sclk_period: period, bits, mode }
    }

    /// Without slack a time short of the limit by any amount breaks it; the SCLK rule is "1/period
    /// above the limit" (the ADS8344's form) for every period around the bound; the modes and the
    /// length are the declared ones.
    #[test]
    fn the_rules_are_the_declared_figures() {
        let r = SpiRules::new(&timing());
        for p in 416_600..416_700 {
            let above = 1e12 / p as f64 > 2.4e6;
            assert_eq!(r.shape(&frame(p, 8, 0)).contains(Violations::SCLK_TOO_FAST), above, "{p}");
        }
        assert!(r.setup_short(1_000, 1_000 + 49_999) && !r.setup_short(1_000, 1_000 + 50_000));
        assert!(r.hold_short(0, 4_999) && !r.hold_short(0, 5_000));
        assert!(r.high_short(10, 10 + 149_999) && !r.high_short(10, 10 + 150_000));
        assert_eq!(r.shape(&frame(500_000, 8, 3)), Violations::default());
        assert_eq!(r.shape(&frame(500_000, 16, 1)), Violations(Violations::FRAME_LENGTH.0 | Violations::SPI_MODE.0));
        let free = SpiRules::new(&SpiTiming { frame_bits: None, cs_hold_ps: None, cs_high_min_ps: None, ..timing() });
        assert_eq!(free.shape(&frame(500_000, 24, 0)), Violations::default());
        assert!(!free.hold_short(0, 0) && !free.high_short(0, 0));
        // With the ADIS16xxx family's 1 ps slack the bound moves by one picosecond.
        let adis = SpiRules::new(&SpiTiming { slack_ps: 1.0, ..timing() });
        assert!(adis.setup_short(0, 49_998) && !adis.setup_short(0, 49_999));
    }
}
