//! `spdcam train`: fit a model (1D CNN, MLP or ridge baseline) to a dataset.

mod options;
mod output;

pub use options::{ModelKind, Preset, ScheduleArgs, TargetArg};
pub use output::{reporter, sibling, write_log};

use anyhow::{bail, Result};
use clap::{Args, ValueEnum};
use spdcam_core::builtin::DataDir;
use spdcam_core::error::short_number;
use spdcam_core::fsio;
use spdcam_core::spectral::Grid;
use spdcam_infer::network::Architecture;
use spdcam_infer::pca::Components;
use spdcam_infer::scale::RowScale;
use spdcam_infer::target::TargetKind;
use spdcam_learn::train::{add_photo_chart, train, Schedule, TrainOptions, TrainingSet};
use std::path::PathBuf;

/// The largest `--ridge`: the features are scaled to unit spread, so a penalty of 10⁶ per
/// row already leaves weights a millionth of the unpenalised ones; far larger ones
/// (1e308) overflow the solver's sums.
const MAX_RIDGE: f64 = 1e6;

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
    /// With `--target pca-colour`: how much each of the two colour outputs (u′, v′) weighs
    /// in the training loss against one PCA coefficient.
    #[arg(long, default_value = "1", value_name = "WEIGHT")]
    colour_weight: f64,
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

/// Runs `spdcam train`.
pub fn run(args: TrainArgs, data_dir: &DataDir) -> Result<()> {
    fsio::check_writable(&args.output)?;
    for path in args.log.iter().chain(&args.plot) {
        fsio::check_writable(path)?;
    }
    let architecture = match (args.model, args.ridge) {
        (ModelKind::Linear, Some(ridge)) if ridge > 0.0 && ridge <= MAX_RIDGE => {
            Architecture::Linear { ridge }
        }
        (ModelKind::Linear, Some(ridge)) if ridge > MAX_RIDGE => bail!(
            "--ridge {} is too large for the solver: the penalty times the training rows \
             must stay a finite number, and above {} the weights are zero anyway; give a \
             positive value up to {} (or leave --ridge out to choose among 1e-8…1 on the \
             validation rows)",
            short_number(ridge),
            short_number(MAX_RIDGE),
            short_number(MAX_RIDGE)
        ),
        (ModelKind::Linear, Some(ridge)) => bail!(
            "--ridge {} must be a positive number up to {}",
            short_number(ridge),
            short_number(MAX_RIDGE)
        ),
        (_, Some(_)) => bail!("--ridge applies to --model linear only"),
        (kind, None) => kind.architecture(),
    };
    let data = TrainingSet::load(&args.data)?;
    let val = args.schedule.load_val()?;
    let base = match args.preset {
        Preset::Thesis => Schedule::thesis(),
        Preset::Default => Schedule::default_for(&architecture),
    };
    let options = TrainOptions {
        target: match args.target {
            TargetArg::Pca => TargetKind::Pca(parse_components(&args.components)?),
            TargetArg::PcaColour => TargetKind::PcaColour {
                components: parse_components(&args.components)?,
                colour_weight: args.colour_weight,
            },
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
