//! Is it the chart at all? Before any number is shown, the patches sampled from a photo (or
//! a feature row) are tested for behaving like the chart they are said to be; patches that
//! do not are refused ([`InferError::NotTheChart`]), whatever the model would make of them.
//!
//! Four statistics, each cheap, each measured on real and generated charts and on images
//! that hold none (`docs/chart-identity.md`, which gives the thresholds and their margins):
//!
//! - **contrast**: the spread of the patches' linear RGB over their mean level; a flat
//!   image has none.
//! - **neutral order** (photos of a chart with many grey patches, the SG's border and
//!   centre): the grey patches reflect every light alike, so they keep their lightness order
//!   under any light: Spearman's rank correlation (Spearman 1904, "The proof and measurement
//!   of association between two things", Am. J. Psychol. 15: 72–101) of their levels with
//!   their reflectances.
//! - **shuffled** (when the chart's reflectances are at hand): the chart's reflectances
//!   rendered under the estimated light through the reference camera
//!   ([`ChartCheck::rendered`]) are mapped to the patches' linear RGB by an affine colour map,
//!   a 3×3 matrix and an offset fitted by least squares (Hong, Luo & Rhodes 2001, Color Res.
//!   Appl. 26: 76–84); its residual is compared with the residuals of the same fit to
//!   [`PERMUTATIONS`] seeded random permutations of the patches, a permutation test (Fisher
//!   1935, "The Design of Experiments", §21; Good 2005, "Permutation, Parametric and
//!   Bootstrap Tests of Hypotheses", ch. 3), with what the place on the chart alone explains
//!   held (Freedman & Lane 1983). The statistic is the residual over the permutations'
//!   median: far below 1 for the chart, about 1 for colours in no relation to it.
//! - **texture** (photos only): the median over the patches of their pixels' standard
//!   deviation: a patch is flat inside, a scene is not.

use super::self_check::{untone, ChartCheck, TONE_CONTRASTS, TONE_GAMMAS};
use crate::error::{InferError, Result};
use crate::model::Model;
use nalgebra::DMatrix;
use rand::rngs::SmallRng;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use serde::Serialize;
use spdcam_core::advice::{not_the_chart, Mismatch, Sampled};
use spdcam_core::camera::colour::srgb_decode_fast;
use spdcam_core::chart::shown_chart_name;
use spdcam_core::colorimetry::srgb_decode;
use spdcam_core::photo::{ChartTemplate, PhotoAnalysis};

/// Random permutations the shuffled statistic compares with.
pub const PERMUTATIONS: usize = 50;
/// The permutations' seed: the same patches always get the same statistic.
const PERMUTATION_SEED: u64 = 0x5EED_C4A7;
/// Below this contrast the patches are all one colour.
pub const MIN_CONTRAST: f64 = 0.02;
/// Below this rank correlation the grey patches are not in the chart's lightness order.
pub const MIN_NEUTRAL_ORDER: f64 = 0.6;
/// Above this residual over the permutations' median the chart does not explain the
/// patches.
pub const MAX_SHUFFLED: f64 = 0.57;
/// Above this median pixel standard deviation (encoded, 0–255) the patches are not flat.
pub const MAX_TEXTURE: f64 = 25.0;
/// Patches a channel's fit needs beyond its columns (fewer leave the map too free).
const MIN_SHUFFLED_SPARE: usize = 8;
/// With this many feature patches or more the map has a light changing across the chart.
const GRADIENT_MIN_PATCHES: usize = 48;
/// A channel at or above this share of the scale is clipped.
const CLIPPED: f64 = 0.995;
/// Where the place on the chart alone leaves less than this share of the patches' spread
/// unexplained, nothing is left for the chart to explain.
const PLACE_EXPLAINS_ALL: f64 = 1e-3;
/// Fewest grey patches the lightness order needs: the SG's border and centre hold about
/// 40; the ColorChecker 24's six are in order by chance too often.
const MIN_ORDER_NEUTRALS: usize = 10;

/// What was measured of the patches (see the module's documentation); `None` where a
/// statistic is not made (no reflectances, not a photo, a chart with few grey patches).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Identity {
    /// The spread of the patches' linear RGB over their mean level.
    pub contrast: f64,
    /// Spearman's rank correlation of the grey patches' levels with their reflectances.
    pub neutral_order: Option<f64>,
    /// The chart's fit residual over the median of the shuffled patches' residuals.
    pub shuffled: Option<f64>,
    /// The median of the patches' pixel standard deviations, 0–255.
    pub texture: Option<f64>,
    /// A statistic the chart allows could not be made: too few patches are neither clipped
    /// nor nearly black.
    pub too_few: bool,
}

impl Identity {
    /// What shows that the patches are not the chart; empty when nothing does. Patches all
    /// of one colour (not textured) say only that.
    pub fn mismatches(&self) -> Vec<Mismatch> {
        let above = |v: Option<f64>, level: f64| v.is_some_and(|v| v.is_nan() || v > level);
        let textured = above(self.texture, MAX_TEXTURE);
        if self.contrast.is_nan() || self.contrast < MIN_CONTRAST {
            return vec![if textured {
                Mismatch::Textured
            } else {
                Mismatch::Flat
            }];
        }
        let mut out = Vec::new();
        if self
            .neutral_order
            .is_some_and(|v| v.is_nan() || v < MIN_NEUTRAL_ORDER)
        {
            out.push(Mismatch::NotOrdered);
        }
        if above(self.shuffled, MAX_SHUFFLED) {
            out.push(Mismatch::Unexplained);
        }
        if textured {
            out.push(Mismatch::Textured);
        }
        if self.too_few && out.is_empty() {
            out.push(Mismatch::TooFewUsable);
        }
        out
    }
}

/// What the identity test of one model's chart needs, made once per model: the chart's
/// name as people know it and the template of the chart photographed.
#[derive(Debug, Clone)]
pub struct ChartIdentity {
    /// The chart as people know it.
    shown: String,
    /// The chart photos show, with its grey patches among all its patches.
    template: Option<ChartTemplate>,
}

impl ChartIdentity {
    /// The test for `model`'s chart.
    pub fn for_model(model: &Model) -> ChartIdentity {
        let chart = model
            .header()
            .chart
            .as_deref()
            .unwrap_or("the model's chart");
        ChartIdentity {
            shown: shown_chart_name(chart),
            template: model.photo_chart().cloned(),
        }
    }

    /// The chart as people know it (`ColorChecker 24`).
    pub fn shown_chart(&self) -> &str {
        &self.shown
    }

    /// The statistics of a feature row (encoded sRGB on `0…scale`, three per feature patch)
    /// that need no light: its contrast.
    pub fn of_row(&self, row: &[f64], scale: f64) -> Identity {
        Identity {
            contrast: contrast(&linear_rgb(row, scale)),
            neutral_order: None,
            shuffled: None,
            texture: None,
            too_few: false,
        }
    }

    /// The statistics of an analysed photo that need no light: its feature row's contrast,
    /// the texture of all its patches and, for a chart with ten grey
    /// patches or more (the SG's border and centre), their lightness order over those
    /// neither clipped nor nearly black.
    pub fn of_photo(&self, analysis: &PhotoAnalysis, scale: f64) -> Identity {
        let row: Vec<f64> = analysis.features.iter().map(|&v| f64::from(v)).collect();
        let mut identity = self.of_row(&row, scale);
        let patches = &analysis.patches;
        let mut spread: Vec<f64> = patches
            .iter()
            .map(|p| f64::from(p.std.iter().sum::<f32>()) / 3.0)
            .collect();
        identity.texture = median(&mut spread);
        let Some(template) = self.template.as_ref().filter(|t| {
            t.name == analysis.chart
                && patches.len() == t.patch_count()
                && t.neutrals.len() >= MIN_ORDER_NEUTRALS
        }) else {
            return identity;
        };
        let pairs: Vec<(f64, f64)> = template
            .neutrals
            .iter()
            .filter(|&&(p, _)| !patches[p].clipped && !patches[p].dark)
            .map(|&(p, r)| {
                let rgb = patches[p].rgb.map(|v| srgb_decode(f64::from(v) / 255.0));
                (level(&rgb), r)
            })
            .collect();
        if pairs.len() >= MIN_ORDER_NEUTRALS {
            identity.neutral_order = Some(spearman(&pairs));
        } else {
            identity.too_few = true;
        }
        identity
    }

    /// Adds to `identity` the shuffled statistic of a feature row (encoded sRGB on
    /// `0…scale`) against the chart of `check` rendered under `spd` (the check's grid):
    /// `skip` marks patches left out (those the photo analysis found clipped); clipped
    /// channels are left out too. Where too few patches are left for the fit,
    /// [`Identity::too_few`] says so.
    pub fn add_shuffled(
        &self,
        identity: &mut Identity,
        row: &[f64],
        scale: f64,
        skip: &[bool],
        (check, spd): (&ChartCheck, &[f64]),
    ) -> Result<()> {
        let rendered = check.rendered(spd)?;
        identity.shuffled = (rendered.len() * 3 == row.len())
            .then(|| shuffled(row, scale, skip, &rendered, check.centres()))
            .flatten();
        identity.too_few |= identity.shuffled.is_none();
        Ok(())
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
    // Tabled decoding: a statistic of every feature row of a file needs no more than its
    // 1e-5, and a power per value was a tenth of `estimate --features`.
    row.chunks_exact(3)
        .map(|p| std::array::from_fn(|c| f64::from(srgb_decode_fast((p[c] / scale) as f32))))
        .collect()
}

/// A patch's level: the mean of its linear channels.
fn level(rgb: &[f64; 3]) -> f64 {
    rgb.iter().sum::<f64>() / 3.0
}

/// The RMS distance of the patches' linear RGB from their mean, over their mean level; 0
/// for fewer than two patches or black ones.
fn contrast(linear: &[[f64; 3]]) -> f64 {
    if linear.len() < 2 {
        return 0.0;
    }
    let n = linear.len() as f64;
    let mean: [f64; 3] = std::array::from_fn(|c| linear.iter().map(|p| p[c]).sum::<f64>() / n);
    let spread = (linear
        .iter()
        .map(|p| (0..3).map(|c| (p[c] - mean[c]).powi(2)).sum::<f64>())
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

/// The shuffled statistic (see the module's documentation), per channel over the patches
/// not skipped whose channel is not clipped, summed over the channels. The map's design is
/// the rendered RGB (over its mean level), a constant (flare) and, with
/// [`GRADIENT_MIN_PATCHES`] patches or more, a light changing linearly across the chart
/// (multiplying and adding, as the self-check's); the residual sum of squares of a fit is
/// RSS = ‖y‖² − ‖Uᵀy‖² with U an orthonormal basis of the design's columns (its SVD). What
/// the place on the chart alone explains (a constant, and x and y with the gradient) is no
/// evidence of the chart: the permutations shuffle the residuals of that fit, put back on
/// its fitted values, and the full map is fitted to them (Freedman & Lane 1983, "A
/// nonstochastic interpretation of reported significance levels", J. Bus. Econ. Stat. 1:
/// 292–298; Anderson & Legendre 1999, J. Stat. Comput. Simul. 62: 271–303), so a smooth
/// gradient or stripes across the photo are not taken for the chart. The tone curve undone
/// is the best of the self-check's for the patches in their order. Where the place alone
/// explains nearly all of the patches, nothing is left for the chart to explain: 1.
fn shuffled(
    row: &[f64],
    scale: f64,
    skip: &[bool],
    rendered: &[[f64; 3]],
    centres: &[[f64; 2]],
) -> Option<f64> {
    let n = rendered.len();
    let mean_level = rendered.iter().map(level).sum::<f64>() / n as f64;
    if mean_level.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) || centres.len() != n {
        return None;
    }
    let gradient = n >= GRADIENT_MIN_PATCHES;
    // The full design's columns: the rendered RGB, a constant and, with the gradient, x, y,
    // x·level and y·level; the place alone: the constant and x, y.
    let full_row = |i: usize| -> Vec<f64> {
        let p = rendered[i].map(|v| v / mean_level);
        let l = level(&p);
        let [x, y] = centres[i];
        let mut r = vec![p[0], p[1], p[2], 1.0];
        if gradient {
            r.extend([x, y, x * l, y * l]);
        }
        r
    };
    let place_row = |i: usize| -> Vec<f64> {
        let [x, y] = centres[i];
        if gradient {
            vec![1.0, x, y]
        } else {
            vec![1.0]
        }
    };
    // Per channel: its patches and orthonormal bases of the full design and of the place's.
    let mut channels: Vec<Channel> = Vec::new();
    for c in 0..3 {
        let used: Vec<usize> = (0..n)
            .filter(|&i| !skip.get(i).copied().unwrap_or(false) && row[3 * i + c] < CLIPPED * scale)
            .collect();
        let columns = full_row(0).len();
        if used.len() < columns + MIN_SHUFFLED_SPARE {
            continue;
        }
        let full = basis(DMatrix::from_fn(used.len(), columns, |r, k| {
            full_row(used[r])[k]
        }))?;
        let places = place_row(0).len();
        let place = basis(DMatrix::from_fn(used.len(), places, |r, k| {
            place_row(used[r])[k]
        }))?;
        channels.push((c, used, full, place));
    }
    if channels.is_empty() {
        return None;
    }
    // Each channel's linear values under one tone curve.
    let targets = |gamma: f64, contrast: f64| -> Vec<Vec<f64>> {
        channels
            .iter()
            .map(|(c, used, _, _)| {
                used.iter()
                    .map(|&i| untone((row[3 * i + c] / scale).clamp(0.0, 1.0), gamma, contrast))
                    .collect()
            })
            .collect()
    };
    // The best tone curve: the least RSS of the full map relative to the total about the
    // mean.
    let mut best: Option<(f64, Vec<Vec<f64>>)> = None;
    for &gamma in &TONE_GAMMAS {
        for &contrast in &TONE_CONTRASTS {
            let y = targets(gamma, contrast);
            let (mut rss, mut tss) = (0.0, 0.0);
            for ((_, _, full, _), y) in channels.iter().zip(&y) {
                rss += residual_ss(full, y);
                let mean = y.iter().sum::<f64>() / y.len() as f64;
                tss += y.iter().map(|v| (v - mean).powi(2)).sum::<f64>();
            }
            if tss > 0.0 && best.as_ref().is_none_or(|b| rss / tss < b.0) {
                best = Some((rss / tss, y));
            }
        }
    }
    let (_, y) = best?;
    // The place's residuals per channel; the full map's RSS of them is the RSS of the
    // patches themselves, as the full design holds the place's columns.
    let residuals: Vec<Vec<f64>> = channels
        .iter()
        .zip(&y)
        .map(|((_, _, _, place), y)| {
            let fitted = place * (place.transpose() * DMatrix::from_column_slice(y.len(), 1, y));
            y.iter().zip(fitted.iter()).map(|(a, b)| a - b).collect()
        })
        .collect();
    let place_rss: f64 = residuals.iter().flatten().map(|v| v * v).sum();
    let total: f64 = y
        .iter()
        .map(|y| {
            let mean = y.iter().sum::<f64>() / y.len() as f64;
            y.iter().map(|v| (v - mean).powi(2)).sum::<f64>()
        })
        .sum();
    // Nothing left (or no number at all): the place explains everything.
    if place_rss.partial_cmp(&(PLACE_EXPLAINS_ALL * total)) != Some(std::cmp::Ordering::Greater) {
        return Some(1.0);
    }
    let rss_of = |orders: Option<&[Vec<usize>]>| -> f64 {
        channels
            .iter()
            .zip(&residuals)
            .enumerate()
            .map(|(k, ((_, _, full, _), e))| match orders {
                None => residual_ss(full, e),
                Some(o) => residual_ss(full, &o[k].iter().map(|&r| e[r]).collect::<Vec<_>>()),
            })
            .sum()
    };
    let own = rss_of(None);
    let mut rng = SmallRng::seed_from_u64(PERMUTATION_SEED);
    let mut orders: Vec<Vec<usize>> = residuals.iter().map(|e| (0..e.len()).collect()).collect();
    let mut shuffled: Vec<f64> = (0..PERMUTATIONS)
        .map(|_| {
            for o in &mut orders {
                o.shuffle(&mut rng);
            }
            rss_of(Some(&orders))
        })
        .collect();
    let typical = median(&mut shuffled)?;
    (typical > 0.0).then(|| own / typical)
}

/// One channel's fit: the channel, its patches, and orthonormal bases of the full design
/// and of the place's.
type Channel = (usize, Vec<usize>, DMatrix<f64>, DMatrix<f64>);

/// An orthonormal basis of `design`'s columns: the left singular vectors of its non-zero
/// singular values.
fn basis(design: DMatrix<f64>) -> Option<DMatrix<f64>> {
    let svd = design.svd(true, false);
    let largest = svd.singular_values.max();
    let keep: Vec<usize> = (0..svd.singular_values.len())
        .filter(|&k| svd.singular_values[k] > 1e-9 * largest)
        .collect();
    Some(svd.u?.select_columns(&keep))
}

/// The residual sum of squares of `y` fitted by least squares on the columns of which `u`
/// is an orthonormal basis: ‖y‖² − ‖uᵀy‖².
fn residual_ss(u: &DMatrix<f64>, y: &[f64]) -> f64 {
    let total: f64 = y.iter().map(|v| v * v).sum();
    let explained: f64 = (0..u.ncols())
        .map(|j| {
            let dot: f64 = u.column(j).iter().zip(y).map(|(a, b)| a * b).sum();
            dot * dot
        })
        .sum();
    (total - explained).max(0.0)
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
            template: None,
        };
        let spd = StandardIlluminant::A.spd(&grid).unwrap();
        let row = features_of(&check, &spd);
        (identity, check, spd.to_vec(), row)
    }

    /// The full identity of `row`: its statistics and the shuffled one under `spd`.
    fn measured(
        identity: &ChartIdentity,
        check: &ChartCheck,
        spd: &[f64],
        row: &[f64],
    ) -> Identity {
        let mut id = identity.of_row(row, 255.0);
        identity
            .add_shuffled(&mut id, row, 255.0, &[], (check, spd))
            .unwrap();
        id
    }

    #[test]
    fn a_chart_under_a_light_passes_and_its_patches_shuffled_do_not() {
        let (identity, check, spd, row) = setup();
        let chart = measured(&identity, &check, &spd, &row);
        assert!(chart.mismatches().is_empty(), "{chart:?}");
        assert!(chart.shuffled.unwrap() < 0.1, "{chart:?}");
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
