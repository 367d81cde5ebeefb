//! Transaction level: one closed-form computation per frame (the fast path).
//!
//! The closed forms are what the bit level (`bitlevel.rs`) derives edge by edge; a property test
//! holds the two equal. The slave is the ADIS16407 in SPI mode 3: it drives DOUT on falling edges
//! (its n-th falling edge since CS↓ drives bit n, the MSB is already valid after CS↓) and samples DIN
//! on rising edges. A line sampled on the same edge the other side changes it reads the value from
//! before the edge (the driver's output delay exceeds the sampler's hold time).
//!
//! With TI's "falling edge without delay" scheme (mode 3) both words arrive intact. With any other
//! scheme the master samples each DOUT bit on the edge the slave moves to the next one, so it
//! reads the MSB twice and loses the LSB: `rx = (dout >> 1) | (dout & 0x8000)`. With "rising edge
//! without delay" (mode 1) the slave also samples each DIN bit on the edge the master changes it,
//! so it reads the previous SPISIMO level first and loses the LSB.

use super::{Exchange, FrameTiming, Lines};
use crate::dsp::spi::{CharShape, Frame};
use crate::time::{Clock, Ps};

/// Shortest full SCLK period of the frame's clock: twice its active (shorter) phase.
pub fn sclk_period(frame: &Frame, lspclk: &Clock) -> Ps {
    lspclk.cycles_to_ps(2 * frame.shape.active_cycles() as u64)
}

/// The timing of a character of `shape` started on LSPCLK cycle `start_cycle`, as the slave sees it
/// (`lspclk`: the clock the character is timed by; `sclk_period`: [`sclk_period`] of the shape, which
/// the link caches per baud setting).
#[inline]
pub fn frame_timing(shape: &CharShape, start_cycle: u64, lspclk: &Clock, sclk_period: Ps) -> FrameTiming {
    TimingOf::new(shape, lspclk, sclk_period).at(start_cycle)
}

/// [`frame_timing`] for any start cycle of one character shape: what does not depend on the start is
/// worked out once (a run of characters shares it).
#[derive(Debug, Clone, Copy)]
pub struct TimingOf {
    /// LSPCLK cycles from the start to the first and to the last SCLK edge.
    first: u64,
    last: u64,
    lspclk: Clock,
    sclk_period: Ps,
    bits: u8,
    cpol: bool,
}

impl TimingOf {
    /// The timing of characters of `shape`.
    #[inline]
    pub fn new(shape: &CharShape, lspclk: &Clock, sclk_period: Ps) -> TimingOf {
        // Without delay the first edge is the start and the last edge is one idle phase before the
        // end; with delay the first edge is one idle phase after the start and the last edge is the end.
        let (first, last) = if shape.scheme.phase {
            (shape.idle_cycles() as u64, shape.length_cycles())
        } else {
            (0, shape.edge_cycle(shape.edges() - 1))
        };
        TimingOf { first, last, lspclk: *lspclk, sclk_period, bits: shape.bits, cpol: shape.scheme.polarity }
    }

    /// The timing of the character started on LSPCLK cycle `start_cycle`.
    #[inline]
    pub fn at(&self, start_cycle: u64) -> FrameTiming {
        FrameTiming {
            first_edge: self.lspclk.cycles_to_ps(start_cycle + self.first),
            last_edge: self.lspclk.cycles_to_ps(start_cycle + self.last),
            sclk_period: self.sclk_period,
            bits: self.bits,
            cpol: self.cpol,
        }
    }
}

/// What master and slave sample in the frame, given the word the slave shifts out.
pub fn exchange(frame: &Frame, dout: u16, lines: Lines) -> Exchange {
    Exchange {
        master_rx: master_rx(frame, dout, lines),
        slave_din: slave_din(frame, lines),
        simo_after: simo_after(frame, lines),
    }
}

/// The bits the master samples, right-justified, given the word the slave shifts out.
#[inline]
pub fn master_rx(frame: &Frame, dout: u16, lines: Lines) -> u16 {
    let drop = 16 - frame.shape.bits as u32;
    let scheme = frame.shape.scheme;
    let rx = if frame.loopback {
        frame.tx >> drop
    } else if !lines.selected {
        if lines.floating {
            0xFFFF
        } else {
            0
        }
    } else if scheme.polarity && !scheme.phase {
        dout >> drop
    } else {
        ((dout >> 1) | (dout & 0x8000)) >> drop
    };
    rx & frame.rx_mask()
}

/// The bits the slave samples on DIN, right-justified (0 when it is not selected).
#[inline]
pub fn slave_din(frame: &Frame, lines: Lines) -> u16 {
    let drop = 16 - frame.shape.bits as u32;
    let scheme = frame.shape.scheme;
    let din = if !lines.selected {
        0
    } else if !frame.talk {
        0xFFFF * u16::from(lines.floating)
    } else if !scheme.polarity && !scheme.phase {
        ((u16::from(lines.simo_before) << 15) | (frame.tx >> 1)) >> drop
    } else {
        frame.tx >> drop
    };
    din & frame.rx_mask()
}

/// The SPISIMO level after the frame: the last bit driven, or the floating level without TALK.
#[inline]
pub fn simo_after(frame: &Frame, lines: Lines) -> bool {
    if frame.talk {
        frame.tx_bit(frame.shape.bits as u32 - 1)
    } else {
        lines.floating
    }
}
