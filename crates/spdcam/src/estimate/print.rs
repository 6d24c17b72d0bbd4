//! What `spdcam estimate` prints and writes besides the SPDs: the estimates as text, the
//! verdicts, the bands' columns and the HTML report.

use super::meter_lines::{film_tv_line, headline_line, metrics_line};
use super::{EstimateArgs, DETAILED_MAX};
use crate::outln;
use anyhow::Result;
use spdcam_core::fsio;
use spdcam_core::light_families::LightKind;
use spdcam_core::spectral::{Grid, Spd, SpectralSet};
use spdcam_infer::trust::{Trust, Verdict};
use spdcam_infer::Estimate;
use spdcam_present::meter::Meter;
use spdcam_present::presentation::glare_words;
use spdcam_present::report::{report_html, ReportImage, ReportItem};
use spdcam_present::rounding::NOT_DETERMINABLE;
use std::path::Path;

/// The estimates as text: colorimetry and the SPD every 25 nm (for up to 20), the score
/// against the truth, with `--explain` what each number means, and where the files went.
/// `reported`: the report's items of the same estimates, when a report was written, whose
/// meters are printed rather than made again.
pub(super) fn print_estimates(
    estimates: &[Estimate],
    args: &EstimateArgs,
    reported: Option<&[ReportItem]>,
) -> Result<()> {
    let mut models: Vec<&str> = estimates.iter().map(|e| e.model.as_str()).collect();
    models.dedup();
    let told = match estimates.first().map(|e| e.light) {
        Some(kind) if kind != LightKind::Unknown => {
            format!(", told the light is {}", kind.describe())
        }
        _ => String::new(),
    };
    let mut raw_models: Vec<&str> = estimates
        .iter()
        .filter_map(|e| e.photo.as_ref()?.raw.as_ref()?.spectrum_model.as_deref())
        .collect();
    raw_models.sort_unstable();
    raw_models.dedup();
    let raw = if raw_models.is_empty() {
        String::new()
    } else {
        format!(" (raw photos' spectra from {})", raw_models.join(", "))
    };
    outln!(
        "{} estimate(s) with {}{raw}{told}",
        estimates.len(),
        models.join(", ")
    )?;
    let detailed = estimates.len() <= DETAILED_MAX;
    for (i, e) in estimates.iter().enumerate() {
        let unusable = e
            .trust
            .as_ref()
            .is_some_and(|t| t.verdict == Verdict::Unusable);
        if unusable {
            outln!("{}: UNUSABLE, no estimate to rely on", e.name)?;
        } else if detailed {
            let made;
            let meter = match reported.and_then(|items| items.get(i)) {
                Some(item) => &item.presentation.meter,
                None => {
                    made = Meter::of(e);
                    &made
                }
            };
            outln!("{}: {}", e.name, headline_line(e, meter))?;
            outln!("  relative SPD: {}", spd_line(&e.spd))?;
            outln!("  {}", metrics_line(e))?;
            if let Some(line) = film_tv_line(meter) {
                outln!("  {line}")?;
            }
            match (&e.absolute, e.photo.as_ref().and_then(|p| p.exposure)) {
                (Some(Ok(a)), _) => outln!(
                    "  absolute (approximate, from {}): PPFD {}, melanopic EDI {}",
                    a.exposure.label(),
                    a.ppfd_umol_m2_s
                        .map_or_else(|| "—".into(), |v| format!("{v:.1} µmol/m²/s")),
                    a.melanopic_edi_lux
                        .map_or_else(|| "—".into(), |v| format!("{v:.0} lx")),
                )?,
                (Some(Err(reason)), Some(_)) => outln!("  no absolute levels: {reason}")?,
                _ => {}
            }
        }
        if let Some(t) = &e.trust {
            outln!("  {}", trust_line(t))?;
            if let Some(veil) = t.self_check.as_ref().and_then(|c| c.veil.as_ref()) {
                outln!("  {}", glare_words(veil))?;
            }
            if let (Some(u), false) = (&t.uncertainty, unusable) {
                outln!(
                    "  expected GFC {:.3}; 95 % band {:.2} wide on average (68 %: {:.2}; SPD peak 1){}",
                    u.expected_gfc,
                    u.band95.mean_width(),
                    u.band68.mean_width(),
                    if u.widening > 1.0 {
                        format!(
                            ", widened {:.1}× (the light found explains this photo {:.1}× worse than typical calibration photos)",
                            u.widening, u.widening
                        )
                    } else {
                        String::new()
                    }
                )?;
            }
        }
        if let Some(s) = e.truth {
            outln!(
                "  against the true SPD: GFC {:.4}, RMSE {:.4} (both peak-normalised)",
                s.gfc,
                s.rmse
            )?;
        }
    }
    if args.explain {
        explain(estimates, detailed)?;
    } else {
        outln!("(--explain: what each number and the verdict mean)")?;
    }
    if let Some(out) = &args.output {
        outln!(
            "SPD{} → {}",
            if estimates.len() > 1 { "s" } else { "" },
            out.display()
        )?;
    }
    if let Some(plot) = &args.plot {
        outln!("plot → {}", plot.display())?;
    }
    if let Some(report) = &args.report {
        outln!("report → {}", report.display())?;
    }
    Ok(())
}

/// For each photo that shows several charts, how the light compares across its places.
pub(super) fn print_places(estimates: &[Estimate]) -> Result<()> {
    let mut shown: Vec<&str> = Vec::new();
    for e in estimates {
        let (Some(across), Some(photo)) = (&e.across_places, &e.photo) else {
            continue;
        };
        if shown.contains(&photo.source.as_str()) {
            continue;
        }
        shown.push(&photo.source);
        outln!(
            "the light across the {} places of {}:",
            across.places.len(),
            photo.source
        )?;
        for line in across.lines() {
            outln!("  {line}")?;
        }
    }
    Ok(())
}

/// What each number means, printed with `--explain`: the detection's confidence, the metrics'
/// abbreviations, the verdict and the GFC, for those the estimates carry.
fn explain(estimates: &[Estimate], detailed: bool) -> Result<()> {
    if estimates.iter().any(|e| e.photo.is_some()) {
        outln!("confidence: how sure the chart's detection is (0–1; below 0.8 check the --debug image)")?;
    }
    if detailed {
        outln!(
            "Ra: CIE 13.3 colour rendering (R9 saturated red); Rf, Rg: TM-30 fidelity and \
             gamut; M-EDER: melanopic daylight efficacy ratio (CIE S 026); S/P: \
             scotopic/photopic; PPF: 400–700 nm photons per 1000 lx"
        )?;
        outln!(
            "±: the 95 % interval when calibrated; \"{NOT_DETERMINABLE}\" with the interval \
             where it is too wide for one number; — where not defined or not meaningful (CRI \
             and TM-30 need a light near white)"
        )?;
        outln!(
            "computed on the estimate's {}–{} nm only (`spdcam metrics` on a wider SPD, \
             `--json` for every number)",
            estimates[0].spd.grid().start_nm,
            estimates[0].spd.grid().end_nm()
        )?;
    }
    if estimates.iter().any(|e| e.trust.is_some()) {
        outln!(
            "verdict: ok, doubtful (use with care) or unusable, from the detection, clipped \
             and dark patches, the self-check (the chart re-rendered under the estimate) and \
             the calibrated uncertainty; the bands hold the true SPD at 68 % and 95 % per \
             wavelength"
        )?;
    }
    if estimates.iter().any(|e| e.truth.is_some()) {
        outln!(
            "GFC: goodness-of-fit of the spectral shape, 1 = identical (≥ 0.999 excellent, \
             ≥ 0.99 good)"
        )?;
    }
    Ok(())
}

/// One estimate of the report: the estimate, for a photo the photo with the chart found
/// (the `overlay` drawn when it was analysed), and its truth.
pub(super) fn report_item(
    estimate: &Estimate,
    overlay: Option<Vec<u8>>,
    truth: Option<Vec<f64>>,
) -> Result<ReportItem> {
    let image = overlay.map(|bytes| ReportImage {
        mime: "image/jpeg",
        bytes,
    });
    Ok(ReportItem::new(estimate.clone(), image, truth))
}

/// Writes the report of `items` to `path` atomically.
pub(super) fn write_report(path: &Path, title: &str, items: &[ReportItem]) -> Result<()> {
    fsio::write_atomic(path, report_html(title, items).as_bytes())?;
    Ok(())
}

/// With the data on standard output (`-o -`, `--json`), each estimate's verdict on standard
/// error, so that whoever runs the command still hears that an estimate is unusable.
pub(super) fn verdicts_to_stderr(estimates: &[Estimate]) {
    for e in estimates {
        if let Some(t) = &e.trust {
            eprintln!("{}", verdict_line(&e.name, t));
        }
    }
}

/// One estimate on one line, for runs of many rows: `estimate_21: xy (0.3127, 0.3290), CCT
/// 6504 K, Duv +0.0003; verdict: ok`, and its score when it has a truth.
pub(super) fn summary_line(e: &Estimate) -> String {
    let mut line = match &e.trust {
        Some(t) if t.verdict == Verdict::Unusable => verdict_line(&e.name, t),
        Some(t) => format!("{}: {}; {}", e.name, e.colorimetry.label(), trust_line(t)),
        None => format!("{}: {}", e.name, e.colorimetry.label()),
    };
    if let Some(s) = e.truth {
        line.push_str(&format!("; GFC {:.4}, RMSE {:.4}", s.gfc, s.rmse));
    }
    line
}

/// `name: UNUSABLE, no estimate to rely on; verdict: unusable (reasons)`, or
/// `name: verdict: ok` — the verdict of one estimate on one line.
pub(super) fn verdict_line(name: &str, t: &Trust) -> String {
    if t.verdict == Verdict::Unusable {
        format!(
            "{name}: UNUSABLE, no estimate to rely on; {}",
            trust_line(t)
        )
    } else {
        format!("{name}: {}", trust_line(t))
    }
}

/// The verdict and its reasons on one line: `verdict: doubtful (2 of 24 patches are …)`.
pub(super) fn trust_line(t: &Trust) -> String {
    if t.reasons.is_empty() {
        format!("verdict: {}", t.verdict.label())
    } else {
        format!("verdict: {} ({})", t.verdict.label(), t.reasons.join("; "))
    }
}

/// The estimates' SPDs as a spectral set, each followed by its bands when it has them:
/// `<name>_lower68, <name>_upper68, <name>_lower95, <name>_upper95`.
pub(super) fn with_bands(estimates: &[Estimate], grid: &Grid) -> Result<SpectralSet> {
    let mut names = Vec::new();
    let mut values = Vec::new();
    for e in estimates {
        names.push(e.name.clone());
        values.push(e.spd.to_vec());
        if let Some(u) = e.trust.as_ref().and_then(|t| t.uncertainty.as_ref()) {
            for (band, level) in [(&u.band68, "68"), (&u.band95, "95")] {
                names.push(format!("{}_lower{level}", e.name));
                values.push(band.lower.to_vec());
                names.push(format!("{}_upper{level}", e.name));
                values.push(band.upper.to_vec());
            }
        }
    }
    Ok(SpectralSet::on_grid(grid, names, values)?)
}

/// The SPD every 25 nm, peak-normalised, on one terminal line: `400:0.12 425:0.40 …`.
pub(super) fn spd_line(spd: &Spd) -> String {
    let spd = spd.normalised_by_max();
    spd.grid()
        .wavelengths()
        .iter()
        .zip(spd.iter())
        .filter(|(w, _)| (*w % 25.0).abs() < 1e-9)
        .map(|(w, v)| format!("{w:.0}:{v:.2}"))
        .collect::<Vec<_>>()
        .join(" ")
}
