//! `spdcam dataset merge`: the shards of one generate run, or datasets with the same
//! columns, joined into one dataset.

use crate::generate::progress_bar;
use anyhow::Result;
use clap::Args;
use spdcam_core::dataset::{self, Dataset, Origin};
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
    let manifest = dataset::merge(&inputs, &args.output, args.force, &|n| {
        if let Some(b) = &bar {
            b.inc(n)
        }
    })?;
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let what = match manifest.origin {
        Origin::Generated(_) => format!("the {} shards of one run", inputs.len()),
        _ => format!("{} datasets", inputs.len()),
    };
    println!(
        "merged {what} into {}: {} samples",
        args.output.display(),
        manifest.samples
    );
    Ok(())
}
