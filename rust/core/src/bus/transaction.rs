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
use crate::dsp::spi::Frame;
use crate::time::{Clock, Ps};

/// Shortest full SCLK period of the frame's clock: twice its active (shorter) phase.
pub fn sclk_period(frame: &Frame, lspclk: &Clock) -> Ps {
    lspclk.cycles_to_ps(2 * frame.shape.active_cycles() as u64)
}

/// The frame's timing as the slave sees it (`lspclk`: the clock the frame is timed by). `sclk_period` is [`sclk_period`] of the frame (the link
/// caches it per baud setting).
#[inline]
pub fn frame_timing(frame: &Frame, lspclk: &Clock, sclk_period: Ps) -> FrameTiming {
    let shape = &frame.shape;
    let bits = shape.bits as u32;
    // Without delay the first edge is the start and the last edge is one idle phase before the end;
    // with delay the first edge is one idle phase after the start and the last edge is the end.
    let (first_edge, last_edge) = if shape.scheme.phase {
        (lspclk.cycles_to_ps(frame.start_cycle + shape.idle_cycles() as u64), frame.end_ps)
    } else {
        (frame.start_ps, lspclk.cycles_to_ps(frame.start_cycle + shape.edge_cycle(2 * bits - 1)))
    };
    FrameTiming { first_edge, last_edge, sclk_period, bits: shape.bits, cpol: shape.scheme.polarity }
}

/// What master and slave sample in the frame, given the word the slave shifts out.
pub fn exchange(frame: &Frame, dout: u16, lines: Lines) -> Exchange {
    let bits = frame.shape.bits as u32;
    let drop = 16 - bits;
    let mask = frame.rx_mask();
    let ones = if lines.floating { mask } else { 0 };
    let scheme = frame.shape.scheme;
    let mode3 = scheme.polarity && !scheme.phase;
    let master_rx = if frame.loopback {
        frame.tx >> drop
    } else if !lines.selected {
        ones
    } else if mode3 {
        dout >> drop
    } else {
        ((dout >> 1) | (dout & 0x8000)) >> drop
    };
    let slave_din = if !lines.selected {
        0
    } else if !frame.talk {
        ones
    } else if !scheme.polarity && !scheme.phase {
        ((u16::from(lines.simo_before) << 15) | (frame.tx >> 1)) >> drop
    } else {
        frame.tx >> drop
    };
    let simo_after = if frame.talk { frame.tx_bit(bits - 1) } else { lines.floating };
    Exchange { master_rx: master_rx & mask, slave_din: slave_din & mask, simo_after }
}
