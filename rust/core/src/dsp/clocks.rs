//! The F28335 clock tree: SYSCLKOUT = crystal × PLLCR / DIVSEL (the PLL bypassed when PLLCR = 0),
//! LSPCLK = SYSCLKOUT / (2·LOSPCP), or SYSCLKOUT itself when LOSPCP = 0.
//!
//! Built once from `profile::Clocks`; every other model takes its clocks from here so the tree is
//! never configured twice.

use crate::error::{Error, Result};
use crate::profile;
use crate::time::Clock;

/// The two clocks the firmware's peripherals run on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DspClocks {
    /// CPU clock (and CPU timer input).
    pub sysclkout: Clock,
    /// Low-speed peripheral clock (SPI-A baud generator input).
    pub lspclk: Clock,
}

impl DspClocks {
    /// The clock tree the registers in `c` produce.
    pub fn from_profile(c: &profile::Clocks) -> Result<DspClocks> {
        if c.crystal_hz == 0 {
            return Err(Error::Config("clocks.crystal_hz = 0: the oscillator must run".into()));
        }
        if c.pllcr > 10 {
            return Err(Error::Config(format!("clocks.pllcr = {}: PLLCR.DIV must be 0…10", c.pllcr)));
        }
        if ![1, 2, 4].contains(&c.divsel) {
            return Err(Error::Config(format!("clocks.divsel = {}: the divider must be 1, 2 or 4", c.divsel)));
        }
        if c.lospcp > 7 {
            return Err(Error::Config(format!("clocks.lospcp = {}: LOSPCP is a 3-bit field (0…7)", c.lospcp)));
        }
        let crystal = Clock::from_hz(c.crystal_hz);
        // PLLCR = 0 bypasses the PLL: the oscillator goes straight to the DIVSEL divider.
        let pll = if c.pllcr == 0 { crystal } else { crystal.multiplied(c.pllcr as u64) };
        let sysclkout = pll.divided(c.divsel as u64);
        let lspclk = if c.lospcp == 0 { sysclkout } else { sysclkout.divided(2 * c.lospcp as u64) };
        Ok(DspClocks { sysclkout, lspclk })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::time::PS_PER_S;

    fn clocks(crystal_hz: u64, pllcr: u32, divsel: u32, lospcp: u32) -> DspClocks {
        DspClocks::from_profile(&profile::Clocks { crystal_hz, pllcr, divsel, lospcp, ..Default::default() }).unwrap()
    }

    #[test]
    fn reference_is_150_and_37_5_mhz() {
        let c = DspClocks::from_profile(&profile::Clocks::default()).unwrap();
        assert_eq!(c.sysclkout, Clock::from_hz(150_000_000));
        assert_eq!(c.lspclk, Clock::new(75_000_000, 2));
        assert_eq!(c.lspclk.cycles_to_ps(37_500_000), PS_PER_S);
    }

    #[test]
    fn pll_bypass_and_lospcp_zero() {
        let c = clocks(30_000_000, 0, 2, 0);
        assert_eq!(c.sysclkout, Clock::from_hz(15_000_000));
        assert_eq!(c.lspclk, c.sysclkout);
        let c = clocks(30_000_000, 10, 1, 7);
        assert_eq!(c.sysclkout, Clock::from_hz(300_000_000));
        assert_eq!(c.lspclk, Clock::new(300_000_000, 14));
        let c = clocks(20_000_000, 3, 4, 1);
        assert_eq!(c.sysclkout, Clock::from_hz(15_000_000));
        assert_eq!(c.lspclk, Clock::new(15_000_000, 2));
    }

    #[test]
    fn invalid_tree_is_a_config_error() {
        let e = DspClocks::from_profile(&profile::Clocks { divsel: 3, ..Default::default() }).unwrap_err();
        assert!(matches!(e, Error::Config(ref m) if m.contains("clocks.divsel")), "{e}");
        let e = DspClocks::from_profile(&profile::Clocks { lospcp: 8, ..Default::default() }).unwrap_err();
        assert!(matches!(e, Error::Config(ref m) if m.contains("clocks.lospcp")), "{e}");
    }
}
