//! spdcam-learn: training the models that estimate the light's SPD from chart features — PCA
//! of the SPDs, the thesis's networks (1D CNN, MLP) trained with burn, a closed-form ridge
//! baseline, fine-tuning and evaluation. The model file, the forward pass and the scalings
//! live in `spdcam-infer` (re-exported here), which estimating needs without burn.

mod burn_net;
pub mod error;
pub mod evaluate;
pub mod recipe;
pub mod synthetic;
pub mod train;

pub use error::{LearnError, Result};
pub use spdcam_infer::{model, network, pca, record, scale, target, Model};
