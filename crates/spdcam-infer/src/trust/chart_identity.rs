//! Is it the chart at all? Before any number is shown, the patches sampled from a photo (or
//! a feature row) are tested for behaving like the chart they are said to be; patches that
//! do not are refused ([`InferError::NotTheChart`]), whatever the model would make of them.
//!
//! Five statistics, each cheap, each measured on real and generated charts and on images
//! that hold none (`docs/chart-identity.md`, which gives the thresholds and their margins):
//!
//! - **contrast**: the spread of the patches' linear RGB over their mean level; a flat
//!   image has none.
//! - **neutral colour**: the patches that are grey on the chart reflect every light alike,
//!   so in a photo of the chart they share one colour, the light's: the spread of their
//!   chromaticities (r, g) = (R, G) / (R + G + B), relative to the spread of all patches'.
//! - **neutral order**: the same patches keep their lightness order under any light:
//!   Spearman's rank correlation (Spearman 1904, "The proof and measurement of association
//!   between two things", Am. J. Psychol. 15: 72–101) of their levels with their
//!   reflectances.
//! - **shuffled**: the chart's reflectances rendered under the estimated light through the
//!   reference camera ([`ChartCheck::rendered`]) are mapped to the patches' linear RGB by an
//!   affine colour map, a 3×3 matrix and an offset fitted by least squares (Hong, Luo &
//!   Rhodes 2001, Color Res. Appl. 26: 76–84); its residual is compared with the residuals of
//!   the same fit to [`PERMUTATIONS`] seeded random permutations of the patches, a
//!   permutation test (Fisher 1935, "The Design of Experiments", §21; Good 2005,
//!   "Permutation, Parametric and Bootstrap Tests of Hypotheses", ch. 3). The statistic is
//!   the residual over the permutations' median: far below 1 for the chart, about 1 for
//!   colours in no relation to it.
//! - **texture** (photos only): the median over the patches of their pixels' standard
//!   deviation: a patch is flat inside, a scene is not.

use super::self_check::ChartCheck;
use crate::error::{InferError, Result};
use crate::model::Model;
use nalgebra::DMatrix;
use rand::rngs::SmallRng;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use serde::Serialize;
use spdcam_core::advice::{not_the_chart, Mismatch, Sampled};
use spdcam_core::chart::shown_chart_name;
use spdcam_core::colorimetry::srgb_decode;
use spdcam_core::photo::{ChartTemplate, PhotoAnalysis};

/// Random permutations the shuffled statistic compares with.
pub const PERMUTATIONS: usize = 50;
/// The permutations' seed: the same patches always get the same statistic.
const PERMUTATION_SEED: u64 = 0x5EED_C4A7;
/// Below this contrast the patches are all one colour.
pub const MIN_CONTRAST: f64 = 0.02;
/// Above this neutral colour spread (relative to all patches') the grey patches are not
/// one colour.
pub const MAX_NEUTRAL_COLOUR: f64 = 0.5;
/// Below this rank correlation the grey patches are not in the chart's lightness order.
pub const MIN_NEUTRAL_ORDER: f64 = 0.5;
/// Above this residual over the permutations' median the chart does not explain the
/// patches.
pub const MAX_SHUFFLED: f64 = 0.5;
/// Above this median pixel standard deviation (encoded, 0–255) the patches are not flat.
pub const MAX_TEXTURE: f64 = 20.0;
/// Patches darker than this share of the brightest are left out of the colour statistics:
/// their chromaticity is mostly noise.
const COLOUR_FLOOR: f64 = 0.05;
/// Fewest usable patches the shuffled statistic needs (a 3×3 map and an offset per
/// channel leave fewer too free).
const MIN_SHUFFLED_PATCHES: usize = 12;
/// Fewest grey patches the neutral statistics need.
const MIN_NEUTRALS: usize = 3;

/// What was measured of the patches (see the module's documentation); `None` where a
/// statistic could not be made (too few usable patches, no reflectances, not a photo).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Identity {
    /// The spread of the patches' linear RGB over their mean level.
    pub contrast: f64,
    /// The grey patches' chromaticity spread over all patches'.
    pub neutral_colour: Option<f64>,
    /// Spearman's rank correlation of the grey patches' levels with their reflectances.
    pub neutral_order: Option<f64>,
    /// The chart's fit residual over the median of the shuffled patches' residuals.
    pub shuffled: Option<f64>,
    /// The median of the patches' pixel standard deviations, 0–255.
    pub texture: Option<f64>,
}

impl Identity {
    /// What shows that the patches are not the chart; empty when nothing does. Patches all
    /// of one colour say only that.
    pub fn mismatches(&self) -> Vec<Mismatch> {
        if self.contrast.is_nan() || self.contrast < MIN_CONTRAST {
            return vec![Mismatch::Flat];
        }
        let above = |v: Option<f64>, level: f64| v.is_some_and(|v| v.is_nan() || v > level);
        let mut out = Vec::new();
        if above(self.neutral_colour, MAX_NEUTRAL_COLOUR) {
            out.push(Mismatch::NotGrey);
        }
        if self
            .neutral_order
            .is_some_and(|v| v.is_nan() || v < MIN_NEUTRAL_ORDER)
        {
            out.push(Mismatch::NotOrdered);
        }
        if above(self.shuffled, MAX_SHUFFLED) {
            out.push(Mismatch::Unexplained);
        }
        if above(self.texture, MAX_TEXTURE) {
            out.push(Mismatch::Textured);
        }
        out
    }
}

/// What the identity test of one model's chart needs, made once per model: the chart's
/// grey patches and, for photos, the template of the chart photographed.
#[derive(Debug, Clone)]
pub struct ChartIdentity {
    /// The chart as people know it.
    shown: String,
    /// The grey feature patches: (feature index, mean reflectance).
    neutral_features: Vec<(usize, f64)>,
    /// The chart photos show, with its grey patches among all its patches.
    template: Option<ChartTemplate>,
}

impl ChartIdentity {
    /// The test for `model`'s chart: its grey patches from the chart's reflectances when
    /// `check` has them, else from the chart template the model carries.
    pub fn for_model(model: &Model, check: Option<&ChartCheck>) -> ChartIdentity {
        let template = model.photo_chart().cloned();
        let neutral_features = match (check, &template) {
            (Some(c), _) => c.neutrals().to_vec(),
            (None, Some(t)) => t
                .neutrals
                .iter()
                .filter_map(|&(p, r)| {
                    let k = t.feature_patches.iter().position(|&f| f == p)?;
                    Some((k, r))
                })
                .collect(),
            (None, None) => Vec::new(),
        };
        let chart = model.header().chart.as_deref().unwrap_or("the model's chart");
        ChartIdentity {
            shown: shown_chart_name(chart),
            neutral_features,
            template,
        }
    }

    /// The chart as people know it (`ColorChecker 24`).
    pub fn shown_chart(&self) -> &str {
        &self.shown
    }

    /// The statistics of a feature row (encoded sRGB on `0…scale`, three per feature patch)
    /// without the shuffled one: `skip` marks clipped or dark patches, left out.
    pub fn of_row(&self, row: &[f64], scale: f64, skip: &[bool]) -> Identity {
        let linear = linear_rgb(row, scale);
        let used = usable(&linear, skip);
        let neutrals: Vec<(usize, f64)> = self
            .neutral_features
            .iter()
            .copied()
            .filter(|&(k, _)| k < linear.len() && !skip.get(k).copied().unwrap_or(false))
            .collect();
        Identity {
            contrast: contrast(&linear, &used),
            neutral_colour: neutral_colour(&linear, &used, &neutrals),
            neutral_order: neutral_order(&linear, &neutrals),
            shuffled: None,
            texture: None,
        }
    }

    /// The statistics of an analysed photo without the shuffled one: those of its feature
    /// row, the grey patches' order over all the chart's grey patches sampled (the SG's
    /// border holds many), and the texture of its feature patches.
    pub fn of_photo(&self, analysis: &PhotoAnalysis, scale: f64, skip: &[bool]) -> Identity {
        let row: Vec<f64> = analysis.features.iter().map(|&v| f64::from(v)).collect();
        let mut identity = self.of_row(&row, scale, skip);
        let Some(template) = self
            .template
            .as_ref()
            .filter(|t| t.name == analysis.chart && analysis.patches.len() == t.patch_count())
        else {
            return identity;
        };
        let patches = &analysis.patches;
        let levels: Vec<(f64, f64)> = template
            .neutrals
            .iter()
            .filter(|&&(p, _)| !patches[p].clipped)
            .map(|&(p, r)| {
                let rgb = patches[p].rgb.map(|v| srgb_decode(f64::from(v) / 255.0));
                (rgb.iter().sum::<f64>() / 3.0, r)
            })
            .collect();
        if levels.len() >= MIN_NEUTRALS {
            identity.neutral_order = Some(spearman(&levels));
        }
        let mut spread: Vec<f64> = template
            .feature_patches
            .iter()
            .map(|&p| f64::from(patches[p].std.iter().sum::<f32>()) / 3.0)
            .collect();
        identity.texture = median(&mut spread);
        identity
    }

    /// The shuffled statistic of a feature row (encoded sRGB on `0…scale`) against the
    /// chart `rendered` (raw RGB per feature patch, [`ChartCheck::rendered`]); `None` with
    /// fewer than [`MIN_SHUFFLED_PATCHES`] usable patches or a degenerate fit.
    pub fn shuffled(
        &self,
        row: &[f64],
        scale: f64,
        skip: &[bool],
        rendered: &[[f64; 3]],
    ) -> Option<f64> {
        let linear = linear_rgb(row, scale);
        if rendered.len() != linear.len() {
            return None;
        }
        shuffled(&linear, &usable(&linear, skip), rendered)
    }

    /// `Ok` when `identity` finds nothing against the chart; else the refusal, naming
    /// `source`, what is wrong and what to do (`sampled`: where the patches came from).
    pub fn require(&self, identity: &Identity, sampled: Sampled, source: &str) -> Result<()> {
        let mismatches = identity.mismatches();
        if mismatches.is_empty() {
            return Ok(());
        }
        let words = not_the_chart(&self.shown, sampled, &mismatches);
        Err(InferError::NotTheChart(match sampled {
            Sampled::Corners => format!("{source}: {words}"),
            Sampled::Detected => {
                format!("{source}: {words}; give its corners with --corners x1,y1,…,x4,y4")
            }
            Sampled::Row(_) => format!("{source} {words}"),
        }))
    }
}

/// Linear RGB (sRGB decoded) of each patch of `row` on `0…scale`.
fn linear_rgb(row: &[f64], scale: f64) -> Vec<[f64; 3]> {
    row.chunks_exact(3)
        .map(|p| std::array::from_fn(|c| srgb_decode((p[c] / scale).clamp(0.0, 1.0))))
        .collect()
}

/// The patches not skipped.
fn usable(linear: &[[f64; 3]], skip: &[bool]) -> Vec<usize> {
    (0..linear.len())
        .filter(|&i| !skip.get(i).copied().unwrap_or(false))
        .collect()
}

/// A patch's level: the mean of its linear channels.
fn level(rgb: &[f64; 3]) -> f64 {
    rgb.iter().sum::<f64>() / 3.0
}

/// The RMS distance of the `used` patches' linear RGB from their mean, over their mean
/// level; 0 for fewer than two patches or black ones.
fn contrast(linear: &[[f64; 3]], used: &[usize]) -> f64 {
    if used.len() < 2 {
        return 0.0;
    }
    let n = used.len() as f64;
    let mean: [f64; 3] = std::array::from_fn(|c| used.iter().map(|&i| linear[i][c]).sum::<f64>() / n);
    let spread = (used
        .iter()
        .map(|&i| (0..3).map(|c| (linear[i][c] - mean[c]).powi(2)).sum::<f64>())
        .sum::<f64>()
        / n)
        .sqrt();
    let mean_level = level(&mean);
    if mean_level > 0.0 {
        spread / mean_level
    } else {
        0.0
    }
}

/// The chromaticity (r, g) of a linear RGB.
fn chromaticity(rgb: &[f64; 3]) -> [f64; 2] {
    let sum = rgb.iter().sum::<f64>();
    [rgb[0] / sum, rgb[1] / sum]
}

/// The RMS distance of chromaticities from their mean.
fn chroma_spread(points: &[[f64; 2]]) -> f64 {
    let n = points.len() as f64;
    let mean = [0, 1].map(|c| points.iter().map(|p| p[c]).sum::<f64>() / n);
    (points
        .iter()
        .map(|p| (p[0] - mean[0]).powi(2) + (p[1] - mean[1]).powi(2))
        .sum::<f64>()
        / n)
        .sqrt()
}

/// The grey patches' chromaticity spread over all used patches', both over the patches
/// brighter than [`COLOUR_FLOOR`] × the brightest; `None` with fewer than
/// [`MIN_NEUTRALS`] such grey patches.
fn neutral_colour(
    linear: &[[f64; 3]],
    used: &[usize],
    neutrals: &[(usize, f64)],
) -> Option<f64> {
    let brightest = used.iter().map(|&i| level(&linear[i])).fold(0.0, f64::max);
    let bright = |i: &usize| level(&linear[*i]) >= COLOUR_FLOOR * brightest && brightest > 0.0;
    let grey: Vec<[f64; 2]> = neutrals
        .iter()
        .map(|n| n.0)
        .filter(bright)
        .map(|i| chromaticity(&linear[i]))
        .collect();
    if grey.len() < MIN_NEUTRALS {
        return None;
    }
    let all: Vec<[f64; 2]> = used
        .iter()
        .filter(|i| bright(i))
        .map(|&i| chromaticity(&linear[i]))
        .collect();
    let whole = chroma_spread(&all);
    Some(if whole > 0.0 {
        chroma_spread(&grey) / whole
    } else {
        1.0
    })
}

/// Spearman's rank correlation of the grey patches' levels with their reflectances;
/// `None` with fewer than [`MIN_NEUTRALS`].
fn neutral_order(linear: &[[f64; 3]], neutrals: &[(usize, f64)]) -> Option<f64> {
    let pairs: Vec<(f64, f64)> = neutrals
        .iter()
        .map(|&(i, r)| (level(&linear[i]), r))
        .collect();
    (pairs.len() >= MIN_NEUTRALS).then(|| spearman(&pairs))
}

/// Spearman's rank correlation of the pairs' two values (ties get their mean rank); 0 when
/// either value is the same for all.
fn spearman(pairs: &[(f64, f64)]) -> f64 {
    let a = ranks(&pairs.iter().map(|p| p.0).collect::<Vec<_>>());
    let b = ranks(&pairs.iter().map(|p| p.1).collect::<Vec<_>>());
    pearson(&a, &b)
}

/// The ranks (1-based, ties their mean rank) of `values`.
fn ranks(values: &[f64]) -> Vec<f64> {
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|&i, &j| values[i].total_cmp(&values[j]));
    let mut out = vec![0.0; values.len()];
    let mut start = 0;
    while start < order.len() {
        let mut end = start + 1;
        while end < order.len() && values[order[end]] == values[order[start]] {
            end += 1;
        }
        let rank = (start + end + 1) as f64 / 2.0;
        for &i in &order[start..end] {
            out[i] = rank;
        }
        start = end;
    }
    out
}

/// Pearson's correlation of `a` and `b`; 0 when either is constant.
fn pearson(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let (mut ab, mut aa, mut bb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        ab += (x - ma) * (y - mb);
        aa += (x - ma).powi(2);
        bb += (y - mb).powi(2);
    }
    if aa > 0.0 && bb > 0.0 {
        ab / (aa * bb).sqrt()
    } else {
        0.0
    }
}

/// The median of `values` (sorted in place); `None` when empty.
fn median(values: &mut [f64]) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    values.sort_by(f64::total_cmp);
    let n = values.len();
    Some(if n % 2 == 1 {
        values[n / 2]
    } else {
        (values[n / 2 - 1] + values[n / 2]) / 2.0
    })
}

/// The shuffled statistic (see the module's documentation) over the `used` patches: the
/// affine map's residual sum of squares, RSS = ‖B‖² − ‖Uᵀ B‖² with U an orthonormal basis of
/// the design's columns (the rendered RGB and a constant), for the patches in their order
/// over its median for [`PERMUTATIONS`] seeded permutations of them.
fn shuffled(linear: &[[f64; 3]], used: &[usize], rendered: &[[f64; 3]]) -> Option<f64> {
    let n = used.len();
    if n < MIN_SHUFFLED_PATCHES {
        return None;
    }
    let mean_level = used.iter().map(|&i| level(&rendered[i])).sum::<f64>() / n as f64;
    if !(mean_level > 0.0) {
        return None;
    }
    let design = DMatrix::from_fn(n, 4, |r, c| match c {
        3 => 1.0,
        c => rendered[used[r]][c] / mean_level,
    });
    let svd = design.svd(true, false);
    let u = svd.u?;
    let largest = svd.singular_values.max();
    let basis: Vec<usize> = (0..svd.singular_values.len())
        .filter(|&k| svd.singular_values[k] > 1e-9 * largest)
        .collect();
    let target: Vec<[f64; 3]> = used.iter().map(|&i| linear[i]).collect();
    let total: f64 = target.iter().flatten().map(|v| v * v).sum();
    let rss = |order: &[usize]| -> f64 {
        let explained: f64 = basis
            .iter()
            .map(|&k| {
                (0..3)
                    .map(|c| {
                        let dot: f64 = (0..n).map(|r| u[(r, k)] * target[order[r]][c]).sum();
                        dot * dot
                    })
                    .sum::<f64>()
            })
            .sum();
        (total - explained).max(0.0)
    };
    let mut order: Vec<usize> = (0..n).collect();
    let own = rss(&order);
    let mut rng = SmallRng::seed_from_u64(PERMUTATION_SEED);
    let mut shuffled: Vec<f64> = (0..PERMUTATIONS)
        .map(|_| {
            order.shuffle(&mut rng);
            rss(&order)
        })
        .collect();
    let typical = median(&mut shuffled)?;
    (typical > 0.0).then(|| own / typical)
}

#[cfg(test)]
mod tests {
    use super::super::self_check::tests::{cc24_check, features_of};
    use super::*;
    use spdcam_core::cie_illuminant::StandardIlluminant;
    use spdcam_core::spectral::Grid;

    /// The ColorChecker 24's test and check on a 5 nm grid, and its features under A.
    fn setup() -> (ChartIdentity, ChartCheck, Vec<f64>, Vec<f64>) {
        let grid = Grid::parse("400-700:5").unwrap();
        let check = cc24_check(&grid);
        let identity = ChartIdentity {
            shown: "ColorChecker 24".into(),
            neutral_features: check.neutrals().to_vec(),
            template: None,
        };
        let spd = StandardIlluminant::A.spd(&grid).unwrap();
        let row = features_of(&check, &spd);
        (identity, check, spd.to_vec(), row)
    }

    /// The full identity of `row`: its statistics and the shuffled one under `spd`.
    fn measured(identity: &ChartIdentity, check: &ChartCheck, spd: &[f64], row: &[f64]) -> Identity {
        let skip = vec![false; row.len() / 3];
        let mut id = identity.of_row(row, 255.0, &skip);
        id.shuffled = identity.shuffled(row, 255.0, &skip, &check.rendered(spd).unwrap());
        id
    }

    #[test]
    fn a_chart_under_a_light_passes_and_its_patches_shuffled_do_not() {
        let (identity, check, spd, row) = setup();
        let chart = measured(&identity, &check, &spd, &row);
        assert!(chart.mismatches().is_empty(), "{chart:?}");
        assert!(chart.shuffled.unwrap() < 0.1, "{chart:?}");
        assert!(chart.neutral_order.unwrap() > 0.99, "{chart:?}");
        // The same colours in another order (a seeded shuffle of the patches).
        let mut order: Vec<usize> = (0..24).collect();
        order.shuffle(&mut SmallRng::seed_from_u64(7));
        let permuted: Vec<f64> = order
            .iter()
            .flat_map(|&p| row[3 * p..3 * p + 3].to_vec())
            .collect();
        let wrong = measured(&identity, &check, &spd, &permuted);
        let said = wrong.mismatches();
        assert!(said.contains(&Mismatch::Unexplained), "{wrong:?}");
        assert!(said.contains(&Mismatch::NotGrey), "{wrong:?}");
        let err = identity
            .require(&wrong, Sampled::Corners, "shuffled.png")
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with(
                "shuffled.png: these corners do not hold a ColorChecker 24: place them on the \
                 chart's four outer corners ("
            ),
            "{err}"
        );
        assert!(matches!(
            identity.require(&chart, Sampled::Corners, "chart.png"),
            Ok(())
        ));
    }

    #[test]
    fn noise_a_gradient_and_a_flat_colour_fail() {
        let (identity, check, spd, _) = setup();
        let mut rng = SmallRng::seed_from_u64(3);
        let noise: Vec<f64> = (0..72)
            .map(|_| rand::Rng::random_range(&mut rng, 0.0..255.0))
            .collect();
        // A smooth colour gradient across the chart's 6 × 4 patches.
        let gradient: Vec<f64> = (0..24)
            .flat_map(|p| {
                let (x, y) = ((p % 6) as f64 / 5.0, (p / 6) as f64 / 3.0);
                [40.0 + 180.0 * x, 60.0 + 120.0 * y, 200.0 - 150.0 * x * y]
            })
            .collect();
        let flat: Vec<f64> = [200.0, 120.0, 60.0].repeat(24);
        for (name, row) in [("noise", noise), ("gradient", gradient), ("flat", flat)] {
            let id = measured(&identity, &check, &spd, &row);
            assert!(!id.mismatches().is_empty(), "{name}: {id:?}");
            let err = identity
                .require(&id, Sampled::Row(2), "rows.csv")
                .unwrap_err()
                .to_string();
            assert!(
                err.starts_with("rows.csv row 2 does not hold a ColorChecker 24's patches"),
                "{err}"
            );
        }
        let flat = measured(&identity, &check, &spd, &[200.0, 120.0, 60.0].repeat(24));
        assert_eq!(flat.mismatches(), [Mismatch::Flat]);
    }

    #[test]
    fn ranks_share_ties_and_a_constant_correlates_with_nothing() {
        assert_eq!(ranks(&[3.0, 1.0, 3.0, 2.0]), [3.5, 1.0, 3.5, 2.0]);
        assert_eq!(spearman(&[(1.0, 0.1), (2.0, 0.2), (3.0, 0.3)]), 1.0);
        assert_eq!(spearman(&[(1.0, 0.3), (2.0, 0.2), (3.0, 0.1)]), -1.0);
        assert_eq!(spearman(&[(1.0, 0.1), (1.0, 0.2), (1.0, 0.3)]), 0.0);
        assert_eq!(median(&mut [3.0, 1.0, 2.0, 10.0]), Some(2.5));
        assert_eq!(median(&mut []), None);
    }
}
