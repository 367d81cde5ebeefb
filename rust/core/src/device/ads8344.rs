//! The ADS8344: a 16-bit, 8-channel SAR ADC on SPI (ads8344.md), the converter of the
//! geomagnetic–gyro board (algorithms.md §1, corrections).
//!
//! The part is modelled clock by clock inside each frame it is handed:
//! - DIN is latched on rising DCLK edges. While no conversion is under way, the first HIGH bit is
//!   the start bit S; the seven bits after it complete the control byte
//!   `S A2 A1 A0 – SGL/DIF PD1 PD0` (Table I/II: the single-ended channel order is **not** the
//!   natural binary one).
//! - The selected input is tracked from the rising edge that latches A0 (clock 4 after S) and held
//!   at the falling edge after PD0 (clock 8): the acquisition time is that interval, checked
//!   against t_ACQ [unconfirmed for ADS8344: the ADS7844 family's behaviour].
//! - External-clock modes (PD = 11, 00): DOUT shows a null bit at clock 9 and D15…D0 at clocks
//!   10…25; the 25th clock may carry the next S (24 clocks per conversion). CS↑ before clock 25
//!   abandons the conversion (`adc_conversion_aborted`).
//! - Internal-clock mode (PD = 10, and 01 if [`Ads8344Config::pd01_internal_clock`]): the
//!   conversion runs for [`Ads8344Timing::t_conv_internal_ps`] after the hold, across CS↑; the
//!   result (null bit, D15…D0) is shifted out by the first 17 clocks that rise after it ends;
//!   clocks before it ends read 0 (`adc_busy_read`).
//! - Coding: straight binary, code = ⌊(V₊ − V₋)/VREF · 2¹⁶⌋ clipped to 0…0xFFFF
//!   (`adc_input_out_of_range` when clipped).
//!
//! Timing rules checked per frame by the shared SPI checker against the part's declared timing
//! (`parts::ads8344::SPI`, with the configuration's DCLK limit and t_CSS): DCLK ≤ `max_dclk_hz`
//! (`sclk_too_fast`), CS↓ to the first edge ≥ t_CSS (`cs_setup`), SPI mode 0 or 3 (`spi_mode`
//! otherwise; mode 3 is electrically the same here: DIN sampled on rising edges, DOUT moved on
//! falling ones).
//!
//! `begin_frame`'s word holds, clock by clock, the bit the master samples at each rising edge in the
//! frame's own mode: the part answers as sampled ([`SpiSlave::answers_as_sampled`]), and the link
//! hands its word over unshifted in mode 0 as in mode 3.
//!
//! The slave-side SPI contract hands a slave its DIN word only when the frame ends
//! ([`SpiSlave::end_frame`]), after it has answered. A conversion whose S bit and result bits fall
//! in one frame (16-bit characters with the control byte in the high byte) therefore cannot have
//! its result in that frame's answer: those bits read 0 and `adc_result_in_command_frame` says so.
//! Byte-wide characters (control byte + 3 read bytes, as both published drivers do) are exact.

use super::frame::Violations;
use super::parts::ads8344::SPI;
use super::spi_rules::SpiRules;
use super::spi_timing::SpiTiming;
use crate::bus::{FrameTiming, SpiSlave};
use crate::events::{Event, EventLog, Severity};
use crate::time::{ps_to_s, Ps};

/// The voltages on the ADC's analogue pins.
pub trait AnalogInputs {
    /// The voltage of channel `channel` (0…7) against ground at time `t`, V.
    fn volts(&mut self, channel: usize, t: Ps) -> f64;
}

/// Every input at one fixed voltage (an unconnected board: the part placed alone).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FixedInputs(pub [f64; 8]);

impl AnalogInputs for FixedInputs {
    fn volts(&mut self, channel: usize, _t: Ps) -> f64 {
        self.0[channel]
    }
}

/// The timing limits (ads8344.md; each one's source there). The SPI ones default to the part's
/// declaration ([`crate::device::parts::ads8344::SPI`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ads8344Timing {
    /// Largest DCLK frequency: 100 kHz × 24 clocks = 2.4 MHz at 5 V [unconfirmed for ADS8344:
    /// ADS8341 p. 15].
    pub max_dclk_hz: f64,
    /// Shortest acquisition, t_ACQ ≥ 1.7 µs [unconfirmed for ADS8344: ADS8345 Table VII].
    pub t_acq_min_ps: Ps,
    /// CS↓ to the first DCLK edge, t_CSS ≥ 50 ns [ADS8345 Table VII].
    pub t_css_min_ps: Ps,
    /// Internal-clock conversion time [unconfirmed: Linux waits 9 µs after the control byte; 8 µs
    /// is chosen below that].
    pub t_conv_internal_ps: Ps,
}

impl Default for Ads8344Timing {
    fn default() -> Self {
        Ads8344Timing {
            max_dclk_hz: SPI.sclk_max_hz,
            t_acq_min_ps: 1_700_000,
            t_css_min_ps: SPI.cs_setup_ps as Ps,
            t_conv_internal_ps: 8_000_000,
        }
    }
}

/// The part's configuration on its board.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ads8344Config {
    /// VREF, V (≥ 0.1 V; the data sheet says 0.5 V on p. 1 and 0.1 V on p. 12).
    pub vref_v: f64,
    /// The COM pin's voltage, V (−IN of every single-ended input).
    pub com_v: f64,
    /// PD1 PD0 = 01 selects the internal clock (possibly the data sheet's Table V) when true, an
    /// external-clock conversion with power-down when false [unconfirmed either way].
    pub pd01_internal_clock: bool,
    /// The timing limits.
    pub timing: Ads8344Timing,
}

impl Ads8344Timing {
    /// The SPI rules these limits give: the part's declaration with this DCLK limit and t_CSS.
    pub fn spi(&self) -> SpiTiming {
        SpiTiming { sclk_max_hz: self.max_dclk_hz, cs_setup_ps: self.t_css_min_ps as f64, ..SPI }
    }
}

impl Default for Ads8344Config {
    /// VREF 2.5 V with COM at ground [a board choice, unconfirmed: the paper gives no circuit].
    fn default() -> Self {
        Ads8344Config { vref_v: 2.5, com_v: 0.0, pd01_internal_clock: true, timing: Ads8344Timing::default() }
    }
}

/// A decoded control byte.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Control {
    /// The + input's channel (single-ended: the channel; differential: the + pin).
    pub plus: usize,
    /// The − input's channel, `None` for COM (single-ended).
    pub minus: Option<usize>,
    /// PD1 PD0.
    pub power_down: u8,
}

/// Table I (single-ended) and Table II (differential, + pin first) by A2A1A0.
const SINGLE: [usize; 8] = [0, 2, 4, 6, 1, 3, 5, 7];
const DIFFERENTIAL: [(usize, usize); 8] = [(0, 1), (2, 3), (4, 5), (6, 7), (1, 0), (3, 2), (5, 4), (7, 6)];

impl Control {
    /// The control byte `b` (bit 7 = S).
    pub fn decode(b: u8) -> Control {
        let a = usize::from((b >> 4) & 7);
        let (plus, minus) =
            if b & 0x04 != 0 { (SINGLE[a], None) } else { (DIFFERENTIAL[a].0, Some(DIFFERENTIAL[a].1)) };
        Control { plus, minus, power_down: b & 3 }
    }

    /// The control byte that converts single-ended channel `channel` with power-down bits `pd`.
    pub fn single_ended(channel: usize, pd: u8) -> u8 {
        let a = SINGLE.iter().position(|&c| c == channel).expect("a channel 0…7") as u8;
        0x80 | a << 4 | 0x04 | (pd & 3)
    }
}

/// One conversion, as held (kept for tests and reports).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Conversion {
    /// The hold edge.
    pub t_hold: Ps,
    /// The control byte.
    pub control: u8,
    /// The differential input voltage held, V.
    pub volts: f64,
    /// The result code.
    pub code: u16,
}

/// Where the part is in a conversion.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    /// Waiting for S.
    Idle,
    /// Control bits coming in: `n` clocks since S (S is 1), the bits so far, A0's latch time.
    Command { n: u8, byte: u8, t_a0: Ps },
    /// External clock: the result shifts out; `n` clocks since S.
    External { n: u8, code: u16 },
    /// Internal clock: converting until `done`, then `sent` of the 17 output bits shifted out.
    Internal { done: Ps, code: u16, sent: u8 },
}

/// The ADS8344 on its chip select.
pub struct Ads8344 {
    config: Ads8344Config,
    inputs: Box<dyn AnalogInputs + Send>,
    phase: Phase,
    /// Hold edge owed (mode 3: the falling edge after PD0 opens the next frame): control byte, A0 time.
    hold_pending: Option<(u8, Ps)>,
    cs_low: bool,
    cs_fell: Option<Ps>,
    frame_in_cs: u32,
    /// The answer is being worked out ahead of DIN (`begin_frame`): nothing is recorded.
    dry: bool,
    /// A control bit was latched in the frame being clocked.
    command_in_frame: bool,
    /// A hold of a control byte latched (in part) in this frame happened: what follows depends on
    /// this frame's DIN.
    held_in_frame: bool,
    /// The SPI rules of `config.timing`.
    rules: SpiRules,
    /// The shape rules the frame being clocked broke at its start (`begin_frame`).
    begun: Violations,
    events: EventLog,
    conversions: Vec<Conversion>,
}

impl std::fmt::Debug for Ads8344 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Ads8344").field("config", &self.config).field("phase", &self.phase).finish()
    }
}

impl Ads8344 {
    /// The part as placed alone by a `[[board.devices]]` table: the default configuration, its
    /// inputs unconnected (0 V) until a board drives them.
    pub fn unconnected() -> Ads8344 {
        Ads8344::new(Ads8344Config::default(), Box::new(FixedInputs([0.0; 8])))
    }

    /// The part with `config`, its channels driven by `inputs`.
    pub fn new(config: Ads8344Config, inputs: Box<dyn AnalogInputs + Send>) -> Ads8344 {
        Ads8344 {
            rules: SpiRules::new(&config.timing.spi()),
            begun: Violations::default(),
            config,
            inputs,
            phase: Phase::Idle,
            hold_pending: None,
            cs_low: false,
            cs_fell: None,
            frame_in_cs: 0,
            dry: false,
            command_in_frame: false,
            held_in_frame: false,
            events: EventLog::default(),
            conversions: Vec::new(),
        }
    }

    /// The configuration.
    pub fn config(&self) -> &Ads8344Config {
        &self.config
    }

    /// Take the events out.
    pub fn drain_events(&mut self) -> Vec<Event> {
        self.events.drain()
    }

    /// The events so far.
    pub fn events(&self) -> &EventLog {
        &self.events
    }

    /// Take the conversions held so far out.
    pub fn drain_conversions(&mut self) -> Vec<Conversion> {
        std::mem::take(&mut self.conversions)
    }

    /// The code of `volts` (differential input): straight binary, 1 LSB = VREF/65536.
    pub fn code_of(&self, volts: f64) -> (u16, bool) {
        let x = (volts / self.config.vref_v * 65536.0).floor();
        if !x.is_finite() || x < 0.0 {
            (0, true)
        } else if x > 65535.0 {
            (0xFFFF, true)
        } else {
            (x as u16, false)
        }
    }

    fn push(&mut self, e: Event) {
        if !self.dry {
            self.events.push(e);
        }
    }

    fn internal(&self, pd: u8) -> bool {
        pd == 0b10 || (pd == 0b01 && self.config.pd01_internal_clock)
    }

    /// The input held at `t` for control byte `b`: the conversion result.
    fn hold(&mut self, b: u8, t_a0: Ps, t: Ps) -> Phase {
        let c = Control::decode(b);
        let plus = self.inputs.volts(c.plus, t);
        let minus = match c.minus {
            Some(m) => self.inputs.volts(m, t),
            None => self.config.com_v,
        };
        let volts = plus - minus;
        let (code, clipped) = self.code_of(volts);
        if !volts.is_finite() {
            self.push(Event::new(t, "non_finite_input", Severity::Error, "ADS8344: a non-finite input voltage"));
        } else if clipped {
            self.push(Event::rule(
                t,
                "adc_input_out_of_range",
                Severity::Warning,
                format!("ADS8344 CH{}: {volts:.4} V outside 0…VREF = {} V: the code clips", c.plus, self.config.vref_v),
                volts,
                self.config.vref_v,
            ));
        }
        let acq = t.saturating_sub(t_a0);
        if acq < self.config.timing.t_acq_min_ps {
            self.push(Event::rule(
                t,
                "adc_acquisition_too_short",
                Severity::Error,
                format!(
                    "ADS8344: input tracked {:.3} µs from A0 to the hold edge, t_ACQ ≥ {:.3} µs (DCLK too fast)",
                    acq as f64 / 1e6,
                    self.config.timing.t_acq_min_ps as f64 / 1e6
                ),
                ps_to_s(acq),
                ps_to_s(self.config.timing.t_acq_min_ps),
            ));
        }
        if !self.dry {
            self.conversions.push(Conversion { t_hold: t, control: b, volts, code });
        }
        self.held_in_frame = self.command_in_frame;
        if self.internal(c.power_down) {
            Phase::Internal { done: t + self.config.timing.t_conv_internal_ps, code, sent: 0 }
        } else {
            Phase::External { n: 8, code }
        }
    }

    /// One DCLK: the falling edge before the rising one (mode 3) or after it (mode 0). Returns the
    /// DOUT bit the master samples at the rising edge and whether it is a result bit.
    fn clock(&mut self, din: bool, rise: Ps, half: Ps, cpol: bool) -> (bool, bool) {
        if cpol {
            self.falling(rise - half);
        }
        let (out, result_bit) = match self.phase {
            Phase::External { n, code } => match n + 1 {
                10..=25 => ((code >> (25 - (n + 1))) & 1 == 1, true),
                _ => (false, false),
            },
            Phase::Internal { done, code, sent } if rise >= done && (1..17).contains(&sent) => {
                ((code >> (16 - sent)) & 1 == 1, true)
            }
            _ => (false, false),
        };
        self.command_in_frame |= matches!(self.phase, Phase::Command { .. });
        self.phase = match self.phase {
            Phase::Idle if din => Phase::Command { n: 1, byte: 1, t_a0: 0 },
            Phase::Idle => Phase::Idle,
            Phase::Command { n, byte, t_a0 } => {
                let byte = byte << 1 | u8::from(din);
                let t_a0 = if n + 1 == 4 { rise } else { t_a0 };
                if n + 1 == 8 {
                    self.hold_pending = Some((byte, t_a0));
                    Phase::Idle // replaced at the hold edge
                } else {
                    Phase::Command { n: n + 1, byte, t_a0 }
                }
            }
            Phase::External { n, .. } if n + 1 >= 25 && din => Phase::Command { n: 1, byte: 1, t_a0: 0 },
            Phase::External { n, code } => Phase::External { n: (n + 1).min(26), code },
            Phase::Internal { done, code, sent } if rise >= done && sent < 17 => {
                Phase::Internal { done, code, sent: sent + 1 }
            }
            Phase::Internal { done, code, sent } if rise < done => {
                self.push(Event::new(
                    rise,
                    "adc_busy_read",
                    Severity::Warning,
                    "ADS8344: DCLK during an internal-clock conversion: DOUT reads 0",
                ));
                Phase::Internal { done, code, sent }
            }
            Phase::Internal { .. } if din => Phase::Command { n: 1, byte: 1, t_a0: 0 },
            p @ Phase::Internal { .. } => p,
        };
        if !cpol {
            self.falling(rise + half);
        }
        (out, result_bit)
    }

    fn falling(&mut self, t: Ps) {
        if let Some((b, t_a0)) = self.hold_pending.take() {
            self.phase = self.hold(b, t_a0, t);
        }
    }

    /// The frame's clocks with DIN `din` (right-justified, `timing.bits` of them): the DOUT word
    /// (MSB first, in the top `bits` bits of the 16) and whether a result bit followed a hold in
    /// this frame (it depends on this frame's DIN).
    fn clock_frame(&mut self, din: u16, timing: &FrameTiming) -> (u16, bool) {
        let bits = u32::from(timing.bits.clamp(1, 16));
        let half = timing.sclk_period / 2;
        let mut dout = 0u16;
        let mut depends = false;
        self.held_in_frame = false;
        self.command_in_frame = false;
        for i in 0..bits {
            // Saturating: a bit-banged frame starts with its period not yet known (`Ps::MAX`).
            let rise = timing
                .first_edge
                .saturating_add(u64::from(i).saturating_mul(timing.sclk_period))
                .saturating_add(if timing.cpol() { half } else { 0 });
            let bit = (din >> (bits - 1 - i)) & 1 == 1;
            let (out, result_bit) = self.clock(bit, rise, half, timing.cpol());
            depends |= result_bit && self.held_in_frame;
            dout |= u16::from(out) << (15 - i);
        }
        (dout, depends)
    }

    fn check_frame(&mut self, timing: &FrameTiming) {
        let t = timing.first_edge;
        let found = self.rules.shape(timing);
        self.begun = found;
        self.report_shape(timing, found);
        if self.frame_in_cs == 0 {
            if let Some(fell) = self.cs_fell.filter(|&fell| self.rules.setup_short(fell, t)) {
                let setup = t.saturating_sub(fell);
                self.push(Event::rule(
                    t,
                    "cs_setup",
                    Severity::Error,
                    format!(
                        "ADS8344: CS↓ {} ps before the first DCLK edge, t_CSS ≥ {} ns",
                        setup,
                        self.config.timing.t_css_min_ps / 1_000
                    ),
                    ps_to_s(setup),
                    ps_to_s(self.config.timing.t_css_min_ps),
                ));
            }
        }
        self.frame_in_cs += 1;
    }

    /// The events of the shape rules `found` that the frame `timing` breaks (DCLK rate, SPI mode).
    fn report_shape(&mut self, timing: &FrameTiming, found: Violations) {
        let t = timing.first_edge;
        let f = 1e12 / timing.sclk_period as f64;
        if found.contains(Violations::SCLK_TOO_FAST) {
            self.push(Event::rule(
                t,
                "sclk_too_fast",
                Severity::Error,
                format!("ADS8344: DCLK {:.3} MHz above {:.3} MHz", f / 1e6, self.config.timing.max_dclk_hz / 1e6),
                f,
                self.config.timing.max_dclk_hz,
            ));
        }
        if found.contains(Violations::SPI_MODE) {
            self.push(Event::new(
                t,
                "spi_mode",
                Severity::Error,
                format!(
                    "ADS8344: a frame in SPI mode {}: the part latches DIN on rising DCLK (mode 0 or 3)",
                    timing.mode
                ),
            ));
        }
    }
}

impl SpiSlave for Ads8344 {
    fn set_cs(&mut self, low: bool, t: Ps) {
        if low == self.cs_low {
            return;
        }
        self.cs_low = low;
        if low {
            self.cs_fell = Some(t);
            self.frame_in_cs = 0;
            return;
        }
        // CS↑: DOUT tri-states, the serial state returns to waiting for S; an internal-clock
        // conversion runs on.
        self.falling(t); // a hold owed (mode 3) happens no later than CS↑ ends the frame
        match self.phase {
            Phase::Command { n, .. } => self.aborted(t, format!("the control byte after {n} of its 8 clocks")),
            Phase::External { n, .. } if n < 25 => self.aborted(t, format!("the result after {n} of its 25 clocks")),
            _ => {}
        }
        self.phase = match self.phase {
            p @ Phase::Internal { .. } => p,
            _ => Phase::Idle,
        };
    }

    fn begin_frame(&mut self, timing: &FrameTiming) -> u16 {
        let mark = self.events.len();
        self.check_frame(timing);
        self.events.tie_to_frame(mark, timing.index);
        // The answer is worked out with DIN low throughout, recording nothing; the frame is clocked
        // for real in `end_frame`, when its DIN is known. The two agree on every bit that does not
        // follow a hold in this frame.
        let saved = (self.phase, self.hold_pending);
        self.dry = true;
        let (dout, _) = self.clock_frame(0, timing);
        self.dry = false;
        (self.phase, self.hold_pending) = saved;
        dout
    }

    fn end_frame(&mut self, din: u16, timing: &FrameTiming) {
        let mark = self.events.len();
        let (_, depends) = self.clock_frame(din, timing);
        if depends {
            self.push(Event::new(
                timing.first_edge,
                "adc_result_in_command_frame",
                Severity::Warning,
                "ADS8344: a result bit fell in the frame that carried its start bit: the word-level link \
                 answers before it hands DIN over, so those bits read 0 (use 8-bit characters)",
            ));
        }
        self.events.tie_to_frame(mark, timing.index);
    }
    /// The measured DCLK rate and mode against the same rules as any frame's (`SpiRules::shape`),
    /// each broken rule reported once per frame.
    fn bitbanged_shape(&mut self, timing: &FrameTiming) {
        let found = Violations(self.rules.shape(timing).0 & !self.begun.0);
        if !found.is_empty() {
            let mark = self.events.len();
            self.report_shape(timing, found);
            self.events.tie_to_frame(mark, timing.index);
            self.begun.insert(found);
        }
    }
    /// `clock` gives the bit the master samples at each rising edge in the frame's own mode.
    fn answers_as_sampled(&self) -> bool {
        true
    }
    fn drain_events(&mut self) -> Vec<Event> {
        Ads8344::drain_events(self)
    }
}

impl Ads8344 {
    fn aborted(&mut self, t: Ps, what: String) {
        self.push(Event::new(
            t,
            "adc_conversion_aborted",
            Severity::Warning,
            format!("ADS8344: CS↑ cut {what} short: no result"),
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::board::links::{known_parts, BoardLinks};
    use crate::bus::{Address, BusLevel, ChipSelects, Device, Link, LinkRecord, SpiLink, SpiSlave};
    use crate::profile::{link_kind, LinkKind, Profile};

    /// A frame of `bits` clocks of `period` ps, its first edge at `first`, SPI mode `mode`.
    fn frame(first: Ps, period: Ps, bits: u8, mode: u8) -> FrameTiming {
        let last = first + (2 * u64::from(bits) - 1) * period / 2;
        FrameTiming { index: 0, first_edge: first, last_edge: last, sclk_period: period, bits, mode }
    }

    /// Clock `words` of `bits` each in one CS-low window starting at `t` with frames `gap` apart;
    /// returns the master's words (the top `bits` of each answer) and the time after CS↑.
    fn window(adc: &mut Ads8344, words: &[u16], bits: u8, period: Ps, mode: u8, t: Ps) -> (Vec<u16>, Ps) {
        adc.set_cs(true, t);
        let mut now = t + 1_000_000;
        let mut rx = Vec::new();
        for &w in words {
            let f = frame(now, period, bits, mode);
            rx.push(adc.begin_frame(&f) >> (16 - bits));
            adc.end_frame(w, &f);
            now = f.last_edge + 2 * period;
        }
        adc.set_cs(false, now + 1_000_000);
        (rx, now + 2_000_000)
    }

    /// A bit-banged frame (`board::bitbang`) starts with its SCLK period unknown (`Ps::MAX`) and
    /// is checked at its end against the measured one by the same rules: 16 cycles of 1 µs
    /// (1 MHz ≤ 2.4 MHz) raise nothing; with a shortest cycle of 200 ns (5 MHz) the part's own
    /// `sclk_too_fast`, once, tied to the frame.
    #[test]
    fn a_bitbanged_frame_is_checked_at_its_end() {
        for (period, kinds) in [(1_000_000, vec![]), (200_000, vec!["sclk_too_fast"])] {
            let mut adc = Ads8344::unconnected();
            adc.set_cs(true, 0);
            let start = FrameTiming {
                index: 4,
                first_edge: 1_000_000,
                last_edge: 1_000_000,
                sclk_period: Ps::MAX,
                bits: 16,
                mode: 0,
            };
            adc.begin_frame(&start);
            assert!(adc.drain_events().is_empty(), "the start knows no period yet");
            let measured = FrameTiming { last_edge: 1_000_000 + 31 * period / 2, sclk_period: period, ..start };
            adc.bitbanged_shape(&measured);
            adc.bitbanged_shape(&measured);
            adc.end_frame(0, &measured);
            let events = adc.drain_events();
            assert_eq!(events.iter().map(|e| e.kind).collect::<Vec<_>>(), kinds, "{events:?}");
            if let Some(e) = events.first() {
                assert_eq!((e.measured, e.required), (Some(5e6), Some(2.4e6)));
                assert_eq!(e.frame, Some(4));
            }
        }
    }

    /// Eight channels at distinct voltages: 0.1 V + 0.25 V·channel.
    fn ramp() -> Box<FixedInputs> {
        Box::new(FixedInputs(std::array::from_fn(|c| 0.1 + 0.25 * c as f64)))
    }

    const P: Ps = 426_667; // SPIBRR = 15 at LSPCLK 37.5 MHz: 2.34 MHz

    /// Table I: the single-ended A2A1A0 order 000 CH0, 100 CH1, 001 CH2, … 111 CH7 (not binary);
    /// Table II: the differential pairs.
    #[test]
    fn control_byte_tables() {
        let a = |ch: usize| (Control::single_ended(ch, 3) >> 4) & 7;
        assert_eq!([0, 1, 2, 3, 4, 5, 6, 7].map(a), [0b000, 0b100, 0b001, 0b101, 0b010, 0b110, 0b011, 0b111]);
        assert_eq!(Control::decode(0x80 | 0b101 << 4 | 0x04 | 3), Control { plus: 3, minus: None, power_down: 3 });
        assert_eq!(Control::decode(0x80 | 0b001 << 4 | 2), Control { plus: 2, minus: Some(3), power_down: 2 });
        assert_eq!(Control::decode(0x80 | 0b111 << 4), Control { plus: 7, minus: Some(6), power_down: 0 });
    }

    /// Straight binary, 1 LSB = VREF/65536, clipped outside 0…VREF − 1 LSB.
    #[test]
    fn quantisation() {
        let adc = Ads8344::new(Ads8344Config::default(), ramp());
        let lsb = 2.5 / 65536.0;
        assert_eq!(adc.code_of(1.25), (32768, false));
        assert_eq!(adc.code_of(1.25 - 0.5 * lsb), (32767, false));
        assert_eq!(adc.code_of(2.5 - lsb), (0xFFFF, false));
        assert_eq!(adc.code_of(2.5), (0xFFFF, true));
        assert_eq!(adc.code_of(-1e-9), (0, true));
        assert_eq!(adc.code_of(f64::NAN), (0, true));
    }

    /// Byte-wide, external clock (PD = 11), both SPI modes 0 and 3: control + 3 bytes give
    /// result = b1<<9 | b2<<1 | b3>>7 (the drivers' formula) for every channel, no event. Then the
    /// 24-clock overlap: the 4th byte carries the next control byte's S at clock 25.
    #[test]
    fn byte_wide_conversions_of_each_channel() {
        for mode in [0, 3] {
            let mut adc = Ads8344::new(Ads8344Config::default(), ramp());
            let mut t = 0;
            for ch in 0..8 {
                let (rx, next) = window(&mut adc, &[u16::from(Control::single_ended(ch, 3)), 0, 0, 0], 8, P, mode, t);
                t = next;
                let code = rx[1] << 9 | rx[2] << 1 | rx[3] >> 7;
                let expected = adc.code_of(0.1 + 0.25 * ch as f64).0;
                assert_eq!((rx[0], code), (0, expected), "mode {mode} CH{ch}");
            }
            assert!(adc.events().events().is_empty(), "{:?}", adc.events().events());
            // Overlap: byte 4 = next S at clock 25 (bit 7 of the byte); 3 more bytes read it.
            let c5 = u16::from(Control::single_ended(5, 3));
            let c6 = u16::from(Control::single_ended(6, 3));
            let (rx, _) = window(&mut adc, &[c5, 0, 0, c6, 0, 0, 0], 8, P, mode, t);
            assert_eq!(rx[1] << 9 | rx[2] << 1 | rx[3] >> 7, adc.code_of(1.35).0);
            assert_eq!(rx[4] << 9 | rx[5] << 1 | rx[6] >> 7, adc.code_of(1.6).0);
            assert!(adc.events().events().is_empty());
        }
    }

    /// Differential CH4+/CH5−: (V4 − V5) < 0 clips to 0 with an event; CH5+/CH4− reads 0.25 V.
    #[test]
    fn differential_pairs() {
        let mut adc = Ads8344::new(Ads8344Config::default(), ramp());
        let (rx, t) = window(&mut adc, &[0x80 | 0b010 << 4 | 3, 0, 0, 0], 8, P, 0, 0);
        assert_eq!(rx[1] << 9 | rx[2] << 1 | rx[3] >> 7, 0);
        assert_eq!(adc.drain_events()[0].kind, "adc_input_out_of_range");
        let (rx, _) = window(&mut adc, &[0x80 | 0b110 << 4 | 3, 0, 0, 0], 8, P, 0, t);
        assert_eq!(rx[1] << 9 | rx[2] << 1 | rx[3] >> 7, adc.code_of(0.25).0);
    }

    /// 16-bit characters, control byte in the high byte: the second frame carries D8…D0 in bits
    /// 15:7; the first frame's low byte (null + D15…D9) cannot be answered at word level: it reads 0
    /// with an `adc_result_in_command_frame` event (the module's note).
    #[test]
    fn sixteen_bit_characters() {
        let mut adc = Ads8344::new(Ads8344Config::default(), ramp());
        let (rx, _) = window(&mut adc, &[u16::from(Control::single_ended(7, 3)) << 8, 0], 16, P, 3, 0);
        let code = adc.code_of(1.85).0;
        assert_eq!((rx[0], rx[1] >> 7), (0, code & 0x1FF));
        let e = adc.drain_events();
        assert_eq!(e.iter().map(|e| e.kind).collect::<Vec<_>>(), ["adc_result_in_command_frame"]);
        assert_eq!(adc.drain_conversions()[0].code, code);
    }

    /// Timing rules: DCLK 3.75 MHz (SPIBRR = 9) is above 2.4 MHz and leaves 4.5 clocks = 1.2 µs of
    /// acquisition (< 1.7 µs); CS↓ 20 ns before the first edge breaks t_CSS; SPI mode 1 is flagged;
    /// CS↑ after two bytes aborts the conversion.
    #[test]
    fn timing_rules() {
        let mut adc = Ads8344::new(Ads8344Config::default(), ramp());
        window(&mut adc, &[0x87, 0, 0, 0], 8, 266_667, 0, 0);
        let kinds: Vec<_> = adc.drain_events().iter().map(|e| e.kind).collect();
        assert_eq!(kinds.iter().filter(|k| **k == "sclk_too_fast").count(), 4);
        assert!(kinds.contains(&"adc_acquisition_too_short"), "{kinds:?}");
        // At 2.34 MHz the acquisition is 4.5 × 426.7 ns = 1.92 µs: clean (checked above too).
        adc.set_cs(true, 100_000_000);
        let f = frame(100_020_000, P, 8, 1);
        adc.begin_frame(&f);
        adc.end_frame(0x87, &f);
        let f2 = frame(f.last_edge + P, P, 8, 1);
        adc.begin_frame(&f2);
        adc.end_frame(0, &f2);
        adc.set_cs(false, f2.last_edge + P);
        let events = adc.drain_events();
        let kinds: Vec<_> = events.iter().map(|e| e.kind).collect();
        assert_eq!(kinds, ["spi_mode", "cs_setup", "spi_mode", "adc_conversion_aborted"]);
        // The message states the declared t_CSS.
        assert_eq!(events[1].message, "ADS8344: CS↓ 20000 ps before the first DCLK edge, t_CSS ≥ 50 ns");
    }

    /// Internal clock (PD = 10): the control byte alone, CS↑, then 3 bytes after the conversion
    /// (t_conv = 8 µs; Linux waits 9 µs) read null + D15…D0; reading at once reads 0 with
    /// `adc_busy_read`. PD = 01 is the internal clock too by default, the external clock when the
    /// option says so.
    #[test]
    fn internal_clock_mode() {
        for pd in [0b10, 0b01] {
            let mut adc = Ads8344::new(Ads8344Config::default(), ramp());
            let c = u16::from(Control::single_ended(3, pd));
            let (_, t) = window(&mut adc, &[c], 8, P, 0, 0);
            let (rx, t) = window(&mut adc, &[0, 0, 0], 8, P, 0, t + 9_000_000);
            assert_eq!(rx[0] << 9 | rx[1] << 1 | rx[2] >> 7, adc.code_of(0.85).0);
            assert!(adc.drain_events().is_empty());
            window(&mut adc, &[c, 0, 0, 0], 8, P, 0, t);
            assert!(adc.drain_events().iter().all(|e| e.kind == "adc_busy_read"));
        }
        let config = Ads8344Config { pd01_internal_clock: false, ..Ads8344Config::default() };
        let mut adc = Ads8344::new(config, ramp());
        let (rx, _) = window(&mut adc, &[u16::from(Control::single_ended(3, 1)), 0, 0, 0], 8, P, 0, 0);
        assert_eq!(rx[1] << 9 | rx[2] << 1 | rx[3] >> 7, adc.code_of(0.85).0);
    }

    /// Placed by a `[[board.devices]]` table on SPI-A's GPIO58 (8-bit characters, mode 3, SPIBRR = 15) and
    /// driven through the generic `Link` driver (SPITXBUF left-justified: the control byte in bits
    /// 15:8; SPIRXBUF right-justified): each channel's code comes back; the crate's
    /// catalogue knows the part (its inputs unconnected: 0 V).
    #[test]
    fn placed_on_spi_a_by_the_profile() {
        let text = "[[board.devices]]\npart = \"ADIS16407\"\nlink = \"spi-a\"\nchip_select = \"GPIO57\"\n\n\
                    [[board.devices]]\npart = \"ADS8344\"\nlink = \"spi-a\"\nchip_select = \"GPIO58\"\n";
        let mut profile = Profile::from_toml(text, "geomag.toml", &[]).unwrap();
        // 8-bit characters: the profile's own check still ties SPICHAR to the `[device]` ADIS part
        // (16-bit), so the registers are set past it here.
        (profile.spi.spiccr, profile.spi.spibrr) = (0x00C7, 15);
        let catalogue = |name: &str, _kind: &LinkKind| {
            (name == "ADS8344").then(|| {
                Ok(Device::new::<dyn SpiSlave + Send>(Box::new(Ads8344::new(Ads8344Config::default(), ramp()))))
            })
        };
        let mut links = BoardLinks::from_profile(&profile, &catalogue, true).unwrap();
        let spi = links.link("spi-a").unwrap();
        let mut t = 0;
        for ch in 0..8 {
            let mut rx = [0u16; 4];
            let tr = spi.transfer(
                Address::ChipSelect(58),
                &[u16::from(Control::single_ended(ch, 3)) << 8, 0, 0, 0],
                &mut rx,
                t,
            );
            t = tr.unwrap().end + 1_000_000;
            let adc = Ads8344::new(Ads8344Config::default(), ramp());
            assert_eq!(rx[1] << 9 | rx[2] << 1 | rx[3] >> 7, adc.code_of(0.1 + 0.25 * ch as f64).0, "CH{ch}");
        }
        assert!(spi.drain_events().is_empty());
        let (spi, i2c) = (link_kind("spi-a").unwrap(), link_kind("i2c-a").unwrap());
        assert!(matches!(known_parts("ADS8344", spi), Some(Ok(d)) if d.is::<dyn SpiSlave + Send>()));
        assert!(matches!(known_parts("ADS8344", i2c), Some(Err(_))));
    }

    /// CH0–CH6 at 0.1 V + 0.25 V·channel, CH7 tied to VREF/2 (1.25 V: code 32768), as the board wires it.
    fn check_inputs() -> Box<FixedInputs> {
        Box::new(FixedInputs(std::array::from_fn(|c| if c == 7 { 1.25 } else { 0.1 + 0.25 * c as f64 })))
    }

    /// The eight channels read through SPI-A at `level` with SPICCR `spiccr` and SPICTL `spictl` (8-bit
    /// characters, SPIBRR = 15) by the generic driver: the codes, the link's log (every frame's
    /// words and the times the part was shown) and the events.
    fn read_through_the_link(spiccr: u32, spictl: u32, level: BusLevel) -> ([u16; 8], Vec<LinkRecord>, Vec<Event>) {
        let text = "[[board.devices]]\npart = \"ADIS16407\"\nlink = \"spi-a\"\nchip_select = \"GPIO57\"\n\n\
                    [[board.devices]]\npart = \"ADS8344\"\nlink = \"spi-a\"\nchip_select = \"GPIO58\"\n";
        let mut profile = Profile::from_toml(text, "geomag.toml", &[]).unwrap();
        (profile.spi.spiccr, profile.spi.spictl, profile.spi.spibrr, profile.spi.level) = (spiccr, spictl, 15, level);
        let adc: Box<dyn SpiSlave + Send> = Box::new(Ads8344::new(Ads8344Config::default(), check_inputs()));
        let mut spi = SpiLink::from_profile(&profile, ChipSelects::new(vec![(58, adc)])).unwrap();
        spi.init_from_profile(&profile.spi, 0).unwrap();
        let spi = &mut spi;
        spi.enable_log();
        let (mut codes, mut t) = ([0u16; 8], 0);
        for (ch, code) in codes.iter_mut().enumerate() {
            let mut rx = [0u16; 4];
            let c = u16::from(Control::single_ended(ch, 3)) << 8;
            t = Link::transfer(spi, Address::ChipSelect(58), &[c, 0, 0, 0], &mut rx, t).unwrap().end + 1_000_000;
            *code = rx[1] << 9 | rx[2] << 1 | rx[3] >> 7;
        }
        let log = spi.take_log();
        (codes, log, Link::drain_events(spi))
    }

    /// SPI mode 0 (the data sheet's drawing: SPICCR 0x87, CLKPOLARITY 0; SPICTL 0x0F, CLK_PHASE 1,
    /// TI's "rising edge with delay") and mode 3 (SPICCR 0xC7, SPICTL 0x07) read every channel's code
    /// at both link levels: CH7 at VREF/2 reads 32768. The part works out the bit the master samples
    /// at each clock in the frame's own mode, and the link keeps its word as it is (it read CH7 as
    /// 16384 in mode 0 when the link also applied the ADIS16xxx's falling-edge shift). The two
    /// levels agree frame for frame: words and the times shown to the part.
    #[test]
    fn modes_0_and_3_read_the_codes_at_both_link_levels() {
        let expected: [u16; 8] = std::array::from_fn(|c| {
            Ads8344::new(Ads8344Config::default(), check_inputs())
                .code_of(if c == 7 { 1.25 } else { 0.1 + 0.25 * c as f64 })
                .0
        });
        assert_eq!(expected[7], 32768);
        for (mode, spiccr, spictl) in [(0, 0x87, 0x0F), (3, 0xC7, 0x07)] {
            let (codes, log, events) = read_through_the_link(spiccr, spictl, BusLevel::Transaction);
            assert_eq!(codes, expected, "mode {mode}, transaction level");
            assert!(events.is_empty(), "mode {mode}: {events:?}");
            let frames = log.iter().filter_map(|r| if let LinkRecord::Frame(f) = r { Some(f) } else { None });
            assert!(frames.clone().all(|f| f.timing.mode == mode), "mode {mode}");
            assert_eq!(frames.count(), 32);
            let (bit_codes, bit_log, bit_events) = read_through_the_link(spiccr, spictl, BusLevel::Bit);
            assert_eq!(bit_codes, expected, "mode {mode}, bit level");
            assert_eq!(bit_log, log, "mode {mode}: the levels agree word for word and time for time");
            assert!(bit_events.is_empty(), "mode {mode}: {bit_events:?}");
        }
    }
}
