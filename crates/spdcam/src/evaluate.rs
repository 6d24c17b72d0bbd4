//! `spdcam evaluate`: score a model on a dataset and write a report directory.

use anyhow::{bail, Context, Result};
use clap::Args;
use spdcam_core::builtin::DataDir;
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::{Camera, CameraConfig};
use spdcam_core::chart::Chart;
use spdcam_core::fsio::write_atomic;
use spdcam_core::imageio::write_png;
use spdcam_core::raster::RgbImage;
use spdcam_core::spectral::{Extrapolation, Grid, Interpolation, Spd, SpectralSet};
use spdcam_infer::model::Model;
use spdcam_learn::evaluate::{
    band_mae_svg, best_median_worst_svg, boxplots_svg, evaluate, Evaluation,
};
use spdcam_learn::train::TrainingSet;
use std::path::{Path, PathBuf};

/// Options of `spdcam evaluate`.
#[derive(Debug, Args)]
pub struct EvaluateArgs {
    /// The model file (.spdm).
    #[arg(long)]
    model: PathBuf,
    /// The dataset to score on.
    #[arg(long, value_name = "DIR")]
    data: PathBuf,
    /// The report directory (created if missing; a directory holding files is refused
    /// unless --force).
    #[arg(short, long, value_name = "REPORT")]
    output: PathBuf,
    /// Write the report into a directory that holds files, replacing the report's files.
    #[arg(long)]
    force: bool,
}

/// Refuses a report directory that holds files unless `force`, as `dataset export` does:
/// a report must not overwrite a user's files by surprise.
fn check_report_dir(dir: &Path, force: bool) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        bail!("report {} exists and is not a directory", dir.display());
    }
    let holds_files = dir.is_dir()
        && std::fs::read_dir(dir)
            .with_context(|| format!("reading {}", dir.display()))?
            .next()
            .is_some();
    if holds_files && !force {
        bail!(
            "report directory {} is not empty; use --force to replace the report's files in it, or choose another directory",
            dir.display()
        );
    }
    Ok(())
}

/// The Markdown table of the four metrics.
pub fn metrics_table(e: &Evaluation) -> String {
    let s = &e.summary;
    let mut t =
        String::from("| metric | mean | std | median | min | max |\n|---|---|---|---|---|---|\n");
    for (name, m) in [
        ("RMSE", s.rmse),
        ("GFC", s.gfc),
        ("SAM (rad)", s.sam),
        ("SID", s.sid),
    ] {
        t.push_str(&format!(
            "| {name} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} |\n",
            m.mean, m.std, m.median, m.min, m.max
        ));
    }
    t
}

/// Writes the report files of an evaluation into `dir`.
pub fn write_report(
    dir: &Path,
    model_name: &str,
    model: &Model,
    set: &TrainingSet,
    e: &Evaluation,
) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let mut csv = String::from("row,sample,family,rmse,gfc,sam,sid\n");
    for (i, m) in e.per_sample.iter().enumerate() {
        csv.push_str(&format!(
            "{},{},{},{:.6},{:.8},{:.6},{:.6}\n",
            i + 1,
            set.samples.samples.get(i).copied().unwrap_or(i as u64),
            set.samples
                .families
                .get(i)
                .map(String::as_str)
                .unwrap_or(""),
            m.rmse,
            m.gfc,
            m.sam,
            m.sid
        ));
    }
    write_atomic(&dir.join("samples.csv"), csv.as_bytes())?;
    let json = serde_json::json!({
        "model": model_name,
        "model_description": model.describe(),
        "data": set.info.path,
        "samples": e.per_sample.len(),
        "grid": e.grid.label(),
        "metrics": e.summary,
        "band_mae": e.band_mae,
    });
    write_atomic(
        &dir.join("metrics.json"),
        serde_json::to_string_pretty(&json)?.as_bytes(),
    )?;
    let md = format!(
        "# Evaluation\n\nModel `{model_name}` ({}) on `{}` ({} samples, {} nm).\n\n{}\n\
         Files: `samples.csv` (per sample), `metrics.json`, `band_mae.csv`, `boxplots.svg`, \
         `band_mae.svg`, `best_median_worst.svg`, and `worst_case.png` when the model names \
         its chart and camera (the chart under the worst case's true SPD, under its \
         estimate, and their difference ×4).\n",
        model.describe(),
        set.info.path,
        e.per_sample.len(),
        e.grid.label(),
        metrics_table(e)
    );
    write_atomic(&dir.join("metrics.md"), md.as_bytes())?;
    let mut band = String::from("wavelength_nm,mae\n");
    for (k, v) in e.band_mae.iter().enumerate() {
        band.push_str(&format!("{},{v:.6}\n", e.grid.wavelength(k)));
    }
    write_atomic(&dir.join("band_mae.csv"), band.as_bytes())?;
    write_atomic(&dir.join("boxplots.svg"), boxplots_svg(e)?.as_bytes())?;
    write_atomic(&dir.join("band_mae.svg"), band_mae_svg(e)?.as_bytes())?;
    write_atomic(
        &dir.join("best_median_worst.svg"),
        best_median_worst_svg(e)?.as_bytes(),
    )?;
    Ok(())
}

/// Gap between the panels of the worst-case image, in pixels.
const PANEL_GAP: usize = 8;
/// How much the worst-case image magnifies the difference of the two renders.
const DIFFERENCE_GAIN: f32 = 4.0;

/// Thesis Fig. 6.7: the model's chart photographed by its camera (noise off) under the
/// true and the estimated SPD of the worst estimate, side by side, then their absolute
/// difference magnified four times. Errs when the model does not name a chart and a camera
/// the data directory knows.
fn worst_case_image(model: &Model, e: &Evaluation, data_dir: &DataDir) -> Result<RgbImage> {
    let header = model.header();
    let (Some(chart), Some(camera)) = (&header.chart, &header.camera) else {
        anyhow::bail!("the model does not record the chart and camera it was trained for");
    };
    let grid = Grid::SIMULATION;
    let chart = Chart::resolve(chart, None, data_dir, &grid)?;
    let config = CameraConfig {
        noise: None,
        ..CameraConfig::default()
    };
    let camera = Camera::new(
        &Sensitivities::resolve(camera, data_dir, &grid)?,
        chart,
        config,
        &grid,
    )?;
    let worst = *e.ranking().last().context("no samples")?;
    let d = e.grid.count;
    let render = |spd: &[f64]| -> Result<RgbImage> {
        let set = SpectralSet::on_grid(&e.grid, vec!["spd".into()], vec![spd.to_vec()])?;
        let (set, _) = set.resample(&grid, Interpolation::Linear, Extrapolation::Zero)?;
        Ok(camera
            .render(&Spd::new(grid, set.item(0).to_vec())?, 0, false)?
            .image)
    };
    let truth = render(&e.truths[worst * d..(worst + 1) * d])?;
    let estimate = render(&e.estimates[worst * d..(worst + 1) * d])?;
    let (w, h) = (truth.width, truth.height);
    let mut out = RgbImage::new(3 * w + 2 * PANEL_GAP, h);
    for (c, plane) in out.planes.iter_mut().enumerate() {
        plane.fill(1.0);
        for y in 0..h {
            for x in 0..w {
                let (t, m) = (truth.planes[c][y * w + x], estimate.planes[c][y * w + x]);
                let row = y * out.width;
                plane[row + x] = t;
                plane[row + w + PANEL_GAP + x] = m;
                plane[row + 2 * (w + PANEL_GAP) + x] = ((t - m).abs() * DIFFERENCE_GAIN).min(1.0);
            }
        }
    }
    Ok(out)
}

/// Runs `spdcam evaluate`.
pub fn run(args: EvaluateArgs, data_dir: &DataDir) -> Result<()> {
    check_report_dir(&args.output, args.force)?;
    spdcam_core::fsio::check_output_apart(&args.output, &[&args.data, &args.model])?;
    let model = Model::load(&args.model)?;
    let set = TrainingSet::load(&args.data)?;
    let e = evaluate(&model, &set)?;
    write_report(
        &args.output,
        &args.model.display().to_string(),
        &model,
        &set,
        &e,
    )?;
    match worst_case_image(&model, &e, data_dir) {
        Ok(image) => write_png(&args.output.join("worst_case.png"), &image, 8)?,
        Err(err) => eprintln!("note: no worst_case.png: {err:#}"),
    }
    println!(
        "{} on {} ({} samples):\n\n{}\nreport: {}",
        args.model.display(),
        args.data.display(),
        e.per_sample.len(),
        metrics_table(&e),
        args.output.display()
    );
    Ok(())
}
