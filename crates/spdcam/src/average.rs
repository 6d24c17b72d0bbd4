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
    /// `--components` and `--grid` (a network and a ridge, say); one member with
    /// `--colour-pull` is that model with another pull.
    #[arg(required = true, num_args = 1..)]
    models: Vec<PathBuf>,
    /// The model file to write (.spdm).
    #[arg(short, long)]
    output: PathBuf,
    /// For members trained with `--target pca-colour`: the share of the way (0–1) from the
    /// spectrum's own chromaticity to the predicted one that the spectrum is moved.
    #[arg(long, value_name = "SHARE")]
    colour_pull: Option<f64>,
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
    let mut model = match members.len() {
        1 if args.colour_pull.is_none() => {
            bail!("one model makes no average; give more members, or --colour-pull to set its pull")
        }
        1 => members.into_iter().next().expect("one member"),
        _ => Model::average(&members)?,
    };
    if let Some(pull) = args.colour_pull {
        model.set_colour_pull(pull)?;
    }
    model.save(&args.output)?;
    println!(
        "  model:    {} — {}",
        args.output.display(),
        model.describe()
    );
    Ok(())
}
