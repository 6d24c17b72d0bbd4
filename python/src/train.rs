//! Training and fine-tuning from Python (`spdcam.train`, `spdcam.finetune`): the same
//! library runs as `spdcam train` and `spdcam finetune`. Built only with the cargo feature
//! `train`, the one part of the binding that needs `spdcam-learn` and so burn.

use crate::{py_err, Models, Reporter, SpdcamError};
use pyo3::prelude::*;
use spdcam_core::builtin::DataDir;
use spdcam_core::fsio;
use spdcam_core::output_guard::{check_outputs, file_output, named};
use spdcam_core::spectral::Grid;
use spdcam_infer::network::{Architecture, CnnSpec, MlpSpec};
use spdcam_infer::pca::Components;
use spdcam_infer::scale::RowScale;
use spdcam_infer::target::TargetKind;
use spdcam_infer::{Model, ModelSet};
use spdcam_learn::recipe;
use spdcam_learn::train::{
    add_photo_chart, Backend, FinetuneOptions, Progress, Schedule, TrainOptions, TrainingSet,
};
use std::path::{Path, PathBuf};

/// The thesis's architecture `spdcam train --model` names: cnn1d, mlp or linear.
fn architecture(model: &str) -> PyResult<Architecture> {
    match model {
        "cnn1d" => Ok(Architecture::Cnn1d(CnnSpec::thesis())),
        "mlp" => Ok(Architecture::Mlp(MlpSpec::thesis())),
        "linear" => Ok(Architecture::Linear { ridge: 0.0 }),
        other => Err(SpdcamError::new_err(format!(
            "unknown model '{other}'; valid: cnn1d, mlp, linear"
        ))),
    }
}

/// Saves `model` at `path` and loads it back as a model set named by the path.
fn saved(model: &Model, path: &Path) -> Result<Models, spdcam_learn::LearnError> {
    model.save(path)?;
    Ok(Models::of(ModelSet::single(
        Model::load(path)?,
        path.display().to_string(),
    ))?)
}

/// A training loop's progress as epochs done of `epochs`.
fn epoch_progress(reporter: &Reporter, epochs: usize) -> impl FnMut(Progress) + '_ {
    reporter.at(0, epochs as u64);
    move |p| {
        if let Progress::Epoch(r) = p {
            reporter.at(r.epoch as u64, epochs as u64);
        }
    }
}

/// Trains a model on the dataset in `data` as `spdcam train --data DATA --model MODEL
/// --output OUTPUT` does (the default preset, PCA target of 99 % variance, 400–700:5 nm,
/// a tenth held out for validation), `epochs` overriding the preset's; writes the model
/// file and returns it loaded from there.
#[pyfunction]
#[pyo3(signature = (data, output, model="cnn1d", epochs=None, seed=1, progress=None))]
fn train(
    py: Python<'_>,
    data: PathBuf,
    output: PathBuf,
    model: &str,
    epochs: Option<usize>,
    seed: u64,
    progress: Option<Py<PyAny>>,
) -> PyResult<Models> {
    let architecture = architecture(model)?;
    let reporter = Reporter::new(progress);
    let models = py
        .allow_threads(|| -> Result<_, spdcam_learn::LearnError> {
            check_outputs(&[named("data=", &data)], &[file_output("output=", &output)])?;
            fsio::check_writable(&output)?;
            let set = TrainingSet::load(&data)?;
            let mut schedule = Schedule::default_for(&architecture);
            schedule.epochs = epochs.unwrap_or(schedule.epochs);
            let options = TrainOptions {
                row_scale: RowScale::Max,
                target: TargetKind::Pca(Components::Variance(0.99)),
                grid: Grid::parse("400-700:5")?,
                schedule,
                seed,
                val_split: 0.1,
                backend: Backend::Cpu,
                architecture,
            };
            let mut on_epoch = epoch_progress(&reporter, options.schedule.epochs);
            let mut model = spdcam_learn::train::train(&set, None, &options, &mut on_epoch)?.model;
            add_photo_chart(&mut model, &DataDir::new(None))?;
            saved(&model, &output)
        })
        .map_err(py_err)?;
    reporter.finish()?;
    Ok(models)
}

/// Fine-tunes the model file `model` on the dataset in `data` as `spdcam finetune` does:
/// with none of `epochs`, `freeze`, `refit_pca` and `keep_output` the recipe is chosen by
/// cross-validation on the data (progress counts the fits), else the thesis's recipe with
/// those changes (progress counts epochs). Writes `output` and returns it loaded.
#[pyfunction]
#[pyo3(signature = (model, data, output, epochs=None, freeze=false, refit_pca=false, keep_output=false, seed=1, progress=None))]
#[allow(clippy::too_many_arguments)]
fn finetune(
    py: Python<'_>,
    model: PathBuf,
    data: PathBuf,
    output: PathBuf,
    epochs: Option<usize>,
    freeze: bool,
    refit_pca: bool,
    keep_output: bool,
    seed: u64,
    progress: Option<Py<PyAny>>,
) -> PyResult<Models> {
    let reporter = Reporter::new(progress);
    let models = py
        .allow_threads(|| -> Result<_, spdcam_learn::LearnError> {
            check_outputs(
                &[named("model=", &model), named("data=", &data)],
                &[file_output("output=", &output)],
            )?;
            fsio::check_writable(&output)?;
            let pretrained = Model::load(&model)?;
            let set = TrainingSet::load(&data)?;
            let tuned = if freeze || refit_pca || keep_output || epochs.is_some() {
                let base = FinetuneOptions::thesis();
                let options = FinetuneOptions {
                    schedule: Schedule {
                        epochs: epochs.unwrap_or(base.schedule.epochs),
                        ..base.schedule
                    },
                    freeze_features: freeze,
                    refit_pca,
                    keep_output,
                    seed,
                    val_split: 0.1,
                    backend: Backend::Cpu,
                };
                let mut on_epoch = epoch_progress(&reporter, options.schedule.epochs);
                spdcam_learn::train::finetune(&pretrained, &set, None, &options, &mut on_epoch)?
                    .model
            } else {
                let mut on_fit = |done: usize, all: usize| reporter.at(done as u64, all as u64);
                recipe::tune(&pretrained, &set, seed, Backend::Cpu, &mut on_fit)?.model
            };
            saved(&tuned, &output)
        })
        .map_err(py_err)?;
    reporter.finish()?;
    Ok(models)
}

/// Adds `train` and `finetune` to the module `m` (their presence tells the Python package
/// that this build trains).
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(train, m)?)?;
    m.add_function(wrap_pyfunction!(finetune, m)?)?;
    Ok(())
}
