//! The ADIS16407 ten-degree-of-freedom IMU: register file, sampling engine on its own clock,
//! Bartlett filter, output encoding, GLOB_CMD, and the SPI slave with its timing rules.
//!
//! - [`encoding`]: physical value ↔ output word, pure functions (also used by the Python binding).
//! - [`registers`]: the register map as one table.
//! - [`filter`]: the Bartlett filter (exact integer arithmetic).
//! - [`sampler`]: the sample clock (SMPL_PRD), the [`Stimulus`] and the [`SensorErrors`] hook.
//! - [`Adis16407`]: the device; it implements [`crate::bus::SpiSlave`]; injected faults (profile
//!   `[faults]`) act inside it (`faults.rs`).
//! - [`replay`]: a slave answering recorded burst words instead of the device (raw-register traces).

mod adis;
pub mod ads8344;
pub mod adxl345;
pub mod analog;
pub mod eeprom24;
pub mod encoding;
mod faults;
pub mod filter;
mod frame;
pub mod gps;
pub mod hmc6343;
pub mod part;
pub mod parts;
pub mod registers;
pub mod replay;
pub mod sampler;
mod slave;
mod spi_rules;
pub mod spi_timing;

pub use adis::{Adis, Adis16407, DataReady, DataReadyLine, ModelOptions, SampleStamp};
pub use encoding::{decode, decode_baro, encode, Channel, DecodedWord, Encoded, GyroRange};
pub use faults::describe as describe_fault;
pub use frame::{ReadRecord, Violations};
pub use sampler::{Constant, FnStimulus, Ideal, SensorErrors, SliceStimulus, Stimulus};

pub mod error_model;

/// The physical quantities the sensor sees at one internal sample instant, in the units of its
/// data sheet. Sensor errors (bias, noise, …) are applied to these before filtering and encoding.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Physical {
    /// Angular rate about the sensor's x, y, z axes, °/s.
    pub gyro_dps: [f64; 3],
    /// Specific force along x, y, z, g.
    pub accel_g: [f64; 3],
    /// Magnetic field along x, y, z, gauss.
    pub mag_gauss: [f64; 3],
    /// Barometric pressure, mbar.
    pub baro_mbar: f64,
    /// Internal temperature, °C.
    pub temp_c: f64,
    /// Supply voltage, V.
    pub supply_v: f64,
    /// Voltage at the AUX_ADC input, V.
    pub aux_v: f64,
}

impl Physical {
    /// A part powered at 5.0 V, at 25 °C and 1013.25 mbar, with no motion, no specific force and no
    /// field: the default stimulus, chosen so that no DIAG_STAT flag sets.
    pub fn powered_idle() -> Physical {
        Physical { baro_mbar: 1013.25, temp_c: 25.0, supply_v: 5.0, ..Physical::default() }
    }

    /// Every value is finite.
    pub fn is_finite(&self) -> bool {
        // 0·x is ±0 for every finite x and NaN for ±∞ and NaN, and a NaN survives the sum: one
        // comparison instead of a branch per value (the device checks every sample).
        self.values().iter().map(|v| 0.0 * v).sum::<f64>() == 0.0
    }

    /// Every value, in the order of [`Physical::values_mut`].
    pub fn values(&self) -> [f64; 13] {
        let ([gx, gy, gz], [ax, ay, az], [mx, my, mz]) = (self.gyro_dps, self.accel_g, self.mag_gauss);
        [gx, gy, gz, ax, ay, az, mx, my, mz, self.baro_mbar, self.temp_c, self.supply_v, self.aux_v]
    }

    /// Every value, mutably (x, y, z of gyro, accel, mag, then baro, temp, supply, aux).
    pub fn values_mut(&mut self) -> impl Iterator<Item = &mut f64> {
        self.gyro_dps.iter_mut().chain(self.accel_g.iter_mut()).chain(self.mag_gauss.iter_mut()).chain([
            &mut self.baro_mbar,
            &mut self.temp_c,
            &mut self.supply_v,
            &mut self.aux_v,
        ])
    }
}

#[cfg(test)]
mod prop_tests;
#[cfg(test)]
mod tests;
