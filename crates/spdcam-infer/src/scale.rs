//! The thesis's scaling of inputs and targets, fitted on the training set and stored in the
//! model: each feature row divided by its own maximum, then each feature min-max scaled;
//! each target min-max scaled to [0, 1] so that a sigmoid output can reach it.

use crate::error::{InferError, Result};
use serde::{Deserialize, Serialize};

/// Per-feature minimum and maximum (after the per-sample maximum), fitted on training rows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FeatureScaler {
    /// Whether each row is first divided by its own maximum (the thesis's choice).
    pub per_sample_max: bool,
    /// Per-feature minimum over the training rows.
    pub min: Vec<f64>,
    /// Per-feature maximum over the training rows.
    pub max: Vec<f64>,
}

/// Divides a row by its maximum in place; a row with no positive value is left as it is.
fn divide_by_max(row: &mut [f64]) {
    let max = row.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if max > 0.0 {
        row.iter_mut().for_each(|v| *v /= max);
    }
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
    if width == 0 || data.len() % width != 0 {
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
    /// Fits the scaler on `data`, rows of `width` features.
    pub fn fit(data: &[f64], width: usize, per_sample_max: bool) -> Result<FeatureScaler> {
        let rows = check_rows(data, width, "features")?;
        if rows == 0 {
            return Err(InferError::invalid(
                "features: no rows to fit the scaling on",
            ));
        }
        let mut copy = data.to_vec();
        if per_sample_max {
            copy.chunks_exact_mut(width).for_each(divide_by_max);
        }
        let (min, max) = min_max(&copy, width);
        Ok(FeatureScaler {
            per_sample_max,
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
        let mut peak = 1.0;
        if self.per_sample_max {
            let max = row.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            if max > 0.0 {
                peak = max;
            }
        }
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
        for (row, o) in data.chunks_exact(width).zip(out.chunks_exact_mut(width)) {
            self.transform_into(row, o);
        }
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
        let s = FeatureScaler::fit(&data, 3, true).unwrap();
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
