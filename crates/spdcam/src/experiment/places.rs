//! `spdcam experiment places`: the light at several places measured on rendered scenes of
//! two to four charts (`spdcam_eval::places`); this parses its options and writes its
//! report.

use crate::args::held_out::{flags, LibraryArgs};
use anyhow::Result;
use clap::Args;
use spdcam_core::builtin::DataDir;
use spdcam_core::fsio::write_atomic;
use spdcam_eval::places::{PlacesOptions, PlacesReport};
use std::path::PathBuf;

/// Options of `spdcam experiment places`.
#[derive(Debug, Args)]
pub(super) struct PlacesArgs {
    /// The validation split (`spdcam lamps split`): its validation and test lamps, its
    /// held-out cameras.
    #[arg(long, value_name = "SPLIT.json")]
    split: PathBuf,
    #[command(flatten)]
    library: LibraryArgs,
    /// Directory of camera sensitivity CSVs holding the split's held-out cameras; default:
    /// the data directory's cameras/.
    #[arg(long, value_name = "DIR")]
    cameras: Option<PathBuf>,
    /// Scenes of each part (validation lamps, test lamps).
    #[arg(long, default_value_t = 40)]
    scenes: u64,
    /// Seed of the scenes.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output Markdown report.
    #[arg(short, long)]
    output: PathBuf,
}

/// Runs `spdcam experiment places`.
pub(super) fn run(args: PlacesArgs, data_dir: &DataDir) -> Result<()> {
    let options = PlacesOptions {
        split: args.split.clone(),
        library: args.library.files(),
        cameras: args.cameras.clone(),
        scenes: args.scenes,
        seed: args.seed,
    };
    let started = std::time::Instant::now();
    let report = PlacesReport::measure(&options, data_dir, &mut |what| {
        eprintln!("{what} ({:.0} s)", started.elapsed().as_secs_f64())
    })?;
    let command = format!(
        "spdcam --data-dir DATA experiment places{} --scenes {} --seed {} -o {}",
        flags(&[], &args.split, &args.library, args.cameras.as_deref()),
        args.scenes,
        args.seed,
        args.output.display()
    );
    let md = report.markdown(&command);
    write_atomic(&args.output, md.as_bytes())?;
    print!("{md}");
    Ok(())
}
