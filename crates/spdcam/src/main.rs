//! spdcam: what light is in the room, from a photo of a colour chart.

mod dataset;
mod generate;
mod list;
mod render;

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// Estimate the spectrum of the light from an sRGB photo of a colour chart, and simulate
/// the camera that takes such photos.
#[derive(Debug, Parser)]
#[command(name = "spdcam", version, about)]
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
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let data_dir = spdcam_core::builtin::DataDir::new(cli.data_dir);
    let result = match cli.command {
        Command::Render(args) => render::run(*args, &data_dir),
        Command::Generate(args) => generate::run(*args, &data_dir),
        Command::Dataset(args) => dataset::run(args, &data_dir),
        Command::List(args) => list::run(args, &data_dir),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
