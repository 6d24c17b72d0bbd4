//! The thesis's scaling of inputs and targets, fitted on the training set and stored in the
//! model: each feature row divided by its own maximum (or its mean, [`RowScale`]), then each
//! feature min-max scaled; each target min-max scaled to [0, 1] so that a sigmoid output can
//! reach it.

use crate::error::{InferError, Result};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// What each feature row is divided by before the per-feature scaling, so that the photo's
/// exposure drops out.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RowScale {
    /// Its maximum (the thesis's choice).
    #[default]
    Max,
    /// Its mean: no single patch, clipped or lit by glare, sets the scale (the input of the
    /// ridge that transfers best to real cameras, `docs/real-cameras.md`).
    Mean,
}

impl RowScale {
    /// Whether this is the maximum, the default a file leaves unwritten: models trained
    /// before the choice existed keep their exact bytes when rebuilt.
    pub fn is_max(&self) -> bool {
        *self == RowScale::Max
    }

    /// The divisor of `row`: its maximum or mean, or 1 when that is not positive.
    fn divisor(self, row: &[f64]) -> f64 {
        let d = match self {
            RowScale::Max => row.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            RowScale::Mean => row.iter().sum::<f64>() / row.len().max(1) as f64,
        };
        if d > 0.0 {
            d
        } else {
            1.0
        }
    }
}

/// Per-feature minimum and maximum (after the per-row division), fitted on training rows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FeatureScaler {
    /// Whether each row is first divided by its own maximum or mean (`row_scale`).
    #[serde(rename = "per_sample_max")]
    pub per_row: bool,
    /// What the row is divided by (files from before this field, and files that leave it
    /// out: the maximum).
    #[serde(default, skip_serializing_if = "RowScale::is_max")]
    pub row_scale: RowScale,
    /// Per-feature minimum over the training rows.
    pub min: Vec<f64>,
    /// Per-feature maximum over the training rows.
    pub max: Vec<f64>,
}

/// Checks stored per-column bounds: equal, non-zero lengths and finite numbers.
fn validate_bounds(min: &[f64], max: &[f64], what: &str) -> Result<()> {
    if min.is_empty() || min.len() != max.len() {
        return Err(InferError::invalid(format!(
            "the {what} scaling has mismatched lengths"
        )));
    }
    if min.iter().chain(max).any(|v| !v.is_finite()) {
        return Err(InferError::invalid(format!(
            "the {what} scaling holds non-finite numbers"
        )));
    }
    Ok(())
}

fn check_rows(data: &[f64], width: usize, what: &str) -> Result<usize> {
    if width == 0 || !data.len().is_multiple_of(width) {
        return Err(InferError::invalid(format!(
            "{what}: {} values do not form rows of {width}",
            data.len()
        )));
    }
    if let Some(v) = data.iter().find(|v| !v.is_finite()) {
        return Err(InferError::invalid(format!(
            "{what}: the data hold the non-finite value {v}"
        )));
    }
    Ok(data.len() / width)
}

fn min_max(data: &[f64], width: usize) -> (Vec<f64>, Vec<f64>) {
    let mut min = vec![f64::INFINITY; width];
    let mut max = vec![f64::NEG_INFINITY; width];
    for row in data.chunks_exact(width) {
        for j in 0..width {
            min[j] = min[j].min(row[j]);
            max[j] = max[j].max(row[j]);
        }
    }
    (min, max)
}

impl FeatureScaler {
    /// Fits the scaler on `data`, rows of `width` features, each first divided as `per_row`
    /// says (or not at all).
    pub fn fit(data: &[f64], width: usize, per_row: Option<RowScale>) -> Result<FeatureScaler> {
        let rows = check_rows(data, width, "features")?;
        if rows == 0 {
            return Err(InferError::invalid(
                "features: no rows to fit the scaling on",
            ));
        }
        let mut copy = data.to_vec();
        if let Some(scale) = per_row {
            for row in copy.chunks_exact_mut(width) {
                let d = scale.divisor(row);
                row.iter_mut().for_each(|v| *v /= d);
            }
        }
        let (min, max) = min_max(&copy, width);
        Ok(FeatureScaler {
            per_row: per_row.is_some(),
            row_scale: per_row.unwrap_or_default(),
            min,
            max,
        })
    }

    /// The number of features.
    pub fn width(&self) -> usize {
        self.min.len()
    }

    /// Scales one row into `out` (as f32, the networks' type).
    pub fn transform_into(&self, row: &[f64], out: &mut [f32]) {
        let peak = if self.per_row {
            self.row_scale.divisor(row)
        } else {
            1.0
        };
        for (j, (o, &v)) in out.iter_mut().zip(row).enumerate() {
            let range = self.max[j] - self.min[j];
            let scaled = if range > 0.0 {
                (v / peak - self.min[j]) / range
            } else {
                0.0
            };
            *o = scaled as f32;
        }
    }

    /// Scales rows of features; an error when a row has the wrong width or a bad value.
    pub fn transform(&self, data: &[f64]) -> Result<Vec<f32>> {
        let width = self.width();
        check_rows(data, width, "features")?;
        let mut out = vec![0.0f32; data.len()];
        // Rows of a large block in parallel, a task's worth at a time.
        let task = (width * 256).max(1);
        out.par_chunks_mut(task)
            .zip(data.par_chunks(task))
            .for_each(|(o, rows)| {
                for (row, o) in rows.chunks_exact(width).zip(o.chunks_exact_mut(width)) {
                    self.transform_into(row, o);
                }
            });
        Ok(out)
    }

    /// Checks the stored numbers (for a scaler read from a file).
    pub fn validate(&self) -> Result<()> {
        validate_bounds(&self.min, &self.max, "feature")
    }
}

/// Per-target minimum and maximum: targets are mapped to [0, 1] for training and back.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TargetScaler {
    /// Per-target minimum over the training rows.
    pub min: Vec<f64>,
    /// Per-target maximum over the training rows.
    pub max: Vec<f64>,
}

impl TargetScaler {
    /// Fits the scaler on rows of `width` targets.
    pub fn fit(data: &[f64], width: usize) -> Result<TargetScaler> {
        let rows = check_rows(data, width, "targets")?;
        if rows == 0 {
            return Err(InferError::invalid(
                "targets: no rows to fit the scaling on",
            ));
        }
        let (min, max) = min_max(data, width);
        Ok(TargetScaler { min, max })
    }

    /// The number of targets.
    pub fn width(&self) -> usize {
        self.min.len()
    }

    /// Targets → [0, 1] (as f32).
    pub fn scale(&self, data: &[f64]) -> Vec<f32> {
        let w = self.width();
        data.iter()
            .enumerate()
            .map(|(i, &v)| {
                let j = i % w;
                let range = self.max[j] - self.min[j];
                if range > 0.0 {
                    ((v - self.min[j]) / range) as f32
                } else {
                    0.0
                }
            })
            .collect()
    }

    /// [0, 1] → targets, in place on one row.
    pub fn unscale_into(&self, scaled: &[f32], out: &mut [f64]) {
        for (j, (o, &s)) in out.iter_mut().zip(scaled).enumerate() {
            *o = self.min[j] + f64::from(s) * (self.max[j] - self.min[j]);
        }
    }

    /// Checks the stored numbers (for a scaler read from a file).
    pub fn validate(&self) -> Result<()> {
        validate_bounds(&self.min, &self.max, "target")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn features_per_sample_max_then_min_max() {
        // Two rows; the second is the first at twice the brightness plus a change.
        let data = [10.0, 5.0, 0.0, 40.0, 10.0, 20.0];
        let s = FeatureScaler::fit(&data, 3, Some(RowScale::Max)).unwrap();
        // After /max: [1, .5, 0] and [1, .25, .5].
        assert_eq!(s.min, vec![1.0, 0.25, 0.0]);
        assert_eq!(s.max, vec![1.0, 0.5, 0.5]);
        let t = s.transform(&data).unwrap();
        assert_eq!(t, vec![0.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
        // Brightness does not matter.
        let brighter: Vec<f64> = data[..3].iter().map(|v| v * 3.0).collect();
        assert_eq!(s.transform(&brighter).unwrap(), t[..3].to_vec());
        assert!(s.transform(&[1.0, 2.0]).is_err());
    }

    #[test]
    fn features_per_row_mean_then_min_max() {
        // Row means 5 and 20: after /mean [2, 1, 0] and [2, .5, .5].
        let data = [10.0, 5.0, 0.0, 40.0, 10.0, 10.0];
        let s = FeatureScaler::fit(&data, 3, Some(RowScale::Mean)).unwrap();
        assert_eq!(s.min, vec![2.0, 0.5, 0.0]);
        assert_eq!(s.max, vec![2.0, 1.0, 0.5]);
        assert_eq!(
            s.transform(&data).unwrap(),
            vec![0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
        );
        // A black row is left undivided rather than divided by zero.
        assert_eq!(s.transform(&[0.0; 3]).unwrap(), vec![0.0, -1.0, 0.0]);
    }

    #[test]
    fn a_scaler_written_before_the_row_scale_divides_by_the_maximum() {
        let old = r#"{"per_sample_max": true, "min": [0.0], "max": [1.0]}"#;
        let s: FeatureScaler = serde_json::from_str(old).unwrap();
        assert!(s.per_row);
        assert_eq!(s.row_scale, RowScale::Max);
        let new = serde_json::to_string(&FeatureScaler {
            row_scale: RowScale::Mean,
            ..s.clone()
        })
        .unwrap();
        assert!(new.contains(r#""per_sample_max":true"#), "{new}");
        assert!(new.contains(r#""row_scale":"mean""#), "{new}");
        // The default is left unwritten, so a model trained as before is written as before.
        let default = serde_json::to_string(&s).unwrap();
        assert_eq!(
            default,
            r#"{"per_sample_max":true,"min":[0.0],"max":[1.0]}"#
        );
    }

    #[test]
    fn targets_round_trip() {
        let data = [1.0, -2.0, 3.0, 2.0];
        let s = TargetScaler::fit(&data, 2).unwrap();
        let scaled = s.scale(&data);
        assert_eq!(scaled, vec![0.0, 0.0, 1.0, 1.0]);
        let mut back = [0.0; 2];
        s.unscale_into(&scaled[2..], &mut back);
        assert_eq!(back, [3.0, 2.0]);
    }
}
