//! How a model was trained, as its file records it: the data, the settings and the outcome.
//! Plain data, so reading a model needs no training code.

use crate::error::{InferError, Result};
use crate::network::Architecture;
use crate::scale::RowScale;
use crate::target::TargetKind;
use serde::{Deserialize, Serialize};
use spdcam_core::dataset::Dataset;
use spdcam_core::spectral::Grid;
use std::collections::BTreeMap;

/// Where the networks train.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Backend {
    /// burn's flex backend on the CPU (always available).
    #[default]
    Cpu,
    /// burn's CUDA backend, GPU 0 (cargo feature `cuda`).
    Cuda,
    /// burn's wgpu backend, the default adapter (cargo feature `wgpu`).
    Wgpu,
}

/// The optimisation schedule.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Schedule {
    /// The most epochs to run.
    pub epochs: usize,
    /// Samples per optimiser step.
    pub batch: usize,
    /// Adam's initial learning rate.
    pub lr: f64,
    /// Stop after this many epochs without a better validation loss (`None`: run all).
    pub patience: Option<usize>,
    /// Halve the learning rate after this many epochs without improvement (`None`: constant).
    pub plateau: Option<usize>,
}

impl Schedule {
    /// The thesis's set-up: 200 epochs, batch 64, learning rate 1e-3, constant, no early
    /// stopping (the best validation epoch is still the one kept).
    pub fn thesis() -> Schedule {
        Schedule {
            epochs: 200,
            batch: 64,
            lr: 1e-3,
            patience: None,
            plateau: None,
        }
    }

    /// Our default, chosen by validation measurements (docs/learning-results.md): larger
    /// batches run faster per epoch on a CPU, and halving the learning rate on plateaus
    /// reaches a lower loss than a constant rate.
    pub fn default_for(architecture: &Architecture) -> Schedule {
        match architecture {
            Architecture::Mlp(_) => Schedule {
                epochs: 400,
                batch: 128,
                lr: 1e-3,
                patience: Some(30),
                plateau: Some(8),
            },
            _ => Schedule {
                epochs: 300,
                batch: 128,
                lr: 2e-3,
                patience: Some(25),
                plateau: Some(6),
            },
        }
    }

    /// Checks that the schedule can run: at least one epoch and sample, a positive rate.
    pub fn validate(&self) -> Result<()> {
        if self.epochs == 0 || self.batch == 0 {
            return Err(InferError::invalid(format!(
                "epochs ({}) and batch size ({}) must be at least 1",
                self.epochs, self.batch
            )));
        }
        if !(self.lr.is_finite() && self.lr > 0.0) {
            return Err(InferError::invalid(format!(
                "the learning rate {} must be positive",
                self.lr
            )));
        }
        Ok(())
    }
}

/// Everything a training run needs besides the data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrainOptions {
    /// The model.
    pub architecture: Architecture,
    /// PCA coefficients or channel weights.
    pub target: TargetKind,
    /// What each feature row is divided by (records from before it, and records that leave
    /// it out: the maximum).
    #[serde(default, skip_serializing_if = "RowScale::is_max")]
    pub row_scale: RowScale,
    /// The grid the model estimates SPDs on (a sub-grid of the dataset's).
    pub grid: Grid,
    /// The optimisation schedule (ignored by `linear`).
    pub schedule: Schedule,
    /// Seed of the split, the initial weights, the shuffling and the dropout.
    pub seed: u64,
    /// The share of the data held out for validation when no validation set is given.
    pub val_split: f64,
    /// Where to train.
    pub backend: Backend,
}

/// Where a training (or validation) set came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DataInfo {
    /// The dataset directory as given on the command line (or a description).
    pub path: String,
    /// Number of samples.
    pub samples: usize,
    /// The chart the features were taken from, when known.
    pub chart: Option<String>,
    /// The camera, when known.
    pub camera: Option<String>,
    /// Samples per light family.
    pub families: BTreeMap<String, u64>,
    /// The dataset manifest's `origin` (generation settings, import source…).
    pub origin: Option<serde_json::Value>,
}

impl DataInfo {
    /// The description of an opened dataset directory, labelled `path`.
    pub fn from_dataset(dataset: &Dataset, path: &str) -> DataInfo {
        let manifest = dataset.manifest();
        let generated = manifest.origin.generated();
        DataInfo {
            path: path.to_string(),
            samples: manifest.samples as usize,
            chart: generated.map(|g| g.chart.name.clone()),
            camera: generated.map(|g| g.camera.name.clone()),
            families: manifest.families.clone(),
            origin: serde_json::to_value(&manifest.origin).ok(),
        }
    }
}

/// How a model was trained.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrainingRecord {
    /// The training data.
    pub data: DataInfo,
    /// A separate validation set, when one was given.
    pub validation: Option<DataInfo>,
    /// Rows trained on.
    pub train_samples: usize,
    /// Rows validated on.
    pub val_samples: usize,
    /// The settings.
    pub options: TrainOptions,
    /// Epochs run (0 for `linear`).
    pub epochs_run: usize,
    /// The epoch whose weights were kept.
    pub best_epoch: usize,
    /// Validation loss (MSE of the scaled targets) of the kept weights.
    pub val_loss: f64,
    /// Mean validation GFC of the kept weights.
    pub val_gfc: f64,
    /// Wall-clock seconds of the whole run.
    pub seconds: f64,
    /// The training of the model this one was fine-tuned from.
    pub finetuned_from: Option<Box<TrainingRecord>>,
}
