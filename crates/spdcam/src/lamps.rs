//! `spdcam lamps`: the real-lamp work. `split` fixes the validation split of the lamp
//! library and the camera pool; `fit` fits the lamp families to the split's fit lamps and
//! writes the parameters the `lamp:` recipes draw around; `validate` runs the validation
//! protocol (`crate::validate_lamps`).

use anyhow::{Context, Result};
use clap::{Args, Subcommand};
use spdcam_core::builtin::DataDir;
use spdcam_core::lighting::lamp_families::{fit_families, LampFits};
use spdcam_core::lighting::validation_split::LampPart;
use spdcam_core::lighting::{LampLibrary, ValidationSplit};
use spdcam_core::spectral::Grid;
use std::path::{Path, PathBuf};

/// The lamp library's files inside the data directory.
pub const LAMP_SPDS: &str = "lamps/ies_tm30_lamps.csv";
/// The lamp library's type table inside the data directory.
pub const LAMP_TYPES: &str = "lamps/ies_tm30_lamps_info.csv";

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
    Validate(Box<crate::validate_lamps::ValidateArgs>),
}

/// Where the lamp library is read from.
#[derive(Debug, Args)]
pub struct LibraryArgs {
    /// Measured lamp SPDs (spectral CSV); default: the data directory's
    /// lamps/ies_tm30_lamps.csv.
    #[arg(long, value_name = "SPDS.csv")]
    pub lamps: Option<PathBuf>,
    /// The lamps' types (`column,type,category`); default: the data directory's
    /// lamps/ies_tm30_lamps_info.csv.
    #[arg(long, value_name = "INFO.csv")]
    pub types: Option<PathBuf>,
}

impl LibraryArgs {
    /// Reads the library on `grid`.
    pub fn read(&self, data_dir: &DataDir, grid: &Grid) -> Result<LampLibrary> {
        let spds = in_data_dir(self.lamps.as_deref(), LAMP_SPDS, data_dir)?;
        let types = in_data_dir(self.types.as_deref(), LAMP_TYPES, data_dir)?;
        Ok(LampLibrary::read(&spds, Some(&types), grid)?)
    }
}

/// `given`, or `default` inside the data directory.
pub fn in_data_dir(given: Option<&Path>, default: &str, data_dir: &DataDir) -> Result<PathBuf> {
    match given {
        Some(p) => Ok(p.to_path_buf()),
        None => Ok(data_dir
            .root()
            .with_context(|| {
                format!("give the file or a data directory (--data-dir / SPDCAM_DATA) holding {default}")
            })?
            .join(default)),
    }
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
        LampsCommand::Validate(a) => crate::validate_lamps::run(*a, data_dir),
    }
}

/// The file stems of the camera CSVs in `dir`, sorted.
pub fn camera_names(dir: &Path) -> Result<Vec<String>> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .with_context(|| format!("reading {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "csv"))
        .filter_map(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
        .collect();
    names.sort();
    Ok(names)
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
            library_name(&args.library),
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

/// The library's file name, for records (no directories: they differ between machines).
pub fn library_name(args: &LibraryArgs) -> String {
    args.lamps
        .as_deref()
        .and_then(|p| p.file_name())
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| LAMP_SPDS.to_string())
}
