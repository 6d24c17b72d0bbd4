//! How far an estimate can be trusted: a self-check that re-renders the chart under the
//! estimated light, per-wavelength uncertainty bands with an expected GFC, and one verdict.
//!
//! ```text
//! features ─► model ─► SPD ─┬─► chart reflectances × SPD × camera ─► 3×3 + offset + gradient
//!                           │     fitted to the photo (tone curve undone) ─► residual and
//!                           │     half-to-half residual (self-check)
//! features ± 2 % ─► model ──┴─► spread of the SPDs ─► × calibrated quantiles ─► bands, GFC
//!            detection, clipping, self-check, spread ─► verdict: ok / doubtful / unusable
//! ```
//!
//! The bands and the expected GFC come from a calibration file per model, measured on
//! held-out virtual photos of held-out lamps (`spdcam trust calibrate`, docs/trust.md).

use crate::error::{InferError, Result};
use crate::model::Model;
use nalgebra::DMatrix;
use rand::rngs::SmallRng;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};
use spdcam_core::builtin::{self, DataDir};
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::chart::Chart;
use spdcam_core::colorimetry::srgb_decode;
use spdcam_core::metrics;
use spdcam_core::photo::{PatchSample, PhotoAnalysis};
use spdcam_core::quality::{LightingMetrics, SCALAR_KEYS};
use spdcam_core::spectral::{Extrapolation, Grid, Interpolation, SpectralSet};
use spdcam_core::uneven_light::UnevenLight;
use std::collections::BTreeMap;

/// How many patches the self-check names as the worst.
const WORST_NAMED: usize = 3;
/// Fewer usable patches than this leave the self-check's 6 parameters per channel too free.
const MIN_CHECK_PATCHES: usize = 12;
/// Fewer patches than this on a half leave its 4 parameters per channel too free.
const MIN_HALF_PATCHES: usize = 8;
/// Perturbed copies of the features whose estimates measure the spread.
pub const JITTER_COPIES: usize = 16;
/// Relative size (standard deviation) of the perturbation of each feature: about the
/// patch-to-patch noise of an 8-bit JPEG of a chart plus the sampling error.
pub const JITTER_SIGMA: f64 = 0.02;
/// Seed of the perturbations, fixed so an estimate is reproducible.
const JITTER_SEED: u64 = 0x7472_7573_7400_0001;

/// How well the estimated light explains the photo's patches.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SelfCheck {
    /// Mean over the patches of the RGB residual relative to the chart's mean RGB length.
    pub mean: f64,
    /// The mean residual, on the same scale, when each half of the chart (left and right,
    /// top and bottom; the larger) is predicted by the colour map of the other half: large
    /// when the halves are lit differently (two lights, glare).
    pub split: f64,
    /// The largest patch residual, on the same scale.
    pub worst: f64,
    /// The worst patches, 1-based in feature order (`p07` is 7), worst first.
    pub worst_patches: Vec<usize>,
    /// How much the light's colour changes across the chart, measured on its neutral
    /// patches ([`UnevenLight::colour_gradient`]); `None` with too few unclipped neutrals.
    pub colour_gradient: Option<f64>,
    /// The share of the residual (0–1) that an additive light changing linearly across the
    /// chart removes: large when glare, a reflection or flare from a light beside the chart
    /// adds light to one side of it.
    pub glare: f64,
}

/// The chart's feature patches seen by a reference camera, ready to be lit by an SPD.
#[derive(Debug, Clone)]
pub struct ChartCheck {
    /// Per feature patch: reference camera sensitivity × reflectance, per channel.
    weights: Vec<[Vec<f64>; 3]>,
    /// Per feature patch: its centre across the chart, −½…½.
    centres: Vec<[f64; 2]>,
    /// The neutral feature patches and their mean reflectances.
    neutrals: Vec<(usize, f64)>,
    grid: Grid,
}

impl ChartCheck {
    /// `chart` seen by `camera`, both on `grid`.
    pub fn new(chart: &Chart, camera: &Sensitivities, grid: &Grid) -> Result<ChartCheck> {
        chart.reflectances.require_grid(grid, "chart")?;
        camera.curves.require_grid(grid, "camera")?;
        let weights = chart
            .feature_patches
            .iter()
            .map(|&p| {
                let refl = chart.reflectances.item(p);
                std::array::from_fn(|c| {
                    let s = camera.curves.item(c);
                    s.iter().zip(refl).map(|(a, b)| a * b).collect()
                })
            })
            .collect();
        let centres = chart.feature_centres();
        Ok(ChartCheck {
            weights,
            centres,
            neutrals: chart.neutral_features(),
            grid: *grid,
        })
    }

    /// The self-check for `model`'s chart on its grid, seen by the built-in Nikon D5100
    /// (NPL, Darrodi et al. 2015); `None` when the chart's reflectances are not at hand
    /// (the ColorChecker SG's come from the data directory).
    pub fn for_model(model: &Model, data_dir: &DataDir) -> Result<Option<ChartCheck>> {
        let grid = model.grid();
        let Some(name) = model.header().chart.as_deref() else {
            return Ok(None);
        };
        let Ok(chart) = Chart::resolve(name, None, data_dir, &grid) else {
            return Ok(None);
        };
        if chart.feature_names() != model.feature_names() {
            return Ok(None);
        }
        let table = &builtin::CAMERAS[0];
        let camera = Sensitivities::new(table.name, &table.load()?, &grid)?;
        Ok(Some(ChartCheck::new(&chart, &camera, &grid)?))
    }

    /// The number of feature patches.
    pub fn patches(&self) -> usize {
        self.weights.len()
    }

    /// Checks `spd` (on the check's grid) against one feature row (encoded sRGB on
    /// `0…scale`, three per patch). Patches with `skip[i]` (clipped, dark) are left out.
    ///
    /// The predicted raw RGB (Σλ camera · reflectance · SPD) is mapped to the photo's linear
    /// RGB (the tone curve undone: contrast S-curve, sRGB and a power; of the tone curves
    /// tried on a grid the one that fits best) by a per-photo affine colour correction fitted by
    /// least squares (Hong, Luo & Rhodes 2001, "A study of digital camera colorimetric
    /// characterisation based on polynomial modelling", Color Res. Appl. 26: 76–84): a 3×3
    /// matrix (camera and white balance), an offset (flare) and a linear light gradient
    /// across the chart. What the fit cannot explain is the residual; what share of it an
    /// additive light changing across the chart would explain is the glare.
    pub fn check(
        &self,
        spd: &[f64],
        features: &[f64],
        scale: f64,
        skip: &[bool],
    ) -> Result<SelfCheck> {
        let n = self.weights.len();
        if spd.len() != self.grid.count || features.len() != 3 * n {
            return Err(InferError::invalid(format!(
                "self-check: {} SPD values and {} features for {} values and {} patches",
                spd.len(),
                features.len(),
                self.grid.count,
                n
            )));
        }
        let used: Vec<usize> = (0..n)
            .filter(|&i| !skip.get(i).copied().unwrap_or(false))
            .collect();
        if used.len() < MIN_CHECK_PATCHES {
            return Err(InferError::invalid(format!(
                "self-check: {} usable patches, at least {MIN_CHECK_PATCHES} needed",
                used.len()
            )));
        }
        let predicted: Vec<[f64; 3]> = self
            .weights
            .iter()
            .map(|w| std::array::from_fn(|c| w[c].iter().zip(spd).map(|(a, b)| a * b).sum()))
            .collect();
        let mut best: Option<MapFit> = None;
        for &gamma in &TONE_GAMMAS {
            for &contrast in &TONE_CONTRASTS {
                let observed: Vec<[f64; 3]> = features
                    .chunks_exact(3)
                    .map(|p| {
                        std::array::from_fn(|c| {
                            untone((p[c] / scale).clamp(0.0, 1.0), gamma, contrast)
                        })
                    })
                    .collect();
                let fitted = self.map_fit(&predicted, &observed, &used)?;
                if best.as_ref().is_none_or(|b| fitted.mean < b.mean) {
                    best = Some(fitted);
                }
            }
        }
        let best = best.ok_or_else(|| InferError::invalid("self-check: no tone curve to try"))?;
        let mut best = self.judge_fit(&best, &used)?;
        best.colour_gradient =
            UnevenLight::fit_neutrals(&self.neutrals, &self.centres, features, scale)
                .ok()
                .map(|u| u.colour_gradient());
        Ok(best)
    }

    /// The per-photo map of `predicted` raw RGB to `observed` linear RGB over the patches
    /// `used`, fitted by least squares, and its residual (see [`ChartCheck::check`]).
    fn map_fit(
        &self,
        predicted: &[[f64; 3]],
        observed: &[[f64; 3]],
        used: &[usize],
    ) -> Result<MapFit> {
        let level = |v: &[[f64; 3]]| {
            used.iter().map(|&i| v[i].iter().sum::<f64>()).sum::<f64>() / used.len() as f64
        };
        let (pl, ol) = (level(predicted), level(observed));
        if !(pl > 0.0 && ol > 0.0) {
            return Err(InferError::invalid(
                "self-check: the chart or the light is black",
            ));
        }
        // Per patch: the predicted RGB, a constant (flare), the light's gradient and an
        // additive light changing across the chart (the last two columns, for the glare).
        let design: Vec<[f64; GLARE_COLUMNS]> = predicted
            .iter()
            .zip(&self.centres)
            .map(|(p, &[x, y])| {
                let p = p.map(|v| v / pl);
                let l = p.iter().sum::<f64>() / 3.0;
                [p[0], p[1], p[2], 1.0, x * l, y * l, x, y]
            })
            .collect();
        let target: Vec<[f64; 3]> = observed.iter().map(|o| o.map(|v| v / ol)).collect();
        let mean_length = used.iter().map(|&i| norm(target[i])).sum::<f64>() / used.len() as f64;
        let mut fitted = MapFit {
            design,
            target,
            mean_length,
            global: DMatrix::zeros(0, 0),
            residuals: Vec::new(),
            mean: 0.0,
        };
        fitted.global = fitted.solve(used, MAP_COLUMNS)?;
        fitted.residuals = used
            .iter()
            .map(|&i| (i, fitted.residual(i, &fitted.global, MAP_COLUMNS)))
            .collect();
        fitted.mean = fitted.residuals.iter().map(|r| r.1).sum::<f64>() / used.len() as f64;
        fitted.residuals.sort_by(|a, b| b.1.total_cmp(&a.1));
        Ok(fitted)
    }

    /// The self-check of the best-fitting map: its residual, the worst patches, the
    /// half-to-half residual and the glare.
    fn judge_fit(&self, fitted: &MapFit, used: &[usize]) -> Result<SelfCheck> {
        // Glare: the same map with an additive light that changes linearly across the chart
        // (two more columns per channel), compared with the map without it, a nested-model
        // comparison (Seber & Lee 2003, "Linear Regression Analysis", section 4.3).
        let with_glare = fitted.solve(used, GLARE_COLUMNS)?;
        let glare_mean = used
            .iter()
            .map(|&i| fitted.residual(i, &with_glare, GLARE_COLUMNS))
            .sum::<f64>()
            / used.len() as f64;
        // Halves: the colour map fitted to one half of the chart (the gradient fixed at the
        // whole chart's) predicts the other half (a Chow-type test for one map across the
        // chart; Chow 1960, Econometrica 28: 591–605).
        let flat = MapFit {
            target: fitted
                .target
                .iter()
                .zip(&fitted.design)
                .map(|(t, d)| {
                    std::array::from_fn(|c| {
                        t[c] - (d[4] * fitted.global[(4, c)] + d[5] * fitted.global[(5, c)])
                    })
                })
                .collect(),
            design: fitted.design.clone(),
            global: DMatrix::zeros(0, 0),
            residuals: Vec::new(),
            ..*fitted
        };
        let mut split = 0.0f64;
        for axis in 0..2 {
            let (a, b): (Vec<usize>, Vec<usize>) =
                used.iter().partition(|&&i| self.centres[i][axis] < 0.0);
            if a.len() < MIN_HALF_PATCHES || b.len() < MIN_HALF_PATCHES {
                continue;
            }
            let mut cross = 0.0;
            for (fit_on, judged) in [(&a, &b), (&b, &a)] {
                let solved = flat.solve(fit_on, HALF_COLUMNS)?;
                cross += judged
                    .iter()
                    .map(|&i| flat.residual(i, &solved, HALF_COLUMNS))
                    .sum::<f64>();
            }
            split = split.max(cross / used.len() as f64);
        }
        let mean = fitted.mean;
        Ok(SelfCheck {
            glare: if mean > 0.0 {
                (1.0 - glare_mean / mean).max(0.0)
            } else {
                0.0
            },
            colour_gradient: None,
            mean,
            split,
            worst: fitted.residuals[0].1,
            worst_patches: fitted
                .residuals
                .iter()
                .take(WORST_NAMED)
                .map(|r| r.0 + 1)
                .collect(),
        })
    }
}

/// Columns of the self-check's map: 3×3 matrix, flare, and the light's gradient in x and y.
const MAP_COLUMNS: usize = 6;
/// The map's columns with the additive light changing across the chart (glare).
const GLARE_COLUMNS: usize = 8;
/// The map's columns fitted on half the chart: matrix and flare.
const HALF_COLUMNS: usize = 4;

/// The self-check's map at one tone curve: per patch its design row and target (the
/// photo's linear RGB over its mean level), the map's solution on the first
/// [`MAP_COLUMNS`] columns and the patch residuals (worst first) with their mean.
struct MapFit {
    design: Vec<[f64; GLARE_COLUMNS]>,
    target: Vec<[f64; 3]>,
    /// The mean RGB length of the targets, the residuals' unit.
    mean_length: f64,
    global: DMatrix<f64>,
    residuals: Vec<(usize, f64)>,
    mean: f64,
}

impl MapFit {
    /// The least-squares map on the first `columns` design columns over the patches `rows`.
    fn solve(&self, rows: &[usize], columns: usize) -> Result<DMatrix<f64>> {
        least_squares(rows, columns, &|i| self.design[i].to_vec(), &|i| {
            self.target[i]
        })
    }

    /// Patch `i`'s residual under the map `solved` on the first `columns` columns, relative
    /// to the mean RGB length.
    fn residual(&self, i: usize, solved: &DMatrix<f64>, columns: usize) -> f64 {
        let (d, t) = (&self.design[i], self.target[i]);
        let fit: [f64; 3] =
            std::array::from_fn(|c| (0..columns).map(|k| d[k] * solved[(k, c)]).sum());
        norm(std::array::from_fn(|c| fit[c] - t[c])) / self.mean_length
    }
}

/// The Euclidean length of an RGB triple.
fn norm(v: [f64; 3]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Gammas of the tone curves the self-check tries (the virtual camera's range, 0.7–1.3).
const TONE_GAMMAS: [f64; 5] = [0.7, 0.85, 1.0, 1.15, 1.3];
/// Contrasts of the S-curves the self-check tries (the virtual camera's range, ±0.4).
const TONE_CONTRASTS: [f64; 5] = [-0.4, -0.2, 0.0, 0.2, 0.4];

/// Linear RGB from an encoded value `y` (0–1) of a camera whose tone curve is a power
/// `gamma` on linear values, the sRGB encoding (IEC 61966-2-1) and the contrast S-curve
/// `e + contrast·e(1−e)(2e−1)` (the virtual camera's in-camera stage): the S-curve inverted
/// by Newton's method (monotone for |contrast| ≤ 0.5), decoded, raised to 1/gamma.
fn untone(y: f64, gamma: f64, contrast: f64) -> f64 {
    let mut e = y;
    for _ in 0..8 {
        let f = e + contrast * e * (1.0 - e) * (2.0 * e - 1.0) - y;
        let df = 1.0 + contrast * (-6.0 * e * e + 6.0 * e - 1.0);
        e = (e - f / df).clamp(0.0, 1.0);
    }
    srgb_decode(e).powf(1.0 / gamma)
}

/// The least-squares solution (SVD) of design(i)[..columns] · X = target(i) over the
/// patches `rows`.
fn least_squares(
    rows: &[usize],
    columns: usize,
    design: &dyn Fn(usize) -> Vec<f64>,
    target: &dyn Fn(usize) -> [f64; 3],
) -> Result<DMatrix<f64>> {
    let a = DMatrix::from_fn(rows.len(), columns, |r, k| design(rows[r])[k]);
    let b = DMatrix::from_fn(rows.len(), 3, |r, c| target(rows[r])[c]);
    a.svd(true, true)
        .solve(&b, 1e-10)
        .map_err(|e| InferError::invalid(format!("self-check fit: {e}")))
}

/// The scale of a feature row: 255 when any value exceeds 1, else 1 (as the feature checks
/// tell them apart).
pub fn feature_scale(row: &[f64]) -> f64 {
    if row.iter().any(|&v| v > 1.0) {
        255.0
    } else {
        1.0
    }
}

/// Whether a patch's encoded RGB has a channel at the top of the scale.
pub fn clipped_patch(rgb: &[f64], scale: f64) -> bool {
    rgb.iter().any(|&v| v >= 0.995 * scale)
}

/// The number of clipped patches of a feature row (see [`clipped_patch`]).
pub fn clipped_patches(row: &[f64]) -> usize {
    let scale = feature_scale(row);
    row.chunks_exact(3)
        .filter(|p| clipped_patch(p, scale))
        .count()
}

/// Patches to leave out of the self-check when no photo analysis flags them: a channel at
/// the top of the scale (clipped) or every channel below 2 % of it (dark).
pub fn flag_patches(row: &[f64], scale: f64) -> Vec<bool> {
    row.chunks_exact(3)
        .map(|p| clipped_patch(p, scale) || p.iter().all(|&v| v < 0.02 * scale))
        .collect()
}

/// The model's estimates of [`JITTER_COPIES`] copies of one feature row, each feature
/// perturbed by ±[`JITTER_SIGMA`] (multiplicative, log-normal), peak-normalised. Where many
/// lights give nearly the same photo the network's answer is steep in its input and the
/// copies spread widely — a sensitivity analysis of the inverse map (Saltelli et al. 2008,
/// "Global Sensitivity Analysis: The Primer", ch. 1), propagated to the metrics by Monte
/// Carlo (JCGM 101:2008, GUM Supplement 1, section 7).
#[derive(Debug, Clone)]
pub struct Perturbed {
    copies: Vec<Vec<f64>>,
}

impl Perturbed {
    /// The perturbed estimates of `row` by `model` (a fixed seed: reproducible).
    pub fn of(model: &Model, row: &[f64]) -> Result<Perturbed> {
        let scale = feature_scale(row);
        let noise = Normal::new(0.0, JITTER_SIGMA)
            .map_err(|e| InferError::invalid(format!("jitter: {e}")))?;
        let mut rng = SmallRng::seed_from_u64(JITTER_SEED);
        let mut rows = Vec::with_capacity(JITTER_COPIES * row.len());
        for _ in 0..JITTER_COPIES {
            rows.extend(
                row.iter()
                    .map(|&v| (v * noise.sample(&mut rng).exp()).clamp(0.0, scale)),
            );
        }
        let d = model.grid().count;
        let copies = model
            .estimate_rows(&rows)?
            .chunks_exact(d)
            .map(metrics::normalise_by_max)
            .collect();
        Ok(Perturbed { copies })
    }

    /// Per wavelength, the standard deviation of the copies.
    pub fn spread(&self) -> Vec<f64> {
        let d = self.copies.first().map_or(0, Vec::len);
        (0..d)
            .map(|k| sample_std(self.copies.iter().map(|s| s[k])))
            .collect()
    }

    /// Per single-number metric ([`SCALAR_KEYS`]), the standard deviation of its values
    /// over the copies (on `wavelengths`, the model's grid); a metric undefined for more than
    /// a quarter of the copies has none.
    pub fn metric_spread(&self, wavelengths: &[f64]) -> BTreeMap<String, f64> {
        let all: Vec<LightingMetrics> = self
            .copies
            .iter()
            .map(|s| LightingMetrics::from_samples(wavelengths, s))
            .collect();
        SCALAR_KEYS
            .iter()
            .filter_map(|&key| {
                let values: Vec<f64> = all.iter().filter_map(|m| m.scalar(key)).collect();
                (4 * values.len() >= 3 * all.len() && values.len() > 1)
                    .then(|| (key.to_string(), sample_std(values.into_iter())))
            })
            .collect()
    }
}

/// The sample standard deviation (n − 1) of `values`; 0 for fewer than two.
fn sample_std(values: impl Iterator<Item = f64> + Clone) -> f64 {
    let n = values.clone().count();
    if n < 2 {
        return 0.0;
    }
    let mean = values.clone().sum::<f64>() / n as f64;
    (values.map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt()
}

/// A band around the SPD on its wavelengths.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Band {
    /// The lower edge, never below 0.
    pub lower: Vec<f64>,
    /// The upper edge.
    pub upper: Vec<f64>,
}

/// Per-wavelength 68 % and 95 % bands and the GFC to expect.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Uncertainty {
    /// Where the true (peak-normalised) SPD lies with 68 % probability, per wavelength.
    pub band68: Band,
    /// The same at 95 %.
    pub band95: Band,
    /// The GFC such estimates reach, in the median: the calibration's [`GfcModel`].
    pub expected_gfc: f64,
    /// The mean spread of the perturbed estimates (see [`Perturbed::spread`]).
    pub difficulty: f64,
    /// How many times the bands and intervals are widened because the estimated light
    /// explains this photo worse than it explains a typical calibration photo
    /// ([`Calibration::widening`]); 1 when it explains it as well or better.
    pub widening: f64,
    /// Half-widths of the 68 % and 95 % intervals of the single-number metrics, by key
    /// ([`SCALAR_KEYS`]): "Ra 82 ± 4" is `cri_ra` ± `half95`. Only metrics the calibration
    /// measured and the perturbed copies define.
    pub metrics: BTreeMap<String, MetricInterval>,
}

/// The calibrated half-widths of one metric's intervals, in the metric's unit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MetricInterval {
    /// The true value lies within ± this of the estimate's with 68 % probability.
    pub half68: f64,
    /// The same at 95 %.
    pub half95: f64,
}

/// One metric's calibration: the same scaled-residual conformal rule as the bands (see
/// [`Calibration`]) with the metric's spread over the perturbed copies as the scale.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MetricCalibration {
    /// The metric's key ([`SCALAR_KEYS`]).
    pub key: String,
    /// The median absolute error of the metric on the calibration photos.
    pub floor: f64,
    /// The 68 % quantile of |error| / ((floor + spread)·widening).
    pub scale68: f64,
    /// The 95 % quantile of the same.
    pub scale95: f64,
    /// How many calibration photos defined the metric (for the estimate and the truth).
    pub photos: usize,
}

impl Band {
    /// The mean width (SPD peak = 1).
    pub fn mean_width(&self) -> f64 {
        let n = self.upper.len().max(1) as f64;
        self.upper
            .iter()
            .zip(&self.lower)
            .map(|(u, l)| u - l)
            .sum::<f64>()
            / n
    }
}

/// A model's uncertainty calibration: measured once on held-out virtual photos of held-out
/// lamps (`spdcam trust calibrate`), a small JSON file per model.
///
/// The band is a scaled-residual conformal band (Lei et al. 2018, "Distribution-free
/// predictive inference for regression", JASA 113: 1094–1111, section 5.2, locally weighted
/// residuals): with the spread s(λ) of the perturbed estimates, a floor f(λ) (the median
/// absolute error at λ) and the widening w ≥ 1 of a photo the estimate explains worse than
/// a typical calibration photo ([`Calibration::widening`]), the q-quantile of
/// |error(λ)| / ((f(λ) + s(λ))·w) over the calibration photos times (f(λ) + s(λ))·w is the
/// band's half-width. The expected GFC comes from [`GfcModel`] (not widened: on the real
/// Telelumen dev photos scaling 1 − GFC by w or w² made it two to four times too
/// pessimistic, while the estimate's shape alone came within 0.02 of their median GFC).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Calibration {
    /// The calibrated model's [`Model::fingerprint`].
    pub model: String,
    /// The model's chart.
    pub chart: String,
    /// How the calibration photos were made.
    pub method: String,
    /// The model's wavelengths (nm).
    pub wavelength_nm: Vec<f64>,
    /// f(λ): the median absolute error of the peak-normalised estimate.
    pub floor: Vec<f64>,
    /// The 68 % quantile of |error| / (f + s), per wavelength.
    pub scale68: Vec<f64>,
    /// The 95 % quantile of the same.
    pub scale95: Vec<f64>,
    /// The expected GFC of an estimate from its shape and difficulty.
    pub gfc_model: GfcModel,
    /// The median self-check residual ([`SelfCheck::mean`]) on the calibration photos, when
    /// the chart's reflectances were at hand: the residual of a typical photo, against which
    /// [`Calibration::widening`] measures a photo's.
    pub residual_reference: Option<f64>,
    /// The 99th percentile of the difficulty on the calibration photos: harder photos are
    /// unlike the lights the model knows, or many lights give nearly the same photo.
    pub difficulty_doubtful: f64,
    /// The 99th percentile of the self-check's mean residual on the calibration photos, when
    /// the chart's reflectances were at hand; above it the estimate is doubtful.
    pub self_check_doubtful: Option<f64>,
    /// Per single-number metric, its interval's calibration (absent from older files).
    #[serde(default)]
    pub metrics: Vec<MetricCalibration>,
    /// The 99th percentile of the self-check's half-to-half residual ([`SelfCheck::split`])
    /// on the calibration photos; above it the estimate is doubtful.
    pub split_doubtful: Option<f64>,
    /// The 99th percentile of the self-check's colour gradient across the chart
    /// ([`SelfCheck::colour_gradient`]) on the calibration photos; above it the estimate is
    /// doubtful (absent from older files).
    #[serde(default)]
    pub colour_gradient_doubtful: Option<f64>,
    /// The 99th percentile of the self-check's glare ([`SelfCheck::glare`]) on the
    /// calibration photos; above it the estimate is doubtful (absent from older files).
    #[serde(default)]
    pub glare_doubtful: Option<f64>,
    /// The 99th percentile of the number of clipped feature patches on the calibration
    /// photos (saturated colours clip a channel under narrow-band light, and the model was
    /// trained with them); more make the estimate doubtful.
    pub clipped_doubtful: usize,
}

/// The GFC to expect of an estimate, from the estimate itself: a ridge regression (Hoerl &
/// Kennard 1970) of ln(1 − GFC) on ln(difficulty) and the estimate's coordinates on the
/// first principal components of the calibration photos' estimates, fitted on those photos
/// (`spdcam trust calibrate` chooses the number of components and the penalty by
/// cross-validation over lamps). Narrow-band and spiky estimates come from lights that
/// 96 broadband patches resolve poorly, so the shape says much of how far to trust it; the
/// regression's value is the conditional median of ln(1 − GFC), hence of the GFC. It never
/// extrapolates: each input is held within the range the calibration photos span, and the
/// value within the range of their ln(1 − GFC).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GfcModel {
    /// The mean of the calibration photos' estimates (peak 1), per wavelength.
    pub mean: Vec<f64>,
    /// The principal components used, unit vectors on the model's wavelengths.
    pub components: Vec<Vec<f64>>,
    /// The weights of ln(difficulty), of each component's coordinate, and of a constant 1.
    pub weights: Vec<f64>,
    /// The smallest value of each input ([`GfcModel::inputs`]) on the calibration photos.
    pub low: Vec<f64>,
    /// The largest value of each input on the calibration photos.
    pub high: Vec<f64>,
    /// The smallest and largest ln(1 − GFC) of the calibration photos.
    pub gap_range: [f64; 2],
}

impl GfcModel {
    /// The regression's inputs for `spd` (peak 1) of mean spread `difficulty`.
    pub fn inputs(&self, spd: &[f64], difficulty: f64) -> Vec<f64> {
        let mut x = Vec::with_capacity(self.components.len() + 2);
        x.push(difficulty.max(f64::MIN_POSITIVE).ln());
        for c in &self.components {
            x.push(
                c.iter()
                    .zip(spd.iter().zip(&self.mean))
                    .map(|(a, (v, m))| a * (v - m))
                    .sum(),
            );
        }
        x.push(1.0);
        x
    }

    /// The median GFC of estimates like `spd` (peak 1) of mean spread `difficulty`.
    pub fn expected(&self, spd: &[f64], difficulty: f64) -> f64 {
        let z: f64 = self
            .inputs(spd, difficulty)
            .iter()
            .zip(self.low.iter().zip(&self.high))
            .zip(&self.weights)
            .map(|((x, (lo, hi)), w)| w * x.clamp(*lo, *hi))
            .sum();
        let [lowest, highest] = self.gap_range;
        (1.0 - z.clamp(lowest, highest).exp()).clamp(0.0, 1.0)
    }

    /// Whether the model's arrays fit `d` wavelengths.
    fn fits(&self, d: usize) -> bool {
        self.mean.len() == d
            && self.components.iter().all(|c| c.len() == d)
            && self.weights.len() == self.components.len() + 2
            && self.low.len() == self.weights.len()
            && self.high.len() == self.weights.len()
            && self.low.iter().zip(&self.high).all(|(l, h)| l <= h)
            && self.gap_range[0] <= self.gap_range[1]
            && self.weights.iter().all(|w| w.is_finite())
    }
}

/// The widening of a photo whose self-check residual is `residual` against the typical
/// residual `reference` (see [`Calibration::widening`]): their ratio, at least 1; 1 when
/// either is unknown.
pub fn widening(residual: Option<f64>, reference: Option<f64>) -> f64 {
    match (residual, reference) {
        (Some(r), Some(reference)) if reference > 0.0 && r.is_finite() => (r / reference).max(1.0),
        _ => 1.0,
    }
}

/// Estimates above this detection confidence are placed surely; the photo analysis warns
/// below the same level.
pub const SURE_DETECTION: f64 = 0.8;
/// Self-check residuals this many times the calibration's doubtful level make an estimate
/// unusable: the light found does not explain the photo.
pub const UNUSABLE_SELF_CHECK_FACTOR: f64 = 3.0;
/// Below this expected GFC an estimate is doubtful (GFC 0.95 is the thesis's "acceptable"
/// level of spectral match; Hernández-Andrés et al. 2001, JOSA A 18: 412–420).
pub const DOUBTFUL_GFC: f64 = 0.95;
/// A share of clipped feature patches above this makes an estimate unusable: half the
/// chart says only that it is brighter than the camera records.
pub const UNUSABLE_CLIPPED_SHARE: f64 = 0.5;
/// A share of dark feature patches above this makes an estimate doubtful.
pub const DOUBTFUL_DARK_SHARE: f64 = 0.25;

impl Calibration {
    /// Whether the self-check `check` exceeds any of this calibration's doubtful levels:
    /// the residual, the half-to-half residual, the colour gradient or the glare.
    pub fn flags(&self, check: &SelfCheck) -> bool {
        let above =
            |value: Option<f64>, level: Option<f64>| value.zip(level).is_some_and(|(v, l)| v > l);
        above(Some(check.mean), self.self_check_doubtful)
            || above(Some(check.split), self.split_doubtful)
            || above(check.colour_gradient, self.colour_gradient_doubtful)
            || above(Some(check.glare), self.glare_doubtful)
    }

    /// Reads a calibration from JSON (`shown` names it in errors), its arrays checked to
    /// agree in length.
    pub fn from_json(text: &str, shown: &str) -> Result<Calibration> {
        let c: Calibration =
            serde_json::from_str(text).map_err(|e| InferError::invalid(format!("{shown}: {e}")))?;
        let d = c.wavelength_nm.len();
        if d == 0
            || c.floor.len() != d
            || c.scale68.len() != d
            || c.scale95.len() != d
            || !c.gfc_model.fits(d)
        {
            return Err(InferError::invalid(format!(
                "{shown}: the calibration's arrays do not agree in length"
            )));
        }
        Ok(c)
    }

    /// How many times worse than a typical calibration photo the estimated light explains
    /// a photo whose self-check residual is `residual`: the residual over the calibration's
    /// median, at least 1 (and 1 without a self-check). A photo the light explains k times
    /// worse (flare, uneven light, a camera unlike the calibration's) is taken to carry k
    /// times the calibration's errors: its bands and intervals are k times as wide.
    pub fn widening(&self, residual: Option<f64>) -> f64 {
        widening(residual, self.residual_reference)
    }

    /// The bands, expected GFC and metric intervals of `spd` (the model's peak-normalised
    /// estimate) whose perturbed estimates spread by `spread` per wavelength and by
    /// `metric_spread` per metric ([`Perturbed`]), and whose self-check residual is
    /// `residual` ([`SelfCheck::mean`]; `None` without a self-check).
    pub fn uncertainty(
        &self,
        spd: &[f64],
        spread: &[f64],
        metric_spread: &BTreeMap<String, f64>,
        residual: Option<f64>,
    ) -> Result<Uncertainty> {
        let d = self.floor.len();
        if spd.len() != d || spread.len() != d {
            return Err(InferError::invalid(format!(
                "the calibration has {d} wavelengths, the estimate {}",
                spd.len()
            )));
        }
        let widening = self.widening(residual);
        let half = |scale: &[f64], k: usize| scale[k] * (self.floor[k] + spread[k]) * widening;
        let band = |scale: &[f64]| Band {
            lower: (0..d).map(|k| (spd[k] - half(scale, k)).max(0.0)).collect(),
            upper: (0..d).map(|k| spd[k] + half(scale, k)).collect(),
        };
        let difficulty = spread.iter().sum::<f64>() / d as f64;
        Ok(Uncertainty {
            band68: band(&self.scale68),
            band95: band(&self.scale95),
            expected_gfc: self.gfc_model.expected(spd, difficulty),
            difficulty,
            widening,
            metrics: self
                .metrics
                .iter()
                .filter_map(|m| {
                    let s = metric_spread.get(&m.key)?;
                    Some((
                        m.key.clone(),
                        MetricInterval {
                            half68: m.scale68 * (m.floor + s) * widening,
                            half95: m.scale95 * (m.floor + s) * widening,
                        },
                    ))
                })
                .collect(),
        })
    }
}

/// One word for how far an estimate can be trusted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Verdict {
    /// Nothing found against it.
    Ok,
    /// Use with care: see the reasons.
    Doubtful,
    /// Do not use the numbers: the photo does not say what the light is.
    Unusable,
}

impl Verdict {
    /// `ok`, `doubtful` or `unusable`.
    pub fn label(self) -> &'static str {
        match self {
            Verdict::Ok => "ok",
            Verdict::Doubtful => "doubtful",
            Verdict::Unusable => "unusable",
        }
    }
}

/// How far an estimate can be trusted: the verdict, why, and the measurements behind it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Trust {
    /// The verdict.
    pub verdict: Verdict,
    /// What lowered it, and checks that could not be made.
    pub reasons: Vec<String>,
    /// The self-check, when the chart's reflectances were at hand.
    pub self_check: Option<SelfCheck>,
    /// Bands and expected GFC, when the model has a calibration.
    pub uncertainty: Option<Uncertainty>,
}

/// What the photo analysis found that bears on trust (all `None`/empty for feature rows).
#[derive(Debug, Clone, Default)]
pub struct PhotoFlags {
    /// The detection's confidence.
    pub confidence: Option<f64>,
    /// Per feature patch: clipped.
    pub clipped: Vec<bool>,
    /// Per feature patch: dark.
    pub dark: Vec<bool>,
}

/// Judges one estimate: `row` the features, `spd` the model's estimate on its own grid
/// (peak-normalised), `flags` what the photo analysis found. The thresholds are constants
/// of this module and levels of the calibration, chosen before any result was seen
/// (docs/trust.md).
pub fn assess(
    model: &Model,
    calibration: Option<&Calibration>,
    check: Option<&ChartCheck>,
    row: &[f64],
    spd: &[f64],
    flags: &PhotoFlags,
) -> Result<Trust> {
    let mut verdict = Verdict::Ok;
    let mut reasons = Vec::new();
    let mut lower = |v: Verdict, reason: String, reasons: &mut Vec<String>| {
        if v as u8 > verdict as u8 {
            verdict = v;
        }
        reasons.push(reason);
    };
    if let Some(c) = flags.confidence.filter(|&c| c < SURE_DETECTION) {
        lower(
            Verdict::Doubtful,
            format!("the chart was found with confidence {c:.2} only"),
            &mut reasons,
        );
    }
    let scale = feature_scale(row);
    let patches = row.len() / 3;
    let mut skip = flag_patches(row, scale);
    for (i, s) in skip.iter_mut().enumerate() {
        *s |= flags.clipped.get(i).copied().unwrap_or(false)
            || flags.dark.get(i).copied().unwrap_or(false);
    }
    let clipped = (0..patches)
        .filter(|&i| {
            flags.clipped.get(i).copied().unwrap_or(false)
                || clipped_patch(&row[3 * i..3 * i + 3], scale)
        })
        .count();
    let clipped_doubtful = calibration.map_or(0, |c| c.clipped_doubtful);
    if clipped as f64 > UNUSABLE_CLIPPED_SHARE * patches as f64 {
        lower(
            Verdict::Unusable,
            format!("{clipped} of {patches} patches are clipped (overexposed)"),
            &mut reasons,
        );
    } else if clipped > clipped_doubtful {
        lower(
            Verdict::Doubtful,
            format!(
                "{clipped} of {patches} patches are clipped (overexposed; at most {clipped_doubtful} in the calibration photos)"
            ),
            &mut reasons,
        );
    }
    let dark = (0..patches)
        .filter(|&i| {
            flags.dark.get(i).copied().unwrap_or(false)
                || row[3 * i..3 * i + 3].iter().all(|&v| v < 0.02 * scale)
        })
        .count();
    if dark as f64 > DOUBTFUL_DARK_SHARE * patches as f64 {
        lower(
            Verdict::Doubtful,
            format!("{dark} of {patches} patches are nearly black (underexposed)"),
            &mut reasons,
        );
    }
    let self_check = match check {
        Some(c) => match c.check(spd, row, scale, &skip) {
            Ok(s) => Some(s),
            Err(e) => {
                lower(
                    Verdict::Unusable,
                    format!("no self-check: {e}"),
                    &mut reasons,
                );
                None
            }
        },
        None => {
            reasons.push("no self-check: the chart's reflectances are not at hand (the data directory holds them)".into());
            None
        }
    };
    let uncertainty = match calibration {
        Some(cal) => {
            let perturbed = Perturbed::of(model, row)?;
            Some(cal.uncertainty(
                spd,
                &perturbed.spread(),
                &perturbed.metric_spread(&model.grid().wavelengths()),
                self_check.as_ref().map(|s| s.mean),
            )?)
        }
        None => {
            reasons.push("no uncertainty: the model has no calibration".into());
            None
        }
    };
    if let (Some(s), Some(level)) = (&self_check, calibration.and_then(|c| c.self_check_doubtful)) {
        if s.mean > level {
            let v = if s.mean > UNUSABLE_SELF_CHECK_FACTOR * level {
                Verdict::Unusable
            } else {
                Verdict::Doubtful
            };
            lower(
                v,
                format!(
                    "the estimated light does not explain the photo: self-check residual {:.3} (clean photos stay below {level:.3}; worst patches {})",
                    s.mean,
                    s.worst_patches.iter().map(|p| format!("p{p:02}")).collect::<Vec<_>>().join(", ")
                ),
                &mut reasons,
            );
        }
    }
    if let (Some(s), Some(level)) = (&self_check, calibration.and_then(|c| c.split_doubtful)) {
        if s.split > level {
            let v = if s.split > UNUSABLE_SELF_CHECK_FACTOR * level {
                Verdict::Unusable
            } else {
                Verdict::Doubtful
            };
            lower(
                v,
                format!(
                    "the two halves of the chart look lit differently (two lights, glare): half-to-half residual {:.3} (clean photos stay below {level:.3})",
                    s.split
                ),
                &mut reasons,
            );
        }
    }
    if let (Some(g), Some(level)) = (
        self_check.as_ref().and_then(|s| s.colour_gradient),
        calibration.and_then(|c| c.colour_gradient_doubtful),
    ) {
        if g > level {
            lower(
                Verdict::Doubtful,
                format!(
                    "the light's colour changes across the chart (two lights, or one light and a reflection): its neutral patches' colour gradient is {g:.2} (clean photos stay below {level:.2})"
                ),
                &mut reasons,
            );
        }
    }
    if let (Some(s), Some(level)) = (&self_check, calibration.and_then(|c| c.glare_doubtful)) {
        if s.glare > level {
            lower(
                Verdict::Doubtful,
                format!(
                    "light is added unevenly across the chart (glare, a reflection, or flare from a light beside it): an additive light changing across the chart explains {:.0} % of the self-check residual (clean photos stay below {:.0} %)",
                    100.0 * s.glare,
                    100.0 * level
                ),
                &mut reasons,
            );
        }
    }
    if let (Some(u), Some(cal)) = (&uncertainty, calibration) {
        if u.difficulty > cal.difficulty_doubtful {
            lower(
                Verdict::Doubtful,
                "many lights give nearly this photo, or it is unlike the training lights: the SPD's shape is uncertain (wide band)".into(),
                &mut reasons,
            );
        }
        if u.expected_gfc < DOUBTFUL_GFC {
            lower(
                Verdict::Doubtful,
                format!("expected GFC {:.3} is below {DOUBTFUL_GFC}", u.expected_gfc),
                &mut reasons,
            );
        }
    }
    Ok(Trust {
        verdict,
        reasons,
        self_check,
        uncertainty,
    })
}

/// The calibrations shipped with the models (`models/<chart>.trust.json`, made by
/// `spdcam trust calibrate`); each names the model it was measured on.
const SHIPPED_CALIBRATIONS: &[(&str, &str)] = &[
    (
        "the colorchecker_sg96 calibration",
        include_str!("../../../models/colorchecker_sg96.trust.json"),
    ),
    (
        "the colorchecker24 calibration",
        include_str!("../../../models/colorchecker24.trust.json"),
    ),
];

/// The shipped calibration measured on `model`, if any.
pub fn calibration_for(model: &Model) -> Result<Option<Calibration>> {
    let fingerprint = model.fingerprint();
    for (name, text) in SHIPPED_CALIBRATIONS {
        let c = Calibration::from_json(text, name)?;
        if c.model == fingerprint {
            return Ok(Some(c));
        }
    }
    Ok(None)
}

/// The flags of an analysed photo's feature patches: `feature_patches` are their indices
/// among the chart's patches (row-major) when the chart has patches that are not features.
pub fn photo_flags(analysis: &PhotoAnalysis, feature_patches: Option<&[usize]>) -> PhotoFlags {
    let count = analysis.features.len() / 3;
    let indices: Vec<usize> = match feature_patches {
        Some(f) if f.len() == count => f.to_vec(),
        _ if analysis.patches.len() == count => (0..count).collect(),
        _ => Vec::new(),
    };
    let flag = |get: fn(&PatchSample) -> bool| -> Vec<bool> {
        indices
            .iter()
            .map(|&i| {
                analysis
                    .patches
                    .iter()
                    .find(|p| p.patch == i)
                    .is_some_and(get)
            })
            .collect()
    };
    PhotoFlags {
        confidence: Some(analysis.confidence),
        clipped: flag(|p| p.clipped),
        dark: flag(|p| p.dark),
    }
}

/// Judges an estimate by `model` from feature `row`, with the checks of [`assess`]; the
/// bands are resampled onto `grid` (linear within, the edge value held beyond).
pub fn judge(
    model: &Model,
    row: &[f64],
    flags: &PhotoFlags,
    data_dir: &DataDir,
    grid: &Grid,
) -> Result<Trust> {
    let spd = metrics::normalise_by_max(&model.estimate(row)?);
    let calibration = calibration_for(model)?;
    let check = ChartCheck::for_model(model, data_dir)?;
    let mut trust = assess(
        model,
        calibration.as_ref(),
        check.as_ref(),
        row,
        &spd,
        flags,
    )?;
    let mg = model.grid();
    if *grid != mg {
        if let Some(u) = &mut trust.uncertainty {
            for band in [&mut u.band68, &mut u.band95] {
                let set = SpectralSet::on_grid(
                    &mg,
                    vec!["lower".into(), "upper".into()],
                    vec![band.lower.clone(), band.upper.clone()],
                )?;
                let (set, _) = set.resample(grid, Interpolation::Auto, Extrapolation::HoldEdge)?;
                band.lower = set.item(0).iter().map(|v| v.max(0.0)).collect();
                band.upper = set.item(1).to_vec();
            }
        }
    }
    Ok(trust)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::estimate::{estimate_features, judge_estimate, FeatureRows};
    use crate::shipped::ModelSet;
    use spdcam_core::colorimetry::{srgb_decode, srgb_encode};
    use spdcam_core::illuminant::StandardIlluminant;

    fn cc24_check(grid: &Grid) -> ChartCheck {
        let chart = Chart::colorchecker24(grid).unwrap();
        let table = &builtin::CAMERAS[0];
        let camera = Sensitivities::new(table.name, &table.load().unwrap(), grid).unwrap();
        ChartCheck::new(&chart, &camera, grid).unwrap()
    }

    /// Features of the check's own chart under `spd`: raw RGB through a colour matrix with
    /// cross-talk, an offset and a gradient, sRGB-encoded on 0–255.
    fn features_of(check: &ChartCheck, spd: &[f64]) -> Vec<f64> {
        let raw: Vec<[f64; 3]> = check
            .weights
            .iter()
            .map(|w| std::array::from_fn(|c| w[c].iter().zip(spd).map(|(a, b)| a * b).sum()))
            .collect();
        let peak = raw.iter().flatten().copied().fold(0.0f64, f64::max);
        let m = [[0.9, 0.15, -0.05], [0.1, 0.8, 0.1], [-0.02, 0.2, 0.7]];
        raw.iter()
            .zip(&check.centres)
            .flat_map(|(p, [x, _])| {
                let gain = 0.8 * (1.0 + 0.1 * x) / peak;
                (0..3).map(move |c| {
                    let lin = gain * (0..3).map(|k| m[c][k] * p[k]).sum::<f64>() + 0.01;
                    255.0 * srgb_encode(lin.clamp(0.0, 1.0))
                })
            })
            .collect()
    }

    #[test]
    fn a_perfect_estimate_explains_the_photo_and_a_wrong_chart_does_not() {
        let grid = Grid::parse("400-700:5").unwrap();
        let check = cc24_check(&grid);
        let spd = StandardIlluminant::A.spd(&grid).unwrap();
        let row = features_of(&check, &spd);
        let skip = vec![false; check.patches()];
        let good = check.check(&spd, &row, 255.0, &skip).unwrap();
        assert!(good.mean < 0.01, "perfect estimate: residual {}", good.mean);
        // The same colours in another order: a chart the light cannot explain.
        let mut wrong = Vec::new();
        for p in (0..check.patches()).rev() {
            wrong.extend_from_slice(&row[3 * p..3 * p + 3]);
        }
        let bad = check.check(&spd, &wrong, 255.0, &skip).unwrap();
        assert!(
            bad.mean > 10.0 * good.mean.max(0.01),
            "wrong chart: {}",
            bad.mean
        );
        assert_eq!(bad.worst_patches.len(), WORST_NAMED);
        assert!(bad.worst >= bad.mean);
    }

    #[test]
    fn light_added_to_one_side_of_the_chart_reads_as_glare() {
        let grid = Grid::parse("400-700:5").unwrap();
        let check = cc24_check(&grid);
        let spd = StandardIlluminant::D65.spd(&grid).unwrap();
        let clean = features_of(&check, &spd);
        // A light beside the chart adds up to a fifth of the white's level on its left side.
        let glared: Vec<f64> = clean
            .iter()
            .enumerate()
            .map(|(f, &v)| {
                let x = check.centres[f / 3][0];
                let lin = srgb_decode(v / 255.0) + 0.2 * (0.5 - x).powi(2);
                255.0 * srgb_encode(lin.min(1.0))
            })
            .collect();
        let skip = vec![false; check.patches()];
        let a = check.check(&spd, &clean, 255.0, &skip).unwrap();
        let b = check.check(&spd, &glared, 255.0, &skip).unwrap();
        assert!((0.0..=1.0).contains(&a.glare) && (0.0..=1.0).contains(&b.glare));
        assert!(a.glare < 0.1, "clean: {}", a.glare);
        assert!(b.glare > 0.3, "glared: {} (clean {})", b.glare, a.glare);
    }

    #[test]
    fn widening_is_the_residual_over_the_typical_one_and_never_narrows() {
        assert_eq!(widening(Some(0.09), Some(0.03)), 3.0);
        assert_eq!(widening(Some(0.01), Some(0.03)), 1.0);
        assert_eq!(widening(None, Some(0.03)), 1.0);
        assert_eq!(widening(Some(0.09), None), 1.0);
        assert_eq!(widening(Some(f64::NAN), Some(0.03)), 1.0);
        assert_eq!(widening(Some(0.09), Some(0.0)), 1.0);
    }

    #[test]
    fn the_expected_gfc_follows_its_regression() {
        // ln(1 − GFC) = −4 + 0.5·ln(difficulty) + 2·(coordinate on the one component).
        let model = GfcModel {
            mean: vec![0.5, 0.5],
            components: vec![vec![0.6, 0.8]],
            weights: vec![0.5, 2.0, -4.0],
            low: vec![-10.0, -1.0, 1.0],
            high: vec![0.0, 1.0, 1.0],
            gap_range: [-20.0, 0.0],
        };
        let (spd, difficulty) = ([1.0, 0.25], 0.04);
        let coordinate = 0.6 * 0.5 + 0.8 * -0.25;
        let want = 1.0 - (-4.0 + 0.5 * 0.04f64.ln() + 2.0 * coordinate).exp();
        assert!((model.expected(&spd, difficulty) - want).abs() < 1e-12);
        assert_eq!(
            model.inputs(&spd, difficulty),
            vec![0.04f64.ln(), coordinate, 1.0]
        );
        // Inputs beyond the calibration's range are held at its edge, and so is the value.
        let narrow = GfcModel {
            low: vec![-10.0, 0.2, 1.0],
            ..model.clone()
        };
        let held = 1.0 - (-4.0 + 0.5 * 0.04f64.ln() + 2.0 * 0.2).exp();
        assert!((narrow.expected(&spd, difficulty) - held).abs() < 1e-12);
        let wild = GfcModel {
            weights: vec![0.0, 0.0, 5.0],
            gap_range: [-20.0, -3.0],
            ..model
        };
        assert!((wild.expected(&spd, difficulty) - (1.0 - (-3.0f64).exp())).abs() < 1e-12);
    }

    #[test]
    fn bands_widen_with_the_residual_and_the_expected_gfc_does_not_move() {
        let d = 2;
        let cal = Calibration {
            model: "0".into(),
            chart: "c".into(),
            method: "m".into(),
            wavelength_nm: vec![400.0, 410.0],
            floor: vec![0.1; d],
            scale68: vec![1.0; d],
            scale95: vec![2.0; d],
            gfc_model: GfcModel {
                mean: vec![0.5; d],
                components: Vec::new(),
                weights: vec![0.0, -3.0],
                low: vec![-10.0, 1.0],
                high: vec![0.0, 1.0],
                gap_range: [-10.0, 0.0],
            },
            residual_reference: Some(0.05),
            difficulty_doubtful: 1.0,
            self_check_doubtful: None,
            metrics: Vec::new(),
            split_doubtful: None,
            colour_gradient_doubtful: None,
            glare_doubtful: None,
            clipped_doubtful: 0,
        };
        let (spd, spread) = ([1.0, 0.5], [0.05, 0.05]);
        let plain = cal
            .uncertainty(&spd, &spread, &BTreeMap::new(), Some(0.04))
            .unwrap();
        let wide = cal
            .uncertainty(&spd, &spread, &BTreeMap::new(), Some(0.1))
            .unwrap();
        assert_eq!((plain.widening, wide.widening), (1.0, 2.0));
        // Half-width 2 × (0.1 + 0.05) = 0.3, doubled by the widening.
        assert!((plain.band95.upper[0] - 1.3).abs() < 1e-12);
        assert!((wide.band95.upper[0] - 1.6).abs() < 1e-12);
        assert_eq!(wide.band95.lower[1], 0.0);
        assert_eq!(plain.expected_gfc, wide.expected_gfc);
        assert!((plain.expected_gfc - (1.0 - (-3.0f64).exp())).abs() < 1e-12);
    }

    #[test]
    fn shipped_models_carry_their_calibrations() {
        for m in ModelSet::shipped().unwrap().models() {
            let c = calibration_for(&m.model).unwrap().expect("a calibration");
            assert_eq!(Some(c.chart.as_str()), m.model.header().chart.as_deref());
            assert_eq!(c.floor.len(), m.model.grid().count);
            assert!(c.scale68.iter().zip(&c.scale95).all(|(a, b)| a <= b));
        }
    }

    #[test]
    fn a_wrong_charts_features_are_not_ok_and_bands_hold_the_estimate() {
        let models = ModelSet::shipped().unwrap();
        let model = &models.for_chart("colorchecker24").unwrap().model;
        let grid = model.grid();
        let check = cc24_check(&grid);
        let row = features_of(&check, &StandardIlluminant::D65.spd(&grid).unwrap());
        let mut wrong = Vec::new();
        for p in (0..check.patches()).rev() {
            wrong.extend_from_slice(&row[3 * p..3 * p + 3]);
        }
        let rows = FeatureRows::from_values(
            model.feature_names().to_vec(),
            [row.clone(), wrong.clone()].concat(),
            "test",
        )
        .unwrap();
        let mut estimates = estimate_features(&models, &rows, "test", &grid).unwrap();
        let data_dir = DataDir::new(None);
        for (e, r) in estimates.iter_mut().zip([&row, &wrong]) {
            judge_estimate(e, &models, model.feature_names(), r, &data_dir).unwrap();
        }
        let t = estimates[1].trust.as_ref().unwrap();
        assert_ne!(t.verdict, Verdict::Ok, "{:?}", t.reasons);
        assert!(t.self_check.as_ref().unwrap().mean > 0.2);

        let e = &estimates[0];
        let json = e.to_json().unwrap();
        for key in [
            "verdict",
            "reasons",
            "self_check",
            "expected_gfc",
            "band_widening",
            "band68",
            "band95",
        ] {
            assert!(json.get(key).is_some_and(|v| !v.is_null()), "no {key}");
        }
        assert_eq!(
            json["band95"]["lower"].as_array().unwrap().len(),
            e.spd.len()
        );
        assert!(json["self_check"]["glare"].as_f64().is_some());
        let u = e.trust.as_ref().unwrap().uncertainty.as_ref().unwrap();
        assert!((0.0..=1.0).contains(&u.expected_gfc));
        assert!(u.widening >= 1.0);
        for k in 0..e.spd.len() {
            let (l95, l68, u68, u95) = (
                u.band95.lower[k],
                u.band68.lower[k],
                u.band68.upper[k],
                u.band95.upper[k],
            );
            assert!(0.0 <= l95 && l95 <= l68 && l68 <= e.spd[k] + 1e-9, "at {k}");
            assert!(e.spd[k] <= u68 + 1e-9 && u68 <= u95, "at {k}");
        }
    }

    #[test]
    fn a_calibration_whose_arrays_disagree_is_refused() {
        let text = r#"{"model":"0","chart":"c","method":"m","wavelength_nm":[400,410],
            "floor":[0.1],"scale68":[1,1],"scale95":[2,2],
            "gfc_model":{"mean":[0.5,0.5],"components":[],"weights":[0.0,-3.0],
                "low":[-9.0,1.0],"high":[0.0,1.0],"gap_range":[-9.0,0.0]},
            "residual_reference":null,"difficulty_doubtful":0.1,"self_check_doubtful":null,"split_doubtful":null,
            "clipped_doubtful":0}"#;
        let err = Calibration::from_json(text, "c.json")
            .unwrap_err()
            .to_string();
        assert!(err.contains("c.json"), "{err}");
    }
}
