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

/// The fields the FIFO registers of the SPI, SCI and I²C modules (SPIFFTX/SPIFFRX, SCIFFTX/SCIFFRX,
/// I2CFFTX/I2CFFRX) share (SPRUEU3, SPRUFZ5, SPRUG03 register tables): the interrupt level, its
/// enable, the flag's clear and the flag, the FIFO's fill count and its reset (active low).
pub(crate) mod fifo_bits {
    /// TXFFIL/RXFFIL: the interrupt level.
    pub const FF_IL: u16 = 0x1F;
    /// TXFFIENA/RXFFIENA.
    pub const FF_IENA: u16 = 1 << 5;
    /// TXFFINTCLR/RXFFINTCLR: write 1 to clear the flag.
    pub const FF_INTCLR: u16 = 1 << 6;
    /// TXFFINT/RXFFINT (read only).
    pub const FF_INT: u16 = 1 << 7;
    /// TXFFST/RXFFST: the words in the FIFO (read only).
    pub const FF_ST: u16 = 0x1F00;
    /// TXFIFO reset / RXFIFORESET: 0 empties and holds the FIFO.
    pub const FF_RST: u16 = 1 << 13;
}

#[cfg(test)]
mod prop_tests;
