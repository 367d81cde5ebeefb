//! The firmware's acquisition interrupt: CPU timer 0 raises it; the ISR drives SPI-A exactly as the
//! published code does (CS low on GPIO57, poll BUFFULL, write SPITXBUF, poll INT_FLAG, read
//! SPIRXBUF, …, CS high), hands the words to the decode, gathers the attitude update's samples by the
//! profile's schedule (`schedule.rs`) and runs the stages (attitude update, Euler extraction,
//! navigation), each costing the cycles the timing model gives it. It reaches the board only through
//! [`Board`]: the CPU timer, SPI-A and the chip-select GPIO.
//!
//! The ISR writes what it did to the run output (one budget row per tick, one read row per burst,
//! one cycle row per update) and its events; the emulator decides when it runs (`emulator`).

pub use super::application::{StageCost, StageCosts};
use super::schedule::{RateSchedule, MAX_SAMPLES};
use super::{samples_per_update, Firmware, Vec3};
use crate::board::glitch;
use crate::board::{Board, FrameSummary, Sensor};
use crate::dsp::spi::{FlagTime, PollSteps, PolledLoop, SPIRXBUF, SPITXBUF};
use crate::error::{Error, Result};
use crate::events::{Event, EventLog, Severity};
use crate::numerics::Scalar;
use crate::output::{BudgetRow, CycleRow, Output, ReadRow};
use crate::profile::{InitialAttitude, OverrunPolicy, Profile};
use crate::time::{ps_to_s, Clock, Divisor, Ps};
use crate::timing::costs::IoCosts;

/// Frames of the longest burst read: the command and the 14 output registers of the ADIS16407 (the
/// read row keeps them all: one declaration, [`crate::output::READ_WORDS`]). A part with a shorter
/// burst (the ADIS16362: the command and 11 registers) is read in its own number of frames, the
/// words past them left 0.
pub const BURST_FRAMES: usize = crate::output::READ_WORDS;
/// Index in the burst of X/Y/Z GYRO_OUT and X/Y/Z ACCL_OUT (frame 0 is the command).
const FIRST_INERTIAL: usize = 2;
/// DIN the firmware sends in the 14 data frames of a burst (don't care for the device).
const BURST_FILL: u16 = 0x0000;
/// A poll that has not seen its flag after this many SYSCLKOUT cycles is a hung firmware.
const POLL_WATCHDOG_CYCLES: u64 = 150_000_000;

/// The firmware running on the board: its state and stages ([`Firmware`]), its acquisition schedule,
/// and what the timing model says each of its parts costs.
pub struct Isr<T: Scalar> {
    fw: Firmware<T>,
    stages: StageCosts,
    io: IoCosts,
    overrun: OverrunPolicy,
    burst_command: u16,
    /// Frames of one burst read: the command and the part's burst words (`Part::burst_frames`).
    burst_frames: usize,
    /// The firmware's status-polling loops.
    poller: Poller,
    /// The burst's word loop in CPU cycles, when SYSCLKOUT is a whole multiple of LSPCLK.
    polled_loop: Option<PolledLoop>,
    /// The fill-word runs' steps per write phase, for the burst's poll and read (fixed per emulator).
    poll_steps: PollSteps,
    /// The update's samples being gathered.
    schedule: RateSchedule<T>,
    bursts_per_tick: usize,
    /// The timer period, s (as the read rows' assumed sample times use it).
    tick_period_s: f64,
    /// The next tick no ISR has serviced yet (ticks serviced by a nested ISR are skipped).
    pub(crate) next_pending: u64,
    /// The tick of the outermost ISR running.
    outer_tick: u64,
    /// Nesting depth of the ISR being emulated (0: the outer one).
    depth: u8,
    /// Nested ISRs so far.
    pub(crate) nested: u64,
    /// Index of the next attitude step.
    step: u64,
    last_accel: Vec3<T>,
    aligning: bool,
    align_until_s: f64,
    /// The run output written so far.
    pub(crate) out: Output,
    /// The firmware's events (overruns, decode range, nested interrupts, injected glitches).
    pub(crate) events: EventLog,
}

impl<T: Scalar> Isr<T> {
    /// The firmware of a profile on `board`, with the stage and I/O costs of the timing model.
    pub fn new<S: Sensor>(profile: &Profile, board: &Board<S>, stages: StageCosts, io: &IoCosts) -> Result<Self> {
        let app = super::application::app_kind(&profile.firmware.application)?;
        if app != super::application::AppKind::AdisBurst {
            return Err(Error::Profile(format!(
                "key `firmware.application` = \"{}\": this is the \"adis-burst\" firmware's build",
                profile.firmware.application
            )));
        }
        let fw = Firmware::<T>::new(profile)?;
        let zero = T::from_f64(0.0, crate::numerics::QClass::Rate);
        let schedule = RateSchedule::new(profile.firmware.schedule, samples_per_update(&profile.firmware)?)?;
        let clocks = &board.clocks;
        let poller = Poller {
            sysclk: clocks.sysclkout,
            poll_cycles: Divisor::new(u64::from(profile.timing.poll_loop_cycles)),
            sysclk_per_lspclk: clocks.sysclkout.cycles_per_cycle_of(clocks.lspclk),
        };
        let burst_frames = profile.device.part_decl()?.burst_frames();
        if !(FIRST_INERTIAL + 6..=BURST_FRAMES).contains(&burst_frames) {
            return Err(Error::Profile(format!(
                "device.part: a burst of {burst_frames} frames; the firmware reads {}…{BURST_FRAMES}",
                FIRST_INERTIAL + 6
            )));
        }
        // X/Y/Z MAGN_OUT right after the six inertial words (burst words 8…10), by register name: the
        // ADIS16362 shifts X/Y/ZTEMP_OUT out at the same addresses.
        let part = profile.device.part_decl()?;
        let name_of = |addr: u8| part.registers.iter().find(|r| r.addr == addr).map(|r| r.name);
        let magnetometer_words = part.burst.get(FIRST_INERTIAL + 5..FIRST_INERTIAL + 8).is_some_and(|a| {
            a.iter().zip(["XMAGN_OUT", "YMAGN_OUT", "ZMAGN_OUT"]).all(|(&addr, want)| name_of(addr) == Some(want))
        });
        if fw.uses_magnetometer() && !magnetometer_words {
            return Err(Error::Profile(format!(
                "key `firmware.dcm.yaw_reference` = \"magnetometer\": the {} burst carries no X/Y/Z MAGN_OUT \
                 (expected \"gps\" or \"none\" on this part)",
                profile.device.part
            )));
        }
        // X/Y/ZTEMP_OUT at the same places, for the wing unit's temperature compensation.
        let temperature_words = part.burst.get(FIRST_INERTIAL + 5..FIRST_INERTIAL + 8).is_some_and(|a| {
            a.iter().zip(["XTEMP_OUT", "YTEMP_OUT", "ZTEMP_OUT"]).all(|(&addr, want)| name_of(addr) == Some(want))
        });
        if fw.uses_temperature() && !temperature_words {
            return Err(Error::Profile(format!(
                "key `firmware.wing.gyro_bias_tempco_dps_per_c`: the {} burst carries no X/Y/ZTEMP_OUT after \
                 the inertial words (expected [0, 0, 0] on this part)",
                profile.device.part
            )));
        }
        let mut isr = Isr {
            fw,
            stages,
            io: io.clone(),
            overrun: profile.firmware.overrun,
            burst_command: profile.device.burst_command as u16,
            burst_frames,
            polled_loop: poller.sysclk_per_lspclk.map(|k| PolledLoop {
                sysclk: clocks.sysclkout,
                sysclk_per_lspclk: Divisor::new(k),
                before_write: poller.poll_cycles.get() + u64::from(io.peripheral_write),
                after_read: u64::from(io.store_word + io.frame_loop),
            }),
            poller,
            poll_steps: PollSteps::default(),
            bursts_per_tick: schedule.bursts_per_tick(),
            schedule,
            tick_period_s: ps_to_s(board.timer.tick_ps(1)),
            next_pending: 1,
            outer_tick: 0,
            depth: 0,
            nested: 0,
            step: 0,
            last_accel: [zero; 3],
            aligning: profile.firmware.initial_attitude == InitialAttitude::Level,
            align_until_s: profile.firmware.alignment_s,
            out: Output::default(),
            events: EventLog::default(),
        };
        for (kind, message) in isr.fw.attitude_notices() {
            isr.events.push(Event::new(0, kind, Severity::Warning, message));
        }
        Ok(isr)
    }

    /// The compute-stage costs in use.
    pub fn stage_costs(&self) -> &StageCosts {
        &self.stages
    }

    /// The firmware's variables (the GPS stream's fixes; tests that force a state).
    #[cfg_attr(not(test), allow(dead_code))]
    pub(crate) fn firmware_mut(&mut self) -> &mut Firmware<T> {
        &mut self.fw
    }

    /// Bursts the ISR reads every tick.
    pub fn bursts_per_tick(&self) -> usize {
        self.bursts_per_tick
    }

    /// What a tick arriving while the ISR runs does (`firmware.overrun`).
    pub fn overrun(&self) -> OverrunPolicy {
        self.overrun
    }

    /// Under `firmware.overrun = "nest"` the ISR re-enables interrupts (EINT) after its entry: a tick
    /// that has arrived is taken at the next interruptible point (after each burst frame, after the
    /// decode, after the attitude update) and runs to completion there, at depth one (the nested ISR
    /// does not re-enable them: one level). Nothing happens under the other policies. Inline: it runs
    /// after every burst frame and usually only tests the policy.
    #[inline]
    fn maybe_nest<S: Sensor>(&mut self, board: &mut Board<S>, c: &mut u64, k: u64) -> Result<()> {
        if !self.may_nest() {
            return Ok(());
        }
        self.nest_if_due(board, c, k)
    }

    /// Whether a tick may preempt the running ISR (`nest` policy, not already nested).
    fn may_nest(&self) -> bool {
        self.overrun == OverrunPolicy::Nest && self.depth == 0
    }

    /// The nested ISR of [`Isr::maybe_nest`], if a tick has arrived (out of line, so the policy
    /// test inlines into the per-frame loop).
    #[inline(never)]
    fn nest_if_due<S: Sensor>(&mut self, board: &mut Board<S>, c: &mut u64, k: u64) -> Result<()> {
        // One nested ISR per interruptible point. On the chip a tick that arrives during a nested ISR
        // is taken right after its IRET, so an ISR longer than the period starves the outer one for
        // ever; here the outer one runs on to its next interruptible point first (documented), so
        // every ISR ends and the starvation shows as a nested ISR at every point.
        if board.tick_cycle(self.next_pending) <= *c {
            let inner = self.next_pending;
            self.next_pending += 1;
            self.nested += 1;
            self.events.push(Event::new(
                board.ps(*c),
                "nested_interrupt",
                Severity::Warning,
                format!("tick {inner} preempts the ISR of tick {k}: it runs inside it (SPI-A and the firmware state are shared)"),
            ));
            self.depth += 1;
            let end = self.isr(board, inner, board.tick_ps(inner), *c, true);
            self.depth -= 1;
            *c = end?;
        }
        Ok(())
    }

    /// One ISR of tick `k` (arrived at `tick_ps`) from cycle `start`; returns the cycle it ends at.
    pub fn isr<S: Sensor>(
        &mut self,
        board: &mut Board<S>,
        k: u64,
        tick_ps: Ps,
        start: u64,
        overrun: bool,
    ) -> Result<u64> {
        if self.depth == 0 {
            self.outer_tick = k;
        }
        let tick_cycle = board.tick_cycle(k);
        let mut c = start + self.stages.entry;
        let entry_end = c;
        let mut all = [Burst::default(); MAX_SAMPLES];
        let bursts = &mut all[..self.bursts_per_tick];
        for b in bursts.iter_mut() {
            self.burst(board, &mut c, k, b)?;
        }
        // The SPI part ends where the CPU raised CS at the end of the last burst: that edge's time.
        let spi_end_ps = bursts[bursts.len() - 1].t_cs_rise_ps;

        // Decode every burst of the tick.
        let mut decoded = [[T::from_f64(0.0, crate::numerics::QClass::Rate); 3]; MAX_SAMPLES];
        for b in 0..bursts.len() {
            let inertial: [u16; 6] = std::array::from_fn(|i| bursts[b].words[FIRST_INERTIAL + i]);
            let d = self.fw.decode(&inertial);
            if self.fw.uses_magnetometer() {
                self.fw.decode_magnetometer(&std::array::from_fn(|i| bursts[b].words[FIRST_INERTIAL + 6 + i]));
            }
            if self.fw.uses_temperature() {
                self.fw.decode_temperature(&std::array::from_fn(|i| bursts[b].words[FIRST_INERTIAL + 6 + i]));
            }
            if !d.report.is_clean() {
                d.report.push_events(board.ps(c), &inertial, &mut self.events);
            }
            c += self.stages.decode.cycles;
            decoded[b] = d.rate;
            self.last_accel = d.accel;
            self.record_read(k, b, &bursts[b], &d.rate, &d.accel);
        }
        self.maybe_nest(board, &mut c, k)?;
        let decode_end = c;

        // Assemble the step's rate samples according to the schedule.
        let (step_ready, interpolated) = self.schedule.add(&decoded[..bursts.len()]);
        if interpolated {
            c += self.stages.interpolation.cycles;
        }
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
                // The latest GPS fix that has reached the board by now (its time plus its latency).
                self.fw.receive_gps(ps_to_s(board.ps(c)));
                self.fw.update_attitude(self.schedule.rates())?;
                let (events, t_ps) = (&mut self.events, board.ps(c));
                self.fw.drain_attitude_events(&mut |kind, severity, message| {
                    events.push(Event::new(t_ps, kind, severity, message))
                });
                c += self.stages.attitude.cycles;
                self.maybe_nest(board, &mut c, k)?;
                let attitude_end = c;
                let e = self.fw.euler();
                c += self.stages.euler.cycles;
                let euler_end = c;
                self.fw.navigate(&self.last_accel);
                c += self.stages.navigation.cycles;
                stage_ends = Some([attitude_end, euler_end, c]);
                self.record_cycle(tick_ps, &e);
            }
            self.schedule.advance();
            self.step += 1;
        }
        c += self.stages.exit;
        let deadline_ps = board.ps(tick_cycle + board.timer.period_cycles());
        // Stages that did not run end where the schedule did (usually the decode's end): one
        // conversion to picoseconds serves them all.
        let decode_end_ps = board.ps(decode_end);
        let [attitude_end_ps, euler_end_ps, nav_end_ps] = match stage_ends {
            Some(ends) => ends.map(|e| board.ps(e)),
            None if schedule_end == decode_end => [decode_end_ps; 3],
            None => [board.ps(schedule_end); 3],
        };
        self.out.budget.push(BudgetRow {
            tick: k,
            tick_ps,
            start_ps: if start == tick_cycle { tick_ps } else { board.ps(start) },
            entry_end_ps: board.ps(entry_end),
            spi_start_ps: bursts[0].t_start_ps,
            spi_end_ps,
            decode_end_ps,
            attitude_end_ps,
            euler_end_ps,
            nav_end_ps,
            end_ps: board.ps(c),
            deadline_ps,
            step: step_ready,
            overrun,
        });
        Ok(c)
    }

    /// One 15-frame burst read as the published code performs it; `b` (nothing read yet) is
    /// filled with what it gave the firmware. `c` is the CPU cycle, advanced by the code's costs.
    fn burst<S: Sensor>(&mut self, board: &mut Board<S>, c: &mut u64, k: u64, b: &mut Burst) -> Result<()> {
        *c += u64::from(self.io.gpio_write);
        let t_cs = board.ps(*c);
        // A nested ISR's burst finds CS already low (asserted by the burst it interrupted).
        let cs_falls = !board.link.cs_asserted();
        board.link.set_gpio57(false, t_cs)?;
        let mut glitch = if t_cs >= board.glitches.watch_from { board.glitches.take(t_cs) } else { None };
        b.t_cs_ps = t_cs;
        // Nothing can come between the words (no CS glitch, no nested ISR): the word loop in whole
        // CPU cycles, in two calls to the link: the command, then the fill words as one run of
        // characters. The read record needs the first data frame: the sensor keeps the second frame
        // since CS fell, which is that frame when CS falls here.
        match &self.polled_loop {
            Some(cpu)
                if cs_falls
                    && glitch.is_none()
                    && !self.may_nest()
                    && matches!(self.burst_frames, 12 | BURST_FRAMES)
                    && board.link.polled_burst_applies(t_cs) =>
            {
                let (poll, read_cost) = (&self.poller, u64::from(self.io.peripheral_read));
                // From the write to the end of the read (the poll's length depends on the wait alone).
                let read_after =
                    |write, wait| Ok(poll.until_cycle(write, write + wait, "INT_FLAG = 1")? + read_cost - write);
                let command = [self.burst_command];
                let [answer] =
                    board.link.polled_burst(command, c, cpu, read_after, |_, slave| b.note_frame(0, 0, slave))?;
                // The fill words as one run, of the part's length (the run's length is a constant of
                // the fast path: the two burst lengths of the parts declared today).
                let n = self.burst_frames;
                let steps = &mut self.poll_steps;
                if n == BURST_FRAMES {
                    let data: [u16; BURST_FRAMES - 1] = board.link.polled_run(BURST_FILL, c, cpu, read_after, steps)?;
                    b.words[1..n].copy_from_slice(&data);
                } else {
                    let data: [u16; 11] = board.link.polled_run(BURST_FILL, c, cpu, read_after, steps)?;
                    b.words[1..n].copy_from_slice(&data);
                }
                let sensor = board.link.slave();
                b.note(1, sensor.second_frame());
                b.note(n - 1, sensor.last_frame());
                b.words[0] = answer;
            }
            _ => self.burst_word_by_word(board, c, k, b, &mut glitch)?,
        }
        *c += u64::from(self.io.gpio_write);
        b.t_cs_rise_ps = board.ps(*c);
        if let Some(g) = glitch.as_mut() {
            board.end_glitch_before(g, b.t_cs_rise_ps)?;
        }
        board.link.set_gpio57(true, b.t_cs_rise_ps)
    }

    /// The burst's words one at a time through the register-level steps, with a CS glitch or a
    /// nested ISR possible between them.
    fn burst_word_by_word<S: Sensor>(
        &mut self,
        board: &mut Board<S>,
        c: &mut u64,
        k: u64,
        b: &mut Burst,
        glitch: &mut Option<glitch::BurstGlitch>,
    ) -> Result<()> {
        let cmd = self.burst_command;
        // Copied once per burst, not per frame (the clock is 48 bytes).
        let (poll, read_cost) = (self.poller, u64::from(self.io.peripheral_read));
        // The latest CPU cycle whose time is known (CS↓, then each fast-path read): see `until_seen`.
        let mut seen = (*c, b.t_cs_ps);
        for i in 0..self.burst_frames {
            // if (Spi_TxReady() == 1) SPITXBUF = sdata;  — wait for BUFFULL_FLAG = 0
            let ready = board.link.buffull_clear_time();
            *c = poll.until_seen(*c, ready, seen, "BUFFULL_FLAG = 0")?;
            *c += u64::from(self.io.peripheral_write);
            let word = if i == 0 { cmd } else { BURST_FILL };
            if let Some(g) = glitch.as_mut() {
                // The CS line may fall back between the write and the read: the register path.
                board.end_glitch_before(g, board.ps(*c))?;
                board.link.write(SPITXBUF, word, board.ps(*c))?;
                // while (Spi_RxReady() != 1) {}  — wait for INT_FLAG = 1, then read SPIRXBUF
                let done = board.link.int_flag_time();
                *c = poll.until(*c, done, "INT_FLAG = 1")? + read_cost;
                board.end_glitch_before(g, board.ps(*c))?;
                b.words[i] = board.link.read(SPIRXBUF, board.ps(*c))?;
            } else {
                // The same write, INT_FLAG poll and read, in one call to the link.
                let mut read_cycle = *c;
                b.words[i] = board.link.write_poll_read(word, board.ps(*c), |done| {
                    read_cycle = poll.until_flag(read_cycle, done, "INT_FLAG = 1")? + read_cost;
                    seen = (read_cycle, poll.sysclk.cycles_to_ps(read_cycle));
                    Ok(seen.1)
                })?;
                *c = read_cycle;
            }
            *c += u64::from(self.io.store_word + self.io.frame_loop);
            b.note_frame(i, self.burst_frames - 1, board.link.slave());
            if let Some(g) = glitch.as_mut().filter(|g| g.after_frame == i) {
                board.raise_glitch(&mut self.events, self.outer_tick, g, board.ps(*c))?;
            }
            self.maybe_nest(board, c, k)?;
        }
        Ok(())
    }

    fn record_read(&mut self, tick: u64, burst: usize, b: &Burst, rate: &Vec3<T>, accel: &Vec3<T>) {
        let assumed_s = self.schedule.assumed_s(tick, burst, self.tick_period_s);
        self.out.reads.push(ReadRow {
            tick,
            t_cs_ps: b.t_cs_ps,
            t_start_ps: b.t_start_ps,
            t_end_ps: b.t_end_ps,
            words: b.words,
            rate: rate.map(|x| x.to_f64()),
            accel: accel.map(|x| x.to_f64()),
            sample_index: b.sample_index,
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
        self.out.cycles.push(row);
        self.fw.record_outputs(self.step, &mut self.out);
        if let Some(c) = self.fw.correction() {
            self.out.corrections.push(crate::output::CorrectionRow {
                step: self.step,
                omega_p: c.omega_p,
                omega_i: c.omega_i,
                error_rp: c.error_rp,
                error_yaw: c.error_yaw,
                orthogonality: c.orthogonality,
            });
        }
    }
}

impl<T: Scalar, S: Sensor> super::application::Application<S> for Isr<T> {
    #[inline]
    fn isr(&mut self, board: &mut Board<S>, k: u64, tick_ps: Ps, start: u64, overrun: bool) -> Result<u64> {
        Isr::isr(self, board, k, tick_ps, start, overrun)
    }
    fn overrun(&self) -> OverrunPolicy {
        self.overrun
    }
    fn reads_per_tick(&self) -> usize {
        self.bursts_per_tick
    }
    #[inline]
    fn next_pending(&self) -> u64 {
        self.next_pending
    }
    #[inline]
    fn set_next_pending(&mut self, k: u64) {
        self.next_pending = k;
    }
    #[inline]
    fn nested(&self) -> u64 {
        self.nested
    }
    #[inline]
    fn output(&mut self) -> &mut Output {
        &mut self.out
    }
    #[inline]
    fn events(&mut self) -> &mut EventLog {
        &mut self.events
    }
    fn stage_costs(&self) -> &StageCosts {
        &self.stages
    }
    fn push_gps(&mut self, fixes: &[super::GpsFix]) -> Result<()> {
        self.fw.push_gps(fixes)
    }
}

/// The timing of the firmware's status-polling loops (a copy, so it can be used while the link is
/// borrowed).
#[derive(Clone, Copy)]
pub(crate) struct Poller {
    pub(crate) sysclk: Clock,
    /// `timing.poll_loop_cycles`, as a divisor (one division per poll).
    poll_cycles: Divisor,
    /// SYSCLKOUT cycles per LSPCLK cycle, when whole (always on this board: LSPCLK is SYSCLKOUT
    /// divided by 2·LOSPCP, or SYSCLKOUT): see [`Clock::cycles_per_cycle_of`].
    sysclk_per_lspclk: Option<u64>,
}

// The per-frame helpers below are `inline(always)`: they are a few instructions each, and left to
// its heuristics the compiler kept them out of line (a call per poll, measured with callgrind).
impl Poller {
    /// The polling loops of a profile's firmware on `board` (`timing.poll_loop_cycles`).
    pub(crate) fn of<S: Sensor>(profile: &Profile, board: &Board<S>) -> Poller {
        let clocks = &board.clocks;
        Poller {
            sysclk: clocks.sysclkout,
            poll_cycles: Divisor::new(u64::from(profile.timing.poll_loop_cycles)),
            sysclk_per_lspclk: clocks.sysclkout.cycles_per_cycle_of(clocks.lspclk),
        }
    }

    /// A status-polling loop starting at cycle `c`: each iteration (call, register read, test,
    /// branch) takes `poll_loop_cycles` and reads the register at its start; the loop exits at the
    /// end of the first iteration whose read sees the flag (set at `flag_ps`).
    #[inline]
    pub(crate) fn until(&self, c: u64, flag_ps: Option<Ps>, what: &str) -> Result<u64> {
        let Some(flag_ps) = flag_ps else {
            return Err(self.hang(c, what, false));
        };
        self.until_cycle(c, self.sysclk.ps_to_cycles_ceil(flag_ps), what)
    }

    /// [`Poller::until`] when cycle `seen.0` ≤ `c` is known to start at `seen.1` ps: a flag set by then
    /// (BUFFULL, clear since the previous read) ends the loop after one iteration without a
    /// conversion, exactly as `until` finds (⌈f/P⌉ ≤ seen.0 when f ≤ ⌊seen.0·P⌋, f whole).
    #[inline(always)]
    pub(crate) fn until_seen(&self, c: u64, flag_ps: Option<Ps>, seen: (u64, Ps), what: &str) -> Result<u64> {
        match flag_ps {
            Some(f) if f <= seen.1 && seen.0 <= c => Ok(c + self.poll_cycles.get()),
            _ => self.until(c, flag_ps, what),
        }
    }

    /// [`Poller::until`] for a flag SPI-A sets on an LSPCLK cycle it names (a character's end): its
    /// SYSCLKOUT cycle is then a product, not a conversion from picoseconds.
    #[inline(always)]
    pub(crate) fn until_flag(&self, c: u64, flag: Option<FlagTime>, what: &str) -> Result<u64> {
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
    /// The sample the data words hold, −1 for none (as the read row keeps it).
    sample_index: i64,
    sample_ps: Ps,
    age_ps: Ps,
}

impl Default for Burst {
    /// Nothing read yet.
    fn default() -> Self {
        Burst {
            words: [0; BURST_FRAMES],
            t_cs_ps: 0,
            t_cs_rise_ps: 0,
            t_start_ps: 0,
            t_end_ps: 0,
            sample_index: -1,
            sample_ps: 0,
            age_ps: 0,
        }
    }
}

impl Burst {
    /// What the read record needs from the sensor's latest frame after word `i`. Only the first,
    /// second and last words matter, and they are noted before a nested ISR can clock frames of its own.
    #[inline(always)]
    fn note_frame<S: Sensor>(&mut self, i: usize, last: usize, sensor: &S) {
        if i < 2 || i == last {
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
                self.sample_index = f.sample.map_or(-1, |x| x.index as i64);
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
