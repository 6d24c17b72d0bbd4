//! spdcam-core: the spectral core, the virtual camera and everything around it that needs no
//! deep learning — spectra and colorimetry, shipped data, charts, the camera stages and the
//! features a model reads.

pub mod builtin;
pub mod camera;
pub mod chart;
pub mod colorimetry;
pub mod dataset;
pub mod error;
pub mod feature_check;
pub mod fsio;
pub mod illuminant;
pub mod imageio;
pub mod light;
pub mod lighting;
pub mod limits;
pub mod metrics;
pub mod photo;
pub mod quality;
pub mod raster;
pub mod seed;
pub mod simple_camera;
pub mod spectral;
pub mod uneven_light;

pub use error::{Error, Result};
