//! The board the firmware runs on, below the firmware: the sensor at the other end of SPI-A (the
//! device model fed a physical input, or a replay of recorded words), that input's feed, and the
//! faults of the wiring (`dropped_burst`: CS glitches), and the other devices `[[board.devices]]`
//! declares, on their links (`links.rs`).

pub mod analog;
pub mod bitbang;
pub(crate) mod glitch;
pub mod input;
pub mod links;
pub mod sensor;
pub mod spi_parts;

pub use input::{InputFeed, StreamStimulus};
pub use sensor::{FrameSummary, Reach, Sensor, StreamedDevice};

use crate::bus::link::SpiLink;
use crate::dsp::clocks::DspClocks;
use crate::dsp::timer::CpuTimer;
use crate::error::Result;
use crate::events::{Event, EventLog, Severity};
use crate::profile::Profile;
use crate::time::{Clock, Ps};
use glitch::{BurstGlitch, Glitches};
use links::BoardLinks;

/// The board as the firmware reaches it: the F28335's clocks and CPU timer 0, SPI-A with its chip
/// select (GPIO57) wired to the sensor `S`, and the faults of that wiring.
pub struct Board<S> {
    /// The clock tree (SYSCLKOUT: the CPU's cycles; LSPCLK: SPI-A's).
    pub clocks: DspClocks,
    /// CPU timer 0, the acquisition interrupt.
    pub timer: CpuTimer,
    /// SPI-A, the chip select and the sensor.
    pub link: SpiLink<S>,
    /// Injected CS glitches (`dropped_burst` faults).
    pub(crate) glitches: Glitches,
    /// The other devices of `[[board.devices]]` on their links (none on the reference board).
    pub links: BoardLinks,
}

impl<S: Sensor> Board<S> {
    /// The board of a profile with `sensor` on SPI-A; InitSpi has run at power-on (t = 0).
    pub fn from_profile(profile: &Profile, sensor: S) -> Result<Self> {
        let clocks = DspClocks::from_profile(&profile.clocks)?;
        let timer = CpuTimer::from_profile(&profile.timer, clocks.sysclkout)?;
        let mut link = SpiLink::from_profile(profile, sensor)?;
        // InitSpi runs at power-on (t = 0) in the published order.
        link.init_from_profile(&profile.spi, 0)?;
        let links = BoardLinks::from_profile(profile, &links::known_parts, true)?;
        Ok(Board { clocks, timer, link, glitches: Glitches::from_profile(&profile.faults), links })
    }

    /// SYSCLKOUT, the CPU's clock.
    pub fn sysclk(&self) -> Clock {
        self.clocks.sysclkout
    }

    /// The time of SYSCLKOUT cycle `cycle`.
    pub fn ps(&self, cycle: u64) -> Ps {
        self.clocks.sysclkout.cycles_to_ps(cycle)
    }

    /// The SYSCLKOUT cycle timer tick `k` arrives on.
    pub fn tick_cycle(&self, k: u64) -> u64 {
        self.timer.period_cycles() * k
    }

    /// The time timer tick `k` arrives at.
    pub fn tick_ps(&self, k: u64) -> Ps {
        self.ps(self.tick_cycle(k))
    }

    /// A `dropped_burst` fault: the CS line goes high at `t`, in the middle of the burst of `tick`.
    #[cold]
    pub(crate) fn raise_glitch(&mut self, events: &mut EventLog, tick: u64, g: &mut BurstGlitch, t: Ps) -> Result<()> {
        g.rise = Some(t);
        self.link.set_gpio57(true, t)?;
        let how_long = g.length.map_or("until the firmware raises CS at the end of the burst".to_string(), |l| {
            format!("for {:.3} µs", l as f64 / 1e6)
        });
        events.push(Event::new(
            t,
            "fault_injected",
            Severity::Warning,
            format!(
                "{}: CS high after frame {} of the burst of tick {tick}, {how_long}",
                crate::device::describe_fault(&g.fault),
                g.after_frame,
            ),
        ));
        Ok(())
    }

    /// The glitch's CS line falls back at its time if that is before `t` (the next bus access).
    pub(crate) fn end_glitch_before(&mut self, g: &mut BurstGlitch, t: Ps) -> Result<()> {
        if let Some(back) = g.pending_return().filter(|&back| back <= t) {
            g.returned = true;
            self.link.set_gpio57(false, back)?;
        }
        Ok(())
    }
}
