//! The error type of the inference crate.

use std::path::PathBuf;

/// Errors of spdcam-infer. Messages name the file, value or setting that is wrong.
#[derive(Debug, thiserror::Error)]
pub enum InferError {
    /// An error of the core library (spectra, photos, files).
    #[error(transparent)]
    Core(#[from] spdcam_core::Error),
    /// A setting or an input is out of range or inconsistent with another one.
    #[error("{0}")]
    Invalid(String),
    /// A model file is not a spdcam model, is damaged, or is of an unknown version.
    #[error("{path}: {message}")]
    ModelFile {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// A numerical step (SVD, a linear solve) failed.
    #[error("{0}")]
    Numerical(String),
}

impl InferError {
    /// Shorthand for [`InferError::Invalid`].
    pub fn invalid(message: impl Into<String>) -> Self {
        InferError::Invalid(message.into())
    }
}

/// Result with the crate's [`InferError`].
pub type Result<T, E = InferError> = std::result::Result<T, E>;
