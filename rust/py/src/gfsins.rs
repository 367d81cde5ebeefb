//! The gyro-free vehicle board (`sins_core::firmware::gfsins`): a run over a vehicle given as
//! sample-and-hold rows, its packets as the DSP decoded them, both processors' budget, the events.

use crate::errors::{guard, to_py};
use crate::event_dict;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sins_core::device::adxl345;
use sins_core::device::{gps, hmc6343};
use sins_core::firmware::gfsins::{self, frame, Budget, GfsinsProfile, Samples, Truth, CLASSES, PROCESSORS};
use sins_core::time::{ps_to_s, s_to_ps, Clock, Ps, PS_PER_S};
use sins_core::Error;
use std::sync::Arc;

fn shape(a: &PyReadonlyArray2<'_, f64>, n: usize, cols: usize, name: &str) -> PyResult<()> {
    let s = a.as_array().shape().to_vec();
    if s != [n, cols] {
        return Err(to_py(Error::Input(format!("gfsins input `{name}`: shape {s:?}, expected ({n}, {cols})"))));
    }
    Ok(())
}

/// Run the board of profile `text` (named `source` in messages; `overrides` as `--set` gives them) for `ticks` 5 ms cycles on the
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
    overrides: Vec<String>,
    t_s: PyReadonlyArray1<'_, f64>,
    array_g: PyReadonlyArray2<'_, f64>,
    compass: PyReadonlyArray2<'_, f64>,
    gps: PyReadonlyArray2<'_, f64>,
    ticks: u64,
) -> PyResult<Bound<'py, PyDict>> {
    let (times, rows) = truth_rows(&t_s, &array_g, &compass, &gps)?;
    let (steps, budget, events) = guard(|| -> Result<_, Error> {
        let profile = GfsinsProfile::parse_with(text, source, &overrides)?;
        let samples = Samples::new(times, rows)?;
        gfsins::run(&profile, samples.source(), ticks)
    })?
    .map_err(to_py)?;
    steps_dict(py, &steps, &budget, &events)
}

/// The input arrays as vehicle samples (checked: shapes, times, GPS rows filled).
fn truth_rows(
    t_s: &PyReadonlyArray1<'_, f64>,
    array_g: &PyReadonlyArray2<'_, f64>,
    compass: &PyReadonlyArray2<'_, f64>,
    gps: &PyReadonlyArray2<'_, f64>,
) -> PyResult<(Vec<Ps>, Vec<Truth>)> {
    let t = t_s.as_array();
    let n = t.len();
    shape(array_g, n, 21, "array_g")?;
    shape(compass, n, 9, "compass")?;
    shape(gps, n, 5, "gps")?;
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
    Ok((times, rows))
}

/// A navigation column: its name, its width and its value (row of the DSP's output, index in the row).
type NavColumn<'a> = (&'a str, usize, &'a dyn Fn(&gfsins::DspOutput, usize) -> f64);

/// The per-cycle arrays, the budget and the events of a run as the Python side takes them.
fn steps_dict<'py>(
    py: Python<'py>,
    steps: &[gfsins::Step],
    budget: &Budget,
    events: &[sins_core::events::Event],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    step_columns(py, steps, &d)?;
    budget_items(py, budget, &d)?;
    let ev = events.iter().map(|e| event_dict(py, e)).collect::<PyResult<Vec<_>>>()?;
    d.set_item("events", ev)?;
    Ok(d)
}

/// The per-cycle arrays of `steps` into `d`.
fn step_columns<'py>(py: Python<'py>, steps: &[gfsins::Step], d: &Bound<'py, PyDict>) -> PyResult<()> {
    let m = steps.len();
    let cols = |w: usize, f: &dyn Fn(&gfsins::Step, usize) -> f64| -> Array2<f64> {
        Array2::from_shape_fn((m, w), |(i, j)| f(&steps[i], j))
    };
    let nan = f64::NAN;
    let span = |(a, b): (Ps, Ps), j: usize| if a == b { nan } else { ps_to_s(if j == 0 { a } else { b }) };
    d.set_item("t0_s", cols(1, &|s, _| ps_to_s(s.timing.t0)).into_pyarray(py))?;
    d.set_item("t_irq_s", cols(1, &|s, _| s.out.as_ref().map_or(nan, |o| ps_to_s(o.t_irq))).into_pyarray(py))?;
    d.set_item("t_done_s", cols(1, &|s, _| s.out.as_ref().map_or(nan, |o| ps_to_s(o.t_done))).into_pyarray(py))?;
    d.set_item("sequence", cols(1, &|s, _| f64::from(s.packet.sequence)).into_pyarray(py))?;
    d.set_item("flags", cols(1, &|s, _| f64::from(s.packet.flags)).into_pyarray(py))?;
    d.set_item("accel_g", cols(9, &|s, j| s.out.as_ref().map_or(nan, |o| o.accel_g[j])).into_pyarray(py))?;
    d.set_item("compass_deg", cols(3, &|s, j| s.out.as_ref().map_or(nan, |o| o.compass_deg[j])).into_pyarray(py))?;
    d.set_item("gps", cols(6, &|s, j| s.out.as_ref().map_or(nan, |o| o.gps[j])).into_pyarray(py))?;
    d.set_item("tilt_deg", cols(2, &|s, j| s.out.as_ref().map_or(nan, |o| o.tilt[j].to_degrees())).into_pyarray(py))?;
    // The navigation (sins_core::output::GFSINS_COLUMNS, checked below).
    let nav_cols: [NavColumn<'_>; 7] = [
        ("nav_rate", 3, &|o, j| o.nav.rate[j]),
        ("nav_bridged", 1, &|o, _| {
            if o.nav.rate[0].is_nan() {
                nan
            } else {
                o.nav.bridged.iter().enumerate().map(|(i, &b)| f64::from(u8::from(b) << i)).sum()
            }
        }),
        ("nav_attitude_deg", 3, &|o, j| o.nav.attitude[j].to_degrees()),
        ("nav_vel_enu", 3, &|o, j| o.nav.vel[j]),
        ("nav_pos", 3, &|o, j| if j < 2 { o.nav.pos[j].to_degrees() } else { o.nav.pos[j] }),
        ("nav_fused", 1, &|o, _| o.nav.fused.map_or(-1.0, |f| f64::from(u8::from(f)))),
        ("dsp_flushes", 1, &|o, _| o.flushes as f64),
    ];
    for (c, (name, w, f)) in sins_core::output::GFSINS_COLUMNS.iter().zip(nav_cols) {
        debug_assert_eq!((c.name, c.file.len()), (name, w));
        d.set_item(name, cols(w, &|s, j| s.out.as_ref().map_or(nan, |o| f(o, j))).into_pyarray(py))?;
    }
    d.set_item("node_cpu_s", cols(1, &|s, _| ps_to_s(s.timing.cpu_ps)).into_pyarray(py))?;
    d.set_item("dsp_cycles", cols(1, &|s, _| s.out.as_ref().map_or(nan, |o| o.cycles as f64)).into_pyarray(py))?;
    d.set_item("class", cols(1, &|s, _| Budget::class(s) as f64).into_pyarray(py))?;
    // The links' activity per cycle (the bus lanes): each SPI core's SS↓/SS↑, the packet on SPI #8
    // (DMA2's start to SS↑), the compass's I²C transaction, the NMEA characters (NaN: none).
    d.set_item("spi_start_s", cols(7, &|s, j| ps_to_s(s.timing.spi[j].0)).into_pyarray(py))?;
    d.set_item("spi_end_s", cols(7, &|s, j| ps_to_s(s.timing.spi[j].1)).into_pyarray(py))?;
    d.set_item("packet_s", cols(2, &|s, j| span((s.timing.dma_start, s.timing.packet_end), j)).into_pyarray(py))?;
    d.set_item("iic_s", cols(2, &|s, j| span(s.timing.iic, j)).into_pyarray(py))?;
    d.set_item("uart_s", cols(2, &|s, j| span(s.timing.uart, j)).into_pyarray(py))?;
    d.set_item("nmea_bytes", cols(1, &|s, _| f64::from(s.timing.nmea_bytes)).into_pyarray(py))?;
    d.set_item("nmea_sentences", cols(1, &|s, _| f64::from(s.timing.nmea_sentences)).into_pyarray(py))?;
    d.set_item("compass_phase", cols(1, &|s, _| f64::from(s.timing.compass_phase)).into_pyarray(py))?;
    Ok(())
}

/// The budget per processor and rate class, by stage, the classes and the period into `d`.
fn budget_items<'py>(py: Python<'py>, budget: &Budget, d: &Bound<'py, PyDict>) -> PyResult<()> {
    let load = |l: &gfsins::ClassLoad| -> PyResult<Bound<'py, PyDict>> {
        let e = PyDict::new(py);
        e.set_item("ticks", l.ticks)?;
        e.set_item("peak_s", ps_to_s(l.peak_ps))?;
        e.set_item("mean_s", l.mean_ps * 1e-12)?;
        e.set_item("peak_fraction", l.peak_ps as f64 / budget.period_ps as f64)?;
        Ok(e)
    };
    let rows = PyDict::new(py);
    for (p, name) in PROCESSORS.iter().enumerate() {
        let per = PyDict::new(py);
        for (k, class) in CLASSES.iter().enumerate() {
            per.set_item(*class, load(&budget.load[p][k])?)?;
        }
        rows.set_item(*name, per)?;
    }
    d.set_item("budget", rows)?;
    let stages = budget
        .stages
        .iter()
        .map(|r| -> PyResult<Bound<'py, PyDict>> {
            let e = PyDict::new(py);
            e.set_item("processor", PROCESSORS[r.processor])?;
            e.set_item("stage", r.name)?;
            for (k, class) in CLASSES.iter().enumerate() {
                e.set_item(*class, load(&r.load[k])?)?;
            }
            Ok(e)
        })
        .collect::<PyResult<Vec<_>>>()?;
    d.set_item("stages", stages)?;
    d.set_item("classes", CLASSES.to_vec())?;
    d.set_item("period_s", ps_to_s(budget.period_ps))?;
    Ok(())
}

/// The gyro-free board run over input pushed in chunks (`sins_core::firmware::gfsins::Streamed`):
/// `push` chunks of the vehicle (as `gfsins_run` takes them, times from 0 increasing across chunks),
/// `end` the input, and `run` blocks of ticks; each `run` returns within about `wall_s` seconds so
/// that the caller can stop between calls (Ctrl-C, SIGTERM), and memory holds a few seconds of input
/// and one block of steps, whatever the run's length.
#[pyclass(module = "sins_fw._core")]
pub struct GfsinsStream {
    inner: std::sync::Mutex<gfsins::Streamed>,
}

impl GfsinsStream {
    fn inner(&self) -> std::sync::MutexGuard<'_, gfsins::Streamed> {
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }
}

#[pymethods]
impl GfsinsStream {
    /// The board of profile `text` (named `source` in messages; `overrides` as `--set` gives them).
    #[new]
    fn new(text: &str, source: &str, overrides: Vec<String>) -> PyResult<Self> {
        let s = guard(|| -> Result<_, Error> {
            let profile = GfsinsProfile::parse_with(text, source, &overrides)?;
            gfsins::Streamed::new(&profile)
        })?
        .map_err(to_py)?;
        Ok(GfsinsStream { inner: std::sync::Mutex::new(s) })
    }

    /// Append a chunk of the vehicle (see `gfsins_run`).
    fn push(
        &self,
        t_s: PyReadonlyArray1<'_, f64>,
        array_g: PyReadonlyArray2<'_, f64>,
        compass: PyReadonlyArray2<'_, f64>,
        gps: PyReadonlyArray2<'_, f64>,
    ) -> PyResult<()> {
        let (times, rows) = truth_rows(&t_s, &array_g, &compass, &gps)?;
        let mut inner = self.inner();
        guard(|| inner.push(&times, &rows))?.map_err(to_py)
    }

    /// Declare the end of the input.
    fn end(&self) {
        self.inner().end_input();
    }

    /// Run at most `max_ticks` ticks the input reaches, while fewer than `limit` have run in all,
    /// for about `wall_s` seconds: the per-cycle arrays (as `gfsins_run` gives them, plus
    /// `truth_deg`, (n, 3): the vehicle's heading, pitch and roll at each tick) and `events`, the
    /// events since the last call. `ticks` 0: no tick could run until more input comes.
    fn run<'py>(&self, py: Python<'py>, max_ticks: u64, limit: u64, wall_s: f64) -> PyResult<Bound<'py, PyDict>> {
        let wall = std::time::Duration::from_secs_f64(wall_s.clamp(0.0, 3600.0));
        let mut inner = self.inner();
        let (steps, events) = guard(|| -> Result<_, Error> {
            let steps = inner.run(max_ticks, limit, wall)?;
            Ok((steps, inner.drain_events()))
        })?
        .map_err(to_py)?;
        let d = PyDict::new(py);
        let plain: Vec<gfsins::Step> = steps.iter().map(|s| s.step).collect();
        step_columns(py, &plain, &d)?;
        let truth = Array2::from_shape_fn((steps.len(), 3), |(i, j)| {
            let c = &steps[i].truth.compass;
            [c.heading_deg, c.pitch_deg, c.roll_deg][j]
        });
        d.set_item("truth_deg", truth.into_pyarray(py))?;
        d.set_item("ticks", steps.len())?;
        let ev = events.iter().map(|e| event_dict(py, e)).collect::<PyResult<Vec<_>>>()?;
        d.set_item("events", ev)?;
        Ok(d)
    }

    /// Ticks run so far.
    fn ticks(&self) -> u64 {
        self.inner().ticks()
    }

    /// Both processors' budget over the ticks run so far: `budget`, `stages`, `classes`, `period_s`
    /// as `gfsins_run` gives them.
    fn budget<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let b = self.inner().budget();
        let d = PyDict::new(py);
        budget_items(py, &b, &d)?;
        Ok(d)
    }
}

/// The profile `text` with `overrides`, checked, every default filled in, as TOML text.
#[pyfunction]
pub fn gfsins_profile(text: &str, source: &str, overrides: Vec<String>) -> PyResult<String> {
    GfsinsProfile::parse_with(text, source, &overrides).map(|p| p.to_toml()).map_err(to_py)
}

/// What `sins-fw board` shows of the gyro-free board: both processors, the links with the rates
/// their settings give, the parts, the rules the settings are checked against (measured, limit,
/// whether kept) and `emulated`: a run of `ticks` cycles on a vehicle at rest (the per-cycle arrays,
/// the budget and the events, as `gfsins_run` gives them), whose events are the rules the parts and
/// links check as they run.
#[pyfunction]
pub fn gfsins_board<'py>(
    py: Python<'py>,
    text: &str,
    source: &str,
    overrides: Vec<String>,
    ticks: u64,
) -> PyResult<Bound<'py, PyDict>> {
    let p = GfsinsProfile::parse_with(text, source, &overrides).map_err(to_py)?;
    let n = &p.node;
    let plb = Clock::from_hz(n.plb_hz);
    let hz = |period: Ps| PS_PER_S as f64 / period as f64;
    let adxl_sck = plb.cycles_to_ps(n.adxl_sck_ratio);
    let dsp_sck = plb.cycles_to_ps(n.dsp_sck_ratio);
    let scl_ps = (u64::from(n.iic_scl_low_ns) + u64::from(n.iic_scl_high_ns)) * 1_000;
    let d = PyDict::new(py);
    let item = |pairs: &[(&str, Bound<'py, PyAny>)]| -> PyResult<Bound<'py, PyDict>> {
        let e = PyDict::new(py);
        for (k, v) in pairs {
            e.set_item(*k, v)?;
        }
        Ok(e)
    };
    let v = |x: f64| x.into_pyobject(py).map(|o| o.into_any());
    let s = |x: &str| x.into_pyobject(py).map(|o| o.into_any());
    d.set_item(
        "processors",
        vec![
            item(&[
                ("name", s("node")?),
                ("part", s("XC3S400AN FPGA, MicroBlaze + PLB IP cores")?),
                ("clock_hz", v(n.cpu_hz as f64)?),
                ("bus_hz", v(n.plb_hz as f64)?),
                ("tick_hz", v(n.timer_hz as f64)?),
            ])?,
            item(&[
                ("name", s("dsp")?),
                ("part", s("TMS320C6727B")?),
                ("clock_hz", v(p.dsp.cpu_hz as f64)?),
                ("bus_hz", v(p.dsp.cpu_hz as f64 / 2.0)?),
                ("tick_hz", v(n.timer_hz as f64)?),
            ])?,
        ],
    )?;
    let words = frame::WORDS as f64;
    let link = |name: &str, kind: &str, rate: f64, what: String, transfer_s: f64| {
        item(&[
            ("name", s(name)?),
            ("kind", s(kind)?),
            ("rate_hz", v(rate)?),
            ("what", s(&what)?),
            ("transfer_s", v(transfer_s)?),
        ])
    };
    let mut links = Vec::new();
    // The cores in order, each with the part `array.parts` puts on it.
    let cores = p.array.cores();
    for core in 0..gfsins::profile::ARRAY_LINKS.len() {
        let Some(i) = cores.iter().position(|&c| c == core) else { continue };
        let part = &p.array.parts[i];
        let [x, y, z] = part.position;
        let part = format!("ADXL345 #{} at ({x}, {y}, {z})·l, channels {}", i + 1, part.channels.join(" "));
        let read = (0.5 * n.ss_setup_half_periods as f64 + 56.0) * adxl_sck as f64 * 1e-12;
        links.push(link(
            gfsins::profile::ARRAY_LINKS[core],
            "spi",
            hz(adxl_sck),
            format!(
                "node SPI #{} → {part}, mode {}, 7-byte read (PLB / {})",
                core + 1,
                adxl345::spi::MODE,
                n.adxl_sck_ratio
            ),
            read,
        )?);
    }
    links.push(link(
        "iic1",
        "i2c",
        hz(scl_ps),
        format!("node IIC #1 → HMC6343 at 0x{:02X}", p.compass.address()),
        ps_to_s(9 * 7 * scl_ps),
    )?);
    links.push(link(
        "uart",
        "uart",
        f64::from(n.uart_baud),
        format!("GR-87 → node UART Lite, {} baud 8N1 (the receiver sends at {})", n.uart_baud, p.gps.baud),
        10.0 / f64::from(n.uart_baud),
    )?);
    links.push(link(
        "spi8",
        "spi",
        hz(dsp_sck),
        format!("node SPI #8 (DMA2) → C6727B SPI1 slave, {} × 16-bit words (PLB / {})", frame::WORDS, n.dsp_sck_ratio),
        (0.5 * n.ss_setup_half_periods as f64 + words * 16.0) * dsp_sck as f64 * 1e-12,
    )?);
    d.set_item("links", links)?;
    let odr = adxl345::odr_hz(p.array.bw_rate & 0x0F);
    d.set_item(
        "parts",
        vec![
            item(&[
                ("part", s("ADXL345 ×7")?),
                ("links", s("spi1…spi7")?),
                ("settings", s(&format!(
                    "ODR {odr} Hz (BW_RATE 0x{:02X}), DATA_FORMAT 0x{:02X}, FIFO_CTL 0x{:02X}, lever arm {} m, errors {}",
                    p.array.bw_rate, p.array.data_format, p.array.fifo_ctl, p.array.lever_arm_m, p.array.preset
                ))?),
            ])?,
            item(&[
                ("part", s("HMC6343")?),
                ("links", s("iic1")?),
                ("settings", s(&format!(
                    "address 0x{:02X}, 10 Hz (OP mode 2 in EEPROM), {} command set, errors {}",
                    p.compass.address(), p.compass.revision, p.compass.errors
                ))?),
            ])?,
            item(&[
                ("part", s("GR-87 GPS")?),
                ("links", s("uart")?),
                ("settings", s(&format!(
                    "1 Hz fixes, {} baud, latency {} ms, CEP {} m",
                    p.gps.baud, p.gps.latency_ms, p.gps.cep_m
                ))?),
            ])?,
        ],
    )?;
    let rule = |name: &str, measured: f64, limit: f64, unit: &str, ok: bool, source: &str| {
        item(&[
            ("rule", s(name)?),
            ("measured", v(measured)?),
            ("limit", v(limit)?),
            ("unit", s(unit)?),
            ("ok", ok.into_pyobject(py)?.to_owned().into_any()),
            ("source", s(source)?),
        ])
    };
    let sclk_min = adxl345::spi::T_SCLK_MIN;
    let rules = vec![
        rule(
            "SPI #1–#7 SCLK within the ADXL345's 5 MHz (tSCLK ≥ 200 ns)",
            hz(adxl_sck),
            hz(sclk_min),
            "Hz",
            adxl_sck >= sclk_min,
            "adxl345.md",
        )?,
        rule(
            "ADXL345 output data rate at least the node's read rate",
            odr,
            n.timer_hz as f64,
            "Hz",
            odr >= n.timer_hz as f64,
            "adxl345.md, thesis §4.3",
        )?,
        rule(
            "I²C SCL within standard mode's 100 kHz (HMC6343)",
            hz(scl_ps),
            100e3,
            "Hz",
            hz(scl_ps) <= 100e3,
            "i2c.md, hmc6343.md",
        )?,
        rule(
            "UART Lite baud rate equals the GPS receiver's",
            f64::from(n.uart_baud),
            f64::from(p.gps.baud),
            "baud",
            n.uart_baud == p.gps.baud,
            "gps-nmea.md",
        )?,
        rule(
            "SPI #8 SCLK within the C6727B SPI1 slave's ceiling",
            hz(dsp_sck),
            p.dsp.spi_max_hz as f64,
            "Hz",
            hz(dsp_sck) <= p.dsp.spi_max_hz as f64,
            "c6727.md, thesis",
        )?,
    ];
    d.set_item("rules", rules)?;
    // A vehicle at rest, level, heading 30°, at the thesis's test place.
    let rest = Truth {
        array_g: [[0.0, 0.0, 1.0]; 7],
        compass: hmc6343::Truth {
            heading_deg: 30.0,
            pitch_deg: 0.0,
            roll_deg: 0.0,
            accel_g: [0.0, 0.0, 1.0],
            mag_gauss: [0.18, 0.31, -0.33],
            temp_c: 25.0,
        },
        gps: gps::Truth { speed_m_s: 0.0, course_deg: 30.0, lat_deg: 28.20021, lon_deg: 112.92647, alt_m: 5.13145 },
    };
    let (steps, budget, events) = guard(|| gfsins::run(&p, Arc::new(move |_| rest), ticks))?.map_err(to_py)?;
    d.set_item("emulated", steps_dict(py, &steps, &budget, &events)?)?;
    Ok(d)
}
