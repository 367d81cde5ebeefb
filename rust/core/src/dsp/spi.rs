//! SPI-A of the F28335 as a register model in virtual time.
//!
//! The firmware model reads and writes 16-bit registers at word offsets, each access stamped with
//! its virtual time. The peripheral is event-driven: a write of SPITXBUF with the shifter idle
//! schedules a character `start_latency_lspclk` LSPCLK cycles later; the character occupies
//! exactly `bits × divisor` LSPCLK cycles; at its end the received word lands in SPIRXBUF and
//! INT_FLAG sets. Every access first *advances* the peripheral to its time, handing the wire each
//! character start and end in time order, so a status read at `t` shows exactly what has happened
//! by `t`. [`SpiA::int_flag_time`] and [`SpiA::buffull_clear_time`] tell a polling firmware model
//! when a flag changes, so a polling loop costs one computation instead of one step per cycle.
//!
//! Modelling choices not fixed by TI's documentation (documented here, tested, and kept in one place):
//! - LSPCLK edges are at whole multiples of the LSPCLK period since power-on; the baud generator
//!   restarts with each character, so every SCLK edge is a whole LSPCLK cycle.
//! - From idle, the character starts `start_latency_lspclk` cycles after the first LSPCLK edge at or
//!   after the write (`profile::Spi::start_latency_lspclk`, [unconfirmed]). From idle, TXBUF is copied
//!   to SPIDAT at once (BUFFULL_FLAG does not set); the shifter counts as busy from then on. A word
//!   written while the shifter is busy waits in TXBUF (BUFFULL_FLAG = 1) and starts the moment the
//!   running character ends (plus TXDLY SPI clocks in FIFO mode).
//! - A character ends (INT_FLAG, RXBUF load) after `bits` full SPI clock periods from its start,
//!   i.e. after the trailing idle-level phase of its last bit.
//! - SPIRXBUF holds the whole shift register after the character: received bits right-justified,
//!   the rest of the transmitted word above them when fewer than 16 bits are clocked.
//! - FIFO mode drives TXFFST/RXFFST and the FIFO interrupt flags; SPISTS flags stay 0 in FIFO mode;
//!   a word arriving at a full receive FIFO is lost and RXFFOVF sets.
//! - Register and configuration changes apply to characters scheduled after them; a character
//!   keeps the configuration it started with. SPIDAT reads return the value at the last character
//!   boundary (mid-character shift states are not modelled).

use crate::error::{Error, Result};
use crate::events::{Event, EventLog, Severity};
use crate::profile;
use crate::time::{Clock, Divisor, Ps};

/// SPI configuration control register (word offset).
pub const SPICCR: u16 = 0x0;
/// SPI operation control register.
pub const SPICTL: u16 = 0x1;
/// SPI status register.
pub const SPISTS: u16 = 0x2;
/// SPI baud rate register.
pub const SPIBRR: u16 = 0x4;
/// SPI emulation buffer (reads the received word without clearing INT_FLAG).
pub const SPIRXEMU: u16 = 0x6;
/// SPI receive buffer.
pub const SPIRXBUF: u16 = 0x7;
/// SPI transmit buffer.
pub const SPITXBUF: u16 = 0x8;
/// SPI shift register.
pub const SPIDAT: u16 = 0x9;
/// SPI FIFO transmit register.
pub const SPIFFTX: u16 = 0xA;
/// SPI FIFO receive register.
pub const SPIFFRX: u16 = 0xB;
/// SPI FIFO control register.
pub const SPIFFCT: u16 = 0xC;
/// SPI priority control register.
pub const SPIPRI: u16 = 0xF;

/// SPICCR.SPISWRESET.
pub const SPICCR_SPISWRESET: u16 = 1 << 7;
/// SPICCR.CLKPOLARITY.
pub const SPICCR_CLKPOLARITY: u16 = 1 << 6;
/// SPICCR.SPILBK (loopback).
pub const SPICCR_SPILBK: u16 = 1 << 4;
/// SPICTL.CLK_PHASE.
pub const SPICTL_CLK_PHASE: u16 = 1 << 3;
/// SPICTL.MASTER_SLAVE (1 = master).
pub const SPICTL_MASTER: u16 = 1 << 2;
/// SPICTL.TALK.
pub const SPICTL_TALK: u16 = 1 << 1;
/// SPISTS.OVERRUN_FLAG.
pub const SPISTS_OVERRUN: u16 = 1 << 7;
/// SPISTS.INT_FLAG.
pub const SPISTS_INT_FLAG: u16 = 1 << 6;
/// SPISTS.BUFFULL_FLAG.
pub const SPISTS_BUFFULL: u16 = 1 << 5;
/// SPIFFTX.SPIRST.
pub const SPIFFTX_SPIRST: u16 = 1 << 15;
/// SPIFFTX.SPIFFENA.
pub const SPIFFTX_SPIFFENA: u16 = 1 << 14;
/// SPIFFTX.TXFIFO (0 = hold the transmit FIFO in reset).
pub const SPIFFTX_TXFIFO: u16 = 1 << 13;
/// SPIFFRX.RXFIFORESET (0 = hold the receive FIFO in reset).
pub const SPIFFRX_RXFIFORESET: u16 = 1 << 13;
/// Depth of each FIFO.
pub const FIFO_DEPTH: usize = 16;

/// One of TI's four SPI clock schemes (SPICCR.CLKPOLARITY × SPICTL.CLK_PHASE).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ClockScheme {
    /// CLKPOLARITY: `true` = SPICLK idles high.
    pub polarity: bool,
    /// CLK_PHASE: `true` = "with delay" (data out half a cycle before the first edge).
    pub phase: bool,
}

impl ClockScheme {
    /// The standard SPI mode number of this scheme (TI's table: (1,0) → 3, (1,1) → 2, (0,0) → 1,
    /// (0,1) → 0).
    pub fn standard_mode(self) -> u8 {
        match (self.polarity, self.phase) {
            (false, false) => 1,
            (false, true) => 0,
            (true, false) => 3,
            (true, true) => 2,
        }
    }

    /// TI's name of the scheme.
    pub fn ti_name(self) -> &'static str {
        match (self.polarity, self.phase) {
            (false, false) => "rising edge without delay",
            (false, true) => "rising edge with delay",
            (true, false) => "falling edge without delay",
            (true, true) => "falling edge with delay",
        }
    }
}

/// LSPCLK cycles per SPI clock for an SPIBRR value: SPIBRR+1, or 4 for SPIBRR = 0…2.
pub fn baud_divisor(spibrr: u16) -> u32 {
    let brr = (spibrr & 0x7F) as u32;
    if brr < 3 {
        4
    } else {
        brr + 1
    }
}

/// The character shape SPICCR (SPICHAR, CLKPOLARITY), SPICTL (CLK_PHASE) and SPIBRR select.
fn shape_of(spiccr: u16, spictl: u16, spibrr: u16) -> CharShape {
    let scheme = ClockScheme { polarity: spiccr & SPICCR_CLKPOLARITY != 0, phase: spictl & SPICTL_CLK_PHASE != 0 };
    CharShape { bits: (spiccr & 0xF) as u8 + 1, divisor: baud_divisor(spibrr), scheme }
}

/// The shape of one character on SPICLK, in LSPCLK cycles from its start.
///
/// Each SPI clock cycle has an *active* phase (SPICLK away from its idle level) of ⌊d/2⌋ cycles and
/// an *idle-level* phase of ⌈d/2⌉ cycles (d = divisor): with an odd SPIBRR+1 the idle-level phase is
/// the longer one. Edge `2k` is the leading edge of bit `k` (idle → active), edge `2k+1` its trailing
/// edge. Without delay (CLK_PHASE = 0) a bit cycle starts with its leading edge; with delay it starts
/// with the idle-level phase, so every edge is half a cycle later and the last trailing edge is the
/// character's end.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CharShape {
    /// Bits per character (SPICHAR+1).
    pub bits: u8,
    /// LSPCLK cycles per SPI clock.
    pub divisor: u32,
    /// Clock scheme.
    pub scheme: ClockScheme,
}

impl CharShape {
    /// LSPCLK cycles SPICLK spends away from its idle level in one bit.
    pub fn active_cycles(&self) -> u32 {
        self.divisor / 2
    }

    /// LSPCLK cycles SPICLK spends at its idle level in one bit.
    pub fn idle_cycles(&self) -> u32 {
        self.divisor - self.divisor / 2
    }

    /// Offset of edge `e` (0 ≤ e < 2·bits) from the character start, in LSPCLK cycles.
    pub fn edge_cycle(&self, e: u32) -> u64 {
        let k = (e / 2) as u64;
        let d = self.divisor as u64;
        let leading = e.is_multiple_of(2);
        match (self.scheme.phase, leading) {
            (false, true) => k * d,
            (false, false) => k * d + self.active_cycles() as u64,
            (true, true) => k * d + self.idle_cycles() as u64,
            (true, false) => (k + 1) * d,
        }
    }

    /// Number of SPICLK edges in the character.
    pub fn edges(&self) -> u32 {
        2 * self.bits as u32
    }

    /// LSPCLK cycles from the start of the character to its end.
    pub fn length_cycles(&self) -> u64 {
        self.bits as u64 * self.divisor as u64
    }
}

/// One character as the master puts it on the wires.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Frame {
    /// Index of the character since power-on (0-based).
    pub index: u64,
    /// LSPCLK cycle (since power-on) at which the character starts.
    pub start_cycle: u64,
    /// Start time (= LSPCLK `cycles_to_ps(start_cycle)`; the clock is not copied into every frame:
    /// it is fixed per link, see [`SpiA::lspclk`]).
    pub start_ps: Ps,
    /// End time: INT_FLAG sets and SPIRXBUF loads.
    pub end_ps: Ps,
    /// SPIDAT at the start: the character left-justified, shifted out from bit 15.
    pub tx: u16,
    /// Clock shape.
    pub shape: CharShape,
    /// SPICTL.TALK: the master drives SPISIMO.
    pub talk: bool,
    /// SPICCR.SPILBK: SPISIMO is looped back to the receiver inside the chip.
    pub loopback: bool,
}

impl Frame {
    /// Time of SPICLK edge `e` (`lspclk`: the clock the character is timed by).
    pub fn edge_ps(&self, lspclk: &Clock, e: u32) -> Ps {
        lspclk.cycles_to_ps(self.start_cycle + self.shape.edge_cycle(e))
    }

    /// Transmitted bit `k` (0 = first, from bit 15 of SPIDAT).
    pub fn tx_bit(&self, k: u32) -> bool {
        (self.tx >> (15 - k)) & 1 == 1
    }

    /// Mask of the received bits (right-justified).
    pub fn rx_mask(&self) -> u16 {
        (((1u32 << self.shape.bits) - 1) & 0xFFFF) as u16
    }
}

/// SPIDAT at the end of `frame`, which shifted in `rx`: the character shifted out at the top (none
/// left of a 16-bit character), the received bits at the bottom.
#[inline]
fn spidat_after(frame: &Frame, rx: u16) -> u16 {
    let shifted = if frame.shape.bits >= 16 { 0 } else { frame.tx << frame.shape.bits };
    shifted | rx
}

/// When a status flag sets, as SPI-A knows it: the time, and the LSPCLK cycle when the flag sets on
/// a known cycle boundary (a character's end). With the cycle, a poller on a clock of whole multiples
/// of LSPCLK (SYSCLKOUT) finds its own cycle by a multiplication instead of a division.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FlagTime {
    /// When the flag sets.
    pub ps: Ps,
    /// The LSPCLK cycle at which it sets, when known (`ps` is its floored time).
    pub lspclk_cycle: Option<u64>,
}

impl FlagTime {
    /// A flag time known in picoseconds only.
    pub fn at(ps: Ps) -> FlagTime {
        FlagTime { ps, lspclk_cycle: None }
    }
}

/// The CPU side of a polled word loop, in SYSCLKOUT cycles (see [`SpiA::polled_burst`]).
#[derive(Debug, Clone, Copy)]
pub struct PolledLoop {
    /// SYSCLKOUT, the CPU clock.
    pub sysclk: Clock,
    /// SYSCLKOUT cycles per LSPCLK cycle.
    pub sysclk_per_lspclk: Divisor,
    /// From the end of the previous word (or the start) to the SPITXBUF write: one BUFFULL poll and
    /// the write.
    pub before_write: u64,
    /// From the end of the SPIRXBUF read to the end of the word: storing it, the loop.
    pub after_read: u64,
}

/// Phases of a polled loop's write remembered (k ≤ 14 on the F28335: 2·LOSPCP); a higher phase is
/// worked out each time.
const POLL_PHASES: usize = 16;

/// What one word of a polled loop does from a write at some phase of LSPCLK: the LSPCLK cycles from
/// the write's cycle to its character's start, the SYSCLKOUT cycles to the end of its read, and the
/// next write's position relative to this one (whole LSPCLK cycles, new phase).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct PollStep {
    start_after: u64,
    to_read: u64,
    lspclk_cycles: u64,
    next_phase: u64,
}

/// The steps of [`SpiA::polled_run`] per write phase, kept from run to run by the caller for one
/// `read_after` function (the firmware's poll and read): they depend otherwise only on the loop's
/// costs, the clock ratio, the start latency and the character's length, and are worked out again
/// when any of these changes.
#[derive(Debug, Clone, Default)]
pub struct PollSteps {
    /// SYSCLKOUT per LSPCLK, start latency, character length (LSPCLK cycles), `before_write`, `after_read`.
    made_for: Option<[u64; 5]>,
    by_phase: [Option<PollStep>; POLL_PHASES],
    /// The latest run from each first-write phase: its words' steps composed, so that the next run
    /// from that phase takes its starts at once instead of stepping word by word.
    runs: [RunPlan; POLL_PHASES],
}

/// A run of a polled loop from a first write at some phase (see [`PollSteps`]): the LSPCLK cycle each
/// character starts on and the next write's position (whole LSPCLK cycles, phase), counted from the
/// first write's LSPCLK cycle q (q cancels, as in one word's step). No characters: none kept.
#[derive(Debug, Clone, Default)]
struct RunPlan {
    start_after: Vec<u64>,
    lspclk_cycles: u64,
    next_phase: u64,
    /// [`closest_spacing`] of the starts.
    closest_spacing: u64,
}

impl PollSteps {
    /// The tables, emptied if they were made for anything but `made_for`.
    #[inline]
    fn for_loop(&mut self, made_for: [u64; 5]) -> &mut PollSteps {
        if self.made_for != Some(made_for) {
            self.empty_for(made_for);
        }
        self
    }

    /// Empty the tables for `made_for` (out of line: rare, and it drops the kept runs).
    #[cold]
    #[inline(never)]
    fn empty_for(&mut self, made_for: [u64; 5]) {
        *self = PollSteps { made_for: Some(made_for), ..PollSteps::default() };
    }
}

/// What the SPI pins are connected to: told about each character's start and end, in time order.
pub trait SpiWire {
    /// The character starts (called once the peripheral has advanced to `frame.start_ps`).
    fn begin(&mut self, frame: &Frame);
    /// The character ends: return the bits the master sampled on SPISOMI, right-justified
    /// (`frame.shape.bits` of them).
    fn finish(&mut self, frame: &Frame) -> u16;
    /// The character starts and ends with nothing else happening on the pins in between (the polled
    /// path): the same as `begin` then `finish`, which a wire may do without keeping the frame.
    fn transfer(&mut self, frame: &Frame) -> u16 {
        self.begin(frame);
        self.finish(frame)
    }
    /// The characters of `run`, one after another with nothing else happening on the pins between
    /// them (a polled loop of one word): `rx[i]` gets what `transfer` of character `i` returns. A wire
    /// may do the run in fewer steps when it can tell the result is the same.
    fn transfer_run(&mut self, run: &FrameRun, rx: &mut [u16])
    where
        Self: Sized,
    {
        transfer_each(self, run, rx);
    }
}

/// [`SpiWire::transfer_run`] one character at a time (its default).
pub fn transfer_each<W: SpiWire>(wire: &mut W, run: &FrameRun, rx: &mut [u16]) {
    for (i, r) in rx.iter_mut().enumerate() {
        *r = wire.transfer(&run.frame(i));
    }
}

/// Characters of one word and shape clocked one after another: character `i` is [`FrameRun::frame`]
/// `(i)`, started on LSPCLK cycle `starts[i]`.
#[derive(Debug, Clone, Copy)]
pub struct FrameRun<'a> {
    /// The first character.
    pub first: Frame,
    /// The LSPCLK cycle each character starts on, in increasing order (the first is `first.start_cycle`).
    pub starts: &'a [u64],
    /// The clock the characters are timed by.
    pub lspclk: Clock,
    /// [`closest_spacing`] of `starts` (kept with the loop's plan: not worked out per run).
    pub closest_spacing: u64,
}

/// The fewest LSPCLK cycles between two consecutive `starts` (increasing); `u64::MAX` for fewer than two.
pub fn closest_spacing(starts: &[u64]) -> u64 {
    starts.windows(2).map(|w| w[1] - w[0]).min().unwrap_or(u64::MAX)
}

impl FrameRun<'_> {
    /// Character `i` of the run.
    #[inline]
    pub fn frame(&self, i: usize) -> Frame {
        let start_cycle = self.starts[i];
        Frame {
            index: self.first.index + i as u64,
            start_cycle,
            start_ps: self.lspclk.cycles_to_ps(start_cycle),
            end_ps: self.lspclk.cycles_to_ps(start_cycle + self.first.shape.length_cycles()),
            ..self.first
        }
    }
}

/// A fixed-capacity FIFO of 16-bit words (no allocation).
#[derive(Debug, Clone, Copy, Default)]
struct Fifo {
    words: [u16; FIFO_DEPTH],
    head: usize,
    len: usize,
}

impl Fifo {
    fn push(&mut self, w: u16) {
        self.words[(self.head + self.len) % FIFO_DEPTH] = w;
        self.len += 1;
    }
    fn push_front(&mut self, w: u16) {
        self.head = (self.head + FIFO_DEPTH - 1) % FIFO_DEPTH;
        self.words[self.head] = w;
        self.len += 1;
    }
    fn pop(&mut self) -> Option<u16> {
        if self.len == 0 {
            return None;
        }
        let w = self.words[self.head];
        self.head = (self.head + 1) % FIFO_DEPTH;
        self.len -= 1;
        Some(w)
    }
    fn peek(&self) -> Option<u16> {
        (self.len > 0).then(|| self.words[self.head])
    }
    fn clear(&mut self) {
        self.len = 0;
    }
}

#[derive(Debug, Clone, Copy)]
struct Active {
    frame: Frame,
    begun: bool,
}

/// The SPI-A peripheral.
#[derive(Debug, Clone)]
pub struct SpiA {
    lspclk: Clock,
    start_latency_lspclk: u64,
    spiccr: u16,
    spictl: u16,
    spibrr: u16,
    /// The character shape SPICCR, SPICTL and SPIBRR select, kept up to date by their writes (every
    /// character needs it; the registers change only at initialisation).
    shape: CharShape,
    spipri: u16,
    spifftx: u16,
    spiffrx: u16,
    spiffct: u16,
    txbuf: u16,
    rxbuf: u16,
    spidat: u16,
    int_flag: bool,
    int_flag_at: Ps,
    overrun: bool,
    /// Words written but not yet copied to SPIDAT (TXBUF in normal mode: at most one).
    tx_queue: Fifo,
    rx_fifo: Fifo,
    rxffovf: bool,
    txffint: bool,
    rxffint: bool,
    /// Times the receive (INT_FLAG, OVERRUN_FLAG, RXFFINT) and transmit (TXFFINT) flags went from
    /// clear to set: the PIE latches a line's rising edge ([`SpiA::interrupt_lines`]).
    raises: [u64; 2],
    active: Option<Active>,
    now: Ps,
    frames: u64,
    warned_not_master: bool,
    events: EventLog,
}

impl SpiA {
    /// SPI-A after a system reset, clocked by `lspclk`; `start_latency_lspclk` is the
    /// [unconfirmed] delay from a SPITXBUF write (shifter idle) to the character start.
    pub fn new(lspclk: Clock, start_latency_lspclk: u32) -> SpiA {
        SpiA {
            lspclk,
            start_latency_lspclk: start_latency_lspclk as u64,
            spiccr: 0,
            spictl: 0,
            spibrr: 0,
            shape: shape_of(0, 0, 0),
            spipri: 0,
            spifftx: 0xA000,
            spiffrx: 0x201F,
            spiffct: 0,
            txbuf: 0,
            rxbuf: 0,
            spidat: 0,
            int_flag: false,
            int_flag_at: 0,
            overrun: false,
            tx_queue: Fifo::default(),
            rx_fifo: Fifo::default(),
            rxffovf: false,
            txffint: false,
            rxffint: false,
            raises: [0; 2],
            active: None,
            now: 0,
            frames: 0,
            warned_not_master: false,
            events: EventLog::default(),
        }
    }

    /// The register writes of the published InitSpi, in order, for the profile's final values:
    /// SPICCR with SPISWRESET = 0, SPICTL, SPIBRR, the FIFO registers when SPIFFTX enables the FIFO,
    /// SPICCR (released), SPIPRI.
    pub fn init_writes(spi: &profile::Spi) -> Vec<(u16, u16)> {
        let ccr = (spi.spiccr & 0xFF) as u16;
        let mut writes = vec![
            (SPICCR, ccr & !SPICCR_SPISWRESET),
            (SPICTL, (spi.spictl & 0x1F) as u16),
            (SPIBRR, (spi.spibrr & 0x7F) as u16),
        ];
        if spi.spifftx as u16 & SPIFFTX_SPIFFENA != 0 {
            writes.push((SPIFFTX, spi.spifftx as u16));
            writes.push((SPIFFRX, spi.spiffrx as u16));
            writes.push((SPIFFCT, (spi.spiffct & 0xFF) as u16));
        }
        writes.push((SPICCR, ccr));
        writes.push((SPIPRI, (spi.spipri & 0xFF) as u16));
        writes
    }

    /// Perform [`SpiA::init_writes`] at time `t`.
    pub fn init_from_profile<W: SpiWire>(&mut self, spi: &profile::Spi, t: Ps, wire: &mut W) -> Result<()> {
        for (offset, value) in SpiA::init_writes(spi) {
            self.write(offset, value, t, wire)?;
        }
        Ok(())
    }

    /// The LSPCLK this peripheral runs on.
    pub fn lspclk(&self) -> Clock {
        self.lspclk
    }

    /// A new LSPCLK (the firmware wrote LOSPCP) from time `t` on. Refused while a character is
    /// scheduled, shifting or waiting in TXBUF/the FIFO: how the divider's change would stretch a
    /// character in progress is not modelled. The new clock's edges fall on its own multiples of the
    /// period from t = 0 (the divider's phase at the change is [unconfirmed]).
    pub fn set_lspclk(&mut self, lspclk: Clock, t: Ps) -> Result<()> {
        self.check_time(t)?;
        if self.active.is_some() || self.tx_queue.len != 0 {
            return Err(Error::Register(format!(
                "LOSPCP written at {t} ps while SPI-A has a character scheduled or shifting: changing LSPCLK \
                 under a character is not modelled; write LOSPCP while SPI-A is idle"
            )));
        }
        self.now = t;
        self.lspclk = lspclk;
        Ok(())
    }

    /// Events recorded so far (overruns, lost writes, writes to read-only registers).
    pub fn events(&self) -> &EventLog {
        &self.events
    }

    /// Take the recorded events out.
    pub fn drain_events(&mut self) -> Vec<Event> {
        self.events.drain()
    }

    /// Characters started since power-on.
    pub fn frames_started(&self) -> u64 {
        self.frames
    }

    /// The clock scheme SPICCR/SPICTL select now.
    pub fn scheme(&self) -> ClockScheme {
        self.shape.scheme
    }

    /// The character shape the registers select now.
    pub fn shape(&self) -> CharShape {
        self.shape
    }

    fn fifo_mode(&self) -> bool {
        self.spifftx & SPIFFTX_SPIFFENA != 0
    }

    fn tx_capacity(&self) -> usize {
        if self.fifo_mode() {
            FIFO_DEPTH
        } else {
            1
        }
    }

    /// Whether a queued word may start a character: out of reset, master, transmit FIFO enabled.
    fn can_run(&self) -> bool {
        let fifo_ok = !self.fifo_mode() || (self.spifftx & SPIFFTX_SPIRST != 0 && self.spifftx & SPIFFTX_TXFIFO != 0);
        self.spiccr & SPICCR_SPISWRESET != 0 && self.spictl & SPICTL_MASTER != 0 && fifo_ok
    }

    fn check_time(&self, t: Ps) -> Result<()> {
        if t < self.now {
            return Err(self.time_reversal(t));
        }
        Ok(())
    }

    #[cold]
    #[inline(never)]
    fn time_reversal(&self, t: Ps) -> Error {
        Error::Register(format!(
            "SPI-A access at t = {t} ps precedes the previous access at {} ps: virtual time must not go backwards",
            self.now
        ))
    }

    /// Process every character start and end up to and including `t`, in time order. Forced inline:
    /// the idle case is a few instructions (left to itself the compiler kept a call, measured).
    #[inline(always)]
    pub fn advance<W: SpiWire>(&mut self, t: Ps, wire: &mut W) -> Result<()> {
        // Idle in normal mode (as at every CS edge of a burst): no character to walk, no FIFO flag
        // to update, only the time moves.
        if self.active.is_none() && !self.fifo_mode() {
            self.check_time(t)?;
            self.now = t;
            return Ok(());
        }
        self.advance_characters(t, wire)
    }

    /// [`SpiA::advance`] with a character in flight or the FIFOs on.
    fn advance_characters<W: SpiWire>(&mut self, t: Ps, wire: &mut W) -> Result<()> {
        self.check_time(t)?;
        self.now = t;
        while let Some(a) = self.active.as_mut() {
            if !a.begun {
                if a.frame.start_ps > t {
                    break;
                }
                a.begun = true;
                wire.begin(&a.frame);
                continue;
            }
            if a.frame.end_ps > t {
                break;
            }
            let frame = a.frame;
            self.active = None;
            let rx = wire.finish(&frame) & frame.rx_mask();
            self.complete(&frame, rx);
            let gap = if self.fifo_mode() { (self.spiffct & 0xFF) as u64 * frame.shape.divisor as u64 } else { 0 };
            self.schedule_from_queue(frame.start_cycle + frame.shape.length_cycles() + gap);
        }
        self.update_fifo_flags();
        Ok(())
    }

    /// A character ended: load the receiver.
    #[inline]
    fn complete(&mut self, frame: &Frame, rx: u16) {
        self.spidat = spidat_after(frame, rx);
        if self.fifo_mode() {
            if self.rx_fifo.len == FIFO_DEPTH {
                self.rxffovf = true;
                self.word_lost(frame, "spi_rx_fifo_overflow");
            } else {
                self.rx_fifo.push(self.spidat);
            }
            return;
        }
        if self.int_flag {
            self.overrun = true;
            self.word_lost(frame, "spi_rx_overrun");
        }
        self.rxbuf = self.spidat;
        if !self.int_flag {
            self.raises[0] += 1;
        }
        self.int_flag = true;
        self.int_flag_at = frame.end_ps;
    }

    /// A received word is lost at the end of `frame` (`kind`: receive FIFO full, or SPIRXBUF not read).
    #[cold]
    #[inline(never)]
    fn word_lost(&mut self, frame: &Frame, kind: &'static str) {
        let message = if kind == "spi_rx_overrun" {
            format!(
                "SPI-A character {} ended before SPIRXBUF was read: word 0x{:04X} lost, OVERRUN_FLAG set",
                frame.index, self.rxbuf
            )
        } else {
            format!("SPI-A receive FIFO full at the end of character {}: word 0x{:04X} lost", frame.index, self.spidat)
        };
        self.events.push(Event::new(frame.end_ps, kind, Severity::Warning, message).in_frame(frame.index));
    }

    /// Start the next queued word at LSPCLK cycle `cycle`, if the peripheral may run.
    fn schedule_from_queue(&mut self, cycle: u64) {
        if self.active.is_some() || !self.can_run() {
            return;
        }
        if let Some(w) = self.tx_queue.pop() {
            self.schedule(w, cycle);
        }
    }

    fn schedule(&mut self, tx: u16, start_cycle: u64) {
        let frame = self.next_frame(tx, start_cycle);
        self.active = Some(Active { frame, begun: false });
    }

    /// The character `tx` starting at LSPCLK cycle `start_cycle`, counted and loaded into SPIDAT
    /// (what scheduling it does, without storing it: the polled frame keeps it local).
    #[inline]
    fn next_frame(&mut self, tx: u16, start_cycle: u64) -> Frame {
        let shape = self.shape();
        let frame = Frame {
            index: self.frames,
            start_cycle,
            start_ps: self.lspclk.cycles_to_ps(start_cycle),
            end_ps: self.lspclk.cycles_to_ps(start_cycle + shape.length_cycles()),
            tx,
            shape,
            talk: self.spictl & SPICTL_TALK != 0,
            loopback: self.spiccr & SPICCR_SPILBK != 0,
        };
        self.frames += 1;
        self.spidat = tx;
        frame
    }

    /// Whether [`SpiA::polled_frame`] may run a SPITXBUF write at `t`: normal (non-FIFO) mode, out of
    /// reset as a master, shifter idle, nothing waiting and INT_FLAG clear, so the write starts a
    /// character at once, the poll waits for its end and nothing else can happen on the link until then.
    pub fn polled_frame_applies(&self, t: Ps) -> bool {
        t >= self.now
            && self.active.is_none()
            && self.tx_queue.len == 0
            && !self.int_flag
            && !self.fifo_mode()
            && self.can_run()
    }

    /// The published per-word polling sequence in one call: write `tx` to SPITXBUF at `t_write`, poll
    /// INT_FLAG, read SPIRXBUF at `read_at(INT_FLAG time)`; returns the word read. Only when
    /// [`SpiA::polled_frame_applies`] (the caller checks). It runs the same steps as the register
    /// path (`next_frame`, `wire.begin`/`finish`, `complete`) without keeping the character in
    /// `active` or walking `advance` twice; a read time before the flag (which a poll never gives)
    /// or an error of `read_at` leaves the character scheduled, exactly as the register path would.
    pub fn polled_frame<W: SpiWire>(
        &mut self,
        tx: u16,
        t_write: Ps,
        read_at: impl FnOnce(Option<FlagTime>) -> Result<Ps>,
        wire: &mut W,
    ) -> Result<u16> {
        debug_assert!(self.polled_frame_applies(t_write));
        self.now = t_write;
        self.txbuf = tx;
        let start_cycle = self.start_cycle_after(t_write);
        let frame = self.next_frame(tx, start_cycle);
        let end_cycle = start_cycle + frame.shape.length_cycles();
        let t_read = match read_at(Some(FlagTime { ps: frame.end_ps, lspclk_cycle: Some(end_cycle) })) {
            Ok(t) if t >= frame.end_ps => t,
            other => {
                self.active = Some(Active { frame, begun: false });
                return self.read(SPIRXBUF, other?, wire);
            }
        };
        self.now = t_read;
        Ok(self.exchange_and_read(&frame, wire))
    }

    /// A polled character from its start to the firmware's SPIRXBUF read: the wires carry it, the
    /// receiver loads, the read clears INT_FLAG. The shared tail of [`SpiA::polled_frame`] and
    /// [`SpiA::polled_burst`].
    #[inline(always)]
    fn exchange_and_read<W: SpiWire>(&mut self, frame: &Frame, wire: &mut W) -> u16 {
        let rx = wire.transfer(frame) & frame.rx_mask();
        self.complete(frame, rx);
        self.read_rxbuf()
    }

    /// The published polled word loop over `words`, in CPU cycles: for each word the CPU polls
    /// BUFFULL_FLAG once (clear: the previous read emptied the buffers), writes SPITXBUF, polls
    /// INT_FLAG and stores the word. `read_after(write, wait)` gives the SYSCLKOUT cycles from the
    /// write (on cycle `write`) to the end of the SPIRXBUF read when INT_FLAG sets `wait` cycles after
    /// the write; as for any polling loop it depends on `wait` alone (`write` only dates an error),
    /// which [`SpiA::polled_run`] relies on. `c` (SYSCLKOUT cycle) advances through the loop.
    ///
    /// The same steps as [`SpiA::polled_frame`] per word, in whole cycles instead of picoseconds:
    /// with SYSCLKOUT = k·LSPCLK (period ≥ 1 ps) the first LSPCLK boundary at or after SYSCLKOUT
    /// cycle c is ⌈c/k⌉, which is what converting through picoseconds gives (see
    /// [`Clock::cycles_per_cycle_of`]). Only when [`SpiA::polled_frame_applies`] at the first write
    /// (it keeps applying: each read clears INT_FLAG and nothing is queued); the emulator's fast-path
    /// equivalence test holds the two paths equal. `after_word(i, wire)` runs after word `i`.
    #[allow(clippy::too_many_arguments)]
    pub fn polled_burst<W: SpiWire, const N: usize>(
        &mut self,
        words: [u16; N],
        c: &mut u64,
        cpu: &PolledLoop,
        read_after: impl Fn(u64, u64) -> Result<u64>,
        wire: &mut W,
        mut after_word: impl FnMut(usize, &W),
    ) -> Result<[u16; N]> {
        let mut read = [0; N];
        let mut last_read = None;
        for (i, &tx) in words.iter().enumerate() {
            *c += cpu.before_write;
            let (start, wait) = self.polled_word(cpu.sysclk_per_lspclk.div_rem(*c), cpu);
            self.txbuf = tx;
            let frame = self.next_frame(tx, start);
            *c += match read_after(*c, wait) {
                Ok(r) => r,
                Err(e) => {
                    // As the register path leaves it: the character scheduled, never read.
                    self.now = cpu.sysclk.cycles_to_ps(*c);
                    self.active = Some(Active { frame, begun: false });
                    return Err(e);
                }
            };
            last_read = Some(*c);
            read[i] = self.exchange_and_read(&frame, wire);
            *c += cpu.after_read;
            after_word(i, wire);
        }
        // Only the last read's time is visible after the loop: nothing reads `now` in between.
        if let Some(r) = last_read {
            self.now = cpu.sysclk.cycles_to_ps(r);
        }
        Ok(read)
    }

    /// [`SpiA::polled_burst`] of `N` copies of the word `tx`, the characters handed to the wire as one
    /// run ([`SpiWire::transfer_run`]). The CPU's side of the loop does not depend on the words, so it
    /// is worked out first, in whole cycles as in [`SpiA::polled_burst`]; then the wire clocks the
    /// characters. Each read empties SPIRXBUF before the next character ends, so of the registers only
    /// what the last character leaves is visible afterwards. Only when [`SpiA::polled_frame_applies`]
    /// at the first write; the emulator's fast-path equivalence test holds it equal to the register path.
    ///
    /// The CPU's side of a word depends only on the phase of its write within an LSPCLK cycle: with
    /// the write on SYSCLKOUT cycle q·k + φ (0 ≤ φ < k) the character starts on LSPCLK cycle
    /// q + [φ > 0] + latency, INT_FLAG sets ([φ > 0] + latency + length)·k − φ cycles after the write
    /// (q cancels), so the poll's length, the next write's distance and the next phase are functions
    /// of φ. Each is worked out once per phase (at most k of them) and kept in `steps` for the next
    /// runs with the same `read_after` (see [`PollSteps`]); so is a whole run of `N` words from the
    /// phase of its first write (its starts and end, counted from that write's LSPCLK cycle).
    #[allow(clippy::too_many_arguments)]
    pub fn polled_run<W: SpiWire, const N: usize>(
        &mut self,
        tx: u16,
        c: &mut u64,
        cpu: &PolledLoop,
        read_after: impl Fn(u64, u64) -> Result<u64>,
        steps: &mut PollSteps,
        wire: &mut W,
    ) -> Result<[u16; N]> {
        if N == 0 {
            return Ok([0; N]);
        }
        let k = cpu.sysclk_per_lspclk;
        let made_for =
            [k.get(), self.start_latency_lspclk, self.shape.length_cycles(), cpu.before_write, cpu.after_read];
        let steps = steps.for_loop(made_for);
        let mut starts = [0u64; N];
        let (q0, phase0) = k.div_rem(*c + cpu.before_write);
        let kept = steps.runs.get(phase0 as usize).filter(|run| run.start_after.len() == N);
        let (q, phase, closest) = if let Some(run) = kept {
            starts.iter_mut().zip(&run.start_after).for_each(|(start, after)| *start = q0 + after);
            (q0 + run.lspclk_cycles, run.next_phase, run.closest_spacing)
        } else {
            let (mut q, mut phase) = (q0, phase0);
            for start in &mut starts {
                let remembered = steps.by_phase.get(phase as usize).copied().flatten();
                let step = match remembered {
                    Some(step) => step,
                    None => {
                        let (start, wait) = self.polled_word((q, phase), cpu);
                        let Ok(to_read) = read_after(q * k.get() + phase, wait) else {
                            // A poll that fails: the word-by-word loop leaves the registers as the register
                            // path does, and returns the error (nothing has changed yet).
                            return self.polled_burst([tx; N], c, cpu, read_after, wire, |_, _| {});
                        };
                        let (lspclk_cycles, next_phase) =
                            k.div_rem(phase + to_read + cpu.after_read + cpu.before_write);
                        let step = PollStep { start_after: start - q, to_read, lspclk_cycles, next_phase };
                        if let Some(slot) = steps.by_phase.get_mut(phase as usize) {
                            *slot = Some(step);
                        }
                        step
                    }
                };
                *start = q + step.start_after;
                (q, phase) = (q + step.lspclk_cycles, step.next_phase);
            }
            let closest = closest_spacing(&starts);
            if let Some(run) = steps.runs.get_mut(phase0 as usize) {
                run.start_after.clear();
                run.start_after.extend(starts.iter().map(|start| start - q0));
                (run.lspclk_cycles, run.next_phase, run.closest_spacing) = (q - q0, phase, closest);
            }
            (q, phase, closest)
        };
        self.txbuf = tx;
        let first = self.next_frame(tx, starts[0]);
        self.frames += N as u64 - 1;
        let run = FrameRun { first, starts: &starts, lspclk: self.lspclk, closest_spacing: closest };
        let mut rx = [0u16; N];
        wire.transfer_run(&run, &mut rx);
        let mask = first.rx_mask();
        let read = rx.map(|r| spidat_after(&first, r & mask));
        self.complete(&run.frame(N - 1), rx[N - 1] & mask);
        self.read_rxbuf();
        // The loop has stepped on to the next write: the last read is its store and BUFFULL poll before.
        let last_read = q * k.get() + phase - cpu.before_write - cpu.after_read;
        self.now = cpu.sysclk.cycles_to_ps(last_read);
        *c = last_read + cpu.after_read;
        Ok(read)
    }

    /// One word of a polled loop written to SPITXBUF on SYSCLKOUT cycle q·k + φ, given as (q, φ)
    /// with 0 ≤ φ < k (shifter idle): the LSPCLK cycle its character starts on (the first boundary
    /// at or after the write, ⌈write/k⌉, plus the start latency) and the SYSCLKOUT cycles from the
    /// write to INT_FLAG (the character's end).
    #[inline(always)]
    fn polled_word(&self, (q, phase): (u64, u64), cpu: &PolledLoop) -> (u64, u64) {
        let k = cpu.sysclk_per_lspclk.get();
        let start = q + u64::from(phase != 0) + self.start_latency_lspclk;
        (start, (start + self.shape.length_cycles()) * k - (q * k + phase))
    }

    /// First LSPCLK cycle a character written at `t` (shifter idle) may start on.
    #[inline]
    fn start_cycle_after(&self, t: Ps) -> u64 {
        self.lspclk.ps_to_cycles_ceil(t) + self.start_latency_lspclk
    }

    fn update_fifo_flags(&mut self) {
        if !self.fifo_mode() {
            return;
        }
        if self.txffst() <= (self.spifftx & 0x1F) as usize && !self.txffint {
            self.txffint = true;
            self.raises[1] += 1;
        }
        if self.rx_fifo.len >= (self.spiffrx & 0x1F) as usize && !self.rxffint {
            self.rxffint = true;
            self.raises[0] += 1;
        }
    }

    /// Words written and not yet copied to SPIDAT.
    fn txffst(&self) -> usize {
        self.tx_queue.len
    }

    fn buffull(&self) -> bool {
        !self.fifo_mode() && self.txffst() > 0
    }

    fn read_only(&mut self, t: Ps, name: &str, value: u16) {
        self.events.push(Event::new(
            t,
            "spi_write_read_only",
            Severity::Info,
            format!("write of 0x{value:04X} to read-only {name} ignored"),
        ));
    }

    /// Read the register at word `offset` at time `t`.
    pub fn read<W: SpiWire>(&mut self, offset: u16, t: Ps, wire: &mut W) -> Result<u16> {
        self.advance(t, wire)?;
        let v = match offset {
            SPICCR => self.spiccr,
            SPICTL => self.spictl,
            SPISTS => self.spists(),
            SPIBRR => self.spibrr,
            SPIRXEMU => {
                if self.fifo_mode() {
                    self.rx_fifo.peek().unwrap_or(self.rxbuf)
                } else {
                    self.rxbuf
                }
            }
            SPIRXBUF => self.read_rxbuf(),
            SPITXBUF => self.txbuf,
            SPIDAT => self.spidat,
            SPIFFTX => (self.spifftx & 0xE03F) | ((self.txffst() as u16) << 8) | (u16::from(self.txffint) << 7),
            SPIFFRX => {
                (self.spiffrx & 0x203F)
                    | (u16::from(self.rxffovf) << 15)
                    | ((self.rx_fifo.len as u16) << 8)
                    | (u16::from(self.rxffint) << 7)
            }
            SPIFFCT => self.spiffct,
            SPIPRI => self.spipri,
            _ => return Err(no_register(offset)),
        };
        Ok(v)
    }

    /// A read of SPIRXBUF: the next word of the receive FIFO, or the buffer (clearing INT_FLAG).
    #[inline]
    fn read_rxbuf(&mut self) -> u16 {
        if self.fifo_mode() {
            if let Some(w) = self.rx_fifo.pop() {
                self.rxbuf = w;
            }
        } else {
            self.int_flag = false;
        }
        self.rxbuf
    }

    fn spists(&self) -> u16 {
        if self.fifo_mode() {
            return 0;
        }
        (u16::from(self.overrun) << 7) | (u16::from(self.int_flag) << 6) | (u16::from(self.buffull()) << 5)
    }

    /// Write `value` to the register at word `offset` at time `t`.
    pub fn write<W: SpiWire>(&mut self, offset: u16, value: u16, t: Ps, wire: &mut W) -> Result<()> {
        self.advance(t, wire)?;
        match offset {
            SPICCR => {
                let was_running = self.spiccr & SPICCR_SPISWRESET != 0;
                self.spiccr = value & 0xDF;
                let running = self.spiccr & SPICCR_SPISWRESET != 0;
                if was_running && !running {
                    self.enter_reset(t, wire);
                } else if !was_running && running {
                    self.schedule_from_queue(self.start_cycle_after(t));
                }
            }
            SPICTL => self.spictl = value & 0x1F,
            SPISTS => {
                if value & SPISTS_OVERRUN != 0 {
                    self.overrun = false;
                }
            }
            SPIBRR => self.spibrr = value & 0x7F,
            SPIRXEMU => self.read_only(t, "SPIRXEMU", value),
            SPIRXBUF => self.read_only(t, "SPIRXBUF", value),
            SPITXBUF => self.write_txbuf(value, t),
            SPIDAT => self.write_spidat(value, t),
            SPIFFTX => {
                self.spifftx = value & 0xE03F;
                if value & 0x40 != 0 {
                    self.txffint = false;
                }
                if value & SPIFFTX_SPIRST == 0 || value & SPIFFTX_TXFIFO == 0 {
                    self.tx_queue.clear();
                }
                if value & SPIFFTX_SPIRST == 0 {
                    self.rx_fifo.clear();
                }
                self.schedule_from_queue(self.start_cycle_after(t));
            }
            SPIFFRX => {
                self.spiffrx = value & 0x203F;
                if value & (1 << 14) != 0 {
                    self.rxffovf = false;
                }
                if value & 0x40 != 0 {
                    self.rxffint = false;
                }
                if value & SPIFFRX_RXFIFORESET == 0 {
                    self.rx_fifo.clear();
                }
            }
            SPIFFCT => self.spiffct = value & 0xFF,
            SPIPRI => self.spipri = value & 0x30,
            _ => return Err(no_register(offset)),
        }
        if matches!(offset, SPICCR | SPICTL | SPIBRR) {
            self.shape = shape_of(self.spiccr, self.spictl, self.spibrr);
        }
        self.update_fifo_flags();
        Ok(())
    }

    fn write_txbuf(&mut self, value: u16, t: Ps) {
        self.txbuf = value;
        let fifo = self.fifo_mode();
        if self.spiccr & SPICCR_SPISWRESET == 0 && !fifo {
            // Held in reset: the buffer latches the value, nothing is queued (BUFFULL stays 0).
            return;
        }
        if self.spictl & SPICTL_MASTER == 0 && !self.warned_not_master {
            self.warned_not_master = true;
            self.events.push(Event::new(
                t,
                "spi_not_master",
                Severity::Warning,
                "SPITXBUF written with SPICTL.MASTER_SLAVE = 0: no SPI clock is generated, the word waits",
            ));
        }
        if self.tx_queue.len >= self.tx_capacity() {
            self.txbuf_overflow(value, t);
            return;
        }
        if self.tx_queue.len == 0 && self.active.is_none() && self.can_run() {
            // Idle with nothing waiting: the word goes straight to SPIDAT (what queueing it and taking
            // it out again would do).
            self.schedule(value, self.start_cycle_after(t));
            return;
        }
        self.tx_queue.push(value);
        self.schedule_from_queue(self.start_cycle_after(t));
    }

    /// A SPITXBUF write finds no room: the transmit FIFO drops it, the single buffer replaces its word.
    #[cold]
    #[inline(never)]
    fn txbuf_overflow(&mut self, value: u16, t: Ps) {
        let fifo = self.fifo_mode();
        let (kind, what) = if fifo {
            ("spi_tx_fifo_overflow", "transmit FIFO full")
        } else {
            ("spi_txbuf_overwrite", "SPITXBUF written while BUFFULL_FLAG = 1")
        };
        self.events.push(Event::new(
            t,
            kind,
            Severity::Warning,
            format!("{what}: word 0x{value:04X} replaces a waiting word"),
        ));
        if !fifo {
            self.tx_queue.clear();
            self.tx_queue.push(value);
        }
    }

    fn write_spidat(&mut self, value: u16, t: Ps) {
        if self.active.is_some() {
            self.events.push(Event::new(
                t,
                "spi_spidat_write_during_transfer",
                Severity::Warning,
                format!("SPIDAT written with 0x{value:04X} while a character is scheduled or shifting: ignored"),
            ));
            return;
        }
        self.spidat = value;
        if self.can_run() {
            let cycle = self.start_cycle_after(t);
            self.schedule(value, cycle);
        }
    }

    fn enter_reset<W: SpiWire>(&mut self, t: Ps, wire: &mut W) {
        if let Some(a) = self.active.take() {
            if a.begun {
                // The slave already saw the start: close its frame; the master discards the word.
                let _ = wire.finish(&a.frame);
                self.events.push(
                    Event::new(
                        t,
                        "spi_reset_during_transfer",
                        Severity::Warning,
                        format!("SPISWRESET cleared while character {} was shifting: it is abandoned", a.frame.index),
                    )
                    .in_frame(a.frame.index),
                );
            } else if self.fifo_mode() && self.tx_queue.len < FIFO_DEPTH {
                // Not started yet: the word is still the transmit FIFO's first.
                self.tx_queue.push_front(a.frame.tx);
            } else if self.fifo_mode() {
                // The FIFO has refilled to its 16 words behind it, so this word was already in SPIDAT:
                // the reset loses it (and the FIFO never holds more than 16).
                self.events.push(
                    Event::new(
                        t,
                        "spi_reset_word_lost",
                        Severity::Warning,
                        format!(
                            "SPISWRESET cleared before character {} started, with the transmit FIFO full behind it: \
                         word 0x{:04X} in SPIDAT is lost",
                            a.frame.index, a.frame.tx
                        ),
                    )
                    .in_frame(a.frame.index),
                );
            }
        }
        if !self.fifo_mode() {
            self.tx_queue.clear();
        }
        self.int_flag = false;
        self.overrun = false;
    }

    /// When INT_FLAG is (or will be) set, if nothing else is written: `Some(t)` with `t` ≤ now when it
    /// is already set (the time it set), the end of the running or scheduled character otherwise;
    /// `None` when no character is coming (or in FIFO mode, where INT_FLAG is not used).
    pub fn int_flag_time(&self) -> Option<Ps> {
        if self.fifo_mode() {
            return None;
        }
        if self.int_flag {
            return Some(self.int_flag_at);
        }
        self.active.map(|a| a.frame.end_ps)
    }

    /// When BUFFULL_FLAG reads 0, if nothing else is written: `Some(now)` when it already does, the
    /// time the waiting word is copied to SPIDAT otherwise; `None` when it never clears (no clock).
    pub fn buffull_clear_time(&self) -> Option<Ps> {
        if !self.buffull() {
            return Some(self.now);
        }
        self.active.map(|a| a.frame.end_ps)
    }

    /// SPI-A's two interrupt lines (SPRUEU3, "SPI Interrupts" and "FIFO Interrupts"): SPIRXINTA
    /// (PIE INT6.1) and SPITXINTA (INT6.2), each as (its level now, how many times its flag has
    /// been raised since reset, whether its interrupt is enabled in SPI-A). In FIFO mode (SPIFFENA)
    /// RXFFINT with RXFFIENA drives SPIRXINTA and TXFFINT with TXFFIENA drives SPITXINTA; in
    /// normal mode INT_FLAG with SPIINTENA (SPICTL bit 0), or OVERRUN_FLAG with OVERRUNINTENA
    /// (bit 4), drives SPIRXINTA, and SPITXINTA stays low.
    pub fn interrupt_lines(&self) -> [(bool, u64, bool); 2] {
        if self.fifo_mode() {
            let rx_en = self.spiffrx & 0x20 != 0;
            let tx_en = self.spifftx & 0x20 != 0;
            [(self.rxffint && rx_en, self.raises[0], rx_en), (self.txffint && tx_en, self.raises[1], tx_en)]
        } else {
            let int_en = self.spictl & 1 != 0;
            let ovr_en = self.spictl & 0x10 != 0;
            let level = (self.int_flag && int_en) || (self.overrun && ovr_en);
            [(level, self.raises[0], int_en || ovr_en), (false, self.raises[1], false)]
        }
    }

    /// The character scheduled or shifting, if any.
    pub fn current_frame(&self) -> Option<&Frame> {
        self.active.as_ref().map(|a| &a.frame)
    }
}

fn no_register(offset: u16) -> Error {
    Error::Register(format!(
        "SPI-A word offset 0x{offset:X}: no register there (registers: SPICCR 0, SPICTL 1, SPISTS 2, SPIBRR 4, \
         SPIRXEMU 6, SPIRXBUF 7, SPITXBUF 8, SPIDAT 9, SPIFFTX 0xA, SPIFFRX 0xB, SPIFFCT 0xC, SPIPRI 0xF)"
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::time::PS_PER_S;

    /// A wire whose far end answers a fixed word and records what it was told.
    #[derive(Default)]
    struct Probe {
        answer: u16,
        begun: Vec<Frame>,
        finished: Vec<Frame>,
    }

    impl SpiWire for Probe {
        fn begin(&mut self, frame: &Frame) {
            self.begun.push(*frame);
        }
        fn finish(&mut self, frame: &Frame) -> u16 {
            self.finished.push(*frame);
            self.answer >> (16 - frame.shape.bits as u32)
        }
        fn transfer_run(&mut self, run: &FrameRun, rx: &mut [u16]) {
            assert_eq!(run.closest_spacing, closest_spacing(run.starts), "the plan's closest spacing is the run's");
            transfer_each(self, run, rx);
        }
    }

    fn lspclk() -> Clock {
        Clock::new(75_000_000, 2)
    }

    fn reference() -> (SpiA, Probe) {
        let mut spi = SpiA::new(lspclk(), 1);
        let mut probe = Probe { answer: 0xC7A7, ..Default::default() };
        spi.init_from_profile(&profile::Spi::default(), 0, &mut probe).unwrap();
        (spi, probe)
    }

    #[test]
    fn reset_values() {
        let mut spi = SpiA::new(lspclk(), 1);
        let mut p = Probe::default();
        let expect = [
            (SPICCR, 0),
            (SPICTL, 0),
            (SPISTS, 0),
            (SPIBRR, 0),
            (SPIRXEMU, 0),
            (SPIRXBUF, 0),
            (SPITXBUF, 0),
            (SPIDAT, 0),
            (SPIFFTX, 0xA000),
            (SPIFFRX, 0x201F),
            (SPIFFCT, 0),
            (SPIPRI, 0),
        ];
        for (off, v) in expect {
            assert_eq!(spi.read(off, 0, &mut p).unwrap(), v, "offset {off:#X}");
        }
        for off in [3u16, 5, 0xD, 0xE, 0x10] {
            let e = spi.read(off, 0, &mut p).unwrap_err();
            assert!(matches!(e, Error::Register(ref m) if m.contains(&format!("0x{off:X}"))), "{e}");
        }
    }

    #[test]
    fn published_init_sequence_in_order() {
        let w = SpiA::init_writes(&profile::Spi::default());
        assert_eq!(w, vec![(SPICCR, 0x004F), (SPICTL, 0x0007), (SPIBRR, 49), (SPICCR, 0x00CF), (SPIPRI, 0x0020)]);
        let (mut spi, mut p) = reference();
        assert_eq!(spi.read(SPICCR, 0, &mut p).unwrap(), 0xCF);
        assert_eq!(spi.read(SPICTL, 0, &mut p).unwrap(), 0x07);
        assert_eq!(spi.read(SPIBRR, 0, &mut p).unwrap(), 49);
        assert_eq!(spi.read(SPIPRI, 0, &mut p).unwrap(), 0x20);
        // With the FIFO enabled its registers are written before the release from reset.
        let fifo = profile::Spi { spifftx: 0xE040, spiffrx: 0x2044, spiffct: 3, ..Default::default() };
        let w = SpiA::init_writes(&fifo);
        assert_eq!(w[3..6], [(SPIFFTX, 0xE040), (SPIFFRX, 0x2044), (SPIFFCT, 3)]);
        assert_eq!(w[6], (SPICCR, 0xCF));
    }

    #[test]
    fn baud_divisor_and_modes() {
        assert_eq!([0, 1, 2, 3, 49, 127].map(baud_divisor), [4, 4, 4, 4, 50, 128]);
        let modes = [(true, false, 3), (true, true, 2), (false, false, 1), (false, true, 0)];
        for (polarity, phase, mode) in modes {
            assert_eq!(ClockScheme { polarity, phase }.standard_mode(), mode);
        }
    }

    #[test]
    fn odd_divisor_makes_the_idle_level_phase_longer() {
        let s = |phase| CharShape { bits: 2, divisor: 5, scheme: ClockScheme { polarity: true, phase } };
        let edges = |sh: CharShape| (0..sh.edges()).map(|e| sh.edge_cycle(e)).collect::<Vec<_>>();
        // Without delay: active (low) 2 cycles, idle level (high) 3 cycles.
        assert_eq!(edges(s(false)), vec![0, 2, 5, 7]);
        // With delay: the idle-level phase first.
        assert_eq!(edges(s(true)), vec![3, 5, 8, 10]);
        assert_eq!(s(true).length_cycles(), 10);
    }

    #[test]
    fn one_character_in_virtual_time() {
        let (mut spi, mut p) = reference();
        let lsp = lspclk();
        let t0 = 1_000_000; // 1 µs: not on an LSPCLK edge (26 666.67 ps period)
        spi.write(SPITXBUF, 0x4200, t0, &mut p).unwrap();
        let start_cycle = lsp.ps_to_cycles_ceil(t0) + 1;
        let start = lsp.cycles_to_ps(start_cycle);
        let end = lsp.cycles_to_ps(start_cycle + 800);
        // From idle the word goes straight to SPIDAT: BUFFULL never sets.
        assert_eq!(spi.buffull_clear_time(), Some(t0));
        assert_eq!(spi.int_flag_time(), Some(end));
        assert_eq!(spi.read(SPISTS, start - 1, &mut p).unwrap(), 0);
        assert!(p.begun.is_empty());
        assert_eq!(spi.read(SPISTS, start, &mut p).unwrap(), 0);
        assert_eq!(p.begun.len(), 1);
        assert_eq!(p.begun[0].tx, 0x4200);
        assert_eq!(spi.read(SPISTS, end - 1, &mut p).unwrap(), 0);
        assert_eq!(spi.read(SPISTS, end, &mut p).unwrap(), SPISTS_INT_FLAG);
        // 16 bits at 750 kHz: 21.333 µs.
        assert_eq!(end - start, 21_333_333);
        // SPIRXEMU does not clear INT_FLAG; SPIRXBUF does.
        assert_eq!(spi.read(SPIRXEMU, end, &mut p).unwrap(), 0xC7A7);
        assert_eq!(spi.read(SPISTS, end, &mut p).unwrap(), SPISTS_INT_FLAG);
        assert_eq!(spi.int_flag_time(), Some(end));
        assert_eq!(spi.read(SPIRXBUF, end + 5, &mut p).unwrap(), 0xC7A7);
        assert_eq!(spi.read(SPISTS, end + 5, &mut p).unwrap(), 0);
        assert_eq!(spi.int_flag_time(), None);
        // Time must not run backwards.
        let e = spi.read(SPISTS, end, &mut p).unwrap_err();
        assert!(matches!(e, Error::Register(_)), "{e}");
    }

    #[test]
    fn double_buffering_overrun_and_clear() {
        let (mut spi, mut p) = reference();
        spi.write(SPITXBUF, 0x1111, 0, &mut p).unwrap();
        spi.write(SPITXBUF, 0x2222, 100, &mut p).unwrap();
        let first_end = spi.int_flag_time().unwrap();
        // BUFFULL stays set until the first character ends and the second is copied to SPIDAT.
        assert_eq!(spi.buffull_clear_time(), Some(first_end));
        assert_eq!(spi.read(SPISTS, first_end - 1, &mut p).unwrap(), SPISTS_BUFFULL);
        assert_eq!(spi.read(SPISTS, first_end, &mut p).unwrap(), SPISTS_INT_FLAG);
        // Back to back: the second starts exactly at the first's end.
        assert_eq!(p.begun[1].start_ps, first_end);
        assert_eq!(p.begun[1].start_cycle, p.begun[0].start_cycle + 800);
        // Not reading SPIRXBUF before the second ends: overrun.
        let second_end = p.begun[1].end_ps;
        assert_eq!(spi.read(SPISTS, second_end, &mut p).unwrap(), SPISTS_INT_FLAG | SPISTS_OVERRUN);
        assert_eq!(spi.events().count("spi_rx_overrun"), 1);
        spi.write(SPISTS, SPISTS_OVERRUN, second_end, &mut p).unwrap();
        assert_eq!(spi.read(SPISTS, second_end, &mut p).unwrap(), SPISTS_INT_FLAG);
        // A third write while one waits overwrites it (and says so).
        spi.write(SPITXBUF, 0x3333, second_end + 1, &mut p).unwrap();
        spi.write(SPITXBUF, 0x4444, second_end + 2, &mut p).unwrap();
        spi.write(SPITXBUF, 0x5555, second_end + 3, &mut p).unwrap();
        assert_eq!(spi.events().count("spi_txbuf_overwrite"), 1);
        spi.advance(PS_PER_S, &mut p).unwrap();
        assert_eq!(p.begun.iter().map(|f| f.tx).collect::<Vec<_>>(), vec![0x1111, 0x2222, 0x3333, 0x5555]);
    }

    #[test]
    fn short_characters_are_left_and_right_justified() {
        let mut spi = SpiA::new(lspclk(), 1);
        let mut p = Probe { answer: 0x5A00, ..Default::default() };
        let spi_cfg = profile::Spi { spiccr: 0xC7, ..Default::default() }; // 8-bit
        spi.init_from_profile(&spi_cfg, 0, &mut p).unwrap();
        spi.write(SPITXBUF, 0x96C3, 0, &mut p).unwrap();
        let end = spi.int_flag_time().unwrap();
        // 8 received bits right-justified; the untransmitted low byte of the word shifted above them.
        assert_eq!(spi.read(SPIRXBUF, end, &mut p).unwrap(), 0xC35A);
        assert_eq!(p.begun[0].shape.bits, 8);
        assert_eq!(end, spi.lspclk().cycles_to_ps(p.begun[0].start_cycle + 8 * 50));
    }

    #[test]
    fn software_reset_clears_flags_keeps_configuration() {
        let (mut spi, mut p) = reference();
        spi.write(SPITXBUF, 0x1111, 0, &mut p).unwrap();
        spi.write(SPITXBUF, 0x2222, 0, &mut p).unwrap();
        let end2 = spi.lspclk().cycles_to_ps(1 + 2 * 800);
        assert_eq!(spi.read(SPISTS, end2, &mut p).unwrap(), SPISTS_INT_FLAG | SPISTS_OVERRUN);
        spi.write(SPITXBUF, 0x3333, end2, &mut p).unwrap();
        spi.advance(end2 + 100_000, &mut p).unwrap();
        spi.write(SPICCR, 0x4F, end2 + 100_000, &mut p).unwrap();
        assert_eq!(spi.events().count("spi_reset_during_transfer"), 1);
        let t = end2 + 100_000;
        assert_eq!(spi.read(SPISTS, t, &mut p).unwrap(), 0);
        assert_eq!(spi.read(SPIBRR, t, &mut p).unwrap(), 49);
        assert_eq!(spi.read(SPICTL, t, &mut p).unwrap(), 7);
        // Held in reset: a TXBUF write starts nothing.
        spi.write(SPITXBUF, 0x4444, t + 2000, &mut p).unwrap();
        assert_eq!(spi.read(SPISTS, t + 2000, &mut p).unwrap(), 0);
        assert_eq!(spi.int_flag_time(), None);
        spi.write(SPICCR, 0xCF, t + 3000, &mut p).unwrap();
        spi.write(SPITXBUF, 0x5555, t + 4000, &mut p).unwrap();
        spi.advance(PS_PER_S, &mut p).unwrap();
        assert_eq!(p.begun.iter().map(|f| f.tx).collect::<Vec<_>>(), vec![0x1111, 0x2222, 0x3333, 0x5555]);
        assert_eq!(p.finished.len(), 4);
    }

    #[test]
    fn slave_mode_never_clocks() {
        let mut spi = SpiA::new(lspclk(), 1);
        let mut p = Probe::default();
        spi.write(SPICCR, 0xCF, 0, &mut p).unwrap();
        spi.write(SPICTL, 0x03, 0, &mut p).unwrap();
        spi.write(SPITXBUF, 0x1234, 0, &mut p).unwrap();
        assert_eq!(spi.read(SPISTS, PS_PER_S, &mut p).unwrap(), SPISTS_BUFFULL);
        assert_eq!((spi.int_flag_time(), spi.buffull_clear_time()), (None, None));
        assert_eq!(spi.events().count("spi_not_master"), 1);
        assert!(p.begun.is_empty());
    }

    #[test]
    fn spidat_write_starts_a_character() {
        let (mut spi, mut p) = reference();
        spi.write(SPIDAT, 0xABCD, 0, &mut p).unwrap();
        spi.write(SPIDAT, 0x1111, 10, &mut p).unwrap();
        assert_eq!(spi.events().count("spi_spidat_write_during_transfer"), 1);
        spi.advance(PS_PER_S, &mut p).unwrap();
        assert_eq!(p.begun.len(), 1);
        assert_eq!(p.begun[0].tx, 0xABCD);
        assert_eq!(spi.read(SPIDAT, PS_PER_S, &mut p).unwrap(), 0xC7A7);
    }

    #[test]
    fn reset_before_a_character_starts_keeps_the_fifo_at_16_words() {
        // Found by the register-traffic proptest: a word taken to SPIDAT but not yet started, with
        // 16 words queued behind it, cannot go back into the FIFO when SPISWRESET is cleared.
        let mut spi = SpiA::new(lspclk(), 1);
        let mut p = Probe::default();
        let cfg = profile::Spi { spifftx: 0xE000, spiffrx: 0x2000, spiffct: 0, ..Default::default() };
        spi.init_from_profile(&cfg, 0, &mut p).unwrap();
        for w in 0..17u16 {
            spi.write(SPITXBUF, 0x1000 + w, 0, &mut p).unwrap();
        }
        assert_eq!(spi.read(SPIFFTX, 0, &mut p).unwrap() >> 8 & 0x1F, 16, "one in SPIDAT, 16 waiting");
        let ccr = spi.read(SPICCR, 0, &mut p).unwrap();
        spi.write(SPICCR, ccr & !SPICCR_SPISWRESET, 0, &mut p).unwrap();
        assert_eq!(spi.read(SPIFFTX, 0, &mut p).unwrap() >> 8 & 0x1F, 16);
        assert_eq!(spi.events().count("spi_reset_word_lost"), 1);
        // After the reset the 16 waiting words go out; the lost one does not.
        spi.write(SPICCR, ccr, 0, &mut p).unwrap();
        spi.advance(PS_PER_S, &mut p).unwrap();
        let sent: Vec<u16> = p.begun.iter().map(|f| f.tx).collect();
        assert_eq!(sent, (1..17u16).map(|w| 0x1000 + w).collect::<Vec<_>>());
    }

    #[test]
    fn fifo_mode_with_txdly_gaps() {
        let mut spi = SpiA::new(lspclk(), 1);
        let mut p = Probe { answer: 0xBEEF, ..Default::default() };
        let cfg = profile::Spi { spifftx: 0xE002, spiffrx: 0x2003, spiffct: 2, ..Default::default() };
        spi.init_from_profile(&cfg, 0, &mut p).unwrap();
        for w in 0..3u16 {
            spi.write(SPITXBUF, 0x1000 + w, 0, &mut p).unwrap();
        }
        // The first went to SPIDAT; two wait: TXFFST = 2. SPISTS is unused in FIFO mode.
        assert_eq!(spi.read(SPIFFTX, 0, &mut p).unwrap() >> 8 & 0x1F, 2);
        assert_eq!(spi.read(SPISTS, 0, &mut p).unwrap(), 0);
        spi.advance(PS_PER_S, &mut p).unwrap();
        let starts: Vec<u64> = p.begun.iter().map(|f| f.start_cycle).collect();
        // 16 bits × 50 cycles, then TXDLY = 2 SPI clocks of 50 cycles.
        assert_eq!(starts, vec![1, 1 + 800 + 100, 1 + 2 * 900]);
        let fftx = spi.read(SPIFFTX, PS_PER_S, &mut p).unwrap();
        assert_eq!((fftx >> 8 & 0x1F, fftx & 0x80), (0, 0x80)); // TXFFST = 0 ≤ TXFFIL = 2: TXFFINT
        let ffrx = spi.read(SPIFFRX, PS_PER_S, &mut p).unwrap();
        assert_eq!((ffrx >> 8 & 0x1F, ffrx & 0x80), (3, 0x80)); // RXFFST = 3 ≥ RXFFIL = 3: RXFFINT
        assert_eq!(spi.read(SPIRXEMU, PS_PER_S, &mut p).unwrap(), 0xBEEF);
        assert_eq!(spi.read(SPIRXBUF, PS_PER_S, &mut p).unwrap(), 0xBEEF);
        assert_eq!(spi.read(SPIFFRX, PS_PER_S, &mut p).unwrap() >> 8 & 0x1F, 2);
        // Seventeen more words without reading: the receive FIFO overflows.
        let t = PS_PER_S;
        for _ in 0..15 {
            spi.write(SPITXBUF, 0, t, &mut p).unwrap();
        }
        spi.advance(2 * PS_PER_S, &mut p).unwrap();
        assert_eq!(spi.read(SPIFFRX, 2 * PS_PER_S, &mut p).unwrap() >> 15, 1);
        assert_eq!(spi.events().count("spi_rx_fifo_overflow"), 1);
        spi.write(SPIFFRX, 0x2003 | (1 << 14), 2 * PS_PER_S, &mut p).unwrap();
        assert_eq!(spi.read(SPIFFRX, 2 * PS_PER_S, &mut p).unwrap() >> 15, 0);
        // Eighteen writes at once overflow the transmit FIFO (one goes to SPIDAT, 16 wait).
        for _ in 0..18 {
            spi.write(SPITXBUF, 0, 2 * PS_PER_S, &mut p).unwrap();
        }
        assert_eq!(spi.events().count("spi_tx_fifo_overflow"), 1);
    }

    /// The burst in whole CPU cycles gives what the register path gives word by word through
    /// picoseconds (SPITXBUF write, INT_FLAG time, SPIRXBUF read): the same words, characters, end
    /// cycle and SPI-A time, for every LSPCLK divider, poll length, start latency and start phase.
    #[test]
    fn polled_burst_equals_the_register_path() {
        let sysclk = Clock::from_hz(150_000_000);
        // A polling loop of `p` cycles from `c` for a flag on SYSCLKOUT cycle `flag`, then the read.
        let poll = |c: u64, flag: u64, p: u64, read: u64| c + (flag.saturating_sub(c).div_ceil(p) + 1) * p + read;
        let words = [0x4200u16, 0, 0x1234, 0xFFFF, 0];
        let mut x = 0x2545_F491_4F6C_DD1Du64;
        // k = 20: more phases than `polled_run` remembers.
        for k in [1u64, 2, 4, 6, 14, 20] {
            for (p, latency, write, read, after) in
                [(1, 0, 0, 0, 0), (5, 1, 2, 3, 4), (12, 3, 7, 1, 9), (39, 1, 4, 4, 7)]
            {
                let lsp = sysclk.divided(k);
                let cpu = PolledLoop {
                    sysclk,
                    sysclk_per_lspclk: Divisor::new(k),
                    before_write: p + write,
                    after_read: after,
                };
                // SPICCR 0xC7: 8-bit characters (SPIDAT keeps the word sent above the word received).
                for (brr, spiccr) in [(2u32, 0xCF), (9, 0xC7), (30, 0xCF)] {
                    x ^= x << 13;
                    x ^= x >> 7;
                    x ^= x << 17;
                    let c0 = 1_000_000 + x % 10_000;
                    let spi_profile = profile::Spi { spibrr: brr, spiccr, ..Default::default() };
                    let fresh = || {
                        let mut spi = SpiA::new(lsp, latency);
                        let mut probe = Probe { answer: 0xC7A7, ..Default::default() };
                        spi.init_from_profile(&spi_profile, 0, &mut probe).unwrap();
                        (spi, probe)
                    };
                    // The register path, word by word through picoseconds.
                    let by_register = |words: &[u16], c_start: u64| {
                        let (mut a, mut pa) = fresh();
                        let mut c = c_start;
                        let mut got = vec![0u16; words.len()];
                        for (i, &w) in words.iter().enumerate() {
                            c += p + write; // BUFFULL clear at the first poll
                            a.write(SPITXBUF, w, sysclk.cycles_to_ps(c), &mut pa).unwrap();
                            let flag = sysclk.ps_to_cycles_ceil(a.int_flag_time().unwrap());
                            c = poll(c, flag, p, read);
                            got[i] = a.read(SPIRXBUF, sysclk.cycles_to_ps(c), &mut pa).unwrap();
                            c += after;
                        }
                        (got, c, a, pa)
                    };
                    let read_after = |w, wait| Ok(poll(w, w + wait, p, read) - w);
                    let case = format!("k={k} p={p} latency={latency} brr={brr} spiccr={spiccr:#X} c0={c0}");
                    let (want, c, a, pa) = by_register(&words, c0);
                    let (mut b, mut pb) = fresh();
                    assert!(b.polled_frame_applies(sysclk.cycles_to_ps(c0)));
                    let mut c_burst = c0;
                    let burst = b.polled_burst(words, &mut c_burst, &cpu, read_after, &mut pb, |_, _| {}).unwrap();
                    assert_eq!((burst.to_vec(), c_burst, &pb.finished), (want, c, &pa.finished), "{case}");
                    assert_eq!(
                        (b.now, b.frames, b.int_flag, b.rxbuf, b.spidat),
                        (a.now, a.frames, a.int_flag, a.rxbuf, a.spidat),
                        "{case}"
                    );
                    // One word 24 times, as one run of characters (long enough to come back to a phase),
                    // with fresh steps, then with steps kept from run to run: from the same first write, a
                    // later one of the same phase (the kept run, shifted), another phase, the first again.
                    let mut kept = PollSteps::default();
                    for (c_start, keep) in [(c0, false), (c0, true), (c0 + 37 * k, true), (c0 + 1, true), (c0, true)] {
                        let (want, c, a, pa) = by_register(&[0x5A5A; 24], c_start);
                        let (mut r, mut pr) = fresh();
                        let mut c_run = c_start;
                        let mut fresh_steps = PollSteps::default();
                        let steps = if keep { &mut kept } else { &mut fresh_steps };
                        let run: [u16; 24] =
                            r.polled_run(0x5A5A, &mut c_run, &cpu, read_after, steps, &mut pr).unwrap();
                        let case = format!("{case} from {c_start} kept={keep}");
                        assert_eq!((run.to_vec(), c_run, &pr.finished), (want, c, &pa.finished), "{case}");
                        assert_eq!(
                            (r.now, r.frames, r.int_flag, r.rxbuf, r.spidat, r.txbuf, r.int_flag_at),
                            (a.now, a.frames, a.int_flag, a.rxbuf, a.spidat, a.txbuf, a.int_flag_at),
                            "{case}"
                        );
                    }
                }
            }
        }
    }
    /// Steps kept from run to run are worked out again when the loop's costs, the start latency or
    /// the character's length change: each run equals the same run with fresh steps.
    #[test]
    fn kept_poll_steps_follow_the_loop_and_the_character() {
        let sysclk = Clock::from_hz(150_000_000);
        let k = 4;
        // A 5-cycle poll, then a 3-cycle read.
        let read_after = |_write: u64, wait: u64| Ok((wait.div_ceil(5) + 1) * 5 + 3);
        let mut kept = PollSteps::default();
        // Each change moves the steps: the length (SPIBRR), the latency, the loop's cost, back again.
        for (brr, latency, after_read) in [(2, 1, 4), (9, 1, 4), (9, 2, 4), (9, 2, 11), (2, 1, 4)] {
            let cpu = PolledLoop { sysclk, sysclk_per_lspclk: Divisor::new(k), before_write: 7, after_read };
            let spi_profile = profile::Spi { spibrr: brr, ..Default::default() };
            let fresh = || {
                let mut spi = SpiA::new(sysclk.divided(k), latency);
                let mut probe = Probe { answer: 0xC7A7, ..Default::default() };
                spi.init_from_profile(&spi_profile, 0, &mut probe).unwrap();
                (spi, probe, 1_000_003u64)
            };
            let (mut a, mut pa, mut ca) = fresh();
            let want: [u16; 13] =
                a.polled_run(0, &mut ca, &cpu, read_after, &mut PollSteps::default(), &mut pa).unwrap();
            let (mut b, mut pb, mut cb) = fresh();
            let got: [u16; 13] = b.polled_run(0, &mut cb, &cpu, read_after, &mut kept, &mut pb).unwrap();
            let case = format!("brr={brr} latency={latency} after_read={after_read}");
            assert_eq!((got, cb, &pb.finished, b.now), (want, ca, &pa.finished, a.now), "{case}");
        }
    }
}
