//! CPU timer 0, the PIE and the C28x CPU's interrupt logic, register by register, as a host-built
//! firmware drives them (the [`crate::host::HostBoard`] holds one).
//!
//! - **CPU timer 0** (`CpuTimer0Regs`, 0x0C00): TIM (32-bit counter), PRD, TCR, TPR/TPRH (the
//!   prescaler TDDRH:TDDR). The counter decrements once every TDDR+1 SYSCLKOUT cycles and, after 0,
//!   reloads from PRD and sets TCR.TIF: a period is (PRD+1)(TDDR+1) cycles, as [`super::CpuTimer`]
//!   counts it. TCR.TSS stops it (reset value 0: it runs from reset with PRD = TIM = 0xFFFFFFFF),
//!   TRB reloads TIM from PRD, TIE lets TIF raise TINT0, writing 1 to TIF clears it. The
//!   prescaler's own counter (PSC) starts at TDDR at every reload; it reads as TDDR.
//! - **PIE** (`PieCtrlRegs`, 0x0CE0): PIECTRL.ENPIE, PIEACK (write 1 to clear), PIEIER1…12,
//!   PIEIFR1…12. TINT0 is group 1, INT7. A group's flag with its enable bit set reaches the CPU's
//!   IFR when the group's PIEACK bit is clear, and sets that bit (TI's SPRUFB0, "PIE").
//! - **CPU**: IER, IFR (TI's `cregister`s), INTM (EINT/DINT) and EALLOW. An interrupt is taken
//!   when INTM = 0 and IER & IFR ≠ 0, lowest INTx first: its IFR bit is cleared, IER, INTM and
//!   EALLOW are saved, its IER bit cleared, INTM set and EALLOW cleared (SPRU430, "Standard
//!   operation for maskable interrupts"); the PIE hands over the vector of the group's
//!   highest-priority flagged and enabled interrupt and clears its PIEIFR bit. [`Interrupts::iret`]
//!   restores what was saved.
//! - **PieVectTable** (0x0D00, EALLOW-protected): 128 vectors. On the host a vector is the address
//!   of a host function, so it is set through [`Interrupts::set_vector`], not as two 16-bit words; a
//!   write without EALLOW is ignored, as on the chip.

use crate::error::{Error, Result};
use crate::time::{Clock, Ps};

/// CpuTimer0Regs' base address.
pub const TIMER0_BASE: u32 = 0x0C00;
/// PieCtrlRegs' base address.
pub const PIE_BASE: u32 = 0x0CE0;
/// PieVectTable's base address (vector `n` at `PIE_VECT_BASE + 2n`).
pub const PIE_VECT_BASE: u32 = 0x0D00;
/// PieVectTable's number of vectors.
pub const VECTORS: usize = 128;
/// TINT0's vector number (PIE group 1, INT7: `PieVectTable.TINT0` at 0x0D4C).
pub const TINT0_VECTOR: usize = 38;

/// The registers of this module: name, address, width in bits.
pub const REGISTERS: &[(&str, u32, u32)] = &[
    ("TIMER0TIM", 0x0C00, 32),
    ("TIMER0PRD", 0x0C02, 32),
    ("TIMER0TCR", 0x0C04, 16),
    ("TIMER0TPR", 0x0C06, 16),
    ("TIMER0TPRH", 0x0C07, 16),
    ("PIECTRL", 0x0CE0, 16),
    ("PIEACK", 0x0CE1, 16),
    ("PIEIER1", 0x0CE2, 16),
    ("PIEIFR1", 0x0CE3, 16),
    ("PIEIER2", 0x0CE4, 16),
    ("PIEIFR2", 0x0CE5, 16),
    ("PIEIER3", 0x0CE6, 16),
    ("PIEIFR3", 0x0CE7, 16),
    ("PIEIER4", 0x0CE8, 16),
    ("PIEIFR4", 0x0CE9, 16),
    ("PIEIER5", 0x0CEA, 16),
    ("PIEIFR5", 0x0CEB, 16),
    ("PIEIER6", 0x0CEC, 16),
    ("PIEIFR6", 0x0CED, 16),
    ("PIEIER7", 0x0CEE, 16),
    ("PIEIFR7", 0x0CEF, 16),
    ("PIEIER8", 0x0CF0, 16),
    ("PIEIFR8", 0x0CF1, 16),
    ("PIEIER9", 0x0CF2, 16),
    ("PIEIFR9", 0x0CF3, 16),
    ("PIEIER10", 0x0CF4, 16),
    ("PIEIFR10", 0x0CF5, 16),
    ("PIEIER11", 0x0CF6, 16),
    ("PIEIFR11", 0x0CF7, 16),
    ("PIEIER12", 0x0CF8, 16),
    ("PIEIFR12", 0x0CF9, 16),
];

const TCR_TSS: u16 = 1 << 4;
const TCR_TRB: u16 = 1 << 5;
const TCR_TIE: u16 = 1 << 14;
const TCR_TIF: u16 = 1 << 15;
/// TCR bits kept as written (TSS, SOFT, FREE, TIE); TRB reads 0, TIF is the flag.
const TCR_KEPT: u16 = TCR_TSS | (1 << 10) | (1 << 11) | TCR_TIE;

/// An interrupt the CPU takes now.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Taken {
    /// The PIE vector number (38 for TINT0).
    pub vector: usize,
    /// The ISR's address (as set in PieVectTable; 0 when never set).
    pub isr: u64,
}

/// Why no interrupt can come while the CPU's state stays as it is (for the diagnostic of a loop that
/// makes no register access): `None` when one can.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Blocked {
    /// INTM is set (DINT, or inside an ISR that did not EINT).
    Intm,
    /// No IER bit of an interrupt source that is modelled (INT1 for TINT0) is set.
    Ier,
    /// PIECTRL.ENPIE is 0.
    Pie,
    /// PIEIER1.INTx7 (TINT0) is 0.
    PieIer,
    /// TCR.TIE is 0.
    Tie,
    /// The timer is stopped (TCR.TSS = 1).
    Stopped,
    /// The group's PIEACK bit is set and nothing will clear it.
    PieAck,
}

impl Blocked {
    /// What blocks, in words.
    pub fn text(self) -> &'static str {
        match self {
            Blocked::Intm => "INTM is set (DINT, or inside an ISR)",
            Blocked::Ier => "IER has INT1 (M_INT1, CPU timer 0's group) clear",
            Blocked::Pie => "PIECTRL.ENPIE is 0 (the PIE is disabled)",
            Blocked::PieIer => "PIEIER1.INTx7 (TINT0) is 0",
            Blocked::Tie => "CpuTimer0Regs.TCR.TIE is 0",
            Blocked::Stopped => "CPU timer 0 is stopped (TCR.TSS = 1)",
            Blocked::PieAck => "PIEACK group 1 is set (the ISR never wrote PIEACK = PIEACK_GROUP1)",
        }
    }
}

/// Timer 0, the PIE and the CPU's interrupt state.
#[derive(Debug, Clone)]
pub struct Interrupts {
    sysclkout: Clock,
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
    /// Cycle the state was brought up to.
    synced: u64,
    enpie: bool,
    pieack: u16,
    pieier: [u16; 12],
    pieifr: [u16; 12],
    ier: u16,
    ifr: u16,
    intm: bool,
    eallow: bool,
    /// Contexts saved by the interrupts being serviced: IER, INTM, EALLOW.
    saved: Vec<(u16, bool, bool)>,
    vectors: Vec<u64>,
}

impl Interrupts {
    /// The reset state at cycle 0: timer 0 running with PRD = TIM = 0xFFFFFFFF and TIE = 0, PIE
    /// disabled, IER = IFR = 0, INTM = 1, EALLOW = 0, every vector 0.
    pub fn new(sysclkout: Clock) -> Interrupts {
        Interrupts {
            sysclkout,
            prd: u32::MAX,
            tddr: 0,
            tcr: 0,
            tif: false,
            next_reload: Some(u64::from(u32::MAX) + 1),
            held_tim: u32::MAX,
            underflows: 0,
            last_underflow: None,
            synced: 0,
            enpie: false,
            pieack: 0,
            pieier: [0; 12],
            pieifr: [0; 12],
            ier: 0,
            ifr: 0,
            intm: true,
            eallow: false,
            saved: Vec::new(),
            vectors: vec![0; VECTORS],
        }
    }

    /// Whether `addr` is one of this module's registers.
    pub fn owns(addr: u32) -> bool {
        matches!(addr, 0x0C00..=0x0C04 | 0x0C06 | 0x0C07 | 0x0CE0..=0x0CF9)
    }

    /// The name of the register at `addr` (the low word's for a 32-bit one).
    pub fn register_name(addr: u32) -> Option<&'static str> {
        REGISTERS.iter().find(|r| addr >= r.1 && addr < r.1 + r.2 / 16).map(|r| r.0)
    }

    fn cycle(&self, t: Ps) -> u64 {
        self.sysclkout.ps_to_cycles(t)
    }

    fn per_count(&self) -> u64 {
        u64::from(self.tddr) + 1
    }

    fn period(&self) -> u64 {
        (u64::from(self.prd) + 1) * self.per_count()
    }

    /// Bring the timer up to time `t`: every reload at or before it sets TIF (and, with TIE, the
    /// PIE's TINT0 flag); the PIE passes flagged groups to the CPU's IFR.
    pub fn sync(&mut self, t: Ps) {
        let c = self.cycle(t).max(self.synced);
        self.synced = c;
        if let Some(next) = self.next_reload {
            if next <= c {
                let k = (c - next) / self.period() + 1;
                self.underflows += k;
                let last = next + (k - 1) * self.period();
                self.last_underflow = Some(last);
                self.next_reload = Some(next + k * self.period());
                self.tif = true;
                if self.tcr & TCR_TIE != 0 {
                    self.pieifr[0] |= 1 << 6;
                }
            }
        }
        self.pie_to_cpu();
    }

    fn pie_to_cpu(&mut self) {
        if !self.enpie {
            return;
        }
        for g in 0..12 {
            if self.pieifr[g] & self.pieier[g] != 0 && self.pieack & (1 << g) == 0 {
                self.ifr |= 1 << g;
                self.pieack |= 1 << g;
            }
        }
    }

    fn tim(&self) -> u32 {
        match self.next_reload {
            Some(next) => {
                let left = next.saturating_sub(self.synced).div_ceil(self.per_count());
                left.saturating_sub(1) as u32
            }
            None => self.held_tim,
        }
    }

    /// Read a register at time `t` (see [`Interrupts::owns`]).
    pub fn read(&mut self, addr: u32, t: Ps) -> Result<u16> {
        self.sync(t);
        Ok(match addr {
            0x0C00 => self.tim() as u16,
            0x0C01 => (self.tim() >> 16) as u16,
            0x0C02 => self.prd as u16,
            0x0C03 => (self.prd >> 16) as u16,
            0x0C04 => self.tcr | if self.tif { TCR_TIF } else { 0 },
            0x0C06 => self.tddr & 0xFF | (self.tddr & 0xFF) << 8,
            0x0C07 => self.tddr >> 8 | (self.tddr & 0xFF00),
            0x0CE0 => u16::from(self.enpie) | (self.pending_vector().unwrap_or(0) as u16) << 1,
            0x0CE1 => self.pieack,
            a @ 0x0CE2..=0x0CF9 => {
                let g = ((a - 0x0CE2) / 2) as usize;
                if (a - 0x0CE2) % 2 == 0 {
                    self.pieier[g]
                } else {
                    self.pieifr[g]
                }
            }
            a => return Err(no_register(a)),
        })
    }

    /// Write a register at time `t` (see [`Interrupts::owns`]).
    pub fn write(&mut self, addr: u32, value: u16, t: Ps) -> Result<()> {
        self.sync(t);
        let c = self.synced;
        match addr {
            0x0C00 | 0x0C01 => {
                let tim = self.tim();
                let tim = if addr == 0x0C00 {
                    (tim & 0xFFFF_0000) | u32::from(value)
                } else {
                    (tim & 0xFFFF) | u32::from(value) << 16
                };
                self.load(tim, c);
            }
            0x0C02 => self.prd = (self.prd & 0xFFFF_0000) | u32::from(value),
            0x0C03 => self.prd = (self.prd & 0xFFFF) | u32::from(value) << 16,
            0x0C04 => {
                if value & TCR_TIF != 0 {
                    self.tif = false;
                }
                let was_stopped = self.next_reload.is_none();
                let tim = self.tim();
                self.tcr = value & TCR_KEPT;
                let tim = if value & TCR_TRB != 0 { self.prd } else { tim };
                if value & TCR_TSS != 0 {
                    self.next_reload = None;
                    self.held_tim = tim;
                } else if was_stopped || value & TCR_TRB != 0 {
                    self.load_running(tim, c);
                }
            }
            0x0C06 => self.tddr = (self.tddr & 0xFF00) | (value & 0xFF),
            0x0C07 => self.tddr = (self.tddr & 0x00FF) | (value & 0xFF) << 8,
            0x0CE0 => self.enpie = value & 1 != 0,
            0x0CE1 => self.pieack &= !(value & 0x0FFF),
            a @ 0x0CE2..=0x0CF9 => {
                let g = ((a - 0x0CE2) / 2) as usize;
                if (a - 0x0CE2) % 2 == 0 {
                    self.pieier[g] = value & 0xFF;
                } else {
                    self.pieifr[g] = value & 0xFF;
                }
            }
            a => return Err(no_register(a)),
        }
        self.pie_to_cpu();
        Ok(())
    }

    fn load(&mut self, tim: u32, c: u64) {
        if self.next_reload.is_some() {
            self.load_running(tim, c);
        } else {
            self.held_tim = tim;
        }
    }

    fn load_running(&mut self, tim: u32, c: u64) {
        self.next_reload = Some(c + (u64::from(tim) + 1) * self.per_count());
    }

    /// IER.
    pub fn ier(&self) -> u16 {
        self.ier
    }

    /// Set IER (`IER = x`, `IER |= M_INT1`).
    pub fn set_ier(&mut self, value: u16) {
        self.ier = value;
    }

    /// IFR at time `t`.
    pub fn ifr(&mut self, t: Ps) -> u16 {
        self.sync(t);
        self.ifr
    }

    /// Set IFR (`IFR = 0x0000` clears the pending interrupts).
    pub fn set_ifr(&mut self, value: u16, t: Ps) {
        self.sync(t);
        self.ifr = value;
    }

    /// INTM (true: interrupts masked).
    pub fn intm(&self) -> bool {
        self.intm
    }

    /// EINT (`false`) / DINT (`true`).
    pub fn set_intm(&mut self, masked: bool) {
        self.intm = masked;
    }

    /// EALLOW state.
    pub fn eallow(&self) -> bool {
        self.eallow
    }

    /// EALLOW (`true`) / EDIS (`false`).
    pub fn set_eallow(&mut self, on: bool) {
        self.eallow = on;
    }

    /// Set vector `n` to the ISR address `isr`; ignored (returns false) without EALLOW, as the
    /// chip ignores the write. An `n` outside the table is an error.
    pub fn set_vector(&mut self, n: usize, isr: u64) -> Result<bool> {
        if n >= VECTORS {
            return Err(Error::Register(format!(
                "PieVectTable vector {n} (address 0x{:04X}): the table has vectors 0…{} (0x0D00…0x0DFF)",
                PIE_VECT_BASE as usize + 2 * n,
                VECTORS - 1
            )));
        }
        if !self.eallow {
            return Ok(false);
        }
        self.vectors[n] = isr;
        Ok(true)
    }

    /// Vector `n` (0 when never set or out of the table).
    pub fn vector(&self, n: usize) -> u64 {
        self.vectors.get(n).copied().unwrap_or(0)
    }

    /// The vector the PIE would hand over for the CPU's lowest pending INTx (PIECTRL.PIEVECT's
    /// vector number), if any.
    fn pending_vector(&self) -> Option<usize> {
        (0..12).find_map(|g| {
            let live = self.pieifr[g] & self.pieier[g];
            (live != 0).then(|| 32 + 8 * g + live.trailing_zeros() as usize)
        })
    }

    /// The interrupt the CPU takes at time `t`, if any (acknowledged: see the module's doc).
    pub fn take(&mut self, t: Ps) -> Option<Taken> {
        self.sync(t);
        if self.intm {
            return None;
        }
        let live = self.ier & self.ifr & 0x0FFF;
        if live == 0 {
            return None;
        }
        let g = live.trailing_zeros() as usize;
        self.ifr &= !(1 << g);
        let flagged = self.pieifr[g] & self.pieier[g];
        if flagged == 0 {
            // The flag went away between the PIE's request and now (cleared by the firmware):
            // the chip fetches a default vector; the host has no ISR for it, so nothing runs.
            return None;
        }
        let y = flagged.trailing_zeros();
        self.pieifr[g] &= !(1 << y);
        self.saved.push((self.ier, self.intm, self.eallow));
        self.ier &= !(1 << g);
        self.intm = true;
        self.eallow = false;
        let vector = 32 + 8 * g + y as usize;
        Some(Taken { vector, isr: self.vectors[vector] })
    }

    /// IRET: restore IER, INTM and EALLOW as the last interrupt taken found them.
    pub fn iret(&mut self) -> Result<()> {
        let (ier, intm, eallow) =
            self.saved.pop().ok_or_else(|| Error::Input("IRET without an interrupt being serviced".into()))?;
        self.ier = ier;
        self.intm = intm;
        self.eallow = eallow;
        Ok(())
    }

    /// When an interrupt may next become takeable by itself (timer 0's next reload, when it runs and
    /// may interrupt), ps; None when none will without a register access.
    pub fn next_interrupt_ps(&self) -> Option<Ps> {
        if self.blocked().is_some() {
            return None;
        }
        self.next_reload.map(|c| self.sysclkout.cycles_to_ps(c))
    }

    /// Timer 0's next reload, ps (None when stopped).
    pub fn next_reload_ps(&self) -> Option<Ps> {
        self.next_reload.map(|c| self.sysclkout.cycles_to_ps(c))
    }

    /// Timer 0's reloads since power-on, and the time of the last one.
    pub fn underflows(&self) -> (u64, Option<Ps>) {
        (self.underflows, self.last_underflow.map(|c| self.sysclkout.cycles_to_ps(c)))
    }

    /// An interrupt pending right now (taken at the next check) or possible later without any
    /// register access; else what blocks it.
    pub fn blocked(&self) -> Option<Blocked> {
        if self.intm {
            return Some(Blocked::Intm);
        }
        if self.ier & self.ifr & 0x0FFF != 0 {
            return None;
        }
        if self.ier & 1 == 0 {
            return Some(Blocked::Ier);
        }
        if !self.enpie {
            return Some(Blocked::Pie);
        }
        if self.pieier[0] & (1 << 6) == 0 {
            return Some(Blocked::PieIer);
        }
        if self.pieack & 1 != 0 {
            return Some(Blocked::PieAck);
        }
        if self.pieifr[0] & (1 << 6) != 0 {
            return None;
        }
        if self.tcr & TCR_TIE == 0 {
            return Some(Blocked::Tie);
        }
        if self.next_reload.is_none() {
            return Some(Blocked::Stopped);
        }
        None
    }
}

impl Interrupts {
    /// A peripheral's interrupt request at time `t`: PIE group `group` (1…12), line `bit` (1…8).
    /// Sets PIEIFRg bit `bit`; when PIEIERg has it set and the group's PIEACK bit is clear, the
    /// group reaches the CPU's IFR (bit g−1) and PIEACK is set, as the PIE does (SPRUFB0, "PIE").
    /// Out-of-range numbers are ignored.
    pub fn set_pie_flag(&mut self, group: u8, bit: u8, t: Ps) {
        if !(1..=12).contains(&group) || !(1..=8).contains(&bit) {
            return;
        }
        self.sync(t);
        self.pieifr[usize::from(group - 1)] |= 1 << (bit - 1);
        self.pie_to_cpu();
    }
}

fn no_register(addr: u32) -> Error {
    Error::Register(format!("C28x address 0x{addr:04X}: not a CPU timer 0 or PIE register"))
}

#[cfg(test)]
mod tests {
    use super::*;

    const NS: Ps = 1000;

    fn sys() -> Clock {
        Clock::from_hz(150_000_000)
    }

    #[test]
    fn a_peripheral_flag_reaches_ifr_through_its_enable_and_pieack() {
        let mut i = Interrupts::new(sys());
        i.write(0x0CE0, 1, 0).unwrap(); // ENPIE
        i.set_pie_flag(9, 1, 0); // SCIRXINTA, PIEIER9 clear: flagged, not passed on
        assert_eq!(i.read(0x0CF3, 0).unwrap(), 1);
        assert_eq!(i.ifr(0), 0);
        i.write(0x0CF2, 0x3, 0).unwrap(); // PIEIER9.INTx1/2: the pending flag goes to INT9
        assert_eq!(i.ifr(0), 1 << 8);
        assert_eq!(i.read(0x0CE1, 0).unwrap(), 1 << 8);
        i.set_ifr(0, 0);
        i.set_pie_flag(9, 2, 0); // PIEACK group 9 still set: held in the PIE
        assert_eq!(i.ifr(0), 0);
        i.write(0x0CE1, 1 << 8, 0).unwrap();
        assert_eq!(i.ifr(0), 1 << 8);
        i.set_pie_flag(13, 1, 0);
        i.set_pie_flag(8, 9, 0);
        assert_eq!(i.read(0x0CF1, 0).unwrap(), 0);
    }

    /// TI's ConfigCpuTimer(&CpuTimer0, 150, 4000) with C2000Ware's PRD rule, then start with TIE.
    fn configured(i: &mut Interrupts, t: Ps) {
        i.write(0x0C04, TCR_TSS, t).unwrap(); // stop
        i.write(0x0C02, (599_999u32 & 0xFFFF) as u16, t).unwrap();
        i.write(0x0C03, (599_999u32 >> 16) as u16, t).unwrap();
        i.write(0x0C06, 0, t).unwrap();
        i.write(0x0C07, 0, t).unwrap();
        i.write(0x0C04, TCR_TSS | TCR_TRB, t).unwrap();
        i.write(0x0C04, 0x4001, t).unwrap(); // TSS = 0, TIE = 1: start
    }

    #[test]
    fn timer0_ticks_every_prd_plus_one_cycles_and_reaches_the_isr_through_the_pie() {
        let mut i = Interrupts::new(sys());
        let t0 = 3000 * NS; // 450 cycles
        configured(&mut i, t0);
        i.write(0x0CE0, 1, t0).unwrap(); // ENPIE
        i.write(0x0CE2, 1 << 6, t0).unwrap(); // PIEIER1.INTx7
        i.set_ier(1);
        i.set_intm(false);
        i.set_eallow(true);
        assert!(i.set_vector(TINT0_VECTOR, 0xABCD).unwrap());
        i.set_eallow(false);
        let tick = t0 + 4_000_000_000;
        assert_eq!(i.take(tick - 1), None);
        assert_eq!(i.read(0x0C00, tick - 7 * NS).unwrap(), 0, "the counter's last count before the reload");
        assert_eq!(i.take(tick), Some(Taken { vector: TINT0_VECTOR, isr: 0xABCD }));
        assert_eq!(i.underflows(), (1, Some(tick)));
        // In the ISR: INTM set, IER's INT1 cleared, PIEACK group 1 set; a second tick waits.
        assert!(i.intm());
        assert_eq!(i.ier(), 0);
        assert_eq!(i.read(0x0CE1, tick).unwrap(), 1);
        assert_eq!(i.read(0x0C04, tick).unwrap() & TCR_TIF, TCR_TIF);
        i.write(0x0C04, 0x4000 | TCR_TIF, tick).unwrap(); // clear TIF, keep TIE, running
        assert_eq!(i.read(0x0C04, tick).unwrap() & TCR_TIF, 0);
        i.write(0x0CE1, 1, tick).unwrap(); // PIEACK = PIEACK_GROUP1
        i.iret().unwrap();
        assert_eq!((i.ier(), i.intm()), (1, false));
        assert_eq!(i.take(tick + 1), None);
        assert_eq!(i.take(tick + 4_000_000_000).map(|t| t.vector), Some(TINT0_VECTOR));
        assert_eq!(i.underflows().0, 2);
    }

    #[test]
    fn without_pieack_the_next_tick_never_reaches_the_cpu() {
        let mut i = Interrupts::new(sys());
        configured(&mut i, 0);
        i.write(0x0CE0, 1, 0).unwrap();
        i.write(0x0CE2, 1 << 6, 0).unwrap();
        i.set_ier(1);
        i.set_intm(false);
        assert!(i.take(4_000_000_000).is_some());
        i.iret().unwrap();
        assert_eq!(i.take(8_000_000_000), None);
        assert_eq!(i.blocked(), Some(Blocked::PieAck));
        assert_eq!(i.read(0x0CE3, 8_000_000_000).unwrap(), 1 << 6, "the flag waits in PIEIFR1");
        i.write(0x0CE1, 1, 8_000_000_000).unwrap();
        assert!(i.take(8_000_000_000).is_some());
    }

    #[test]
    fn a_vector_write_without_eallow_is_ignored() {
        let mut i = Interrupts::new(sys());
        assert!(!i.set_vector(TINT0_VECTOR, 7).unwrap());
        assert_eq!(i.vector(TINT0_VECTOR), 0);
        assert!(i.set_vector(VECTORS, 7).unwrap_err().to_string().contains("0x0E00"));
    }

    #[test]
    fn what_blocks_an_interrupt_is_named() {
        let mut i = Interrupts::new(sys());
        assert_eq!(i.blocked(), Some(Blocked::Intm));
        i.set_intm(false);
        assert_eq!(i.blocked(), Some(Blocked::Ier));
        i.set_ier(1);
        assert_eq!(i.blocked(), Some(Blocked::Pie));
        i.write(0x0CE0, 1, 0).unwrap();
        assert_eq!(i.blocked(), Some(Blocked::PieIer));
        i.write(0x0CE2, 1 << 6, 0).unwrap();
        assert_eq!(i.blocked(), Some(Blocked::Tie));
        i.write(0x0C04, TCR_TSS | TCR_TIE, 0).unwrap();
        assert_eq!(i.blocked(), Some(Blocked::Stopped));
        i.write(0x0C04, TCR_TIE, 0).unwrap();
        assert_eq!(i.blocked(), None);
        assert_eq!(i.next_interrupt_ps(), i.next_reload_ps());
    }

    #[test]
    fn the_prescaler_divides_the_count_rate() {
        let mut i = Interrupts::new(sys());
        i.write(0x0C04, TCR_TSS, 0).unwrap();
        i.write(0x0C02, 99, 0).unwrap();
        i.write(0x0C03, 0, 0).unwrap();
        i.write(0x0C06, 2, 0).unwrap(); // TDDR = 2: one count per 3 cycles
        i.write(0x0C04, TCR_TRB, 0).unwrap(); // reload and start
        assert_eq!(i.next_reload_ps(), Some(sys().cycles_to_ps(300)));
        assert_eq!(i.read(0x0C00, sys().cycles_to_ps(3)).unwrap(), 98);
        assert_eq!(i.read(0x0C06, 0).unwrap(), 0x0202);
    }
}
