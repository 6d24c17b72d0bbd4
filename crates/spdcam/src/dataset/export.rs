//! `spdcam dataset export`: a dataset written as CSV files.

use anyhow::{bail, Result};
use clap::Args;
use spdcam_core::dataset::{self, Dataset, ExportOptions};
use spdcam_core::spectral::Grid;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub(super) struct ExportArgs {
    /// The dataset directory.
    dataset: PathBuf,
    /// Write CSV (the only format so far): features.csv, spds.csv, weights.csv, samples.csv.
    #[arg(long, required = true)]
    csv: bool,
    /// Output directory.
    #[arg(short, long)]
    output: PathBuf,
    /// Scale to write the features on: 255 (0–255) or 1 (0–1).
    #[arg(long, default_value = "255", value_parser = ["255", "1"])]
    feature_scale: String,
    /// Wavelengths to write the SPDs at; default: the dataset's own.
    #[arg(long, value_name = "START-END[:STEP]")]
    spd_grid: Option<String>,
    /// Replace what the output directory holds.
    #[arg(long)]
    force: bool,
}

/// Runs `spdcam dataset export`.
pub(super) fn run(args: ExportArgs) -> Result<()> {
    if !args.csv {
        bail!("name the format to export: --csv");
    }
    let dataset = Dataset::open(&args.dataset)?;
    let options = ExportOptions {
        feature_scale: args.feature_scale.parse()?,
        spd_grid: args.spd_grid.as_deref().map(Grid::parse).transpose()?,
    };
    let files = dataset::export_csv(&dataset, &args.output, &options, args.force)?;
    println!(
        "{} samples written as {}",
        dataset.len(),
        files
            .iter()
            .map(|f| f.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    Ok(())
}
