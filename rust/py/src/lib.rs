//! The Python binding, `sins_fw._core`. Thin on purpose: argument conversion, error mapping, and
//! whole arrays in and out (never a Python call per sample).

use pyo3::prelude::*;
use sins_core::profile::Profile;

mod errors;

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

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", sins_core::VERSION)?;
    m.add_function(wrap_pyfunction!(resolve_profile, m)?)?;
    m.add_function(wrap_pyfunction!(profile_keys, m)?)?;
    Ok(())
}
