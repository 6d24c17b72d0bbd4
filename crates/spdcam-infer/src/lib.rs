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
//! The modules in pipeline order:
//!
//! - [`shipped`]: the models inside the binary and the [`ModelSet`] an estimate chooses
//!   from; [`model`]: the `.spdm` file ([`record`]: how a model was trained).
//! - [`scale`] (the feature and target scalings), [`network`] (the forward pass),
//!   [`target`] and [`pca`] (from the network's outputs back to an SPD).
//! - [`estimator`]: the [`Estimator`], built once from the models, the data directory and
//!   the output grid, the one path every front end (command line, web app, Python) takes
//!   from a photo (file, bytes, decoded) or feature rows (in memory, streamed) to a judged
//!   [`Estimate`]; its inputs: [`feature_rows`] (feature rows in memory) and
//!   [`photo_options`] (how photos are analysed, the charts looked for); [`estimate`]: what
//!   an estimate is (SPD, colorimetry, lighting metrics, verdict, bands); [`stream`]: feature
//!   rows read a block at a time, and the CSV layouts of many SPDs.
//! - Beside the spectrum's shape: [`colour_head`] (the light's u′v′ as the model predicts
//!   it), [`colour_map`] (a white light's CCT and Duv corrected as learnt on validation
//!   photos), [`measured_colour`] (the light's chromaticity a raw photo measured, given to
//!   the spectrum), [`kind_prior`] (the estimate kept among lights of the kind a person names) and
//!   [`absolute`] (approximate absolute levels from the photo's EXIF exposure, and the
//!   chart's linear level they rest on); [`places`]: the light compared across the charts
//!   of one photo.
//! - [`trust`]: how far an estimate can be trusted (self-check with the glare read on the
//!   chart, uncertainty bands, verdict). What an estimate means for a person (rounded
//!   numbers, the meter's screen, plots, the HTML report) is the `spdcam-present` crate's.
//! - [`ridge`]: closed-form ridge regression, the `linear` model's fit and the simple
//!   learner every protocol compares against (here, so that it runs without burn).
//! - [`error`]: the crate's error type.
//!
//! Estimating the light from the example photo of a ColorChecker Digital SG with the
//! shipped models:
//!
//! ```
//! use spdcam_core::builtin::DataDir;
//! use spdcam_core::spectral::{Grid, Spd, SpectralSet};
//! use spdcam_infer::{Estimator, PhotoOptions};
//! use std::path::Path;
//!
//! let examples = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples");
//! let grid = Grid::parse("400-700:5")?;
//! let estimator = Estimator::shipped(DataDir::new(None), grid)?;
//! let photo = Path::new(examples).join("sg-telelumen.jpg");
//! let mut estimate = estimator.estimate_photo(&photo, &PhotoOptions::default())?;
//! assert_eq!(estimate.spd.len(), grid.count);
//! // This spiky LED mix lies far from the Planckian locus: no CCT, the label says so.
//! match estimate.colorimetry.cct {
//!     Some(cct) => println!("CCT {cct:.0} K"),
//!     None => println!("no CCT: {}", estimate.colorimetry.label()),
//! }
//! // The true SPD beside the photo (380–780 nm, 5 nm), on the estimate's wavelengths.
//! let truth = SpectralSet::read_csv(&Path::new(examples).join("sg-telelumen.truth.csv"))?;
//! let truth = Spd::new(Grid::SIMULATION, truth.item(0).to_vec())?.resampled(&grid)?;
//! estimate.score_against(&truth)?;
//! let gfc = estimate.truth.unwrap().gfc;
//! println!("GFC against the truth {gfc:.4}");
//! assert!(gfc > 0.9);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![deny(missing_docs)]

pub mod absolute;
pub mod colour_head;
pub mod colour_map;
pub mod error;
pub mod estimate;
pub mod estimator;
pub mod feature_rows;
pub mod kind_prior;
pub mod measured_colour;
pub mod model;
pub mod network;
pub mod pca;
pub mod photo_options;
pub mod places;
pub mod record;
pub mod ridge;
pub mod scale;
pub mod shipped;
pub mod stream;
pub mod target;
pub mod trust;

pub use error::{InferError, Result};
pub use estimate::Estimate;
pub use estimator::{AnalysedPhoto, Estimator, PhotoEstimate, PhotoProgress, RowStream};
pub use feature_rows::FeatureRows;
pub use model::Model;
pub use photo_options::PhotoOptions;
pub use shipped::{ModelSet, NamedModel};
