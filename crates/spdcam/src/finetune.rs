//! `spdcam finetune`: the thesis's transfer learning (section 6.4) — a new output layer, then
//! all layers (or only the new one) trained on a small dataset of the new camera or lights.
//! With no recipe flags, the recipe is chosen by cross-validation on the data given
//! (`spdcam_learn::recipe`), the model left unchanged among the candidates.

use crate::train::{reporter, sibling, write_log, ScheduleArgs};
use anyhow::Result;
use clap::Args;
use spdcam_core::fsio;
use spdcam_infer::model::Model;
use spdcam_learn::recipe;
use spdcam_learn::train::{finetune, FinetuneOptions, TrainingSet};
use std::path::PathBuf;

/// Options of `spdcam finetune`. Without --freeze, --refit-pca, --keep-output, --epochs,
/// --batch, --lr or --patience the recipe is chosen by 5-fold cross-validation on the data.
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

impl FinetuneArgs {
    /// Whether a flag gives the recipe by hand.
    fn recipe_given(&self) -> bool {
        let s = &self.schedule;
        self.freeze
            || self.refit_pca
            || self.keep_output
            || s.epochs.is_some()
            || s.batch.is_some()
            || s.lr.is_some()
            || s.patience.is_some()
    }
}

/// Runs `spdcam finetune`.
pub fn run(args: FinetuneArgs) -> Result<()> {
    fsio::check_writable(&args.output)?;
    let model = Model::load(&args.model)?;
    let data = TrainingSet::load(&args.data)?;
    if !args.recipe_given() {
        return run_chosen(&args, &model, &data);
    }
    let val = args.schedule.load_val()?;
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

/// Chooses the recipe by cross-validation on `data`, prints every candidate's score, and
/// writes the model the best one gives (trained on all of `data`).
fn run_chosen(args: &FinetuneArgs, model: &Model, data: &TrainingSet) -> Result<()> {
    let backend = args.schedule.device.backend();
    println!(
        "choosing a fine-tuning recipe for {} by {}-fold cross-validation on {} ({} samples)",
        args.model.display(),
        recipe::FOLDS.min(data.samples.len() / 2),
        args.data.display(),
        data.samples.len()
    );
    let tuned = recipe::tune(model, data, args.schedule.seed, backend, &mut |_, _| {})?;
    let scored = &tuned.scored;
    for s in scored {
        println!(
            "  {:<40} cross-validated GFC {:.5}",
            s.recipe.name, s.cv_gfc
        );
    }
    let best = &scored[0];
    tuned.model.save(&args.output)?;
    println!(
        "chosen: {} (cross-validated GFC {:.5}) → {}",
        best.recipe.name,
        best.cv_gfc,
        args.output.display()
    );
    Ok(())
}
