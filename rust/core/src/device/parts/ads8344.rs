//! The ADS8344's SPI timing (ads8344.md, each figure's source there); its model is
//! `device::ads8344`, whose configuration may change the DCLK limit and t_CSS.

use crate::device::spi_timing::SpiTiming;

/// DCLK ≤ 2.4 MHz (100 kHz × 24 clocks at 5 V) [unconfirmed for ADS8344: ADS8341 p. 15]; CS↓ to
/// the first DCLK edge t_CSS ≥ 50 ns [ADS8345 Table VII]; SPI mode 0, or 3, which is electrically
/// the same for it (DIN sampled on rising edges, DOUT moved on falling ones); clocked bit by bit
/// (a frame of any length), read correctly with 8-bit characters; no CS hold or CS-high minimum.
pub const SPI: SpiTiming = SpiTiming {
    sclk_max_hz: 2.4e6,
    cs_setup_ps: 50_000.0,
    cs_hold_ps: None,
    cs_high_min_ps: None,
    modes: &[0, 3],
    frame_bits: None,
    char_bits: &[8],
    slack_ps: 0.0,
};
