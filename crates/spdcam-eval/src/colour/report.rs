//! The colour protocol's results as Markdown: a summary over each set of lights, then per
//! model and for the baselines a row per lamp type or reference, and the protocol in words.

use super::lights::LightSet;
use super::{ColourReport, Group, ModelColour, Row, Summary, CCT_MAX_DUV};
use crate::held_out::file_name;
use spdcam_core::light_families::LampType;
use spdcam_core::spectral::Grid;

/// The columns every table shares after its own.
const COLUMNS: &str = "photos | refused | ok | mean GFC | median Δu′v′ | CCT photos | median CCT error | CCT too high | median abs CCT error | median CCT 95 % half-width | CCT interval holds |";
/// Their alignment row.
const ALIGN: &str = "---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|";
/// The names of a model's two kinds of photo.
const PATHS: [&str; 2] = ["(a) scene", "(b) patch level"];
/// The names of the two baselines.
const BASELINES: [&str; 2] = ["constant", "truth over 400–700 nm"];

/// A share as a percentage.
fn percent(x: f64) -> String {
    format!("{:.0} %", 100.0 * x)
}

/// A signed relative error as a percentage.
fn signed_percent(x: f64) -> String {
    format!("{:+.1} %", 100.0 * x)
}

/// The shared cells of one summary; `judged`: whether the estimates were refused or judged
/// at all (not for the baselines).
fn cells(s: &Summary, judged: bool) -> String {
    let dash = || "–".to_string();
    let (refused, ok) = if judged {
        (percent(s.refused), percent(s.ok))
    } else {
        (dash(), dash())
    };
    let mut out = format!(
        "{} | {refused} | {ok} | {:.4} | {:.4} |",
        s.photos, s.gfc, s.delta_uv_prime
    );
    match &s.cct {
        Some(c) => {
            let (width, holds) = c.interval.map_or_else(
                || (dash(), dash()),
                |(w, h)| (format!("±{:.1} %", 100.0 * w), percent(h)),
            );
            out += &format!(
                " {} | {} | {} | {:.1} % | {width} | {holds} |",
                c.photos,
                signed_percent(c.median_error),
                percent(c.too_high),
                100.0 * c.median_abs_error
            );
        }
        None => out += " 0 | – | – | – | – | – |",
    }
    out
}

/// `400–700` for a grid.
fn wavelengths(grid: &Grid) -> String {
    format!("{}–{}", grid.start_nm, grid.end_nm())
}

/// The label of a row's group.
fn group_label(group: &Group) -> String {
    match group {
        Group::Type(t) => t.label().to_string(),
        Group::Light(name) => name.clone(),
        Group::All => "**all**".into(),
    }
}

impl ModelColour {
    /// `` `model.spdm` ``, or `` `model.spdm` told the kind of light ``.
    fn label(&self) -> String {
        let told = if self.light_named {
            " told the kind of light"
        } else {
            ""
        };
        format!("`{}`{told}", file_name(&self.model))
    }
}

impl ColourReport {
    /// The results as the Markdown `spdcam experiment colour` writes.
    pub fn markdown(&self) -> String {
        let mut md = String::from("## Summary: every light of each set\n\n");
        md += &format!(
            "| model and kind of photo | set | lights | {COLUMNS}\n|---|---|---:|{ALIGN}\n"
        );
        let all = |rows: &[Row<[Summary; 2]>], set: LightSet| -> Option<(usize, [Summary; 2])> {
            rows.iter()
                .find(|r| r.set == set && r.group == Group::All)
                .map(|r| (r.lights, r.scores))
        };
        for m in &self.models {
            for (k, path) in PATHS.iter().enumerate() {
                for set in LightSet::ALL {
                    if let Some((n, s)) = all(&m.rows, set) {
                        md += &format!(
                            "| {} {path} | {} | {n} | {}\n",
                            m.label(),
                            set.label(),
                            cells(&s[k], true)
                        );
                    }
                }
            }
        }
        for (k, name) in BASELINES.iter().enumerate() {
            for set in LightSet::ALL {
                if let Some((n, s)) = all(&self.baselines, set) {
                    md += &format!(
                        "| {name} | {} | {n} | {}\n",
                        set.label(),
                        cells(&s[k], false)
                    );
                }
            }
        }
        md.push('\n');
        for m in &self.models {
            md += &format!("## {} ({})\n\n", m.label(), m.chart);
            md += &format!(
                "| set | group | lights | kind of photo | {COLUMNS}\n|---|---|---:|---|{ALIGN}\n"
            );
            for r in &m.rows {
                for (k, path) in PATHS.iter().enumerate() {
                    md += &format!(
                        "| {} | {} | {} | {path} | {}\n",
                        r.set.label(),
                        group_label(&r.group),
                        r.lights,
                        cells(&r.scores[k], true)
                    );
                }
            }
            if !m.calibrated {
                md += "\nThe program holds no trust calibration for this model: its estimates carry no CCT interval.\n";
            }
            md.push('\n');
        }
        md += "## Baselines\n\n";
        md +=
            &format!("| set | group | lights | estimate | {COLUMNS}\n|---|---|---:|---|{ALIGN}\n");
        for r in &self.baselines {
            for (k, name) in BASELINES.iter().enumerate() {
                md += &format!(
                    "| {} | {} | {} | {name} | {}\n",
                    r.set.label(),
                    group_label(&r.group),
                    r.lights,
                    cells(&r.scores[k], false)
                );
            }
        }
        md.push('\n');
        md += &self.protocol();
        md
    }

    /// The protocol in words.
    fn protocol(&self) -> String {
        let [lamp, reference, patch] = self.photos;
        let types = LampType::ALL.map(LampType::label).join(", ");
        format!(
            "## Protocol\n\n\
             Lights: the validation split's validation lamps (choose on these) and test lamps \
             (report only), grouped by lamp type ({types}), and eight white references built by \
             the program's own illuminant code: CIE A, D50 and D65 (CIE 015 tables), Planckian \
             radiators at 2,700, 3,000 and 4,000 K (Planck's law) and CIE daylight at 5,000 and \
             6,500 K (CIE 015 daylight formulas). Cameras: the split's {} held-out cameras, \
             outside every training pool. (a) Scene photos: the code of `spdcam render --scene` \
             ({}×{} pixels; the chart in a cluttered scene with perspective, blur, vignetting, \
             the default camera stage — Bayer mosaic, sensor noise, demosaicing, white balance, \
             colour matrix, tone — and a JPEG), each camera in turn; {lamp} per lamp and \
             {reference} per reference; found, sampled and estimated by the program's `Estimator` \
             as a user's photo is (an SG 96 model reads the 140-patch chart's photo). \
             (b) Patch-level photos: each camera drawn at random with the randomised in-camera \
             stage (exposure, white balance, tone, JPEG, lighting gradient; as `spdcam lamps \
             validate` (a)), noise-free; {patch} per light; estimated by the same `Estimator` as \
             feature rows. Seed {}.\n\n\
             Scores: GFC of the peak-normalised estimate against the truth over the model's \
             wavelengths (400–700 nm); Δu′v′: the distance in CIE 1976 u′v′ (CIE 1931 2° \
             observer, CIE 015:2018) between the estimate as the program gives it (its \
             wavelengths only) and the whole true light (380–780 nm) — what a colour meter \
             beside the chart would show; CCT by Ohno (2014), scored only where the true light \
             lies within |Duv| ≤ {CCT_MAX_DUV} of the Planckian locus; the CCT error is \
             (estimate − truth) / truth. The 95 % half-width is the estimate's calibrated \
             `metric_uncertainty` for `cct_k` relative to its CCT, and the interval holds when \
             the true CCT lies within it (models with a trust calibration only). A refused \
             photo (no chart found) counts against `ok` and is left out of the other numbers. \
             Baselines, over {} nm: the constant (the mean SPD of the split's fit lamps, the \
             estimate of a model that knows nothing) and the true SPD itself cut to those \
             wavelengths (the nearest any estimate over them can come).\n",
            self.cameras,
            super::photos::SCENE_SIZE.0,
            super::photos::SCENE_SIZE.1,
            self.seed,
            wavelengths(&Grid::ESTIMATION),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colour::{CctSummary, ModelColour};
    use std::path::PathBuf;

    fn summary(interval: Option<(f64, f64)>) -> Summary {
        Summary {
            photos: 4,
            refused: 0.25,
            ok: 0.5,
            gfc: 0.95,
            delta_uv_prime: 0.0042,
            cct: Some(CctSummary {
                photos: 3,
                median_error: -0.055,
                too_high: 1.0 / 3.0,
                median_abs_error: 0.06,
                interval,
            }),
        }
    }

    #[test]
    fn rows_show_shares_signed_errors_and_dashes_where_nothing_was_measured() {
        let row = |scores| Row {
            set: LightSet::Validation,
            group: Group::All,
            lights: 2,
            scores,
        };
        let report = ColourReport {
            models: vec![ModelColour {
                model: PathBuf::from("models/cc24.spdm"),
                chart: "colorchecker24".into(),
                light_named: false,
                calibrated: false,
                rows: vec![row([summary(Some((0.04, 0.9))), summary(None)])],
            }],
            baselines: vec![row([summary(None), summary(None)])],
            photos: [2, 4, 8],
            cameras: 13,
            seed: 1,
            skipped: Vec::new(),
        };
        let md = report.markdown();
        assert!(md.contains("| `cc24.spdm` (a) scene | validation lamps | 2 | 4 | 25 % | 50 % | 0.9500 | 0.0042 | 3 | -5.5 % | 33 % | 6.0 % | ±4.0 % | 90 % |\n"), "{md}");
        assert!(md.contains("| `cc24.spdm` (b) patch level | validation lamps | 2 | 4 | 25 % | 50 % | 0.9500 | 0.0042 | 3 | -5.5 % | 33 % | 6.0 % | – | – |\n"), "{md}");
        assert!(
            md.contains("| constant | validation lamps | 2 | 4 | – | – | 0.9500 |"),
            "{md}"
        );
        assert!(md.contains("carry no CCT interval"));
        assert!(md.contains("the split's 13 held-out cameras"));
        assert!(md.contains("Baselines, over 400–700 nm"));
    }
}
