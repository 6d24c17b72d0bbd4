//! spdcam: what light is in the room, from a photo of a colour chart.

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
    Render(render::RenderArgs),
    /// List built-in cameras, charts, illuminants and presets.
    List(list::ListArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let data_dir = spdcam_core::builtin::DataDir::new(cli.data_dir);
    let result = match cli.command {
        Command::Render(args) => render::run(args, &data_dir),
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
