//! `spdcam train`: fit a model (1D CNN, MLP or ridge baseline) to a dataset.

use anyhow::{bail, Result};
use clap::{Args, ValueEnum};
use spdcam_core::builtin::DataDir;
use spdcam_core::fsio;
use spdcam_core::spectral::Grid;
use spdcam_learn::evaluate::loss_curve_svg;
use spdcam_learn::network::{Architecture, CnnSpec, MlpSpec};
use spdcam_learn::pca::Components;
use spdcam_learn::scale::RowScale;
use spdcam_learn::target::TargetKind;
use spdcam_learn::train::{
    add_photo_chart, train, Backend, EpochRecord, Progress, Schedule, TrainOptions, TrainingSet,
};
use std::path::{Path, PathBuf};

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

/// `--row-scale`: what each feature row is divided by.
#[derive(Debug, Clone, Copy, ValueEnum)]
enum RowScaleArg {
    /// Its maximum.
    Max,
    /// Its mean.
    Mean,
}

/// Options of `spdcam train`.
#[derive(Debug, Args)]
pub struct TrainArgs {
    /// The dataset directory (from `spdcam generate` or `spdcam dataset import`).
    #[arg(long, value_name = "DIR")]
    data: PathBuf,
    /// The model.
    #[arg(long, value_enum)]
    model: ModelKind,
    /// With `--model linear`: a fixed ridge penalty (per sample, on the scaled features)
    /// instead of the one the validation rows choose. A strong penalty transfers better to
    /// real photos than the best fit to virtual ones.
    #[arg(long, value_name = "LAMBDA")]
    ridge: Option<f64>,
    /// The model file to write (.spdm).
    #[arg(short, long)]
    output: PathBuf,
    /// What the model predicts.
    #[arg(long, value_enum, default_value = "pca")]
    target: TargetArg,
    /// PCA components: an explained-variance share (0.99) or a count (12).
    #[arg(long, default_value = "0.99")]
    components: String,
    /// What each feature row is divided by before scaling: its maximum (the thesis) or its
    /// mean (no single clipped or glare-lit patch sets the scale).
    #[arg(long, value_enum, default_value = "max")]
    row_scale: RowScaleArg,
    /// Schedule preset; --epochs, --batch, --lr and --patience override it.
    #[arg(long, value_enum, default_value = "default")]
    preset: Preset,
    /// Wavelength grid of the estimates, START-END[:STEP] in nm.
    #[arg(long, default_value = "400-700:5", value_name = "START-END[:STEP]")]
    grid: String,
    /// Training log CSV; default: the model file with `.log.csv`.
    #[arg(long)]
    log: Option<PathBuf>,
    /// Loss-curve SVG; default: the model file with `.loss.svg`.
    #[arg(long)]
    plot: Option<PathBuf>,
    #[command(flatten)]
    schedule: ScheduleArgs,
}

/// Parses `0.99` (a share) or `12` (a count).
fn parse_components(text: &str) -> Result<Components> {
    if let Ok(n) = text.parse::<usize>() {
        return Ok(Components::Count(n));
    }
    match text.parse::<f64>() {
        Ok(f) if f > 0.0 && f <= 1.0 => Ok(Components::Variance(f)),
        _ => {
            bail!("--components {text}: give a share in (0, 1] such as 0.99, or a count such as 12")
        }
    }
}

/// `path` with its extension replaced by `suffix` (e.g. `.log.csv`).
pub fn sibling(path: &Path, suffix: &str) -> PathBuf {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!("{stem}{suffix}"))
}

/// A progress reporter: a bar per run on a terminal (epoch, loss, validation loss and GFC),
/// one plain line per epoch when stderr is not a terminal.
pub fn reporter(epochs: usize) -> (impl FnMut(Progress), Option<indicatif::ProgressBar>) {
    use std::io::IsTerminal;
    let bar = std::io::stderr().is_terminal().then(|| {
        let style = indicatif::ProgressStyle::with_template(
            "{elapsed_precise} [{wide_bar}] epoch {pos}/{len}, ETA {eta} {msg}",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
        indicatif::ProgressBar::new(epochs as u64).with_style(style)
    });
    let handle = bar.clone();
    let report = move |p: Progress| {
        let Progress::Epoch(r) = p else {
            return;
        };
        let line = format!(
            "loss {:.3e}, val loss {:.3e}, val GFC {:.5}, {:.1} s/epoch",
            r.train_loss, r.val_loss, r.val_gfc, r.seconds
        );
        match &bar {
            Some(bar) => {
                bar.set_position(r.epoch as u64);
                bar.set_message(line);
            }
            // Not a terminal (a log file, a batch job): one plain line per epoch.
            None => eprintln!("epoch {}/{epochs}: {line}", r.epoch),
        }
    };
    (report, handle)
}

/// Writes the training log CSV and the loss curve.
pub fn write_log(log: &[EpochRecord], best: usize, csv: &Path, svg: &Path) -> Result<()> {
    let mut text = String::from("epoch,train_loss,val_loss,val_gfc,lr,seconds\n");
    for r in log {
        text.push_str(&format!(
            "{},{:.6e},{:.6e},{:.6},{:.3e},{:.3}\n",
            r.epoch, r.train_loss, r.val_loss, r.val_gfc, r.lr, r.seconds
        ));
    }
    fsio::write_atomic(csv, text.as_bytes())?;
    fsio::write_atomic(svg, loss_curve_svg(log, best)?.as_bytes())?;
    println!("  log:      {}", csv.display());
    println!("  plot:     {}", svg.display());
    Ok(())
}

/// Runs `spdcam train`.
pub fn run(args: TrainArgs, data_dir: &DataDir) -> Result<()> {
    fsio::check_writable(&args.output)?;
    for path in args.log.iter().chain(&args.plot) {
        fsio::check_writable(path)?;
    }
    let data = TrainingSet::load(&args.data)?;
    let val = args.schedule.load_val()?;
    let architecture = match (args.model, args.ridge) {
        (ModelKind::Linear, Some(ridge)) if ridge.is_finite() && ridge > 0.0 => {
            Architecture::Linear { ridge }
        }
        (ModelKind::Linear, Some(ridge)) => bail!("--ridge {ridge} must be a positive number"),
        (_, Some(_)) => bail!("--ridge applies to --model linear only"),
        (kind, None) => kind.architecture(),
    };
    let base = match args.preset {
        Preset::Thesis => Schedule::thesis(),
        Preset::Default => Schedule::default_for(&architecture),
    };
    let options = TrainOptions {
        target: match args.target {
            TargetArg::Pca => TargetKind::Pca(parse_components(&args.components)?),
            TargetArg::Weights => TargetKind::Weights,
        },
        row_scale: match args.row_scale {
            RowScaleArg::Max => RowScale::Max,
            RowScaleArg::Mean => RowScale::Mean,
        },
        grid: Grid::parse(&args.grid)?,
        schedule: args.schedule.apply(base),
        seed: args.schedule.seed,
        val_split: args.schedule.val_split,
        backend: args.schedule.device.backend(),
        architecture,
    };
    println!(
        "training {} on {} ({} samples)",
        args.model
            .to_possible_value()
            .map(|v| v.get_name().to_string())
            .unwrap_or_default(),
        args.data.display(),
        data.samples.len()
    );
    let (mut report, bar) = reporter(options.schedule.epochs);
    let trained = train(&data, val.as_ref(), &options, &mut report)?;
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    let mut model = trained.model;
    add_photo_chart(&mut model, data_dir)?;
    model.save(&args.output)?;
    let t = model.training();
    println!(
        "  model:    {} — {}",
        args.output.display(),
        model.describe()
    );
    println!(
        "  kept:     epoch {} of {} run; validation GFC {:.5}, loss {:.3e}; {:.1} s",
        t.best_epoch, t.epochs_run, t.val_gfc, t.val_loss, t.seconds
    );
    if !trained.log.is_empty() {
        let csv = args
            .log
            .unwrap_or_else(|| sibling(&args.output, ".log.csv"));
        let svg = args
            .plot
            .unwrap_or_else(|| sibling(&args.output, ".loss.svg"));
        write_log(&trained.log, t.best_epoch, &csv, &svg)?;
    }
    Ok(())
}
