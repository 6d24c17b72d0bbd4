//! The fine-tuning learning curve of `spdcam sim2real --finetune MODEL`: mean GFC on real
//! photos against the number of real photos a virtual-trained model is fine-tuned on,
//! k-fold cross-validated on each real set (the photos come from the folds outside the test
//! fold), beside baselines trained on the same photos ([`learning_curve`]); every set's
//! curve beside two ridge baselines as a table ([`FinetuneCurves`]).

use super::ridge::fit_and_score;
use super::{RealSet, GRID};
use crate::error::Result;
use crate::recipe;
use crate::train::{finetune, FinetuneOptions, TrainingSet};
use rand::rngs::SmallRng;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use spdcam_core::dataset::MeasuredPhotos;
use spdcam_core::dataset::{Columns, Precision, SampleBatch};
use spdcam_core::spectral::Grid;
use spdcam_core::spectral_error;
use spdcam_infer::model::Model;
use spdcam_infer::record::{Backend, DataInfo};
use spdcam_infer::ridge::Ridge;
use std::collections::BTreeMap;

/// How the curve is measured.
#[derive(Debug, Clone)]
pub struct CurveOptions {
    /// Numbers of real photos to fine-tune on (0: the model as it is).
    pub sizes: Vec<usize>,
    /// Cross-validation folds.
    pub folds: usize,
    /// Seed of the photo picks and the fine-tuning.
    pub seed: u64,
    /// Fine-tune by the recipe [`recipe::tune`] chooses (as `spdcam finetune` without recipe
    /// flags) instead of the fixed recipe (all layers, about 150 steps).
    pub choose: bool,
}

/// One point of a curve: mean GFCs, `None` where the folds hold fewer photos than the size
/// (and for the baselines at size 0).
#[derive(Debug)]
pub struct CurvePoint {
    /// The fine-tuned model (at size 0: the model as it is).
    pub tuned: Option<f64>,
    /// Each baseline trained on the same photos.
    pub baselines: Vec<Option<f64>>,
}

/// One set's curve, a point per size of [`CurveOptions::sizes`].
#[derive(Debug)]
pub struct Curve {
    /// The points, in the order of the sizes.
    pub points: Vec<CurvePoint>,
}

/// The photos `indices` of `set` as a training set on `grid` (the grid of the set's SPDs).
fn training_set(
    set: &MeasuredPhotos,
    indices: &[usize],
    names: &[String],
    grid: &Grid,
) -> TrainingSet {
    let mut samples = SampleBatch {
        feature_count: names.len(),
        spd_len: grid.count,
        ..SampleBatch::default()
    };
    for (k, &i) in indices.iter().enumerate() {
        samples.samples.push(k as u64);
        samples.families.push("measured".into());
        samples.features.extend(&set.features[i]);
        samples.spds.extend(set.spds[i].iter());
        samples.attempts.push(1);
    }
    TrainingSet {
        samples,
        columns: Columns {
            feature_names: names.to_vec(),
            feature_precision: Precision::Float64,
            spd_grid: *grid,
            weight_names: Vec::new(),
        },
        info: DataInfo {
            path: format!("{} real photos", indices.len()),
            samples: indices.len(),
            chart: None,
            camera: None,
            families: BTreeMap::from([("measured".to_string(), indices.len() as u64)]),
            origin: None,
        },
    }
}

/// The truth of photo `i` on the model's grid, peak-normalised.
fn truth_on(set: &MeasuredPhotos, i: usize, set_grid: &Grid, model_grid: &Grid) -> Vec<f64> {
    let values: Vec<f64> = model_grid
        .wavelengths()
        .iter()
        .map(|nm| set.spds[i][((nm - set_grid.start_nm) / set_grid.step_nm).round() as usize])
        .collect();
    spdcam_core::spectral::normalise_by_max(&values)
}

/// Mean GFC of `model` on the photos `test`.
fn model_gfc(model: &Model, set: &MeasuredPhotos, test: &[usize], set_grid: &Grid) -> Result<f64> {
    let features: Vec<f64> = test.iter().flat_map(|&i| set.features[i].clone()).collect();
    let spds = model.estimate_rows(&features)?;
    let grid = model.grid();
    let mut total = 0.0;
    for (k, &i) in test.iter().enumerate() {
        let est = &spds[k * grid.count..(k + 1) * grid.count];
        total += spectral_error::gfc(&truth_on(set, i, set_grid, &grid), est)?;
    }
    Ok(total / test.len() as f64)
}

/// The fine-tuning recipe for `n` photos: the model's output layer kept, all layers
/// trained with a small learning rate for about 150 steps (chosen on the dev set among 150,
/// 600 and 3,000: longer overfits a few photos). There are too few photos to hold some back
/// for early stopping: the photos themselves validate, so the kept epoch is the one that
/// fits them best.
fn recipe(n: usize, seed: u64) -> FinetuneOptions {
    recipe::all_layers(n, 150, seed, Backend::Cpu)
}

/// Fits the baselines on the photos `train` and returns each one's mean GFC on the photos
/// `test`.
pub type Baselines<'a> = dyn Fn(&[usize], &[usize]) -> Result<Vec<f64>> + 'a;

/// The learning curve of `model` on one real set; `baselines` fits and scores the
/// baselines on (train, test) photo indices.
pub fn learning_curve(
    model: &Model,
    set: &MeasuredPhotos,
    set_grid: &Grid,
    options: &CurveOptions,
    baselines: &Baselines,
) -> Result<Curve> {
    let n = set.features.len();
    let folds = options.folds.max(2);
    let names = model.feature_names().to_vec();
    // Per size: the fine-tuned sum, the baselines' sums, the photos scored.
    let mut sums = vec![(0.0, Vec::<f64>::new(), 0usize); options.sizes.len()];
    for f in 0..folds {
        let (test, mut pool): (Vec<usize>, Vec<usize>) = (0..n).partition(|i| i % folds == f);
        pool.shuffle(&mut SmallRng::seed_from_u64(options.seed + f as u64));
        for (s, &size) in options.sizes.iter().enumerate() {
            if size > pool.len() {
                continue;
            }
            let picked = &pool[..size];
            let (tuned, baseline) = if size == 0 {
                (model_gfc(model, set, &test, set_grid)?, Vec::new())
            } else {
                let data = training_set(set, picked, &names, set_grid);
                let tuned = if options.choose {
                    recipe::tune(model, &data, options.seed, Backend::Cpu, &mut |_, _| {})?.model
                } else {
                    finetune(
                        model,
                        &data,
                        Some(&data),
                        &recipe(size, options.seed),
                        &mut |_| {},
                    )?
                    .model
                };
                (
                    model_gfc(&tuned, set, &test, set_grid)?,
                    baselines(picked, &test)?,
                )
            };
            let w = test.len() as f64;
            let sum = &mut sums[s];
            sum.0 += tuned * w;
            sum.1.resize(baseline.len(), 0.0);
            sum.1
                .iter_mut()
                .zip(&baseline)
                .for_each(|(t, b)| *t += b * w);
            sum.2 += test.len();
        }
    }
    let points = sums
        .iter()
        .map(|(tuned, base, count)| {
            let mean = |v: f64| (*count == n).then(|| v / n as f64);
            CurvePoint {
                tuned: mean(*tuned),
                baselines: base.iter().map(|&b| mean(b)).collect(),
            }
        })
        .collect();
    Ok(Curve { points })
}

/// The baselines' columns beside the fine-tuned model's.
const COLUMNS: [&str; 3] = ["fine-tuned", "ridge", "ridge towards virtual"];

/// The fine-tuning learning curve of one model on every real set, beside two linear
/// baselines on the same photos: ridge on the photos alone, and the virtual ridge prior
/// corrected by the photos (shrunk towards it); both choose their penalty by
/// cross-validation on the photos.
#[derive(Debug)]
pub struct FinetuneCurves {
    /// The real sets' labels.
    pub sets: Vec<String>,
    /// Each set's curve, in the order of the sets.
    pub curves: Vec<Curve>,
    /// How the curves were measured.
    pub options: CurveOptions,
    /// The model, as the table names it (its file).
    pub model: String,
    /// The model described ([`Model::describe`]).
    pub description: String,
    /// Virtual samples the prior was trained on.
    pub prior_samples: u64,
}

impl FinetuneCurves {
    /// Measures `model` (named `name` in the table) on every set of `sets`, beside ridge on
    /// the photos alone and ridge shrunk towards `prior` (trained on `prior_samples` virtual
    /// samples); `progress` hears each set's curve as it is measured.
    pub fn measure(
        model: &Model,
        name: &str,
        sets: &[RealSet],
        prior: &Ridge,
        prior_samples: u64,
        options: CurveOptions,
        progress: &mut dyn FnMut(&str, &Curve),
    ) -> Result<FinetuneCurves> {
        let options = CurveOptions {
            folds: options.folds.max(2),
            ..options
        };
        let curves = sets
            .iter()
            .map(|RealSet { label, photos: set }| {
                let baselines = |train: &[usize], test: &[usize]| -> Result<Vec<f64>> {
                    [None, Some(prior)]
                        .into_iter()
                        .map(|p| fit_and_score(set, train, test, 5, p))
                        .collect()
                };
                let curve = learning_curve(model, set, &GRID, &options, &baselines)?;
                progress(label, &curve);
                Ok(curve)
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(FinetuneCurves {
            sets: sets.iter().map(|s| s.label.to_string()).collect(),
            curves,
            options,
            model: name.to_string(),
            description: model.describe(),
            prior_samples,
        })
    }

    /// The curves as the Markdown table `spdcam sim2real --finetune` writes, with how they
    /// were measured.
    pub fn markdown(&self) -> String {
        let mut md = format!(
            "| real photos used | {} |\n|---:|{}\n",
            self.sets
                .iter()
                .map(|n| format!("{n}: {}", COLUMNS.join(" | ")))
                .collect::<Vec<_>>()
                .join(" | "),
            "---:|".repeat(COLUMNS.len() * self.sets.len())
        );
        let cell = |v: Option<f64>| v.map_or("–".to_string(), |v| format!("{v:.4}"));
        for (row, &size) in self.options.sizes.iter().enumerate() {
            md += &format!("| {size} |");
            for curve in &self.curves {
                let point = &curve.points[row];
                md += &format!(" {} |", cell(point.tuned));
                for k in 0..COLUMNS.len() - 1 {
                    md += &format!(" {} |", cell(point.baselines.get(k).copied().flatten()));
                }
            }
            md.push('\n');
        }
        md += &format!(
            "\nMean GFC (400–700 nm; the model at 5 nm, ridge at 10 nm) on the photos of the test \
             fold, {}-fold cross-validated; the photos used come from the other folds (seeded \
             random picks). Model: `{}` ({}), fine-tuned {}. Ridge: features ÷ their mean → SPD, \
             the penalty chosen by 5-fold cross-validation on the photos used; towards virtual: \
             shrunk towards the ridge trained on {} virtual samples (randomised cameras, \
             in-camera stage and lighting gradient) instead of towards zero.\n",
            self.options.folds,
            self.model,
            self.description,
            if self.options.choose {
                "as `spdcam finetune` without recipe flags: the recipe chosen by 5-fold \
                 cross-validation on the photos used among the model unchanged, the network \
                 recipes (for a network) and ridge on the photos at three penalties"
            } else {
                "with its output layer kept, all layers, learning rate 2e-4, batch ≤ 16, about \
                 150 steps"
            },
            self.prior_samples
        );
        md
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_leaves_a_dash_where_a_curve_has_no_point() {
        let curves = FinetuneCurves {
            sets: vec!["A".into()],
            curves: vec![Curve {
                points: vec![
                    CurvePoint {
                        tuned: Some(0.5),
                        baselines: Vec::new(),
                    },
                    CurvePoint {
                        tuned: Some(0.9),
                        baselines: vec![Some(0.8), None],
                    },
                ],
            }],
            options: CurveOptions {
                sizes: vec![0, 10],
                folds: 2,
                seed: 1,
                choose: false,
            },
            model: "m.spdm".into(),
            description: "linear".into(),
            prior_samples: 100,
        };
        let md = curves.markdown();
        assert!(md.starts_with(
            "| real photos used | A: fine-tuned | ridge | ridge towards virtual |\n\
             |---:|---:|---:|---:|\n| 0 | 0.5000 | – | – |\n| 10 | 0.9000 | 0.8000 | – |\n"
        ));
        assert!(md.contains("2-fold cross-validated"));
        assert!(md.contains("Model: `m.spdm` (linear)"));
    }
}
