//! The geomagnetic–gyro board's sensor chain and firmware without the bus (`firmware::geomag_chain`):
//! one turntable run, whole arrays out.

use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sins_core::device::analog::{GyroPreset, MagnetometerPreset};
use sins_core::firmware::geomag::AidGains;
use sins_core::firmware::geomag_chain::{run, ChainConfig, ChainMotion};

use crate::errors::{guard, to_py};
use crate::event_dict;

/// One turntable run of the chain (SPIN1200 on x, ADXRS300 on y and z, the AMR magnetometer, the
/// ADS8344's 16 bits at `vref_v`, None: exact voltages): a dict of arrays per recorded update
/// (`t_s`, `roll_aided`, `roll_gyro`, `tilt_aided`, `tilt_gyro`, `innovation`, rad), the aid's
/// `events`, the unit drawn (`gyro_bias_dps`, `gyro_scale_error`, `mag_offset_gauss`) and the
/// `clipped` read count.
#[pyfunction]
#[pyo3(signature = (
    *, spin_dps, seconds, seed, field_enu_gauss, step_s = 0.0025, spin_up_s = 0.0, yaw_deg = 90.0,
    pitch_deg = 0.0, temp_c = 25.0, kp = 1.0, ki = 0.25, gate_gauss = 0.05, mag_cutoff_hz = None,
    gyro_delay_s = None, vref_v = Some(5.0), record_every = 1
))]
#[allow(clippy::too_many_arguments)]
pub fn geomag_spin_chain<'py>(
    py: Python<'py>,
    spin_dps: f64,
    seconds: f64,
    seed: u64,
    field_enu_gauss: [f64; 3],
    step_s: f64,
    spin_up_s: f64,
    yaw_deg: f64,
    pitch_deg: f64,
    temp_c: f64,
    kp: f64,
    ki: f64,
    gate_gauss: f64,
    mag_cutoff_hz: Option<f64>,
    gyro_delay_s: Option<f64>,
    vref_v: Option<f64>,
    record_every: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let config = ChainConfig {
        motion: ChainMotion::Turntable { spin_dps, spin_up_s, yaw_deg, pitch_deg },
        seconds,
        step_s,
        field_n: field_enu_gauss,
        temp_c,
        gyro: [GyroPreset::SPIN1200, GyroPreset::ADXRS300, GyroPreset::ADXRS300],
        mag: MagnetometerPreset::AMR,
        vref_v,
        gains: AidGains { kp, ki, gate_gauss, mag_cutoff_hz },
        gyro_delay_s,
        seed,
        record_every,
    };
    let r = py.detach(|| guard(|| run(&config)))?.map_err(to_py)?;
    let d = PyDict::new(py);
    d.set_item("t_s", r.t_s.into_pyarray(py))?;
    d.set_item("roll_aided", r.roll_aided.into_pyarray(py))?;
    d.set_item("roll_gyro", r.roll_gyro.into_pyarray(py))?;
    d.set_item("tilt_aided", r.tilt_aided.into_pyarray(py))?;
    d.set_item("tilt_gyro", r.tilt_gyro.into_pyarray(py))?;
    d.set_item("innovation", r.innovation.into_pyarray(py))?;
    d.set_item("events", r.events.iter().map(|e| event_dict(py, e)).collect::<PyResult<Vec<_>>>()?)?;
    d.set_item("gyro_bias_dps", r.gyro_bias_dps.to_vec())?;
    d.set_item("gyro_scale_error", r.gyro_scale_error.to_vec())?;
    d.set_item("mag_offset_gauss", r.mag_offset_gauss.to_vec())?;
    d.set_item("clipped", r.clipped)?;
    Ok(d)
}
