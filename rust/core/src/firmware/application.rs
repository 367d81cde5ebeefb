//! The firmware's application seam: what the emulator needs of a board's firmware. The emulator
//! only decides when each timer tick's interrupt runs (`emulator`); what the interrupt does — which
//! devices it reads over which links, what it computes, what it writes to the run output — is the
//! application's. It reaches the board only through [`Board`]: the MCU's clocks, CPU timer, SPI-A
//! with the device on its acquisition chip select, and the other links of `[[board.devices]]`.
//!
//! Applications today, chosen by `firmware.application`:
//! - `adis-burst` ([`crate::firmware::isr::Isr`]): the reference firmware, an ADIS16xxx burst read
//!   per tick, decode, the attitude update of `firmware.algorithm`, Euler, navigation;
//!
//! - `ads8344-geomag` ([`crate::firmware::geomag_app::GeomagApp`]): the geomagnetic–gyro board, the
//!   ADS8344's channels per tick, gyro compensation, the three-sample rotation vector with the
//!   magnetometer roll aid, Euler for a spinning body.
//!
//! A new board's firmware implements [`Application`] (one file in `firmware/`) and adds its row to
//! [`APPLICATIONS`]; the binding builds the emulator of the row's [`AppKind`].
//!
//! The emulator is generic over the application (monomorphised: no dynamic dispatch per tick).

use crate::board::{Board, Sensor};
use crate::error::{Error, Result};
use crate::events::EventLog;
use crate::firmware::GpsFix;
use crate::numerics::counter::OpCounts;
use crate::output::Output;
use crate::profile::OverrunPolicy;
use crate::time::Ps;

/// A board's firmware as the emulator runs it: one interrupt per timer tick.
pub trait Application<S: Sensor>: Send {
    /// The interrupt of tick `k` (arrived at `tick_ps`), starting at SYSCLKOUT cycle `start`
    /// (`overrun`: it waited for the previous one); returns the cycle it ends at. It writes its rows
    /// to [`Application::output`] and its events to [`Application::events`]; a nested interrupt
    /// (if its overrun policy allows one) advances [`Application::next_pending`] itself.
    fn isr(&mut self, board: &mut Board<S>, k: u64, tick_ps: Ps, start: u64, overrun: bool) -> Result<u64>;
    /// What a tick arriving while the interrupt runs does (`firmware.overrun`).
    fn overrun(&self) -> OverrunPolicy;
    /// Device reads per tick (the read rows a tick writes; the replay's bursts per tick).
    fn reads_per_tick(&self) -> usize;
    /// The next tick no interrupt has serviced yet.
    fn next_pending(&self) -> u64;
    /// Set the next tick to service (the emulator sets `k + 1` before running tick `k`).
    fn set_next_pending(&mut self, k: u64);
    /// Nested interrupts so far.
    fn nested(&self) -> u64;
    /// The run output written so far.
    fn output(&mut self) -> &mut Output;
    /// The firmware's events.
    fn events(&mut self) -> &mut EventLog;
    /// What the timing model says each stage costs.
    fn stage_costs(&self) -> &StageCosts;
    /// Whether each read row carries the device sample it read (`ReadRow::sample_index`, −1: none):
    /// the emulator then reports a part that produces no data (`state_check::DataWatch`). An
    /// application whose reads are conversions it starts itself (an ADC) says no.
    fn sampled_reads(&self) -> bool {
        true
    }
    /// Fixes of the board's GPS stream; an application without a GPS input refuses them.
    fn push_gps(&mut self, _fixes: &[GpsFix]) -> Result<()> {
        Err(Error::Input("push_gps: this board's firmware reads no GPS stream".into()))
    }
}

/// Which application a profile runs: the binding builds the emulator of the kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AppKind {
    /// The reference ADIS16xxx burst reader (`isr.rs`).
    AdisBurst,
    /// The geomagnetic–gyro board (`geomag_app.rs`).
    Ads8344Geomag,
}

/// The registered applications: `firmware.application`'s name, one line of what it is, its kind.
pub const APPLICATIONS: &[(&str, &str, AppKind)] = &[
    ("adis-burst", "an ADIS16xxx burst read per tick, the reference attitude loop (isr.rs)", AppKind::AdisBurst),
    (
        "ads8344-geomag",
        "the ADS8344's eight channels per tick, the three-sample rotation vector with the magnetometer roll aid \
         (geomag_app.rs)",
        AppKind::Ads8344Geomag,
    ),
];

/// The application `name` names (`firmware.application`); an unknown name is refused naming the key
/// and the registered names.
pub fn app_kind(name: &str) -> Result<AppKind> {
    APPLICATIONS.iter().find(|a| a.0 == name).map(|a| a.2).ok_or_else(|| {
        let names: Vec<String> = APPLICATIONS.iter().map(|a| format!("\"{}\"", a.0)).collect();
        Error::Profile(format!("key `firmware.application` = \"{name}\": expected one of {}", names.join(", ")))
    })
}

/// Operation counts and cycles of one stage.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct StageCost {
    /// Operations the stage executes.
    pub counts: OpCounts,
    /// SYSCLKOUT cycles they cost.
    pub cycles: u64,
}

/// Cycles of every part of the ISR that is not SPI traffic.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct StageCosts {
    /// Hardware context save and the C prologue.
    pub entry: u64,
    /// Epilogue, PIE acknowledge and IRET.
    pub exit: u64,
    /// Decode of one burst (three gyro and three accel words).
    pub decode: StageCost,
    /// One attitude update (rate correction, RK4 or rotation vector, normalisation, DCM).
    pub attitude: StageCost,
    /// Euler extraction.
    pub euler: StageCost,
    /// One navigation step.
    pub navigation: StageCost,
    /// Midpoint interpolation of the `endpoint` schedule.
    pub interpolation: StageCost,
}
