//! spdcam-learn: estimating the light's SPD from chart features with learned models — PCA of
//! the SPDs, the thesis's networks (1D CNN, MLP) trained with burn, a closed-form ridge
//! baseline, the `.spdm` model file and a plain-Rust forward pass for fast estimates.
//!
//! ```text
//! features ─► FeatureScaler ─► Network (cnn1d | mlp | linear) ─► TargetScaler⁻¹ ─► Target ─► SPD
//!             (per-sample max,   (burn for training,              ([0,1] → PCA      (PCA inverse or
//!              per-feature        plain Rust for estimates)         coefficients     Σ wᵢ·channelᵢ,
//!              min-max)                                             or weights)      max-normalised)
//! ```

mod burn_net;
pub mod error;
pub mod evaluate;
pub mod model;
pub mod network;
pub mod pca;
pub mod scale;
pub mod synthetic;
pub mod target;
pub mod train;

pub use error::{LearnError, Result};
pub use model::Model;
