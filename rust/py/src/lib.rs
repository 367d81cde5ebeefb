//! The Python binding: `sins_fw._core`. Thin on purpose: conversions and error mapping only.

use pyo3::prelude::*;

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", sins_core::VERSION)?;
    Ok(())
}
