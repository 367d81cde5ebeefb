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

/// The chunks not yet consumed, shared between the emulator (which feeds them) and the device
/// (which reads them). A mutex because the device's stimulus must be `Send`; it is never contended,
/// and the device takes it only when it moves past the last row of a chunk (see [`StreamStimulus`]).
/// The chunks are kept as they were fed (moved in, never copied or regrown); the first one holds
/// the device's current row.
#[derive(Debug, Default)]
struct Window {
    chunks: VecDeque<Arc<Chunk>>,
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
    fn first_time(&self) -> Option<f64> {
        self.chunks.front().map(|c| c.t[0])
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

/// The device-side view of the same window. It reads through a cursor on the chunk holding its
/// current row (shared with the window, whose first chunk it is), so a sample locks the window only
/// when it moves past that chunk's last row (once per chunk) or falls outside the fed data.
#[derive(Debug)]
pub struct StreamStimulus {
    window: Arc<Mutex<Window>>,
    /// The current row (the last one at or before the latest sample time): `None` until the first
    /// chunk is read.
    cursor: Option<Cursor>,
}

/// A row of a chunk.
#[derive(Debug)]
struct Cursor {
    chunk: Arc<Chunk>,
    pos: usize,
}

impl InputFeed {
    /// A new, empty input and the stimulus that reads it.
    pub fn new() -> (InputFeed, StreamStimulus) {
        let window = Arc::new(Mutex::new(Window::default()));
        (InputFeed { window: window.clone() }, StreamStimulus { window, cursor: None })
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
            w.chunks.push_back(Arc::new(Chunk { t: t_s.to_vec(), p: samples }));
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

    /// The first time the input still holds, seconds: the first row of the oldest chunk not yet
    /// passed by the device (rows the device has passed may still be counted until it leaves their
    /// chunk).
    pub fn first_time_s(&self) -> Option<f64> {
        self.lock().first_time()
    }

    /// Reads that fell outside the fed data.
    pub fn held_reads(&self) -> u64 {
        self.lock().held
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Window> {
        lock(&self.window)
    }
}

impl Stimulus for StreamStimulus {
    fn at(&mut self, _k: u64, t: Ps) -> Physical {
        let ts = ps_to_s(t);
        match self.cursor.as_mut().and_then(|cursor| cursor.within_chunk(ts)) {
            Some(p) => p,
            None => self.at_anywhere(ts),
        }
    }
}

impl Cursor {
    /// Move the cursor on to the last row of its chunk at or before `ts` (never back); true when
    /// the chunk holds a row after it.
    #[inline(always)]
    fn step_within_chunk(&mut self, ts: f64) -> bool {
        while let Some(&t1) = self.chunk.t.get(self.pos + 1) {
            if t1 > ts {
                return true;
            }
            self.pos += 1;
        }
        false
    }

    /// [`value_at`] between the cursor's row and the next row of its chunk (which must exist).
    #[inline(always)]
    fn value_in_chunk(&self, ts: f64) -> (Physical, bool) {
        let (t, p, pos) = (&self.chunk.t, &self.chunk.p, self.pos);
        value_at(ts, (t[pos], &p[pos]), Some((t[pos + 1], &p[pos + 1])))
    }

    /// The input at `ts` when the cursor's chunk holds a row after `ts` and the cursor's row is not
    /// after it (the common case: no lock), the cursor moved to the last row at or before `ts`.
    /// `None` otherwise (the cursor moved on as far as its chunk allows).
    #[inline(always)]
    fn within_chunk(&mut self, ts: f64) -> Option<Physical> {
        if !self.step_within_chunk(ts) {
            return None;
        }
        match self.value_in_chunk(ts) {
            (p, false) => Some(p),
            (_, true) => None,
        }
    }
}

impl StreamStimulus {
    /// The input at `ts` wherever it falls: before any row is fed, between chunks (moving the cursor
    /// into the next chunk and dropping the one left), outside the fed data (held and counted).
    #[inline(never)]
    fn at_anywhere(&mut self, ts: f64) -> Physical {
        if self.cursor.is_none() {
            self.cursor = lock(&self.window).chunks.front().map(|chunk| Cursor { chunk: chunk.clone(), pos: 0 });
        }
        let Some(cursor) = &mut self.cursor else {
            lock(&self.window).held += 1;
            return Physical::powered_idle();
        };
        // Move on to the last row at or before `ts` (the device's sample times only increase, so rows
        // before it are never needed again): within the chunk, then into the next chunk under the
        // lock.
        loop {
            if cursor.step_within_chunk(ts) {
                let (p, held) = cursor.value_in_chunk(ts);
                if held {
                    lock(&self.window).held += 1;
                }
                return p;
            }
            let row = (cursor.chunk.t[cursor.pos], &cursor.chunk.p[cursor.pos]);
            let mut w = lock(&self.window);
            match w.chunks.get(1) {
                Some(c) if c.t[0] <= ts => {
                    *cursor = Cursor { chunk: c.clone(), pos: 0 };
                    w.chunks.pop_front();
                }
                next_chunk => {
                    let (p, held) = value_at(ts, row, next_chunk.map(|c| (c.t[0], &c.p[0])));
                    w.held += u64::from(held);
                    return p;
                }
            }
        }
    }
}

fn lock(window: &Mutex<Window>) -> std::sync::MutexGuard<'_, Window> {
    // A poisoned lock means a panic elsewhere already failed the run; the data is still valid.
    window.lock().unwrap_or_else(|e| e.into_inner())
}

/// The input at `ts` from `row`, the last row at or before `ts` (or the first row fed, if `ts` is
/// before it), and the row after it, if any: interpolated between them, or `row` held outside the
/// fed data (the flag: the read is to be counted as held). Inline: it is most of a sample's work
/// here, and out of line its result is copied once more.
#[inline(always)]
fn value_at(ts: f64, (t0, p0): (f64, &Physical), next: Option<(f64, &Physical)>) -> (Physical, bool) {
    if ts <= t0 {
        return (*p0, ts < t0);
    }
    match next {
        None => (*p0, true),
        Some((t1, p1)) => (lerp(p0, p1, (ts - t0) / (t1 - t0)), false),
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

    /// The input at `ts` as the rows `t`, `p` define it, computed from scratch: the last row at or
    /// before `ts` (the first row if none), interpolated towards the next; the flag: held.
    fn reference(t: &[f64], p: &[Physical], ts: f64) -> (Physical, bool) {
        if t.is_empty() {
            return (Physical::powered_idle(), true);
        }
        let i = t.iter().rposition(|&ti| ti <= ts).unwrap_or(0);
        if ts <= t[i] {
            return (p[i], ts < t[i]);
        }
        match t.get(i + 1) {
            None => (p[i], true),
            Some(&t1) => (lerp(&p[i], &p[i + 1], (ts - t[i]) / (t1 - t[i])), false),
        }
    }

    #[test]
    fn the_cursor_reads_what_the_rows_define_across_chunks_gaps_and_ends() {
        // Chunks of 1…6 rows at irregular times, fed between reads; reads on rows, between rows,
        // across chunk boundaries, before the first row and past the last (held and counted), some
        // before any row is fed. The cursor (which locks only between chunks) must give the values
        // and the held count of the rows taken as a whole, bit for bit.
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut random = move |n: u64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state % n
        };
        for case in 0..40 {
            let (feed, mut stim) = InputFeed::new();
            let (mut t, mut p) = (Vec::new(), Vec::new());
            let (mut row_t, mut read_ps, mut held) = (0.5e-3 * random(3) as f64, 0u64, 0u64);
            for chunk in 0..30 {
                // Reads up to a little before or past the last row fed so far (none at first).
                let last = t.last().copied().unwrap_or(0.0);
                let horizon = s_to_ps(last + 1e-4 * (random(5) as f64 - 2.0));
                while read_ps <= horizon {
                    let (want, was_held) = reference(&t, &p, ps_to_s(read_ps));
                    let got = stim.at(0, read_ps);
                    assert_eq!(got, want, "case {case}, chunk {chunk}, t = {read_ps} ps");
                    held += u64::from(was_held);
                    assert_eq!(feed.held_reads(), held, "case {case}, chunk {chunk}, t = {read_ps} ps");
                    // Steps of 0 … 2.4 ms, or to the next row exactly.
                    read_ps = if random(4) == 0 {
                        t.iter().map(|&ti| s_to_ps(ti)).find(|&r| r > read_ps).unwrap_or(read_ps + 1)
                    } else {
                        read_ps + 1_000_000 * random(2400)
                    };
                }
                let rows = 1 + random(6) as usize;
                let (mut ct, mut cp) = (Vec::new(), Vec::new());
                for _ in 0..rows {
                    ct.push(row_t);
                    cp.push(rate((random(2001) as f64 - 1000.0) * 0.37));
                    row_t += 1e-4 * (1 + random(30)) as f64;
                }
                t.extend_from_slice(&ct);
                p.extend_from_slice(&cp);
                feed.push(&ct, cp).unwrap();
            }
            assert!(held > 0 && feed.held_reads() == held, "case {case}: no read was held");
        }
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
