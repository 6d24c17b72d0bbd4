//! What `spdcam estimate` prints of one estimate's numbers, as a colour meter shows them:
//! the headline (CCT and Δuv, or the dominant wavelength), the lighting metrics and the film
//! and TV numbers, every number written by the library's one rule
//! ([`spdcam_present::rounding`]), as the report and the web page write it.

use spdcam_core::quality::registry::{self, Group};
use spdcam_infer::Estimate;
use spdcam_present::meter::Meter;
use spdcam_present::presentation::meaningful_value;
use spdcam_present::rounding::{marked_uncalibrated, shown_with_unit};

/// `xy (0.3127, 0.3290); CCT 6500 ± 300 K, Δuv +0.0031 ± 0.0012`, or for coloured light
/// the dominant wavelength, purity and peak; and the illuminance when known.
pub(super) fn headline_line(e: &Estimate, meter: &Meter) -> String {
    let mut parts: Vec<String> = meter
        .headline
        .iter()
        .map(|r| format!("{} {}", r.label, r.value))
        .collect();
    if let Some(lux) = &meter.illuminance {
        parts.push(format!("illuminance {lux}"));
    }
    format!(
        "xy ({:.4}, {:.4}); {}",
        e.colorimetry.xy[0],
        e.colorimetry.xy[1],
        parts.join(", ")
    )
}

/// The main lighting-quality numbers on one line (the registry's metrics past the colour
/// group, which the headline gives), `—` where undefined or not meaningful for this light
/// (CRI and TM-30 far from white), each with its 95 % interval when the estimate has one:
/// `Ra 82 ± 4, R9 20 ± 15, …, PPF 30 ± 8 µmol s⁻¹ m⁻² per 1000 lx`.
pub(super) fn metrics_line(e: &Estimate) -> String {
    let intervals = e
        .trust
        .as_ref()
        .and_then(|t| t.uncertainty.as_ref())
        .map(|u| &u.metrics);
    Group::PRESENTED
        .iter()
        .filter(|&&g| g != Group::Colour)
        .flat_map(|&g| registry::in_group(g))
        .map(|m| {
            let value = match meaningful_value(e, m.key) {
                Err(_) => "—".to_string(),
                Ok(v) => {
                    let half95 = intervals.and_then(|i| i.get(m.key)).map(|i| i.half95);
                    marked_uncalibrated(
                        shown_with_unit(m.key, v, half95),
                        half95,
                        intervals.is_some(),
                    )
                }
            };
            format!("{} {value}", m.symbol)
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// The film and TV numbers on one line, `None` for a light without a meaningful CCT:
/// `film/TV: R1–R15 98 97 …; SSI (own CCT) 85; To 3200 K −40 ± 10 mired (…); …`.
pub(super) fn film_tv_line(meter: &Meter) -> Option<String> {
    let mut parts = Vec::new();
    if let Some(r) = &meter.r1_r15 {
        let bars: Vec<String> = r
            .iter()
            .map(|v| v.map_or_else(|| "—".into(), |v| format!("{v:.0}")))
            .collect();
        parts.push(format!("R1–R15 {}", bars.join(" ")));
        parts.extend(meter.r9_note.clone());
    }
    parts.extend(
        meter
            .film_tv
            .iter()
            .map(|r| format!("{} {}", r.label, r.value)),
    );
    (!parts.is_empty()).then(|| format!("film/TV: {}", parts.join("; ")))
}

#[cfg(test)]
mod tests {
    use super::*;
    use spdcam_core::builtin::DataDir;
    use spdcam_core::spectral::Grid;
    use spdcam_infer::trust::MetricInterval;
    use spdcam_infer::{Estimator, ModelSet, PhotoOptions};
    use spdcam_present::presentation::Presentation;
    use spdcam_present::report::{report_html, ReportItem};
    use spdcam_present::rounding::NOT_DETERMINABLE;

    const EXAMPLE: &[u8] = include_bytes!("../../../../examples/sg-telelumen.jpg");

    /// The example's estimate with its metrics and intervals moved to `k`'s values: a white
    /// light of a different CCT, Duv and metrics, some intervals too wide to show.
    fn variant(base: &spdcam_infer::Estimate, k: usize) -> spdcam_infer::Estimate {
        let mut e = base.clone();
        let f = k as f64;
        let m = &mut e.metrics;
        m.cct_k = Some(2500.0 + 397.3 * f);
        m.duv = Some(-0.004 + 0.00053 * f);
        m.cri_ra = Some(70.0 + 1.37 * f);
        m.tm30_rf = Some(68.0 + 1.13 * f);
        m.tm30_rg = Some(92.0 + 0.71 * f);
        m.mel_der = Some(0.4 + 0.031 * f);
        m.sp_ratio = Some(1.1 + 0.077 * f);
        m.ppf_per_lux = Some(0.012 + 0.0011 * f);
        if let Some(r) = &mut m.cri_r {
            r[8] = -20.0 + 4.3 * f;
        }
        let u = e.trust.as_mut().unwrap().uncertainty.as_mut().unwrap();
        for (key, half) in [
            ("cct_k", 40.0 + 31.0 * f),
            ("duv", 0.0004 + 0.0007 * f),
            ("cri_ra", 1.2 + 1.4 * f),
            ("cri_r9", 3.0 + 2.1 * f),
            ("tm30_rf", 0.9 + 1.1 * f),
            ("tm30_rg", 0.5 + 0.6 * f),
            ("mel_der", 0.011 + 0.013 * f),
            ("sp_ratio", 0.02 + 0.05 * f),
            ("ppf_per_lux", 0.0004 + 0.0007 * f),
        ] {
            u.metrics.insert(
                key.into(),
                MetricInterval {
                    half68: half / 2.0,
                    half95: half,
                },
            );
        }
        e
    }

    #[test]
    fn the_command_line_the_report_and_the_page_show_the_same_digits() {
        let estimator = Estimator::new(
            ModelSet::shipped().unwrap(),
            DataDir::new(None),
            Grid::parse("400-700:5").unwrap(),
        )
        .unwrap();
        let base = estimator
            .photo_bytes(EXAMPLE, "example.jpg", &PhotoOptions::default())
            .estimate
            .unwrap()
            .unwrap();
        let (mut shown_numbers, mut not_determinable) = (0, 0);
        for k in 0..20 {
            let e = variant(&base, k);
            let p = Presentation::of(&e);
            // The page shows the strings of the server's JSON (`presentation`).
            let page = serde_json::to_value(&p).unwrap();
            let cli = format!("{}\n{}", headline_line(&e, &p.meter), metrics_line(&e));
            let html = report_html("t", &[ReportItem::new(e.clone(), None, None)]);
            for group in page["groups"].as_array().unwrap() {
                for m in group["metrics"].as_array().unwrap() {
                    let key = m["key"].as_str().unwrap();
                    match m["value"].as_str() {
                        Some(v) => {
                            shown_numbers += 1;
                            assert!(cli.contains(v), "{key} {v} not in the CLI's {cli}");
                            assert!(html.contains(v), "{key} {v} not in the report");
                        }
                        None if m["not_meaningful"]
                            .as_str()
                            .unwrap()
                            .starts_with(NOT_DETERMINABLE) =>
                        {
                            not_determinable += 1;
                            // The same words, with the same interval, everywhere.
                            let words = m["not_meaningful"].as_str().unwrap();
                            assert!(words.contains("between"), "{key}: {words}");
                            assert!(cli.contains(words), "{key}: {words} not in {cli}");
                        }
                        None => {}
                    }
                }
            }
            for r in page["meter"]["headline"].as_array().unwrap() {
                let v = r["value"].as_str().unwrap();
                assert!(cli.contains(v) && html.contains(v), "{v}: {cli}");
            }
        }
        // Both cases met: numbers shown, and numbers withheld for too wide an interval.
        assert!(
            shown_numbers > 50 && not_determinable > 5,
            "{shown_numbers} {not_determinable}"
        );
    }
}
