//! sins-core: a firmware-in-the-loop emulator of a TMS320F28335 + ADIS16407 strapdown attitude board.
//!
//! The folders are the architecture:
//! - [`device`]: the ADIS16407 IMU (register file, sampling engine, filter, encoding, SPI slave).
//! - [`dsp`]: the F28335 peripherals the firmware touches (clocks, SPI-A, CPU timer).
//! - [`bus`]: the SPI link between them, at transaction level and at bit level.
//! - [`numerics`]: the scalar types the firmware arithmetic runs in (f64, C28x f32, IQ, op counter).
//! - [`firmware`]: the firmware model (acquisition, decode, attitude, navigation), generic over numerics.
//! - [`timing`]: the compute-time model and the per-cycle budget.
//! - [`profile`]: board and firmware profiles (TOML) with `key=value` overrides.
//! - [`time`] and [`events`]: integer virtual time and the event log shared by every model.
#![forbid(unsafe_code)]

pub mod board;
pub mod bus;
pub mod device;
pub mod dsp;
pub mod emulator;
pub mod error;
pub mod events;
pub mod firmware;
pub mod numerics;
pub mod output;
pub mod profile;
pub mod time;
pub mod timing;

pub use error::{Error, Result};

/// The crate version, shared with the Python package.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
