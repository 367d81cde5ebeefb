//! The gyro-free vehicle board (issue 25, algorithms.md §4 and its corrections, thesis chapter 4):
//! an XC3S400AN acquisition node (MicroBlaze + PLB IP cores, [`node`]) reading seven ADXL345, an
//! HMC6343 and a GR-87, sending one packet per 5 ms ([`frame`], layout [unconfirmed]) over SPI to a
//! TMS320C6727B ([`dsp`]) that navigates ([`nav`], issue 23).
//!
//! [`Board`] runs the two processors tick by tick: `step` is one 5 ms cycle (the node's timer
//! interrupt, its packet, the DSP's packet interrupt); [`Budget`] gathers both processors' time
//! per rate class (200 Hz every tick, 10 Hz compass ticks, 1 Hz GPS ticks). A board dispatch
//! (`sins-fw board/budget/run`) plugs in through [`Board::new`] + [`Board::step`].

pub mod dsp;
pub mod frame;
pub mod nav;
pub mod node;
pub mod profile;

pub use dsp::{Dsp, DspOutput};
pub use frame::Packet;
pub use node::{Node, TickTiming};
pub use profile::GfsinsProfile;

use crate::device::{gps, hmc6343};
use crate::error::{Error, Result};
use crate::events::Event;
use crate::time::Ps;
use std::sync::Arc;

/// What the vehicle's parts feel at one time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Truth {
    /// Specific force at each ADXL345 (`array.parts` in order: in the thesis's layout 0–5 outer, 6
    /// centre), g, part axes (= body axes).
    pub array_g: [[f64; 3]; 7],
    /// What the compass sees.
    pub compass: hmc6343::Truth,
    /// What the GPS antenna sees.
    pub gps: gps::Truth,
}

/// The vehicle over time.
pub type Source = Arc<dyn Fn(Ps) -> Truth + Send + Sync>;

/// A vehicle given as samples, held from each sample's time to the next (a `synth vehicle` trace).
#[derive(Debug, Clone, PartialEq)]
pub struct Samples {
    t_ps: Vec<Ps>,
    rows: Vec<Truth>,
}

impl Samples {
    /// Samples at strictly increasing `t_ps` (the first at 0).
    pub fn new(t_ps: Vec<Ps>, rows: Vec<Truth>) -> Result<Samples> {
        if t_ps.is_empty() || t_ps.len() != rows.len() {
            return Err(Error::Input(format!("vehicle samples: {} times for {} rows", t_ps.len(), rows.len())));
        }
        if let Some(i) = t_ps.windows(2).position(|w| w[0] >= w[1]) {
            return Err(Error::Input(format!("vehicle samples: time of row {} does not increase", i + 1)));
        }
        Ok(Samples { t_ps, rows })
    }

    /// The sample in force at `t`.
    pub fn at(&self, t: Ps) -> Truth {
        let i = self.t_ps.partition_point(|&s| s <= t).saturating_sub(1);
        self.rows[i]
    }

    /// The last sample's time.
    pub fn end(&self) -> Ps {
        *self.t_ps.last().unwrap_or(&0)
    }

    /// As a source.
    pub fn source(self) -> Source {
        Arc::new(move |t| self.at(t))
    }
}

/// Most stages a processor's cycle is split into.
pub const MAX_STAGES: usize = 12;

/// One processor's time in one cycle split into named stages, in execution order, ps (the budget's
/// stage rows: each processor names its own, the budget shows whatever it finds). Fixed capacity so
/// a [`Step`] stays `Copy`; a stage pushed beyond [`MAX_STAGES`] is added to the last row.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Stages {
    names: [&'static str; MAX_STAGES],
    ps: [Ps; MAX_STAGES],
    len: usize,
}

impl Stages {
    /// Add a stage of `ps` named `name` (a name already there adds to its row).
    pub fn push(&mut self, name: &'static str, ps: Ps) {
        if let Some(i) = self.names[..self.len].iter().position(|&n| n == name) {
            self.ps[i] += ps;
        } else if self.len < MAX_STAGES {
            self.names[self.len] = name;
            self.ps[self.len] = ps;
            self.len += 1;
        } else {
            self.ps[MAX_STAGES - 1] += ps;
        }
    }

    /// The stages, in order.
    pub fn iter(&self) -> impl Iterator<Item = (&'static str, Ps)> + '_ {
        self.names[..self.len].iter().copied().zip(self.ps[..self.len].iter().copied())
    }

    /// Their sum, ps.
    pub fn total(&self) -> Ps {
        self.ps[..self.len].iter().sum()
    }
}

/// One 5 ms cycle of the board.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step {
    /// The node's tick.
    pub timing: TickTiming,
    /// The packet it sent.
    pub packet: Packet,
    /// The DSP's output (`None`: packet refused).
    pub out: Option<DspOutput>,
}

impl Step {
    /// The DSP's packet handler by stage (none when the packet was refused): decode, strapdown,
    /// compass filter, GPS filter, fusion, as far as the packet ran them.
    pub fn dsp_stages(&self) -> Stages {
        self.out.map_or_else(Stages::default, |o| o.stages)
    }
}

/// The node and the DSP.
#[derive(Debug)]
pub struct Board {
    node: Node,
    dsp: Dsp,
}

impl Board {
    /// The board of `profile` on the vehicle `source`, powered up at 0.
    pub fn new(profile: &GfsinsProfile, source: Source) -> Result<Board> {
        let (a, c, g) = (source.clone(), source.clone(), source);
        let node = Node::new(
            profile,
            Arc::new(move |i, t| a(t).array_g[i]),
            Box::new(move |t| c(t).compass),
            Box::new(move |t| g(t).gps),
        )?;
        let dsp = Dsp::new(profile, node.period());
        Ok(Board { node, dsp })
    }

    /// One cycle.
    pub fn step(&mut self) -> Result<Step> {
        let (packet, timing) = self.node.tick()?;
        let out = self.dsp.receive(&packet.encode(), &timing);
        Ok(Step { timing, packet, out })
    }

    /// The node.
    pub fn node(&self) -> &Node {
        &self.node
    }

    /// The DSP.
    pub fn dsp(&self) -> &Dsp {
        &self.dsp
    }

    /// Take every event out (node, parts, links, DSP), in time order.
    pub fn drain_events(&mut self) -> Vec<Event> {
        let mut out = self.node.drain_events();
        out.extend(self.dsp.drain_events());
        out.sort_by_key(|e| e.t_ps);
        out
    }
}

/// The rate classes of the budget.
pub const CLASSES: [&str; 3] = ["200 Hz", "10 Hz", "1 Hz"];

/// One processor's time in one rate class.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ClassLoad {
    /// Ticks in the class.
    pub ticks: u64,
    /// The busiest tick's time, ps.
    pub peak_ps: Ps,
    /// Mean time per tick, ps.
    pub mean_ps: f64,
}

/// The processors of the budget, in [`Budget::load`]'s order.
pub const PROCESSORS: [&str; 2] = ["node", "dsp"];

/// One stage of one processor per rate class (ticks: the ticks of the class that ran it).
#[derive(Debug, Clone, PartialEq)]
pub struct StageLoad {
    /// Index into [`PROCESSORS`].
    pub processor: usize,
    /// The stage's name, as the processor gave it.
    pub name: &'static str,
    /// Per rate class.
    pub load: [ClassLoad; 3],
}

/// Both processors' time per rate class over a run: [node, DSP] × [`CLASSES`], in total and by stage.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Budget {
    /// The tick period, ps.
    pub period_ps: Ps,
    /// [node, DSP][class].
    pub load: [[ClassLoad; 3]; 2],
    /// Every stage either processor reported, the node's first, each in first-seen order.
    pub stages: Vec<StageLoad>,
}

impl Budget {
    /// The rate class of a step: 1 Hz when the node handled NMEA bytes (the GPS burst) or the DSP
    /// took a new fix, 10 Hz on the compass's three ticks, 200 Hz otherwise.
    pub fn class(step: &Step) -> usize {
        if step.timing.nmea_bytes > 0 || step.packet.flags & frame::NEW_GPS != 0 {
            2
        } else if step.timing.compass_phase < 3 {
            1
        } else {
            0
        }
    }

    /// The budget of `steps`.
    pub fn of(steps: &[Step], period_ps: Ps) -> Budget {
        let mut acc = BudgetAcc::new(period_ps);
        for s in steps {
            acc.add(s);
        }
        acc.budget()
    }
}

/// A [`Budget`] gathered step by step (a run streamed in blocks keeps this, not its steps).
#[derive(Debug, Clone, Default)]
pub struct BudgetAcc {
    b: Budget,
    sums: [[f64; 3]; 2],
    stage_sums: Vec<[f64; 3]>,
}

impl BudgetAcc {
    /// No step yet, at tick period `period_ps`.
    pub fn new(period_ps: Ps) -> BudgetAcc {
        BudgetAcc { b: Budget { period_ps, ..Budget::default() }, ..BudgetAcc::default() }
    }

    /// Add one step.
    pub fn add(&mut self, s: &Step) {
        let add = |l: &mut ClassLoad, sum: &mut f64, t: Ps| {
            l.ticks += 1;
            l.peak_ps = l.peak_ps.max(t);
            *sum += t as f64;
        };
        let b = &mut self.b;
        let c = Budget::class(s);
        let dsp_ps = s.out.map_or(0, |o| o.t_done - o.t_irq);
        for (p, t) in [s.timing.cpu_ps, dsp_ps].into_iter().enumerate() {
            add(&mut b.load[p][c], &mut self.sums[p][c], t);
        }
        for (p, stages) in [s.timing.stages, s.dsp_stages()].iter().enumerate() {
            let mut prev: Option<usize> = None;
            for (name, t) in stages.iter() {
                let i = match b.stages.iter().position(|r| r.processor == p && r.name == name) {
                    Some(i) => i,
                    None => {
                        // The node's rows before the DSP's; a stage first seen goes right after the
                        // stage that ran before it in this cycle, so the rows keep the execution
                        // order whichever rate's stages come first.
                        let at =
                            prev.map_or_else(|| b.stages.iter().take_while(|r| r.processor < p).count(), |i| i + 1);
                        b.stages.insert(at, StageLoad { processor: p, name, load: Default::default() });
                        self.stage_sums.insert(at, [0.0; 3]);
                        at
                    }
                };
                add(&mut b.stages[i].load[c], &mut self.stage_sums[i][c], t);
                prev = Some(i);
            }
        }
    }

    /// The budget of the steps added so far.
    pub fn budget(&self) -> Budget {
        let mut b = self.b.clone();
        let loads = b.load.iter_mut().flatten().zip(self.sums.iter().flatten());
        let stage_loads = b.stages.iter_mut().flat_map(|r| r.load.iter_mut()).zip(self.stage_sums.iter().flatten());
        for (l, sum) in loads.chain(stage_loads) {
            l.mean_ps = if l.ticks > 0 { sum / l.ticks as f64 } else { 0.0 };
        }
        b
    }
}

/// Vehicle samples pushed in chunks (a trace read a chunk at a time), held from each sample's time
/// to the next as [`Samples`] holds them; the rows older than the parts can still ask for are
/// dropped ([`Window::trim`]), so memory stays that of a few seconds of input.
#[derive(Debug, Clone, Default)]
pub struct Window {
    t_ps: Vec<Ps>,
    rows: Vec<Truth>,
    ended: bool,
}

impl Window {
    /// Append samples at strictly increasing times (after the last one pushed).
    pub fn push(&mut self, t_ps: &[Ps], rows: &[Truth]) -> Result<()> {
        if t_ps.len() != rows.len() {
            return Err(Error::Input(format!("vehicle samples: {} times for {} rows", t_ps.len(), rows.len())));
        }
        if self.ended {
            return Err(Error::Input("vehicle samples pushed after the end of the input".into()));
        }
        let mut prev = self.t_ps.last().copied();
        for (i, &t) in t_ps.iter().enumerate() {
            if prev.is_some_and(|p| p >= t) {
                return Err(Error::Input(format!("vehicle samples: time of row {i} of the chunk does not increase")));
            }
            prev = Some(t);
        }
        self.t_ps.extend_from_slice(t_ps);
        self.rows.extend_from_slice(rows);
        Ok(())
    }

    /// The sample in force at `t` (the first one before the first sample).
    pub fn at(&self, t: Ps) -> Truth {
        let i = self.t_ps.partition_point(|&s| s <= t).saturating_sub(1);
        self.rows.get(i).copied().unwrap_or(REST)
    }

    /// Drop the samples no query at or after `t` can need (the one in force at `t` stays).
    pub fn trim(&mut self, t: Ps) {
        let i = self.t_ps.partition_point(|&s| s <= t).saturating_sub(1);
        // Drop only when it frees at least half the rows: each row is moved at most once on average.
        if i > 0 && 2 * i >= self.t_ps.len() {
            self.t_ps.drain(..i);
            self.rows.drain(..i);
        }
    }

    /// The last sample's time, and whether the input has ended.
    pub fn reach(&self) -> (Option<Ps>, bool) {
        (self.t_ps.last().copied(), self.ended)
    }

    /// Samples held.
    pub fn len(&self) -> usize {
        self.t_ps.len()
    }

    /// Whether no sample is held.
    pub fn is_empty(&self) -> bool {
        self.t_ps.is_empty()
    }
}

/// What a query before any sample sees (never asked on a run fed its first rows before it steps).
const REST: Truth = Truth {
    array_g: [[0.0, 0.0, 1.0]; 7],
    compass: hmc6343::Truth {
        heading_deg: 0.0,
        pitch_deg: 0.0,
        roll_deg: 0.0,
        accel_g: [0.0, 0.0, 1.0],
        mag_gauss: [0.0; 3],
        temp_c: 25.0,
    },
    gps: gps::Truth { speed_m_s: 0.0, course_deg: 0.0, lat_deg: 0.0, lon_deg: 0.0, alt_m: 0.0 },
};

/// How far past a tick's time the input must reach before the tick runs (unless the input has
/// ended): the parts are read within the tick's handler, which the profile's bounds on the cost keys
/// keep within a few periods; one second is hundreds of periods.
pub const LOOKAHEAD_PS: Ps = crate::time::PS_PER_S;
/// How far before a tick's time the parts may still ask for the vehicle (the GPS's fix epochs lie
/// `gps.latency_ms` ≤ 10 s before the characters that report them): rows older than this are dropped.
pub const LOOKBACK_PS: Ps = 12 * crate::time::PS_PER_S;

/// The board run over input pushed in chunks, a block of ticks at a time: memory bounded by a few
/// seconds of input and a block of steps, whatever the run's length; every call returns within a
/// bounded time so that the caller can stop it.
pub struct Streamed {
    board: Board,
    window: Arc<std::sync::Mutex<Window>>,
    budget: BudgetAcc,
    ticks: u64,
}

impl std::fmt::Debug for Streamed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Streamed").field("ticks", &self.ticks).finish()
    }
}

/// A step with the vehicle's truth at its tick (what the harness compares the DSP's output with).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruthStep {
    /// The step.
    pub step: Step,
    /// The truth in force at the node's tick (`step.timing.t0`).
    pub truth: Truth,
}

impl Streamed {
    /// The board of `profile` at power-up, with no input yet.
    pub fn new(profile: &GfsinsProfile) -> Result<Streamed> {
        let window = Arc::new(std::sync::Mutex::new(Window::default()));
        let w = window.clone();
        let source: Source = Arc::new(move |t| w.lock().unwrap_or_else(std::sync::PoisonError::into_inner).at(t));
        let board = Board::new(profile, source)?;
        let budget = BudgetAcc::new(board.node().period());
        Ok(Streamed { board, window, budget, ticks: 0 })
    }

    fn window(&self) -> std::sync::MutexGuard<'_, Window> {
        self.window.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// Append vehicle samples (times from 0, increasing across calls).
    pub fn push(&mut self, t_ps: &[Ps], rows: &[Truth]) -> Result<()> {
        self.window().push(t_ps, rows)
    }

    /// Declare the end of the input.
    pub fn end_input(&mut self) {
        self.window().ended = true;
    }

    /// Run the ticks the input reaches (a tick's time plus [`LOOKAHEAD_PS`], or any tick once the
    /// input has ended), while fewer than `limit` ticks have run in all, at most `max` in this call
    /// and for about `wall` of the caller's time (checked after each tick): the steps, each with the
    /// truth at its tick. Empty: no tick can run until more input comes (or none is left).
    pub fn run(&mut self, max: u64, limit: u64, wall: std::time::Duration) -> Result<Vec<TruthStep>> {
        let started = std::time::Instant::now();
        let mut out = Vec::new();
        while (out.len() as u64) < max && self.ticks < limit {
            let t = self.board.node().tick_time(self.ticks);
            let (last, ended) = self.window().reach();
            let Some(last) = last else { break };
            if !ended && t.saturating_add(LOOKAHEAD_PS) > last {
                break;
            }
            let step = self.board.step()?;
            self.ticks += 1;
            self.budget.add(&step);
            let truth = self.window().at(step.timing.t0);
            out.push(TruthStep { step, truth });
            self.window().trim(t.saturating_sub(LOOKBACK_PS));
            if started.elapsed() >= wall {
                break;
            }
        }
        Ok(out)
    }

    /// Ticks run so far.
    pub fn ticks(&self) -> u64 {
        self.ticks
    }

    /// Both processors' budget over the ticks run so far.
    pub fn budget(&self) -> Budget {
        self.budget.budget()
    }

    /// Take every event out (node, parts, links, DSP), in time order.
    pub fn drain_events(&mut self) -> Vec<Event> {
        self.board.drain_events()
    }

    /// The tick period, ps.
    pub fn period(&self) -> Ps {
        self.board.node().period()
    }
}

/// Run `profile` on `source` for `ticks` cycles: the steps, the budget, the events.
pub fn run(profile: &GfsinsProfile, source: Source, ticks: u64) -> Result<(Vec<Step>, Budget, Vec<Event>)> {
    let mut board = Board::new(profile, source)?;
    let steps = (0..ticks).map(|_| board.step()).collect::<Result<Vec<_>>>()?;
    let budget = Budget::of(&steps, board.node().period());
    let events = board.drain_events();
    Ok((steps, budget, events))
}

#[cfg(test)]
mod tests;
