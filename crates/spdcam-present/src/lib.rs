//! spdcam-present: what a judged estimate ([`spdcam_infer::Estimate`]) means for a person,
//! the same in every front end (command line, HTML report, web page, Python). The inference
//! crate reads "features in, judged estimate out"; this crate only reads estimates.
//!
//! The modules, from numbers to pages:
//!
//! - [`rounding`]: the one rule every front end writes a number by (the PDG's rounding to
//!   the uncertainty; "not determinable from this photo" past stated widths), read from the
//!   metric registry ([`spdcam_core::quality::registry`]); [`meaningful`]: which metrics
//!   mean anything for the light.
//! - [`meter`]: what a colour meter's screen shows (headline, film and TV numbers);
//!   [`presentation`]: the estimate in words and rounded numbers, in the registry's groups.
//! - [`chromaticity`]: the CIE 1976 u′v′ diagram with the estimate's 95 % region;
//!   [`plot`]: the SVG plots of the SPD, its band and the TM-30 hue bins.
//! - [`report`]: the one-page HTML report (its meter parts in `report_meter`, its escaping
//!   in `html`).
//!
//! ```
//! use spdcam_core::builtin::DataDir;
//! use spdcam_core::spectral::Grid;
//! use spdcam_infer::{Estimator, PhotoOptions};
//! use spdcam_present::presentation::Presentation;
//! use std::path::Path;
//!
//! let examples = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples");
//! let estimator = Estimator::shipped(DataDir::new(None), Grid::parse("400-700:5")?)?;
//! let photo = Path::new(examples).join("cc24-led.jpg");
//! let estimate = estimator.estimate_photo(&photo, &PhotoOptions::default())?;
//! let shown = Presentation::of(&estimate);
//! // Every group's heading comes from the metric registry.
//! assert_eq!(shown.groups[0].title, "Colour");
//! println!("{}", shown.summary);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![deny(missing_docs)]

pub mod chromaticity;
mod html;
pub mod meaningful;
pub mod meter;
pub mod plot;
pub mod presentation;
pub mod report;
mod report_meter;
pub mod rounding;
#[cfg(test)]
mod test_support;
