//! `spdcam average`: one model that estimates the mean of several trained models' outputs
//! (an ensemble; `spdcam_infer::network::Architecture::Average`).

use anyhow::Result;
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
    // The command line's output guard has refused an output onto a member.
    fsio::check_writable(&args.output)?;
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
