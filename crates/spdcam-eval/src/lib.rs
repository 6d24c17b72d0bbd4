//! spdcam-eval: the protocols that measure spdcam's estimates and calibrate how far they can
//! be trusted — the trust calibration's fit and its report, the real-camera study, the
//! reliability diagram, the lamp validation, the coverage of measured lamps by lighting
//! recipes, and the held-out lamps and cameras they share. They sit between the
//! inference crate (the estimate they measure) and the command line (which parses their
//! options and prints their results), and need no training stack (burn): ridge regression, the
//! one learner they fit, lives in `spdcam_infer::ridge`.
//!
//! - [`held_out`]: the lamp library, the validation split's held-out cameras, the models
//!   measured.
//! - [`trust`]: the uncertainty calibration ([`trust::fit::calibrate`]) and its measurement
//!   ([`trust::report::TrustReport`]).
//! - [`real_cameras`]: the real photo sets split for choosing and reporting, the simple
//!   learners every number stands beside, virtual photos of a light prior.
//! - [`reliability`]: the reliability diagram.
//! - [`lamp_validation`]: held-out lamps photographed by held-out cameras and by an
//!   independent simple camera, scored per lamp type beside the average SPD
//!   ([`lamp_validation::LampValidation`]).
//! - [`colour`]: every model judged on the light's colour as a colour meter reads it
//!   (Δu′v′, CCT) on scene and patch-level photos by held-out cameras
//!   ([`colour::ColourReport`]).
//! - [`places`]: the light at several places of one photo, on rendered scenes of two to
//!   four charts ([`places::PlacesReport`]).
//! - [`light_kinds`]: a model's priors for each kind of light a person can name
//!   ([`light_kinds::KindFit`]).
//! - [`coverage`]: how well lighting recipes reach measured SPDs, per lamp type
//!   ([`coverage::Coverage`]).
//! - [`error`]: the crate's error type.
//!
//! The split-conformal quantile the bands are scaled by, on ten calibration errors:
//!
//! ```
//! use spdcam_eval::trust::judged::conformal_quantile;
//!
//! let mut errors: Vec<f64> = (1..=10).map(f64::from).collect();
//! // ⌈(n + 1)·0.8⌉ = 9: the 9th smallest, not the 8th a plain quantile would give.
//! assert_eq!(conformal_quantile(&mut errors, 0.8), 9.0);
//! ```

#![deny(missing_docs)]

pub mod colour;
pub mod coverage;
pub mod error;
pub mod held_out;
pub mod lamp_validation;
pub mod light_kinds;
pub mod places;
pub mod real_cameras;
pub mod reliability;
pub mod trust;

pub use error::{EvalError, Result};
