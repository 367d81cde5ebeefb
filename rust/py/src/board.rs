//! `_core.encode`/`_core.decode` (ADIS16407 words) and `_core.Board`: the F28335 SPI-A, GPIO57 and
//! the ADIS16407 driven register by register from Python, as firmware would, in virtual time.

use std::sync::Mutex;

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sins_core::bus::link::{LinkRecord, SpiLink};
use sins_core::device::{self, Adis16407, Channel, Constant, GyroRange, Physical};
use sins_core::dsp::spi;
use sins_core::profile::Profile;
use sins_core::time::{ps_to_s, s_to_ps, Ps};
use sins_core::Error;

use crate::errors::{guard, to_py};
use crate::event_dict;

/// Encode a physical value into an ADIS16407 output word: (code, overrange).
#[pyfunction]
#[pyo3(signature = (channel, value, range_dps=300.0))]
pub fn encode(channel: &str, value: f64, range_dps: f64) -> PyResult<(u16, bool)> {
    let run = || -> Result<(u16, bool), Error> {
        let e = device::encode(Channel::from_name(channel)?, value, GyroRange::from_dps(range_dps)?)?;
        Ok((e.code, e.overrange))
    };
    guard(run)?.map_err(to_py)
}

/// Decode an ADIS16407 output word: (value, nd, ea).
#[pyfunction]
#[pyo3(signature = (channel, word, range_dps=300.0))]
pub fn decode(channel: &str, word: u16, range_dps: f64) -> PyResult<(f64, bool, bool)> {
    let run = || -> Result<(f64, bool, bool), Error> {
        let d = device::decode(Channel::from_name(channel)?, word, GyroRange::from_dps(range_dps)?);
        Ok((d.value, d.nd, d.ea))
    };
    guard(run)?.map_err(to_py)
}

/// SPI-A register offsets by name.
fn spi_offset(name: &str) -> Result<u16, Error> {
    Ok(match name.to_ascii_uppercase().as_str() {
        "SPICCR" => spi::SPICCR,
        "SPICTL" => spi::SPICTL,
        "SPISTS" => spi::SPISTS,
        "SPIBRR" => spi::SPIBRR,
        "SPIRXEMU" => spi::SPIRXEMU,
        "SPIRXBUF" => spi::SPIRXBUF,
        "SPITXBUF" => spi::SPITXBUF,
        "SPIDAT" => spi::SPIDAT,
        "SPIFFTX" => spi::SPIFFTX,
        "SPIFFRX" => spi::SPIFFRX,
        "SPIFFCT" => spi::SPIFFCT,
        "SPIPRI" => spi::SPIPRI,
        _ => {
            return Err(Error::Register(format!(
                "SPI-A register `{name}`: expected one of SPICCR, SPICTL, SPISTS, SPIBRR, SPIRXEMU, SPIRXBUF, \
                 SPITXBUF, SPIDAT, SPIFFTX, SPIFFRX, SPIFFCT, SPIPRI"
            )))
        }
    })
}

/// The board without firmware: SPI-A (reset state), GPIO57 and an ADIS16407 seeing a constant
/// physical state, at virtual time `now`.
#[pyclass(module = "sins_fw._core")]
pub struct Board {
    inner: Mutex<State>,
}

struct State {
    link: SpiLink<Adis16407>,
    now: Ps,
}

impl Board {
    fn with<R>(&self, f: impl FnOnce(&mut State) -> Result<R, Error>) -> PyResult<R> {
        let mut s = self.inner.lock().unwrap_or_else(|e| e.into_inner());
        guard(|| f(&mut s))?.map_err(to_py)
    }
}

#[pymethods]
impl Board {
    /// A board of a profile (TOML text, source name, overrides). The bus log is on.
    #[new]
    fn new(text: &str, source: &str, overrides: Vec<String>) -> PyResult<Self> {
        let build = || -> Result<State, Error> {
            let profile = Profile::from_toml(text, source, &overrides)?;
            let mut dev = Adis16407::new(&profile.device)?;
            dev.set_stimulus(Box::new(Constant(Physical::powered_idle())));
            let mut link = SpiLink::from_profile(&profile, dev)?;
            link.enable_log();
            Ok(State { link, now: 0 })
        };
        Ok(Board { inner: Mutex::new(guard(build)?.map_err(to_py)?) })
    }

    /// Virtual time, s.
    #[getter]
    fn now_s(&self) -> PyResult<f64> {
        self.with(|s| Ok(ps_to_s(s.now)))
    }

    /// Let `seconds` of virtual time pass (the device samples, characters shift).
    fn advance(&self, seconds: f64) -> PyResult<()> {
        self.with(|s| {
            if !(seconds.is_finite() && seconds >= 0.0) {
                return Err(Error::Input(format!("advance({seconds}): expected a finite time ≥ 0 s")));
            }
            s.now += s_to_ps(seconds);
            s.link.advance(s.now)
        })
    }

    /// Write an SPI-A register (by name) now.
    fn write(&self, register: &str, value: u16) -> PyResult<()> {
        self.with(|s| {
            let now = s.now;
            s.link.write(spi_offset(register)?, value, now)
        })
    }

    /// Read an SPI-A register (by name) now.
    fn read(&self, register: &str) -> PyResult<u16> {
        self.with(|s| {
            let now = s.now;
            s.link.read(spi_offset(register)?, now)
        })
    }

    /// Drive GPIO57, the chip select (`high=False` asserts it).
    fn set_gpio57(&self, high: bool) -> PyResult<()> {
        self.with(|s| {
            let now = s.now;
            s.link.set_gpio57(high, now)
        })
    }

    /// The published InitSpi register writes from the profile, now.
    fn init_spi(&self, text: &str, source: &str, overrides: Vec<String>) -> PyResult<()> {
        self.with(|s| {
            let p = Profile::from_toml(text, source, &overrides)?;
            let now = s.now;
            s.link.init_from_profile(&p.spi, now)
        })
    }

    /// When SPISTS.INT_FLAG sets (None: no character in flight), s.
    fn int_flag_time_s(&self) -> PyResult<Option<f64>> {
        self.with(|s| Ok(s.link.int_flag_time().map(ps_to_s)))
    }

    /// What the ADIS16407 sees from now on: gyro (°/s), accel (g), and optionally mag (gauss),
    /// pressure (mbar), temperature (°C), supply (V).
    #[pyo3(signature = (gyro_dps, accel_g, mag_gauss=None, baro_mbar=None, temp_c=None, supply_v=None))]
    fn set_physical(
        &self,
        gyro_dps: PyReadonlyArray1<'_, f64>,
        accel_g: PyReadonlyArray1<'_, f64>,
        mag_gauss: Option<PyReadonlyArray1<'_, f64>>,
        baro_mbar: Option<f64>,
        temp_c: Option<f64>,
        supply_v: Option<f64>,
    ) -> PyResult<()> {
        let v3 = |a: &PyReadonlyArray1<'_, f64>, name: &str| -> Result<[f64; 3], Error> {
            let s = a.as_slice().map_err(|_| Error::Input(format!("{name}: expected a contiguous array")))?;
            <[f64; 3]>::try_from(s).map_err(|_| Error::Input(format!("{name}: expected 3 values, got {}", s.len())))
        };
        let gyro = v3(&gyro_dps, "gyro_dps");
        let accel = v3(&accel_g, "accel_g");
        let mag = mag_gauss.as_ref().map(|m| v3(m, "mag_gauss"));
        self.with(|s| {
            let idle = Physical::powered_idle();
            let p = Physical {
                gyro_dps: gyro?,
                accel_g: accel?,
                mag_gauss: mag.transpose()?.unwrap_or(idle.mag_gauss),
                baro_mbar: baro_mbar.unwrap_or(idle.baro_mbar),
                temp_c: temp_c.unwrap_or(idle.temp_c),
                supply_v: supply_v.unwrap_or(idle.supply_v),
                aux_v: idle.aux_v,
            };
            if !p.is_finite() {
                return Err(Error::Input("set_physical: every value must be finite".into()));
            }
            let now = s.now;
            s.link.advance(now)?;
            s.link.slave_mut().set_stimulus(Box::new(Constant(p)));
            Ok(())
        })
    }

    /// An ADIS16407 register's current contents (no SPI traffic), by address.
    fn peek_device(&self, addr: u8) -> PyResult<u16> {
        self.with(|s| s.link.slave().peek(addr))
    }

    /// The transaction log since the last call: frames (index, start/end s, first/last SCLK edge s,
    /// master TX/RX, DIN/DOUT) and CS edges, as a list of dicts in time order.
    fn take_log<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let log = self.with(|s| Ok(s.link.take_log()))?;
        log.iter()
            .map(|r| {
                let d = PyDict::new(py);
                match r {
                    LinkRecord::Cs { t_ps, low } => {
                        d.set_item("type", "cs")?;
                        d.set_item("t_s", ps_to_s(*t_ps))?;
                        d.set_item("low", *low)?;
                    }
                    LinkRecord::Frame(f) => {
                        d.set_item("type", "frame")?;
                        d.set_item("index", f.index)?;
                        d.set_item("start_s", ps_to_s(f.start_ps))?;
                        d.set_item("end_s", ps_to_s(f.end_ps))?;
                        d.set_item("first_edge_s", ps_to_s(f.timing.first_edge))?;
                        d.set_item("last_edge_s", ps_to_s(f.timing.last_edge))?;
                        d.set_item("master_tx", f.master_tx)?;
                        d.set_item("master_rx", f.master_rx)?;
                        d.set_item("din", f.din)?;
                        d.set_item("dout", f.dout)?;
                    }
                }
                Ok(d)
            })
            .collect()
    }

    /// Events of SPI-A, the link and the device since the last call.
    fn take_events<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let events = self.with(|s| {
            let mut all = s.link.drain_events();
            all.extend(s.link.slave_mut().drain_events());
            all.sort_by_key(|e| e.t_ps);
            Ok(all)
        })?;
        events.iter().map(|e| event_dict(py, e)).collect()
    }
}
