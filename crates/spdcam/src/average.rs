//! `spdcam average`: one model that estimates the mean of several trained models' outputs
//! (an ensemble; `spdcam_infer::network::Architecture::Average`).

use anyhow::{bail, Result};
use clap::Args;
use spdcam_core::fsio;
use spdcam_infer::Model;
use std::path::PathBuf;

/// Options of `spdcam average`.
#[derive(Debug, Args)]
pub struct AverageArgs {
    /// The members: models trained on one dataset with the same `--row-scale`, `--target`,
    /// `--components` and `--grid` (a network and a ridge, say).
    #[arg(required = true, num_args = 2..)]
    models: Vec<PathBuf>,
    /// The model file to write (.spdm).
    #[arg(short, long)]
    output: PathBuf,
}

/// Runs `spdcam average`.
pub fn run(args: AverageArgs) -> Result<()> {
    fsio::check_writable(&args.output)?;
    if args.models.contains(&args.output) {
        bail!(
            "{} is a member; write the average to another file",
            args.output.display()
        );
    }
    let members = args
        .models
        .iter()
        .map(|p| Model::load(p))
        .collect::<spdcam_infer::Result<Vec<_>>>()?;
    let model = Model::average(&members)?;
    model.save(&args.output)?;
    println!(
        "  model:    {} — {}",
        args.output.display(),
        model.describe()
    );
    Ok(())
}
