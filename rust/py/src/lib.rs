//! The Python binding, `sins_fw._core`. Thin on purpose: argument conversion, error mapping, and
//! whole arrays in and out (never a Python call per sample).

use pyo3::prelude::*;
use pyo3::types::PyDict;
use sins_core::emulator::BoardReport;
use sins_core::events::{Event, Severity};
use sins_core::profile::{Numeric, Profile};
use sins_core::time::ps_to_s;
use sins_core::timing::CostTable;

/// The allocator of this extension's memory, output columns included: see `Cargo.toml` for why.
#[cfg(target_os = "linux")]
#[global_allocator]
static ALLOC: tikv_jemallocator::Jemalloc = tikv_jemallocator::Jemalloc;

/// A dict of `key => value` pairs, each value converted as `PyDict::set_item` converts it; the
/// first failure returns from the enclosing function (which returns a `PyResult`).
macro_rules! py_dict {
    ($py:expr; $($key:expr => $value:expr),* $(,)?) => {{
        let d = pyo3::types::PyDict::new($py);
        $(d.set_item($key, $value)?;)*
        d
    }};
}

mod board;
mod emulate;
mod errors;
mod geomag;
mod gfsins;

use errors::{guard, to_py};

/// Validate a profile (TOML text, the file name for messages, `key=value` overrides) and return it
/// with every default filled in, as TOML text.
#[pyfunction]
fn resolve_profile(text: &str, source: &str, overrides: Vec<String>) -> PyResult<String> {
    guard(|| Profile::from_toml(text, source, &overrides).map(|p| p.to_toml()))?.map_err(to_py)
}

/// Every key a profile may hold, dotted.
#[pyfunction]
fn profile_keys() -> Vec<String> {
    Profile::known_keys()
}

/// An event as a dict: t_s, kind, severity, message, measured, required, frame (the bus frame it is
/// about, as the bus log's `frame_index` numbers it, or None).
pub(crate) fn event_dict<'py>(py: Python<'py>, e: &Event) -> PyResult<Bound<'py, PyDict>> {
    Ok(py_dict!(py;
        "t_s" => ps_to_s(e.t_ps), "kind" => e.kind, "severity" => e.severity.as_str(), "message" => &e.message,
        "measured" => e.measured, "required" => e.required, "frame" => e.frame,
    ))
}

/// What the profile's registers produce (clocks, SPI baud and mode, frame and burst times, rules
/// broken), as a dict.
#[pyfunction]
fn board_summary<'py>(
    py: Python<'py>,
    text: &str,
    source: &str,
    overrides: Vec<String>,
    costs_text: &str,
    costs_source: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let r = guard(|| -> Result<BoardReport, sins_core::Error> {
        let p = Profile::from_toml(text, source, &overrides)?;
        BoardReport::of(&p, &CostTable::from_toml(costs_text, costs_source)?)
    })?
    .map_err(to_py)?;
    let s = &r.summary;
    let d = PyDict::new(py);
    d.set_item("sysclkout_hz", s.clocks.sysclkout.hz())?;
    d.set_item("lspclk_hz", s.clocks.lspclk.hz())?;
    d.set_item("spi_divisor", s.spi_divisor)?;
    d.set_item("spi_baud_hz", s.spi_baud_hz)?;
    d.set_item("clock_scheme", s.scheme.ti_name())?;
    d.set_item("spi_mode", s.spi_mode)?;
    d.set_item("mode_matches_device", s.mode_matches_device)?;
    d.set_item("char_bits", s.char_bits)?;
    d.set_item("part", s.part)?;
    d.set_item("part_modes", s.part_modes.iter().map(|&m| u32::from(m)).collect::<Vec<u32>>())?;
    d.set_item("read_frames", s.read_frames)?;
    d.set_item("frame_s", ps_to_s(s.frame_ps))?;
    d.set_item("burst_clocking_s", ps_to_s(s.burst_clocking_ps))?;
    d.set_item("burst_s", ps_to_s(r.burst_ps))?;
    d.set_item("frame_gap_s", ps_to_s(r.frame_gap_ps))?;
    d.set_item("timer_period_s", ps_to_s(s.timer_period_ps))?;
    let violations =
        s.violations.iter().chain(&r.burst_events).map(|e| event_dict(py, e)).collect::<PyResult<Vec<_>>>()?;
    d.set_item("violations", violations)?;
    Ok(d)
}

/// The rows of an error-model preset: quantity, value, unit, source, unconfirmed.
#[pyfunction]
fn preset_table<'py>(py: Python<'py>, name: &str) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let rows = guard(|| sins_core::device::error_model::preset_table(name))?.map_err(to_py)?;
    rows.iter()
        .map(|r| {
            Ok(py_dict!(py;
                "quantity" => r.quantity, "value" => r.value, "unit" => r.unit, "source" => r.source,
                "unconfirmed" => r.unconfirmed,
            ))
        })
        .collect()
}

/// Raise a panic inside the core's guard: lets the test suite prove that a panic reaches Python as
/// `sins_fw.errors.InternalError` instead of aborting the interpreter.
#[pyfunction]
fn _selftest_panic() -> PyResult<()> {
    guard(|| -> () { panic!("self-test panic") })
}

/// The error-model preset names.
#[pyfunction]
fn preset_names() -> Vec<&'static str> {
    sins_core::device::error_model::PRESET_NAMES.to_vec()
}

/// The benchmark's lower bound: the firmware's RK4 step alone in f64 over pre-decoded rates (n×3,
/// rad/s, two rows per step). Returns (steps, final quaternion); the caller times the call (it runs
/// on the calling thread with the GIL released, so `time.thread_time()` counts it).
#[pyfunction]
fn bench_rk4_lower_bound(
    py: Python<'_>,
    rates: numpy::PyReadonlyArray2<'_, f64>,
    step_s: f64,
) -> PyResult<(u64, [f64; 4])> {
    let v = rates.as_array();
    if v.ncols() != 3 {
        return Err(to_py(sins_core::Error::Input(format!("rates: shape {:?}, expected (n, 3)", v.shape()))));
    }
    let rows: Vec<[f64; 3]> = v.rows().into_iter().map(|r| [r[0], r[1], r[2]]).collect();
    Ok(py.detach(|| {
        let (q, steps) = sins_core::emulator::bench::rk4_lower_bound(&rows, step_s);
        (steps, q)
    }))
}

/// The benchmark's firmware stages alone: decode, RK4 update, Euler, navigation in f64 over
/// recorded burst words (n×6 uint16: X/Y/Z GYRO_OUT, X/Y/Z ACCL_OUT, one row per 4 ms read) with the
/// profile's firmware. Returns (updates, final quaternion); timed by the caller as the lower bound is.
#[pyfunction]
fn bench_firmware_stages(
    py: Python<'_>,
    text: &str,
    source: &str,
    overrides: Vec<String>,
    reads: numpy::PyReadonlyArray2<'_, u16>,
) -> PyResult<(u64, [f64; 4])> {
    let v = reads.as_array();
    if v.ncols() != 6 {
        return Err(to_py(sins_core::Error::Input(format!("reads: shape {:?}, expected (n, 6)", v.shape()))));
    }
    let rows: Vec<[u16; 6]> = v.rows().into_iter().map(|r| std::array::from_fn(|i| r[i])).collect();
    let profile = guard(|| Profile::from_toml(text, source, &overrides))?.map_err(to_py)?;
    py.detach(|| guard(|| sins_core::emulator::bench::firmware_stages(&profile, &rows)))?
        .map(|(q, steps)| (steps, q))
        .map_err(to_py)
}

/// The profile's attitude algorithm (`firmware.algorithm`, `dcm` or `vqf`) at algorithm level in the
/// profile's numeric type over recorded samples (`sins_core::firmware::attitude_run_samples`): one
/// quaternion (C_b^n, ENU) per row.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn attitude_orientation<'py>(
    py: Python<'py>,
    text: &str,
    source: &str,
    overrides: Vec<String>,
    gyr: numpy::PyReadonlyArray2<'py, f64>,
    acc: numpy::PyReadonlyArray2<'py, f64>,
    mag: numpy::PyReadonlyArray2<'py, f64>,
    step_s: f64,
) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
    use numpy::IntoPyArray;
    let rows = |name: &str, a: &numpy::PyReadonlyArray2<'py, f64>| -> PyResult<Vec<[f64; 3]>> {
        let v = a.as_array();
        if v.ncols() != 3 {
            return Err(to_py(sins_core::Error::Input(format!("{name}: shape {:?}, expected (n, 3)", v.shape()))));
        }
        Ok(v.rows().into_iter().map(|r| [r[0], r[1], r[2]]).collect())
    };
    let (g, a, m) = (rows("gyr", &gyr)?, rows("acc", &acc)?, rows("mag", &mag)?);
    let profile = guard(|| Profile::from_toml(text, source, &overrides))?.map_err(to_py)?;
    let q = py
        .detach(|| guard(|| sins_core::firmware::attitude_run_samples(&profile.firmware, step_s, &g, &a, &m)))?
        .map_err(to_py)?;
    let n = q.len();
    let array = numpy::ndarray::Array2::from_shape_vec((n, 4), q.into_flattened())
        .unwrap_or_else(|_| unreachable!("rows have 4 values"));
    Ok(array.into_pyarray(py))
}

/// The event kinds (`sins_core::events::KINDS`) as dicts: name, severity, source, spi_rule, meaning.
fn event_kinds(py: Python<'_>) -> PyResult<Vec<Bound<'_, PyDict>>> {
    sins_core::events::KINDS
        .iter()
        .map(|k| {
            Ok(py_dict!(py;
                "name" => k.name, "severity" => k.severity.as_str(), "source" => k.source, "spi_rule" => k.spi_rule,
                "meaning" => k.meaning,
            ))
        })
        .collect()
}

/// The output columns (`sins_core::emulator::COLUMNS`) as dicts: name, unit, meaning, file (the
/// run output file's (name, unit) per component).
fn output_columns(py: Python<'_>) -> PyResult<Vec<Bound<'_, PyDict>>> {
    column_dicts(py, sins_core::emulator::COLUMNS)
}

/// A column table as dicts (name, unit, meaning, file).
fn column_dicts<'py>(py: Python<'py>, table: &[sins_core::output::Column]) -> PyResult<Vec<Bound<'py, PyDict>>> {
    table
        .iter()
        .map(|c| {
            Ok(py_dict!(py; "name" => c.name, "unit" => c.unit, "meaning" => c.meaning, "file" => c.file.to_vec()))
        })
        .collect()
}

/// The budget's stages (`sins_core::output::BUDGET_STAGES`) as dicts: name, start and end (their
/// bounding columns), solution.
fn budget_stages(py: Python<'_>) -> PyResult<Vec<Bound<'_, PyDict>>> {
    sins_core::output::BUDGET_STAGES
        .iter()
        .map(|s| Ok(py_dict!(py; "name" => s.name, "start" => s.start, "end" => s.end, "solution" => s.solution)))
        .collect()
}

/// The parts (`sins_core::device::parts::PARTS`) by name, each a dict: prod_id, burst_command and
/// burst (the names of the registers a burst shifts out after its command frame, in order).
fn parts(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let out = PyDict::new(py);
    for p in sins_core::device::parts::PARTS {
        let burst: Vec<&str> = p.burst.iter().filter_map(|&a| p.lookup(a).map(|r| r.name)).collect();
        out.set_item(
            p.name,
            py_dict!(py; "prod_id" => p.prod_id, "burst_command" => p.burst_command, "burst" => burst),
        )?;
    }
    Ok(out)
}

/// The GPS model's NMEA lines (`sins_core::device::gps`) over its first `seconds` s, for a receiver
/// at (`lat_deg`, `lon_deg`, `alt_m`) moving at `speed_m_s` on `course_deg`, with `faults` given as
/// (kind, a, b): ("corrupt", epoch, sentence index), ("lost", from, to), ("cold", at, 0). Returns
/// (end of the line's last character in s, line) pairs.
#[pyfunction]
#[pyo3(signature = (seconds, seed=0, lat_deg=40.0, lon_deg=116.0, alt_m=50.0, speed_m_s=0.0, course_deg=0.0, faults=Vec::new()))]
#[allow(clippy::too_many_arguments)]
fn gps_nmea_lines(
    seconds: u64,
    seed: u64,
    lat_deg: f64,
    lon_deg: f64,
    alt_m: f64,
    speed_m_s: f64,
    course_deg: f64,
    faults: Vec<(String, u64, u64)>,
) -> PyResult<Vec<(f64, String)>> {
    use sins_core::device::gps::{self, Fault, Settings, Truth};
    let faults = faults
        .into_iter()
        .map(|(k, a, b)| match k.as_str() {
            "corrupt" => Ok(Fault::CorruptSentence { epoch: a, index: b as usize }),
            "lost" => Ok(Fault::LostFix { from: a, to: b }),
            "cold" => Ok(Fault::ColdStart { at: a }),
            _ => Err(to_py(sins_core::Error::Config(format!("GPS fault `{k}`: expected corrupt, lost or cold")))),
        })
        .collect::<PyResult<Vec<_>>>()?;
    let truth = Truth { lat_deg, lon_deg, alt_m, speed_m_s, course_deg };
    let settings = Settings { seed, faults, ..Settings::default() };
    guard(|| {
        gps::lines(settings, Box::new(move |_| truth), seconds).into_iter().map(|(t, l)| (ps_to_s(t), l)).collect()
    })
}

/// The receiving side's check of NMEA text (`gps::NmeaReader`): the sentence bodies it passes and
/// its events (a bad checksum is an `nmea_bad_checksum` event).
#[pyfunction]
fn nmea_read<'py>(py: Python<'py>, text: &str) -> PyResult<(Vec<String>, Vec<Bound<'py, PyDict>>)> {
    let mut reader = sins_core::device::gps::NmeaReader::default();
    let bodies: Vec<String> = text.bytes().filter_map(|b| reader.push(b, 0)).collect();
    let events = reader.drain_events().iter().map(|e| event_dict(py, e)).collect::<PyResult<_>>()?;
    Ok((bodies, events))
}

/// The twelve turntable positions (Table 3.1, corrected): per position, the body x, y, z axes as
/// (east, north, up) unit vectors.
#[pyfunction]
fn gfnav_orientations() -> Vec<[[f64; 3]; 3]> {
    sins_core::firmware::gfnav::calib::ORIENTATIONS.to_vec()
}

/// Twelve-position calibration from the positions' mean rate (rad/s) and specific force (m/s²), 12×3
/// each, at latitude `lat_rad` with gravity `g`; `printed` uses the thesis's bias sets. Returns
/// {"rate"|"accel": {"bias": [3], "scale": [3], "misalignment": {"xy": …, …}}}.
#[pyfunction]
fn gfnav_calibrate<'py>(
    py: Python<'py>,
    rate: Vec<[f64; 3]>,
    force: Vec<[f64; 3]>,
    lat_rad: f64,
    g: f64,
    printed: bool,
) -> PyResult<Bound<'py, PyDict>> {
    use sins_core::firmware::gfnav::calib::{calibrate, BiasSets, TriadErrors};
    let (Ok(rate), Ok(force)) = (<[[f64; 3]; 12]>::try_from(rate), <[[f64; 3]; 12]>::try_from(force)) else {
        return Err(to_py(sins_core::Error::Input("gfnav_calibrate: expected 12 positions of rate and force".into())));
    };
    let sets = if printed { BiasSets::Printed } else { BiasSets::Corrected };
    let cal = guard(|| calibrate(&rate, &force, lat_rad, g, sets))?;
    let triad = |e: &TriadErrors| -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("bias", e.bias.to_vec())?;
        d.set_item("scale", e.scale.to_vec())?;
        let m = PyDict::new(py);
        let a = e.misalignment;
        for (k, v) in [("xy", a.xy), ("xz", a.xz), ("yx", a.yx), ("yz", a.yz), ("zx", a.zx), ("zy", a.zy)] {
            m.set_item(k, v)?;
        }
        d.set_item("misalignment", m)?;
        Ok(d)
    };
    let d = PyDict::new(py);
    d.set_item("rate", triad(&cal.rate)?)?;
    d.set_item("accel", triad(&cal.accel)?)?;
    Ok(d)
}

/// (Ω², product resolution, orders between them) for a reading LSB (m/s²) at lever `lever_m`.
#[pyfunction]
fn gfnav_earth_rate_observability(lsb_m_s2: f64, lever_m: f64) -> (f64, f64, f64) {
    sins_core::firmware::gfnav::calib::earth_rate_observability(lsb_m_s2, lever_m)
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("EVENT_KINDS", event_kinds(m.py())?)?;
    m.add("OUTPUT_COLUMNS", output_columns(m.py())?)?;
    m.add("GFSINS_COLUMNS", column_dicts(m.py(), sins_core::output::GFSINS_COLUMNS)?)?;
    m.add("BUDGET_STAGES", budget_stages(m.py())?)?;
    m.add("SEVERITIES", Severity::ALL.map(Severity::as_str).to_vec())?;
    m.add("NUMERICS", Numeric::ALL.map(Numeric::name).to_vec())?;
    m.add("READ_WORDS", sins_core::emulator::READ_WORDS)?;
    m.add("PARTS", parts(m.py())?)?;
    m.add("__version__", sins_core::VERSION)?;
    m.add("BLOCK_TICKS", sins_core::emulator::BLOCK_TICKS)?;
    m.add_function(wrap_pyfunction!(resolve_profile, m)?)?;
    m.add_function(wrap_pyfunction!(profile_keys, m)?)?;
    m.add_function(wrap_pyfunction!(board_summary, m)?)?;
    m.add_function(wrap_pyfunction!(preset_table, m)?)?;
    m.add_function(wrap_pyfunction!(preset_names, m)?)?;
    m.add_function(wrap_pyfunction!(_selftest_panic, m)?)?;
    m.add_function(wrap_pyfunction!(bench_rk4_lower_bound, m)?)?;
    m.add_function(wrap_pyfunction!(bench_firmware_stages, m)?)?;
    m.add_function(wrap_pyfunction!(attitude_orientation, m)?)?;
    m.add_function(wrap_pyfunction!(gps_nmea_lines, m)?)?;
    m.add_function(wrap_pyfunction!(nmea_read, m)?)?;
    m.add_function(wrap_pyfunction!(geomag::geomag_spin_chain, m)?)?;
    m.add_function(wrap_pyfunction!(gfsins::gfsins_run, m)?)?;
    m.add_class::<gfsins::GfsinsStream>()?;
    m.add_function(wrap_pyfunction!(gfsins::gfsins_profile, m)?)?;
    m.add_function(wrap_pyfunction!(gfsins::gfsins_board, m)?)?;
    m.add_function(wrap_pyfunction!(gfnav_orientations, m)?)?;
    m.add_function(wrap_pyfunction!(gfnav_calibrate, m)?)?;
    m.add_function(wrap_pyfunction!(gfnav_earth_rate_observability, m)?)?;
    m.add_class::<emulate::Emulator>()?;
    m.add_class::<board::Board>()?;
    m.add_function(wrap_pyfunction!(board::encode, m)?)?;
    m.add_function(wrap_pyfunction!(board::decode, m)?)?;
    Ok(())
}
