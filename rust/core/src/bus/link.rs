//! The SPI link: SPI-A (master) wired to a slave, with GPIO57 as chip select, at either level.
//!
//! The firmware model talks to the link as it would to the chip: register reads and writes at word
//! offsets, GPIO57 writes, each at its virtual time. The link advances SPI-A to that time, so the
//! slave is told about CS edges and frames in time order. Per frame it asks the slave for DOUT when
//! the frame starts, and delivers DIN when it ends.

use super::{
    bitlevel, devices_of, transaction, Address, BusLevel, Device, Exchange, FrameTiming, Lines, Link, RunTiming,
    SpiSlave, Transfer,
};
use crate::dsp::spi::{
    self, CharShape, FlagTime, Frame, FrameRun, PollSteps, PolledLoop, SpiA, SpiWire, SPIRXBUF, SPITXBUF,
};
use crate::dsp::DspClocks;
use crate::error::{Error, Result};
use crate::events::{Event, EventLog, Severity};
use crate::profile::{self, BoardDevice, BoxedLink, Devices, LinkKind, Placed, Profile};
use crate::time::{Clock, Ps};

/// One frame on the wires, as logged.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FrameRecord {
    /// Character index since power-on.
    pub index: u64,
    /// Character start (first SCLK edge without delay).
    pub start_ps: Ps,
    /// Character end (INT_FLAG).
    pub end_ps: Ps,
    /// What the slave was told about the frame.
    pub timing: FrameTiming,
    /// Whether CS was asserted at the start (the slave took part).
    pub selected: bool,
    /// SPIDAT at the start (the master's word, left-justified).
    pub master_tx: u16,
    /// Bits the master received, right-justified.
    pub master_rx: u16,
    /// Bits the slave sampled on DIN, right-justified.
    pub din: u16,
    /// The word the slave shifted out on DOUT (the floating word when not selected).
    pub dout: u16,
}

/// One entry of the link's transaction log.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LinkRecord {
    /// GPIO57 changed: `low` = CS asserted.
    Cs {
        /// Time of the edge.
        t_ps: Ps,
        /// New state: `true` = asserted (low).
        low: bool,
    },
    /// A frame.
    Frame(FrameRecord),
}

#[derive(Debug, Clone, Copy)]
struct InFlight {
    timing: FrameTiming,
    dout: u16,
    selected: bool,
}

/// What the bit level's walk of a frame depends on, besides the slave's word.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct ExchangeKey {
    tx: u16,
    shape: CharShape,
    talk: bool,
    loopback: bool,
    lines: Lines,
}

/// The wires between SPI-A and the slave.
#[derive(Debug)]
struct Wires<S> {
    slave: S,
    /// SPI-A's LSPCLK (fixed per link: kept here rather than copied into every frame).
    lspclk: Clock,
    level: BusLevel,
    cs_low: bool,
    simo: bool,
    floating: bool,
    in_flight: Option<InFlight>,
    /// The bit-level waveform of the latest character shape (kept here, not copied per frame): rebuilt
    /// only when the shape changes.
    waveform: Option<bitlevel::Waveform>,
    period_cache: Option<(u32, Ps)>,
    /// The bit level's map of what a run's frames exchange, and what it was made for.
    exchange_map: Option<(ExchangeKey, Box<bitlevel::ExchangeMap>)>,
    log: Option<Vec<LinkRecord>>,
    events: EventLog,
    /// SPISTE drives the chip select (GPIO57 muxed to SPISTEA, SPI-A master): low from ½ SCLK period
    /// before each character's first edge to ½ after its last, low throughout between characters
    /// that follow without a gap (spec f28335-peripherals.md §4 [unconfirmed]).
    ste: bool,
    /// STE pulses high between characters that follow without a gap (profile
    /// `spi.ste_pulse_between_words`, [unconfirmed]); otherwise it stays low between them.
    ste_pulse: bool,
    /// The STE line is low (the slave was told), and when it is due to rise (after a character).
    ste_low: bool,
    ste_rise: Option<Ps>,
}

impl<S: SpiSlave> SpiWire for Wires<S> {
    fn begin(&mut self, frame: &Frame) {
        self.in_flight = Some(self.start(frame));
    }

    fn finish(&mut self, frame: &Frame) -> u16 {
        let Some(f) = self.in_flight.take() else {
            // The peripheral pairs every finish with a begin; an unpaired one reads the floating level.
            return if self.floating { frame.rx_mask() } else { 0 };
        };
        self.end(frame, f)
    }

    #[inline(always)]
    fn transfer(&mut self, frame: &Frame) -> u16 {
        // Nothing can happen on the wires in between: the frame need not be stored in `in_flight`.
        let f = self.start(frame);
        self.end(frame, f)
    }

    fn transfer_run(&mut self, run: &FrameRun, rx: &mut [u16]) {
        let first = &run.first;
        let lines = self.lines(self.cs_low);
        // What the slave samples does not depend on what it answers: at the bit level one walk of
        // the word tells it (and where SPISIMO is left).
        let (din, simo_after) = match self.level {
            BusLevel::Transaction => (transaction::slave_din(first, lines), transaction::simo_after(first, lines)),
            BusLevel::Bit => {
                let ex = self.exchange_map(first, lines).exchange(0);
                (ex.slave_din, ex.simo_after)
            }
        };
        // Every character of the run sees the same lines when CS stays asserted (nothing can move it
        // during a run) and SPISIMO already rests where each character leaves it: then the slave is
        // told about all of them at once. The log records each character on its own.
        if self.log.is_some() || !lines.selected || simo_after != lines.simo_before {
            return spi::transfer_each(self, run, rx);
        }
        let timing = match self.level {
            BusLevel::Transaction => {
                let period = self.sclk_period(first);
                transaction::TimingOf::new(&first.shape, &self.lspclk, period)
            }
            BusLevel::Bit => self.waveform_of(first).timing_of(),
        };
        // The slave is handed the run's timing formula: it times only the frames it looks at.
        self.slave.run_frames(&RunTiming::new(timing, first.index, run.starts, run.closest_spacing), din, rx);
        // What the master samples: each character's word through the closed form or the walk's map
        // (the walk depends on the word, the shape and the lines, not on the character's time).
        match self.level {
            // In the slave's own mode the master reads its words as they are: no pass over them.
            BusLevel::Transaction if transaction::master_rx_is_dout(first, lines) => {}
            BusLevel::Transaction => rx.iter_mut().for_each(|r| *r = transaction::master_rx(first, *r, lines)),
            BusLevel::Bit => {
                let map = self.exchange_map(first, lines);
                rx.iter_mut().for_each(|r| *r = map.exchange(*r).master_rx);
            }
        }
    }
}

impl<S: SpiSlave> Wires<S> {
    /// The lines around a frame that starts now, with the slave `selected` or not.
    #[inline(always)]
    fn lines(&self, selected: bool) -> Lines {
        Lines {
            selected,
            simo_before: self.simo,
            floating: self.floating,
            dout_as_sampled: self.slave.answers_as_sampled(),
        }
    }

    /// The frame starts: what the slave is shown and what it answers. `start` and `end` are forced
    /// inline: each runs once per frame and the compiler kept them out of line (measured).
    #[inline(always)]
    fn start(&mut self, frame: &Frame) -> InFlight {
        let timing = match self.level {
            BusLevel::Transaction => {
                let period = self.sclk_period(frame);
                transaction::frame_timing(&frame.shape, frame.index, frame.start_cycle, &self.lspclk, period)
            }
            BusLevel::Bit => self.waveform_of(frame).timing(frame.index, frame.start_cycle),
        };
        if self.ste && !self.cs_low {
            self.ste_fall(&timing);
        }
        let selected = self.cs_low || self.ste_low;
        let dout = if selected { self.slave.begin_frame(&timing) } else { self.unselected(frame) };
        InFlight { timing, dout, selected }
    }

    /// The bit-level waveform of the frame's shape (built when the shape is not the last one's).
    #[inline(always)]
    fn waveform_of(&mut self, frame: &Frame) -> &bitlevel::Waveform {
        if self.waveform.as_ref().map(bitlevel::Waveform::shape) != Some(frame.shape) {
            self.waveform = None;
        }
        self.waveform.get_or_insert_with(|| bitlevel::Waveform::of(frame, &self.lspclk))
    }

    /// The bit level's map of what frames like `frame` exchange with these `lines` (kept: rebuilt
    /// only when the frame's word, shape, TALK, loopback or the lines change).
    fn exchange_map(&mut self, frame: &Frame, lines: Lines) -> &bitlevel::ExchangeMap {
        let key = ExchangeKey { tx: frame.tx, shape: frame.shape, talk: frame.talk, loopback: frame.loopback, lines };
        if self.exchange_map.as_ref().map(|(k, _)| k) != Some(&key) {
            self.exchange_map = None;
        }
        &self.exchange_map.get_or_insert_with(|| (key, Box::new(bitlevel::ExchangeMap::of(frame, lines)))).1
    }

    /// The shortest SCLK period of the frame's clock (cached per baud setting).
    #[inline(always)]
    fn sclk_period(&mut self, frame: &Frame) -> Ps {
        let divisor = frame.shape.divisor;
        match self.period_cache {
            Some((d, p)) if d == divisor => p,
            _ => {
                let p = transaction::sclk_period(frame, &self.lspclk);
                self.period_cache = Some((divisor, p));
                p
            }
        }
    }

    /// The frame `f` ends: what both sides sampled; returns the master's bits.
    #[inline(always)]
    fn end(&mut self, frame: &Frame, f: InFlight) -> u16 {
        let lines = self.lines(f.selected);
        let ex: Exchange = match self.level {
            BusLevel::Bit => bitlevel::exchange(frame, f.dout, lines),
            BusLevel::Transaction => transaction::exchange(frame, f.dout, lines),
        };
        self.simo = ex.simo_after;
        if f.selected {
            self.slave.end_frame(ex.slave_din, &f.timing);
        }
        if self.ste_low {
            self.ste_rise = Some(f.timing.last_edge + f.timing.sclk_period / 2);
        }
        if let Some(log) = self.log.as_mut() {
            log.push(LinkRecord::Frame(FrameRecord {
                index: frame.index,
                start_ps: frame.start_ps,
                end_ps: frame.end_ps,
                timing: f.timing,
                selected: f.selected,
                master_tx: frame.tx,
                master_rx: ex.master_rx,
                din: ex.slave_din,
                dout: f.dout,
            }));
        }
        ex.master_rx
    }
}

impl<S: SpiSlave> Wires<S> {
    /// SPISTE falls ½ SCLK period before the character's first edge, unless it is still low from a
    /// character that ended no sooner than that (no gap: it stays low, or with `ste_pulse` rises and
    /// falls again at that instant).
    #[cold]
    #[inline(never)]
    fn ste_fall(&mut self, timing: &FrameTiming) {
        let fall = timing.first_edge.saturating_sub(timing.sclk_period / 2);
        if let Some(rise) = self.ste_rise.take() {
            if rise >= fall && !self.ste_pulse {
                return; // back to back: STE stays low
            }
            self.ste_edge(false, rise.min(fall));
        }
        self.ste_edge(true, fall);
    }

    /// SPISTE moves at `t` (`low`: asserted): the slave and the log are told.
    fn ste_edge(&mut self, low: bool, t: Ps) {
        self.ste_low = low;
        self.slave.set_cs(low, t);
        if let Some(log) = self.log.as_mut() {
            log.push(LinkRecord::Cs { t_ps: t, low });
        }
    }
}

impl<S> Wires<S> {
    /// GPIO57 moved while frame `f` is on the wires (out of line: the CS edge is on every burst's
    /// path, the event almost never fires).
    #[cold]
    #[inline(never)]
    fn cs_changed_mid_frame(&mut self, f: &InFlight, high: bool, t: Ps) {
        self.events.push(
            Event::new(
                t,
                "cs_changed_mid_frame",
                Severity::Warning,
                format!(
                    "GPIO57 (CS) went {} at {t} ps inside a frame (edges {}…{} ps)",
                    if high { "high" } else { "low" },
                    f.timing.first_edge,
                    f.timing.last_edge
                ),
            )
            .in_frame(f.timing.index),
        );
    }

    /// A frame clocked with CS high: the slave is not involved and DOUT floats.
    #[cold]
    #[inline(never)]
    fn unselected(&mut self, frame: &Frame) -> u16 {
        self.events.push(
            Event::new(
                frame.start_ps,
                "spi_frame_without_cs",
                Severity::Warning,
                format!("SPI character {} clocked with GPIO57 (CS) high: the slave ignores it", frame.index),
            )
            .in_frame(frame.index),
        );
        if self.floating {
            0xFFFF
        } else {
            0
        }
    }
}

/// SPI-A, GPIO57 and a slave, emulated at the chosen [`BusLevel`].
#[derive(Debug)]
pub struct SpiLink<S> {
    spi: SpiA,
    wires: Wires<S>,
    /// Run [`SpiLink::write_poll_read`] in one step when it applies (on by default; off only to check
    /// that the two paths agree).
    polled_fast_path: bool,
}

impl<S: SpiSlave> SpiLink<S> {
    /// A link with SPI-A in its reset state. CS (GPIO57) starts high (deasserted), SPISIMO low
    /// (SPIDAT's reset MSB), and an undriven line reads 1 ([unconfirmed]: no pull resistor is
    /// documented; see [`SpiLink::set_floating_level`]).
    pub fn new(spi: SpiA, slave: S, level: BusLevel) -> SpiLink<S> {
        SpiLink {
            wires: Wires {
                slave,
                lspclk: spi.lspclk(),
                level,
                cs_low: false,
                simo: false,
                floating: true,
                in_flight: None,
                waveform: None,
                period_cache: None,
                exchange_map: None,
                log: None,
                events: EventLog::default(),
                ste: false,
                ste_pulse: false,
                ste_low: false,
                ste_rise: None,
            },
            spi,
            polled_fast_path: true,
        }
    }

    /// A link for the profile's board (LSPCLK, start latency, level). SPI-A is in its reset state:
    /// run [`SpiLink::init_from_profile`] when the firmware initialises it.
    pub fn from_profile(profile: &Profile, slave: S) -> Result<SpiLink<S>> {
        let clocks = DspClocks::from_profile(&profile.clocks)?;
        let spi = SpiA::new(clocks.lspclk, profile.spi.start_latency_lspclk);
        let mut link = SpiLink::new(spi, slave, profile.spi.level);
        link.set_ste_pulse_between_words(profile.spi.ste_pulse_between_words);
        Ok(link)
    }

    /// The published InitSpi register writes at time `t` (see [`SpiA::init_writes`]).
    pub fn init_from_profile(&mut self, spi: &profile::Spi, t: Ps) -> Result<()> {
        self.spi.init_from_profile(spi, t, &mut self.wires)
    }

    /// Read an SPI-A register at time `t`.
    pub fn read(&mut self, offset: u16, t: Ps) -> Result<u16> {
        self.spi.read(offset, t, &mut self.wires)
    }

    /// Write an SPI-A register at time `t`.
    pub fn write(&mut self, offset: u16, value: u16, t: Ps) -> Result<()> {
        self.spi.write(offset, value, t, &mut self.wires)
    }

    /// The firmware's per-word polling sequence: write `tx` to SPITXBUF at `t_write`, poll INT_FLAG,
    /// read SPIRXBUF at the time `read_at` gives for the INT_FLAG time it is handed (`None`: the flag
    /// never sets); returns the word read. The same as `write`, `int_flag_time`, `read`; when SPI-A is
    /// idle in normal mode it is done in one step (the hot path of every burst).
    pub fn write_poll_read(
        &mut self,
        tx: u16,
        t_write: Ps,
        read_at: impl FnOnce(Option<FlagTime>) -> Result<Ps>,
    ) -> Result<u16> {
        if self.polled_fast_path && self.spi.polled_frame_applies(t_write) {
            return self.spi.polled_frame(tx, t_write, read_at, &mut self.wires);
        }
        self.write(SPITXBUF, tx, t_write)?;
        let t_read = read_at(self.int_flag_time().map(FlagTime::at))?;
        self.read(SPIRXBUF, t_read)
    }

    /// Whether [`SpiLink::polled_burst`] may run from a first write at `t` (see
    /// [`SpiA::polled_frame_applies`]); never with the one-step path turned off.
    pub fn polled_burst_applies(&self, t: Ps) -> bool {
        self.polled_fast_path && self.spi.polled_frame_applies(t)
    }

    /// A whole polled word loop in CPU cycles: [`SpiLink::write_poll_read`] for each of `words`, as
    /// [`SpiA::polled_burst`] runs it; `after_word(i, slave)` runs after word `i`.
    pub fn polled_burst<const N: usize>(
        &mut self,
        words: [u16; N],
        c: &mut u64,
        cpu: &PolledLoop,
        read_after: impl Fn(u64, u64) -> Result<u64>,
        mut after_word: impl FnMut(usize, &S),
    ) -> Result<[u16; N]> {
        self.spi.polled_burst(words, c, cpu, read_after, &mut self.wires, |i, w| after_word(i, &w.slave))
    }

    /// [`SpiLink::polled_burst`] of `N` copies of the word `tx`, the characters clocked as one run
    /// (see [`SpiA::polled_run`]; `steps` are kept by the caller for its `read_after`).
    pub fn polled_run<const N: usize>(
        &mut self,
        tx: u16,
        c: &mut u64,
        cpu: &PolledLoop,
        read_after: impl Fn(u64, u64) -> Result<u64>,
        steps: &mut PollSteps,
    ) -> Result<[u16; N]> {
        self.spi.polled_run(tx, c, cpu, read_after, steps, &mut self.wires)
    }

    /// Turn the one-step path of [`SpiLink::write_poll_read`] on or off (on by default). Off, every
    /// word goes through the register path: for checking that both give the same results.
    pub fn set_polled_fast_path(&mut self, on: bool) {
        self.polled_fast_path = on;
    }

    /// Process everything that happens on the link up to time `t`.
    pub fn advance(&mut self, t: Ps) -> Result<()> {
        self.spi.advance(t, &mut self.wires)
    }

    /// The firmware writes GPIO57 (the chip select) at time `t`: `high = false` asserts CS.
    pub fn set_gpio57(&mut self, high: bool, t: Ps) -> Result<()> {
        self.spi.advance(t, &mut self.wires)?;
        let low = !high;
        if low == self.wires.cs_low {
            return Ok(());
        }
        if let Some(f) = self.wires.in_flight {
            self.wires.cs_changed_mid_frame(&f, high, t);
        }
        self.wires.cs_low = low;
        self.wires.slave.set_cs(low, t);
        if let Some(log) = self.wires.log.as_mut() {
            log.push(LinkRecord::Cs { t_ps: t, low });
        }
        Ok(())
    }

    /// GPIO57 is muxed to SPISTEA (`on`) or not, from time `t`: with it, SPI-A drives the chip select
    /// around each character as a master does (see `Wires::ste`); without it, only
    /// [`SpiLink::set_gpio57`] moves it.
    pub fn set_ste_driven(&mut self, on: bool, t: Ps) -> Result<()> {
        self.spi.advance(t, &mut self.wires)?;
        self.flush_ste(if on { t } else { Ps::MAX });
        self.wires.ste = on;
        Ok(())
    }

    /// Whether SPISTE pulses high between characters that follow without a gap (profile
    /// `spi.ste_pulse_between_words`, [unconfirmed]) or stays low (the default).
    pub fn set_ste_pulse_between_words(&mut self, on: bool) {
        self.wires.ste_pulse = on;
    }

    /// SPISTE rises if it was due to by `t` and no character followed (the caller moved time to `t`).
    #[inline]
    pub fn flush_ste(&mut self, t: Ps) {
        if let Some(rise) = self.wires.ste_rise.filter(|&r| r <= t && self.wires.in_flight.is_none()) {
            self.wires.ste_rise = None;
            self.wires.ste_edge(false, rise);
        }
    }

    /// Whether SPISTE drives the chip select (GPIO57 muxed to SPISTEA).
    pub fn ste_driven(&self) -> bool {
        self.wires.ste
    }

    /// Whether SPISTE is low now (a character is on the wires, or one just ended and its rise is
    /// not due yet).
    pub fn cs_asserted_by_ste(&self) -> bool {
        self.wires.ste_low
    }

    /// A new LSPCLK from time `t` on (the firmware wrote LOSPCP); see [`SpiA::set_lspclk`].
    pub fn set_lspclk(&mut self, lspclk: Clock, t: Ps) -> Result<()> {
        self.spi.advance(t, &mut self.wires)?;
        self.spi.set_lspclk(lspclk, t)?;
        self.wires.lspclk = lspclk;
        self.wires.waveform = None;
        self.wires.period_cache = None;
        self.wires.exchange_map = None;
        Ok(())
    }

    /// Whether CS is asserted (GPIO57 low).
    pub fn cs_asserted(&self) -> bool {
        self.wires.cs_low
    }

    /// When SPISTS.INT_FLAG is (or will be) set; see [`SpiA::int_flag_time`].
    pub fn int_flag_time(&self) -> Option<Ps> {
        self.spi.int_flag_time()
    }

    /// When SPISTS.BUFFULL_FLAG reads 0; see [`SpiA::buffull_clear_time`].
    pub fn buffull_clear_time(&self) -> Option<Ps> {
        self.spi.buffull_clear_time()
    }

    /// Start recording the transaction log (frames and CS edges). Off by default: the fast path
    /// does not allocate.
    pub fn enable_log(&mut self) {
        self.wires.log.get_or_insert_with(Vec::new);
    }

    /// Stop recording and take what was recorded (the bus view logs a window, not a whole run).
    pub fn stop_log(&mut self) -> Vec<LinkRecord> {
        self.wires.log.take().unwrap_or_default()
    }

    /// Take the log recorded so far (empty when logging is off); logging stays on if it was.
    pub fn take_log(&mut self) -> Vec<LinkRecord> {
        self.wires.log.as_mut().map(std::mem::take).unwrap_or_default()
    }

    /// The log recorded so far, to drain in place (None when logging is off): its buffer stays the
    /// link's, so a caller that empties it after each access does not reallocate it for each frame.
    pub fn log_mut(&mut self) -> Option<&mut Vec<LinkRecord>> {
        self.wires.log.as_mut()
    }

    /// The level an undriven line (SPISIMO with TALK = 0, DOUT with CS high) reads as.
    pub fn set_floating_level(&mut self, high: bool) {
        self.wires.floating = high;
    }

    /// Switch the emulation level. Refused while a frame is in flight (it was begun at the other
    /// level); switch between frames.
    pub fn set_level(&mut self, level: BusLevel) -> Result<()> {
        if self.wires.in_flight.is_some() && level != self.wires.level {
            return Err(Error::Config("bus level switched while a frame is in flight: switch between frames".into()));
        }
        self.wires.level = level;
        Ok(())
    }

    /// The emulation level.
    pub fn level(&self) -> BusLevel {
        self.wires.level
    }

    /// The master peripheral.
    pub fn spi(&self) -> &SpiA {
        &self.spi
    }

    /// The slave.
    pub fn slave(&self) -> &S {
        &self.wires.slave
    }

    /// The slave, mutably (e.g. to feed a device model its physical inputs).
    pub fn slave_mut(&mut self) -> &mut S {
        &mut self.wires.slave
    }

    /// Events of the link itself (frames without CS, CS edges inside a frame); SPI-A's own events
    /// are in `spi().events()`.
    pub fn events(&self) -> &EventLog {
        &self.wires.events
    }

    /// Take the link's and SPI-A's events out, in that order.
    pub fn drain_events(&mut self) -> Vec<Event> {
        let mut e = self.wires.events.drain();
        let mut spi = self.spi.drain_events();
        if !spi.is_empty() {
            e.append(&mut spi);
        }
        e
    }
}

/// Several SPI slaves on one SPI-A, each on its own chip select: the slave the link talks to is the
/// one whose chip select the driver asserts ([`ChipSelects::select`] before the link's CS falls).
pub struct ChipSelects {
    devices: Vec<(u8, Box<dyn SpiSlave + Send>)>,
    selected: Option<usize>,
}

impl std::fmt::Debug for ChipSelects {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ChipSelects").field("gpios", &self.gpios()).field("selected", &self.selected).finish()
    }
}

impl ChipSelects {
    /// The slaves and their chip-select GPIO numbers (unique: the profile checks it).
    pub fn new(devices: Vec<(u8, Box<dyn SpiSlave + Send>)>) -> ChipSelects {
        ChipSelects { devices, selected: None }
    }

    /// The chip-select GPIO numbers, in declaration order.
    pub fn gpios(&self) -> Vec<u8> {
        self.devices.iter().map(|(g, _)| *g).collect()
    }

    /// Route the next chip-select edge and frames to the slave on `gpio`; an error naming the
    /// wired chip selects when none is on it.
    pub fn select(&mut self, gpio: u8) -> Result<()> {
        let Some(i) = self.devices.iter().position(|(g, _)| *g == gpio) else {
            let wired: Vec<String> = self.gpios().iter().map(|g| format!("GPIO{g}")).collect();
            return Err(Error::Config(format!(
                "SPI-A: no device on chip select GPIO{gpio} (devices on {})",
                if wired.is_empty() { "no chip select".to_string() } else { wired.join(", ") }
            )));
        };
        self.selected = Some(i);
        Ok(())
    }

    /// The slave on `gpio`.
    pub fn device(&self, gpio: u8) -> Option<&(dyn SpiSlave + Send)> {
        self.devices.iter().find(|(g, _)| *g == gpio).map(|(_, d)| d.as_ref())
    }

    fn current(&mut self) -> &mut (dyn SpiSlave + Send) {
        let i = self.selected.expect("the link selects a device before it asserts CS");
        self.devices[i].1.as_mut()
    }
}

impl SpiSlave for ChipSelects {
    fn set_cs(&mut self, low: bool, t: Ps) {
        self.current().set_cs(low, t);
    }
    fn begin_frame(&mut self, timing: &FrameTiming) -> u16 {
        self.current().begin_frame(timing)
    }
    fn end_frame(&mut self, din: u16, timing: &FrameTiming) {
        self.current().end_frame(din, timing);
    }
    /// The selected slave's (none selected: no frame reaches a slave, the default).
    fn answers_as_sampled(&self) -> bool {
        self.selected.is_some_and(|i| self.devices[i].1.answers_as_sampled())
    }
    fn drain_events(&mut self) -> Vec<Event> {
        self.devices.iter_mut().flat_map(|(_, d)| d.drain_events()).collect()
    }
}

/// The wait of [`Link::transfer`]'s SPI driver after CS↓, between a frame's INT_FLAG and the next
/// write, and before CS↑: 40 µs, so that frames outside a burst keep the ADIS16xxx family's
/// tDATARATE (40 µs first edge to first edge, [unconfirmed] for the ADIS16407) at any SCLK, and
/// above its t_STALL (9 µs) and CS set-up and hold times. A choice of this generic driver, not a
/// hardware figure: the acquisition ISR, which counts its own CPU cycles, drives SPI-A through its
/// registers instead.
pub const DRIVER_WAIT_PS: Ps = 40_000_000;

/// SPI-A as a [`Link`]: CS↓ at `t`, each word written to SPITXBUF [`DRIVER_WAIT_PS`] after the
/// previous step, read at its INT_FLAG time, CS↑ [`DRIVER_WAIT_PS`] after the last read.
impl Link for SpiLink<ChipSelects> {
    fn transfer(&mut self, to: Address, tx: &[u16], rx: &mut [u16], t: Ps) -> Result<Transfer> {
        let Address::ChipSelect(gpio) = to else {
            return Err(Error::Config(format!("SPI-A addresses a device by chip select, not by {to}")));
        };
        if rx.len() != tx.len() {
            return Err(Error::Config(format!(
                "SPI-A: {} words to send and {} to receive: one word comes back per frame",
                tx.len(),
                rx.len()
            )));
        }
        if self.cs_asserted() {
            return Err(Error::Config(format!("SPI-A: chip select GPIO{gpio} asserted while another is")));
        }
        self.wires.slave.select(gpio)?;
        self.set_gpio57(false, t)?;
        let mut now = t;
        for (w, r) in tx.iter().zip(rx.iter_mut()) {
            now += DRIVER_WAIT_PS;
            let mut read_at = now;
            *r = self.write_poll_read(*w, now, |flag| {
                read_at = flag
                    .ok_or_else(|| Error::Config("SPI-A is not enabled (SPICCR.SPISWRESET = 0): no frame".into()))?
                    .ps;
                Ok(read_at)
            })?;
            now = read_at;
        }
        now += DRIVER_WAIT_PS;
        self.set_gpio57(true, now)?;
        Ok(Transfer { start: t, end: now, complete: true })
    }

    fn drain_events(&mut self) -> Vec<Event> {
        let mut e = SpiLink::drain_events(self);
        e.extend(self.slave_mut().drain_events());
        e
    }
}

inventory::submit! {
    LinkKind {
        name: "spi",
        links: &["spi-a"],
        keys: &["chip_select"],
        section: None,
        place: chip_select,
        check: |_| Ok(()),
        fits: Device::is::<dyn SpiSlave + Send>,
        build: spi_a,
    }
}

/// The highest GPIO number of the F28335 (GPIO0…GPIO87).
const LAST_GPIO: u8 = 87;

/// An SPI device's place: the GPIO the firmware drives as its chip select (`chip_select = "GPIO58"`).
fn chip_select(d: &BoardDevice) -> Placed {
    let value = d.keys.get("chip_select");
    let gpio = value
        .and_then(|v| v.as_str())
        .and_then(|t| t.strip_prefix("GPIO"))
        .and_then(|n| n.parse::<u8>().ok().filter(|&g| g <= LAST_GPIO && (n == "0" || !n.starts_with('0'))));
    gpio.map(Address::ChipSelect).ok_or_else(|| {
        let given = value.map_or("\"\"".to_string(), |v| v.to_string());
        ("chip_select", given, "\"GPIO0\" … \"GPIO87\"".to_string())
    })
}

/// SPI-A with its devices by chip select, initialised as InitSpi leaves it at power-on.
fn spi_a(profile: &Profile, link: &str, devices: Devices) -> Result<BoxedLink> {
    let slaves = devices_of::<dyn SpiSlave + Send, _>(link, devices, "an SPI slave", |a| match a {
        Address::ChipSelect(gpio) => Some(gpio),
        _ => None,
    })?;
    let mut spi = SpiLink::from_profile(profile, ChipSelects::new(slaves))?;
    spi.init_from_profile(&profile.spi, 0)?;
    Ok(Box::new(spi))
}
