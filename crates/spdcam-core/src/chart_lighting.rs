//! The photo's own corrections: the light's gradient across the chart and the veiling glare
//! (flare), measured on the chart's neutral patches and taken out of a feature row.
//!
//! A neutral patch i of mean reflectance ρᵢ at chart position (xᵢ, yᵢ) (−½…½) is seen, per
//! channel c and in linear units (the sRGB encoding undone), as
//!
//! ```text
//! vᵢc = a_c · ρᵢ · (1 + gx_c · xᵢ + gy_c · yᵢ) + f_c
//! ```
//!
//! — the exposure and white balance a_c, a linear gain across the chart (g) and an additive
//! flare f_c (the veiling-glare model of ISO 9358 and McCann & Rizzi 2007, "Veiling glare:
//! the dynamic range limit of HDR images", Proc. SPIE 6492). The model is linear in
//! (a_c, a_c·gx_c, a_c·gy_c, f_c), fitted by least squares per channel. The correction
//! divides every patch by its gain and subtracts the flare, then re-encodes.

use crate::chart::Chart;
use crate::colorimetry::{srgb_decode, srgb_encode};
use crate::error::{Error, Result};
use nalgebra::{DMatrix, DVector};

/// Fewer usable neutral patches than this leave the four unknowns per channel too free.
pub const MIN_NEUTRALS: usize = 6;
/// Neutral patches spread over less than this share of the chart's width (height) leave
/// the gradient along it unmeasured.
const MIN_SPREAD: f64 = 0.2;
/// Linear values above this share of the feature scale are taken as clipped.
const CLIPPED: f64 = 0.98;
/// The gain is kept at least this (a fit that makes a patch's light vanish is not trusted).
const MIN_GAIN: f64 = 0.25;

/// What the neutral patches say about the light across the chart, per channel.
#[derive(Debug, Clone, PartialEq)]
pub struct UnevenLight {
    /// Additive flare per channel, in linear units of the feature scale (0–1).
    pub flare: [f64; 3],
    /// Relative gain per chart width (x) and height (y), per channel.
    pub gradient: [[f64; 2]; 3],
    /// The neutral patches the fit used.
    pub neutrals: usize,
}

impl UnevenLight {
    /// How much the light's colour changes across the chart: the largest difference
    /// between two channels' gradients (relative gain per chart width or height). One light
    /// falling off across the chart changes every channel alike; two lights, one on each
    /// side, do not.
    pub fn colour_gradient(&self) -> f64 {
        let mut most: f64 = 0.0;
        for a in 0..3 {
            for b in a + 1..3 {
                for axis in 0..2 {
                    most = most.max((self.gradient[a][axis] - self.gradient[b][axis]).abs());
                }
            }
        }
        most
    }
}

/// Which corrections [`UnevenLight::correct`] applies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Corrections {
    /// Subtract the flare.
    pub flare: bool,
    /// Divide by the gain across the chart.
    pub gradient: bool,
}

impl UnevenLight {
    /// Fits the model of the module documentation to the neutral feature patches of
    /// `chart` in `row` (encoded sRGB on 0…`scale`, three values per feature patch); an error
    /// when fewer than [`MIN_NEUTRALS`] neutral patches are unclipped.
    pub fn fit(chart: &Chart, row: &[f64], scale: f64) -> Result<UnevenLight> {
        if row.len() != 3 * chart.feature_patches.len() {
            return Err(Error::invalid(format!(
                "{} feature values for a chart of {} feature patches",
                row.len(),
                chart.feature_patches.len()
            )));
        }
        UnevenLight::fit_neutrals(
            &chart.neutral_features(),
            &chart.feature_centres(),
            row,
            scale,
        )
        .map_err(|e| Error::invalid(format!("{}: {e}", chart.name)))
    }

    /// [`UnevenLight::fit`] from a chart's neutral features ([`Chart::neutral_features`])
    /// and feature centres ([`Chart::feature_centres`]).
    pub fn fit_neutrals(
        neutral_features: &[(usize, f64)],
        centres: &[[f64; 2]],
        row: &[f64],
        scale: f64,
    ) -> Result<UnevenLight> {
        if row.len() != 3 * centres.len() || scale <= 0.0 {
            return Err(Error::invalid(format!(
                "{} feature values for {} feature patches",
                row.len(),
                centres.len()
            )));
        }
        let linear = |k: usize, c: usize| srgb_decode((row[3 * k + c] / scale).clamp(0.0, 1.0));
        let neutrals: Vec<(usize, f64)> = neutral_features
            .iter()
            .copied()
            .filter(|&(k, _)| k < centres.len() && (0..3).all(|c| linear(k, c) < CLIPPED))
            .collect();
        if neutrals.len() < MIN_NEUTRALS {
            return Err(Error::invalid(format!(
                "{} unclipped neutral patches; the light across the chart needs {MIN_NEUTRALS}",
                neutrals.len()
            )));
        }
        // A direction along which the neutrals do not spread says nothing of the gradient
        // there (the ColorChecker 24's neutral row has one height): it is left at 0.
        let spread = |axis: usize| {
            let v = neutrals.iter().map(|&(k, _)| centres[k][axis]);
            v.clone().fold(f64::NEG_INFINITY, f64::max) - v.fold(f64::INFINITY, f64::min)
        };
        let axes: Vec<usize> = (0..2).filter(|&a| spread(a) >= MIN_SPREAD).collect();
        let design = DMatrix::from_fn(neutrals.len(), 2 + axes.len(), |i, j| {
            let (k, rho) = neutrals[i];
            match j {
                0 => rho,
                j if j <= axes.len() => rho * centres[k][axes[j - 1]],
                _ => 1.0,
            }
        });
        let svd = design.svd(true, true);
        let mut flare = [0.0; 3];
        let mut gradient = [[0.0; 2]; 3];
        for c in 0..3 {
            let v =
                DVector::from_iterator(neutrals.len(), neutrals.iter().map(|&(k, _)| linear(k, c)));
            let p = svd
                .solve(&v, 1e-9)
                .map_err(|e| Error::invalid(format!("fitting the light across the chart: {e}")))?;
            if p[0] <= 0.0 {
                return Err(Error::invalid(
                    "the neutral patches do not brighten with their reflectance",
                ));
            }
            flare[c] = p[axes.len() + 1];
            for (j, &a) in axes.iter().enumerate() {
                gradient[c][a] = p[j + 1] / p[0];
            }
        }
        Ok(UnevenLight {
            flare,
            gradient,
            neutrals: neutrals.len(),
        })
    }

    /// `row` (encoded sRGB on 0…`scale`) with the chosen corrections applied, re-encoded on
    /// the same scale.
    pub fn correct(&self, chart: &Chart, row: &[f64], scale: f64, which: Corrections) -> Vec<f64> {
        let centres = chart.feature_centres();
        row.iter()
            .enumerate()
            .map(|(i, &value)| {
                let (k, c) = (i / 3, i % 3);
                let mut v = srgb_decode((value / scale).clamp(0.0, 1.0));
                if which.flare {
                    v -= self.flare[c];
                }
                if which.gradient {
                    let [gx, gy] = self.gradient[c];
                    v /= (1.0 + gx * centres[k][0] + gy * centres[k][1]).max(MIN_GAIN);
                }
                scale * srgb_encode(v.clamp(0.0, 1.0))
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectral::Grid;

    /// The ColorChecker 24's features under a known flare and gradient.
    fn seen(chart: &Chart, flare: [f64; 3], gradient: [[f64; 2]; 3]) -> (Vec<f64>, Vec<f64>) {
        let centres = chart.feature_centres();
        let mut clean = Vec::new();
        let mut seen = Vec::new();
        for (k, &p) in chart.feature_patches.iter().enumerate() {
            let refl = chart.reflectances.item(p);
            let rho = refl.iter().sum::<f64>() / refl.len() as f64;
            for c in 0..3 {
                let base = 0.7 * rho * [1.0, 0.9, 0.8][c];
                let gain = 1.0 + gradient[c][0] * centres[k][0] + gradient[c][1] * centres[k][1];
                clean.push(255.0 * srgb_encode(base));
                seen.push(255.0 * srgb_encode(base * gain + flare[c]));
            }
        }
        (clean, seen)
    }

    #[test]
    fn a_known_flare_and_gradient_are_found_and_taken_out() {
        let chart = Chart::colorchecker24(&Grid::SIMULATION).unwrap();
        assert_eq!(chart.neutral_features().len(), 6, "the bottom row");
        let flare = [0.03, 0.02, 0.04];
        // The neutral row spans the chart's width, not its height: a gradient along x.
        let gradient = [[0.3, 0.0], [0.25, 0.0], [0.2, 0.0]];
        let (clean, row) = seen(&chart, flare, gradient);
        let fit = UnevenLight::fit(&chart, &row, 255.0).unwrap();
        for c in 0..3 {
            // The chart's neutrals are flat to a few per cent: close, not exact.
            assert!((fit.flare[c] - flare[c]).abs() < 0.01, "{fit:?}");
            assert!(
                (fit.gradient[c][0] - gradient[c][0]).abs() < 0.05,
                "{fit:?}"
            );
        }
        let both = Corrections {
            flare: true,
            gradient: true,
        };
        let corrected = fit.correct(&chart, &row, 255.0, both);
        let err = |a: &[f64]| -> f64 {
            a.iter()
                .zip(&clean)
                .map(|(x, y)| (x - y).abs())
                .sum::<f64>()
                / a.len() as f64
        };
        assert!(
            err(&corrected) < 0.25 * err(&row),
            "{} vs {}",
            err(&corrected),
            err(&row)
        );
        // Nothing to correct: the row stays as it was.
        let none = Corrections {
            flare: false,
            gradient: false,
        };
        let same = fit.correct(&chart, &row, 255.0, none);
        assert!(same.iter().zip(&row).all(|(a, b)| (a - b).abs() < 1e-9));
    }

    #[test]
    fn too_few_neutrals_or_a_wrong_row_is_an_error() {
        let chart = Chart::colorchecker24(&Grid::SIMULATION).unwrap();
        let err = UnevenLight::fit(&chart, &[1.0; 6], 255.0).unwrap_err();
        assert!(err.to_string().contains("feature patches"), "{err}");
        // Every patch clipped.
        let err = UnevenLight::fit(&chart, &[255.0; 72], 255.0).unwrap_err();
        assert!(
            err.to_string().starts_with("colorchecker24: 0 unclipped"),
            "{err}"
        );
        assert!(
            err.to_string().contains("unclipped neutral patches"),
            "{err}"
        );
    }
}
