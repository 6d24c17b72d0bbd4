//! `spdcam trust`: the uncertainty calibration of a model (`calibrate`: held-out virtual
//! photos of the split's validation lamps → `<chart>.trust.json`) and its measurement
//! (`report`: the split's test lamps, the real photo sets, photos made bad on purpose →
//! docs/trust.md). The protocols are `spdcam_eval::trust`'s; this parses their options and
//! writes their results.

use crate::held_out_args::HeldOutArgs;
use crate::plot_file;
use anyhow::{Context, Result};
use clap::{Args, Subcommand};
use spdcam_core::builtin::DataDir;
use spdcam_core::fsio::write_atomic;
use spdcam_eval::held_out::file_name;
use spdcam_eval::trust::fit::calibrate as fit;
use spdcam_eval::trust::report::TrustReport;
use std::path::PathBuf;

/// Options of `spdcam trust`.
#[derive(Debug, Args)]
pub struct TrustArgs {
    #[command(subcommand)]
    command: TrustCommand,
}

#[derive(Debug, Subcommand)]
enum TrustCommand {
    /// Calibrate the bands and expected GFC of models on the split's validation lamps.
    Calibrate(Box<CalibrateArgs>),
    /// Measure the calibrated models on the test lamps, the real photo sets and bad photos.
    Report(Box<ReportArgs>),
}

/// Options of `spdcam trust calibrate`.
#[derive(Debug, Args)]
struct CalibrateArgs {
    #[command(flatten)]
    photos: HeldOutArgs,
    /// For an SG model, also calibrate on the real photo sets' validation photos (the split
    /// of `spdcam experiment real-cameras`; each set at most a third as many photos as the
    /// virtual ones, evenly spaced): they join the bands, the expected GFC, the metric
    /// intervals and the clipping and difficulty levels; the self-check's levels stay those
    /// of the virtual photos.
    #[arg(long)]
    real: bool,
    /// The thesis's data (holding measured/…); default: the data directory's thesis/.
    #[arg(long)]
    thesis_data: Option<PathBuf>,
    /// Directory to write `<chart>.trust.json` into.
    #[arg(short, long)]
    output: PathBuf,
}

/// Options of `spdcam trust report`.
#[derive(Debug, Args)]
struct ReportArgs {
    #[command(flatten)]
    photos: HeldOutArgs,
    /// The calibrations, in the order of the models.
    #[arg(long, required = true)]
    calibration: Vec<PathBuf>,
    /// The thesis's data (holding measured/…); default: the data directory's thesis/.
    #[arg(long)]
    thesis_data: Option<PathBuf>,
    /// Output Markdown (printed too).
    #[arg(short, long)]
    output: PathBuf,
    /// Also draw the reliability diagram (.svg or .png) and show it in the Markdown.
    #[arg(long)]
    reliability: Option<PathBuf>,
}

/// Runs `spdcam trust`.
pub fn run(args: TrustArgs, data_dir: &DataDir) -> Result<()> {
    match args.command {
        TrustCommand::Calibrate(a) => calibrate(*a, data_dir),
        TrustCommand::Report(a) => report(*a, data_dir),
    }
}

fn calibrate(args: CalibrateArgs, data_dir: &DataDir) -> Result<()> {
    std::fs::create_dir_all(&args.output)
        .with_context(|| format!("creating {}", args.output.display()))?;
    let fitted = fit(
        &args.photos.protocol(),
        args.real,
        args.thesis_data.as_deref(),
        data_dir,
    )?;
    for skipped in &fitted.skipped {
        eprintln!("warning: {skipped}");
    }
    for c in fitted.models {
        let out = args.output.join(format!("{}.trust.json", c.chart));
        let json = serde_json::to_string_pretty(&c.calibration)?;
        write_atomic(&out, format!("{json}\n").as_bytes())?;
        eprintln!(
            "{}: calibration → {} (expected GFC from ln(difficulty) and {} principal components; {} real photos)",
            c.model.display(),
            out.display(),
            c.calibration.gfc_model.components.len(),
            c.calibration.real_photos
        );
    }
    Ok(())
}

fn report(args: ReportArgs, data_dir: &DataDir) -> Result<()> {
    let measured = TrustReport::measure(
        &args.photos.protocol(),
        &args.calibration,
        args.thesis_data.as_deref(),
        data_dir,
        &mut |model| eprintln!("{}: measured", model.display()),
    )?;
    for skipped in measured.skipped() {
        eprintln!("warning: {skipped}");
    }
    let diagram = match &args.reliability {
        Some(path) => {
            plot_file::write_plot(path, &measured.diagram_svg()?)?;
            // Beside the report, the image is named by its file name alone.
            Some(match (path.parent(), args.output.parent()) {
                (Some(a), Some(b)) if a == b => file_name(path),
                _ => path.display().to_string(),
            })
        }
        None => None,
    };
    let photos = args.photos.command_line();
    let report_options: String = args
        .calibration
        .iter()
        .map(|c| format!(" --calibration {}", c.display()))
        .chain(
            args.reliability
                .iter()
                .map(|r| format!(" --reliability {}", r.display())),
        )
        .collect();
    let commands = format!(
        "spdcam trust calibrate --real{photos} -o models\nspdcam trust report{photos}{report_options} -o {}",
        args.output.display()
    );
    let md = measured.markdown(diagram.as_deref(), &commands);
    write_atomic(&args.output, md.as_bytes())?;
    print!("{md}");
    Ok(())
}
