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
use crate::dsp::spi::Frame;

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

    /// The frame's timing as the slave sees it.
    pub fn timing(&self, frame: &Frame) -> FrameTiming {
        let at = |off: u32| frame.lspclk.cycles_to_ps(frame.start_cycle + off as u64);
        FrameTiming {
            first_edge: at(self.offsets[0]),
            last_edge: at(self.offsets[self.count - 1]),
            sclk_period: frame.lspclk.cycles_to_ps(2 * self.shortest_phase as u64),
            bits: frame.shape.bits,
            cpol: frame.shape.scheme.polarity,
        }
    }
}

/// Simulate the frame edge by edge: what master and slave sample, given the word the slave shifts
/// out (`dout`, MSB first) and the lines around the frame.
pub fn exchange(frame: &Frame, waveform: &Waveform, dout: u16, lines: Lines) -> Exchange {
    let polarity = frame.shape.scheme.polarity;
    let delay = frame.shape.scheme.phase;
    let bits = frame.shape.bits as u32;
    let tx_bit = |k: u32| frame.tx_bit(k);
    let mut sclk = polarity;
    // The shifter's output bit; SPISIMO shows it only with TALK (loopback takes it internally).
    let mut out = if delay { tx_bit(0) } else { lines.simo_before };
    let pin = |out: bool| if frame.talk { out } else { lines.floating };
    let mut somi = if lines.selected { dout & 0x8000 != 0 } else { lines.floating };
    let (mut rx, mut din) = (0u16, 0u16);
    let mut falls = 0u32;
    for e in 0..waveform.count as u32 {
        sclk = !sclk;
        let leading = sclk != polarity;
        let rising = sclk;
        // Samples first.
        let master_samples = leading == delay;
        if master_samples {
            let line = if frame.loopback { out } else { somi };
            rx = (rx << 1) | u16::from(line);
        }
        if lines.selected && rising {
            din = (din << 1) | u16::from(pin(out));
        }
        // Then drives.
        if !master_samples {
            let next = if delay { e / 2 + 1 } else { e / 2 };
            if next < bits {
                out = tx_bit(next);
            }
        }
        if lines.selected && !rising {
            if falls < 16 {
                somi = (dout >> (15 - falls)) & 1 == 1;
            }
            falls += 1;
        }
    }
    let mask = frame.rx_mask();
    Exchange { master_rx: rx & mask, slave_din: din & mask, simo_after: pin(out) }
}
