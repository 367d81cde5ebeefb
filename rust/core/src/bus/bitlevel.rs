//! Bit level: walk every SCLK edge of a frame and let each side drive and sample its line.
//!
//! The waveform is built by toggling SCLK phase by phase from the master's registers (not from the
//! closed forms of the transaction level), and the data are moved edge by edge:
//! - master (TI schemes), with its shifter output on SPISIMO only when TALK = 1 (loopback feeds the
//!   receiver from the shifter output inside the chip): without delay it drives a bit on each leading edge (idle → active) and
//!   samples on each trailing edge; with delay it puts bit 0 out at the start, samples on each
//!   leading edge and drives the next bit on each trailing edge;
//! - slave (ADIS16407, SPI mode 3): MSB valid on DOUT from CS↓; its n-th falling edge drives bit n;
//!   every rising edge samples DIN;
//! - at one edge, every sample happens before every drive (outputs change after the hold time).

use super::{Exchange, FrameTiming, Lines};
use crate::dsp::spi::{CharShape, Frame};
use crate::time::Clock;

/// SCLK edges of one frame, as LSPCLK cycle offsets from the frame start.
#[derive(Debug, Clone, Copy, Default)]
pub struct Waveform {
    offsets: [u32; 32],
    count: usize,
    shortest_phase: u32,
}

impl Waveform {
    /// Toggle SCLK through the frame: with delay an idle-level phase comes first; then each bit is
    /// an active phase (⌊d/2⌋ cycles) followed by an idle-level phase (⌈d/2⌉ cycles).
    pub fn of(frame: &Frame) -> Waveform {
        let d = frame.shape.divisor;
        let active = d / 2;
        let idle = d - active;
        let mut offsets = [0u32; 32];
        let mut t = if frame.shape.scheme.phase { idle } else { 0 };
        let mut count = 0;
        let mut shortest_phase = u32::MAX;
        for _ in 0..frame.shape.bits {
            offsets[count] = t;
            t += active;
            offsets[count + 1] = t;
            t += idle;
            count += 2;
        }
        for pair in offsets[..count].windows(2) {
            shortest_phase = shortest_phase.min(pair[1] - pair[0]);
        }
        Waveform { offsets, count, shortest_phase }
    }

    /// Edge offsets from the frame start, LSPCLK cycles.
    pub fn offsets(&self) -> &[u32] {
        &self.offsets[..self.count]
    }

    /// The timing, as the slave sees it, of a character of this waveform's `shape` started on LSPCLK
    /// cycle `start_cycle` (`lspclk`: the clock the character is timed by).
    pub fn timing(&self, shape: &CharShape, start_cycle: u64, lspclk: &Clock) -> FrameTiming {
        let at = |off: u32| lspclk.cycles_to_ps(start_cycle + off as u64);
        FrameTiming {
            first_edge: at(self.offsets[0]),
            last_edge: at(self.offsets[self.count - 1]),
            sclk_period: lspclk.cycles_to_ps(2 * self.shortest_phase as u64),
            bits: shape.bits,
            cpol: shape.scheme.polarity,
        }
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
    let floating = lines.floating;
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
            let next = if DELAY { bit + 1 } else { bit };
            out = (tx << next.min(bits - 1)) & 0x8000 != 0;
        }
        // The slave's n-th falling edge drives bit n: at most `bits` ≤ 16 falling edges, so n < 16.
        if selected && !rising {
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
