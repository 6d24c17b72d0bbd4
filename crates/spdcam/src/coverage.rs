//! `spdcam coverage`: how well lighting recipes cover a file of measured SPDs, per lamp type:
//! for each SPD the best GFC (400–700 nm) among N draws of each recipe (and of each member
//! of a `mix:`), and the GFC of the lamp-family model fitted to it directly. The protocol is
//! `spdcam_eval::coverage`'s; this parses its options and prints and writes its results.

use anyhow::Result;
use clap::Args;
use spdcam_core::builtin::DataDir;
use spdcam_core::fsio::write_atomic;
use spdcam_core::light_families::validation_split::LampPart;
use spdcam_eval::coverage::{Coverage, CoverageOptions};
use std::path::PathBuf;

/// Options of `spdcam coverage`.
#[derive(Debug, Args)]
pub struct CoverageArgs {
    /// Measured SPDs (spectral CSV, one column per lamp).
    spds: PathBuf,
    /// Lighting recipe to measure (repeatable); a `mix:` is measured whole and member by member.
    #[arg(long, required = true)]
    lighting: Vec<String>,
    /// The SPDs' types (`column,type[,category]`, as the TM-30 library's info file); without
    /// it every SPD is of type "other".
    #[arg(long, value_name = "INFO.csv")]
    types: Option<PathBuf>,
    /// Only the lamps of one part of this validation split (`spdcam lamps split`)…
    #[arg(long, value_name = "SPLIT.json", requires = "part")]
    split: Option<PathBuf>,
    /// …this part: fit, validation or test.
    #[arg(long, value_parser = ["fit", "validation", "test"], requires = "split")]
    part: Option<String>,
    /// Draws per recipe (and per member of a mixture).
    #[arg(long, default_value_t = 20_000)]
    draws: u64,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Skip the direct fit of each lamp's family model.
    #[arg(long)]
    no_fit: bool,
    /// Markdown table to write (it is printed too).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Per-SPD results as CSV.
    #[arg(long, value_name = "FILE.csv")]
    per_lamp: Option<PathBuf>,
}

impl CoverageArgs {
    /// The options as the protocol takes them.
    fn protocol(&self) -> CoverageOptions {
        let part = |p: &str| match p {
            "fit" => LampPart::Fit,
            "validation" => LampPart::Validation,
            _ => LampPart::Test,
        };
        CoverageOptions {
            spds: self.spds.clone(),
            types: self.types.clone(),
            split: match (&self.split, &self.part) {
                (Some(path), Some(p)) => Some((path.clone(), part(p))),
                _ => None,
            },
            lighting: self.lighting.clone(),
            draws: self.draws,
            seed: self.seed,
            fit: !self.no_fit,
        }
    }
}

/// Runs `spdcam coverage`.
pub fn run(args: CoverageArgs, data_dir: &DataDir) -> Result<()> {
    let coverage = Coverage::measure(&args.protocol(), data_dir, &mut |spec| {
        eprintln!("{spec}: done")
    })?;
    let md = coverage.markdown();
    print!("{md}");
    if let Some(path) = &args.output {
        write_atomic(path, md.as_bytes())?;
    }
    if let Some(path) = &args.per_lamp {
        write_atomic(path, coverage.per_lamp_csv().as_bytes())?;
    }
    Ok(())
}
