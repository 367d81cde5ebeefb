//! SCI-A/B/C, the F28335's UARTs, register by register as a host-built firmware drives them (the
//! [`crate::host::HostBoard`] holds three). Source: TI's SPRUFZ5 (TMS320x2833x/2823x Serial
//! Communications Interface reference guide); register layout and reset values as
//! the spec's `f28335-peripherals.md` §6 lists them.
//!
//! - **Character format** (SCICCR, SPRUFZ5 "SCI communication control register"): SCICHAR + 1 data
//!   bits (1…8), an optional parity bit (PARITYENA, PARITY 1 = even), one or two stop bits
//!   (STOPBITS), one start bit. A character takes `frame bits / baud` on the line; the transmitter
//!   shifts one out in that time and the receiver has one complete that long after its start bit.
//! - **Baud** (SCIHBAUD/SCILBAUD, SPRUFZ5 "Baud-select registers"): BRR = SCIHBAUD:SCILBAUD, baud =
//!   LSPCLK / ((BRR + 1) · 8); BRR = 0 gives LSPCLK / 16.
//! - **Control and status** (SCICTL1, SCICTL2, SCIRXST): SWRESET = 0 holds the state machines and the
//!   flags (TXRDY = TXEMPTY = 1, RXRDY and the errors 0) in reset; TXENA/RXENA enable the
//!   transmitter/receiver. Reading SCIRXBUF clears RXRDY (non-FIFO mode); writing SCITXBUF clears
//!   TXRDY until the shifter takes the character. A character received while RXRDY is still set sets
//!   OE (overrun); a stop bit read low sets FE, a parity mismatch PE; RXERROR is their OR.
//! - **FIFOs** (SCIFFTX/SCIFFRX/SCIFFCT, SPRUFZ5 "SCI FIFO description"): 16 words each way once
//!   SCIFFENA = 1; SCIRST = 0 resets both channels, TXFIFOXRESET/RXFIFORESET = 0 empty their FIFO and
//!   hold it. TXFFINT is set while TXFFST ≤ TXFFIL, RXFFINT while RXFFST ≥ RXFFIL; writing 1 to
//!   TXFFINTCLR/RXFFINTCLR clears the flag (it sets again at once if the condition still holds). A
//!   character arriving with 16 in the RX FIFO is lost and sets RXFFOVF (RXFFOVRCLR, write 1, clears
//!   it). FFTXDLY baud-clock periods separate characters leaving the TX FIFO. Each RX FIFO word
//!   carries its character's FE (bit 15) and PE (bit 14).
//! - **Interrupts**: SCIRXINTx is RXFFINT with RXFFIENA (FIFO mode), else RXRDY with RXBKINTENA or
//!   RXERROR with RXERRINTENA; SCITXINTx is TXFFINT with TXFFIENA, else TXRDY with TXINTENA. A rising
//!   request sets the PIE flag: SCI-A 9.1/9.2, SCI-B 9.3/9.4, SCI-C 8.5/8.6 (RX/TX).
//! - **Loopback** (SCICCR.LOOPBKENA): the transmitter's output is the receiver's input inside the
//!   chip; the receiver's pin is not heard and the transmitted characters are not on the TX pin's
//!   capture (taken as the chip ties them: [unconfirmed] in the spec, TI's loopback examples rely on
//!   the internal path only).
//! - **Line outside the chip**: what the port transmits is kept (its bytes, and each line, up to a
//!   newline or 128 bytes, as an `sci_tx_line` event with the port as prefix, `SCI-B> …`); what it
//!   receives comes from a [`RxFeed`] (a file given in the profile, `serial.sci_b.rx_file`), 8N1 at
//!   the feed's baud: a feed whose baud differs from the port's by more than a receiver can take
//!   (half a bit over the 9.5 bits to the stop bit's middle: 5.26 %), or a port not set to 8N1,
//!   reads its characters with FE set (`uart_framing_error`, once per setting).
//!
//! Misuse is an `sci_misuse` event naming the register and what was expected: a write to SCITXBUF
//! with the TX FIFO full or held in reset, or with TXBUF still full (non-FIFO), a read of SCIRXBUF
//! with nothing received, a write to a read-only register, autobaud (not modelled).

use std::collections::VecDeque;

use super::fifo_bits::{FF_IENA, FF_IL, FF_INTCLR};
use crate::error::{Error, Result};
use crate::events::{Event, Severity};
use crate::time::{Clock, Ps, PS_PER_S};

/// A PIE line: (group 1…12, line 1…8).
pub type PieLine = (u8, u8);

/// The three ports: name, base address, the PIE lines of SCIRXINT and of SCITXINT.
pub const PORTS: [(&str, u32, PieLine, PieLine); 3] =
    [("SCI-A", 0x7050, (9, 1), (9, 2)), ("SCI-B", 0x7750, (9, 3), (9, 4)), ("SCI-C", 0x7770, (8, 5), (8, 6))];

/// Register offsets (SPRUFZ5 "SCI registers").
pub const SCICCR: u32 = 0x0;
/// SCICTL1.
pub const SCICTL1: u32 = 0x1;
/// SCIHBAUD.
pub const SCIHBAUD: u32 = 0x2;
/// SCILBAUD.
pub const SCILBAUD: u32 = 0x3;
/// SCICTL2.
pub const SCICTL2: u32 = 0x4;
/// SCIRXST.
pub const SCIRXST: u32 = 0x5;
/// SCIRXEMU.
pub const SCIRXEMU: u32 = 0x6;
/// SCIRXBUF.
pub const SCIRXBUF: u32 = 0x7;
/// SCITXBUF.
pub const SCITXBUF: u32 = 0x9;
/// SCIFFTX.
pub const SCIFFTX: u32 = 0xA;
/// SCIFFRX.
pub const SCIFFRX: u32 = 0xB;
/// SCIFFCT.
pub const SCIFFCT: u32 = 0xC;
/// SCIPRI.
pub const SCIPRI: u32 = 0xF;

/// The registers of one port: name suffix, offset.
pub const REGISTER_OFFSETS: &[(&str, u32)] = &[
    ("SCICCR", SCICCR),
    ("SCICTL1", SCICTL1),
    ("SCIHBAUD", SCIHBAUD),
    ("SCILBAUD", SCILBAUD),
    ("SCICTL2", SCICTL2),
    ("SCIRXST", SCIRXST),
    ("SCIRXEMU", SCIRXEMU),
    ("SCIRXBUF", SCIRXBUF),
    ("SCITXBUF", SCITXBUF),
    ("SCIFFTX", SCIFFTX),
    ("SCIFFRX", SCIFFRX),
    ("SCIFFCT", SCIFFCT),
    ("SCIPRI", SCIPRI),
];

/// The modelled registers of the three ports (host.rs's names: `SCIB_SCIRXBUF`): name, address,
/// width in bits.
pub const REGISTERS: &[(&str, u32, u32)] = &[
    ("SCIA_SCICCR", 0x7050, 16),
    ("SCIA_SCICTL1", 0x7051, 16),
    ("SCIA_SCIHBAUD", 0x7052, 16),
    ("SCIA_SCILBAUD", 0x7053, 16),
    ("SCIA_SCICTL2", 0x7054, 16),
    ("SCIA_SCIRXST", 0x7055, 16),
    ("SCIA_SCIRXEMU", 0x7056, 16),
    ("SCIA_SCIRXBUF", 0x7057, 16),
    ("SCIA_SCITXBUF", 0x7059, 16),
    ("SCIA_SCIFFTX", 0x705A, 16),
    ("SCIA_SCIFFRX", 0x705B, 16),
    ("SCIA_SCIFFCT", 0x705C, 16),
    ("SCIA_SCIPRI", 0x705F, 16),
    ("SCIB_SCICCR", 0x7750, 16),
    ("SCIB_SCICTL1", 0x7751, 16),
    ("SCIB_SCIHBAUD", 0x7752, 16),
    ("SCIB_SCILBAUD", 0x7753, 16),
    ("SCIB_SCICTL2", 0x7754, 16),
    ("SCIB_SCIRXST", 0x7755, 16),
    ("SCIB_SCIRXEMU", 0x7756, 16),
    ("SCIB_SCIRXBUF", 0x7757, 16),
    ("SCIB_SCITXBUF", 0x7759, 16),
    ("SCIB_SCIFFTX", 0x775A, 16),
    ("SCIB_SCIFFRX", 0x775B, 16),
    ("SCIB_SCIFFCT", 0x775C, 16),
    ("SCIB_SCIPRI", 0x775F, 16),
    ("SCIC_SCICCR", 0x7770, 16),
    ("SCIC_SCICTL1", 0x7771, 16),
    ("SCIC_SCIHBAUD", 0x7772, 16),
    ("SCIC_SCILBAUD", 0x7773, 16),
    ("SCIC_SCICTL2", 0x7774, 16),
    ("SCIC_SCIRXST", 0x7775, 16),
    ("SCIC_SCIRXEMU", 0x7776, 16),
    ("SCIC_SCIRXBUF", 0x7777, 16),
    ("SCIC_SCITXBUF", 0x7779, 16),
    ("SCIC_SCIFFTX", 0x777A, 16),
    ("SCIC_SCIFFRX", 0x777B, 16),
    ("SCIC_SCIFFCT", 0x777C, 16),
    ("SCIC_SCIPRI", 0x777F, 16),
];

/// The port (0, 1, 2) and offset of an SCI register address.
pub fn port_of(addr: u32) -> Option<(usize, u32)> {
    PORTS.iter().enumerate().find_map(|(i, (_, base, _, _))| {
        let o = addr.checked_sub(*base)?;
        REGISTER_OFFSETS.iter().any(|r| r.1 == o).then_some((i, o))
    })
}

const FIFO_DEPTH: usize = 16;
/// A transmitted line is reported at its newline or at this many bytes (an NMEA 0183 sentence is at
/// most 82).
pub const TX_LINE_MAX: usize = 128;
const CCR_LOOPBKENA: u16 = 1 << 4;
const CCR_PARITYENA: u16 = 1 << 5;
const CCR_STOPBITS: u16 = 1 << 7;
const CTL1_RXENA: u16 = 1 << 0;
const CTL1_TXENA: u16 = 1 << 1;
const CTL1_SWRESET: u16 = 1 << 5;
const CTL1_RXERRINTENA: u16 = 1 << 6;
const CTL2_TXINTENA: u16 = 1 << 0;
const CTL2_RXBKINTENA: u16 = 1 << 1;
const FFTX_TXFIFOXRESET: u16 = 1 << 13;
const FFTX_SCIFFENA: u16 = 1 << 14;
const FFTX_SCIRST: u16 = 1 << 15;
const FFRX_RXFIFORESET: u16 = 1 << 13;
const FFRX_RXFFOVRCLR: u16 = 1 << 14;
const RX_FE: u16 = 1 << 15;
const RX_PE: u16 = 1 << 14;
/// A receiver samples each bit in its middle: the stop bit's middle is 9.5 bits after the start
/// edge of an 8N1 character, so a baud error above half a bit in 9.5 (5.26 %) reads it wrong.
pub const BAUD_TOLERANCE: f64 = 0.5 / 9.5;

/// What a port receives from outside: 8N1 characters, each with the time its stop bit ends.
#[derive(Debug, Clone, Default)]
pub struct RxFeed {
    /// (time the character is complete, byte), in time order.
    chars: VecDeque<(Ps, u8)>,
    /// The line's baud.
    pub baud: u32,
    /// Where it comes from (named in events).
    pub source: String,
}

impl RxFeed {
    /// `bytes` sent 8N1 at `baud` from `start` on: back to back, or (`line_period` > 0) each line
    /// (up to and with its `\n`) starting `line_period` after the one before, as a GPS sends its
    /// NMEA sentences once per epoch. A line longer than the period is an error naming `source`.
    pub fn new(bytes: &[u8], baud: u32, start: Ps, line_period: Ps, source: &str) -> Result<RxFeed> {
        if !(300..=4_000_000).contains(&baud) {
            return Err(Error::Config(format!("{source}: baud {baud}: expected 300…4000000")));
        }
        let char_ps = (10 * PS_PER_S).div_ceil(u64::from(baud));
        let mut chars = VecDeque::with_capacity(bytes.len());
        let mut t = start;
        let mut line_start = start;
        for (k, &b) in bytes.iter().enumerate() {
            t += char_ps;
            chars.push_back((t, b));
            if b == b'\n' && line_period > 0 {
                if t - line_start > line_period {
                    return Err(Error::Config(format!(
                        "{source}: the line ending at byte {k} takes {:.6} s at {baud} Bd, longer than the line \
                         period {:.6} s",
                        (t - line_start) as f64 / PS_PER_S as f64,
                        line_period as f64 / PS_PER_S as f64
                    )));
                }
                line_start += line_period;
                t = line_start;
            }
        }
        Ok(RxFeed { chars, baud, source: source.to_string() })
    }

    /// A file's bytes (see [`RxFeed::new`]); an unreadable file is an error naming it and `key`.
    pub fn from_file(path: &str, baud: u32, start: Ps, line_period: Ps, key: &str) -> Result<RxFeed> {
        let bytes = std::fs::read(path).map_err(|e| Error::Config(format!("{key} = \"{path}\": {e}")))?;
        RxFeed::new(&bytes, baud, start, line_period, &format!("{key} = \"{path}\""))
    }

    /// The characters still to come.
    pub fn remaining(&self) -> usize {
        self.chars.len()
    }
}

/// One SCI port.
#[derive(Debug, Clone)]
pub struct Sci {
    port: usize,
    lspclk: Clock,
    now: Ps,
    ccr: u16,
    ctl1: u16,
    hbaud: u16,
    lbaud: u16,
    ctl2: u16,
    fftx: u16,
    ffrx: u16,
    ffct: u16,
    pri: u16,
    /// TXBUF (non-FIFO: at most one) or the TX FIFO.
    tx_queue: VecDeque<u8>,
    /// The character shifting out: byte, start, end.
    shifter: Option<(u8, Ps, Ps)>,
    rx_fifo: VecDeque<u16>,
    rxbuf: u16,
    rxrdy: bool,
    oe: bool,
    fe: bool,
    pe: bool,
    rxffovf: bool,
    txffint: bool,
    rxffint: bool,
    rx_line: bool,
    tx_line: bool,
    feed: Option<RxFeed>,
    /// The setting whose framing errors were reported (baud, CCR), to report once per setting.
    fe_reported: Option<(u64, u16)>,
    tx_bytes: Vec<(Ps, u8)>,
    tx_text: Vec<u8>,
    events: Vec<Event>,
    requests: Vec<(u8, u8, Ps)>,
}

impl Sci {
    /// Port `port` (0 = A, 1 = B, 2 = C) in its reset state (SPRUFZ5: every control register 0,
    /// SCIFFTX 0xA000, SCIFFRX 0x201F, TXRDY = TXEMPTY = 1), clocked by `lspclk`.
    pub fn new(port: usize, lspclk: Clock) -> Sci {
        Sci {
            port,
            lspclk,
            now: 0,
            ccr: 0,
            ctl1: 0,
            hbaud: 0,
            lbaud: 0,
            ctl2: 0,
            fftx: 0xA000,
            ffrx: 0x201F,
            ffct: 0,
            pri: 0,
            tx_queue: VecDeque::new(),
            shifter: None,
            rx_fifo: VecDeque::new(),
            rxbuf: 0,
            rxrdy: false,
            oe: false,
            fe: false,
            pe: false,
            rxffovf: false,
            txffint: false,
            rxffint: false,
            rx_line: false,
            tx_line: false,
            feed: None,
            fe_reported: None,
            tx_bytes: Vec::new(),
            tx_text: Vec::new(),
            events: Vec::new(),
            requests: Vec::new(),
        }
    }

    fn name(&self) -> &'static str {
        PORTS[self.port].0
    }

    /// The receive feed (replacing any).
    pub fn set_feed(&mut self, feed: RxFeed) {
        self.feed = Some(feed);
    }

    /// LSPCLK changes at `t`: a character shifting keeps its timing, the next ones take the new one.
    pub fn set_lspclk(&mut self, lspclk: Clock, t: Ps) {
        self.advance(t);
        self.lspclk = lspclk;
    }

    /// BRR (SCIHBAUD:SCILBAUD).
    pub fn brr(&self) -> u16 {
        self.hbaud << 8 | self.lbaud
    }

    /// LSPCLK cycles per bit: (BRR + 1) · 8, or 16 with BRR = 0.
    fn bit_cycles(&self) -> u64 {
        match self.brr() {
            0 => 16,
            b => (u64::from(b) + 1) * 8,
        }
    }

    /// The baud, bits per second.
    pub fn baud(&self) -> f64 {
        self.lspclk.hz() / self.bit_cycles() as f64
    }

    /// Bits of a character on the line: start, data, parity, stop.
    pub fn frame_bits(&self) -> u64 {
        let data = u64::from(self.ccr & 7) + 1;
        1 + data + u64::from(self.ccr & CCR_PARITYENA != 0) + 1 + u64::from(self.ccr & CCR_STOPBITS != 0)
    }

    fn bits_ps(&self, bits: u64) -> Ps {
        self.lspclk.cycles_to_ps(bits * self.bit_cycles())
    }

    /// A character's time on the line, ps.
    pub fn char_ps(&self) -> Ps {
        self.bits_ps(self.frame_bits())
    }

    fn fifo_mode(&self) -> bool {
        self.fftx & FFTX_SCIFFENA != 0
    }

    fn active(&self) -> bool {
        self.ctl1 & CTL1_SWRESET != 0 && self.fftx & FFTX_SCIRST != 0
    }

    fn tx_enabled(&self) -> bool {
        self.active() && self.ctl1 & CTL1_TXENA != 0
    }

    fn loopback(&self) -> bool {
        self.ccr & CCR_LOOPBKENA != 0
    }

    fn txrdy(&self) -> bool {
        if self.fifo_mode() {
            self.tx_queue.len() < FIFO_DEPTH
        } else {
            self.tx_queue.is_empty()
        }
    }

    fn txempty(&self) -> bool {
        self.tx_queue.is_empty() && self.shifter.is_none()
    }

    fn misuse(&mut self, message: String) {
        self.events.push(Event::new(self.now, "sci_misuse", Severity::Warning, format!("{}: {message}", self.name())));
    }

    /// The time of the port's next change by itself after `now` (a character's start or end, a
    /// received character's arrival), if any.
    /// A port whose receiver listens to a pin with a feed that has ended may still hear a character
    /// (the line's sender is outside the model): it may change one character time from now, so that
    /// a firmware waiting for its next sentence runs on to the end of the run rather than being
    /// taken for a loop that can never end.
    pub fn next_change_ps(&self) -> Option<Ps> {
        let shift = self.shifter.map(|(_, s, e)| if s > self.now { s } else { e });
        let rx = self.feed.as_ref().and_then(|f| f.chars.front().map(|c| c.0));
        let next = shift.into_iter().chain(rx).filter(|&t| t > self.now).min();
        let listening = self.feed.is_some() && self.rx_enabled() && !self.loopback();
        next.or_else(|| listening.then(|| self.now + self.char_ps()))
    }

    /// [`Sci::next_change_ps`] when an interrupt of this port is enabled (a change may raise one).
    pub fn next_interrupt_ps(&self) -> Option<Ps> {
        let any = (self.fftx | self.ffrx) & FF_IENA != 0
            || self.ctl2 & (CTL2_TXINTENA | CTL2_RXBKINTENA) != 0
            || self.ctl1 & CTL1_RXERRINTENA != 0;
        if any {
            self.next_change_ps()
        } else {
            None
        }
    }

    /// Bring the port up to `t`: characters end and start, received ones arrive, in time order.
    #[inline]
    pub fn advance(&mut self, t: Ps) {
        // The board brings every port up to date at each step of time: a port with no character
        // shifting and none to receive only moves its clock (inline, without a call).
        if self.shifter.is_none() && self.feed.as_ref().is_none_or(|f| f.chars.is_empty()) {
            self.now = self.now.max(t);
            return;
        }
        self.advance_busy(t);
    }

    fn advance_busy(&mut self, t: Ps) {
        loop {
            let tx_end = self.shifter.map(|(_, _, e)| e).filter(|&e| e <= t);
            let rx_at = self.feed.as_ref().and_then(|f| f.chars.front().map(|c| c.0)).filter(|&a| a <= t);
            match (tx_end, rx_at) {
                (Some(e), r) if r.is_none_or(|r| e <= r) => self.end_tx(e),
                (_, Some(r)) => {
                    let (_, b) = self.feed.as_mut().and_then(|f| f.chars.pop_front()).unwrap_or((r, 0));
                    self.now = self.now.max(r);
                    if !self.loopback() {
                        let (fe, pe) = self.framing(r);
                        self.receive(u16::from(b), fe, pe, r);
                    }
                }
                _ => break,
            }
        }
        self.now = self.now.max(t);
    }

    /// Whether a character from the feed is read with FE or PE at this port's setting.
    fn framing(&mut self, t: Ps) -> (bool, bool) {
        let Some(feed) = &self.feed else { return (false, false) };
        let want = f64::from(feed.baud);
        let err = (self.baud() - want).abs() / want;
        let format_ok = self.ccr & 7 == 7 && self.ccr & CCR_PARITYENA == 0;
        if err <= BAUD_TOLERANCE && format_ok {
            return (false, false);
        }
        let setting = (self.bit_cycles(), self.ccr);
        if self.fe_reported != Some(setting) && self.rx_enabled() {
            self.fe_reported = Some(setting);
            let msg = format!(
                "{}: {} sends 8N1 at {} Bd; the port is set to {:.1} Bd ({:+.2} %, a receiver takes ±{:.2} %), \
                 {} data bits{}: its characters are read with FE set",
                self.name(),
                feed.source,
                feed.baud,
                self.baud(),
                100.0 * (self.baud() - want) / want,
                100.0 * BAUD_TOLERANCE,
                (self.ccr & 7) + 1,
                if self.ccr & CCR_PARITYENA != 0 { ", parity" } else { "" }
            );
            self.events.push(Event::new(t, "uart_framing_error", Severity::Warning, msg));
        }
        (true, false)
    }

    fn rx_enabled(&self) -> bool {
        self.active() && self.ctl1 & CTL1_RXENA != 0
    }

    fn end_tx(&mut self, e: Ps) {
        let Some((b, _, _)) = self.shifter.take() else { return };
        self.now = self.now.max(e);
        if self.loopback() {
            self.receive(u16::from(b), false, false, e);
        } else {
            self.tx_bytes.push((e, b));
            self.tx_text.push(b);
            if b == b'\n' || self.tx_text.len() >= TX_LINE_MAX {
                self.flush_line(e);
            }
        }
        self.start_tx(e, true);
        self.update_irq(e);
    }

    fn flush_line(&mut self, t: Ps) {
        let text: String = self
            .tx_text
            .iter()
            .map(|&c| match c {
                b'\n' => "\\n".to_string(),
                b'\r' => "\\r".to_string(),
                0x20..=0x7E => (c as char).to_string(),
                _ => format!("\\x{c:02X}"),
            })
            .collect();
        self.tx_text.clear();
        self.events.push(Event::new(t, "sci_tx_line", Severity::Info, format!("{}> {text}", self.name())));
    }

    /// Start the next character at `t` when the shifter is free (after FFTXDLY baud-clock periods
    /// when it follows one from the FIFO).
    fn start_tx(&mut self, t: Ps, after_char: bool) {
        if self.shifter.is_some() || !self.tx_enabled() || self.tx_queue.is_empty() {
            return;
        }
        if self.fifo_mode() && self.fftx & FFTX_TXFIFOXRESET == 0 {
            return;
        }
        let Some(b) = self.tx_queue.pop_front() else { return };
        let gap = if after_char && self.fifo_mode() { self.bits_ps(u64::from(self.ffct & 0xFF)) } else { 0 };
        let start = t + gap;
        self.shifter = Some((b, start, start + self.char_ps()));
    }

    fn receive(&mut self, data: u16, fe: bool, pe: bool, t: Ps) {
        if !self.rx_enabled() {
            return;
        }
        let mask = (1u16 << ((self.ccr & 7) + 1)) - 1;
        let data = data & mask;
        self.fe |= fe;
        self.pe |= pe;
        if self.fifo_mode() {
            if self.ffrx & FFRX_RXFIFORESET == 0 {
                return;
            }
            if self.rx_fifo.len() >= FIFO_DEPTH {
                if !self.rxffovf {
                    self.overrun(t, "with the 16-word RX FIFO full: lost (RXFFOVF set)");
                }
                self.rxffovf = true;
            } else {
                self.rx_fifo.push_back(data | if fe { RX_FE } else { 0 } | if pe { RX_PE } else { 0 });
            }
        } else {
            if self.rxrdy {
                if !self.oe {
                    self.overrun(t, "before SCIRXBUF's last one was read: it is overwritten (OE set)");
                }
                self.oe = true;
            }
            self.rxbuf = data;
            self.rxrdy = true;
        }
        self.update_irq(t);
    }

    /// A character lost or overwritten at `t` (`how` it arrived and what became of it).
    fn overrun(&mut self, t: Ps, how: &str) {
        let what = format!("{}: a character arrived {how}", self.name());
        self.events.push(Event::new(t, "uart_overrun", Severity::Warning, what));
    }

    fn rxerror(&self) -> bool {
        self.oe || self.fe || self.pe
    }

    /// Raise the PIE requests of rising interrupt lines.
    fn update_irq(&mut self, t: Ps) {
        let (rx, tx) = if self.fifo_mode() {
            if self.rx_fifo.len() >= usize::from(self.ffrx & FF_IL) && self.ffrx & FFRX_RXFIFORESET != 0 {
                self.rxffint = true;
            }
            if self.tx_queue.len() <= usize::from(self.fftx & FF_IL) && self.fftx & FFTX_TXFIFOXRESET != 0 {
                self.txffint = true;
            }
            (self.rxffint && self.ffrx & FF_IENA != 0, self.txffint && self.fftx & FF_IENA != 0)
        } else {
            let rx = (self.rxrdy && self.ctl2 & CTL2_RXBKINTENA != 0)
                || (self.rxerror() && self.ctl1 & CTL1_RXERRINTENA != 0);
            (rx, self.txrdy() && self.active() && self.ctl2 & CTL2_TXINTENA != 0)
        };
        let (_, _, rxi, txi) = PORTS[self.port];
        if rx && !self.rx_line {
            self.requests.push((rxi.0, rxi.1, t));
        }
        if tx && !self.tx_line {
            self.requests.push((txi.0, txi.1, t));
        }
        self.rx_line = rx;
        self.tx_line = tx;
    }

    /// The PIE requests raised since the last call: (group, line, time).
    pub fn take_requests(&mut self) -> Vec<(u8, u8, Ps)> {
        std::mem::take(&mut self.requests)
    }

    /// The events since the last call.
    pub fn drain_events(&mut self) -> Vec<Event> {
        std::mem::take(&mut self.events)
    }

    /// Whether the port holds no interrupt request and no event to take.
    #[inline]
    pub fn nothing_to_take(&self) -> bool {
        self.requests.is_empty() && self.events.is_empty()
    }

    /// Every byte transmitted on the TX pin so far, with the time its stop bit ended.
    pub fn tx_bytes(&self) -> &[(Ps, u8)] {
        &self.tx_bytes
    }

    /// Reset the state machines and flags (SWRESET = 0, SCIRST = 0).
    fn reset_channels(&mut self) {
        self.rxrdy = false;
        self.oe = false;
        self.fe = false;
        self.pe = false;
        self.shifter = None;
        if !self.fifo_mode() {
            self.tx_queue.clear();
        }
    }

    /// Read the register at offset `off` at `t`.
    pub fn read(&mut self, off: u32, t: Ps) -> Result<u16> {
        self.advance(t);
        let v = match off {
            SCICCR => self.ccr,
            SCICTL1 => self.ctl1,
            SCIHBAUD => self.hbaud,
            SCILBAUD => self.lbaud,
            SCICTL2 => {
                let (rdy, empty) = if self.active() { (self.txrdy(), self.txempty()) } else { (true, true) };
                self.ctl2 | u16::from(rdy) << 7 | u16::from(empty) << 6
            }
            SCIRXST => {
                let rxrdy = if self.fifo_mode() { !self.rx_fifo.is_empty() } else { self.rxrdy };
                u16::from(self.rxerror()) << 7
                    | u16::from(rxrdy) << 6
                    | u16::from(self.fe) << 4
                    | u16::from(self.oe) << 3
                    | u16::from(self.pe) << 2
            }
            SCIRXEMU => {
                if self.fifo_mode() {
                    self.rx_fifo.front().copied().unwrap_or(self.rxbuf)
                } else {
                    self.rxbuf
                }
            }
            SCIRXBUF => {
                if self.fifo_mode() {
                    match self.rx_fifo.pop_front() {
                        Some(w) => {
                            self.rxbuf = w;
                            w
                        }
                        None => {
                            self.misuse(
                                "SCIRXBUF read with the RX FIFO empty (RXFFST = 0): it reads the last word again"
                                    .into(),
                            );
                            self.rxbuf
                        }
                    }
                } else {
                    if !self.rxrdy {
                        self.misuse(
                            "SCIRXBUF read with RXRDY = 0 (nothing received): it reads the last word again".into(),
                        );
                    }
                    self.rxrdy = false;
                    self.rxbuf
                }
            }
            SCITXBUF => 0,
            SCIFFTX => self.fftx | u16::from(self.txffint) << 7 | (self.tx_queue.len().min(FIFO_DEPTH) as u16) << 8,
            SCIFFRX => {
                self.ffrx
                    | u16::from(self.rxffint) << 7
                    | (self.rx_fifo.len() as u16) << 8
                    | u16::from(self.rxffovf) << 15
            }
            SCIFFCT => self.ffct,
            SCIPRI => self.pri,
            o => return Err(no_register(self.port, o)),
        };
        self.update_irq(t);
        Ok(v)
    }

    /// Write the register at offset `off` at `t`.
    pub fn write(&mut self, off: u32, value: u16, t: Ps) -> Result<()> {
        self.advance(t);
        match off {
            SCICCR => self.ccr = value & 0xFF,
            SCICTL1 => {
                self.ctl1 = value & 0x6F;
                if self.ctl1 & CTL1_SWRESET == 0 {
                    self.reset_channels();
                }
            }
            SCIHBAUD => self.hbaud = value & 0xFF,
            SCILBAUD => self.lbaud = value & 0xFF,
            SCICTL2 => self.ctl2 = value & 0x3,
            SCIRXST | SCIRXEMU | SCIRXBUF => self.misuse(format!(
                "{} written (0x{value:04X}): a read-only register, the write is ignored",
                REGISTER_OFFSETS.iter().find(|r| r.1 == off).map_or("?", |r| r.0)
            )),
            SCITXBUF => self.write_txbuf(value, t),
            SCIFFTX => {
                if value & FF_INTCLR != 0 {
                    // The flag clears; if its condition still holds it sets again: a new request.
                    self.txffint = false;
                    self.tx_line = false;
                }
                self.fftx = value & 0xE03F;
                if self.fftx & FFTX_TXFIFOXRESET == 0 && self.fifo_mode() {
                    self.tx_queue.clear();
                }
                if self.fftx & FFTX_SCIRST == 0 {
                    self.reset_channels();
                }
            }
            SCIFFRX => {
                if value & FF_INTCLR != 0 {
                    self.rxffint = false;
                    self.rx_line = false;
                }
                if value & FFRX_RXFFOVRCLR != 0 {
                    self.rxffovf = false;
                }
                self.ffrx = value & 0x203F;
                if self.ffrx & FFRX_RXFIFORESET == 0 {
                    self.rx_fifo.clear();
                }
            }
            SCIFFCT => {
                if value & (1 << 13) != 0 {
                    self.misuse("SCIFFCT.CDC = 1 (autobaud detection): not modelled, the baud stays BRR's".into());
                }
                self.ffct = value & 0x20FF;
            }
            SCIPRI => self.pri = value & 0x18,
            o => return Err(no_register(self.port, o)),
        }
        self.start_tx(t, false);
        self.update_irq(t);
        Ok(())
    }

    fn write_txbuf(&mut self, value: u16, t: Ps) {
        let b = (value & 0xFF) as u8;
        if !self.active() {
            self.misuse(format!(
                "SCITXBUF written (0x{value:02X}) with the SCI held in reset (SCICTL1.SWRESET = 0 or SCIFFTX.SCIRST = 0): \
                 the character is lost"
            ));
            return;
        }
        if self.fifo_mode() {
            if self.fftx & FFTX_TXFIFOXRESET == 0 {
                self.misuse(format!(
                    "SCITXBUF written (0x{value:02X}) with the TX FIFO held in reset (SCIFFTX.TXFIFOXRESET = 0): the \
                     character is lost"
                ));
                return;
            }
            if self.tx_queue.len() >= FIFO_DEPTH {
                self.misuse(format!(
                    "SCITXBUF written (0x{value:02X}) with the TX FIFO full (TXFFST = 16): the character is lost"
                ));
                return;
            }
        } else if !self.tx_queue.is_empty() {
            self.misuse(format!(
                "SCITXBUF written (0x{value:02X}) with TXRDY = 0 (the last character still waits for the shifter): it \
                 overwrites that character"
            ));
            self.tx_queue.clear();
        }
        self.tx_queue.push_back(b);
        let _ = t;
    }
}

fn no_register(port: usize, off: u32) -> Error {
    Error::Register(format!(
        "C28x address 0x{:04X}: not an {} register (SCICCR…SCIPRI at offsets 0…7, 9…0xC, 0xF)",
        PORTS[port].1 + off,
        PORTS[port].0
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    const LSPCLK: u64 = 37_500_000;

    fn sci() -> Sci {
        Sci::new(0, Clock::from_hz(LSPCLK))
    }

    /// TI's FFDLB setup: FIFO mode, 8N1, loopback, released from reset.
    fn ffdlb(s: &mut Sci, brr: u16) {
        s.write(SCIFFTX, 0xE040, 0).unwrap();
        s.write(SCIFFRX, 0x204F, 0).unwrap();
        s.write(SCIFFCT, 0, 0).unwrap();
        s.write(SCICCR, 0x0007, 0).unwrap();
        s.write(SCICTL1, 0x0003, 0).unwrap();
        s.write(SCIHBAUD, brr >> 8, 0).unwrap();
        s.write(SCILBAUD, brr & 0xFF, 0).unwrap();
        s.write(SCICCR, 0x0017, 0).unwrap();
        s.write(SCICTL1, 0x0023, 0).unwrap();
    }

    #[test]
    fn reset_values_follow_sprufz5() {
        let mut s = sci();
        assert_eq!(s.read(SCIFFTX, 0).unwrap(), 0xA000);
        assert_eq!(s.read(SCIFFRX, 0).unwrap() & 0xFF7F, 0x201F);
        assert_eq!(s.read(SCICTL2, 0).unwrap(), 0x00C0); // TXRDY, TXEMPTY
        assert_eq!(s.read(SCIRXST, 0).unwrap(), 0);
        assert_eq!(s.read(SCICCR, 0).unwrap(), 0);
    }

    #[test]
    fn baud_and_character_time_follow_brr() {
        let mut s = sci();
        s.write(SCICCR, 7, 0).unwrap();
        s.write(SCILBAUD, 0xE7, 0).unwrap();
        s.write(SCIHBAUD, 0x01, 0).unwrap();
        // 9600 Bd at 37.5 MHz: BRR = 0x1E7 (TI's sci_echoback), 37.5e6 / (488 · 8) = 9605.3 Bd.
        assert!((s.baud() - 37.5e6 / (488.0 * 8.0)).abs() < 1e-9);
        assert_eq!(s.frame_bits(), 10);
        assert_eq!(s.char_ps(), Clock::from_hz(LSPCLK).cycles_to_ps(10 * 488 * 8));
        s.write(SCICCR, 0x00E7, 0).unwrap(); // two stop bits, even parity
        assert_eq!(s.frame_bits(), 12);
        s.write(SCIHBAUD, 0, 0).unwrap();
        s.write(SCILBAUD, 0, 0).unwrap();
        assert_eq!(s.baud(), 37.5e6 / 16.0);
    }

    #[test]
    fn fifo_loopback_returns_each_character_after_its_time_on_the_line() {
        let mut s = sci();
        ffdlb(&mut s, 0x1E7);
        let c = s.char_ps();
        s.write(SCITXBUF, 0x41, 1000).unwrap();
        s.write(SCITXBUF, 0x42, 1000).unwrap();
        assert_eq!(s.read(SCIFFTX, 1000).unwrap() >> 8 & 0x1F, 1); // one waits, one shifts
        assert_eq!(s.read(SCIFFRX, 1000 + c - 1).unwrap() >> 8 & 0x1F, 0);
        assert_eq!(s.next_change_ps(), Some(1000 + c));
        assert_eq!(s.read(SCIFFRX, 1000 + c).unwrap() >> 8 & 0x1F, 1);
        assert_eq!(s.read(SCIFFRX, 1000 + 2 * c).unwrap() >> 8 & 0x1F, 2);
        assert_eq!(s.read(SCIRXBUF, 1000 + 2 * c).unwrap(), 0x41);
        assert_eq!(s.read(SCIRXBUF, 1000 + 2 * c).unwrap(), 0x42);
        assert!(s.tx_bytes().is_empty(), "loopback keeps the characters inside the chip");
        assert!(s.drain_events().is_empty());
        s.read(SCIRXBUF, 1000 + 2 * c).unwrap();
        let e = s.drain_events();
        assert_eq!(e.len(), 1);
        assert_eq!(e[0].kind, "sci_misuse");
        assert!(e[0].message.contains("RX FIFO empty"), "{}", e[0].message);
    }

    #[test]
    fn fftxdly_separates_fifo_characters() {
        let mut s = sci();
        ffdlb(&mut s, 9);
        s.write(SCIFFCT, 5, 0).unwrap();
        let (c, gap) = (s.char_ps(), s.bits_ps(5));
        s.write(SCITXBUF, 1, 0).unwrap();
        s.write(SCITXBUF, 2, 0).unwrap();
        s.advance(c);
        assert_eq!(s.shifter.map(|x| x.1), Some(c + gap));
    }

    #[test]
    fn fifo_interrupts_rise_at_their_levels_and_clear_by_writing_one() {
        let mut s = sci();
        // TI's Example_2833xSci_FFDLB_int: TXFFIL = RXFFIL = 2, both interrupts enabled.
        s.write(SCICCR, 0x0017, 0).unwrap();
        s.write(SCICTL1, 0x0003, 0).unwrap();
        s.write(SCILBAUD, 9, 0).unwrap();
        s.write(SCIFFTX, 0xC022, 0).unwrap();
        s.write(SCIFFRX, 0x0022, 0).unwrap();
        s.write(SCICTL1, 0x0023, 0).unwrap();
        s.write(SCIFFTX, 0xE022, 0).unwrap();
        s.write(SCIFFRX, 0x2022, 0).unwrap();
        assert_eq!(s.take_requests(), vec![(9, 2, 0)]); // TXFFST 0 ≤ 2
        s.write(SCITXBUF, 1, 0).unwrap();
        s.write(SCITXBUF, 2, 0).unwrap();
        s.write(SCIFFTX, 0xE062, 0).unwrap(); // TXFFINTCLR: 1 waits ≤ 2, so it sets again
        assert_eq!(s.take_requests(), vec![(9, 2, 0)]);
        let c = s.char_ps();
        s.advance(2 * c - 1);
        assert!(s.take_requests().is_empty());
        s.advance(2 * c);
        assert_eq!(s.take_requests(), vec![(9, 1, 2 * c)]);
        assert_eq!(s.read(SCIRXBUF, 2 * c).unwrap(), 1);
        assert_eq!(s.read(SCIRXBUF, 2 * c).unwrap(), 2);
        s.write(SCIFFRX, 0x2062, 2 * c).unwrap();
        assert!(s.take_requests().is_empty(), "RXFFST 0 < 2: the flag stays clear");
        assert_eq!(s.read(SCIFFRX, 2 * c).unwrap() & 0x80, 0);
    }

    #[test]
    fn rx_fifo_overflow_sets_rxffovf_and_loses_the_character() {
        let mut s = sci();
        ffdlb(&mut s, 0);
        for k in 0..17u16 {
            s.write(SCITXBUF, k, s.now).unwrap();
            let c = s.char_ps();
            s.advance(s.now + c);
        }
        assert_eq!(s.read(SCIFFRX, s.now).unwrap() >> 8 & 0x9F, 0x80 | 16);
        let e = s.drain_events();
        assert_eq!(e.iter().filter(|e| e.kind == "uart_overrun").count(), 1);
        s.write(SCIFFRX, 0x604F, s.now).unwrap(); // RXFFOVRCLR
        assert_eq!(s.read(SCIFFRX, s.now).unwrap() & 0x8000, 0);
        assert_eq!(s.read(SCIRXBUF, s.now).unwrap(), 0);
    }

    #[test]
    fn non_fifo_receive_sets_rxrdy_and_overrun_sets_oe() {
        let mut s = sci();
        s.write(SCICCR, 0x0017, 0).unwrap();
        s.write(SCICTL1, 0x0023, 0).unwrap();
        s.write(SCICTL2, CTL2_RXBKINTENA, 0).unwrap();
        s.write(SCIFFTX, 0x8000, 0).unwrap(); // FIFO off
        let c = s.char_ps();
        s.write(SCITXBUF, 0x55, 0).unwrap();
        assert_eq!(s.read(SCICTL2, 0).unwrap() & 0xC0, 0x80); // TXRDY, not TXEMPTY
        s.advance(c);
        assert_eq!(s.take_requests(), vec![(9, 1, c)]);
        assert_eq!(s.read(SCIRXST, c).unwrap(), 0x40);
        s.write(SCITXBUF, 0x56, c).unwrap();
        s.advance(2 * c);
        assert_eq!(s.read(SCIRXST, 2 * c).unwrap(), 0xC8); // RXERROR, RXRDY, OE
        assert_eq!(s.read(SCIRXBUF, 2 * c).unwrap(), 0x56);
        assert_eq!(s.read(SCIRXST, 2 * c).unwrap(), 0x88);
        s.write(SCICTL1, 0x0003, 2 * c).unwrap(); // SWRESET = 0 clears the flags
        assert_eq!(s.read(SCIRXST, 2 * c).unwrap(), 0);
    }

    #[test]
    fn transmitted_lines_are_captured_with_the_port_prefix() {
        let mut s = Sci::new(1, Clock::from_hz(LSPCLK));
        s.write(SCICCR, 7, 0).unwrap();
        s.write(SCICTL1, 0x0023, 0).unwrap();
        s.write(SCIFFTX, 0xE040, 0).unwrap();
        for &b in b"OK\r\n" {
            s.write(SCITXBUF, u16::from(b), 0).unwrap();
        }
        let c = s.char_ps();
        s.advance(4 * c);
        assert_eq!(s.tx_bytes().iter().map(|x| x.1).collect::<Vec<_>>(), b"OK\r\n");
        assert_eq!(s.tx_bytes()[3].0, 4 * c);
        let e = s.drain_events();
        assert_eq!(e.len(), 1);
        assert_eq!(e[0].message, "SCI-B> OK\\r\\n");
        assert_eq!(e[0].t_ps, 4 * c);
    }

    #[test]
    fn a_feed_arrives_at_its_baud_and_a_wrong_baud_reads_framing_errors() {
        let feed = RxFeed::new(b"$A\n$B\n", 9600, 0, PS_PER_S, "test").unwrap();
        let times: Vec<Ps> = feed.chars.iter().map(|c| c.0).collect();
        let char_ps = (10 * PS_PER_S).div_ceil(9600);
        assert_eq!(
            times,
            vec![char_ps, 2 * char_ps, 3 * char_ps, PS_PER_S + char_ps, PS_PER_S + 2 * char_ps, PS_PER_S + 3 * char_ps]
        );
        let mut s = Sci::new(1, Clock::from_hz(LSPCLK));
        s.set_feed(feed.clone());
        s.write(SCICCR, 7, 0).unwrap();
        s.write(SCILBAUD, 0xE7, 0).unwrap();
        s.write(SCIHBAUD, 0x01, 0).unwrap();
        s.write(SCIFFTX, 0xE000, 0).unwrap();
        s.write(SCICTL1, 0x0021, 0).unwrap();
        s.advance(3 * char_ps);
        assert_eq!(s.read(SCIFFRX, 3 * char_ps).unwrap() >> 8 & 0x1F, 3);
        assert_eq!(s.read(SCIRXBUF, 3 * char_ps).unwrap(), u16::from(b'$'));
        assert!(s.drain_events().is_empty());
        // 19200 Bd against the 9600 Bd line: every character with FE, reported once.
        let mut s = Sci::new(1, Clock::from_hz(LSPCLK));
        s.set_feed(feed);
        s.write(SCICCR, 7, 0).unwrap();
        s.write(SCILBAUD, 0xF3, 0).unwrap();
        s.write(SCIFFTX, 0xE000, 0).unwrap();
        s.write(SCICTL1, 0x0021, 0).unwrap();
        s.advance(2 * PS_PER_S);
        assert_eq!(s.read(SCIRXBUF, s.now).unwrap(), RX_FE | u16::from(b'$'));
        assert_eq!(s.read(SCIRXST, s.now).unwrap() & 0x90, 0x90);
        let e = s.drain_events();
        assert_eq!(e.len(), 1, "{e:?}");
        assert_eq!(e.iter().filter(|e| e.kind == "uart_framing_error").count(), 1);
    }

    #[test]
    fn a_line_longer_than_its_period_is_refused_naming_the_source() {
        let mut line = vec![b'x'; 20];
        line.push(b'\n');
        let e = RxFeed::new(&line, 9600, 0, PS_PER_S / 1000, "serial.sci_b.rx_file").unwrap_err().to_string();
        assert!(e.contains("serial.sci_b.rx_file") && e.contains("longer than the line period"), "{e}");
    }

    #[test]
    fn misuse_is_reported() {
        let mut s = sci();
        s.write(SCITXBUF, 1, 0).unwrap();
        s.write(SCIRXST, 1, 0).unwrap();
        let e = s.drain_events();
        assert!(e[0].message.contains("held in reset"), "{}", e[0].message);
        assert!(e[1].message.contains("SCIRXST written"), "{}", e[1].message);
        assert!(s.write(0x8, 0, 0).is_err());
    }
}
