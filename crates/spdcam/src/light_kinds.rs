//! `spdcam light-kinds`: the kinds of light a person can name (`estimate --light`, the page's
//! picker, Python's `light=`), and `fit`: a model's priors for each (the protocol is
//! `spdcam_eval::light_kinds`'s; this parses its options and writes its results).

use anyhow::Result;
use clap::{Args, Subcommand};
use spdcam_core::builtin::DataDir;
use spdcam_core::chart::KnownChart;
use spdcam_core::fsio;
use spdcam_core::light_families::LightKind;
use spdcam_eval::light_kinds::{real_checks, real_markdown, KindFit, KindFitOptions};
use std::path::PathBuf;

/// Options of `spdcam light-kinds`.
#[derive(Debug, Args)]
pub struct LightKindsArgs {
    #[command(subcommand)]
    command: LightKindsCommand,
}

#[derive(Debug, Subcommand)]
enum LightKindsCommand {
    /// The kinds of light `estimate --light` takes, each with the recipe its prior is drawn
    /// from.
    List,
    /// Fit a model's priors for every kind of light: lights drawn from each kind's recipe,
    /// photographed by the split's training cameras (needs the data directory).
    Fit(FitArgs),
}

#[derive(Debug, Args)]
struct FitArgs {
    /// The model (.spdm) whose estimates the priors move.
    #[arg(long, value_name = "MODEL.spdm")]
    model: PathBuf,
    /// The validation split (`spdcam lamps split`): its training cameras take the photos.
    #[arg(long, value_name = "SPLIT.json")]
    split: PathBuf,
    /// Directory of camera sensitivity CSVs holding the split's training cameras; default:
    /// the data directory's cameras/.
    #[arg(long, value_name = "DIR")]
    cameras: Option<PathBuf>,
    /// Lights of each kind kept as its prior.
    #[arg(long, default_value_t = 400)]
    particles: usize,
    /// Photos of each kind the model's residuals are measured on.
    #[arg(long, default_value_t = 2000)]
    photos: usize,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output JSON (the shipped models' priors live in `models/<chart>.kinds.json`).
    #[arg(short, long)]
    output: PathBuf,
}

/// Runs `spdcam light-kinds`.
pub fn run(args: LightKindsArgs, data_dir: &DataDir) -> Result<()> {
    match args.command {
        LightKindsCommand::List => {
            for kind in LightKind::ALL {
                println!(
                    "{:<13} {}; prior: {}",
                    kind.name(),
                    kind.describe(),
                    kind.recipe()
                        .unwrap_or("every light the model was trained on")
                );
            }
            Ok(())
        }
        LightKindsCommand::Fit(a) => fit(a, data_dir),
    }
}

fn fit(args: FitArgs, data_dir: &DataDir) -> Result<()> {
    fsio::check_parent_dir(&args.output)?;
    let options = KindFitOptions {
        model: args.model,
        split: args.split,
        cameras: args.cameras,
        particles: args.particles,
        photos: args.photos,
        seed: args.seed,
    };
    let fit = KindFit::fit(&options, data_dir, &mut |kind| eprintln!("fitting {kind}"))?;
    for s in &fit.skipped {
        eprintln!("left out training camera {}: {}", s.name, s.reason);
    }
    fsio::write_atomic(&args.output, fit.priors.to_json()?.as_bytes())?;
    println!(
        "Each kind's prior fitted on half its photos, tried on the other half (training \
         cameras, in distribution):\n\n{}",
        fit.markdown()
    );
    if fit.model.header().chart.as_deref() == Some(KnownChart::Sg96.name()) {
        let checks = real_checks(&fit.model, &fit.priors, data_dir)?;
        println!(
            "The real photo sets (outside their test photos):\n\n{}",
            real_markdown(&checks)
        );
    }
    println!("wrote {}", args.output.display());
    Ok(())
}
