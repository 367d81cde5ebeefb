//! The ADIS16407 ten-degree-of-freedom IMU: register file, sampling engine on its own clock,
//! Bartlett filter, output encoding, GLOB_CMD, and the SPI slave with its timing rules.

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
