//! `spdcam dataset`: import, export, merge, split and inspect dataset directories.

mod export;
mod import;
mod info;
mod merge;
mod split;

use anyhow::Result;
use clap::{Args, Subcommand};
use export::ExportArgs;
use import::ImportArgs;
use info::InfoArgs;
use merge::MergeArgs;
use spdcam_core::builtin::DataDir;
use split::SplitArgs;

/// Options of `spdcam dataset`.
#[derive(Debug, Args)]
pub struct DatasetArgs {
    #[command(subcommand)]
    command: DatasetCommand,
}

#[derive(Debug, Subcommand)]
enum DatasetCommand {
    /// Bring features and SPDs from CSV files (rows = samples) into a dataset.
    Import(ImportArgs),
    /// Write a dataset as CSV files: features.csv, spds.csv (header = wavelengths), ….
    Export(ExportArgs),
    /// Join the shards of one generate run, or datasets with the same columns.
    Merge(MergeArgs),
    /// Split a dataset into train, val and test parts (seeded).
    Split(SplitArgs),
    /// Counts, families, columns and settings; optionally a plot of 20 SPDs.
    Info(InfoArgs),
}

/// Runs `spdcam dataset …`.
pub fn run(args: DatasetArgs, data_dir: &DataDir) -> Result<()> {
    match args.command {
        DatasetCommand::Import(a) => import::run(a, data_dir),
        DatasetCommand::Export(a) => export::run(a),
        DatasetCommand::Merge(a) => merge::run(a),
        DatasetCommand::Split(a) => split::run(a),
        DatasetCommand::Info(a) => info::run(a),
    }
}
