//! The options every protocol over held-out lamps and cameras shares (`spdcam lamps`,
//! `spdcam trust`): where the lamp library is read from, the models, the split and the photos.

use anyhow::Result;
use clap::Args;
use spdcam_core::builtin::DataDir;
use spdcam_core::light_families::LampLibrary;
use spdcam_core::spectral::Grid;
use spdcam_eval::held_out::{HeldOutPhotos, LampFiles};
use std::path::{Path, PathBuf};

/// Where the lamp library is read from.
#[derive(Debug, Args)]
pub struct LibraryArgs {
    /// Measured lamp SPDs (spectral CSV); default: the data directory's
    /// lamps/ies_tm30_lamps.csv.
    #[arg(long, value_name = "SPDS.csv")]
    pub lamps: Option<PathBuf>,
    /// The lamps' types (`column,type,category`); default: the data directory's
    /// lamps/ies_tm30_lamps_info.csv.
    #[arg(long, value_name = "INFO.csv")]
    pub types: Option<PathBuf>,
}

impl LibraryArgs {
    /// The files as the protocols take them.
    pub fn files(&self) -> LampFiles {
        LampFiles {
            lamps: self.lamps.clone(),
            types: self.types.clone(),
        }
    }

    /// Reads the library on `grid`.
    pub fn read(&self, data_dir: &DataDir, grid: &Grid) -> Result<LampLibrary> {
        Ok(self.files().read(data_dir, grid)?)
    }
}

/// Held-out lamps photographed by held-out cameras: the models, the split and how many
/// photos (shared by `spdcam lamps validate` and `spdcam trust`).
#[derive(Debug, Args)]
pub struct HeldOutArgs {
    /// Models (repeatable).
    #[arg(long, required = true)]
    pub model: Vec<PathBuf>,
    /// The validation split (`spdcam lamps split`).
    #[arg(long, value_name = "SPLIT.json")]
    pub split: PathBuf,
    #[command(flatten)]
    pub library: LibraryArgs,
    /// Directory of camera sensitivity CSVs holding the split's held-out cameras; default:
    /// the data directory's cameras/.
    #[arg(long, value_name = "DIR")]
    pub cameras: Option<PathBuf>,
    /// Photos of each lamp, each by a held-out camera and in-camera settings drawn at random.
    #[arg(long, default_value_t = 8)]
    pub shots: u64,
    /// Seed of the draws.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

impl HeldOutArgs {
    /// The photos as the protocols take them.
    pub fn protocol(&self) -> HeldOutPhotos {
        HeldOutPhotos {
            models: self.model.clone(),
            split: self.split.clone(),
            library: self.library.files(),
            cameras: self.cameras.clone(),
            shots: self.shots,
            seed: self.seed,
        }
    }

    /// The options as a command line, for the records that say how to regenerate a result.
    pub fn command_line(&self) -> String {
        let mut out = flags(
            &self.model,
            &self.split,
            &self.library,
            self.cameras.as_deref(),
        );
        out += &format!(" --shots {} --seed {}", self.shots, self.seed);
        out
    }
}

/// The models, split, lamp library and cameras of a protocol over held-out lamps as
/// command-line flags (each with a leading space), for the records that say how to
/// regenerate a result.
pub fn flags(
    models: &[PathBuf],
    split: &Path,
    library: &LibraryArgs,
    cameras: Option<&Path>,
) -> String {
    let mut out: String = models
        .iter()
        .map(|m| format!(" --model {}", m.display()))
        .collect();
    out += &format!(" --split {}", split.display());
    if let Some(l) = &library.lamps {
        out += &format!(" --lamps {}", l.display());
    }
    if let Some(t) = &library.types {
        out += &format!(" --types {}", t.display());
    }
    if let Some(c) = cameras {
        out += &format!(" --cameras {}", c.display());
    }
    out
}
