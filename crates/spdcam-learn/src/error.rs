//! The error type of the learning crate.

use std::path::PathBuf;

/// Errors of spdcam-learn. Messages name the file, value or setting that is wrong.
#[derive(Debug, thiserror::Error)]
pub enum LearnError {
    /// An error of the simulation library (datasets, spectra, files).
    #[error(transparent)]
    Core(#[from] spdcam_core::Error),
    /// An error of the inference crate (model files, scalings, targets).
    #[error(transparent)]
    Infer(#[from] spdcam_infer::InferError),
    /// A dataset directory could not be opened or read (`action`: "opening", "reading").
    #[error("{action} dataset {}: {source}", path.display())]
    Dataset {
        /// What failed.
        action: &'static str,
        /// The dataset directory.
        path: PathBuf,
        /// The cause.
        #[source]
        source: spdcam_core::Error,
    },
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
    /// A file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// A numerical step (SVD, a linear solve) failed.
    #[error("{0}")]
    Numerical(String),
}

impl LearnError {
    /// Shorthand for [`LearnError::Invalid`].
    pub fn invalid(message: impl Into<String>) -> Self {
        LearnError::Invalid(message.into())
    }
}

/// Result with the crate's [`LearnError`].
pub type Result<T, E = LearnError> = std::result::Result<T, E>;
