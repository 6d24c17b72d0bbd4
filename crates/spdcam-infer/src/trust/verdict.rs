//! The verdict: what the photo analysis found (detection, clipped and dark patches), the
//! self-check and the calibrated uncertainty weighed into ok, doubtful or unusable, with the
//! reasons.

use super::calibration::{TrustCalibration, Uncertainty};
use super::self_check::{ChartCheck, SelfCheck, MIN_CHECK_PATCHES};
use super::spread::{clipped_patch, feature_scale, Perturbed};
use crate::error::Result;
use crate::model::Model;
use serde::Serialize;
use spdcam_core::advice::Advice;
use spdcam_core::chart::{feature_patch_name, shown_chart_name, KnownChart};
use spdcam_core::photo::{PatchSample, PhotoAnalysis};

/// Estimates above this detection confidence are placed surely; the photo analysis warns
/// below the same level.
pub const SURE_DETECTION: f64 = 0.8;
/// Self-check residuals this many times the calibration's doubtful level make an estimate
/// unusable: the light found does not explain the photo.
pub const UNUSABLE_SELF_CHECK_FACTOR: f64 = 3.0;
/// Below this expected GFC an estimate is doubtful (GFC 0.95 is the thesis's "acceptable"
/// level of spectral match; Hernández-Andrés et al. 2001, JOSA A 18: 412–420).
pub const DOUBTFUL_GFC: f64 = 0.95;
/// Below this GFC an estimate's shape is a poor match: an estimate is `ok` only where 95 %
/// of the calibration's estimates like it reach it ([`Uncertainty::gfc_at_least95`]), so
/// that a photo called `ok` is not a poor one.
pub const POOR_GFC: f64 = 0.90;
/// A share of clipped feature patches above this makes an estimate unusable: half the
/// chart says only that it is brighter than the camera records.
pub const UNUSABLE_CLIPPED_SHARE: f64 = 0.5;

/// The number of clipped patches of a feature row (see [`clipped_patch`]).
pub fn clipped_patches(row: &[f64]) -> usize {
    clipped_features(row, &PhotoFlags::default()).len()
}

/// The feature patches of `row` the verdict counts as clipped: those the photo analysis
/// flags (`flags`; on a raw file, clipped photosites left out of the patch) and those with
/// a channel at the top of the scale ([`clipped_patch`]).
pub fn clipped_features(row: &[f64], flags: &PhotoFlags) -> Vec<usize> {
    let scale = feature_scale(row);
    (0..row.len() / 3)
        .filter(|&i| {
            flags.clipped.get(i).copied().unwrap_or(false)
                || clipped_patch(&row[3 * i..3 * i + 3], scale)
        })
        .collect()
}

/// Patches to leave out of the self-check when no photo analysis flags them: a channel at
/// the top of the scale (clipped) or every channel below 2 % of it (dark).
pub fn flag_patches(row: &[f64], scale: f64) -> Vec<bool> {
    row.chunks_exact(3)
        .map(|p| clipped_patch(p, scale) || p.iter().all(|&v| v < 0.02 * scale))
        .collect()
}

/// The patches of `row` (on `0…scale`) every check leaves out: those [`flag_patches`] flags
/// and those the photo analysis found clipped or dark (`flags`).
pub fn skipped_patches(row: &[f64], scale: f64, flags: &PhotoFlags) -> Vec<bool> {
    let mut skip = flag_patches(row, scale);
    for (i, s) in skip.iter_mut().enumerate() {
        *s |= flags.clipped.get(i).copied().unwrap_or(false)
            || flags.dark.get(i).copied().unwrap_or(false);
    }
    skip
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
    /// Whether the chart's corners were placed by hand.
    pub placed: bool,
}

/// Judges one estimate: `row` the features, `spd` the model's estimate on its own grid
/// (peak-normalised), `flags` what the photo analysis found. The thresholds are constants
/// of this module and levels of the calibration, chosen before any result was seen
/// (docs/trust.md).
pub fn assess(
    model: &Model,
    calibration: Option<&TrustCalibration>,
    check: Option<&ChartCheck>,
    row: &[f64],
    spd: &[f64],
    flags: &PhotoFlags,
) -> Result<Trust> {
    Ok(weigh(model, calibration, check, row, spd, flags)?.into())
}

/// The model an estimate's spectrum was read by and the feature row it read: its answers
/// to perturbed copies of that row give the estimate's difficulty and spread. For a photo's
/// colours that is the photo's own row; for a raw photo read by a raw model, the patches'
/// XYZ through the file's matrices.
#[derive(Debug, Clone, Copy)]
pub struct ReadBy<'a> {
    /// The model (its calibration is the one the estimate is judged by).
    pub model: &'a Model,
    /// The row it read.
    pub row: &'a [f64],
}

impl From<Weighed> for Trust {
    /// The trust of what [`weigh`] found, its reasons in words.
    fn from((verdict, advice, self_check, uncertainty): Weighed) -> Trust {
        Trust {
            verdict,
            reasons: advice.iter().map(Advice::to_string).collect(),
            self_check,
            uncertainty,
        }
    }
}

/// What [`weigh`] finds: the verdict, the advice behind it, the self-check and the bands.
pub type Weighed = (Verdict, Vec<Advice>, Option<SelfCheck>, Option<Uncertainty>);

/// [`assess`] with its reasons as [`Advice`] (their words are the advice's): what a
/// measurement of the verdict counts by kind.
pub fn weigh(
    model: &Model,
    calibration: Option<&TrustCalibration>,
    check: Option<&ChartCheck>,
    row: &[f64],
    spd: &[f64],
    flags: &PhotoFlags,
) -> Result<Weighed> {
    weigh_read_by(ReadBy { model, row }, calibration, check, row, spd, flags)
}

/// [`weigh`] of a spectrum read by `read_by`, the photo's own colours `row` checked
/// (clipping, dark patches, the self-check): how a raw photo read by a raw model is judged,
/// by that model's calibration.
pub fn weigh_read_by(
    read_by: ReadBy<'_>,
    calibration: Option<&TrustCalibration>,
    check: Option<&ChartCheck>,
    row: &[f64],
    spd: &[f64],
    flags: &PhotoFlags,
) -> Result<Weighed> {
    let model = read_by.model;
    let mut verdict = Verdict::Ok;
    let mut reasons = Vec::new();
    let mut lower = |v: Verdict, reason: Advice, reasons: &mut Vec<Advice>| {
        if v as u8 > verdict as u8 {
            verdict = v;
        }
        reasons.push(reason);
    };
    let chart = model.header().chart.as_deref().unwrap_or("");
    let names = |patches: &[usize]| -> Vec<String> {
        patches
            .iter()
            .map(|&k| feature_patch_name(chart, k))
            .collect()
    };
    if let Some(c) = flags.confidence.filter(|&c| c < SURE_DETECTION) {
        lower(
            Verdict::Doubtful,
            Advice::LowConfidence {
                confidence: c,
                placed: flags.placed,
            },
            &mut reasons,
        );
    }
    let scale = feature_scale(row);
    let patches = row.len() / 3;
    let skip = skipped_patches(row, scale, flags);
    let clipped = clipped_features(row, flags);
    let clipped_doubtful = calibration.map_or(0, |c| c.clipped_doubtful);
    let clipped_advice = |most: Option<usize>| Advice::Clipped {
        count: clipped.len(),
        of: patches,
        names: names(&clipped),
        calibration_most: most,
    };
    if clipped.len() as f64 > UNUSABLE_CLIPPED_SHARE * patches as f64 {
        lower(Verdict::Unusable, clipped_advice(None), &mut reasons);
    } else if clipped.len() > clipped_doubtful {
        lower(
            Verdict::Doubtful,
            clipped_advice(Some(clipped_doubtful)),
            &mut reasons,
        );
    }
    let dark: Vec<usize> = (0..patches)
        .filter(|&i| {
            flags.dark.get(i).copied().unwrap_or(false)
                || row[3 * i..3 * i + 3].iter().all(|&v| v < 0.02 * scale)
        })
        .collect();
    // Any nearly black patch: the photo analysis warns of it ("expose more"), and a verdict
    // of `ok` beside that warning would contradict it.
    if !dark.is_empty() {
        lower(
            Verdict::Doubtful,
            Advice::Dark {
                count: dark.len(),
                of: patches,
                names: names(&dark),
            },
            &mut reasons,
        );
    }
    let self_check = match check {
        Some(c) => match c.check(spd, row, scale, &skip) {
            Ok(s) => Some(s),
            Err(e) => {
                let usable = skip.iter().filter(|s| !**s).count();
                let advice = if usable < MIN_CHECK_PATCHES {
                    Advice::TooFewToCheck {
                        usable,
                        needed: MIN_CHECK_PATCHES,
                    }
                } else {
                    Advice::CheckFailed { why: e.to_string() }
                };
                lower(Verdict::Unusable, advice, &mut reasons);
                None
            }
        },
        None => {
            reasons.push(no_check(chart));
            None
        }
    };
    let uncertainty = match calibration {
        Some(cal) => {
            let perturbed = Perturbed::of(model, read_by.row)?;
            Some(cal.uncertainty(
                spd,
                &perturbed.spread(),
                &perturbed.metric_spread(&model.grid().wavelengths()),
                self_check.as_ref(),
            )?)
        }
        None => {
            reasons.push(Advice::NoCalibration);
            None
        }
    };
    // Doubtful above a level, unusable above UNUSABLE_SELF_CHECK_FACTOR times it.
    let graded = |value: f64, level: f64| {
        if value > UNUSABLE_SELF_CHECK_FACTOR * level {
            Verdict::Unusable
        } else {
            Verdict::Doubtful
        }
    };
    if let (Some(s), Some(level)) = (&self_check, calibration.and_then(|c| c.self_check_doubtful)) {
        if s.mean > level {
            let worst: Vec<usize> = s.worst_patches.iter().map(|p| p - 1).collect();
            lower(
                graded(s.mean, level),
                Advice::Residual {
                    residual: s.mean,
                    level,
                    worst: names(&worst),
                },
                &mut reasons,
            );
        }
    }
    if let (Some(s), Some(level)) = (&self_check, calibration.and_then(|c| c.split_doubtful)) {
        if s.split > level {
            lower(
                graded(s.split, level),
                Advice::Halves {
                    split: s.split,
                    level,
                },
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
                Advice::ColourGradient { gradient: g, level },
                &mut reasons,
            );
        }
    }
    if let (Some(s), Some(level)) = (&self_check, calibration.and_then(|c| c.two_lights_doubtful)) {
        if s.two_lights > level {
            lower(
                Verdict::Doubtful,
                Advice::TwoLights {
                    ratio: s.two_lights,
                    level,
                },
                &mut reasons,
            );
        }
    }
    if let (Some(s), Some(level)) = (&self_check, calibration.and_then(|c| c.glare_doubtful)) {
        if s.glare > level {
            lower(
                Verdict::Doubtful,
                Advice::Glare {
                    share: s.glare,
                    level,
                },
                &mut reasons,
            );
        }
    }
    if let (Some(u), Some(cal)) = (&uncertainty, calibration) {
        if u.difficulty > cal.difficulty_doubtful {
            lower(Verdict::Doubtful, Advice::Ambiguous, &mut reasons);
        }
        if u.expected_gfc < DOUBTFUL_GFC {
            lower(
                Verdict::Doubtful,
                Advice::LowGfc {
                    expected: u.expected_gfc,
                    level: DOUBTFUL_GFC,
                },
                &mut reasons,
            );
        } else if u.gfc_at_least95 < POOR_GFC {
            lower(
                Verdict::Doubtful,
                Advice::MayBePoor {
                    at_least: u.gfc_at_least95,
                    level: POOR_GFC,
                },
                &mut reasons,
            );
        }
    }
    Ok((verdict, reasons, self_check, uncertainty))
}

/// Why the chart called `chart` has no self-check: its reflectances are measured data
/// spdcam was started without, or they are not known.
fn no_check(chart: &str) -> Advice {
    match KnownChart::from_name(chart) {
        Some(known) if known.needs_data_dir() => Advice::NoChartData {
            chart: known.shown_name().into(),
            file: known.data_file().unwrap_or_default(),
        },
        _ => Advice::UnknownChart {
            chart: shown_chart_name(chart),
        },
    }
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
        placed: analysis.method == "corners",
    }
}

#[cfg(test)]
mod tests {
    use super::super::self_check::tests::{cc24_check, features_of};
    use super::*;
    use crate::error::InferError;
    use crate::estimator::Estimator;
    use crate::feature_rows::FeatureRows;
    use crate::shipped::ModelSet;
    use spdcam_core::builtin::DataDir;
    use spdcam_core::chart::Chart;
    use spdcam_core::cie_illuminant::StandardIlluminant;
    use spdcam_core::colorimetry::{srgb_decode, srgb_encode};

    /// The shipped models and the ColorChecker 24's self-check on their model's grid.
    fn cc24_setup() -> (ModelSet, ChartCheck) {
        let models = ModelSet::shipped().unwrap();
        let grid = models
            .for_known(KnownChart::ColorChecker24)
            .unwrap()
            .model
            .grid();
        (models, cc24_check(&grid))
    }

    #[test]
    fn a_wrong_charts_features_are_not_ok_and_bands_hold_the_estimate() {
        let (models, check) = cc24_setup();
        let model = &models.for_known(KnownChart::ColorChecker24).unwrap().model;
        let grid = model.grid();
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
        let estimator = Estimator::new(models.clone(), DataDir::new(None), grid).unwrap();
        // The chart's colours in reverse order are no ColorChecker 24: the row is refused
        // before any number is made of it.
        let refused = estimator.estimate_rows(&rows, "test").unwrap_err();
        assert!(matches!(refused, InferError::NotTheChart(_)), "{refused}");
        assert!(refused
            .to_string()
            .starts_with("test row 2 does not hold a ColorChecker 24"));
        // Judged all the same (as a row that passed the test would be), the light found
        // does not explain it.
        let spd = model.estimate(&wrong).unwrap();
        let calibration = crate::trust::calibration_for(model).unwrap();
        let t = assess(
            model,
            calibration.as_ref(),
            Some(&check),
            &wrong,
            &spd,
            &PhotoFlags::default(),
        )
        .unwrap();
        assert_ne!(t.verdict, Verdict::Ok, "{:?}", t.reasons);
        assert!(t.self_check.as_ref().unwrap().mean > 0.2);

        let rows = FeatureRows::from_values(model.feature_names().to_vec(), row, "test").unwrap();
        let estimates = estimator.estimate_rows(&rows, "test").unwrap();
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

    /// Whether `text` names no command-line option, patch index, feature column, debug
    /// image, file layout or module path.
    fn plain(text: &str) -> bool {
        let b = text.as_bytes();
        let patch_index = (0..b.len().saturating_sub(2))
            .any(|i| b[i] == b'p' && b[i + 1].is_ascii_digit() && b[i + 2].is_ascii_digit());
        !patch_index
            && ["--", "feature", "debug image", "data directory holds", "::"]
                .iter()
                .all(|w| !text.contains(w))
    }

    #[test]
    fn every_reason_says_what_went_wrong_and_what_to_do_in_plain_words() {
        let models = ModelSet::shipped().unwrap();
        let cc24 = &models.for_known(KnownChart::ColorChecker24).unwrap().model;
        let sg = &models.for_known(KnownChart::Sg96).unwrap().model;
        let check = cc24_check(&cc24.grid());
        // A calibration whose every level is crossed by any estimate.
        let mut strict = crate::trust::calibration_for(cc24).unwrap().unwrap();
        strict.self_check_doubtful = Some(0.0);
        strict.split_doubtful = Some(0.0);
        strict.colour_gradient_doubtful = Some(0.0);
        strict.two_lights_doubtful = Some(0.0);
        strict.glare_doubtful = Some(0.0);
        strict.difficulty_doubtful = 0.0;
        strict.clipped_doubtful = 0;
        strict.gfc_model.gap_range = [0.1f64.ln(); 2];
        // A calibration whose median is good (0.96) and whose 95 % floor is poor (0.80).
        let mut loose = crate::trust::calibration_for(cc24).unwrap().unwrap();
        loose.gfc_model.gap_range = [0.04f64.ln(); 2];
        loose.gfc_model.gap_margin95 = 5.0f64.ln();
        let row = features_of(&check, &StandardIlluminant::D65.spd(&cc24.grid()).unwrap());
        let spd = cc24.estimate(&row).unwrap();
        let n = check.patches();
        let some = |k: usize| (0..n).map(|i| i < k).collect::<Vec<bool>>();
        let flags = |confidence: f64, placed: bool, clipped: usize, dark: usize| PhotoFlags {
            confidence: Some(confidence),
            clipped: some(clipped),
            dark: (0..n).map(|i| i >= n - dark).collect(),
            placed,
        };
        // The left half under daylight, the right under a bulb: two lights, halves apart.
        let bulb = features_of(&check, &StandardIlluminant::A.spd(&cc24.grid()).unwrap());
        let centres = Chart::colorchecker24(&cc24.grid())
            .unwrap()
            .feature_centres();
        let two: Vec<f64> = (0..n)
            .flat_map(|p| {
                let from = if centres[p][0] >= 0.0 { &bulb } else { &row };
                from[3 * p..3 * p + 3].to_vec()
            })
            .collect();
        let two_spd = cc24.estimate(&two).unwrap();
        let sg_row: Vec<f64> = (0..288).map(|i| 30.0 + ((i * 37) % 200) as f64).collect();
        let sg_spd = sg.estimate(&sg_row).unwrap();
        // What the verdict weighs: model, calibration, check, row, SPD and photo flags.
        type Case<'a> = (
            &'a Model,
            Option<&'a TrustCalibration>,
            Option<&'a ChartCheck>,
            &'a [f64],
            Vec<f64>,
            PhotoFlags,
        );
        let cases: Vec<Case> = vec![
            // Every level crossed, a patch clipped, many dark, a doubtful detection.
            (
                cc24,
                Some(&strict),
                Some(&check),
                &row,
                spd.clone(),
                flags(0.6, false, 1, 8),
            ),
            // Corners placed with a low confidence; most patches clipped: too few to check.
            (
                cc24,
                Some(&strict),
                Some(&check),
                &row,
                spd.clone(),
                flags(0.6, true, 20, 0),
            ),
            // Two lights.
            (
                cc24,
                Some(&strict),
                Some(&check),
                &two,
                two_spd,
                PhotoFlags::default(),
            ),
            // A black light: the check fails; no calibration.
            (
                cc24,
                None,
                Some(&check),
                &row,
                vec![0.0; spd.len()],
                PhotoFlags::default(),
            ),
            // An estimate good in the median that may well be poor.
            (
                cc24,
                Some(&loose),
                Some(&check),
                &row,
                spd.clone(),
                PhotoFlags::default(),
            ),
            // The SG without the measured data: no check.
            (sg, None, None, &sg_row, sg_spd, PhotoFlags::default()),
        ];
        let mut advice: Vec<Advice> = Vec::new();
        for (model, calibration, check, row, spd, flags) in cases {
            advice.extend(
                weigh(model, calibration, check, row, &spd, &flags)
                    .unwrap()
                    .1,
            );
        }
        advice.push(no_check("my_chart.csv"));
        let mut kinds: Vec<&str> = advice.iter().map(Advice::kind).collect();
        kinds.sort_unstable();
        kinds.dedup();
        let every = [
            "ambiguous",
            "check_failed",
            "clipped",
            "colour_gradient",
            "dark",
            "glare",
            "halves",
            "low_confidence",
            "low_gfc",
            "may_be_poor",
            "no_calibration",
            "no_chart_data",
            "residual",
            "too_few_to_check",
            "two_lights",
            "unknown_chart",
        ];
        assert_eq!(kinds, every, "reasons the verdict can give, driven");
        for a in &advice {
            let text = a.to_string();
            assert!(plain(&text), "{text}");
        }
        // Patches by the names the chart prints; the placed corners and the data said so.
        let all: Vec<String> = advice.iter().map(Advice::to_string).collect();
        let said = |w: &str| all.iter().any(|t| t.contains(w));
        assert!(said("(dark skin)") && said("(magenta, cyan"), "{all:?}");
        assert!(said("place them again") && said("place the corners by hand"));
        assert!(said("not shipped with spdcam"));
        let sg_file = KnownChart::Sg96.data_file().unwrap();
        assert!(
            said(&sg_file) && said("photograph a ColorChecker 24"),
            "{all:?}"
        );
        assert!(!plain("worst at p07") && !plain("use --data-dir") && !plain("features 1, 2"));
    }

    #[test]
    fn a_chart_lit_by_two_lights_each_half_balanced_says_so() {
        let (models, check) = cc24_setup();
        let model = &models.for_known(KnownChart::ColorChecker24).unwrap().model;
        let grid = model.grid();
        let daylight = features_of(&check, &StandardIlluminant::D65.spd(&grid).unwrap());
        let bulb = features_of(&check, &StandardIlluminant::A.spd(&grid).unwrap());
        let centres = Chart::colorchecker24(&grid).unwrap().feature_centres();
        // Left half under daylight, right half under the bulb, each balanced to grey.
        let balance = |row: &[f64], p: usize| -> Vec<f64> {
            let white: Vec<f64> = row[3 * 18..3 * 18 + 3].to_vec();
            (0..3)
                .map(|c| {
                    let lin = srgb_decode(row[3 * p + c] / 255.0) / srgb_decode(white[c] / 255.0);
                    255.0 * srgb_encode((0.9 * lin).min(1.0))
                })
                .collect()
        };
        let two: Vec<f64> = (0..centres.len())
            .flat_map(|p| {
                balance(
                    if centres[p][0] >= 0.0 {
                        &bulb
                    } else {
                        &daylight
                    },
                    p,
                )
            })
            .collect();
        let one: Vec<f64> = (0..centres.len())
            .flat_map(|p| balance(&daylight, p))
            .collect();
        let rows =
            FeatureRows::from_values(model.feature_names().to_vec(), [one, two].concat(), "test")
                .unwrap();
        let estimator = Estimator::new(models.clone(), DataDir::new(None), grid).unwrap();
        let estimates = estimator.estimate_rows(&rows, "test").unwrap();
        let says = |k: usize| {
            let t = estimates[k].trust.as_ref().unwrap();
            t.reasons.iter().any(|r| r.contains("two different lights"))
        };
        assert!(
            !says(0),
            "{:?}",
            estimates[0].trust.as_ref().unwrap().reasons
        );
        assert!(
            says(1),
            "{:?}",
            estimates[1].trust.as_ref().unwrap().reasons
        );
    }
}
