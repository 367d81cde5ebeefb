//! The emulator: the scheduler of virtual time that wires the board ([`Board`]: the F28335's clocks,
//! CPU timer 0, SPI-A and the sensor) to the firmware ([`Isr`]: its acquisition interrupt, schedule
//! and stages). It decides when each timer tick's ISR runs (how far the input reaches, and the
//! `firmware.overrun` policy when the previous ISR is still running) and collects the output.
//!
//! The CPU's own time is counted in SYSCLKOUT cycles (an integer) and converted to picoseconds by the
//! clock, so the CPU and the peripherals share one exact timeline.
//!
//! The sensor is a type parameter ([`Sensor`]): the ADIS16407 model fed a physical input
//! ([`Emulator::new`]), or the replay of a raw-register trace's words ([`Emulator::replay`]). Faults of
//! the profile act inside the device model, except `dropped_burst`, a glitch of the CS line
//! (`board/glitch.rs`).

pub mod bench;
mod board;
mod prices;

pub use crate::board::{input, sensor};
pub use crate::board::{FrameSummary, InputFeed, Reach, Sensor, StreamStimulus, StreamedDevice};
pub use crate::firmware::isr::BURST_FRAMES;
pub use crate::output::{is_column_list, BudgetRow, Column, CycleRow, Output, ReadRow, COLUMNS, READ_WORDS};
pub use crate::timing::stages::CostTerm;
pub use board::BoardReport;
pub use prices::{price_list, PriceList, StagePrice};

/// Timer ticks one call to [`Emulator::run`] runs at most before it returns
/// [`Progress::BlockFull`]: the output it holds is then at most this many budget rows (one per tick,
/// plus one per nested ISR), three read rows and one step row per tick, and the events of these
/// ticks, whatever the input (a long gap, a tiny timer period). 2^15 ticks: 131 s at the reference
/// period, 3.4 MB of budget rows; a chunk of a trace at 819.2 SPS fed as the harness feeds it
/// (8 192 rows, 10 s) never fills a block.
pub const BLOCK_TICKS: u64 = 1 << 15;

use crate::board::analog::AnalogBoard;
use crate::board::Board;
use crate::deadline;
use crate::device::error_model::ErrorModel;
use crate::device::replay::{ReplaySlave, RECORDED_WORDS};
use crate::device::{Adis16407, Physical};
use crate::error::{Error, Result};
use crate::events::{Event, Severity};
use crate::firmware::application::Application;
use crate::firmware::geomag_app::GeomagApp;
use crate::firmware::isr::Isr;
use crate::firmware::isr::StageCosts;
use crate::firmware::state_check::{DataWatch, StateWatch};
use crate::numerics::Scalar;
use crate::profile::{OverrunPolicy, Profile};
use crate::time::{ps_to_s, Ps};
use crate::timing::costs::CostTable;
use crate::timing::stages::stage_costs;

/// The emulated board running its firmware in the numeric backend `T`, reading the sensor `S`: the
/// ADIS16407 model fed a physical input (the default), or a [`ReplaySlave`] answering recorded words.
/// The firmware is the application `A` (`firmware::application`): the reference ADIS burst reader
/// by default.
pub struct Emulator<T: Scalar, S: Sensor = StreamedDevice, A: Application<S> = Isr<T>> {
    board: Board<S>,
    fw: A,
    _numeric: std::marker::PhantomData<fn() -> T>,
    /// Next timer tick to service.
    tick: u64,
    /// SYSCLKOUT cycle at which the CPU finishes the ISR it is running.
    cpu_free: u64,
    /// The firmware state's range check (every application's step rows).
    state: StateWatch,
    /// The part's data check (every application whose reads carry device samples).
    data: DataWatch,
}

/// Where the emulation stands after a call to [`Emulator::run`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Progress {
    /// Every tick the input covers has run; feed more input.
    NeedInput,
    /// [`BLOCK_TICKS`] ticks have run: take the output, then run again (the input may cover more).
    BlockFull,
    /// The input has ended and every tick it covers has run.
    Finished,
}

impl<T: Scalar> Emulator<T> {
    /// Build the board and firmware of a profile; `costs` is the cycle-cost table.
    pub fn new(profile: &Profile, costs: &CostTable) -> Result<Self> {
        let mut device = Adis16407::new(&profile.device)?;
        let period_s = device.sample_clock().period_s();
        device.set_sensor_errors(Box::new(ErrorModel::from_profile(&profile.errors, period_s)?));
        device.set_faults(&profile.faults);
        Emulator::with_sensor(profile, costs, StreamedDevice::new(device))
    }

    /// The input feed: push chunks of physical samples, then [`Emulator::run`].
    pub fn feed(&self) -> &InputFeed {
        self.board.link.slave().feed()
    }

    /// Append a chunk of physical input (times in s, values in data-sheet units).
    pub fn push_input(&mut self, t_s: &[f64], samples: Vec<Physical>) -> Result<()> {
        self.feed().push(t_s, samples)
    }

    /// Declare the end of the input.
    pub fn end_input(&mut self) {
        self.feed().end();
    }
}

impl<T: Scalar, S: Sensor, A: Application<S>> Emulator<T, S, A> {
    /// Append fixes of the board's GPS stream (times on the input's clock; see
    /// [`crate::firmware::Firmware::push_gps`]). From the first call on, the board has a GPS; give each
    /// chunk's fixes before the chunk's physical input, so every fix is there before it is due.
    pub fn push_gps(&mut self, fixes: &[crate::firmware::GpsFix]) -> Result<()> {
        self.fw.push_gps(fixes)
    }
}

impl<T: Scalar> Emulator<T, ReplaySlave> {
    /// The board and firmware of a profile reading recorded bursts instead of the device model (a
    /// raw-register trace): push them with [`Emulator::push_words`]. The profile's device timing
    /// rules are not checked against the recording, and its faults cannot apply (they act on the
    /// device model): a profile with faults is refused.
    pub fn replay(profile: &Profile, costs: &CostTable) -> Result<Self> {
        if let Some(f) = profile.faults.list.first() {
            return Err(Error::Config(format!(
                "faults.list: a replayed raw-register trace bypasses the device model, so the `{}` fault (and any \
                 other) cannot be injected; remove the faults or emulate a physical trace",
                f.kind.as_str()
            )));
        }
        let slave = ReplaySlave::new(profile.device.dout_after_write as u16, profile.device.burst_command as u16);
        Emulator::with_sensor(profile, costs, slave)
    }

    /// Append recorded bursts: timestamps (s since power-on) and the 15 DOUT words of each.
    pub fn push_words(&mut self, t_s: &[f64], words: &[[u16; RECORDED_WORDS]]) -> Result<()> {
        self.board.link.slave_mut().push(t_s, words)
    }

    /// Declare the end of the recording.
    pub fn end_input(&mut self) {
        self.board.link.slave_mut().end();
    }
}

impl<T: Scalar> Emulator<T, AnalogBoard, GeomagApp<T>> {
    /// The geomagnetic–gyro board (`firmware.application = "ads8344-geomag"`): the ADS8344 and its
    /// analogue front end on SPI-A's acquisition chip select, running the geomag firmware.
    pub fn geomag(profile: &Profile, costs: &CostTable) -> Result<Self> {
        if let Some(f) = profile.faults.list.first() {
            return Err(Error::Config(format!(
                "faults.list: the `{}` fault acts on the ADIS16xxx device model; the ads8344-geomag board takes none",
                f.kind.as_str()
            )));
        }
        let board = Board::from_profile(profile, AnalogBoard::from_profile(profile)?)?;
        let fw = GeomagApp::new(profile, &board, stage_costs(profile, costs)?, &costs.io)?;
        Ok(Emulator::of(board, fw))
    }

    /// Append a chunk of physical input (times in s; rates, field and temperature are read).
    pub fn push_input(&mut self, t_s: &[f64], samples: Vec<Physical>) -> Result<()> {
        self.board.link.slave().feed().push(t_s, samples)
    }

    /// Declare the end of the input.
    pub fn end_input(&mut self) {
        self.board.link.slave().feed().end();
    }
}

impl<T: Scalar, S: Sensor> Emulator<T, S> {
    /// The board and firmware of a profile reading `sensor`.
    fn with_sensor(profile: &Profile, costs: &CostTable, sensor: S) -> Result<Self> {
        let board = Board::from_profile(profile, sensor)?;
        let fw = Isr::new(profile, &board, stage_costs(profile, costs)?, &costs.io)?;
        Ok(Emulator::of(board, fw))
    }
}

impl<T: Scalar, S: Sensor, A: Application<S>> Emulator<T, S, A> {
    /// The emulator of a built board and the application running on it, at power-on.
    pub fn of(board: Board<S>, fw: A) -> Self {
        Emulator {
            board,
            fw,
            _numeric: std::marker::PhantomData,
            tick: 1,
            cpu_free: 0,
            state: StateWatch::default(),
            data: DataWatch::default(),
        }
    }

    /// The sensor on the acquisition chip select (its input feed, its recording).
    pub fn sensor_mut(&mut self) -> &mut S {
        self.board.link.slave_mut()
    }

    /// The compute-stage costs in use.
    pub fn stage_costs(&self) -> &StageCosts {
        self.fw.stage_costs()
    }

    /// Record every SPI frame and CS edge from now on (for the bus view; off by default).
    pub fn enable_bus_log(&mut self) {
        self.board.link.enable_log();
    }

    /// Take the bus log recorded so far.
    pub fn take_bus_log(&mut self) -> Vec<crate::bus::link::LinkRecord> {
        self.board.link.take_log()
    }

    /// Stop recording the bus log and take what it holds.
    pub fn stop_bus_log(&mut self) -> Vec<crate::bus::link::LinkRecord> {
        self.board.link.stop_log()
    }

    /// The output accumulated since the last [`Emulator::take_output`].
    pub fn take_output(&mut self) -> Output {
        self.collect_events();
        std::mem::take(self.fw.output())
    }

    /// Run the timer ticks the input covers, at most [`BLOCK_TICKS`] of them per call (then
    /// [`Progress::BlockFull`]: take the output and call again), so the output held stays bounded.
    /// A physical input: a tick runs when the input reaches past the end of the tick's period (its
    /// reads happen within it), or, after the end of the input, when the tick itself is inside the
    /// input. A recording: a tick runs while the bursts it reads are queued (after the end, the
    /// bursts left over for a partial tick are not read).
    pub fn run(&mut self) -> Result<Progress> {
        match self.board.link.slave().reach() {
            Reach::Time { last_s, ended } => self.run_to_time(last_s, ended),
            Reach::Bursts { queued, ended } => self.run_bursts(queued, ended),
        }
    }

    fn run_bursts(&mut self, queued: usize, ended: bool) -> Result<Progress> {
        self.reserve_rows(queued / self.fw.reads_per_tick());
        for _ in 0..BLOCK_TICKS {
            let queued = match self.board.link.slave().reach() {
                Reach::Bursts { queued, .. } => queued,
                Reach::Time { .. } => 0,
            };
            if queued < self.fw.reads_per_tick() {
                return Ok(self.stop(ended));
            }
            self.run_tick()?;
            self.tick = self.fw.next_pending();
        }
        Ok(Progress::BlockFull)
    }

    /// Where a call that ran every tick the input covers stands (at the end: the watches' last word).
    fn stop(&mut self, ended: bool) -> Progress {
        if ended {
            self.finish_watch();
            Progress::Finished
        } else {
            Progress::NeedInput
        }
    }

    /// Room for the rows of the ticks ahead (at most a block), at once: growing by doubling copies
    /// them again and again.
    fn reserve_rows(&mut self, ticks_ahead: usize) {
        let ticks_ahead = ticks_ahead.min(BLOCK_TICKS as usize);
        let reads = ticks_ahead * self.fw.reads_per_tick();
        let out = self.fw.output();
        out.budget.reserve(ticks_ahead);
        out.reads.reserve(reads);
        out.cycles.reserve(ticks_ahead);
    }

    fn run_to_time(&mut self, last_s: Option<f64>, ended: bool) -> Result<Progress> {
        let Some(last_s) = last_s else {
            return Ok(self.stop(ended));
        };
        let ticks_ahead = (last_s / ps_to_s(self.board.timer.tick_ps(1))) as u64;
        self.reserve_rows(ticks_ahead.saturating_sub(self.tick).saturating_add(1).min(BLOCK_TICKS) as usize);
        for _ in 0..BLOCK_TICKS {
            let horizon_ps = self.board.timer.tick_ps(if ended { self.tick } else { self.tick + 1 });
            if ps_to_s(horizon_ps) > last_s {
                return Ok(self.stop(ended));
            }
            self.run_tick()?;
            self.tick = self.fw.next_pending();
        }
        Ok(Progress::BlockFull)
    }

    /// One timer tick: the firmware's acquisition interrupt (which, when the schedule completes a
    /// step, runs the attitude, Euler and navigation stages), unless the overrun policy loses it.
    fn run_tick(&mut self) -> Result<()> {
        let k = self.tick;
        self.fw.set_next_pending(k + 1);
        let tick_cycle = self.board.tick_cycle(k);
        let tick_ps = self.board.tick_ps(k);
        let busy = tick_cycle < self.cpu_free;
        let start = if busy {
            match self.fw.overrun() {
                OverrunPolicy::Queue => {
                    // The PIE latches one pending interrupt: a second tick while one is still
                    // pending is lost.
                    if k > 1 && self.board.tick_cycle(k + 1) <= self.cpu_free {
                        let why = "TINT0 arrived while the previous one was still pending: lost";
                        self.skip_tick(k, tick_ps, "tick_lost", why);
                        return Ok(());
                    }
                    self.cpu_free
                }
                OverrunPolicy::Drop => {
                    self.skip_tick(
                        k,
                        tick_ps,
                        "overrun",
                        "the ISR of the previous tick was still running: tick dropped",
                    );
                    return Ok(());
                }
                // Arrived during the ISR's last instructions (after its last interruptible point):
                // taken as soon as it returns.
                OverrunPolicy::Nest => self.cpu_free,
            }
        } else {
            tick_cycle
        };
        if busy {
            let late = self.board.ps(self.cpu_free) - tick_ps;
            let policy = self.fw.overrun();
            self.fw.events().push(deadline::overrun(
                tick_ps,
                late,
                format!("tick {k}: the previous ISR ran {:.1} µs past this tick ({:?})", late as f64 / 1e6, policy),
            ));
        }

        let out = self.fw.output();
        let (budget_at, reads_at, cycles_at) = (out.budget.len(), out.reads.len(), out.cycles.len());
        let nested_before = self.fw.nested();
        let end = self.fw.isr(&mut self.board, k, tick_ps, start, busy)?;
        self.cpu_free = end;
        if self.fw.nested() != nested_before {
            // A nested ISR wrote its rows inside this one's: put every row back in tick/time order.
            let out = self.fw.output();
            out.budget[budget_at..].sort_by_key(|r| r.tick);
            out.reads[reads_at..].sort_by_key(|r| r.tick);
            out.cycles[cycles_at..].sort_by_key(|r| r.t_ps);
        }
        self.watch_rows(reads_at, cycles_at);
        Ok(())
    }

    /// The guards every application gets: the state of each step row it wrote (`state_check`:
    /// an error event at the first step out of range) and the data of each read (an error event when
    /// the part has produced no sample for [`crate::firmware::state_check::NO_DATA_PS`]).
    #[inline]
    fn watch_rows(&mut self, reads_at: usize, cycles_at: usize) {
        let sampled = self.fw.sampled_reads();
        let out = self.fw.output();
        let mut found: Vec<Event> = Vec::new();
        for row in &out.cycles[cycles_at..] {
            found.extend(self.state.check(row));
        }
        if sampled {
            for r in &out.reads[reads_at..] {
                found.extend(self.data.read(r));
            }
        }
        for e in found {
            self.fw.events().push(e);
        }
    }

    /// The end of the input: a part that produced no sample over a whole run shorter than
    /// [`crate::firmware::state_check::NO_DATA_PS`] is reported too.
    fn finish_watch(&mut self) {
        if let Some(e) = self.data.finish() {
            self.fw.events().push(e);
        }
    }

    /// Tick `k` is not serviced (`kind`, `why`): an error event and a skipped budget row.
    #[cold]
    fn skip_tick(&mut self, k: u64, tick_ps: Ps, kind: &'static str, why: &str) {
        self.fw.events().push(Event::new(tick_ps, kind, Severity::Error, format!("tick {k}: {why}")));
        self.fw.output().budget.push(BudgetRow::skipped(k, tick_ps));
    }

    /// Move the models' events into the output, in time order.
    fn collect_events(&mut self) {
        let mut all = self.fw.events().drain();
        all.extend(self.board.link.drain_events());
        all.extend(self.board.link.slave_mut().drain_events());
        all.extend(self.board.links.drain_events());
        all.sort_by_key(|e| e.t_ps);
        self.fw.output().events.extend(all);
    }
}

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_drain;
#[cfg(test)]
mod tests_faults;
#[cfg(test)]
mod tests_replay;
