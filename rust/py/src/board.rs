//! `_core.encode`/`_core.decode` (ADIS16407 words) and `_core.Board`: the F28335 SPI-A, GPIO57 and
//! the ADIS16407 driven register by register from Python, as firmware would, in virtual time.

use std::sync::Mutex;

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sins_core::bus::link::LinkRecord;
use sins_core::device::{self, Channel, GyroRange, Physical};
use sins_core::host::HostBoard;
use sins_core::profile::Profile;
use sins_core::time::{ps_to_s, s_to_ps};
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

/// The board without firmware ([`HostBoard`]): SPI-A, LOSPCP, the GPIO data registers (GPIO57 is
/// the chip select) and an ADIS16407 with the profile's errors and faults, at virtual time `now`.
#[pyclass(module = "sins_fw._core")]
pub struct Board {
    inner: Mutex<HostBoard>,
}

impl Board {
    fn with<R>(&self, f: impl FnOnce(&mut HostBoard) -> Result<R, Error>) -> PyResult<R> {
        let mut s = self.inner.lock().unwrap_or_else(|e| e.into_inner());
        guard(|| f(&mut s))?.map_err(to_py)
    }
}

/// A 16-bit word from Python, or an error naming what it is for and the value.
fn word(what: &str, value: i64) -> Result<u16, Error> {
    u16::try_from(value).map_err(|_| {
        let shown = if value < 0 { format!("-0x{:X}", value.unsigned_abs()) } else { format!("0x{value:X}") };
        Error::Register(format!("{what} = {value} ({shown}): expected 0…0xFFFF (a 16-bit word)"))
    })
}

#[pymethods]
impl Board {
    /// A board of a profile (TOML text, source name, overrides). The bus log is on.
    #[new]
    fn new(text: &str, source: &str, overrides: Vec<String>) -> PyResult<Self> {
        let build = || -> Result<HostBoard, Error> { HostBoard::new(&Profile::from_toml(text, source, &overrides)?) };
        Ok(Board { inner: Mutex::new(guard(build)?.map_err(to_py)?) })
    }

    /// Virtual time, s.
    #[getter]
    fn now_s(&self) -> PyResult<f64> {
        self.with(|s| Ok(s.now_s()))
    }

    /// LSPCLK, Hz.
    #[getter]
    fn lspclk_hz(&self) -> PyResult<f64> {
        self.with(|s| Ok(s.lspclk_hz()))
    }

    /// Let `seconds` of virtual time pass (a negative rounding residue is no step).
    fn advance(&self, seconds: f64) -> PyResult<()> {
        self.with(|s| s.advance_s(seconds))
    }

    /// Move virtual time to `t_s` seconds since power-on.
    fn advance_to(&self, t_s: f64) -> PyResult<()> {
        self.with(|s| s.advance_to_s(t_s))
    }

    /// Write a register by name (SPI-A, LOSPCP, GPIO data registers), the value checked.
    fn write(&self, register: &str, value: i64) -> PyResult<()> {
        self.with(|s| s.write_named(register, value))
    }

    /// Read a register by name.
    fn read(&self, register: &str) -> PyResult<u32> {
        self.with(|s| s.read_named(register))
    }

    /// Write a 16-bit word at a C28x address.
    fn write_address(&self, address: i64, value: i64) -> PyResult<()> {
        self.with(|s| {
            let a =
                u32::try_from(address).map_err(|_| Error::Register(format!("C28x address {address}: expected ≥ 0")))?;
            s.write(a, word(&format!("the word at 0x{a:04X}"), value)?)
        })
    }

    /// Read the 16-bit word at a C28x address.
    fn read_address(&self, address: i64) -> PyResult<u16> {
        self.with(|s| {
            let a =
                u32::try_from(address).map_err(|_| Error::Register(format!("C28x address {address}: expected ≥ 0")))?;
            s.read(a)
        })
    }

    /// Drive GPIO57, the chip select (`high=False` asserts it).
    fn set_gpio57(&self, high: bool) -> PyResult<()> {
        self.with(|s| s.set_gpio57(high))
    }

    /// The published InitSpi register writes from the profile, now.
    fn init_spi(&self) -> PyResult<()> {
        self.with(|s| s.init_spi())
    }

    /// Set SCLK (Hz; exact or the nearest below) and/or the SPI mode (0…3) through SPI-A's registers;
    /// returns what was set: spibrr, sclk_hz, exact, mode, lspclk_hz.
    #[pyo3(signature = (sclk_hz=None, mode=None))]
    fn configure_spi<'py>(
        &self,
        py: Python<'py>,
        sclk_hz: Option<f64>,
        mode: Option<i64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let set = self.with(|s| {
            let m = mode
                .map(|m| u8::try_from(m).map_err(|_| Error::Config(format!("SPI mode {m}: expected 0…3"))))
                .transpose()?;
            s.configure_spi(sclk_hz, m)
        })?;
        Ok(py_dict!(py;
            "spibrr" => set.spibrr, "sclk_hz" => set.sclk_hz, "exact" => set.exact, "mode" => set.mode,
            "lspclk_hz" => set.lspclk_hz,
        ))
    }

    /// One frame as a polling driver does it (see `HostBoard::transfer`); returns the received word.
    fn transfer(&self, din: i64, stall_s: f64) -> PyResult<u16> {
        self.with(|s| {
            if !(stall_s.is_finite() && stall_s >= 0.0) {
                return Err(Error::Input(format!("transfer stall {stall_s} s: expected a finite time ≥ 0 s")));
            }
            s.transfer(word("SPITXBUF", din)?, s_to_ps(stall_s))
        })
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
            s.set_physical(Physical {
                gyro_dps: gyro?,
                accel_g: accel?,
                mag_gauss: mag.transpose()?.unwrap_or(idle.mag_gauss),
                baro_mbar: baro_mbar.unwrap_or(idle.baro_mbar),
                temp_c: temp_c.unwrap_or(idle.temp_c),
                supply_v: supply_v.unwrap_or(idle.supply_v),
                aux_v: idle.aux_v,
            })
        })
    }

    /// An ADIS16407 register's current contents (no SPI traffic), by address.
    fn peek_device(&self, addr: i64) -> PyResult<u16> {
        self.with(|s| s.peek_device(addr))
    }

    /// The transaction log since the last call: frames (index, start/end s, first/last SCLK edge s,
    /// master TX/RX, DIN/DOUT) and CS edges, as a list of dicts in time order.
    fn take_log<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let log = self.with(|s| Ok(s.take_log()))?;
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

    /// Events of SPI-A, the link and the device since the last call, each with `frame` (the SPI-A
    /// character index of the frame it concerns, as in the log) and `din`, or None for both.
    fn take_events<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let events = self.with(|s| Ok(s.take_events()))?;
        events
            .iter()
            .map(|e| {
                let d = event_dict(py, &e.event)?;
                // The frame on the wires at the event (for a CS edge the frame before it) when the
                // event names none of its own (`HostEvent::frame`).
                d.set_item("frame", e.frame_index())?;
                d.set_item("din", e.din())?;
                Ok(d)
            })
            .collect()
    }
}
