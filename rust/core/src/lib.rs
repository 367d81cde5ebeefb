//! sins-core: a firmware-in-the-loop emulator of a TMS320F28335 + ADIS16407 strapdown attitude board.
//!
//! The folders are the architecture:
//! - [`profile`]: board and firmware profiles (TOML) with `key=value` overrides; `[[board.devices]]`
//!   says which part sits on which link.
//! - [`device`]: the ADIS16407 IMU (register file, sampling engine, filter, encoding, SPI slave).
//! - [`dsp`]: the F28335 peripherals the firmware touches (clocks, SPI-A, CPU timer).
//! - [`bus`]: the links between MCU and devices, one kind per file (SPI at transaction and bit
//!   level; I²C and UART declared for the boards that need them).
//! - [`board`]: the board as the firmware reaches it (clocks, CPU timer, SPI-A with its chip select
//!   and sensor, wiring faults) and the sensor's input feed.
//! - [`numerics`]: the scalar types the firmware arithmetic runs in (f64, C28x f32, IQ, op counter).
//! - [`firmware`]: the firmware model, generic over numerics: its acquisition ISR (`firmware::isr`),
//!   schedule, decode, the attitude update as a trait with its registry (`firmware::attitude`),
//!   Euler extraction and navigation.
//! - [`timing`]: the compute-time model (the firmware's stages counted and priced).
//! - [`emulator`]: the scheduler of virtual time that wires board and firmware; [`output`]: the run's rows.
//! - [`host`]: the board without firmware, driven register by register by a host-side driver (the
//!   Python `Board`, the C ABI).
//! - [`time`] and [`events`]: integer virtual time and the event log shared by every model; [`deadline`]:
//!   a missed deadline of any processor, one `overrun` event.
#![forbid(unsafe_code)]

pub mod board;
pub mod bus;
pub mod deadline;
pub mod device;
pub mod dsp;
pub mod emulator;
pub mod error;
pub mod events;
pub mod firmware;
pub mod host;
pub mod numerics;
pub mod output;
pub mod profile;
pub mod time;
pub mod timing;

pub use error::{Error, Result};

/// The crate version, shared with the Python package.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
