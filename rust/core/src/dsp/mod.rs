//! The F28335 peripherals the firmware touches: the clock tree, CPU timer 0 and SPI-A, plus a
//! summary of what a profile's register values produce.

pub mod clocks;
pub mod gpio;
pub mod interrupts;
pub mod spi;
pub mod summary;
pub mod timer;

pub use clocks::DspClocks;
pub use spi::SpiA;
pub use summary::BoardSummary;
pub use timer::CpuTimer;

#[cfg(test)]
mod prop_tests;
