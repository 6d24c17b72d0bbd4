//! `manifest.json`: everything needed to read, trust and reproduce a dataset.

use super::batch::{Columns, Counts};
use crate::camera::CameraConfig;
use crate::chart::Layout;
use crate::error::{Error, Result};
use crate::fsio;
use crate::spectral::{Grid, ResampleReport};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// The manifest's file name inside a dataset directory.
pub const MANIFEST_FILE: &str = "manifest.json";
/// The value of [`Manifest::format`].
pub const FORMAT: &str = "spdcam-dataset";
/// The layout version this program writes and reads.
pub const FORMAT_VERSION: u32 = 1;
/// The scale features are stored on: mean encoded sRGB, 0–255.
pub const FEATURE_SCALE: f64 = 255.0;

/// The manifest of a dataset directory. Written last, atomically: a directory without one is
/// an unfinished run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// Always [`FORMAT`]: what the directory is.
    pub format: String,
    /// The layout's version, [`FORMAT_VERSION`] when written by this spdcam.
    pub format_version: u32,
    /// Version of the spdcam that wrote the dataset.
    pub spdcam_version: String,
    /// Number of samples (rows) in this directory.
    pub samples: u64,
    /// Lights drawn in all, rejected ones included.
    pub attempts: u64,
    /// `samples / attempts`: the share of drawn lights that were valid.
    pub valid_ratio: Option<f64>,
    /// Samples per light family.
    pub families: BTreeMap<String, u64>,
    /// Features are mean encoded sRGB of each patch's central region on 0…`feature_scale`.
    pub feature_scale: f64,
    /// The column names and the SPDs' wavelengths.
    pub columns: Columns,
    /// The sample files in row order.
    pub files: Vec<FileEntry>,
    /// Where the samples came from.
    pub origin: Origin,
}

/// One sample file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FileEntry {
    /// Its path relative to the directory (`samples/part-00000.parquet`).
    pub name: String,
    /// The samples (rows) it holds.
    pub rows: u64,
    /// SHA-256 of the file's bytes, lower-case hex (what `sha256sum` prints); absent in
    /// datasets written before checksums were kept.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sha256: Option<String>,
}

impl FileEntry {
    /// The entry of a file of `rows` rows whose content is `bytes`.
    pub fn of_bytes(name: String, rows: u64, bytes: &[u8]) -> FileEntry {
        FileEntry {
            name,
            rows,
            sha256: Some(sha256_hex(bytes)),
        }
    }

    /// Checks `bytes`, the content of this file, against the checksum (when there is one).
    pub fn verify(&self, bytes: &[u8], dir: &Path) -> Result<()> {
        match &self.sha256 {
            Some(expected) if *expected != sha256_hex(bytes) => Err(Error::invalid(format!(
                "{}: the file does not match its checksum in the manifest: it was damaged or \
                 changed after spdcam wrote it (if you rewrote it on purpose, run `spdcam \
                 dataset info {} --update-checksums`)",
                dir.join(&self.name).display(),
                dir.display()
            ))),
            _ => Ok(()),
        }
    }
}

/// SHA-256 (FIPS 180-4) of `bytes` as lower-case hex.
pub fn sha256_hex(bytes: &[u8]) -> String {
    use sha2::Digest;
    sha2::Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// Where a dataset's samples came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Origin {
    /// Made by `spdcam generate` (one run, or all its shards merged).
    Generated(Box<GenerateSettings>),
    /// Brought in from feature and SPD CSV files.
    Imported(ImportSource),
    /// Several datasets joined one after the other.
    Merged {
        /// Each joined dataset's origin, in row order.
        sources: Vec<Origin>,
    },
    /// One part of a seeded train/val/test split of another dataset.
    Split {
        /// Which part: `train`, `val` or `test`.
        part: String,
        /// The shares of train, val and test.
        fractions: [f64; 3],
        /// The seed of the shuffle.
        seed: u64,
        /// Samples of the dataset that was split.
        source_samples: u64,
        /// Where that dataset came from.
        source: Box<Origin>,
    },
}

impl Origin {
    /// The generation settings behind the samples, looking through splits.
    pub fn generated(&self) -> Option<&GenerateSettings> {
        match self {
            Origin::Generated(s) => Some(s),
            Origin::Split { source, .. } => source.generated(),
            _ => None,
        }
    }
}

/// The generate runs whose samples `origin` holds (some of them, for a split part).
fn generate_runs(origin: &Origin) -> Vec<&GenerateSettings> {
    match origin {
        Origin::Generated(s) => vec![s.as_ref()],
        Origin::Merged { sources } => sources.iter().flat_map(generate_runs).collect(),
        Origin::Split { source, .. } => generate_runs(source),
        Origin::Imported(_) => Vec::new(),
    }
}

/// Column names in short: `p01_r … p24_b`, or the only one.
pub(crate) fn name_range(names: &[String]) -> String {
    match names {
        [] => "none".to_string(),
        [one] => one.clone(),
        [first, .., last] => format!("{first} … {last}"),
    }
}

/// Which camera pipeline renders the samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Pipeline {
    /// The whole virtual camera: noise, demosaicing, white balance, aberration, colour.
    Full,
    /// Noise-free patch-level features without an image (`Camera::features_fast`).
    Fast,
    /// Noise-free patch-level features as a raw file is read: each patch's exposed camera
    /// RGB (no white balance, tone or JPEG) taken to XYZ by the camera's DNG colour matrices
    /// at the chart's own neutral, a perfect white at Y = 100
    /// (`spdcam_core::photo::raw::RawColour::relative_xyz`).
    Raw,
}

/// Part `index` of `count` of a run: a contiguous range of its sample files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// This part, 0-based (below `count`).
    pub index: u32,
    /// The parts the run is cut into.
    pub count: u32,
}

impl Shard {
    /// Parses `K/N` with 0 ≤ K < N.
    pub fn parse(text: &str) -> Result<Shard> {
        let bad = || {
            Error::invalid(format!(
                "shard '{text}' is not K/N with 0 <= K < N (e.g. 0/3, 1/3, 2/3)"
            ))
        };
        let (k, n) = text.split_once('/').ok_or_else(bad)?;
        let index: u32 = k.trim().parse().map_err(|_| bad())?;
        let count: u32 = n.trim().parse().map_err(|_| bad())?;
        if index >= count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// Every setting of a `spdcam generate` run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GenerateSettings {
    /// Samples of the whole run (all shards).
    pub count: u64,
    /// The run's seed: every light, camera draw and noise derives from it and the sample.
    pub seed: u64,
    /// This part of the run; `None` for a whole run.
    pub shard: Option<Shard>,
    /// The samples `[start, end)` this directory holds.
    pub sample_range: [u64; 2],
    /// Full image pipeline or fast patch-level features.
    pub pipeline: Pipeline,
    /// Samples per file; file `k` holds samples `[k·chunk_size, (k+1)·chunk_size)`.
    pub chunk_size: u64,
    /// Whether each rendered chart was also written as `images/sample-NNNNNNNN.png`.
    pub images: bool,
    /// The grid lights are simulated on.
    pub simulation_grid: Grid,
    /// How sample `i`'s light and noise are seeded.
    pub seeding: String,
    /// The lighting recipe the lights were drawn from.
    pub lighting: LightingInfo,
    /// The chart photographed.
    pub chart: ChartInfo,
    /// The camera that photographed it.
    pub camera: CameraInfo,
    /// Domain randomisation (cameras and in-camera parameters drawn per sample), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub randomisation: Option<super::randomise::RandomisationInfo>,
}

/// The lighting recipe.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LightingInfo {
    /// The recipe as given (`gaussian:7`, `telelumen:config1`, …).
    pub spec: String,
    /// What the recipe draws, in words.
    pub description: String,
}

/// The chart the camera photographs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChartInfo {
    /// The chart's name or file.
    pub name: String,
    /// Where its patches lie on the rendered image.
    pub layout: Layout,
    /// The feature patches (row-major indices), in feature order.
    pub feature_patches: Vec<usize>,
    /// The reflectance of gaps and margins.
    pub background_reflectance: f64,
}

/// The camera.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CameraInfo {
    /// Name of the sensitivities.
    pub name: String,
    /// Every stage's settings.
    pub config: CameraConfig,
    /// The D65-fitted camera RGB → XYZ matrix (rows), when colour correction is on.
    pub correction_matrix: Option<[[f64; 3]; 3]>,
}

/// Where imported samples came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImportSource {
    /// The features CSV (as given).
    pub features_file: String,
    /// The SPDs (or channel weights) CSV (as given).
    pub spds_file: String,
    /// When the second file held channel weights: the lighting whose channels made the SPDs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weights_of: Option<String>,
    /// The scale of the features in the file (255 or 1); they are stored on 0–255.
    pub feature_scale: f64,
    /// Wavelengths of the SPD file's columns.
    pub source_wavelengths: Vec<f64>,
    /// How wavelengths the file lacks were filled, if any were.
    pub resampling: Option<ResampleReport>,
}

impl Manifest {
    /// A manifest for samples with `columns`, `counts` and `files`, from `origin`.
    pub fn new(
        columns: Columns,
        counts: Counts,
        files: Vec<FileEntry>,
        origin: Origin,
    ) -> Manifest {
        Manifest {
            format: FORMAT.to_string(),
            format_version: FORMAT_VERSION,
            spdcam_version: env!("CARGO_PKG_VERSION").to_string(),
            samples: counts.samples,
            attempts: counts.attempts,
            valid_ratio: (counts.attempts > 0)
                .then(|| counts.samples as f64 / counts.attempts as f64),
            families: counts.families,
            feature_scale: FEATURE_SCALE,
            columns,
            files,
            origin,
        }
    }

    /// Reads and checks `DIR/manifest.json`.
    pub fn read(dir: &Path) -> Result<Manifest> {
        let path = dir.join(MANIFEST_FILE);
        if !path.is_file() {
            let hint = if dir.is_dir() {
                " (an unfinished `spdcam generate`? run the same command again to finish it)"
            } else {
                ""
            };
            return Err(Error::invalid(format!(
                "{} is not a dataset: it has no {MANIFEST_FILE}{hint}",
                dir.display()
            )));
        }
        let text = fsio::read_text(&path)?;
        let source = path.display().to_string();
        let value: serde_json::Value = serde_json::from_str(&text)
            .map_err(|e| Error::parse(&source, format!("not valid JSON: {e}")))?;
        if value.get("format").and_then(|f| f.as_str()) != Some(FORMAT) {
            return Err(Error::parse(&source, format!("not an {FORMAT} manifest")));
        }
        let version = value.get("format_version").and_then(|v| v.as_u64());
        if version != Some(FORMAT_VERSION as u64) {
            return Err(Error::parse(
                &source,
                format!(
                    "format version {} is not {FORMAT_VERSION}, the one this spdcam reads",
                    version.map_or("missing".to_string(), |v| v.to_string())
                ),
            ));
        }
        let manifest: Manifest =
            serde_json::from_value(value).map_err(|e| Error::parse(&source, e.to_string()))?;
        manifest
            .columns
            .validate()
            .map_err(|e| Error::parse(&source, e.to_string()))?;
        manifest
            .check_feature_layout()
            .map_err(|e| Error::parse(&source, e))?;
        Ok(manifest)
    }

    /// Checks the feature columns against the chart of every generate run the samples came
    /// from (through splits and merges): the names that chart gives, three a feature patch.
    /// (Imported samples name no chart; their sample files are checked for feature columns
    /// the manifest leaves out as they are read.)
    fn check_feature_layout(&self) -> std::result::Result<(), String> {
        let found = &self.columns.feature_names;
        for run in generate_runs(&self.origin) {
            let expected = crate::chart::feature_names_of(run.chart.feature_patches.len());
            if *found != expected {
                return Err(format!(
                    "the manifest names {} feature columns ({}), but chart '{}' the samples were \
                     generated with gives {} ({}): the manifest was edited or damaged; restore \
                     the one spdcam wrote, or generate the dataset again",
                    found.len(),
                    name_range(found),
                    run.chart.name,
                    expected.len(),
                    name_range(&expected)
                ));
            }
        }
        Ok(())
    }

    /// Writes `DIR/manifest.json` atomically.
    pub fn write(&self, dir: &Path) -> Result<()> {
        let mut text = serde_json::to_string_pretty(self)
            .map_err(|e| Error::invalid(format!("manifest: {e}")))?;
        text.push('\n');
        fsio::write_atomic(&dir.join(MANIFEST_FILE), text.as_bytes())
    }
}
