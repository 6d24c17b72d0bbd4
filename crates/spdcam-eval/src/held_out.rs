//! Held-out lamps photographed by held-out cameras: where the lamp library and the cameras
//! are read from, the split's held-out cameras, and the models a protocol measures (shared by
//! the lamp validation and the trust calibration and report).

use crate::error::{EvalError, Result};
use spdcam_core::builtin::DataDir;
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::CameraConfig;
use spdcam_core::chart::Chart;
use spdcam_core::dataset::randomise::{camera_pool, InCameraRanges, Randomisation};
use spdcam_core::lighting::{LampLibrary, ValidationSplit};
use spdcam_core::metrics;
use spdcam_core::spectral::{Extrapolation, Grid, Interpolation, SpectralSet};
use spdcam_infer::Model;
use std::path::{Path, PathBuf};

/// The lamp library's SPDs inside the data directory.
pub const LAMP_SPDS: &str = "lamps/ies_tm30_lamps.csv";
/// The lamp library's type table inside the data directory.
pub const LAMP_TYPES: &str = "lamps/ies_tm30_lamps_info.csv";
/// The grid the lamps are photographed on.
pub const GRID: Grid = Grid::SIMULATION;

/// The in-camera stage every protocol over held-out lamps draws from: exposure, white
/// balance, tone, JPEG and the light's gradient across the chart.
pub const IN_CAMERA_GROUPS: [&str; 5] = ["exposure", "wb", "tone", "jpeg", "gradient"];

/// `cameras` photographing `chart` without sensor noise, each shot with in-camera settings
/// drawn from [`IN_CAMERA_GROUPS`] (`stream` seeds the draws): what the lamp validation and
/// the trust protocols photograph held-out lamps with.
pub fn randomised_cameras(
    cameras: &[Sensitivities],
    stream: u64,
    chart: &Chart,
) -> Result<Randomisation> {
    let config = CameraConfig {
        noise: None,
        ..CameraConfig::default()
    };
    let pool = camera_pool(cameras, 0, stream, chart, config, &GRID)?;
    Ok(Randomisation::new(
        pool,
        InCameraRanges::for_groups(&IN_CAMERA_GROUPS)?,
    )?)
}

/// `given`, or `default` inside the data directory.
///
/// ```
/// use spdcam_core::builtin::DataDir;
/// use spdcam_eval::held_out::in_data_dir;
/// use std::path::Path;
///
/// let data = DataDir::new(Some(Path::new("/srv/spdcam-data").to_path_buf()));
/// assert_eq!(in_data_dir(None, "cameras", &data)?, Path::new("/srv/spdcam-data/cameras"));
/// assert_eq!(in_data_dir(Some(Path::new("mine")), "cameras", &data)?, Path::new("mine"));
/// // Without a data directory the default cannot be found, and the message says what to give.
/// if std::env::var_os("SPDCAM_DATA").is_none() {
///     let err = in_data_dir(None, "cameras", &DataDir::new(None)).unwrap_err();
///     assert!(err.to_string().contains("cameras"));
/// }
/// # Ok::<(), spdcam_eval::EvalError>(())
/// ```
pub fn in_data_dir(given: Option<&Path>, default: &str, data_dir: &DataDir) -> Result<PathBuf> {
    match given {
        Some(p) => Ok(p.to_path_buf()),
        None => Ok(data_dir
            .root()
            .ok_or_else(|| {
                EvalError::invalid(format!(
                    "give the file or a data directory (--data-dir / SPDCAM_DATA) holding {default}"
                ))
            })?
            .join(default)),
    }
}

/// The file stems of the camera CSVs in `dir`, sorted.
pub fn camera_names(dir: &Path) -> Result<Vec<String>> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map_err(|source| EvalError::Io {
            path: dir.to_path_buf(),
            source,
        })?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "csv"))
        .filter_map(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
        .collect();
    names.sort();
    Ok(names)
}

/// A file's name without its directories (they differ between machines), for the tables
/// that name models; the whole path when it has no name.
pub fn file_name(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into(),
    )
}

/// Where the lamp library is read from: given files, or the data directory's IES TM-30
/// library.
#[derive(Debug, Clone, Default)]
pub struct LampFiles {
    /// Measured lamp SPDs (spectral CSV); `None`: the data directory's [`LAMP_SPDS`].
    pub lamps: Option<PathBuf>,
    /// The lamps' types (`column,type,category`); `None`: the data directory's
    /// [`LAMP_TYPES`].
    pub types: Option<PathBuf>,
}

impl LampFiles {
    /// Reads the library on `grid`.
    pub fn read(&self, data_dir: &DataDir, grid: &Grid) -> Result<LampLibrary> {
        let spds = in_data_dir(self.lamps.as_deref(), LAMP_SPDS, data_dir)?;
        let types = in_data_dir(self.types.as_deref(), LAMP_TYPES, data_dir)?;
        Ok(LampLibrary::read(&spds, Some(&types), grid)?)
    }

    /// The library's file name, for records (no directories: they differ between machines).
    pub fn name(&self) -> String {
        self.lamps
            .as_deref()
            .and_then(|p| p.file_name())
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| LAMP_SPDS.to_string())
    }
}

/// The split's held-out cameras, read from `dir` (default: the data directory's cameras/);
/// cameras training skips (unusable curves) are skipped here too, named; none readable is an
/// error.
pub fn held_out_cameras(
    split: &ValidationSplit,
    dir: Option<&Path>,
    data_dir: &DataDir,
) -> Result<Vec<Sensitivities>> {
    let dir = in_data_dir(dir, "cameras", data_dir)?;
    let available = camera_names(&dir)?;
    let mut held_out: Vec<Sensitivities> = Vec::new();
    for name in &split.cameras.held_out {
        if !available.contains(name) {
            return Err(EvalError::invalid(format!(
                "held-out camera '{name}' is not in {}",
                dir.display()
            )));
        }
        let path = dir.join(format!("{name}.csv"));
        match Sensitivities::resolve(&path.to_string_lossy(), data_dir, &GRID) {
            Ok(s) => held_out.push(s),
            Err(e) => eprintln!("warning: skipping held-out camera {name}: {e:#}"),
        }
    }
    if held_out.is_empty() {
        return Err(EvalError::invalid(
            "none of the split's held-out cameras could be read",
        ));
    }
    Ok(held_out)
}

/// Every lamp of the library on `grid` (linear interpolation), normalised by its maximum.
pub fn on_grid(library: &LampLibrary, grid: &Grid) -> Result<Vec<Vec<f64>>> {
    let set = SpectralSet::from_spds(library.names.clone(), &library.spds)?;
    let (set, _) = set.resample(grid, Interpolation::Linear, Extrapolation::Zero)?;
    Ok(set
        .items()
        .iter()
        .map(|s| metrics::normalise_by_max(s))
        .collect())
}

/// Held-out lamps photographed by held-out cameras: the models measured, the split and how
/// many photos.
#[derive(Debug, Clone)]
pub struct HeldOutPhotos {
    /// The models' files.
    pub models: Vec<PathBuf>,
    /// The validation split (`spdcam lamps split`).
    pub split: PathBuf,
    /// The lamp library.
    pub library: LampFiles,
    /// Directory of camera sensitivity CSVs holding the split's held-out cameras; `None`:
    /// the data directory's cameras/.
    pub cameras: Option<PathBuf>,
    /// Photos of each lamp, each by a held-out camera and in-camera settings drawn at random.
    pub shots: u64,
    /// Seed of the draws.
    pub seed: u64,
}

/// What every protocol over [`HeldOutPhotos`] reads once: the library, the split and its
/// held-out cameras.
pub struct Setup {
    /// The lamp library on [`GRID`].
    pub library: LampLibrary,
    /// The validation split.
    pub split: ValidationSplit,
    /// The split's held-out cameras.
    pub cameras: Vec<Sensitivities>,
}

impl HeldOutPhotos {
    /// Reads the library, the split and the held-out cameras.
    pub fn setup(&self, data_dir: &DataDir) -> Result<Setup> {
        if self.shots == 0 {
            return Err(EvalError::invalid("--shots must be at least 1"));
        }
        let split = ValidationSplit::read(&self.split)?;
        Ok(Setup {
            library: self.library.read(data_dir, &GRID)?,
            cameras: held_out_cameras(&split, self.cameras.as_deref(), data_dir)?,
            split,
        })
    }

    /// The models, each with the chart it names.
    pub fn models(&self) -> Result<Vec<(PathBuf, Model, String)>> {
        self.models
            .iter()
            .map(|p| {
                let m = Model::load(p)?;
                let chart = m.header().chart.clone().ok_or_else(|| {
                    EvalError::invalid(format!("{}: the model names no chart", p.display()))
                })?;
                Ok((p.clone(), m, chart))
            })
            .collect()
    }
}
