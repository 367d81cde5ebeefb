//! The ADIS16xxx family device: register file (the part's map, `part.rs`), sampling engine on its
//! own clock, filter, calibration registers and GLOB_CMD. The SPI slave side is in `slave.rs`.
//!
//! The device is lazy: it computes samples only when time is moved on ([`Adis::advance_to`],
//! or a frame or write at a later time). Every internal sample is still processed in order, since the
//! filter is stateful, but nothing is allocated per sample.

use super::encoding::{
    sign_extend, surely_unclipped, to_field, Channel, FieldCode, GyroRange, ACCEL_LSB_G, GYRO_OFF_LSB_DPS,
    MAG_HIC_LSB_GAUSS, MAG_SIC_UNITY,
};
use super::faults::{DeviceFaults, SampleFaults};
use super::filter::Bartlett;
use super::frame::{MinPs, ReadRecord};
use super::part::{Access, Format, Part, PowerOn, RegisterDef, Role, MAX_BURST_WORDS, SLOTS};
use super::sampler::{sample_clock, Constant, Ideal, Schedule, SensorErrors, Stimulus};
use super::spi_rules::SpiRules;
use super::spi_timing::SpiTiming;
use super::Physical;
use crate::error::{Error, Result};
use crate::events::{Event, EventLog, Severity};
use crate::profile::{Device, Faults, TimingMode};
use crate::time::{s_to_ps, Clock, Ps, PS_PER_S};

/// Model choices the data sheet leaves open, each with the documented default. (They are model
/// parameters rather than profile keys for now; see the report on lifting them into the profile.)
#[derive(Debug, Clone, PartialEq)]
pub struct ModelOptions {
    /// Run the Bartlett filter on the magnetometer and barometer too. Default `false`: the spec puts
    /// SENS_AVG's filter on the inertial sensors, and the family's later parts (ADIS16448) filter only
    /// gyro and accelerometer [unconfirmed for the 16407].
    pub filter_mag_baro: bool,
    /// DIAG_STAT bit set when an output clips at its field limit (sibling map: bit 4) [unconfirmed].
    pub diag_overrange_bit: u8,
    /// DIAG_STAT bit set while the supply is above `supply_high_v` (sibling map: bit 1) [unconfirmed].
    pub diag_supply_high_bit: u8,
    /// DIAG_STAT bit set while the supply is below `supply_low_v` (sibling map: bit 0) [unconfirmed].
    pub diag_supply_low_bit: u8,
    /// Supply above which the high-supply flag sets, V.
    pub supply_high_v: f64,
    /// Supply below which the low-supply flag sets, V.
    pub supply_low_v: f64,
    /// DIAG_STAT flags stay set until DIAG_STAT is read (sibling behaviour). When `false` the flags
    /// show the latest sample's conditions only.
    pub diag_clear_on_read: bool,
    /// Smallest M allowed with the ±150 °/s range; a smaller SENS_AVG[2:0] is raised to it [unconfirmed].
    pub min_m_150: u8,
    /// Smallest M allowed with the ±75 °/s range [unconfirmed].
    pub min_m_75: u8,
}

impl Default for ModelOptions {
    fn default() -> Self {
        ModelOptions {
            filter_mag_baro: false,
            diag_overrange_bit: 4,
            diag_supply_high_bit: 1,
            diag_supply_low_bit: 0,
            supply_high_v: 5.25,
            supply_low_v: 4.75,
            diag_clear_on_read: true,
            min_m_150: GyroRange::Dps150.min_m(),
            min_m_75: GyroRange::Dps75.min_m(),
        }
    }
}

impl ModelOptions {
    fn validate(&self) -> Result<()> {
        for (key, bit) in [
            ("diag_overrange_bit", self.diag_overrange_bit),
            ("diag_supply_high_bit", self.diag_supply_high_bit),
            ("diag_supply_low_bit", self.diag_supply_low_bit),
        ] {
            if bit > 15 {
                return Err(Error::Config(format!("device option {key} = {bit}: expected a DIAG_STAT bit 0…15")));
            }
        }
        for (key, m) in [("min_m_150", self.min_m_150), ("min_m_75", self.min_m_75)] {
            if m > super::filter::MAX_M {
                return Err(Error::Config(format!("device option {key} = {m}: expected M in 0…7")));
            }
        }
        if !(self.supply_low_v.is_finite() && self.supply_high_v.is_finite() && self.supply_low_v < self.supply_high_v)
        {
            return Err(Error::Config(format!(
                "device options supply_low_v = {}, supply_high_v = {}: expected finite values, low < high",
                self.supply_low_v, self.supply_high_v
            )));
        }
        Ok(())
    }

    /// Smallest M the range allows.
    pub fn min_m(&self, range: GyroRange) -> u8 {
        match range {
            GyroRange::Dps300 => 0,
            GyroRange::Dps150 => self.min_m_150,
            GyroRange::Dps75 => self.min_m_75,
        }
    }
}

/// One internal sample: its index since power-on and its instant.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct SampleStamp {
    /// Sample index (counts every sample since power-on, across SMPL_PRD changes and resets).
    pub index: u64,
    /// Time the sample was taken and the output registers updated.
    pub t: Ps,
}

/// The pin data ready is driven on (MSC_CTRL[0]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DataReadyLine {
    /// DIO1 (MSC_CTRL[0] = 0).
    Dio1,
    /// DIO2 (MSC_CTRL[0] = 1).
    Dio2,
}

/// A data-ready assertion: the active edge at the instant the output registers updated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct DataReady {
    /// Time of the active edge.
    pub t: Ps,
    /// The sample that caused it.
    pub sample_index: u64,
    /// The pin.
    pub line: DataReadyLine,
    /// Polarity (MSC_CTRL[1]): `true` when the active edge is rising.
    pub active_high: bool,
}

/// The SPI timing rules of the profile, in picoseconds, converted once.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Limits {
    pub sclk_max_hz: f64,
    pub sclk_burst_max_hz: f64,
    pub t_stall_ps: f64,
    pub t_stall_slow_ps: f64,
    pub t_datarate_ps: f64,
    pub t_cs_ps: f64,
    pub t_sfs_ps: f64,
    /// The SPI rules the family shares with every SPI part (normal-mode SCLK, tCS, tSFS, mode 3,
    /// 16-bit frames), checked by the shared checker.
    pub spi: SpiRules,
    /// The family's own rules as whole-ps bounds, for the per-frame checks: the shortest SCLK period
    /// in a burst, stall, tDATARATE.
    pub min_burst_sclk_period: MinPs,
    pub min_stall: MinPs,
    pub min_stall_slow: MinPs,
    pub min_datarate: MinPs,
    pub strict: bool,
    pub corrupt_word: u16,
    pub idle_word: u16,
    pub burst_command: u16,
}

/// Where the family protocol finds a part's registers, worked out once from its declaration.
#[derive(Debug, Clone)]
pub(super) struct Layout {
    pub part: &'static Part,
    /// Slot → index into the part's registers ([`NONE`] where none lives).
    index: [u8; SLOTS],
    /// Bits of `nd` that belong to the output registers.
    output_slots: u64,
    diag: usize,
    msc: usize,
    smpl: usize,
    sens: usize,
    flash_cnt: Option<usize>,
    /// Slots of the calibration registers XGYRO_OFF … ZMAGN_SIC (`None`: the part has no such register).
    calibration: [Option<usize>; 12],
    /// The output registers.
    outputs: Outputs,
    /// Slots of the burst's registers, in burst order (the first `burst_len`).
    burst_slots: [usize; MAX_BURST_WORDS],
    pub burst_len: usize,
    /// ND bits of the first `i` burst words (a run of burst words clears its ND flags with two look-ups).
    burst_nd_prefix: [u64; MAX_BURST_WORDS + 1],
}

const NONE: u8 = u8::MAX;

/// The output registers of a part: slot, channel, axis (a fixed array: the calibration copies it).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Outputs {
    list: [(u8, Channel, u8); 16],
    len: usize,
}

impl Layout {
    fn of(part: &'static Part) -> Layout {
        let mut index = [NONE; SLOTS];
        let mut outputs = Outputs { list: [(0, Channel::Supply, 0); 16], len: 0 };
        let mut calibration = [None; 12];
        let mut output_slots = 0u64;
        for (i, r) in part.registers.iter().enumerate() {
            index[r.slot()] = i as u8;
            match r.role {
                Role::Output(ch, axis) => {
                    outputs.list[outputs.len] = (r.slot() as u8, ch, axis);
                    outputs.len += 1;
                    output_slots |= 1 << r.slot();
                }
                Role::GyroOffset(a) => calibration[usize::from(a)] = Some(r.slot()),
                Role::AccelOffset(a) => calibration[3 + usize::from(a)] = Some(r.slot()),
                Role::MagHardIron(a) => calibration[6 + usize::from(a)] = Some(r.slot()),
                Role::MagSoftIron(a) => calibration[9 + usize::from(a)] = Some(r.slot()),
                _ => {}
            }
        }
        let role = |role| part.with_role(role).map(RegisterDef::slot);
        // The part tests hold every declaration to having these roles.
        let must = |r| role(r).unwrap_or(0);
        let mut burst_slots = [0; MAX_BURST_WORDS];
        let mut burst_nd_prefix = [0u64; MAX_BURST_WORDS + 1];
        for (i, &a) in part.burst.iter().enumerate() {
            burst_slots[i] = s(a);
            burst_nd_prefix[i + 1] = burst_nd_prefix[i] | 1 << s(a);
        }
        Layout {
            part,
            index,
            output_slots,
            diag: must(Role::DiagStat),
            msc: must(Role::MscCtrl),
            smpl: must(Role::SmplPrd),
            sens: must(Role::SensAvg),
            flash_cnt: role(Role::FlashCount),
            calibration,
            outputs,
            burst_slots,
            burst_len: part.burst.len(),
            burst_nd_prefix,
        }
    }

    /// The register holding byte address `addr`, if any.
    pub fn lookup(&self, addr: u8) -> Option<&'static RegisterDef> {
        let i = *self.index.get(usize::from(addr >> 1))?;
        self.part.registers.get(usize::from(i))
    }

    /// The register slot of burst word `i`.
    #[inline]
    pub fn burst_slot(&self, i: usize) -> usize {
        self.burst_slots[i]
    }

    /// The register address of burst word `i`.
    pub fn burst_register(&self, i: usize) -> u8 {
        self.part.burst[i]
    }

    /// ND bits of the output registers of burst words `words` (each register appears once in a
    /// burst, so the prefix difference is exactly theirs).
    #[inline]
    fn burst_nd_mask(&self, words: std::ops::Range<usize>) -> u64 {
        self.burst_nd_prefix[words.end] & !self.burst_nd_prefix[words.start]
    }

    /// The calibration words (XGYRO_OFF … ZMAGN_SIC) in `regs`, the neutral value where the part has none.
    fn calibration_words(&self, regs: &[u16; SLOTS]) -> [u16; 12] {
        std::array::from_fn(|i| self.calibration[i].map_or(if i >= 9 { MAG_SIC_UNITY } else { 0 }, |s| regs[s]))
    }
}

/// Add the spikes of `sf` to the filtered values they concern (by burst index of the register).
fn spike(f: &mut Physical, sf: &SampleFaults) {
    let d = &sf.spike;
    f.supply_v += d[0];
    for i in 0..3 {
        f.gyro_dps[i] += d[1 + i];
        f.accel_g[i] += d[4 + i];
        f.mag_gauss[i] += d[7 + i];
    }
    f.baro_mbar += d[10] + d[11];
    f.temp_c += d[12];
    f.aux_v += d[13];
}

/// The word a read of `slot` returns from the register image `regs` with ND flags `nd`: outputs
/// carry ND (bit 15) and EA (bit 14, any DIAG_STAT flag).
#[inline]
fn word(layout: &Layout, regs: &[u16; SLOTS], nd: u64, slot: usize) -> u16 {
    let value = regs[slot];
    if layout.output_slots >> slot & 1 == 0 {
        return value;
    }
    let nd = if nd >> slot & 1 != 0 { 0x8000 } else { 0 };
    let ea = if regs[layout.diag] != 0 { 0x4000 } else { 0 };
    value | nd | ea
}

/// Slot of a register address.
const fn s(a: u8) -> usize {
    (a >> 1) as usize
}

/// The calibration registers in the units of the outputs they correct, and what they make of the
/// overrange test. The device applies them at every sample (the overrange flag) but they are written
/// almost never, so it keeps them converted ([`Adis::refresh_calibration`]).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Calibration {
    /// The register words (XGYRO_OFF … ZMAGN_SIC) the values come from.
    words: [u16; 12],
    /// The gyro range the unclipped intervals and the encodings are for.
    range: GyroRange,
    /// How each output register (the first `n_outputs`) encodes a sample, resolved from the part's
    /// declaration, these registers and the range: a sample's encoding is arithmetic only.
    outputs: [OutputCode; 16],
    n_outputs: usize,
    /// The factor from g to the encoder's accelerometer unit (3.333 mg LSBs): 3.333 mg over the
    /// part's accelerometer LSB (exactly 1 for the ADIS16407, so its codes are unchanged bit for bit).
    accel_scale: f64,
    /// X/Y/ZGYRO_OFF, °/s.
    gyro_offset: [f64; 3],
    /// X/Y/ZACCL_OFF, g.
    accel_offset: [f64; 3],
    /// X/Y/ZMAGN_HIC, gauss.
    hard_iron: [f64; 3],
    /// X/Y/ZMAGN_SIC, as a factor.
    soft_iron: [f64; 3],
    /// Per value of [`Physical::values`]: centre and half width of an interval of the filtered value
    /// in which no output field can clip (the encoding's [`surely_unclipped`] interval taken back
    /// through the calibration; the few roundings of that are ~1e-16 relative against its 1 % margin;
    /// an infinite width for a value no output of the part encodes).
    unclipped_centre: [f64; 13],
    unclipped_half_width: [f64; 13],
}

/// One output register's encoding: the value at index `value` of [`Physical::values`], calibrated
/// as `(value + add) × mul` (the offset, hard iron or soft iron and the accelerometer's scale; 0 and 1
/// where the channel has none, which change no bit), into `field`, written to register slot `slot`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct OutputCode {
    slot: u8,
    value: u8,
    add: f64,
    mul: f64,
    field: FieldCode,
}

impl OutputCode {
    /// The calibrated value this register encodes, from the sample's values.
    #[inline(always)]
    fn calibrated(&self, values: &[f64; 13]) -> f64 {
        (values[usize::from(self.value)] + self.add) * self.mul
    }
}

impl Calibration {
    fn of(layout: &Layout, regs: &[u16; SLOTS], range: GyroRange) -> Calibration {
        let words = layout.calibration_words(regs);
        let accel_lsb = layout.part.accel_lsb_g;
        let accel_scale = ACCEL_LSB_G / accel_lsb;
        let gyro_offset = std::array::from_fn(|i| f64::from(sign_extend(words[i], 13)) * GYRO_OFF_LSB_DPS);
        let accel_offset = std::array::from_fn(|i| f64::from(sign_extend(words[3 + i], 12)) * accel_lsb);
        let hard_iron = std::array::from_fn(|i| f64::from(sign_extend(words[6 + i], 14)) * MAG_HIC_LSB_GAUSS);
        let soft_iron: [f64; 3] = std::array::from_fn(|i| f64::from(words[9 + i]) / f64::from(MAG_SIC_UNITY));
        // Each interval as centre and half width (|v − centre| ≤ half width: three operations per
        // value), moved back through the calibration.
        let outputs = layout.outputs;
        let unclipped = |ch| {
            if !outputs.list[..outputs.len].iter().any(|o| o.1 == ch) {
                return (0.0, f64::INFINITY);
            }
            let (low, high) = surely_unclipped(ch, range);
            (0.5 * (low + high), 0.5 * (high - low))
        };
        let offset = |(centre, half_width): (f64, f64), by: f64| (centre - by, half_width);
        let (gyro, mag) = (unclipped(Channel::Gyro), unclipped(Channel::Mag));
        let accel = unclipped(Channel::Accel);
        let accel = (accel.0 / accel_scale, accel.1 / accel_scale);
        let mag_axis = |i: usize| {
            // (v + hard iron) × soft iron; a zero soft iron makes every value encode as 0.
            let sic = soft_iron[i];
            if sic > 0.0 {
                (mag.0 / sic - hard_iron[i], mag.1 / sic)
            } else {
                (0.0, f64::INFINITY)
            }
        };
        let baro = unclipped(Channel::Baro);
        let intervals = [
            offset(gyro, gyro_offset[0]),
            offset(gyro, gyro_offset[1]),
            offset(gyro, gyro_offset[2]),
            offset(accel, accel_offset[0]),
            offset(accel, accel_offset[1]),
            offset(accel, accel_offset[2]),
            mag_axis(0),
            mag_axis(1),
            mag_axis(2),
            if baro.1.is_finite() { baro } else { unclipped(Channel::BaroLow) },
            unclipped(Channel::Temp),
            unclipped(Channel::Supply),
            unclipped(Channel::Aux),
        ];
        let mut codes =
            [OutputCode { slot: 0, value: 0, add: 0.0, mul: 1.0, field: FieldCode::of(Channel::Supply, range) }; 16];
        for (code, &(slot, ch, axis)) in codes.iter_mut().zip(&outputs.list[..outputs.len]) {
            let i = usize::from(axis);
            // Indices into `Physical::values`: gyro, accel, mag x y z, baro, temp, supply, aux.
            let (value, add, mul) = match ch {
                Channel::Gyro => (i, gyro_offset[i], 1.0),
                Channel::Accel => (3 + i, accel_offset[i], accel_scale),
                // Hard iron adds, then soft iron scales [unconfirmed order; sibling ADIS16405].
                Channel::Mag => (6 + i, hard_iron[i], soft_iron[i]),
                Channel::Baro | Channel::BaroLow => (9, 0.0, 1.0),
                Channel::Temp => (10, 0.0, 1.0),
                Channel::Supply => (11, 0.0, 1.0),
                Channel::Aux => (12, 0.0, 1.0),
            };
            *code = OutputCode { slot, value: value as u8, add, mul, field: FieldCode::of(ch, range) };
        }
        Calibration {
            words,
            range,
            outputs: codes,
            n_outputs: outputs.len,
            accel_scale,
            gyro_offset,
            accel_offset,
            hard_iron,
            soft_iron,
            unclipped_centre: intervals.map(|(centre, _)| centre),
            unclipped_half_width: intervals.map(|(_, half_width)| half_width),
        }
    }

    /// Whether no output field can clip for the sample values `f`. A screen: `false` only means
    /// that the exact test ([`Calibration::outputs_overrange`]) must decide.
    #[inline(always)]
    fn nothing_can_clip(&self, f: &Physical) -> bool {
        let mut inside = true;
        for ((v, centre), half_width) in
            f.values().into_iter().zip(self.unclipped_centre).zip(self.unclipped_half_width)
        {
            // `&=`, not `&&`: no branch per value. NaN compares false, so it goes to the exact test.
            inside &= (v - centre).abs() <= half_width;
        }
        inside
    }

    /// Write the output registers' codes for the sample values `f` into `regs` (in place: the
    /// registers are not copied).
    fn encode_outputs(&self, f: &Physical, regs: &mut [u16; SLOTS]) {
        let values = f.values();
        for o in &self.outputs[..self.n_outputs] {
            // (Slots are below SLOTS: the mask only spares a bounds check.)
            regs[usize::from(o.slot) & (SLOTS - 1)] = o.field.code(o.calibrated(&values));
        }
    }

    /// Whether any output register clips at its field limit for the sample values `f`.
    fn outputs_overrange(&self, f: &Physical) -> bool {
        let values = f.values();
        self.outputs[..self.n_outputs].iter().fold(false, |over, o| over | o.field.clips(o.calibrated(&values)))
    }
}

/// The output words of a burst in progress (the SPI protocol's state, [`super::slave`]).
#[derive(Debug, Clone, Copy)]
pub(super) struct Burst {
    pub(super) words: [u16; MAX_BURST_WORDS],
    pub(super) len: usize,
    pub(super) sample: Option<SampleStamp>,
    pub(super) next: usize,
}

/// The slave's protocol state.
#[derive(Debug, Clone, Default)]
pub(crate) struct SlaveState {
    pub(super) cs_low: bool,
    pub(super) cs_fall: Ps,
    /// A frame has been clocked since CS fell.
    pub(super) framed_since_cs: bool,
    /// Last SCLK edge of the previous frame.
    pub(super) last_edge: Option<Ps>,
    /// The bus index of the previous frame ([`crate::bus::FrameTiming::index`]), which a CS↑ too
    /// soon after its last edge concerns.
    pub(super) last_index: u64,
    /// First SCLK edge of the previous frame when it was outside a burst (tDATARATE counts from it).
    pub(super) last_plain_start: Option<Ps>,
    /// Register asked for by the previous read frame.
    pub(super) pending_read: Option<u8>,
    /// A cs_hold violation under strict corrupts the next DOUT.
    pub(super) corrupt_next: bool,
    pub(super) burst: Option<Burst>,
    /// The records of the frame in progress (slot `frames % 2`) and of the latest finished frame (the
    /// other slot): finishing a frame moves on `frames` instead of copying the record (88 bytes).
    pub(super) records: [ReadRecord; 2],
    /// Frames finished since power-on.
    pub(super) frames: u64,
    /// Frames finished when CS last fell.
    pub(super) frames_at_cs_fall: u64,
    /// The record of the second frame to end since CS last fell (a burst's first data frame) as it
    /// ended, kept for the read records, which need that frame's sample after the whole burst has run.
    pub(super) second_in_window: Option<ReadRecord>,
    pub(super) log: Option<Vec<ReadRecord>>,
}

impl SlaveState {
    /// Forget the protocol state (a software reset); counters and the log stay.
    pub fn reset(&mut self) {
        self.pending_read = None;
        self.corrupt_next = false;
        self.burst = None;
    }

    /// `n` burst data frames ended: the burst moves on by `n` words, and is over after the last.
    pub(super) fn burst_frames_done(&mut self, n: usize) {
        if let Some(b) = &mut self.burst {
            b.next += n;
            if b.next == b.len {
                self.burst = None;
            }
        }
    }

    /// Slot of the frame in progress.
    pub(super) fn current(&self) -> usize {
        (self.frames % 2) as usize
    }

    /// Slot of the latest finished frame.
    pub(super) fn finished(&self) -> usize {
        self.current() ^ 1
    }

    /// The latest finished frame.
    pub(super) fn last(&self) -> Option<&ReadRecord> {
        (self.frames > 0).then(|| &self.records[self.finished()])
    }

    /// The number (counted as `frames`) of the second frame to end since CS last fell.
    pub(super) fn second_in_window_number(&self) -> u64 {
        self.frames_at_cs_fall + 1
    }
}

/// The power-on value of this register for a device profile.
fn power_on_value(r: &RegisterDef, cfg: &Device) -> u16 {
    // The profile validates these to 16 bits.
    let v = match r.power_on {
        PowerOn::Fixed(v) => v,
        PowerOn::ProdId => cfg.prod_id as u16,
        PowerOn::SmplPrd => cfg.smpl_prd as u16,
        PowerOn::SensAvg => cfg.sens_avg as u16,
        PowerOn::MscCtrl => cfg.msc_ctrl as u16,
        PowerOn::LotId1 => cfg.lot_id1 as u16,
        PowerOn::LotId2 => cfg.lot_id2 as u16,
        PowerOn::SerialNum => cfg.serial_num as u16,
    };
    v & r.mask
}

/// A part of the ADIS16xxx family (which one: the profile's `device.part`).
pub struct Adis {
    pub(super) layout: Layout,
    pub(super) limits: Limits,
    opts: ModelOptions,
    clock_ppb: i64,
    reset_ps: Ps,
    regs: [u16; SLOTS],
    /// The register image a software reset restores (power-on values until a flash update).
    flash: [u16; SLOTS],
    /// The power-on register values (what a factory restore returns the calibration registers to).
    factory: [u16; SLOTS],
    /// ND flags, one bit per slot.
    nd: u64,
    range: GyroRange,
    /// The calibration registers converted, as of the words and range it holds
    /// ([`Adis::refresh_calibration`]).
    calibration: Calibration,
    /// Bartlett filters of gyro x, y, z and accel x, y, z.
    inertial_filter: Bartlett<6>,
    /// Bartlett filters of mag x, y, z and baro (used when `filter_mag_baro`).
    mag_baro_filter: Bartlett<4>,
    stimulus: Box<dyn Stimulus + Send>,
    errors: Box<dyn SensorErrors + Send>,
    schedule: Schedule,
    latest: Option<SampleStamp>,
    /// The latest sample after the sensor errors and the filter, before the calibration registers.
    filtered: Physical,
    /// The output registers have not been encoded from `filtered` yet. Most samples are overwritten
    /// by the next one before anything reads them (the firmware reads every 4 ms, the part samples
    /// every 1.22 ms), so encoding waits for a read or a register write
    /// ([`Adis::encode_pending`]); the result is the same bit for bit. (A sample with injected
    /// spikes, whose outputs differ from `filtered`, is encoded at once.)
    pending: bool,
    now: Ps,
    busy_until: Ps,
    /// How long the part had been powered at time 0, and its start-up time (ps): it answers and
    /// samples from `startup − powered_before` on ([`Adis::ready_at`]).
    powered_before: Ps,
    startup: Ps,
    /// The latest data-ready assertion as of the last MSC_CTRL change ([`Adis::set_data_ready_pin`]);
    /// the samples since then assert data ready on `data_ready_pin`, so the record is derived from
    /// the latest sample when asked for instead of being written at every sample.
    data_ready: Option<DataReady>,
    /// The pin and polarity data ready drives with the MSC_CTRL in force (`None`: MSC_CTRL[2] clear).
    data_ready_pin: Option<(DataReadyLine, bool)>,
    /// Index of the first sample taken with `data_ready_pin` in force.
    data_ready_pin_from: u64,
    /// The last sample's physical input was beyond the rated range (events fire on entry only).
    over_rated: bool,
    /// The last sample's supply was outside the DIAG_STAT supply limits (events on entry only).
    supply_bad: bool,
    /// Injected faults (profile `[faults]`); none by default.
    faults: DeviceFaults,
    pub(super) events: EventLog,
    pub(super) spi: SlaveState,
}

/// The reference board's part (the family device with the ADIS16407's declaration).
pub type Adis16407 = Adis;

impl std::fmt::Debug for Adis {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Adis")
            .field("part", &self.layout.part.name)
            .field("now", &self.now)
            .field("latest", &self.latest)
            .field("range", &self.range)
            .field("regs", &self.regs)
            .finish_non_exhaustive()
    }
}

impl Adis {
    /// A powered-on device configured by the profile, with the default [`ModelOptions`], a constant
    /// [`Physical::powered_idle`] stimulus and an ideal sensor.
    pub fn new(cfg: &Device) -> Result<Self> {
        Adis::with_options(cfg, ModelOptions::default())
    }

    /// [`Adis::new`] with explicit model options.
    pub fn with_options(cfg: &Device, opts: ModelOptions) -> Result<Self> {
        cfg.validate()?;
        opts.validate()?;
        let layout = Layout::of(cfg.part_decl()?);
        let mut regs = [0u16; SLOTS];
        for r in layout.part.registers {
            regs[r.slot()] = power_on_value(r, cfg);
        }
        let (t_stall_ps, t_cs_ps, t_sfs_ps) = (cfg.t_stall_us * 1e6, cfg.t_cs_ns * 1e3, cfg.t_sfs_ns * 1e3);
        let limits = Limits {
            sclk_max_hz: cfg.sclk_max_hz,
            sclk_burst_max_hz: cfg.sclk_burst_max_hz,
            t_stall_ps,
            t_stall_slow_ps: cfg.t_stall_slow_us * 1e6,
            t_datarate_ps: cfg.t_datarate_us * 1e6,
            t_cs_ps,
            t_sfs_ps,
            spi: SpiRules::new(&SpiTiming {
                sclk_max_hz: cfg.sclk_max_hz,
                cs_setup_ps: t_cs_ps,
                cs_hold_ps: Some(t_sfs_ps),
                ..layout.part.spi
            }),
            min_burst_sclk_period: MinPs::new(PS_PER_S as f64 / cfg.sclk_burst_max_hz),
            min_stall: MinPs::new(t_stall_ps),
            min_stall_slow: MinPs::new(cfg.t_stall_slow_us * 1e6),
            min_datarate: MinPs::new(cfg.t_datarate_us * 1e6),
            strict: cfg.timing_mode == TimingMode::Strict,
            corrupt_word: cfg.corrupt_word as u16,
            idle_word: cfg.dout_after_write as u16,
            burst_command: cfg.burst_command as u16,
        };
        // Before the start-up ends the part neither samples nor answers: its sample clock starts then.
        let (powered_before, startup) = (s_to_ps(cfg.powered_before_ms * 1e-3), s_to_ps(layout.part.startup_ms * 1e-3));
        let ready_at = startup.saturating_sub(powered_before);
        let first_t = ready_at + s_to_ps(cfg.first_sample_us * 1e-6);
        let smpl_prd = regs[layout.smpl];
        let calibration = Calibration::of(&layout, &regs, GyroRange::Dps300);
        let mut dev = Adis {
            layout,
            limits,
            opts,
            clock_ppb: cfg.clock_ppb,
            reset_ps: s_to_ps(cfg.reset_time_ms * 1e-3),
            regs,
            flash: regs,
            factory: regs,
            nd: 0,
            range: GyroRange::Dps300,
            calibration,
            inertial_filter: Bartlett::new(0)?,
            mag_baro_filter: Bartlett::new(0)?,
            stimulus: Box::new(Constant(Physical::powered_idle())),
            errors: Box::new(Ideal),
            schedule: Schedule::new(sample_clock(smpl_prd, cfg.clock_ppb), first_t, 0),
            latest: None,
            filtered: Physical::default(),
            pending: false,
            now: 0,
            busy_until: ready_at,
            powered_before,
            startup,
            data_ready: None,
            data_ready_pin: None,
            data_ready_pin_from: 0,
            over_rated: false,
            supply_bad: false,
            faults: DeviceFaults::default(),
            events: EventLog::default(),
            spi: SlaveState::default(),
        };
        let sens_avg = dev.checked_sens_avg(dev.regs[dev.layout.sens], 0);
        dev.regs[dev.layout.sens] = sens_avg;
        dev.flash = dev.regs;
        dev.factory = dev.regs;
        dev.set_data_ready_pin();
        dev.refresh_calibration();
        Ok(dev)
    }

    /// Replace what the sensor sees (takes effect from the next sample).
    pub fn set_stimulus(&mut self, stimulus: Box<dyn Stimulus + Send>) {
        self.stimulus = stimulus;
    }

    /// Replace the sensor error model (takes effect from the next sample).
    pub fn set_sensor_errors(&mut self, errors: Box<dyn SensorErrors + Send>) {
        self.errors = errors;
    }

    /// Inject the device kinds of the profile's faults (`[faults]`; `dropped_burst` acts on the bus
    /// and is left to whoever drives CS). Replaces any faults set before.
    pub fn set_faults(&mut self, faults: &Faults) {
        self.faults = DeviceFaults::from_profile(faults);
    }

    /// The model options in force.
    pub fn options(&self) -> &ModelOptions {
        &self.opts
    }

    /// Take every internal sample due at or before `t` (each updates the output registers).
    /// Moving backwards is a no-op.
    #[inline]
    pub fn advance_to(&mut self, t: Ps) {
        // Every SPI frame moves the device on, but a sample is due only every ~40 frames: the common
        // case is this comparison, kept out of the sampling loop's call.
        if self.next_event() > t {
            self.now = self.now.max(t);
            return;
        }
        self.take_samples_to(t);
    }

    /// The time of the next sample or injected reset: before it, [`Adis::advance_to`] only moves
    /// the device's time and nothing the device holds changes (a run of SPI frames relies on this).
    #[inline]
    pub(super) fn next_event(&self) -> Ps {
        self.schedule.next_t.min(self.faults.next_reset)
    }

    /// [`Adis::advance_to`] when a sample or an injected reset is due at or before `t`.
    #[inline(never)]
    fn take_samples_to(&mut self, t: Ps) {
        while self.schedule.next_t <= t || self.faults.next_reset <= t {
            // An injected reset due before (or at) the next sample happens first.
            if self.faults.next_reset <= self.schedule.next_t {
                let tr = self.faults.take_reset(&mut self.events);
                self.software_reset(tr);
                continue;
            }
            let (k, tk) = (self.schedule.next_k, self.schedule.next_t);
            self.take_sample(k, tk);
            self.schedule.step();
        }
        self.now = self.now.max(t);
    }

    /// SMPL_PRD as the part holds it (it decides the slow sample mode's tSTALL).
    pub(super) fn smpl_prd(&self) -> u16 {
        self.regs[self.layout.smpl]
    }

    /// The time the device has been advanced to.
    pub fn now(&self) -> Ps {
        self.now
    }

    /// The latest sample taken, if any since power-on or the last reset.
    pub fn latest_sample(&self) -> Option<SampleStamp> {
        self.latest
    }

    /// When the next sample will be taken (lets a harness schedule data-ready interrupts).
    pub fn next_sample(&self) -> SampleStamp {
        SampleStamp { index: self.schedule.next_k, t: self.schedule.next_t }
    }

    /// The internal sample clock in force (SMPL_PRD and the clock error).
    pub fn sample_clock(&self) -> Clock {
        self.schedule.clock()
    }

    /// The latest data-ready assertion (none while MSC_CTRL[2] is clear).
    pub fn last_data_ready(&self) -> Option<DataReady> {
        match (self.data_ready_pin, self.latest) {
            (Some((line, active_high)), Some(latest)) if latest.index >= self.data_ready_pin_from => {
                Some(DataReady { t: latest.t, sample_index: latest.index, line, active_high })
            }
            _ => self.data_ready,
        }
    }

    /// The gyro range in force.
    pub fn gyro_range(&self) -> GyroRange {
        self.range
    }

    /// M of the Bartlett filter in force (N = 2^M taps per stage).
    pub fn filter_m(&self) -> u8 {
        self.inertial_filter.m()
    }

    /// The latest sample's physical values after the sensor errors and the filter, before the
    /// calibration registers and quantisation.
    pub fn filtered(&self) -> &Physical {
        &self.filtered
    }

    /// End of the current software reset or of the power-on start-up (0 if neither is running
    /// at or after time 0); the part ignores SPI until then.
    pub fn busy_until(&self) -> Ps {
        self.busy_until
    }

    /// When the power-on start-up ends (0 if it ended before time 0).
    pub fn ready_at(&self) -> Ps {
        self.startup.saturating_sub(self.powered_before)
    }

    /// How long the part had been powered at time 0, and its start-up time, ps.
    pub(super) fn startup(&self) -> (Ps, Ps) {
        (self.powered_before, self.startup)
    }

    /// Events recorded so far.
    pub fn events(&self) -> &EventLog {
        &self.events
    }

    /// Take the recorded events out.
    pub fn drain_events(&mut self) -> Vec<crate::events::Event> {
        self.events.drain()
    }

    /// The register at even address `addr` as a read would return it (ND and EA included for the
    /// outputs), without a read's side effects.
    pub fn peek(&self, addr: u8) -> Result<u16> {
        let def = self.layout.lookup(addr).filter(|d| d.addr == addr).ok_or_else(|| {
            let part = self.layout.part;
            let names: Vec<String> = part.registers.iter().map(|r| format!("0x{:02X}", r.addr)).collect();
            Error::Register(format!(
                "no {} register at address 0x{addr:02X} (expected the even address of one of its registers: {})",
                part.name,
                names.join(", ")
            ))
        })?;
        if def.access == Access::W {
            return Err(Error::Register(format!("{} (0x{addr:02X}) is write-only", def.name)));
        }
        let mut regs = self.regs;
        if self.pending {
            // The kept calibration is the registers' own (refreshed at every write and reset).
            self.calibration.encode_outputs(&self.filtered, &mut regs);
        }
        Ok(word(&self.layout, &regs, self.nd, def.slot()))
    }

    /// [`Adis::peek`] by register name.
    pub fn peek_name(&self, name: &str) -> Result<u16> {
        let def =
            self.layout.part.by_name(name).ok_or_else(|| {
                Error::Register(format!("no register named `{name}` on the {}", self.layout.part.name))
            })?;
        self.peek(def.addr)
    }

    /// Write one byte at time `t`, as an SPI write frame ending at `t` does (0x8000 | addr<<8 | byte).
    pub fn write_byte(&mut self, addr: u8, byte: u8, t: Ps) {
        self.advance_to(t);
        // A write may change what the latest sample encodes to (offsets, range): encode it first.
        self.encode_pending();
        let Some(def) = self.layout.lookup(addr) else {
            self.events.push(Event::new(
                t,
                "write_unmapped",
                Severity::Warning,
                format!("write of 0x{byte:02X} to address 0x{addr:02X}: no register there; ignored"),
            ));
            return;
        };
        let high = addr & 1 == 1;
        match def.access {
            Access::R => self.events.push(Event::new(
                t,
                "read_only_write",
                Severity::Info,
                format!(
                    "write of 0x{byte:02X} to {} {} byte (0x{addr:02X}): the register is read-only; ignored",
                    def.name,
                    if high { "high" } else { "low" }
                ),
            )),
            Access::W => {
                if !high {
                    self.glob_cmd(byte, t);
                }
            }
            Access::RW => {
                let shift = if high { 8 } else { 0 };
                let old = self.regs[def.slot()];
                let new = ((old & !(0xFF << shift)) | (u16::from(byte) << shift)) & def.mask;
                self.set_control(def, new, t);
            }
        }
        self.refresh_calibration();
    }

    /// Write a whole register as two byte writes, low byte first (what a host does in two frames).
    pub fn write_register(&mut self, addr: u8, value: u16, t: Ps) {
        self.write_byte(addr & !1, value as u8, t);
        self.write_byte(addr | 1, (value >> 8) as u8, t);
    }

    /// Encode the output registers from the latest sample if that has not been done yet.
    fn encode_pending(&mut self) {
        if self.pending {
            self.calibration.encode_outputs(&self.filtered, &mut self.regs);
            self.pending = false;
        }
    }

    /// A read of register `addr` shifted out now: the word, the sample it holds (outputs only), and
    /// the read's side effects (ND clears; DIAG_STAT clears if so configured). `None` for an address
    /// holding no readable register (recorded as an event).
    pub(super) fn read_for_output(&mut self, addr: u8, t: Ps) -> (u16, Option<SampleStamp>) {
        let def = match self.layout.lookup(addr) {
            Some(d) if d.access != Access::W => d,
            found => {
                let what = found.map_or("no register".to_string(), |d| format!("{} is write-only", d.name));
                self.events.push(Event::new(
                    t,
                    "read_unreadable",
                    Severity::Warning,
                    format!("read of address 0x{addr:02X}: {what}; DOUT reads 0x0000"),
                ));
                return (0, None);
            }
        };
        let slot = def.slot();
        self.encode_pending();
        let w = word(&self.layout, &self.regs, self.nd, slot);
        let sample = if matches!(def.format, Format::Output(_)) { self.latest } else { None };
        self.nd &= !(1 << slot);
        if slot == self.layout.diag && self.opts.diag_clear_on_read {
            self.regs[slot] = 0;
        }
        (w, sample)
    }

    /// The output words of a burst (the first `burst_len`), as of now, with the sample they hold.
    pub(super) fn burst_snapshot(&mut self) -> ([u16; MAX_BURST_WORDS], Option<SampleStamp>) {
        self.encode_pending();
        // Every burst word is an output register (the part tests hold the declarations to it): its
        // word is the register with ND and EA ([`word`]), here without a branch per word.
        let ea = if self.regs[self.layout.diag] != 0 { 0x4000 } else { 0 };
        let mut words = [0u16; MAX_BURST_WORDS];
        let slots = self.layout.burst_slots[..self.layout.burst_len].iter();
        let all = self.layout.burst_nd_mask(0..self.layout.burst_len);
        if self.nd & all == all {
            // Usually every word is new (a sample since the last burst): one flag word for all.
            let flags = ea | 0x8000;
            words.iter_mut().zip(slots).for_each(|(w, &slot)| *w = self.regs[slot & (SLOTS - 1)] | flags);
        } else {
            for (w, &slot) in words.iter_mut().zip(slots) {
                *w = self.regs[slot & (SLOTS - 1)] | ea | ((self.nd >> slot & 1) as u16) << 15;
            }
        }
        (words, self.latest)
    }

    /// Clear the ND flags of the burst words `words` (indices into the part's burst) after a burst
    /// shifted them out, unless a newer sample than the one shifted out has set them since.
    #[inline]
    pub(super) fn clear_nd_after_burst(&mut self, words: std::ops::Range<usize>, shifted: Option<SampleStamp>) {
        if shifted == self.latest {
            self.nd &= !self.layout.burst_nd_mask(words);
        }
    }

    /// Whether the physical input is beyond the sensor's rated range (gyro ±300/150/75 °/s, accel
    /// the part's rated range). Above it the part's output is [unconfirmed]: the model keeps encoding the filtered value
    /// (clipping at the 14-bit limit) and sets the overrange flag; the first sample of each overrange
    /// episode is an event, so a trace that leaves the range shows where and by how much.
    fn check_rated_range(&mut self, p: &Physical, t: Ps) -> bool {
        let gyro_limit = self.range.rated_dps();
        let gyro = p.gyro_dps.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let accel = p.accel_g.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let accel_limit = self.layout.part.accel_rated_g;
        let over = gyro > gyro_limit || accel > accel_limit;
        if over && !self.over_rated {
            let (what, measured, limit, unit) = if gyro > gyro_limit {
                ("rate", gyro, gyro_limit, "°/s")
            } else {
                ("specific force", accel, accel_limit, "g")
            };
            self.events.push(Event::rule(
                t,
                "sensor_overrange",
                Severity::Warning,
                format!("{what} {measured:.1} {unit} beyond the rated ±{limit} {unit}: outputs clip, DIAG_STAT overrange set"),
                measured,
                limit,
            ));
        }
        self.over_rated = over;
        over
    }

    fn take_sample(&mut self, k: u64, t: Ps) {
        let mut p = self.stimulus.at(k, t);
        self.errors.apply(k, t, &mut p);
        if !p.is_finite() {
            self.sanitize(&mut p, k, t);
        }
        let faults = if t >= self.faults.watch_from {
            // A stuck register freezes what the previous sample left in it.
            self.encode_pending();
            Some(self.sample_faults(t))
        } else {
            None
        };
        if let Some(v) = faults.as_ref().and_then(|f| f.supply_v) {
            p.supply_v = v;
        }
        let rated = self.check_rated_range(&p, t);
        let [gx, gy, gz] = p.gyro_dps;
        let [ax, ay, az] = p.accel_g;
        let y = self.inertial_filter.push([gx, gy, gz, ax, ay, az]);
        // The filter's outputs go straight to where the sample is kept (not into `p`, then copied).
        self.filtered = Physical { gyro_dps: [y[0], y[1], y[2]], accel_g: [y[3], y[4], y[5]], ..p };
        if self.opts.filter_mag_baro {
            let [mx, my, mz] = p.mag_gauss;
            let y = self.mag_baro_filter.push([mx, my, mz, p.baro_mbar]);
            self.filtered.mag_gauss = [y[0], y[1], y[2]];
            self.filtered.baro_mbar = y[3];
        }
        // What the outputs encode: the filtered values, plus any injected spikes (in `p`, whose
        // unfiltered values are not needed any more).
        let f = match faults.as_ref().filter(|sf| sf.any_spike) {
            Some(sf) => {
                p = self.filtered;
                spike(&mut p, sf);
                &p
            }
            None => &self.filtered,
        };
        let unclipped = self.calibration.nothing_can_clip(f);
        let over = !unclipped && self.calibration.outputs_overrange(f);
        if let Some(sf) = &faults {
            self.calibration.encode_outputs(f, &mut self.regs);
            for i in 0..self.layout.burst_len {
                if sf.stuck >> i & 1 != 0 {
                    self.regs[self.layout.burst_slot(i)] = sf.frozen[i];
                }
            }
            self.pending = false;
        } else {
            self.pending = true;
        }

        let o = &self.opts;
        let mut flags = faults.map_or(0, |sf| sf.diag);
        if over || rated {
            flags |= 1 << o.diag_overrange_bit;
        }
        if f.supply_v > o.supply_high_v {
            flags |= 1 << o.diag_supply_high_bit;
        }
        if f.supply_v < o.supply_low_v {
            flags |= 1 << o.diag_supply_low_bit;
        }
        let supply_bad = f.supply_v > o.supply_high_v || f.supply_v < o.supply_low_v;
        let clear_on_read = o.diag_clear_on_read;
        if supply_bad != self.supply_bad {
            self.supply_changed(supply_bad, f.supply_v, t);
        }
        let diag = &mut self.regs[self.layout.diag];
        *diag = if clear_on_read { *diag | flags } else { flags };

        self.nd |= self.layout.output_slots;
        // With MSC_CTRL[2] set this sample also asserts data ready ([`Adis::last_data_ready`]).
        self.latest = Some(SampleStamp { index: k, t });
    }

    /// Take the data-ready pin and polarity from MSC_CTRL ([0] line, [1] polarity, [2] enable), after
    /// keeping the record of the latest assertion under the previous setting. Called whenever a
    /// control register may have changed (writes and resets): the samples need not look at MSC_CTRL.
    fn set_data_ready_pin(&mut self) {
        self.data_ready = self.last_data_ready();
        let msc = self.regs[self.layout.msc];
        self.data_ready_pin = (msc & 0x0004 != 0).then(|| {
            let line = if msc & 1 == 0 { DataReadyLine::Dio1 } else { DataReadyLine::Dio2 };
            (line, msc & 2 != 0)
        });
        self.data_ready_pin_from = self.schedule.next_k;
    }

    /// Bring `calibration` up to date: recomputed only when one of the registers' words or the
    /// range changed since the last call. Called after every register write and every reset, the
    /// only ways either can change, so the samples use `calibration` as it is.
    fn refresh_calibration(&mut self) {
        if self.layout.calibration_words(&self.regs) != self.calibration.words || self.range != self.calibration.range {
            self.calibration = Calibration::of(&self.layout, &self.regs, self.range);
        }
    }

    /// What the injected faults do to the sample at `t` (cold: only once a fault is due).
    #[cold]
    fn sample_faults(&mut self, t: Ps) -> SampleFaults {
        let regs = self.regs;
        let layout = &self.layout;
        self.faults.at_sample(
            t,
            |i| if i < layout.burst_len { regs[layout.burst_slot(i)] } else { 0 },
            &mut self.events,
        )
    }

    /// The supply left or re-entered the DIAG_STAT limits: an event on leaving (one per episode).
    #[cold]
    fn supply_changed(&mut self, bad: bool, volts: f64, t: Ps) {
        self.supply_bad = bad;
        if !bad {
            return;
        }
        let o = &self.opts;
        let (limit, which, bit) = if volts > o.supply_high_v {
            (o.supply_high_v, "above", o.diag_supply_high_bit)
        } else {
            (o.supply_low_v, "below", o.diag_supply_low_bit)
        };
        self.events.push(Event::rule(
            t,
            "supply_out_of_range",
            Severity::Warning,
            format!(
                "supply {volts:.3} V {which} the {limit} V limit: DIAG_STAT bit {bit} set, EA in every output word"
            ),
            volts,
            limit,
        ));
    }

    /// NaN inputs (from a closure or an error model) become 0 and are reported; infinities are kept,
    /// they saturate the filter and the encoder.
    #[cold]
    fn sanitize(&mut self, p: &mut Physical, k: u64, t: Ps) {
        self.events.push(Event::new(
            t,
            "non_finite_input",
            Severity::Error,
            format!("device sample {k}: the stimulus or error model gave a non-finite value ({p:?}); NaN taken as 0"),
        ));
        for v in p.values_mut() {
            if v.is_nan() {
                *v = 0.0;
            }
        }
    }

    /// SENS_AVG as the part accepts `requested`: an invalid range code keeps the previous range, and
    /// M is raised to the range's minimum. Sets the range and the filters.
    fn checked_sens_avg(&mut self, requested: u16, t: Ps) -> u16 {
        let range = match GyroRange::from_bits(requested >> 8 & 7) {
            Some(r) => r,
            None => {
                self.events.push(Event::new(
                    t,
                    "invalid_register_value",
                    Severity::Warning,
                    format!(
                        "SENS_AVG = 0x{requested:04X}: range bits 10:8 = {:03b} select no range (100, 010 or 001); \
                         the range stays ±{} °/s",
                        requested >> 8 & 7,
                        self.range.rated_dps()
                    ),
                ));
                self.range
            }
        };
        let min_m = self.opts.min_m(range);
        let mut m = (requested & 7) as u8;
        if m < min_m {
            self.events.push(Event::new(
                t,
                "sens_avg_raised",
                Severity::Info,
                format!(
                    "SENS_AVG: M = {m} is below the minimum {min_m} of the ±{} °/s range; raised to {min_m}",
                    range.rated_dps()
                ),
            ));
            m = min_m;
        }
        self.range = range;
        // m ≤ 7 by construction (3 bits, or a validated minimum).
        let _ = self.inertial_filter.set_m(m);
        let _ = self.mag_baro_filter.set_m(m);
        range.bits() << 8 | u16::from(m)
    }

    fn set_control(&mut self, def: &RegisterDef, value: u16, t: Ps) {
        let slot = def.slot();
        let self_test = def.field("self_test").map_or(0, |f| f.mask());
        let value = match def.role {
            Role::SensAvg => self.checked_sens_avg(value, t),
            Role::SmplPrd => {
                let clock = sample_clock(value, self.clock_ppb);
                // Before the first sample the first sample keeps its time; afterwards the new period
                // counts from the write (the part's behaviour at a rate change is not documented).
                let first = if self.latest.is_some() { t + clock.cycles_to_ps(1) } else { self.schedule.next_t };
                self.schedule.restart(clock, first);
                value
            }
            Role::MscCtrl if value & self_test != 0 => {
                self.not_modelled(t, "MSC_CTRL[10] self-test: completes at once with every test passing");
                value & !self_test
            }
            Role::SlpCnt if value != 0 => {
                self.not_modelled(t, "SLP_CNT sleep: the part keeps sampling");
                value
            }
            _ => value,
        };
        self.regs[slot] = value;
        if def.role == Role::MscCtrl {
            self.set_data_ready_pin();
        }
    }

    fn not_modelled(&mut self, t: Ps, what: &str) {
        self.events.push(Event::new(t, "command_not_modelled", Severity::Warning, format!("{what} (not modelled)")));
    }

    /// GLOB_CMD: [0] autonull, [1] factory restore, [2] DAC latch, [3] flash update,
    /// [4] precision autonull (not modelled), [7] software reset (last, so it wins).
    fn glob_cmd(&mut self, cmd: u8, t: Ps) {
        if cmd & 0x01 != 0 {
            self.autonull(t);
        }
        if cmd & 0x02 != 0 {
            // Factory restore: the user calibration registers return to their factory values.
            for slot in self.layout.calibration.into_iter().flatten() {
                self.regs[slot] = self.factory[slot];
            }
        }
        // [2] DAC latch: AUX_DAC drives no pin this model observes, so latching changes nothing.
        if cmd & 0x08 != 0 {
            if let Some(slot) = self.layout.flash_cnt {
                self.regs[slot] = self.regs[slot].wrapping_add(1);
            }
            self.flash = self.regs;
        }
        if cmd & 0x10 != 0 {
            self.not_modelled(t, "GLOB_CMD[4] precision autonull");
        }
        if cmd & 0x80 != 0 {
            self.software_reset(t);
        }
    }

    /// Autonull: each gyro offset becomes minus the current filtered reading, rounded to the offset
    /// LSB (0.0125 °/s). The averaging window is the Bartlett filter's: the 2N − 1 latest samples,
    /// triangle-weighted (the sibling data sheets describe autonull as using the filtered output).
    fn autonull(&mut self, t: Ps) {
        if self.latest.is_none() {
            self.events.push(Event::new(
                t,
                "autonull_without_data",
                Severity::Warning,
                "GLOB_CMD autonull before the first sample: offsets unchanged",
            ));
            return;
        }
        for i in 0..3 {
            let want = -(self.filtered.gyro_dps[i] / GYRO_OFF_LSB_DPS).round();
            let code = want.clamp(-4096.0, 4095.0);
            if code != want {
                self.events.push(Event::new(
                    t,
                    "autonull_saturated",
                    Severity::Warning,
                    format!("autonull: gyro axis {i} bias {} °/s exceeds the 13-bit offset", self.filtered.gyro_dps[i]),
                ));
            }
            if let Some(slot) = self.layout.calibration[i] {
                self.regs[slot] = to_field(code as i32, 13);
            }
        }
    }

    /// Software reset: the flash image comes back, the outputs clear, and the part neither samples nor
    /// answers SPI until `reset_time_ms` has passed; sampling restarts at that instant.
    fn software_reset(&mut self, t: Ps) {
        self.busy_until = t + self.reset_ps;
        // Control registers come back from flash; outputs and DIAG_STAT clear; FLASH_CNT and PROD_ID
        // keep their values.
        for r in self.layout.part.registers {
            match (r.access, r.format) {
                (Access::RW, _) => self.regs[r.slot()] = self.flash[r.slot()],
                (_, Format::Output(_)) => self.regs[r.slot()] = 0,
                _ => {}
            }
        }
        self.regs[self.layout.diag] = 0;
        self.nd = 0;
        self.pending = false;
        let sens_avg = self.checked_sens_avg(self.regs[self.layout.sens], t);
        self.regs[self.layout.sens] = sens_avg;
        self.inertial_filter.reset();
        self.mag_baro_filter.reset();
        self.schedule.restart(sample_clock(self.regs[self.layout.smpl], self.clock_ppb), self.busy_until);
        self.latest = None;
        self.data_ready = None;
        self.set_data_ready_pin();
        self.refresh_calibration();
        self.spi.reset();
        self.events.push(Event::new(
            t,
            "software_reset",
            Severity::Info,
            format!(
                "GLOB_CMD software reset: the part is unavailable for {} s",
                self.reset_ps as f64 / PS_PER_S as f64
            ),
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::device::registers::{addr, BURST_ORDER};
    use rand::{Rng, SeedableRng};

    /// Slots of the ADIS16407's calibration registers XGYRO_OFF … ZMAGN_SIC (contiguous: twelve).
    const CALIBRATION_SLOTS: std::ops::Range<usize> = s(addr::XGYRO_OFF)..s(addr::ZMAGN_SIC) + 1;

    fn layout() -> Layout {
        Layout::of(&crate::device::parts::adis16407::PART)
    }

    /// [`Physical::values`] inverted: the sample whose values are `v`.
    fn from_screened(v: [f64; 13]) -> Physical {
        let mut p = Physical::default();
        p.values_mut().zip(v).for_each(|(x, v)| *x = v);
        p
    }

    #[test]
    fn the_converted_calibration_follows_every_write_and_reset() {
        // Random writes between samples to the calibration registers, SENS_AVG (range and M) and
        // GLOB_CMD (autonull, factory restore, flash update, software reset), and resets as an injected
        // fault makes them: after each, the device's converted calibration must be the one its
        // registers and range give now.
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(16_407);
        let mut d = Adis::new(&Device::default()).unwrap();
        const PERIOD: Ps = 1_220_703_125;
        let mut t = 0;
        let mut changes = 0;
        for step in 0..4000 {
            t += rng.gen_range(0..2 * PERIOD);
            d.advance_to(t);
            let before = d.calibration;
            match rng.gen_range(0..10) {
                0..=4 => {
                    let slot = rng.gen_range(CALIBRATION_SLOTS);
                    d.write_byte((slot as u8) << 1 | rng.gen_range(0..2), rng.gen(), t);
                }
                5 | 6 => d.write_byte(addr::SENS_AVG | 1, [1, 2, 4, 3][rng.gen_range(0..4)], t),
                7 => d.write_byte(addr::GLOB_CMD, [0x01, 0x02, 0x08][rng.gen_range(0..3)], t),
                8 if step % 50 == 0 => d.write_byte(addr::GLOB_CMD, 0x80, t),
                _ if step % 50 == 1 => d.software_reset(t),
                _ => {}
            }
            assert_eq!(d.calibration, Calibration::of(&d.layout, &d.regs, d.range), "step {step}");
            changes += u32::from(d.calibration != before);
        }
        assert!(changes > 1500, "{changes} changes of the calibration");
    }

    #[test]
    fn a_run_of_burst_words_clears_the_nd_flags_of_exactly_its_registers() {
        for start in 0..=BURST_ORDER.len() {
            for end in start..=BURST_ORDER.len() {
                let one_by_one = BURST_ORDER[start..end].iter().fold(0u64, |mask, &a| mask | 1 << s(a));
                assert_eq!(layout().burst_nd_mask(start..end), one_by_one, "burst words {start}..{end}");
            }
        }
    }

    /// Samples swept across the ends of the overrange screen, with their calibration: random
    /// calibration words (full register widths, soft iron 0 included, and cases with every word at
    /// its most negative or largest value) and ranges; one value at a time swept across its screen
    /// interval's end (±2 % around it, so across the clip limit 1 % beyond it too, and exactly at the
    /// end and one ulp either side) with the others at their centres.
    fn for_each_swept_sample(mut check: impl FnMut(usize, usize, &Calibration, &Physical)) {
        const BITS: [u32; 12] = [13, 13, 13, 12, 12, 12, 14, 14, 14, 12, 12, 12];
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(16407);
        for case in 0..400 {
            let mut regs = [0u16; SLOTS];
            for (i, slot) in CALIBRATION_SLOTS.enumerate() {
                let field = ((1u32 << BITS[i]) - 1) as u16;
                regs[slot] = match case % 20 {
                    // The offsets' most negative words (sign bit only), the soft iron's largest.
                    1 if i < 9 => 1 << (BITS[i] - 1),
                    // The offsets' most positive words.
                    2 if i < 9 => field >> 1,
                    1 | 2 => field,
                    _ => rng.gen::<u16>() & field,
                };
            }
            if case % 10 == 0 {
                regs[CALIBRATION_SLOTS.end - 1] = 0;
            }
            let range = [GyroRange::Dps300, GyroRange::Dps150, GyroRange::Dps75][case % 3];
            let cal = Calibration::of(&layout(), &regs, range);
            for i in 0..13 {
                for j in 0..206 {
                    let mut v = cal.unclipped_centre;
                    let side = if j % 2 == 0 { 1.0 } else { -1.0 };
                    let end = v[i] + side * cal.unclipped_half_width[i];
                    v[i] = match j / 2 {
                        0 => end,
                        1 => end.next_up(),
                        2 => end.next_down(),
                        _ => v[i] + side * cal.unclipped_half_width[i] * rng.gen_range(0.98..1.02),
                    };
                    check(case, i, &cal, &from_screened(v));
                }
            }
        }
    }

    #[test]
    fn the_overrange_screen_never_passes_a_value_the_exact_test_flags() {
        // Wherever the screen passes a sample, no output may clip.
        let (mut passed, mut flagged) = (0u32, 0u32);
        for_each_swept_sample(|case, i, cal, f| {
            let over = cal.outputs_overrange(f);
            if cal.nothing_can_clip(f) {
                passed += 1;
                assert!(!over, "case {case}, value {i}: passed by the screen but clips: {f:?}");
            }
            flagged += u32::from(over);
        });
        // About half the sweep is inside the screen, and its outer quarter (past the 1 % margin)
        // clips: the test reached both the screen's ends and the clip limits.
        assert!(passed > 400_000 && flagged > 200_000, "{passed} passed, {flagged} clipped");
    }
}
