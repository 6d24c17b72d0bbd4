//! `spdcam finetune`: the thesis's transfer learning (section 6.4) — a new output layer, then
//! all layers (or only the new one) trained on a small dataset of the new camera or lights.

use crate::train::{load_set, reporter, sibling, write_log, ScheduleArgs};
use anyhow::Result;
use clap::Args;
use spdcam_core::fsio;
use spdcam_learn::model::Model;
use spdcam_learn::train::{finetune, FinetuneOptions};
use std::path::PathBuf;

/// Options of `spdcam finetune`.
#[derive(Debug, Args)]
pub struct FinetuneArgs {
    /// The pretrained model.
    #[arg(long)]
    model: PathBuf,
    /// The (small) dataset to adapt to.
    #[arg(long, value_name = "DIR")]
    data: PathBuf,
    /// The model file to write.
    #[arg(short, long)]
    output: PathBuf,
    /// Train only the new output layer; keep the feature layers fixed.
    #[arg(long)]
    freeze: bool,
    /// Fit a new PCA (same number of components) on the new data.
    #[arg(long, conflicts_with = "keep_output")]
    refit_pca: bool,
    /// Keep the trained output layer instead of a new one (for a few dozen samples).
    #[arg(long)]
    keep_output: bool,
    #[command(flatten)]
    schedule: ScheduleArgs,
}

/// Runs `spdcam finetune`.
pub fn run(args: FinetuneArgs) -> Result<()> {
    fsio::check_writable(&args.output)?;
    let model = Model::load(&args.model)?;
    let data = load_set(&args.data)?;
    let val = args.schedule.val.as_deref().map(load_set).transpose()?;
    let base = FinetuneOptions::thesis();
    let options = FinetuneOptions {
        schedule: args.schedule.apply(base.schedule),
        freeze_features: args.freeze,
        refit_pca: args.refit_pca,
        keep_output: args.keep_output,
        seed: args.schedule.seed,
        val_split: args.schedule.val_split,
        backend: args.schedule.device.backend(),
    };
    println!(
        "fine-tuning {} on {} ({} samples)",
        args.model.display(),
        args.data.display(),
        data.samples.len()
    );
    let (mut report, bar) = reporter(options.schedule.epochs);
    let trained = finetune(&model, &data, val.as_ref(), &options, &mut report)?;
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    trained.model.save(&args.output)?;
    let t = trained.model.training();
    println!(
        "  model:    {} — {}",
        args.output.display(),
        trained.model.describe()
    );
    println!(
        "  kept:     epoch {} of {} run; validation GFC {:.5} (before: {:.5} on its own data)",
        t.best_epoch,
        t.epochs_run,
        t.val_gfc,
        model.training().val_gfc
    );
    write_log(
        &trained.log,
        t.best_epoch,
        &sibling(&args.output, ".log.csv"),
        &sibling(&args.output, ".loss.svg"),
    )
}
