//! The I²C link kind: its place in the bus layer, for the boards that need it (the HMC6343 compass
//! of the gyro-free board, at 100 kbit/s). Not emulated yet: a profile that puts a device on
//! `i2c-a` is refused (`profile::Board`).
//!
//! Shape, the SPI link's counterpart ([`super::SpiSlave`]): the master (the MCU's I2C-A) computes
//! what the wires show — START, the address byte, data bytes with their ACK bits, STOP, clock
//! stretching — and the target answers at byte level with the times of the bits it sees, checking
//! its own timing rules (setup/hold, bus free time) against them.

use crate::time::Ps;

/// The target (slave) side of an I²C link, at byte level.
pub trait I2cTarget {
    /// The target's 7-bit address.
    fn address(&self) -> u8;
    /// A START (or repeated START) at `t`.
    fn start(&mut self, t: Ps);
    /// The master wrote `byte` (the address byte after a START, then data) whose ninth clock is at
    /// `t`: whether the target ACKs it.
    fn write(&mut self, byte: u8, t: Ps) -> bool;
    /// The master reads a byte whose first clock is at `t`; `ack` is what the master answers after it.
    fn read(&mut self, t: Ps, ack: bool) -> u8;
    /// A STOP at `t`.
    fn stop(&mut self, t: Ps);
}
