//! CPU timer 0, the PIE and the C28x CPU's interrupt logic, register by register, as a host-built
//! firmware drives them (the [`crate::host::HostBoard`] holds one).
//!
//! - **CPU timers 0, 1, 2** (`CpuTimer0Regs` 0x0C00, `CpuTimer1Regs` 0x0C08, `CpuTimer2Regs`
//!   0x0C10; SPRUFB0, "CPU Timers"): each a [`CpuTimerRegs`] counting SYSCLKOUT cycles. TINT0 goes
//!   through the PIE (group 1, INT7); TINT1 is the CPU's INT13 and TINT2 its INT14, straight to IFR
//!   bits 12 and 13 with no PIE and no PIEACK (SPRUFB0, "CPU Timer Interrupt Signals"). SYSCLKOUT
//!   may change while they run (the PLL: [`Interrupts::set_sysclkout`]); cycles are counted on.
//! - **PIE** (`PieCtrlRegs`, 0x0CE0; SPRUFB0, "Peripheral Interrupt Expansion"): PIECTRL.ENPIE,
//!   PIEACK (write 1 to clear), PIEIER1…12, PIEIFR1…12, reset 0. A group's flag with its enable bit
//!   set reaches the CPU's IFR when the group's PIEACK bit is clear, and sets that bit. A
//!   peripheral raises its line with [`Interrupts::set_pie_flag`].
//! - **CPU**: IER, IFR (TI's `cregister`s), INTM (EINT/DINT) and EALLOW. An interrupt is taken
//!   when INTM = 0 and IER & IFR ≠ 0, lowest INTx first: its IFR bit is cleared, IER, INTM and
//!   EALLOW are saved, its IER bit cleared, INTM set and EALLOW cleared (SPRU430, "Standard
//!   operation for maskable interrupts"); the PIE hands over the vector of the group's
//!   highest-priority flagged and enabled interrupt and clears its PIEIFR bit. [`Interrupts::iret`]
//!   restores what was saved.
//! - **PieVectTable** (0x0D00, EALLOW-protected): 128 vectors. On the host a vector is the address
//!   of a host function, so it is set through [`Interrupts::set_vector`], not as two 16-bit words; a
//!   write without EALLOW is ignored, as on the chip.

use super::timer::CpuTimerRegs;
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
/// INT13's vector number (`PieVectTable.XINT13`, CPU timer 1's TINT1, at 0x0D1A).
pub const INT13_VECTOR: usize = 13;
/// INT14's vector number (`PieVectTable.TINT2`, CPU timer 2, at 0x0D1C).
pub const INT14_VECTOR: usize = 14;

/// The PIE's 96 peripheral interrupts by group and line, as TI's `PIE_VECT_TABLE` names their vectors
/// (vectors 32…127; SPRUFB0, "PIE Vector Table"). `rsvdG_L` are reserved lines.
#[rustfmt::skip]
pub const PIE_NAMES: [&str; 96] = [
    "SEQ1INT", "SEQ2INT", "rsvd1_3", "XINT1", "XINT2", "ADCINT", "TINT0", "WAKEINT",
    "EPWM1_TZINT", "EPWM2_TZINT", "EPWM3_TZINT", "EPWM4_TZINT", "EPWM5_TZINT", "EPWM6_TZINT", "rsvd2_7", "rsvd2_8",
    "EPWM1_INT", "EPWM2_INT", "EPWM3_INT", "EPWM4_INT", "EPWM5_INT", "EPWM6_INT", "rsvd3_7", "rsvd3_8",
    "ECAP1_INT", "ECAP2_INT", "ECAP3_INT", "ECAP4_INT", "ECAP5_INT", "ECAP6_INT", "rsvd4_7", "rsvd4_8",
    "EQEP1_INT", "EQEP2_INT", "rsvd5_3", "rsvd5_4", "rsvd5_5", "rsvd5_6", "rsvd5_7", "rsvd5_8",
    "SPIRXINTA", "SPITXINTA", "MRINTB", "MXINTB", "MRINTA", "MXINTA", "rsvd6_7", "rsvd6_8",
    "DINTCH1", "DINTCH2", "DINTCH3", "DINTCH4", "DINTCH5", "DINTCH6", "rsvd7_7", "rsvd7_8",
    "I2CINT1A", "I2CINT2A", "rsvd8_3", "rsvd8_4", "SCIRXINTC", "SCITXINTC", "rsvd8_7", "rsvd8_8",
    "SCIRXINTA", "SCITXINTA", "SCIRXINTB", "SCITXINTB", "ECAN0INTA", "ECAN1INTA", "ECAN0INTB", "ECAN1INTB",
    "rsvd10_1", "rsvd10_2", "rsvd10_3", "rsvd10_4", "rsvd10_5", "rsvd10_6", "rsvd10_7", "rsvd10_8",
    "rsvd11_1", "rsvd11_2", "rsvd11_3", "rsvd11_4", "rsvd11_5", "rsvd11_6", "rsvd11_7", "rsvd11_8",
    "XINT3", "XINT4", "XINT5", "XINT6", "XINT7", "rsvd12_6", "LVF", "LUF",
];

/// The name of PieVectTable vector `n` (TI's field name; vectors 1…12 are reserved for INT1…12,
/// which the PIE serves from 32…127).
pub fn vector_name(n: usize) -> &'static str {
    #[rustfmt::skip]
    const LOW: [&str; 32] = [
        "PIE_RESERVED", "rsvd1_1", "rsvd1_2", "rsvd1_3", "rsvd1_4", "rsvd1_5", "rsvd1_6", "rsvd1_7", "rsvd1_8",
        "rsvd1_9", "rsvd1_10", "rsvd1_11", "rsvd1_12", "XINT13", "TINT2", "DATALOG", "RTOSINT", "EMUINT", "XNMI",
        "ILLEGAL", "USER1", "USER2", "USER3", "USER4", "USER5", "USER6", "USER7", "USER8", "USER9", "USER10",
        "USER11", "USER12",
    ];
    match n {
        0..=31 => LOW[n],
        32..=127 => PIE_NAMES[n - 32],
        _ => "?",
    }
}

/// The registers of this module: name, address, width in bits.
pub const REGISTERS: &[(&str, u32, u32)] = &[
    ("TIMER0TIM", 0x0C00, 32),
    ("TIMER0PRD", 0x0C02, 32),
    ("TIMER0TCR", 0x0C04, 16),
    ("TIMER0TPR", 0x0C06, 16),
    ("TIMER0TPRH", 0x0C07, 16),
    ("TIMER1TIM", 0x0C08, 32),
    ("TIMER1PRD", 0x0C0A, 32),
    ("TIMER1TCR", 0x0C0C, 16),
    ("TIMER1TPR", 0x0C0E, 16),
    ("TIMER1TPRH", 0x0C0F, 16),
    ("TIMER2TIM", 0x0C10, 32),
    ("TIMER2PRD", 0x0C12, 32),
    ("TIMER2TCR", 0x0C14, 16),
    ("TIMER2TPR", 0x0C16, 16),
    ("TIMER2TPRH", 0x0C17, 16),
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

/// An interrupt the CPU takes now.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Taken {
    /// The PIE vector number (38 for TINT0).
    pub vector: usize,
    /// The ISR's address (as set in PieVectTable; 0 when never set).
    pub isr: u64,
}

/// Why no interrupt can come while the CPU's state stays as it is (for the diagnostic of a loop that
/// makes no register access), naming the interrupt concerned: the first one the firmware enabled
/// (in PIEIERx, or IER's INT13/INT14), else TINT0.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Blocked {
    /// INTM is set (DINT, or inside an ISR that did not EINT).
    Intm,
    /// The interrupt's IER bit (`INTn`, n = 1…14) is clear.
    Ier {
        /// The CPU interrupt, 1…14.
        int: u8,
        /// The interrupt's vector name.
        name: &'static str,
    },
    /// PIECTRL.ENPIE is 0.
    Pie {
        /// The interrupt's vector name.
        name: &'static str,
    },
    /// Its PIEIERg.INTxl bit is 0.
    PieIer {
        /// PIE group, 1…12.
        group: u8,
        /// Line in the group, 1…8.
        line: u8,
        /// The interrupt's vector name.
        name: &'static str,
    },
    /// A CPU timer's TCR.TIE is 0.
    Tie {
        /// Timer 0, 1 or 2.
        timer: u8,
    },
    /// A CPU timer is stopped (TCR.TSS = 1).
    Stopped {
        /// Timer 0, 1 or 2.
        timer: u8,
    },
    /// The group's PIEACK bit is set and nothing will clear it.
    PieAck {
        /// PIE group, 1…12.
        group: u8,
    },
    /// Its path is open, but no modelled peripheral will raise its flag by itself.
    NoSource {
        /// The interrupt's vector name.
        name: &'static str,
    },
    /// Its path is open and its peripheral set to raise it, but nothing is under way that would.
    Idle {
        /// The interrupts concerned.
        name: &'static str,
    },
}

impl Blocked {
    /// What blocks, in words.
    pub fn text(self) -> String {
        match self {
            Blocked::Intm => "INTM is set (DINT, or inside an ISR)".into(),
            Blocked::Ier { int, name } => {
                format!("IER has INT{int} (M_INT{int}, the CPU interrupt of {name}) clear")
            }
            Blocked::Pie { name } => format!("PIECTRL.ENPIE is 0 (the PIE is disabled; {name} goes through it)"),
            Blocked::PieIer { group, line, name } => format!("PIEIER{group}.INTx{line} ({name}) is 0"),
            Blocked::Tie { timer } => format!("CpuTimer{timer}Regs.TCR.TIE is 0"),
            Blocked::Stopped { timer } => format!("CPU timer {timer} is stopped (TCR.TSS = 1)"),
            Blocked::PieAck { group } => {
                format!("PIEACK group {group} is set (the ISR never wrote PIEACK = PIEACK_GROUP{group})")
            }
            Blocked::NoSource { name } => {
                format!("{name} is enabled, but its peripheral is not set to raise it")
            }
            Blocked::Idle { name } => {
                format!("{name} enabled, but nothing under way will raise it (no transfer, no running timer)")
            }
        }
    }
}

/// The CPU timers, the PIE and the CPU's interrupt state.
#[derive(Debug, Clone)]
pub struct Interrupts {
    sysclkout: Clock,
    /// Cycles are counted from this time and cycle on at `sysclkout` (the last clock change).
    epoch_ps: Ps,
    epoch_cycle: u64,
    timers: [CpuTimerRegs; 3],
    /// Cycle the state was brought up to.
    synced: u64,
    enpie: bool,
    pieack: u16,
    pieier: [u16; 12],
    pieifr: [u16; 12],
    /// PIE lines a peripheral will raise by itself once its condition holds (set by the board).
    armed: [u16; 12],
    ier: u16,
    ifr: u16,
    intm: bool,
    eallow: bool,
    /// Contexts saved by the interrupts being serviced: IER, INTM, EALLOW.
    saved: Vec<(u16, bool, bool)>,
    vectors: Vec<u64>,
}

impl Interrupts {
    /// The reset state at cycle 0: the timers running with PRD = TIM = 0xFFFFFFFF and TIE = 0, PIE
    /// disabled, IER = IFR = 0, INTM = 1, EALLOW = 0, every vector 0.
    pub fn new(sysclkout: Clock) -> Interrupts {
        Interrupts {
            sysclkout,
            epoch_ps: 0,
            epoch_cycle: 0,
            timers: Default::default(),
            synced: 0,
            enpie: false,
            pieack: 0,
            pieier: [0; 12],
            pieifr: [0; 12],
            armed: [0; 12],
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
        matches!(addr, 0x0C00..=0x0C17 if addr % 8 != 5) || matches!(addr, 0x0CE0..=0x0CF9)
    }

    /// The name of the register at `addr` (the low word's for a 32-bit one).
    pub fn register_name(addr: u32) -> Option<&'static str> {
        REGISTERS.iter().find(|r| addr >= r.1 && addr < r.1 + r.2 / 16).map(|r| r.0)
    }

    fn cycle(&self, t: Ps) -> u64 {
        self.epoch_cycle + self.sysclkout.ps_to_cycles(t.saturating_sub(self.epoch_ps))
    }

    fn ps_of(&self, c: u64) -> Ps {
        self.epoch_ps + self.sysclkout.cycles_to_ps(c.saturating_sub(self.epoch_cycle))
    }

    /// CPU timer `n`'s clock (PCLKCR3.CPUTIMERnENCLK) goes off or on at time `t`: brought up to `t`,
    /// then held or counting on ([`super::timer::CpuTimerRegs::set_clock`]).
    pub fn set_timer_clock(&mut self, n: usize, on: bool, t: Ps) {
        self.sync(t);
        let c = self.synced;
        if let Some(tm) = self.timers.get_mut(n) {
            tm.set_clock(on, c);
        }
    }

    /// SYSCLKOUT changes at time `t` (the PLL, SPRUFB0 "PLL-Based Clock Module"): the timers are
    /// brought up to `t` and count on at the new rate.
    pub fn set_sysclkout(&mut self, clock: Clock, t: Ps) {
        self.sync(t);
        self.epoch_cycle = self.synced;
        self.epoch_ps = t;
        self.sysclkout = clock;
    }

    /// Raise a peripheral's interrupt line at time `t`: PIE group `group` (1…12), line `bit` (1…8)
    /// sets its PIEIFR bit; if its PIEIER bit is set, the PIE is enabled and the group's PIEACK bit
    /// is clear, the CPU's IFR bit `group − 1` is set (and PIEACK's with it). Numbers out of range
    /// are the caller's bug: ignored (a debug build panics).
    pub fn set_pie_flag(&mut self, group: u8, bit: u8, t: Ps) {
        debug_assert!((1..=12).contains(&group) && (1..=8).contains(&bit), "PIE INT{group}.{bit}");
        if !(1..=12).contains(&group) || !(1..=8).contains(&bit) {
            return;
        }
        self.sync(t);
        self.pieifr[usize::from(group - 1)] |= 1 << (bit - 1);
        self.pie_to_cpu();
    }

    /// Say whether a peripheral will raise PIE line `group`.`bit` by itself once its condition holds
    /// (its interrupt enabled in the peripheral): for the diagnostic of a loop nothing can interrupt.
    pub fn set_armed(&mut self, group: u8, bit: u8, armed: bool) {
        if let Some(a) = self.armed.get_mut(usize::from(group.wrapping_sub(1))) {
            let m = 1u16 << (bit.wrapping_sub(1) & 7);
            *a = if armed { *a | m } else { *a & !m };
        }
    }

    /// Bring the timers up to time `t`: every reload at or before it sets TIF (and, with TIE,
    /// TINT0's PIE flag, INT13's or INT14's IFR bit); the PIE passes flagged groups to the CPU.
    pub fn sync(&mut self, t: Ps) {
        let c = self.cycle(t).max(self.synced);
        self.synced = c;
        if self.timers[0].sync(c) {
            self.pieifr[0] |= 1 << 6;
        }
        if self.timers[1].sync(c) {
            self.ifr |= 1 << 12;
        }
        if self.timers[2].sync(c) {
            self.ifr |= 1 << 13;
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

    /// Read a register at time `t` (see [`Interrupts::owns`]).
    pub fn read(&mut self, addr: u32, t: Ps) -> Result<u16> {
        self.sync(t);
        let c = self.synced;
        Ok(match addr {
            0x0C00..=0x0C17 => {
                let (n, off) = ((addr - 0x0C00) / 8, (addr - 0x0C00) % 8);
                self.timers[n as usize].read(off, c).ok_or_else(|| no_register(addr))?
            }
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
            0x0C00..=0x0C17 => {
                let (n, off) = ((addr - 0x0C00) / 8, (addr - 0x0C00) % 8);
                if !self.timers[n as usize].write(off, value, c) {
                    return Err(no_register(addr));
                }
            }
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

    /// IFR as last brought up to date.
    pub fn ifr_now(&self) -> u16 {
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

    /// The interrupt the CPU takes at time `t`, if any (acknowledged: see the module's doc). INT13
    /// and INT14 (timers 1 and 2) bypass the PIE: their vectors are 13 and 14.
    pub fn take(&mut self, t: Ps) -> Option<Taken> {
        self.sync(t);
        if self.intm {
            return None;
        }
        let live = self.ier & self.ifr & 0x3FFF;
        if live == 0 {
            return None;
        }
        let g = live.trailing_zeros() as usize;
        self.ifr &= !(1 << g);
        let vector = if g >= 12 {
            g + 1
        } else {
            let flagged = self.pieifr[g] & self.pieier[g];
            if flagged == 0 {
                // The flag went away between the PIE's request and now (cleared by the firmware):
                // the chip fetches a default vector; the host has no ISR for it, so nothing runs.
                return None;
            }
            let y = flagged.trailing_zeros();
            self.pieifr[g] &= !(1 << y);
            32 + 8 * g + y as usize
        };
        self.saved.push((self.ier, self.intm, self.eallow));
        self.ier &= !(1 << g);
        self.intm = true;
        self.eallow = false;
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

    /// When an interrupt may next become takeable by itself (a timer's next reload, when any may
    /// interrupt), ps; None when none will without a register access. A peripheral's own flags
    /// (SPI-A's) are the board's to add.
    pub fn next_interrupt_ps(&self) -> Option<Ps> {
        if self.blocked().is_some() {
            return None;
        }
        self.timers.iter().filter(|t| t.tie()).filter_map(|t| t.next_reload()).min().map(|c| self.ps_of(c))
    }

    /// Timer 0's next reload, ps (None when stopped).
    pub fn next_reload_ps(&self) -> Option<Ps> {
        self.next_reload_ps_of(0)
    }

    /// Timer `n`'s next reload, ps (None when stopped).
    pub fn next_reload_ps_of(&self, n: usize) -> Option<Ps> {
        self.timers[n].next_reload().map(|c| self.ps_of(c))
    }

    /// Timer 0's reloads since power-on, and the time of the last one.
    pub fn underflows(&self) -> (u64, Option<Ps>) {
        let (n, last) = self.timers[0].underflows();
        (n, last.map(|c| self.ps_of(c)))
    }

    /// The time of timer 0's `k`-th reload (`k` ≤ the reloads so far), counted back from the last at
    /// its period now (a PRD written between them is not seen); None before the first.
    pub fn underflow_ps(&self, k: u64) -> Option<Ps> {
        let (n, last) = self.timers[0].underflows();
        let back = n.checked_sub(k)?.checked_mul(self.timers[0].reload_period())?;
        Some(self.ps_of(last?.checked_sub(back)?))
    }

    /// The interrupts whose path the firmware opened at least partly, in priority order: (CPU
    /// interrupt 1…14, PIE line 1…8 or 0, vector). TINT0 when there is none.
    fn candidates(&self) -> Vec<(u8, u8, usize)> {
        let mut out = Vec::new();
        for g in 0..12u8 {
            for l in 0..8u8 {
                if self.pieier[usize::from(g)] & (1 << l) != 0 {
                    out.push((g + 1, l + 1, 32 + 8 * usize::from(g) + usize::from(l)));
                }
            }
        }
        if self.ier & (1 << 12) != 0 || self.timers[1].tie() {
            out.push((13, 0, INT13_VECTOR));
        }
        if self.ier & (1 << 13) != 0 || self.timers[2].tie() {
            out.push((14, 0, INT14_VECTOR));
        }
        if out.is_empty() {
            out.push((1, 7, TINT0_VECTOR));
        }
        out
    }

    fn timer_path(&self, n: usize) -> Option<Blocked> {
        let tm = &self.timers[n];
        if !tm.tie() {
            Some(Blocked::Tie { timer: n as u8 })
        } else if tm.next_reload().is_none() {
            Some(Blocked::Stopped { timer: n as u8 })
        } else {
            None
        }
    }

    fn path(&self, (int, line, vector): (u8, u8, usize)) -> Option<Blocked> {
        let name = vector_name(vector);
        let g = usize::from(int - 1);
        if self.ier & (1 << g) == 0 {
            return Some(Blocked::Ier { int, name });
        }
        if int >= 13 {
            return self.timer_path(usize::from(int - 12));
        }
        if !self.enpie {
            return Some(Blocked::Pie { name });
        }
        let m = 1u16 << (line - 1);
        if self.pieier[g] & m == 0 {
            return Some(Blocked::PieIer { group: int, line, name });
        }
        if self.pieack & (1 << g) != 0 {
            return Some(Blocked::PieAck { group: int });
        }
        if self.pieifr[g] & m != 0 {
            return None;
        }
        if vector == TINT0_VECTOR {
            return self.timer_path(0);
        }
        if self.armed[g] & m != 0 {
            None
        } else {
            Some(Blocked::NoSource { name })
        }
    }

    /// An interrupt pending right now (taken at the next check) or possible later without any
    /// register access; else what blocks the first interrupt the firmware enabled.
    pub fn blocked(&self) -> Option<Blocked> {
        if self.intm {
            return Some(Blocked::Intm);
        }
        if self.ier & self.ifr & 0x3FFF != 0 {
            return None;
        }
        let mut first = None;
        for c in self.candidates() {
            match self.path(c) {
                None => return None,
                Some(b) => {
                    first.get_or_insert(b);
                }
            }
        }
        first
    }
}

fn no_register(addr: u32) -> Error {
    Error::Register(format!("C28x address 0x{addr:04X}: not a CPU timer or PIE register"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dsp::timer::{TCR_TIE, TCR_TIF, TCR_TRB, TCR_TSS};

    const NS: Ps = 1000;
    const US: Ps = 1_000_000;

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
        assert_eq!(i.blocked(), Some(Blocked::PieAck { group: 1 }));
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
        assert_eq!(i.blocked(), Some(Blocked::Ier { int: 1, name: "TINT0" }));
        i.set_ier(1);
        assert_eq!(i.blocked(), Some(Blocked::Pie { name: "TINT0" }));
        i.write(0x0CE0, 1, 0).unwrap();
        assert_eq!(i.blocked(), Some(Blocked::PieIer { group: 1, line: 7, name: "TINT0" }));
        i.write(0x0CE2, 1 << 6, 0).unwrap();
        assert_eq!(i.blocked(), Some(Blocked::Tie { timer: 0 }));
        i.write(0x0C04, TCR_TSS | TCR_TIE, 0).unwrap();
        assert_eq!(i.blocked(), Some(Blocked::Stopped { timer: 0 }));
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
    #[test]
    fn set_pie_flag_reaches_ifr_only_through_an_enabled_unacknowledged_line() {
        let mut i = Interrupts::new(sys());
        i.set_pie_flag(6, 1, 0); // SPIRXINTA with the PIE off: flagged, not passed on
        assert_eq!((i.read(0x0CED, 0).unwrap(), i.ifr(0)), (1, 0));
        i.write(0x0CE0, 1, 0).unwrap();
        assert_eq!(i.ifr(0), 0, "PIEIER6.INTx1 is 0");
        i.write(0x0CEC, 0b11, 0).unwrap(); // PIEIER6: SPIRXINTA, SPITXINTA
        assert_eq!((i.ifr(0), i.read(0x0CE1, 0).unwrap()), (1 << 5, 1 << 5), "IFR bit 5, PIEACK group 6");
        i.set_ier(1 << 5);
        i.set_intm(false);
        i.set_eallow(true);
        i.set_vector(72, 0x72).unwrap();
        i.set_vector(73, 0x73).unwrap();
        i.set_eallow(false);
        assert_eq!(i.take(0), Some(Taken { vector: 72, isr: 0x72 }));
        i.iret().unwrap();
        i.set_pie_flag(6, 2, 1); // SPITXINTA: waits for PIEACK
        assert_eq!(i.take(1), None);
        assert_eq!(i.blocked(), Some(Blocked::PieAck { group: 6 }));
        i.write(0x0CE1, 1 << 5, 1).unwrap();
        assert_eq!(i.take(1).map(|t| t.vector), Some(73));
        assert_eq!(vector_name(72), "SPIRXINTA");
        assert_eq!(vector_name(73), "SPITXINTA");
    }

    #[test]
    fn timers_1_and_2_interrupt_on_int13_and_int14_without_the_pie() {
        let mut i = Interrupts::new(sys());
        for base in [0x0C08, 0x0C10] {
            i.write(base + 4, TCR_TSS, 0).unwrap();
            i.write(base + 2, if base == 0x0C08 { 149 } else { 299 }, 0).unwrap(); // 1 µs and 2 µs
            i.write(base + 3, 0, 0).unwrap();
            i.write(base + 4, TCR_TIE | TCR_TRB, 0).unwrap();
        }
        i.set_ier((1 << 12) | (1 << 13));
        i.set_intm(false);
        assert_eq!(i.take(US - 1), None);
        assert_eq!(i.take(US).map(|t| t.vector), Some(INT13_VECTOR));
        i.iret().unwrap();
        assert_eq!(i.take(2 * US).map(|t| t.vector), Some(INT13_VECTOR), "INT13 before INT14");
        i.iret().unwrap();
        assert_eq!(i.take(2 * US).map(|t| t.vector), Some(INT14_VECTOR));
        i.iret().unwrap();
        assert_eq!(i.read(0x0CE1, 2 * US).unwrap(), 0, "no PIEACK for INT13/INT14");
        assert_eq!((vector_name(13), vector_name(14)), ("XINT13", "TINT2"));
    }

    #[test]
    fn a_sysclkout_change_rescales_the_running_timers() {
        let mut i = Interrupts::new(sys());
        i.write(0x0C04, TCR_TSS, 0).unwrap();
        i.write(0x0C02, 1499, 0).unwrap(); // 1500 cycles: 10 µs at 150 MHz
        i.write(0x0C03, 0, 0).unwrap();
        i.write(0x0C04, TCR_TIE | TCR_TRB, 0).unwrap();
        assert_eq!(i.next_reload_ps(), Some(10 * US));
        // Half way, SYSCLKOUT halves: the other 750 cycles take 10 µs.
        i.set_sysclkout(Clock::from_hz(75_000_000), 5 * US);
        assert_eq!(i.next_reload_ps(), Some(15 * US));
        assert_eq!(i.read(0x0C00, 5 * US).unwrap(), 749);
    }
}
