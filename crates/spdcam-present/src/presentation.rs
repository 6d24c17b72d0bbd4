//! What an estimate means, in words and in numbers rounded to what their uncertainty
//! supports: the one source of the HTML report ([`crate::report`]) and of the web page's
//! summary and metric tables, so the two never say different things.
//!
//! - Numbers are written by the one rule of [`crate::rounding`] (the PDG's rounding; "not
//!   determinable from this photo" where the 95 % interval is too wide), as the command
//!   line and Python write them.
//! - A metric that is not meaningful for the light has no number, only the reason: CCT and
//!   TM-30 (whose reference illuminant is chosen by the CCT) farther than |Duv| 0.05 from the
//!   Planckian locus (CIE 015:2018 §9.5; Ohno 2014), CIE 13.3 Ra and R1–R14 farther than
//!   ΔC 5.4·10⁻³ (CIE 13.3-1995 §5.2).
//! - The light is described by simple rules on its chromaticity and its spectrum's shape
//!   ([`describe_light`]).

use crate::meaningful::{cct_meaningful, cri_meaningful};
use crate::meter::Meter;
use crate::rounding::{marked_uncalibrated, shown, undetermined_words};
pub use crate::rounding::{round_sig, round_with_uncertainty};
use serde::Serialize;
use spdcam_core::light_families::LightKind;
use spdcam_core::quality::registry::{self, Group, MeaningfulFor};
use spdcam_infer::estimate::{Estimate, MAX_CCT_DUV};
use spdcam_infer::trust::{Veil, Verdict};

/// Within this |Duv| a light reads as white without a tint (ANSI C78.377-2017 puts its
/// nominal white quadrangles about ±0.006 around the locus).
const WHITE_DUV: f64 = 0.006;

/// Beyond this |Duv| the tint is plain to see, not slight.
const TINTED_DUV: f64 = 0.02;

/// A peak of the peak-normalised SPD counts when it stands this far above the deeper of the
/// two valleys beside it.
const PEAK_PROMINENCE: f64 = 0.15;

/// Everything the report and the page say about one estimate.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Presentation {
    /// One or two sentences at the top: the light, and how far the estimate can be trusted.
    pub summary: String,
    /// The light in words, e.g. `warm white light with an LED-like spectrum`.
    pub light: String,
    /// The chart the photo showed, as people know it (`ColorChecker 24`); `None` for an
    /// estimate of feature rows.
    pub chart: Option<String>,
    /// The verdict in plain words, when the estimate was judged.
    pub verdict: Option<VerdictWords>,
    /// What the goodness-of-fit coefficient is, and what this estimate's expected one means.
    pub gfc: String,
    /// What a colour meter's screen shows: the headline readings and the film/TV numbers.
    pub meter: Meter,
    /// The CIE 1976 u′v′ diagram of the estimate, SVG ([`crate::chromaticity`]): the
    /// drawing the report shows, served to the web page.
    pub uv_diagram: String,
    /// The photo's and the metrics' warnings (in a person's words at their source,
    /// [`spdcam_core::advice`]), less those a greyed metric says already.
    pub warnings: Vec<String>,
    /// The metrics in groups (colour, colour rendering, circadian and eye, plants), each
    /// group's meaningful metrics first.
    pub groups: Vec<MetricGroup>,
}

/// The verdict with its reasons, in plain words.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct VerdictWords {
    /// `ok`, `doubtful` or `unusable` (as the JSON's `verdict`).
    pub label: &'static str,
    /// One line: what to do with the numbers.
    pub headline: &'static str,
    /// What the verdict rests on.
    pub explanation: &'static str,
    /// What lowered it, and checks that could not be made.
    pub reasons: Vec<String>,
    /// The glare read on the chart's dark patches ([`glare_words`]), when the self-check
    /// was made.
    pub glare: Option<String>,
}

/// A group of metrics under one heading.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MetricGroup {
    /// The heading, e.g. `Colour rendering`.
    pub title: &'static str,
    /// Its metrics, the meaningful ones first.
    pub metrics: Vec<MetricLine>,
}

/// One metric as it is shown: a rounded value, or why there is none.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MetricLine {
    /// The key in the estimate's `metrics` (`cri_r9` for R9).
    pub key: &'static str,
    /// Its name, e.g. `CRI Ra`.
    pub label: &'static str,
    /// Its unit, empty for none.
    pub unit: &'static str,
    /// One line of what it tells.
    pub explanation: &'static str,
    /// The value rounded to what its uncertainty supports, with `± half-width (95 %)` when
    /// there is one; `None` when not meaningful or undefined.
    pub value: Option<String>,
    /// Why there is no value; `None` when there is one.
    pub not_meaningful: Option<String>,
}

impl Presentation {
    /// The presentation of `estimate`.
    pub fn of(estimate: &Estimate) -> Presentation {
        let light = describe_light(estimate);
        let uncertainty = estimate.trust.as_ref().and_then(|t| t.uncertainty.as_ref());
        let groups = Group::PRESENTED
            .iter()
            .map(|&group| {
                let mut lines: Vec<MetricLine> = registry::in_group(group)
                    .map(|metric| {
                        let key = metric.key;
                        let half95 = uncertainty
                            .and_then(|u| u.metrics.get(key))
                            .map(|i| i.half95);
                        let (value, not_meaningful) = match meaningful_value(estimate, key) {
                            Ok(v) => match shown(key, v, half95) {
                                Ok(text) => (
                                    Some(marked_uncalibrated(text, half95, uncertainty.is_some())),
                                    None,
                                ),
                                Err(_) => (None, Some(undetermined_words(key, v, half95))),
                            },
                            Err(why) => (None, Some(why)),
                        };
                        MetricLine {
                            key,
                            label: metric.label,
                            unit: metric.unit,
                            explanation: metric.explanation,
                            value,
                            not_meaningful,
                        }
                    })
                    .collect();
                // Stable: the meaningful ones first, each part in its own order.
                lines.sort_by_key(|l| l.value.is_none());
                MetricGroup {
                    title: group.title(),
                    metrics: lines,
                }
            })
            .collect();
        let spread = band_spread(estimate);
        let mut summary = capitalised(&light);
        let cct_half = uncertainty
            .and_then(|u| u.metrics.get("cct_k"))
            .map(|i| i.half95);
        match estimate
            .metrics
            .cct_k
            .filter(|_| cct_meaningful(estimate).is_ok())
        {
            Some(cct) => match shown("cct_k", cct, cct_half) {
                Ok(text) => summary.push_str(&format!(", CCT {text} K")),
                Err(_) => summary.push_str(&format!(
                    ", its colour temperature {}",
                    undetermined_words("cct_k", cct, cct_half)
                )),
            },
            None => summary.push_str(", too far from white for a colour temperature"),
        }
        summary.push('.');
        if estimate.light != LightKind::Unknown {
            summary.push_str(&format!(
                " You said the light is {}: the estimate is kept among such lights.",
                estimate.light.label()
            ));
        }
        match (spread, uncertainty) {
            (Some(spread), Some(u)) => summary.push_str(&format!(
                " The estimate is good to about ±{} % of the spectrum's peak (95 % band, \
                 averaged over {}–{} nm); expected GFC {:.3}.",
                round_sig(100.0 * spread, 1),
                estimate.spd.grid().start_nm,
                estimate.spd.grid().end_nm(),
                u.expected_gfc
            )),
            _ => summary.push_str(" How good the estimate is cannot be said: no calibration."),
        }
        let verdict = estimate.trust.as_ref().map(|t| {
            let (headline, explanation) = verdict_words(t.verdict);
            VerdictWords {
                label: t.verdict.label(),
                headline,
                explanation,
                reasons: t.reasons.clone(),
                glare: t
                    .self_check
                    .as_ref()
                    .and_then(|c| c.veil.as_ref())
                    .map(glare_words),
            }
        });
        Presentation {
            summary,
            light,
            chart: estimate
                .photo
                .as_ref()
                .map(|p| spdcam_core::chart::shown_chart_name(&p.chart)),
            verdict,
            gfc: gfc_words(uncertainty.map(|u| u.expected_gfc)),
            meter: Meter::of(estimate),
            uv_diagram: crate::chromaticity::uv_diagram_svg(estimate, None),
            warnings: estimate
                .photo
                .iter()
                .flat_map(|a| &a.warnings)
                // A metric's warning that it is not meaningful is said by its greyed row.
                .chain(
                    estimate
                        .metrics
                        .warnings
                        .iter()
                        .filter(|w| !w.contains("not meaningful")),
                )
                .cloned()
                .collect(),
            groups,
        }
    }

    /// The line of `key`, if it is shown.
    pub fn metric(&self, key: &str) -> Option<&MetricLine> {
        self.groups
            .iter()
            .flat_map(|g| &g.metrics)
            .find(|m| m.key == key)
    }
}

/// Glare below this share of the chart's mean reads as none.
const NO_GLARE: f64 = 0.02;

/// The glare read on the chart in a person's words: "Glare on the chart: about 31 % of its
/// mean brightness in the photo is light laid over it (read on its 9 darkest patches); a
/// glow near its centre adds 56 % more there." Where it is strongest is said on the chart as printed (its top is the
/// top of its layout).
pub fn glare_words(veil: &Veil) -> String {
    let on = match veil.patches {
        1 => "its darkest patch".to_string(),
        n => format!("its {n} darkest patches"),
    };
    let mut words = if veil.share < NO_GLARE {
        format!("Glare on the chart: none seen (read on {on})")
    } else {
        format!(
            "Glare on the chart: about {:.0} % of its mean brightness in the photo is light \
             laid over it (read on {on})",
            100.0 * veil.share
        )
    };
    if let Some(([x, y], local)) = veil.strongest {
        let third = 1.0 / 6.0;
        let vertical = if y < -third {
            "top"
        } else if y > third {
            "bottom"
        } else {
            ""
        };
        let horizontal = if x < -third {
            "left"
        } else if x > third {
            "right"
        } else {
            ""
        };
        let place = match (vertical, horizontal) {
            ("", "") => "near its centre".to_string(),
            (v, "") | ("", v) => format!("towards its {v}"),
            (v, h) => format!("towards its {v} {h}"),
        };
        words.push_str(&format!(
            "; a glow {place} adds {:.0} % more there",
            100.0 * local
        ));
    }
    words.push('.');
    words
}

/// The verdict's headline and what it rests on.
fn verdict_words(verdict: Verdict) -> (&'static str, &'static str) {
    match verdict {
        Verdict::Ok => (
            "Good: nothing was found against this estimate.",
            "The chart was found clearly, no patch is nearly black nor more are clipped than \
             in spdcam's calibration photos, and the light found explains them as well as it \
             explains those.",
        ),
        Verdict::Doubtful => (
            "Use with care: something makes this estimate less sure than usual.",
            "The numbers may be further off than their ± says; the reasons below say why. \
             A new photo (chart square to the camera, evenly lit by this light alone, not \
             overexposed) usually clears them.",
        ),
        Verdict::Unusable => (
            "Do not use these numbers: the photo does not say what the light is.",
            "The reasons below say what went wrong; take a new photo of the chart.",
        ),
    }
}

/// What the GFC is, with the expected one when known.
fn gfc_words(expected: Option<f64>) -> String {
    let what = "GFC (goodness-of-fit coefficient) says how alike two spectra's shapes are: \
                1 is identical, above 0.99 a close match, above 0.999 an excellent one; \
                below 0.95 they differ visibly (Hernández-Andrés et al. 2001).";
    match expected {
        Some(g) => format!(
            "{what} Photos like this one reach a GFC of about {g:.3} against the true \
             spectrum (the median on spdcam's calibration photos)."
        ),
        None => what.to_string(),
    }
}

/// The value of metric `key` when it is meaningful for this light, else why not (CCT and
/// TM-30 far from white, CRI farther than CIE 13.3 allows, or undefined), by the metric's
/// row of the registry ([`registry::Metric::meaningful_for`]).
pub fn meaningful_value(estimate: &Estimate, key: &str) -> Result<f64, String> {
    let m = &estimate.metrics;
    let Some(metric) = registry::metric(key) else {
        return Err(format!("{key} is not a metric"));
    };
    let Some(value) = metric.value(m) else {
        return Err(m
            .reasons
            .get(metric.reason_key)
            .cloned()
            .unwrap_or_else(|| "not defined for this light".into()));
    };
    match metric.meaningful_for {
        MeaningfulFor::WhiteLight => cct_meaningful(estimate)?,
        MeaningfulFor::Cri => cri_meaningful(estimate)?,
        MeaningfulFor::AnyLight => {}
    }
    Ok(value)
}

/// The mean half-width of the 95 % band over the wavelengths (the SPD's peak is 1).
fn band_spread(estimate: &Estimate) -> Option<f64> {
    let u = estimate.trust.as_ref()?.uncertainty.as_ref()?;
    let b = &u.band95;
    let n = b.upper.len().min(b.lower.len());
    (n > 0).then(|| {
        b.upper
            .iter()
            .zip(b.lower.iter())
            .map(|(hi, lo)| (hi - lo) / 2.0)
            .sum::<f64>()
            / n as f64
    })
}

/// The light in words, by documented rules:
///
/// - colour: near the Planckian locus (|Duv| ≤ 0.05) by its CCT in the colour-appearance
///   groups of EN 12464-1:2021 §5.3.4 (warm below 3300 K, neutral to 5300 K, cool above),
///   tinted `slightly greenish`/`slightly pinkish` beyond |Duv| 0.006 (ANSI C78.377's
///   tolerance) and `greenish`/`pinkish` beyond 0.02; farther, a coloured light named by
///   its hue angle around the equal-energy white point in CIE 1931 xy;
/// - spectrum: peaks of the peak-normalised SPD that stand 0.15 above the deeper valley
///   beside them; one blue peak (430–475 nm) with the maximum beyond 500 nm is
///   `LED-like (a blue peak and a broad phosphor hump)`, three or more peaks `spiky
///   (fluorescent- or multi-LED-like)`, none with the maximum in the last fifth of the
///   range `smooth, rising towards red (incandescent- or halogen-like)`, at most one
///   otherwise `smooth and broad (daylight-like)`, two `two-peaked`.
pub fn describe_light(estimate: &Estimate) -> String {
    let colour = match (estimate.metrics.cct_k, estimate.metrics.duv) {
        (Some(cct), Some(duv)) if duv.abs() <= MAX_CCT_DUV => {
            let base = if cct < 3300.0 {
                "warm white"
            } else if cct <= 5300.0 {
                "neutral white"
            } else {
                "cool white"
            };
            let tint = match (duv.abs(), duv > 0.0) {
                (d, _) if d <= WHITE_DUV => "",
                (d, true) if d <= TINTED_DUV => "slightly greenish ",
                (d, false) if d <= TINTED_DUV => "slightly pinkish ",
                (_, true) => "greenish ",
                (_, false) => "pinkish ",
            };
            format!("{tint}{base} light")
        }
        _ => format!("{} coloured light", hue_name(estimate.colorimetry.xy)),
    };
    let shape = spectrum_shape(&estimate.spd.grid().wavelengths(), &estimate.spd);
    format!("{colour} with a {shape} spectrum")
}

/// The hue of a chromaticity far from white, by its angle around the equal-energy point.
fn hue_name(xy: [f64; 2]) -> &'static str {
    let angle = (xy[1] - 1.0 / 3.0).atan2(xy[0] - 1.0 / 3.0).to_degrees();
    match angle {
        a if (-20.0..20.0).contains(&a) => "reddish",
        a if (20.0..60.0).contains(&a) => "yellowish",
        a if (60.0..140.0).contains(&a) => "greenish",
        a if (140.0..=180.0).contains(&a) || a < -160.0 => "bluish-green",
        a if (-160.0..-100.0).contains(&a) => "bluish",
        _ => "purplish",
    }
}

/// The shape of the spectrum in words (see [`describe_light`]).
fn spectrum_shape(wavelengths: &[f64], spd: &[f64]) -> &'static str {
    let peak = spd.iter().copied().fold(0.0_f64, f64::max);
    if peak <= 0.0 || spd.len() < 3 {
        return "flat";
    }
    let v: Vec<f64> = spd.iter().map(|x| x / peak).collect();
    let peaks = prominent_peaks(&v);
    // The last fifth of the range.
    let red_end = wavelengths[0] + 0.8 * (wavelengths[wavelengths.len() - 1] - wavelengths[0]);
    let top = v
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map_or(0, |(i, _)| i);
    let blue = peaks
        .iter()
        .filter(|&&i| (430.0..=475.0).contains(&wavelengths[i]))
        .count();
    if peaks.len() >= 3 {
        "spiky (fluorescent- or multi-LED-like)"
    } else if blue == 1 && wavelengths[top] > 500.0 {
        "LED-like (a blue peak and a broad phosphor hump)"
    } else if peaks.is_empty() && wavelengths[top] >= red_end {
        "smooth, rising towards red (incandescent- or halogen-like)"
    } else if peaks.len() <= 1 {
        "smooth and broad (daylight-like)"
    } else {
        "two-peaked"
    }
}

/// Indices of the local maxima of `v` standing at least [`PEAK_PROMINENCE`] above the
/// higher of the lowest points on either side before a higher value (topographic
/// prominence); the ends of the range are never peaks (a curve rising to its end is not
/// one).
fn prominent_peaks(v: &[f64]) -> Vec<usize> {
    let n = v.len();
    (1..n.saturating_sub(1))
        .filter(|&i| {
            if !(v[i] > v[i - 1] && v[i] >= v[i + 1]) {
                return false;
            }
            // The lowest point on each side before the curve rises above this peak.
            let side = |range: &mut dyn Iterator<Item = usize>| -> Option<f64> {
                let mut low = v[i];
                let mut any = false;
                for j in range {
                    if v[j] > v[i] {
                        return Some(low);
                    }
                    low = low.min(v[j]);
                    any = true;
                }
                any.then_some(low)
            };
            let (Some(left), Some(right)) = (side(&mut (0..i).rev()), side(&mut (i + 1..n))) else {
                return false;
            };
            let base = left.max(right);
            v[i] - base >= PEAK_PROMINENCE
        })
        .collect()
}

/// `text` with its first letter upper-case.
fn capitalised(text: &str) -> String {
    let mut chars = text.chars();
    match chars.next() {
        Some(c) => c.to_uppercase().chain(chars).collect(),
        None => String::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glare_is_said_with_where_it_is_strongest_on_the_chart_as_printed() {
        let veil = |share: f64, strongest: Option<([f64; 2], f64)>| Veil {
            share,
            patches: 9,
            strongest,
        };
        assert_eq!(
            glare_words(&veil(0.314, Some(([-0.04, 0.06], 0.56)))),
            "Glare on the chart: about 31 % of its mean brightness in the photo is light laid \
             over it (read on its 9 darkest patches); a glow near its centre adds 56 % more there."
        );
        assert!(glare_words(&veil(0.3, Some(([-0.3, -0.3], 0.4))))
            .ends_with("; a glow towards its top left adds 40 % more there."));
        assert!(glare_words(&veil(0.3, Some(([0.4, 0.0], 0.4)))).contains("towards its right"));
        assert!(glare_words(&veil(0.3, Some(([0.0, 0.4], 0.4)))).contains("towards its bottom"));
        // Below 2 %, or negative (a camera's tone curve that deepens blacks): none.
        for share in [0.01, -0.09] {
            assert_eq!(
                glare_words(&veil(share, None)),
                "Glare on the chart: none seen (read on its 9 darkest patches)."
            );
        }
        let one = Veil {
            patches: 1,
            ..veil(0.2, None)
        };
        assert!(glare_words(&one).contains("(read on its darkest patch)"));
    }

    #[test]
    fn peaks_and_shapes_follow_the_documented_rules() {
        let w: Vec<f64> = (0..61).map(|i| 400.0 + 5.0 * f64::from(i)).collect();
        let gauss = |c: f64, s: f64| -> Vec<f64> {
            w.iter()
                .map(|&x| (-(x - c).powi(2) / (2.0 * s * s)).exp())
                .collect()
        };
        // A white LED: a blue peak at 450 nm and a phosphor hump at 580 nm.
        let led: Vec<f64> = gauss(450.0, 10.0)
            .iter()
            .zip(gauss(580.0, 50.0))
            .map(|(a, b)| 0.7 * a + b)
            .collect();
        assert_eq!(
            spectrum_shape(&w, &led),
            "LED-like (a blue peak and a broad phosphor hump)"
        );
        let bulb: Vec<f64> = w.iter().map(|x| (x - 380.0) / 320.0).collect();
        assert_eq!(
            spectrum_shape(&w, &bulb),
            "smooth, rising towards red (incandescent- or halogen-like)"
        );
        let tri: Vec<f64> = [gauss(450.0, 6.0), gauss(545.0, 6.0), gauss(610.0, 6.0)]
            .iter()
            .fold(vec![0.0; w.len()], |acc, g| {
                acc.iter().zip(g).map(|(a, b)| a + b).collect()
            });
        assert_eq!(
            spectrum_shape(&w, &tri),
            "spiky (fluorescent- or multi-LED-like)"
        );
        assert_eq!(
            spectrum_shape(&w, &gauss(540.0, 120.0)),
            "smooth and broad (daylight-like)"
        );
        assert_eq!(hue_name([0.2, 0.6]), "greenish");
        assert_eq!(hue_name([0.65, 0.3]), "reddish");
        assert_eq!(hue_name([0.16, 0.08]), "bluish");
    }

    #[test]
    fn the_summary_says_which_kind_of_light_was_named() {
        use spdcam_core::cie_illuminant::StandardIlluminant;
        use spdcam_core::spectral::Grid;
        let d65 = StandardIlluminant::D65.spd(&Grid::ESTIMATION).unwrap();
        let mut e = crate::test_support::estimate_of(d65, &[]);
        let plain = Presentation::of(&e).summary;
        assert!(!plain.contains("You said"), "{plain}");
        e.light = LightKind::Daylight;
        let told = Presentation::of(&e).summary;
        assert!(
            told.contains(
                "You said the light is daylight: the estimate is kept among such lights."
            ),
            "{told}"
        );
    }
}
