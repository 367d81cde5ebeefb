//! `dropped_burst` faults: the CS line goes high inside a burst read (a glitch on the wire, not a
//! firmware write), after burst frame `after_frame`, for `glitch_us` or until the firmware raises CS
//! itself at the end of the burst. The firmware keeps clocking and stores whatever SPIRXBUF then
//! gives: the device has ended the burst (`burst_truncated`); frames clocked with CS high read the
//! floating line (`spi_frame_without_cs`); after a short glitch the device takes the next frames as
//! commands and answers them under its normal-mode rules.
//!
//! Bursts glitched: the first whose CS falls at or after `start_s`, and every later one whose CS falls
//! before `start_s + duration_s`. One glitch per burst: overlapping entries take turns.

use crate::profile::{Fault, FaultKind, Faults, DEFAULT_AFTER_FRAME};
use crate::time::{s_to_ps, Ps};

#[derive(Debug, Clone)]
struct Entry {
    fault: Fault,
    start: Ps,
    end: Ps,
    started: bool,
    done: bool,
}

/// The CS glitches of a run.
#[derive(Debug, Clone, Default)]
pub(crate) struct Glitches {
    entries: Vec<Entry>,
    /// Bursts whose CS falls at or after this time may be glitched (`Ps::MAX`: none left).
    pub watch_from: Ps,
}

/// The glitch of one burst.
#[derive(Debug, Clone)]
pub(crate) struct BurstGlitch {
    /// CS rises after this burst frame.
    pub after_frame: usize,
    /// How long it stays high (`None`: until the firmware raises it).
    pub length: Option<Ps>,
    /// When it rose (once it has).
    pub rise: Option<Ps>,
    /// It has fallen back.
    pub returned: bool,
    /// The fault, for the event.
    pub fault: Fault,
}

impl BurstGlitch {
    /// When CS falls back, if it does and has not yet.
    pub fn pending_return(&self) -> Option<Ps> {
        match (self.rise, self.length, self.returned) {
            (Some(r), Some(l), false) => Some(r + l),
            _ => None,
        }
    }
}

impl Glitches {
    /// The `dropped_burst` entries of the profile's faults.
    pub fn from_profile(faults: &Faults) -> Glitches {
        let entries: Vec<Entry> = faults
            .list
            .iter()
            .filter(|f| f.kind == FaultKind::DroppedBurst)
            .map(|f| {
                let start = s_to_ps(f.start_s);
                let end = s_to_ps(f.start_s + f.duration_s.unwrap_or(0.0)).max(start);
                Entry { fault: f.clone(), start, end, started: false, done: false }
            })
            .collect();
        let mut g = Glitches { entries, watch_from: Ps::MAX };
        g.refresh();
        g
    }

    fn refresh(&mut self) {
        self.watch_from = self.entries.iter().filter(|e| !e.done).map(|e| e.start).min().unwrap_or(Ps::MAX);
    }

    /// The glitch of the burst whose CS falls at `t_cs`, if any.
    pub fn take(&mut self, t_cs: Ps) -> Option<BurstGlitch> {
        let mut found = None;
        for e in self.entries.iter_mut().filter(|e| !e.done && t_cs >= e.start) {
            // The first burst at or after the start always; later ones while inside the window.
            let applies = !e.started || t_cs < e.end;
            e.started = true;
            if !applies || t_cs >= e.end {
                e.done = true;
            }
            if applies {
                found = Some(BurstGlitch {
                    after_frame: e.fault.after_frame.unwrap_or(DEFAULT_AFTER_FRAME) as usize,
                    length: e.fault.glitch_us.map(|us| s_to_ps(us * 1e-6)),
                    rise: None,
                    returned: false,
                    fault: e.fault.clone(),
                });
                break;
            }
        }
        self.refresh();
        found
    }
}
