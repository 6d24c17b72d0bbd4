//! `spdcam trust calibrate`: the uncertainty calibration of models on held-out virtual
//! photos of the split's validation lamps (`spdcam_eval::trust::fit`), written as
//! `<chart>.trust.json`; of raw models on raw scene photos of the same lamps
//! (`spdcam_eval::trust::raw`), written as `<chart>.raw.trust.json`.

use crate::args::held_out::HeldOutArgs;
use anyhow::{bail, Context, Result};
use clap::Args;
use spdcam_core::builtin::DataDir;
use spdcam_core::fsio::write_atomic;
use spdcam_eval::trust::fit::calibrate as fit;
use spdcam_eval::trust::raw::calibrate_raw;
use spdcam_eval::trust::records::write_records;
use std::path::PathBuf;

/// Options of `spdcam trust calibrate`.
#[derive(Debug, Args)]
pub(super) struct CalibrateArgs {
    #[command(flatten)]
    photos: HeldOutArgs,
    /// For an SG model, also calibrate on the real photo sets' validation photos (the split
    /// of `spdcam experiment real-cameras`; each set at most a third as many photos as the
    /// virtual ones, evenly spaced): they join the bands, the expected GFC, the metric
    /// intervals and the clipping and difficulty levels; the self-check's levels stay those
    /// of the virtual photos.
    #[arg(long)]
    real: bool,
    /// Also calibrate on this many scene photos of each validation lamp (the chart in a
    /// cluttered scene through the whole camera chain, by the held-out cameras, found and
    /// sampled as a user's photo is): they join what the real photos join. 0: none.
    #[arg(long, default_value_t = 0)]
    scenes: usize,
    /// Calibrate this raw model (`spdcam generate --raw`; repeatable) instead of the
    /// `--model`s: on `--scenes` raw scene photos (DNGs) of each validation lamp, each
    /// estimated as a user's raw photo is, the `--model` of its chart finding and checking
    /// the chart. Written as `<chart>.raw.trust.json`.
    #[arg(long = "raw-model", value_name = "FILE")]
    raw_models: Vec<PathBuf>,
    /// The thesis's data (holding measured/…); default: the data directory's thesis/.
    #[arg(long)]
    thesis_data: Option<PathBuf>,
    /// Also write each model's calibration photos one by one (source, light, GFC, expected
    /// GFC, held-out residual, self-check, veil, clipping, CCT) as
    /// `<chart>.calibration-photos.csv` into this directory.
    #[arg(long)]
    records: Option<PathBuf>,
    /// Directory to write `<chart>.trust.json` into.
    #[arg(short, long)]
    output: PathBuf,
}

/// Runs `spdcam trust calibrate`.
pub(super) fn run(args: CalibrateArgs, data_dir: &DataDir) -> Result<()> {
    std::fs::create_dir_all(&args.output)
        .with_context(|| format!("creating {}", args.output.display()))?;
    let raw = !args.raw_models.is_empty();
    if raw && args.real {
        bail!("--real calibrates a model on the real photo sets' JPEGs; a raw model (--raw-model) is calibrated on raw scene photos alone: leave out --real");
    }
    let fitted = if raw {
        calibrate_raw(
            &args.photos.protocol(),
            &args.raw_models,
            args.scenes,
            data_dir,
        )?
    } else {
        fit(
            &args.photos.protocol(),
            args.scenes,
            args.real,
            args.thesis_data.as_deref(),
            data_dir,
        )?
    };
    let stem = |chart: &str| {
        if raw {
            format!("{chart}.raw")
        } else {
            chart.to_string()
        }
    };
    for skipped in &fitted.skipped {
        eprintln!("warning: {skipped}");
    }
    for c in fitted.models {
        let out = args.output.join(format!("{}.trust.json", stem(&c.chart)));
        let json = serde_json::to_string_pretty(&c.calibration)?;
        write_atomic(&out, format!("{json}\n").as_bytes())?;
        if let Some(dir) = &args.records {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
            let file = dir.join(format!("{}.calibration-photos.csv", stem(&c.chart)));
            write_records(&file, &c.records)?;
            eprintln!(
                "{}: {} calibration photos → {}",
                c.model.display(),
                c.records.len(),
                file.display()
            );
        }
        eprintln!(
            "{}: calibration → {} (expected GFC from ln(difficulty) and {} principal components, its margin {}; {} scene photos per lamp; {} real photos)",
            c.model.display(),
            out.display(),
            c.calibration.gfc_model.components.len(),
            c.calibration.local_margin.as_ref().map_or("pooled".to_string(), |l| format!(
                "among the {} calibration photos most like each photo",
                l.neighbours
            )),
            c.calibration.scenes_per_lamp,
            c.calibration.real_photos
        );
    }
    Ok(())
}
