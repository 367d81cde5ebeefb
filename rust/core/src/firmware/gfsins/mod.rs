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
    /// Specific force at each ADXL345 (0–5 outer, 6 centre), g, part axes (= body axes).
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
        let mut b = Budget { period_ps, ..Budget::default() };
        let mut sums = [[0.0f64; 3]; 2];
        let mut stage_sums: Vec<[f64; 3]> = Vec::new();
        let add = |l: &mut ClassLoad, sum: &mut f64, t: Ps| {
            l.ticks += 1;
            l.peak_ps = l.peak_ps.max(t);
            *sum += t as f64;
        };
        for s in steps {
            let c = Budget::class(s);
            let dsp_ps = s.out.map_or(0, |o| o.t_done - o.t_irq);
            for (p, t) in [s.timing.cpu_ps, dsp_ps].into_iter().enumerate() {
                add(&mut b.load[p][c], &mut sums[p][c], t);
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
                            stage_sums.insert(at, [0.0; 3]);
                            at
                        }
                    };
                    add(&mut b.stages[i].load[c], &mut stage_sums[i][c], t);
                    prev = Some(i);
                }
            }
        }
        let loads = b.load.iter_mut().flatten().zip(sums.iter().flatten());
        let stage_loads = b.stages.iter_mut().flat_map(|r| r.load.iter_mut()).zip(stage_sums.iter().flatten());
        for (l, sum) in loads.chain(stage_loads) {
            l.mean_ps = if l.ticks > 0 { sum / l.ticks as f64 } else { 0.0 };
        }
        b
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
