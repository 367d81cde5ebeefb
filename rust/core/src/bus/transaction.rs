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
        TimingOf::with_edges((first, last), lspclk, sclk_period, shape.bits, shape.scheme.polarity)
    }

    /// The timing of characters whose first and last SCLK edges come `edges` = (first, last) LSPCLK
    /// cycles after their start (`first ≤ last`), of `bits` SCLK cycles, SCLK idling high if `cpol`.
    #[inline]
    pub fn with_edges(edges: (u64, u64), lspclk: &Clock, sclk_period: Ps, bits: u8, cpol: bool) -> TimingOf {
        let (first, last) = edges;
        debug_assert!(first <= last);
        TimingOf { first, last, lspclk: *lspclk, sclk_period, bits, cpol }
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

    /// [`TimingOf::at`] of each of `starts` (in increasing order), appended to `out`. A run converts
    /// its start cycles with the overflow test made once, and each last edge from its first edge's
    /// conversion ([`crate::time::CyclesToPs::after`]): one division per character instead of two.
    pub fn extend_run(&self, starts: &[u64], out: &mut Vec<FrameTiming>) {
        let Some(&latest) = starts.last() else { return };
        debug_assert!(starts.windows(2).all(|w| w[0] < w[1]), "a run's starts increase");
        let Some(exact) = self.lspclk.cycles_to_ps_up_to(latest + self.first) else {
            return out.extend(starts.iter().map(|&s| self.at(s)));
        };
        let edge_to_edge = exact.span(self.last - self.first);
        out.extend(starts.iter().map(|&s| {
            let first_edge = exact.split(s + self.first);
            FrameTiming {
                first_edge: first_edge.ps,
                last_edge: exact.after(first_edge, edge_to_edge),
                sclk_period: self.sclk_period,
                bits: self.bits,
                cpol: self.cpol,
            }
        }));
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
        floating_bits(lines)
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
        floating_bits(lines)
    } else if !scheme.polarity && !scheme.phase {
        ((u16::from(lines.simo_before) << 15) | (frame.tx >> 1)) >> drop
    } else {
        frame.tx >> drop
    };
    din & frame.rx_mask()
}

/// What an undriven line reads as, all bits of a word: the floating level.
#[inline]
fn floating_bits(lines: Lines) -> u16 {
    if lines.floating {
        0xFFFF
    } else {
        0
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dsp::spi::ClockScheme;

    #[test]
    fn a_run_of_timings_is_each_start_timed_alone() {
        let lspclks = [Clock::new(75_000_000, 2), Clock::from_hz(150_000_000 / 14), Clock::new(7, 3)];
        let mut run = Vec::new();
        for lspclk in lspclks {
            for (bits, divisor, polarity, phase) in
                [(16, 50, true, true), (16, 4, false, false), (8, 7, true, false), (1, 3, false, true)]
            {
                let shape = CharShape { bits, divisor, scheme: ClockScheme { polarity, phase } };
                let timing = TimingOf::new(&shape, &lspclk, 1_333_333);
                // A burst's spacing, from small starts to runs just inside, across and past the largest
                // count the 64-bit conversion takes (the run then converts each start alone).
                let (mut lo, mut hi) = (0u64, u64::MAX / 2);
                while lo < hi {
                    let mid = lo + (hi - lo).div_ceil(2);
                    (lo, hi) = if lspclk.cycles_to_ps_up_to(mid).is_some() { (mid, hi) } else { (lo, mid - 1) };
                }
                let bound = lo - 60;
                for first in [0, 3, 123_456_789, bound - 13_000, bound - 11_000, bound - 5_000, bound + 1] {
                    let starts: Vec<u64> = (0..14).map(|i| first + 853 * i + i * i % 5).collect();
                    run.clear();
                    timing.extend_run(&starts, &mut run);
                    let alone: Vec<FrameTiming> = starts.iter().map(|&s| timing.at(s)).collect();
                    assert_eq!(run, alone, "{lspclk:?} {shape:?} from {first}");
                }
            }
        }
    }
}
