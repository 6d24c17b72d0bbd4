//! The spread: the model's estimates of copies of the feature row, each feature perturbed
//! by about the noise of a photo of a chart. Where many lights give nearly the same photo the
//! copies spread widely; the calibration turns the spread into bands and intervals.

use crate::error::{InferError, Result};
use crate::model::Model;
use rand::rngs::SmallRng;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use spdcam_core::quality::{registry, LightingMetrics};
use std::collections::BTreeMap;

/// Perturbed copies of the features whose estimates measure the spread.
pub const JITTER_COPIES: usize = 16;
/// Relative size (standard deviation) of the perturbation of each feature: about the
/// patch-to-patch noise of an 8-bit JPEG of a chart plus the sampling error.
pub const JITTER_SIGMA: f64 = 0.02;
/// Seed of the perturbations, fixed so an estimate is reproducible.
const JITTER_SEED: u64 = 0x7472_7573_7400_0001;

/// The scale of a feature row: 255 when any value exceeds 1, else 1 (as the feature checks
/// tell them apart).
pub fn feature_scale(row: &[f64]) -> f64 {
    if row.iter().any(|&v| v > 1.0) {
        255.0
    } else {
        1.0
    }
}

/// Whether a patch's encoded RGB has a channel at the top of the scale.
pub fn clipped_patch(rgb: &[f64], scale: f64) -> bool {
    rgb.iter().any(|&v| v >= 0.995 * scale)
}

/// The model's estimates of [`JITTER_COPIES`] copies of one feature row, each feature
/// perturbed by ±[`JITTER_SIGMA`] (multiplicative, log-normal), peak-normalised. Where many
/// lights give nearly the same photo the network's answer is steep in its input and the
/// copies spread widely — a sensitivity analysis of the inverse map (Saltelli et al. 2008,
/// "Global Sensitivity Analysis: The Primer", ch. 1), propagated to the metrics by Monte
/// Carlo (JCGM 101:2008, GUM Supplement 1, section 7).
#[derive(Debug, Clone)]
pub struct Perturbed {
    copies: Vec<Vec<f64>>,
}

impl Perturbed {
    /// The perturbed estimates of `row` by `model` (a fixed seed: reproducible).
    pub fn of(model: &Model, row: &[f64]) -> Result<Perturbed> {
        let scale = feature_scale(row);
        let noise = Normal::new(0.0, JITTER_SIGMA)
            .map_err(|e| InferError::invalid(format!("jitter: {e}")))?;
        let mut rng = SmallRng::seed_from_u64(JITTER_SEED);
        let mut rows = Vec::with_capacity(JITTER_COPIES * row.len());
        for _ in 0..JITTER_COPIES {
            rows.extend(
                row.iter()
                    .map(|&v| (v * noise.sample(&mut rng).exp()).clamp(0.0, scale)),
            );
        }
        let d = model.grid().count;
        let copies = model
            .estimate_rows(&rows)?
            .chunks_exact(d)
            .map(spdcam_core::spectral::normalise_by_max)
            .collect();
        Ok(Perturbed { copies })
    }

    /// Per wavelength, the standard deviation of the copies.
    pub fn spread(&self) -> Vec<f64> {
        let d = self.copies.first().map_or(0, Vec::len);
        (0..d)
            .map(|k| sample_std(self.copies.iter().map(|s| s[k])))
            .collect()
    }

    /// Per calibrated metric ([`registry::calibrated`]), the standard deviation of its values
    /// over the copies (on `wavelengths`, the model's grid); a metric undefined for more than
    /// a quarter of the copies has none.
    pub fn metric_spread(&self, wavelengths: &[f64]) -> BTreeMap<String, f64> {
        let all: Vec<LightingMetrics> = self
            .copies
            .iter()
            .map(|s| LightingMetrics::from_samples(wavelengths, s))
            .collect();
        registry::calibrated()
            .filter_map(|metric| {
                let values: Vec<f64> = all.iter().filter_map(|m| metric.value(m)).collect();
                (4 * values.len() >= 3 * all.len() && values.len() > 1)
                    .then(|| (metric.key.to_string(), sample_std(values.into_iter())))
            })
            .collect()
    }
}

/// The sample standard deviation (n − 1) of `values`; 0 for fewer than two.
fn sample_std(values: impl Iterator<Item = f64> + Clone) -> f64 {
    let n = values.clone().count();
    if n < 2 {
        return 0.0;
    }
    let mean = values.clone().sum::<f64>() / n as f64;
    (values.map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt()
}
