//! Choosing how to fine-tune on a few photos of one's own: each candidate recipe (the model
//! left as it is among them) is scored by k-fold cross-validation on the photos given (mean
//! GFC of the held-out fold, every photo held out once; Hastie, Tibshirani & Friedman, *The
//! Elements of Statistical Learning*, 2nd ed., §7.10), and the best one is then run on all
//! of them. Leaving the model unchanged is a candidate, so a recipe that does not help on
//! held-out photos is never chosen.

use crate::error::{LearnError, Result};
use crate::evaluate::evaluate;
use crate::model::Model;
use crate::record::{Backend, Schedule};
use crate::train::{finetune, FinetuneOptions, TrainingSet};
use spdcam_core::dataset::SampleBatch;

/// Fewest samples a recipe can be chosen on: two folds of at least two photos.
pub const MIN_SAMPLES: usize = 4;
/// Cross-validation folds (fewer when there are fewer photos).
pub const FOLDS: usize = 5;

/// A fine-tuning recipe `choose` weighs.
#[derive(Debug, Clone)]
pub struct Recipe {
    /// What it does, in a few words.
    pub name: &'static str,
    /// The fine-tuning; `None` leaves the model as it is.
    pub options: Option<FinetuneOptions>,
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
/// layers frozen, for 600 steps.
pub fn candidates(n: usize, seed: u64, backend: Backend) -> Vec<Recipe> {
    let steps = |count: usize| all_layers(n, count, seed, backend);
    vec![
        Recipe {
            name: "the model unchanged",
            options: None,
        },
        Recipe {
            name: "all layers, about 150 steps",
            options: Some(steps(150)),
        },
        Recipe {
            name: "all layers, about 600 steps",
            options: Some(steps(600)),
        },
        Recipe {
            name: "output layer only, about 600 steps",
            options: Some(FinetuneOptions {
                freeze_features: true,
                ..steps(600)
            }),
        },
    ]
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
    let mut sums = vec![0.0; candidates(n, seed, backend).len()];
    let fits = folds * sums.len();
    for f in 0..folds {
        let (test, train): (Vec<usize>, Vec<usize>) = (0..n).partition(|i| i % folds == f);
        let test_set = subset(data, &test)?;
        let train_set = subset(data, &train)?;
        for (k, recipe) in candidates(train.len(), seed, backend).iter().enumerate() {
            let scored = match &recipe.options {
                None => evaluate(model, &test_set)?,
                Some(options) => {
                    // Too few photos to hold some back for early stopping: the training
                    // photos validate, as in `spdcam sim2real --finetune`.
                    let tuned =
                        finetune(model, &train_set, Some(&train_set), options, &mut |_| {})?;
                    evaluate(&tuned.model, &test_set)?
                }
            };
            sums[k] += scored.per_sample.iter().map(|m| m.gfc).sum::<f64>();
            progress(f * sums.len() + k + 1, fits);
        }
    }
    let mut scored: Vec<Scored> = candidates(n, seed, backend)
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
    let chosen = match &scored[0].recipe.options {
        None => model.clone(),
        Some(options) => finetune(model, data, Some(data), options, &mut |_| {})?.model,
    };
    progress(all, all);
    Ok(Tuned {
        scored,
        model: chosen,
    })
}
