//! The options `train`, `finetune` and `experiment` share: the model, its target, the
//! schedule preset, the device, and the schedule's flags.

use anyhow::Result;
use clap::{Args, ValueEnum};
use spdcam_infer::network::{Architecture, CnnSpec, MlpSpec};
use spdcam_learn::train::{Backend, Schedule, TrainingSet};
use std::path::PathBuf;

/// The model to train.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ModelKind {
    /// The thesis's 1D CNN (Table 4.5).
    Cnn1d,
    /// The thesis's DNN (Table 4.1).
    Mlp,
    /// Ridge regression in closed form: the baseline.
    Linear,
}

impl ModelKind {
    /// The architecture with the thesis's layer sizes.
    pub fn architecture(self) -> Architecture {
        match self {
            ModelKind::Cnn1d => Architecture::Cnn1d(CnnSpec::thesis()),
            ModelKind::Mlp => Architecture::Mlp(MlpSpec::thesis()),
            ModelKind::Linear => Architecture::Linear { ridge: 0.0 },
        }
    }
}

/// What the model predicts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum TargetArg {
    /// PCA coefficients of the SPD.
    Pca,
    /// PCA coefficients and the light's u′v′ chromaticity, the spectrum made to have that
    /// colour (`--colour-weight`).
    PcaColour,
    /// The luminaire's channel weights (datasets with weight columns).
    Weights,
}

/// A schedule preset.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Preset {
    /// Ours: measured best on validation data (see docs/learning-results.md).
    Default,
    /// The thesis's: 200 epochs, batch 64, learning rate 1e-3, constant, no early stopping.
    Thesis,
}

/// Where to train.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum DeviceArg {
    /// burn's flex backend on the CPU.
    Cpu,
    /// CUDA GPU 0 (a build with the spdcam-learn feature `cuda`).
    Cuda,
    /// Any GPU through wgpu (a build with the spdcam-learn feature `wgpu`).
    Wgpu,
}

impl DeviceArg {
    /// The library's backend.
    pub fn backend(self) -> Backend {
        match self {
            DeviceArg::Cpu => Backend::Cpu,
            DeviceArg::Cuda => Backend::Cuda,
            DeviceArg::Wgpu => Backend::Wgpu,
        }
    }
}

/// Options shared by `train` and `finetune`: the schedule.
#[derive(Debug, Args)]
pub struct ScheduleArgs {
    /// Most epochs to run (default: the preset's).
    #[arg(long)]
    pub epochs: Option<usize>,
    /// Samples per optimiser step (default: the preset's).
    #[arg(long)]
    pub batch: Option<usize>,
    /// Adam's learning rate (default: the preset's).
    #[arg(long)]
    pub lr: Option<f64>,
    /// Stop after this many epochs without a better validation loss; 0: never.
    #[arg(long)]
    pub patience: Option<usize>,
    /// Seed of the split, initial weights, shuffling and dropout.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Share of the data held out for validation (when no --val set is given).
    #[arg(long, default_value_t = 0.1)]
    pub val_split: f64,
    /// A separate validation dataset (instead of --val-split).
    #[arg(long, value_name = "DIR")]
    pub val: Option<PathBuf>,
    /// Where to train.
    #[arg(long, value_enum, default_value = "cpu")]
    pub device: DeviceArg,
}

impl ScheduleArgs {
    /// The validation dataset of `--val`, read into memory, when given.
    pub fn load_val(&self) -> Result<Option<TrainingSet>> {
        Ok(self.val.as_deref().map(TrainingSet::load).transpose()?)
    }

    /// `base` with the flags given here applied.
    pub fn apply(&self, mut base: Schedule) -> Schedule {
        if let Some(e) = self.epochs {
            base.epochs = e;
        }
        if let Some(b) = self.batch {
            base.batch = b;
        }
        if let Some(lr) = self.lr {
            base.lr = lr;
        }
        if let Some(p) = self.patience {
            base.patience = (p > 0).then_some(p);
        }
        base
    }
}
