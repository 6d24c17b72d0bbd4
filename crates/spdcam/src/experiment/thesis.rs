//! `spdcam experiment thesis`: the thesis's model-selection experiment (section 4.6, Tables
//! 4.2–4.4) on its own virtual datasets — Gaussian G1–G4 (4–7 channels) and the 24-channel
//! Telelumen set, ColorChecker 24 — with our models, beside the thesis's numbers.
//!
//! Each set's `_train` part trains (a seeded 10 % of it selects the epoch), its `_val` part
//! is the test set (the thesis's own test parts are kept aside). SPDs are made from the
//! weights with the thesis's channels (`THESIS-PARAMETERS.md`), then normalised to a maximum
//! of 1. Models predict PCA coefficients of the SPD (`--target weights`: the channel weights,
//! as the thesis did for these sets). The protocol is `spdcam_learn::experiment`'s; this
//! parses its options and prints and writes its results.

use crate::evaluate::metrics_table;
use crate::train::{reporter, ModelKind, Preset, TargetArg};
use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use spdcam_core::fsio::write_atomic;
use spdcam_core::spectral::Grid;
use spdcam_infer::pca::Components;
use spdcam_infer::target::TargetKind;
use spdcam_learn::experiment::sets;
use spdcam_learn::experiment::thesis::{train_options, SetParts, ThesisRow};
use spdcam_learn::train::Schedule;
use std::path::PathBuf;

/// Options of `spdcam experiment thesis`.
#[derive(Debug, Args)]
pub(super) struct ThesisArgs {
    /// The thesis's data directory (holding `virtual/` and `telelumen_24_channels.csv`);
    /// default: `thesis` under --data-dir / $SPDCAM_DATA.
    #[arg(long, value_name = "DIR")]
    thesis_data: Option<PathBuf>,
    /// Report directory.
    #[arg(short, long)]
    output: PathBuf,
    /// Sets to run: g1–g4 (the thesis's Gaussian sets), t24 (all 24 Telelumen channels; the
    /// thesis's H2 used the SG chart, this set uses CC24).
    #[arg(long, value_delimiter = ',', default_value = "g1,g2,g3,g4,t24")]
    sets: Vec<sets::SetName>,
    /// Models to run.
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        default_value = "cnn1d,mlp,linear"
    )]
    models: Vec<ModelKind>,
    /// Schedule preset.
    #[arg(long, value_enum, default_value = "default")]
    preset: Preset,
    /// Override the preset's epochs.
    #[arg(long)]
    epochs: Option<usize>,
    /// Seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Targets: PCA coefficients of the SPD (measured best) or the channel weights (the
    /// thesis's choice for these sets).
    #[arg(long, value_enum, default_value = "pca")]
    target: TargetArg,
    /// Grid the SPDs are scored on.
    #[arg(long, default_value = "400-700:5", value_name = "START-END[:STEP]")]
    grid: String,
}

/// Runs `spdcam experiment thesis`.
pub(super) fn run(args: ThesisArgs, data_dir: &spdcam_core::builtin::DataDir) -> Result<()> {
    let root = match (&args.thesis_data, data_dir.root()) {
        (Some(p), _) => p.clone(),
        (None, Some(r)) => r.join("thesis"),
        (None, None) => {
            bail!("give --thesis-data DIR, or --data-dir / SPDCAM_DATA holding thesis/")
        }
    };
    spdcam_core::fsio::check_output_apart(&args.output, &[&root])?;
    std::fs::create_dir_all(&args.output)
        .with_context(|| format!("creating {}", args.output.display()))?;
    let grid = Grid::parse(&args.grid)?;
    let mut table = String::from(
        "| set | model | GFC mean | GFC std | RMSE | SAM | SID | thesis GFC | epochs (best) | train s | s/epoch |\n\
         |---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut results = Vec::new();
    let mut details = String::new();
    for &set in &args.sets {
        let parts = SetParts::read(set, &root)?;
        for &kind in &args.models {
            let architecture = kind.architecture();
            let mut schedule = match args.preset {
                Preset::Thesis => Schedule::thesis(),
                Preset::Default => Schedule::default_for(&architecture),
            };
            if let Some(e) = args.epochs {
                schedule.epochs = e;
            }
            let target = match args.target {
                TargetArg::Weights => TargetKind::Weights,
                TargetArg::Pca => TargetKind::Pca(Components::default()),
                TargetArg::PcaColour => TargetKind::PcaColour {
                    components: Components::default(),
                    colour_weight: 1.0,
                },
            };
            let options = train_options(architecture, schedule, target, grid, args.seed);
            let name = kind
                .to_possible_value()
                .map(|v| v.get_name().to_string())
                .unwrap_or_default();
            eprintln!(
                "{} {name}: training on {} samples",
                parts.set.label(),
                parts.train.samples.len()
            );
            let (mut report, bar) = reporter(options.schedule.epochs);
            let row = ThesisRow::measure(&parts, &name, &options, &mut report);
            if let Some(bar) = bar {
                bar.finish_and_clear();
            }
            let row = row?;
            let line = row.table_line();
            eprint!("{line}");
            table.push_str(&line);
            details.push_str(&format!(
                "\n## {} — {name}\n\n{}",
                parts.set.label(),
                metrics_table(&row.evaluation)
            ));
            results.push(row.json());
        }
    }
    let md = format!(
        "# The thesis's virtual datasets\n\nTrained on `_train` (10 % of it held out to select \
         the epoch), tested on `_val`; targets {:?}; SPDs scored on {} nm; preset {:?}, \
         seed {}.\n\n{table}{details}",
        args.target,
        grid.label(),
        args.preset,
        args.seed
    );
    write_atomic(&args.output.join("results.md"), md.as_bytes())?;
    write_atomic(
        &args.output.join("results.json"),
        serde_json::to_string_pretty(&results)?.as_bytes(),
    )?;
    println!("{table}\nreport: {}", args.output.display());
    Ok(())
}
