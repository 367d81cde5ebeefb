//! McBSP-A and McBSP-B (`McbspaRegs` 0x5000, `McbspbRegs` 0x5040) as far as an SPI master uses
//! them: the clock-stop (SPI) mode with the internal sample-rate generator, the digital loopback
//! (DLB) of TI's McBSP SPI loopback example, RRDY/XRDY/RFULL/XEMPTY, the word lengths 8…32 bits.
//!
//! Source: TI SPRUFB7, *TMS320x2833x, 2823x Multichannel Buffered Serial Port (McBSP) Reference
//! Guide*, with the facts of spec `f28335-peripherals.md` §8 (register offsets from TI's
//! `DSP2833x_McBSP.h`; TI's SPI-master set-up):
//! - Registers (offset): DRR2 0, DRR1 1, DXR2 2, DXR1 3, SPCR2 4, SPCR1 5, RCR2 6, RCR1 7, XCR2 8,
//!   XCR1 9, SRGR2 0xA, SRGR1 0xB, MCR2 0xC, MCR1 0xD, RCERA…XCERB 0xE–0x11, PCR 0x12,
//!   RCERC…XCERH 0x13–0x1E, MFFINT 0x23. Not EALLOW-protected.
//! - Reset values: SRGR2 0x2000 (CLKSM = 1), SRGR1 0x0001 (CLKGDV = 1), every other 0
//!   [unconfirmed, SPRUFB7's register descriptions; the spec's §10 says "McBSP 0"].
//! - SPCR1: 0 RRST, 1 RRDY (read-only), 2 RFULL (read-only), 12:11 CLKSTP, 15 DLB. SPCR2: 0 XRST,
//!   1 XRDY (read-only), 2 XEMPTY (read-only, active low: 0 = the transmit shift register is
//!   empty), 6 GRST, 7 FRST. RCR1/XCR1 7:5 the word length code (0…5 = 8, 12, 16, 20, 24, 32 bits).
//!   RCR2/XCR2 1:0 the data delay. SRGR1 7:0 CLKGDV; SRGR2 13 CLKSM. PCR 9 CLKXM, 11 FSXM.
//! - The bit clock CLKG = LSPCLK / (CLKGDV + 1) (CLKSM = 1, the only input modelled).
//! - A write of DXR1 (after DXR2 for words above 16 bits) with the transmitter out of reset
//!   (XRST = 1) and the sample-rate generator running (GRST = 1) starts a word: XRDY falls while
//!   DXR is full and rises when the word moves into the shift register (at once when it is empty);
//!   the word takes XDATDLY + its bits CLKG periods [unconfirmed: the data delay counted as whole
//!   clocks]. A write of DXR1 while GRST = 0 waits for GRST. A word written while another shifts
//!   starts when that one ends.
//! - At a word's end the receiver (RRST = 1) takes what DR shows: the word sent, with DLB = 1; with
//!   DLB = 0 the MDR pin, which no part drives on this board (every bit 1, the floating level). DRR
//!   gets it and RRDY rises; a word that ends with RRDY still set is lost and sets RFULL
//!   [unconfirmed]. Reading DRR1 clears RRDY and RFULL.
//! - Interrupts: with SPCR1.RINTM = 00 the receive interrupt (MRINT) is raised when RRDY rises
//!   (a word reaches DRR); with SPCR2.XINTM = 00 the transmit interrupt (MXINT) when XRDY rises
//!   (the transmitter leaves reset with DXR empty, or a word moves from DXR into the shift
//!   register). Their PIE lines (spec §6 table, TI's `DSP2833x_PieVect.h`, vectors 74–77):
//!   MRINTB INT6.3, MXINTB INT6.4, MRINTA INT6.5, MXINTA INT6.6. The other RINTM/XINTM modes
//!   (end of block, frame sync, sync error) and MFFINT are stored, not raised [not modelled].

use crate::dsp::interrupts::Interrupts;
use crate::time::{Clock, Ps};

/// McBSP-A's base address.
pub const MCBSPA_BASE: u32 = 0x5000;
/// McBSP-B's base address.
pub const MCBSPB_BASE: u32 = 0x5040;
/// Words modelled per McBSP (DRR2…MFFINT).
pub const WORDS: u32 = 0x24;

const DRR2: usize = 0x0;
const DRR1: usize = 0x1;
const DXR2: usize = 0x2;
const DXR1: usize = 0x3;
const SPCR2: usize = 0x4;
const SPCR1: usize = 0x5;
const RCR1: usize = 0x7;
const XCR2: usize = 0x8;
const XCR1: usize = 0x9;
const SRGR2: usize = 0xA;
const SRGR1: usize = 0xB;

const RRST: u16 = 1 << 0;
const RRDY: u16 = 1 << 1;
const RFULL: u16 = 1 << 2;
const DLB: u16 = 1 << 15;
const XRST: u16 = 1 << 0;
const XRDY: u16 = 1 << 1;
const XEMPTY: u16 = 1 << 2;
const GRST: u16 = 1 << 6;
/// SPCR1.RINTM / SPCR2.XINTM (bits 5:4): 00 raises the interrupt on RRDY / XRDY.
const INTM: u16 = 3 << 4;
/// PIE group of the McBSP lines.
const PIE_GROUP: u8 = 6;
/// PIE lines in group 6 (receive, transmit) of McBSP-A and McBSP-B.
const PIE_LINES: [(u8, u8); 2] = [(5, 6), (3, 4)];

/// The registers of one McBSP: name and offset (SPRUFB7's register map).
pub const REGISTER_NAMES: &[(&str, u32)] = &[
    ("DRR2", 0x0),
    ("DRR1", 0x1),
    ("DXR2", 0x2),
    ("DXR1", 0x3),
    ("SPCR2", 0x4),
    ("SPCR1", 0x5),
    ("RCR2", 0x6),
    ("RCR1", 0x7),
    ("XCR2", 0x8),
    ("XCR1", 0x9),
    ("SRGR2", 0xA),
    ("SRGR1", 0xB),
    ("MCR2", 0xC),
    ("MCR1", 0xD),
    ("PCR", 0x12),
    ("MFFINT", 0x23),
];

/// The registers, named `MCBSPA_SPCR1` etc. (the host board's register table).
pub const REGISTERS: &[(&str, u32, u32)] = &[
    ("MCBSPA_DRR2", 0x5000, 16),
    ("MCBSPA_DRR1", 0x5001, 16),
    ("MCBSPA_DXR2", 0x5002, 16),
    ("MCBSPA_DXR1", 0x5003, 16),
    ("MCBSPA_SPCR2", 0x5004, 16),
    ("MCBSPA_SPCR1", 0x5005, 16),
    ("MCBSPA_RCR2", 0x5006, 16),
    ("MCBSPA_RCR1", 0x5007, 16),
    ("MCBSPA_XCR2", 0x5008, 16),
    ("MCBSPA_XCR1", 0x5009, 16),
    ("MCBSPA_SRGR2", 0x500A, 16),
    ("MCBSPA_SRGR1", 0x500B, 16),
    ("MCBSPA_PCR", 0x5012, 16),
    ("MCBSPA_MFFINT", 0x5023, 16),
    ("MCBSPB_DRR2", 0x5040, 16),
    ("MCBSPB_DRR1", 0x5041, 16),
    ("MCBSPB_DXR2", 0x5042, 16),
    ("MCBSPB_DXR1", 0x5043, 16),
    ("MCBSPB_SPCR2", 0x5044, 16),
    ("MCBSPB_SPCR1", 0x5045, 16),
    ("MCBSPB_RCR2", 0x5046, 16),
    ("MCBSPB_RCR1", 0x5047, 16),
    ("MCBSPB_XCR2", 0x5048, 16),
    ("MCBSPB_XCR1", 0x5049, 16),
    ("MCBSPB_SRGR2", 0x504A, 16),
    ("MCBSPB_SRGR1", 0x504B, 16),
    ("MCBSPB_PCR", 0x5052, 16),
    ("MCBSPB_MFFINT", 0x5063, 16),
];

/// The reset value of the word at `offset`.
fn reset_value(offset: usize) -> u16 {
    match offset {
        SRGR2 => 0x2000,
        SRGR1 => 0x0001,
        _ => 0,
    }
}

/// The bits of a word length code (RWDLEN1/XWDLEN1): 8, 12, 16, 20, 24, 32; codes 6 and 7 are
/// reserved, taken as 32 [unconfirmed].
pub fn word_bits(code: u16) -> u32 {
    match code & 7 {
        0 => 8,
        1 => 12,
        2 => 16,
        3 => 20,
        4 => 24,
        _ => 32,
    }
}

/// One McBSP.
#[derive(Debug, Clone)]
pub struct Mcbsp {
    regs: [u16; WORDS as usize],
    /// The word shifting and its end.
    shifting: Option<(u32, Ps)>,
    /// A word written to DXR waiting for the shift register (or for GRST).
    dxr_full: Option<u32>,
    /// Interrupt requests not yet handed to the PIE: (receive line, time).
    requests: Vec<(bool, Ps)>,
}

impl Default for Mcbsp {
    fn default() -> Self {
        Mcbsp::new()
    }
}

impl Mcbsp {
    /// At reset.
    pub fn new() -> Mcbsp {
        let mut regs = [0u16; WORDS as usize];
        for (k, r) in regs.iter_mut().enumerate() {
            *r = reset_value(k);
        }
        Mcbsp { regs, shifting: None, dxr_full: None, requests: Vec::new() }
    }

    fn word_mask(bits: u32) -> u32 {
        if bits >= 32 {
            u32::MAX
        } else {
            (1 << bits) - 1
        }
    }

    fn tx_bits(&self) -> u32 {
        word_bits(self.regs[XCR1] >> 5)
    }

    fn rx_bits(&self) -> u32 {
        word_bits(self.regs[RCR1] >> 5)
    }

    /// CLKG = LSPCLK / (CLKGDV + 1).
    fn clkg(&self, lspclk: Clock) -> Clock {
        lspclk.divided(u64::from(self.regs[SRGR1] & 0xFF) + 1)
    }

    fn running(&self) -> bool {
        self.regs[SPCR2] & XRST != 0 && self.regs[SPCR2] & GRST != 0
    }

    /// Start the word waiting in DXR at `t` if the shift register is free.
    fn start(&mut self, t: Ps, lspclk: Clock) {
        if self.shifting.is_some() || !self.running() {
            return;
        }
        let Some(word) = self.dxr_full.take() else { return };
        self.xrdy_rises(t);
        let clkg = self.clkg(lspclk);
        let delay = u64::from(self.regs[XCR2] & 3);
        let first = clkg.ps_to_cycles_ceil(t);
        let end = clkg.cycles_to_ps(first + delay + u64::from(self.tx_bits()));
        self.shifting = Some((word, end.max(t)));
    }

    /// Everything that happens up to `t`: words end, the next one starts.
    pub fn advance(&mut self, t: Ps, lspclk: Clock) {
        while let Some((word, end)) = self.shifting.filter(|s| s.1 <= t) {
            self.shifting = None;
            self.receive(word, end);
            self.start(end, lspclk);
        }
    }

    /// XRDY rises at `t`: MXINT with XINTM = 00.
    fn xrdy_rises(&mut self, t: Ps) {
        if self.regs[SPCR2] & INTM == 0 {
            self.requests.push((false, t));
        }
    }

    /// Whether (MRINT, MXINT) will be raised by themselves: the receiver (transmitter) out of
    /// reset with RINTM (XINTM) = 00.
    fn armed(&self) -> (bool, bool) {
        let on = |r: u16, rst: u16| r & rst != 0 && r & INTM == 0;
        (on(self.regs[SPCR1], RRST), on(self.regs[SPCR2], XRST))
    }

    /// When a line may next be raised by itself: the end of the shifting word, if a line is armed.
    pub fn next_interrupt_ps(&self) -> Option<Ps> {
        let (rx, tx) = self.armed();
        self.shifting.filter(|_| rx || tx).map(|s| s.1)
    }

    /// A word ended at `t`: the receiver takes what DR shows.
    fn receive(&mut self, sent: u32, t: Ps) {
        if self.regs[SPCR1] & RRST == 0 {
            return;
        }
        let bits = self.rx_bits();
        let dr = if self.regs[SPCR1] & DLB != 0 { sent } else { u32::MAX };
        let word = dr & Mcbsp::word_mask(bits);
        if self.regs[SPCR1] & RRDY != 0 {
            self.regs[SPCR1] |= RFULL;
            return;
        }
        self.regs[DRR1] = word as u16;
        self.regs[DRR2] = if bits > 16 { (word >> 16) as u16 } else { 0 };
        self.regs[SPCR1] |= RRDY;
        if self.regs[SPCR1] & INTM == 0 {
            self.requests.push((true, t));
        }
    }

    /// The time the next word ends (a flag changes then), if one is shifting.
    pub fn next_change_ps(&self) -> Option<Ps> {
        self.shifting.map(|s| s.1)
    }

    /// Read the word at `offset` (0…0x23) at `t` (after [`Mcbsp::advance`]).
    pub fn read(&mut self, offset: u32) -> u16 {
        let o = offset as usize;
        match o {
            SPCR2 => {
                let mut v = self.regs[SPCR2] & !(XRDY | XEMPTY);
                if v & XRST != 0 && self.dxr_full.is_none() {
                    v |= XRDY;
                }
                if self.shifting.is_some() || self.dxr_full.is_some() {
                    v |= XEMPTY; // active low: 1 = not empty
                }
                v
            }
            DRR1 => {
                let v = self.regs[DRR1];
                self.regs[SPCR1] &= !(RRDY | RFULL);
                v
            }
            _ => self.regs[o],
        }
    }

    /// Write the word at `offset` at `t` (after [`Mcbsp::advance`]).
    pub fn write(&mut self, offset: u32, value: u16, t: Ps, lspclk: Clock) {
        let o = offset as usize;
        match o {
            SPCR1 => {
                let ro = RRDY | RFULL;
                let mut v = (value & !ro) | (self.regs[SPCR1] & ro);
                if v & RRST == 0 {
                    v &= !ro; // the receiver in reset: its flags clear
                }
                self.regs[SPCR1] = v;
            }
            SPCR2 => {
                let was_reset = self.regs[SPCR2] & XRST == 0;
                self.regs[SPCR2] = value & !(XRDY | XEMPTY);
                if was_reset && value & XRST != 0 && self.dxr_full.is_none() {
                    self.xrdy_rises(t); // out of reset with DXR empty: XRDY rises
                }
                if value & XRST == 0 {
                    self.dxr_full = None;
                    self.shifting = None;
                }
                self.start(t, lspclk);
            }
            DXR1 => {
                self.regs[DXR1] = value;
                if self.regs[SPCR2] & XRST != 0 {
                    let word = (u32::from(self.regs[DXR2]) << 16 | u32::from(value)) & Mcbsp::word_mask(self.tx_bits());
                    self.dxr_full = Some(word);
                    self.start(t, lspclk);
                }
            }
            DRR1 | DRR2 => {} // read-only
            _ => self.regs[o] = value,
        }
    }
}

/// McBSP-A and McBSP-B.
#[derive(Debug, Clone, Default)]
pub struct McbspPorts {
    ports: [Mcbsp; 2],
}

impl McbspPorts {
    /// Both at reset.
    pub fn new() -> McbspPorts {
        McbspPorts::default()
    }

    /// Whether `addr` is a modelled McBSP word.
    #[inline]
    pub fn owns(addr: u32) -> bool {
        (MCBSPA_BASE..MCBSPA_BASE + WORDS).contains(&addr) || (MCBSPB_BASE..MCBSPB_BASE + WORDS).contains(&addr)
    }

    /// The instance at `addr` ("McBSP-A"/"McBSP-B", as its clock enable is named).
    pub fn instance(addr: u32) -> &'static str {
        if addr >= MCBSPB_BASE {
            "McBSP-B"
        } else {
            "McBSP-A"
        }
    }

    fn port(&mut self, addr: u32) -> (&mut Mcbsp, u32) {
        if addr >= MCBSPB_BASE {
            (&mut self.ports[1], addr - MCBSPB_BASE)
        } else {
            (&mut self.ports[0], addr - MCBSPA_BASE)
        }
    }

    /// Read at `t`.
    pub fn read(&mut self, addr: u32, t: Ps, lspclk: Clock) -> u16 {
        let (p, o) = self.port(addr);
        p.advance(t, lspclk);
        p.read(o)
    }

    /// Write at `t`.
    pub fn write(&mut self, addr: u32, value: u16, t: Ps, lspclk: Clock) {
        let (p, o) = self.port(addr);
        p.advance(t, lspclk);
        p.write(o, value, t, lspclk);
    }

    /// When a register of the McBSP at `addr` may next read differently by itself.
    pub fn next_change_ps(&self, addr: u32) -> Option<Ps> {
        self.ports[usize::from(addr >= MCBSPB_BASE)].next_change_ps()
    }

    /// Both McBSPs up to `t` (words end, their interrupt requests are made at their times).
    pub fn advance(&mut self, t: Ps, lspclk: Clock) {
        for p in &mut self.ports {
            if p.shifting.is_some() {
                p.advance(t, lspclk);
            }
        }
    }

    /// Hand the interrupt requests made so far to the PIE (MRINTA INT6.5, MXINTA INT6.6, MRINTB
    /// INT6.3, MXINTB INT6.4), and say which lines are armed.
    pub fn drain(&mut self, irq: &mut Interrupts) {
        for (p, &(rx_line, tx_line)) in self.ports.iter_mut().zip(&PIE_LINES) {
            for (rx, t) in p.requests.drain(..) {
                irq.set_pie_flag(PIE_GROUP, if rx { rx_line } else { tx_line }, t);
            }
            let (rx, tx) = p.armed();
            irq.set_armed(PIE_GROUP, rx_line, rx);
            irq.set_armed(PIE_GROUP, tx_line, tx);
        }
    }

    /// When a line of either McBSP may next be raised by itself.
    pub fn next_interrupt_ps(&self) -> Option<Ps> {
        self.ports.iter().filter_map(Mcbsp::next_interrupt_ps).min()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const BIG: Ps = 1_000_000_000_000; // 1 s

    fn lspclk() -> Clock {
        Clock::from_hz(37_500_000)
    }

    fn spi_master_dlb(p: &mut Mcbsp, wdlen: u16) {
        p.write(SPCR2 as u32, 0, 0, lspclk());
        p.write(SPCR1 as u32, 0x1000 | DLB, 0, lspclk()); // CLKSTP = 2, DLB
        p.write(0x12, 0x0F08, 0, lspclk()); // PCR: CLKXM CLKRM FSXM FSRM, FSXP
        p.write(XCR2 as u32, 1, 0, lspclk());
        p.write(0x6, 1, 0, lspclk());
        p.write(XCR1 as u32, wdlen << 5, 0, lspclk());
        p.write(RCR1 as u32, wdlen << 5, 0, lspclk());
        p.write(SRGR1 as u32, 0x000F, 0, lspclk()); // CLKGDV 15
        p.write(SPCR2 as u32, GRST, 0, lspclk());
        p.write(SPCR2 as u32, GRST | XRST, 0, lspclk());
        p.write(SPCR1 as u32, 0x1000 | DLB | RRST, 0, lspclk());
    }

    /// MRINT on each RRDY rise, MXINT on each XRDY rise (RINTM = XINTM = 00), at their times, on
    /// McBSP-A's lines INT6.5/6.6 and McBSP-B's INT6.3/6.4 (PIEIFR6 0x0CED); RINTM = 01 raises none.
    #[test]
    fn rrdy_and_xrdy_raise_their_pie_lines() {
        const PIEIFR6: u32 = 0x0CED;
        for (base, rx, tx) in [(MCBSPA_BASE, 1u16 << 4, 1u16 << 5), (MCBSPB_BASE, 1 << 2, 1 << 3)] {
            let mut ports = McbspPorts::new();
            let mut irq = Interrupts::new(Clock::from_hz(150_000_000));
            let port = &mut ports.ports[usize::from(base == MCBSPB_BASE)];
            spi_master_dlb(port, 2);
            ports.drain(&mut irq);
            assert_eq!(irq.read(PIEIFR6, 0).unwrap(), tx, "XRST 0 → 1 with DXR empty: XRDY rises");
            let mut irq = Interrupts::new(Clock::from_hz(150_000_000));
            ports.write(base + DXR1 as u32, 0x1234, 10, lspclk());
            let end = ports.next_interrupt_ps().unwrap();
            ports.advance(end - 1, lspclk());
            ports.drain(&mut irq);
            assert_eq!(irq.read(PIEIFR6, end - 1).unwrap(), tx, "DXR into the shift register: XRDY rises");
            ports.advance(end, lspclk());
            ports.drain(&mut irq);
            assert_eq!(irq.read(PIEIFR6, end).unwrap(), rx | tx, "the word in DRR: RRDY rises");
            assert_eq!(ports.next_interrupt_ps(), None);
            // RINTM = 01 (end of block): not raised, not armed.
            let mut irq = Interrupts::new(Clock::from_hz(150_000_000));
            ports.write(base + SPCR1 as u32, 0x1000 | DLB | RRST | 1 << 4, end, lspclk());
            ports.write(base + SPCR2 as u32, GRST | XRST | 1 << 4, end, lspclk());
            ports.read(base + DRR1 as u32, end, lspclk());
            ports.write(base + DXR1 as u32, 1, end, lspclk());
            assert_eq!(ports.next_interrupt_ps(), None);
            ports.advance(BIG, lspclk());
            ports.drain(&mut irq);
            assert_eq!(irq.read(PIEIFR6, BIG).unwrap(), 0);
            assert_eq!(ports.read(base + SPCR1 as u32, BIG, lspclk()) & RRDY, RRDY);
        }
    }

    #[test]
    fn reset_values() {
        let mut p = Mcbsp::new();
        assert_eq!((p.read(SRGR2 as u32), p.read(SRGR1 as u32)), (0x2000, 0x0001));
        assert_eq!((p.read(SPCR1 as u32), p.read(SPCR2 as u32), p.read(0x12)), (0, 0, 0));
    }

    /// A 16-bit word in DLB comes back after XDATDLY + 16 CLKG periods (CLKG = 37.5 MHz / 16);
    /// RRDY clears when DRR1 is read; a second word not read sets RFULL.
    #[test]
    fn dlb_word_timing_and_flags() {
        let mut p = Mcbsp::new();
        spi_master_dlb(&mut p, 2);
        assert_eq!(p.read(SPCR2 as u32) & XRDY, XRDY);
        p.write(DXR1 as u32, 0x1234, 0, lspclk());
        let clkg = lspclk().divided(16);
        let end = clkg.cycles_to_ps(17);
        assert_eq!(p.next_change_ps(), Some(end));
        assert_eq!(p.read(SPCR2 as u32) & (XRDY | XEMPTY), XRDY | XEMPTY, "DXR moved to the shift register");
        p.advance(end - 1, lspclk());
        assert_eq!(p.read(SPCR1 as u32) & RRDY, 0);
        p.advance(end, lspclk());
        assert_eq!(p.read(SPCR1 as u32) & RRDY, RRDY);
        assert_eq!(p.read(SPCR2 as u32) & XEMPTY, 0, "empty: XEMPTY low");
        assert_eq!(p.read(DRR1 as u32), 0x1234);
        assert_eq!(p.read(SPCR1 as u32) & RRDY, 0);
        // Two words, the first not read: RFULL.
        p.write(DXR1 as u32, 1, end, lspclk());
        p.write(DXR1 as u32, 2, end, lspclk());
        assert_eq!(p.read(SPCR2 as u32) & XRDY, 0, "DXR full behind the shifting word");
        p.advance(BIG, lspclk());
        assert_eq!(p.read(SPCR1 as u32) & (RRDY | RFULL), RRDY | RFULL);
        assert_eq!(p.read(DRR1 as u32), 1);
    }

    /// 32-bit words: DXR2 then DXR1, DRR2 then DRR1; 8-bit words are masked; without DLB the
    /// undriven MDR pin gives ones.
    #[test]
    fn word_lengths_and_no_loopback() {
        let mut p = Mcbsp::new();
        spi_master_dlb(&mut p, 5);
        p.write(DXR2 as u32, 0xBEEF, 0, lspclk());
        p.write(DXR1 as u32, 0xCAFE, 0, lspclk());
        p.advance(BIG, lspclk());
        assert_eq!((p.read(DRR2 as u32), p.read(DRR1 as u32)), (0xBEEF, 0xCAFE));
        let mut p = Mcbsp::new();
        spi_master_dlb(&mut p, 0);
        p.write(DXR1 as u32, 0x1234, 0, lspclk());
        p.advance(BIG, lspclk());
        assert_eq!(p.read(DRR1 as u32), 0x34);
        p.write(SPCR1 as u32, 0x1000 | RRST, 0, lspclk());
        p.write(DXR1 as u32, 0x12, BIG, lspclk());
        p.advance(BIG + 1_000_000_000, lspclk());
        assert_eq!(p.read(DRR1 as u32), 0xFF);
    }
}
