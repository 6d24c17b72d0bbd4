//! Choosing how to fine-tune on a few photos of one's own: each candidate recipe (the model
//! left as it is among them) is scored by k-fold cross-validation on the photos given (mean
//! GFC of the held-out fold, every photo held out once; Hastie, Tibshirani & Friedman, *The
//! Elements of Statistical Learning*, 2nd ed., §7.10), and the best one is then run on all
//! of them. Leaving the model unchanged is a candidate, so a recipe that does not help on
//! held-out photos is never chosen. Beside the network recipes stand the simple candidates
//! a few real photos allow: ridge regression on the photos alone (a linear model with its own
//! PCA, as `spdcam train --model linear` makes), at three penalties. On 100 real Telelumen
//! photos such a ridge beats every network recipe on held-out photos (`docs/sim2real.md`),
//! so the choice never settles on a recipe that cross-validates worse than the simple thing.

use crate::error::{LearnError, Result};
use crate::evaluate::evaluate;
use crate::train::{finetune, train, FinetuneOptions, TrainOptions, TrainingSet};
use spdcam_core::dataset::SampleBatch;
use spdcam_infer::model::Model;
use spdcam_infer::network::Architecture;
use spdcam_infer::pca::Components;
use spdcam_infer::record::{Backend, Schedule};
use spdcam_infer::scale::RowScale;
use spdcam_infer::target::TargetKind;

/// Fewest samples a recipe can be chosen on: two folds of at least two photos.
pub const MIN_SAMPLES: usize = 4;
/// Cross-validation folds (fewer when there are fewer photos).
pub const FOLDS: usize = 5;

/// A fine-tuning recipe `choose` weighs.
#[derive(Debug, Clone)]
pub struct Recipe {
    /// What it does, in a few words.
    pub name: &'static str,
    /// What it makes of the model and the photos.
    pub fit: Fit,
}

/// How a [`Recipe`] makes its model.
#[derive(Debug, Clone)]
pub enum Fit {
    /// The model as it is.
    Unchanged,
    /// The model fine-tuned on the photos.
    Finetune(FinetuneOptions),
    /// A new linear model: ridge regression from the photos' features to the PCA
    /// coefficients of their SPDs (99.9 % of the variance, fitted on the photos), the
    /// feature weights penalised by `penalty`·n; the model's grid kept.
    Ridge {
        /// The penalty (per photo, on standardised features).
        penalty: f64,
    },
}

/// Penalties of the ridge candidates: weak, middling and strong shrinkage.
pub const RIDGE_PENALTIES: [(f64, &str); 3] = [
    (1e-4, "ridge on the photos alone, penalty 1e-4"),
    (1e-2, "ridge on the photos alone, penalty 1e-2"),
    (1.0, "ridge on the photos alone, penalty 1"),
];

impl Fit {
    /// The model this fit makes from `model` and `data` (which also validates a network:
    /// too few photos to hold some back).
    pub fn run(&self, model: &Model, data: &TrainingSet, seed: u64) -> Result<Model> {
        match self {
            Fit::Unchanged => Ok(model.clone()),
            Fit::Finetune(options) => {
                Ok(finetune(model, data, Some(data), options, &mut |_| {})?.model)
            }
            Fit::Ridge { penalty } => {
                let options = TrainOptions {
                    row_scale: RowScale::Mean,
                    architecture: Architecture::Linear { ridge: *penalty },
                    target: TargetKind::Pca(Components::Variance(0.999)),
                    grid: model.grid(),
                    schedule: Schedule::thesis(),
                    seed,
                    val_split: 0.2,
                    backend: Backend::Cpu,
                };
                let mut fitted = train(data, Some(data), &options, &mut |_| {})?.model;
                if let Some(template) = model.photo_chart() {
                    fitted.set_photo_chart(template.clone())?;
                }
                Ok(fitted)
            }
        }
    }
}

/// A recipe with its cross-validated score.
#[derive(Debug, Clone)]
pub struct Scored {
    /// The recipe.
    pub recipe: Recipe,
    /// Mean GFC over the photos, each predicted by a model fine-tuned without it.
    pub cv_gfc: f64,
}

/// The candidates for `n` photos: the model unchanged; all layers trained from the model's
/// own output layer with a small learning rate for about 150 and 600 optimiser steps (150
/// was best among 150, 600 and 3,000 on the real Telelumen dev photos in `spdcam sim2real
/// --finetune`; 600 for when there are more photos); and the output layer alone, the feature
/// layers frozen, for 600 steps; and ridge on the photos alone at each of
/// [`RIDGE_PENALTIES`]. A model with no network to fine-tune (`linear`, `average`) has the
/// unchanged model and the ridges only.
pub fn candidates(model: &Model, n: usize, seed: u64, backend: Backend) -> Vec<Recipe> {
    let steps = |count: usize| all_layers(n, count, seed, backend);
    let unchanged = Recipe {
        name: "the model unchanged",
        fit: Fit::Unchanged,
    };
    let ridges = RIDGE_PENALTIES.iter().map(|&(penalty, name)| Recipe {
        name,
        fit: Fit::Ridge { penalty },
    });
    if !model.network().architecture().trained_by_gradient() {
        return std::iter::once(unchanged).chain(ridges).collect();
    }
    let mut all = vec![
        unchanged,
        Recipe {
            name: "all layers, about 150 steps",
            fit: Fit::Finetune(steps(150)),
        },
        Recipe {
            name: "all layers, about 600 steps",
            fit: Fit::Finetune(steps(600)),
        },
        Recipe {
            name: "output layer only, about 600 steps",
            fit: Fit::Finetune(FinetuneOptions {
                freeze_features: true,
                ..steps(600)
            }),
        },
    ];
    all.extend(ridges);
    all
}

/// All layers trained from the model's own output layer on `n` samples for about `steps`
/// optimiser steps: batches of at most 16, learning rate 2e-4, no early stopping (too few
/// samples to hold some back), between 10 and 400 epochs.
pub fn all_layers(n: usize, steps: usize, seed: u64, backend: Backend) -> FinetuneOptions {
    let batch = 16.min(n.max(1));
    FinetuneOptions {
        schedule: Schedule {
            epochs: (steps / n.max(1).div_ceil(batch)).clamp(10, 400),
            batch,
            lr: 2e-4,
            patience: None,
            plateau: None,
        },
        keep_output: true,
        seed,
        backend,
        ..FinetuneOptions::thesis()
    }
}

/// The rows `rows` of `set`, as a set of their own.
fn subset(set: &TrainingSet, rows: &[usize]) -> Result<TrainingSet> {
    let mut samples = SampleBatch {
        feature_count: set.samples.feature_count,
        spd_len: set.samples.spd_len,
        weight_count: set.samples.weight_count,
        ..SampleBatch::default()
    };
    for &i in rows {
        samples.push(set.samples.row(i))?;
    }
    let mut info = set.info.clone();
    info.samples = rows.len();
    Ok(TrainingSet {
        samples,
        columns: set.columns.clone(),
        info,
    })
}

/// Scores every recipe of [`candidates`] on `data` by k-fold cross-validation (photo `i` in
/// fold `i mod k`) and returns them best first. With too few photos to hold any back, the
/// error says how many are needed. `progress` is told (fits done, fits in all) after each
/// candidate of each fold.
pub fn choose(
    model: &Model,
    data: &TrainingSet,
    seed: u64,
    backend: Backend,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Vec<Scored>> {
    let n = data.samples.len();
    if n < MIN_SAMPLES {
        return Err(LearnError::invalid(format!(
            "{}: {n} sample(s); choosing a fine-tuning recipe holds photos back and needs at least {MIN_SAMPLES} (or give the recipe by hand, e.g. --epochs and --keep-output)",
            data.info.path
        )));
    }
    let folds = FOLDS.min(n / 2);
    let mut sums = vec![0.0; candidates(model, n, seed, backend).len()];
    let fits = folds * sums.len();
    for f in 0..folds {
        let (test, train): (Vec<usize>, Vec<usize>) = (0..n).partition(|i| i % folds == f);
        let test_set = subset(data, &test)?;
        let train_set = subset(data, &train)?;
        for (k, recipe) in candidates(model, train.len(), seed, backend)
            .iter()
            .enumerate()
        {
            // Too few photos to hold some back for early stopping: the training photos
            // validate, as in `spdcam sim2real --finetune`.
            let scored = evaluate(&recipe.fit.run(model, &train_set, seed)?, &test_set)?;
            sums[k] += scored.per_sample.iter().map(|m| m.gfc).sum::<f64>();
            progress(f * sums.len() + k + 1, fits);
        }
    }
    let mut scored: Vec<Scored> = candidates(model, n, seed, backend)
        .into_iter()
        .zip(sums)
        .map(|(recipe, sum)| Scored {
            recipe,
            cv_gfc: sum / n as f64,
        })
        .collect();
    // Best first; a tie keeps the simpler (earlier) recipe.
    scored.sort_by(|a, b| b.cv_gfc.total_cmp(&a.cv_gfc));
    Ok(scored)
}

/// What [`tune`] gives: every recipe scored, best first, and the model the best one made.
#[derive(Debug, Clone)]
pub struct Tuned {
    /// The recipes with their cross-validated scores, best first.
    pub scored: Vec<Scored>,
    /// The model the best recipe gives, trained on all of the data.
    pub model: Model,
}

/// Chooses the recipe by cross-validation on `data` ([`choose`]) and runs the best one on
/// all of `data` (which also validates: too few samples to hold some back). `progress` is
/// told (fits done, fits in all), the last fit being the chosen recipe's.
pub fn tune(
    model: &Model,
    data: &TrainingSet,
    seed: u64,
    backend: Backend,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Tuned> {
    let mut all = 0;
    let scored = choose(model, data, seed, backend, &mut |done, fits| {
        all = fits + 1;
        progress(done, all);
    })?;
    let chosen = scored[0].recipe.fit.run(model, data, seed)?;
    progress(all, all);
    Ok(Tuned {
        scored,
        model: chosen,
    })
}
