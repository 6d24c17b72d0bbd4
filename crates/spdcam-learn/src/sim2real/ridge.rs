//! The ablation's ridge regression from features to the SPD: its inputs and targets,
//! trained on virtual samples or on real photos, and scored on real photos.

use super::GRID;
use crate::error::Result;
use spdcam_core::camera::Camera;
use spdcam_core::dataset::randomise::Randomisation;
use spdcam_core::dataset::{GenerateOptions, Generator, MeasuredPhotos, Pipeline};
use spdcam_core::light_families::Lighting;
use spdcam_core::spectral_error;
use spdcam_infer::ridge::Ridge;

/// Input vector: features divided by their mean (removes exposure), and a bias.
///
/// ```
/// use spdcam_learn::sim2real::ridge::inputs;
///
/// assert_eq!(inputs(&[1.0, 3.0]), [0.5, 1.5, 1.0]);
/// ```
pub fn inputs(features: &[f64]) -> Vec<f64> {
    let mean = features.iter().sum::<f64>() / features.len() as f64;
    let mut x: Vec<f64> = features.iter().map(|v| v / mean.max(1e-9)).collect();
    x.push(1.0);
    x
}

/// The SPD at 400–700 nm / 10 nm from values on [`GRID`] (the simulation grid),
/// normalised to a maximum of 1.
pub fn target(spd: &[f64]) -> Vec<f64> {
    let v: Vec<f64> = (0..31)
        .map(|k| {
            let nm = 400.0 + 10.0 * k as f64;
            spd[((nm - GRID.start_nm) / GRID.step_nm).round() as usize]
        })
        .collect();
    spdcam_core::spectral::normalise_by_max(&v)
}

/// Mean GFC of `model` on the photos `indices` of `set`.
pub fn score(model: &Ridge, set: &MeasuredPhotos, indices: &[usize]) -> Result<f64> {
    let mut total = 0.0;
    for &i in indices {
        let truth = target(&set.spds[i]);
        let est = model.predict_non_negative(&inputs(&set.features[i]));
        total += spectral_error::gfc(&truth, &est).unwrap_or(0.0);
    }
    Ok(total / indices.len() as f64)
}

/// Ridge (penalty `ridge`, relative) trained on `count` virtual samples of `camera`
/// (optionally randomised) under `lighting`.
pub fn train_virtual(
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

/// Ridge fitted on the photos `train` of `set` and scored on the photos `test`, the
/// penalty chosen by `folds`-fold cross-validation on `train`, shrunk towards `prior`
/// (none: towards zero).
pub fn fit_and_score(
    set: &MeasuredPhotos,
    train: &[usize],
    test: &[usize],
    folds: usize,
    prior: Option<&Ridge>,
) -> Result<f64> {
    let x: Vec<Vec<f64>> = train.iter().map(|&i| inputs(&set.features[i])).collect();
    let y: Vec<Vec<f64>> = train.iter().map(|&i| target(&set.spds[i])).collect();
    score(&Ridge::fit_cv(&x, &y, folds, prior)?, set, test)
}

/// Ridge trained and tested on real photos (k-fold; the penalty chosen by an inner
/// cross-validation on the training folds), the reference.
pub fn real_to_real(set: &MeasuredPhotos, folds: usize) -> Result<f64> {
    let n = set.features.len();
    let mut total = 0.0;
    for f in 0..folds {
        let (test, train): (Vec<usize>, Vec<usize>) = (0..n).partition(|i| i % folds == f);
        total += fit_and_score(set, &train, &test, folds, None)? * test.len() as f64;
    }
    Ok(total / n as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_target_reads_every_other_simulation_sample_and_peaks_at_one() {
        let spd: Vec<f64> = GRID.wavelengths().iter().map(|nm| nm / 10.0).collect();
        let t = target(&spd);
        assert_eq!(t.len(), 31);
        assert_eq!(t[30], 1.0);
        assert!((t[0] - 400.0 / 700.0).abs() < 1e-12);
    }
}
