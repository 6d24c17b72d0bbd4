//! The colour protocol's results as Markdown: a summary over each set of lights, then per
//! model and for the baselines a row per lamp type or reference, and the protocol in words.

use super::lights::LightSet;
use super::{ColourReport, Group, ModelColour, Row, Summary, CCT_MAX_DUV};
use crate::error::EvalError;
use crate::held_out::file_name;
use spdcam_core::light_families::LampType;
use spdcam_core::spectral::Grid;

/// The columns every table shares after its own.
const COLUMNS: &str = "photos | refused | ok | mean GFC | median Δu′v′ | CCT photos | median CCT error | CCT too high | median abs CCT error | median CCT 95 % half-width | CCT interval holds |";
/// Their alignment row.
const ALIGN: &str = "---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|";
/// The names of a model's two kinds of photo.
const PATHS: [&str; 2] = ["(a) scene", "(b) patch level"];
/// The same with raw scene photos.
const RAW_PATHS: [&str; 2] = ["(a) raw scene", "(b) patch level"];
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

/// The columns of [`ColourReport::photos_csv`].
const PHOTO_COLUMNS: [&str; 24] = [
    "model",
    "light_named",
    "photo",
    "set",
    "light",
    "lamp_type",
    "camera",
    "refused",
    "gfc",
    "true_u_prime",
    "true_v_prime",
    "estimate_u_prime",
    "estimate_v_prime",
    "delta_uv_prime",
    "true_cct_k",
    "estimate_cct_k",
    "cct_half95_k",
    "true_duv",
    "estimate_duv",
    "estimate_rf",
    "expected_gfc",
    "raw_bias_uv",
    "band95_held",
    "ok",
];

impl ColourReport {
    /// Every photo of every model as CSV, a row each (model, light, camera, GFC, the true and
    /// estimated u′v′ and CCT, the CCT's 95 % half-width, the true and estimated Duv, the
    /// estimate's TM-30 Rf, its expected GFC, the bias the raw colour correction
    /// expects for its shape, the share of wavelengths its 95 % band holds, verdict): what
    /// the tables summarise, for a study of its own (empty cells where a photo was refused
    /// or a CCT is not scored).
    pub fn photos_csv(&self) -> crate::error::Result<String> {
        let mut w = csv::Writer::from_writer(Vec::new());
        let fail = |e: csv::Error| EvalError::invalid(format!("the photos' CSV: {e}"));
        w.write_record(PHOTO_COLUMNS).map_err(fail)?;
        let number = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v}"));
        for m in &self.models {
            for (k, photos) in m.photos.iter().enumerate() {
                for p in photos {
                    let light = &self.lights[p.light];
                    let e = p.estimate.as_ref();
                    let c = e.map(|e| &e.colour);
                    let record = [
                        file_name(&m.model),
                        m.light_named.to_string(),
                        ["scene", "patch"][k].to_string(),
                        light.set.label().to_string(),
                        light.name.clone(),
                        light.kind.label().to_string(),
                        p.camera
                            .and_then(|i| self.camera_names.get(i))
                            .cloned()
                            .unwrap_or_default(),
                        e.is_none().to_string(),
                        number(e.map(|e| e.gfc)),
                        number(c.map(|c| c.true_uv_prime[0])),
                        number(c.map(|c| c.true_uv_prime[1])),
                        number(c.map(|c| c.estimate_uv_prime[0])),
                        number(c.map(|c| c.estimate_uv_prime[1])),
                        number(c.map(|c| c.delta_uv_prime)),
                        number(c.and_then(|c| c.true_cct)),
                        number(c.and_then(|c| c.estimate_cct)),
                        number(e.and_then(|e| e.cct_interval).map(|(_, half)| half)),
                        number(c.and_then(|c| c.true_duv)),
                        number(c.and_then(|c| c.estimate_duv)),
                        number(e.and_then(|e| e.rf)),
                        number(e.and_then(|e| e.expected_gfc)),
                        number(e.and_then(|e| e.raw_bias)),
                        number(e.and_then(|e| e.band95_held)),
                        e.is_some_and(|e| e.ok).to_string(),
                    ];
                    w.write_record(&record).map_err(fail)?;
                }
            }
        }
        let bytes = w
            .into_inner()
            .map_err(|e| EvalError::invalid(format!("the photos' CSV: {e}")))?;
        String::from_utf8(bytes).map_err(|e| EvalError::invalid(format!("the photos' CSV: {e}")))
    }

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
            for (k, path) in self.paths().iter().enumerate() {
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
                for (k, path) in self.paths().iter().enumerate() {
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

    /// The names of the two kinds of photo measured.
    fn paths(&self) -> [&'static str; 2] {
        if self.raw {
            RAW_PATHS
        } else {
            PATHS
        }
    }

    /// The protocol in words.
    fn protocol(&self) -> String {
        let [lamp, reference, patch] = self.photos;
        let types = LampType::ALL
            .into_iter()
            .filter(|&t| t != LampType::Daylight)
            .map(LampType::label)
            .collect::<Vec<_>>()
            .join(", ");
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
             colour matrix, tone — and a JPEG{}), each camera in turn; {lamp} per lamp and \
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
            if self.raw {
                "; here the sensor's mosaic before all of that, written as a DNG with the \
                 camera's matrices fitted under A and D65 and its neutral under the light, as \
                 `-o scene.dng` writes it"
            } else {
                ""
            },
            self.seed,
            wavelengths(&Grid::ESTIMATION),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colour::photos::PhotoScore;
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

    /// The ColorChecker 24 model's measurement with `rows` and `photos`, uncalibrated.
    fn cc24(rows: Vec<Row<[Summary; 2]>>, photos: [Vec<PhotoScore>; 2]) -> ModelColour {
        ModelColour {
            model: PathBuf::from("models/cc24.spdm"),
            chart: "colorchecker24".into(),
            light_named: false,
            calibrated: false,
            rows,
            photos,
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
            models: vec![cc24(
                vec![row([summary(Some((0.04, 0.9))), summary(None)])],
                [Vec::new(), Vec::new()],
            )],
            baselines: vec![row([summary(None), summary(None)])],
            lights: Vec::new(),
            camera_names: Vec::new(),
            photos: [2, 4, 8],
            cameras: 13,
            seed: 1,
            skipped: Vec::new(),
            raw: false,
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

    #[test]
    fn every_photo_is_a_csv_row_with_empty_cells_where_nothing_was_scored() {
        use crate::colour::lights::Light;
        use crate::colour::photos::Scored;
        use crate::colour::score::ColourScore;
        use spdcam_core::cie_illuminant::planck;
        let light = Light {
            name: "Lamp, \"warm\"".into(),
            set: LightSet::Test,
            kind: LampType::ALL[0],
            spd: planck(3000.0, &Grid::ESTIMATION).unwrap(),
        };
        let scored = Scored {
            gfc: 0.97,
            colour: ColourScore {
                delta_uv_prime: 0.005,
                true_uv_prime: [0.25, 0.52],
                estimate_uv_prime: [0.245, 0.52],
                true_cct: Some(3000.0),
                estimate_cct: None,
                true_duv: Some(0.0004),
                estimate_duv: None,
            },
            ok: true,
            cct_interval: None,
            rf: None,
            expected_gfc: Some(0.98),
            raw_bias: Some(0.0042),
            band95_held: Some(0.9),
        };
        let report = ColourReport {
            models: vec![cc24(
                Vec::new(),
                [
                    vec![PhotoScore {
                        light: 0,
                        camera: Some(1),
                        estimate: Some(scored),
                    }],
                    vec![PhotoScore {
                        light: 0,
                        camera: None,
                        estimate: None,
                    }],
                ],
            )],
            baselines: Vec::new(),
            lights: vec![light],
            camera_names: vec!["cam_a".into(), "cam_b".into()],
            photos: [1, 1, 1],
            cameras: 2,
            seed: 1,
            skipped: Vec::new(),
            raw: false,
        };
        let csv = report.photos_csv().unwrap();
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 3, "{csv}");
        assert_eq!(lines[0], PHOTO_COLUMNS.join(","));
        let kind = LampType::ALL[0].label();
        assert_eq!(
            lines[1],
            format!(
                "cc24.spdm,false,scene,test lamps,\"Lamp, \"\"warm\"\"\",{kind},cam_b,false,\
                 0.97,0.25,0.52,0.245,0.52,0.005,3000,,,0.0004,,,0.98,0.0042,0.9,true"
            )
        );
        assert_eq!(
            lines[2],
            format!("cc24.spdm,false,patch,test lamps,\"Lamp, \"\"warm\"\"\",{kind},,true,,,,,,,,,,,,,,,,false")
        );
    }
}
