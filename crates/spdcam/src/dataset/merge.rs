//! `spdcam dataset merge`: the shards of one generate run, or datasets with the same
//! columns, joined into one dataset, each sample once.

use crate::generate::progress_bar;
use anyhow::Result;
use clap::Args;
use spdcam_core::dataset::{self, Dataset, Duplicates, Origin};
use std::path::PathBuf;

#[derive(Debug, Args)]
pub(super) struct MergeArgs {
    /// The datasets (shard directories or datasets with the same columns).
    #[arg(required = true)]
    datasets: Vec<PathBuf>,
    /// Output dataset directory.
    #[arg(short, long)]
    output: PathBuf,
    /// Replace what the output directory holds.
    #[arg(long)]
    force: bool,
    /// Keep the first copy of each sample and leave out samples already held (same
    /// features and light: a split part or an export imported again of another input);
    /// without it such samples refuse the merge.
    #[arg(long)]
    drop_duplicates: bool,
}

fn open_all(dirs: &[PathBuf]) -> Result<Vec<Dataset>> {
    dirs.iter()
        .map(|d| Dataset::open(d).map_err(Into::into))
        .collect()
}

/// Runs `spdcam dataset merge`.
pub(super) fn run(args: MergeArgs) -> Result<()> {
    let inputs = open_all(&args.datasets)?;
    let total = inputs.iter().map(Dataset::len).sum();
    let bar = progress_bar(total, "rows");
    let duplicates = if args.drop_duplicates {
        Duplicates::Drop
    } else {
        Duplicates::Refuse
    };
    let report = dataset::merge(&inputs, &args.output, args.force, duplicates, &|n| {
        if let Some(b) = &bar {
            b.inc(n)
        }
    })?;
    let manifest = report.manifest;
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let what = match manifest.origin {
        Origin::Generated(_) => format!("the {} shards of one run", inputs.len()),
        _ => format!("{} datasets", inputs.len()),
    };
    let dropped = match report.dropped {
        0 => String::new(),
        n => format!(" ({n} samples already held left out)"),
    };
    println!(
        "merged {what} into {}: {} samples{dropped}",
        args.output.display(),
        manifest.samples
    );
    Ok(())
}
