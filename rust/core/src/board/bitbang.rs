//! SPI bit-banged on GPIO: the firmware drives SPI-A's pins as GPIO (GPBMUX2 = 0 for GPIO54–56,
//! GPIO54 SIMO and GPIO56 SCLK outputs, GPIO55 SOMI an input) and moves them itself, as a master
//! without the SPI peripheral does. The parts on SPI-A's wires (the reference design's GPIO54 =
//! SPISIMOA, GPIO55 = SPISOMIA, GPIO56 = SPICLKA; spec `reference-design.md`) see the same edges:
//! while a part's chip select is asserted, the SCLK edges the firmware makes form frames that reach
//! the part, and the part's DOUT is on GPIO55 when the firmware reads it.
//!
//! - A frame is 16 SCLK cycles (the ADIS16xxx family's word), or fewer when CS rises before its
//!   last cycle (the part then finds it of the wrong length). Its first edge starts it: the part is
//!   told then (`begin_frame`), with its first edge's time, so that the CS set-up and the stall
//!   since the previous frame are checked by the part as for SPI-A's frames.
//! - SCLK's level before the first edge is CPOL. Both standard modes with CPOL = CPHA (0 and 3)
//!   sample on the rising edge: DIN (GPIO54's level) is sampled at each rising edge, and the
//!   frame's mode is taken as 3 when SCLK idles high, 0 when it idles low (a part clocked in the
//!   other is told so, as by SPI-A).
//! - A frame's shape is known at its end: its length and its SCLK period, the shortest full cycle
//!   between two edges of one direction (a bit-banged clock is as fast as its fastest cycle). The
//!   part checks it then with its own rules ([`SpiSlave::bitbanged_shape`]); at the start it was
//!   given the period of the previous frame of the same chip-select window (none for the first:
//!   its period is not yet known, and no rule of a window's first frame needs it).
//! - DOUT on GPIO55: for a part that shifts its word out on falling edges with the MSB valid from
//!   CS↓ (the ADIS16xxx family: `answers_as_sampled` false), bit 15 until the second falling edge,
//!   then one bit further at each falling edge; for a part whose word is what the master samples
//!   (`answers_as_sampled` true), bit 15 − (rising edges so far). After a frame DOUT holds its last
//!   bit; with no part selected GPIO55 floats (read high, as every undriven pin).
//!
//! Bit-banged frames are numbered on their own (from 0, in the order they start), as their events
//! name them; they are not in SPI-A's transaction log (no SPI-A character carries them).

use crate::board::spi_parts::SpiParts;
use crate::bus::{FrameTiming, SpiSlave};
use crate::time::Ps;

/// SPISIMOA's pin on the board: the parts' DIN.
pub const SIMO: u32 = 54;
/// SPISOMIA's pin: the parts' DOUT.
pub const SOMI: u32 = 55;
/// SPICLKA's pin: SCLK.
pub const CLK: u32 = 56;
/// SCLK cycles of one bit-banged frame.
pub const FRAME_BITS: u32 = 16;

/// A frame being clocked.
#[derive(Debug, Clone, Copy)]
struct Partial {
    /// What the part was told at the first edge (its index, first edge and mode are final).
    timing: FrameTiming,
    rises: u32,
    falls: u32,
    last_rise: Option<Ps>,
    last_fall: Option<Ps>,
    last_edge: Ps,
    /// The shortest full cycle so far, and the shortest half cycle (between any two edges).
    shortest: Option<Ps>,
    shortest_half: Option<Ps>,
    din: u16,
    dout: u16,
}

impl Partial {
    fn edges(&self) -> u32 {
        self.rises + self.falls
    }

    /// The bit of `dout` on DOUT now.
    fn somi(&self, as_sampled: bool) -> bool {
        let shifted = if as_sampled { self.rises } else { self.falls.max(1) - 1 };
        let k = FRAME_BITS.saturating_sub(1 + shifted);
        self.dout >> k & 1 == 1
    }
}

/// The bit-banged master's frames, as the board sees its GPIO pins move.
#[derive(Debug, Clone, Default)]
pub struct BitBang {
    /// SCLK's level as last seen while GPIO56 is a GPIO output (None: it is not one).
    sclk: Option<bool>,
    frame: Option<Partial>,
    /// DOUT after the last frame of the chip-select window (it holds its last bit).
    held: Option<bool>,
    /// The SCLK period of the last frame of the chip-select window.
    window_period: Option<Ps>,
    /// The next frame's number.
    index: u64,
}

impl BitBang {
    /// No frame yet, SCLK not a GPIO output.
    pub fn new() -> BitBang {
        BitBang::default()
    }

    /// Bit-banged frames clocked so far.
    pub fn frames(&self) -> u64 {
        self.index
    }

    /// The pins as the firmware left them at `t`: SCLK's level when GPIO56 is a GPIO output
    /// (`None` otherwise), SIMO's level, whether a part's chip select is asserted (`parts` has it
    /// selected). An SCLK edge with a part selected clocks it.
    pub fn pins(&mut self, t: Ps, sclk: Option<bool>, simo: bool, selected: bool, parts: &mut SpiParts) {
        let before = std::mem::replace(&mut self.sclk, sclk);
        if let (Some(b), Some(a), true) = (before, sclk, selected) {
            if a != b {
                self.edge(t, a, simo, parts);
            }
        }
    }

    fn edge(&mut self, t: Ps, rising: bool, simo: bool, parts: &mut SpiParts) {
        let mut f = match self.frame {
            Some(f) => f,
            None => {
                // SCLK idled at the level before the first edge: high (a falling first edge) is
                // CPOL = 1, mode 3; low is mode 0.
                let timing = FrameTiming {
                    index: self.index,
                    first_edge: t,
                    last_edge: t,
                    sclk_period: self.window_period.unwrap_or(Ps::MAX),
                    bits: FRAME_BITS as u8,
                    mode: if rising { 0 } else { 3 },
                };
                let dout = parts.begin_frame(&timing);
                Partial {
                    timing,
                    rises: 0,
                    falls: 0,
                    last_rise: None,
                    last_fall: None,
                    last_edge: t,
                    shortest: None,
                    shortest_half: None,
                    din: 0,
                    dout,
                }
            }
        };
        if f.edges() > 0 {
            let half = t - f.last_edge;
            f.shortest_half = Some(f.shortest_half.map_or(half, |h| h.min(half)));
        }
        let last = if rising { &mut f.last_rise } else { &mut f.last_fall };
        if let Some(prev) = last.replace(t) {
            let cycle = t - prev;
            f.shortest = Some(f.shortest.map_or(cycle, |c| c.min(cycle)));
        }
        if rising {
            f.rises += 1;
            f.din = f.din << 1 | u16::from(simo);
        } else {
            f.falls += 1;
        }
        f.last_edge = t;
        self.frame = Some(f);
        if f.edges() == 2 * FRAME_BITS {
            self.finish(parts);
        }
    }

    /// The frame being clocked ends (its last cycle, or CS rising): the part checks its shape and
    /// takes its DIN.
    fn finish(&mut self, parts: &mut SpiParts) {
        let Some(f) = self.frame.take() else { return };
        let period = f.shortest.or(f.shortest_half.map(|h| 2 * h)).unwrap_or(Ps::MAX);
        let timing =
            FrameTiming { last_edge: f.last_edge, sclk_period: period, bits: f.edges().div_ceil(2) as u8, ..f.timing };
        parts.bitbanged_shape(&timing);
        parts.end_frame(f.din, &timing);
        self.held = Some(f.somi(parts.answers_as_sampled()));
        self.window_period = Some(period);
        self.index += 1;
    }

    /// The selected part's chip select is about to rise (or another part to be selected): a frame
    /// still being clocked ends first, shorter than 16 cycles.
    pub fn before_cs_change(&mut self, parts: &mut SpiParts) {
        self.finish(parts);
        self.held = None;
        self.window_period = None;
    }

    /// The level the selected part drives on GPIO55 (SOMI) now, if it drives one: during a frame
    /// and after it, until CS changes.
    pub fn somi(&self, as_sampled: bool) -> Option<bool> {
        match &self.frame {
            Some(f) => Some(f.somi(as_sampled)),
            None => self.held,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::{Profile, SENSOR_CHIP_SELECT};

    const HALF: Ps = 1_000_000; // 1 µs per half cycle: SCLK 500 kHz

    /// The reference board's parts (the ADIS16407 on GPIO57), its chip select low, SCLK idling
    /// high (mode 3) as the firmware leaves it, at 1 ms.
    fn selected() -> (BitBang, SpiParts, Ps) {
        let mut parts = SpiParts::from_profile(&Profile::default()).unwrap();
        assert!(parts.select(SENSOR_CHIP_SELECT));
        let mut bb = BitBang::new();
        let t = 1_000_000_000;
        bb.pins(t, Some(true), false, false, &mut parts);
        parts.set_cs(true, t);
        (bb, parts, t + 10_000_000)
    }

    /// `cycles` SCLK cycles (mode 3: fall, then rise) with DIN the top `cycles` bits of `word`,
    /// each half cycle `half` long; the bits read on GPIO55 just before each rising edge, as the
    /// master samples them, and the time after the last edge.
    fn clock(bb: &mut BitBang, parts: &mut SpiParts, mut t: Ps, word: u16, cycles: u32, half: Ps) -> (u16, Ps) {
        let mut rx = 0u16;
        for i in 0..cycles {
            let bit = word >> (15 - i) & 1 == 1;
            bb.pins(t, Some(false), bit, true, parts);
            t += half;
            rx = rx << 1 | u16::from(bb.somi(parts.answers_as_sampled()).unwrap());
            bb.pins(t, Some(true), bit, true, parts);
            t += half;
        }
        (rx, t)
    }

    /// Frames formed from the edges: 16 cycles make a frame whose DIN is GPIO54's level at each
    /// rising edge (a PROD_ID read command, 0x5600), the part's answer to it is on GPIO55 in the
    /// next frame MSB first (PROD_ID); SCLK level changes with CS high clock nothing; CS rising
    /// after 8 cycles ends a frame of 8, which the part finds of the wrong length at its end.
    #[test]
    fn frames_are_formed_from_the_edges() {
        let (mut bb, mut parts, t) = selected();
        let (_, t) = clock(&mut bb, &mut parts, t, 0x5600, 16, HALF);
        assert_eq!(bb.frames(), 1);
        let (rx, t) = clock(&mut bb, &mut parts, t + 100_000_000, 0x0000, 16, HALF);
        let sensor = parts.sensor().unwrap();
        let prod_id = sensor.peek_name("prod_id").unwrap();
        assert_eq!(rx, prod_id, "DOUT on GPIO55, MSB first");
        let rec = sensor.last_frame().unwrap();
        assert_eq!((rec.din, rec.dout, rec.register), (0x0000, prod_id, Some(0x56)));
        assert_eq!((bb.frames(), sensor.frames_clocked()), (2, 2));
        assert!(parts.drain_events().is_empty());
        // Eight cycles, then CS rises: a frame of 8 cycles.
        let (_, t) = clock(&mut bb, &mut parts, t + 100_000_000, 0x5600, 8, HALF);
        bb.before_cs_change(&mut parts);
        parts.set_cs(false, t + 10_000_000);
        let events = parts.drain_events();
        assert_eq!(events.iter().map(|e| e.kind).collect::<Vec<_>>(), ["frame_length"], "{events:?}");
        assert_eq!((events[0].measured, events[0].frame), (Some(8.0), Some(2)));
        assert_eq!(bb.frames(), 3);
        // With CS high the part is not selected: SCLK moving clocks no frame.
        let mut u = t + 20_000_000;
        for level in [false, true, false, true] {
            bb.pins(u, Some(level), true, false, &mut parts);
            u += HALF;
        }
        assert_eq!((bb.frames(), parts.sensor().unwrap().frames_clocked()), (3, 3));
    }
}
