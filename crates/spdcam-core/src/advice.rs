//! Every warning and reason a person reads about a photo or an estimate, in plain words: what
//! went wrong and what to do about it. The one place that owns these words, so that the
//! command line, the report, the web page and Python say the same.
//!
//! The words name no command-line option, no file or module and no column index: a patch is
//! named as the chart prints it ([`crate::chart::feature_patch_name`]), a chart as people
//! know it ([`crate::chart::shown_chart_name`]).

use crate::chart::KnownChart;
use std::fmt;

/// What a truncated JPEG is, for warnings and errors.
pub(crate) const TRUNCATED: &str =
    "the JPEG file is truncated (it ends before its end-of-image marker)";
/// What a corrupt JPEG is, for warnings and errors.
pub(crate) const CORRUPT: &str = "the JPEG data is corrupt (a damaged byte breaks its marker \
     segments, though the file is complete)";

/// At most this many patch names are listed; the rest are counted.
const NAMES_LISTED: usize = 4;

/// One warning or reason, with the numbers it states; [`fmt::Display`] gives its words.
#[derive(Debug, Clone, PartialEq)]
pub enum Advice {
    /// The chart was placed (found, or fitted to the corners given) with a low confidence.
    LowConfidence {
        /// The confidence, 0–1.
        confidence: f64,
        /// Whether the corners were placed by hand.
        placed: bool,
    },
    /// Patches with a clipped channel.
    Clipped {
        /// How many.
        count: usize,
        /// Of how many.
        of: usize,
        /// Their names, when known.
        names: Vec<String>,
        /// The most the calibration photos had, when the verdict compares with them.
        calibration_most: Option<usize>,
    },
    /// Patches nearly black in every channel.
    Dark {
        /// How many.
        count: usize,
        /// Of how many.
        of: usize,
        /// Their names, when known.
        names: Vec<String>,
    },
    /// The JPEG file ends before its end-of-image marker.
    TruncatedJpeg,
    /// The JPEG's marker segments are damaged though the file is complete.
    CorruptJpeg,
    /// Too few patches are usable (neither clipped nor nearly black) to check the estimate
    /// against the chart.
    TooFewToCheck {
        /// Usable patches.
        usable: usize,
        /// Patches the check needs.
        needed: usize,
    },
    /// The estimate could not be checked against the chart for another reason.
    CheckFailed {
        /// Why, in plain words.
        why: String,
    },
    /// No check against the chart: its reflectances are measured data spdcam was started
    /// without.
    NoChartData {
        /// The chart as people know it.
        chart: String,
        /// The measured data's file of its reflectances (`charts/…csv`,
        /// [`crate::chart::KnownChart::data_file`]).
        file: String,
    },
    /// No check against the chart: spdcam does not know its reflectances.
    UnknownChart {
        /// The chart's name.
        chart: String,
    },
    /// The model has no calibration, so no bands.
    NoCalibration,
    /// The light found explains the patches worse than on clean photos.
    Residual {
        /// The residual.
        residual: f64,
        /// The level clean photos stay below.
        level: f64,
        /// The worst patches' names, worst first.
        worst: Vec<String>,
    },
    /// The chart's halves look lit differently.
    Halves {
        /// The half-to-half residual.
        split: f64,
        /// The level clean photos stay below.
        level: f64,
    },
    /// The light's colour changes across the chart.
    ColourGradient {
        /// The neutral patches' colour gradient.
        gradient: f64,
        /// The level clean photos stay below.
        level: f64,
    },
    /// Each half of the chart looks lit by a light of its own.
    TwoLights {
        /// How many times more of the patches a light of its own explains than noise would.
        ratio: f64,
        /// The level clean photos stay below.
        level: f64,
    },
    /// Light is added unevenly across the chart.
    Glare {
        /// The share of the residual an additive light changing across the chart explains.
        share: f64,
        /// The level clean photos stay below.
        level: f64,
    },
    /// Many lights give nearly this photo: the shape is uncertain.
    Ambiguous,
    /// The expected goodness of fit of the shape is good, but estimates like this one are
    /// often poor.
    MayBePoor {
        /// The GFC 95 % of such estimates reach at least.
        at_least: f64,
        /// The level below which a match is poor.
        level: f64,
    },
    /// The kind of light named does not fit the photo: the model's estimate lies farther
    /// from every light of the kind than nearly all photos of the kind do.
    UnlikeKind {
        /// The kind, as a noun ([`crate::light_families::LightKind::label`]).
        kind: String,
    },
    /// The expected goodness of fit of the shape is low.
    LowGfc {
        /// The expected GFC.
        expected: f64,
        /// The level below which it is low.
        level: f64,
    },
}

impl Advice {
    /// A short name of the kind of advice (`clipped`, `residual`), the same for every value
    /// of it: what a test that drives every kind counts.
    pub fn kind(&self) -> &'static str {
        match self {
            Advice::LowConfidence { .. } => "low_confidence",
            Advice::Clipped { .. } => "clipped",
            Advice::Dark { .. } => "dark",
            Advice::TruncatedJpeg => "truncated_jpeg",
            Advice::CorruptJpeg => "corrupt_jpeg",
            Advice::TooFewToCheck { .. } => "too_few_to_check",
            Advice::CheckFailed { .. } => "check_failed",
            Advice::NoChartData { .. } => "no_chart_data",
            Advice::UnknownChart { .. } => "unknown_chart",
            Advice::NoCalibration => "no_calibration",
            Advice::Residual { .. } => "residual",
            Advice::Halves { .. } => "halves",
            Advice::ColourGradient { .. } => "colour_gradient",
            Advice::TwoLights { .. } => "two_lights",
            Advice::Glare { .. } => "glare",
            Advice::Ambiguous => "ambiguous",
            Advice::LowGfc { .. } => "low_gfc",
            Advice::MayBePoor { .. } => "may_be_poor",
            Advice::UnlikeKind { .. } => "unlike_kind",
        }
    }
}

/// The charts checked with nothing beside the program (their reflectances built in), as
/// people know them: `ColorChecker 24`.
fn built_in_charts() -> String {
    let mut names: Vec<&str> = KnownChart::ALL
        .into_iter()
        .filter(|c| !c.needs_data_dir())
        .map(KnownChart::shown_name)
        .collect();
    names.dedup();
    names.join(" or a ")
}

impl fmt::Display for Advice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Advice::LowConfidence {
                confidence,
                placed: false,
            } => write!(
                f,
                "the chart was found with confidence {confidence:.2} only: check that its \
                 outline sits on the chart's four outer corners, and place the corners by \
                 hand if it does not"
            ),
            Advice::LowConfidence {
                confidence,
                placed: true,
            } => write!(
                f,
                "the corners placed fit the chart with confidence {confidence:.2} only: \
                 check that they sit on the chart's four outer corners, and place them \
                 again if they do not"
            ),
            Advice::Clipped {
                count,
                of,
                names,
                calibration_most,
            } => {
                write!(
                    f,
                    "{count} of {of} patches {} clipped{}",
                    are(*count),
                    listed(names)
                )?;
                if let Some(most) = calibration_most {
                    write!(f, " (at most {most} in the calibration photos)")?;
                }
                write!(
                    f,
                    ": the photo is overexposed there and the estimate biased; expose less \
                     (a shorter exposure or a lower ISO), or move the chart out of the glare"
                )
            }
            Advice::Dark { count, of, names } => write!(
                f,
                "{count} of {of} patches {} nearly black{}: their colour is mostly noise; \
                 expose more, or light the chart more brightly",
                are(*count),
                listed(names)
            ),
            Advice::TruncatedJpeg => write!(
                f,
                "{TRUNCATED}, and the decoder fills in the missing part of the picture: copy \
                 the photo from the camera again"
            ),
            Advice::CorruptJpeg => write!(
                f,
                "{CORRUPT}, and part of the picture may be wrong: copy the photo from the \
                 camera again"
            ),
            Advice::TooFewToCheck { usable, needed } => write!(
                f,
                "the light found cannot be checked against the chart: only {usable} of its \
                 patches are neither clipped nor nearly black, and the check needs \
                 {needed}; retake the photo exposed so that the chart's white is bright but \
                 not clipped"
            ),
            Advice::CheckFailed { why } => write!(
                f,
                "the light found cannot be checked against the chart ({why}): retake the \
                 photo with the chart well exposed and evenly lit"
            ),
            Advice::NoChartData { chart, file } => write!(
                f,
                "the light found is not checked against the chart: the {chart}'s measured \
                 reflectances are not shipped with spdcam, and it was started without the \
                 folder that holds them ({file} in the measured data). To have the check, \
                 start spdcam with that data folder (its data-directory option or the \
                 SPDCAM_DATA variable), or photograph a {}, which is checked with nothing \
                 else",
                built_in_charts()
            ),
            Advice::UnknownChart { chart } => write!(
                f,
                "the light found is not checked against the chart: the reflectances of \
                 {chart} are not known to spdcam"
            ),
            Advice::NoCalibration => write!(
                f,
                "no uncertainty bands: this model was not calibrated; calibrate it to have \
                 bands and a full verdict"
            ),
            Advice::Residual {
                residual,
                level,
                worst,
            } => write!(
                f,
                "the light found does not explain the chart's colours (residual \
                 {residual:.3}; clean photos stay below {level:.3}){}: light the chart \
                 evenly by this light alone, keep glare and reflections off it, and check \
                 that the corners sit on its four outer corners",
                match worst.as_slice() {
                    [] => String::new(),
                    names => format!(", worst at {}", names.join(", ")),
                }
            ),
            Advice::Halves { split, level } => write!(
                f,
                "the two halves of the chart look lit differently (two lights, a shadow or \
                 glare; half-to-half residual {split:.3}, clean photos stay below \
                 {level:.3}): light the whole chart evenly by this light alone"
            ),
            Advice::ColourGradient { gradient, level } => write!(
                f,
                "the light's colour changes across the chart (two lights, or one light and \
                 a coloured reflection; its grey patches' colour gradient is {gradient:.2}, \
                 clean photos stay below {level:.2}): light the chart by this light alone, \
                 away from coloured walls"
            ),
            Advice::TwoLights { ratio, level } => write!(
                f,
                "the chart looks lit by two different lights, one on each half, even if \
                 the camera balanced each half to grey (a light of its own for one half \
                 explains {ratio:.1} times more of the patches than noise would; clean \
                 photos stay below {level:.1}): turn the other light off, or move the chart \
                 to where this light alone falls on it"
            ),
            Advice::Glare { share, level } => write!(
                f,
                "light is added unevenly across the chart (glare, a reflection, or flare \
                 from a light beside it: an additive light changing across the chart \
                 explains {:.0} % of what the light found leaves unexplained, clean photos \
                 stay below {:.0} %): turn the chart or the camera so that no light shines \
                 off the chart or into the lens, and shade the lens",
                100.0 * share,
                100.0 * level
            ),
            Advice::Ambiguous => write!(
                f,
                "many lights give nearly this photo, or it is unlike the lights spdcam \
                 learned from: the spectrum's shape is uncertain (wide band), so take it as \
                 a rough guide; the {}, with more patches, tells such lights apart better",
                KnownChart::Sg140.shown_name()
            ),
            Advice::MayBePoor { at_least, level } => write!(
                f,
                "the spectrum's shape may match the true one only poorly: one estimate in \
                 twenty like this one has a GFC below {at_least:.2} ({level:.2} or less is a \
                 poor match): take it as a rough guide, or retake the photo with the chart \
                 larger, evenly lit and out of glare"
            ),
            Advice::UnlikeKind { kind } => write!(
                f,
                "the light in this photo does not look like {kind}, the kind of light named: \
                 the estimate was kept among such lights anyway and may be far off; check \
                 what lights the room, or name no kind"
            ),
            Advice::LowGfc { expected, level } => write!(
                f,
                "the spectrum's shape is expected to match the true one only loosely \
                 (expected GFC {expected:.3}, below {level}): take it as a rough guide"
            ),
        }
    }
}

/// What shows that sampled patches are not the chart they are said to be (the chart
/// identity test of `spdcam_infer::trust::chart_identity`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mismatch {
    /// The patches are all of one colour.
    Flat,
    /// The patches that are grey on the chart are not ordered from light to dark as the
    /// chart's are.
    NotOrdered,
    /// The chart under a light explains the patches' colours no better than shuffled.
    Unexplained,
    /// The patches are not flat inside.
    Textured,
    /// Too few patches are neither clipped nor nearly black to tell.
    TooFewUsable,
}

impl fmt::Display for Mismatch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Mismatch::Flat => "the patches are all of one colour",
            Mismatch::NotOrdered => {
                "the patches that are grey on the chart do not run from light to dark as the \
                 chart's do"
            }
            Mismatch::Unexplained => {
                "the patches' colours do not follow the chart's: the chart under a light \
                 explains them no better than the same colours shuffled"
            }
            Mismatch::Textured => "the patches are not flat: they hold detail, not one colour each",
            Mismatch::TooFewUsable => {
                "too few of the patches are neither clipped nor nearly black to tell; if they \
                 are on the chart, retake the photo exposed so that its white is bright but \
                 not clipped"
            }
        })
    }
}

/// Where the patches that are not the chart came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sampled {
    /// Inside corners placed by hand.
    Corners,
    /// Where the chart was detected.
    Detected,
    /// A feature row (1-based) of a file or an array.
    Row(usize),
}

/// The refusal of patches that are not the chart `chart` (as people know it) and what to
/// do: place the corners again, show where the chart is, give a real chart's patches.
pub fn not_the_chart(chart: &str, sampled: Sampled, mismatches: &[Mismatch]) -> String {
    let what = mismatch_list(mismatches);
    match sampled {
        Sampled::Corners => format!(
            "these corners do not hold a {chart}: place them on the chart's four outer \
             corners ({what})"
        ),
        Sampled::Detected => format!(
            "what was found is not a {chart}: show where the chart is by its four outer \
             corners ({what})"
        ),
        Sampled::Row(row) => format!(
            "row {row} does not hold a {chart}'s patches: give the patches of a photo of \
             that chart, in the order the model reads them ({what})"
        ),
    }
}

/// The note on a photo's charts that a grid of patches found beside them (centred at
/// `centre`, photo pixels) was left out because it is not a `chart` (`mismatches`: why).
pub fn place_left_out(chart: &str, centre: Option<[f64; 2]>, mismatches: &[Mismatch]) -> String {
    let at = centre.map_or(String::new(), |[x, y]| format!(" at {x:.0}, {y:.0} px"));
    let why = match mismatch_list(mismatches) {
        list if list.is_empty() => list,
        list => format!(" ({list})"),
    };
    format!("a grid of patches{at} was left out: it is not a {chart}{why}")
}

/// What was found against a chart, in words, separated by semicolons.
fn mismatch_list(mismatches: &[Mismatch]) -> String {
    mismatches
        .iter()
        .map(Mismatch::to_string)
        .collect::<Vec<_>>()
        .join("; ")
}

/// `is` for one, `are` for more.
fn are(count: usize) -> &'static str {
    if count == 1 {
        "is"
    } else {
        "are"
    }
}

/// ` (dark skin, blue sky and 3 more)`: up to [`NAMES_LISTED`] names, the rest counted;
/// empty for none.
fn listed(names: &[String]) -> String {
    match names.len() {
        0 => String::new(),
        n if n <= NAMES_LISTED => format!(" ({})", names.join(", ")),
        n => format!(
            " ({} and {} more)",
            names[..NAMES_LISTED].join(", "),
            n - NAMES_LISTED
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_warning_and_refusal_is_in_plain_words() {
        let mut texts: Vec<String> = [
            Advice::LowConfidence {
                confidence: 0.6,
                placed: false,
            },
            Advice::LowConfidence {
                confidence: 0.6,
                placed: true,
            },
            Advice::TruncatedJpeg,
            Advice::CorruptJpeg,
        ]
        .iter()
        .map(Advice::to_string)
        .collect();
        let every = [
            Mismatch::Flat,
            Mismatch::NotOrdered,
            Mismatch::Unexplained,
            Mismatch::Textured,
            Mismatch::TooFewUsable,
        ];
        for sampled in [Sampled::Corners, Sampled::Detected, Sampled::Row(3)] {
            texts.push(not_the_chart("ColorChecker 24", sampled, &every));
        }
        for text in &texts {
            let b = text.as_bytes();
            let index = (0..b.len() - 2)
                .any(|i| b[i] == b'p' && b[i + 1].is_ascii_digit() && b[i + 2].is_ascii_digit());
            assert!(!index, "{text}");
            for word in ["--", "feature", "debug image", "data directory holds", "::"] {
                assert!(!text.contains(word), "{text}");
            }
        }
        assert!(texts[4].starts_with(
            "these corners do not hold a ColorChecker 24: place them on the chart's four outer \
             corners (the patches are all of one colour; "
        ));
        assert!(texts[2].contains("truncated") && texts[3].contains("corrupt"));
    }

    #[test]
    fn patch_lists_are_short_and_counted() {
        let names: Vec<String> = ["A1", "B2", "C3", "D4", "E5", "F6"]
            .map(String::from)
            .to_vec();
        let clipped = Advice::Clipped {
            count: 6,
            of: 96,
            names,
            calibration_most: Some(2),
        }
        .to_string();
        assert!(
            clipped.starts_with(
                "6 of 96 patches are clipped (A1, B2, C3, D4 and 2 more) (at most 2 in the \
                 calibration photos): "
            ),
            "{clipped}"
        );
        assert!(clipped.contains("expose less"), "{clipped}");
        let dark = Advice::Dark {
            count: 1,
            of: 24,
            names: vec!["black 2".into()],
        }
        .to_string();
        assert!(dark.starts_with("1 of 24 patches is nearly black (black 2): "));
    }
}
