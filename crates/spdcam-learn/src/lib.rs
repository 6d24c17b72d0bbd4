//! spdcam-learn: training the models that estimate the light's SPD from chart features — PCA
//! of the SPDs, the thesis's networks (1D CNN, MLP) trained with burn, a closed-form ridge
//! baseline, fine-tuning and evaluation. The model file, the forward pass and the scalings
//! live in `spdcam-infer` (import them from there), which estimating needs without burn.
//!
//! The modules in pipeline order:
//!
//! - [`synthetic`]: a small synthetic dataset in memory, for tests and benchmarks (real
//!   datasets come from `spdcam_core::dataset`).
//! - [`train`]: PCA or channel-weight targets, the scalings, and the training loop (Adam,
//!   early stopping) for the networks, or [`spdcam_infer::ridge`] regression in closed form for the
//!   `linear` model; fine-tuning a trained model on a new dataset. `burn_net`: the
//!   networks as burn modules, their weights laid out as `spdcam_infer::network`'s.
//! - [`recipe`]: choosing a fine-tuning recipe for a few photos by cross-validation.
//! - [`evaluate`]: scoring a model on a dataset (RMSE, GFC, SAM, SID; plots).
//! - [`experiment`]: the thesis's model-selection experiment on its virtual datasets.
//! - [`sim2real`]: the sim-to-real ablation (ridge on virtual data scored on the real photo
//!   sets) and the learning curve of fine-tuning on real photos.
//! - [`error`]: the crate's error type.
//!
//! Training the ridge baseline on a synthetic dataset and checking it on fresh samples:
//!
//! ```
//! use spdcam_core::spectral::Grid;
//! use spdcam_infer::network::Architecture;
//! use spdcam_infer::pca::Components;
//! use spdcam_infer::scale::RowScale;
//! use spdcam_learn::synthetic::gaussian_set;
//! use spdcam_infer::target::TargetKind;
//! use spdcam_learn::train::{train, Backend, Schedule, TrainOptions};
//!
//! let data = gaussian_set(400, 24, 1, 2);
//! let options = TrainOptions {
//!     row_scale: RowScale::Max,
//!     architecture: Architecture::Linear { ridge: 0.0 },
//!     target: TargetKind::Pca(Components::default()),
//!     grid: Grid::ESTIMATION,
//!     schedule: Schedule::thesis(),
//!     seed: 7,
//!     val_split: 0.15,
//!     backend: Backend::Cpu,
//! };
//! let trained = train(&data, None, &options, &mut |_| {})?;
//! let test = gaussian_set(20, 24, 99, 2);
//! let estimates = trained.model.estimate_rows(&test.samples.features)?;
//! assert_eq!(estimates.len(), 20 * Grid::ESTIMATION.count);
//! # Ok::<(), spdcam_learn::LearnError>(())
//! ```

#![deny(missing_docs)]

mod burn_net;
pub mod error;
pub mod evaluate;
pub mod experiment;
pub mod recipe;
pub mod sim2real;
pub mod synthetic;
pub mod train;

pub use error::{LearnError, Result};
