//! Output-word encoding and decoding of the ADIS16407 (pure functions, shared with the Python binding).
//!
//! Rounding rule: a physical value becomes the nearest code, `round(value × (1/LSB))`, ties away from zero
//! (the data sheet does not state the converter's tie rule; a tie needs the value to sit exactly on a
//! half-LSB boundary, so the choice is invisible in practice). Codes beyond the field saturate at the
//! field limits and report `overrange`. Decoding is the exact inverse for every in-range code:
//! `encode(decode(w)) == w` for every word of every channel (tested exhaustively).

use crate::error::{Error, Result};

/// Gyro LSB at ±300 °/s, °/s.
pub const GYRO_LSB_300_DPS: f64 = 0.05;
/// Gyro LSB at ±150 °/s, °/s.
pub const GYRO_LSB_150_DPS: f64 = 0.025;
/// Gyro LSB at ±75 °/s, °/s.
pub const GYRO_LSB_75_DPS: f64 = 0.0125;
/// Accelerometer LSB, g.
pub const ACCEL_LSB_G: f64 = 3.333e-3;
/// Magnetometer LSB, gauss (0.5 mgauss).
pub const MAG_LSB_GAUSS: f64 = 0.5e-3;
/// SUPPLY_OUT LSB, V.
pub const SUPPLY_LSB_V: f64 = 2.418e-3;
/// AUX_ADC LSB, V (also the AUX_DAC LSB).
pub const AUX_LSB_V: f64 = 0.806e-3;
/// TEMP_OUT LSB, °C.
pub const TEMP_LSB_C: f64 = 0.136;
/// Temperature of TEMP_OUT code 0, °C.
pub const TEMP_ZERO_C: f64 = 25.0;
/// BARO_OUT LSB, mbar.
pub const BARO_LSB_MBAR: f64 = 0.08;
/// LSB of the 22-bit pressure BARO_OUT·256 + BARO_OUTL, mbar (= 0.08 / 256).
pub const BARO_FINE_LSB_MBAR: f64 = 0.0003125;
/// X/Y/ZGYRO_OFF LSB, °/s (13-bit two's complement, independent of the range).
pub const GYRO_OFF_LSB_DPS: f64 = 0.0125;
/// X/Y/ZACCL_OFF LSB, g (12-bit two's complement).
pub const ACCEL_OFF_LSB_G: f64 = 3.333e-3;
/// X/Y/ZMAGN_HIC LSB, gauss (14-bit two's complement).
pub const MAG_HIC_LSB_GAUSS: f64 = 0.5e-3;
/// X/Y/ZMAGN_SIC value meaning a scale of exactly 1 (12-bit unsigned, 0x800 = 100 %).
pub const MAG_SIC_UNITY: u16 = 0x0800;

/// Bits of the full barometer code BARO_OUT·256 + BARO_OUTL.
const BARO_FINE_BITS: u32 = 22;

/// Gyro measurement range, selected by SENS_AVG[10:8].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum GyroRange {
    /// ±300 °/s, 0.05 °/s per LSB (SENS_AVG[10:8] = 100).
    Dps300,
    /// ±150 °/s, 0.025 °/s per LSB (SENS_AVG[10:8] = 010).
    Dps150,
    /// ±75 °/s, 0.0125 °/s per LSB (SENS_AVG[10:8] = 001).
    Dps75,
}

impl GyroRange {
    /// The smallest M (SENS_AVG bits 2:0) the part allows at this range: M ≥ 2 at ±150 °/s, M ≥ 4 at
    /// ±75 °/s (adis16407.md, SENS_AVG); the defaults of `ModelOptions`.
    pub fn min_m(self) -> u8 {
        match self {
            GyroRange::Dps300 => 0,
            GyroRange::Dps150 => 2,
            GyroRange::Dps75 => 4,
        }
    }

    /// Output LSB in °/s.
    pub fn lsb_dps(self) -> f64 {
        match self {
            GyroRange::Dps300 => GYRO_LSB_300_DPS,
            GyroRange::Dps150 => GYRO_LSB_150_DPS,
            GyroRange::Dps75 => GYRO_LSB_75_DPS,
        }
    }

    /// Rated range in °/s (the 14-bit field reaches 8191 LSB beyond it).
    pub fn rated_dps(self) -> f64 {
        match self {
            GyroRange::Dps300 => 300.0,
            GyroRange::Dps150 => 150.0,
            GyroRange::Dps75 => 75.0,
        }
    }

    /// The range selected by the three bits SENS_AVG[10:8] (already shifted down), if valid.
    /// The bit codes are the sibling parts' [unconfirmed for the 16407].
    pub fn from_bits(bits: u16) -> Option<GyroRange> {
        match bits {
            0b100 => Some(GyroRange::Dps300),
            0b010 => Some(GyroRange::Dps150),
            0b001 => Some(GyroRange::Dps75),
            _ => None,
        }
    }

    /// The value of SENS_AVG[10:8] selecting this range.
    pub fn bits(self) -> u16 {
        match self {
            GyroRange::Dps300 => 0b100,
            GyroRange::Dps150 => 0b010,
            GyroRange::Dps75 => 0b001,
        }
    }

    /// The range whose rated full scale is `dps` (300, 150 or 75).
    pub fn from_dps(dps: f64) -> Result<GyroRange> {
        [GyroRange::Dps300, GyroRange::Dps150, GyroRange::Dps75]
            .into_iter()
            .find(|r| r.rated_dps() == dps)
            .ok_or_else(|| Error::Input(format!("gyro range {dps} °/s: expected 300, 150 or 75")))
    }
}

/// One kind of output word.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Channel {
    /// X/Y/ZGYRO_OUT: 14-bit two's complement, LSB from the range, °/s.
    Gyro,
    /// X/Y/ZACCL_OUT: 14-bit two's complement, 3.333 mg, g.
    Accel,
    /// X/Y/ZMAGN_OUT: 14-bit two's complement, 0.5 mgauss, gauss.
    Mag,
    /// SUPPLY_OUT: 12-bit unsigned, 2.418 mV, V.
    Supply,
    /// TEMP_OUT: 12-bit two's complement, 0.136 °C, 0 = 25 °C, °C.
    Temp,
    /// BARO_OUT: 14-bit unsigned, 0.08 mbar. Encoding takes the full pressure and returns the top
    /// 14 bits of its 22-bit code (so BARO_OUT and BARO_OUTL always belong to the same code).
    Baro,
    /// BARO_OUTL: 8 bits. Encoding takes the full pressure and returns the low byte of its 22-bit
    /// code; decoding returns that byte's contribution, byte × 0.0003125 mbar.
    BaroLow,
    /// AUX_ADC: 12-bit unsigned, 0.806 mV, V.
    Aux,
}

impl Channel {
    /// Every channel.
    pub const ALL: [Channel; 8] = [
        Channel::Gyro,
        Channel::Accel,
        Channel::Mag,
        Channel::Supply,
        Channel::Temp,
        Channel::Baro,
        Channel::BaroLow,
        Channel::Aux,
    ];

    /// Width of the data field in bits.
    pub fn bits(self) -> u32 {
        match self {
            Channel::Gyro | Channel::Accel | Channel::Mag | Channel::Baro => 14,
            Channel::Supply | Channel::Temp | Channel::Aux => 12,
            Channel::BaroLow => 8,
        }
    }

    /// Whether the field is two's complement.
    pub fn signed(self) -> bool {
        matches!(self, Channel::Gyro | Channel::Accel | Channel::Mag | Channel::Temp)
    }

    /// Value of one LSB in the channel's unit.
    pub fn lsb(self, range: GyroRange) -> f64 {
        match self {
            Channel::Gyro => range.lsb_dps(),
            Channel::Accel => ACCEL_LSB_G,
            Channel::Mag => MAG_LSB_GAUSS,
            Channel::Supply => SUPPLY_LSB_V,
            Channel::Temp => TEMP_LSB_C,
            Channel::Baro => BARO_LSB_MBAR,
            Channel::BaroLow => BARO_FINE_LSB_MBAR,
            Channel::Aux => AUX_LSB_V,
        }
    }

    /// 1 / LSB, folded at compile time: the per-sample encoder multiplies instead of dividing. The
    /// gyro reciprocals (20, 40, 80) are exact; for the others `code·lsb·(1/lsb)` stays within a few
    /// ulps of `code`, so decoding still inverts exactly (tested for every code).
    #[inline]
    fn inv_lsb(self, range: GyroRange) -> f64 {
        match self {
            Channel::Gyro => match range {
                GyroRange::Dps300 => 1.0 / GYRO_LSB_300_DPS,
                GyroRange::Dps150 => 1.0 / GYRO_LSB_150_DPS,
                GyroRange::Dps75 => 1.0 / GYRO_LSB_75_DPS,
            },
            Channel::Accel => 1.0 / ACCEL_LSB_G,
            Channel::Mag => 1.0 / MAG_LSB_GAUSS,
            Channel::Supply => 1.0 / SUPPLY_LSB_V,
            Channel::Temp => 1.0 / TEMP_LSB_C,
            Channel::Baro => 1.0 / BARO_LSB_MBAR,
            Channel::BaroLow => 1.0 / BARO_FINE_LSB_MBAR,
            Channel::Aux => 1.0 / AUX_LSB_V,
        }
    }

    /// Physical value of code 0 (25 °C for the temperature, 0 otherwise).
    pub fn zero(self) -> f64 {
        if self == Channel::Temp {
            TEMP_ZERO_C
        } else {
            0.0
        }
    }

    /// The smallest and largest code of the field, as integers.
    pub fn code_limits(self) -> (i32, i32) {
        let bits = self.bits();
        if self.signed() {
            (-(1 << (bits - 1)), (1 << (bits - 1)) - 1)
        } else {
            (0, (1 << bits) - 1)
        }
    }

    /// Unit of the physical value.
    pub fn unit(self) -> &'static str {
        match self {
            Channel::Gyro => "°/s",
            Channel::Accel => "g",
            Channel::Mag => "gauss",
            Channel::Supply | Channel::Aux => "V",
            Channel::Temp => "°C",
            Channel::Baro | Channel::BaroLow => "mbar",
        }
    }

    /// snake_case name (as used by the Python binding).
    pub fn name(self) -> &'static str {
        match self {
            Channel::Gyro => "gyro",
            Channel::Accel => "accel",
            Channel::Mag => "mag",
            Channel::Supply => "supply",
            Channel::Temp => "temp",
            Channel::Baro => "baro",
            Channel::BaroLow => "baro_low",
            Channel::Aux => "aux",
        }
    }

    /// The channel called `name` (see [`Channel::name`]).
    pub fn from_name(name: &str) -> Result<Channel> {
        Channel::ALL.into_iter().find(|c| c.name() == name).ok_or_else(|| {
            Error::Input(format!(
                "channel `{name}`: expected one of gyro, accel, mag, supply, temp, baro, baro_low, aux"
            ))
        })
    }
}

/// An encoded field: the code in the field's own width (two's complement for signed channels, bits
/// above the field zero) and whether the value had to be clipped to the field.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Encoded {
    /// The field bits.
    pub code: u16,
    /// The value lay beyond the field and was clipped to its limit.
    pub overrange: bool,
}

/// A decoded output word.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DecodedWord {
    /// Physical value of the field, in the channel's unit.
    pub value: f64,
    /// The field as a signed integer (sign-extended for two's complement channels).
    pub raw: i32,
    /// Bit 15: new data since the register was last read.
    pub nd: bool,
    /// Bit 14: some DIAG_STAT flag was set.
    pub ea: bool,
}

/// Encode a physical value into a channel's field. NaN is rejected; ±∞ saturate.
pub fn encode(channel: Channel, value: f64, range: GyroRange) -> Result<Encoded> {
    if value.is_nan() {
        return Err(Error::Input(format!("cannot encode NaN into a {} word", channel.name())));
    }
    Ok(FieldCode::of(channel, range).encode(value))
}

/// A channel's field at one gyro range, resolved once so that encoding is arithmetic only:
/// `(value − zero) × 1/LSB`, rounded half away from zero and clipped to the field's codes, then the
/// register's bits of the code. The barometer's two registers share one 22-bit unsigned code:
/// BARO_OUT holds its high 14 bits, BARO_OUTL its low 8.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct FieldCode {
    zero: f64,
    inv_lsb: f64,
    /// The smallest and largest code (as floats), and the scaled values from which on a value clips
    /// (round(x) > hi ⟺ x ≥ hi + ½ and round(x) < lo ⟺ x ≤ lo − ½, ties away from zero).
    lo_f: f64,
    hi_f: f64,
    below: f64,
    above: f64,
    shift: u32,
    mask: u32,
}

impl FieldCode {
    /// The field of `channel` at `range`.
    pub(crate) fn of(channel: Channel, range: GyroRange) -> FieldCode {
        let (lo, hi, inv_lsb) = match channel {
            Channel::Baro | Channel::BaroLow => (0, (1 << BARO_FINE_BITS) - 1, Channel::BaroLow.inv_lsb(range)),
            _ => {
                let (lo, hi) = channel.code_limits();
                (lo, hi, channel.inv_lsb(range))
            }
        };
        let (shift, mask) = match channel {
            Channel::Baro => (8, field_mask(14)),
            Channel::BaroLow => (0, 0xFF),
            _ => (0, field_mask(channel.bits())),
        };
        let (below, above) = (f64::from(lo) - 0.5, f64::from(hi) + 0.5);
        FieldCode {
            zero: channel.zero(),
            inv_lsb,
            lo_f: f64::from(lo),
            hi_f: f64::from(hi),
            below,
            above,
            shift,
            mask: u32::from(mask),
        }
    }

    /// `value` in LSB of the field.
    #[inline(always)]
    fn scaled(&self, value: f64) -> f64 {
        (value - self.zero) * self.inv_lsb
    }

    /// The register bits of `value`'s code (NaN encodes as code 0: [`encode`] rejects it, the
    /// device's input is sanitised).
    #[inline(always)]
    pub(crate) fn code(&self, value: f64) -> u16 {
        // Limited to the field's codes before rounding: the same code as rounding then clipping
        // (the rounding is monotone and the limits are whole), without a branch. NaN passes both
        // comparisons and casts to 0.
        let x = self.scaled(value);
        let x = if x < self.lo_f { self.lo_f } else { x };
        let x = if x > self.hi_f { self.hi_f } else { x };
        ((round_half_away(x) as i32 >> self.shift) as u32 & self.mask) as u16
    }

    /// Whether `value` clips at the field's limits (its code is not the rounded value).
    #[inline(always)]
    pub(crate) fn clips(&self, value: f64) -> bool {
        let x = self.scaled(value);
        x >= self.above || x <= self.below
    }

    /// [`FieldCode::code`] with whether it clipped.
    #[inline(always)]
    pub(crate) fn encode(&self, value: f64) -> Encoded {
        Encoded { code: self.code(value), overrange: self.clips(value) }
    }
}

/// An interval of values of `channel` that surely encode without clipping: the field's range shrunk
/// by 1 %, for a cheap screen before the exact [`FieldCode::clips`] test. Inside it the exact test cannot
/// fire: its scaling rounds by a few ulps (1e-16 relative), the margin is 1e-2 of the range.
pub(crate) fn surely_unclipped(channel: Channel, range: GyroRange) -> (f64, f64) {
    const MARGIN: f64 = 0.99;
    // The limits and LSB `scaled` uses.
    let (lo, hi, lsb) = match channel {
        Channel::Baro | Channel::BaroLow => (0, (1 << BARO_FINE_BITS) - 1, BARO_FINE_LSB_MBAR),
        _ => {
            let (lo, hi) = channel.code_limits();
            (lo, hi, channel.lsb(range))
        }
    };
    let zero = channel.zero();
    (zero + MARGIN * (f64::from(lo) - 0.5) * lsb, zero + MARGIN * (f64::from(hi) + 0.5) * lsb)
}

/// Decode a whole 16-bit output word: the channel's field plus the ND and EA flags.
pub fn decode(channel: Channel, word: u16, range: GyroRange) -> DecodedWord {
    let field = word & field_mask(channel.bits());
    let raw = if channel.signed() { sign_extend(field, channel.bits()) } else { i32::from(field) };
    DecodedWord {
        value: channel.zero() + f64::from(raw) * channel.lsb(range),
        raw,
        nd: word & 0x8000 != 0,
        ea: word & 0x4000 != 0,
    }
}

/// Pressure from the pair BARO_OUT, BARO_OUTL: (BARO_OUT·256 + BARO_OUTL) × 0.0003125 mbar.
pub fn decode_baro(baro_out: u16, baro_outl: u16) -> f64 {
    let full = (u32::from(baro_out & field_mask(14)) << 8) | u32::from(baro_outl & 0xFF);
    f64::from(full) * BARO_FINE_LSB_MBAR
}

/// Round to nearest, ties away from zero (as `f64::round`), for |x| < 2⁶³, without a libm call
/// (`f64::round` is one on baseline x86-64, and this sits on the per-sample path) and without a
/// branch: x + ±H truncated, H = ½ − 2⁻⁵⁴ (the largest double below ½).
///
/// Why it is exact (x > 0, n = ⌊x⌋; negative x is the mirror image): if x − n ≥ ½, x + H ≥ n + 1 −
/// 2⁻⁵⁴, which rounds to n + 1 (the spacing below n + 1 is at least 2⁻⁵³; for n = 0 it is a tie that
/// goes to the even 1.0), and x + H < n + 1.5, so the truncation is n + 1. If x − n < ½, x is at
/// most n + ½ − ulp(x), so x + H ≤ n + 1 − ulp(x) − 2⁻⁵⁴ with n + 1 − ulp(x) a double (x and the
/// doubles just below n + 1 share their spacing), so the sum rounds below n + 1: truncated, n.
/// From 2⁵² on every double is whole and adding H changes nothing.
#[inline]
pub(crate) fn round_half_away(x: f64) -> i64 {
    const H: f64 = 0.499_999_999_999_999_94;
    (x + H.copysign(x)) as i64
}

/// Mask of the low `bits` bits.
pub fn field_mask(bits: u32) -> u16 {
    ((1u32 << bits) - 1) as u16
}

/// The low `bits` bits of `value` read as two's complement.
pub fn sign_extend(value: u16, bits: u32) -> i32 {
    let shift = 32 - bits;
    ((u32::from(value) << shift) as i32) >> shift
}

/// `value` as a `bits`-wide two's complement field (bits above the field zero).
pub fn to_field(value: i32, bits: u32) -> u16 {
    (value as u32 & u32::from(field_mask(bits))) as u16
}

#[cfg(test)]
mod tests {
    use super::*;

    const R300: GyroRange = GyroRange::Dps300;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    #[test]
    fn gyro_vectors_at_300() {
        let cases = [(0x1770u16, 300.0), (0x0001, 0.05), (0x3FFF, -0.05), (0x3FFE, -0.10), (0x2890, -300.0)];
        for (word, value) in cases {
            let d = decode(Channel::Gyro, word, R300);
            // The product code × 0.05 is exact to a few ulps of the value.
            assert!(close(d.value, value, 4.0 * f64::EPSILON * 300.0), "0x{word:04X} → {}", d.value);
            let e = encode(Channel::Gyro, value, R300).unwrap();
            assert_eq!(e, Encoded { code: word, overrange: false }, "{value} °/s");
        }
        assert_eq!(decode(Channel::Gyro, 0x1770, R300).raw, 6000);
        assert_eq!(decode(Channel::Gyro, 0x2890, R300).raw, -6000);
    }

    #[test]
    fn datasheet_example_at_75() {
        let d = decode(Channel::Gyro, 0xF9DA, GyroRange::Dps75);
        assert_eq!(d.raw, -1574);
        assert!(close(d.value, -19.675, 1e-12), "{}", d.value);
        assert!(d.nd && d.ea);
        assert_eq!(encode(Channel::Gyro, -19.675, GyroRange::Dps75).unwrap().code, 0xF9DA & 0x3FFF);
    }

    #[test]
    fn accel_vectors() {
        let p = decode(Channel::Accel, 0x1519, R300);
        let n = decode(Channel::Accel, 0x2AE7, R300);
        assert_eq!((p.raw, n.raw), (5401, -5401));
        assert!(close(p.value, 5401.0 * 3.333e-3, 1e-12) && close(p.value, 18.0, 0.005));
        assert!(close(n.value, -5401.0 * 3.333e-3, 1e-12) && close(n.value, -18.0, 0.005));
        assert_eq!(encode(Channel::Accel, 18.0, R300).unwrap().code, 0x1519);
        assert_eq!(encode(Channel::Accel, -18.0, R300).unwrap().code, 0x2AE7);
    }

    #[test]
    fn supply_vectors() {
        let d = decode(Channel::Supply, 0xC7A7, R300);
        assert_eq!(d.raw, 0x7A7);
        assert!(close(d.value, 4.737, 0.0005) && d.nd && d.ea, "{d:?}");
        for (word, volts) in [(0x814u16, 5.0), (0x7AC, 4.75), (0x87B, 5.25)] {
            assert_eq!(encode(Channel::Supply, volts, R300).unwrap().code, word, "{volts} V");
            // Decoding recovers the voltage to within half an LSB.
            assert!(close(decode(Channel::Supply, word, R300).value, volts, SUPPLY_LSB_V / 2.0));
        }
        assert_eq!(encode(Channel::Supply, 4.737, R300).unwrap().code, 0x7A7);
    }

    #[test]
    fn temperature_zero_is_25_c() {
        assert_eq!(decode(Channel::Temp, 0x000, R300).value, 25.0);
        assert_eq!(encode(Channel::Temp, 25.0, R300).unwrap().code, 0);
        assert_eq!(decode(Channel::Temp, 0xFFF, R300).raw, -1);
        assert!(close(decode(Channel::Temp, 0xFFF, R300).value, 25.0 - 0.136, 1e-12));
    }

    #[test]
    fn barometer_pair() {
        // 1013.25 mbar = 3242400 × 0.0003125 exactly: BARO_OUT 12665 (×0.08 = 1013.2), BARO_OUTL 160.
        let hi = encode(Channel::Baro, 1013.25, R300).unwrap().code;
        let lo = encode(Channel::BaroLow, 1013.25, R300).unwrap().code;
        assert_eq!((hi, lo), (12665, 160));
        assert!(close(decode_baro(hi, lo), 1013.25, 1e-9));
        assert!(close(decode(Channel::Baro, hi, R300).value, 1013.2, 1e-9));
        assert!(close(decode(Channel::BaroLow, lo, R300).value, 0.05, 1e-12));
    }

    #[test]
    fn saturation_sets_overrange() {
        // 409.55 °/s is 8191 LSB; above it the 14-bit field clips.
        assert_eq!(encode(Channel::Gyro, 409.55, R300).unwrap(), Encoded { code: 0x1FFF, overrange: false });
        assert_eq!(encode(Channel::Gyro, 450.0, R300).unwrap(), Encoded { code: 0x1FFF, overrange: true });
        assert_eq!(encode(Channel::Gyro, -1e9, R300).unwrap(), Encoded { code: 0x2000, overrange: true });
        assert_eq!(encode(Channel::Gyro, f64::INFINITY, R300).unwrap().code, 0x1FFF);
        assert!(encode(Channel::Supply, -1.0, R300).unwrap().overrange);
        assert!(encode(Channel::Baro, 2000.0, R300).unwrap().overrange);
        assert_eq!(encode(Channel::BaroLow, 2000.0, R300).unwrap().code, 0xFF);
        assert!(encode(Channel::Gyro, f64::NAN, R300).is_err());
    }

    #[test]
    fn range_changes_the_lsb() {
        assert_eq!(encode(Channel::Gyro, 10.0, GyroRange::Dps300).unwrap().code, 200);
        assert_eq!(encode(Channel::Gyro, 10.0, GyroRange::Dps150).unwrap().code, 400);
        assert_eq!(encode(Channel::Gyro, 10.0, GyroRange::Dps75).unwrap().code, 800);
        assert_eq!(GyroRange::from_dps(150.0).unwrap(), GyroRange::Dps150);
        assert!(GyroRange::from_dps(200.0).is_err());
    }

    #[test]
    fn every_code_of_every_channel_round_trips() {
        for range in [GyroRange::Dps300, GyroRange::Dps150, GyroRange::Dps75] {
            for ch in Channel::ALL {
                for code in 0..=field_mask(ch.bits()) {
                    // Flags and don't-care bits above the field must not disturb the decode.
                    let dont_care = 0x3FFF & !field_mask(ch.bits());
                    for flags in [0u16, 0xC000] {
                        let word = code | flags | dont_care;
                        let d = decode(ch, word, range);
                        let e = encode(ch, d.value, range).unwrap();
                        assert_eq!(e, Encoded { code, overrange: false }, "{} word 0x{word:04X}", ch.name());
                    }
                }
            }
        }
    }

    #[test]
    fn the_unclipped_interval_is_inside_the_field_by_its_margin() {
        for range in [GyroRange::Dps300, GyroRange::Dps150, GyroRange::Dps75] {
            for ch in Channel::ALL {
                let (lo, hi) = surely_unclipped(ch, range);
                let zero = ch.zero();
                assert!(lo < zero && zero < hi, "{}", ch.name());
                // The ends do not clip; 1.1 % further out (past the 1 % margin) they do: the interval
                // has the field's limits and LSB.
                for (end, side) in [(lo, "low"), (hi, "high")] {
                    assert!(!FieldCode::of(ch, range).clips(end), "{} {side} end clips", ch.name());
                    let beyond = zero + (end - zero) / 0.99 * 1.001;
                    assert!(
                        FieldCode::of(ch, range).clips(beyond),
                        "{} beyond the {side} end does not clip",
                        ch.name()
                    );
                }
            }
        }
    }

    #[test]
    fn fast_rounding_matches_f64_round() {
        let mut x = 0.123_f64;
        for _ in 0..100_000 {
            x = (x * 3.99 * (1.0 - x)).clamp(1e-12, 1.0);
            for v in [x * 1e4 - 5e3, (x * 64.0).floor() / 2.0 - 16.0, -x, x * 1e15] {
                assert_eq!(round_half_away(v) as f64, v.round(), "{v}");
            }
        }
        // Every half (the ties) and the doubles either side of it, from 0.5 through 2⁵³, among them
        // the halves next to every power of two (where the spacing changes), both signs.
        let mut halves: Vec<f64> = (0..4096).map(|n| n as f64 + 0.5).collect();
        for k in 1..=53 {
            let p = 2f64.powi(k);
            halves.extend([p - 1.5, p - 0.5, p + 0.5, p + 1.5]);
        }
        for h in halves {
            for v in [h.next_down(), h, h.next_up(), h.next_down().next_down(), h.next_up().next_up()] {
                for v in [v, -v] {
                    assert_eq!(round_half_away(v) as f64, v.round(), "{v}");
                }
            }
        }
        for v in [0.5, -0.5, 1.5, -1.5, 2.5, 0.499_999_999_999_999_94, -0.0, 4_503_599_627_370_495.5, 1e18] {
            assert_eq!(round_half_away(v) as f64, v.round(), "{v}");
        }
    }

    #[test]
    fn sign_helpers() {
        assert_eq!(sign_extend(0x1000, 13), -4096);
        assert_eq!(sign_extend(0x0FFF, 13), 4095);
        assert_eq!(to_field(-1, 13), 0x1FFF);
        assert_eq!(Channel::from_name("baro_low").unwrap(), Channel::BaroLow);
        assert!(Channel::from_name("gyros").is_err());
    }
}
