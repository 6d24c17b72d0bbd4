//! `spdcam fit-in-camera`: fits the in-camera rendering (auto exposure, partial white balance,
//! tone curve, flare) of a real camera to a few of its photos of the chart under known
//! lights, and writes it as JSON for `spdcam generate --in-camera`.

use crate::render::CameraArgs;
use anyhow::{bail, Context, Result};
use clap::Args;
use spdcam_core::builtin::DataDir;
use spdcam_core::camera::in_camera::{fit_to_photos, InCamera};
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::Camera;
use spdcam_core::chart::Chart;
use spdcam_core::dataset::MeasuredPhotos;
use spdcam_core::fsio::write_atomic;
use spdcam_core::spectral::Grid;
use std::path::{Path, PathBuf};

/// Options of `spdcam fit-in-camera`.
#[derive(Debug, Args)]
pub struct FitInCameraArgs {
    /// Features of the real photos: CSV with a header, one row per photo (0–255, the
    /// chart's feature order, e.g. p01_r,p01_g,…).
    #[arg(long)]
    features: PathBuf,
    /// The lights' SPDs: CSV whose header row holds the wavelengths (nm), one row per photo.
    #[arg(long)]
    spds: PathBuf,
    /// How many photos to fit on (the first N rows).
    #[arg(long, default_value_t = 10)]
    photos: usize,
    /// Objective evaluations of the Nelder–Mead search.
    #[arg(long, default_value_t = 3000)]
    evaluations: usize,
    /// Output JSON (the fitted in-camera stage and the fit's error).
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    camera: CameraArgs,
}

/// Every camera sensitivity CSV in `dir`, sorted by file name; a file that is not a valid
/// sensitivity set is skipped with a warning naming it and why.
#[cfg(feature = "train")]
pub fn sensitivities_in(dir: &Path, data_dir: &DataDir, grid: &Grid) -> Result<Vec<Sensitivities>> {
    let (found, skipped) = Sensitivities::in_dir(dir, data_dir, grid)
        .with_context(|| format!("reading {}", dir.display()))?;
    for (f, e) in skipped {
        warn_skipped(&f, &e);
    }
    Ok(found)
}

/// The warning for a camera file skipped as no valid sensitivity set.
pub fn warn_skipped(path: &Path, error: &spdcam_core::Error) {
    eprintln!("warning: skipping camera {}: {error}", path.display());
}

/// Reads an in-camera stage written by `spdcam fit-in-camera` (or a bare in-camera JSON object).
pub fn read_in_camera(path: &Path) -> Result<InCamera> {
    let text = spdcam_core::fsio::read_text(path)?;
    let value: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("{} is not JSON", path.display()))?;
    let inner = value.get("in_camera").cloned().unwrap_or(value);
    let ic: InCamera = serde_json::from_value(inner)
        .with_context(|| format!("{}: not an in-camera stage", path.display()))?;
    ic.validate()?;
    Ok(ic)
}

/// Runs `spdcam fit-in-camera`.
pub fn run(args: FitInCameraArgs, data_dir: &DataDir) -> Result<()> {
    let grid = Grid::SIMULATION;
    let chart: Chart = args.camera.chart(data_dir, &grid)?;
    let sens = Sensitivities::resolve(&args.camera.camera, data_dir, &grid)?;
    let camera = Camera::new(&sens, chart, args.camera.config()?, &grid)?;
    let measured = MeasuredPhotos::read(&args.features, &args.spds, &grid)?;
    if args.photos == 0 {
        bail!("--photos must be at least 1");
    }
    let n = args.photos.min(measured.features.len());
    let indices: Vec<usize> = (0..n).collect();
    let fit = fit_to_photos(
        &camera,
        &measured.reference_photos(&indices),
        InCamera::NEUTRAL,
        args.evaluations,
    )?;
    let mut text = serde_json::to_string_pretty(&fit)?;
    text.push('\n');
    write_atomic(&args.output, text.as_bytes())?;
    println!(
        "fitted on {n} photos: feature RMS {:.2} → {:.2} (0–255), {} evaluations; {}",
        fit.rms_before,
        fit.rms_after,
        fit.evaluations,
        args.output.display()
    );
    Ok(())
}
