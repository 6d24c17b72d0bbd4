//! `spdcam sim2real`: the sim-to-real ablation. A ridge regression from features to the SPD
//! (400–700 nm, 10 nm) is trained on virtual samples only, each step of the virtual camera
//! on or off, and scored (mean GFC) on the real measured sets; steps that use real photos
//! (calibration) are cross-validated: calibrated on a few photos outside the test fold.

mod curve_table;
mod ridge;

use crate::calibrate::{photos, sensitivities_in};
use anyhow::{Context, Result};
use clap::Args;
use curve_table::curve_table;
use ridge::{real_to_real, score, train_virtual};
use spdcam_core::builtin::DataDir;
use spdcam_core::camera::in_camera::{calibrate, InCamera};
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::{Camera, CameraConfig};
use spdcam_core::chart::{Chart, KnownChart};
use spdcam_core::dataset::randomise::{camera_pool, InCameraRanges, Randomisation};
use spdcam_core::dataset::{MeasuredPhotos, REAL_PHOTO_SETS};
use spdcam_core::fsio::write_atomic;
use spdcam_core::lighting::Lighting;
use spdcam_core::spectral::Grid;
use std::path::PathBuf;

/// Options of `spdcam sim2real`.
#[derive(Debug, Args)]
pub struct Sim2realArgs {
    /// The thesis's data (holding measured/…); default: the data directory's `thesis/`.
    #[arg(long)]
    thesis_data: Option<PathBuf>,
    /// Virtual training samples per model.
    #[arg(long, default_value_t = 4000)]
    count: u64,
    /// Real photos each calibration fits on.
    #[arg(long, default_value_t = 10)]
    calibration_photos: usize,
    /// Cross-validation folds for the rows that use real photos.
    #[arg(long, default_value_t = 5)]
    folds: usize,
    /// Ridge penalty (relative to the mean diagonal of XᵀX).
    #[arg(long, default_value_t = 1e-2)]
    ridge: f64,
    /// Instead of the ablation: the learning curve of fine-tuning this (virtual-trained)
    /// model on growing numbers of real photos, beside ridge on those photos alone.
    #[arg(long, value_name = "MODEL.spdm")]
    finetune: Option<PathBuf>,
    /// With --finetune: fine-tune as `spdcam finetune` does without recipe flags (the recipe
    /// chosen by cross-validation on the photos used, ridge on the photos among the
    /// candidates) instead of the one fixed network recipe.
    #[arg(long, requires = "finetune")]
    choose: bool,
    /// Numbers of real photos of the learning curve.
    #[arg(long, value_delimiter = ',', default_values_t = [0, 10, 30, 100, 300])]
    sizes: Vec<usize>,
    /// Output Markdown table.
    #[arg(short, long)]
    output: PathBuf,
}

/// Training lights: the Telelumen configurations with some white LED and Planckian light.
const LIGHTING: &str =
    "mix:telelumen:config1=0.3,telelumen:config2=0.3,telelumen:config3=0.2,phosphor=0.1,planck=0.1";
const GRID: Grid = Grid::SIMULATION;

/// Runs `spdcam sim2real`.
pub fn run(args: Sim2realArgs, data_dir: &DataDir) -> Result<()> {
    let thesis = match &args.thesis_data {
        Some(p) => p.clone(),
        None => data_dir
            .root()
            .context("give --thesis-data or a data directory (--data-dir / SPDCAM_DATA)")?
            .join("thesis"),
    };
    let folds = args.folds.max(2);
    let sets = REAL_PHOTO_SETS
        .iter()
        .map(|set| Ok((set.label, set.load(&thesis, &GRID)?)))
        .collect::<Result<Vec<_>>>()?;
    let lighting = Lighting::parse(LIGHTING, data_dir, &GRID)?;
    let config = CameraConfig {
        noise: None,
        ..CameraConfig::default()
    };
    let make = |cam: &str, chart: &str, ic: Option<InCamera>| -> Result<Camera> {
        let chart = Chart::resolve(chart, None, data_dir, &GRID)?;
        let config = CameraConfig {
            in_camera: ic,
            ..config
        };
        Ok(Camera::new(
            &Sensitivities::resolve(cam, data_dir, &GRID)?,
            chart,
            config,
            &GRID,
        )?)
    };
    let thesis_cam = "canon_eos_5d_mark_ii_mod_bw486";
    let plain_cam = "canon_eos_5d_mark_ii";
    let sg = KnownChart::Sg96.name();
    // The domain-randomisation pool: every camera of the data directory's cameras/.
    let chart = Chart::resolve(sg, None, data_dir, &GRID)?;
    let mut sens = match data_dir.root().map(|p| p.join("cameras")) {
        Some(dir) => sensitivities_in(&dir, data_dir, &GRID)?,
        None => Vec::new(),
    };
    sens.push(Sensitivities::resolve(plain_cam, data_dir, &GRID)?);
    let pool = camera_pool(&sens, 1, 11, &chart, config, &GRID)?;
    let pool_size = pool.len();
    let randomised = Randomisation::new(
        pool,
        InCameraRanges::for_groups(&["exposure", "wb", "tone", "jpeg"])?,
    )?;
    let with_gradient = Randomisation::new(
        randomised.cameras().to_vec(),
        InCameraRanges::for_groups(&["exposure", "wb", "tone", "jpeg", "gradient"])?,
    )?;
    if let Some(path) = &args.finetune {
        let prior = train_virtual(
            &make(plain_cam, sg, None)?,
            Some(&with_gradient),
            &lighting,
            args.count,
            args.ridge,
        )?;
        return curve_table(&args, path, &sets, &prior);
    }
    let wb_only = Randomisation::new(
        vec![make(plain_cam, sg, None)?],
        InCameraRanges::for_groups(&["exposure", "wb", "tone", "jpeg"])?,
    )?;

    let mut rows: Vec<(String, Vec<f64>)> = Vec::new();
    let all = |set: &MeasuredPhotos| (0..set.features.len()).collect::<Vec<usize>>();
    let mut fixed_row = |label: &str, camera: &Camera, r: Option<&Randomisation>| -> Result<()> {
        let model = train_virtual(camera, r, &lighting, args.count, args.ridge)?;
        let scores = sets
            .iter()
            .map(|(_, s)| score(&model, s, &all(s)))
            .collect::<Result<Vec<f64>>>()?;
        eprintln!("{label}: {scores:?}");
        rows.push((label.to_string(), scores));
        Ok(())
    };
    fixed_row(
        "thesis camera (5D II + BW486, file patch order)",
        &make(thesis_cam, "colorchecker_sg96_thesis", None)?,
        None,
    )?;
    fixed_row("+ physical patch order", &make(thesis_cam, sg, None)?, None)?;
    fixed_row(
        "+ unmodified 5D II curves",
        &make(plain_cam, sg, None)?,
        None,
    )?;
    fixed_row(
        "+ randomised in-camera stage (exposure, wb, tone, jpeg)",
        &make(plain_cam, sg, None)?,
        Some(&wb_only),
    )?;
    fixed_row(
        &format!("+ randomised camera ({pool_size} curves incl. perturbed) and in-camera stage"),
        &make(plain_cam, sg, None)?,
        Some(&randomised),
    )?;
    fixed_row(
        "+ uneven lighting across the chart (randomised gradient)",
        &make(plain_cam, sg, None)?,
        Some(&with_gradient),
    )?;
    // Calibrated: per fold, fit on a few photos outside the fold, test on the fold.
    let mut calibrated = Vec::new();
    for (_, set) in &sets {
        let n = set.features.len();
        let base = make(plain_cam, sg, None)?;
        let mut total = 0.0;
        for f in 0..folds {
            let (test, rest): (Vec<usize>, Vec<usize>) = (0..n).partition(|i| i % folds == f);
            let step = (rest.len() / args.calibration_photos.max(1)).max(1);
            let pick: Vec<usize> = rest
                .iter()
                .step_by(step)
                .take(args.calibration_photos)
                .copied()
                .collect();
            let fit = calibrate(&base, &photos(set, &pick), InCamera::NEUTRAL, 2000)?;
            let camera = make(plain_cam, sg, Some(fit.in_camera))?;
            let model = train_virtual(&camera, None, &lighting, args.count, args.ridge)?;
            total += score(&model, set, &test)? * test.len() as f64;
        }
        calibrated.push(total / n as f64);
    }
    eprintln!("calibrated: {calibrated:?}");
    rows.push((
        format!(
            "+ in-camera stage calibrated on {} real photos (CV)",
            args.calibration_photos
        ),
        calibrated,
    ));
    let reference = sets
        .iter()
        .map(|(_, s)| real_to_real(s, folds))
        .collect::<Result<Vec<f64>>>()?;
    rows.push((
        format!("reference: ridge trained on real photos ({folds}-fold CV, penalty by inner CV)"),
        reference,
    ));

    let mut md = String::from("| virtual camera (ridge on virtual data only, unless noted) | ");
    md += &sets.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(" | ");
    md += " |\n|---|";
    md += &"---:|".repeat(sets.len());
    md.push('\n');
    for (label, scores) in &rows {
        md += &format!(
            "| {label} | {} |\n",
            scores
                .iter()
                .map(|s| format!("{s:.4}"))
                .collect::<Vec<_>>()
                .join(" | ")
        );
    }
    md += &format!(
        "\nMean GFC (400–700 nm, 10 nm). {} virtual samples per model, lighting `{LIGHTING}`, \
         noise-free patch-level camera, ridge λ = {} (relative) for the rows trained on virtual \
         data.\n",
        args.count, args.ridge
    );
    write_atomic(&args.output, md.as_bytes())?;
    print!("{md}");
    Ok(())
}
