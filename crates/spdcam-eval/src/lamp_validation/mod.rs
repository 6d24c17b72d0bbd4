//! The validation protocol for real lamps (`spdcam lamps validate`). (a) The split's held-out
//! lamps photographed (patch level) by the split's held-out cameras with the randomised
//! in-camera stage; (b) the same lamps photographed by an independent simple camera model
//! (`spdcam_core::simple_camera`); both scored per lamp type (mean GFC, 400–700 nm) beside
//! the average-SPD baseline, for the validation lamps (choose on these) and the test lamps
//! (report only). (c) The real photo sets of the thesis (SG 96 models only).
//!
//! [`LampValidation::measure`] runs it; [`LampValidation::markdown`] is the table
//! `spdcam lamps validate` writes.

mod photos;

pub use photos::average_spd;
pub(crate) use photos::randomised_rows;

use crate::error::Result;
use crate::held_out::{file_name, in_data_dir, on_grid, HeldOutPhotos, SkippedCamera, GRID};
use photos::{pipeline_photos, score, simple_photos};
use spdcam_core::builtin::DataDir;
use spdcam_core::chart::{Chart, KnownChart};
use spdcam_core::dataset::REAL_PHOTO_SETS;
use spdcam_core::light_families::validation_split::LampPart;
use spdcam_core::light_families::LampType;
use spdcam_core::spectral::{Extrapolation, Interpolation, SpectralSet};
use spdcam_core::{seed, spectral_error};
use spdcam_infer::Model;
use std::path::{Path, PathBuf};

/// The options of the lamp validation beyond the held-out photos.
#[derive(Debug, Clone, Default)]
pub struct LampValidationOptions {
    /// The thesis's data (holding measured/…) for (c); `None`: the data directory's thesis/.
    pub thesis_data: Option<PathBuf>,
    /// Leave out (c), the real photo sets (they need the thesis's data).
    pub no_real: bool,
}

/// One model's mean GFC over the lamps of a type in one part of the split.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scores {
    /// The average SPD of the split's fit lamps, the estimate of a model that knows nothing.
    pub average: f64,
    /// (a): photos by the held-out cameras with the randomised in-camera stage.
    pub pipeline: f64,
    /// (b): photos by the independent simple camera.
    pub simple: f64,
}

/// One row of a model's table: a lamp type (or all lamps) in the validation and test parts.
#[derive(Debug, Clone, PartialEq)]
pub struct TypeScores {
    /// The lamp type; `None`: every lamp of the part.
    pub kind: Option<LampType>,
    /// How many lamps of the type the validation part and the test part hold.
    pub lamps: [usize; 2],
    /// The mean scores on the validation part and the test part; `None` where the part holds
    /// no lamp of the type.
    pub scores: [Option<Scores>; 2],
}

/// One model measured: its table per lamp type and, for an SG 96 model, its real-set scores.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelValidation {
    /// The model's file.
    pub model: PathBuf,
    /// The chart the model names.
    pub chart: String,
    /// One row per lamp type of the validation and test lamps (in [`LampType::ALL`]'s
    /// order), then all lamps.
    pub types: Vec<TypeScores>,
    /// (c): mean GFC on each of the real photo sets (in [`REAL_PHOTO_SETS`]' order); `None`
    /// for other charts and with [`LampValidationOptions::no_real`].
    pub real: Option<[f64; 3]>,
}

/// The lamp validation's results: every model measured and how the photos were made.
#[derive(Debug, Clone, PartialEq)]
pub struct LampValidation {
    /// Each model, in the order given.
    pub models: Vec<ModelValidation>,
    /// Photos of each lamp.
    pub shots: u64,
    /// How many held-out cameras took them.
    pub cameras: usize,
    /// The seed of the draws.
    pub seed: u64,
    /// The split's held-out cameras left out (unreadable curves), for the caller to report.
    pub skipped: Vec<SkippedCamera>,
}

impl LampValidation {
    /// Measures each of `photos`' models on the split's validation and test lamps ((a) and
    /// (b)) and, unless `options` leave them out, an SG 96 model on the real photo sets (c);
    /// `progress` hears of each model measured.
    pub fn measure(
        photos: &HeldOutPhotos,
        options: &LampValidationOptions,
        data_dir: &DataDir,
        progress: &mut dyn FnMut(&Path),
    ) -> Result<LampValidation> {
        let setup = photos.setup(data_dir)?;
        let (library, split) = (&setup.library, &setup.split);
        let parts = [
            ("validation", LampPart::Validation),
            ("test", LampPart::Test),
        ];
        let lamps: Vec<Vec<usize>> = parts
            .iter()
            .map(|(name, p)| {
                library.positions(split.lamps(*p), &format!("the split's {name} lamps"))
            })
            .collect::<spdcam_core::Result<_>>()?;
        let fit_lamps = library.positions(split.lamps(LampPart::Fit), "the split's fit lamps")?;
        let shots = photos.shots;

        let mut models = Vec::new();
        for (path, model, chart_name) in photos.models()? {
            let chart = Chart::resolve(&chart_name, None, data_dir, &GRID)?;
            model.check_features(&chart.feature_names(), &chart_name)?;
            let truth = on_grid(library, &model.grid())?;
            let average = average_spd(&truth, &fit_lamps);
            // Per part, the mean GFC per lamp of the average SPD, (a) and (b).
            let mut cells: Vec<[Vec<f64>; 3]> = Vec::new();
            for (k, ids) in lamps.iter().enumerate() {
                let stream = seed::derive(photos.seed, k as u64);
                let a = pipeline_photos(&setup.cameras, &chart, library, ids, shots, stream)?;
                let b = simple_photos(&setup.cameras, &chart, library, ids, shots, stream)?;
                let baseline: Vec<f64> = ids
                    .iter()
                    .map(|&i| spectral_error::gfc(&truth[i], &average).unwrap_or(0.0))
                    .collect();
                cells.push([
                    baseline,
                    score(&model, &a, &truth, ids, shots)?,
                    score(&model, &b, &truth, ids, shots)?,
                ]);
            }
            let kinds: Vec<Option<LampType>> = LampType::ALL
                .iter()
                .filter(|t| lamps.iter().flatten().any(|&i| library.types[i] == **t))
                .map(|&t| Some(t))
                .chain([None])
                .collect();
            let types = kinds
                .into_iter()
                .map(|kind| {
                    let select = |part: usize| -> Vec<usize> {
                        (0..lamps[part].len())
                            .filter(|&j| kind.is_none_or(|t| library.types[lamps[part][j]] == t))
                            .collect()
                    };
                    let (sv, st) = (select(0), select(1));
                    let mean = |part: usize, col: usize, rows: &[usize]| -> f64 {
                        rows.iter().map(|&j| cells[part][col][j]).sum::<f64>() / rows.len() as f64
                    };
                    let scores = |part: usize, rows: &[usize]| {
                        (!rows.is_empty()).then(|| Scores {
                            average: mean(part, 0, rows),
                            pipeline: mean(part, 1, rows),
                            simple: mean(part, 2, rows),
                        })
                    };
                    TypeScores {
                        kind,
                        lamps: [sv.len(), st.len()],
                        scores: [scores(0, &sv), scores(1, &st)],
                    }
                })
                .collect();
            let real = if !options.no_real
                && KnownChart::from_name(&chart_name) == Some(KnownChart::Sg96)
            {
                Some(real_scores(
                    options.thesis_data.as_deref(),
                    &model,
                    data_dir,
                )?)
            } else {
                None
            };
            progress(&path);
            models.push(ModelValidation {
                model: path,
                chart: chart_name,
                types,
                real,
            });
        }
        Ok(LampValidation {
            models,
            shots,
            cameras: setup.cameras.len(),
            seed: photos.seed,
            skipped: setup.skipped,
        })
    }

    /// The results as the Markdown `spdcam lamps validate` writes: a table per model, the
    /// real photo sets' table where any model was scored on them, and how the photos were
    /// made.
    pub fn markdown(&self) -> String {
        let cell = |s: Option<Scores>, value: fn(&Scores) -> f64| -> String {
            s.map_or_else(|| "–".into(), |s| format!("{:.4}", value(&s)))
        };
        let mut md = String::new();
        for m in &self.models {
            md += &format!("### `{}` ({})\n\n", file_name(&m.model), m.chart);
            md += "| lamp type | lamps (val / test) | average SPD (val) | (a) randomised in-camera (val) | (b) simple camera (val) | average SPD (test) | (a) test | (b) test |\n|---|---:|---:|---:|---:|---:|---:|---:|\n";
            for t in &m.types {
                let label = t.kind.map_or("**all**", LampType::label);
                let [v, s] = t.scores;
                md += &format!(
                    "| {label} | {} / {} | {} | {} | {} | {} | {} | {} |\n",
                    t.lamps[0],
                    t.lamps[1],
                    cell(v, |s| s.average),
                    cell(v, |s| s.pipeline),
                    cell(v, |s| s.simple),
                    cell(s, |s| s.average),
                    cell(s, |s| s.pipeline),
                    cell(s, |s| s.simple)
                );
            }
            md.push('\n');
        }
        let real: Vec<(&Path, [f64; 3])> = self
            .models
            .iter()
            .filter_map(|m| m.real.map(|r| (m.model.as_path(), r)))
            .collect();
        if !real.is_empty() {
            md += "### (c) the real photo sets (virtual-only models)\n\n| model | Telelumen, Canon 5D IV (dev) | Hue, Canon 5D IV | Telelumen, Galaxy Tab S7 |\n|---|---:|---:|---:|\n";
            for (path, scores) in &real {
                md += &format!(
                    "| `{}` | {:.4} | {:.4} | {:.4} |\n",
                    file_name(path),
                    scores[0],
                    scores[1],
                    scores[2]
                );
            }
            md.push('\n');
        }
        md += &format!(
            "Mean GFC (400–700 nm) per lamp (over {} photos each), then over the lamps of a type. \
             (a): each photo by a held-out camera of the split ({} cameras) with the randomised \
             in-camera stage (exposure, white balance, tone, JPEG, lighting gradient), patch level, \
             noise-free; (b): by the independent simple camera (grey-world white balance partly \
             applied, D65-fitted colour matrix, auto exposure, a little flare and gradient, sRGB, \
             8 bit) with the same cameras. Average SPD: the mean of the split's fit lamps, the \
             estimate of a model that knows nothing. Seed {}.\n",
            self.shots, self.cameras, self.seed
        );
        md
    }
}

/// (c): mean GFC of `model` on each real photo set (dev; Hue train + val; tablet train + val).
fn real_scores(thesis_data: Option<&Path>, model: &Model, data_dir: &DataDir) -> Result<[f64; 3]> {
    let thesis = match thesis_data {
        Some(p) => p.to_path_buf(),
        None => in_data_dir(None, "thesis", data_dir)?,
    };
    let sets = REAL_PHOTO_SETS
        .iter()
        .map(|set| set.load(&thesis, &GRID))
        .collect::<spdcam_core::Result<Vec<_>>>()?;
    let grid = model.grid();
    let mut out = [0.0; 3];
    for (k, set) in sets.iter().enumerate() {
        let rows: Vec<f64> = set.features.iter().flatten().copied().collect();
        let estimates = model.estimate_rows(&rows)?;
        let names = (0..set.spds.len()).map(|i| format!("s{i}")).collect();
        let truth = SpectralSet::from_spds(names, &set.spds)?
            .resample(&grid, Interpolation::Linear, Extrapolation::Zero)?
            .0;
        let d = grid.count;
        out[k] = (0..set.spds.len())
            .map(|i| {
                spectral_error::gfc(
                    &spdcam_core::spectral::normalise_by_max(truth.item(i)),
                    &estimates[i * d..(i + 1) * d],
                )
                .unwrap_or(0.0)
            })
            .sum::<f64>()
            / set.spds.len() as f64;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn validation(real: Option<[f64; 3]>) -> LampValidation {
        let scores = Scores {
            average: 0.9,
            pipeline: 0.95,
            simple: 0.925,
        };
        LampValidation {
            models: vec![ModelValidation {
                model: PathBuf::from("models/sg.spdm"),
                chart: "colorchecker_sg96".into(),
                types: vec![
                    TypeScores {
                        kind: Some(LampType::Hid),
                        lamps: [2, 0],
                        scores: [Some(scores), None],
                    },
                    TypeScores {
                        kind: None,
                        lamps: [2, 0],
                        scores: [Some(scores), None],
                    },
                ],
                real,
            }],
            shots: 4,
            cameras: 3,
            seed: 7,
            skipped: Vec::new(),
        }
    }

    #[test]
    fn a_part_without_lamps_of_a_type_shows_a_dash_and_the_file_name_alone() {
        let md = validation(None).markdown();
        assert!(md.starts_with("### `sg.spdm` (colorchecker_sg96)\n\n"));
        assert!(md.contains("| HID | 2 / 0 | 0.9000 | 0.9500 | 0.9250 | – | – | – |\n"));
        assert!(md.contains("| **all** | 2 / 0 |"));
        assert!(!md.contains("(c) the real photo sets"));
        assert!(md.ends_with("over 4 photos each), then over the lamps of a type. (a): each photo by a held-out camera of the split (3 cameras) with the randomised in-camera stage (exposure, white balance, tone, JPEG, lighting gradient), patch level, noise-free; (b): by the independent simple camera (grey-world white balance partly applied, D65-fitted colour matrix, auto exposure, a little flare and gradient, sRGB, 8 bit) with the same cameras. Average SPD: the mean of the split's fit lamps, the estimate of a model that knows nothing. Seed 7.\n"));
    }

    #[test]
    fn the_real_sets_table_appears_only_with_real_scores() {
        let md = validation(Some([0.8, 0.9, 0.85])).markdown();
        assert!(md.contains("| `sg.spdm` | 0.8000 | 0.9000 | 0.8500 |\n\nMean GFC"));
    }
}
