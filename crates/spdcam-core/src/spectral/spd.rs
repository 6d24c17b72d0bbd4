//! One spectral power distribution with the grid it is sampled on.

use super::{Extrapolation, Grid, Interpolation, SpectralSet};
use crate::error::{Error, Result};

/// A spectrum (an SPD, absolute or relative) on a uniform wavelength grid. The grid travels
/// with the values, so a function taking an `Spd` can check it got values on the grid it
/// works on, rather than trusting a bare slice's length.
#[derive(Debug, Clone, PartialEq)]
pub struct Spd {
    grid: Grid,
    values: Vec<f64>,
}

impl Spd {
    /// The spectrum of `values` on `grid`; an error when their counts differ.
    ///
    /// ```
    /// use spdcam_core::spectral::{Grid, Spd};
    ///
    /// let grid = Grid::parse("400-700:100")?;
    /// let spd = Spd::new(grid, vec![0.2, 1.0, 0.6, 0.1])?;
    /// assert_eq!(spd.grid().wavelengths(), [400.0, 500.0, 600.0, 700.0]);
    /// assert_eq!(spd[1], 1.0); // reads as its values
    /// assert!(Spd::new(grid, vec![1.0; 3]).is_err());
    /// # Ok::<(), spdcam_core::Error>(())
    /// ```
    pub fn new(grid: Grid, values: Vec<f64>) -> Result<Spd> {
        if values.len() != grid.count {
            return Err(Error::invalid(format!(
                "a spectrum on {grid} needs {} values, got {}",
                grid.count,
                values.len()
            )));
        }
        Ok(Spd { grid, values })
    }

    /// The grid the values are sampled on.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The values, one per wavelength of [`Spd::grid`].
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The values, giving up the grid.
    pub fn into_values(self) -> Vec<f64> {
        self.values
    }

    /// The values, after checking the spectrum is on `grid`; the error names `what` needs
    /// it and both grids.
    pub fn on(&self, grid: &Grid, what: &str) -> Result<&[f64]> {
        if self.grid != *grid {
            return Err(Error::invalid(format!(
                "{what} works on {grid}; the spectrum is on {}",
                self.grid
            )));
        }
        Ok(&self.values)
    }

    /// The spectrum divided by its maximum (peak 1), negative values set to 0: the
    /// normalisation every comparison of SPD shapes uses (thesis section 4.3). A spectrum
    /// whose maximum is not a positive number comes back as zeros.
    pub fn normalised_by_max(&self) -> Spd {
        Spd {
            grid: self.grid,
            values: normalise_by_max(&self.values),
        }
    }

    /// The spectrum resampled onto `grid` (Sprague 1880 interpolation where the spectrum
    /// has six or more samples, else linear; zero outside its range).
    ///
    /// ```
    /// use spdcam_core::cie_illuminant::StandardIlluminant;
    /// use spdcam_core::spectral::Grid;
    ///
    /// let a = StandardIlluminant::A.spd(&Grid::SIMULATION)?; // 380–780 nm, 5 nm
    /// let coarse = a.resampled(&Grid::parse("400-700:10")?)?;
    /// assert_eq!(coarse.len(), 31);
    /// // Every 10 nm sample is one of the 5 nm samples.
    /// assert_eq!(coarse[0], a[4]);
    /// # Ok::<(), spdcam_core::Error>(())
    /// ```
    pub fn resampled(&self, grid: &Grid) -> Result<Spd> {
        if self.grid == *grid {
            return Ok(self.clone());
        }
        let set = SpectralSet::on_grid(&self.grid, vec!["spd".into()], vec![self.values.clone()])?;
        let (set, _) = set.resample(grid, Interpolation::Auto, Extrapolation::Zero)?;
        Spd::new(*grid, set.item(0).to_vec())
    }
}

/// Divides `values` by their largest value so the peak is 1: the one peak normalisation of
/// the workspace (relative SPDs of lights, decoded estimates, the spectra a comparison
/// normalises first). An error, the values left as they were, when a value is not finite
/// or none is positive (a dark spectrum has no shape to keep).
///
/// ```
/// use spdcam_core::spectral::normalise_peak;
///
/// let mut spd = vec![1.0, 4.0, 2.0];
/// normalise_peak(&mut spd)?;
/// assert_eq!(spd, [0.25, 1.0, 0.5]);
/// let mut dark = vec![0.0, -1.0];
/// assert!(normalise_peak(&mut dark).is_err());
/// assert!(normalise_peak(&mut [1.0, f64::NAN]).is_err());
/// # Ok::<(), spdcam_core::Error>(())
/// ```
pub fn normalise_peak(values: &mut [f64]) -> Result<()> {
    if let Some(v) = values.iter().find(|v| !v.is_finite()) {
        return Err(Error::invalid(format!(
            "a spectrum holding the non-finite value {v} has no peak to normalise by"
        )));
    }
    let peak = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if peak.is_nan() || peak <= 0.0 {
        return Err(Error::invalid(
            "a spectrum without a positive value (dark) has no peak to normalise by",
        ));
    }
    values.iter_mut().for_each(|v| *v /= peak);
    Ok(())
}

/// The spectrum divided by its maximum ([`normalise_peak`]), with negative values clipped
/// to 0. A spectrum that cannot be normalised (a non-finite value, no positive one) comes
/// back as zeros.
pub fn normalise_by_max(spd: &[f64]) -> Vec<f64> {
    let mut out = spd.to_vec();
    clip_normalise(&mut out);
    out
}

/// [`normalise_by_max`] in place.
pub fn clip_normalise(spd: &mut [f64]) {
    if normalise_peak(spd).is_err() {
        spd.fill(0.0);
        return;
    }
    spd.iter_mut().for_each(|v| *v = v.max(0.0));
}

/// Reading an `Spd` as its values (indexing, iterating, slice functions), the way a `String`
/// reads as a `str`; the grid stays with the `Spd`.
impl std::ops::Deref for Spd {
    type Target = [f64];

    fn deref(&self) -> &[f64] {
        &self.values
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_values_must_fill_the_grid() {
        let grid = Grid::new(400.0, 700.0, 100.0).unwrap();
        assert!(Spd::new(grid, vec![1.0, 2.0, 3.0, 4.0]).is_ok());
        let err = Spd::new(grid, vec![1.0; 3]).unwrap_err().to_string();
        assert!(err.contains("needs 4 values, got 3"), "{err}");
    }

    #[test]
    fn a_spectrum_on_another_grid_is_refused_by_name() {
        let grid = Grid::new(400.0, 700.0, 100.0).unwrap();
        let other = Grid::new(400.0, 700.0, 50.0).unwrap();
        let spd = Spd::new(grid, vec![1.0; 4]).unwrap();
        assert_eq!(spd.on(&grid, "the camera").unwrap(), &[1.0; 4]);
        let err = spd.on(&other, "the camera").unwrap_err().to_string();
        assert!(err.starts_with("the camera works on"), "{err}");
    }

    #[test]
    fn peak_normalisation_and_resampling_of_a_line() {
        let grid = Grid::new(400.0, 700.0, 100.0).unwrap();
        let spd = Spd::new(grid, vec![-1.0, 2.0, 4.0, 1.0]).unwrap();
        assert_eq!(spd.normalised_by_max().values(), &[0.0, 0.5, 1.0, 0.25]);
        // Linear interpolation (four samples) halfway between the points.
        let fine = spd
            .resampled(&Grid::new(400.0, 700.0, 50.0).unwrap())
            .unwrap();
        assert_eq!(fine.values(), &[-1.0, 0.5, 2.0, 3.0, 4.0, 2.5, 1.0]);
        assert_eq!(spd.resampled(&grid).unwrap(), spd);
    }
}
