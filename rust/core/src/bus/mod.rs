//! The SPI link between the F28335 (master) and the ADIS16407 (slave).
//!
//! The bus computes, from the master's configuration, what the wires show in each frame and hands the
//! slave a [`FrameTiming`]; the slave answers with the word it shifts out. Two levels must agree:
//! a transaction level (one computation per frame, the fast path) and a bit level (every SCLK edge).

pub mod bitlevel;
pub mod link;
pub mod transaction;

pub use crate::profile::BusLevel;
pub use link::{FrameRecord, LinkRecord, SpiLink};

use crate::time::Ps;

/// What the wires show the slave about one frame, computed by the bus from the master's registers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FrameTiming {
    /// Time of the first SCLK edge of the frame.
    pub first_edge: Ps,
    /// Time of the last SCLK edge of the frame.
    pub last_edge: Ps,
    /// Shortest full SCLK period in the frame (the asymmetric clock of an odd SPIBRR+1 counts its
    /// shorter phase twice, which is what the slave's SCLK limit is about).
    pub sclk_period: Ps,
    /// Number of SCLK cycles in the frame (the master's character length).
    pub bits: u8,
    /// Clock polarity on the wire: `true` when SCLK idles high.
    pub cpol: bool,
}

/// The slave side of the link, at word level. The slave is told about chip select and frames; it
/// checks its own timing rules against what the wires show.
pub trait SpiSlave {
    /// Chip select changes at time `t` (`low == true`: asserted).
    fn set_cs(&mut self, low: bool, t: Ps);
    /// A frame is about to be clocked: return the 16-bit word the slave shifts out on DOUT
    /// (MSB first, in its own SPI mode).
    fn begin_frame(&mut self, timing: &FrameTiming) -> u16;
    /// The frame is over; `din` is the word the slave sampled on DIN.
    fn end_frame(&mut self, din: u16, timing: &FrameTiming);
}

/// The state of the lines around one frame that decides what each side samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Lines {
    /// The slave's chip select is asserted when the frame starts (it sees the frame).
    pub selected: bool,
    /// SPISIMO level before the frame (the last bit the master drove, or the floating level).
    pub simo_before: bool,
    /// The level an undriven line reads as (SPISIMO with TALK = 0, DOUT with CS high).
    pub floating: bool,
}

/// What one frame exchanged, as both sides sampled it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Exchange {
    /// Bits the master sampled, right-justified (the frame's character length).
    pub master_rx: u16,
    /// Bits the slave sampled on DIN at its rising edges, right-justified (0 when not selected).
    pub slave_din: u16,
    /// SPISIMO level after the frame.
    pub simo_after: bool,
}
