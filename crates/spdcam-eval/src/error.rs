//! The error type of the evaluation protocols.

use std::path::PathBuf;

/// Errors of spdcam-eval. Messages name the file, value or setting that is wrong.
#[derive(Debug, thiserror::Error)]
pub enum EvalError {
    /// An error of the core library (spectra, cameras, charts, files).
    #[error(transparent)]
    Core(#[from] spdcam_core::Error),
    /// An error of the inference crate (model files, estimates, calibrations).
    #[error(transparent)]
    Infer(#[from] spdcam_infer::InferError),
    /// A setting or an input is out of range or inconsistent with another one.
    #[error("{0}")]
    Invalid(String),
    /// A file or directory could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
}

impl EvalError {
    /// Shorthand for [`EvalError::Invalid`].
    pub fn invalid(message: impl Into<String>) -> Self {
        EvalError::Invalid(message.into())
    }
}

/// Result with the crate's [`EvalError`].
pub type Result<T, E = EvalError> = std::result::Result<T, E>;
