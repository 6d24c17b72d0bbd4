//! `spdcam experiment colour`: every model judged on the light's colour as a colour meter
//! reads it (Δu′v′, CCT and its interval) beside its shape (GFC), on scene photos and
//! patch-level photos of the split's lamps and of white references by held-out cameras,
//! beside the constant. The protocol is `spdcam_eval::colour`'s; this parses its options
//! and writes its results.

use crate::args::held_out::{flags, LibraryArgs};
use anyhow::Result;
use clap::Args;
use spdcam_core::builtin::DataDir;
use spdcam_core::fsio::write_atomic;
use spdcam_eval::colour::{ColourOptions, ColourReport};
use spdcam_eval::held_out::HeldOutPhotos;
use spdcam_infer::kind_prior::KindPriors;
use std::path::PathBuf;

/// Options of `spdcam experiment colour`.
#[derive(Debug, Args)]
pub(super) struct ColourArgs {
    /// Models (repeatable); each reads the photos of the chart it names.
    #[arg(long, required = true)]
    model: Vec<PathBuf>,
    /// The validation split (`spdcam lamps split`): its lamps and held-out cameras.
    #[arg(long, value_name = "SPLIT.json")]
    split: PathBuf,
    #[command(flatten)]
    library: LibraryArgs,
    /// Directory of camera sensitivity CSVs holding the split's held-out cameras; default:
    /// the data directory's cameras/.
    #[arg(long, value_name = "DIR")]
    cameras: Option<PathBuf>,
    /// Scene photos of each lamp.
    #[arg(long, default_value_t = 2)]
    photos: u64,
    /// Scene photos of each white reference; default: twice --photos.
    #[arg(long)]
    reference_photos: Option<u64>,
    /// Patch-level photos of each light.
    #[arg(long, default_value_t = 8)]
    patch_photos: u64,
    /// Seed of the photos.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Also measure each model told each light's kind (`estimate --light`: a lamp's kind from
    /// its type, daylight or incandescent for the references), on the same photos.
    #[arg(long)]
    light_named: bool,
    /// Light-kind priors (`spdcam light-kinds fit`) for models without built-in ones
    /// (repeatable; each used for the model it was fitted to).
    #[arg(long, value_name = "PRIORS.json")]
    light_priors: Vec<PathBuf>,
    /// Take the scene photos (a) as raw DNGs of the same scenes (`render --scene -o x.dng`)
    /// instead of JPEGs.
    #[arg(long)]
    raw: bool,
    /// With --raw: a model that reads raw patches (`spdcam generate --raw`) for the chart of
    /// a --model, whose spectrum replaces that model's on the raw photos (repeatable).
    #[arg(long, value_name = "MODEL.spdm", requires = "raw")]
    raw_model: Vec<PathBuf>,
    /// Also write every photo's scores as CSV (model, light, camera, GFC, the true and
    /// estimated u′v′ and CCT, verdict): a row each.
    #[arg(long, value_name = "FILE.csv")]
    photos_csv: Option<PathBuf>,
    /// Output Markdown report.
    #[arg(short, long)]
    output: PathBuf,
}

impl ColourArgs {
    /// The options as a command line, for the record that says how to regenerate the report.
    fn command_line(&self, reference_photos: u64) -> String {
        let mut out = String::from("spdcam --data-dir DATA experiment colour");
        out += &flags(
            &self.model,
            &self.split,
            &self.library,
            self.cameras.as_deref(),
        );
        out += &format!(
            " --photos {} --reference-photos {reference_photos} --patch-photos {} --seed {}",
            self.photos, self.patch_photos, self.seed,
        );
        if self.light_named {
            out += " --light-named";
        }
        if self.raw {
            out += " --raw";
        }
        for p in &self.raw_model {
            out += &format!(" --raw-model {}", p.display());
        }
        for p in &self.light_priors {
            out += &format!(" --light-priors {}", p.display());
        }
        out += &format!(" -o {}", self.output.display());
        out
    }
}

/// Runs `spdcam experiment colour`.
pub(super) fn run(args: ColourArgs, data_dir: &DataDir) -> Result<()> {
    let reference_photos = args.reference_photos.unwrap_or(2 * args.photos);
    let options = ColourOptions {
        held_out: HeldOutPhotos {
            models: args.model.clone(),
            split: args.split.clone(),
            library: args.library.files(),
            cameras: args.cameras.clone(),
            shots: args.photos,
            seed: args.seed,
        },
        reference_photos,
        patch_photos: args.patch_photos,
        light_named: args.light_named,
        raw: args.raw,
        raw_models: args.raw_model.clone(),
        light_priors: args
            .light_priors
            .iter()
            .map(|p| {
                let text = spdcam_core::fsio::read_text(p)?;
                Ok(KindPriors::from_json(&text, &p.display().to_string())?)
            })
            .collect::<Result<_>>()?,
    };
    let started = std::time::Instant::now();
    let report = ColourReport::measure(&options, data_dir, &mut |what| {
        eprintln!("{what} ({:.0} s)", started.elapsed().as_secs_f64())
    })?;
    for skipped in &report.skipped {
        eprintln!("warning: {skipped}");
    }
    let md = format!(
        "# The light's colour, read as a colour meter reads it\n\n\
         Regenerated by the command at the end.\n\n{}\n```\n{}\n```\n",
        report.markdown(),
        args.command_line(reference_photos)
    );
    if let Some(path) = &args.photos_csv {
        write_atomic(path, report.photos_csv()?.as_bytes())?;
    }
    write_atomic(&args.output, md.as_bytes())?;
    print!("{md}");
    Ok(())
}
