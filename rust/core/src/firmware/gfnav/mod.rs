//! Gyro-free navigation (spec `algorithms.md` §4 and its corrections; source
//! `gfsins-vehicle-thesis-2010.zh.txt`): the firmware algorithms of the accelerometer-array vehicle
//! board, generic over the numeric type (the C6727 computes in IEEE single precision).
//!
//! Conventions (one right-handed set, chosen where the thesis mixes NED and "E-N-down"):
//! - body axes x right, y forward, z up (the thesis's §2.1 body frame, completed right-handed);
//! - navigation frame ENU (x east, y north, z up), as the rest of the project;
//! - specific force (an accelerometer at rest reads +g on its upward axis).
//!
//! Parts:
//! - [`array`]: the nine readings' forward model and its exact inversion (A, ω̇, rate products);
//! - [`rate`]: the rate from the products and their backward differences (corrected ω̂z), with
//!   singular steps bridged and reported;
//! - [`calib`]: twelve-position turntable calibration of the rate meter and the accelerometers;
//! - [`compass`]: tilt compensation and the 24-point deviation least squares;
//! - [`federated`]: the federated Kalman filter (compass and GPS sub-filters, fusion, no reset).

pub mod array;
pub mod calib;
pub mod compass;
pub mod federated;
pub mod rate;

pub use array::{invert, readings, ArrayMotion, Channel, GeometryError, Inverse};
pub use rate::{singular_event, Bridge, RateConfig, RateOutput, RateRecovery, ZNumerator};
