//! `spdcam sim2real`: the sim-to-real ablation. A ridge regression from features to the SPD
//! (400–700 nm, 10 nm) is trained on virtual samples only, each step of the virtual camera
//! on or off, and scored (mean GFC) on the real measured sets; steps that use real photos
//! (calibration) are cross-validated: calibrated on a few photos outside the test fold.
//! With `--finetune`, the fine-tuning learning curve instead. The protocols are
//! `spdcam_learn::sim2real`'s; this parses their options and writes their results.

use crate::fit_in_camera::sensitivities_in;
use anyhow::{Context, Result};
use clap::Args;
use spdcam_core::builtin::DataDir;
use spdcam_core::fsio::write_atomic;
use spdcam_infer::model::Model;
use spdcam_learn::sim2real::curve::{CurveOptions, FinetuneCurves};
use spdcam_learn::sim2real::{real_sets, Ablation, AblationOptions, VirtualCameras, GRID};
use std::path::{Path, PathBuf};

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

/// Runs `spdcam sim2real`.
pub fn run(args: Sim2realArgs, data_dir: &DataDir) -> Result<()> {
    let thesis = match &args.thesis_data {
        Some(p) => p.clone(),
        None => data_dir
            .root()
            .context("give --thesis-data or a data directory (--data-dir / SPDCAM_DATA)")?
            .join("thesis"),
    };
    let sets = real_sets(&thesis)?;
    // The domain-randomisation pool: every camera of the data directory's cameras/.
    let pool = match data_dir.root().map(|p| p.join("cameras")) {
        Some(dir) => sensitivities_in(&dir, data_dir, &GRID)?,
        None => Vec::new(),
    };
    let cameras = VirtualCameras::new(&pool, data_dir)?;
    let md = match &args.finetune {
        Some(path) => {
            let prior = cameras.prior(args.count, args.ridge)?;
            curves(&args, path, &sets, &prior)?.markdown()
        }
        None => {
            let options = AblationOptions {
                count: args.count,
                calibration_photos: args.calibration_photos,
                folds: args.folds,
                ridge: args.ridge,
            };
            Ablation::measure(&sets, &cameras, &options, &mut |label, scores| {
                eprintln!("{label}: {scores:?}")
            })?
            .markdown()
        }
    };
    write_atomic(&args.output, md.as_bytes())?;
    print!("{md}");
    Ok(())
}

/// The fine-tuning learning curve of the model at `path` on every real set.
fn curves(
    args: &Sim2realArgs,
    path: &Path,
    sets: &[spdcam_learn::sim2real::RealSet],
    prior: &spdcam_infer::ridge::Ridge,
) -> Result<FinetuneCurves> {
    let model = Model::load(path)?;
    let options = CurveOptions {
        sizes: args.sizes.clone(),
        folds: args.folds,
        seed: 1,
        choose: args.choose,
    };
    Ok(FinetuneCurves::measure(
        &model,
        &path.display().to_string(),
        sets,
        prior,
        args.count,
        options,
        &mut |name, curve| eprintln!("{name}: {:?}", curve.points),
    )?)
}
