//! The board and its firmware in virtual time: CPU timer 0 raises the acquisition interrupt, the
//! ISR drives SPI-A exactly as the published code does (CS low on GPIO57, poll BUFFULL, write
//! SPITXBUF, poll INT_FLAG, read SPIRXBUF, …, CS high), so the SPI traffic and its gaps come out of
//! the peripheral and device models; the compute stages cost the cycles the timing model gives them.
//!
//! The CPU's own time is counted in SYSCLKOUT cycles (an integer) and converted to picoseconds by the
//! clock, so the CPU and the peripherals share one exact timeline.
//!
//! The sensor is a type parameter ([`Sensor`]): the ADIS16407 model fed a physical input
//! ([`Emulator::new`]), or the replay of a raw-register trace's words ([`Emulator::replay`]). Faults of
//! the profile act inside the device model, except `dropped_burst`, a glitch of the CS line driven here
//! (`glitch.rs`).

pub mod bench;
mod board;
mod glitch;
pub mod input;
mod output;
pub mod sensor;
pub mod state_check;

pub use board::BoardReport;
pub use input::{InputFeed, StreamStimulus};
pub use output::{is_column_list, BudgetRow, Column, CycleRow, Output, ReadRow, COLUMNS, READ_WORDS};
pub use sensor::{FrameSummary, Reach, Sensor, StreamedDevice};

use crate::bus::link::SpiLink;
use crate::device::error_model::ErrorModel;
use crate::device::replay::{ReplaySlave, RECORDED_WORDS};
use glitch::Glitches;

use crate::device::{Adis16407, Physical};
use crate::dsp::clocks::DspClocks;
use crate::dsp::spi::{FlagTime, PollSteps, PolledLoop, SPIRXBUF, SPITXBUF};
use crate::dsp::timer::CpuTimer;
use crate::error::{Error, Result};
use crate::events::{Event, EventLog, Severity};
use crate::firmware::{Firmware, Vec3};
use crate::numerics::Scalar;
use crate::profile::{OverrunPolicy, Profile, Schedule};
use crate::time::{ps_to_s, Clock, Divisor, Ps};
use crate::timing::costs::CostTable;
use crate::timing::stages::{stage_costs, StageCosts};

/// Frames of one burst read: the command and the 14 output registers.
pub const BURST_FRAMES: usize = 15;
/// Index in the burst of X/Y/Z GYRO_OUT and X/Y/Z ACCL_OUT (frame 0 is the command).
const FIRST_INERTIAL: usize = 2;
/// DIN the firmware sends in the 14 data frames of a burst (don't care for the device).
const BURST_FILL: u16 = 0x0000;
/// A poll that has not seen its flag after this many SYSCLKOUT cycles is a hung firmware.
const POLL_WATCHDOG_CYCLES: u64 = 150_000_000;
/// Timer ticks one call to [`Emulator::run`] runs at most before it returns
/// [`Progress::BlockFull`]: the output it holds is then at most this many budget rows (one per tick,
/// plus one per nested ISR), three read rows and one step row per tick, and the events of these
/// ticks, whatever the input (a long gap, a tiny timer period). 2^15 ticks: 131 s at the reference
/// period, 3.4 MB of budget rows; a chunk of a trace at 819.2 SPS fed as the harness feeds it
/// (8 192 rows, 10 s) never fills a block.
pub const BLOCK_TICKS: u64 = 1 << 15;

/// The emulated board running its firmware in the numeric backend `T`, reading the sensor `S`: the
/// ADIS16407 model fed a physical input (the default), or a [`ReplaySlave`] answering recorded words.
pub struct Emulator<T: Scalar, S: Sensor = StreamedDevice> {
    profile: Profile,
    sysclk: Clock,
    timer: CpuTimer,
    link: SpiLink<S>,
    fw: Firmware<T>,
    /// Injected CS glitches (`dropped_burst` faults).
    glitches: Glitches,
    stages: StageCosts,
    io: crate::timing::costs::IoCosts,
    /// The firmware's status-polling loops.
    poller: Poller,
    /// The burst's word loop in CPU cycles, when SYSCLKOUT is a whole multiple of LSPCLK.
    polled_loop: Option<PolledLoop>,
    /// The fill-word runs' steps per write phase, for the burst's poll and read (fixed per emulator).
    poll_steps: PollSteps,
    bursts_per_tick: usize,
    /// The timer period, s (as the read rows' assumed sample times use it).
    tick_period_s: f64,
    /// Next timer tick to service.
    tick: u64,
    /// A tick's arrival worked out ahead, (tick, ps): each ISR's deadline is the next tick's arrival.
    known_tick_ps: (u64, Ps),
    /// SYSCLKOUT cycle at which the CPU finishes the ISR it is running.
    cpu_free: u64,
    /// The next tick no ISR has serviced yet (ticks serviced by a nested ISR are skipped).
    next_pending: u64,
    /// Nesting depth of the ISR being emulated (0: the outer one).
    depth: u8,
    /// Nested ISRs so far.
    nested: u64,
    /// Rate samples of the step being assembled (ω_ib, rad/s) and their true sample times.
    rates: [Vec3<T>; 3],
    have: usize,
    /// Index of the next attitude step.
    step: u64,
    last_accel: Vec3<T>,
    aligning: bool,
    align_until_s: f64,
    /// No step's state has been out of range yet (checked until the first one is: see `state_check`).
    state_in_range: bool,
    out: Output,
    events: EventLog,
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
        self.link.slave().feed()
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
        self.link.slave_mut().push(t_s, words)
    }

    /// Declare the end of the recording.
    pub fn end_input(&mut self) {
        self.link.slave_mut().end();
    }
}

impl<T: Scalar, S: Sensor> Emulator<T, S> {
    /// The board and firmware of a profile reading `sensor`.
    fn with_sensor(profile: &Profile, costs: &CostTable, sensor: S) -> Result<Self> {
        let clocks = DspClocks::from_profile(&profile.clocks)?;
        let timer = CpuTimer::from_profile(&profile.timer, clocks.sysclkout)?;
        let mut link = SpiLink::from_profile(profile, sensor)?;
        // InitSpi runs at power-on (t = 0) in the published order.
        link.init_from_profile(&profile.spi, 0)?;
        let fw = Firmware::<T>::new(profile)?;
        let stages = stage_costs(profile, costs)?;
        let zero = T::from_f64(0.0, crate::numerics::QClass::Rate);
        let bursts_per_tick = if profile.firmware.schedule == Schedule::BackToBack { 3 } else { 1 };
        let tick_period_s = ps_to_s(timer.tick_ps(1));
        let aligning = profile.firmware.initial_attitude == crate::profile::InitialAttitude::Level;
        let poller = Poller {
            sysclk: clocks.sysclkout,
            poll_cycles: Divisor::new(u64::from(profile.timing.poll_loop_cycles)),
            sysclk_per_lspclk: clocks.sysclkout.cycles_per_cycle_of(clocks.lspclk),
        };
        Ok(Emulator {
            sysclk: clocks.sysclkout,
            timer,
            link,
            fw,
            glitches: Glitches::from_profile(&profile.faults),
            stages,
            io: costs.io.clone(),
            polled_loop: poller.sysclk_per_lspclk.map(|k| PolledLoop {
                sysclk: clocks.sysclkout,
                sysclk_per_lspclk: Divisor::new(k),
                before_write: poller.poll_cycles.get() + u64::from(costs.io.peripheral_write),
                after_read: u64::from(costs.io.store_word + costs.io.frame_loop),
            }),
            poller,
            poll_steps: PollSteps::default(),
            bursts_per_tick,
            tick_period_s,
            tick: 1,
            // Tick 0 arrives at cycle 0.
            known_tick_ps: (0, 0),
            cpu_free: 0,
            next_pending: 1,
            depth: 0,
            nested: 0,
            rates: [[zero; 3]; 3],
            have: 0,
            step: 0,
            last_accel: [zero; 3],
            aligning,
            align_until_s: profile.firmware.alignment_s,
            state_in_range: true,
            out: Output::default(),
            events: EventLog::default(),
            profile: profile.clone(),
        })
    }

    /// The compute-stage costs in use.
    pub fn stage_costs(&self) -> &StageCosts {
        &self.stages
    }

    /// Record every SPI frame and CS edge from now on (for the bus view; off by default).
    pub fn enable_bus_log(&mut self) {
        self.link.enable_log();
    }

    /// Take the bus log recorded so far.
    pub fn take_bus_log(&mut self) -> Vec<crate::bus::link::LinkRecord> {
        self.link.take_log()
    }

    /// Stop recording the bus log and take what it holds.
    pub fn stop_bus_log(&mut self) -> Vec<crate::bus::link::LinkRecord> {
        self.link.stop_log()
    }

    /// The output accumulated since the last [`Emulator::take_output`].
    pub fn take_output(&mut self) -> Output {
        self.collect_events();
        std::mem::take(&mut self.out)
    }

    /// Run the timer ticks the input covers, at most [`BLOCK_TICKS`] of them per call (then
    /// [`Progress::BlockFull`]: take the output and call again), so the output held stays bounded.
    /// A physical input: a tick runs when the input reaches past the end of the tick's period (its
    /// reads happen within it), or, after the end of the input, when the tick itself is inside the
    /// input. A recording: a tick runs while the bursts it reads are queued (after the end, the
    /// bursts left over for a partial tick are not read).
    pub fn run(&mut self) -> Result<Progress> {
        match self.link.slave().reach() {
            Reach::Time { last_s, ended } => self.run_to_time(last_s, ended),
            Reach::Bursts { queued, ended } => self.run_bursts(queued, ended),
        }
    }

    fn run_bursts(&mut self, queued: usize, ended: bool) -> Result<Progress> {
        self.reserve_rows(queued / self.bursts_per_tick);
        for _ in 0..BLOCK_TICKS {
            let queued = match self.link.slave().reach() {
                Reach::Bursts { queued, .. } => queued,
                Reach::Time { .. } => 0,
            };
            if queued < self.bursts_per_tick {
                return Ok(if ended { Progress::Finished } else { Progress::NeedInput });
            }
            self.run_tick()?;
            self.tick = self.next_pending;
        }
        Ok(Progress::BlockFull)
    }

    /// Room for the rows of the ticks ahead (at most a block), at once: growing by doubling copies
    /// them again and again.
    fn reserve_rows(&mut self, ticks_ahead: usize) {
        let ticks_ahead = ticks_ahead.min(BLOCK_TICKS as usize);
        self.out.budget.reserve(ticks_ahead);
        self.out.reads.reserve(ticks_ahead * self.bursts_per_tick);
        self.out.cycles.reserve(ticks_ahead);
    }

    fn run_to_time(&mut self, last_s: Option<f64>, ended: bool) -> Result<Progress> {
        let Some(last_s) = last_s else {
            return Ok(if ended { Progress::Finished } else { Progress::NeedInput });
        };
        let ticks_ahead = (last_s / ps_to_s(self.timer.tick_ps(1))) as u64;
        self.reserve_rows(ticks_ahead.saturating_sub(self.tick).saturating_add(1).min(BLOCK_TICKS) as usize);
        for _ in 0..BLOCK_TICKS {
            let horizon_ps = self.timer.tick_ps(if ended { self.tick } else { self.tick + 1 });
            if ps_to_s(horizon_ps) > last_s {
                return Ok(if ended { Progress::Finished } else { Progress::NeedInput });
            }
            self.run_tick()?;
            self.tick = self.next_pending;
        }
        Ok(Progress::BlockFull)
    }

    fn ps(&self, cycle: u64) -> Ps {
        self.sysclk.cycles_to_ps(cycle)
    }

    /// The SYSCLKOUT cycle timer tick `k` arrives on.
    fn tick_cycle(&self, k: u64) -> u64 {
        self.timer.period_cycles() * k
    }

    /// The time tick `k` arrives at: usually the deadline the previous ISR worked out.
    #[inline]
    fn tick_ps(&self, k: u64) -> Ps {
        match self.known_tick_ps {
            (known, ps) if known == k => ps,
            _ => self.ps(self.tick_cycle(k)),
        }
    }

    /// One timer tick: the acquisition interrupt and, when the schedule completes a step, the
    /// attitude, Euler and navigation stages.
    fn run_tick(&mut self) -> Result<()> {
        let k = self.tick;
        self.next_pending = k + 1;
        let tick_cycle = self.tick_cycle(k);
        let tick_ps = self.tick_ps(k);
        let busy = tick_cycle < self.cpu_free;
        let start = if busy {
            match self.profile.firmware.overrun {
                OverrunPolicy::Queue => {
                    // The PIE latches one pending interrupt: a second tick while one is still
                    // pending is lost.
                    if k > 1 && self.tick_cycle(k + 1) <= self.cpu_free {
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
            let late = self.ps(self.cpu_free) - tick_ps;
            self.events.push(Event::rule(
                tick_ps,
                "overrun",
                Severity::Error,
                format!(
                    "tick {k}: the previous ISR ran {:.1} µs past this tick ({:?})",
                    late as f64 / 1e6,
                    self.profile.firmware.overrun
                ),
                ps_to_s(late),
                0.0,
            ));
        }

        let (budget_at, reads_at, cycles_at) = (self.out.budget.len(), self.out.reads.len(), self.out.cycles.len());
        let nested_before = self.nested;
        let end = self.isr(k, tick_ps, start, busy)?;
        self.cpu_free = end;
        if self.nested != nested_before {
            // A nested ISR wrote its rows inside this one's: put every row back in tick/time order.
            self.out.budget[budget_at..].sort_by_key(|r| r.tick);
            self.out.reads[reads_at..].sort_by_key(|r| r.tick);
            self.out.cycles[cycles_at..].sort_by_key(|r| r.t_ps);
        }
        Ok(())
    }

    /// Under `firmware.overrun = "nest"` the ISR re-enables interrupts (EINT) after its entry: a tick
    /// that has arrived is taken at the next interruptible point (after each burst frame, after the
    /// decode, after the attitude update) and runs to completion there, at depth one (the nested ISR
    /// does not re-enable them: one level). Nothing happens under the other policies. Inline: it runs
    /// after every burst frame and usually only tests the policy.
    #[inline]
    fn maybe_nest(&mut self, c: &mut u64, k: u64) -> Result<()> {
        if !self.may_nest() {
            return Ok(());
        }
        self.nest_if_due(c, k)
    }

    /// Whether a tick may preempt the running ISR (`nest` policy, not already nested).
    fn may_nest(&self) -> bool {
        self.profile.firmware.overrun == OverrunPolicy::Nest && self.depth == 0
    }

    /// The nested ISR of [`Emulator::maybe_nest`], if a tick has arrived (out of line, so the policy
    /// test inlines into the per-frame loop).
    #[inline(never)]
    fn nest_if_due(&mut self, c: &mut u64, k: u64) -> Result<()> {
        // One nested ISR per interruptible point. On the chip a tick that arrives during a nested ISR
        // is taken right after its IRET, so an ISR longer than the period starves the outer one for
        // ever; here the outer one runs on to its next interruptible point first (documented), so
        // every ISR ends and the starvation shows as a nested ISR at every point.
        if self.tick_cycle(self.next_pending) <= *c {
            let inner = self.next_pending;
            self.next_pending += 1;
            self.nested += 1;
            self.events.push(Event::new(
                self.ps(*c),
                "nested_interrupt",
                Severity::Warning,
                format!("tick {inner} preempts the ISR of tick {k}: it runs inside it (SPI-A and the firmware state are shared)"),
            ));
            self.depth += 1;
            let end = self.isr(inner, self.tick_ps(inner), *c, true);
            self.depth -= 1;
            *c = end?;
        }
        Ok(())
    }

    /// One ISR of tick `k` (arrived at `tick_ps`) from cycle `start`; returns the cycle it ends at.
    fn isr(&mut self, k: u64, tick_ps: Ps, start: u64, overrun: bool) -> Result<u64> {
        let tick_cycle = self.tick_cycle(k);
        let mut c = start + self.stages.entry;
        let entry_end = c;
        // Only as many bursts as the schedule reads are set up (zeroing three on every tick cost as
        // much as the rest of the ISR's bookkeeping, measured with callgrind).
        let (mut one, mut three);
        let bursts: &mut [Burst] = if self.bursts_per_tick == 1 {
            one = [Burst::EMPTY];
            &mut one
        } else {
            three = [Burst::EMPTY; 3];
            &mut three[..self.bursts_per_tick]
        };
        for b in bursts.iter_mut() {
            self.burst(&mut c, k, b)?;
        }
        // The SPI part ends where the CPU raised CS at the end of the last burst: that edge's time.
        let spi_end_ps = bursts[bursts.len() - 1].t_cs_rise_ps;

        // Decode every burst of the tick.
        let mut decoded = [[T::from_f64(0.0, crate::numerics::QClass::Rate); 3]; 3];
        for b in 0..bursts.len() {
            let inertial: [u16; 6] = std::array::from_fn(|i| bursts[b].words[FIRST_INERTIAL + i]);
            let d = self.fw.decode(&inertial);
            if !d.report.is_clean() {
                d.report.push_events(self.ps(c), &inertial, &mut self.events);
            }
            c += self.stages.decode.cycles;
            decoded[b] = d.rate;
            self.last_accel = d.accel;
            self.record_read(k, b, &bursts[b], &d.rate, &d.accel);
        }
        self.maybe_nest(&mut c, k)?;
        let decode_end = c;

        // Assemble the step's rate samples according to the schedule.
        let step_ready = self.schedule(&decoded, &mut c);
        let schedule_end = c;
        // Where the attitude, Euler and navigation stages ended, when they ran.
        let mut stage_ends = None;
        if step_ready {
            let t_end_s = ps_to_s(tick_ps);
            if self.aligning {
                self.fw.add_alignment_sample(&self.last_accel);
                if t_end_s >= self.align_until_s {
                    self.fw.finish_alignment()?;
                    self.aligning = false;
                }
            } else {
                self.fw.update_attitude(&self.rates)?;
                c += self.stages.attitude.cycles;
                self.maybe_nest(&mut c, k)?;
                let attitude_end = c;
                let e = self.fw.euler();
                c += self.stages.euler.cycles;
                let euler_end = c;
                self.fw.navigate(&self.last_accel);
                c += self.stages.navigation.cycles;
                stage_ends = Some([attitude_end, euler_end, c]);
                self.record_cycle(tick_ps, &e);
            }
            self.rates[0] = self.rates[2];
            self.step += 1;
        }
        c += self.stages.exit;
        let deadline_ps = self.ps(tick_cycle + self.timer.period_cycles());
        self.known_tick_ps = (k + 1, deadline_ps);
        // Stages that did not run end where the schedule did (usually the decode's end): one
        // conversion to picoseconds serves them all.
        let decode_end_ps = self.ps(decode_end);
        let [attitude_end_ps, euler_end_ps, nav_end_ps] = match stage_ends {
            Some(ends) => ends.map(|e| self.ps(e)),
            None if schedule_end == decode_end => [decode_end_ps; 3],
            None => [self.ps(schedule_end); 3],
        };
        self.out.budget.push(BudgetRow {
            tick: k,
            tick_ps,
            start_ps: if start == tick_cycle { tick_ps } else { self.ps(start) },
            entry_end_ps: self.ps(entry_end),
            spi_start_ps: bursts[0].t_start_ps,
            spi_end_ps,
            decode_end_ps,
            attitude_end_ps,
            euler_end_ps,
            nav_end_ps,
            end_ps: self.ps(c),
            deadline_ps,
            step: step_ready,
            overrun,
        });
        Ok(c)
    }

    /// Tick `k` is not serviced (`kind`, `why`): an error event and a skipped budget row.
    #[cold]
    fn skip_tick(&mut self, k: u64, tick_ps: Ps, kind: &'static str, why: &str) {
        self.events.push(Event::new(tick_ps, kind, Severity::Error, format!("tick {k}: {why}")));
        self.out.budget.push(BudgetRow::skipped(k, tick_ps));
    }

    /// Fill the step's rate samples from this tick's decoded bursts; true when a step is ready.
    fn schedule(&mut self, decoded: &[Vec3<T>; 3], c: &mut u64) -> bool {
        match self.profile.firmware.schedule {
            Schedule::HalfStep => {
                self.rates[self.have] = decoded[0];
                self.have += 1;
                if self.have == 3 {
                    self.have = 1; // the step's last sample is the next step's first
                    return true;
                }
                false
            }
            Schedule::Endpoint => {
                if self.have == 0 {
                    self.rates[0] = decoded[0];
                    self.have = 1;
                    return false;
                }
                let half = T::from_f64(0.5, crate::numerics::QClass::Generic);
                let a = self.rates[0];
                let b = decoded[0];
                self.rates[1] = std::array::from_fn(|i| ((a[i] + b[i]) * half).to_class(crate::numerics::QClass::Rate));
                self.rates[2] = b;
                *c += self.stages.interpolation.cycles;
                true
            }
            Schedule::BackToBack => {
                self.rates = *decoded;
                true
            }
        }
    }

    /// One 15-frame burst read as the published code performs it; `b` (as [`Burst::EMPTY`]) is
    /// filled with what it gave the firmware. `c` is the CPU cycle, advanced by the code's costs.
    fn burst(&mut self, c: &mut u64, k: u64, b: &mut Burst) -> Result<()> {
        *c += u64::from(self.io.gpio_write);
        let t_cs = self.ps(*c);
        // A nested ISR's burst finds CS already low (asserted by the burst it interrupted).
        let cs_falls = !self.link.cs_asserted();
        self.link.set_gpio57(false, t_cs)?;
        let mut glitch = if t_cs >= self.glitches.watch_from { self.glitches.take(t_cs) } else { None };
        b.t_cs_ps = t_cs;
        // Nothing can come between the words (no CS glitch, no nested ISR): the word loop in whole
        // CPU cycles, in two calls to the link: the command, then the fill words as one run of
        // characters. The read record needs the first data frame: the sensor keeps the second frame
        // since CS fell, which is that frame when CS falls here.
        match &self.polled_loop {
            Some(cpu) if cs_falls && glitch.is_none() && !self.may_nest() && self.link.polled_burst_applies(t_cs) => {
                let (poll, read_cost) = (&self.poller, u64::from(self.io.peripheral_read));
                // From the write to the end of the read (the poll's length depends on the wait alone).
                let read_after =
                    |write, wait| Ok(poll.until_cycle(write, write + wait, "INT_FLAG = 1")? + read_cost - write);
                let command = [self.profile.device.burst_command as u16];
                let [answer] =
                    self.link.polled_burst(command, c, cpu, read_after, |_, slave| b.note_frame(0, slave))?;
                let data: [u16; BURST_FRAMES - 1] =
                    self.link.polled_run(BURST_FILL, c, cpu, read_after, &mut self.poll_steps)?;
                let sensor = self.link.slave();
                b.note(1, sensor.second_frame());
                b.note(BURST_FRAMES - 1, sensor.last_frame());
                b.words[0] = answer;
                b.words[1..].copy_from_slice(&data);
            }
            _ => self.burst_word_by_word(c, k, b, &mut glitch)?,
        }
        *c += u64::from(self.io.gpio_write);
        b.t_cs_rise_ps = self.ps(*c);
        if let Some(g) = glitch.as_mut() {
            self.end_glitch_before(g, b.t_cs_rise_ps)?;
        }
        self.link.set_gpio57(true, b.t_cs_rise_ps)
    }

    /// The burst's words one at a time through the register-level steps, with a CS glitch or a
    /// nested ISR possible between them.
    fn burst_word_by_word(
        &mut self,
        c: &mut u64,
        k: u64,
        b: &mut Burst,
        glitch: &mut Option<glitch::BurstGlitch>,
    ) -> Result<()> {
        let cmd = self.profile.device.burst_command as u16;
        // Copied once per burst, not per frame (the clock is 48 bytes).
        let (poll, read_cost) = (self.poller, u64::from(self.io.peripheral_read));
        // The latest CPU cycle whose time is known (CS↓, then each fast-path read): see `until_seen`.
        let mut seen = (*c, b.t_cs_ps);
        for i in 0..BURST_FRAMES {
            // if (Spi_TxReady() == 1) SPITXBUF = sdata;  — wait for BUFFULL_FLAG = 0
            let ready = self.link.buffull_clear_time();
            *c = poll.until_seen(*c, ready, seen, "BUFFULL_FLAG = 0")?;
            *c += u64::from(self.io.peripheral_write);
            let word = if i == 0 { cmd } else { BURST_FILL };
            if let Some(g) = glitch.as_mut() {
                // The CS line may fall back between the write and the read: the register path.
                self.end_glitch_before(g, self.ps(*c))?;
                self.link.write(SPITXBUF, word, self.ps(*c))?;
                // while (Spi_RxReady() != 1) {}  — wait for INT_FLAG = 1, then read SPIRXBUF
                let done = self.link.int_flag_time();
                *c = poll.until(*c, done, "INT_FLAG = 1")? + read_cost;
                self.end_glitch_before(g, self.ps(*c))?;
                b.words[i] = self.link.read(SPIRXBUF, self.ps(*c))?;
            } else {
                // The same write, INT_FLAG poll and read, in one call to the link.
                let mut read_cycle = *c;
                b.words[i] = self.link.write_poll_read(word, self.ps(*c), |done| {
                    read_cycle = poll.until_flag(read_cycle, done, "INT_FLAG = 1")? + read_cost;
                    seen = (read_cycle, poll.sysclk.cycles_to_ps(read_cycle));
                    Ok(seen.1)
                })?;
                *c = read_cycle;
            }
            *c += u64::from(self.io.store_word + self.io.frame_loop);
            b.note_frame(i, self.link.slave());
            if let Some(g) = glitch.as_mut().filter(|g| g.after_frame == i) {
                self.raise_glitch(g, self.ps(*c))?;
            }
            self.maybe_nest(c, k)?;
        }
        Ok(())
    }

    /// A `dropped_burst` fault: the CS line goes high at `t`, in the middle of the burst.
    #[cold]
    fn raise_glitch(&mut self, g: &mut glitch::BurstGlitch, t: Ps) -> Result<()> {
        g.rise = Some(t);
        self.link.set_gpio57(true, t)?;
        let how_long = g.length.map_or("until the firmware raises CS at the end of the burst".to_string(), |l| {
            format!("for {:.3} µs", l as f64 / 1e6)
        });
        self.events.push(Event::new(
            t,
            "fault_injected",
            Severity::Warning,
            format!(
                "{}: CS high after frame {} of the burst of tick {}, {how_long}",
                crate::device::describe_fault(&g.fault),
                g.after_frame,
                self.tick
            ),
        ));
        Ok(())
    }

    /// The glitch's CS line falls back at its time if that is before `t` (the next bus access).
    fn end_glitch_before(&mut self, g: &mut glitch::BurstGlitch, t: Ps) -> Result<()> {
        if let Some(back) = g.pending_return().filter(|&back| back <= t) {
            g.returned = true;
            self.link.set_gpio57(false, back)?;
        }
        Ok(())
    }

    fn record_read(&mut self, tick: u64, burst: usize, b: &Burst, rate: &Vec3<T>, accel: &Vec3<T>) {
        let period_s = self.tick_period_s;
        let assumed_s = match self.profile.firmware.schedule {
            Schedule::HalfStep | Schedule::Endpoint => tick as f64 * period_s,
            // Three bursts treated as t, t+T/2, t+T of the step ending at this tick.
            Schedule::BackToBack => (tick as f64 - 1.0 + burst as f64 / 2.0) * period_s,
        };
        self.out.reads.push(ReadRow {
            tick,
            t_cs_ps: b.t_cs_ps,
            t_start_ps: b.t_start_ps,
            t_end_ps: b.t_end_ps,
            words: b.words,
            rate: rate.map(|x| x.to_f64()),
            accel: accel.map(|x| x.to_f64()),
            sample_index: b.sample_index.map_or(-1, |i| i as i64),
            sample_ps: b.sample_ps,
            assumed_s,
            age_ps: b.age_ps,
        });
    }

    fn record_cycle(&mut self, t_ps: Ps, e: &crate::firmware::EulerAngles<T>) {
        let q = self.fw.quat();
        let nav = self.fw.nav_state();
        let row = CycleRow {
            step: self.step,
            t_ps,
            quat: q.map(|x| x.to_f64()),
            euler_deg: [e.roll.to_f64().to_degrees(), e.pitch.to_f64().to_degrees(), e.yaw.to_f64().to_degrees()],
            vel_enu: nav.vel.map(|x| x.to_f64()),
            pos: [nav.lat.to_f64().to_degrees(), nav.lon.to_f64().to_degrees(), nav.height.to_f64()],
        };
        if self.state_in_range && !state_check::in_range(&row) {
            self.report_state_out_of_range(&row);
        }
        self.out.cycles.push(row);
    }

    /// The first step whose firmware state is out of range: one error event naming what (later
    /// steps are not checked: the state does not come back from there on its own).
    #[cold]
    #[inline(never)]
    fn report_state_out_of_range(&mut self, row: &CycleRow) {
        self.state_in_range = false;
        let (value, limit, what) = state_check::describe(row);
        self.events.push(Event::rule(
            row.t_ps,
            "state_out_of_range",
            Severity::Error,
            format!(
                "step {} at {:.3} s: the firmware state is out of range: {what}; the output is no navigation \
                 solution from here",
                row.step,
                ps_to_s(row.t_ps)
            ),
            value,
            limit,
        ));
    }

    /// Move the models' events into the output, in time order.
    fn collect_events(&mut self) {
        let mut all = self.events.drain();
        all.extend(self.link.drain_events());
        all.extend(self.link.slave_mut().drain_events());
        all.sort_by_key(|e| e.t_ps);
        self.out.events.extend(all);
    }
}

/// The timing of the firmware's status-polling loops (a copy, so it can be used while the link is
/// borrowed).
#[derive(Clone, Copy)]
struct Poller {
    sysclk: Clock,
    /// `timing.poll_loop_cycles`, as a divisor (one division per poll).
    poll_cycles: Divisor,
    /// SYSCLKOUT cycles per LSPCLK cycle, when whole (always on this board: LSPCLK is SYSCLKOUT
    /// divided by 2·LOSPCP, or SYSCLKOUT): see [`Clock::cycles_per_cycle_of`].
    sysclk_per_lspclk: Option<u64>,
}

// The per-frame helpers below are `inline(always)`: they are a few instructions each, and left to
// its heuristics the compiler kept them out of line (a call per poll, measured with callgrind).
impl Poller {
    /// A status-polling loop starting at cycle `c`: each iteration (call, register read, test,
    /// branch) takes `poll_loop_cycles` and reads the register at its start; the loop exits at the
    /// end of the first iteration whose read sees the flag (set at `flag_ps`).
    #[inline]
    fn until(&self, c: u64, flag_ps: Option<Ps>, what: &str) -> Result<u64> {
        let Some(flag_ps) = flag_ps else {
            return Err(self.hang(c, what, false));
        };
        self.until_cycle(c, self.sysclk.ps_to_cycles_ceil(flag_ps), what)
    }

    /// [`Poller::until`] when cycle `seen.0` ≤ `c` is known to start at `seen.1` ps: a flag set by then
    /// (BUFFULL, clear since the previous read) ends the loop after one iteration without a
    /// conversion, exactly as `until` finds (⌈f/P⌉ ≤ seen.0 when f ≤ ⌊seen.0·P⌋, f whole).
    #[inline(always)]
    fn until_seen(&self, c: u64, flag_ps: Option<Ps>, seen: (u64, Ps), what: &str) -> Result<u64> {
        match flag_ps {
            Some(f) if f <= seen.1 && seen.0 <= c => Ok(c + self.poll_cycles.get()),
            _ => self.until(c, flag_ps, what),
        }
    }

    /// [`Poller::until`] for a flag SPI-A sets on an LSPCLK cycle it names (a character's end): its
    /// SYSCLKOUT cycle is then a product, not a conversion from picoseconds.
    #[inline(always)]
    fn until_flag(&self, c: u64, flag: Option<FlagTime>, what: &str) -> Result<u64> {
        let Some(flag) = flag else {
            return Err(self.hang(c, what, false));
        };
        let flag_cycle = match (flag.lspclk_cycle, self.sysclk_per_lspclk) {
            (Some(n), Some(k)) => n * k,
            _ => self.sysclk.ps_to_cycles_ceil(flag.ps),
        };
        self.until_cycle(c, flag_cycle, what)
    }

    /// A polling loop from cycle `c` for a flag that sets at SYSCLKOUT cycle boundary `flag_cycle`.
    #[inline(always)]
    fn until_cycle(&self, c: u64, flag_cycle: u64, what: &str) -> Result<u64> {
        let p = self.poll_cycles.get();
        let iterations = if flag_cycle <= c { 0 } else { self.poll_cycles.div_ceil(flag_cycle - c) };
        if iterations * p > POLL_WATCHDOG_CYCLES {
            return Err(self.hang(c, what, true));
        }
        Ok(c + (iterations + 1) * p)
    }

    /// The error of a polling loop that does not end (out of line: the poll is on the per-frame path).
    #[cold]
    #[inline(never)]
    fn hang(&self, c: u64, what: &str, watchdog: bool) -> Error {
        let t_s = ps_to_s(self.sysclk.cycles_to_ps(c));
        Error::Config(if watchdog {
            format!("firmware polls {what} for over a second at {t_s:.6} s")
        } else {
            format!(
                "firmware hangs at {t_s:.6} s: polling for {what}, which never happens (is SPI-A released from reset?)"
            )
        })
    }
}

/// What one burst read gave the firmware.
#[derive(Debug, Clone, Copy)]
struct Burst {
    words: [u16; BURST_FRAMES],
    t_cs_ps: Ps,
    /// CS rising at the end of the burst.
    t_cs_rise_ps: Ps,
    t_start_ps: Ps,
    t_end_ps: Ps,
    sample_index: Option<u64>,
    sample_ps: Ps,
    age_ps: Ps,
}

impl Burst {
    /// Nothing read yet.
    const EMPTY: Burst = Burst {
        words: [0; BURST_FRAMES],
        t_cs_ps: 0,
        t_cs_rise_ps: 0,
        t_start_ps: 0,
        t_end_ps: 0,
        sample_index: None,
        sample_ps: 0,
        age_ps: 0,
    };

    /// What the read record needs from the sensor's latest frame after word `i`. Only the first,
    /// second and last words matter, and they are noted before a nested ISR can clock frames of its own.
    #[inline(always)]
    fn note_frame<S: Sensor>(&mut self, i: usize, sensor: &S) {
        if i < 2 || i == BURST_FRAMES - 1 {
            self.note(i, sensor.last_frame());
        }
    }

    /// What the read record needs from word `i`'s frame `frame`.
    #[inline(always)]
    fn note(&mut self, i: usize, frame: Option<FrameSummary>) {
        if let Some(f) = frame {
            if i == 0 {
                self.t_start_ps = f.t_start;
            }
            if i == 1 {
                // Every data word of a burst comes from the sample latest at the burst's start (the
                // device latches it at the command frame); its age is counted from there.
                self.sample_index = f.sample.map(|x| x.index);
                self.sample_ps = f.sample.map_or(f.t_start, |x| x.t);
                self.age_ps = self.t_start_ps.saturating_sub(self.sample_ps);
            }
            self.t_end_ps = f.t_end;
        }
    }
}

#[cfg(test)]
mod poller_tests {
    use super::*;

    /// The shortcuts of the poller (a flag already seen, a flag on a named LSPCLK cycle) give the
    /// cycle the plain conversion from picoseconds gives, for every LOSPCP and poll length.
    #[test]
    fn shortcuts_equal_the_conversion_from_picoseconds() {
        let sysclk = Clock::from_hz(150_000_000);
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        for lospcp in 0..8u64 {
            // LSPCLK = SYSCLKOUT / (2·LOSPCP), or SYSCLKOUT for LOSPCP = 0.
            let k = if lospcp == 0 { 1 } else { 2 * lospcp };
            let lspclk = sysclk.divided(k);
            for poll in [1, 7, 12] {
                let poller = Poller {
                    sysclk,
                    poll_cycles: Divisor::new(poll),
                    sysclk_per_lspclk: sysclk.cycles_per_cycle_of(lspclk),
                };
                assert_eq!(poller.sysclk_per_lspclk, Some(k));
                for _ in 0..2_000 {
                    x = x.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
                    let c = (x >> 24) % 10_000_000_000;
                    // A flag from a few LSPCLK cycles before `c` to a few thousand after.
                    let end_cycle = (c / k + (x >> 8) % 4_000).saturating_sub(3);
                    let end_ps = lspclk.cycles_to_ps(end_cycle);
                    let flag = FlagTime { ps: end_ps, lspclk_cycle: Some(end_cycle) };
                    let plain = poller.until(c, Some(end_ps), "flag").unwrap();
                    assert_eq!(poller.until_flag(c, Some(flag), "flag").unwrap(), plain, "LOSPCP {lospcp}");
                    let seen = (c - (x & 0xFF).min(c), 0);
                    let seen = (seen.0, sysclk.cycles_to_ps(seen.0));
                    for f in [seen.1.saturating_sub(1), seen.1, seen.1 + 1, end_ps] {
                        let plain = poller.until(c, Some(f), "flag").unwrap();
                        assert_eq!(poller.until_seen(c, Some(f), seen, "flag").unwrap(), plain, "{f} {seen:?}");
                    }
                }
            }
        }
    }
}
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_faults;
#[cfg(test)]
mod tests_replay;
