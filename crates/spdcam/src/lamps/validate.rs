//! `spdcam lamps validate`: the validation protocol for real lamps. (a) The split's held-out
//! lamps photographed (patch level) by the split's held-out cameras with the randomised
//! in-camera stage; (b) the same lamps photographed by an independent simple camera model
//! (`spdcam_core::simple_camera`); both scored per lamp type (mean GFC, 400–700 nm) beside
//! the average-SPD baseline, for the validation lamps (choose on these) and the test lamps
//! (report only). (c) The real photo sets of the thesis (SG 96 models only). The protocol is
//! `spdcam_eval::lamp_validation`'s; this parses its options and writes its results.

use crate::args::held_out::HeldOutArgs;
use anyhow::Result;
use clap::Args;
use spdcam_core::builtin::DataDir;
use spdcam_core::fsio::write_atomic;
use spdcam_eval::lamp_validation::{LampValidation, LampValidationOptions};
use std::path::PathBuf;

/// Options of `spdcam lamps validate`.
#[derive(Debug, Args)]
pub struct ValidateArgs {
    #[command(flatten)]
    photos: HeldOutArgs,
    /// The thesis's data (holding measured/…); default: the data directory's thesis/.
    #[arg(long)]
    thesis_data: Option<PathBuf>,
    /// Leave out (c), the real photo sets.
    #[arg(long)]
    no_real: bool,
    /// Output Markdown table (printed too).
    #[arg(short, long)]
    output: PathBuf,
}

/// Runs `spdcam lamps validate`.
pub fn run(args: ValidateArgs, data_dir: &DataDir) -> Result<()> {
    let options = LampValidationOptions {
        thesis_data: args.thesis_data.clone(),
        no_real: args.no_real,
    };
    let validation =
        LampValidation::measure(&args.photos.protocol(), &options, data_dir, &mut |model| {
            eprintln!("{}: done", model.display())
        })?;
    for skipped in &validation.skipped {
        eprintln!("warning: {skipped}");
    }
    let md = validation.markdown();
    write_atomic(&args.output, md.as_bytes())?;
    print!("{md}");
    Ok(())
}
