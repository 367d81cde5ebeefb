//! What the emulator needs from the sensor at the other end of SPI-A: the slave side of the bus, the
//! latest frame it answered (for the read records), its events, and how far its input reaches (the
//! emulator's horizon). Two sensors: the ADIS16407 model fed a physical input ([`StreamedDevice`],
//! the default), and the replay of recorded burst words ([`ReplaySlave`]), which bypasses the device.

use crate::board::input::{InputFeed, StreamStimulus};
use crate::bus::{FrameTiming, RunTiming, SpiSlave};
use crate::device::replay::ReplaySlave;
use crate::device::{Adis16407, ReadRecord, SampleStamp};
use crate::events::Event;
use crate::time::Ps;

/// The latest frame a sensor answered, as the read records need it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FrameSummary {
    /// First SCLK edge.
    pub t_start: Ps,
    /// Last SCLK edge.
    pub t_end: Ps,
    /// The sample the frame's word holds: the device's internal sample, or for a replay the
    /// recorded burst (its index and recorded timestamp).
    pub sample: Option<SampleStamp>,
}

/// How far a sensor's input reaches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Reach {
    /// Physical input: the last time it covers (s; `None` before the first chunk).
    Time {
        /// Last input time, s.
        last_s: Option<f64>,
        /// No more input will come.
        ended: bool,
    },
    /// Recorded bursts not read yet.
    Bursts {
        /// Bursts queued.
        queued: usize,
        /// No more bursts will come.
        ended: bool,
    },
}

/// The emulator's sensor: an SPI slave (its events: [`SpiSlave::drain_events`]) with a frame summary
/// and an input horizon.
pub trait Sensor: SpiSlave + Send {
    /// The latest frame clocked at the sensor.
    fn last_frame(&self) -> Option<FrameSummary>;
    /// The second frame clocked since CS last fell (a burst's first data frame), once it has ended:
    /// what [`Sensor::last_frame`] gave right after it, still there after the rest of the burst.
    fn second_frame(&self) -> Option<FrameSummary>;
    /// How far the input reaches.
    fn reach(&self) -> Reach;
}

/// The ADIS16407 model reading a physical input streamed in chunks.
pub struct StreamedDevice {
    device: Adis16407,
    feed: InputFeed,
}

impl StreamedDevice {
    /// The device, its stimulus replaced by a new (empty) input stream.
    pub fn new(mut device: Adis16407) -> StreamedDevice {
        let (feed, stimulus): (InputFeed, StreamStimulus) = InputFeed::new();
        device.set_stimulus(Box::new(stimulus));
        StreamedDevice { device, feed }
    }

    /// The input stream.
    pub fn feed(&self) -> &InputFeed {
        &self.feed
    }

    /// The device model.
    pub fn device(&self) -> &Adis16407 {
        &self.device
    }
}

impl SpiSlave for StreamedDevice {
    #[inline]
    fn set_cs(&mut self, low: bool, t: Ps) {
        self.device.set_cs(low, t);
    }
    #[inline]
    fn begin_frame(&mut self, timing: &FrameTiming) -> u16 {
        self.device.begin_frame(timing)
    }
    #[inline]
    fn end_frame(&mut self, din: u16, timing: &FrameTiming) {
        self.device.end_frame(din, timing);
    }
    #[inline]
    fn run_frames(&mut self, run: &RunTiming, din: u16, dout: &mut [u16]) {
        self.device.run_frames(run, din, dout);
    }
    fn drain_events(&mut self) -> Vec<Event> {
        self.device.drain_events()
    }
}

/// What the read records need of one of the device's frames.
fn device_frame(f: ReadRecord) -> FrameSummary {
    FrameSummary {
        t_start: f.t_start,
        t_end: f.t_end,
        sample: f
            .sample_index
            .map(|index| SampleStamp { index, t: f.t_start.saturating_sub(f.sample_age_ps.unwrap_or(0)) }),
    }
}

impl Sensor for StreamedDevice {
    #[inline]
    fn last_frame(&self) -> Option<FrameSummary> {
        self.device.last_frame().map(device_frame)
    }
    #[inline]
    fn second_frame(&self) -> Option<FrameSummary> {
        self.device.second_frame_in_window().map(device_frame)
    }
    fn reach(&self) -> Reach {
        Reach::Time { last_s: self.feed.last_time_s(), ended: self.feed.ended() }
    }
}

impl ReplaySlave {
    /// What the read records need of one of the replay's frames of the current window (the sample is
    /// the window's recorded burst).
    fn window_frame(&self, f: ReadRecord) -> FrameSummary {
        FrameSummary { t_start: f.t_start, t_end: f.t_end, sample: self.last_sample() }
    }
}

impl Sensor for ReplaySlave {
    #[inline]
    fn last_frame(&self) -> Option<FrameSummary> {
        ReplaySlave::last_frame(self).map(|f| self.window_frame(f))
    }
    #[inline]
    fn second_frame(&self) -> Option<FrameSummary> {
        self.second_frame_in_window().map(|f| self.window_frame(f))
    }
    fn reach(&self) -> Reach {
        Reach::Bursts { queued: self.queued(), ended: self.ended() }
    }
}
