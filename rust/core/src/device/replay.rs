//! Replay of a raw-register trace: an SPI slave that answers each burst with the next recorded
//! burst's 15 DOUT words, bypassing the device model (what a logic analyser or the board's debug log
//! recorded is exactly what the firmware gets).
//!
//! - Each CS falling edge takes the next recorded burst; the frames of that CS-low window answer its
//!   words in order (frame 0: the recorded answer to the command frame). The published firmware
//!   lowers CS once per burst, so one record answers one burst read.
//! - Nothing of the ADIS16407's timing rules is checked: a recording carries no SCLK or stall times,
//!   and its words are what the part gave under the timing of the recording, not of this profile.
//! - A frame beyond the 15th of a window answers `idle_word` (`replay_extra_frame`); a CS-low window
//!   with no record left answers `idle_word` in every frame (`replay_exhausted`: the emulator's
//!   horizon normally prevents it). A command frame whose DIN is not the burst command is reported
//!   (`replay_unexpected_command`): the recording answers burst reads only.
//! - The sample a word "holds" is the recorded burst: index = its row, time = its recorded timestamp.

use std::collections::VecDeque;

use super::adis::SampleStamp;
use super::frame::ReadRecord;
use super::registers::BURST_ORDER;
use crate::bus::{FrameTiming, SpiSlave};
use crate::error::{Error, Result};
use crate::events::{Event, EventLog, Severity};
use crate::time::{s_to_ps, Ps};

/// Words of one recorded burst: the command frame's answer and the 14 output registers.
pub const RECORDED_WORDS: usize = 15;

/// One recorded burst.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Recorded {
    /// Row of the recording (counted from the first row ever pushed).
    row: u64,
    /// Recorded timestamp.
    t: Ps,
    words: [u16; RECORDED_WORDS],
}

/// The replaying slave.
#[derive(Debug, Clone)]
pub struct ReplaySlave {
    queue: VecDeque<Recorded>,
    rows_pushed: u64,
    last_pushed_s: Option<f64>,
    ended: bool,
    cs_low: bool,
    /// The record answering the current CS-low window and the next frame of it.
    current: Option<Recorded>,
    frame_in_window: usize,
    frames: u64,
    last: Option<ReadRecord>,
    /// The record of the window's second frame (its first data frame), once it has ended.
    second_in_window: Option<ReadRecord>,
    idle_word: u16,
    burst_command: u16,
    events: EventLog,
}

impl ReplaySlave {
    /// An empty replay; `idle_word` answers frames no record covers, `burst_command` is the DIN a
    /// window's first frame is expected to carry.
    pub fn new(idle_word: u16, burst_command: u16) -> ReplaySlave {
        ReplaySlave {
            queue: VecDeque::new(),
            rows_pushed: 0,
            last_pushed_s: None,
            ended: false,
            cs_low: false,
            current: None,
            frame_in_window: 0,
            frames: 0,
            last: None,
            second_in_window: None,
            idle_word,
            burst_command,
            events: EventLog::default(),
        }
    }

    /// Append recorded bursts: timestamps (s since power-on, finite, ≥ 0, strictly increasing across
    /// pushes) and their words. Errors name the row (counted from the first row ever pushed).
    pub fn push(&mut self, t_s: &[f64], words: &[[u16; RECORDED_WORDS]]) -> Result<()> {
        if t_s.len() != words.len() {
            return Err(Error::Input(format!("recorded bursts: {} times but {} word rows", t_s.len(), words.len())));
        }
        if self.ended {
            return Err(Error::Input("recorded bursts: a chunk was pushed after the end of the recording".into()));
        }
        let mut last = self.last_pushed_s;
        for (i, &t) in t_s.iter().enumerate() {
            let row = self.rows_pushed + i as u64;
            if !(t.is_finite() && t >= 0.0) {
                return Err(Error::Input(format!(
                    "recorded burst row {row}: column `t_s` is {t}; expected a finite time ≥ 0 s (since power-on)"
                )));
            }
            if let Some(prev) = last.filter(|&p| t <= p) {
                return Err(Error::Input(format!(
                    "recorded burst row {row}: column `t_s` = {t} s is not after the previous row ({prev} s): \
                     times must be strictly increasing"
                )));
            }
            last = Some(t);
        }
        self.queue.reserve(t_s.len());
        for (i, (&t, w)) in t_s.iter().zip(words).enumerate() {
            self.queue.push_back(Recorded { row: self.rows_pushed + i as u64, t: s_to_ps(t), words: *w });
        }
        self.rows_pushed += t_s.len() as u64;
        self.last_pushed_s = last;
        Ok(())
    }

    /// No more bursts will be pushed.
    pub fn end(&mut self) {
        self.ended = true;
    }

    /// Whether the recording has ended.
    pub fn ended(&self) -> bool {
        self.ended
    }

    /// Recorded bursts not taken yet.
    pub fn queued(&self) -> usize {
        self.queue.len()
    }

    /// The latest frame answered.
    pub fn last_frame(&self) -> Option<ReadRecord> {
        self.last
    }

    /// The second frame of the current (or latest) CS-low window, once it has ended.
    pub fn second_frame_in_window(&self) -> Option<ReadRecord> {
        self.second_in_window
    }

    /// The recorded burst answering the current (or latest) CS-low window.
    pub fn last_sample(&self) -> Option<SampleStamp> {
        self.current.map(|r| SampleStamp { index: r.row, t: r.t })
    }

    /// Take the recorded events out.
    pub fn drain_events(&mut self) -> Vec<Event> {
        self.events.drain()
    }
}

impl SpiSlave for ReplaySlave {
    fn set_cs(&mut self, low: bool, t: Ps) {
        if low && !self.cs_low {
            self.frame_in_window = 0;
            self.second_in_window = None;
            self.current = self.queue.pop_front();
            if self.current.is_none() {
                self.events.push(Event::new(
                    t,
                    "replay_exhausted",
                    Severity::Error,
                    format!(
                        "CS↓ after all {} recorded bursts were replayed: frames read 0x{:04X}",
                        self.rows_pushed, self.idle_word
                    ),
                ));
            }
        }
        self.cs_low = low;
    }

    fn begin_frame(&mut self, timing: &FrameTiming) -> u16 {
        let i = self.frame_in_window;
        let word = match self.current {
            Some(r) if i < RECORDED_WORDS => r.words[i],
            Some(r) => {
                self.events.push(
                    Event::new(
                        timing.first_edge,
                        "replay_extra_frame",
                        Severity::Warning,
                        format!(
                            "frame {} of the CS-low window of recorded burst {}: a burst has 15; it reads 0x{:04X}",
                            i, r.row, self.idle_word
                        ),
                    )
                    .in_frame(timing.index),
                );
                self.idle_word
            }
            None => self.idle_word,
        };
        let sample = self.last_sample();
        self.last = Some(ReadRecord {
            index: self.frames,
            t_start: timing.first_edge,
            t_end: timing.last_edge,
            dout: word,
            register: (1..RECORDED_WORDS).contains(&i).then(|| BURST_ORDER[i - 1]),
            sample_index: sample.map(|s| s.index),
            sample_age_ps: sample.map(|s| timing.first_edge.saturating_sub(s.t)),
            in_burst: (1..RECORDED_WORDS).contains(&i),
            ..ReadRecord::default()
        });
        word
    }

    fn end_frame(&mut self, din: u16, timing: &FrameTiming) {
        if self.frame_in_window == 0 && din != self.burst_command {
            self.events.push(
                Event::new(
                    timing.first_edge,
                    "replay_unexpected_command",
                    Severity::Warning,
                    format!(
                        "first frame of a CS-low window sent 0x{din:04X}, not the burst command 0x{:04X}: the \
                     recording answers burst reads only",
                        self.burst_command
                    ),
                )
                .in_frame(timing.index),
            );
        }
        if let Some(rec) = self.last.as_mut() {
            rec.din = din;
        }
        if self.frame_in_window == 1 {
            self.second_in_window = self.last;
        }
        self.frame_in_window += 1;
        self.frames += 1;
    }
    fn drain_events(&mut self) -> Vec<Event> {
        ReplaySlave::drain_events(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn timing(t: Ps) -> FrameTiming {
        FrameTiming { index: 0, first_edge: t, last_edge: t + 20_000_000, sclk_period: 1_333_333, bits: 16, mode: 3 }
    }

    fn burst(slave: &mut ReplaySlave, t: Ps, frames: usize) -> Vec<u16> {
        slave.set_cs(true, t);
        let words = (0..frames)
            .map(|i| {
                let tm = FrameTiming { index: 100 + i as u64, ..timing(t + 100_000 + i as Ps * 22_000_000) };
                let w = slave.begin_frame(&tm);
                slave.end_frame(if i == 0 { 0x4200 } else { 0 }, &tm);
                w
            })
            .collect();
        slave.set_cs(false, t + 400_000_000);
        words
    }

    #[test]
    fn each_cs_window_answers_the_next_record_in_order() {
        let mut s = ReplaySlave::new(0x0000, 0x4200);
        let a: [u16; 15] = std::array::from_fn(|i| 0x1000 + i as u16);
        let b: [u16; 15] = std::array::from_fn(|i| 0x2000 + i as u16);
        s.push(&[0.004, 0.008], &[a, b]).unwrap();
        assert_eq!(s.queued(), 2);
        assert_eq!(burst(&mut s, 4_000_000_000, 15), a.to_vec());
        let rec = s.last_frame().unwrap();
        assert_eq!((rec.register, rec.sample_index, rec.din), (Some(0x1C), Some(0), 0));
        assert_eq!(s.last_sample(), Some(SampleStamp { index: 0, t: 4_000_000_000 }));
        // A 16th frame reads the idle word and is reported.
        assert_eq!(burst(&mut s, 8_000_000_000, 16), [b.to_vec(), vec![0]].concat());
        assert_eq!(s.events.count("replay_extra_frame"), 1);
        let extra = s.events.events().iter().find(|e| e.kind == "replay_extra_frame").unwrap();
        assert_eq!(extra.frame, Some(115), "the 16th frame's");
        // No record left.
        assert_eq!(burst(&mut s, 12_000_000_000, 2), vec![0, 0]);
        assert_eq!(s.events.count("replay_exhausted"), 1);
        assert_eq!(s.events.count("replay_unexpected_command"), 0);
    }

    /// The window's second frame (a burst's first data frame) is kept as it ended, for the read
    /// records, and forgotten when CS falls again.
    #[test]
    fn the_second_frame_of_the_window_is_kept() {
        let mut s = ReplaySlave::new(0x0000, 0x4200);
        s.push(&[0.004, 0.008], &[[0x1111; 15], [0x2222; 15]]).unwrap();
        s.set_cs(true, 4_000_000_000);
        let mut after_frame_1 = None;
        for i in 0..15 {
            let tm = timing(4_000_100_000 + i as Ps * 22_000_000);
            s.begin_frame(&tm);
            s.end_frame(if i == 0 { 0x4200 } else { 0 }, &tm);
            if i == 1 {
                after_frame_1 = s.last_frame();
            }
        }
        let second = s.second_frame_in_window();
        assert_eq!(second, after_frame_1);
        assert_eq!(second.map(|r| (r.t_start, r.register)), Some((4_022_100_000, Some(BURST_ORDER[0]))));
        s.set_cs(false, 4_400_000_000);
        s.set_cs(true, 8_000_000_000);
        assert_eq!(s.second_frame_in_window(), None);
    }

    #[test]
    fn pushes_are_checked_with_the_row() {
        let mut s = ReplaySlave::new(0, 0x4200);
        s.push(&[0.0, 1.0], &[[0; 15]; 2]).unwrap();
        let e = s.push(&[2.0, 2.0], &[[0; 15]; 2]).unwrap_err().to_string();
        assert!(e.contains("row 3") && e.contains("strictly increasing"), "{e}");
        let e = s.push(&[f64::NAN], &[[0; 15]]).unwrap_err().to_string();
        assert!(e.contains("row 2") && e.contains("finite"), "{e}");
        let e = s.push(&[3.0], &[]).unwrap_err().to_string();
        assert!(e.contains("1 times but 0"), "{e}");
        s.end();
        assert!(s.push(&[5.0], &[[0; 15]]).is_err());
    }
}
