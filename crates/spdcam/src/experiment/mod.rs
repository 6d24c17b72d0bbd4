//! `spdcam experiment`: the thesis's model-selection experiment on its virtual datasets,
//! the real-camera study, the light's colour as a colour meter reads it, and the light at
//! several places of one photo.

mod colour;
mod places;
mod real_cameras;
mod thesis;

use anyhow::Result;
use clap::{Args, Subcommand};
use thesis::ThesisArgs;

/// Options of `spdcam experiment`.
#[derive(Debug, Args)]
pub struct ExperimentArgs {
    #[command(subcommand)]
    command: ExperimentCommand,
}

#[derive(Debug, Subcommand)]
enum ExperimentCommand {
    /// Train and test on the thesis's virtual datasets; compare with its Tables 4.2–4.4.
    Thesis(ThesisArgs),
    /// Every way of estimating on the real photo sets' validation and test photos, beside a
    /// constant guess and ridge on real photos (`docs/real-cameras-table.md`).
    RealCameras(real_cameras::RealCamerasArgs),
    /// Every model judged on the light's colour (Δu′v′, CCT and its interval) on scene and
    /// patch-level photos of the split's lamps and white references by held-out cameras,
    /// beside the constant (`docs/colour.md`).
    Colour(colour::ColourArgs),
    /// The light at several places: rendered scenes of two to four charts under the split's
    /// lamps through its held-out cameras, each chart against itself alone, the lights told
    /// apart, the light levels between places (`docs/places.md`).
    Places(places::PlacesArgs),
}

/// Runs `spdcam experiment`.
pub fn run(args: ExperimentArgs, data_dir: &spdcam_core::builtin::DataDir) -> Result<()> {
    match args.command {
        ExperimentCommand::Thesis(a) => thesis::run(a, data_dir),
        ExperimentCommand::RealCameras(a) => real_cameras::run(a, data_dir),
        ExperimentCommand::Colour(a) => colour::run(a, data_dir),
        ExperimentCommand::Places(a) => places::run(a, data_dir),
    }
}
