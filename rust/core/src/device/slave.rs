//! The ADIS16xxx family's SPI slave (written once for every part): SPI mode 3, 16-bit frames, MSB first.
//!
//! - A read frame's register comes out on DOUT in the *next* frame; the pipeline holds across
//!   CS-high gaps. After a write frame, and in the very first frame, DOUT is the profile's
//!   `dout_after_write` (the part's DOUT is undefined there).
//! - A frame whose DIN equals `burst_command` starts a burst: the next frames carry the part's burst words (14 for the ADIS16407),
//!   all taken from the latest sample at the start of the command frame; DIN is ignored during them.
//!   CS high ends a burst early.
//! - The data a frame carries is taken at the frame's first SCLK edge (the slave loads its shift
//!   register then); a write acts at the frame's last edge.
//!
//! Timing rules (profile `device.*`), checked on every frame; each violation is an event:
//! `sclk_too_fast` (SCLK above `sclk_max_hz`, or `sclk_burst_max_hz` in a burst's data frames),
//! `stall_too_short` (last edge of a frame to first edge of the next below `t_stall_us`, or
//! `t_stall_slow_us` in the slow sample mode, or below one SCLK period inside a burst),
//! `datarate_too_short` (first edge to first edge of two frames outside a burst below
//! `t_datarate_us`; a burst is one chip-select window and is not held to it), `cs_setup` (CS↓ to first edge below `t_cs_ns`), `cs_hold` (last edge
//! to CS↑ below `t_sfs_ns`), `spi_mode` (the frame is clocked in another SPI mode than the family's
//! mode 3; the link has already shifted the words as the wires do). SCLK is judged by its full period
//! (the data sheet limits f_SCLK; no minimum SCLK pulse width is modelled: none of the sources at hand
//! gives one). Measured and required figures are in seconds or hertz; a 1 ps allowance absorbs the
//! bus's flooring to whole picoseconds.
//!
//! Consequences: under `strict` a violating frame's DOUT reads as `corrupt_word`; a `cs_hold`
//! violation corrupts the next frame's DOUT (the command it would answer may have been mis-latched).
//! Under `lenient` the data stay correct. In both modes the read still happens on the slave's side
//! (ND clears) and DIN is taken as sent, since the data sheet gives no failure mode for either.
//! Three conditions corrupt DOUT in both modes and ignore DIN: `frame_length` (not 16 SCLK cycles),
//! `frame_without_cs` (CS high: DOUT floats, read as `corrupt_word`) and `device_busy` (during a
//! software reset).

use super::adis::{Adis, Burst, SampleStamp};
use super::frame::{short_ps, MinPs, ReadRecord, Violations};
use super::part::family::{slow_mode, FRAME_BITS, SPI_MODE};
use crate::bus::{FrameTiming, RunTiming, SpiSlave};
use crate::events::{Event, Severity};
use crate::time::{Ps, PS_PER_S};

fn hz(period: Ps) -> f64 {
    if period == 0 {
        f64::INFINITY
    } else {
        PS_PER_S as f64 / period as f64
    }
}

fn s(t: f64) -> f64 {
    t / PS_PER_S as f64
}

/// The record of frame `index` (DIN not known yet: 0).
fn read_record(
    index: u64,
    timing: &FrameTiming,
    dout: u16,
    register: Option<u8>,
    sample: Option<SampleStamp>,
    violations: Violations,
    in_burst: bool,
) -> ReadRecord {
    let t = timing.first_edge;
    ReadRecord {
        index,
        t_start: t,
        t_end: timing.last_edge,
        din: 0,
        dout,
        register,
        sample_index: sample.map(|x| x.index),
        sample_age_ps: sample.map(|x| t.saturating_sub(x.t)),
        violations,
        in_burst,
    }
}

impl Adis {
    /// The latest frame clocked at this slave.
    pub fn last_frame(&self) -> Option<ReadRecord> {
        self.spi.last().copied()
    }

    /// The second frame to end since CS last fell (a burst's first data frame), once it has ended.
    pub fn second_frame_in_window(&self) -> Option<ReadRecord> {
        self.spi.second_in_window
    }

    /// Frames clocked so far.
    pub fn frames_clocked(&self) -> u64 {
        self.spi.frames
    }

    /// Keep a record of every frame (off by default; costs one push per frame when on).
    pub fn set_frame_log(&mut self, enabled: bool) {
        match (enabled, self.spi.log.is_some()) {
            (true, false) => self.spi.log = Some(Vec::new()),
            (false, true) => self.spi.log = None,
            _ => {}
        }
    }

    /// Take the logged frame records out.
    pub fn drain_frame_log(&mut self) -> Vec<ReadRecord> {
        self.spi.log.as_mut().map(std::mem::take).unwrap_or_default()
    }

    /// Whether a burst is in progress.
    pub fn in_burst(&self) -> bool {
        self.spi.burst.is_some()
    }

    /// A frame clocked bit by bit from GPIO pins (a bit-banged master, `board::bitbang`) is over:
    /// `timing` is its shape as measured (its length, its shortest SCLK period), which its start
    /// (`begin_frame` at its first edge) could not know. The shape rules it breaks that its start
    /// did not find are reported as any frame's, by the same checker ([`Adis::shape_violations`]),
    /// and recorded before the frame ends (`end_frame`), so that a frame of the wrong length is
    /// ignored as any other.
    pub fn bitbanged_shape(&mut self, timing: &FrameTiming) {
        let slot = self.spi.current();
        let rec = self.spi.records[slot];
        if rec.violations.intersects(Violations::IGNORE_DIN) {
            return;
        }
        let found = Violations(self.shape_violations(timing, rec.in_burst).0 & !rec.violations.0);
        if !found.is_empty() {
            self.report_timing(timing, rec.in_burst, found);
            self.spi.records[slot].violations.insert(found);
        }
    }

    /// The event of a broken rule `v` in bus frame `frame` (the caller records the bit in the
    /// frame's record).
    fn violation(&mut self, v: Violations, t: Ps, frame: u64, message: String, measured: f64, required: f64) {
        let kind = v.kinds().next().unwrap_or("spi_violation");
        self.events.push(Event::rule(t, kind, Severity::Error, message, measured, required).in_frame(frame));
    }

    /// The SCLK limit that applies to a frame: (in Hz, which limit).
    fn sclk_limit(&self, in_burst: bool) -> (f64, &'static str) {
        if in_burst {
            (self.limits.sclk_burst_max_hz, "burst")
        } else {
            (self.limits.sclk_max_hz, "normal-mode")
        }
    }

    /// Shortest time from the previous frame's last edge to this frame's first edge, ps, and what it is.
    fn stall_limit(&self, timing: &FrameTiming, in_burst: bool) -> (f64, &'static str) {
        if in_burst {
            (timing.sclk_period as f64, "one SCLK period inside a burst")
        } else if slow_mode(self.smpl_prd()) {
            (self.limits.t_stall_slow_ps, "the stall time in the slow sample mode")
        } else {
            (self.limits.t_stall_ps, "the stall time between frames")
        }
    }

    /// The timing rules the frame breaks, with their events ([`Adis::report_timing`]) when
    /// there is one.
    fn check_timing(&mut self, timing: &FrameTiming, in_burst: bool) -> Violations {
        let found = self.timing_violations(timing, in_burst);
        if !found.is_empty() {
            self.report_timing(timing, in_burst, found);
        }
        found
    }

    /// The timing rules the frame breaks: comparisons only (this runs on every frame).
    #[inline(always)]
    fn timing_violations(&self, timing: &FrameTiming, in_burst: bool) -> Violations {
        let mut found = self.shape_violations(timing, in_burst);
        found.insert(self.gap_violations(timing, in_burst));
        found
    }

    /// The rules a frame breaks by its shape alone (length, clock polarity, SCLK rate against the
    /// normal-mode or, in a burst, the burst limit): the same for every frame of one character shape.
    #[inline(always)]
    fn shape_violations(&self, timing: &FrameTiming, in_burst: bool) -> Violations {
        if in_burst {
            self.limits.spi.shape_against(timing, self.limits.min_burst_sclk_period)
        } else {
            self.limits.spi.shape(timing)
        }
    }

    /// The rules a frame breaks by when it starts: the stall since the previous frame, CS setup.
    #[inline(always)]
    fn gap_violations(&self, timing: &FrameTiming, in_burst: bool) -> Violations {
        let t = timing.first_edge;
        let mut found = Violations::default();
        if let Some(le) = self.spi.last_edge {
            let gap = t.saturating_sub(le);
            let stall_short = if in_burst {
                short_ps(gap, timing.sclk_period)
            } else if slow_mode(self.smpl_prd()) {
                self.limits.min_stall_slow.short(gap)
            } else {
                self.limits.min_stall.short(gap)
            };
            if stall_short {
                found.insert(Violations::STALL_TOO_SHORT);
            }
        }
        if let (false, Some(start)) = (in_burst, self.spi.last_plain_start) {
            if self.limits.min_datarate.short(t.saturating_sub(start)) {
                found.insert(Violations::DATARATE_TOO_SHORT);
            }
        }
        if !self.spi.framed_since_cs && self.limits.spi.setup_short(self.spi.cs_fall, t) {
            found.insert(Violations::CS_SETUP);
        }
        found
    }

    /// The events of the timing violations `found` in the frame in progress (one each, in rule order).
    #[cold]
    #[inline(never)]
    fn report_timing(&mut self, timing: &FrameTiming, in_burst: bool, found: Violations) {
        let t = timing.first_edge;
        let n = self.spi.frames;
        if found.contains(Violations::FRAME_LENGTH) {
            let msg =
                format!("frame {n}: {} SCLK cycles; the {} needs 16-bit frames", timing.bits, self.layout.part.name);
            self.violation(
                Violations::FRAME_LENGTH,
                t,
                timing.index,
                msg,
                f64::from(timing.bits),
                f64::from(FRAME_BITS),
            );
        }
        if found.contains(Violations::SPI_MODE) {
            let m = timing.mode;
            let msg = format!(
                "frame {n}: clocked in SPI mode {m} (CPOL = {}, CPHA = {}); the {} needs mode {SPI_MODE} \
                 (CPOL = 1, CPHA = 1), so each word is read one bit late",
                m >> 1,
                m & 1,
                self.layout.part.name
            );
            self.violation(Violations::SPI_MODE, t, timing.index, msg, f64::from(m), f64::from(SPI_MODE));
        }
        if found.contains(Violations::SCLK_TOO_FAST) {
            let (max_hz, which) = self.sclk_limit(in_burst);
            let f = hz(timing.sclk_period);
            let msg = format!("frame {n}: SCLK {:.6} MHz exceeds the {which} limit {:.6} MHz", f / 1e6, max_hz / 1e6);
            self.violation(Violations::SCLK_TOO_FAST, t, timing.index, msg, f, max_hz);
        }
        if let (true, Some(le)) = (found.contains(Violations::STALL_TOO_SHORT), self.spi.last_edge) {
            let gap = t.saturating_sub(le);
            let (required, which) = self.stall_limit(timing, in_burst);
            let msg = format!(
                "frame {n}: {:.3} µs since the previous frame; {which} is {:.3} µs",
                gap as f64 / 1e6,
                required / 1e6
            );
            self.violation(Violations::STALL_TOO_SHORT, t, timing.index, msg, s(gap as f64), s(required));
        }
        if let (true, Some(start)) = (found.contains(Violations::DATARATE_TOO_SHORT), self.spi.last_plain_start) {
            let period = t.saturating_sub(start);
            let required = self.limits.t_datarate_ps;
            let msg = format!(
                "frame {n}: {:.3} µs since the previous frame started; tDATARATE is {:.3} µs between frames \
                 outside a burst",
                period as f64 / 1e6,
                required / 1e6
            );
            self.violation(Violations::DATARATE_TOO_SHORT, t, timing.index, msg, s(period as f64), s(required));
        }
        if found.contains(Violations::CS_SETUP) {
            let gap = t.saturating_sub(self.spi.cs_fall);
            let msg = format!(
                "frame {n}: CS↓ to first SCLK edge {:.1} ns; tCS ≥ {:.1} ns",
                gap as f64 / 1e3,
                self.limits.t_cs_ps / 1e3
            );
            self.violation(Violations::CS_SETUP, t, timing.index, msg, s(gap as f64), s(self.limits.t_cs_ps));
        }
    }

    #[cold]
    #[inline(never)]
    fn time_reversal(&mut self, t: Ps, frame: u64) {
        self.events.push(
            Event::new(
                t,
                "time_reversal",
                Severity::Warning,
                format!(
                    "frame {} starts at {} ps, before the device time {} ps: it sees samples from its future",
                    self.spi.frames,
                    t,
                    self.now()
                ),
            )
            .in_frame(frame),
        );
    }

    /// A frame the slave does not take part in (CS high, the power-on start-up or a software reset
    /// running): DIN is ignored, DOUT reads as the corrupt word (0x0000 during the start-up).
    #[cold]
    #[inline(never)]
    fn ignored_frame(&mut self, timing: &FrameTiming) -> u16 {
        let (t, n) = (timing.first_edge, self.spi.frames);
        let mut dout = self.limits.corrupt_word;
        let violation = if !self.spi.cs_low {
            let msg = format!("frame {n}: clocked with CS high; the {} ignores it", self.layout.part.name);
            self.violation(Violations::NO_CHIP_SELECT, t, timing.index, msg, 1.0, 0.0);
            Violations::NO_CHIP_SELECT
        } else if t < self.ready_at() {
            // The part is still starting up: it drives no register onto DOUT, modelled as 0x0000 (the
            // data sheet says nothing of DOUT during the start-up).
            let (since_power_on, startup) = self.startup();
            let since = since_power_on + t;
            let msg = format!(
                "frame {n}: {:.3} ms after power-on; the {} answers after its {:.3} ms start-up",
                since as f64 / 1e9,
                self.layout.part.name,
                startup as f64 / 1e9
            );
            self.violation(Violations::BEFORE_STARTUP, t, timing.index, msg, s(since as f64), s(startup as f64));
            dout = 0x0000;
            Violations::BEFORE_STARTUP
        } else {
            let left = self.busy_until() - t;
            let msg = format!(
                "frame {n}: the {} is resetting for another {:.3} ms",
                self.layout.part.name,
                left as f64 / 1e9
            );
            self.violation(Violations::DEVICE_BUSY, t, timing.index, msg, s(left as f64), 0.0);
            self.spi.reset();
            Violations::DEVICE_BUSY
        };
        self.record_start(read_record(self.spi.frames, timing, dout, None, None, violation, false));
        dout
    }

    #[inline(always)]
    fn start_frame(&mut self, timing: &FrameTiming) -> u16 {
        let t = timing.first_edge;
        if t < self.now() {
            self.time_reversal(t, timing.index);
        }
        self.advance_to(t);
        if !self.spi.cs_low || t < self.busy_until() {
            return self.ignored_frame(timing);
        }
        let in_burst = self.spi.burst.is_some();
        let violations = self.check_timing(timing, in_burst);

        let (register, word, sample) = if let Some((register, word, sample)) = self.burst_word() {
            (Some(register), word, sample)
        } else if let Some(reg) = self.spi.pending_read.take() {
            // What the read reports (no register there, a write-only one) is about this frame.
            let mark = self.events.len();
            let (word, sample) = self.read_for_output(reg, t);
            self.events.tie_to_frame(mark, timing.index);
            (Some(reg & !1), word, sample)
        } else {
            (None, self.limits.idle_word, None)
        };

        let corrupt_next = std::mem::take(&mut self.spi.corrupt_next);
        let wrong_length = violations.contains(Violations::FRAME_LENGTH);
        let dout = if wrong_length || corrupt_next || (self.limits.strict && !violations.is_empty()) {
            self.limits.corrupt_word
        } else {
            word
        };
        self.record_start(read_record(self.spi.frames, timing, dout, register, sample, violations, in_burst));
        dout
    }

    /// Write the record of the frame in progress (all but DIN) straight into its slot, once.
    fn record_start(&mut self, record: ReadRecord) {
        let slot = self.spi.current();
        self.spi.records[slot] = record;
    }

    /// Data frames of the burst in progress from frame `from` of `run` (each with DIN `din`), for as
    /// long as they break no rule and need no event: what `start_frame` and `finish_frame` do for
    /// such frames, with the record written for the last one only (a frame's record is read only
    /// until the next frame ends). Returns the end of the frames it answered into `dout` (indexed
    /// as `run`); at `from` nothing has changed but the device's time, which the frame's own steps
    /// would move as well. (An index rather than a shorter run: a run is not copied per call.)
    ///
    /// The frames go in stretches that end before the device's next sample or injected reset
    /// ([`Adis::next_event`]): inside one, advancing the device only moves its time, so CS, the
    /// reset state, the burst's sample and the latest sample stay as they are at the stretch's first
    /// frame, whose checks are made in full. A later frame of the stretch needs only the stall rule
    /// against the frame before it (CS setup concerns the first frame after CS↓ alone), and the
    /// stretch's words, ND flags and counters are moved on at once. The stall rule is checked for the
    /// whole run at once when the run's bound on its stalls ([`RunTiming::min_stall`]) passes it, and
    /// frame by frame otherwise; only the frames looked at are timed.
    pub(super) fn clean_burst_frames(&mut self, run: &RunTiming, from: usize, din: u16, dout: &mut [u16]) -> usize {
        if from >= run.len() {
            return from;
        }
        // One shape for the whole run (see `SpiSlave::run_frames`): its rules are checked once.
        let first = run.frame(from);
        if self.spi.log.is_some() || self.spi.corrupt_next || !self.shape_violations(&first, true).is_empty() {
            return from;
        }
        let min_stall = MinPs::whole(first.sclk_period);
        // The stall rule for the whole run at once when its bound on its stalls passes it.
        let stalls_clear = run.min_stall().is_some_and(|bound| !min_stall.short(bound));
        let mut answered = from;
        while answered < run.len() {
            // The stretch's first frame: every check, as `start_frame` makes them.
            let timing = if answered == from { first } else { run.frame(answered) };
            let t = timing.first_edge;
            if t < self.now() {
                break;
            }
            self.advance_to(t);
            let clean = self.spi.cs_low && t >= self.busy_until();
            let Some(burst) = self.spi.burst.as_ref().filter(|_| clean) else { break };
            if !self.gap_violations(&timing, true).is_empty() {
                break;
            }
            // The frames after it up to the next device event (their first edges, in time order,
            // are past `now` and the end of any reset), the burst's last word, or a short stall.
            let horizon = self.next_event();
            let last_word = run.len().min(answered + burst.len - burst.next);
            let end = if stalls_clear {
                run.end_before(answered + 1..last_word, horizon)
            } else {
                let (mut end, mut last_edge) = (answered + 1, timing.last_edge);
                while end < last_word {
                    let next = run.frame(end);
                    if next.first_edge >= horizon || min_stall.short(next.first_edge.saturating_sub(last_edge)) {
                        break;
                    }
                    (end, last_edge) = (end + 1, next.last_edge);
                }
                end
            };
            let n = end - answered;
            let words = burst.next..burst.next + n;
            dout[answered..end].copy_from_slice(&burst.words[words.clone()]);
            // The record of the stretch's frame `k` (`k` < n), timed by `timing`.
            let (first_word, first_index, sample) = (burst.next, self.spi.frames, burst.sample);
            let burst_registers = self.layout.part.burst;
            let record_of = |k: usize, timing: &FrameTiming| {
                let word = first_word + k;
                let register = Some(burst_registers[word]);
                let dout = dout[answered + k];
                let record =
                    read_record(first_index + k as u64, timing, dout, register, sample, Violations::default(), true);
                ReadRecord { din, ..record }
            };
            if let Some(k) = self.spi.second_in_window_number().checked_sub(first_index).filter(|&k| k < n as u64) {
                // Usually the stretch's first frame (the burst's first data frame), already timed.
                let second = if k == 0 { timing } else { run.frame(answered + k as usize) };
                self.spi.second_in_window = Some(record_of(k as usize, &second));
            }
            self.clear_nd_after_burst(words, sample);
            let last = if n == 1 { timing } else { run.frame(end - 1) };
            self.advance_to(last.first_edge);
            self.spi.last_edge = Some(last.last_edge);
            self.spi.last_index = last.index;
            self.spi.last_plain_start = None;
            self.spi.framed_since_cs = true;
            self.spi.frames += n as u64;
            self.spi.burst_frames_done(n);
            self.spi.records[self.spi.finished()] = record_of(n - 1, &last);
            answered = end;
        }
        answered
    }

    #[inline(always)]
    fn finish_frame(&mut self, din: u16, timing: &FrameTiming) {
        let slot = self.spi.current();
        let rec = &mut self.spi.records[slot];
        rec.din = din;
        let (violations, in_burst) = (rec.violations, rec.in_burst);
        if !violations.contains(Violations::NO_CHIP_SELECT) {
            self.spi.last_edge = Some(timing.last_edge);
            self.spi.last_index = timing.index;
            self.spi.last_plain_start = (!in_burst).then_some(timing.first_edge);
            self.spi.framed_since_cs = true;
        }
        if self.spi.frames == self.spi.second_in_window_number() {
            self.spi.second_in_window = Some(self.spi.records[slot]);
        }
        self.spi.frames += 1;
        if self.spi.log.is_some() {
            self.log_frame(slot);
        }
        // What the frame does with DIN: nothing when it was ignored, nothing but move the burst on in
        // a burst data frame, else it is a command.
        if violations.intersects(Violations::IGNORE_DIN) {
            return;
        }
        if in_burst {
            self.spi.burst_frames_done(1);
        } else {
            self.command(din, timing.last_edge, timing.index);
        }
    }

    /// The word the burst in progress shifts out next (its register, the word, the sample it holds),
    /// with the register's ND bit cleared as the read does; `None` without a burst.
    #[inline(always)]
    fn burst_word(&mut self) -> Option<(u8, u16, Option<SampleStamp>)> {
        let b = self.spi.burst.as_ref()?;
        let (register, word, sample) = (self.layout.burst_register(b.next), b.words[b.next], b.sample);
        self.clear_nd_after_burst(b.next..b.next + 1, sample);
        Some((register, word, sample))
    }

    /// Append the record in `slot` to the frame log (out of line: the log is off by default).
    #[cold]
    #[inline(never)]
    fn log_frame(&mut self, slot: usize) {
        if let Some(log) = &mut self.spi.log {
            log.push(self.spi.records[slot]);
        }
    }

    /// Act on a command frame's DIN at its last edge `t`. Kept out of line: two frames in 30 are
    /// commands, and inlined its paths would cost the data frames' path stack and registers.
    #[inline(never)]
    fn command(&mut self, din: u16, t: Ps, frame: u64) {
        let addr = ((din >> 8) & 0x7F) as u8;
        if din & 0x8000 != 0 {
            // What the write reports (a read-only register, an unmodelled command) is about its frame.
            let mark = self.events.len();
            self.write_byte(addr, din as u8, t);
            self.events.tie_to_frame(mark, frame);
        } else if din == self.limits.burst_command {
            let (words, sample) = self.burst_snapshot();
            self.spi.burst = Some(Burst { words, len: self.layout.burst_len, sample, next: 0 });
        } else {
            self.spi.pending_read = Some(addr);
        }
    }

    fn chip_select(&mut self, low: bool, t: Ps) {
        if low {
            if !self.spi.cs_low {
                self.spi.cs_low = true;
                self.spi.cs_fall = t;
                self.spi.framed_since_cs = false;
                self.spi.frames_at_cs_fall = self.spi.frames;
                self.spi.second_in_window = None;
            }
            return;
        }
        if !self.spi.cs_low {
            return;
        }
        self.spi.cs_low = false;
        if let (true, Some(le), Some(last)) = (self.spi.framed_since_cs, self.spi.last_edge, self.spi.last()) {
            let (gap, index) = (t.saturating_sub(le), last.index);
            if self.limits.spi.hold_short(le, t) {
                self.cs_hold_violated(index, gap, t);
            }
        }
        if let Some(b) = self.spi.burst.take() {
            self.burst_truncated(&b, t);
        }
    }

    /// CS rose `gap` after the last SCLK edge (of frame `index`), sooner than tSFS. Out of line, as
    /// [`Adis::burst_truncated`]: the CS edge is on every burst's path, the events almost never fire.
    #[cold]
    #[inline(never)]
    fn cs_hold_violated(&mut self, index: u64, gap: Ps, t: Ps) {
        let msg = format!(
            "frame {index}: last SCLK edge to CS↑ {:.1} ns; tSFS ≥ {:.1} ns",
            gap as f64 / 1e3,
            self.limits.t_sfs_ps / 1e3
        );
        self.violation(Violations::CS_HOLD, t, self.spi.last_index, msg, s(gap as f64), s(self.limits.t_sfs_ps));
        let last = &mut self.spi.records[self.spi.finished()];
        last.violations.insert(Violations::CS_HOLD);
        if let Some(entry) = self.spi.log.as_mut().and_then(|l| l.last_mut()) {
            *entry = *last;
        }
        if self.limits.strict {
            self.spi.corrupt_next = true;
        }
    }

    /// CS rose before the burst `b` shifted all its data frames out.
    #[cold]
    #[inline(never)]
    fn burst_truncated(&mut self, b: &Burst, t: Ps) {
        let message = format!("CS↑ after {} of the {} burst data frames", b.next, b.len);
        self.events.push(Event::new(t, "burst_truncated", Severity::Info, message));
    }
}

impl SpiSlave for Adis {
    fn set_cs(&mut self, low: bool, t: Ps) {
        self.chip_select(low, t);
    }

    fn bitbanged_shape(&mut self, timing: &FrameTiming) {
        Adis::bitbanged_shape(self, timing);
    }

    fn begin_frame(&mut self, timing: &FrameTiming) -> u16 {
        self.start_frame(timing)
    }

    fn end_frame(&mut self, din: u16, timing: &FrameTiming) {
        self.finish_frame(din, timing);
    }

    /// A burst's data frames come as a run: the clean ones in few steps, any other frame by its
    /// own steps.
    fn run_frames(&mut self, run: &RunTiming, din: u16, dout: &mut [u16]) {
        let mut i = 0;
        while i < run.len() {
            let end = self.clean_burst_frames(run, i, din, dout);
            if end == i {
                let timing = run.frame(i);
                dout[i] = self.start_frame(&timing);
                self.finish_frame(din, &timing);
                i += 1;
            } else {
                i = end;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The record kept of the second frame since CS fell is the latest frame's record right after that
    /// frame, whether the frames after the command come one by one or as a run (the emulator reads it
    /// after a burst's run): a burst (its clean path), a register read (no burst: frame 1 holds the
    /// register's sample, frame 14 another), a software reset between the command and frame 1 (frame 1
    /// ignored, no sample). A new CS window forgets it.
    #[test]
    fn the_second_frame_since_cs_fell_is_kept_as_it_ended() {
        use crate::device::{Constant, Physical};
        const SCLK: Ps = 1_333_333;
        // A frame of 16 mode-3 cycles starting at `t`.
        let timing = |t: Ps| FrameTiming {
            index: 0,
            first_edge: t,
            last_edge: t + SCLK * 31 / 2,
            sclk_period: SCLK,
            bits: 16,
            mode: 3,
        };
        let t0: Ps = 9_800_000_000;
        let frame_0 = timing(t0 + 100_000);
        // Frame 1 starts 2 µs after the command; the data frames follow 2 µs apart.
        let data: Vec<FrameTiming> = (0..14)
            .map(|i| FrameTiming {
                index: i,
                ..timing(frame_0.last_edge + 2_000_000 + i * (SCLK * 31 / 2 + 2_000_000))
            })
            .collect();
        let reset_s = (frame_0.last_edge + 1_000_000) as f64 * 1e-12;
        for (name, command, reset) in [("burst", 0x4200, false), ("read", 0x0400, false), ("reset", 0x4200, true)] {
            let make = || {
                let mut d = Adis::new(&crate::profile::Device::default()).unwrap();
                let mut p = Physical::powered_idle();
                p.gyro_dps = [10.0, -20.0, 30.0];
                d.set_stimulus(Box::new(Constant(p)));
                if reset {
                    let ov = [format!("faults.list=[{{kind=\"sensor_reset\", start_s={reset_s:e}}}]")];
                    d.set_faults(&crate::profile::Profile::from_toml("", "test", &ov).unwrap().faults);
                }
                d.set_cs(true, t0);
                d.begin_frame(&frame_0);
                d.end_frame(command, &frame_0);
                assert_eq!(d.second_frame_in_window(), None, "{name}");
                d
            };
            let (mut one, mut run) = (make(), make());
            let mut after_frame_1 = None;
            for (i, tm) in data.iter().enumerate() {
                one.begin_frame(tm);
                one.end_frame(0, tm);
                if i == 0 {
                    after_frame_1 = one.last_frame();
                }
            }
            let mut dout = [0u16; 14];
            let (of, starts) = crate::device::tests::ps_run(&data);
            run.run_frames(&RunTiming::of_starts(of, &starts), 0, &mut dout);
            let first = after_frame_1.unwrap();
            assert_eq!(first.sample_index.is_some(), !reset, "{name}: {first:?}");
            assert_eq!(one.second_frame_in_window(), Some(first), "{name}");
            assert_eq!(run.second_frame_in_window(), Some(first), "{name}");
            assert_ne!(run.last_frame(), Some(first), "{name}");
            run.set_cs(false, data[13].last_edge + 100_000);
            assert_eq!(run.second_frame_in_window(), Some(first), "{name}: kept until CS falls again");
            run.set_cs(true, data[13].last_edge + 200_000);
            assert_eq!(run.second_frame_in_window(), None, "{name}");
        }
    }
}
