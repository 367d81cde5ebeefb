//! Decode of the six inertial output words (X/Y/Z GYRO_OUT, X/Y/Z ACCL_OUT) into rad/s and m/s².
//!
//! `published` is the thesis code (§4.4.3): keep the 14 valid bits, then two range tests per
//! register; a word in neither range leaves the variable at its previous value (stale, silently on
//! target; reported here). It multiplies gyro codes by 0.05 whatever range SENS_AVG selects, because
//! it was written for ±300 °/s. `correct` masks, sign-extends and uses the configured range's LSB.
//! Both flag saturation (a code at the 14-bit limit, 0x1FFF or 0x2000).
//!
//! Units, in the order the firmware converts. Float backends run the published code: the code times
//! the LSB in °/s (g), the value the published decode holds, then one multiplication by π/180 (by the
//! firmware's g constant, `firmware.accel_g_m_s2`). A fixed-point build cannot hold that intermediate
//! (±409.6 °/s and ±27 g do not fit GLOBAL_Q = Q24's ±128), so its firmware folds the two constants
//! into one per-LSB constant in the firmware unit and decodes with one `_IQmpyI32(constant, code)`
//! ([`Scalar::mul_i32`]), then shifts the product to the class's Q (`_IQ28toIQ24`). The constant is
//! `_IQN(LSB·π/180)` (`_IQN(LSB·g)`) in the finest N that holds the full-scale product 8192·LSB
//! ([`Scalar::from_f64_range`]): Q28 for 0.05 °/s (7.15 rad/s), Q22 for 3.333 mg (268 m/s²). In the
//! class's own Q instead, `_IQ()`'s truncation would be a scale-factor error of up to one class LSB over
//! the constant: 0.83/14640 = 5.7e-5 for 0.05 °/s in Q24, 0.13° over a 2300° turn. The held previous
//! values are the fine products.

use super::{lit, Vec3};
use crate::device::encoding::TEMP_LSB_C;
use crate::device::part::Part;
use crate::device::GyroRange;
use crate::events::{Event, EventLog, Severity};
use crate::numerics::counter::Work;
use crate::numerics::{QClass, Scalar};
use crate::profile::{Decode, Device, Firmware as FirmwareProfile};
use crate::time::Ps;
use crate::{Error, Result};

/// The gyro LSB the published code uses for every range, °/s.
pub const PUBLISHED_GYRO_LSB_DPS: f64 = 0.05;
/// The ADIS16407's accelerometer LSB, g (data sheet: 3.333 mg; the published literal `3.333e-003`).
/// The decoder takes the LSB of the profile's part (`device.part`, 0.333 mg for the ADIS16362).
pub const ACCEL_LSB_G: f64 = 3.333e-3;

const VALID_BITS_MASK: u16 = 0x3FFF;
/// X/Y/ZMAGN_OUT: 14-bit two's complement, 0.5 mgauss per LSB (adis16407.md).
pub const MAG_LSB_GAUSS: f64 = 0.0005;
/// X/Y/ZTEMP_OUT: 12 valid bits, 0.136 °C per LSB, code 0 = 25 °C (the device's encoding).
const TEMP_BITS_MASK: u16 = 0x0FFF;
/// The largest magnitude of a 12-bit two's-complement code (0x800 = −2048).
const TEMP_FULL_SCALE_CODE: f64 = 2048.0;
const SATURATED_POSITIVE: u16 = 0x1FFF;
const SATURATED_NEGATIVE: u16 = 0x2000;
/// Published range tests: (positive upper bound, negative lower bound) of the 14-bit code: ±300 °/s
/// (±6000 codes) for the gyros; the accelerometers' rated range in codes of the part's LSB
/// ([`accel_range`]: ±18 g = ±5401 codes, 0x1519 / 0x2AE7, on the ADIS16407).
const GYRO_RANGE: (u16, u16) = (0x1770, 0x2890);
/// The largest magnitude of a 14-bit two's-complement code (0x2000 = −8192).
const FULL_SCALE_CODE: f64 = 8192.0;

/// The published accelerometer range test for a part: ± its rated range in its LSBs, rounded (the
/// published literals are the ADIS16407's, 5401 = 18 g / 3.333 mg), as 14-bit codes.
pub fn accel_range(part: &Part) -> (u16, u16) {
    let n = (part.accel_rated_g / part.accel_lsb_g).round().clamp(1.0, 8190.0) as u16;
    (n, 0x4000 - n)
}

/// X/Y/ZTEMP_OUT (the ADIS16362's burst words 8…10): 12-bit two's complement, 0.136 °C per LSB, code 0 =
/// 25 °C (adis16362.md, data sheet p. 11); each axis's distance from 25 °C, °C. The LSB is a constant in
/// the finest Q that holds the full scale (±278.5 °C), as for the magnetometer.
pub fn decode_temperature<T: Scalar>(words: &[u16; 3]) -> Vec3<T> {
    let lsb = T::from_f64_range(TEMP_LSB_C, TEMP_LSB_C * TEMP_FULL_SCALE_CODE);
    words.map(|w| {
        let code = (w & TEMP_BITS_MASK) as i32;
        let signed = if code >= 0x800 { code - 0x1000 } else { code };
        lsb.mul_i32(signed).to_class(QClass::Generic)
    })
}

/// The magnetometer axes (bit i: X/Y/Z MAGN_OUT) whose 14-bit code is at its limit (0x1FFF or 0x2000):
/// the field on that axis is clipped.
pub fn saturated_magnetometer(words: &[u16; 3]) -> u8 {
    (0..3).fold(0, |m, i| {
        let code = words[i] & VALID_BITS_MASK;
        m | u8::from(code == SATURATED_POSITIVE || code == SATURATED_NEGATIVE) << i
    })
}

/// Per channel, the published stale range hi < code < lo as `code − (hi + 1) < lo − hi − 1` (wrapping).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct StaleRanges {
    from: [u16; 6],
    width: [u16; 6],
}

impl StaleRanges {
    /// Both saturated codes (0x1FFF, 0x2000) lie inside every stale range (`of_codes` relies on it):
    /// the ranges are at most ±8190 codes wide.
    fn new(accel: (u16, u16)) -> StaleRanges {
        let ranges: [(u16, u16); 6] = std::array::from_fn(|i| if i < 3 { GYRO_RANGE } else { accel });
        StaleRanges { from: ranges.map(|(hi, _)| hi + 1), width: ranges.map(|(hi, lo)| lo - hi - 1) }
    }
}
const CHANNELS: [&str; 6] = ["XGYRO_OUT", "YGYRO_OUT", "ZGYRO_OUT", "XACCL_OUT", "YACCL_OUT", "ZACCL_OUT"];

/// The gyro LSB, °/s, of the range selected by SENS_AVG bits 10:8 (100 → ±300, 010 → ±150,
/// 001 → ±75).
pub fn gyro_lsb_dps(sens_avg: u32) -> Result<f64> {
    match (sens_avg >> 8) & 0x7 {
        4 => Ok(0.05),
        2 => Ok(0.025),
        1 => Ok(0.0125),
        other => Err(Error::Register(format!(
            "SENS_AVG = 0x{sens_avg:04X}: range bits 10:8 = {other:03b}, expected 100 (±300), 010 (±150) or 001 (±75)"
        ))),
    }
}

/// The gyro LSB, °/s, the published decode scales by: `firmware.gyro_range_dps` over the 6000 codes
/// its range test accepts (±300 °/s → 0.05, as published; ±150 → 0.025; ±75 → 0.0125).
pub fn firmware_gyro_lsb_dps(range_dps: f64) -> Result<f64> {
    Ok(GyroRange::from_dps(range_dps)?.lsb_dps())
}

/// What happened to each channel in one decode; bit i is channel i (X/Y/Z gyro, X/Y/Z accel).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct DecodeReport {
    /// The published decode matched no range and kept the previous value.
    pub stale: u8,
    /// The 14-bit code is at its limit (0x1FFF or 0x2000): the reading is clipped.
    pub saturated: u8,
    /// The published and the correct decode give different values (stale or wrong LSB).
    pub differs: u8,
    /// The gyro range the firmware decodes for (`firmware.gyro_range_dps`) and the one SENS_AVG
    /// selects, °/s.
    pub ranges_dps: [u16; 2],
}

impl DecodeReport {
    /// The flags of the six 14-bit codes (X/Y/Z gyro, X/Y/Z accel); `gyro_lsb_differs`: the published
    /// decode's gyro LSB is not the configured range's, so every nonzero gyro code decodes differently.
    /// Each flag is one mask over the six channels (the compiler packs them together).
    fn of_codes(codes: &[u16; 6], ranges: &StaleRanges, gyro_lsb_differs: bool) -> DecodeReport {
        fn mask(codes: &[u16; 6], flagged: impl Fn(usize, u16) -> bool) -> u8 {
            (0..6).fold(0, |m, i| m | u8::from(flagged(i, codes[i])) << i)
        }
        // hi < code < lo as one unsigned comparison: code − (hi + 1) < lo − hi − 1, wrapping.
        let stale = mask(codes, |i, code| code.wrapping_sub(ranges.from[i]) < ranges.width[i]);
        // Both saturated codes lie inside both stale ranges ([`StaleRanges::new`]): without a
        // stale code there is no saturated one, the usual case, and its test is skipped.
        let saturated = if stale == 0 {
            0
        } else {
            mask(codes, |_, code| code == SATURATED_POSITIVE || code == SATURATED_NEGATIVE)
        };
        let differs = if gyro_lsb_differs { stale | mask(codes, |i, code| i < 3 && code != 0) } else { stale };
        DecodeReport { stale, saturated, differs, ranges_dps: [0; 2] }
    }

    /// A `decode_mismatch` message: both ranges and the key that makes the firmware match.
    fn mismatch_message(&self, name: &str, word: u16) -> String {
        let [firmware, device] = self.ranges_dps;
        format!(
            "{name} = 0x{word:04X}: the firmware decodes for ±{firmware} °/s (firmware.gyro_range_dps = {firmware}), \
             SENS_AVG selects ±{device} °/s: set firmware.gyro_range_dps = {device} for firmware that matches the device"
        )
    }

    /// True when nothing is to report.
    pub fn is_clean(&self) -> bool {
        self.stale | self.saturated | self.differs == 0
    }

    /// Record one event per flagged channel (`stale_decode`, `saturated_reading`,
    /// `decode_mismatch`). Formats strings only when something fired.
    pub fn push_events(&self, t_ps: Ps, words: &[u16; 6], log: &mut EventLog) {
        if self.is_clean() {
            return;
        }
        let mut warn = |kind: &'static str, what: String| log.push(Event::new(t_ps, kind, Severity::Warning, what));
        for (i, (name, word)) in CHANNELS.iter().zip(words).enumerate() {
            let bit = 1u8 << i;
            if self.stale & bit != 0 {
                warn(
                    "stale_decode",
                    format!("{name} = 0x{word:04X}: outside both published ranges, previous value kept"),
                );
            } else if self.differs & bit != 0 {
                warn("decode_mismatch", self.mismatch_message(name, *word));
            }
            if self.saturated & bit != 0 {
                warn("saturated_reading", format!("{name} = 0x{word:04X}: code at the 14-bit limit"));
            }
        }
    }
}

/// One decoded sample in the firmware's units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Decoded<T> {
    /// ω_ib^b, rad/s.
    pub rate: Vec3<T>,
    /// f^b, m/s².
    pub accel: Vec3<T>,
    /// Flags of this decode.
    pub report: DecodeReport,
}

/// How a code becomes the firmware unit: `lsb.mul_i32(code)`, then `× unit` when there is one.
#[derive(Debug, Clone, Copy)]
struct Scale<T> {
    /// Per LSB: in the source unit (°/s, g) on a float backend, in the firmware unit (rad/s, m/s²)
    /// on a fixed-point one.
    lsb: T,
    /// Source to firmware unit (π/180 or g) on a float backend; folded into `lsb` in fixed point.
    unit: Option<T>,
    /// The firmware unit's class.
    class: QClass,
}

impl<T: Scalar> Scale<T> {
    fn new(lsb: f64, unit: f64, class: QClass) -> Self {
        if T::fixed_point() {
            let full_scale = FULL_SCALE_CODE * (lsb * unit).abs();
            Scale { lsb: T::from_f64_range(lsb * unit, full_scale), unit: None, class }
        } else {
            Scale { lsb: lit(lsb), unit: Some(lit(unit)), class }
        }
    }

    /// The held value (what the published code stores) to the firmware unit.
    fn firmware_unit(&self, held: T) -> T {
        match self.unit {
            Some(unit) => (held * unit).to_class(self.class),
            None => held.to_class(self.class),
        }
    }
}

/// The decode stage with its state: the previous values the published code keeps.
#[derive(Debug, Clone)]
pub struct Decoder<T> {
    mode: Decode,
    gyro: Scale<T>,
    published_gyro: Scale<T>,
    accel: Scale<T>,
    zero: T,
    published_matches_range: bool,
    /// The firmware's gyro range and SENS_AVG's, °/s (for the `decode_mismatch` message).
    ranges_dps: [u16; 2],
    accel_range: (u16, u16),
    stale: StaleRanges,
    previous: [T; 6],
}

/// Sign-extended value of a 14-bit two's-complement code.
fn sign_extend_14(code: u16) -> i32 {
    ((code ^ 0x2000) as i32) - 0x2000
}

impl<T: Scalar> Decoder<T> {
    /// A decoder for the device's SENS_AVG range and the firmware's decode choice.
    pub fn new(device: &Device, firmware: &FirmwareProfile) -> Result<Self> {
        let lsb = gyro_lsb_dps(device.sens_avg)?;
        let firmware_lsb = firmware_gyro_lsb_dps(firmware.gyro_range_dps)?;
        let part = device.part_decl()?;
        let accel_range = accel_range(part);
        let zero = lit(0.0);
        let deg_to_rad = std::f64::consts::PI / 180.0;
        Ok(Decoder {
            mode: firmware.decode,
            gyro: Scale::new(lsb, deg_to_rad, QClass::Rate),
            published_gyro: Scale::new(firmware_lsb, deg_to_rad, QClass::Rate),
            accel: Scale::new(part.accel_lsb_g, firmware.accel_g_m_s2, QClass::Accel),
            zero,
            published_matches_range: lsb == firmware_lsb,
            ranges_dps: [firmware.gyro_range_dps as u16, (lsb * 6000.0).round() as u16],
            accel_range,
            stale: StaleRanges::new(accel_range),
            previous: [zero; 6],
        })
    }

    /// The published range test on one 14-bit code: `Some(held value)` or `None` (stale). Its
    /// integer work as the C executes it ([`Scalar::work`]): the load of `rdata1[i]`, per test one
    /// compare and conditional branch (`rdata1[i] >= 0x0000` is always true of an unsigned word: no
    /// code), the positive branch's jump over the negative one, the negative's XOR, ADD and store.
    fn published(&self, code: u16, (hi, lo): (u16, u16), lsb: T) -> Option<T> {
        let test = Work { int_ops: 1, cond_branches: 1, ..Work::NONE };
        T::work(Work { loads: 1, ..test });
        if code <= hi {
            T::work(Work { branches: 1, ..Work::NONE });
            Some(lsb.mul_i32(code as i32))
        } else {
            T::work(test);
            if code >= lo {
                // `r ^= 0x3FFF; r = r + 1; a = 0 - (r * scale);`
                T::work(Work { int_ops: 2, stores: 1, ..Work::NONE });
                let r = (code ^ VALID_BITS_MASK) + 1;
                Some(self.zero - lsb.mul_i32(r as i32))
            } else {
                None
            }
        }
    }

    /// Decode X/Y/Z MAGN_OUT (burst words 8…10): mask the 14 valid bits, sign-extend, × 0.5 mgauss;
    /// gauss. The LSB is a constant in the finest Q that holds the full scale (±4.096 gauss), so the
    /// integer product loses nothing before it lands in the specific-force class.
    pub fn decode_magnetometer(&self, words: &[u16; 3]) -> Vec3<T> {
        let lsb = T::from_f64_range(MAG_LSB_GAUSS, MAG_LSB_GAUSS * FULL_SCALE_CODE);
        words.map(|w| {
            // Per word: its load, the mask, the sign test and branch, the subtraction; the loop.
            T::work(Work { int_ops: 4, loads: 1, cond_branches: 2, ..Work::NONE });
            let code = (w & VALID_BITS_MASK) as i32;
            let signed = if code >= 0x2000 { code - 0x4000 } else { code };
            lsb.mul_i32(signed).to_class(QClass::Accel)
        })
    }

    /// Decode X/Y/Z GYRO_OUT and X/Y/Z ACCL_OUT (burst words 2…7). The integer work of the C
    /// ([`Scalar::work`]): the call `convert_data(rdata)`; the published code's first loop (per word a
    /// load, the AND, the store into `rdata1`) and its range-test loops ([`Decoder::published`]), each
    /// pass an increment, compare and branch; the correct decode's one loop (load, AND, the sign
    /// extension's XOR and SUB).
    pub fn decode(&mut self, words: &[u16; 6]) -> Decoded<T> {
        T::work(Work::call(1));
        let codes = words.map(|w| w & VALID_BITS_MASK);
        let mut report = DecodeReport::of_codes(&codes, &self.stale, !self.published_matches_range);
        report.ranges_dps = self.ranges_dps;
        let mut out = [self.zero; 6];
        for (i, &code) in codes.iter().enumerate() {
            let gyro = i < 3;
            let (range, published_scale, correct_scale) = if gyro {
                (GYRO_RANGE, self.published_gyro, self.gyro)
            } else {
                (self.accel_range, self.accel, self.accel)
            };
            // Both decodes of a channel share the unit (the same π/180 or g), so the held value of
            // either converts with `correct_scale`'s unit.
            let held = match self.mode {
                Decode::Published => {
                    // The first loop's pass (AND and the loop's two), then the second loop's.
                    T::work(Work { int_ops: 3, loads: 1, stores: 1, ..Work::LOOP_PASS });
                    T::work(Work::LOOP_PASS);
                    self.published(code, range, published_scale.lsb).unwrap_or(self.previous[i])
                }
                Decode::Correct => {
                    // AND, XOR, SUB and the loop's two.
                    T::work(Work { int_ops: 5, loads: 1, ..Work::LOOP_PASS });
                    correct_scale.lsb.mul_i32(sign_extend_14(code))
                }
            };
            self.previous[i] = held;
            out[i] = correct_scale.firmware_unit(held);
        }
        Decoded { rate: [out[0], out[1], out[2]], accel: [out[3], out[4], out[5]], report }
    }

    /// The previous decoded values as the published code holds them: in °/s and g on a float backend,
    /// in rad/s and m/s² on a fixed-point one (folded scale, see the module documentation).
    pub fn previous(&self) -> &[T; 6] {
        &self.previous
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn decoder(mode: Decode, sens_avg: u32) -> Decoder<f64> {
        let device = Device { sens_avg, ..Device::default() };
        let firmware = FirmwareProfile { decode: mode, ..FirmwareProfile::default() };
        Decoder::new(&device, &firmware).unwrap()
    }

    fn dps(d: &Decoded<f64>, i: usize) -> f64 {
        d.rate[i].to_degrees()
    }

    #[test]
    fn published_vectors() {
        let mut d = decoder(Decode::Published, 0x0402);
        let out = d.decode(&[0x1770, 0x0001, 0x3FFF, 0x1519, 0x2AE7, 0x3FFE]);
        assert!((dps(&out, 0) - 300.0).abs() < 1e-12);
        assert!((dps(&out, 1) - 0.05).abs() < 1e-12);
        assert!((dps(&out, 2) + 0.05).abs() < 1e-12);
        let g = 9.80665;
        assert!((out.accel[0] / g - 18.001_533).abs() < 1e-9, "5401 × 3.333 mg");
        assert!((out.accel[1] / g + 18.001_533).abs() < 1e-9);
        assert!((out.accel[2] / g + 2.0 * 3.333e-3).abs() < 1e-12);
        assert!(out.report.is_clean());
        let out = d.decode(&[0x2890, 0x3FFE, 0xC000, 0, 0, 0]);
        assert!((dps(&out, 0) + 300.0).abs() < 1e-12);
        assert!((dps(&out, 1) + 0.10).abs() < 1e-12);
        assert_eq!(dps(&out, 2), 0.0, "top two bits are flags, not data");
    }

    #[test]
    fn published_keeps_previous_value_for_0x1800_and_reports_it() {
        let mut d = decoder(Decode::Published, 0x0402);
        d.decode(&[0x0014, 0, 0, 0, 0, 0]); // +1.00 °/s
        let out = d.decode(&[0x1800, 0, 0, 0, 0, 0]);
        assert!((dps(&out, 0) - 1.0).abs() < 1e-12, "stale value kept");
        assert_eq!(out.report.stale, 0b1);
        assert_eq!(out.report.differs, 0b1);
        assert_eq!(out.report.saturated, 0);
        let mut log = EventLog::default();
        out.report.push_events(5, &[0x1800, 0, 0, 0, 0, 0], &mut log);
        assert_eq!(log.count("stale_decode"), 1);
        assert!(log.events()[0].message.contains("XGYRO_OUT = 0x1800"));
    }

    #[test]
    fn correct_decodes_0x1800_and_flags_saturation() {
        let mut d = decoder(Decode::Correct, 0x0402);
        let out = d.decode(&[0x1800, 0x1FFF, 0x2000, 0x1FFF, 0x2000, 0x2001]);
        assert!((dps(&out, 0) - 307.2).abs() < 1e-12);
        assert!((dps(&out, 1) - 8191.0 * 0.05).abs() < 1e-9);
        assert!((dps(&out, 2) + 8192.0 * 0.05).abs() < 1e-9);
        assert_eq!(out.report.saturated, 0b01_1110);
        assert_eq!(out.report.stale, 0b11_1111, "the published decode would be stale on all six");
    }

    #[test]
    fn correct_uses_the_configured_range() {
        // ±75 °/s, 0.0125 °/s per LSB: 0xF9DA → bits 13:0 = −1574 → −19.675 °/s.
        let mut d = decoder(Decode::Correct, 0x0102);
        let out = d.decode(&[0xF9DA, 0x0000, 0x0001, 0, 0, 0]);
        assert!((dps(&out, 0) + 19.675).abs() < 1e-12);
        assert!((dps(&out, 2) - 0.0125).abs() < 1e-12);
        assert_eq!(out.report.differs, 0b100 | 0b1, "published would scale by 0.05");
        // The published decode on the same board: four times too large.
        let mut p = decoder(Decode::Published, 0x0102);
        let out = p.decode(&[0xF9DA, 0, 0, 0, 0, 0]);
        assert!((dps(&out, 0) + 78.7).abs() < 1e-12);
    }

    #[test]
    fn the_firmware_gyro_range_key_sets_the_published_scale_and_names_itself() {
        // ±75 °/s on the device (0x0104): the published firmware, unchanged, decodes at 0.05 °/s and
        // says which key to change; rebuilt for ±75 (firmware.gyro_range_dps = 75) it decodes the
        // same code at 0.0125 °/s, with the published range test and no mismatch.
        let device = Device { sens_avg: 0x0104, ..Device::default() };
        let unchanged = FirmwareProfile::default();
        let rebuilt = FirmwareProfile { gyro_range_dps: 75.0, ..FirmwareProfile::default() };
        let words = [0xF9DA, 0x0000, 0x0001, 0, 0, 0];
        let out = Decoder::<f64>::new(&device, &unchanged).unwrap().decode(&words);
        assert!((dps(&out, 0) + 78.7).abs() < 1e-12);
        let mut log = EventLog::default();
        out.report.push_events(5, &words, &mut log);
        assert_eq!(log.count("decode_mismatch"), 2);
        let m = &log.events()[0].message;
        assert!(m.contains("firmware.gyro_range_dps = 300") && m.contains("set firmware.gyro_range_dps = 75"), "{m}");
        let out = Decoder::<f64>::new(&device, &rebuilt).unwrap().decode(&words);
        assert!((dps(&out, 0) + 19.675).abs() < 1e-12 && (dps(&out, 2) - 0.0125).abs() < 1e-12);
        assert!(out.report.is_clean());
        // The published default is the published literal, bit for bit.
        assert_eq!(firmware_gyro_lsb_dps(300.0).unwrap().to_bits(), PUBLISHED_GYRO_LSB_DPS.to_bits());
        assert!(firmware_gyro_lsb_dps(100.0).is_err());
    }

    #[test]
    fn float_decode_is_the_published_two_step_conversion() {
        // Bit for bit: code × LSB (the held °/s or g), then × π/180 or × g.
        let mut d = decoder(Decode::Published, 0x0402);
        let out = d.decode(&[0x1770, 0x3FFE, 0x0001, 0x012C, 0x2AE7, 0x0000]);
        let rad = std::f64::consts::PI / 180.0;
        assert_eq!(out.rate[0].to_bits(), ((6000.0 * 0.05) * rad).to_bits());
        assert_eq!(out.rate[1].to_bits(), ((0.0 - 2.0 * 0.05) * rad).to_bits());
        assert_eq!(out.accel[0].to_bits(), ((300.0f64 * 3.333e-3) * 9.80665).to_bits());
        assert_eq!(out.accel[1].to_bits(), ((0.0f64 - 5401.0 * 3.333e-3) * 9.80665).to_bits());
        assert_eq!(d.previous()[0], 300.0, "the published code holds °/s");
    }

    #[test]
    fn iq_decodes_full_scale_straight_to_the_firmware_unit() {
        use crate::numerics::iq::{count_overflows, q_of};
        use crate::numerics::Iq;
        let rad = std::f64::consts::PI / 180.0;
        // Codes from full scale to one LSB, both signs (published ranges, then correct's 14-bit limits).
        let cases = [
            (Decode::Published, [0x1770, 0x2890, 0x0001, 0x1519, 0x2AE7, 0x3FFF]),
            (Decode::Correct, [0x1FFF, 0x2000, 0x3FFF, 0x1FFF, 0x2000, 0x012C]),
        ];
        for (mode, words) in cases {
            let device = Device { sens_avg: 0x0402, ..Device::default() };
            let firmware = FirmwareProfile { decode: mode, ..FirmwareProfile::default() };
            let (out, overflows) = count_overflows(|| {
                let mut d = Decoder::<Iq>::new(&device, &firmware).unwrap();
                d.decode(&words)
            });
            assert_eq!(overflows, 0, "{mode:?}: 409.6 °/s and 27 g fit the rate and accel classes");
            for (i, w) in words.iter().enumerate() {
                let n = sign_extend_14(w & VALID_BITS_MASK) as f64;
                let (value, exact, q) = if i < 3 {
                    (out.rate[i], n * 0.05 * rad, q_of(QClass::Rate))
                } else {
                    (out.accel[i - 3], n * ACCEL_LSB_G * 9.80665, q_of(QClass::Accel))
                };
                assert_eq!(value.q(), q);
                // The folded constant (Q28 gyro, Q22 accel) is truncated by less than one of its LSB, the
                // product is exact, the shift to the class floors: the error is below |n| constant LSB
                // plus one class LSB.
                let err = value.to_f64() - exact;
                let lsb = 2f64.powi(-(q as i32));
                let constant_lsb = 2f64.powi(if i < 3 { -28 } else { -22 });
                assert!(err.abs() < n.abs() * constant_lsb + lsb, "{mode:?} word {i}: {err:e}");
            }
        }
    }

    /// The flags of every 14-bit code on every channel, against the published tests written out word
    /// by word.
    #[test]
    fn flags_of_every_code() {
        let ranges = StaleRanges::new(accel_range(&crate::device::parts::adis16407::PART));
        for code in 0..=VALID_BITS_MASK {
            for i in 0..6 {
                for gyro_lsb_differs in [false, true] {
                    let mut codes = [0u16; 6];
                    codes[i] = code;
                    let r = DecodeReport::of_codes(&codes, &ranges, gyro_lsb_differs);
                    let (hi, lo) = if i < 3 { (0x1770, 0x2890) } else { (0x1519, 0x2AE7) };
                    let stale = hi < code && code < lo;
                    let saturated = code == 0x1FFF || code == 0x2000;
                    let differs = stale || (i < 3 && gyro_lsb_differs && code != 0);
                    let bit = |flag: bool| u8::from(flag) << i;
                    let want = DecodeReport {
                        stale: bit(stale),
                        saturated: bit(saturated),
                        differs: bit(differs),
                        ranges_dps: [0; 2],
                    };
                    assert_eq!(r, want, "code 0x{code:04X} on channel {i}");
                }
            }
        }
    }

    /// The published range literals are the ADIS16407's rated ranges in its LSBs; the ADIS16362's
    /// accelerometer test is its ±1.7 g in 0.333 mg codes, and its decode scales by 0.333 mg.
    #[test]
    fn the_accelerometer_range_and_scale_come_from_the_part() {
        use crate::device::parts::{adis16362, adis16407};
        assert_eq!(accel_range(&adis16407::PART), (0x1519, 0x2AE7));
        assert_eq!(accel_range(&adis16362::PART), (5105, 0x4000 - 5105));
        let device = Device { part: "ADIS16362".into(), ..Device::default() };
        let mut d = Decoder::<f64>::new(&device, &FirmwareProfile::default()).unwrap();
        let out = d.decode(&[0, 0, 0, 3003, 0x4000 - 3003, 5106]);
        let g = FirmwareProfile::default().accel_g_m_s2;
        assert!((out.accel[0] / g - 3003.0 * 0.333e-3).abs() < 1e-12, "1 g is 3003 codes");
        assert!((out.accel[1] / g + 3003.0 * 0.333e-3).abs() < 1e-12);
        assert_eq!(out.report.stale, 1 << 5, "5106 codes is beyond ±1.7 g");
    }

    #[test]
    fn bad_range_is_a_register_error() {
        let device = Device { sens_avg: 0x0302, ..Device::default() };
        let e = Decoder::<f64>::new(&device, &FirmwareProfile::default()).unwrap_err();
        assert!(e.to_string().contains("SENS_AVG"), "{e}");
    }

    #[test]
    fn magnetometer_words_are_14_bit_half_milligauss() {
        let d = Decoder::<f64>::new(&crate::profile::Device::default(), &crate::profile::Firmware::default()).unwrap();
        // 1000 = 0.5 gauss; 0x3C18 = −1000; ND/EA flags (bits 15, 14) ignored; full scale 0x1FFF / 0x2000.
        assert_eq!(d.decode_magnetometer(&[1000, 0x3C18, 0xC000 | 1000]), [0.5, -0.5, 0.5]);
        assert_eq!(d.decode_magnetometer(&[0x1FFF, 0x2000, 0]), [8191.0 * 0.0005, -4.096, 0.0]);
        let q = Decoder::<crate::numerics::Iq>::new(
            &crate::profile::Device::default(),
            &crate::profile::Firmware::default(),
        )
        .unwrap()
        .decode_magnetometer(&[1000, 0x3C18, 1]);
        // IQ: the LSB truncated into Q28 (the finest Q holding ±4.096), the product floored into Q20.
        let lsb = (0.0005 * 2f64.powi(28)).trunc() / 2f64.powi(28);
        let expected = [1000.0, -1000.0, 1.0].map(|c: f64| (lsb * c * 2f64.powi(20)).floor() / 2f64.powi(20));
        assert_eq!(q.map(|x| x.to_f64()), expected);
    }
}
