//! Bit level: walk every SCLK edge of a frame and let each side drive and sample its line.
//!
//! The waveform is built by toggling SCLK phase by phase from the master's registers (not from the
//! closed forms of the transaction level), and the data are moved edge by edge:
//! - master (TI schemes), with its shifter output on SPISIMO only when TALK = 1 (loopback feeds the
//!   receiver from the shifter output inside the chip): without delay it drives a bit on each leading edge (idle → active) and
//!   samples on each trailing edge; with delay it puts bit 0 out at the start, samples on each
//!   leading edge and drives the next bit on each trailing edge;
//! - slave (ADIS16407, SPI mode 3): MSB valid on DOUT from CS↓; its n-th falling edge drives bit n;
//!   every rising edge samples DIN. A slave that answers as sampled (`Lines::dout_as_sampled`, the
//!   ADS8344, whose word already follows the frame's mode) drives instead on the edges the master
//!   does not sample on: bit 0 valid from CS↓, bit n + 1 after the master's n-th sample;
//! - at one edge, every sample happens before every drive (outputs change after the hold time).

use super::transaction::TimingOf;
use super::{Exchange, FrameTiming, Lines};
use crate::dsp::spi::{CharShape, Frame};
use crate::time::{Clock, Ps};

/// SCLK edges of one frame, as LSPCLK cycle offsets from the frame start, for one character shape
/// and LSPCLK.
#[derive(Debug, Clone, Copy)]
pub struct Waveform {
    offsets: [u32; 32],
    count: usize,
    shape: CharShape,
    lspclk: Clock,
    /// The full SCLK period (an active and an idle phase), in ps: the same for every character.
    sclk_period: Ps,
}

impl Waveform {
    /// Toggle SCLK through a character of `frame`'s shape: with delay an idle-level phase comes first;
    /// then each bit is an active phase (⌊d/2⌋ cycles) followed by an idle-level phase (⌈d/2⌉
    /// cycles). `lspclk`: the clock the characters are timed by.
    pub fn of(frame: &Frame, lspclk: &Clock) -> Waveform {
        let d = frame.shape.divisor;
        let active = d / 2;
        let idle = d - active;
        let mut offsets = [0u32; 32];
        let mut t = if frame.shape.scheme.phase { idle } else { 0 };
        let mut count = 0;
        for _ in 0..frame.shape.bits {
            offsets[count] = t;
            t += active;
            offsets[count + 1] = t;
            t += idle;
            count += 2;
        }
        let sclk_period = lspclk.cycles_to_ps(u64::from(active + idle));
        Waveform { offsets, count, shape: frame.shape, lspclk: *lspclk, sclk_period }
    }

    /// The character shape the waveform was built for.
    pub fn shape(&self) -> CharShape {
        self.shape
    }

    /// Edge offsets from the frame start, LSPCLK cycles.
    pub fn offsets(&self) -> &[u32] {
        &self.offsets[..self.count]
    }

    /// The timing, as the slave sees it, of character `index` of this waveform started on LSPCLK
    /// cycle `start_cycle`.
    pub fn timing(&self, index: u64, start_cycle: u64) -> FrameTiming {
        self.timing_of().at(index, start_cycle)
    }

    /// The timing of characters of this waveform for any start cycle (its first and last edges).
    pub fn timing_of(&self) -> TimingOf {
        let edges = (self.offsets[0] as u64, self.offsets[self.count - 1] as u64);
        TimingOf::with_edges(edges, &self.lspclk, self.sclk_period, self.shape.bits, self.shape.scheme.standard_mode())
    }
}

/// Simulate the frame edge by edge: what master and slave sample, given the word the slave shifts
/// out (`dout`, MSB first) and the lines around the frame.
pub fn exchange(frame: &Frame, dout: u16, lines: Lines) -> Exchange {
    // One walk, compiled once per clock scheme so the per-edge roles are constants, and once more
    // for the usual frame (slave selected, TALK on, no loopback) so its line choices are too.
    let usual = lines.selected && frame.talk && !frame.loopback;
    match (frame.shape.scheme.polarity, frame.shape.scheme.phase, usual) {
        (false, false, false) => walk::<false, false, false>(frame, dout, lines),
        (false, true, false) => walk::<false, true, false>(frame, dout, lines),
        (true, false, false) => walk::<true, false, false>(frame, dout, lines),
        (true, true, false) => walk::<true, true, false>(frame, dout, lines),
        (false, false, true) => walk::<false, false, true>(frame, dout, lines),
        (false, true, true) => walk::<false, true, true>(frame, dout, lines),
        (true, false, true) => walk::<true, false, true>(frame, dout, lines),
        (true, true, true) => walk::<true, true, true>(frame, dout, lines),
    }
}

/// What frames of one word, shape and lines exchange (a run of characters), as a function of the
/// slave's word: the edge walk of [`exchange`] made once per DOUT bit instead of once per frame.
///
/// Why that is exact: what the slave samples on DIN and where SPISIMO is left come from the
/// master's side alone (the word, TALK, the lines), so the walk for DOUT = 0 tells them. In the walk
/// the master samples SPISOMI, or with loopback its own shifter output; SPISOMI shows one bit of
/// DOUT or the floating level, the shifter output one bit of SPIDAT or the SPISIMO level before the
/// frame. So each received bit is either one bit of DOUT or a level that does not depend on DOUT:
/// the received word is the walk's word for DOUT = 0 with, for each set bit `j` of DOUT, the bits
/// that bit alone sets (the walk for DOUT = `1 << j`, less the walk for 0). Two tables, over the low
/// and the high byte of DOUT, hold those unions.
#[derive(Debug, Clone)]
pub struct ExchangeMap {
    /// The walk for DOUT = 0.
    fixed: Exchange,
    low: [u16; 256],
    high: [u16; 256],
}

impl ExchangeMap {
    /// Walk `frame` (its word, shape, TALK and loopback) with the `lines` once per DOUT bit.
    pub fn of(frame: &Frame, lines: Lines) -> ExchangeMap {
        let fixed = exchange(frame, 0, lines);
        let by_bit: [u16; 16] = std::array::from_fn(|j| exchange(frame, 1 << j, lines).master_rx ^ fixed.master_rx);
        let (mut low, mut high) = ([0u16; 256], [0u16; 256]);
        for byte in 1..256usize {
            // The byte's lowest set bit, added to the byte without it (already in the table).
            let (j, rest) = (byte.trailing_zeros() as usize, byte & (byte - 1));
            low[byte] = low[rest] | by_bit[j];
            high[byte] = high[rest] | by_bit[j + 8];
        }
        ExchangeMap { fixed, low, high }
    }

    /// `exchange(frame, dout, lines)` for the frame and lines the map was made for.
    #[inline]
    pub fn exchange(&self, dout: u16) -> Exchange {
        let master_rx = self.fixed.master_rx | self.low[usize::from(dout & 0xFF)] | self.high[usize::from(dout >> 8)];
        Exchange { master_rx, ..self.fixed }
    }
}

/// The edge walk of [`exchange`] for SPICLK idling high (`POLARITY`) and clocking with delay (`DELAY`);
/// `USUAL`: the slave is selected, TALK is on and loopback off (the same walk, those three known).
///
/// The waveform alternates leading (idle → active) and trailing edges, starting with a leading one;
/// the walk takes them in pairs, one bit per pair.
fn walk<const POLARITY: bool, const DELAY: bool, const USUAL: bool>(
    frame: &Frame,
    dout: u16,
    lines: Lines,
) -> Exchange {
    let bits = frame.shape.bits as u32;
    let (talk, loopback, selected) =
        if USUAL { (true, false, true) } else { (frame.talk, frame.loopback, lines.selected) };
    let (floating, as_sampled) = (lines.floating, lines.dout_as_sampled);
    let tx = frame.tx;
    // The shifter's output bit; SPISIMO shows it only with TALK (loopback takes it internally).
    let mut out = if DELAY { tx & 0x8000 != 0 } else { lines.simo_before };
    let pin = |out: bool| if talk { out } else { floating };
    let mut somi = if selected { dout & 0x8000 != 0 } else { floating };
    let (mut rx, mut din) = (0u16, 0u16);
    let mut falls = 0u32;
    let mut edge = |leading: bool, bit: u32| {
        // SCLK leaves its idle level on a leading edge: it rises there when it idles low.
        let rising = leading != POLARITY;
        // Samples first.
        let master_samples = leading == DELAY;
        if master_samples {
            let line = if loopback { out } else { somi };
            rx = (rx << 1) | u16::from(line);
        }
        if selected && rising {
            din = (din << 1) | u16::from(pin(out));
        }
        // Then drives: without delay each leading edge puts out its bit, with delay each trailing
        // edge puts out the next one; after the last bit the output holds it (the `min`: bit
        // `bits − 1` is what it already shows), which keeps the edge free of branches.
        if !master_samples {
            let next = (if DELAY { bit + 1 } else { bit }).min(bits - 1);
            out = (tx << next) & 0x8000 != 0;
            // A slave answering as sampled moves on with the master: the bit of the next sample.
            if selected && as_sampled {
                somi = (dout << next) & 0x8000 != 0;
            }
        }
        // The slave's n-th falling edge drives bit n: at most `bits` ≤ 16 falling edges, so n < 16.
        if selected && !rising && !as_sampled {
            somi = (dout << falls) & 0x8000 != 0;
            falls += 1;
        }
    };
    // Two edges per bit, as `Waveform::of` toggles SCLK; the frame's bit count bounds the walk (and
    // the shifts above).
    for bit in 0..bits {
        edge(true, bit);
        edge(false, bit);
    }
    let mask = frame.rx_mask();
    Exchange { master_rx: rx & mask, slave_din: din & mask, simo_after: pin(out) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dsp::spi::ClockScheme;
    use rand::{Rng, SeedableRng};

    /// The map gives what the walk gives, for every scheme, character length, TALK, loopback and
    /// lines (either kind of slave), for random words and every single-bit and all-ones word.
    #[test]
    fn exchange_map_equals_the_walk() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        for code in 0..(1 << 8) {
            let flag = |b: u32| code >> b & 1 == 1;
            let scheme = ClockScheme { polarity: flag(0), phase: flag(1) };
            let lines = Lines { selected: flag(4), simo_before: flag(5), floating: flag(6), dout_as_sampled: flag(7) };
            for bits in 1..=16u8 {
                let frame = Frame {
                    index: 0,
                    start_cycle: 0,
                    start_ps: 0,
                    end_ps: 0,
                    tx: rng.gen(),
                    shape: CharShape { bits, divisor: 4, scheme },
                    talk: flag(2),
                    loopback: flag(3),
                };
                let map = ExchangeMap::of(&frame, lines);
                let singles = (0..16).map(|j| 1u16 << j);
                let random: Vec<u16> = (0..64).map(|_| rng.gen()).collect();
                for dout in singles.chain([0, 0xFFFF]).chain(random) {
                    let walked = exchange(&frame, dout, lines);
                    assert_eq!(map.exchange(dout), walked, "{frame:?} {lines:?} DOUT {dout:#06x}");
                }
            }
        }
    }
}
