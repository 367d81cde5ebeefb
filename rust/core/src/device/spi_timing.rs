//! What an SPI part asks of the master that clocks it, as data: one [`SpiTiming`] per part, in
//! the part's declaration (`parts/`). The part's model checks its frames against it with the one
//! shared checker (`device::spi_rules`), and the profile's SPI-A checks and `sins-fw board` read
//! the same figures (`parts::spi_needs`). Data only: it sits below the profile with the other
//! declarations.

/// A part's SPI timing and framing rules, from its data sheet.
///
/// A rule is broken when the measured time (whole ps, as the bus floors it) plus
/// [`SpiTiming::slack_ps`] falls short of the required one: see `device::frame::short`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpiTiming {
    /// SCLK limit, Hz (`sclk_too_fast` above it: the frame's full SCLK period shorter than 1/f).
    pub sclk_max_hz: f64,
    /// CS↓ to the first SCLK edge of a chip-select window, at least, ps (`cs_setup`).
    pub cs_setup_ps: f64,
    /// The last SCLK edge to CS↑, at least, ps (`cs_hold`); `None`: not a rule of the part.
    pub cs_hold_ps: Option<f64>,
    /// CS high between two chip-select windows, at least, ps (`cs_high_too_short`); `None`: not a
    /// rule of the part.
    pub cs_high_min_ps: Option<f64>,
    /// The standard SPI modes the part is clocked correctly in (`spi_mode` otherwise).
    pub modes: &'static [u8],
    /// SCLK cycles of one frame the part takes (a frame of another length is a broken rule);
    /// `None`: the part is clocked bit by bit and takes frames of any length.
    pub frame_bits: Option<u8>,
    /// The master's character lengths (SPICHAR + 1) the part is read with correctly: what the
    /// profile checks `spi.spiccr` against.
    pub char_bits: &'static [u8],
    /// The allowance added to a measured time before it is compared, ps: 1 where the part's
    /// rules absorb the bus's flooring of times to whole picoseconds (the ADIS16xxx family), 0
    /// where a time short of the limit by any amount breaks it.
    pub slack_ps: f64,
}

impl SpiTiming {
    /// The shortest SCLK period the part takes, ps.
    pub const fn min_sclk_period_ps(&self) -> f64 {
        1e12 / self.sclk_max_hz
    }
}
