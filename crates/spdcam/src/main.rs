//! spdcam: what light is in the room, from a photo of a colour chart.
//!
//! One module per subcommand, each parsing its arguments and calling the libraries
//! (`spdcam_infer` to estimate, `spdcam_core` to render and generate, `spdcam_learn` and
//! `spdcam_eval` to train and measure): `estimate`, `metrics`, `serve` (the web app),
//! `render`, `generate`, `dataset`, `list`, `lamps`, `detection`, `coverage`, `light_kinds`,
//! `trust`, `colour_map`, `fit_in_camera`; with the `train` feature `train`, `average`,
//! `evaluate`, `finetune`, `experiment` and `sim2real`. Shared by them: `args` (argument
//! groups), `command_paths` (the paths a command reads and writes), `messages` and `stdout` (where text
//! goes, and failed writes reported), `plot_file` (SVG or PNG plots).

// The commands' doc comments are clap's help text, where `[:STEP]` marks an optional part,
// not a link.
#![allow(rustdoc::broken_intra_doc_links)]

mod args;
#[cfg(feature = "train")]
mod average;
mod colour_map;
mod command_paths;
mod coverage;
mod dataset;
mod detection;
mod estimate;
#[cfg(feature = "train")]
mod evaluate;
#[cfg(feature = "train")]
mod experiment;
#[cfg(feature = "train")]
mod finetune;
mod fit_in_camera;
mod generate;
mod lamps;
mod light_kinds;
mod list;
mod messages;
mod metrics;
mod plot_file;
mod render;
mod serve;
#[cfg(feature = "train")]
mod sim2real;
mod stdout;
#[cfg(feature = "train")]
mod train;
mod trust;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// Estimate the spectrum of the light from an sRGB photo of a colour chart, and simulate
/// the camera that takes such photos.
#[derive(Debug, Parser)]
#[command(name = "spdcam", version, about, max_term_width = 100)]
struct Cli {
    /// Directory where named data (cameras, charts, luminaires) are found; default: $SPDCAM_DATA.
    #[arg(long, global = true, value_name = "DIR")]
    data_dir: Option<PathBuf>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Render a chart under a light through the virtual camera.
    Render(Box<render::RenderArgs>),
    /// Generate a dataset of (features, SPD) samples with the virtual camera.
    Generate(Box<generate::GenerateArgs>),
    /// Import, export, merge, split and inspect datasets.
    Dataset(dataset::DatasetArgs),
    /// List built-in cameras, charts, illuminants, lighting recipes and presets.
    List(list::ListArgs),
    /// Lighting-quality metrics (CCT, CRI, TM-30, α-opic, S/P, PPF) of SPDs.
    Metrics(metrics::MetricsArgs),
    #[cfg(feature = "train")]
    /// Train a model (1D CNN, MLP or ridge baseline) on a dataset.
    Train(Box<train::TrainArgs>),
    #[cfg(feature = "train")]
    /// Make one model of several trained ones that estimates the mean of their outputs.
    Average(average::AverageArgs),
    /// Estimate the light's SPD from photos of a colour chart (or chart features).
    Estimate(Box<estimate::EstimateArgs>),
    /// How often the charts are found in scene photos, per difficulty (Markdown).
    Detection(detection::DetectionArgs),
    #[cfg(feature = "train")]
    /// Score a model on a dataset: metrics, per-band error, plots.
    Evaluate(evaluate::EvaluateArgs),
    #[cfg(feature = "train")]
    /// Adapt a trained model to a small new dataset (transfer learning).
    Finetune(Box<finetune::FinetuneArgs>),
    #[cfg(feature = "train")]
    /// Reproduce the thesis's experiments on its own datasets.
    Experiment(experiment::ExperimentArgs),
    /// Fit a real camera's in-camera rendering to a few of its chart photos with known light.
    FitInCamera(Box<fit_in_camera::FitInCameraArgs>),
    #[cfg(feature = "train")]
    /// The sim-to-real ablation: virtual-only models scored on the real photo sets.
    Sim2real(sim2real::Sim2realArgs),
    /// Serve a local web page where photos are dropped and their light is shown.
    Serve(serve::ServeArgs),
    /// How well lighting recipes cover measured SPDs, per lamp type.
    Coverage(Box<coverage::CoverageArgs>),
    /// Real lamps: the validation split, the lamp-family fits, the validation protocol.
    Lamps(lamps::LampsArgs),
    /// The kinds of light `estimate --light` takes, and each model's priors for them.
    LightKinds(light_kinds::LightKindsArgs),
    /// A model's correction of the light's colour, fitted on validation photos.
    ColourMap(colour_map::ColourMapArgs),
    /// Calibrate and measure how far estimates can be trusted (bands, verdicts).
    Trust(trust::TrustArgs),
}

/// Output piped into a program that stops reading (`spdcam … | head`) ends spdcam quietly,
/// as it ends other command-line tools, instead of failing a write.
#[cfg(unix)]
fn exit_quietly_on_closed_pipe() {
    // SAFETY: sets the disposition of one signal to its default, before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

fn main() -> ExitCode {
    #[cfg(unix)]
    exit_quietly_on_closed_pipe();
    let command = Cli::command();
    let matches = command.clone().get_matches();
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    if let Err(e) = command_paths::check(&command, &matches) {
        eprintln!("error: {}", error_text(&e));
        return ExitCode::FAILURE;
    }
    let data_dir = spdcam_core::builtin::DataDir::new(cli.data_dir);
    if let Err(e) = data_dir.check() {
        eprintln!("error: {e}");
        return ExitCode::FAILURE;
    }
    // A limit's variable that is not a number is named before any work, whichever limits
    // the command meets.
    if let Some(e) = spdcam_core::limits::ALL
        .iter()
        .find_map(|l| l.value().err())
    {
        eprintln!("error: {e}");
        return ExitCode::FAILURE;
    }
    let result = match cli.command {
        Command::Render(args) => render::run(*args, &data_dir),
        Command::Generate(args) => generate::run(*args, &data_dir),
        Command::Dataset(args) => dataset::run(args, &data_dir),
        Command::List(args) => list::run(args, &data_dir),
        Command::Metrics(args) => metrics::run(args, &data_dir),
        #[cfg(feature = "train")]
        Command::Train(args) => train::run(*args, &data_dir),
        #[cfg(feature = "train")]
        Command::Average(args) => average::run(args),
        Command::Estimate(args) => estimate::run(*args, &data_dir),
        Command::Detection(args) => detection::run(args, &data_dir),
        #[cfg(feature = "train")]
        Command::Evaluate(args) => evaluate::run(args, &data_dir),
        #[cfg(feature = "train")]
        Command::Finetune(args) => finetune::run(*args),
        #[cfg(feature = "train")]
        Command::Experiment(args) => experiment::run(args, &data_dir),
        Command::FitInCamera(args) => fit_in_camera::run(*args, &data_dir),
        #[cfg(feature = "train")]
        Command::Sim2real(args) => sim2real::run(args, &data_dir),
        Command::Serve(args) => serve::run(args, &data_dir),
        Command::Coverage(args) => coverage::run(*args, &data_dir),
        Command::Lamps(args) => lamps::run(args, &data_dir),
        Command::LightKinds(args) => light_kinds::run(args, &data_dir),
        Command::ColourMap(args) => colour_map::run(args, &data_dir),
        Command::Trust(args) => trust::run(args, &data_dir),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", error_text(&e));
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes joined by ": ", leaving out a cause the text already says (an
/// I/O error is often both in a message and its source).
fn error_text(error: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in error.chain() {
        let message = cause.to_string();
        if !text.contains(&message) {
            if !text.is_empty() {
                text.push_str(": ");
            }
            text.push_str(&message);
        }
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_os_error_is_printed_once() {
        // Issue 15: "Permission denied (os error 13): Permission denied (os error 13)".
        let io = std::io::Error::from(std::io::ErrorKind::PermissionDenied);
        let e = anyhow::Error::from(spdcam_core::Error::io("out.csv", io)).context("writing");
        let text = error_text(&e);
        assert_eq!(text.matches("denied").count(), 1, "{text}");
        assert!(text.starts_with("writing: out.csv: "), "{text}");
    }
}
