//! Held-out lamps photographed by held-out cameras: where the lamp library and the cameras
//! are read from, the split's held-out cameras, and the models a protocol measures (shared by
//! the lamp validation and the trust calibration and report).

use crate::error::{EvalError, Result};
use spdcam_core::builtin::DataDir;
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::CameraConfig;
use spdcam_core::chart::Chart;
use spdcam_core::dataset::randomise::{
    camera_pool, InCameraRanges, Randomisation, IN_CAMERA_AND_GRADIENT_GROUPS,
};
use spdcam_core::light_families::{LampLibrary, ValidationSplit};
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
/// balance, tone, JPEG and the light's gradient across the chart (the core's
/// [`IN_CAMERA_AND_GRADIENT_GROUPS`]).
pub const IN_CAMERA_GROUPS: [&str; 5] = IN_CAMERA_AND_GRADIENT_GROUPS;

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

/// A held-out camera left out because its curves could not be read (unusable curves, as
/// training skips them too).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SkippedCamera {
    /// The camera's name in the split.
    pub name: String,
    /// Why it was left out.
    pub reason: String,
}

impl std::fmt::Display for SkippedCamera {
    /// The warning a command prints: `skipping held-out camera NAME: REASON`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "skipping held-out camera {}: {}", self.name, self.reason)
    }
}

/// The split's held-out cameras that could be read, and those left out.
#[derive(Debug, Clone)]
pub struct HeldOutCameras {
    /// The cameras read, in the split's order.
    pub cameras: Vec<Sensitivities>,
    /// The cameras left out, named with why; for the caller to report.
    pub skipped: Vec<SkippedCamera>,
}

/// The split's held-out cameras, read from `dir` (default: the data directory's cameras/);
/// cameras training skips (unusable curves) are left out and returned named, with why, in
/// [`HeldOutCameras::skipped`]; a camera missing from `dir` or none readable is an error.
pub fn held_out_cameras(
    split: &ValidationSplit,
    dir: Option<&Path>,
    data_dir: &DataDir,
) -> Result<HeldOutCameras> {
    split_cameras(&split.cameras.held_out, "held-out", dir, data_dir)
}

/// The split's training cameras, read as [`held_out_cameras`] reads the held-out ones: what
/// a model's own calibrations (light-kind priors) photograph with, so that the held-out
/// cameras stay unseen.
pub fn training_cameras(
    split: &ValidationSplit,
    dir: Option<&Path>,
    data_dir: &DataDir,
) -> Result<HeldOutCameras> {
    split_cameras(&split.cameras.training, "training", dir, data_dir)
}

/// The cameras `names` (the split's `part` cameras) read from `dir`.
fn split_cameras(
    names: &[String],
    part: &str,
    dir: Option<&Path>,
    data_dir: &DataDir,
) -> Result<HeldOutCameras> {
    let dir = in_data_dir(dir, "cameras", data_dir)?;
    let available = camera_names(&dir)?;
    let mut cameras: Vec<Sensitivities> = Vec::new();
    let mut skipped = Vec::new();
    for name in names {
        if !available.contains(name) {
            return Err(EvalError::invalid(format!(
                "{part} camera '{name}' is not in {}",
                dir.display()
            )));
        }
        let path = dir.join(format!("{name}.csv"));
        match Sensitivities::resolve(&path.to_string_lossy(), data_dir, &GRID) {
            Ok(s) => cameras.push(s),
            Err(e) => skipped.push(SkippedCamera {
                name: name.clone(),
                reason: format!("{e:#}"),
            }),
        }
    }
    if cameras.is_empty() {
        return Err(EvalError::invalid(format!(
            "none of the split's {part} cameras could be read"
        )));
    }
    Ok(HeldOutCameras { cameras, skipped })
}

/// Every lamp of the library on `grid` (linear interpolation), normalised by its maximum.
pub fn on_grid(library: &LampLibrary, grid: &Grid) -> Result<Vec<Vec<f64>>> {
    let set = SpectralSet::from_spds(library.names.clone(), &library.spds)?;
    let (set, _) = set.resample(grid, Interpolation::Linear, Extrapolation::Zero)?;
    Ok(set
        .items()
        .iter()
        .map(|s| spdcam_core::spectral::normalise_by_max(s))
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
    /// The held-out cameras left out (unreadable curves), for the caller to report.
    pub skipped: Vec<SkippedCamera>,
}

impl HeldOutPhotos {
    /// Reads the library, the split and the held-out cameras.
    pub fn setup(&self, data_dir: &DataDir) -> Result<Setup> {
        if self.shots == 0 {
            return Err(EvalError::invalid("--shots must be at least 1"));
        }
        let split = ValidationSplit::read(&self.split)?;
        let library = self.library.read(data_dir, &GRID)?;
        let HeldOutCameras { cameras, skipped } =
            held_out_cameras(&split, self.cameras.as_deref(), data_dir)?;
        Ok(Setup {
            library,
            split,
            cameras,
            skipped,
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

#[cfg(test)]
mod tests {
    use super::*;
    use spdcam_core::light_families::validation_split::{CameraSplit, LampSplit};

    #[test]
    fn unreadable_held_out_cameras_are_returned_not_printed() {
        let dir = std::env::temp_dir().join(format!("spdcam-held-out-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // Gaussian r, g, b curves over 380–780 nm, and a file with one column too few.
        let mut good = String::from("wavelength_nm,r,g,b\n");
        for nm in (380..=780).step_by(5) {
            let g = |peak: f64| (-((nm as f64 - peak) / 40.0).powi(2)).exp();
            good += &format!("{nm},{},{},{}\n", g(600.0), g(540.0), g(460.0));
        }
        std::fs::write(dir.join("good.csv"), good).unwrap();
        std::fs::write(dir.join("bad.csv"), "wavelength_nm,r,g\n400,1,1\n700,1,1\n").unwrap();
        let split = |held_out: &[&str]| ValidationSplit {
            method: String::new(),
            seed: 0,
            lamps: LampSplit {
                fit: Vec::new(),
                validation: Vec::new(),
                test: Vec::new(),
            },
            cameras: CameraSplit {
                training: Vec::new(),
                held_out: held_out.iter().map(|s| s.to_string()).collect(),
            },
        };
        let data = DataDir::new(None);
        let found = held_out_cameras(&split(&["bad", "good"]), Some(&dir), &data).unwrap();
        assert_eq!(found.cameras.len(), 1);
        assert_eq!(found.skipped.len(), 1);
        assert_eq!(found.skipped[0].name, "bad");
        let warning = found.skipped[0].to_string();
        assert!(
            warning.starts_with("skipping held-out camera bad: "),
            "{warning}"
        );
        // None readable, or one missing from the directory, is an error.
        assert!(held_out_cameras(&split(&["bad"]), Some(&dir), &data).is_err());
        assert!(held_out_cameras(&split(&["absent"]), Some(&dir), &data).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
