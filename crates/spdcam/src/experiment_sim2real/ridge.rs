//! The ablation's ridge regression from features to the SPD: its inputs and targets,
//! trained on virtual samples or on real photos, and scored on real photos.

use super::GRID;
use anyhow::Result;
use spdcam_core::camera::Camera;
use spdcam_core::dataset::randomise::Randomisation;
use spdcam_core::dataset::{GenerateOptions, Generator, MeasuredPhotos, Pipeline};
use spdcam_core::lighting::Lighting;
use spdcam_core::metrics;
use spdcam_learn::ridge::Ridge;

/// Input vector: features divided by their mean (removes exposure), and a bias.
pub(super) fn inputs(features: &[f64]) -> Vec<f64> {
    let mean = features.iter().sum::<f64>() / features.len() as f64;
    let mut x: Vec<f64> = features.iter().map(|v| v / mean.max(1e-9)).collect();
    x.push(1.0);
    x
}

/// The SPD at 400–700 nm / 10 nm from the simulation grid, normalised to a maximum of 1.
pub(super) fn target(spd: &[f64]) -> Vec<f64> {
    let v: Vec<f64> = (0..31)
        .map(|k| {
            let nm = 400.0 + 10.0 * k as f64;
            spd[((nm - GRID.start_nm) / GRID.step_nm).round() as usize]
        })
        .collect();
    metrics::normalise_by_max(&v)
}

/// Mean GFC of `model` on the photos `indices`.
pub(super) fn score(model: &Ridge, set: &MeasuredPhotos, indices: &[usize]) -> Result<f64> {
    let mut total = 0.0;
    for &i in indices {
        let truth = target(&set.spds[i]);
        let est = model.predict_non_negative(&inputs(&set.features[i]));
        total += metrics::gfc(&truth, &est).unwrap_or(0.0);
    }
    Ok(total / indices.len() as f64)
}

/// Trains on `count` virtual samples of `camera` (optionally randomised).
pub(super) fn train_virtual(
    camera: &Camera,
    randomisation: Option<&Randomisation>,
    lighting: &Lighting,
    count: u64,
    ridge: f64,
) -> Result<Ridge> {
    let mut options = GenerateOptions::new(count, 1);
    options.pipeline = Pipeline::Fast;
    let mut generator = Generator::new(camera, lighting, options)?;
    if let Some(r) = randomisation {
        generator = generator.with_randomisation(r)?;
    }
    let batch = generator.samples(0..count, None, &|_| {})?;
    let x: Vec<Vec<f64>> = (0..batch.len())
        .map(|i| inputs(batch.features_of(i)))
        .collect();
    let y: Vec<Vec<f64>> = (0..batch.len()).map(|i| target(batch.spd_of(i))).collect();
    Ok(Ridge::fit(&x, &y, ridge, None)?)
}

/// Ridge trained and tested on real photos (k-fold; the penalty chosen by an inner
/// cross-validation on the training folds), the reference.
pub(super) fn real_to_real(set: &MeasuredPhotos, folds: usize) -> Result<f64> {
    let n = set.features.len();
    let mut total = 0.0;
    for f in 0..folds {
        let (test, train): (Vec<usize>, Vec<usize>) = (0..n).partition(|i| i % folds == f);
        let x: Vec<Vec<f64>> = train.iter().map(|&i| inputs(&set.features[i])).collect();
        let y: Vec<Vec<f64>> = train.iter().map(|&i| target(&set.spds[i])).collect();
        total += score(&Ridge::fit_cv(&x, &y, folds, None)?, set, &test)? * test.len() as f64;
    }
    Ok(total / n as f64)
}
