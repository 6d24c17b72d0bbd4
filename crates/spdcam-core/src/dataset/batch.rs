//! The columns of a dataset and a block of samples held in memory.

use crate::error::{Error, Result};
use crate::spectral::Grid;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// How the float columns (features, SPDs, weights) are stored in the sample files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Precision {
    /// Parquet FLOAT: what the camera computes; used for generated sets. Its relative
    /// error (2⁻²⁴ ≈ 6e-8) is far below the features' 8-bit quantisation (1/255).
    Float32,
    /// Parquet DOUBLE: keeps every digit of imported data.
    Float64,
}

/// The columns of every sample file of a dataset, in file order: `sample` (INT64), `family`
/// (UTF-8), the features (`p01_r`, …; mean encoded sRGB on 0–255), the SPD (`spd_380`, …
/// in nm), the weights (`w_<name>`) and `attempts` (INT32); the float columns are FLOAT or
/// DOUBLE as `feature_precision` says (datasets written before SPDs and weights followed it
/// hold them as DOUBLE, and are read as they are).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Columns {
    /// Feature column names (`p01_r`, `p01_g`, …), in feature order.
    pub feature_names: Vec<String>,
    /// Whether float columns are stored as 32- or 64-bit floats.
    pub feature_precision: Precision,
    /// The wavelengths of the SPD columns.
    pub spd_grid: Grid,
    /// Names of the lighting's weights (channel drive levels); empty when it has none.
    pub weight_names: Vec<String>,
}

impl Columns {
    /// Number of feature values per sample.
    pub fn feature_count(&self) -> usize {
        self.feature_names.len()
    }

    /// Number of SPD values per sample.
    pub fn spd_len(&self) -> usize {
        self.spd_grid.count
    }

    /// Number of weights per sample.
    pub fn weight_count(&self) -> usize {
        self.weight_names.len()
    }

    /// Every column name in file order.
    pub fn column_names(&self) -> Vec<String> {
        let mut names = vec!["sample".to_string(), "family".to_string()];
        names.extend(self.feature_names.iter().cloned());
        names.extend(self.spd_grid.wavelengths().into_iter().map(spd_column_name));
        names.extend(self.weight_names.iter().map(|w| format!("w_{w}")));
        names.push("attempts".to_string());
        names
    }

    /// Checks that there are features and that no two columns share a name.
    pub fn validate(&self) -> Result<()> {
        if self.feature_names.is_empty() {
            return Err(Error::invalid(
                "a dataset needs at least one feature column",
            ));
        }
        let names = self.column_names();
        let mut seen = std::collections::HashSet::new();
        if let Some(dup) = names.iter().find(|n| !seen.insert(n.as_str())) {
            return Err(Error::invalid(format!(
                "column name '{dup}' appears twice in the dataset's columns"
            )));
        }
        Ok(())
    }

    /// An empty batch with this layout.
    pub fn batch(&self) -> SampleBatch {
        SampleBatch {
            feature_count: self.feature_count(),
            spd_len: self.spd_len(),
            weight_count: self.weight_count(),
            ..SampleBatch::default()
        }
    }
}

/// The column name of the SPD value at `nm`: `spd_380`, or `spd_380p5` for 380.5 nm.
fn spd_column_name(nm: f64) -> String {
    format!("spd_{nm}").replace('.', "p")
}

/// Samples held in memory, each quantity row-major (`features[row * feature_count + j]`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SampleBatch {
    /// Features per sample.
    pub feature_count: usize,
    /// SPD values per sample.
    pub spd_len: usize,
    /// Lighting weights per sample (0 when the lighting has none).
    pub weight_count: usize,
    /// Sample index within its generating run (or row of the imported file).
    pub samples: Vec<u64>,
    /// The lighting family each sample's light was drawn from.
    pub families: Vec<String>,
    /// Chart features (mean encoded sRGB, 0–255), `feature_count` per sample.
    pub features: Vec<f64>,
    /// Relative SPDs (maximum 1), `spd_len` per sample.
    pub spds: Vec<f64>,
    /// Lighting weights (channel drive levels), `weight_count` per sample.
    pub weights: Vec<f64>,
    /// Lights drawn for this sample, the accepted one included.
    pub attempts: Vec<u32>,
}

/// One sample borrowed from a batch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleRow<'a> {
    /// Sample index within its generating run (or row of the imported file).
    pub sample: u64,
    /// The lighting family its light was drawn from.
    pub family: &'a str,
    /// Chart features (0–255).
    pub features: &'a [f64],
    /// Relative SPD (maximum 1).
    pub spd: &'a [f64],
    /// Lighting weights; empty when the lighting has none.
    pub weights: &'a [f64],
    /// Lights drawn for the sample, the accepted one included.
    pub attempts: u32,
}

impl SampleBatch {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// Whether the batch holds no sample.
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// The features of row `i`.
    pub fn features_of(&self, i: usize) -> &[f64] {
        &self.features[i * self.feature_count..(i + 1) * self.feature_count]
    }

    /// The SPD of row `i`.
    pub fn spd_of(&self, i: usize) -> &[f64] {
        &self.spds[i * self.spd_len..(i + 1) * self.spd_len]
    }

    /// The weights of row `i` (empty when the dataset has none).
    pub fn weights_of(&self, i: usize) -> &[f64] {
        &self.weights[i * self.weight_count..(i + 1) * self.weight_count]
    }

    /// Row `i`.
    pub fn row(&self, i: usize) -> SampleRow<'_> {
        SampleRow {
            sample: self.samples[i],
            family: &self.families[i],
            features: self.features_of(i),
            spd: self.spd_of(i),
            weights: self.weights_of(i),
            attempts: self.attempts[i],
        }
    }

    /// Appends one row, checking its lengths against the batch's layout.
    pub fn push(&mut self, row: SampleRow<'_>) -> Result<()> {
        let lengths = (row.features.len(), row.spd.len(), row.weights.len());
        if lengths != (self.feature_count, self.spd_len, self.weight_count) {
            return Err(Error::invalid(format!(
                "sample {} has {} features, {} SPD values and {} weights; the dataset needs {}, {} and {}",
                row.sample,
                lengths.0,
                lengths.1,
                lengths.2,
                self.feature_count,
                self.spd_len,
                self.weight_count
            )));
        }
        self.samples.push(row.sample);
        self.families.push(row.family.to_string());
        self.features.extend_from_slice(row.features);
        self.spds.extend_from_slice(row.spd);
        self.weights.extend_from_slice(row.weights);
        self.attempts.push(row.attempts);
        Ok(())
    }

    /// Moves every row of `other` (same layout) to the end of this batch.
    pub fn append(&mut self, mut other: SampleBatch) {
        debug_assert_eq!(
            (other.feature_count, other.spd_len, other.weight_count),
            (self.feature_count, self.spd_len, self.weight_count)
        );
        self.samples.append(&mut other.samples);
        self.families.append(&mut other.families);
        self.features.append(&mut other.features);
        self.spds.append(&mut other.spds);
        self.weights.append(&mut other.weights);
        self.attempts.append(&mut other.attempts);
    }
}

/// Counts gathered over the samples of a dataset.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Counts {
    /// Samples.
    pub samples: u64,
    /// Lights drawn for them, rejected draws included.
    pub attempts: u64,
    /// Samples per lighting family.
    pub families: BTreeMap<String, u64>,
}

impl Counts {
    /// Adds the samples of `batch`.
    pub fn add(&mut self, batch: &SampleBatch) {
        self.samples += batch.len() as u64;
        self.attempts += batch.attempts.iter().map(|&a| a as u64).sum::<u64>();
        for f in &batch.families {
            match self.families.get_mut(f) {
                Some(n) => *n += 1,
                None => {
                    self.families.insert(f.clone(), 1);
                }
            }
        }
    }

    /// Adds the counts of other samples.
    pub fn merge(&mut self, other: Counts) {
        self.samples += other.samples;
        self.attempts += other.attempts;
        for (family, n) in other.families {
            *self.families.entry(family).or_insert(0) += n;
        }
    }
}

/// What a column of a sample file holds, in file order: the one layout the writer
/// (`file`) and the reader (`file_read`) share.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Field {
    /// The sample's index.
    Sample,
    /// The light family's name.
    Family,
    /// Feature column j.
    Feature(usize),
    /// SPD band j.
    Spd(usize),
    /// Drive weight j.
    Weight(usize),
    /// How many draws the sample took.
    Attempts,
}

/// The columns of a sample file with `columns`, in file order.
pub(super) fn fields(columns: &Columns) -> Vec<Field> {
    let mut f = vec![Field::Sample, Field::Family];
    f.extend((0..columns.feature_count()).map(Field::Feature));
    f.extend((0..columns.spd_len()).map(Field::Spd));
    f.extend((0..columns.weight_count()).map(Field::Weight));
    f.push(Field::Attempts);
    f
}
