//! The self-check: the chart's reflectances re-rendered under the estimated light by a
//! reference camera, mapped to the photo by a per-photo colour correction; what the map
//! cannot explain (the residual, the half-to-half residual, the glare) says how well the
//! light found explains the photo.

use crate::error::{InferError, Result};
use crate::model::Model;
use nalgebra::DMatrix;
use serde::Serialize;
use spdcam_core::builtin::{self, DataDir};
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::chart::Chart;
use spdcam_core::chart_lighting::UnevenLight;
use spdcam_core::colorimetry::srgb_decode;
use spdcam_core::spectral::Grid;

/// How many patches the self-check names as the worst.
const WORST_NAMED: usize = 3;
/// Fewer usable patches than this leave the self-check's 6 parameters per channel too free.
pub(crate) const MIN_CHECK_PATCHES: usize = 12;
/// Fewer patches than this on a half leave its 4 parameters per channel too free.
const MIN_HALF_PATCHES: usize = 8;
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
    /// How much better the photo is explained when one half of the chart (left or right,
    /// top or bottom; the larger) is lit by a light of its own, as an F ratio: large when two
    /// different lights each light a half, even when the camera balanced each half to grey.
    pub two_lights: f64,
    /// Glare laid over the chart, read on its dark patches ([`ChartCheck::veil`]); `None`
    /// when no dark patch is usable.
    pub veil: Option<Veil>,
}

/// Glare laid over the chart, read where it shows most: on the patches the light found
/// leaves dark. Shares are of the chart's mean level (green channel, linear light).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Veil {
    /// The share of the chart's mean level in the photo that is light added to every
    /// patch: the median over the dark patches (negative when they read darker than the light found gives them, as a
    /// camera's tone curve that crushes blacks makes them).
    pub share: f64,
    /// How many dark patches it was read on.
    pub patches: usize,
    /// Where the glare is strongest, when one dark patch reads at least [`LOCAL_GLARE`]
    /// more than their median: its centre across the chart (−½…½, x to the right, y down)
    /// and its excess over the median, as a share of the chart's mean.
    pub strongest: Option<([f64; 2], f64)>,
}

/// A feature patch counts as dark for [`ChartCheck::veil`] when the light found gives it
/// less than this share of the chart's mean green.
pub const VEIL_DARK_SHARE: f64 = 0.25;
/// A dark patch reading this much more than the dark patches' median (a share of the
/// chart's mean) shows where the glare is strongest ([`Veil::strongest`]). Chosen on the
/// real SG sets' training and validation photos (docs/glow.md): the glare-free Hue photos'
/// blackest patch reads up to 0.15 above the others' median through the camera's tone
/// curve, the Telelumen photos' glow about 0.5.
pub const LOCAL_GLARE: f64 = 0.2;
/// At least this many dark patches are needed to say where the glare is strongest.
const LOCAL_GLARE_PATCHES: usize = 3;

/// The chart's feature patches seen by a reference camera, ready to be lit by an SPD.
#[derive(Debug, Clone)]
pub struct ChartCheck {
    /// Per feature patch: reference camera sensitivity × reflectance, per channel.
    weights: Vec<[Vec<f64>; 3]>,
    /// Per feature patch: its centre across the chart, −½…½.
    centres: Vec<[f64; 2]>,
    /// The neutral feature patches and their mean reflectances.
    neutrals: Vec<(usize, f64)>,
    /// Per feature patch: its raw RGB under each of the [`LIGHT_CHANGES`] cosine spectra,
    /// `[change][channel]`, the ways the light of one half may differ from the other's.
    changes: Vec<Vec<[f64; 3]>>,
    grid: Grid,
}

impl ChartCheck {
    /// `chart` seen by `camera`, both on `grid`.
    pub fn new(chart: &Chart, camera: &Sensitivities, grid: &Grid) -> Result<ChartCheck> {
        chart.reflectances.require_grid(grid, "chart")?;
        camera.curves.require_grid(grid, "camera")?;
        let weights: Vec<[Vec<f64>; 3]> = chart
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
        let basis = cosine_basis(grid.count, LIGHT_CHANGES);
        let changes = weights
            .iter()
            .map(|w| {
                basis
                    .iter()
                    .map(|b| std::array::from_fn(|c| w[c].iter().zip(b).map(|(a, b)| a * b).sum()))
                    .collect()
            })
            .collect();
        Ok(ChartCheck {
            weights,
            centres,
            neutrals: chart.neutral_features(),
            changes,
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

    /// Each feature patch's centre across the chart, −½…½ ([`Chart::feature_centres`]).
    pub fn centres(&self) -> &[[f64; 2]] {
        &self.centres
    }

    /// The neutral feature patches (feature index, mean reflectance), as
    /// [`Chart::neutral_features`] gives them.
    pub fn neutrals(&self) -> &[(usize, f64)] {
        &self.neutrals
    }

    /// Each feature patch's raw RGB through the reference camera under `spd` (on the check's
    /// grid): Σλ camera · reflectance · SPD.
    pub fn rendered(&self, spd: &[f64]) -> Result<Vec<[f64; 3]>> {
        if spd.len() != self.grid.count {
            return Err(InferError::invalid(format!(
                "the chart rendered under an SPD of {} values on a grid of {}",
                spd.len(),
                self.grid.count
            )));
        }
        Ok(self
            .weights
            .iter()
            .map(|w| std::array::from_fn(|c| w[c].iter().zip(spd).map(|(a, b)| a * b).sum()))
            .collect())
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
        let predicted = self.rendered(spd)?;
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
        best.veil = self.veil(&predicted, features, scale);
        best.colour_gradient =
            UnevenLight::fit_neutrals(&self.neutrals, &self.centres, features, scale)
                .ok()
                .map(|u| u.colour_gradient());
        Ok(best)
    }

    /// Glare laid over the chart, read on its dark patches: veiling glare adds light to
    /// every patch (ISO 18844's veiling glare; as `spdcam_core::camera::optics::VeilingGlare`
    /// renders it); when it is a share w of the photo's mean level, a patch the light found
    /// gives q of the chart's mean reads r = q·(1 − w) + w of the photo's mean, so
    /// w = (r − q)/(1 − q). Read in green (the photo's sRGB decoded to linear light) on the
    /// unclipped patches with q below [`VEIL_DARK_SHARE`], where glare shows most and the
    /// light's colour least; their median is the veil, and a patch reading
    /// [`LOCAL_GLARE`] more shows where it is strongest.
    pub fn veil(&self, predicted: &[[f64; 3]], features: &[f64], scale: f64) -> Option<Veil> {
        let unclipped: Vec<usize> = (0..predicted.len())
            .filter(|&i| {
                features
                    .get(3 * i..3 * i + 3)
                    .is_some_and(|p| !super::spread::clipped_patch(p, scale))
            })
            .collect();
        if unclipped.is_empty() {
            return None;
        }
        let green = |i: usize| srgb_decode((features[3 * i + 1] / scale).clamp(0.0, 1.0));
        let n = unclipped.len() as f64;
        let observed_mean = unclipped.iter().map(|&i| green(i)).sum::<f64>() / n;
        let predicted_mean = unclipped.iter().map(|&i| predicted[i][1]).sum::<f64>() / n;
        if !(observed_mean > 0.0 && predicted_mean > 0.0) {
            return None;
        }
        let mut dark: Vec<(usize, f64)> = unclipped
            .iter()
            .filter_map(|&i| {
                let q = predicted[i][1] / predicted_mean;
                let r = green(i) / observed_mean;
                (q < VEIL_DARK_SHARE).then(|| (i, (r - q) / (1.0 - q)))
            })
            .collect();
        if dark.is_empty() {
            return None;
        }
        dark.sort_by(|a, b| a.1.total_cmp(&b.1));
        let m = dark.len();
        let share = if m % 2 == 1 {
            dark[m / 2].1
        } else {
            0.5 * (dark[m / 2 - 1].1 + dark[m / 2].1)
        };
        let (top, most) = dark[m - 1];
        let strongest = (m >= LOCAL_GLARE_PATCHES && most - share >= LOCAL_GLARE)
            .then(|| (self.centres[top], most - share));
        Some(Veil {
            share,
            patches: m,
            strongest,
        })
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
            return Err(InferError::invalid("the chart or the light is black"));
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
            level: pl,
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
            two_lights: self.two_lights(fitted, used)?,
            glare: if mean > 0.0 {
                (1.0 - glare_mean / mean).max(0.0)
            } else {
                0.0
            },
            colour_gradient: None,
            veil: None,
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

    /// [`SelfCheck::two_lights`]: with the best map's 3×3 matrix M held, each patch's target
    /// is fitted per channel by M·prediction with a gain, a flare and a gradient in x and y,
    /// a second gain and flare on one half (its own exposure and white balance) and the
    /// light changed along the first K cosine spectra (raw RGB through M) on the whole chart;
    /// the F ratio of the same K changes added on that half alone, a nested-model comparison
    /// (Seber & Lee 2003, "Linear Regression Analysis", section 4.3; Chow 1960, Econometrica
    /// 28: 591–605). The changes are shared by the three channels: a different light, not a
    /// different colour map. K is a quarter of the usable patches, at most [`LIGHT_CHANGES`].
    fn two_lights(&self, fitted: &MapFit, used: &[usize]) -> Result<f64> {
        let k = LIGHT_CHANGES.min(used.len() / PATCHES_PER_CHANGE);
        if k == 0 {
            return Ok(0.0);
        }
        let m = &fitted.global;
        let map = |v: [f64; 3]| -> [f64; 3] {
            std::array::from_fn(|c| (0..3).map(|j| v[j] * m[(j, c)]).sum())
        };
        let mapped: Vec<[f64; 3]> = used
            .iter()
            .map(|&i| {
                let d = fitted.design[i];
                map([d[0], d[1], d[2]])
            })
            .collect();
        let changes: Vec<Vec<[f64; 3]>> = used
            .iter()
            .map(|&i| {
                self.changes[i][..k]
                    .iter()
                    .map(|q| map(q.map(|v| v / fitted.level)))
                    .collect()
            })
            .collect();
        let rows = 3 * used.len();
        let shared = SHARED_COLUMNS + k;
        let columns = shared + k;
        if rows <= columns {
            return Ok(0.0);
        }
        let floor = (RESIDUAL_FLOOR * fitted.mean_length).powi(2);
        let mut most = 0.0f64;
        for axis in 0..2 {
            let side: Vec<f64> = used
                .iter()
                .map(|&i| f64::from(u8::from(self.centres[i][axis] >= 0.0)))
                .collect();
            let on = side.iter().filter(|&&s| s > 0.0).count();
            if on < MIN_HALF_PATCHES || used.len() - on < MIN_HALF_PATCHES {
                continue;
            }
            let a = DMatrix::from_fn(rows, columns, |r, col| {
                let (u, c) = (r / 3, r % 3);
                let [x, y] = self.centres[used[u]];
                let channel = |v: f64, of: usize| if of == c { v } else { 0.0 };
                match col {
                    0..=2 => channel(mapped[u][c], col),
                    3..=5 => channel(1.0, col - 3),
                    6..=8 => channel(x * mapped[u][c], col - 6),
                    9..=11 => channel(y * mapped[u][c], col - 9),
                    12..=14 => channel(side[u] * mapped[u][c], col - 12),
                    15..=17 => channel(side[u], col - 15),
                    col if col < shared => changes[u][col - SHARED_COLUMNS][c],
                    col => side[u] * changes[u][col - shared][c],
                }
            });
            let b = DMatrix::from_fn(rows, 1, |r, _| fitted.target[used[r / 3]][r % 3]);
            let rss = |cols: usize| -> Result<f64> {
                let first = a.columns(0, cols);
                let x = first
                    .clone_owned()
                    .svd(true, true)
                    .solve(&b, 1e-10)
                    .map_err(|e| {
                        InferError::invalid(format!("the fit to the chart failed: {e}"))
                    })?;
                Ok((first * x - &b).norm_squared())
            };
            let (one, two) = (rss(shared)?, rss(columns)?);
            let noise = (two / (rows - columns) as f64).max(floor);
            most = most.max((one - two).max(0.0) / k as f64 / noise);
        }
        Ok(most)
    }
}

/// The most cosine spectra one half's light may change along ([`SelfCheck::two_lights`]).
const LIGHT_CHANGES: usize = 16;
/// Usable patches per light change: K is the usable patches over this, at most
/// [`LIGHT_CHANGES`] (chosen on the validation lamps' photos among 3–25 changes).
const PATCHES_PER_CHANGE: usize = 4;
/// The two-lights fit's columns before the light changes: per channel a gain, a flare, a
/// gradient in x and y, and the half's own gain and flare.
const SHARED_COLUMNS: usize = 18;
/// The smallest residual, relative to the chart's mean RGB length, the two-lights ratio
/// divides by (a noise-free photo's residual is rounding).
const RESIDUAL_FLOOR: f64 = 1e-4;

/// The first `k` spectra of the DCT-II basis on `count` wavelengths, cos(π·j·(l + ½)/count)
/// (Ahmed, Natarajan & Rao 1974, "Discrete cosine transform", IEEE Trans. Computers C-23:
/// 90–93): smooth changes of a light, the coarsest first.
fn cosine_basis(count: usize, k: usize) -> Vec<Vec<f64>> {
    (0..k)
        .map(|j| {
            (0..count)
                .map(|l| (std::f64::consts::PI * j as f64 * (l as f64 + 0.5) / count as f64).cos())
                .collect()
        })
        .collect()
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
    /// The predicted raw RGB's mean level the design is divided by.
    level: f64,
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
pub(crate) const TONE_GAMMAS: [f64; 5] = [0.7, 0.85, 1.0, 1.15, 1.3];
/// Contrasts of the S-curves the self-check tries (the virtual camera's range, ±0.4).
pub(crate) const TONE_CONTRASTS: [f64; 5] = [-0.4, -0.2, 0.0, 0.2, 0.4];

/// Linear RGB from an encoded value `y` (0–1) of a camera whose tone curve is a power
/// `gamma` on linear values, the sRGB encoding (IEC 61966-2-1) and the contrast S-curve
/// `e + contrast·e(1−e)(2e−1)` (the virtual camera's in-camera stage): the S-curve inverted
/// by Newton's method (monotone for |contrast| ≤ 0.5), decoded, raised to 1/gamma.
pub(crate) fn untone(y: f64, gamma: f64, contrast: f64) -> f64 {
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
        .map_err(|e| InferError::invalid(format!("the fit to the chart failed: {e}")))
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use spdcam_core::cie_illuminant::StandardIlluminant;
    use spdcam_core::colorimetry::srgb_encode;

    pub(in crate::trust) fn cc24_check(grid: &Grid) -> ChartCheck {
        let chart = Chart::colorchecker24(grid).unwrap();
        let table = &builtin::CAMERAS[0];
        let camera = Sensitivities::new(table.name, &table.load().unwrap(), grid).unwrap();
        ChartCheck::new(&chart, &camera, grid).unwrap()
    }

    /// Features of the check's own chart under `spd`: raw RGB through a colour matrix with
    /// cross-talk, an offset and a gradient, sRGB-encoded on 0–255.
    pub(in crate::trust) fn features_of(check: &ChartCheck, spd: &[f64]) -> Vec<f64> {
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
    fn a_veil_laid_over_the_chart_is_read_back_on_its_dark_patches() {
        let grid = Grid::parse("400-700:5").unwrap();
        let check = cc24_check(&grid);
        for light in [StandardIlluminant::A, StandardIlluminant::D65] {
            let spd = light.spd(&grid).unwrap();
            let raw = check.rendered(&spd).unwrap();
            let peak = raw.iter().flatten().copied().fold(0.0f64, f64::max);
            let mean: [f64; 3] =
                std::array::from_fn(|c| raw.iter().map(|p| p[c]).sum::<f64>() / raw.len() as f64);
            // Veiling glare as the virtual camera lays it: v of the chart's mean raw level
            // added to every patch, per channel; then exposure and sRGB encoding.
            let photo = |veil: f64| -> Vec<f64> {
                raw.iter()
                    .flat_map(|p| {
                        (0..3).map(move |c| {
                            255.0 * srgb_encode(0.7 * (p[c] + veil * mean[c]) / peak / (1.0 + veil))
                        })
                    })
                    .collect()
            };
            for veil in [0.0, 0.05, 0.3, 0.6] {
                let read = check.veil(&raw, &photo(veil), 255.0).unwrap();
                // v of the mean raw level added is v/(1 + v) of the photo's mean.
                assert!(
                    (read.share - veil / (1.0 + veil)).abs() < 1e-9,
                    "{light:?}: laid {veil}, read {}",
                    read.share
                );
                assert!(read.patches >= 1 && read.strongest.is_none());
            }
            // The ColorChecker 24 has two patches dark in green (black and blue): too few
            // to say where glare is strongest.
            assert_eq!(check.veil(&raw, &photo(0.2), 255.0).unwrap().patches, 2);
        }
        // Two ColorChecker 24s side by side (6 × 8): four dark patches, and a glow on the
        // second black patch (bottom right) is where the glare is strongest.
        let cc24 = spdcam_core::chart::registry::COLORCHECKER24_TABLE
            .load()
            .unwrap();
        let double = spdcam_core::spectral::SpectralSet::new(
            cc24.wavelengths().to_vec(),
            (0..48).map(|i| format!("p{i}")).collect(),
            cc24.items().iter().chain(cc24.items()).cloned().collect(),
        )
        .unwrap();
        let chart = Chart::from_reflectances("double", &double, 6, 8, &grid).unwrap();
        let table = &builtin::CAMERAS[0];
        let camera = Sensitivities::new(table.name, &table.load().unwrap(), &grid).unwrap();
        let check = ChartCheck::new(&chart, &camera, &grid).unwrap();
        let raw = check
            .rendered(&StandardIlluminant::D65.spd(&grid).unwrap())
            .unwrap();
        let peak = raw.iter().flatten().copied().fold(0.0f64, f64::max);
        let mut photo: Vec<f64> = raw
            .iter()
            .flat_map(|p| p.map(|v| 255.0 * srgb_encode(0.7 * v / peak)))
            .collect();
        let even = check.veil(&raw, &photo, 255.0).unwrap();
        assert_eq!((even.patches, even.strongest), (4, None));
        photo[3 * 47 + 1] = 255.0 * srgb_encode(srgb_decode(photo[3 * 47 + 1] / 255.0) * 4.0);
        let glow = check.veil(&raw, &photo, 255.0).unwrap();
        let (at, local) = glow.strongest.unwrap();
        assert_eq!(at, check.centres()[47]);
        assert!(
            at[0] > 0.4 && at[1] > 0.4 && local > LOCAL_GLARE,
            "{at:?} {local}"
        );
        // A chart with every patch clipped has nothing to read glare on.
        assert!(check
            .veil(
                &check
                    .rendered(&StandardIlluminant::A.spd(&grid).unwrap())
                    .unwrap(),
                &vec![255.0; 72],
                255.0
            )
            .is_none());
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
    fn two_lights_one_on_each_half_are_told_from_one() {
        let grid = Grid::parse("400-700:5").unwrap();
        let check = cc24_check(&grid);
        let daylight = StandardIlluminant::D65.spd(&grid).unwrap();
        let bulb = StandardIlluminant::A.spd(&grid).unwrap();
        let peak = |s: &[f64]| s.iter().copied().fold(0.0, f64::max);
        let (pd, pb) = (peak(&daylight), peak(&bulb));
        let mean: Vec<f64> = daylight
            .iter()
            .zip(bulb.iter())
            .map(|(a, b)| a / pd + b / pb)
            .collect();
        let skip = vec![false; check.patches()];
        // Each light alone, the estimate right: a second light adds little (what it adds is
        // the map's gradient, which is not quite the photo's).
        let one_light = [&daylight[..], &bulb[..], &mean[..]].map(|spd| {
            check
                .check(spd, &features_of(&check, spd), 255.0, &skip)
                .unwrap()
                .two_lights
        });
        let most_for_one = one_light.iter().copied().fold(0.0, f64::max);
        assert!(most_for_one < 4.0, "one light: {one_light:?}");
        // The right half under the bulb, the left under daylight; each half's exposure and
        // white balance differ too, which the fit allows. The estimate is their mean.
        let (left, right) = (features_of(&check, &daylight), features_of(&check, &bulb));
        let two: Vec<f64> = (0..check.patches())
            .flat_map(|p| {
                let from = if check.centres[p][0] >= 0.0 {
                    &right
                } else {
                    &left
                };
                from[3 * p..3 * p + 3].to_vec()
            })
            .collect();
        let both = check.check(&mean, &two, 255.0, &skip).unwrap().two_lights;
        assert!(
            both > 2.5 * most_for_one.max(1.0),
            "two lights: {both}, one light: {one_light:?}"
        );
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
}
