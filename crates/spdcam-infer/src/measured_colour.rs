//! A raw photo's light colour, measured through the file's own colour matrices
//! ([`spdcam_core::photo::raw::RawReading::light_xy`]), given to the model's spectrum: the model
//! reads the shape from the developed patches, the chromaticity comes from the sensor.
//!
//! Why: after white balance (the camera's, or the raw development's) a light's colour lives
//! only in small shifts of the coloured patches, which the model reads to about Δu′v′ 0.01;
//! the raw values of the chart's grey patches are the camera's reading of the light itself,
//! which a 3×3 calibration takes to XYZ far more closely. The spectrum is moved to that
//! chromaticity by the smallest change in the model's PCA coefficients
//! ([`ColourHead::conform`]), so its shape changes as little as the colour needs; its CCT
//! and Duv intervals are those of the measured chromaticity's own calibrated error
//! ([`cct_duv_intervals`]), not the model's.
//!
//! A 3×3 calibration reads a smooth light (incandescent, daylight) nearly exactly, and a
//! spiky one (LEDs, fluorescents) with a bias that every camera shares: through the held-out
//! cameras of the validation split, phosphor white LEDs read greener by v′ 0.007 on average,
//! each camera between 0.003 and 0.010. [`RawColourCorrection`] takes that bias off, as
//! a linear function of the estimated spectrum's shape fitted on the split's fit lamps
//! through its training cameras (`spdcam colour-map raw`).

use crate::colour_head::ColourHead;
use crate::error::{InferError, Result};
use crate::model::Model;
use crate::ridge::Ridge;
use crate::trust::MetricInterval;
use serde::{Deserialize, Serialize};
use spdcam_core::colorimetry::{uv1960_to_xy, xy_to_xyz};
use spdcam_core::quality::uv::{uv1976_to_uv1960, xyz_to_uv1976};
use spdcam_core::spectral::{Grid, Spd};
use std::collections::BTreeMap;
use std::sync::OnceLock;

/// The shipped correction (`models/raw-colour.json`, made by the README's recipe).
const SHIPPED_CORRECTION: &str = include_str!("../../../models/raw-colour.json");

/// The wavelengths the correction reads a spectrum's shape on: 400–700 nm every 10 nm.
pub const CORRECTION_GRID: Grid = Grid {
    start_nm: 400.0,
    step_nm: 10.0,
    count: 31,
};

/// The bias of a raw file's 3×3 colour matrices in CIE 1976 u′v′ as a linear function of the
/// light's spectrum: bias = intercept + Σ weightᵢ·sᵢ, with s the spectrum on
/// [`CORRECTION_GRID`] scaled to sum 1 (its shape only). Fitted by ridge regression (Hoerl &
/// Kennard 1970; [`Ridge`]) on the matrix readings of virtual cameras' DNGs
/// ([`spdcam_core::photo::raw::dng::virtual_raw_colour`]) against the true light.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RawColourCorrection {
    /// The bias where the shape is all zero, (u′, v′).
    pub intercept: [f64; 2],
    /// Weights of the shape's values on [`CORRECTION_GRID`], for u′ and for v′.
    pub weights: [Vec<f64>; 2],
    /// The ridge penalty, relative to the mean diagonal of XᵀX.
    pub penalty: f64,
    /// What it was fitted on, in words.
    pub fitted_on: String,
}

impl RawColourCorrection {
    /// The shape the correction reads: `spd` on [`CORRECTION_GRID`], negatives 0, sum 1; an
    /// error for a spectrum without light there.
    pub fn shape(spd: &Spd) -> Result<Vec<f64>> {
        let on_grid = spd
            .resampled(&CORRECTION_GRID)
            .map_err(|e| InferError::invalid(format!("the raw colour correction: {e}")))?;
        let values: Vec<f64> = on_grid.values().iter().map(|v| v.max(0.0)).collect();
        let sum: f64 = values.iter().sum();
        if !(sum > 0.0 && sum.is_finite()) {
            return Err(InferError::invalid(
                "the raw colour correction needs a spectrum with light in 400–700 nm",
            ));
        }
        Ok(values.iter().map(|v| v / sum).collect())
    }

    /// Fits the correction to `samples`, each a shape ([`RawColourCorrection::shape`]) and
    /// the matrices' bias (read − true u′v′) for that light, with the relative ridge
    /// `penalty` (the intercept as a constant input, penalised alike).
    pub fn fit(samples: &[(Vec<f64>, [f64; 2])], penalty: f64, fitted_on: String) -> Result<Self> {
        let n = CORRECTION_GRID.count;
        if samples.iter().any(|(s, _)| s.len() != n) {
            return Err(InferError::invalid(format!(
                "the raw colour correction reads shapes of {n} values"
            )));
        }
        let x: Vec<Vec<f64>> = samples
            .iter()
            .map(|(s, _)| std::iter::once(1.0).chain(s.iter().copied()).collect())
            .collect();
        let y: Vec<Vec<f64>> = samples.iter().map(|(_, b)| b.to_vec()).collect();
        let ridge = Ridge::fit(&x, &y, penalty, None)?;
        Ok(RawColourCorrection {
            intercept: [ridge.weight(0, 0), ridge.weight(1, 0)],
            weights: [0, 1].map(|t| (1..=n).map(|j| ridge.weight(t, j)).collect()),
            penalty,
            fitted_on,
        })
    }

    /// The matrices' bias (u′, v′) the correction expects for a light of shape `shape`.
    pub fn bias(&self, shape: &[f64]) -> [f64; 2] {
        [0, 1].map(|t| {
            self.intercept[t]
                + self.weights[t]
                    .iter()
                    .zip(shape)
                    .map(|(w, s)| w * s)
                    .sum::<f64>()
        })
    }

    /// The chromaticity (CIE 1931 xy) the matrices read as `xy`, less the bias the
    /// correction expects for a light estimated as `spd`.
    pub fn correct(&self, xy: [f64; 2], spd: &Spd) -> Result<[f64; 2]> {
        let bias = self.bias(&Self::shape(spd)?);
        let read = xyz_to_uv1976(xy_to_xyz(xy, 1.0));
        let corrected = [read[0] - bias[0], read[1] - bias[1]];
        Ok(uv1960_to_xy(uv1976_to_uv1960(corrected)))
    }

    /// Checks the numbers (for a correction read from a file).
    pub fn validate(&self) -> Result<()> {
        let n = CORRECTION_GRID.count;
        let finite = self
            .intercept
            .iter()
            .chain(self.weights.iter().flatten())
            .all(|v| v.is_finite());
        if self.weights.iter().any(|w| w.len() != n) || !finite {
            return Err(InferError::invalid(format!(
                "a raw colour correction holds {n} finite weights for u′ and for v′"
            )));
        }
        Ok(())
    }

    /// The correction shipped with the program (`models/raw-colour.json`).
    pub fn shipped() -> Result<&'static RawColourCorrection> {
        static SHIPPED: OnceLock<std::result::Result<RawColourCorrection, String>> =
            OnceLock::new();
        SHIPPED
            .get_or_init(|| {
                let c: RawColourCorrection =
                    serde_json::from_str(SHIPPED_CORRECTION).map_err(|e| e.to_string())?;
                c.validate().map_err(|e| e.to_string())?;
                Ok(c)
            })
            .as_ref()
            .map_err(|e| InferError::invalid(format!("models/raw-colour.json: {e}")))
    }
}

/// `spds` (the model's SPDs on its grid, peak 1, row-major) each moved to chromaticity `xy`
/// (CIE 1931); `false` and unchanged where the model has no PCA basis to move them in.
pub fn conform(model: &Model, spds: &mut [f64], xy: [f64; 2]) -> bool {
    let Some(pca) = model.target().pca() else {
        return false;
    };
    let Ok(head) = ColourHead::on_grid(&model.grid(), 1.0) else {
        return false;
    };
    let target = xyz_to_uv1976(xy_to_xyz(xy, 1.0));
    let d = model.grid().count;
    for spd in spds.chunks_mut(d) {
        let mut coefficients = pca.project(spd);
        head.conform(pca, &mut coefficients, target);
        let mut moved = pca.reconstruct(&coefficients);
        spdcam_core::spectral::clip_normalise(&mut moved);
        spd.copy_from_slice(&moved);
    }
    true
}

/// How closely a raw photo's light is read, for one group of photos: the relative CCT
/// error (|estimate − truth| / truth) and the Duv error (absolute) at 68 % and 95 %.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RawIntervals {
    /// Relative CCT error, 68 % and 95 %.
    pub cct_relative: [f64; 2],
    /// Duv error, 68 % and 95 %.
    pub duv: [f64; 2],
}

/// The expected GFC (the trust calibration's) that splits raw photos into the two groups
/// of [`RAW_INTERVALS`]: the median of the validation photos below.
pub const RAW_SPLIT_EXPECTED_GFC: f64 = 0.990389;

/// The intervals of a raw photo read by a chart's model without a raw model (a raw model's
/// calibration has intervals of its own), for photos whose expected GFC is below
/// [`RAW_SPLIT_EXPECTED_GFC`] and for those at or above it: the 68th and 95th percentiles of their errors on raw scene photos
/// of the validation split's validation lamps through its held-out cameras (108 photos
/// each), both charts pooled, read as shipped before the raw models (the matrices' shared
/// bias taken off for the JPEG model's shape, [`RawColourCorrection`]; with the raw models
/// they hold on 97–98 % of those photos and 91 % of the test lamps');
/// `tools/raw_intervals.py` on the photos CSV of
/// `spdcam experiment colour --raw --photos-csv` (`docs/raw.md`, which gives the rule and
/// the coverage on the test lamps). A lamp the chart reads poorly (a mixed-colour LED, a
/// fluorescent) has a low expected GFC and its colour too is read less closely. Split
/// conformal intervals (Vovk, Gammerman & Shafer, *Algorithmic Learning in a Random World*,
/// 2005; Lei et al., JASA 2018) in groups, one quantile each (Vovk 2012, "Conditional
/// validity of inductive conformal predictors", PMLR 25: 475–490).
pub const RAW_INTERVALS: [RawIntervals; 2] = [
    RawIntervals {
        cct_relative: [0.0476, 0.1040],
        duv: [0.0030, 0.0074],
    },
    RawIntervals {
        cct_relative: [0.0312, 0.0507],
        duv: [0.0020, 0.0043],
    },
];

/// The CCT and Duv intervals (half-widths at 68 % and 95 %) of a light a raw photo read at
/// CCT `cct_k`, the estimate's expected GFC `expected_gfc` choosing the group.
pub fn cct_duv_intervals(cct_k: f64, expected_gfc: f64) -> [MetricInterval; 2] {
    let group = &RAW_INTERVALS[usize::from(expected_gfc >= RAW_SPLIT_EXPECTED_GFC)];
    [
        MetricInterval {
            half68: group.cct_relative[0] * cct_k,
            half95: group.cct_relative[1] * cct_k,
        },
        MetricInterval {
            half68: group.duv[0],
            half95: group.duv[1],
        },
    ]
}

/// Sets the CCT and Duv intervals of `metrics` (where they are there) for an estimate of
/// CCT `cct_k` and expected GFC `expected_gfc` from a raw photo ([`cct_duv_intervals`]).
pub fn set_intervals(
    metrics: &mut BTreeMap<String, MetricInterval>,
    cct_k: f64,
    expected_gfc: f64,
) {
    let [cct, duv] = cct_duv_intervals(cct_k, expected_gfc);
    for (key, interval) in [("cct_k", cct), ("duv", duv)] {
        if let Some(slot) = metrics.get_mut(key) {
            *slot = interval;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use spdcam_core::cie_illuminant::planck;

    #[test]
    fn a_raw_photos_intervals_follow_its_expected_gfc() {
        let below = cct_duv_intervals(4000.0, 0.95);
        let above = cct_duv_intervals(4000.0, RAW_SPLIT_EXPECTED_GFC);
        assert!((below[0].half95 - 0.1040 * 4000.0).abs() < 1e-9);
        assert!((below[1].half95 - 0.0074).abs() < 1e-12);
        assert!((above[0].half68 - 0.0312 * 4000.0).abs() < 1e-9);
        assert!((above[1].half95 - 0.0043).abs() < 1e-12);
        // Each group's 68 % interval lies inside its 95 %, and the well-read group's inside
        // the other's.
        for g in &RAW_INTERVALS {
            assert!(g.cct_relative[0] < g.cct_relative[1] && g.duv[0] < g.duv[1]);
        }
        assert!(above[0].half95 < below[0].half95 && above[1].half95 < below[1].half95);
        // Set where the estimate has the metric, left out where it has none.
        let mut metrics = BTreeMap::new();
        metrics.insert(
            "cct_k".to_string(),
            MetricInterval {
                half68: 1.0,
                half95: 2.0,
            },
        );
        set_intervals(&mut metrics, 4000.0, 0.999);
        assert_eq!(metrics["cct_k"], above[0]);
        assert!(!metrics.contains_key("duv"));
    }

    /// A made-up bias: 0.002 in u′ and −0.01 in v′ per unit of the shape's share at
    /// 450 nm (index 5), and a constant 0.001 in v′.
    fn made_up_bias(shape: &[f64]) -> [f64; 2] {
        [0.002 * shape[5], 0.001 - 0.01 * shape[5]]
    }

    #[test]
    fn a_linear_bias_is_fitted_back_and_taken_off() {
        // Planckian lights of 2000–9800 K with a spike at 450 nm of varying height.
        let samples: Vec<(Vec<f64>, [f64; 2])> = (0..40)
            .map(|k| {
                let mut spd = planck(2000.0 + 200.0 * k as f64, &CORRECTION_GRID).unwrap();
                let mut values = spd.values().to_vec();
                values[5] += 0.05 * (k % 7) as f64;
                spd = Spd::new(CORRECTION_GRID, values).unwrap();
                let shape = RawColourCorrection::shape(&spd).unwrap();
                let bias = made_up_bias(&shape);
                (shape, bias)
            })
            .collect();
        let c = RawColourCorrection::fit(&samples, 1e-9, "made up".into()).unwrap();
        c.validate().unwrap();
        for (shape, bias) in &samples {
            let b = c.bias(shape);
            assert!((b[0] - bias[0]).abs() < 1e-6 && (b[1] - bias[1]).abs() < 1e-6);
        }
        // Correcting a reading moves it by the bias in u′v′.
        let spd = Spd::new(CORRECTION_GRID, samples[3].0.clone()).unwrap();
        let read = [0.40, 0.39];
        let corrected = c.correct(read, &spd).unwrap();
        let (a, b) = (
            xyz_to_uv1976(xy_to_xyz(read, 1.0)),
            xyz_to_uv1976(xy_to_xyz(corrected, 1.0)),
        );
        let expected = made_up_bias(&samples[3].0);
        assert!((a[0] - b[0] - expected[0]).abs() < 1e-6, "{a:?} {b:?}");
        assert!((a[1] - b[1] - expected[1]).abs() < 1e-6, "{a:?} {b:?}");
    }

    #[test]
    fn a_black_spectrum_or_a_damaged_correction_is_an_error() {
        let black = Spd::new(CORRECTION_GRID, vec![0.0; 31]).unwrap();
        assert!(RawColourCorrection::shape(&black).is_err());
        let mut c = RawColourCorrection::shipped().unwrap().clone();
        c.validate().unwrap();
        c.weights[1].pop();
        assert!(c.validate().is_err());
        c.weights[1].push(f64::NAN);
        assert!(c.validate().is_err());
    }
}
