//! Wavelength grids, single spectra with their grid ([`Spd`]), named spectral sets, the
//! spectral CSV layout and resampling.

mod grid;
mod resample;
mod set;
mod spd;

pub use grid::Grid;
pub use resample::{clamp_undershoot, Extrapolation, Interpolation, ResampleReport};
pub use set::SpectralSet;
pub use spd::{clip_normalise, normalise_by_max, normalise_peak, Spd};
