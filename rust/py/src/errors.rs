//! Core errors and panics → `sins_fw.errors` exceptions.

use pyo3::PyErr;
use sins_core::Error;

pyo3::import_exception!(sins_fw.errors, ProfileError);
pyo3::import_exception!(sins_fw.errors, TraceError);
pyo3::import_exception!(sins_fw.errors, RegisterError);
pyo3::import_exception!(sins_fw.errors, ConfigError);
pyo3::import_exception!(sins_fw.errors, InternalError);

/// The Python exception for a core error, with the core's message.
pub fn to_py(e: Error) -> PyErr {
    match e {
        Error::Profile(m) => ProfileError::new_err(m),
        Error::Input(m) => TraceError::new_err(m),
        Error::Register(m) => RegisterError::new_err(m),
        Error::Config(m) => ConfigError::new_err(m),
    }
}

/// Run core code, turning a panic into `InternalError` so that a bug never aborts the interpreter
/// and always reaches the user as one documented exception class.
pub fn guard<R>(f: impl FnOnce() -> R) -> Result<R, PyErr> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).map_err(|payload| {
        let msg = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into());
        InternalError::new_err(format!("internal error in the emulator core (please report): {msg}"))
    })
}
