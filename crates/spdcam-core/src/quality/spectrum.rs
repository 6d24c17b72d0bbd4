//! A light's spectrum on the grid the lighting-quality metrics work on.

use crate::colorimetry::Observer;
use crate::error::{short_number, Error, Result};
use crate::spectral::{Extrapolation, Grid, Interpolation, ResampleReport, SpectralSet};
use std::sync::OnceLock;

/// 360–780 nm at 1 nm: the grid of the metrics. CIE 015:2018 integrates at 1 nm (or 5 nm) over
/// 360–830 nm; 780–830 nm adds less than 1e-4 of Y, and the α-opic action spectra (CIE S 026),
/// V′(λ) and TM-30 end at 780 nm.
pub const QUALITY_GRID: Grid = Grid {
    start_nm: 360.0,
    step_nm: 1.0,
    count: 421,
};

/// Negative input values down to this fraction of the peak are taken as measurement noise.
const NEGATIVE_TOLERANCE: f64 = 0.01;

/// The CIE 1931 2° observer on [`QUALITY_GRID`], built once.
pub(crate) fn observer_2deg() -> &'static Observer {
    static OBS: OnceLock<Observer> = OnceLock::new();
    OBS.get_or_init(|| Observer::cie1931(&QUALITY_GRID).expect("CIE 1931 observer on 360–780 nm"))
}

/// A light's spectral power distribution resampled onto [`QUALITY_GRID`], with its CIE 1931
/// tristimulus values. Any sampling comes in: a regular grid of 6 or more samples is
/// resampled with Sprague (1880) interpolation (CIE 167:2005, exact at the given samples),
/// anything else linearly; wavelengths the data do not cover are zero (the light has no power
/// there as far as anyone knows). Values are divided by the largest magnitude first (every
/// metric is a ratio or a chromaticity, so none depends on the scale), so that an SPD in
/// any units — 1e-320 or 1e308 per nm — gives the same metrics without under- or overflow
/// in the sums; small negatives are kept.
#[derive(Debug, Clone, PartialEq)]
pub struct LightSpectrum {
    values: Vec<f64>,
    xyz: [f64; 3],
    source_range_nm: (f64, f64),
}

impl LightSpectrum {
    /// The spectrum sampled at `wavelengths` (nm, strictly increasing). Errors on mismatched
    /// lengths, non-finite values and spectra without visible light (luminance Y ≤ 0).
    pub fn from_samples(wavelengths: &[f64], values: &[f64]) -> Result<LightSpectrum> {
        let set = SpectralSet::new(
            wavelengths.to_vec(),
            vec!["light".into()],
            vec![values.to_vec()],
        )?;
        LightSpectrum::from_set(&set, 0)
    }

    /// The spectrum on a regular `grid`.
    pub fn on_grid(grid: &Grid, values: &[f64]) -> Result<LightSpectrum> {
        if values.len() != grid.count {
            return Err(Error::invalid(format!(
                "spectrum has {} values for the {} samples of {grid}",
                values.len(),
                grid.count
            )));
        }
        LightSpectrum::from_samples(&grid.wavelengths(), values)
    }

    /// Item `index` of a spectral set. Errors on values below −1 % of the spectrum's peak
    /// (more negative than measurement noise) and on spectra without visible light.
    ///
    /// # Panics
    /// If `index` is out of range.
    pub fn from_set(set: &SpectralSet, index: usize) -> Result<LightSpectrum> {
        let w = set.wavelengths();
        let source_range_nm = (w[0], w[w.len() - 1]);
        let name = &set.names()[index];
        let input = set.item(index);
        let peak = input.iter().cloned().fold(0.0, f64::max);
        if let Some((i, v)) = input
            .iter()
            .enumerate()
            .find(|(_, v)| **v < -NEGATIVE_TOLERANCE * peak || (peak == 0.0 && **v < 0.0))
        {
            return Err(Error::invalid(format!(
                "spectrum '{name}' is negative ({}) at {} nm; a light's SPD cannot be below \
                 −1 % of its peak ({})",
                short_number(*v),
                w[i],
                short_number(peak)
            )));
        }
        let magnitude = input.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let scale = if magnitude > 0.0 {
            1.0 / magnitude
        } else {
            1.0
        };
        let relative: Vec<f64> = if scale.is_finite() {
            input.iter().map(|v| v * scale).collect()
        } else {
            // 1/magnitude overflows for the smallest subnormals: divide instead.
            input.iter().map(|v| v / magnitude).collect()
        };
        let values = if set.grid().is_some_and(|g| same_grid(&g, &QUALITY_GRID)) {
            relative
        } else {
            let single = SpectralSet::new(w.to_vec(), vec![name.clone()], vec![relative])?;
            // Unclamped, as the metrics' standards and their reference implementations
            // resample (colour-science keeps Sprague's undershoot beside a spike).
            let (resampled, _): (SpectralSet, ResampleReport) = single.resample_unclamped(
                &QUALITY_GRID,
                Interpolation::Auto,
                Extrapolation::Zero,
            )?;
            resampled.item(0).to_vec()
        };
        let xyz = observer_2deg().spd_to_xyz(&values);
        if xyz[1].is_nan() || xyz[1] <= 0.0 {
            return Err(Error::invalid(format!(
                "spectrum '{name}' has no visible light (luminance Y = {} over {}–{} nm)",
                xyz[1],
                QUALITY_GRID.start_nm,
                QUALITY_GRID.end_nm()
            )));
        }
        Ok(LightSpectrum {
            values,
            xyz,
            source_range_nm,
        })
    }

    /// The values on [`QUALITY_GRID`], divided by the input's largest magnitude.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// CIE 1931 2° tristimulus values Σ S·x̄·Δλ etc. (CIE 015:2018) of the SPD divided by its
    /// largest magnitude, × nm.
    pub fn xyz(&self) -> [f64; 3] {
        self.xyz
    }

    /// The wavelength range the input data covered, in nm.
    pub fn source_range_nm(&self) -> (f64, f64) {
        self.source_range_nm
    }

    /// Σ S(λ)·w(λ)·Δλ over the grid for a weighting function `w` on [`QUALITY_GRID`].
    pub(crate) fn weighted_sum(&self, w: &[f64]) -> f64 {
        self.values.iter().zip(w).map(|(s, w)| s * w).sum::<f64>() * QUALITY_GRID.step_nm
    }
}

/// A set of weighting functions on one grid, stored band-major so that applying all of them
/// to a spectrum runs one independent accumulator per function (vectorised), rather than one
/// long dependent sum per function.
#[derive(Debug, Clone)]
pub(crate) struct BandWeights {
    functions: usize,
    /// `values[band * functions + function]`.
    values: Vec<f64>,
}

impl BandWeights {
    /// The weighting functions `functions[f][band]`, all of one length.
    pub(crate) fn new(functions: &[Vec<f64>]) -> BandWeights {
        let bands = functions.first().map_or(0, Vec::len);
        assert!(
            functions.iter().all(|f| f.len() == bands),
            "weights of unequal length"
        );
        let values = (0..bands)
            .flat_map(|b| functions.iter().map(move |f| f[b]))
            .collect();
        BandWeights {
            functions: functions.len(),
            values,
        }
    }

    /// How many weighting functions there are.
    pub(crate) fn functions(&self) -> usize {
        self.functions
    }

    /// Σ_band w_f(band)·spd(band) for every function f, into `out` (one value per function).
    ///
    /// # Panics
    /// If `spd` or `out` has the wrong length.
    pub(crate) fn apply(&self, spd: &[f64], out: &mut [f64]) {
        assert_eq!(
            spd.len() * self.functions,
            self.values.len(),
            "spectrum length"
        );
        assert_eq!(out.len(), self.functions, "output length");
        out.fill(0.0);
        for (row, s) in self.values.chunks_exact(self.functions).zip(spd) {
            for (acc, w) in out.iter_mut().zip(row) {
                *acc += w * s;
            }
        }
    }
}

fn same_grid(a: &Grid, b: &Grid) -> bool {
    a.count == b.count
        && (a.start_nm - b.start_nm).abs() < 1e-9
        && (a.step_nm - b.step_nm).abs() < 1e-9
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn five_nm_input_is_kept_at_its_samples_and_zero_outside() {
        let grid = Grid::new(400.0, 700.0, 5.0).unwrap();
        let values: Vec<f64> = grid
            .wavelengths()
            .iter()
            .map(|w| 1.0 + w / 1000.0)
            .collect();
        let light = LightSpectrum::on_grid(&grid, &values).unwrap();
        assert_eq!(light.values().len(), 421);
        assert!((light.values()[450 - 360] - 1.45 / 1.7).abs() < 1e-12);
        assert_eq!(light.values()[399 - 360], 0.0);
        assert_eq!(light.values()[701 - 360], 0.0);
        assert_eq!(light.source_range_nm(), (400.0, 700.0));
        assert!(light.xyz()[1] > 0.0);
    }

    #[test]
    fn band_weights_equal_plain_dot_products() {
        let f = vec![vec![1.0, 2.0, 3.0], vec![0.5, 0.0, -1.0]];
        let w = BandWeights::new(&f);
        let mut out = [0.0; 2];
        w.apply(&[1.0, 10.0, 100.0], &mut out);
        assert_eq!(out, [321.0, -99.5]);
    }

    #[test]
    fn dark_or_malformed_spectra_are_errors() {
        let grid = Grid::new(400.0, 700.0, 10.0).unwrap();
        let e = LightSpectrum::on_grid(&grid, &vec![0.0; grid.count]).unwrap_err();
        assert!(e.to_string().contains("no visible light"), "{e}");
        assert!(LightSpectrum::on_grid(&grid, &[1.0, 2.0]).is_err());
        assert!(LightSpectrum::from_samples(&[500.0, 400.0], &[1.0, 1.0]).is_err());
        let e = LightSpectrum::from_samples(&[400.0, 500.0, 600.0], &[1.0, -0.5, 1.0]);
        assert!(e
            .unwrap_err()
            .to_string()
            .contains("negative (-0.5) at 500 nm"));
        assert!(LightSpectrum::from_samples(&[400.0, 500.0, 600.0], &[1.0, -0.005, 1.0]).is_ok());
        // Infrared only: nothing the eye sees.
        assert!(LightSpectrum::from_samples(&[800.0, 900.0], &[1.0, 1.0]).is_err());
    }
}
