//! Errors of the core. Each variant maps to one exception class in `sins_fw.errors`.

/// Everything that can go wrong in the core. Messages name the file, key, register or row and what
/// was expected, because they reach the user verbatim.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A profile key, type or value is wrong (→ `sins_fw.errors.ProfileError`).
    #[error("{0}")]
    Profile(String),
    /// Input data (a trace or arrays passed in) is malformed (→ `TraceError`).
    #[error("{0}")]
    Input(String),
    /// A register access or value the model rejects (→ `RegisterError`).
    #[error("{0}")]
    Register(String),
    /// A configuration the hardware cannot realise (→ `ConfigError`).
    #[error("{0}")]
    Config(String),
}

/// Result with the core's [`Error`].
pub type Result<T> = std::result::Result<T, Error>;
