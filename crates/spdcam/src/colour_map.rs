//! `spdcam colour-map fit`: a correction of the light's colour for a model, fitted on the
//! split's validation lamps through its training cameras (the protocol is
//! `spdcam_eval::colour::map_fit`'s; this parses its options and writes the model).
//! `spdcam colour-map raw`: the correction of raw files' colour matrices, fitted on the
//! split's fit lamps through its training cameras (`spdcam_eval::colour::raw_fit`).

use crate::args::held_out::LibraryArgs;
use anyhow::Result;
use clap::{Args, Subcommand};
use spdcam_core::builtin::DataDir;
use spdcam_core::fsio;
use spdcam_eval::colour::map_fit::{MapFit, MapFitOptions};
use spdcam_eval::colour::raw_fit::{RawFit, RawFitOptions};
use std::path::PathBuf;

/// Options of `spdcam colour-map`.
#[derive(Debug, Args)]
pub struct ColourMapArgs {
    #[command(subcommand)]
    command: ColourMapCommand,
}

#[derive(Debug, Subcommand)]
enum ColourMapCommand {
    /// Fit the map of a model's estimated colour temperature and Duv of white light to the
    /// true light's on the split's validation lamps photographed by its training cameras,
    /// and write the model with it (needs the data directory).
    Fit(FitArgs),
    /// Fit the correction of the light's colour that raw files' 3×3 colour matrices read, as
    /// a function of the light's shape, on the split's fit lamps seen by its training
    /// cameras, and write it (`models/raw-colour.json`; needs the data directory).
    Raw(RawArgs),
}

#[derive(Debug, Args)]
struct RawArgs {
    /// The validation split (`spdcam lamps split`): its fit lamps and training cameras.
    #[arg(long, value_name = "SPLIT.json")]
    split: PathBuf,
    #[command(flatten)]
    library: LibraryArgs,
    /// Directory of camera sensitivity CSVs holding the split's training cameras; default:
    /// the data directory's cameras/.
    #[arg(long, value_name = "DIR")]
    cameras: Option<PathBuf>,
    /// The ridge penalty, relative to the mean diagonal of XᵀX.
    #[arg(long, default_value_t = spdcam_eval::colour::raw_fit::PENALTY)]
    penalty: f64,
    /// A raw model (`spdcam generate --raw`; repeatable): fit the bias on the shapes it
    /// reads from each training camera's raw patches of its chart, rather than on the lights'
    /// true shapes (every model's readings pooled).
    #[arg(long = "raw-model", value_name = "FILE")]
    raw_models: Vec<PathBuf>,
    /// The correction (JSON).
    #[arg(short, long, value_name = "FILE.json")]
    output: PathBuf,
}

#[derive(Debug, Args)]
struct FitArgs {
    /// The model (.spdm); a map it has already is replaced.
    #[arg(long, value_name = "MODEL.spdm")]
    model: PathBuf,
    /// The validation split (`spdcam lamps split`): its validation lamps and training
    /// cameras.
    #[arg(long, value_name = "SPLIT.json")]
    split: PathBuf,
    #[command(flatten)]
    library: LibraryArgs,
    /// Directory of camera sensitivity CSVs holding the split's training cameras; default:
    /// the data directory's cameras/.
    #[arg(long, value_name = "DIR")]
    cameras: Option<PathBuf>,
    /// Scene photos of each lamp (the full camera chain, found and sampled as a user's).
    #[arg(long, default_value_t = 8)]
    photos: u64,
    /// Patch-level photos of each lamp (the randomised in-camera stage; none by default:
    /// the map is for photos as users take them).
    #[arg(long, default_value_t = 0)]
    patch_photos: u64,
    /// Seed of the photos.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// The model with its map (.spdm).
    #[arg(short, long, value_name = "MODEL.spdm")]
    output: PathBuf,
}

/// Runs `spdcam colour-map`.
pub fn run(args: ColourMapArgs, data_dir: &DataDir) -> Result<()> {
    match args.command {
        ColourMapCommand::Fit(a) => fit(a, data_dir),
        ColourMapCommand::Raw(a) => raw(a, data_dir),
    }
}

fn raw(args: RawArgs, data_dir: &DataDir) -> Result<()> {
    fsio::check_parent_dir(&args.output)?;
    let options = RawFitOptions {
        split: args.split,
        library: args.library.files(),
        cameras: args.cameras,
        penalty: args.penalty,
        raw_models: args.raw_models,
    };
    let fit = RawFit::fit(&options, data_dir, &mut |what| eprintln!("{what}"))?;
    for s in &fit.skipped {
        eprintln!("left out training camera {}: {}", s.name, s.reason);
    }
    let mut text = serde_json::to_string_pretty(&fit.correction)?;
    text.push('\n');
    fsio::write_atomic(&args.output, text.as_bytes())?;
    let [[fit_before, fit_after], [val_before, val_after]] = fit.median_delta_uv;
    println!(
        "fitted on {}\nmedian Δu′v′ of the matrices' reading: fit lights {fit_before:.4} → \
         {fit_after:.4}; validation lamps (unseen), the same cameras {val_before:.4} → \
         {val_after:.4}\nwrote {}",
        fit.correction.fitted_on,
        args.output.display()
    );
    Ok(())
}

fn fit(args: FitArgs, data_dir: &DataDir) -> Result<()> {
    fsio::check_parent_dir(&args.output)?;
    let options = MapFitOptions {
        model: args.model,
        split: args.split,
        library: args.library.files(),
        cameras: args.cameras,
        scene_photos: args.photos,
        patch_photos: args.patch_photos,
        seed: args.seed,
    };
    let fit = MapFit::fit(&options, data_dir, &mut |what| eprintln!("{what}"))?;
    for s in &fit.skipped {
        eprintln!("left out training camera {}: {}", s.name, s.reason);
    }
    fit.model.save(&args.output)?;
    let map = fit
        .model
        .header()
        .colour_map
        .as_ref()
        .ok_or_else(|| anyhow::anyhow!("the fitted model lost its colour map"))?;
    println!(
        "mired ← {:.4}·mired {:+.2}\nDuv ← {:.4}·Duv {:+.5}\n(white light only: in full up to |Duv| {}, \
         fading to nothing at {})\nfitted on {}\nmedian Δu′v′ on those photos: {:.4} → {:.4}\nwrote {}",
        map.mired.slope,
        map.mired.offset,
        map.duv.slope,
        map.duv.offset,
        spdcam_infer::colour_map::FULL_DUV,
        spdcam_infer::colour_map::NO_DUV,
        map.fitted_on,
        fit.median_delta_uv[0],
        fit.median_delta_uv[1],
        args.output.display()
    );
    Ok(())
}
