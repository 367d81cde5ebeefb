//! The sections of a profile. Defaults are the reference design as published; values marked
//! [unconfirmed] in the spec are parameters here, documented in `firmware_model/SCHEMA.md`.

use crate::device::encoding::GyroRange;
use crate::device::part::{family, Part, Role};
use crate::device::parts;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

pub(super) fn bad(key: &str, value: impl std::fmt::Display, expected: &str) -> Error {
    Error::Profile(format!("key `{key}` = {value}: expected {expected}"))
}

fn check_reg(key: &str, value: u32, bits: u32) -> Result<()> {
    if value >> bits != 0 {
        return Err(bad(
            key,
            format!("0x{value:X}"),
            &format!("a {bits}-bit register value (0…{})", (1u64 << bits) - 1),
        ));
    }
    Ok(())
}

/// A float as a user wrote it, unless that is unreadably long (1e-308 has 300 digits in full).
fn num(value: f64) -> String {
    let full = value.to_string();
    if full.len() > 24 {
        format!("{value:e}")
    } else {
        full
    }
}

fn check_pos(key: &str, value: f64) -> Result<()> {
    if !(value.is_finite() && value > 0.0) {
        return Err(bad(key, num(value), "a finite number > 0"));
    }
    Ok(())
}

/// `allowed` says the range in words, as a user would write it (`1e6…1e8 m`).
fn check_range(key: &str, value: f64, lo: f64, hi: f64, allowed: &str) -> Result<()> {
    if !(value.is_finite() && (lo..=hi).contains(&value)) {
        return Err(bad(key, num(value), allowed));
    }
    Ok(())
}

fn check_nonneg(key: &str, value: f64) -> Result<()> {
    if !(value.is_finite() && value >= 0.0) {
        return Err(bad(key, num(value), "a finite number ≥ 0"));
    }
    Ok(())
}

/// Name and description of a profile.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Meta {
    /// Short name.
    pub name: String,
    /// One line on what the profile models.
    pub description: String,
}

impl Default for Meta {
    fn default() -> Self {
        Meta {
            name: "reference".into(),
            description: "TMS320F28335 + ADIS16407, RK4 every 8 ms, as published (2014 thesis)".into(),
        }
    }
}

/// The F28335's rated maximum SYSCLKOUT, Hz (data sheet: 150 MHz, 6.67 ns cycle).
pub const MAX_SYSCLKOUT_HZ: f64 = 150e6;

/// The F28335 clock tree: SYSCLKOUT = crystal × PLLCR / DIVSEL, LSPCLK = SYSCLKOUT / (2·LOSPCP).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Clocks {
    /// External crystal / oscillator, Hz.
    pub crystal_hz: u64,
    /// PLLCR.DIV (0…10; 0 bypasses the PLL).
    pub pllcr: u32,
    /// Divider selected by PLLSTS.DIVSEL: 1, 2 or 4.
    pub divsel: u32,
    /// LOSPCP (0…7): LSPCLK = SYSCLKOUT / (2·LOSPCP), SYSCLKOUT when 0.
    pub lospcp: u32,
    /// The system control state a C firmware's main starts from: "initialised" (every peripheral
    /// clock on, the watchdog disabled, as TI's start-up code and InitSysCtrl leave them) or
    /// "reset" (the chip's reset values: PCLKCR0/1 = 0, the watchdog running). The PLL is the keys
    /// above either way.
    pub at_main: String,
    /// OSCCLK cycles the PLL takes to lock after PLLCR changes (SPRUFB0: 131072 [unconfirmed]).
    pub pll_lock_oscclk: u64,
}

impl Default for Clocks {
    fn default() -> Self {
        Clocks {
            crystal_hz: 30_000_000,
            pllcr: 10,
            divsel: 2,
            lospcp: 2,
            at_main: "initialised".into(),
            pll_lock_oscclk: 131_072,
        }
    }
}

impl Clocks {
    pub(crate) fn validate(&self) -> Result<()> {
        if self.crystal_hz == 0 || self.crystal_hz > 35_000_000 {
            return Err(bad("clocks.crystal_hz", self.crystal_hz, "1…35000000 Hz"));
        }
        if self.pllcr > 10 {
            return Err(bad("clocks.pllcr", self.pllcr, "0…10"));
        }
        if ![1, 2, 4].contains(&self.divsel) {
            return Err(bad("clocks.divsel", self.divsel, "1, 2 or 4"));
        }
        if self.lospcp > 7 {
            return Err(bad("clocks.lospcp", self.lospcp, "0…7"));
        }
        if !["initialised", "reset"].contains(&self.at_main.as_str()) {
            return Err(Error::Profile(format!(
                "key `clocks.at_main` = \"{}\": expected \"initialised\" or \"reset\"",
                self.at_main
            )));
        }
        if self.pll_lock_oscclk > 1 << 24 {
            return Err(bad("clocks.pll_lock_oscclk", self.pll_lock_oscclk, "0…16777216 OSCCLK cycles"));
        }
        // The three keys together set SYSCLKOUT; the part is rated for 150 MHz at most.
        let pll = if self.pllcr == 0 { 1 } else { u64::from(self.pllcr) };
        let sysclkout_hz = self.crystal_hz as f64 * pll as f64 / f64::from(self.divsel);
        if sysclkout_hz > MAX_SYSCLKOUT_HZ {
            return Err(Error::Profile(format!(
                "keys `clocks.crystal_hz` = {}, `clocks.pllcr` = {}, `clocks.divsel` = {} give SYSCLKOUT = {} MHz: \
                 expected at most {} MHz (the F28335's rated maximum)",
                self.crystal_hz,
                self.pllcr,
                self.divsel,
                sysclkout_hz / 1e6,
                MAX_SYSCLKOUT_HZ / 1e6
            )));
        }
        Ok(())
    }
}

/// Which level the SPI link is emulated at.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BusLevel {
    /// One computation per frame (fast path).
    Transaction,
    /// Every SCLK edge.
    Bit,
}

/// SPI-A register values. The firmware's InitSpi writes them in the published order:
/// SPICCR with SPISWRESET = 0, SPICTL, SPIBRR, SPICCR (released), SPIPRI; FIFO registers only when
/// `spifftx` enables the FIFO.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Spi {
    /// SPICCR final value (bit 7 SPISWRESET, 6 CLKPOLARITY, 4 SPILBK, 3:0 SPICHAR).
    pub spiccr: u32,
    /// SPICTL (4 OVERRUNINTENA, 3 CLK_PHASE, 2 MASTER_SLAVE, 1 TALK, 0 SPIINTENA).
    pub spictl: u32,
    /// SPIBRR (0…127): baud = LSPCLK/(SPIBRR+1), LSPCLK/4 for 0…2.
    pub spibrr: u32,
    /// SPIPRI (5 SOFT, 4 FREE).
    pub spipri: u32,
    /// SPIFFTX (bit 14 SPIFFENA enables the FIFO).
    pub spifftx: u32,
    /// SPIFFRX.
    pub spiffrx: u32,
    /// SPIFFCT (7:0 TXDLY).
    pub spiffct: u32,
    /// Emulation level of the link.
    pub level: BusLevel,
    /// LSPCLK cycles from a SPITXBUF write (shifter idle) to the first SCLK edge [unconfirmed].
    pub start_latency_lspclk: u32,
    /// SPISTE (GPIO57 muxed to SPISTEA) between characters that follow without a gap: `false` keeps
    /// it low (the F2833x data sheet's SPI master timing notes, spec f28335-peripherals.md §4
    /// [unconfirmed]), `true` pulses it high between them. Left out of the profile's text when
    /// `false`.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub ste_pulse_between_words: bool,
}

impl Default for Spi {
    fn default() -> Self {
        Spi {
            spiccr: 0x00CF,
            spictl: 0x0007,
            spibrr: 49,
            spipri: 0x0020,
            spifftx: 0xA000,
            spiffrx: 0x201F,
            spiffct: 0,
            level: BusLevel::Transaction,
            start_latency_lspclk: 1,
            ste_pulse_between_words: false,
        }
    }
}

impl Spi {
    pub(crate) fn validate(&self) -> Result<()> {
        check_reg("spi.spiccr", self.spiccr, 8)?;
        check_reg("spi.spictl", self.spictl, 5)?;
        check_reg("spi.spibrr", self.spibrr, 7)?;
        check_reg("spi.spipri", self.spipri, 8)?;
        check_reg("spi.spifftx", self.spifftx, 16)?;
        check_reg("spi.spiffrx", self.spiffrx, 16)?;
        check_reg("spi.spiffct", self.spiffct, 8)?;
        if self.spictl & 0b100 == 0 {
            return Err(bad(
                "spi.spictl",
                format!("0x{:X}", self.spictl),
                "MASTER_SLAVE (bit 2) = 1: the firmware is the SPI master",
            ));
        }
        if self.start_latency_lspclk > 64 {
            return Err(bad("spi.start_latency_lspclk", self.start_latency_lspclk, "0…64 LSPCLK cycles"));
        }
        Ok(())
    }
}

/// CPU timer 0. The firmware's ConfigCpuTimer turns `period_us` into PRD = SYSCLKOUT·µs/(TDDR+1) − 1.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Timer {
    /// Interrupt period requested by the firmware, µs.
    pub period_us: f64,
    /// Prescaler TDDRH:TDDR (0…65535).
    pub tddr: u32,
}

impl Default for Timer {
    fn default() -> Self {
        Timer { period_us: 4000.0, tddr: 0 }
    }
}

impl Timer {
    pub(crate) fn validate(&self) -> Result<()> {
        check_pos("timer.period_us", self.period_us)?;
        check_reg("timer.tddr", self.tddr, 16)?;
        Ok(())
    }
}

/// What a timing violation does to the data.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TimingMode {
    /// The frame reads as the documented corrupted word.
    Strict,
    /// Data correct; the event is only recorded.
    Lenient,
}

/// The IMU part (`part` selects its declaration, `device/parts/`): register defaults at power-on and
/// the timing rules of its SPI slave. The keys a part declares (PROD_ID, burst command, reset time,
/// SCLK limits) default to that part's values ([`fill_part_defaults`]); `Device::default()` is the
/// ADIS16407's.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Device {
    /// Part name: one of the parts in `device/parts/` (ADIS16407, ADIS16362).
    pub part: String,
    /// PROD_ID value.
    pub prod_id: u32,
    /// Burst-read command word (0x4200 for the 16407; 0x3E00 for ADIS16400/16405).
    pub burst_command: u32,
    /// SMPL_PRD at power-on (0x0001 → 819.2 SPS).
    pub smpl_prd: u32,
    /// SENS_AVG at power-on (0x0402 → ±300 °/s, M = 2).
    pub sens_avg: u32,
    /// MSC_CTRL at power-on (0x0006 → data ready on DIO1, active high).
    pub msc_ctrl: u32,
    /// Device sample-clock error, parts per billion (positive = fast).
    pub clock_ppb: i64,
    /// Time of the device's first internal sample after power-on, µs.
    pub first_sample_us: f64,
    /// Time the part is unavailable after a software reset, ms [unconfirmed; siblings 90–170].
    pub reset_time_ms: f64,
    /// How long the part had been powered when the run starts, ms. It is ready its part's start-up
    /// time after power-on; until then it neither samples nor answers (`read_before_startup`). The
    /// default, 1 s, leaves either part ready at the start.
    pub powered_before_ms: f64,
    /// Consequence of a timing violation.
    pub timing_mode: TimingMode,
    /// Maximum SCLK in normal mode, Hz.
    pub sclk_max_hz: f64,
    /// Maximum SCLK during a burst read, Hz.
    pub sclk_burst_max_hz: f64,
    /// Minimum stall between normal frames (CS high or low), µs [unconfirmed: sibling ADIS16405].
    pub t_stall_us: f64,
    /// Minimum stall in the slow (low-power) sample mode, µs [unconfirmed: sibling ADIS16405].
    pub t_stall_slow_us: f64,
    /// Minimum period of frames outside a burst (tDATARATE), µs [unconfirmed: sibling ADIS16405].
    pub t_datarate_us: f64,
    /// Minimum CS↓ to first SCLK edge, ns [unconfirmed].
    pub t_cs_ns: f64,
    /// Minimum last SCLK edge to CS↑, ns [unconfirmed].
    pub t_sfs_ns: f64,
    /// LOT_ID1 (unit-specific; 0 unless a unit's value is given).
    pub lot_id1: u32,
    /// LOT_ID2 (unit-specific).
    pub lot_id2: u32,
    /// SERIAL_NUM (unit-specific).
    pub serial_num: u32,
    /// DOUT in the frame after a write frame (undefined on the part; this model's fixed pattern).
    pub dout_after_write: u32,
    /// The word a frame reads as under `strict` when a timing rule is broken.
    pub corrupt_word: u32,
}

impl Default for Device {
    /// The reference board's part, the ADIS16407, with its declared values.
    fn default() -> Self {
        Device::of_part(&parts::adis16407::PART)
    }
}

impl Device {
    /// The defaults with the part's declared values (what a profile naming only `part` gives): its
    /// PROD_ID, burst command, reset time and SPI timing from the declaration, the family's tCS and
    /// tSFS; the rest the model's own defaults.
    pub fn of_part(part: &Part) -> Device {
        Device {
            part: part.name.into(),
            prod_id: u32::from(part.prod_id),
            burst_command: u32::from(part.burst_command),
            smpl_prd: 0x0001,
            sens_avg: 0x0402,
            msc_ctrl: 0x0006,
            clock_ppb: 0,
            first_sample_us: 0.0,
            reset_time_ms: part.reset_ms,
            powered_before_ms: 1000.0,
            timing_mode: TimingMode::Strict,
            sclk_max_hz: part.spi.sclk_max_hz,
            sclk_burst_max_hz: part.sclk_burst_max_hz,
            t_stall_us: part.t_stall_us,
            t_stall_slow_us: part.t_stall_slow_us,
            t_datarate_us: part.t_datarate_us,
            t_cs_ns: family::T_CS_NS,
            t_sfs_ns: family::T_SFS_NS,
            lot_id1: 0,
            lot_id2: 0,
            serial_num: 0,
            dout_after_write: 0x0000,
            corrupt_word: 0xFFFF,
        }
    }
}

/// The `[device]` keys whose defaults a part declares, with the part's values.
fn part_defaults(part: &Part) -> [(&'static str, toml::Value); 8] {
    [
        ("prod_id", toml::Value::Integer(i64::from(part.prod_id))),
        ("burst_command", toml::Value::Integer(i64::from(part.burst_command))),
        ("reset_time_ms", toml::Value::Float(part.reset_ms)),
        ("sclk_max_hz", toml::Value::Float(part.spi.sclk_max_hz)),
        ("sclk_burst_max_hz", toml::Value::Float(part.sclk_burst_max_hz)),
        ("t_stall_us", toml::Value::Float(part.t_stall_us)),
        ("t_stall_slow_us", toml::Value::Float(part.t_stall_slow_us)),
        ("t_datarate_us", toml::Value::Float(part.t_datarate_us)),
    ]
}

/// Give the `[device]` keys a profile leaves out the values its part declares (a profile table
/// before it is read; an unknown part is left to [`Device::validate`]).
pub(crate) fn fill_part_defaults(table: &mut toml::Table) {
    let Some(toml::Value::Table(device)) = table.get_mut("device") else { return };
    let Some(part) = device.get("part").and_then(|p| p.as_str()).and_then(parts::by_name) else { return };
    for (key, value) in part_defaults(part) {
        device.entry(key).or_insert(value);
    }
}

/// `device.gyro_range_dps` (75, 150 or 300), another way to write SENS_AVG's range bits 10:8: it sets
/// them in `device.sens_avg` (the profile's, or the default 0x0402) and raises M (bits 2:0) to the
/// range's minimum, as the part does on a write; so `gyro_range_dps = 75` gives 0x0104. The key
/// is replaced by the `sens_avg` it stands for before the profile is read.
pub(crate) fn apply_gyro_range(table: &mut toml::Table) -> Result<()> {
    const KEY: &str = "device.gyro_range_dps";
    let Some(toml::Value::Table(device)) = table.get_mut("device") else { return Ok(()) };
    let Some(value) = device.remove("gyro_range_dps") else { return Ok(()) };
    let dps = value.as_float().or_else(|| value.as_integer().map(|i| i as f64));
    let range = dps
        .and_then(|d| GyroRange::from_dps(d).ok())
        .ok_or_else(|| bad(KEY, &value, "75, 150 or 300 (°/s: SENS_AVG's range bits 10:8)"))?;
    let sens_avg = match device.get("sens_avg") {
        Some(v) => v
            .as_integer()
            .and_then(|i| u32::try_from(i).ok())
            .ok_or_else(|| bad("device.sens_avg", v, "a 16-bit register value (with `device.gyro_range_dps`)"))?,
        None => Device::default().sens_avg,
    };
    let m = (sens_avg & 0x7).max(u32::from(range.min_m()));
    let sens_avg = (sens_avg & !0x0707) | u32::from(range.bits()) << 8 | m;
    device.insert("sens_avg".into(), toml::Value::Integer(i64::from(sens_avg)));
    Ok(())
}

impl Device {
    /// The declaration of the part `part` names.
    pub fn part_decl(&self) -> Result<&'static Part> {
        parts::by_name(&self.part).ok_or_else(|| bad("device.part", &self.part, &format!("one of {}", parts::names())))
    }

    pub(crate) fn validate(&self) -> Result<()> {
        let part = self.part_decl()?;
        check_reg("device.lot_id1", self.lot_id1, 16)?;
        check_reg("device.lot_id2", self.lot_id2, 16)?;
        check_reg("device.serial_num", self.serial_num, 16)?;
        check_reg("device.prod_id", self.prod_id, 16)?;
        check_reg("device.burst_command", self.burst_command, 16)?;
        check_reg("device.smpl_prd", self.smpl_prd, 16)?;
        check_reg("device.sens_avg", self.sens_avg, 16)?;
        check_reg("device.msc_ctrl", self.msc_ctrl, 16)?;
        check_reg("device.dout_after_write", self.dout_after_write, 16)?;
        check_reg("device.corrupt_word", self.corrupt_word, 16)?;
        if self.burst_command & 0x8000 != 0 {
            return Err(bad(
                "device.burst_command",
                format!("0x{:04X}", self.burst_command),
                "a read command (bit 15 = 0)",
            ));
        }
        // A power-on value is what the part holds: bits the register does not have cannot be set.
        for (key, value, role) in [
            ("device.smpl_prd", self.smpl_prd, Role::SmplPrd),
            ("device.sens_avg", self.sens_avg, Role::SensAvg),
            ("device.msc_ctrl", self.msc_ctrl, Role::MscCtrl),
        ] {
            let mask = part.with_role(role).map_or(0xFFFF, |r| u32::from(r.mask));
            if value & !mask != 0 {
                return Err(bad(key, format!("0x{value:04X}"), &format!("only the register's bits 0x{mask:04X} set")));
            }
        }
        if GyroRange::from_bits((self.sens_avg >> 8) as u16 & 0x7).is_none() {
            return Err(bad(
                "device.sens_avg",
                format!("0x{:04X}", self.sens_avg),
                "range bits 10:8 = 100 (±300), 010 (±150) or 001 (±75)",
            ));
        }
        // unsigned_abs: i64::MIN is a valid TOML integer and has no i64 absolute value.
        if self.clock_ppb.unsigned_abs() > 100_000_000 {
            return Err(bad("device.clock_ppb", self.clock_ppb, "−1e8…1e8 ppb"));
        }
        check_nonneg("device.first_sample_us", self.first_sample_us)?;
        check_nonneg("device.reset_time_ms", self.reset_time_ms)?;
        check_nonneg("device.powered_before_ms", self.powered_before_ms)?;
        check_pos("device.sclk_max_hz", self.sclk_max_hz)?;
        check_pos("device.sclk_burst_max_hz", self.sclk_burst_max_hz)?;
        if self.sclk_burst_max_hz > self.sclk_max_hz {
            return Err(Error::Profile(format!(
                "key `device.sclk_burst_max_hz` = {} is above `device.sclk_max_hz` = {}: expected the burst limit \
                 to be the stricter one (≤ the normal-mode limit)",
                self.sclk_burst_max_hz, self.sclk_max_hz
            )));
        }
        check_nonneg("device.t_stall_us", self.t_stall_us)?;
        check_nonneg("device.t_stall_slow_us", self.t_stall_slow_us)?;
        check_nonneg("device.t_datarate_us", self.t_datarate_us)?;
        check_nonneg("device.t_cs_ns", self.t_cs_ns)?;
        check_nonneg("device.t_sfs_ns", self.t_sfs_ns)?;
        Ok(())
    }
    /// The power-on SENS_AVG must be a value the part can hold. The device model accepts a smaller M
    /// and raises it like a write (with an event), as the part would; a profile stating one is
    /// rejected, because its SENS_AVG would read back differently from what it says.
    pub(crate) fn validate_power_on_sens_avg(&self) -> Result<()> {
        let Some(range) = GyroRange::from_bits((self.sens_avg >> 8) as u16 & 0x7) else {
            return Ok(()); // reported by `validate`
        };
        // The part raises M to the range's minimum on every write, so it cannot hold a smaller M:
        // a power-on value with one would read back differently from what the profile states.
        let m = (self.sens_avg & 0x7) as u8;
        let min_m = range.min_m();
        if m < min_m {
            return Err(bad(
                "device.sens_avg",
                format!("0x{:04X} (±{} °/s, M = {m})", self.sens_avg, range.rated_dps()),
                &format!(
                    "M (bits 2:0) ≥ {min_m} with the ±{} °/s range (bits 10:8): the part raises M to {min_m}, \
                     so write 0x{:04X}",
                    range.rated_dps(),
                    self.sens_avg & !0x7 | u32::from(min_m)
                ),
            ));
        }
        Ok(())
    }
}

/// The error-model presets `errors.preset` names (`device::error_model::ErrorParams::preset`).
pub const PRESET_NAMES: [&str; 4] = ["ideal", "adis16407", "adis16407-nulled", "adis16362"];
/// Default R of `errors.gauss_markov_update_ratio`: a term is redrawn at least R times per
/// correlation time, so the held value moves by ≈ σ·√(2/R) = 0.14 σ per update (`device::error_model`).
pub const DEFAULT_GAUSS_MARKOV_UPDATE_RATIO: f64 = 100.0;

/// Check `errors.gauss_markov_update_ratio` (the error model checks its parameters with this too).
pub fn check_update_ratio(ratio: f64) -> Result<()> {
    if !(ratio.is_finite() && ratio >= 1.0) {
        return Err(bad(
            "errors.gauss_markov_update_ratio",
            ratio,
            "a finite number ≥ 1 (below 1 a term would be held longer than its correlation time)",
        ));
    }
    Ok(())
}

/// The sensor error model applied inside the device (presets in the traces work).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Errors {
    /// Preset name: `ideal` or `adis16407`.
    pub preset: String,
    /// Seed of the random realisation.
    pub seed: u64,
    /// R of the bias-instability bank: each Gauss–Markov term is redrawn every m samples, m·Δt ≤ τ/R
    /// (`device::error_model` module docs: multi-rate bank).
    pub gauss_markov_update_ratio: f64,
}

impl Default for Errors {
    fn default() -> Self {
        Errors { preset: "ideal".into(), seed: 1, gauss_markov_update_ratio: DEFAULT_GAUSS_MARKOV_UPDATE_RATIO }
    }
}

impl Errors {
    pub(crate) fn validate(&self) -> Result<()> {
        if !PRESET_NAMES.contains(&self.preset.as_str()) {
            let names: Vec<String> = PRESET_NAMES.iter().map(|n| format!("`{n}`")).collect();
            return Err(bad("errors.preset", &self.preset, &format!("one of {}", names.join(", "))));
        }
        check_update_ratio(self.gauss_markov_update_ratio)
    }
}

/// How the firmware schedules its burst reads for one attitude step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Schedule {
    /// A burst every timer tick, a step every two ticks (rates at t, t+T/2, t+T; the last sample
    /// of a step is the first of the next). T = 2 × timer period.
    HalfStep,
    /// One burst per step (every tick); the midpoint rate is interpolated. T = timer period.
    Endpoint,
    /// Three bursts in a row each tick, treated as t, t+T/2, t+T. T = timer period.
    BackToBack,
}

/// Decode of the 14-bit output words.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Decode {
    /// The thesis code: valid bits, then its range tests (a stale value outside both ranges).
    Published,
    /// Mask and sign-extend with the configured range's LSB.
    Correct,
}

/// The yaw reference of the DCM's drift cancellation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum YawReference {
    /// The magnetometer, projected to the horizontal with the current attitude.
    Magnetometer,
    /// The GPS course over ground.
    Gps,
    /// None: yaw integrates the gyros open loop.
    None,
}

/// The DCM with drift cancellation (algorithms.md §2): one PI controller on the weighted roll–pitch and
/// yaw errors. No gains are published; the defaults are this model's [unconfirmed: chosen]; against the
/// source's recovery "within ≈ 10 s" see `firmware_model/SCHEMA.md` and `firmware/dcm.rs`'s
/// `pi_recovery_follows_the_linearised_loop`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Dcm {
    /// Proportional gain K_P, 1/s.
    pub kp: f64,
    /// Integral gain K_I, 1/s².
    pub ki: f64,
    /// Weight of the roll–pitch (accelerometer) error.
    pub w_rp: f64,
    /// Weight of the yaw error.
    pub w_yaw: f64,
    /// Where the yaw error comes from.
    pub yaw_reference: YawReference,
    /// Subtract the centripetal acceleration ω × [V, 0, 0] (V: GPS ground speed) from the accelerometer.
    pub centripetal: bool,
    /// Each component of the integrator ω_I is held within ± this, °/s.
    pub integrator_limit_dps: f64,
    /// Magnetic declination (the horizontal field's azimuth east of true north), degrees.
    pub declination_deg: f64,
    /// Below this GPS ground speed the course over ground gives no yaw error (it is undefined at
    /// rest), m/s.
    pub gps_min_speed_mps: f64,
    /// The roll–pitch and yaw gains are multiplied by this while a gyro axis is clipped and for
    /// `clip_recovery_s` after (the integrator is frozen meanwhile); 1: no change.
    pub clip_gain: f64,
    /// How long the raised gain lasts after the last clipped update, s.
    pub clip_recovery_s: f64,
    /// Pre-compensate the first-order update's lag: dθ·(1 + |dθ|²/3) (the renormalised R·(I + [dθ×])
    /// turns by atan|dθ|, dθ³/3 short).
    pub lag_compensation: bool,
    /// Errors beyond 90° (tilt, or heading from the magnetometer) pull at full strength: the error vector
    /// at unit length instead of sin e (which falls back to 0 at 180°).
    pub full_range: bool,
    /// The roll–pitch error is weighted by max(0, 1 − |‖f‖ − g|/(band·g)): a specific force whose norm is
    /// not g proves an acceleration, and then the accelerometer is not gravity; 0: no weighting.
    pub accel_norm_band: f64,
    /// While the gain is raised after a gyro clip, only K_P·(clip_gain − 1)·k is added, k the weight
    /// max(0, 1 − |‖f‖ − g|/(band·g)) of this band: the raised gain trusts the accelerometer only when its
    /// norm says it measures gravity; 0: the whole raised gain.
    pub clip_accel_band: f64,
}

impl Default for Dcm {
    fn default() -> Self {
        Dcm {
            kp: 0.2,
            ki: 0.0087,
            w_rp: 1.0,
            w_yaw: 1.0,
            yaw_reference: YawReference::None,
            centripetal: false,
            integrator_limit_dps: 5.0,
            declination_deg: 0.0,
            gps_min_speed_mps: 2.0,
            clip_gain: 1.0,
            clip_recovery_s: 0.0,
            lag_compensation: false,
            full_range: false,
            accel_norm_band: 0.0,
            clip_accel_band: 0.0,
        }
    }
}

impl Dcm {
    pub(crate) fn validate(&self) -> Result<()> {
        check_nonneg("firmware.dcm.kp", self.kp)?;
        check_nonneg("firmware.dcm.ki", self.ki)?;
        check_nonneg("firmware.dcm.w_rp", self.w_rp)?;
        check_nonneg("firmware.dcm.w_yaw", self.w_yaw)?;
        // ω_I is held in the direction-cosine class (Q30 under IQ: |x| < 2 rad/s = 114.6 °/s).
        check_range("firmware.dcm.integrator_limit_dps", self.integrator_limit_dps, 0.0, 90.0, "0…90 °/s")?;
        check_range("firmware.dcm.declination_deg", self.declination_deg, -180.0, 180.0, "−180…180 degrees")?;
        check_range("firmware.dcm.gps_min_speed_mps", self.gps_min_speed_mps, 0.0, 100.0, "0…100 m/s")?;
        check_range("firmware.dcm.clip_gain", self.clip_gain, 1.0, 100.0, "1…100")?;
        check_range("firmware.dcm.clip_recovery_s", self.clip_recovery_s, 0.0, 600.0, "0…600 s")?;
        check_range("firmware.dcm.accel_norm_band", self.accel_norm_band, 0.0, 1.0, "0…1 (a fraction of g)")?;
        check_range("firmware.dcm.clip_accel_band", self.clip_accel_band, 0.0, 1.0, "0…1 (a fraction of g)")?;
        Ok(())
    }
}

/// The magnetic disturbance gate of the fusing algorithms (`firmware/gating.rs`): the field used for
/// yaw is checked in norm and dip against a reference learned at rest. The tolerances and times are
/// this model's [unconfirmed: chosen on the BROAD trials, see `benchmarks/broad_eval.md`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MagGate {
    /// Gate the field (false: every field is used, as before the gate).
    pub enabled: bool,
    /// A field whose norm differs from the reference's by more than this fraction is not used.
    pub norm_tol: f64,
    /// A field whose dip differs from the reference's by more than this is not used, degrees.
    pub dip_tol_deg: f64,
    /// Rest needed before the reference is learned (and the low-pass time constant), s.
    pub rest_s: f64,
    /// Rest: |ω| below this, °/s.
    pub rest_gyro_dps: f64,
    /// Rest: |f| within this fraction of g.
    pub rest_accel_g: f64,
    /// A rejection longer than this adopts the field as the new reference, s.
    pub relearn_s: f64,
}

impl Default for MagGate {
    fn default() -> Self {
        MagGate {
            enabled: true,
            norm_tol: 0.1,
            dip_tol_deg: 10.0,
            rest_s: 1.0,
            rest_gyro_dps: 3.0,
            rest_accel_g: 0.05,
            relearn_s: 60.0,
        }
    }
}

impl MagGate {
    pub(crate) fn validate(&self) -> Result<()> {
        check_range("firmware.mag_gate.norm_tol", self.norm_tol, 0.0, 10.0, "0…10 (a fraction of the norm)")?;
        check_range("firmware.mag_gate.dip_tol_deg", self.dip_tol_deg, 0.0, 90.0, "0…90 degrees")?;
        check_range("firmware.mag_gate.rest_s", self.rest_s, 0.001, 600.0, "0.001…600 s")?;
        check_range("firmware.mag_gate.rest_gyro_dps", self.rest_gyro_dps, 0.0, 100.0, "0…100 °/s")?;
        check_range("firmware.mag_gate.rest_accel_g", self.rest_accel_g, 0.0, 1.0, "0…1 (a fraction of g)")?;
        check_range("firmware.mag_gate.relearn_s", self.relearn_s, 0.001, 3600.0, "0.001…3600 s")?;
        Ok(())
    }
}

/// The VQF-class filter (`firmware/vqf.rs`; Laidig & Seel 2022): time constants and bias-estimation
/// parameters. Defaults are the published method's defaults; the BROAD set is in
/// `python/sins_fw/broad_eval.py` (chosen on the ten trials, `benchmarks/broad_eval.md`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Vqf {
    /// Time constant of the accelerometer low-pass in the almost-inertial frame, s.
    pub tau_acc_s: f64,
    /// Time constant of the magnetometer heading correction, s.
    pub tau_mag_s: f64,
    /// Use the magnetometer for heading (false: 6D, heading open loop).
    pub magnetometer: bool,
    /// Estimate the gyro bias at rest.
    pub rest_bias: bool,
    /// Estimate the gyro bias in motion (from the accelerometer correction).
    pub motion_bias: bool,
    /// Initial standard deviation of the bias estimate, °/s.
    pub bias_sigma_init_dps: f64,
    /// Time for the bias estimate's variance to grow from 0 to `bias_sigma_init_dps`², s.
    pub bias_forgetting_s: f64,
    /// The bias estimate is held within ± this, °/s.
    pub bias_clip_dps: f64,
    /// Standard deviation of the motion bias measurement, °/s.
    pub bias_sigma_motion_dps: f64,
    /// Standard deviation of the rest bias measurement, °/s.
    pub bias_sigma_rest_dps: f64,
    /// Rest: the deviation of the gyro from its low-pass below this, °/s.
    pub rest_gyro_dps: f64,
    /// Rest: the deviation of the accelerometer from its low-pass below this, m/s².
    pub rest_accel_m_s2: f64,
    /// Rest: for at least this long, s.
    pub rest_min_s: f64,
    /// Time constant of the rest detection's low-pass, s.
    pub rest_tau_s: f64,
    /// The heading gain is multiplied by this for as long as the field was rejected, after it is
    /// accepted again (VQF's faster heading recovery).
    pub mag_recovery_gain: f64,
    /// The accelerometer correction's time constant is divided by this while a gyro axis is clipped and
    /// for `clip_recovery_s` after (and the motion bias estimate is frozen); 1: no change.
    pub clip_gain: f64,
    /// How long the raised accelerometer gain lasts after the last clipped update, s.
    pub clip_recovery_s: f64,
}

impl Default for Vqf {
    fn default() -> Self {
        Vqf {
            tau_acc_s: 3.0,
            tau_mag_s: 9.0,
            magnetometer: true,
            rest_bias: true,
            motion_bias: true,
            bias_sigma_init_dps: 0.5,
            bias_forgetting_s: 100.0,
            bias_clip_dps: 2.0,
            bias_sigma_motion_dps: 0.1,
            bias_sigma_rest_dps: 0.03,
            rest_gyro_dps: 2.0,
            rest_accel_m_s2: 0.5,
            rest_min_s: 1.5,
            rest_tau_s: 0.5,
            mag_recovery_gain: 2.0,
            clip_gain: 1.0,
            clip_recovery_s: 0.0,
        }
    }
}

impl Vqf {
    pub(crate) fn validate(&self) -> Result<()> {
        for (key, v, lo, hi, allowed) in [
            ("firmware.vqf.tau_acc_s", self.tau_acc_s, 0.001, 1000.0, "0.001…1000 s"),
            ("firmware.vqf.tau_mag_s", self.tau_mag_s, 0.001, 1000.0, "0.001…1000 s"),
            ("firmware.vqf.bias_sigma_init_dps", self.bias_sigma_init_dps, 0.0, 100.0, "0…100 °/s"),
            ("firmware.vqf.bias_forgetting_s", self.bias_forgetting_s, 0.001, 1e6, "0.001…1e6 s"),
            ("firmware.vqf.bias_clip_dps", self.bias_clip_dps, 0.0, 100.0, "0…100 °/s"),
            ("firmware.vqf.bias_sigma_motion_dps", self.bias_sigma_motion_dps, 1e-6, 100.0, "1e-6…100 °/s"),
            ("firmware.vqf.bias_sigma_rest_dps", self.bias_sigma_rest_dps, 1e-6, 100.0, "1e-6…100 °/s"),
            ("firmware.vqf.rest_gyro_dps", self.rest_gyro_dps, 0.0, 100.0, "0…100 °/s"),
            ("firmware.vqf.rest_accel_m_s2", self.rest_accel_m_s2, 0.0, 100.0, "0…100 m/s²"),
            ("firmware.vqf.rest_min_s", self.rest_min_s, 0.0, 600.0, "0…600 s"),
            ("firmware.vqf.rest_tau_s", self.rest_tau_s, 0.001, 600.0, "0.001…600 s"),
            ("firmware.vqf.mag_recovery_gain", self.mag_recovery_gain, 1.0, 100.0, "1…100"),
            ("firmware.vqf.clip_gain", self.clip_gain, 1.0, 100.0, "1…100"),
            ("firmware.vqf.clip_recovery_s", self.clip_recovery_s, 0.0, 600.0, "0…600 s"),
        ] {
            check_range(key, v, lo, hi, allowed)?;
        }
        Ok(())
    }
}

/// The numeric backend the firmware arithmetic runs in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Numeric {
    /// IEEE double: the golden reference.
    F64,
    /// C28x FPU single precision, round to nearest (after TI's start-up code).
    C28xF32,
    /// C28x FPU single precision, round toward zero (the RND32 reset value).
    C28xF32Rz,
    /// TI IQmath fixed point.
    Iq,
}

impl Numeric {
    /// Every backend, the golden reference first (Python reads their names from here:
    /// `sins_fw._core.NUMERICS`).
    pub const ALL: [Numeric; 4] = [Numeric::F64, Numeric::C28xF32, Numeric::C28xF32Rz, Numeric::Iq];

    /// The name `firmware.numeric` takes (serde's kebab-case name; a test keeps them equal).
    pub fn name(self) -> &'static str {
        match self {
            Numeric::F64 => "f64",
            Numeric::C28xF32 => "c28x-f32",
            Numeric::C28xF32Rz => "c28x-f32-rz",
            Numeric::Iq => "iq",
        }
    }
}

/// Euler-angle extraction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Euler {
    /// atan principal values resolved by the published quadrant tables, with their "→0" rows.
    PublishedTables,
    /// atan2 for roll, atan2 mod 360° for yaw.
    Atan2,
}

/// Initial attitude.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum InitialAttitude {
    /// Q = [1, 0, 0, 0] (as published).
    Zero,
    /// Pitch and roll from the accelerometer averaged over `alignment_s`, yaw from `initial_yaw_deg`.
    Level,
}

/// What the firmware does when a timer tick arrives while the previous work still runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum OverrunPolicy {
    /// The PIE latches the interrupt: it runs as soon as the previous ISR returns.
    Queue,
    /// Ticks arriving while busy are lost.
    Drop,
    /// Interrupts are re-enabled in the ISR: the new tick preempts the old one.
    Nest,
}

/// How the GPIO pins are set when the firmware's `main` starts (the C firmware runtime and the host
/// board: `host::HostBoard`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum GpioAtStart {
    /// The chip selects of the SPI parts of `[[board.devices]]` are GPIO outputs driven high (what
    /// the board's boot code leaves them as [unconfirmed]: the reference firmware never sets their
    /// direction); every other pin as reset leaves it.
    #[default]
    ChipSelects,
    /// Every pin as reset leaves it (a GPIO input): the firmware sets up its pins itself, as a
    /// TI-style project's `InitGpio` does.
    Reset,
}

fn is_default_gpio(g: &GpioAtStart) -> bool {
    *g == GpioAtStart::default()
}

/// The wing unit's temperature compensation (`firmware.algorithm` = "wing"): each gyro axis is corrected
/// by its coefficient times its own X/Y/ZTEMP_OUT reading's distance from the register's zero (25 °C). The
/// source asks for the compensation ("barely reachable with the temperature compensated") and gives no
/// method or coefficients: the law and the reference are [unconfirmed], the coefficients a unit's
/// thermal calibration (`rust/core/src/firmware/wing/app.rs`). All zero: no compensation, and the burst's
/// temperature words are not decoded.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Wing {
    /// Gyro bias temperature coefficient per axis (x, y, z), °/s per °C.
    pub gyro_bias_tempco_dps_per_c: [f64; 3],
}

impl Wing {
    /// True when the profile compensates nothing.
    pub fn is_default(&self) -> bool {
        *self == Wing::default()
    }

    /// Whether the firmware compensates the gyro's temperature drift.
    pub fn compensates(&self) -> bool {
        self.gyro_bias_tempco_dps_per_c.iter().any(|&k| k != 0.0)
    }

    pub(crate) fn validate(&self) -> Result<()> {
        for (axis, k) in ["x", "y", "z"].iter().zip(self.gyro_bias_tempco_dps_per_c) {
            check_range(
                &format!("firmware.wing.gyro_bias_tempco_dps_per_c ({axis})"),
                k,
                -1.0,
                1.0,
                "−1…1 °/s per °C (the part's figure is 0.01)",
            )?;
        }
        Ok(())
    }
}

/// Where the firmware's code runs from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CodeLocation {
    /// Zero-wait-state RAM (ramfuncs).
    Ram,
    /// Flash with wait states.
    Flash,
}

/// The rule turning rate samples into angle increments for the rotation-vector algorithm.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum IncrementRule {
    /// Trapezoid between consecutive rate samples.
    Trapezoid,
    /// Rectangle: each sub-interval's increment is its end rate × h.
    Rectangle,
}

/// The quaternion-derivative matrix of the RK4 update.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum QuatDerivative {
    /// Q̇ = ½ Q ⊗ [0, ω]: the kinematics that match the published T matrix (C_b^n). Equals the
    /// published appendix-1 code in the rows of q̇0, q̇1, q̇3.
    Correct,
    /// The appendix-1 code as printed: its q̇2 row reads `ωy·q0 − ωz·q1 − ωx·q3` (the sign of the
    /// last term is wrong, the matrix is not skew-symmetric) [unconfirmed: OCR, four lines agree].
    Published,
}

/// The reference application's name (`firmware.application`).
pub const ADIS_BURST: &str = "adis-burst";

fn is_adis_burst(name: &str) -> bool {
    name == ADIS_BURST
}

/// Firmware choices.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Firmware {
    /// The application the board runs (`firmware::application::APPLICATIONS`): its acquisition and
    /// loop; looked up when the firmware is built.
    #[serde(skip_serializing_if = "is_adis_burst")]
    pub application: String,
    /// Acquisition schedule.
    pub schedule: Schedule,
    /// Output-word decode.
    pub decode: Decode,
    /// Attitude update.
    pub algorithm: String,
    /// Coning samples for the rotation-vector algorithm (1, 2 or 3).
    pub coning_samples: u32,
    /// Rates → angle increments rule for the rotation-vector algorithm.
    pub increment_rule: IncrementRule,
    /// Numeric backend.
    pub numeric: Numeric,
    /// Euler extraction.
    pub euler: Euler,
    /// Below this magnitude T33 or T11 counts as "→0" in the published tables.
    pub euler_zero_eps: f64,
    /// Subtract earth rate and transport rate (ω_nb = ω_ib − C_n^b(ω_ie + ω_en)).
    pub earth_rate: bool,
    /// Initial attitude.
    pub initial_attitude: InitialAttitude,
    /// Initial yaw for `level`, degrees.
    pub initial_yaw_deg: f64,
    /// Still period averaged by `level`, s.
    pub alignment_s: f64,
    /// Overrun policy.
    pub overrun: OverrunPolicy,
    /// Where the code runs from.
    pub code_location: CodeLocation,
    /// Run the navigation (velocity, position) every step.
    pub navigation: bool,
    /// The quaternion-derivative rows of the RK4 update.
    pub quat_derivative: QuatDerivative,
    /// The firmware's g → m/s² factor for decoded accelerations [unconfirmed: the conversion is
    /// not published; 9.80665 is the standard gravity the data sheet's g means].
    pub accel_g_m_s2: f64,
    /// The gyro range the published decode was written for, °/s (75, 150 or 300): it scales every
    /// gyro code by range / 6000 °/s (the 6000 codes its range test accepts), 0.05 °/s for ±300,
    /// whatever SENS_AVG selects. `decode = "correct"` uses SENS_AVG's range instead.
    pub gyro_range_dps: f64,
    /// The DCM algorithm's gains and references (`firmware.algorithm` = "dcm").
    pub dcm: Dcm,
    /// The magnetic disturbance gate of the fusing algorithms (`dcm`, `vqf`).
    pub mag_gate: MagGate,
    /// The VQF-class algorithm's parameters (`firmware.algorithm` = "vqf").
    pub vqf: Vqf,
    /// How the GPIO pins are set when the firmware's `main` starts.
    #[serde(skip_serializing_if = "is_default_gpio")]
    pub gpio_at_start: GpioAtStart,
    /// The wing unit's temperature compensation (`firmware.algorithm` = "wing").
    #[serde(skip_serializing_if = "Wing::is_default")]
    pub wing: Wing,
}

impl Default for Firmware {
    fn default() -> Self {
        Firmware {
            application: ADIS_BURST.into(),
            schedule: Schedule::HalfStep,
            decode: Decode::Published,
            algorithm: "rk4".into(),
            coning_samples: 2,
            increment_rule: IncrementRule::Trapezoid,
            numeric: Numeric::C28xF32,
            euler: Euler::PublishedTables,
            euler_zero_eps: 1e-6,
            earth_rate: true,
            initial_attitude: InitialAttitude::Zero,
            initial_yaw_deg: 0.0,
            alignment_s: 1.0,
            overrun: OverrunPolicy::Queue,
            code_location: CodeLocation::Ram,
            navigation: true,
            quat_derivative: QuatDerivative::Correct,
            accel_g_m_s2: 9.80665,
            gyro_range_dps: 300.0,
            dcm: Dcm::default(),
            mag_gate: MagGate::default(),
            vqf: Vqf::default(),
            gpio_at_start: GpioAtStart::default(),
            wing: Wing::default(),
        }
    }
}

impl Firmware {
    pub(crate) fn validate(&self) -> Result<()> {
        if !(1..=3).contains(&self.coning_samples) {
            return Err(bad("firmware.coning_samples", self.coning_samples, "1, 2 or 3"));
        }
        check_nonneg("firmware.euler_zero_eps", self.euler_zero_eps)?;
        if !self.initial_yaw_deg.is_finite() {
            return Err(bad("firmware.initial_yaw_deg", self.initial_yaw_deg, "a finite angle in degrees"));
        }
        check_nonneg("firmware.alignment_s", self.alignment_s)?;
        if self.initial_attitude == InitialAttitude::Level && self.alignment_s <= 0.0 {
            return Err(Error::Profile(format!(
                "key `firmware.alignment_s` = {} with `firmware.initial_attitude` = \"level\": expected a still \
                 period > 0 s to average the accelerometer over (or `firmware.initial_attitude` = \"zero\")",
                self.alignment_s
            )));
        }
        check_range("firmware.accel_g_m_s2", self.accel_g_m_s2, 1.0, 100.0, "1…100 m/s² per g")?;
        if GyroRange::from_dps(self.gyro_range_dps).is_err() {
            return Err(bad("firmware.gyro_range_dps", self.gyro_range_dps, "75, 150 or 300 (°/s)"));
        }
        self.dcm.validate()?;
        self.mag_gate.validate()?;
        self.vqf.validate()?;
        self.wing.validate()?;
        Ok(())
    }
}

/// Navigation initial state and the earth model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Navigation {
    /// Initial latitude, degrees [unconfirmed: the thesis does not state it; Hohhot].
    pub latitude_deg: f64,
    /// Initial longitude, degrees [unconfirmed].
    pub longitude_deg: f64,
    /// Initial height, m [unconfirmed].
    pub height_m: f64,
    /// Initial velocity east, north, up, m/s.
    pub velocity_enu: [f64; 3],
    /// Equatorial radius R_e, m (WGS-84).
    pub earth_radius_m: f64,
    /// Flattening e.
    pub flattening: f64,
    /// Earth rate ω_ie, rad/s.
    pub earth_rate_rad_s: f64,
    /// Gravity at the equator, m/s² (normal gravity, Somigliana closed form).
    pub gravity_equator: f64,
}

impl Default for Navigation {
    fn default() -> Self {
        Navigation {
            latitude_deg: 40.84,
            longitude_deg: 111.75,
            height_m: 1050.0,
            velocity_enu: [0.0; 3],
            earth_radius_m: 6_378_137.0,
            flattening: 1.0 / 298.257,
            earth_rate_rad_s: 7.292115e-5,
            gravity_equator: 9.780_325_335_9,
        }
    }
}

impl Navigation {
    pub(crate) fn validate(&self) -> Result<()> {
        if !(self.latitude_deg.is_finite() && self.latitude_deg.abs() < 89.0) {
            return Err(bad(
                "navigation.latitude_deg",
                self.latitude_deg,
                "−89…89 degrees (the local-level frame is singular at the poles)",
            ));
        }
        if !self.longitude_deg.is_finite() {
            return Err(bad("navigation.longitude_deg", self.longitude_deg, "a finite angle"));
        }
        check_range("navigation.height_m", self.height_m, -1e4, 1e5, "−1e4…1e5 m (a mine to the edge of space)")?;
        // Beyond orbital speeds the position update leaves the ellipsoid within a step.
        if self.velocity_enu.iter().any(|v| !(v.is_finite() && v.abs() <= 1e4)) {
            return Err(bad(
                "navigation.velocity_enu",
                format!("{:?}", self.velocity_enu),
                "three m/s values within ±1e4",
            ));
        }
        // Earth-model constants may be changed (another ellipsoid, an exaggerated earth rate for a
        // test), but only within ranges where the navigation equations stay finite: outside them
        // the output would turn to NaN without a word.
        for (key, value, lo, hi, what) in [
            ("navigation.earth_radius_m", self.earth_radius_m, 1e6, 1e8, "1e6…1e8 m (a planet-sized radius)"),
            ("navigation.flattening", self.flattening, 0.0, 0.1, "0…0.1 (an ellipsoid's flattening)"),
            ("navigation.earth_rate_rad_s", self.earth_rate_rad_s, 0.0, 1e-2, "0…0.01 rad/s"),
            ("navigation.gravity_equator", self.gravity_equator, 1.0, 100.0, "1…100 m/s²"),
        ] {
            check_range(key, value, lo, hi, what)?;
        }
        Ok(())
    }
}

/// IQmath Q formats per quantity class (fractional bits, 1…30).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct IqFormats {
    /// Quaternion and direction-cosine elements.
    pub quat_q: u32,
    /// Angular rates (rad/s) and increments.
    pub rate_q: u32,
    /// Angles.
    pub angle_q: u32,
    /// Specific force, accelerations, velocities.
    pub accel_q: u32,
    /// Latitude and longitude (rad) and the flattening: |x| ≤ π needs 2 integer bits, hence ≤ 29.
    pub nav_q: u32,
    /// Lengths in metres (earth radius, R + h, height): 6.4e6 m needs 23 integer bits, hence ≤ 8.
    pub length_q: u32,
    /// Everything else (GLOBAL_Q).
    pub global_q: u32,
}

impl Default for IqFormats {
    fn default() -> Self {
        IqFormats { quat_q: 30, rate_q: 24, angle_q: 24, accel_q: 20, nav_q: 29, length_q: 8, global_q: 24 }
    }
}

impl IqFormats {
    pub(crate) fn validate(&self) -> Result<()> {
        for (k, v) in [
            ("iq.quat_q", self.quat_q),
            ("iq.rate_q", self.rate_q),
            ("iq.angle_q", self.angle_q),
            ("iq.accel_q", self.accel_q),
            ("iq.nav_q", self.nav_q),
            ("iq.length_q", self.length_q),
            ("iq.global_q", self.global_q),
        ] {
            if !(1..=30).contains(&v) {
                return Err(bad(k, v, "1…30 fractional bits"));
            }
        }
        Ok(())
    }
}

/// Compute-time model settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Timing {
    /// Cycle-cost table, relative to `firmware_model/`.
    pub costs: String,
    /// SYSCLKOUT cycles of one iteration of a status-polling loop (load, test, branch).
    pub poll_loop_cycles: u32,
}

impl Default for Timing {
    fn default() -> Self {
        Timing { costs: "c28x-costs.toml".into(), poll_loop_cycles: 39 }
    }
}

impl Timing {
    pub(crate) fn validate(&self) -> Result<()> {
        if self.costs.trim().is_empty() {
            return Err(bad("timing.costs", "\"\"", "a cost-table file name"));
        }
        if self.poll_loop_cycles == 0 || self.poll_loop_cycles > 1000 {
            return Err(bad("timing.poll_loop_cycles", self.poll_loop_cycles, "1…1000 cycles"));
        }
        Ok(())
    }
}
