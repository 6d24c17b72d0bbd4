//! `spdcam dataset split`: a dataset split into train, val and test parts (seeded).

use crate::generate::progress_bar;
use anyhow::{Context, Result};
use clap::Args;
use spdcam_core::dataset::{self, Dataset};
use std::path::PathBuf;

#[derive(Debug, Args)]
pub(super) struct SplitArgs {
    /// The dataset directory.
    dataset: PathBuf,
    /// Output directory; receives train/, val/ and test/.
    #[arg(short, long)]
    output: PathBuf,
    /// Fractions of train, val and test, adding up to 1.
    #[arg(long, default_value = "0.7,0.1,0.2", value_name = "TRAIN,VAL,TEST")]
    fractions: String,
    /// Seed of the shuffle.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Replace what the output directory holds.
    #[arg(long)]
    force: bool,
}

fn parse_fractions(text: &str) -> Result<[f64; 3]> {
    let values: Vec<f64> = text
        .split(',')
        .map(|v| v.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .ok()
        .filter(|v: &Vec<f64>| v.len() == 3)
        .with_context(|| {
            format!("fractions '{text}' are not three numbers TRAIN,VAL,TEST, e.g. 0.7,0.1,0.2")
        })?;
    Ok([values[0], values[1], values[2]])
}

/// Runs `spdcam dataset split`.
pub(super) fn run(args: SplitArgs) -> Result<()> {
    let fractions = parse_fractions(&args.fractions)?;
    let input = Dataset::open(&args.dataset)?;
    let bar = progress_bar(input.len(), "rows");
    let parts = dataset::split(
        &input,
        &args.output,
        fractions,
        args.seed,
        args.force,
        &|n| {
            if let Some(b) = &bar {
                b.inc(n)
            }
        },
    )?;
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let counts: Vec<String> = ["train", "val", "test"]
        .iter()
        .zip(&parts)
        .map(|(name, m)| format!("{name} {}", m.samples))
        .collect();
    println!(
        "split {} samples into {}: {}",
        input.len(),
        args.output.display(),
        counts.join(", ")
    );
    Ok(())
}
