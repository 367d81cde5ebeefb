//! Device-side faults of the profile's `[faults]` section, as the ADIS16407 model applies them at its
//! own sample instants (the model is lazy: a fault acts when the sample it concerns is taken).
//!
//! - `stuck_axis`: from the first sample at or after `start_s`, the register keeps the value it held
//!   before (ND still sets with every sample: the sampling engine runs, one output path is frozen).
//! - `spike`: `samples` samples from `start_s` on carry `magnitude` more on the channel, added after
//!   the filter (a glitch of the output path, not a motion the filter would smooth); encoding clips
//!   and flags overrange as usual. `baro` and `baro_low` both spike the pressure (both registers).
//! - `sensor_reset`: a software reset at `start_s`, exactly as GLOB_CMD[7].
//! - `diag_flags`: every sample in the window ORs `flags` into DIAG_STAT (EA then shows in every output
//!   word; with `diag_clear_on_read` the flags stay until DIAG_STAT is read, which the published
//!   firmware never does).
//! - `supply_out_of_range`: the supply is `volts` for the samples in the window: SUPPLY_OUT and the
//!   DIAG_STAT supply flags follow from the model's usual rules.
//!
//! Windows are `[start_s, start_s + duration_s)` (open-ended without `duration_s`). Each fault is one
//! `fault_injected` event at its start (when the run reaches it). With no faults the sampling path pays
//! one comparison per sample ([`DeviceFaults::watch_from`] stays at `Ps::MAX`).

use crate::events::{Event, EventLog, Severity};
use crate::profile::{Fault, FaultKind, Faults, OutputChannel};
use crate::time::{s_to_ps, Ps};

/// Where a window fault stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    Pending,
    Active,
    Done,
}

/// One device fault, in picoseconds.
#[derive(Debug, Clone)]
struct Entry {
    fault: Fault,
    start: Ps,
    /// End of the window (`Ps::MAX`: to the end of the run).
    end: Ps,
    state: State,
    /// The value a stuck register keeps.
    frozen: u16,
    /// Spike samples still to come.
    spike_left: u32,
}

/// What the faults do to one sample.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct SampleFaults {
    /// Supply voltage replacing the input's, V.
    pub supply_v: Option<f64>,
    /// Added to the filtered value of each output register (burst index: SUPPLY_OUT = 0 …).
    pub spike: [f64; 14],
    pub any_spike: bool,
    /// DIAG_STAT bits to set.
    pub diag: u16,
    /// Output registers (bit = burst index) that keep their value, and the values.
    pub stuck: u16,
    pub frozen: [u16; 14],
}

/// The device's faults and the earliest time one of them needs attention.
#[derive(Debug, Clone)]
pub(crate) struct DeviceFaults {
    entries: Vec<Entry>,
    /// Samples at or after this time go through [`DeviceFaults::at_sample`].
    pub watch_from: Ps,
    /// The next software reset due (`Ps::MAX`: none).
    pub next_reset: Ps,
}

impl Default for DeviceFaults {
    fn default() -> Self {
        DeviceFaults { entries: Vec::new(), watch_from: Ps::MAX, next_reset: Ps::MAX }
    }
}

/// A one-line description of a fault for its `fault_injected` event.
pub fn describe(f: &Fault) -> String {
    let mut s = format!("{} at {} s", f.kind.as_str(), f.start_s);
    if let Some(d) = f.duration_s {
        s += &format!(" for {d} s");
    }
    if let Some(c) = f.channel {
        s += &format!(", channel {}", c.as_str());
    }
    for (k, v) in [("magnitude", f.magnitude), ("glitch_us", f.glitch_us), ("volts", f.volts)] {
        if let Some(v) = v {
            s += &format!(", {k} {v}");
        }
    }
    for (k, v) in [("samples", f.samples), ("after_frame", f.after_frame)] {
        if let Some(v) = v {
            s += &format!(", {k} {v}");
        }
    }
    if let Some(v) = f.flags {
        s += &format!(", flags 0x{v:04X}");
    }
    s
}

impl DeviceFaults {
    /// The device kinds of the profile's faults (`dropped_burst` acts on the bus, not here).
    pub fn from_profile(faults: &Faults) -> DeviceFaults {
        let entries: Vec<Entry> = faults
            .list
            .iter()
            .filter(|f| f.kind != FaultKind::DroppedBurst)
            .map(|f| {
                let start = s_to_ps(f.start_s);
                let end = f.duration_s.map_or(Ps::MAX, |d| s_to_ps(f.start_s + d).max(start));
                Entry {
                    fault: f.clone(),
                    start,
                    end,
                    state: State::Pending,
                    frozen: 0,
                    spike_left: f.samples.unwrap_or(1),
                }
            })
            .collect();
        let mut d = DeviceFaults { entries, ..DeviceFaults::default() };
        d.refresh();
        d
    }

    fn refresh(&mut self) {
        self.watch_from = Ps::MAX;
        self.next_reset = Ps::MAX;
        for e in &self.entries {
            match (e.fault.kind, e.state) {
                (_, State::Done) => {}
                (FaultKind::SensorReset, _) => self.next_reset = self.next_reset.min(e.start),
                (_, State::Active) => self.watch_from = 0,
                (_, State::Pending) => self.watch_from = self.watch_from.min(e.start),
            }
        }
    }

    /// Take the reset due at `next_reset`, recording its event; returns its time.
    pub fn take_reset(&mut self, events: &mut EventLog) -> Ps {
        let t = self.next_reset;
        if let Some(e) = self
            .entries
            .iter_mut()
            .find(|e| e.fault.kind == FaultKind::SensorReset && e.state == State::Pending && e.start == t)
        {
            e.state = State::Done;
            events.push(Event::new(t, "fault_injected", Severity::Warning, describe(&e.fault)));
        }
        self.refresh();
        t
    }

    /// What the faults do to the sample taken at `t`; `regs_now` gives the current value of an
    /// output register (by burst index), which a stuck register keeps.
    pub fn at_sample(&mut self, t: Ps, regs_now: impl Fn(usize) -> u16, events: &mut EventLog) -> SampleFaults {
        let mut out = SampleFaults::default();
        for e in &mut self.entries {
            if e.fault.kind == FaultKind::SensorReset || e.state == State::Done || t < e.start {
                continue;
            }
            if e.state == State::Pending {
                e.state = State::Active;
                let mut msg = describe(&e.fault);
                if let (FaultKind::StuckAxis, Some(c)) = (e.fault.kind, e.fault.channel) {
                    e.frozen = regs_now(c.burst_index());
                    msg += &format!(": the register keeps 0x{:04X}", e.frozen);
                }
                if t >= e.end {
                    msg += ": no internal sample fell inside the window";
                }
                events.push(Event::new(e.start, "fault_injected", Severity::Warning, msg));
            }
            let in_window = t < e.end;
            match e.fault.kind {
                FaultKind::StuckAxis if in_window => {
                    let i = e.fault.channel.map_or(0, OutputChannel::burst_index);
                    out.stuck |= 1 << i;
                    out.frozen[i] = e.frozen;
                }
                FaultKind::Spike if e.spike_left > 0 => {
                    let i = e.fault.channel.map_or(0, OutputChannel::burst_index);
                    out.spike[i] += e.fault.magnitude.unwrap_or(0.0);
                    out.any_spike = true;
                    e.spike_left -= 1;
                }
                FaultKind::DiagFlags if in_window => out.diag |= e.fault.flags.unwrap_or(0) as u16,
                FaultKind::SupplyOutOfRange if in_window => out.supply_v = e.fault.volts,
                _ => {}
            }
            let finished = match e.fault.kind {
                FaultKind::Spike => e.spike_left == 0,
                _ => !in_window,
            };
            if finished {
                e.state = State::Done;
            }
        }
        self.refresh();
        out
    }
}
