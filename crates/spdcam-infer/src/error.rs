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
    /// The patches sampled from a photo, or a feature row, do not behave like the chart
    /// they are said to be (no chart there, the corners placed off it, another chart): no
    /// number is made of them. The message names what is wrong and what to do
    /// ([`crate::trust::chart_identity`]).
    #[error("{0}")]
    NotTheChart(String),
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

/// Why the photo at `path` gave no estimate, as every front end says it: `PATH: unusable
/// photo: WHY`, the photo named once (the library's message often names it already).
pub fn unusable_photo(path: &std::path::Path, why: &dyn std::fmt::Display) -> String {
    let shown = path.display().to_string();
    let why = why.to_string();
    let why = why.strip_prefix(&format!("{shown}: ")).unwrap_or(&why);
    format!("{shown}: unusable photo: {why}")
}

/// Result with the crate's [`InferError`].
pub type Result<T, E = InferError> = std::result::Result<T, E>;
