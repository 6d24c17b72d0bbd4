//! `spdcam trust`: the uncertainty calibration of a model (`calibrate`: held-out virtual
//! photos of the split's validation lamps → `<chart>.trust.json`) and its measurement
//! (`report`: the split's test lamps, the real photo sets, photos made bad on purpose →
//! docs/trust.md). The protocols are `spdcam_eval::trust`'s; this parses their options and
//! writes their results.

mod calibrate;
mod report;

use anyhow::Result;
use calibrate::CalibrateArgs;
use clap::{Args, Subcommand};
use report::ReportArgs;
use spdcam_core::builtin::DataDir;

/// Options of `spdcam trust`.
#[derive(Debug, Args)]
pub struct TrustArgs {
    #[command(subcommand)]
    command: TrustCommand,
}

#[derive(Debug, Subcommand)]
enum TrustCommand {
    /// Calibrate the bands and expected GFC of models on the split's validation lamps.
    Calibrate(Box<CalibrateArgs>),
    /// Measure the calibrated models on the test lamps, the real photo sets and bad photos.
    Report(Box<ReportArgs>),
}

/// Runs `spdcam trust`.
pub fn run(args: TrustArgs, data_dir: &DataDir) -> Result<()> {
    match args.command {
        TrustCommand::Calibrate(a) => calibrate::run(*a, data_dir),
        TrustCommand::Report(a) => report::run(*a, data_dir),
    }
}
