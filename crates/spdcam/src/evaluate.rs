//! `spdcam evaluate`: score a model on a dataset and write a report directory.

use crate::train::load_set;
use anyhow::{Context, Result};
use clap::Args;
use spdcam_core::fsio::write_atomic;
use spdcam_learn::evaluate::{
    band_mae_svg, best_median_worst_svg, boxplots_svg, evaluate, Evaluation,
};
use spdcam_learn::model::Model;
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
    /// The report directory (created if missing).
    #[arg(short, long, value_name = "REPORT")]
    output: PathBuf,
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
         `band_mae.svg`, `best_median_worst.svg`.\n",
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

/// Runs `spdcam evaluate`.
pub fn run(args: EvaluateArgs) -> Result<()> {
    let model = Model::load(&args.model)?;
    let set = load_set(&args.data)?;
    let e = evaluate(&model, &set)?;
    write_report(
        &args.output,
        &args.model.display().to_string(),
        &model,
        &set,
        &e,
    )?;
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
