//! What each SPI part needs of the master that clocks it: character lengths, clock modes, the SCLK
//! limit, derived from its [`SpiTiming`] declaration. The profile checks SPI-A's registers against
//! the part it places on the acquisition chip select (`[[board.devices]]`), and `sins-fw board`
//! reports from the same figures. The ADIS16xxx family's come from its declarations (`family`,
//! each part's [`Part::spi`](super::super::part::Part::spi)); the other families' parts are the rows of [`OTHER`].

use super::super::spi_timing::SpiTiming;

/// A part's needs of the SPI master.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpiNeeds {
    /// The part's name.
    pub part: &'static str,
    /// Character lengths (SPICHAR + 1) the part is read with correctly.
    pub char_bits: &'static [u8],
    /// Standard SPI modes it accepts.
    pub modes: &'static [u8],
    /// Its SCLK limit, Hz.
    pub sclk_max_hz: f64,
    /// Characters of one read (the ADIS16xxx burst; one ADS8344 conversion).
    pub chars_per_read: u32,
    /// What the data sheet asks, for the messages: "…: expected <this>".
    pub expects: &'static str,
}

impl SpiNeeds {
    /// The needs of `part`, whose SPI timing is `timing`.
    const fn of(part: &'static str, timing: &SpiTiming, chars_per_read: u32, expects: &'static str) -> SpiNeeds {
        SpiNeeds {
            part,
            char_bits: timing.char_bits,
            modes: timing.modes,
            sclk_max_hz: timing.sclk_max_hz,
            chars_per_read,
            expects,
        }
    }
}

/// The parts of other families on SPI.
pub const OTHER: &[SpiNeeds] = &[
    SpiNeeds::of(
        "ADS8344",
        &super::ads8344::SPI,
        4,
        "SPICHAR = 7 (8-bit characters: the control byte, then three bytes holding the null bit and \
         D15…D0, ads8344.md); with 16-bit characters D15…D9 fall in the command's character and are \
         lost (24-clock framing needs the result bits after the character that carries S); SPI mode 0 \
         (mode 3 is electrically the same for it), DCLK ≤ 2.4 MHz",
    ),
    SpiNeeds::of(
        "ADXL345",
        &super::adxl345::SPI,
        7,
        "byte-wide transfers (8- or 16-bit characters), SPI mode 3, SCLK ≤ 5 MHz (adxl345.md)",
    ),
];

/// The needs of the part `name` (case-insensitive), ADIS16xxx or another family's.
pub fn spi_needs(name: &str) -> Option<SpiNeeds> {
    if let Some(p) = super::by_name(name) {
        return Some(SpiNeeds::of(
            p.name,
            &p.spi,
            p.burst_frames() as u32,
            "SPICHAR = 15 (16-bit characters): the ADIS16xxx family uses 16-bit frames, SPI mode 3",
        ));
    }
    OTHER.iter().find(|n| n.part.eq_ignore_ascii_case(name)).copied()
}
