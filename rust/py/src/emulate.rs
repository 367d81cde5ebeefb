//! `_core.Emulator`: the board and firmware of a profile, fed whole numpy arrays in chunks and
//! returning whole numpy arrays. The numeric backend is chosen at construction; every call runs
//! inside the profile's IQ formats (harmless for the float backends).

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyReadonlyArray, PyReadonlyArray1, PyReadonlyArray2};
use std::borrow::Cow;
use std::sync::Mutex;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use sins_core::board::analog::AnalogBoard;
use sins_core::bus::link::{FrameRecord, LinkRecord};
use sins_core::device::replay::{ReplaySlave, RECORDED_WORDS};
use sins_core::device::Physical;
use sins_core::emulator::{price_list, CostTerm, Emulator as Core, Output, Progress, Sensor};
use sins_core::events::Event;
use sins_core::firmware::application::{app_kind, AppKind, Application};
use sins_core::firmware::geomag_app::GeomagApp;
use sins_core::firmware::GpsFix;
use sins_core::numerics::{iq, Scalar};
use sins_core::profile::{IqFormats, Numeric, Profile};
use sins_core::timing::{CostTable, StageCosts};
use sins_core::Error;

use crate::errors::{guard, to_py};
use crate::event_dict;

/// The type-erased emulator (one instantiation per numeric backend and sensor).
trait Run: Send {
    fn push(&mut self, t: &[f64], p: Vec<Physical>) -> Result<(), Error>;
    fn push_words(&mut self, t: &[f64], words: &[[u16; RECORDED_WORDS]]) -> Result<(), Error>;
    fn push_gps(&mut self, fixes: &[GpsFix]) -> Result<(), Error>;
    fn end(&mut self);
    fn run(&mut self) -> Result<Progress, Error>;
    fn take(&mut self) -> Output;
    fn stage_cycles(&self) -> Vec<(&'static str, u64)>;
    fn stage_costs(&self) -> StageCosts;
    fn enable_bus_log(&mut self);
    fn take_bus_log(&mut self, stop: bool) -> Vec<LinkRecord>;
}

/// What each sensor takes as input: physical samples (the device model) or recorded words (a replay).
trait Inputs {
    fn push(&mut self, t: &[f64], p: Vec<Physical>) -> Result<(), Error>;
    fn push_words(&mut self, t: &[f64], words: &[[u16; RECORDED_WORDS]]) -> Result<(), Error>;
    fn end(&mut self);
}

impl<T: Scalar> Inputs for Core<T> {
    fn push(&mut self, t: &[f64], p: Vec<Physical>) -> Result<(), Error> {
        self.push_input(t, p)
    }
    fn push_words(&mut self, _t: &[f64], _words: &[[u16; RECORDED_WORDS]]) -> Result<(), Error> {
        Err(Error::Input("push_words: this emulator reads a physical input; build it with replay=True".into()))
    }
    fn end(&mut self) {
        self.end_input()
    }
}

impl<T: Scalar> Inputs for Core<T, AnalogBoard, GeomagApp<T>> {
    fn push(&mut self, t: &[f64], p: Vec<Physical>) -> Result<(), Error> {
        self.push_input(t, p)
    }
    fn push_words(&mut self, _t: &[f64], _words: &[[u16; RECORDED_WORDS]]) -> Result<(), Error> {
        Err(Error::Input("push_words: this board reads the ADC's channels from a physical input".into()))
    }
    fn end(&mut self) {
        self.end_input()
    }
}

impl<T: Scalar> Inputs for Core<T, ReplaySlave> {
    fn push(&mut self, _t: &[f64], _p: Vec<Physical>) -> Result<(), Error> {
        Err(Error::Input("push: this emulator replays recorded words (replay=True); use push_words".into()))
    }
    fn push_words(&mut self, t: &[f64], words: &[[u16; RECORDED_WORDS]]) -> Result<(), Error> {
        Core::push_words(self, t, words)
    }
    fn end(&mut self) {
        self.end_input()
    }
}

impl<T: Scalar + Send + 'static, S: Sensor + 'static, A: Application<S> + 'static> Run for Core<T, S, A>
where
    Core<T, S, A>: Inputs,
{
    fn push(&mut self, t: &[f64], p: Vec<Physical>) -> Result<(), Error> {
        Inputs::push(self, t, p)
    }
    fn push_words(&mut self, t: &[f64], words: &[[u16; RECORDED_WORDS]]) -> Result<(), Error> {
        Inputs::push_words(self, t, words)
    }
    fn push_gps(&mut self, fixes: &[GpsFix]) -> Result<(), Error> {
        Core::push_gps(self, fixes)
    }
    fn end(&mut self) {
        Inputs::end(self)
    }
    fn run(&mut self) -> Result<Progress, Error> {
        Core::run(self)
    }
    fn take(&mut self) -> Output {
        self.take_output()
    }
    fn stage_cycles(&self) -> Vec<(&'static str, u64)> {
        let s = self.stage_costs();
        vec![
            ("entry", s.entry),
            ("decode", s.decode.cycles),
            ("attitude", s.attitude.cycles),
            ("euler", s.euler.cycles),
            ("navigation", s.navigation.cycles),
            ("interpolation", s.interpolation.cycles),
            ("exit", s.exit),
        ]
    }
    fn stage_costs(&self) -> StageCosts {
        *Core::stage_costs(self)
    }
    fn enable_bus_log(&mut self) {
        Core::enable_bus_log(self)
    }
    fn take_bus_log(&mut self, stop: bool) -> Vec<LinkRecord> {
        if stop {
            self.stop_bus_log()
        } else {
            Core::take_bus_log(self)
        }
    }
}

/// The emulated board.
#[pyclass(module = "sins_fw._core")]
pub struct Emulator {
    // A mutex makes the (Send, not Sync) emulator shareable as Python requires; never contended.
    inner: Mutex<Box<dyn Run>>,
    formats: IqFormats,
    /// What prices the stages: the table, the backend's section and the code-location factor.
    costs: CostTable,
    /// The profile (its prices are worked out from it when asked for).
    profile: Profile,
    /// The output since the last `take`, already in columns: each `run` call moves its rows (and
    /// its events, time-sorted per call) out of the core into them, and `take` hands them to numpy
    /// without a copy.
    held: Columns,
    /// The last input time pushed, s (what the output so far covers, about).
    input_reach_s: Option<f64>,
    /// The caller's hint (`expect_input_until`): the input's last time, s; used once, to size the
    /// columns at the first run that produces rows.
    expected_end_s: Option<f64>,
}

impl Emulator {
    fn inner(&self) -> std::sync::MutexGuard<'_, Box<dyn Run>> {
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }
}

fn build(profile: &Profile, costs: &CostTable, replay: bool) -> Result<Box<dyn Run>, Error> {
    fn one<T: Scalar + Send + 'static>(
        profile: &Profile,
        costs: &CostTable,
        replay: bool,
    ) -> Result<Box<dyn Run>, Error> {
        // One arm per application (`firmware::application::APPLICATIONS`).
        match app_kind(&profile.firmware.application)? {
            AppKind::AdisBurst => {}
            AppKind::Ads8344Geomag if replay => {
                return Err(Error::Input(
                    "replay=True: the ads8344-geomag board reads the ADC's channels, not recorded ADIS16xxx \
                     bursts; emulate a physical trace"
                        .into(),
                ))
            }
            AppKind::Ads8344Geomag => {
                return Ok(Box::new(Core::<T, AnalogBoard, GeomagApp<T>>::geomag(profile, costs)?))
            }
        }
        Ok(if replay {
            Box::new(Core::<T, ReplaySlave>::replay(profile, costs)?)
        } else {
            Box::new(Core::<T>::new(profile, costs)?)
        })
    }
    match profile.firmware.numeric {
        Numeric::F64 => one::<f64>(profile, costs, replay),
        Numeric::C28xF32 => one::<sins_core::numerics::C28xF32Rn>(profile, costs, replay),
        Numeric::C28xF32Rz => one::<sins_core::numerics::C28xF32Rz>(profile, costs, replay),
        Numeric::Iq => iq::with_formats(&profile.iq, || one::<sins_core::numerics::Iq>(profile, costs, replay))?,
    }
}

/// An array's elements in logical (row-major) order as one slice: numpy's own buffer when it is
/// C-contiguous (the harness always passes such arrays), else a copy.
fn flat<'a, D: numpy::ndarray::Dimension>(a: &'a PyReadonlyArray<'_, f64, D>) -> Cow<'a, [f64]> {
    // ndarray's `to_slice` is row-major only (numpy's `as_slice` also takes a Fortran-ordered buffer).
    let v = a.as_array();
    match v.to_slice() {
        Some(s) => Cow::Borrowed(s),
        None => Cow::Owned(v.iter().copied().collect()),
    }
}

/// An optional n×3 input column, checked and flattened (see [`flat`]).
fn col3<'a>(a: Option<&'a PyReadonlyArray2<'_, f64>>, n: usize, name: &str) -> PyResult<Option<Cow<'a, [f64]>>> {
    let Some(a) = a else { return Ok(None) };
    if a.as_array().shape() != [n, 3] {
        let shape = a.as_array().shape().to_vec();
        return Err(to_py(Error::Input(format!("input column `{name}`: shape {shape:?}, expected ({n}, 3)"))));
    }
    Ok(Some(flat(a)))
}

/// An optional n-row input column, checked and flattened (see [`flat`]).
fn col1<'a>(a: Option<&'a PyReadonlyArray1<'_, f64>>, n: usize, name: &str) -> PyResult<Option<Cow<'a, [f64]>>> {
    let Some(a) = a else { return Ok(None) };
    let rows = a.as_array().len();
    if rows != n {
        return Err(to_py(Error::Input(format!("input column `{name}`: {rows} rows, expected {n}"))));
    }
    Ok(Some(flat(a)))
}

#[pymethods]
impl Emulator {
    /// Build the board of a profile (TOML text, its source name, overrides) with a cost table. With
    /// `replay=True` the firmware reads recorded burst words (`push_words`) instead of the device model.
    #[new]
    #[pyo3(signature = (text, source, overrides, costs_text, costs_source, replay=false))]
    fn new(
        text: &str,
        source: &str,
        overrides: Vec<String>,
        costs_text: &str,
        costs_source: &str,
        replay: bool,
    ) -> PyResult<Self> {
        let (inner, profile, costs) = guard(|| -> Result<_, Error> {
            let profile = Profile::from_toml(text, source, &overrides)?;
            let costs = CostTable::from_toml(costs_text, costs_source)?;
            Ok((build(&profile, &costs, replay)?, profile, costs))
        })?
        .map_err(to_py)?;
        Ok(Emulator {
            inner: Mutex::new(inner),
            formats: profile.iq.clone(),
            profile,
            costs,
            held: Columns::default(),
            input_reach_s: None,
            expected_end_s: None,
        })
    }

    /// Append a chunk of physical input: t (s), gyro (°/s, n×3), accel (g, n×3), and optionally
    /// mag (gauss, n×3), baro (mbar), temp (°C).
    #[pyo3(signature = (t, gyro, accel, mag=None, baro=None, temp=None))]
    fn push(
        &mut self,
        t: PyReadonlyArray1<'_, f64>,
        gyro: PyReadonlyArray2<'_, f64>,
        accel: PyReadonlyArray2<'_, f64>,
        mag: Option<PyReadonlyArray2<'_, f64>>,
        baro: Option<PyReadonlyArray1<'_, f64>>,
        temp: Option<PyReadonlyArray1<'_, f64>>,
    ) -> PyResult<()> {
        let t = flat(&t);
        let n = t.len();
        let gyro = col3(Some(&gyro), n, "gyro")?.unwrap_or_default();
        let accel = col3(Some(&accel), n, "accel")?.unwrap_or_default();
        let mag = col3(mag.as_ref(), n, "mag")?;
        let baro = col1(baro.as_ref(), n, "baro")?;
        let temp = col1(temp.as_ref(), n, "temp")?;
        // The required columns first, then each optional one over them: no per-row test of which
        // columns came.
        let idle = Physical::powered_idle();
        let mut samples: Vec<Physical> = gyro
            .chunks_exact(3)
            .zip(accel.chunks_exact(3))
            .map(|(g, a)| Physical { gyro_dps: [g[0], g[1], g[2]], accel_g: [a[0], a[1], a[2]], ..idle })
            .collect();
        if let Some(mag) = mag {
            samples.iter_mut().zip(mag.chunks_exact(3)).for_each(|(p, m)| p.mag_gauss = [m[0], m[1], m[2]]);
        }
        if let Some(baro) = baro {
            samples.iter_mut().zip(baro.iter()).for_each(|(p, &b)| p.baro_mbar = b);
        }
        if let Some(temp) = temp {
            samples.iter_mut().zip(temp.iter()).for_each(|(p, &x)| p.temp_c = x);
        }
        self.input_reach_s = t.last().copied().or(self.input_reach_s);
        let mut inner = self.inner();
        guard(|| iq::with_formats(&self.formats, || inner.push(&t, samples)))?.map_err(to_py)?.map_err(to_py)
    }

    /// Append recorded bursts (an emulator built with `replay=True`): t (s since power-on, strictly
    /// increasing) and words (n×15 uint16: the command frame's answer, SUPPLY_OUT … AUX_ADC).
    fn push_words(&mut self, t: PyReadonlyArray1<'_, f64>, words: PyReadonlyArray2<'_, u16>) -> PyResult<()> {
        let t = t.as_array().to_vec();
        let w = words.as_array();
        if w.shape() != [t.len(), RECORDED_WORDS] {
            return Err(to_py(Error::Input(format!(
                "recorded words: shape {:?}, expected ({}, {RECORDED_WORDS})",
                w.shape(),
                t.len()
            ))));
        }
        let rows: Vec<[u16; RECORDED_WORDS]> = w.rows().into_iter().map(|r| std::array::from_fn(|i| r[i])).collect();
        self.input_reach_s = t.last().copied().or(self.input_reach_s);
        let mut inner = self.inner();
        guard(|| iq::with_formats(&self.formats, || inner.push_words(&t, &rows)))?.map_err(to_py)?.map_err(to_py)
    }

    /// Append fixes of the board's GPS stream (from the first call on, the board has a GPS): t (s, the
    /// fix's time of validity on the input's clock), ground speed (m/s) and course over ground
    /// (degrees from true north), one per fix, and the receiver's latency (s): each fix reaches the
    /// firmware at t + latency. Give a chunk's fixes before its physical input.
    fn push_gps(
        &mut self,
        t: PyReadonlyArray1<'_, f64>,
        latency_s: f64,
        speed_mps: PyReadonlyArray1<'_, f64>,
        course_deg: PyReadonlyArray1<'_, f64>,
    ) -> PyResult<()> {
        let (t, v, c) = (t.as_array(), speed_mps.as_array(), course_deg.as_array());
        if v.len() != t.len() || c.len() != t.len() {
            return Err(to_py(Error::Input(format!(
                "GPS fixes: {} times, {} speeds and {} courses; expected one of each per fix",
                t.len(),
                v.len(),
                c.len()
            ))));
        }
        let fixes: Vec<GpsFix> =
            (0..t.len()).map(|i| GpsFix { t_s: t[i], latency_s, ground_speed_mps: v[i], course_deg: c[i] }).collect();
        self.inner().push_gps(&fixes).map_err(to_py)
    }

    /// A hint: the input will end at `t_s` (seconds, the time of its last row, as pushed). The
    /// output columns are then sized once for the whole run, extrapolated from the first run that
    /// produces rows, instead of growing by doubling (which copies them). Only worth giving when
    /// the output is taken once, at the end.
    fn expect_input_until(&mut self, t_s: f64) {
        self.expected_end_s = Some(t_s).filter(|t| t.is_finite());
    }

    /// No more input will come.
    fn end(&mut self) {
        self.inner().end();
    }

    /// Run every tick the input covers; True when the input has ended and everything ran. The
    /// output of the call is held (its events sorted by time) until `take`.
    fn run(&mut self, py: Python<'_>) -> PyResult<bool> {
        loop {
            match self.run_block(py)? {
                "block_full" => continue,
                progress => return Ok(progress == "finished"),
            }
        }
    }

    /// Run the ticks the input covers, a block of them at most (`_core.BLOCK_TICKS`), and hold their output until `take`. Returns `"block_full"` (take the output
    /// if it is to stay bounded, then call again: the input may cover more), `"need_input"` or
    /// `"finished"` (the input has ended and everything ran).
    fn run_block(&mut self, py: Python<'_>) -> PyResult<&'static str> {
        // The GIL is released while the emulator runs: other Python threads (a progress bar, a
        // second emulator in a thread pool) keep going.
        // Output rows are uniform in input time: the whole run's are the first output's times
        // expected end / input reach.
        let scale = match (self.expected_end_s, self.input_reach_s) {
            (Some(end), Some(reach)) if reach > 0.0 && end > reach => Some(end / reach),
            _ => None,
        };
        let held = &mut self.held;
        let (inner, formats) = (&self.inner, &self.formats);
        let (progress, sized) = py
            .detach(|| {
                guard(|| {
                    iq::with_formats(formats, || {
                        let mut inner = inner.lock().unwrap_or_else(|e| e.into_inner());
                        let progress = inner.run()?;
                        let out = inner.take();
                        let scale = scale.filter(|_| !out.budget.is_empty());
                        held.append(out, scale);
                        Ok::<_, Error>((progress, scale.is_some()))
                    })
                })
            })?
            .map_err(to_py)?
            .map_err(to_py)?;
        if sized {
            self.expected_end_s = None;
        }
        Ok(match progress {
            Progress::NeedInput => "need_input",
            Progress::BlockFull => "block_full",
            Progress::Finished => "finished",
        })
    }

    /// SYSCLKOUT cycles of each compute stage, from the op counts and the cost table.
    fn stage_cycles(&self) -> Vec<(&'static str, u64)> {
        self.inner().stage_cycles()
    }

    /// Every compute stage's price, as a dict: `update_period_s` (the attitude step T),
    /// `code_location_factor`, `arith_section` (`float` or `iq`) and, per stage (`entry`, `decode`,
    /// `attitude`, `euler`, `navigation`, `interpolation`, `exit`), a dict with `cycles`, `counts`
    /// (op kind → count; empty for entry and exit) and `terms`: a list of dicts `op`, `count`, `key`
    /// (the cost-table entry), `unit_cycles`, `scaled` (whether the code-location factor applies).
    fn stage_costs<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let prices = price_list(&self.profile, &self.costs, &self.inner().stage_costs());
        let d = PyDict::new(py);
        d.set_item("update_period_s", prices.update_period_s)?;
        d.set_item("code_location_factor", prices.code_location_factor)?;
        d.set_item("arith_section", prices.arith_section)?;
        for stage in &prices.stages {
            let counted = stage.counts.map(|_| stage.terms.as_slice());
            let sd = stage_dict(py, stage.cycles, counted, &stage.terms)?;
            // The stage's parts (the DCM's attitude update), each priced like a stage, in order.
            let parts = PyDict::new(py);
            for part in &stage.parts {
                parts.set_item(part.name, stage_dict(py, part.cycles, Some(&part.terms), &part.terms)?)?;
            }
            sd.set_item("parts", parts)?;
            d.set_item(stage.name, sd)?;
        }
        Ok(d)
    }

    /// Record every CS edge and SPI frame from now on (off by default: it costs memory per frame).
    fn enable_bus_log(&mut self) {
        self.inner().enable_bus_log();
    }

    /// The bus log since the last call, as numpy columns: `cs_*` per CS edge, `frame_*` per frame.
    /// With `stop=True` recording stops too.
    #[pyo3(signature = (stop=false))]
    fn take_bus_log<'py>(&mut self, py: Python<'py>, stop: bool) -> PyResult<Bound<'py, PyDict>> {
        let log = self.inner().take_bus_log(stop);
        bus_log_dict(py, &log)
    }

    /// The output since the last call, as a dict of numpy arrays (and a list of event dicts).
    fn take<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let rest = self.inner().take();
        self.held.append(rest, None);
        std::mem::take(&mut self.held).into_dict(py)
    }
}

/// One stage's price as a dict (see `Emulator.stage_costs`).
fn stage_dict<'py>(
    py: Python<'py>,
    cycles: u64,
    counted: Option<&[CostTerm]>,
    terms: &[CostTerm],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("cycles", cycles)?;
    let counts = PyDict::new(py);
    for t in counted.unwrap_or_default() {
        counts.set_item(t.op, t.count)?;
    }
    d.set_item("counts", counts)?;
    let lines = terms
        .iter()
        .map(|t| {
            Ok(py_dict!(py;
                "op" => t.op, "count" => t.count, "key" => t.key, "unit_cycles" => t.unit_cycles, "scaled" => t.scaled,
            ))
        })
        .collect::<PyResult<Vec<_>>>()?;
    d.set_item("terms", lines)?;
    Ok(d)
}

/// A column of the output, handed to numpy without a copy: a field of one value per row becomes a
/// 1-D array, a field of N values an n×N array.
trait IntoColumn {
    fn into_column(self, py: Python<'_>) -> Bound<'_, PyAny>;
}

macro_rules! one_value_columns {
    ($($t:ty),*) => {$(
        impl IntoColumn for Vec<$t> {
            fn into_column(self, py: Python<'_>) -> Bound<'_, PyAny> {
                self.into_pyarray(py).into_any()
            }
        }
    )*};
}
one_value_columns!(u64, i64, f64, bool);

impl<T: numpy::Element, const N: usize> IntoColumn for Vec<[T; N]> {
    fn into_column(self, py: Python<'_>) -> Bound<'_, PyAny> {
        let rows = self.len();
        Array2::from_shape_vec((rows, N), self.into_flattened())
            .unwrap_or_else(|_| unreachable!("rows have N values"))
            .into_pyarray(py)
            .into_any()
    }
}

/// Rows to make room for: `scale` times `rows`, with 1 % and 64 rows of margin (the first output
/// lags its input by up to a tick), capped at 2^28 so that a wild hint cannot reserve without bound.
fn room_for(rows: usize, scale: f64) -> usize {
    ((rows as f64 * scale * 1.01) as usize + 64).min(1 << 28)
}

/// Declares [`Columns`]: one column per output field (`name: type = rows.field`), in the order
/// `Emulator.take` returns them.
macro_rules! output_columns {
    ($($name:ident: $t:ty = $rows:ident.$field:ident),* $(,)?) => {
        /// The output in columns, as `Emulator.take` returns it.
        #[derive(Default)]
        struct Columns {
            $($name: Vec<$t>,)*
            events: Vec<Event>,
        }

        // The columns are the core's output table (`sins_core::emulator::COLUMNS`), in order.
        const _: () = assert!(
            sins_core::emulator::is_column_list(&[$(stringify!($name)),*]),
            "output_columns! differs from sins_core's output::COLUMNS"
        );

        impl Columns {
            /// Append one run's output (rows in order; events after the ones already held). With
            /// `scale`, first make room for `scale` times this output's rows (see `expect_input_until`).
            fn append(&mut self, o: Output, scale: Option<f64>) {
                if let Some(scale) = scale {
                    // A hint: if the memory is not there, the columns just grow as they would have.
                    $(let _ = self.$name.try_reserve_exact(room_for(o.$rows.len(), scale));)*
                }
                $(self.$name.extend(o.$rows.iter().map(|r| r.$field));)*
                self.events.extend(o.events);
            }

            /// The columns as numpy arrays (moved, not copied) and the events as dicts.
            fn into_dict(self, py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
                let d = PyDict::new(py);
                $(d.set_item(stringify!($name), self.$name.into_column(py))?;)*
                let events = self.events.iter().map(|e| event_dict(py, e)).collect::<PyResult<Vec<_>>>()?;
                d.set_item("events", events)?;
                Ok(d)
            }
        }
    };
}

output_columns! {
    cycle_step: u64 = cycles.step,
    cycle_t_ps: u64 = cycles.t_ps,
    cycle_quat: [f64; 4] = cycles.quat,
    cycle_euler_deg: [f64; 3] = cycles.euler_deg,
    cycle_vel_enu: [f64; 3] = cycles.vel_enu,
    cycle_pos: [f64; 3] = cycles.pos,
    read_tick: u64 = reads.tick,
    read_t_cs_ps: u64 = reads.t_cs_ps,
    read_t_start_ps: u64 = reads.t_start_ps,
    read_t_end_ps: u64 = reads.t_end_ps,
    read_words: [u16; sins_core::emulator::READ_WORDS] = reads.words,
    read_rate: [f64; 3] = reads.rate,
    read_accel: [f64; 3] = reads.accel,
    read_sample_index: i64 = reads.sample_index,
    read_sample_ps: u64 = reads.sample_ps,
    read_assumed_s: f64 = reads.assumed_s,
    read_age_ps: u64 = reads.age_ps,
    budget_tick: u64 = budget.tick,
    budget_tick_ps: u64 = budget.tick_ps,
    budget_start_ps: u64 = budget.start_ps,
    budget_entry_end_ps: u64 = budget.entry_end_ps,
    budget_spi_start_ps: u64 = budget.spi_start_ps,
    budget_spi_end_ps: u64 = budget.spi_end_ps,
    budget_decode_end_ps: u64 = budget.decode_end_ps,
    budget_attitude_end_ps: u64 = budget.attitude_end_ps,
    budget_euler_end_ps: u64 = budget.euler_end_ps,
    budget_nav_end_ps: u64 = budget.nav_end_ps,
    budget_end_ps: u64 = budget.end_ps,
    budget_deadline_ps: u64 = budget.deadline_ps,
    budget_step: bool = budget.step,
    budget_overrun: bool = budget.overrun,
    dcm_step: u64 = corrections.step,
    dcm_omega_p: [f64; 3] = corrections.omega_p,
    dcm_omega_i: [f64; 3] = corrections.omega_i,
    dcm_error_rp: [f64; 3] = corrections.error_rp,
    dcm_error_yaw: [f64; 3] = corrections.error_yaw,
    dcm_orthogonality: f64 = corrections.orthogonality,
    wing_step: u64 = wing.step,
    wing_alpha_deg: f64 = wing.alpha_deg,
    wing_axis: [f64; 3] = wing.axis,
    wing_axis_source: u64 = wing.axis_source,
    wing_at_rest: bool = wing.at_rest,
}

fn bus_log_dict<'py>(py: Python<'py>, log: &[LinkRecord]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let (mut cs_t, mut cs_low) = (Vec::new(), Vec::new());
    let mut frames: Vec<FrameRecord> = Vec::with_capacity(log.len());
    for r in log {
        match r {
            LinkRecord::Cs { t_ps, low } => {
                cs_t.push(*t_ps);
                cs_low.push(*low);
            }
            LinkRecord::Frame(f) => frames.push(*f),
        }
    }
    d.set_item("cs_t_ps", cs_t.into_pyarray(py))?;
    d.set_item("cs_low", cs_low.into_pyarray(py))?;
    macro_rules! frame_col {
        ($name:literal, $f:expr) => {
            d.set_item($name, frames.iter().map($f).collect::<Vec<_>>().into_pyarray(py))?;
        };
    }
    frame_col!("frame_index", |f| f.index);
    frame_col!("frame_start_ps", |f| f.start_ps);
    frame_col!("frame_end_ps", |f| f.end_ps);
    frame_col!("frame_first_edge_ps", |f| f.timing.first_edge);
    frame_col!("frame_last_edge_ps", |f| f.timing.last_edge);
    frame_col!("frame_sclk_period_ps", |f| f.timing.sclk_period);
    frame_col!("frame_bits", |f| f.timing.bits);
    frame_col!("frame_selected", |f| f.selected);
    frame_col!("frame_master_tx", |f| f.master_tx);
    frame_col!("frame_master_rx", |f| f.master_rx);
    frame_col!("frame_din", |f| f.din);
    frame_col!("frame_dout", |f| f.dout);
    Ok(d)
}
