//! I2C-A, the F28335's I²C module, as master, register by register as a host-built firmware drives it
//! (the [`crate::host::HostBoard`] holds it with the SCIs in [`super::serial::SerialPorts`]), reaching
//! the I²C parts the profile's `[[board.devices]]` places on `i2c-a` (each an
//! [`I2cTarget`], as on the gyro-free board's I²C link: the same target protocol, and the master side's
//! START timing, bus-free time and SCL rules are `bus::i2c::Master`'s). Source: TI's SPRUG03
//! (TMS320x2833x Inter-Integrated Circuit module reference guide); register layout as the spec's
//! `f28335-peripherals.md` §7 lists it; where SPRUG03 could not be read, the same module's newer
//! guides (SPRUHM9 F2807x, SPRUIN7 F28002x) are followed and marked [unconfirmed].
//!
//! - **Clocks** (SPRUG03 "Clock generation", "I2CPSC", "I2CCLKL/H"): module clock = SYSCLKOUT /
//!   (IPSC + 1), taken when IRS goes 0 → 1 and required to be 7–12 MHz (an `i2c_misuse` warning when
//!   not); SCL low = Tmod·(ICCL + d), high = Tmod·(ICCH + d), d = 7 (IPSC = 0), 6 (IPSC = 1), 5 (IPSC
//!   > 1). TI's example: IPSC = 14, ICCL = 10, ICCH = 5 at 150 MHz → 10 MHz, 1.5 µs + 1.0 µs = 400 kHz.
//! - **Master transfer** (I2CMDR, "Master transmitter/receiver modes"): STT with MST = 1 makes a START
//!   (after the bus-free time tBUF since the last STOP; a repeated START when the module holds the bus),
//!   then the address byte I2CSAR·2 + R/W̄ (TRX = 0: read), then data bytes, each nine SCL periods, in the
//!   order of `bus::i2c`'s link: the START, one high phase (tHD;STA), then the bytes; a repeated START
//!   takes a low phase and two high ones; a STOP a low and a high phase. I2CCNT is copied to an internal
//!   counter at the START (0 = 65 536) and keeps its value; in non-repeat mode (RM = 0) the counter ending
//!   makes a STOP when STP = 1, else sets ARDY and holds SCL low until the firmware writes STT (repeated
//!   START) or STP; in repeat mode (RM = 1) bytes go on until STP, ARDY set after each one. STT and STP
//!   clear themselves when their condition is made; MST clears at the STOP; BB is 1 from the START to the
//!   STOP; the STOP sets SCD.
//! - **Data** (I2CDXR/I2CDRR, XRDY/RRDY/XSMT/RSFULL): without the FIFOs, a byte written to I2CDXR is
//!   copied to the shift register when its byte starts (XRDY = 1 again then); with none there the module
//!   holds SCL low (XSMT = 0) until one is written. A byte received goes to I2CDRR (RRDY); with I2CDRR
//!   still unread the next one waits in the shift register (RSFULL) and SCL is held low. With the FIFOs
//!   (I2CFFTX.I2CFFEN, 16 bytes each way [unconfirmed depth]), bytes come from the TX FIFO and go to the
//!   RX FIFO; TXFFST/RXFFST count them; TXFFRST/RXFFRST = 0 empty and hold a FIFO; TXFFINT is set while
//!   TXFFST ≤ TXFFIL, RXFFINT while RXFFST ≥ RXFFIL, cleared by writing 1 to TXFFINTCLR/RXFFINTCLR.
//! - **NACK** ("NACK bit", "ARDY"): a byte the target does not acknowledge (its address: absent, or busy
//!   like an EEPROM in its write cycle) sets NACK and ARDY; the module holds the bus and makes the STOP
//!   once STP = 1 (TI's ISR sets STP and clears NACK on ARDY; a firmware that had set STP before gets
//!   its STOP at once) [unconfirmed: SPRUG03 not read]. An address no part answers at all is also an
//!   `i2c_nack` event (once per address); a present part refusing (acknowledge polling) is not.
//! - The master-receiver acknowledges each byte but the last of a non-repeat transfer with STP = 1,
//!   and every byte with NACKMOD = 1 cleared (NACKMOD = 1 NACKs the next byte).
//! - **Status and interrupts** (I2CSTR, I2CIER, I2CISRC): ARBL, NACK, ARDY, RRDY, SCD and NACKSNT are
//!   cleared by writing 1; I2CINT1A (PIE 8.1) is raised when a flag of I2CSTR bits 0–5 or AAS (bit 9) is
//!   set with its I2CIER bit (bits 0–6); I2CISRC reads the highest-priority such source (1 ARBL, 2 NACK,
//!   3 ARDY, 4 RRDY, 5 XRDY, 6 SCD, 7 AAS) and reading it clears that flag (ARBL, NACK, ARDY, SCD, AAS;
//!   RRDY and XRDY follow the data) [unconfirmed]. I2CINT2A (PIE 8.2) is TXFFINT with TXFFIENA or
//!   RXFFINT with RXFFIENA.
//! - **Reset** (IRS = 0): the module stops, the status reads its reset value 0x0410 (XSMT, XRDY), the
//!   FIFOs' counts 0. Register reset values: I2CSAR 0x03FF, I2CEMDR 0x0001 (SPRUG03 register tables
//!   [unconfirmed]); the others 0 (the spec's §10 says the FIFO registers reset as SPI's, 0xA000/0x201F,
//!   itself [unconfirmed]; SPRUG03's I2CFFTX/I2CFFRX bit tables give 0: followed here).
//!
//! - **Pins**: the module reaches the bus only through GPIO32/33 muxed to SDAA/SCLA (GPBMUX1 = 1, as
//!   TI's InitI2CGpio sets them); a START without them is an `i2c_misuse` warning (once) and every
//!   address reads NACKed (the idle bus's SDA, pulled high).
//!
//! Not modelled, each an `i2c_misuse` warning when asked for: slave mode (MST = 0 with STT), 10-bit
//! addressing (XA), the free data format (FDF), digital loopback (DLB), arbitration (one master: ARBL
//! never sets), the emulation modes (FREE is ignored).

use std::collections::VecDeque;

use super::fifo_bits::{FF_IENA, FF_IL, FF_INT, FF_INTCLR, FF_RST, FF_ST};
use crate::bus::i2c::{nack_address, stretch_rule, I2cTarget, Master};
use crate::bus::Address;
use crate::error::{Error, Result};
use crate::events::{Event, Severity};
use crate::time::{Clock, Ps};

/// I2C-A's base address (I2caRegs).
pub const BASE: u32 = 0x7900;
/// I2COAR (own address).
pub const I2COAR: u32 = 0x0;
/// I2CIER.
pub const I2CIER: u32 = 0x1;
/// I2CSTR.
pub const I2CSTR: u32 = 0x2;
/// I2CCLKL.
pub const I2CCLKL: u32 = 0x3;
/// I2CCLKH.
pub const I2CCLKH: u32 = 0x4;
/// I2CCNT.
pub const I2CCNT: u32 = 0x5;
/// I2CDRR.
pub const I2CDRR: u32 = 0x6;
/// I2CSAR.
pub const I2CSAR: u32 = 0x7;
/// I2CDXR.
pub const I2CDXR: u32 = 0x8;
/// I2CMDR.
pub const I2CMDR: u32 = 0x9;
/// I2CISRC.
pub const I2CISRC: u32 = 0xA;
/// I2CEMDR.
pub const I2CEMDR: u32 = 0xB;
/// I2CPSC.
pub const I2CPSC: u32 = 0xC;
/// I2CFFTX.
pub const I2CFFTX: u32 = 0x20;
/// I2CFFRX.
pub const I2CFFRX: u32 = 0x21;

/// The modelled registers (host.rs's names): name, address, width in bits.
pub const REGISTERS: &[(&str, u32, u32)] = &[
    ("I2COAR", BASE + I2COAR, 16),
    ("I2CIER", BASE + I2CIER, 16),
    ("I2CSTR", BASE + I2CSTR, 16),
    ("I2CCLKL", BASE + I2CCLKL, 16),
    ("I2CCLKH", BASE + I2CCLKH, 16),
    ("I2CCNT", BASE + I2CCNT, 16),
    ("I2CDRR", BASE + I2CDRR, 16),
    ("I2CSAR", BASE + I2CSAR, 16),
    ("I2CDXR", BASE + I2CDXR, 16),
    ("I2CMDR", BASE + I2CMDR, 16),
    ("I2CISRC", BASE + I2CISRC, 16),
    ("I2CEMDR", BASE + I2CEMDR, 16),
    ("I2CPSC", BASE + I2CPSC, 16),
    ("I2CFFTX", BASE + I2CFFTX, 16),
    ("I2CFFRX", BASE + I2CFFRX, 16),
];

/// I2CSTR bits.
pub const ARBL: u16 = 1 << 0;
/// NACK received.
pub const NACK: u16 = 1 << 1;
/// Registers ready for access.
pub const ARDY: u16 = 1 << 2;
/// Receive data ready.
pub const RRDY: u16 = 1 << 3;
/// Transmit data ready.
pub const XRDY: u16 = 1 << 4;
/// STOP condition detected.
pub const SCD: u16 = 1 << 5;
/// Addressed as slave.
pub const AAS: u16 = 1 << 9;
/// Transmit shift register not empty (0 = underflow).
pub const XSMT: u16 = 1 << 10;
/// Receive shift register full.
pub const RSFULL: u16 = 1 << 11;
/// Bus busy.
pub const BB: u16 = 1 << 12;
/// NACK sent.
pub const NACKSNT: u16 = 1 << 13;

/// I2CMDR bits.
pub const MDR_FDF: u16 = 1 << 3;
/// Reset (0) / enabled (1).
pub const MDR_IRS: u16 = 1 << 5;
/// Digital loopback.
pub const MDR_DLB: u16 = 1 << 6;
/// Repeat mode.
pub const MDR_RM: u16 = 1 << 7;
/// 10-bit addressing.
pub const MDR_XA: u16 = 1 << 8;
/// Transmitter (1) / receiver (0).
pub const MDR_TRX: u16 = 1 << 9;
/// Master.
pub const MDR_MST: u16 = 1 << 10;
/// STOP.
pub const MDR_STP: u16 = 1 << 11;
/// START.
pub const MDR_STT: u16 = 1 << 13;
/// NACK mode.
pub const MDR_NACKMOD: u16 = 1 << 15;

const FFTX_I2CFFEN: u16 = 1 << 14;
/// FIFO depth [unconfirmed, spec §7].
pub const FIFO_DEPTH: usize = 16;
/// The status bits that are write-1-to-clear.
const W1C: u16 = ARBL | NACK | ARDY | RRDY | SCD | NACKSNT;
/// I2CSTR at reset: XSMT, XRDY.
const STR_RESET: u16 = XSMT | XRDY;

/// What the wires are doing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Wire {
    /// No transfer of this master (the bus is free after the last STOP's tBUF).
    Idle,
    /// A byte is clocked from `start` (SCL's fall) to `start + 9 periods`; `out` is the byte sent
    /// (None: a byte received); `address` for the address byte.
    Byte { start: Ps, out: Option<u8>, address: bool },
    /// SCL held low since `since` (between bytes, waiting for the firmware).
    Held { since: Ps },
    /// The STOP is made at `at`.
    Stopping { at: Ps },
}

/// I2C-A.
pub struct I2cA {
    m: Master,
    sysclkout: Clock,
    /// The prescaler taken at the last IRS 0 → 1.
    ipsc: u16,
    oar: u16,
    ier: u16,
    status: u16,
    clkl: u16,
    clkh: u16,
    cnt: u16,
    drr: u16,
    sar: u16,
    /// I2CDXR's byte not yet taken by the shift register (non-FIFO mode).
    dxr: Option<u8>,
    /// I2CDXR as last written (reads back).
    dxr_reg: u16,
    mdr: u16,
    emdr: u16,
    psc: u16,
    fftx: u16,
    ffrx: u16,
    tx_fifo: VecDeque<u8>,
    rx_fifo: VecDeque<u8>,
    /// A received byte waiting in the shift register (RSFULL).
    rsr: Option<u8>,
    wire: Wire,
    /// The target addressed in this transfer (index into the master's targets).
    target: Option<usize>,
    /// Bytes left of the internal counter (non-repeat mode).
    left: u32,
    /// Receiving (the address's R/W̄ bit was 1).
    reading: bool,
    /// Holding the bus after a NACK or after the count ended without STP, until STT or STP.
    halted: bool,
    /// Addresses reported absent already.
    absent_reported: Vec<u8>,
    /// GPIO32/33 are muxed to SDAA/SCLA (GPBMUX1 = 1): the module reaches the bus.
    pins: bool,
    /// The unmuxed pins were reported.
    pins_reported: bool,
    /// Interrupt lines as last seen (I2CINT1A, I2CINT2A).
    lines: [bool; 2],
    requests: Vec<(u8, u8, Ps)>,
    now: Ps,
}

impl std::fmt::Debug for I2cA {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("I2cA").field("mdr", &self.mdr).field("status", &self.status).field("wire", &self.wire).finish()
    }
}

impl I2cA {
    /// I2C-A at reset, clocked by `sysclkout`, with `targets` on its bus.
    pub fn new(sysclkout: Clock, targets: Vec<(u8, Box<dyn I2cTarget + Send>)>) -> I2cA {
        I2cA {
            m: Master::with_targets(targets),
            sysclkout,
            ipsc: 0,
            oar: 0,
            ier: 0,
            status: STR_RESET,
            clkl: 0,
            clkh: 0,
            cnt: 0,
            drr: 0,
            sar: 0x03FF,
            dxr: None,
            dxr_reg: 0,
            mdr: 0,
            emdr: 0x0001,
            psc: 0,
            fftx: 0,
            ffrx: 0,
            tx_fifo: VecDeque::new(),
            rx_fifo: VecDeque::new(),
            rsr: None,
            wire: Wire::Idle,
            target: None,
            left: 0,
            reading: false,
            halted: false,
            absent_reported: Vec::new(),
            pins: false,
            pins_reported: false,
            lines: [false; 2],
            requests: Vec::new(),
            now: 0,
        }
    }

    /// Whether `addr` is one of its registers.
    pub fn owns(addr: u32) -> bool {
        REGISTERS.iter().any(|r| r.1 == addr)
    }

    /// SYSCLKOUT changes (taken at the next IRS 0 → 1, as the prescaler).
    pub fn set_sysclkout(&mut self, c: Clock) {
        self.sysclkout = c;
    }

    /// Whether GPIO32/33 are muxed to SDAA/SCLA (the board says so when the mux changes).
    pub fn set_pins(&mut self, muxed: bool) {
        self.pins = muxed;
    }

    /// SCL's low and high phases now, ps.
    pub fn scl_phases(&self) -> (Ps, Ps) {
        (self.m.low, self.m.high)
    }

    /// The part at `address`, to look at it.
    pub fn target(&self, address: u8) -> Option<&(dyn I2cTarget + Send)> {
        self.m.targets.iter().find(|(a, _)| *a == address).map(|(_, t)| t.as_ref())
    }

    fn in_reset(&self) -> bool {
        self.mdr & MDR_IRS == 0
    }

    fn fifo_mode(&self) -> bool {
        self.fftx & FFTX_I2CFFEN != 0
    }

    fn period(&self) -> Ps {
        self.m.low + self.m.high
    }

    fn misuse(&mut self, message: String) {
        self.m.events.push(Event::new(self.now, "i2c_misuse", Severity::Warning, format!("I2C-A: {message}")));
    }

    /// IRS 0 → 1: the prescaler and the SCL phases are taken.
    fn take_clocks(&mut self) {
        self.ipsc = self.psc & 0xFF;
        let module = self.sysclkout.divided(u64::from(self.ipsc) + 1);
        let hz = module.hz();
        if !(7.0e6..=12.0e6).contains(&hz) {
            self.misuse(format!(
                "module clock SYSCLKOUT/(IPSC+1) = {:.3} MHz (I2CPSC = {}): SPRUG03 requires 7-12 MHz (TI's \
                 example: IPSC = 14 at 150 MHz, 10 MHz)",
                hz / 1e6,
                self.ipsc
            ));
        }
        if self.clkl == 0 || self.clkh == 0 {
            self.misuse(format!(
                "I2CCLKL = {}, I2CCLKH = {}: both must be non-zero (SPRUG03; TI's example: 10 and 5)",
                self.clkl, self.clkh
            ));
        }
        let d = match self.ipsc {
            0 => 7,
            1 => 6,
            _ => 5,
        };
        let low = module.cycles_to_ps(u64::from(self.clkl) + d);
        let high = module.cycles_to_ps(u64::from(self.clkh) + d);
        self.m.set_phases(low, high);
    }

    /// Read a register (offset from [`BASE`]) at `t`.
    pub fn read(&mut self, off: u32, t: Ps) -> Result<u16> {
        self.advance(t);
        let v = match off {
            I2COAR => self.oar,
            I2CIER => self.ier,
            I2CSTR => self.status,
            I2CCLKL => self.clkl,
            I2CCLKH => self.clkh,
            I2CCNT => self.cnt,
            I2CDRR => self.read_drr(),
            I2CSAR => self.sar,
            I2CDXR => self.dxr_reg,
            I2CMDR => self.mdr,
            I2CISRC => self.read_isrc(),
            I2CEMDR => self.emdr,
            I2CPSC => self.psc,
            I2CFFTX => self.fftx_value(),
            I2CFFRX => self.ffrx_value(),
            _ => return Err(Error::Register(format!("C28x address 0x{:04X}: not an I2C-A register", BASE + off))),
        };
        self.update_irq();
        Ok(v)
    }

    fn fftx_value(&self) -> u16 {
        let st = (self.tx_fifo.len() as u16) << 8;
        (self.fftx & !(FF_ST | FF_INT | FF_INTCLR)) | st | if self.txffint() { FF_INT } else { 0 }
    }

    fn ffrx_value(&self) -> u16 {
        let st = (self.rx_fifo.len() as u16) << 8;
        (self.ffrx & !(FF_ST | FF_INT | FF_INTCLR)) | st | if self.rxffint() { FF_INT } else { 0 }
    }

    /// TXFFINT: the condition itself (a clear by TXFFINTCLR sets again at once while it holds).
    fn txffint(&self) -> bool {
        self.fifo_mode() && self.fftx & FF_RST != 0 && self.tx_fifo.len() <= usize::from(self.fftx & FF_IL)
    }

    /// RXFFINT: the condition itself (see [`I2cA::txffint`]).
    fn rxffint(&self) -> bool {
        self.fifo_mode() && self.ffrx & FF_RST != 0 && self.rx_fifo.len() >= usize::from(self.ffrx & FF_IL).max(1)
    }

    fn read_drr(&mut self) -> u16 {
        if self.fifo_mode() {
            if let Some(b) = self.rx_fifo.pop_front() {
                self.drr = u16::from(b);
            }
        } else {
            self.status &= !RRDY;
        }
        let v = self.drr;
        // A byte waiting in the shift register moves on; the held SCL is released.
        if let Some(b) = self.rsr.take() {
            self.status &= !RSFULL;
            self.receive(b);
        }
        self.resume(self.now);
        v
    }

    fn read_isrc(&mut self) -> u16 {
        let pending = self.status & (self.ier & 0x3F) | if self.ier & (1 << 6) != 0 { self.status & AAS } else { 0 };
        let order: [(u16, u16); 7] = [(ARBL, 1), (NACK, 2), (ARDY, 3), (RRDY, 4), (XRDY, 5), (SCD, 6), (AAS, 7)];
        match order.iter().find(|(bit, _)| pending & bit != 0) {
            Some(&(bit, code)) => {
                if bit & (ARBL | NACK | ARDY | SCD | AAS) != 0 {
                    self.status &= !bit;
                }
                code
            }
            None => 0,
        }
    }

    /// Write a register (offset from [`BASE`]) at `t`.
    pub fn write(&mut self, off: u32, value: u16, t: Ps) -> Result<()> {
        self.advance(t);
        match off {
            I2COAR => self.oar = value & 0x03FF,
            I2CIER => self.ier = value & 0x7F,
            I2CSTR => {
                self.status &= !(value & W1C);
                if value & BB != 0 {
                    // BB is cleared by writing 1 only once the bus is free [unconfirmed].
                    if self.wire == Wire::Idle {
                        self.status &= !BB;
                    }
                }
            }
            I2CCLKL => self.clkl = value,
            I2CCLKH => self.clkh = value,
            I2CCNT => self.cnt = value,
            I2CDRR => self.misuse("I2CDRR is read-only: the write is ignored".into()),
            I2CSAR => self.sar = value & 0x03FF,
            I2CDXR => self.write_dxr(value),
            I2CMDR => self.write_mdr(value),
            I2CISRC => {}
            I2CEMDR => self.emdr = value & 0x1,
            I2CPSC => self.psc = value & 0xFF,
            I2CFFTX => self.write_fftx(value),
            I2CFFRX => self.write_ffrx(value),
            _ => return Err(Error::Register(format!("C28x address 0x{:04X}: not an I2C-A register", BASE + off))),
        }
        self.update_irq();
        Ok(())
    }

    fn write_dxr(&mut self, value: u16) {
        self.dxr_reg = value & 0xFF;
        if self.in_reset() {
            self.misuse(format!("I2CDXR written (0x{value:02X}) with the module in reset (I2CMDR.IRS = 0): lost"));
            return;
        }
        if self.fifo_mode() {
            if self.fftx & FF_RST == 0 {
                self.misuse(format!("I2CDXR written (0x{value:02X}) with the TX FIFO held in reset (TXFFRST = 0)"));
            } else if self.tx_fifo.len() >= FIFO_DEPTH {
                self.misuse(format!("I2CDXR written (0x{value:02X}) with the TX FIFO full (16 bytes): lost"));
            } else {
                self.tx_fifo.push_back(value as u8);
            }
        } else {
            if self.dxr.is_some() {
                self.misuse(format!(
                    "I2CDXR written (0x{value:02X}) while XRDY = 0: the byte not yet sent is overwritten"
                ));
            }
            self.dxr = Some(value as u8);
            self.status &= !XRDY;
        }
        self.resume(self.now);
    }

    fn write_fftx(&mut self, value: u16) {
        if value & FF_RST == 0 {
            self.tx_fifo.clear();
        }
        self.fftx = value & !(FF_INT | FF_INTCLR | FF_ST);
    }

    fn write_ffrx(&mut self, value: u16) {
        if value & FF_RST == 0 {
            self.rx_fifo.clear();
        }
        self.ffrx = value & !(FF_INT | FF_INTCLR | FF_ST);
    }

    fn write_mdr(&mut self, value: u16) {
        let was = self.mdr;
        if value & MDR_IRS == 0 {
            // Reset: the module stops; the bus is let go (a transfer cut short makes no STOP).
            self.mdr = value & !(MDR_STT | MDR_STP);
            self.status = STR_RESET;
            self.wire = Wire::Idle;
            self.halted = false;
            self.target = None;
            self.dxr = None;
            self.rsr = None;
            return;
        }
        if was & MDR_IRS == 0 {
            self.take_clocks();
        }
        for (bit, what) in [
            (MDR_XA, "10-bit addressing (XA)"),
            (MDR_FDF, "the free data format (FDF)"),
            (MDR_DLB, "digital loopback (DLB)"),
        ] {
            if value & bit != 0 && was & bit == 0 {
                self.misuse(format!("I2CMDR = 0x{value:04X} asks for {what}, which is not modelled: ignored"));
            }
        }
        // STT and STP stay set until their condition is made (writing 0 does not clear them).
        self.mdr = value | (was & (MDR_STT | MDR_STP));
        if value & MDR_STT != 0 {
            if value & MDR_MST == 0 {
                self.misuse(format!("I2CMDR = 0x{value:04X}: STT without MST (slave mode) is not modelled: no START"));
                self.mdr &= !MDR_STT;
            } else {
                self.start_requested();
            }
        }
        if value & MDR_STP != 0 {
            self.resume(self.now);
        }
    }

    /// STT = 1 as master: a START now (or when the bus is free), or a repeated START when the module
    /// holds the bus; during a byte it waits for the byte's end.
    fn start_requested(&mut self) {
        match self.wire {
            Wire::Idle => {
                let addr = (self.sar & 0x7F) as u8;
                let (_, start) = match self.m.begin(Address::I2c(addr), &[], self.now) {
                    Ok(x) => x,
                    Err(_) => return,
                };
                self.begin_transfer(start, false);
            }
            Wire::Held { since } => {
                let restart = since.max(self.now) + self.m.low + self.m.high;
                self.begin_transfer(restart, true);
            }
            Wire::Byte { .. } | Wire::Stopping { .. } => {} // taken when the byte or the STOP ends
        }
    }

    fn begin_transfer(&mut self, start: Ps, _repeated: bool) {
        let addr = (self.sar & 0x7F) as u8;
        self.reading = self.mdr & MDR_TRX == 0;
        self.left = if self.cnt == 0 { 65_536 } else { u32::from(self.cnt) };
        self.target = self.m.targets.iter().position(|(a, _)| *a == addr).filter(|_| self.pins);
        if !self.pins && !self.pins_reported {
            self.pins_reported = true;
            self.misuse(
                "a START with GPIO32/33 not muxed to SDAA/SCLA (GPBMUX1 = 1, TI's InitI2CGpio): the module drives \
                 no pin, no part sees the transfer, and the address reads NACKed (SDA pulled high)"
                    .into(),
            );
        }
        if let Some(i) = self.target {
            self.m.targets[i].1.start(start);
        }
        self.mdr &= !MDR_STT;
        self.halted = false;
        self.status |= BB;
        let byte = (addr << 1) | u8::from(self.reading);
        self.wire = Wire::Byte { start: start + self.m.high, out: Some(byte), address: true };
    }

    /// The time of the next change on the wires, if one is coming.
    fn next_step(&self) -> Option<Ps> {
        match self.wire {
            Wire::Byte { start, .. } => Some(start + 9 * self.period()),
            Wire::Stopping { at } => Some(at),
            _ => None,
        }
    }

    /// Bring the module up to `t`: bytes end and start, STOPs are made, in time order.
    pub fn advance(&mut self, t: Ps) {
        while let Some(at) = self.next_step().filter(|&a| a <= t) {
            self.now = at;
            self.step(at);
        }
        self.now = self.now.max(t);
        self.update_irq();
    }

    fn step(&mut self, at: Ps) {
        match self.wire {
            Wire::Stopping { at } => {
                if let Some(i) = self.target.take() {
                    self.m.targets[i].1.stop(at);
                }
                self.m.last_stop = Some(at);
                self.status = (self.status | SCD) & !BB;
                self.mdr &= !(MDR_STP | MDR_MST);
                self.wire = Wire::Idle;
                self.halted = false;
                if self.mdr & MDR_STT != 0 {
                    self.mdr |= MDR_MST;
                    self.start_requested();
                }
            }
            Wire::Byte { start, out, address } => {
                let (low, period) = (self.m.low, self.period());
                let ninth_rise = start + 8 * period + low;
                let ack = match out {
                    Some(b) => match self.target {
                        Some(i) => self.m.targets[i].1.write(b, ninth_rise),
                        None => false,
                    },
                    None => {
                        let ack = self.receiver_acks();
                        let b = self.target.map_or(0xFF, |i| self.m.targets[i].1.read(start + low, ack));
                        if !ack {
                            self.status |= NACKSNT;
                        }
                        self.receive(b);
                        true
                    }
                };
                let end = match self.target {
                    Some(i) => {
                        let release = self.m.targets[i].1.hold_scl(at);
                        stretch_rule(release, at, low, self.m.honours_stretching, &mut self.m.events)
                    }
                    None => at,
                };
                self.wire = Wire::Held { since: end };
                if !ack {
                    if address && self.target.is_none() && self.pins {
                        let a = (self.sar & 0x7F) as u8;
                        if !self.absent_reported.contains(&a) {
                            self.absent_reported.push(a);
                            nack_address(&mut self.m.events, ninth_rise, a, self.reading);
                        }
                    }
                    self.status |= NACK | ARDY;
                    self.halted = true;
                    self.resume(end);
                    return;
                }
                if !address {
                    self.left = self.left.saturating_sub(1);
                    if self.mdr & MDR_RM != 0 {
                        self.status |= ARDY;
                    } else if self.left == 0 && self.mdr & MDR_STP == 0 {
                        self.status |= ARDY;
                        self.halted = true;
                    }
                }
                self.resume(end);
            }
            _ => {}
        }
    }

    /// Whether the master-receiver acknowledges the byte it is clocking.
    fn receiver_acks(&mut self) -> bool {
        if self.mdr & MDR_NACKMOD != 0 {
            self.mdr &= !MDR_NACKMOD;
            return false;
        }
        let last = self.mdr & MDR_RM == 0 && self.left == 1;
        !(last && self.mdr & MDR_STP != 0)
    }

    fn receive(&mut self, b: u8) {
        if self.fifo_mode() {
            if self.rx_fifo.len() < FIFO_DEPTH && self.ffrx & FF_RST != 0 {
                self.rx_fifo.push_back(b);
            } else {
                self.rsr = Some(b);
                self.status |= RSFULL;
            }
        } else if self.status & RRDY != 0 {
            self.rsr = Some(b);
            self.status |= RSFULL;
        } else {
            self.drr = u16::from(b);
            self.status |= RRDY;
        }
    }

    /// With SCL held low after a byte: go on as the registers now say (the next byte, a STOP, a
    /// repeated START), or keep holding.
    fn resume(&mut self, t: Ps) {
        let Wire::Held { since } = self.wire else { return };
        let go = since.max(t);
        if self.halted {
            // After a NACK, or the count done without STP: the firmware says what comes next.
            if self.mdr & MDR_STP != 0 {
                self.wire = Wire::Stopping { at: go + self.m.low + self.m.high };
            } else if self.mdr & MDR_STT != 0 {
                self.start_requested();
            }
            return;
        }
        let done = self.mdr & MDR_RM == 0 && self.left == 0;
        if done || (self.mdr & MDR_RM != 0 && self.mdr & MDR_STP != 0) {
            if self.mdr & MDR_STP != 0 {
                self.wire = Wire::Stopping { at: go + self.m.low + self.m.high };
            }
            return;
        }
        if self.rsr.is_some() {
            return; // the received byte has nowhere to go: SCL held low
        }
        if self.reading {
            self.wire = Wire::Byte { start: go, out: None, address: false };
            return;
        }
        let next = if self.fifo_mode() { self.tx_fifo.pop_front() } else { self.dxr.take() };
        match next {
            Some(b) => {
                self.status |= XSMT;
                if !self.fifo_mode() {
                    self.status |= XRDY;
                }
                self.wire = Wire::Byte { start: go, out: Some(b), address: false };
            }
            None => self.status &= !XSMT, // underflow: SCL held low until a byte is written
        }
    }

    fn update_irq(&mut self) {
        let flags = self.status & 0x3F | if self.status & AAS != 0 { 1 << 6 } else { 0 };
        let int1 = flags & self.ier != 0;
        let int2 = (self.txffint() && self.fftx & FF_IENA != 0) || (self.rxffint() && self.ffrx & FF_IENA != 0);
        for (k, level) in [int1, int2].into_iter().enumerate() {
            if level && !self.lines[k] {
                self.requests.push((8, k as u8 + 1, self.now));
            }
            self.lines[k] = level;
        }
    }

    /// The PIE requests raised since the last call: (group, line, time).
    pub fn take_requests(&mut self) -> Vec<(u8, u8, Ps)> {
        std::mem::take(&mut self.requests)
    }

    /// Whether each line is enabled in the module (I2CINT1A, I2CINT2A).
    pub fn armed(&self) -> [bool; 2] {
        [self.ier != 0, (self.fftx | self.ffrx) & FF_IENA != 0]
    }

    /// The events since the last call (the module's and its parts').
    pub fn drain_events(&mut self) -> Vec<Event> {
        let mut e = self.m.events.drain();
        // On every register access and step of time (HostBoard::sync): nothing to move, no call.
        for (_, t) in &mut self.m.targets {
            let mut more = t.drain_events();
            if !more.is_empty() {
                e.append(&mut more);
            }
        }
        e
    }

    /// The time of the module's next change by itself after now, if any.
    pub fn next_change_ps(&self) -> Option<Ps> {
        self.next_step().filter(|&t| t > self.now)
    }

    /// [`I2cA::next_change_ps`] when an interrupt of the module is enabled.
    pub fn next_interrupt_ps(&self) -> Option<Ps> {
        if self.armed().iter().any(|a| *a) {
            self.next_change_ps()
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::device::eeprom24::{Eeprom24lc256, T_WR_PS};

    const US: Ps = 1_000_000;

    /// I2C-A at 150 MHz as TI's EEPROM example sets it up: IPSC = 14 (10 MHz), ICCL = 10, ICCH = 5,
    /// the FIFOs on, a 24LC256 at 0x50.
    fn ti_setup() -> I2cA {
        let mut i = I2cA::new(Clock::from_hz(150_000_000), vec![(0x50, Box::new(Eeprom24lc256::erased()))]);
        i.set_pins(true);
        for (off, v) in [(I2CSAR, 0x50), (I2CPSC, 14), (I2CCLKL, 10), (I2CCLKH, 5), (I2CIER, 0x24), (I2CMDR, 0x0020)] {
            i.write(off, v, 0).unwrap();
        }
        i.write(I2CFFTX, 0x6000, 0).unwrap();
        i.write(I2CFFRX, 0x2040, 0).unwrap();
        i
    }

    fn send(i: &mut I2cA, bytes: &[u16], mdr: u16, t: Ps) {
        i.write(I2CCNT, bytes.len() as u16, t).unwrap();
        for &b in bytes {
            i.write(I2CDXR, b, t).unwrap();
        }
        i.write(I2CMDR, mdr, t).unwrap();
    }

    fn status(i: &mut I2cA, t: Ps) -> u16 {
        i.read(I2CSTR, t).unwrap()
    }

    #[test]
    fn the_bit_clock_follows_the_prescaler_and_the_divider_rule() {
        let i = ti_setup();
        // Tmod = 15 / 150 MHz = 100 ns; low (10 + 5)·100 ns, high (5 + 5)·100 ns: 400 kHz.
        assert_eq!(i.scl_phases(), (1_500_000, 1_000_000));
        // IPSC = 0 gives d = 7 and a module clock of 150 MHz, outside 7-12 MHz: reported.
        let mut j = I2cA::new(Clock::from_hz(150_000_000), vec![]);
        for (off, v) in [(I2CPSC, 0), (I2CCLKL, 3), (I2CCLKH, 3), (I2CMDR, 0x0020)] {
            j.write(off, v, 0).unwrap();
        }
        assert_eq!(
            j.scl_phases(),
            (Clock::from_hz(150_000_000).cycles_to_ps(10), Clock::from_hz(150_000_000).cycles_to_ps(10))
        );
        let kinds: Vec<&str> = j.drain_events().iter().map(|e| e.kind).collect();
        assert_eq!(kinds, ["i2c_misuse"]);
    }

    #[test]
    fn a_page_write_then_acknowledge_polling_then_a_random_read() {
        let mut i = ti_setup();
        // Address 0x0040, four data bytes, STT STP MST TRX IRS FREE.
        send(&mut i, &[0x00, 0x40, 0x11, 0x22, 0x33, 0x44], 0x6E20, 0);
        assert_ne!(status(&mut i, 0) & BB, 0);
        // START, one high phase, seven bytes of nine periods (2.5 µs), the STOP (a low and a high phase).
        let stop = US + 7 * 9 * 5 * US / 2 + 5 * US / 2;
        assert_eq!(status(&mut i, stop - 1) & SCD, 0);
        let s = status(&mut i, stop);
        assert_eq!((s & SCD != 0, s & BB), (true, 0));
        assert_eq!(i.read(I2CISRC, stop).unwrap(), 6); // SCD, and reading clears it
        assert_eq!(status(&mut i, stop) & SCD, 0);
        // Acknowledge polling: the address set-up of a read, no STOP (0x2620). During tWR the
        // control byte is NACKed: NACK and ARDY; STP then ends the attempt.
        let mut t = stop;
        let mut polls = 0;
        loop {
            send(&mut i, &[0x00, 0x40], 0x2620, t);
            // tBUF (1.3 µs, fast mode) after the last STOP, a high phase, the address byte.
            let ardy = t.max(i.m.last_stop.unwrap() + 1_300_000) + US + 9 * 5 * US / 2;
            t = ardy;
            let s = status(&mut i, t);
            if s & NACK == 0 {
                break; // ACKed: the address bytes go on
            }
            assert_ne!(s & ARDY, 0, "poll {polls}");
            polls += 1;
            i.write(I2CMDR, 0x0020 | MDR_STP, t).unwrap();
            i.write(I2CSTR, NACK | ARDY, t).unwrap();
            // The address bytes not sent stay in the TX FIFO: reset it.
            i.write(I2CFFTX, 0x4000, t).unwrap();
            i.write(I2CFFTX, 0x6000, t).unwrap();
            t += 5 * US / 2; // the STOP
            assert_eq!(status(&mut i, t) & BB, 0);
        }
        // Attempt k's START is tBUF + k·27.3 µs after the write's STOP (tBUF 1.3 + high 1 + 9 periods
        // 22.5 + the STOP 2.5); the part looks at its control byte at the ninth rise, 22.5 µs after the
        // START: it is NACKed while that is before the write cycle's end, tWR after the STOP.
        let (attempt, first_look) = (27_300_000, 1_300_000 + 22_500_000);
        assert_eq!(polls, (T_WR_PS - first_look).div_ceil(attempt)); // 183
        assert_eq!(polls, 183);
        // The address bytes go on, then the repeated START as receiver with STP: 4 bytes.
        let t_addr = t + 2 * 9 * 5 * US / 2;
        assert_eq!(status(&mut i, t_addr) & (ARDY | NACK), ARDY);
        i.write(I2CSTR, ARDY | SCD, t_addr).unwrap(); // SCD: the last failed attempt's STOP
        i.write(I2CCNT, 4, t_addr).unwrap();
        i.write(I2CMDR, 0x2C20, t_addr).unwrap();
        let end = t_addr + 5 * US / 2 + US + 5 * 9 * 5 * US / 2 + 5 * US / 2;
        assert_eq!(status(&mut i, end - 1) & SCD, 0);
        assert_ne!(status(&mut i, end) & SCD, 0);
        assert_eq!(i.read(I2CFFRX, end).unwrap() >> 8 & 0x1F, 4);
        let got: Vec<u16> = (0..4).map(|_| i.read(I2CDRR, end).unwrap()).collect();
        assert_eq!(got, [0x11, 0x22, 0x33, 0x44]);
        let ev = i.drain_events();
        assert!(ev.is_empty(), "{ev:?}");
        // ARDY and SCD were enabled: I2CINT1A requests on PIE 8.1.
        assert!(i.take_requests().iter().all(|r| (r.0, r.1) == (8, 1)));
    }

    #[test]
    fn an_absent_address_sets_nack_and_is_an_event_once() {
        let mut i = ti_setup();
        i.write(I2CSAR, 0x51, 0).unwrap();
        for k in 0..2 {
            let t = k * 100 * US;
            send(&mut i, &[0x00, 0x00, 0x5A], 0x6E20, t);
            // STP was set: the STOP follows the NACK.
            let nack = t + US + 9 * 5 * US / 2;
            let s = status(&mut i, nack);
            assert_eq!(s & (NACK | ARDY), NACK | ARDY);
            let s = status(&mut i, nack + 5 * US / 2);
            assert_eq!((s & SCD != 0, s & BB), (true, 0));
            i.write(I2CSTR, NACK | ARDY | SCD, nack + 5 * US / 2).unwrap();
            // The unsent bytes stay in the TX FIFO until it is reset.
            i.write(I2CFFTX, 0x4000, nack + 5 * US / 2).unwrap();
            i.write(I2CFFTX, 0x6000, nack + 5 * US / 2).unwrap();
        }
        let ev = i.drain_events();
        assert_eq!(ev.len(), 1);
        assert_eq!(ev[0].kind, "i2c_nack");
        assert!(ev[0].message.contains("0x51"), "{}", ev[0].message);
    }
}
