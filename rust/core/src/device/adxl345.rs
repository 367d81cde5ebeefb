//! ADXL345 (Analog Devices 3-axis digital accelerometer) as an SPI part: the gyro-free board's seven
//! accelerometers. Every fact is from `adxl345.md` (data sheet Rev. E pp. 14–33 as read, Linux
//! `adxl34x.c`/`adxl34x-spi.c`, i2cdevlib); what that sheet marks [unconfirmed] is marked here too.
//!
//! - **Register map as data** ([`REGISTERS`]): name, address, access, reset value, bit fields (the
//!   [`Field`]s and [`Access`] of the ADIS declarations; the ADXL345's registers are 8 bits wide).
//! - **SPI** (p. 15): mode 3; the first byte of a CS-low window is the command, bit 7 R/W (1 = read),
//!   bit 6 MB (1 = the address steps after each byte), bits 5:0 the address; data or dummy bytes follow.
//!   The part is clocked in 8-bit frames (the byte is the left-justified character of the master's
//!   16-bit shift register, DIN right-justified: `bus::transaction`). Timing rules of Table 10 are
//!   checked per frame and chip-select edge: f_SCLK ≤ 5 MHz (`sclk_too_fast`), tDELAY ≥ 5 ns
//!   (`cs_setup`), tQUIET ≥ 5 ns (`cs_hold`), tCS,DIS ≥ 150 ns (`cs_high_too_short`), mode 3
//!   (`spi_mode`), 8 SCLK cycles (`byte_frame_length`).
//! - **Output data rate** 3200/2^(15−code) Hz from BW_RATE (Table 7; bandwidth ODR/2), samples taken
//!   from 1.1 ms + 1/ODR after the measure bit is set [unconfirmed turn-on] at the stimulus's value
//!   at the sample instant (the part's own anti-alias filter is not modelled).
//! - **Encodings** (DATA_FORMAT): 10-bit (3.9·2^range mg/LSB) or full resolution (3.9 mg/LSB,
//!   10…13 bits), right-justified sign-extended or left-justified; the LSB is 0 at 1600/3200 Hz in
//!   full resolution or ±2 g 10-bit (p. 32). Offsets OFSX/Y/Z, 15.6 mg/LSB, are added to the output.
//! - **FIFO** (32 entries): bypass, FIFO, stream, trigger; the data registers show the oldest entry,
//!   and the end of a data read (the address step 0x37 → 0x38 or CS↑) pops it. The next read of the
//!   data registers or FIFO_STATUS must come ≥ 5 µs after the pop (`fifo_pop_too_soon`; the
//!   consequence is [unconfirmed]: the model reports it and reads on).
//! - **Errors** ([`ErrorPreset`]): the `adxl345` preset's offsets, sensitivities and noise, each
//!   value with its source.
//!
//! Not modelled: tap, activity, free-fall detection (their registers store what is written), the
//! interrupt pins, 3-wire SPI, I²C on this part, self-test's deflection.

use super::frame::Violations;
use super::parts::adxl345::SPI;
use super::spi_rules::SpiRules;
use crate::bus::{FrameTiming, SpiSlave};
use crate::device::part::{f, Access, Field};
use crate::events::{Event, EventLog, Severity};
use crate::time::Ps;
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use rand_xoshiro::Xoshiro256PlusPlus;
use std::collections::VecDeque;

/// One 8-bit register of the map.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RegisterDef {
    /// Data-sheet name.
    pub name: &'static str,
    /// Address (6 bits).
    pub addr: u8,
    /// SPI access.
    pub access: Access,
    /// Value after power-on.
    pub reset: u8,
    /// Whether the reset value has a source (false: [unconfirmed], Table 19 was not retrievable).
    pub reset_sourced: bool,
    /// The bit fields.
    pub fields: &'static [Field],
}

const fn r(
    name: &'static str,
    addr: u8,
    access: Access,
    reset: u8,
    sourced: bool,
    fields: &'static [Field],
) -> RegisterDef {
    RegisterDef { name, addr, access, reset, reset_sourced: sourced, fields }
}

use Access::{R, RW};
const D8: &[Field] = &[f("data", 0, 8)];
const INT_BITS: &[Field] = &[
    f("DATA_READY", 7, 1),
    f("SINGLE_TAP", 6, 1),
    f("DOUBLE_TAP", 5, 1),
    f("Activity", 4, 1),
    f("Inactivity", 3, 1),
    f("FREE_FALL", 2, 1),
    f("Watermark", 1, 1),
    f("Overrun", 0, 1),
];

/// The register map (adxl345.md "Register map"; 0x01…0x1C are reserved).
pub const REGISTERS: [RegisterDef; 30] = [
    r("DEVID", 0x00, R, 0xE5, true, D8),
    r("THRESH_TAP", 0x1D, RW, 0, false, D8),
    r("OFSX", 0x1E, RW, 0, false, D8),
    r("OFSY", 0x1F, RW, 0, false, D8),
    r("OFSZ", 0x20, RW, 0, false, D8),
    r("DUR", 0x21, RW, 0, false, D8),
    r("LATENT", 0x22, RW, 0, false, D8),
    r("WINDOW", 0x23, RW, 0, false, D8),
    r("THRESH_ACT", 0x24, RW, 0, false, D8),
    r("THRESH_INACT", 0x25, RW, 0, false, D8),
    r("TIME_INACT", 0x26, RW, 0, false, D8),
    r(
        "ACT_INACT_CTL",
        0x27,
        RW,
        0,
        false,
        &[f("ACT_ac_dc", 7, 1), f("ACT_enable", 4, 3), f("INACT_ac_dc", 3, 1), f("INACT_enable", 0, 3)],
    ),
    r("THRESH_FF", 0x28, RW, 0, false, D8),
    r("TIME_FF", 0x29, RW, 0, false, D8),
    r("TAP_AXES", 0x2A, RW, 0, false, &[f("Suppress", 3, 1), f("TAP_enable", 0, 3)]),
    r("ACT_TAP_STATUS", 0x2B, R, 0, false, &[f("ACT_source", 4, 3), f("Asleep", 3, 1), f("TAP_source", 0, 3)]),
    r("BW_RATE", 0x2C, RW, 0x0A, true, &[f("LOW_POWER", 4, 1), f("Rate", 0, 4)]),
    r(
        "POWER_CTL",
        0x2D,
        RW,
        0,
        true,
        &[f("Link", 5, 1), f("AUTO_SLEEP", 4, 1), f("Measure", 3, 1), f("Sleep", 2, 1), f("Wakeup", 0, 2)],
    ),
    r("INT_ENABLE", 0x2E, RW, 0, false, INT_BITS),
    r("INT_MAP", 0x2F, RW, 0, false, INT_BITS),
    r("INT_SOURCE", 0x30, R, 0x02, false, INT_BITS),
    r(
        "DATA_FORMAT",
        0x31,
        RW,
        0,
        false,
        &[
            f("SELF_TEST", 7, 1),
            f("SPI", 6, 1),
            f("INT_INVERT", 5, 1),
            f("FULL_RES", 3, 1),
            f("Justify", 2, 1),
            f("Range", 0, 2),
        ],
    ),
    r("DATAX0", 0x32, R, 0, true, D8),
    r("DATAX1", 0x33, R, 0, true, D8),
    r("DATAY0", 0x34, R, 0, true, D8),
    r("DATAY1", 0x35, R, 0, true, D8),
    r("DATAZ0", 0x36, R, 0, true, D8),
    r("DATAZ1", 0x37, R, 0, true, D8),
    r("FIFO_CTL", 0x38, RW, 0, false, &[f("FIFO_MODE", 6, 2), f("Trigger", 5, 1), f("Samples", 0, 5)]),
    r("FIFO_STATUS", 0x39, R, 0, false, &[f("FIFO_TRIG", 7, 1), f("Entries", 0, 6)]),
];

/// The register at `addr`, if any.
pub fn register(addr: u8) -> Option<&'static RegisterDef> {
    REGISTERS.iter().find(|r| r.addr == addr)
}

/// The register called `name` (case-insensitive).
pub fn register_named(name: &str) -> Option<&'static RegisterDef> {
    REGISTERS.iter().find(|r| r.name.eq_ignore_ascii_case(name))
}

const DATAX0: u8 = 0x32;
const DATAZ1: u8 = 0x37;
const BW_RATE: u8 = 0x2C;
const POWER_CTL: u8 = 0x2D;
const INT_SOURCE: u8 = 0x30;
const DATA_FORMAT: u8 = 0x31;
const FIFO_CTL: u8 = 0x38;
const FIFO_STATUS: u8 = 0x39;

/// SPI facts of Table 10 and p. 15: the timing is the part's declaration
/// ([`crate::device::parts::adxl345::SPI`]), named here as whole picoseconds.
pub mod spi {
    use crate::device::parts::adxl345::SPI;
    use crate::time::Ps;
    /// SPI mode (CPOL = 1, CPHA = 1).
    pub const MODE: u8 = SPI.modes[0];
    /// Command bit 7: read.
    pub const READ: u8 = 0x80;
    /// Command bit 6: multi-byte (the address steps).
    pub const MULTI_BYTE: u8 = 0x40;
    /// Shortest SCLK period (f_SCLK ≤ 5 MHz), ps.
    pub const T_SCLK_MIN: Ps = SPI.min_sclk_period_ps() as Ps;
    /// tDELAY: CS↓ to the first SCLK edge, ps.
    pub const T_DELAY: Ps = SPI.cs_setup_ps as Ps;
    /// tQUIET: the last SCLK edge to CS↑, ps.
    pub const T_QUIET: Ps = whole(SPI.cs_hold_ps);
    /// tCS,DIS: CS high between two communications, ps.
    pub const T_CS_DIS: Ps = whole(SPI.cs_high_min_ps);

    /// A declared minimum as whole ps (the part declares both).
    const fn whole(ps: Option<f64>) -> Ps {
        match ps {
            Some(t) => t as Ps,
            None => 0,
        }
    }
    /// Time from the end of a data read (the FIFO pop) to the next read of the FIFO or
    /// FIFO_STATUS, ps (Linux adxl34x.c quoting the data sheet).
    pub const T_FIFO_POP: Ps = 5_000_000;
}

/// Turn-on time before the first sample after the measure bit is set, ps ([unconfirmed]: ≈ 1.1 ms
/// + 1/ODR, adxl345.md "Noise, offset, self-test").
pub const TURN_ON_PS: Ps = 1_100_000_000;

/// FIFO depth (entries).
pub const FIFO_DEPTH: usize = 32;

/// Typical sensitivity in full resolution (and ±2 g 10-bit): 256 LSB/g, i.e. 3.9 mg/LSB.
pub const LSB_G: f64 = 1.0 / 256.0;

/// OFSX/Y/Z scale: 15.6 mg/LSB (0x7F = 2 g), i.e. four full-resolution LSBs.
pub const OFFSET_LSB_G: f64 = 4.0 / 256.0;

/// The output data rate of BW_RATE's rate code (Table 7: 3200 Hz at 0b1111, halving per step).
pub fn odr_hz(code: u8) -> f64 {
    3200.0 / f64::from(1u32 << (15 - u32::from(code & 0x0F)))
}

/// The sample period of rate code `code`, ps (exact: 312.5 µs · 2^(15−code)).
pub fn period_ps(code: u8) -> Ps {
    312_500_000 << (15 - u32::from(code & 0x0F))
}

/// The output bandwidth of rate code `code` (Table 7: ODR/2), Hz.
pub fn bandwidth_hz(code: u8) -> f64 {
    odr_hz(code) / 2.0
}

/// How DATA_FORMAT encodes an acceleration: (bits, g per LSB).
pub fn resolution(data_format: u8) -> (u32, f64) {
    let range = u32::from(data_format & 0x03);
    if data_format & 0x08 != 0 {
        (10 + range, LSB_G)
    } else {
        (10, LSB_G * f64::from(1u32 << range))
    }
}

/// The 16-bit DATAx word of `accel_g` under DATA_FORMAT `data_format` at rate code `rate`: the code
/// rounded and clipped to the resolution's bits, its LSB cleared where p. 32 says it is always 0,
/// right-justified with sign extension or left-justified (Justify = 1).
pub fn encode(accel_g: f64, data_format: u8, rate: u8) -> u16 {
    let (bits, lsb) = resolution(data_format);
    let (lo, hi) = (-(1i32 << (bits - 1)), (1i32 << (bits - 1)) - 1);
    let mut code = ((accel_g / lsb).round() as i32).clamp(lo, hi);
    let full_res = data_format & 0x08 != 0;
    if (rate & 0x0F) >= 0x0E && (full_res || data_format & 0x03 == 0) {
        code &= !1;
    }
    if data_format & 0x04 != 0 {
        ((code as u32) << (16 - bits)) as u16
    } else {
        code as i16 as u16
    }
}

/// The FIFO's mode (FIFO_CTL[7:6]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FifoMode {
    /// 00: the FIFO is not used; the data registers hold the latest sample.
    Bypass,
    /// 01: collects up to 32 entries, then stops.
    Fifo,
    /// 10: keeps the latest 32 entries.
    Stream,
    /// 11: as stream until a trigger, then keeps the last `samples` entries and collects as FIFO.
    Trigger,
}

impl FifoMode {
    /// The mode of a FIFO_CTL value.
    pub fn of(fifo_ctl: u8) -> FifoMode {
        [FifoMode::Bypass, FifoMode::Fifo, FifoMode::Stream, FifoMode::Trigger][usize::from(fifo_ctl >> 6)]
    }
}

/// The part's errors: fixed per unit (offset, sensitivity) and white noise per sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorPreset {
    /// Preset name.
    pub name: &'static str,
    /// 1σ of the 0 g offset per axis, g ([unconfirmed]: Table 1 as recollected, X/Y ±40 mg, Z ±80 mg
    /// typical, taken as 1σ).
    pub offset_sigma_g: [f64; 3],
    /// 1σ of the relative sensitivity error (Table 1's distributor copy: 230…282 LSB/g around 256 at
    /// ±2 g, taken as ±3σ: 26/256/3).
    pub scale_sigma: f64,
    /// Noise at ODR ≤ 100 Hz, LSB rms of 3.9 mg, per axis (p. 33: 400 Hz X/Y < 1.5, Z < 2.2 LSB, halved).
    pub noise_lsb_100hz: [f64; 3],
    /// Noise factor in low-power mode (p. 33: X/Y 1.8 against 1.5, Z 2.6 against 2.2 at 400 Hz).
    pub low_power_factor: [f64; 3],
}

/// The presets: `ideal` (no error) and `adxl345`.
pub const PRESETS: [ErrorPreset; 2] = [
    ErrorPreset {
        name: "ideal",
        offset_sigma_g: [0.0; 3],
        scale_sigma: 0.0,
        noise_lsb_100hz: [0.0; 3],
        low_power_factor: [1.0; 3],
    },
    ErrorPreset {
        name: "adxl345",
        offset_sigma_g: [0.040, 0.040, 0.080],
        scale_sigma: 26.0 / 256.0 / 3.0,
        noise_lsb_100hz: [0.75, 0.75, 1.1],
        low_power_factor: [1.8 / 1.5, 1.8 / 1.5, 2.6 / 2.2],
    },
];

impl ErrorPreset {
    /// The preset called `name`.
    pub fn by_name(name: &str) -> Option<&'static ErrorPreset> {
        PRESETS.iter().find(|p| p.name.eq_ignore_ascii_case(name))
    }

    /// Noise 1σ per axis at rate code `rate`, g: the 100 Hz figure up to 100 Hz, ×√2 per doubling
    /// above (p. 33), times the low-power factor.
    pub fn noise_sigma_g(&self, rate: u8, low_power: bool) -> [f64; 3] {
        let growth = (odr_hz(rate) / 100.0).max(1.0).sqrt();
        std::array::from_fn(|i| {
            let lp = if low_power { self.low_power_factor[i] } else { 1.0 };
            self.noise_lsb_100hz[i] * growth * lp * LSB_G
        })
    }
}

/// One unit's drawn errors and its noise stream.
#[derive(Debug, Clone)]
pub struct UnitErrors {
    preset: ErrorPreset,
    /// The unit's offsets, g.
    pub offset_g: [f64; 3],
    /// The unit's relative sensitivity errors.
    pub scale: [f64; 3],
    rng: Xoshiro256PlusPlus,
}

impl UnitErrors {
    /// A unit of `preset` drawn from `seed` (the same seed, the same unit and noise).
    pub fn draw(preset: &ErrorPreset, seed: u64) -> UnitErrors {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let mut n = || rng.sample::<f64, _>(StandardNormal);
        let offset_g = std::array::from_fn(|i| preset.offset_sigma_g[i] * n());
        let scale = std::array::from_fn(|_| preset.scale_sigma * n());
        UnitErrors { preset: *preset, offset_g, scale, rng }
    }

    fn apply(&mut self, a: [f64; 3], rate: u8, low_power: bool) -> [f64; 3] {
        let sigma = self.preset.noise_sigma_g(rate, low_power);
        std::array::from_fn(|i| {
            let noise = if sigma[i] > 0.0 { sigma[i] * self.rng.sample::<f64, _>(StandardNormal) } else { 0.0 };
            a[i] * (1.0 + self.scale[i]) + self.offset_g[i] + noise
        })
    }
}

/// The specific force the part feels at a time, g (x, y, z of the part).
pub type Stimulus = Box<dyn FnMut(Ps) -> [f64; 3] + Send>;

/// Where the SPI protocol is in the current CS-low window.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    /// CS high.
    Idle,
    /// The next byte is the command.
    Command,
    /// Reading from `addr` (stepping when `mb`).
    Read { addr: u8, mb: bool },
    /// Writing to `addr`.
    Write { addr: u8, mb: bool },
}

/// One ADXL345.
pub struct Adxl345 {
    regs: [u8; 64],
    stimulus: Stimulus,
    errors: UnitErrors,
    /// The next sample's time (None: standby).
    next_sample: Option<Ps>,
    /// The latest sample (bypass), g, after errors and offsets.
    latest: [f64; 3],
    /// A bypass sample not yet read.
    unread: bool,
    fifo: VecDeque<[f64; 3]>,
    overrun: bool,
    triggered: bool,
    /// The data registers' sample, latched by the first data byte read in a CS window.
    latched: Option<[u16; 3]>,
    /// The end of the last data read (the pop), for the 5 µs rule.
    popped_at: Option<Ps>,
    phase: Phase,
    cs_low_at: Ps,
    cs_high_at: Option<Ps>,
    last_edge: Option<Ps>,
    /// The SPI rules of [`SPI`].
    rules: SpiRules,
    /// The shape rules the frame being clocked broke at its start (`begin_frame`).
    begun: Violations,
    events: EventLog,
}

impl std::fmt::Debug for Adxl345 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Adxl345").field("regs", &&self.regs[0x1D..0x3A]).field("fifo", &self.fifo.len()).finish()
    }
}

impl Adxl345 {
    /// A part at power-on (standby, registers at their reset values) feeling `stimulus`, with the
    /// errors of `preset` drawn from `seed`.
    pub fn new(stimulus: Stimulus, preset: &ErrorPreset, seed: u64) -> Adxl345 {
        let mut regs = [0u8; 64];
        for d in &REGISTERS {
            regs[usize::from(d.addr)] = d.reset;
        }
        Adxl345 {
            regs,
            stimulus,
            errors: UnitErrors::draw(preset, seed),
            next_sample: None,
            latest: [0.0; 3],
            unread: false,
            fifo: VecDeque::with_capacity(FIFO_DEPTH),
            overrun: false,
            triggered: false,
            latched: None,
            popped_at: None,
            phase: Phase::Idle,
            cs_low_at: 0,
            cs_high_at: None,
            last_edge: None,
            rules: SpiRules::new(&SPI),
            begun: Violations::default(),
            events: EventLog::default(),
        }
    }

    /// A part at rest, level (+1 g on z), without errors: what a board declaration builds.
    pub fn at_rest() -> Adxl345 {
        Adxl345::new(Box::new(|_| [0.0, 0.0, 1.0]), &PRESETS[0], 0)
    }

    /// Take the part's events out.
    pub fn drain_events(&mut self) -> Vec<Event> {
        self.events.drain()
    }

    /// The part's events so far.
    pub fn events(&self) -> &EventLog {
        &self.events
    }

    /// A register's current stored value (computed registers as a read at the last time would see).
    pub fn register_value(&self, addr: u8) -> u8 {
        self.regs[usize::from(addr & 0x3F)]
    }

    /// Entries in the FIFO.
    pub fn fifo_entries(&self) -> usize {
        self.fifo.len()
    }

    /// A trigger event (the interrupt FIFO_CTL.Trigger routes) at `t`: in trigger mode the FIFO
    /// keeps the last `samples` entries and then collects as in FIFO mode.
    pub fn trigger(&mut self, t: Ps) {
        self.advance(t);
        if FifoMode::of(self.regs[usize::from(FIFO_CTL)]) == FifoMode::Trigger && !self.triggered {
            self.triggered = true;
            let keep = usize::from(self.regs[usize::from(FIFO_CTL)] & 0x1F);
            while self.fifo.len() > keep {
                self.fifo.pop_front();
            }
        }
    }

    fn rate(&self) -> u8 {
        self.regs[usize::from(BW_RATE)] & 0x0F
    }

    /// Take every sample due at or before `t`.
    fn advance(&mut self, t: Ps) {
        let period = period_ps(self.rate());
        while let Some(ts) = self.next_sample.filter(|&ts| ts <= t) {
            self.next_sample = Some(ts + period);
            let low_power = self.regs[usize::from(BW_RATE)] & 0x10 != 0;
            let a = self.errors.apply((self.stimulus)(ts), self.rate(), low_power);
            let s: [f64; 3] = std::array::from_fn(|i| a[i] + f64::from(self.regs[0x1E + i] as i8) * OFFSET_LSB_G);
            match FifoMode::of(self.regs[usize::from(FIFO_CTL)]) {
                FifoMode::Bypass => {
                    self.overrun |= self.unread;
                    self.latest = s;
                    self.unread = true;
                }
                FifoMode::Fifo => self.collect(s),
                FifoMode::Trigger if self.triggered => self.collect(s),
                FifoMode::Stream | FifoMode::Trigger => {
                    if self.fifo.len() == FIFO_DEPTH {
                        self.fifo.pop_front();
                        self.overrun = true;
                    }
                    self.fifo.push_back(s);
                }
            }
        }
    }

    fn collect(&mut self, s: [f64; 3]) {
        if self.fifo.len() < FIFO_DEPTH {
            self.fifo.push_back(s);
        } else {
            self.overrun = true;
        }
    }

    fn rule(&mut self, t: Ps, kind: &'static str, what: String, measured_ps: Ps, required_ps: Ps) {
        let s = |p: Ps| p as f64 / 1e12;
        self.events.push(Event::rule(t, kind, Severity::Error, what, s(measured_ps), s(required_ps)));
    }

    /// The FIFO-pop rule before a read of the data registers or FIFO_STATUS at `t`.
    fn check_pop_spacing(&mut self, t: Ps, name: &str) {
        if FifoMode::of(self.regs[usize::from(FIFO_CTL)]) == FifoMode::Bypass {
            return;
        }
        if let Some(p) = self.popped_at.filter(|&p| t < p + spi::T_FIFO_POP) {
            let what = format!("ADXL345: {name} read {} ns after the FIFO pop (needs 5 µs)", (t - p) / 1_000);
            self.rule(t, "fifo_pop_too_soon", what, t - p, spi::T_FIFO_POP);
            self.popped_at = None;
        }
    }

    /// The end of a data read at `t`: the FIFO (or the bypass sample) moves on.
    fn pop(&mut self, t: Ps) {
        if self.latched.take().is_none() {
            return;
        }
        if FifoMode::of(self.regs[usize::from(FIFO_CTL)]) == FifoMode::Bypass {
            self.unread = false;
        } else {
            self.fifo.pop_front();
        }
        self.overrun = false;
        self.popped_at = Some(t);
    }

    fn read(&mut self, addr: u8, t: Ps) -> u8 {
        self.advance(t);
        match addr {
            DATAX0..=DATAZ1 => {
                if self.latched.is_none() {
                    self.check_pop_spacing(t, "DATA");
                    let (fmt, rate) = (self.regs[usize::from(DATA_FORMAT)], self.rate());
                    let s = match FifoMode::of(self.regs[usize::from(FIFO_CTL)]) {
                        FifoMode::Bypass => self.latest,
                        _ => self.fifo.front().copied().unwrap_or(self.latest),
                    };
                    if FifoMode::of(self.regs[usize::from(FIFO_CTL)]) != FifoMode::Bypass {
                        if let Some(&front) = self.fifo.front() {
                            self.latest = front;
                        }
                    }
                    self.latched = Some(s.map(|g| encode(g, fmt, rate)));
                }
                let word = self.latched.unwrap_or_default()[usize::from((addr - DATAX0) / 2)];
                if addr.is_multiple_of(2) {
                    word as u8
                } else {
                    (word >> 8) as u8
                }
            }
            FIFO_STATUS => {
                self.check_pop_spacing(t, "FIFO_STATUS");
                (u8::from(self.triggered) << 7) | self.fifo.len() as u8
            }
            INT_SOURCE => {
                let fifo = FifoMode::of(self.regs[usize::from(FIFO_CTL)]);
                let ready = if fifo == FifoMode::Bypass { self.unread } else { !self.fifo.is_empty() };
                let watermark = self.fifo.len() >= usize::from(self.regs[usize::from(FIFO_CTL)] & 0x1F);
                (u8::from(ready) << 7) | (u8::from(watermark && fifo != FifoMode::Bypass) << 1) | u8::from(self.overrun)
            }
            _ => match register(addr) {
                Some(_) => self.regs[usize::from(addr)],
                None => {
                    self.events.push(Event::new(
                        t,
                        "read_unreadable",
                        Severity::Warning,
                        format!("ADXL345: read of reserved address 0x{addr:02X}: reads 0"),
                    ));
                    0
                }
            },
        }
    }

    fn write(&mut self, addr: u8, value: u8, t: Ps) {
        self.advance(t);
        let Some(def) = register(addr) else {
            let what = format!("ADXL345: write of 0x{value:02X} to reserved address 0x{addr:02X}: ignored");
            self.events.push(Event::new(t, "write_unmapped", Severity::Warning, what));
            return;
        };
        if def.access == Access::R {
            let what = format!("ADXL345: write of 0x{value:02X} to read-only {}: ignored", def.name);
            self.events.push(Event::new(t, "read_only_write", Severity::Info, what));
            return;
        }
        let old = std::mem::replace(&mut self.regs[usize::from(addr)], value);
        match addr {
            POWER_CTL => {
                let (was, now) = (old & 0x08 != 0, value & 0x08 != 0);
                if now && !was {
                    self.next_sample = Some(t + TURN_ON_PS + period_ps(self.rate()));
                } else if !now {
                    self.next_sample = None;
                }
            }
            BW_RATE if self.next_sample.is_some() && (old ^ value) & 0x0F != 0 => {
                self.next_sample = Some(t + period_ps(self.rate()));
            }
            FIFO_CTL => {
                let mode = FifoMode::of(value);
                if mode == FifoMode::Bypass {
                    self.fifo.clear();
                }
                if mode != FifoMode::of(old) {
                    self.triggered = false;
                }
            }
            _ => {}
        }
    }
}

impl Adxl345 {
    /// The events of the shape rules `found` that the frame `timing` breaks (SCLK period, SPI
    /// mode, length).
    fn report_shape(&mut self, timing: &FrameTiming, found: Violations) {
        let t = timing.first_edge;
        if found.contains(Violations::SCLK_TOO_FAST) {
            let what = format!(
                "ADXL345: SCLK period {} ps, below {} ns ({} MHz)",
                timing.sclk_period,
                spi::T_SCLK_MIN / 1_000,
                SPI.sclk_max_hz / 1e6
            );
            self.rule(t, "sclk_too_fast", what, timing.sclk_period, spi::T_SCLK_MIN);
        }
        if found.contains(Violations::SPI_MODE) {
            let what = format!("ADXL345: a frame in SPI mode {}, the part is mode {}", timing.mode, spi::MODE);
            self.events.push(Event::new(t, "spi_mode", Severity::Error, what));
        }
        if found.contains(Violations::FRAME_LENGTH) {
            let what = format!("ADXL345: a frame of {} SCLK cycles: the part takes bytes; DIN ignored", timing.bits);
            self.events.push(Event::new(t, "byte_frame_length", Severity::Error, what));
        }
    }
}

impl SpiSlave for Adxl345 {
    fn set_cs(&mut self, low: bool, t: Ps) {
        if low {
            if let Some(h) = self.cs_high_at.filter(|&h| self.rules.high_short(h, t)) {
                let what = format!(
                    "ADXL345: CS high for {} ps between communications (tCS,DIS {} ns)",
                    t - h,
                    spi::T_CS_DIS / 1_000
                );
                self.rule(t, "cs_high_too_short", what, t - h, spi::T_CS_DIS);
            }
            self.cs_low_at = t;
            self.last_edge = None;
            self.phase = Phase::Command;
        } else {
            if let Some(e) = self.last_edge.filter(|&e| self.rules.hold_short(e, t)) {
                self.rule(
                    t,
                    "cs_hold",
                    format!("ADXL345: CS rose {} ps after SCLK (tQUIET {} ns)", t - e, spi::T_QUIET / 1_000),
                    t - e,
                    spi::T_QUIET,
                );
            }
            self.pop(t);
            self.cs_high_at = Some(t);
            self.phase = Phase::Idle;
        }
    }

    fn begin_frame(&mut self, timing: &FrameTiming) -> u16 {
        let mark = self.events.len();
        let dout = 'frame: {
            let t = timing.first_edge;
            let found = self.rules.shape(timing);
            if self.last_edge.is_none() && self.rules.setup_short(self.cs_low_at, t) {
                let d = t.saturating_sub(self.cs_low_at);
                self.rule(
                    t,
                    "cs_setup",
                    format!("ADXL345: first SCLK edge {d} ps after CS↓ (tDELAY {} ns)", spi::T_DELAY / 1_000),
                    d,
                    spi::T_DELAY,
                );
            }
            self.begun = found;
            self.report_shape(timing, found);
            if found.contains(Violations::FRAME_LENGTH) {
                break 'frame 0xFFFF;
            }
            match self.phase {
                Phase::Read { addr, .. } => u16::from(self.read(addr, t)) << 8,
                // Data returned during the command and writes is to be ignored (p. 15): the model drives 0.
                _ => 0,
            }
        };
        self.events.tie_to_frame(mark, timing.index);
        dout
    }

    /// The measured SCLK period, mode and length against the same rules as any frame's
    /// (`SpiRules::shape`), each broken rule reported once per frame; a frame its start found of
    /// the wrong length is ignored already.
    fn bitbanged_shape(&mut self, timing: &FrameTiming) {
        if self.begun.contains(Violations::FRAME_LENGTH) {
            return;
        }
        let found = Violations(self.rules.shape(timing).0 & !self.begun.0);
        if !found.is_empty() {
            let mark = self.events.len();
            self.report_shape(timing, found);
            self.events.tie_to_frame(mark, timing.index);
            self.begun.insert(found);
        }
    }

    fn end_frame(&mut self, din: u16, timing: &FrameTiming) {
        let mark = self.events.len();
        'frame: {
            let t = timing.last_edge;
            self.last_edge = Some(t);
            if Some(timing.bits) != SPI.frame_bits {
                break 'frame;
            }
            let byte = din as u8;
            self.phase = match self.phase {
                Phase::Idle => Phase::Idle,
                Phase::Command => {
                    let (addr, mb) = (byte & 0x3F, byte & spi::MULTI_BYTE != 0);
                    if byte & spi::READ != 0 {
                        Phase::Read { addr, mb }
                    } else {
                        Phase::Write { addr, mb }
                    }
                }
                Phase::Read { addr, mb } => {
                    // Without MB the same register is read again ([unconfirmed]).
                    let next = if mb { (addr + 1) & 0x3F } else { addr };
                    if addr == DATAZ1 && next != DATAZ1 {
                        self.pop(t);
                    }
                    Phase::Read { addr: next, mb }
                }
                Phase::Write { addr, mb } => {
                    self.write(addr, byte, t);
                    Phase::Write { addr: if mb { (addr + 1) & 0x3F } else { addr }, mb }
                }
            };
        }
        self.events.tie_to_frame(mark, timing.index);
    }
    fn drain_events(&mut self) -> Vec<Event> {
        Adxl345::drain_events(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bus::{Address, ChipSelects, Link, SpiLink};
    use crate::profile::Profile;
    use std::sync::{Arc, Mutex};

    /// The register map against adxl345.md's table: address, name, access and reset of each row,
    /// with the reserved block 0x01…0x1C empty.
    #[test]
    fn the_register_map_is_the_data_sheet_table() {
        let table: [(u8, &str, Access, Option<u8>); 30] = [
            (0x00, "DEVID", R, Some(0xE5)),
            (0x1D, "THRESH_TAP", RW, None),
            (0x1E, "OFSX", RW, None),
            (0x1F, "OFSY", RW, None),
            (0x20, "OFSZ", RW, None),
            (0x21, "DUR", RW, None),
            (0x22, "LATENT", RW, None),
            (0x23, "WINDOW", RW, None),
            (0x24, "THRESH_ACT", RW, None),
            (0x25, "THRESH_INACT", RW, None),
            (0x26, "TIME_INACT", RW, None),
            (0x27, "ACT_INACT_CTL", RW, None),
            (0x28, "THRESH_FF", RW, None),
            (0x29, "TIME_FF", RW, None),
            (0x2A, "TAP_AXES", RW, None),
            (0x2B, "ACT_TAP_STATUS", R, None),
            (0x2C, "BW_RATE", RW, Some(0x0A)),
            (0x2D, "POWER_CTL", RW, Some(0)),
            (0x2E, "INT_ENABLE", RW, None),
            (0x2F, "INT_MAP", RW, None),
            (0x30, "INT_SOURCE", R, None),
            (0x31, "DATA_FORMAT", RW, None),
            (0x32, "DATAX0", R, Some(0)),
            (0x33, "DATAX1", R, Some(0)),
            (0x34, "DATAY0", R, Some(0)),
            (0x35, "DATAY1", R, Some(0)),
            (0x36, "DATAZ0", R, Some(0)),
            (0x37, "DATAZ1", R, Some(0)),
            (0x38, "FIFO_CTL", RW, None),
            (0x39, "FIFO_STATUS", R, None),
        ];
        for (d, (addr, name, access, reset)) in REGISTERS.iter().zip(table) {
            assert_eq!((d.addr, d.name, d.access), (addr, name, access));
            // A sourced reset is the table's; the others are the [unc.] 0 (INT_SOURCE 0x02).
            assert_eq!(d.reset_sourced, reset.is_some(), "{name}");
            assert_eq!(d.reset, reset.unwrap_or(if name == "INT_SOURCE" { 0x02 } else { 0 }), "{name}");
            let mut seen = 0u16;
            for fl in d.fields {
                assert!(fl.lsb + fl.width <= 8 && seen & fl.mask() == 0, "{name}.{}", fl.name);
                seen |= fl.mask();
            }
        }
        assert!((0x01..=0x1C).all(|a| register(a).is_none()));
        let field =
            |reg: &str, name: &str| *register_named(reg).unwrap().fields.iter().find(|f| f.name == name).unwrap();
        // Bit fields of the table's rows: BW_RATE D4 LOW_POWER, D3–D0 rate; DATA_FORMAT D3 FULL_RES,
        // D2 justify, D1–D0 range; FIFO_CTL D7–D6 mode, D4–D0 samples; FIFO_STATUS D5–D0 entries.
        assert_eq!((field("BW_RATE", "LOW_POWER").mask(), field("BW_RATE", "Rate").mask()), (0x10, 0x0F));
        assert_eq!(field("DATA_FORMAT", "FULL_RES").mask(), 0x08);
        assert_eq!((field("DATA_FORMAT", "Justify").mask(), field("DATA_FORMAT", "Range").mask()), (0x04, 0x03));
        assert_eq!((field("FIFO_CTL", "FIFO_MODE").mask(), field("FIFO_CTL", "Samples").mask()), (0xC0, 0x1F));
        assert_eq!(field("FIFO_STATUS", "Entries").mask(), 0x3F);
        assert_eq!(field("POWER_CTL", "Measure").mask(), 0x08);
    }

    /// Tables 7 and 8: the rate codes' ODRs as printed (two decimals), bandwidth ODR/2.
    #[test]
    fn output_data_rates_are_table_7() {
        let printed =
            [3200.0, 1600.0, 800.0, 400.0, 200.0, 100.0, 50.0, 25.0, 12.5, 6.25, 3.13, 1.56, 0.78, 0.39, 0.20, 0.10];
        for (i, p) in printed.iter().enumerate() {
            let code = 15 - i as u8;
            assert!((odr_hz(code) - p).abs() < 0.006, "code {code:04b}: {} Hz", odr_hz(code));
            assert_eq!(bandwidth_hz(code), odr_hz(code) / 2.0);
            assert_eq!(period_ps(code) as f64, (1e12 / odr_hz(code)).round(), "code {code}");
        }
        assert_eq!(period_ps(0x0B), 5_000_000_000, "200 Hz: the board's 5 ms");
    }

    /// "Data format and scale": 256/128/64/32 LSB/g in 10-bit mode (3.9/7.8/15.6/31.2 mg/LSB), 3.9
    /// mg/LSB and 10…13 bits in full resolution, clipping at the bits, justification, the LSB forced
    /// to 0 at 3200/1600 Hz (p. 32).
    #[test]
    fn encodings_follow_the_format_register() {
        let lsb_per_g = |fmt: u8| 1.0 / resolution(fmt).1;
        assert_eq!([0, 1, 2, 3].map(lsb_per_g), [256.0, 128.0, 64.0, 32.0]);
        assert_eq!([8, 9, 10, 11].map(resolution), [10, 11, 12, 13].map(|b| (b, LSB_G)));
        assert_eq!(encode(1.0, 0x00, 0x0A), 256);
        assert_eq!(encode(-1.0, 0x00, 0x0A), (-256i16) as u16);
        assert_eq!(encode(3.0, 0x00, 0x0A), 511, "±2 g 10-bit clips at +511");
        assert_eq!(encode(-3.0, 0x00, 0x0A), (-512i16) as u16);
        assert_eq!(encode(3.0, 0x01, 0x0A), 384);
        assert_eq!(encode(15.0, 0x0B, 0x0A), 3840, "full resolution ±16 g: 3.9 mg/LSB, 13 bits");
        assert_eq!(encode(17.0, 0x0B, 0x0A), 4095);
        assert_eq!(encode(1.0, 0x04, 0x0A), 256 << 6, "left-justified 10-bit");
        assert_eq!(encode(-1.0 / 256.0, 0x0C, 0x0A), 0xFFC0, "left-justified full resolution ±2 g");
        assert_eq!(encode(3.0 / 256.0, 0x08, 0x0F), 2, "3200 Hz full resolution: LSB 0");
        assert_eq!(encode(3.0 / 128.0, 0x01, 0x0F), 3, "±4 g 10-bit keeps its LSB");
    }

    /// The `adxl345` preset's values and their growth with the rate (p. 33).
    #[test]
    fn the_error_preset_has_the_sheets_values() {
        let p = ErrorPreset::by_name("ADXL345").unwrap();
        assert_eq!(p.noise_sigma_g(0x0A, false), [0.75 * LSB_G, 0.75 * LSB_G, 1.1 * LSB_G]);
        assert_eq!(p.noise_sigma_g(0x05, false), p.noise_sigma_g(0x0A, false), "≤ 100 Hz: the 100 Hz figure");
        let at400 = p.noise_sigma_g(0x0C, false);
        assert!((at400[0] / LSB_G - 1.5).abs() < 1e-12 && (at400[2] / LSB_G - 2.2).abs() < 1e-12);
        let lp = p.noise_sigma_g(0x0C, true);
        assert!((lp[0] / LSB_G - 1.8).abs() < 1e-12 && (lp[2] / LSB_G - 2.6).abs() < 1e-12);
        // A unit draws the same offsets from the same seed, other ones from another.
        let (a, b) = (UnitErrors::draw(p, 7), UnitErrors::draw(p, 7));
        assert_eq!(a.offset_g, b.offset_g);
        assert_ne!(a.offset_g, UnitErrors::draw(p, 8).offset_g);
    }

    /// The part behind an `Arc` so that the test can look inside it while the link drives it.
    struct Shared(Arc<Mutex<Adxl345>>);

    impl SpiSlave for Shared {
        fn set_cs(&mut self, low: bool, t: Ps) {
            self.0.lock().unwrap().set_cs(low, t);
        }
        fn begin_frame(&mut self, timing: &FrameTiming) -> u16 {
            self.0.lock().unwrap().begin_frame(timing)
        }
        fn end_frame(&mut self, din: u16, timing: &FrameTiming) {
            self.0.lock().unwrap().end_frame(din, timing);
        }
    }

    const MS: Ps = 1_000_000_000;

    /// SPI-A in 8-bit characters (SPICCR 0xC7: CLKPOLARITY 1, SPICHAR 7; CLK_PHASE 0: mode 3) at
    /// `spibrr`, the part on GPIO58.
    fn link(part: Adxl345, spibrr: u32) -> (SpiLink<ChipSelects>, Arc<Mutex<Adxl345>>) {
        // The profile's `[spi]` is the ADIS16407's (16-bit characters); the FPGA's byte-wide SPI
        // core is stood in for by SPI-A initialised with 8-bit characters.
        let profile = Profile::default();
        let spi = crate::profile::Spi { spiccr: 0xC7, spibrr, ..profile.spi.clone() };
        let part = Arc::new(Mutex::new(part));
        let cs = ChipSelects::new(vec![(58, Box::new(Shared(Arc::clone(&part))))]);
        let mut link = SpiLink::from_profile(&profile, cs).unwrap();
        link.init_from_profile(&spi, 0).unwrap();
        (link, part)
    }

    /// One CS window: `bytes` out (left-justified in the 16-bit TX word), the bytes back.
    fn xfer(link: &mut SpiLink<ChipSelects>, bytes: &[u8], t: Ps) -> (Vec<u8>, Ps) {
        let tx: Vec<u16> = bytes.iter().map(|&b| u16::from(b) << 8).collect();
        let mut rx = vec![0u16; tx.len()];
        let tr = link.transfer(Address::ChipSelect(58), &tx, &mut rx, t).unwrap();
        (rx.iter().map(|&w| w as u8).collect(), tr.end)
    }

    fn kinds(part: &Arc<Mutex<Adxl345>>) -> Vec<&'static str> {
        part.lock().unwrap().drain_events().iter().map(|e| e.kind).collect()
    }

    /// Through the SPI link: DEVID reads 0xE5; a single-byte write lands and reads back; a multi-byte
    /// write steps the address (OFSX…OFSZ); a multi-byte read of the six data bytes gives one coherent
    /// sample, little-endian, with the offsets added; a write to a read-only register is ignored.
    #[test]
    fn registers_read_and_write_through_the_spi_link() {
        let part = Adxl345::new(Box::new(|_| [0.5, -0.25, 1.0]), &PRESETS[0], 0);
        let (mut link, part) = link(part, 49);
        let (rx, t) = xfer(&mut link, &[0x80, 0], 0);
        assert_eq!(rx[1], 0xE5);
        let (_, t) = xfer(&mut link, &[0x31, 0x0B], t + MS); // DATA_FORMAT: full resolution ±16 g
        let (rx, t) = xfer(&mut link, &[0x80 | 0x31, 0], t + MS);
        assert_eq!(rx[1], 0x0B);
        let (_, t) = xfer(&mut link, &[0x40 | 0x1E, 2, 0xFF, 0], t + MS); // OFSX = +2, OFSY = −1, OFSZ = 0
        let (rx, t) = xfer(&mut link, &[0xC0 | 0x1E, 0, 0, 0], t + MS);
        assert_eq!(&rx[1..], [2, 0xFF, 0]);
        let (_, t) = xfer(&mut link, &[0x2D, 0x08], t + MS); // measure
        let (rx, t) = xfer(&mut link, &[0xC0 | 0x32, 0, 0, 0, 0, 0, 0], t + 20 * MS);
        let word = |i: usize| i16::from_le_bytes([rx[1 + 2 * i], rx[2 + 2 * i]]);
        // 0.5 g = 128 LSB + 2 × 4 LSB offset; −0.25 g = −64 − 4; 1 g = 256.
        assert_eq!([word(0), word(1), word(2)], [136, -68, 256]);
        let (_, _) = xfer(&mut link, &[0x00, 0x12], t + MS);
        assert_eq!(kinds(&part), ["read_only_write"]);
        assert_eq!(part.lock().unwrap().register_value(0x00), 0xE5);
    }

    /// FIFO modes at 200 Hz (the board's rate): stream keeps the latest 32 and sets overrun; FIFO mode
    /// stops at 32 (the oldest kept); each data read pops one entry (FIFO_STATUS counts down); bypass
    /// empties the FIFO; trigger mode keeps `samples` entries at the trigger, then fills to 32.
    #[test]
    fn fifo_modes_keep_what_the_sheet_says() {
        // The stimulus counts samples: the k-th sample reads k/256 g on x.
        let k = Arc::new(Mutex::new(0.0));
        let kk = Arc::clone(&k);
        let stim: Stimulus = Box::new(move |_| {
            let mut k = kk.lock().unwrap();
            *k += 1.0;
            [*k / 256.0, 0.0, 0.0]
        });
        let (mut link, part) = link(Adxl345::new(stim, &PRESETS[0], 0), 49);
        let (_, t) = xfer(&mut link, &[0x40 | 0x2C, 0x0B, 0x08], 0); // 200 Hz, measure (BW_RATE, POWER_CTL)
        let (_, t) = xfer(&mut link, &[0x31, 0x08], t + 1_000_000);
        let (_, t) = xfer(&mut link, &[0x38, 0x80 | 16], t + 1_000_000); // stream
                                                                         // First sample at 1.1 ms + 5 ms; 40 samples by 1.1 + 200 ms.
        let t = t + 205 * MS;
        let (rx, t) = xfer(&mut link, &[0x80 | 0x39, 0], t);
        assert_eq!(rx[1], 32);
        let (rx, t) = xfer(&mut link, &[0x80 | 0x30, 0], t + 10 * 1_000_000);
        assert_eq!(rx[1] & 0x83, 0x83, "data ready, watermark (32 ≥ 16), overrun");
        let n = *k.lock().unwrap() as i16;
        let read_x = |link: &mut SpiLink<ChipSelects>, t: Ps| {
            let (rx, t) = xfer(link, &[0xC0 | 0x32, 0, 0], t);
            (i16::from_le_bytes([rx[1], rx[2]]), t)
        };
        let (x, t) = read_x(&mut link, t + 10_000_000);
        assert_eq!(x, n - 31, "stream: the oldest of the latest 32");
        let (rx, t) = xfer(&mut link, &[0x80 | 0x39, 0], t + 10_000_000);
        assert_eq!(rx[1], 31, "the read popped one");
        // FIFO mode: after the change, collect up to 32 and stop.
        let (_, t) = xfer(&mut link, &[0x38, 0x00], t + 10_000_000); // bypass clears
        assert_eq!(part.lock().unwrap().fifo_entries(), 0);
        let (_, t) = xfer(&mut link, &[0x38, 0x40], t + 10_000_000);
        let first = *k.lock().unwrap() as i16 + 1;
        let (x, t) = read_x(&mut link, t + 400 * MS);
        assert_eq!(x, first, "FIFO mode keeps the oldest");
        assert_eq!(part.lock().unwrap().fifo_entries(), 31);
        // Trigger mode: keep 4 at the trigger, then collect.
        let (_, t) = xfer(&mut link, &[0x38, 0x00], t + 10_000_000);
        let (_, t) = xfer(&mut link, &[0x38, 0xC0 | 4], t + 10_000_000);
        let t = t + 100 * MS;
        part.lock().unwrap().trigger(t);
        assert_eq!(part.lock().unwrap().fifo_entries(), 4);
        let last_before = *k.lock().unwrap() as i16;
        let (rx, t) = xfer(&mut link, &[0x80 | 0x39, 0], t + 12 * MS);
        let new = *k.lock().unwrap() as u8 - last_before as u8;
        assert!(new >= 2, "12 ms at 200 Hz: 2 or 3 samples");
        assert_eq!(rx[1], 0x80 | (4 + new), "FIFO_TRIG, 4 kept + the new ones");
        let (x, _) = read_x(&mut link, t + 10_000_000);
        assert_eq!(x, last_before - 3);
        let events = part.lock().unwrap().drain_events();
        assert!(events.is_empty(), "{events:?}");
    }

    /// One CS window driven as tightly as SPI-A allows: each byte written 100 ns after the previous
    /// one's INT_FLAG, CS↑ 100 ns after the last (the generic `Link` driver waits 40 µs instead).
    fn tight(link: &mut SpiLink<ChipSelects>, bytes: &[u8], t: Ps) -> (Vec<u8>, Ps) {
        link.slave_mut().select(58).unwrap();
        link.set_gpio57(false, t).unwrap();
        let (mut now, mut out) = (t + 100_000, Vec::new());
        for &b in bytes {
            let mut at = now;
            let w = link
                .write_poll_read(u16::from(b) << 8, now, |flag| {
                    at = flag.unwrap().ps;
                    Ok(at)
                })
                .unwrap();
            out.push(w as u8);
            now = at + 100_000;
        }
        link.set_gpio57(true, now).unwrap();
        (out, now)
    }

    /// The FIFO-pop rule (≥ 5 µs from the end of a data read to the next FIFO or FIFO_STATUS read):
    /// at 3.75 MHz (SPIBRR 9) a FIFO_STATUS read in the next CS window comes 2.6 µs after the pop and
    /// is a `fifo_pop_too_soon` event, as is reading on past 0x37 in the same window; at the board's
    /// 1.39 MHz (SPIBRR 26) the command byte alone takes 5.8 µs: no event (adxl345.md: "at ≤ 1.5 MHz
    /// the next address byte is enough"). CS high for 100 ns is `cs_high_too_short`; SCLK above 5 MHz
    /// is `sclk_too_fast`; a 16-bit frame is `byte_frame_length`.
    #[test]
    fn timing_violations_are_events() {
        let setup = |link: &mut SpiLink<ChipSelects>| {
            let (_, t) = xfer(link, &[0x40 | 0x2C, 0x0B, 0x08], 0); // 200 Hz, measure
            xfer(link, &[0x38, 0x80], t + 1_000_000).1 // stream
        };
        let (mut spi, part) = link(Adxl345::at_rest(), 9);
        let t = setup(&mut spi);
        let (_, t) = tight(&mut spi, &[0xC0 | 0x32, 0, 0, 0, 0, 0, 0], t + 50 * MS);
        let (status, t) = tight(&mut spi, &[0x80 | 0x39, 0], t + 200_000);
        let events = part.lock().unwrap().drain_events();
        assert_eq!(events.iter().map(|e| e.kind).collect::<Vec<_>>(), ["fifo_pop_too_soon"], "{events:?}");
        assert_eq!(events[0].required, Some(5e-6));
        assert!(events[0].measured.unwrap() < 5e-6 && events[0].measured.unwrap() > 2e-6, "{:?}", events[0]);
        let (rx, t) = tight(&mut spi, &[0xC0 | 0x32, 0, 0, 0, 0, 0, 0, 0, 0], t + 100_000_000);
        assert_eq!(kinds(&part), ["fifo_pop_too_soon"], "0x38, 0x39 read on after the pop");
        assert_eq!(rx[8] & 0x3F, status[1] - 1, "the data read popped one");
        let _ = tight(&mut spi, &[0x80, 0], t + 100_000);
        assert_eq!(kinds(&part), ["cs_high_too_short"]);
        let (mut board, part) = link(Adxl345::at_rest(), 26);
        let t = setup(&mut board);
        let (_, t) = tight(&mut board, &[0xC0 | 0x32, 0, 0, 0, 0, 0, 0], t + 50 * MS);
        let _ = tight(&mut board, &[0x80 | 0x39, 0], t + 200_000);
        assert!(kinds(&part).is_empty());
        // SPIBRR 2: LSPCLK/4 = 9.375 MHz at the reference clocks.
        let (mut fast, part) = link(Adxl345::at_rest(), 2);
        let _ = xfer(&mut fast, &[0x80, 0], 0);
        assert_eq!(kinds(&part), ["sclk_too_fast", "sclk_too_fast"]);
        let mut dev = Adxl345::at_rest();
        let timing = FrameTiming {
            index: 0,
            first_edge: 1_000_000,
            last_edge: 2_000_000,
            sclk_period: 1_000_000,
            bits: 16,
            mode: 3,
        };
        dev.set_cs(true, 10);
        assert_eq!(dev.begin_frame(&timing), 0xFFFF);
        assert_eq!(dev.drain_events().iter().map(|e| e.kind).collect::<Vec<_>>(), ["byte_frame_length"]);
    }

    /// A bit-banged frame (`board::bitbang`) starts with its SCLK period unknown (`Ps::MAX`) and
    /// is checked at its end against the measured one by the same rules: 8 cycles of 1 µs (1 MHz
    /// ≤ 5 MHz) raise nothing; with a shortest cycle of 100 ns (10 MHz) the part's own
    /// `sclk_too_fast`, once, tied to the frame.
    #[test]
    fn a_bitbanged_frame_is_checked_at_its_end() {
        for (period, kinds) in [(1_000_000, vec![]), (100_000, vec!["sclk_too_fast"])] {
            let mut dev = Adxl345::at_rest();
            dev.set_cs(true, 0);
            let start = FrameTiming {
                index: 7,
                first_edge: 1_000_000,
                last_edge: 1_000_000,
                sclk_period: Ps::MAX,
                bits: 8,
                mode: 3,
            };
            dev.begin_frame(&start);
            assert!(dev.drain_events().is_empty(), "the start knows no period yet");
            let measured = FrameTiming { last_edge: 1_000_000 + 15 * period / 2, sclk_period: period, ..start };
            dev.bitbanged_shape(&measured);
            dev.bitbanged_shape(&measured);
            dev.end_frame(0x80, &measured);
            let events = dev.drain_events();
            assert_eq!(events.iter().map(|e| e.kind).collect::<Vec<_>>(), kinds, "{events:?}");
            if let Some(e) = events.first() {
                assert_eq!(e.message, "ADXL345: SCLK period 100000 ps, below 200 ns (5 MHz)");
                assert_eq!(e.frame, Some(7));
            }
        }
    }

    /// Each SPI rule's message states the part's declared limit: CS↓ 1 ns before a mode-0 frame
    /// clocked at 10 MHz, CS↑ 1 ns after it, CS high for 100 ns.
    #[test]
    fn rule_messages_state_the_declared_limits() {
        let mut dev = Adxl345::at_rest();
        let frame =
            FrameTiming { index: 0, first_edge: 1_000, last_edge: 701_000, sclk_period: 100_000, bits: 8, mode: 0 };
        dev.set_cs(true, 0);
        dev.begin_frame(&frame);
        dev.end_frame(0, &frame);
        dev.set_cs(false, frame.last_edge + 1_000);
        dev.set_cs(true, frame.last_edge + 101_000);
        let messages: Vec<String> = dev.drain_events().into_iter().map(|e| e.message).collect();
        assert_eq!(
            messages,
            [
                "ADXL345: first SCLK edge 1000 ps after CS↓ (tDELAY 5 ns)",
                "ADXL345: SCLK period 100000 ps, below 200 ns (5 MHz)",
                "ADXL345: a frame in SPI mode 0, the part is mode 3",
                "ADXL345: CS rose 1000 ps after SCLK (tQUIET 5 ns)",
                "ADXL345: CS high for 100000 ps between communications (tCS,DIS 150 ns)",
            ]
        );
    }

    /// A `[[board.devices]]` table places the part by name on SPI, and refuses it on another link.
    #[test]
    fn a_board_declaration_builds_the_part_on_spi() {
        use crate::board::links::known_parts;
        use crate::bus::SpiSlave;
        use crate::profile::link_kind;
        let (spi, i2c) = (link_kind("spi-a").unwrap(), link_kind("i2c-a").unwrap());
        assert!(matches!(known_parts("adxl345", spi), Some(Ok(d)) if d.is::<dyn SpiSlave + Send>()));
        assert!(matches!(known_parts("ADXL345", i2c), Some(Err(_))));
    }
}
