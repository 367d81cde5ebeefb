//! The F28335 peripherals the firmware touches: the clock tree and system control, CPU timers 0-2,
//! the PIE, SPI-A, SCI-A/B/C, I2C-A, McBSP-A/B in SPI mode, the registers of the peripherals not modelled yet, plus a summary of what a
//! profile's register values produce.

pub mod clocks;
pub mod gpio;
pub mod i2c;
pub mod interrupts;
pub mod mcbsp;
pub mod sci;
pub mod serial;
pub mod spi;
pub mod summary;
pub mod sysctrl;
pub mod timer;
pub mod unmodelled;

pub use clocks::DspClocks;
pub use spi::SpiA;
pub use summary::BoardSummary;
pub use timer::CpuTimer;

#[cfg(test)]
mod prop_tests;
