//! The F28335's system control registers (`SysCtrlRegs`, 0x7010; TI's SPRUFB0, "Clocking" and
//! "Watchdog Block"): the PLL, the peripheral clock prescalers and enables, and the watchdog, as a
//! host-built firmware drives them. Every register here is EALLOW-protected (a write with
//! EALLOW = 0 is ignored, the caller reports it); reads are not.
//!
//! - **PLL** (PLLSTS 0x7011, PLLCR 0x7021): SYSCLKOUT = OSCCLK × PLLCR.DIV / n, n = 4 for
//!   PLLSTS.DIVSEL 0 or 1, 2 for DIVSEL 2, 1 for DIVSEL 3 ([`super::clocks::DspClocks`]); DIV = 0
//!   bypasses the PLL. Writing a new DIV clears PLLSTS.PLLLOCKS; the PLL locks `clocks.pll_lock_oscclk`
//!   OSCCLK cycles later (SPRUFB0: 131072, [unconfirmed]), when PLLLOCKS sets and SYSCLKOUT takes the
//!   new rate (until then the CPU runs on at the old one). A DIVSEL write takes effect at once.
//!   PLLSTS: 0 PLLLOCKS (read-only), 2 PLLOFF, 3 MCLKSTS (read-only, 0: the oscillator never fails
//!   here), 4 MCLKCLR (reads 0), 5 OSCOFF, 6 MCLKOFF, 8:7 DIVSEL.
//! - **Prescalers** (HISPCP 0x701A, LOSPCP 0x701B; bits 2:0): HSPCLK, LSPCLK = SYSCLKOUT / (2·n),
//!   SYSCLKOUT when n = 0. Reset 0x0001 and 0x0002. SPI-A's baud follows LSPCLK.
//! - **Clock enables** (PCLKCR0 0x701C, PCLKCR1 0x701D, PCLKCR3 0x7020): one bit per peripheral
//!   ([`clock_bit`]); reset 0, 0 and 0x2700 (CPU timers 0-2 and GPIOIN on). A peripheral used with
//!   its clock off is the board's to report (`peripheral_clock_off`).
//! - **Watchdog** (SCSR 0x7022, WDCNTR 0x7023, WDKEY 0x7025, WDCR 0x7029): WDCLK = OSCCLK/512,
//!   divided by 1 (WDPS 0, 1) or 2^(WDPS−1); WDCNTR counts WDCLKs up; its overflow (256 counts)
//!   resets the chip, or, with SCSR.WDENINT = 1, raises WAKEINT (PIE INT1.8) and starts again. 0x55
//!   then 0xAA written to WDKEY clear the counter; WDCR written with WDCHK (5:3) other than 101b
//!   resets the chip at once; WDCR.WDDIS (bit 6) stops the dog, and can be changed only while
//!   SCSR.WDOVERRIDE (write 1 to clear) is 1; WDFLAG (bit 7) is set by a watchdog reset, write 1 to
//!   clear. SCSR: 0 WDOVERRIDE, 1 WDENINT, 2 WDINTS (read-only: 1 while the WDINT line is high,
//!   inactive). Reset: WDCR = 0 (running, fastest), SCSR = 0x0005.

use super::clocks::DspClocks;
use crate::error::{Error, Result};
use crate::profile;
use crate::time::{Clock, Ps};

/// SysCtrlRegs' base address.
pub const SYSCTRL_BASE: u32 = 0x7010;
/// PLLSTS.
pub const PLLSTS: u32 = 0x7011;
/// HISPCP.
pub const HISPCP: u32 = 0x701A;
/// LOSPCP.
pub const LOSPCP: u32 = 0x701B;
/// PCLKCR0.
pub const PCLKCR0: u32 = 0x701C;
/// PCLKCR1.
pub const PCLKCR1: u32 = 0x701D;
/// LPMCR0.
pub const LPMCR0: u32 = 0x701E;
/// PCLKCR3.
pub const PCLKCR3: u32 = 0x7020;
/// PLLCR.
pub const PLLCR: u32 = 0x7021;
/// SCSR.
pub const SCSR: u32 = 0x7022;
/// WDCNTR.
pub const WDCNTR: u32 = 0x7023;
/// WDKEY.
pub const WDKEY: u32 = 0x7025;
/// WDCR.
pub const WDCR: u32 = 0x7029;

/// The registers of this module: name, address, width in bits.
pub const REGISTERS: &[(&str, u32, u32)] = &[
    ("PLLSTS", PLLSTS, 16),
    ("HISPCP", HISPCP, 16),
    ("PCLKCR0", PCLKCR0, 16),
    ("PCLKCR1", PCLKCR1, 16),
    ("LPMCR0", LPMCR0, 16),
    ("PCLKCR3", PCLKCR3, 16),
    ("PLLCR", PLLCR, 16),
    ("SCSR", SCSR, 16),
    ("WDCNTR", WDCNTR, 16),
    ("WDKEY", WDKEY, 16),
    ("WDCR", WDCR, 16),
];

const PLLSTS_PLLLOCKS: u16 = 1;
const PLLSTS_MCLKCLR: u16 = 1 << 4;
const PLLSTS_DIVSEL: u16 = 3 << 7;
/// PLLSTS bits kept as written: PLLOFF, OSCOFF, MCLKOFF, DIVSEL.
const PLLSTS_KEPT: u16 = (1 << 2) | (1 << 5) | (1 << 6) | PLLSTS_DIVSEL;
const SCSR_WDOVERRIDE: u16 = 1;
const SCSR_WDENINT: u16 = 1 << 1;
const WDCR_WDDIS: u16 = 1 << 6;
const WDCR_WDFLAG: u16 = 1 << 7;
const WDCR_WDCHK_OK: u16 = 0b101 << 3;

/// A peripheral's clock enable: (register, bit) as SPRUFB0's PCLKCR0/1/3 tables give them.
pub fn clock_bit(peripheral: &str) -> Option<(u32, u16)> {
    let (reg, bit) = match peripheral {
        "ADC" => (PCLKCR0, 3),
        "I2C-A" => (PCLKCR0, 4),
        "SCI-C" => (PCLKCR0, 5),
        "SPI-A" => (PCLKCR0, 8),
        "SCI-A" => (PCLKCR0, 10),
        "SCI-B" => (PCLKCR0, 11),
        "McBSP-A" => (PCLKCR0, 12),
        "McBSP-B" => (PCLKCR0, 13),
        "eCAN-A" => (PCLKCR0, 14),
        "eCAN-B" => (PCLKCR0, 15),
        "ePWM1" => (PCLKCR1, 0),
        "ePWM2" => (PCLKCR1, 1),
        "ePWM3" => (PCLKCR1, 2),
        "ePWM4" => (PCLKCR1, 3),
        "ePWM5" => (PCLKCR1, 4),
        "ePWM6" => (PCLKCR1, 5),
        "eCAP1" => (PCLKCR1, 8),
        "eCAP2" => (PCLKCR1, 9),
        "eCAP3" => (PCLKCR1, 10),
        "eCAP4" => (PCLKCR1, 11),
        "eCAP5" => (PCLKCR1, 12),
        "eCAP6" => (PCLKCR1, 13),
        "eQEP1" => (PCLKCR1, 14),
        "eQEP2" => (PCLKCR1, 15),
        "CPU timer 0" => (PCLKCR3, 8),
        "CPU timer 1" => (PCLKCR3, 9),
        "CPU timer 2" => (PCLKCR3, 10),
        "DMA" => (PCLKCR3, 11),
        "XINTF" => (PCLKCR3, 12),
        _ => return None,
    };
    Some((reg, 1 << bit))
}

/// What a system-control write or the passing of time did, for the board to act on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SysEvent {
    /// SYSCLKOUT (and with it HSPCLK and LSPCLK) changed at this time.
    Clocks(Ps),
    /// LSPCLK changed at this time (LOSPCP written).
    Lspclk(Ps),
    /// The watchdog counter overflowed with WDENINT = 1: WAKEINT (INT1.8) at this time.
    WatchdogInterrupt(Ps),
    /// The watchdog reset the chip at this time (`true`: its counter overflowed; `false`: WDCR
    /// written with a wrong WDCHK).
    WatchdogReset(Ps, bool),
}

/// The system control registers.
#[derive(Debug, Clone)]
pub struct SysCtrl {
    oscclk: Clock,
    lock_oscclk: u64,
    pllcr: u16,
    pllsts: u16,
    /// The PLL locks at this time (PLLLOCKS reads 0 until then), with this DIV.
    locking: Option<(Ps, u16)>,
    /// The DIV SYSCLKOUT runs on (the last locked one).
    div: u16,
    hispcp: u16,
    lospcp: u16,
    pclkcr: [u16; 3],
    lpmcr0: u16,
    scsr: u16,
    wdcr: u16,
    /// 0x55 was the last WDKEY write.
    wdkey_armed: bool,
    /// The watchdog's count at `wd_epoch` (it counts from there while enabled).
    wd_count: u64,
    wd_epoch: Ps,
    /// WAKEINT's line is low (SCSR.WDINTS reads 0) until this time.
    wdint_until: Ps,
}

impl SysCtrl {
    /// The registers at main's entry: the PLL as the profile's clocks give it (PLLCR = `pllcr`,
    /// DIVSEL for `divsel`, locked), LOSPCP = `lospcp`, HISPCP = 1; with `clocks.at_main` =
    /// `"initialised"` every peripheral clock on and the watchdog disabled (as TI's start-up code
    /// and InitSysCtrl leave them), with `"reset"` the chip's reset values (PCLKCR0 = PCLKCR1 = 0,
    /// PCLKCR3 = 0x2700, the watchdog running at its fastest).
    pub fn from_profile(c: &profile::Clocks) -> Result<SysCtrl> {
        DspClocks::from_profile(c)?;
        let divsel_field: u16 = match c.divsel {
            4 => 0,
            2 => 2,
            _ => 3,
        };
        let initialised = match c.at_main.as_str() {
            "initialised" => true,
            "reset" => false,
            other => {
                return Err(Error::Config(format!(
                    "clocks.at_main = \"{other}\": expected \"initialised\" or \"reset\""
                )))
            }
        };
        Ok(SysCtrl {
            oscclk: Clock::from_hz(c.crystal_hz),
            lock_oscclk: c.pll_lock_oscclk,
            pllcr: c.pllcr as u16,
            pllsts: PLLSTS_PLLLOCKS | divsel_field << 7,
            locking: None,
            div: c.pllcr as u16,
            hispcp: 1,
            lospcp: c.lospcp as u16,
            pclkcr: if initialised { [0xFD3C, 0xFF3F, 0x3F00] } else { [0, 0, 0x2700] },
            lpmcr0: 0x00FC,
            scsr: 0x0005,
            wdcr: if initialised { WDCR_WDDIS } else { 0 },
            wdkey_armed: false,
            wd_count: 0,
            wd_epoch: 0,
            wdint_until: 0,
        })
    }

    /// Whether `addr` is one of this module's registers (LOSPCP included).
    pub fn owns(addr: u32) -> bool {
        matches!(
            addr,
            PLLSTS | HISPCP | LOSPCP | PCLKCR0 | PCLKCR1 | LPMCR0 | PCLKCR3 | PLLCR | SCSR | WDCNTR | WDKEY | WDCR
        )
    }

    fn divider(&self) -> u64 {
        match (self.pllsts & PLLSTS_DIVSEL) >> 7 {
            0 | 1 => 4,
            2 => 2,
            _ => 1,
        }
    }

    /// SYSCLKOUT now.
    pub fn sysclkout(&self) -> Clock {
        let pll = if self.div == 0 { self.oscclk } else { self.oscclk.multiplied(u64::from(self.div)) };
        pll.divided(self.divider())
    }

    fn prescaled(&self, n: u16) -> Clock {
        if n == 0 {
            self.sysclkout()
        } else {
            self.sysclkout().divided(2 * u64::from(n))
        }
    }

    /// HSPCLK now (the ADC's clock).
    pub fn hspclk(&self) -> Clock {
        self.prescaled(self.hispcp)
    }

    /// LSPCLK now (SPI, SCI, McBSP).
    pub fn lspclk(&self) -> Clock {
        self.prescaled(self.lospcp)
    }

    /// LOSPCP.
    pub fn lospcp(&self) -> u16 {
        self.lospcp
    }

    /// Whether the clock of `peripheral` ([`clock_bit`]'s names) is enabled; true for one without
    /// an enable bit.
    pub fn clock_on(&self, peripheral: &str) -> bool {
        clock_bit(peripheral).is_none_or(|(reg, m)| self.pclkcr[pclkcr_index(reg)] & m != 0)
    }

    fn wd_enabled(&self) -> bool {
        self.wdcr & WDCR_WDDIS == 0
    }

    fn wdclk(&self) -> Clock {
        let ps = self.wdcr & 7;
        let pre = if ps <= 1 { 1 } else { 1u64 << (ps - 1) };
        self.oscclk.divided(512 * pre)
    }

    fn wd_count_at(&self, t: Ps) -> u64 {
        if !self.wd_enabled() {
            return self.wd_count;
        }
        self.wd_count + self.wdclk().ps_to_cycles(t.saturating_sub(self.wd_epoch))
    }

    /// Restart the count at `t` from the count it has then.
    fn wd_rebase(&mut self, t: Ps) {
        self.wd_count = self.wd_count_at(t);
        self.wd_epoch = t;
    }

    /// The next time something happens by itself: the PLL locking, the watchdog overflowing.
    pub fn next_event_ps(&self) -> Option<Ps> {
        let lock = self.locking.map(|(t, _)| t);
        let wd =
            self.wd_enabled().then(|| self.wd_epoch + self.wdclk().cycles_to_ps(256u64.saturating_sub(self.wd_count)));
        [lock, wd].into_iter().flatten().min()
    }

    /// Let time pass up to `t`: the first thing that happens at or before it, if any (call again
    /// until None).
    pub fn advance(&mut self, t: Ps) -> Option<SysEvent> {
        let next = self.next_event_ps().filter(|&n| n <= t)?;
        if let Some((lock, div)) = self.locking.filter(|&(lock, _)| lock == next) {
            self.locking = None;
            self.div = div;
            self.pllsts |= PLLSTS_PLLLOCKS;
            return Some(SysEvent::Clocks(lock));
        }
        // The watchdog overflowed at `next`.
        self.wd_count = 0;
        self.wd_epoch = next;
        self.wdkey_armed = false;
        if self.scsr & SCSR_WDENINT != 0 {
            self.wdint_until = next + self.oscclk.cycles_to_ps(512);
            Some(SysEvent::WatchdogInterrupt(next))
        } else {
            self.wdcr |= WDCR_WDFLAG;
            Some(SysEvent::WatchdogReset(next, true))
        }
    }

    /// Read the register at `addr` at time `t` (after [`SysCtrl::advance`] to `t`).
    pub fn read(&self, addr: u32, t: Ps) -> Result<u16> {
        Ok(match addr {
            PLLSTS => self.pllsts,
            HISPCP => self.hispcp,
            LOSPCP => self.lospcp,
            PCLKCR0 | PCLKCR1 | PCLKCR3 => self.pclkcr[pclkcr_index(addr)],
            LPMCR0 => self.lpmcr0,
            PLLCR => self.pllcr,
            SCSR => self.scsr & 3 | if t >= self.wdint_until { 1 << 2 } else { 0 },
            WDCNTR => self.wd_count_at(t) as u16 & 0xFF,
            WDKEY => 0,
            WDCR => self.wdcr & (WDCR_WDFLAG | WDCR_WDDIS | 7),
            a => return Err(no_register(a)),
        })
    }

    /// Write the register at `addr` at time `t` (EALLOW is the caller's to check): what it set off.
    pub fn write(&mut self, addr: u32, value: u16, t: Ps) -> Result<Option<SysEvent>> {
        match addr {
            PLLSTS => {
                let before = self.pllsts;
                self.pllsts = (self.pllsts & !PLLSTS_KEPT) | (value & PLLSTS_KEPT & !PLLSTS_MCLKCLR);
                if (before ^ self.pllsts) & PLLSTS_DIVSEL != 0 {
                    return Ok(Some(SysEvent::Clocks(t)));
                }
            }
            HISPCP => self.hispcp = value & 7,
            LOSPCP => {
                if value & 7 != self.lospcp {
                    self.lospcp = value & 7;
                    return Ok(Some(SysEvent::Lspclk(t)));
                }
            }
            PCLKCR0 | PCLKCR1 | PCLKCR3 => self.pclkcr[pclkcr_index(addr)] = value,
            LPMCR0 => self.lpmcr0 = value,
            PLLCR => {
                let div = value & 0xF;
                if div != self.pllcr {
                    self.pllcr = div;
                    self.pllsts &= !PLLSTS_PLLLOCKS;
                    self.locking = Some((t + self.oscclk.cycles_to_ps(self.lock_oscclk), div));
                }
            }
            SCSR => {
                // WDOVERRIDE is write-1-to-clear; WDENINT as written; WDINTS read-only.
                let keep = self.scsr & SCSR_WDOVERRIDE & !(value & SCSR_WDOVERRIDE);
                self.scsr = keep | (value & SCSR_WDENINT);
            }
            WDCNTR => {}
            WDKEY => {
                let v = value & 0xFF;
                if v == 0xAA && self.wdkey_armed {
                    self.wd_count = 0;
                    self.wd_epoch = t;
                }
                self.wdkey_armed = v == 0x55;
            }
            WDCR => {
                if value & (7 << 3) != WDCR_WDCHK_OK {
                    self.wdcr |= WDCR_WDFLAG;
                    return Ok(Some(SysEvent::WatchdogReset(t, false)));
                }
                self.wd_rebase(t);
                let mut wdcr = (self.wdcr & WDCR_WDFLAG & !(value & WDCR_WDFLAG)) | (value & 7);
                wdcr |= if self.scsr & SCSR_WDOVERRIDE != 0 { value & WDCR_WDDIS } else { self.wdcr & WDCR_WDDIS };
                self.wdcr = wdcr;
            }
            a => return Err(no_register(a)),
        }
        Ok(None)
    }
}

fn pclkcr_index(reg: u32) -> usize {
    match reg {
        PCLKCR0 => 0,
        PCLKCR1 => 1,
        _ => 2,
    }
}

fn no_register(addr: u32) -> Error {
    Error::Register(format!("C28x address 0x{addr:04X}: not a modelled system control register"))
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: Ps = 1_000_000_000;

    fn reset() -> SysCtrl {
        SysCtrl::from_profile(&profile::Clocks { at_main: "reset".into(), ..Default::default() }).unwrap()
    }

    #[test]
    fn the_profile_gives_the_pll_and_the_prescalers() {
        let s = SysCtrl::from_profile(&profile::Clocks::default()).unwrap();
        assert_eq!(s.sysclkout(), Clock::from_hz(150_000_000));
        assert_eq!(s.lspclk(), Clock::new(75_000_000, 2));
        assert_eq!(s.hspclk(), Clock::from_hz(75_000_000));
        assert_eq!(s.read(PLLSTS, 0).unwrap(), 0x0101, "locked, DIVSEL = 2 (/2)");
        assert!(s.clock_on("SPI-A") && s.clock_on("ePWM6") && s.clock_on("XINTF"));
        assert_eq!(s.next_event_ps(), None, "the dog is disabled, the PLL locked");
        let r = reset();
        assert!(!r.clock_on("SPI-A") && r.clock_on("CPU timer 2") && !r.clock_on("DMA"));
    }

    #[test]
    fn a_new_pllcr_relocks_then_changes_sysclkout() {
        let mut s = SysCtrl::from_profile(&profile::Clocks::default()).unwrap();
        assert_eq!(s.write(PLLCR, 10, 0).unwrap(), None, "the same DIV: no relock (TI's InitPll checks)");
        assert_eq!(s.read(PLLSTS, 0).unwrap() & 1, 1);
        s.write(PLLCR, 5, MS).unwrap();
        assert_eq!(s.read(PLLSTS, MS).unwrap() & 1, 0, "PLLLOCKS clear while locking");
        let lock = MS + Clock::from_hz(30_000_000).cycles_to_ps(131_072);
        assert_eq!(s.next_event_ps(), Some(lock));
        assert_eq!(s.advance(lock - 1), None);
        assert_eq!(s.sysclkout(), Clock::from_hz(150_000_000));
        assert_eq!(s.advance(lock), Some(SysEvent::Clocks(lock)));
        assert_eq!(s.sysclkout(), Clock::from_hz(75_000_000));
        assert_eq!(s.read(PLLSTS, lock).unwrap() & 1, 1);
        // DIVSEL 3 (/1) at once.
        assert_eq!(s.write(PLLSTS, 3 << 7, lock).unwrap(), Some(SysEvent::Clocks(lock)));
        assert_eq!(s.sysclkout(), Clock::from_hz(150_000_000));
    }

    #[test]
    fn the_watchdog_bites_after_256_wdclks_unless_serviced() {
        let mut s = reset();
        // WDCLK = 30 MHz / 512: 256 of them are 4.369 ms.
        let bite = Clock::from_hz(30_000_000).cycles_to_ps(512 * 256);
        assert_eq!(s.next_event_ps(), Some(bite));
        s.write(WDKEY, 0x55, MS).unwrap();
        s.write(WDKEY, 0xAA, MS).unwrap();
        assert_eq!(s.read(WDCNTR, MS).unwrap(), 0);
        assert_eq!(s.next_event_ps(), Some(MS + bite));
        // 0xAA alone does not service it.
        s.write(WDKEY, 0xAA, 2 * MS).unwrap();
        assert!(s.read(WDCNTR, 2 * MS).unwrap() > 0);
        assert_eq!(s.advance(MS + bite), Some(SysEvent::WatchdogReset(MS + bite, true)));
        assert_eq!(s.read(WDCR, MS + bite).unwrap() & WDCR_WDFLAG, WDCR_WDFLAG);
    }

    #[test]
    fn disable_dog_and_the_override_bit() {
        let mut s = reset();
        s.write(WDCR, 0x0068, 0).unwrap(); // TI's DisableDog
        assert_eq!(s.next_event_ps(), None);
        s.write(SCSR, SCSR_WDOVERRIDE, 0).unwrap(); // write 1 to clear: WDDIS is locked now
        assert_eq!(s.read(SCSR, 0).unwrap() & 1, 0);
        s.write(WDCR, 0x0028, 0).unwrap();
        assert_eq!(s.next_event_ps(), None, "WDDIS cannot be cleared once WDOVERRIDE is 0");
        assert_eq!(s.write(WDCR, 0x0040, 0).unwrap(), Some(SysEvent::WatchdogReset(0, false)), "WDCHK ≠ 101");
    }

    #[test]
    fn wdenint_raises_wakeint_instead_of_a_reset() {
        let mut s = reset();
        s.write(SCSR, SCSR_WDENINT, 0).unwrap();
        s.write(WDCR, 0x002F, 0).unwrap(); // WDPS = 7: /64
        let period = Clock::from_hz(30_000_000).cycles_to_ps(512 * 64 * 256);
        assert_eq!(s.advance(period), Some(SysEvent::WatchdogInterrupt(period)));
        assert_eq!(s.read(SCSR, period).unwrap() & 4, 0, "WDINTS low during the pulse");
        assert_eq!(s.next_event_ps(), Some(2 * period));
    }
}
