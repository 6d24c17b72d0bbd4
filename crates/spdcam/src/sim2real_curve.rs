//! The fine-tuning learning curve of `spdcam sim2real --finetune MODEL`: mean GFC on real
//! photos against the number of real photos a virtual-trained model is fine-tuned on,
//! k-fold cross-validated on each real set (the photos come from the folds outside the test
//! fold), beside baselines trained on the same photos.

use anyhow::Result;
use rand::rngs::SmallRng;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use spdcam_core::dataset::MeasuredPhotos;
use spdcam_core::dataset::{Columns, Precision, SampleBatch};
use spdcam_core::metrics;
use spdcam_core::spectral::Grid;
use spdcam_learn::model::Model;
use spdcam_learn::recipe;
use spdcam_learn::record::Backend;
use spdcam_learn::record::DataInfo;
use spdcam_learn::train::{finetune, FinetuneOptions, TrainingSet};
use std::collections::BTreeMap;

/// How the curve is measured.
pub struct CurveOptions {
    /// Numbers of real photos to fine-tune on (0: the model as it is).
    pub sizes: Vec<usize>,
    /// Cross-validation folds.
    pub folds: usize,
    /// Seed of the photo picks and the fine-tuning.
    pub seed: u64,
    /// Fine-tune by the recipe [`recipe::tune`] chooses (as `spdcam finetune` without recipe
    /// flags) instead of the fixed [`recipe`].
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
pub struct Curve {
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
    metrics::normalise_by_max(&values)
}

/// Mean GFC of `model` on the photos `test`.
fn model_gfc(model: &Model, set: &MeasuredPhotos, test: &[usize], set_grid: &Grid) -> Result<f64> {
    let features: Vec<f64> = test.iter().flat_map(|&i| set.features[i].clone()).collect();
    let spds = model.estimate_rows(&features)?;
    let grid = model.grid();
    let mut total = 0.0;
    for (k, &i) in test.iter().enumerate() {
        let est = &spds[k * grid.count..(k + 1) * grid.count];
        total += metrics::gfc(&truth_on(set, i, set_grid, &grid), est)?;
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
