//! spdcam-infer: the light's SPD from chart features or photos with a trained model — the
//! `.spdm` model file, the networks' forward pass in plain Rust, the scalings, the PCA
//! decoding, and the models shipped inside spdcam. It does not depend on the training stack
//! (burn), so estimating builds fast and small.
//!
//! ```text
//! features ─► FeatureScaler ─► Network (cnn1d | mlp | linear) ─► TargetScaler⁻¹ ─► Target ─► SPD
//!             (per-sample max,   (plain Rust forward pass)        ([0,1] → PCA      (PCA inverse or
//!              per-feature                                         coefficients     Σ wᵢ·channelᵢ,
//!              min-max)                                            or weights)      max-normalised)
//! ```
//!
//! Estimating the light from a photo of a chart with the shipped models:
//!
//! ```
//! use spdcam_core::builtin::DataDir;
//! use spdcam_core::spectral::Grid;
//! use spdcam_infer::{estimate_photo, ModelSet, PhotoOptions};
//!
//! let models = ModelSet::shipped()?;
//! let photo = std::path::Path::new("../../examples/sg-telelumen.jpg");
//! let grid = Grid::parse("400-700:5")?;
//! let estimate = estimate_photo(photo, &models, &PhotoOptions::default(), &DataDir::new(None), &grid)?;
//! assert_eq!(estimate.spd.len(), 61);
//! println!("{}", estimate.colorimetry.label());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod absolute;
pub mod error;
pub mod estimate;
pub mod model;
pub mod network;
pub mod pca;
pub mod plot;
pub mod record;
pub mod report;
pub mod scale;
pub mod shipped;
pub mod stream;
pub mod target;
pub mod trust;

pub use error::{InferError, Result};
pub use estimate::{
    analyse_photo_bytes, estimate_decoded, estimate_features, estimate_photo, estimate_photo_bytes,
    Estimate, FeatureRows, PhotoOptions,
};
pub use model::Model;
pub use shipped::ModelSet;
