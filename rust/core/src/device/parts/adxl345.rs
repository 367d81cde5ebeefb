//! The ADXL345's SPI timing (adxl345.md: data sheet Rev. E Table 10 and p. 15); its model is
//! `device::adxl345`.

use crate::device::spi_timing::SpiTiming;

/// Mode 3, byte-wide frames; f_SCLK ≤ 5 MHz, tDELAY (CS↓ to the first SCLK edge) ≥ 5 ns, tQUIET
/// (the last SCLK edge to CS↑) ≥ 5 ns, tCS,DIS (CS high between two communications) ≥ 150 ns. The
/// master may use 8- or 16-bit characters (the byte is the character's top half).
pub const SPI: SpiTiming = SpiTiming {
    sclk_max_hz: 5.0e6,
    cs_setup_ps: 5_000.0,
    cs_hold_ps: Some(5_000.0),
    cs_high_min_ps: Some(150_000.0),
    modes: &[3],
    frame_bits: Some(8),
    char_bits: &[8, 16],
    slack_ps: 0.0,
};
