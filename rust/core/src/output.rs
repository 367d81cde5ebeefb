//! What a run produces: one row per attitude step, per burst read and per timer tick, and the
//! events. Rows are plain data; the binding turns each column into a numpy array.

use crate::events::Event;
use crate::time::Ps;

/// One attitude step's output (what the firmware would send out every T).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CycleRow {
    /// Step index (0 = first step after alignment).
    pub step: u64,
    /// Virtual time of the tick that completed the step.
    pub t_ps: Ps,
    /// Q = [q0, q1, q2, q3], body → navigation.
    pub quat: [f64; 4],
    /// Roll, pitch, yaw, degrees (the firmware's extraction).
    pub euler_deg: [f64; 3],
    /// Velocity east, north, up, m/s.
    pub vel_enu: [f64; 3],
    /// Latitude (°), longitude (°), height (m).
    pub pos: [f64; 3],
}

/// One burst read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReadRow {
    /// Timer tick of the read.
    pub tick: u64,
    /// CS falling edge of the burst (the firmware's GPIO57 write): what a raw-register trace records.
    pub t_cs_ps: Ps,
    /// First SCLK edge of the burst.
    pub t_start_ps: Ps,
    /// Last SCLK edge of the burst.
    pub t_end_ps: Ps,
    /// The 15 words SPIRXBUF gave (frame 0: the command frame's don't-care word).
    pub words: [u16; 15],
    /// Decoded ω_ib^b, rad/s (the firmware's values as f64).
    pub rate: [f64; 3],
    /// Decoded f^b, m/s².
    pub accel: [f64; 3],
    /// Device sample the burst carried (−1: none, e.g. before the first sample); in a replay, the
    /// row of the recorded burst.
    pub sample_index: i64,
    /// True time of that sample (device clock); in a replay, the recorded timestamp of the burst.
    pub sample_ps: Ps,
    /// The time the firmware assumes the sample belongs to, s.
    pub assumed_s: f64,
    /// Age of the sample at the burst's first data frame.
    pub age_ps: Ps,
}

/// One timer tick's budget: when each part of the ISR ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BudgetRow {
    /// Tick index (tick k arrives at k × period).
    pub tick: u64,
    /// Arrival of the tick.
    pub tick_ps: Ps,
    /// First ISR cycle (later than the tick after an overrun).
    pub start_ps: Ps,
    /// End of the interrupt entry (context save and prologue).
    pub entry_end_ps: Ps,
    /// First SCLK edge of the first burst.
    pub spi_start_ps: Ps,
    /// CS high after the last burst.
    pub spi_end_ps: Ps,
    /// End of the decode.
    pub decode_end_ps: Ps,
    /// End of the attitude update (= decode end when no step ran).
    pub attitude_end_ps: Ps,
    /// End of the Euler extraction.
    pub euler_end_ps: Ps,
    /// End of the navigation.
    pub nav_end_ps: Ps,
    /// End of the ISR (after the exit).
    pub end_ps: Ps,
    /// The next tick: the deadline of this one.
    pub deadline_ps: Ps,
    /// This tick completed an attitude step.
    pub step: bool,
    /// This tick arrived while the previous ISR was running.
    pub overrun: bool,
}

impl BudgetRow {
    /// A tick that did not run (dropped or lost): every time is the tick's arrival.
    pub fn skipped(tick: u64, tick_ps: Ps) -> BudgetRow {
        BudgetRow {
            tick,
            tick_ps,
            start_ps: tick_ps,
            entry_end_ps: tick_ps,
            spi_start_ps: tick_ps,
            spi_end_ps: tick_ps,
            decode_end_ps: tick_ps,
            attitude_end_ps: tick_ps,
            euler_end_ps: tick_ps,
            nav_end_ps: tick_ps,
            end_ps: tick_ps,
            deadline_ps: tick_ps,
            step: false,
            overrun: true,
        }
    }
}

/// Everything a run produced since the output was last taken.
#[derive(Debug, Clone, Default)]
pub struct Output {
    /// One row per attitude step.
    pub cycles: Vec<CycleRow>,
    /// One row per burst read.
    pub reads: Vec<ReadRow>,
    /// One row per timer tick.
    pub budget: Vec<BudgetRow>,
    /// Events of every model, in time order.
    pub events: Vec<Event>,
}

impl Output {
    /// Append another chunk's output (rows and events keep their order).
    pub fn append(&mut self, other: Output) {
        self.cycles.extend(other.cycles);
        self.reads.extend(other.reads);
        self.budget.extend(other.budget);
        self.events.extend(other.events);
    }
}
