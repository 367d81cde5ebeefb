//! The gyro-free vehicle board (`sins_core::firmware::gfsins`): a run over a vehicle given as
//! sample-and-hold rows, its packets as the DSP decoded them, both processors' budget, the events.

use crate::errors::{guard, to_py};
use crate::event_dict;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sins_core::device::{gps, hmc6343};
use sins_core::firmware::gfsins::{self, Budget, GfsinsProfile, Samples, Truth, CLASSES};
use sins_core::time::{ps_to_s, s_to_ps};
use sins_core::Error;

fn shape(a: &PyReadonlyArray2<'_, f64>, n: usize, cols: usize, name: &str) -> PyResult<()> {
    let s = a.as_array().shape().to_vec();
    if s != [n, cols] {
        return Err(to_py(Error::Input(format!("gfsins input `{name}`: shape {s:?}, expected ({n}, {cols})"))));
    }
    Ok(())
}

/// Run the board of profile `text` (named `source` in messages) for `ticks` 5 ms cycles on the
/// vehicle: `t_s` (n) sample times from 0; `array_g` (n, 21) the seven parts' specific force, g;
/// `compass` (n, 9) heading, pitch, roll (°), specific force (g) and field (gauss) at the compass;
/// `gps` (n, 5) speed (m/s), course (°), latitude, longitude (°), height (m), every row filled.
/// Returns a dict of arrays per cycle (the DSP's view; NaN where a packet was refused), the budget
/// per processor and rate class, and the events.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
pub fn gfsins_run<'py>(
    py: Python<'py>,
    text: &str,
    source: &str,
    t_s: PyReadonlyArray1<'_, f64>,
    array_g: PyReadonlyArray2<'_, f64>,
    compass: PyReadonlyArray2<'_, f64>,
    gps: PyReadonlyArray2<'_, f64>,
    ticks: u64,
) -> PyResult<Bound<'py, PyDict>> {
    let t = t_s.as_array();
    let n = t.len();
    shape(&array_g, n, 21, "array_g")?;
    shape(&compass, n, 9, "compass")?;
    shape(&gps, n, 5, "gps")?;
    let (a, c, g) = (array_g.as_array(), compass.as_array(), gps.as_array());
    if let Some(i) = (0..n).find(|&i| !(t[i].is_finite() && t[i] >= 0.0)) {
        return Err(to_py(Error::Input(format!("gfsins input `t_s`: row {i} = {}, expected a time ≥ 0 s", t[i]))));
    }
    if let Some((i, j)) = (0..n).flat_map(|i| (0..5).map(move |j| (i, j))).find(|&(i, j)| !g[[i, j]].is_finite()) {
        return Err(to_py(Error::Input(format!(
            "gfsins input `gps`: row {i} column {j} is not finite (fill every row)"
        ))));
    }
    let rows: Vec<Truth> = (0..n)
        .map(|i| Truth {
            array_g: std::array::from_fn(|p| std::array::from_fn(|k| a[[i, 3 * p + k]])),
            compass: hmc6343::Truth {
                heading_deg: c[[i, 0]],
                pitch_deg: c[[i, 1]],
                roll_deg: c[[i, 2]],
                accel_g: [c[[i, 3]], c[[i, 4]], c[[i, 5]]],
                mag_gauss: [c[[i, 6]], c[[i, 7]], c[[i, 8]]],
                temp_c: 25.0,
            },
            gps: gps::Truth {
                speed_m_s: g[[i, 0]],
                course_deg: g[[i, 1]],
                lat_deg: g[[i, 2]],
                lon_deg: g[[i, 3]],
                alt_m: g[[i, 4]],
            },
        })
        .collect();
    let times: Vec<u64> = t.iter().map(|&s| s_to_ps(s)).collect();
    let (steps, budget, events) = guard(|| -> Result<_, Error> {
        let profile = GfsinsProfile::parse(text, source)?;
        let samples = Samples::new(times, rows)?;
        gfsins::run(&profile, samples.source(), ticks)
    })?
    .map_err(to_py)?;
    let m = steps.len();
    let cols = |w: usize, f: &dyn Fn(&gfsins::Step, usize) -> f64| -> Array2<f64> {
        Array2::from_shape_fn((m, w), |(i, j)| f(&steps[i], j))
    };
    let d = PyDict::new(py);
    let nan = f64::NAN;
    d.set_item("t_irq_s", cols(1, &|s, _| s.out.map_or(nan, |o| ps_to_s(o.t_irq))).into_pyarray(py))?;
    d.set_item("sequence", cols(1, &|s, _| f64::from(s.packet.sequence)).into_pyarray(py))?;
    d.set_item("flags", cols(1, &|s, _| f64::from(s.packet.flags)).into_pyarray(py))?;
    d.set_item("accel_g", cols(9, &|s, j| s.out.map_or(nan, |o| o.accel_g[j])).into_pyarray(py))?;
    d.set_item("compass_deg", cols(3, &|s, j| s.out.map_or(nan, |o| o.compass_deg[j])).into_pyarray(py))?;
    d.set_item("gps", cols(6, &|s, j| s.out.map_or(nan, |o| o.gps[j])).into_pyarray(py))?;
    d.set_item("tilt_deg", cols(2, &|s, j| s.out.map_or(nan, |o| o.tilt[j].to_degrees())).into_pyarray(py))?;
    d.set_item("node_cpu_s", cols(1, &|s, _| ps_to_s(s.timing.cpu_ps)).into_pyarray(py))?;
    d.set_item("dsp_cycles", cols(1, &|s, _| s.out.map_or(nan, |o| o.cycles as f64)).into_pyarray(py))?;
    d.set_item("class", cols(1, &|s, _| Budget::class(s) as f64).into_pyarray(py))?;
    let rows = PyDict::new(py);
    for (p, name) in ["node", "dsp"].iter().enumerate() {
        let per = PyDict::new(py);
        for (k, class) in CLASSES.iter().enumerate() {
            let l = budget.load[p][k];
            let e = PyDict::new(py);
            e.set_item("ticks", l.ticks)?;
            e.set_item("peak_s", ps_to_s(l.peak_ps))?;
            e.set_item("mean_s", l.mean_ps * 1e-12)?;
            e.set_item("peak_fraction", l.peak_ps as f64 / budget.period_ps as f64)?;
            per.set_item(*class, e)?;
        }
        rows.set_item(*name, per)?;
    }
    d.set_item("budget", rows)?;
    d.set_item("period_s", ps_to_s(budget.period_ps))?;
    let ev = events.iter().map(|e| event_dict(py, e)).collect::<PyResult<Vec<_>>>()?;
    d.set_item("events", ev)?;
    Ok(d)
}
