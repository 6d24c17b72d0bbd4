//! Wavelength grids, named spectral sets, the spectral CSV layout and resampling.

mod grid;
mod resample;
mod set;

pub use grid::Grid;
pub use resample::{Extrapolation, Interpolation, ResampleReport};
pub use set::SpectralSet;
