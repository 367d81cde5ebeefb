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
//!
//! A slave whose word is already what the master samples in the frame's own mode
//! ([`Lines::dout_as_sampled`], the ADS8344: it works out each clock's edges itself) moves DOUT on
//! the edges the master does not sample on: the master reads its word as it is, in every scheme.

use super::{Exchange, FrameTiming, Lines};
use crate::dsp::spi::{CharShape, Frame};
use crate::time::{Clock, Ps};

/// The full SCLK period of the frame's clock: SPIBRR+1 LSPCLK cycles (an active and an idle phase).
pub fn sclk_period(frame: &Frame, lspclk: &Clock) -> Ps {
    lspclk.cycles_to_ps(u64::from(frame.shape.divisor))
}

/// The timing of character `index` of `shape` started on LSPCLK cycle `start_cycle`, as the slave
/// sees it (`lspclk`: the clock the character is timed by; `sclk_period`: [`sclk_period`] of the shape, which
/// the link caches per baud setting).
#[inline]
pub fn frame_timing(shape: &CharShape, index: u64, start_cycle: u64, lspclk: &Clock, sclk_period: Ps) -> FrameTiming {
    TimingOf::new(shape, lspclk, sclk_period).at(index, start_cycle)
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
    mode: u8,
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
        TimingOf::with_edges((first, last), lspclk, sclk_period, shape.bits, shape.scheme.standard_mode())
    }

    /// The timing of characters whose first and last SCLK edges come `edges` = (first, last) LSPCLK
    /// cycles after their start (`first ≤ last`), of `bits` SCLK cycles, in standard SPI mode `mode`.
    #[inline]
    pub fn with_edges(edges: (u64, u64), lspclk: &Clock, sclk_period: Ps, bits: u8, mode: u8) -> TimingOf {
        let (first, last) = edges;
        debug_assert!(first <= last);
        TimingOf { first, last, lspclk: *lspclk, sclk_period, bits, mode }
    }

    /// The timing of character `index`, started on LSPCLK cycle `start_cycle`.
    #[inline]
    pub fn at(&self, index: u64, start_cycle: u64) -> FrameTiming {
        FrameTiming {
            index,
            first_edge: self.first_edge(start_cycle),
            last_edge: self.lspclk.cycles_to_ps(start_cycle + self.last),
            sclk_period: self.sclk_period,
            bits: self.bits,
            mode: self.mode,
        }
    }

    /// The first edge of the character started on LSPCLK cycle `start_cycle` (that of [`TimingOf::at`]).
    #[inline]
    pub fn first_edge(&self, start_cycle: u64) -> Ps {
        self.lspclk.cycles_to_ps(start_cycle + self.first)
    }

    /// The characters whose first edge comes before `t` are those started below the returned LSPCLK
    /// cycle (⌈t·D/N⌉ − first, one cycle being N/D ps), for `t` no later than the first edge of a
    /// character within [`TimingOf::exact_up_to`] (then the count fits u64 and converts exactly).
    #[inline]
    pub fn starts_before(&self, t: Ps) -> u64 {
        self.lspclk.ps_to_cycles_ceil(t).saturating_sub(self.first)
    }

    /// Whether every edge of the characters started up to LSPCLK cycle `latest_start` converts to ps
    /// in 64 bits ([`Clock::converts_in_64_bits_up_to`]): then no edge time passes u64, edge times grow
    /// with the start, and [`TimingOf::min_stall`] holds for these characters.
    pub fn exact_up_to(&self, latest_start: u64) -> bool {
        latest_start.checked_add(self.last).is_some_and(|c| self.lspclk.converts_in_64_bits_up_to(c))
    }

    /// A lower bound of the stall from the last edge of a character to the first edge of a character
    /// started `spacing` or more LSPCLK cycles later, both within [`TimingOf::exact_up_to`]:
    /// ⌊(spacing + first − last)·N/D⌋ ps, 0 when such characters may overlap.
    ///
    /// Why: one LSPCLK cycle is N/D ps and an edge c cycles after power-on is at ⌊c·N/D⌋ ps. For a
    /// character started on cycle s, x = (s + spacing + first)·N/D and y = (s + last)·N/D, the stall
    /// is at least ⌊x⌋ − ⌊y⌋ ≥ ⌊x − y⌋ (⌊y⌋ + ⌊x − y⌋ is a whole number at most x), and a later start
    /// only moves the first edge later.
    pub fn min_stall(&self, spacing: u64) -> Ps {
        match spacing.checked_add(self.first).and_then(|c| c.checked_sub(self.last)) {
            Some(cycles) => self.lspclk.cycles_to_ps(cycles),
            None => 0,
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
        floating_bits(lines)
    } else if (scheme.polarity && !scheme.phase) || lines.dout_as_sampled {
        dout >> drop
    } else {
        ((dout >> 1) | (dout & 0x8000)) >> drop
    };
    rx & frame.rx_mask()
}

/// Whether the master samples the slave's word unchanged ([`master_rx`] is the identity): a selected
/// 16-bit character, not looped back, in the slave's own mode (SPICLK idles high, no delay) or from
/// a slave that answers as sampled. A run of such characters needs no pass over its words.
#[inline]
pub fn master_rx_is_dout(frame: &Frame, lines: Lines) -> bool {
    let scheme = frame.shape.scheme;
    lines.selected
        && !frame.loopback
        && frame.shape.bits == 16
        && ((scheme.polarity && !scheme.phase) || lines.dout_as_sampled)
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
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The stall bound is a lower bound of every stall between characters `spacing` (or more) cycles
    /// apart, and a tight one: each stall is the bound or one more, and the bound itself occurs. Over
    /// clocks whose cycle is a whole or a fractional number of ps (N/D with D from 1 to large), shapes
    /// of both schemes, spacings shorter and longer than a character, and starts from 0 to the
    /// largest count that converts in 64 bits (where the bound stops being offered).
    #[test]
    fn the_stall_bound_is_below_every_stall_and_reached() {
        let mut rng = ChaCha8Rng::seed_from_u64(61);
        let mut clocks = vec![Clock::new(75_000_000, 2), Clock::from_hz(150_000_000 / 14), Clock::new(7, 3)];
        clocks.extend((0..20).map(|_| Clock::new(rng.gen_range(1_000_000..200_000_000), rng.gen_range(1..12))));
        let (mut reached, mut carried) = (0, 0);
        for lspclk in clocks {
            // The largest start count whose conversion is exact.
            let (mut lo, mut hi) = (0u64, u64::MAX / 2);
            while lo < hi {
                let mid = lo + (hi - lo).div_ceil(2);
                (lo, hi) = if lspclk.converts_in_64_bits_up_to(mid) { (mid, hi) } else { (lo, mid - 1) };
            }
            let exact_limit = lo;
            for (bits, divisor, polarity, phase) in [(16, 50, true, true), (16, 4, false, false), (8, 7, true, false)] {
                let shape = CharShape { bits, divisor, scheme: ClockScheme { polarity, phase } };
                let timing = TimingOf::new(&shape, &lspclk, 1_333_333);
                let span = timing.last - timing.first;
                assert!(timing.exact_up_to(exact_limit - timing.last), "{lspclk:?}");
                assert!(!timing.exact_up_to(exact_limit - timing.last + 1), "{lspclk:?}");
                for _ in 0..40 {
                    let spacing = span.saturating_sub(3) + rng.gen_range(0..3 * span + 10);
                    let bound = timing.min_stall(spacing);
                    let mut seen_bound = false;
                    let far = exact_limit - timing.last - spacing - 20;
                    let low: Vec<u64> = (0..200).map(|_| rng.gen_range(0..1u64 << 40)).collect();
                    let high: Vec<u64> = (0..20).map(|_| far - rng.gen_range(0..1u64 << 30)).chain([far]).collect();
                    for start in low.into_iter().chain(high) {
                        for later in [start + spacing, start + spacing + rng.gen_range(0..20)] {
                            let (earlier, next) = (timing.at(0, start), timing.at(1, later));
                            let stall = next.first_edge.saturating_sub(earlier.last_edge);
                            assert!(bound <= stall, "{lspclk:?} {shape:?}: {bound} > {stall} from {start} to {later}");
                            if later == start + spacing {
                                if spacing + timing.first >= timing.last {
                                    assert!(stall <= bound + 1, "{lspclk:?} {shape:?}: {stall} ≫ {bound}");
                                    carried += usize::from(stall == bound + 1);
                                }
                                seen_bound |= stall == bound;
                            }
                        }
                    }
                    reached += usize::from(seen_bound);
                }
            }
        }
        assert!(reached > 1_000 && carried > 10_000, "the bound is reached {reached}×, exceeded by 1 {carried}×");
    }

    /// Where `master_rx_is_dout` says so, the master reads every word the slave shifts out as it is:
    /// over every character length, scheme, loopback, TALK and state of the lines (a slave answering
    /// as sampled or not); and it says so for the reference setup (16 bits, mode 3, selected), where
    /// a run skips the pass over its words.
    #[test]
    fn the_master_reads_the_word_unchanged_where_said() {
        let mut rng = ChaCha8Rng::seed_from_u64(63);
        let frame_of = |shape, tx, talk, loopback| Frame {
            index: 0,
            start_cycle: 0,
            start_ps: 0,
            end_ps: 0,
            tx,
            shape,
            talk,
            loopback,
        };
        let mut said = 0;
        for bits in 1..=16u8 {
            for flags in 0..128u32 {
                let bit = |i: u32| flags >> i & 1 == 1;
                let shape = CharShape { bits, divisor: 4, scheme: ClockScheme { polarity: bit(0), phase: bit(1) } };
                let frame = frame_of(shape, rng.gen(), bit(2), bit(3));
                let lines =
                    Lines { selected: bit(4), simo_before: bit(5), floating: rng.gen(), dout_as_sampled: bit(6) };
                if !master_rx_is_dout(&frame, lines) {
                    continue;
                }
                said += 1;
                for dout in (0..=u16::MAX).step_by(7).chain([u16::MAX]) {
                    assert_eq!(master_rx(&frame, dout, lines), dout, "{frame:?} {lines:?}");
                }
            }
        }
        // Mode 3 with either slave (2 × 4 of TALK and SPISIMO's level, which do not matter), and
        // the three other schemes with a slave that answers as sampled (3 × 4).
        assert_eq!(said, 20);
        let reference = CharShape { bits: 16, divisor: 50, scheme: ClockScheme { polarity: true, phase: false } };
        let lines = Lines { selected: true, simo_before: false, floating: true, dout_as_sampled: false };
        assert!(master_rx_is_dout(&frame_of(reference, 0, true, false), lines));
    }
}
