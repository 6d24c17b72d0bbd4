//! spdcam-core: the spectral core, the virtual camera and everything around it that needs no
//! deep learning — spectra and colorimetry, shipped data, charts, the camera stages and the
//! features a model reads.
//!
//! The modules in pipeline order, from a light's spectrum to a dataset and back from a
//! photo:
//!
//! - [`spectral`]: wavelength grids, named spectral sets and resampling; [`builtin`]: the
//!   tables shipped inside the binary and names resolved against a data directory.
//! - [`cie_illuminant`], [`named_light`], [`light_families`]: the CIE standard illuminants,
//!   one light named on the command line or read from a file, and random but reproducible
//!   families of lights (recipes) drawn for datasets; [`chart_lighting`]: the light across
//!   the chart in a photo (gradient, veiling glare) measured and taken out of its features.
//! - [`chart`]: colour charts (patch reflectances and layout).
//! - [`camera`]: the virtual camera of the thesis (sensor, noise, demosaicing, white
//!   balance, aberration, colour) and the chart features a model reads; [`raster`] holds its
//!   image buffers, [`imageio`] writes them; [`simple_camera`] is an independent, simpler
//!   camera to validate against.
//! - [`dataset`]: (features, SPD) samples generated with the camera or imported, stored as
//!   Parquet; [`seed`] makes every random draw depend only on the seed and the sample.
//! - [`sampler`]: the one patch sampler (the region read and its robust statistic) that
//!   turns pixels into features, for simulated images and photos alike.
//! - [`photo`]: real photos — find the chart, rectify it, sample the patches into the same
//!   feature row, from encoded pixels or, for camera raw files ([`photo::raw`]), from the
//!   sensor's mosaic with the light's colour read through the file's own matrices; every
//!   chart of a photo that shows several, each with its place; synthetic scenes of one chart
//!   ([`photo::scene`]) or of several ([`photo::scene_places`]), a ColorChecker Passport in
//!   its case among them ([`photo::pocket`]), to test and measure it;
//!   [`feature_check`] rejects rows that cannot say anything about the light.
//! - [`spectral_error`] (RMSE, GFC, SAM, SID between spectra), [`colorimetry`] (XYZ, CCT/Duv,
//!   sRGB, CIELAB) and [`quality`] (CRI, TM-30, α-opic and other metrics of a light).
//! - [`advice`]: every warning and reason a person reads, with what to do, in one place.
//! - [`error`], [`fsio`] (atomic file writes), [`output_guard`] (no output onto an input),
//!   [`limits`] (resource limits) and `minimise` (derivative-free minimisation for the
//!   few small fits without a gradient) serve all of them.
//!
//! Rendering the ColorChecker 24 under CIE D65 through the built-in Nikon D5100:
//!
//! ```
//! use spdcam_core::builtin;
//! use spdcam_core::camera::sensor::Sensitivities;
//! use spdcam_core::camera::{Camera, CameraConfig};
//! use spdcam_core::chart::Chart;
//! use spdcam_core::cie_illuminant::StandardIlluminant;
//! use spdcam_core::spectral::Grid;
//!
//! let grid = Grid::SIMULATION;
//! let measured = builtin::CAMERAS[0].load()?;
//! let sensitivities = Sensitivities::new(builtin::CAMERAS[0].name, &measured, &grid)?;
//! let chart = Chart::colorchecker24(&grid)?;
//! let camera = Camera::new(&sensitivities, chart, CameraConfig::default(), &grid)?;
//! let d65 = StandardIlluminant::D65.spd(&grid)?;
//! let rendering = camera.render(&d65, 1, false)?;
//! // Mean encoded sRGB (0–255) of each patch: p01_r, p01_g, p01_b, …, p24_b.
//! let f = &rendering.features;
//! assert_eq!(f.len(), 24 * 3);
//! assert!(f.iter().all(|v| (0.0..=255.0).contains(v)));
//! // Patch 19 (white) is brighter than patch 24 (black) in every channel.
//! assert!((0..3).all(|c| f[18 * 3 + c] > f[23 * 3 + c] + 100.0));
//! # Ok::<(), spdcam_core::Error>(())
//! ```
//!
//! Generating a small dataset in memory (four samples of Gaussian lights, seed 7, the fast
//! patch-level pipeline); the same seed gives the same samples:
//!
//! ```
//! use spdcam_core::builtin::{self, DataDir};
//! use spdcam_core::camera::sensor::Sensitivities;
//! use spdcam_core::camera::{Camera, CameraConfig};
//! use spdcam_core::chart::Chart;
//! use spdcam_core::dataset::{GenerateOptions, Generator, Pipeline};
//! use spdcam_core::light_families::Lighting;
//! use spdcam_core::spectral::Grid;
//!
//! let grid = Grid::SIMULATION;
//! let measured = builtin::CAMERAS[0].load()?;
//! let sensitivities = Sensitivities::new(builtin::CAMERAS[0].name, &measured, &grid)?;
//! let camera = Camera::new(
//!     &sensitivities,
//!     Chart::colorchecker24(&grid)?,
//!     CameraConfig::default(),
//!     &grid,
//! )?;
//! let lighting = Lighting::parse("gaussian:3", &DataDir::default(), &grid)?;
//! let options = GenerateOptions {
//!     pipeline: Pipeline::Fast,
//!     ..GenerateOptions::new(4, 7)
//! };
//! let generator = Generator::new(&camera, &lighting, options)?;
//! let batch = generator.samples(0..4, None, &|_| {})?;
//! assert_eq!(batch.len(), 4);
//! assert_eq!(batch.features_of(0).len(), 24 * 3);
//! assert_eq!(batch.spd_of(0).len(), grid.count);
//! assert_eq!(generator.samples(0..4, None, &|_| {})?, batch);
//! # Ok::<(), spdcam_core::Error>(())
//! ```

#![deny(missing_docs)]

pub mod advice;
pub mod builtin;
pub mod camera;
pub mod chart;
pub mod chart_lighting;
pub mod cie_illuminant;
pub mod colorimetry;
pub mod dataset;
pub mod error;
pub mod feature_check;
pub mod fsio;
pub mod imageio;
pub mod light_families;
pub mod limits;
mod minimise;
pub mod named_light;
pub mod output_guard;
pub mod photo;
pub mod quality;
pub mod raster;
pub mod sampler;
pub mod seed;
pub mod simple_camera;
pub mod spectral;
pub mod spectral_error;

pub use error::{Error, Result};
