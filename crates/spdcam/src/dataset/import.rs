//! `spdcam dataset import`: features and SPDs (or channel weights) from CSV files into a
//! dataset.

use anyhow::{Context, Result};
use clap::Args;
use spdcam_core::builtin::DataDir;
use spdcam_core::dataset::{self, ImportOptions, Origin, DEFAULT_CHUNK_SIZE, FEATURE_SCALE};
use spdcam_core::light_families::Lighting;
use spdcam_core::spectral::Grid;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub(super) struct ImportArgs {
    /// Features CSV: header p01_r,p01_g,…; one row per sample.
    #[arg(long, value_name = "F.csv")]
    features: PathBuf,
    /// SPDs CSV: header = wavelengths in nm; one row per sample, same order as the features.
    #[arg(
        long,
        value_name = "S.csv",
        required_unless_present = "weights",
        conflicts_with = "weights"
    )]
    spds: Option<PathBuf>,
    /// Instead of SPDs: channel weights (one column per channel of --lighting, one row per
    /// sample); each SPD is the weighted sum of the channels, normalised by its maximum.
    #[arg(long, value_name = "W.csv", requires = "lighting")]
    weights: Option<PathBuf>,
    /// The lighting whose channels the weights drive (gaussian:N, leds:FILE, telelumen:PRESET).
    #[arg(long, value_name = "RECIPE", requires = "weights")]
    lighting: Option<String>,
    /// Scale of the features in the file: 255 (0–255) or 1 (0–1). Stored on 0–255.
    #[arg(long, default_value = "255", value_parser = ["255", "1"])]
    feature_scale: String,
    /// Wavelengths the SPDs are stored at, START-END[:STEP] in nm.
    #[arg(long, default_value = "380-780:5", value_name = "START-END[:STEP]")]
    spd_grid: String,
    /// Family name of the samples; default: the features file's directory name.
    #[arg(long)]
    family: Option<String>,
    /// Output dataset directory.
    #[arg(short, long)]
    output: PathBuf,
    /// Replace what the output directory holds.
    #[arg(long)]
    force: bool,
}

/// Runs `spdcam dataset import`.
pub(super) fn run(args: ImportArgs, data_dir: &DataDir) -> Result<()> {
    let feature_scale: f64 = args.feature_scale.parse()?;
    let family = match args.family {
        Some(f) => f,
        None => args
            .features
            .canonicalize()
            .ok()
            .and_then(|p| Some(p.parent()?.file_name()?.to_string_lossy().into_owned()))
            .unwrap_or_else(|| "imported".to_string()),
    };
    let weights_of = match &args.lighting {
        Some(spec) => Some(Lighting::parse(spec, data_dir, &Grid::SIMULATION)?),
        None => None,
    };
    let options = ImportOptions {
        feature_scale,
        spd_grid: Grid::parse(&args.spd_grid)?,
        family,
        chunk_size: DEFAULT_CHUNK_SIZE,
        weights_of,
    };
    let second = args
        .spds
        .as_ref()
        .or(args.weights.as_ref())
        .context("give --spds S.csv, or --weights W.csv with --lighting")?;
    let report = dataset::import_csv(&args.features, second, &args.output, &options, args.force)?;
    let m = &report.manifest;
    if let Origin::Imported(source) = &m.origin {
        if let Some(r) = source.resampling.as_ref().filter(|r| r.extrapolated()) {
            eprintln!(
                "warning: {}",
                r.describe(&second.display().to_string(), &options.spd_grid)
            );
        }
    }
    if feature_scale == FEATURE_SCALE && report.largest_feature <= 1.0 {
        eprintln!(
            "warning: no feature exceeds 1; if the file is on 0–1, import it with --feature-scale 1"
        );
    }
    println!(
        "imported {} samples ({} features, SPDs on {}) as family '{}' into {}",
        m.samples,
        m.columns.feature_count(),
        m.columns.spd_grid,
        options.family,
        args.output.display()
    );
    Ok(())
}
