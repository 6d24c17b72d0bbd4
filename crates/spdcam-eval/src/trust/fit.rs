//! The calibration of a model's trust (`spdcam trust calibrate`): the bands' floor and
//! conformal scales, the metric intervals, the expected-GFC regression and the verdict's
//! levels, fitted on held-out virtual photos of the split's validation lamps and, for the SG,
//! the real photo sets' validation photos.

use crate::error::{EvalError, Result};
use crate::held_out::{on_grid, HeldOutPhotos, SkippedCamera, GRID};
use crate::trust::judged::{
    band_z, conformal_quantile, difficulty, gfc, judge_rows, median, quantile_scales, residual,
    Judged,
};
use crate::trust::real::{balanced, real_split};
use crate::trust::records::CalibrationRecord;
use crate::trust::scenes::scene_rows;
use spdcam_core::builtin::DataDir;
use spdcam_core::chart::Chart;
use spdcam_core::light_families::validation_split::LampPart;
use spdcam_core::quality::registry;
use spdcam_core::spectral::Grid;
use spdcam_infer::pca::{Components, Pca};
use spdcam_infer::ridge::{Gram, Ridge};
use spdcam_infer::trust::calibration::estimate_cct;
use spdcam_infer::trust::local_margin::{photo_coordinates, LocalMargin, COORDINATES};
use spdcam_infer::trust::{
    self, ChartCheck, GfcModel, MetricCalibration, SelfCheck, TrustCalibration, DOUBTFUL_GFC,
    JITTER_COPIES, JITTER_SIGMA, POOR_GFC,
};
use spdcam_infer::Model;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Fewer calibration photos defining a metric than this leave it without an interval.
const MIN_METRIC_PHOTOS: usize = 40;

/// The photos a calibration is fitted on: held-out virtual photos (`shots` consecutive ones
/// per lamp), with `--scenes` scene photos of the same lamps and with `--real` real photos
/// of the real sets' validation split.
pub struct CalibrationPhotos {
    /// Every photo's clipped patches, as the verdict counts them
    /// ([`trust::clipped_features`]).
    clipped: Vec<usize>,
    /// Every photo judged, in the same order.
    judged: Vec<Judged>,
    /// Every photo's kind, in the same order.
    kinds: Vec<PhotoKind>,
    /// Scene photos asked for per lamp.
    scenes_per_lamp: usize,
    /// The cross-validation group of each photo: a lamp's photos (patch level and scene)
    /// together, so that a lamp never informs its own prediction; each real photo alone.
    groups: Vec<usize>,
    /// Each photo's source (`virtual`, `scene` or the real set's name) and light's type,
    /// for its record.
    sources: Vec<(String, String)>,
}

/// The kinds of calibration photo, each of which the metric intervals and the expected
/// GFC's margin must hold on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PhotoKind {
    /// Virtual, patch level.
    Virtual,
    /// Virtual scene photos through the whole camera chain.
    Scene,
    /// The real sets' validation photos.
    Real,
    /// Virtual scene photos of smooth lights (Planckian radiators and CIE daylight): a raw
    /// model's calibration has them beside the lamps' scene photos.
    Smooth,
}

impl PhotoKind {
    /// Every kind.
    pub const ALL: [PhotoKind; 4] = [
        PhotoKind::Virtual,
        PhotoKind::Scene,
        PhotoKind::Real,
        PhotoKind::Smooth,
    ];

    /// The kind's name in a calibration file: `virtual`, `scene`, `real` or `smooth`.
    pub fn label(self) -> &'static str {
        match self {
            PhotoKind::Virtual => "virtual",
            PhotoKind::Scene => "scene",
            PhotoKind::Real => "real",
            PhotoKind::Smooth => "smooth",
        }
    }
}

impl CalibrationPhotos {
    /// Scene photos alone, as a raw model's calibration has them: per photo its clipped
    /// patches as the verdict counts them, its judgement, its kind
    /// ([`PhotoKind::Scene`] or [`PhotoKind::Smooth`]), its cross-validation group (a
    /// light's photos share one) and its source and light's type, for its record; `per_lamp`
    /// photos asked for per lamp.
    pub(crate) fn scenes_only(
        clipped: Vec<usize>,
        judged: Vec<Judged>,
        kinds: Vec<PhotoKind>,
        groups: Vec<usize>,
        sources: Vec<(String, String)>,
        per_lamp: usize,
    ) -> CalibrationPhotos {
        CalibrationPhotos {
            scenes_per_lamp: per_lamp,
            clipped,
            judged,
            kinds,
            groups,
            sources,
        }
    }

    /// The photos the self-check's levels are fitted on: the virtual patch-level photos
    /// (clean by construction, so that the levels tell bad photos); with none, every scene
    /// photo (clean too: one light, no glare).
    fn check_judged(&self) -> Vec<&Judged> {
        let of = |wanted: &[PhotoKind]| -> Vec<&Judged> {
            self.judged
                .iter()
                .zip(&self.kinds)
                .filter(|(_, k)| wanted.contains(k))
                .map(|(j, _)| j)
                .collect()
        };
        let virtual_photos = of(&[PhotoKind::Virtual]);
        if virtual_photos.is_empty() {
            of(&[PhotoKind::Scene, PhotoKind::Smooth])
        } else {
            virtual_photos
        }
    }

    /// How many photos are of `kind`.
    fn count(&self, kind: PhotoKind) -> usize {
        self.kinds.iter().filter(|&&k| k == kind).count()
    }
}

/// Fits `model`'s calibration: the self-check's levels on the clean photos alone (the
/// virtual patch-level ones; without them, every scene photo), everything else on all of
/// `photos`; beside it, each photo's record.
pub fn fit_calibration(
    model: &Model,
    chart: &str,
    photos: &CalibrationPhotos,
    method: String,
) -> Result<(TrustCalibration, Vec<CalibrationRecord>)> {
    let judged = &photos.judged;
    let d = model.grid().count;
    let err = |j: &Judged, k: usize| (j.spd[k] - j.truth.as_ref().map_or(0.0, |t| t[k])).abs();
    let clean_judged = photos.check_judged();
    let checks_of = |value: fn(&SelfCheck) -> Option<f64>| -> Vec<f64> {
        clean_judged
            .iter()
            .filter_map(|j| j.self_check.as_ref().and_then(value))
            .collect()
    };
    let mut checks = checks_of(|s| Some(s.mean));
    let all_checked = checks.len() == clean_judged.len();
    let residual_reference = all_checked.then(|| median(&mut checks.clone()));
    let widenings: Vec<f64> = judged
        .iter()
        .map(|j| trust::widening(residual(j), residual_reference))
        .collect();
    let floor: Vec<f64> = (0..d)
        .map(|k| {
            median(
                &mut judged
                    .iter()
                    .zip(&widenings)
                    .map(|(j, w)| err(j, k) / w)
                    .collect::<Vec<_>>(),
            )
            .max(1e-4)
        })
        .collect();
    let z: Vec<Vec<f64>> = judged
        .iter()
        .zip(&widenings)
        .map(|(j, &w)| band_z(&floor, w, j))
        .collect();
    let [scale68, scale95]: [Vec<f64>; 2] = quantile_scales(&z, &[0.68, 0.95])
        .try_into()
        .map_err(|_| EvalError::invalid("two band scales"))?;
    let mut difficulties: Vec<f64> = judged.iter().map(difficulty).collect();
    let mut splits = checks_of(|s| Some(s.split));
    let mut gradients = checks_of(|s| s.colour_gradient);
    let mut glares = checks_of(|s| Some(s.glare));
    let mut two_lights = checks_of(|s| Some(s.two_lights));
    let kinds = photos.kinds.clone();
    let (gfc_model, held_out) = fit_gfc_model(judged, &photos.groups, &kinds)?;
    let expected_gaps: Vec<f64> = judged
        .iter()
        .map(|j| 1.0 - gfc_model.expected(&j.spd, difficulty(j)))
        .collect();
    let metric_calibrations = registry::calibrated()
        .filter_map(|metric| {
            let key = metric.key;
            let photos: Vec<MetricPhoto> = judged
                .iter()
                .zip(&widenings)
                .zip(expected_gaps.iter().zip(&kinds))
                .filter_map(|((j, &widening), (&expected_gap, &kind))| {
                    Some(MetricPhoto {
                        error: *j.metric_error.get(key)?,
                        spread: *j.metric_spread.get(key)?,
                        value: j.metric_value.get(key)?.abs(),
                        expected_gap,
                        widening,
                        kind,
                    })
                })
                .collect();
            fit_metric(key, &photos)
        })
        .collect();
    let mut clipped: Vec<f64> = photos.clipped.iter().map(|&c| c as f64).collect();
    let local_margin = fit_local_margin(
        &model.grid(),
        judged,
        &expected_gaps,
        &held_out,
        (&photos.groups, &kinds),
        gfc_model.gap_margin95,
    )?;
    let records = (0..judged.len())
        .map(|i| {
            let (source, light) = &photos.sources[i];
            CalibrationRecord::of(
                &judged[i],
                source,
                light,
                photos.groups[i],
                1.0 - expected_gaps[i],
                held_out[i],
                clipped[i] as usize,
            )
        })
        .collect();
    let calibration = TrustCalibration {
        model: model.fingerprint(),
        chart: chart.to_string(),
        method,
        wavelength_nm: model.grid().wavelengths(),
        floor,
        scale68,
        scale95,
        gfc_model,
        residual_reference,
        difficulty_doubtful: conformal_quantile(&mut difficulties, 0.99),
        self_check_doubtful: all_checked.then(|| conformal_quantile(&mut checks, 0.99)),
        split_doubtful: (splits.len() == clean_judged.len())
            .then(|| conformal_quantile(&mut splits, 0.99)),
        // Measured where most photos had enough unclipped neutral patches.
        colour_gradient_doubtful: (10 * gradients.len() >= 9 * clean_judged.len())
            .then(|| conformal_quantile(&mut gradients, 0.99)),
        glare_doubtful: (glares.len() == clean_judged.len())
            .then(|| conformal_quantile(&mut glares, 0.99)),
        two_lights_doubtful: (two_lights.len() == clean_judged.len())
            .then(|| conformal_quantile(&mut two_lights, 0.99)),
        clipped_doubtful: conformal_quantile(&mut clipped, 0.99) as usize,
        metrics: metric_calibrations,
        real_photos: photos.count(PhotoKind::Real),
        scenes_per_lamp: photos.scenes_per_lamp,
        local_margin,
    };
    Ok((calibration, records))
}

/// Calibration photos among which a photo's expected-GFC margin is taken
/// ([`LocalMargin`]). Chosen on the SG's calibration photos of `docs/trust.md`
/// (`tools/local_margin_choice.py`) among 30, 50 and 100 and four sets of coordinates by
/// the rule the calibration applies before it keeps a local margin at all: no kind of photo
/// with more poor estimates `ok`, and more good ones `ok`.
pub const LOCAL_NEIGHBOURS: usize = 100;

/// The local margin of the calibration photos `judged` (estimates on `grid`; 1 − their
/// expected GFC `expected_gaps`, their held-out residuals of ln(1 − GFC) `held_out`, their
/// cross-validation groups and kinds), where it wins over the pooled margin `pooled` by
/// [`local_margin_wins`]: built on the photos that can be placed ([`photo_coordinates`]: a
/// CCT and a self-check); `None` with fewer than [`LOCAL_NEIGHBOURS`] of them or where it
/// does not win.
fn fit_local_margin(
    grid: &Grid,
    judged: &[Judged],
    expected_gaps: &[f64],
    held_out: &[f64],
    (groups, kinds): (&[usize], &[PhotoKind]),
    pooled: f64,
) -> Result<Option<LocalMargin>> {
    let mut placed: Vec<([f64; COORDINATES], f64)> = Vec::with_capacity(judged.len());
    let mut photos = Vec::with_capacity(judged.len());
    for (i, j) in judged.iter().enumerate() {
        let check = j.self_check.as_ref();
        if let Some(x) = photo_coordinates(
            1.0 - expected_gaps[i],
            estimate_cct(grid, &j.spd)?,
            check.map(|c| c.mean),
            check.and_then(|c| c.veil.as_ref()).map(|v| v.share),
        ) {
            placed.push((x, held_out[i]));
            photos.push(PlacedPhoto {
                group: groups[i],
                kind: kinds[i],
                expected_gfc: 1.0 - expected_gaps[i],
                gfc: gfc(j),
            });
        }
    }
    let Some(local) = LocalMargin::fit(&placed, LOCAL_NEIGHBOURS) else {
        return Ok(None);
    };
    Ok(local_margin_wins(&local, &photos, pooled).then_some(local))
}

/// A calibration photo placed among the others, for [`local_margin_wins`].
struct PlacedPhoto {
    /// Its cross-validation group (a lamp's photos share one).
    group: usize,
    /// Its kind.
    kind: PhotoKind,
    /// Its expected GFC.
    expected_gfc: f64,
    /// Its GFC.
    gfc: f64,
}

/// Whether the local margin `local` serves the verdict better than the pooled margin
/// `pooled` on the calibration photos `photos` (in `local`'s order), each judged by the
/// neighbours of other groups only (cross-validated over lamps): no kind of photo may have
/// more `ok` photos (as far as the margin decides: expected GFC ≥ [`DOUBTFUL_GFC`] and its 95 %
/// floor ≥ [`POOR_GFC`]) below GFC [`POOR_GFC`] than under the pooled margin, and more photos
/// of GFC ≥ [`DOUBTFUL_GFC`] must be `ok`. Fixed with the candidates of
/// [`LOCAL_NEIGHBOURS`], before any test photo was judged.
fn local_margin_wins(local: &LocalMargin, photos: &[PlacedPhoto], pooled: f64) -> bool {
    let ok = |p: &PlacedPhoto, margin: f64| {
        p.expected_gfc >= DOUBTFUL_GFC
            && 1.0 - (1.0 - p.expected_gfc) * margin.max(0.0).exp() >= POOR_GFC
    };
    // Per kind: poor photos called ok, pooled and local; good photos called ok, the same.
    let mut counts: BTreeMap<&str, [usize; 4]> = BTreeMap::new();
    for (i, p) in photos.iter().enumerate() {
        let others: Vec<usize> = (0..photos.len())
            .filter(|&o| photos[o].group != p.group)
            .collect();
        let margin = local.margin95_among(&local.photos[i], &others);
        let c = counts.entry(p.kind.label()).or_default();
        let poor = p.gfc < POOR_GFC;
        let good = p.gfc >= DOUBTFUL_GFC;
        c[0] += usize::from(poor && ok(p, pooled));
        c[1] += usize::from(poor && ok(p, margin));
        c[2] += usize::from(good && ok(p, pooled));
        c[3] += usize::from(good && ok(p, margin));
    }
    let no_more_poor = counts.values().all(|c| c[1] <= c[0]);
    let (good_pooled, good_local) = counts
        .values()
        .fold((0, 0), |(a, b), c| (a + c[2], b + c[3]));
    no_more_poor && good_local > good_pooled
}

/// Powers of the expected 1 − GFC in a metric's floor that the calibration chooses among
/// ([`MetricCalibration::gap_power`]); 0 is one floor for every photo.
const GAP_POWERS: [f64; 5] = [0.0, 0.25, 0.5, 0.75, 1.0];

/// One calibration photo's numbers for a metric's interval, in the metric's unit.
struct MetricPhoto {
    /// |estimate − truth|.
    error: f64,
    /// The spread over the perturbed copies.
    spread: f64,
    /// |the estimate's value|.
    value: f64,
    /// 1 − the expected GFC.
    expected_gap: f64,
    /// The photo's widening.
    widening: f64,
    /// Its kind.
    kind: PhotoKind,
}

/// The calibration of metric `key` on `photos` (none below [`MIN_METRIC_PHOTOS`]): for each
/// power of the expected 1 − GFC in the floor ([`GAP_POWERS`]), the floor (median of |error|
/// / (widening · gap factor)) and the group-conditional conformal scales; the power whose 95 %
/// intervals are narrowest in the median over the photos is kept (for CCT as a share of the
/// estimate, [`registry::Metric::interval_in_per_cent`]). The conformal quantile holds for any power fixed
/// beforehand; choosing among five on the same photos costs little coverage, which the
/// report measures on held-out photos.
fn fit_metric(key: &str, photos: &[MetricPhoto]) -> Option<MetricCalibration> {
    let as_share = registry::metric(key).is_some_and(|m| m.interval_in_per_cent);
    // A width as a share needs the estimate's value; photos without one are left out.
    let photos: Vec<&MetricPhoto> = photos
        .iter()
        .filter(|p| !as_share || (p.value > 0.0 && p.value.is_finite()))
        .collect();
    if photos.len() < MIN_METRIC_PHOTOS {
        return None;
    }
    let mut gaps: Vec<f64> = photos.iter().map(|p| p.expected_gap).collect();
    let gap_reference = median(&mut gaps).max(f64::EPSILON);
    let candidate = |gap_power: f64| -> (f64, MetricCalibration) {
        let mut m = MetricCalibration {
            key: key.to_string(),
            floor: 1.0,
            scale68: 1.0,
            scale95: 1.0,
            photos: photos.len(),
            gap_power,
            gap_reference,
        };
        m.floor = median(
            &mut photos
                .iter()
                .map(|p| p.error / (p.widening * m.gap_factor(p.expected_gap)))
                .collect::<Vec<_>>(),
        )
        .max(f64::EPSILON);
        let units: Vec<f64> = photos
            .iter()
            .map(|p| m.unit(p.spread, p.expected_gap, p.widening))
            .collect();
        let ratios: Vec<(f64, PhotoKind)> = photos
            .iter()
            .zip(&units)
            .map(|(p, u)| (p.error / u, p.kind))
            .collect();
        m.scale68 = group_conditional_quantile(&ratios, 0.68, MIN_METRIC_PHOTOS);
        m.scale95 = group_conditional_quantile(&ratios, 0.95, MIN_METRIC_PHOTOS);
        let width = median(
            &mut photos
                .iter()
                .zip(&units)
                .map(|(p, u)| u * m.scale95 / if as_share { p.value } else { 1.0 })
                .collect::<Vec<_>>(),
        );
        (width, m)
    };
    // The narrowest; a tie keeps the smaller power (tried first).
    GAP_POWERS
        .iter()
        .map(|&power| candidate(power))
        .fold(
            None,
            |best: Option<(f64, MetricCalibration)>, c| match best {
                Some(b) if b.0 <= c.0 => Some(b),
                _ => Some(c),
            },
        )
        .map(|(_, m)| m)
}

/// The group-conditional (Mondrian) conformal `q` quantile of `values`, each tagged with its
/// kind of photo: the largest of each kind's own quantile (kinds with at least `min` values)
/// and the pooled one, so that an interval scaled by it holds on each kind of photo, not
/// only on all of them pooled (Vovk, Gammerman & Shafer 2005, "Algorithmic Learning in a
/// Random World", section 4.5).
fn group_conditional_quantile(values: &[(f64, PhotoKind)], q: f64, min: usize) -> f64 {
    group_quantiles(values, q, min)
        .into_values()
        .fold(0.0, f64::max)
}

/// The conformal `q` quantile of `values` for each kind of photo with at least `min` of them
/// (keyed by [`PhotoKind::label`]) and for all of them (`pooled`): the quantiles
/// [`group_conditional_quantile`] takes the largest of.
fn group_quantiles(values: &[(f64, PhotoKind)], q: f64, min: usize) -> BTreeMap<String, f64> {
    let of = |kind: Option<PhotoKind>| -> Vec<f64> {
        values
            .iter()
            .filter(|v| kind.is_none_or(|k| v.1 == k))
            .map(|v| v.0)
            .collect()
    };
    PhotoKind::ALL
        .iter()
        .map(|&k| (k.label(), of(Some(k))))
        .filter(|(_, v)| v.len() >= min)
        .chain(std::iter::once(("pooled", of(None))))
        .map(|(label, mut v)| (label.to_string(), conformal_quantile(&mut v, q)))
        .collect()
}

/// Numbers of principal components the expected-GFC regression chooses among.
const GFC_COMPONENTS: [usize; 7] = [0, 1, 2, 3, 5, 8, 12];
/// Penalties (× each input's centred sum of squares) it chooses among.
const GFC_PENALTIES: [f64; 7] = [1e-4, 1e-3, 1e-2, 1e-1, 1.0, 10.0, 100.0];
/// Folds of its cross-validation, whole lamps at a time.
const GFC_FOLDS: usize = 5;
/// The smallest 1 − GFC the regression's logarithm sees (GFC is printed to 4 decimals).
const GFC_GAP_FLOOR: f64 = 1e-5;

/// The expected-GFC regression ([`GfcModel`]) of the judged calibration photos: the number
/// of principal components and the penalty with the least squared error of ln(1 − GFC) in
/// cross-validation over whole groups (`groups[i]` is photo i's: a lamp's photos share one,
/// so a lamp never informs its own prediction; ties go to fewer components and the stronger
/// penalty), then refitted on every photo. The constant is not penalised. Beside the model,
/// each photo's residual ln(1 − GFC) minus its prediction without its own group, in order.
pub fn fit_gfc_model(
    judged: &[Judged],
    groups: &[usize],
    kinds: &[PhotoKind],
) -> Result<(GfcModel, Vec<f64>)> {
    let n = judged.len();
    if groups.len() != n || kinds.len() != n {
        return Err(EvalError::invalid(format!(
            "{} photos but {} cross-validation groups and {} kinds",
            n,
            groups.len(),
            kinds.len()
        )));
    }
    let d = judged
        .first()
        .ok_or_else(|| EvalError::invalid("no calibration photos"))?
        .spd
        .len();
    let most = *GFC_COMPONENTS.iter().max().unwrap_or(&0);
    let estimates: Vec<f64> = judged.iter().flat_map(|j| j.spd.iter().copied()).collect();
    let pca = Pca::fit(&estimates, d, Components::Count(most.min(d).min(n - 1)))?;
    let target: Vec<Vec<f64>> = judged
        .iter()
        .map(|j| vec![(1.0 - gfc(j)).max(GFC_GAP_FLOOR).ln()])
        .collect();
    let with = |k: usize| GfcModel {
        mean: pca.mean.clone(),
        components: pca.components[..k.min(pca.len())].to_vec(),
        weights: Vec::new(),
        low: Vec::new(),
        high: Vec::new(),
        gap_range: [0.0; 2],
        gap_margin95: 0.0,
        gap_quantiles95: BTreeMap::new(),
    };
    let inputs = |m: &GfcModel| -> Vec<Vec<f64>> {
        judged
            .iter()
            .map(|j| m.inputs(&j.spd, difficulty(j)))
            .collect()
    };
    // Per input, the penalty's unit: its centred sum of squares, at least a millionth per
    // row so that an input without variance is shrunk to nothing (0 for the constant).
    let unit = |x: &[Vec<f64>], rows: &[usize]| -> Vec<f64> {
        let p = x[0].len();
        (0..p)
            .map(|c| {
                if c == p - 1 {
                    return 0.0;
                }
                let mean = rows.iter().map(|&i| x[i][c]).sum::<f64>() / rows.len() as f64;
                rows.iter()
                    .map(|&i| (x[i][c] - mean).powi(2))
                    .sum::<f64>()
                    .max(1e-6 * rows.len() as f64)
            })
            .collect()
    };
    // The Gram matrices of `rows` and their penalty units, solved for any penalty.
    let gram = |x: &[Vec<f64>], rows: &[usize]| -> Result<(Gram, Vec<f64>)> {
        let xs: Vec<&[f64]> = rows.iter().map(|&i| x[i].as_slice()).collect();
        let ys: Vec<&[f64]> = rows.iter().map(|&i| target[i].as_slice()).collect();
        Ok((Gram::from_rows(&xs, &ys)?, unit(x, rows)))
    };
    let solve = |(gram, unit): &(Gram, Vec<f64>), penalty: f64| -> Result<Ridge> {
        let diagonal: Vec<f64> = unit.iter().map(|u| penalty * u).collect();
        Ok(gram.solve(&diagonal, None)?)
    };
    let folds: Vec<(Vec<usize>, Vec<usize>)> = (0..GFC_FOLDS)
        .map(|f| (0..n).partition(|&i| groups[i] % GFC_FOLDS == f))
        .filter(|(test, train): &(Vec<usize>, Vec<usize>)| !test.is_empty() && !train.is_empty())
        .collect();
    let mut best: Option<(f64, usize, f64)> = None;
    for &k in GFC_COMPONENTS.iter().filter(|&&k| k <= pca.len()) {
        let x = inputs(&with(k));
        let mut sse = [0.0; GFC_PENALTIES.len()];
        for (test, train) in &folds {
            let fitted = gram(&x, train)?;
            for (total, &penalty) in sse.iter_mut().zip(&GFC_PENALTIES) {
                let ridge = solve(&fitted, penalty)?;
                *total += test
                    .iter()
                    .map(|&i| (ridge.predict(&x[i])[0] - target[i][0]).powi(2))
                    .sum::<f64>();
            }
        }
        // The strongest penalty first, so that a tie keeps it.
        for (&total, &penalty) in sse.iter().zip(&GFC_PENALTIES).rev() {
            if best.is_none_or(|b| total < b.0) {
                best = Some((total, k, penalty));
            }
        }
    }
    let (_, k, penalty) =
        best.ok_or_else(|| EvalError::invalid("no expected-GFC regression could be fitted"))?;
    let mut model = with(k);
    let x = inputs(&model);
    // Each photo's residual predicted without its own group, with the chosen settings.
    let mut held_out = vec![0.0; n];
    for (test, train) in &folds {
        let ridge = solve(&gram(&x, train)?, penalty)?;
        for &i in test {
            held_out[i] = target[i][0] - ridge.predict(&x[i])[0];
        }
    }
    let residuals: Vec<(f64, PhotoKind)> = held_out
        .iter()
        .copied()
        .zip(kinds.iter().copied())
        .collect();
    model.gap_quantiles95 = group_quantiles(&residuals, 0.95, MIN_METRIC_PHOTOS);
    model.gap_margin95 = model.gap_quantiles95.values().copied().fold(0.0, f64::max);
    let ridge = solve(&gram(&x, &(0..n).collect::<Vec<_>>())?, penalty)?;
    model.weights = (0..ridge.inputs()).map(|j| ridge.weight(0, j)).collect();
    let range = |values: &mut dyn Iterator<Item = f64>| {
        values.fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], v| {
            [lo.min(v), hi.max(v)]
        })
    };
    let input_ranges: Vec<[f64; 2]> = (0..model.weights.len())
        .map(|c| range(&mut x.iter().map(|row| row[c])))
        .collect();
    model.low = input_ranges.iter().map(|r| r[0]).collect();
    model.high = input_ranges.iter().map(|r| r[1]).collect();
    model.gap_range = range(&mut target.iter().map(|t| t[0]));
    Ok((model, held_out))
}

/// One model's fitted calibration.
pub struct Calibrated {
    /// The model's file.
    pub model: PathBuf,
    /// The chart it reads (the calibration's file is `<chart>.trust.json`).
    pub chart: String,
    /// The calibration.
    pub calibration: TrustCalibration,
    /// The photos it was fitted on, one record each.
    pub records: Vec<CalibrationRecord>,
}

/// The calibrations [`calibrate`] fitted, and the held-out cameras it left out.
pub struct Calibrations {
    /// Each model's calibration, in the order of the models.
    pub models: Vec<Calibrated>,
    /// The split's held-out cameras left out (unreadable curves), for the caller to report.
    pub skipped: Vec<SkippedCamera>,
}

/// Fits the calibration of each of `photos`' models on the split's validation lamps: their
/// held-out virtual photos, `scenes` scene photos of each ([`scene_rows`]) and, with `real`,
/// the real photo sets' validation photos (SG models only; `thesis_data` holds the sets,
/// default the data directory's thesis/).
pub fn calibrate(
    photos: &HeldOutPhotos,
    scenes: usize,
    real: bool,
    thesis_data: Option<&Path>,
    data_dir: &DataDir,
) -> Result<Calibrations> {
    let setup = photos.setup(data_dir)?;
    let lamps = setup
        .library
        .positions(setup.split.lamps(LampPart::Validation), "the split's lamps")?;
    let mut out = Vec::new();
    for (path, model, chart_name) in photos.models()? {
        let chart = Chart::resolve(&chart_name, None, data_dir, &GRID)?;
        model.check_features(&chart.feature_names(), &chart_name)?;
        let check = ChartCheck::for_model(&model, data_dir)?;
        let shots = photos.shots(&setup, &chart, &model, LampPart::Validation)?;
        let mut judged = judge_rows(
            &model,
            check.as_ref(),
            &shots.clean.features,
            Some(&shots.clean.truths),
        )?;
        let virtual_count = judged.len();
        let per_lamp = photos.shots as usize;
        let mut groups: Vec<usize> = (0..virtual_count).map(|i| i / per_lamp.max(1)).collect();
        let light_of = |lamp: usize| -> String {
            lamps
                .get(lamp)
                .and_then(|&l| setup.library.types.get(l))
                .map_or("other", |t| t.label())
                .to_string()
        };
        let mut sources: Vec<(String, String)> = groups
            .iter()
            .map(|&g| ("virtual".to_string(), light_of(g)))
            .collect();
        let mut features = shots.clean.features;
        let mut method = format!(
            "the split's {} validation lamps, {} photos each by its held-out cameras with the \
             randomised in-camera stage, patch level, seed {}; spread of {JITTER_COPIES} copies \
             perturbed by {JITTER_SIGMA}",
            lamps.len(),
            photos.shots,
            photos.seed
        );
        let scene_count = if scenes > 0 {
            let found = scene_rows(
                &model,
                &chart_name,
                &setup,
                LampPart::Validation,
                scenes,
                data_dir,
                photos.seed,
            )?;
            let truth = on_grid(&setup.library, &model.grid())?;
            let (lamp_of, rows): (Vec<usize>, Vec<Vec<f64>>) = found.rows.into_iter().unzip();
            let truths: Vec<Vec<f64>> = lamp_of.iter().map(|&l| truth[lamps[l]].clone()).collect();
            judged.extend(judge_rows(&model, check.as_ref(), &rows, Some(&truths))?);
            sources.extend(lamp_of.iter().map(|&l| ("scene".to_string(), light_of(l))));
            groups.extend(lamp_of);
            features.extend(rows);
            method += &format!(
                "; {scenes} scene photos of each (the whole camera chain, found and sampled as a \
                 user's photo is; {} of them refused: no chart found)",
                found.refused
            );
            judged.len() - virtual_count
        } else {
            0
        };
        let real = if real {
            real_split(thesis_data, data_dir, &model, &chart_name)?
        } else {
            Vec::new()
        };
        let real = balanced(real, virtual_count);
        for set in &real {
            judged.extend(judge_rows(
                &model,
                check.as_ref(),
                &set.val.features,
                Some(&set.val.truths),
            )?);
            features.extend(set.val.features.iter().cloned());
            sources.extend(
                (0..set.val.features.len())
                    .map(|_| (set.label.to_string(), "measured".to_string())),
            );
        }
        let real_count = judged.len() - virtual_count - scene_count;
        groups.extend((0..real_count).map(|i| lamps.len() + i));
        if !real.is_empty() {
            method += &format!(
                "; and {real_count} real photos, the validation photos of {}",
                real.iter().map(|s| s.label).collect::<Vec<_>>().join(", ")
            );
        }
        let kinds = [
            (PhotoKind::Virtual, virtual_count),
            (PhotoKind::Scene, scene_count),
            (PhotoKind::Real, real_count),
        ]
        .into_iter()
        .flat_map(|(kind, n)| std::iter::repeat_n(kind, n))
        .collect();
        let calibration_photos = CalibrationPhotos {
            clipped: features
                .iter()
                .map(|row| trust::clipped_patches(row))
                .collect(),
            judged,
            kinds,
            scenes_per_lamp: scenes,
            groups,
            sources,
        };
        let (calibration, records) =
            fit_calibration(&model, &chart_name, &calibration_photos, method)?;
        out.push(Calibrated {
            model: path,
            chart: chart_name,
            calibration,
            records,
        });
    }
    Ok(Calibrations {
        models: out,
        skipped: setup.skipped,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trust::judged::fixtures::judged;

    #[test]
    fn intervals_are_scaled_to_hold_on_the_hardest_kind_of_photo() {
        // 200 patch-level ratios spread evenly over (0, 1], 100 scene ratios over (0, 3].
        let mut values: Vec<(f64, PhotoKind)> = (1..=200)
            .map(|i| (f64::from(i) / 200.0, PhotoKind::Virtual))
            .collect();
        values.extend((1..=100).map(|i| (3.0 * f64::from(i) / 100.0, PhotoKind::Scene)));
        // The scenes' own 95 % quantile: the ⌈101 · 0.95⌉ = 96th of 100, 2.88; pooled it
        // would be the 286th of 300, 2.58.
        let q = group_conditional_quantile(&values, 0.95, 40);
        assert!((q - 2.88).abs() < 1e-9, "{q}");
        // Each kind's own quantile is kept (the patch-level photos' the 191st of 200), with
        // the pool's: the calibration file says which kind set the margin.
        let each = group_quantiles(&values, 0.95, 40);
        let keys: Vec<&str> = each.keys().map(String::as_str).collect();
        assert_eq!(keys, ["pooled", "scene", "virtual"]);
        for (key, want) in [("virtual", 0.955), ("scene", 2.88), ("pooled", 2.58)] {
            assert!((each[key] - want).abs() < 1e-9, "{key}: {}", each[key]);
        }
        let mut pooled: Vec<f64> = values.iter().map(|v| v.0).collect();
        assert!((conformal_quantile(&mut pooled, 0.95) - 2.58).abs() < 1e-9);
        // Too few scene photos (30) to stand on their own: the patch-level photos' quantile
        // (the 191st of 200, 0.955) and the pool's (the 220th of 230, 0.95) decide.
        let few: Vec<(f64, PhotoKind)> = values[..230].to_vec();
        let q = group_conditional_quantile(&few, 0.95, 40);
        assert!((q - 0.955).abs() < 1e-9, "{q}");
    }

    /// 200 calibration photos whose expected 1 − GFC runs from 0.001 to 0.1 and whose
    /// metric error is `error(expected gap, i)`, spread 0, widening 1.
    fn metric_photos(error: impl Fn(f64, usize) -> f64) -> Vec<MetricPhoto> {
        (0..200)
            .map(|i| {
                let expected_gap = 0.001 * 100f64.powf(i as f64 / 199.0);
                MetricPhoto {
                    error: error(expected_gap, i),
                    spread: 0.0,
                    value: 1000.0 + 50.0 * (i % 100) as f64,
                    expected_gap,
                    widening: 1.0,
                    kind: PhotoKind::Virtual,
                }
            })
            .collect()
    }

    #[test]
    fn a_metric_floor_follows_the_expected_gfc_where_the_errors_do() {
        // Errors proportional to the expected 1 − GFC, times a factor cycling over 0.1–1:
        // the floor grows with the gap (power 1) and the intervals are narrower than one
        // floor for every photo would make them, while they still hold.
        let cycle = |i: usize| 0.1 + 0.9 * ((i * 37) % 100) as f64 / 99.0;
        let photos = metric_photos(|gap, i| 50.0 * gap * cycle(i));
        let m = fit_metric("cri_ra", &photos).expect("enough photos");
        assert_eq!(m.gap_power, 1.0);
        let mut gaps: Vec<f64> = photos.iter().map(|p| p.expected_gap).collect();
        assert!((m.gap_reference - median(&mut gaps)).abs() < 1e-15);
        let held = photos
            .iter()
            .filter(|p| p.error <= m.scale95 * m.unit(p.spread, p.expected_gap, p.widening))
            .count();
        assert!(held >= 190, "{held} of 200 inside the 95 % interval");
        // The easiest photo's interval is far narrower than the hardest's.
        let first = m.unit(0.0, photos[0].expected_gap, 1.0);
        let last = m.unit(0.0, photos[199].expected_gap, 1.0);
        assert!((last / first - 100.0).abs() < 1e-6, "{first} {last}");
        // Errors unrelated to the gap keep one floor.
        let flat = fit_metric("cri_ra", &metric_photos(|_, i| cycle(i))).unwrap();
        assert_eq!(flat.gap_power, 0.0);
        assert_eq!(flat.gap_factor(0.5), 1.0);
        // Too few photos: no interval.
        assert!(fit_metric("cri_ra", &photos[..MIN_METRIC_PHOTOS - 1]).is_none());
    }

    #[test]
    fn the_expected_gfc_regression_learns_how_the_gfc_falls_with_difficulty() {
        // 1 − GFC = 0.2 · difficulty: ln(1 − GFC) = ln 0.2 + ln(difficulty); the shapes vary
        // a little, unrelated to the GFC. 20 lamps of 4 photos.
        let rows: Vec<Judged> = (0..80)
            .map(|i| {
                let difficulty = 0.01 * (1.0 + (i * 7 % 10) as f64);
                let spd = [1.0, 0.5 + 0.02 * (i % 5) as f64, 0.6, 0.4, 0.3];
                judged(&spd, 1.0 - 0.2 * difficulty, difficulty)
            })
            .collect();
        for r in &rows {
            let want = 1.0 - 0.2 * difficulty(r);
            assert!((gfc(r) - want).abs() < 1e-9, "{} {want}", gfc(r));
        }
        let groups: Vec<usize> = (0..rows.len()).map(|i| i / 4).collect();
        let (model, _) = fit_gfc_model(&rows, &groups, &[PhotoKind::Virtual; 80]).unwrap();
        // An exact law leaves no residual: the 95 % floor is the median.
        assert!(model.gap_margin95.abs() < 0.05, "{}", model.gap_margin95);
        for r in &rows {
            let gap = 1.0 - model.expected(&r.spd, difficulty(r));
            let want = 0.2 * difficulty(r);
            assert!(
                (gap / want - 1.0).abs() < 0.05,
                "expected 1 − GFC {gap}, true {want}"
            );
        }
    }
}
