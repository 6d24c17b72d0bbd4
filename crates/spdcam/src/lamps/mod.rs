//! `spdcam lamps`: the real-lamp work. `split` fixes the validation split of the lamp
//! library and the camera pool; `fit` fits the lamp families to the split's fit lamps and
//! writes the parameters the `lamp:` recipes draw around; `validate` runs the validation
//! protocol (`validate`).

mod validate;

use crate::args::held_out::LibraryArgs;
use anyhow::Result;
use clap::{Args, Subcommand};
use spdcam_core::builtin::DataDir;
use spdcam_core::light_families::lamp_families::{fit_families, LampFits};
use spdcam_core::light_families::validation_split::LampPart;
use spdcam_core::light_families::ValidationSplit;
use spdcam_core::spectral::Grid;
use spdcam_eval::held_out::{camera_names, in_data_dir};
use std::path::PathBuf;

/// Options of `spdcam lamps`.
#[derive(Debug, Args)]
pub struct LampsArgs {
    #[command(subcommand)]
    command: LampsCommand,
}

#[derive(Debug, Subcommand)]
enum LampsCommand {
    /// Split the lamp library (fit / validation / test, per type) and the camera pool
    /// (training / held out), seeded, and write the names as JSON.
    Split(SplitArgs),
    /// Fit every lamp family to the split's fit lamps of its type; write the parameters.
    Fit(FitArgs),
    /// The validation protocol: held-out lamps through held-out cameras (the randomised
    /// in-camera stage and an independent simple camera), and the real photo sets.
    Validate(Box<validate::ValidateArgs>),
}

#[derive(Debug, Args)]
struct SplitArgs {
    #[command(flatten)]
    library: LibraryArgs,
    /// Directory of camera sensitivity CSVs (the camera pool); default: the data
    /// directory's cameras/.
    #[arg(long, value_name = "DIR")]
    cameras: Option<PathBuf>,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output JSON.
    #[arg(short, long)]
    output: PathBuf,
}

#[derive(Debug, Args)]
struct FitArgs {
    #[command(flatten)]
    library: LibraryArgs,
    /// The validation split (`spdcam lamps split`): only its fit lamps are fitted.
    #[arg(long, value_name = "SPLIT.json")]
    split: PathBuf,
    /// Output JSON (the shipped fits live in data/lamp_fits.json).
    #[arg(short, long)]
    output: PathBuf,
}

/// Runs `spdcam lamps`.
pub fn run(args: LampsArgs, data_dir: &DataDir) -> Result<()> {
    match args.command {
        LampsCommand::Split(a) => split(a, data_dir),
        LampsCommand::Fit(a) => fit(a, data_dir),
        LampsCommand::Validate(a) => validate::run(*a, data_dir),
    }
}

fn split(args: SplitArgs, data_dir: &DataDir) -> Result<()> {
    let library = args.library.read(data_dir, &Grid::SIMULATION)?;
    let dir = in_data_dir(args.cameras.as_deref(), "cameras", data_dir)?;
    let cameras = camera_names(&dir)?;
    let split = ValidationSplit::make(&library, &cameras, args.seed)?;
    split.write(&args.output)?;
    println!(
        "{} lamps: {} fit, {} validation, {} test; {} cameras: {} training, {} held out; {}",
        library.names.len(),
        split.lamps.fit.len(),
        split.lamps.validation.len(),
        split.lamps.test.len(),
        cameras.len(),
        split.cameras.training.len(),
        split.cameras.held_out.len(),
        args.output.display()
    );
    Ok(())
}

fn fit(args: FitArgs, data_dir: &DataDir) -> Result<()> {
    let grid = Grid::SIMULATION;
    let library = args.library.read(data_dir, &grid)?;
    let split = ValidationSplit::read(&args.split)?;
    let fit_lamps = library.positions(split.lamps(LampPart::Fit), "the split's fit lamps")?;
    let families = fit_families(&library, &fit_lamps)?;
    for f in &families {
        let gfcs: Vec<f64> = f.lamps.iter().map(|l| l.gfc).collect();
        println!(
            "{:<14} {:>3} lamps, fit GFC mean {:.4}, worst {:.4}",
            f.family.name(),
            gfcs.len(),
            gfcs.iter().sum::<f64>() / gfcs.len() as f64,
            gfcs.iter().cloned().fold(1.0, f64::min)
        );
    }
    let fits = LampFits {
        method: format!(
            "each family's model fitted by least squares (380–780 nm, 5 nm; heights by \
             non-negative least squares, positions and widths by Levenberg–Marquardt, best of \
             several starts) to the fit lamps of its type in {} (the fit part of the split with \
             seed {})",
            args.library.files().name(),
            split.seed
        ),
        families,
    };
    let mut text = serde_json::to_string_pretty(&fits)?;
    text.push('\n');
    spdcam_core::fsio::write_atomic(&args.output, text.as_bytes())?;
    // The written file must read back as fits.
    LampFits::from_json(&text, &args.output.display().to_string())?;
    println!("{}", args.output.display());
    Ok(())
}
