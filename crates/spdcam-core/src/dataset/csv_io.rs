//! The thesis's CSV layout in and out: `features.csv` (one row per sample, columns
//! `p01_r,p01_g,…`) and `spds.csv` (one row per sample, header = wavelengths in nm), for
//! datasets and for measured photos ([`MeasuredPhotos`]).

use super::batch::{Columns, Precision, SampleBatch, SampleRow};
use super::manifest::{ImportSource, Manifest, Origin, FEATURE_SCALE};
use super::reader::Dataset;
use super::spd_map::SpdMap;
use super::writer::{prepare_output, DatasetWriter};
use crate::error::{short_number, Error, Result};
use crate::fsio;
use crate::light_families::Lighting;
use crate::named_light::SPD_NEGATIVE_TOLERANCE;
use crate::spectral::{Extrapolation, Grid, Interpolation, Spd, SpectralSet};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Settings of [`import_csv`].
#[derive(Debug, Clone)]
pub struct ImportOptions {
    /// The scale of the features in the file: 255 (0–255) or 1 (0–1, multiplied by 255).
    pub feature_scale: f64,
    /// The grid the SPDs are stored on.
    pub spd_grid: Grid,
    /// The family name every imported sample gets.
    pub family: String,
    /// Samples per file.
    pub chunk_size: u64,
    /// When set, the second file holds channel weights (one column per channel of this
    /// lighting, in its order) instead of SPDs: each SPD is the channels' weighted sum,
    /// normalised by its maximum, and the weights are kept.
    pub weights_of: Option<Lighting>,
}

/// What [`import_csv`] did.
#[derive(Debug, Clone)]
pub struct ImportReport {
    /// The manifest of the dataset written.
    pub manifest: Manifest,
    /// The largest feature value in the file, before scaling (a 0–1 file read as 0–255
    /// shows here).
    pub largest_feature: f64,
}

fn reader(path: &Path) -> Result<csv::Reader<std::fs::File>> {
    csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_path(path)
        .map_err(|e| Error::parse(path.display().to_string(), e.to_string()))
}

fn header(reader: &mut csv::Reader<std::fs::File>, path: &Path) -> Result<Vec<String>> {
    let header = reader
        .headers()
        .map_err(|e| Error::parse(path.display().to_string(), format!("line 1: {e}")))?;
    crate::limits::check_csv_columns(header.len(), &path.display().to_string())?;
    let names: Vec<String> = header.iter().map(str::to_string).collect();
    if names.iter().all(String::is_empty) {
        return Err(Error::parse(
            path.display().to_string(),
            "the file is empty",
        ));
    }
    Ok(names)
}

/// Parses the numbers of one CSV record; errors name the file, line and column.
fn numbers(record: &csv::StringRecord, names: &[String], path: &Path) -> Result<Vec<f64>> {
    let line = record.position().map_or(0, |p| p.line());
    let err = |msg: String| Error::parse(path.display().to_string(), format!("line {line}: {msg}"));
    if record.len() != names.len() {
        return Err(err(format!(
            "{} cells, the header has {}",
            record.len(),
            names.len()
        )));
    }
    record
        .iter()
        .zip(names)
        .map(|(cell, name)| {
            cell.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| err(format!("column '{name}': '{cell}' is not a number")))
        })
        .collect()
}

/// Photos measured in the thesis's CSV layout: the chart features of each photo and the
/// SPD of its light, measured beside it.
#[derive(Debug, Clone)]
pub struct MeasuredPhotos {
    /// Each photo's features (0–255), in the file's column order.
    pub features: Vec<Vec<f64>>,
    /// Each photo's measured SPD, on the grid it was read onto.
    pub spds: Vec<Spd>,
}

impl MeasuredPhotos {
    /// The photos `indices` as photos an in-camera stage is fitted to
    /// ([`crate::camera::in_camera::fit_to_photos`]).
    ///
    /// # Panics
    /// If an index is out of range.
    pub fn reference_photos(
        &self,
        indices: &[usize],
    ) -> Vec<crate::camera::in_camera::ReferencePhoto> {
        indices
            .iter()
            .map(|&i| crate::camera::in_camera::ReferencePhoto {
                features: self.features[i].clone(),
                spd: self.spds[i].clone(),
            })
            .collect()
    }

    /// Reads `features` (one row per photo) and `spds` (one row per photo, the header the
    /// wavelengths in nm); the SPDs are resampled onto `grid` by linear interpolation, zero
    /// outside their range. Errors name the file and line.
    pub fn read(features: &Path, spds: &Path, grid: &Grid) -> Result<MeasuredPhotos> {
        let (_, feature_rows) = read_rows(features)?;
        let (header, spd_rows) = read_rows(spds)?;
        let wavelengths = wavelength_columns(&header, spds)?;
        if feature_rows.len() != spd_rows.len() {
            return Err(Error::invalid(format!(
                "{} has {} photos but {} has {} SPDs; the two files need one row per photo, \
                 in the same order",
                features.display(),
                feature_rows.len(),
                spds.display(),
                spd_rows.len()
            )));
        }
        let names = (0..spd_rows.len()).map(|i| format!("s{i}")).collect();
        let set = SpectralSet::new(wavelengths, names, spd_rows)?;
        let (set, _) = set.resample(grid, Interpolation::Linear, Extrapolation::Zero)?;
        Ok(MeasuredPhotos {
            features: feature_rows,
            spds: (0..set.len()).map(|i| set.spd(i)).collect::<Result<_>>()?,
        })
    }
}

/// One of the thesis's real photo sets (data directory `thesis/measured/…`, thesis chapter
/// 5): a label for tables and the measured folders it joins (a set's training and
/// validation halves are scored together when no model was fitted on them).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RealPhotoSet {
    /// How tables name the set.
    pub label: &'static str,
    /// Folders of `thesis/measured/`, each holding `features.csv` and `spds.csv`.
    pub folders: &'static [&'static str],
}

/// The three real photo sets every evaluation scores on: the Telelumen development set by a
/// Canon 5D IV, Philips Hue lamps by the same camera, and Telelumen lights by a Galaxy Tab S7.
pub const REAL_PHOTO_SETS: [RealPhotoSet; 3] = [
    RealPhotoSet {
        label: "Telelumen, Canon 5D IV (dev)",
        folders: &["telelumen_canon5d4_dev"],
    },
    RealPhotoSet {
        label: "Philips Hue, Canon 5D IV",
        folders: &["hue_canon5d4_train", "hue_canon5d4_val"],
    },
    RealPhotoSet {
        label: "Telelumen, Galaxy Tab S7",
        folders: &[
            "telelumen_galaxy_tab_s7_train",
            "telelumen_galaxy_tab_s7_val",
        ],
    },
];

impl RealPhotoSet {
    /// Reads the set's folders under `thesis` (the data directory's `thesis/`) and joins
    /// them, the SPDs on `grid` ([`MeasuredPhotos::read`]).
    pub fn load(&self, thesis: &Path, grid: &Grid) -> Result<MeasuredPhotos> {
        let mut all = MeasuredPhotos {
            features: Vec::new(),
            spds: Vec::new(),
        };
        for folder in self.folders {
            let dir = thesis.join("measured").join(folder);
            let m = MeasuredPhotos::read(&dir.join("features.csv"), &dir.join("spds.csv"), grid)?;
            all.features.extend(m.features);
            all.spds.extend(m.spds);
        }
        Ok(all)
    }
}

/// Every row of a numeric CSV file with a header: the header's names and the rows.
fn read_rows(path: &Path) -> Result<(Vec<String>, Vec<Vec<f64>>)> {
    let mut reader = reader(path)?;
    let names = header(&mut reader, path)?;
    let mut rows = Vec::new();
    for record in reader.records() {
        let record = record.map_err(|e| Error::parse(path.display().to_string(), e.to_string()))?;
        rows.push(numbers(&record, &names, path)?);
    }
    Ok((names, rows))
}

/// Imports samples from a features CSV and an SPDs CSV (same rows) into the dataset
/// directory `out`. Features are stored as DOUBLE on 0–255 (multiplied by 255 when the file
/// is on 0–1); SPDs are moved onto `options.spd_grid`, keeping the values at the file's
/// own wavelengths exactly and setting wavelengths outside the file's range to zero.
pub fn import_csv(
    features: &Path,
    spds: &Path,
    out: &Path,
    options: &ImportOptions,
    overwrite: bool,
) -> Result<ImportReport> {
    if options.feature_scale != 255.0 && options.feature_scale != 1.0 {
        return Err(Error::invalid(format!(
            "feature scale {} is not 255 or 1",
            options.feature_scale
        )));
    }
    let mut feature_reader = reader(features)?;
    let feature_names = header(&mut feature_reader, features)?;
    let mut spd_reader = reader(spds)?;
    let spd_header = header(&mut spd_reader, spds)?;
    let (wavelengths, weight_names) = match &options.weights_of {
        Some(lighting) => weight_columns(lighting, &spd_header, spds)?,
        None => (wavelength_columns(&spd_header, spds)?, Vec::new()),
    };
    let map = SpdMap::new(&wavelengths, &options.spd_grid)
        .map_err(|e| Error::parse(spds.display().to_string(), e.to_string()))?;
    let columns = Columns {
        feature_names,
        feature_precision: Precision::Float64,
        spd_grid: options.spd_grid,
        weight_names,
    };
    columns
        .validate()
        .map_err(|e| Error::parse(features.display().to_string(), e.to_string()))?;
    let output = prepare_output(out, &[features, spds], overwrite)?;
    let mut writer = DatasetWriter::new(out, columns.clone(), options.chunk_size)?;
    let mut feature_rows = feature_reader.records();
    let mut spd_rows = spd_reader.records();
    let mut largest_feature = f64::NEG_INFINITY;
    let mut spd = Vec::with_capacity(columns.spd_len());
    for sample in 0u64.. {
        let (f, s) = match (feature_rows.next(), spd_rows.next()) {
            (None, None) => break,
            (Some(f), Some(s)) => (f, s),
            (f, _) => {
                let (longer, shorter) = if f.is_some() {
                    (features, spds)
                } else {
                    (spds, features)
                };
                return Err(Error::invalid(format!(
                    "{} has more rows than {} ({sample}): rows must be the same samples",
                    longer.display(),
                    shorter.display()
                )));
            }
        };
        let f = f.map_err(|e| Error::parse(features.display().to_string(), e.to_string()))?;
        let s = s.map_err(|e| Error::parse(spds.display().to_string(), e.to_string()))?;
        let mut values = numbers(&f, &columns.feature_names, features)?;
        for (v, name) in values.iter_mut().zip(&columns.feature_names) {
            if *v < 0.0 || *v > options.feature_scale {
                let line = f.position().map_or(0, |p| p.line());
                let hint = if options.feature_scale == 1.0 {
                    " (a 0–255 file? use a feature scale of 255)"
                } else {
                    ""
                };
                return Err(Error::parse(
                    features.display().to_string(),
                    format!(
                        "line {line}, column '{name}': {v} is outside 0–{}{hint}",
                        options.feature_scale
                    ),
                ));
            }
            largest_feature = largest_feature.max(*v);
            *v *= FEATURE_SCALE / options.feature_scale;
        }
        spd.clear();
        let second = numbers(&s, &spd_header, spds)?;
        let weights = match &options.weights_of {
            Some(lighting) => {
                let line = s.position().map_or(0, |p| p.line());
                let light = weighted_spd(lighting, &second).map_err(|e| {
                    Error::parse(spds.display().to_string(), format!("line {line}: {e}"))
                })?;
                map.apply(&light, &mut spd)?;
                second.as_slice()
            }
            None => {
                let line = s.position().map_or(0, |p| p.line());
                let light = physical_spd(&second, &wavelengths).map_err(|e| {
                    Error::parse(spds.display().to_string(), format!("line {line}: {e}"))
                })?;
                map.apply(&light, &mut spd)?;
                &[]
            }
        };
        if spd.iter().all(|&v| v == 0.0) {
            let line = s.position().map_or(0, |p| p.line());
            return Err(Error::parse(
                spds.display().to_string(),
                format!(
                    "line {line}: the SPD is zero everywhere on {}",
                    options.spd_grid
                ),
            ));
        }
        writer.push(SampleRow {
            sample,
            family: &options.family,
            features: &values,
            spd: &spd,
            weights,
            attempts: 1,
        })?;
    }
    if writer.is_empty() {
        return Err(Error::invalid(format!(
            "{} and {} hold no samples (a header and no rows): nothing to import; give files \
             with one row per sample",
            features.display(),
            spds.display()
        )));
    }
    let origin = Origin::Imported(ImportSource {
        features_file: features.display().to_string(),
        spds_file: spds.display().to_string(),
        weights_of: options.weights_of.as_ref().map(|l| l.spec().to_string()),
        feature_scale: options.feature_scale,
        source_wavelengths: wavelengths,
        resampling: map.report().cloned(),
    });
    let manifest = writer.finish(origin)?;
    output.finish();
    Ok(ImportReport {
        manifest,
        largest_feature,
    })
}

/// The wavelengths named by an SPD file's header. A spectral CSV (one wavelength per row,
/// `wavelength_nm` first) is told apart and refused with the layout expected.
fn wavelength_columns(header: &[String], path: &Path) -> Result<Vec<f64>> {
    if header.first().is_some_and(|h| {
        h.eq_ignore_ascii_case("wavelength_nm") || h.eq_ignore_ascii_case("wavelength")
    }) {
        return Err(Error::parse(
            path.display().to_string(),
            format!(
                "line 1 starts with '{}': the file is a spectral CSV, one wavelength per row \
                 and one column per SPD; SPDs here are one per row: a header of the \
                 wavelengths in nm (380,385,…,780), then one row per photo, in the order of \
                 the features; transpose the table",
                header[0]
            ),
        ));
    }
    let wavelengths: Vec<f64> = header
        .iter()
        .map(|h| {
            h.trim_end_matches("nm")
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|w| w.is_finite())
                .ok_or_else(|| {
                    Error::parse(
                        path.display().to_string(),
                        format!("line 1: header cell '{h}' is not a wavelength in nm"),
                    )
                })
        })
        .collect::<Result<_>>()?;
    let bad = |msg: String| Error::parse(path.display().to_string(), format!("line 1: {msg}"));
    if let Some(w) = wavelengths.windows(2).find(|w| w[1] <= w[0]) {
        return Err(bad(format!(
            "wavelength {} nm follows {} nm; they must increase",
            w[1], w[0]
        )));
    }
    if wavelengths.len() < 2 {
        return Err(bad(format!(
            "{} wavelength column; an SPD needs at least two",
            wavelengths.len()
        )));
    }
    let (lo, hi) = (wavelengths[0], wavelengths[wavelengths.len() - 1]);
    if hi < MIN_WAVELENGTH_NM {
        return Err(bad(format!(
            "wavelengths {lo}–{hi} are not in nm (micrometres? 0.38 µm is 380 nm); \
             the header must name wavelengths in nm"
        )));
    }
    Ok(wavelengths)
}

/// Below this, a header's wavelengths are not nanometres of visible light (a file in µm
/// has 0.38–0.78).
const MIN_WAVELENGTH_NM: f64 = 100.0;

/// The SPD of one row, as `render --spd` accepts one: negative values beyond
/// [`SPD_NEGATIVE_TOLERANCE`] of the peak are refused (small ones, measurement noise, become zero), and so is an SPD that is
/// zero everywhere.
fn physical_spd(values: &[f64], wavelengths: &[f64]) -> Result<Vec<f64>> {
    let peak = values.iter().cloned().fold(0.0f64, f64::max);
    if let Some((i, v)) = values
        .iter()
        .enumerate()
        .find(|(_, v)| **v < -SPD_NEGATIVE_TOLERANCE * peak.max(f64::MIN_POSITIVE))
    {
        return Err(Error::invalid(format!(
            "the SPD is negative ({}) at {} nm, beyond {} % of its peak ({}); light cannot be \
             negative (smaller negatives are taken as noise and set to 0): correct that value",
            short_number(*v),
            short_number(wavelengths[i]),
            short_number(100.0 * SPD_NEGATIVE_TOLERANCE),
            short_number(peak)
        )));
    }
    if peak <= 0.0 {
        return Err(Error::invalid("the SPD is zero everywhere"));
    }
    Ok(values.iter().map(|v| v.max(0.0)).collect())
}

/// For a weights file: the lighting's grid (where the SPDs are made) and its weight names,
/// after checking that the file has one column per channel.
fn weight_columns(
    lighting: &Lighting,
    header: &[String],
    path: &Path,
) -> Result<(Vec<f64>, Vec<String>)> {
    let channels = lighting.channels().ok_or_else(|| {
        Error::invalid(format!(
            "lighting '{}' has no channels to weight; use gaussian:N, leds:FILE or telelumen:PRESET",
            lighting.spec()
        ))
    })?;
    if header.len() != channels.len() {
        return Err(Error::parse(
            path.display().to_string(),
            format!(
                "line 1: {} weight columns, but lighting '{}' has {} channels",
                header.len(),
                lighting.spec(),
                channels.len()
            ),
        ));
    }
    Ok((lighting.grid().wavelengths(), channels.names.clone()))
}

/// The SPD made by `weights` of the lighting's channels; negative weights are refused.
fn weighted_spd(lighting: &Lighting, weights: &[f64]) -> Result<Vec<f64>> {
    if let Some(w) = weights.iter().find(|w| **w < 0.0) {
        return Err(Error::invalid(format!("weight {w} is negative")));
    }
    lighting
        .channels()
        .ok_or_else(|| Error::invalid("the lighting has no channels"))?
        .combine(weights)
}

/// Settings of [`export_csv`].
#[derive(Debug, Clone)]
pub struct ExportOptions {
    /// The scale to write features on: 255 (as stored) or 1 (divided by 255).
    pub feature_scale: f64,
    /// The wavelengths to write SPDs at; the dataset's grid when `None`.
    pub spd_grid: Option<Grid>,
}

/// Writes one CSV file from every sample of `dataset`, atomically.
fn write_table(
    dataset: &Dataset,
    path: &Path,
    header: &[String],
    mut row: impl FnMut(&SampleBatch, usize, &mut String) -> Result<()>,
) -> Result<()> {
    let mut failure = None;
    let written = fsio::write_atomic_with(path, |w| {
        writeln!(w, "{}", header.join(","))?;
        let mut line = String::new();
        for batch in dataset.batches() {
            let batch = batch.map_err(|e| {
                failure = Some(e);
                std::io::Error::other("reading the dataset failed")
            })?;
            for i in 0..batch.len() {
                line.clear();
                if let Err(e) = row(&batch, i, &mut line) {
                    failure = Some(e);
                    return Err(std::io::Error::other("formatting a row failed"));
                }
                line.push('\n');
                w.write_all(line.as_bytes())?;
            }
        }
        Ok(())
    });
    match (failure, written) {
        (Some(e), _) => Err(e),
        (None, r) => r,
    }
}

fn join_numbers(line: &mut String, values: impl Iterator<Item = String>) {
    for (k, v) in values.enumerate() {
        if k > 0 {
            line.push(',');
        }
        line.push_str(&v);
    }
}

/// Writes `dataset` into `out` in the thesis's CSV layout: `features.csv`, `spds.csv`,
/// `weights.csv` (when the dataset has weights) and `samples.csv` (sample, family,
/// attempts), rows in dataset order. Returns the files written.
pub fn export_csv(
    dataset: &Dataset,
    out: &Path,
    options: &ExportOptions,
    overwrite: bool,
) -> Result<Vec<PathBuf>> {
    if options.feature_scale != 255.0 && options.feature_scale != 1.0 {
        return Err(Error::invalid(format!(
            "feature scale {} is not 255 or 1",
            options.feature_scale
        )));
    }
    let columns = dataset.columns();
    let own = columns.spd_grid;
    let grid = options.spd_grid.unwrap_or(own);
    if grid.start_nm < own.start_nm - 1e-9 || grid.end_nm() > own.end_nm() + 1e-9 {
        return Err(Error::invalid(format!(
            "SPD grid {grid} reaches outside the dataset's SPDs, {}–{} nm ({}): they are not \
             known there; give a grid within {}–{} nm",
            own.start_nm,
            own.end_nm(),
            dataset.dir().display(),
            own.start_nm,
            own.end_nm()
        )));
    }
    let map = SpdMap::new(&columns.spd_grid.wavelengths(), &grid)?;
    let output = prepare_output(out, &[dataset.dir()], overwrite)?;
    let mut written = Vec::new();

    let path = out.join("features.csv");
    let single = columns.feature_precision == Precision::Float32;
    let divisor = FEATURE_SCALE / options.feature_scale;
    write_table(dataset, &path, &columns.feature_names, |b, i, line| {
        let values = b
            .features_of(i)
            .iter()
            .map(|&v| match (single, divisor == 1.0) {
                (true, true) => format!("{}", v as f32),
                _ => format!("{}", v / divisor),
            });
        join_numbers(line, values);
        Ok(())
    })?;
    written.push(path);

    let path = out.join("spds.csv");
    let header: Vec<String> = grid.wavelengths().iter().map(|w| format!("{w}")).collect();
    let mut spd = Vec::new();
    write_table(dataset, &path, &header, |b, i, line| {
        spd.clear();
        map.apply(b.spd_of(i), &mut spd)?;
        join_numbers(line, spd.iter().map(|v| format!("{v}")));
        Ok(())
    })?;
    written.push(path);

    if !columns.weight_names.is_empty() {
        let path = out.join("weights.csv");
        write_table(dataset, &path, &columns.weight_names, |b, i, line| {
            join_numbers(line, b.weights_of(i).iter().map(|v| format!("{v}")));
            Ok(())
        })?;
        written.push(path);
    }

    let path = out.join("samples.csv");
    let header = ["sample", "family", "attempts"].map(String::from);
    write_table(dataset, &path, &header, |b, i, line| {
        let family = &b.families[i];
        let family = if family.contains([',', '"', '\n']) {
            format!("\"{}\"", family.replace('"', "\"\""))
        } else {
            family.clone()
        };
        line.push_str(&format!("{},{family},{}", b.samples[i], b.attempts[i]));
        Ok(())
    })?;
    written.push(path);
    output.finish();
    Ok(written)
}
