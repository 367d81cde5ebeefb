//! The physical input stream: recorded or synthetic samples fed in chunks, resampled onto the
//! device's own sample instants by linear interpolation.
//!
//! Why linear: it is exact for the constant and piecewise-linear segments of synthetic traces, it
//! never overshoots (no invented rate peaks for the saturation logic to see), and its error on a
//! sinusoid of frequency f sampled at fs is bounded by (π f / fs)² / 2 of the amplitude, which the
//! coning report states. Trace time 0 is the device's power-on instant plus `offset_s`.

use std::collections::VecDeque;
use std::sync::{Arc, Mutex};

use crate::device::{Physical, Stimulus};
use crate::error::{Error, Result};
use crate::time::{ps_to_s, Ps};

/// The samples not yet consumed, shared between the emulator (which feeds them) and the device
/// (which reads them). A mutex because the device's stimulus must be `Send`; it is never contended.
/// The chunks are kept as they were fed (moved in, never copied or regrown): the current row is
/// `pos` of the first chunk.
#[derive(Debug, Default)]
struct Window {
    chunks: VecDeque<Chunk>,
    pos: usize,
    /// Total rows fed so far (to name rows in errors).
    rows_fed: u64,
    /// Reads that fell outside the fed data (held at the nearest end).
    held: u64,
    /// No more chunks will come.
    ended: bool,
}

/// One fed chunk (never empty).
#[derive(Debug)]
struct Chunk {
    t: Vec<f64>,
    p: Vec<Physical>,
}

impl Window {
    /// The row after the current one. (Inline: the stimulus asks for it two or three times per device
    /// sample, and out of line each call re-derives the first chunk.)
    #[inline]
    fn next_row(&self) -> Option<(f64, &Physical)> {
        let first = self.chunks.front()?;
        if self.pos + 1 < first.t.len() {
            return Some((first.t[self.pos + 1], &first.p[self.pos + 1]));
        }
        self.chunks.get(1).map(|c| (c.t[0], &c.p[0]))
    }

    /// Make the next row the current one.
    fn step(&mut self) {
        self.pos += 1;
        if self.chunks.front().is_some_and(|c| self.pos == c.t.len()) {
            self.chunks.pop_front();
            self.pos = 0;
        }
    }

    fn first_time(&self) -> Option<f64> {
        self.chunks.front().map(|c| c.t[self.pos])
    }

    fn last_time(&self) -> Option<f64> {
        self.chunks.back().and_then(|c| c.t.last().copied())
    }
}

/// Handle the emulator keeps to feed chunks and ask how far the input reaches.
#[derive(Debug, Clone, Default)]
pub struct InputFeed {
    window: Arc<Mutex<Window>>,
}

/// The device-side view of the same window.
#[derive(Debug)]
pub struct StreamStimulus {
    window: Arc<Mutex<Window>>,
}

impl InputFeed {
    /// A new, empty input and the stimulus that reads it.
    pub fn new() -> (InputFeed, StreamStimulus) {
        let window = Arc::new(Mutex::new(Window::default()));
        (InputFeed { window: window.clone() }, StreamStimulus { window })
    }

    /// Append a chunk: times in seconds (strictly increasing, continuing the previous chunk) and
    /// the physical values at those times. Rows are checked; errors name the row (counted from the
    /// first row ever fed) and the column.
    pub fn push(&self, t_s: &[f64], samples: Vec<Physical>) -> Result<()> {
        if t_s.len() != samples.len() {
            return Err(Error::Input(format!("input chunk: {} times but {} samples", t_s.len(), samples.len())));
        }
        let mut w = self.lock();
        if w.ended {
            return Err(Error::Input("input: a chunk was fed after the end of the input".into()));
        }
        let mut last = w.last_time();
        for (i, (&t, p)) in t_s.iter().zip(&samples).enumerate() {
            let row = w.rows_fed + i as u64;
            if !t.is_finite() {
                return Err(Error::Input(format!("input row {row}: column `t_s` is {t}, expected a finite time")));
            }
            if let Some(prev) = last {
                if t <= prev {
                    return Err(Error::Input(format!(
                        "input row {row}: column `t_s` = {t} s is not after the previous row ({prev} s): \
                         times must be strictly increasing"
                    )));
                }
            }
            if !p.is_finite() {
                return Err(Error::Input(format!("input row {row}: a sensor column is NaN or infinite")));
            }
            last = Some(t);
        }
        w.rows_fed += t_s.len() as u64;
        if !t_s.is_empty() {
            w.chunks.push_back(Chunk { t: t_s.to_vec(), p: samples });
        }
        Ok(())
    }

    /// No more chunks will come.
    pub fn end(&self) {
        self.lock().ended = true;
    }

    /// Whether the input has ended.
    pub fn ended(&self) -> bool {
        self.lock().ended
    }

    /// The last time the input covers, seconds (None before the first chunk).
    pub fn last_time_s(&self) -> Option<f64> {
        self.lock().last_time()
    }

    /// The first time the input covers, seconds.
    pub fn first_time_s(&self) -> Option<f64> {
        self.lock().first_time()
    }

    /// Reads that fell outside the fed data.
    pub fn held_reads(&self) -> u64 {
        self.lock().held
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Window> {
        // A poisoned lock means a panic elsewhere already failed the run; the data is still valid.
        self.window.lock().unwrap_or_else(|e| e.into_inner())
    }
}

impl Stimulus for StreamStimulus {
    fn at(&mut self, _k: u64, t: Ps) -> Physical {
        let mut w = self.window.lock().unwrap_or_else(|e| e.into_inner());
        let ts = ps_to_s(t);
        // Drop rows the device will never need again (its sample times only increase), keeping one
        // row before `ts` to interpolate from.
        while w.next_row().is_some_and(|(t1, _)| t1 <= ts) {
            w.step();
        }
        let Some(first) = w.chunks.front() else {
            w.held += 1;
            return Physical::powered_idle();
        };
        let (t0, p0) = (first.t[w.pos], first.p[w.pos]);
        if ts <= t0 {
            if ts < t0 {
                w.held += 1;
            }
            return p0;
        }
        match w.next_row() {
            None => {
                w.held += 1;
                p0
            }
            Some((t1, p1)) => lerp(&p0, p1, (ts - t0) / (t1 - t0)),
        }
    }
}

fn lerp(a: &Physical, b: &Physical, x: f64) -> Physical {
    let l = |u: f64, v: f64| u + (v - u) * x;
    let l3 = |u: [f64; 3], v: [f64; 3]| [l(u[0], v[0]), l(u[1], v[1]), l(u[2], v[2])];
    Physical {
        gyro_dps: l3(a.gyro_dps, b.gyro_dps),
        accel_g: l3(a.accel_g, b.accel_g),
        mag_gauss: l3(a.mag_gauss, b.mag_gauss),
        baro_mbar: l(a.baro_mbar, b.baro_mbar),
        temp_c: l(a.temp_c, b.temp_c),
        supply_v: l(a.supply_v, b.supply_v),
        aux_v: l(a.aux_v, b.aux_v),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::time::s_to_ps;

    fn rate(x: f64) -> Physical {
        Physical { gyro_dps: [x, 0.0, 0.0], ..Physical::powered_idle() }
    }

    #[test]
    fn interpolates_between_rows_and_across_chunks() {
        let (feed, mut stim) = InputFeed::new();
        feed.push(&[0.0, 1.0], vec![rate(0.0), rate(10.0)]).unwrap();
        feed.push(&[2.0], vec![rate(30.0)]).unwrap();
        assert_eq!(stim.at(0, s_to_ps(0.5)).gyro_dps[0], 5.0);
        assert_eq!(stim.at(1, s_to_ps(1.5)).gyro_dps[0], 20.0);
        assert_eq!(feed.held_reads(), 0);
        // Past the end: held and counted.
        assert_eq!(stim.at(2, s_to_ps(3.0)).gyro_dps[0], 30.0);
        assert_eq!(feed.held_reads(), 1);
    }

    #[test]
    fn rejects_non_increasing_time_with_row() {
        let (feed, _) = InputFeed::new();
        feed.push(&[0.0, 1.0], vec![rate(0.0), rate(1.0)]).unwrap();
        let e = feed.push(&[2.0, 2.0], vec![rate(0.0), rate(1.0)]).unwrap_err().to_string();
        assert!(e.contains("row 3") && e.contains("strictly increasing"), "{e}");
    }

    #[test]
    fn rejects_nan() {
        let (feed, _) = InputFeed::new();
        let e = feed.push(&[0.0], vec![rate(f64::NAN)]).unwrap_err().to_string();
        assert!(e.contains("row 0") && e.contains("NaN"), "{e}");
    }
}
