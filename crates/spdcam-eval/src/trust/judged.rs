//! Photos judged as an estimate judges them (the estimate, its spread, its self-check and
//! its metrics' spread and error), and the statistics the calibration and its measurement
//! take of them.

use crate::error::Result;
use spdcam_core::quality::{registry, LightingMetrics};
use spdcam_core::spectral_error;
use spdcam_infer::trust::{self, ChartCheck, Perturbed, SelfCheck};
use spdcam_infer::Model;
use std::collections::BTreeMap;

/// One feature row judged: the estimate, its spread, its GFC, its self-check, and per
/// single-number metric its spread and (with a truth) its absolute error.
pub struct Judged {
    /// The estimate, peak 1.
    pub spd: Vec<f64>,
    /// The true SPD (peak 1), when known.
    pub truth: Option<Vec<f64>>,
    /// The perturbed copies' spread per wavelength ([`Perturbed::spread`]).
    pub spread: Vec<f64>,
    /// The self-check.
    pub self_check: Option<SelfCheck>,
    /// Per single-number metric, its spread over the perturbed copies (with a truth only).
    pub metric_spread: BTreeMap<String, f64>,
    /// Per single-number metric, its absolute error against the truth.
    pub metric_error: BTreeMap<String, f64>,
    /// Per single-number metric, the estimate's value (with a truth only).
    pub metric_value: BTreeMap<String, f64>,
}

/// `features` estimated and judged by `model` (with the chart check `check`, when the
/// model has one), each beside its truth from `truths`.
pub fn judge_rows(
    model: &Model,
    check: Option<&ChartCheck>,
    features: &[Vec<f64>],
    truths: Option<&[Vec<f64>]>,
) -> Result<Vec<Judged>> {
    let d = model.grid().count;
    let flat: Vec<f64> = features.iter().flatten().copied().collect();
    let spds = model.estimate_rows(&flat)?;
    features
        .iter()
        .enumerate()
        .map(|(r, row)| {
            let spd = spdcam_core::spectral::normalise_by_max(&spds[r * d..(r + 1) * d]);
            let scale = trust::feature_scale(row);
            let self_check = match check {
                Some(c) => c
                    .check(&spd, row, scale, &trust::flag_patches(row, scale))
                    .ok(),
                None => None,
            };
            let perturbed = Perturbed::of(model, row)?;
            let truth = truths.map(|t| t[r].clone());
            Judged::of(
                spd,
                truth,
                &perturbed,
                self_check,
                &model.grid().wavelengths(),
            )
        })
        .collect()
}

impl Judged {
    /// The estimate `spd` (peak 1, on `wavelengths`) judged: beside its truth when known,
    /// its perturbed copies `perturbed` and its self-check.
    pub fn of(
        spd: Vec<f64>,
        truth: Option<Vec<f64>>,
        perturbed: &Perturbed,
        self_check: Option<SelfCheck>,
        wavelengths: &[f64],
    ) -> Result<Judged> {
        let (metric_error, metric_value) = match &truth {
            Some(t) => {
                let (e, t) = (
                    LightingMetrics::from_samples(wavelengths, &spd),
                    LightingMetrics::from_samples(wavelengths, t),
                );
                registry::calibrated()
                    .filter_map(|metric| {
                        let (k, value) = (metric.key, metric.value(&e)?);
                        let error = (value - metric.value(&t)?).abs();
                        Some(((k.to_string(), error), (k.to_string(), value)))
                    })
                    .unzip()
            }
            None => (BTreeMap::new(), BTreeMap::new()),
        };
        Ok(Judged {
            spread: perturbed.spread(),
            // The metrics' spread serves the intervals, measured only against a truth.
            metric_spread: if truth.is_some() {
                perturbed.metric_spread(wavelengths)
            } else {
                BTreeMap::new()
            },
            metric_error,
            metric_value,
            truth,
            spd,
            self_check,
        })
    }
}

pub use spdcam_infer::trust::conformal_quantile;

/// The median of `values`.
pub fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}

/// The GFC of a judged photo against its truth (0 without one).
pub fn gfc(judged: &Judged) -> f64 {
    judged
        .truth
        .as_deref()
        .and_then(|t| spectral_error::gfc(t, &judged.spd).ok())
        .unwrap_or(0.0)
}

/// The difficulty of a judged photo: the mean spread of its perturbed estimates.
pub fn difficulty(judged: &Judged) -> f64 {
    judged.spread.iter().sum::<f64>() / judged.spread.len() as f64
}

/// The self-check residual of a judged photo ([`SelfCheck::mean`]).
pub fn residual(judged: &Judged) -> Option<f64> {
    judged.self_check.as_ref().map(|s| s.mean)
}

/// A photo's band error in units of its calibrated scale: per wavelength
/// |error(λ)| / ((f(λ) + s(λ))·w), the quantity the calibration's conformal quantiles are
/// taken of ([`trust::TrustCalibration`]); `floor` is the calibration's f(λ) and `widening` the
/// photo's w.
pub fn band_z(floor: &[f64], widening: f64, judged: &Judged) -> Vec<f64> {
    let truth = judged.truth.as_deref().unwrap_or_default();
    truth
        .iter()
        .enumerate()
        .map(|(k, t)| (judged.spd[k] - t).abs() / ((floor[k] + judged.spread[k]) * widening))
        .collect()
}

/// Per level of `levels`, per wavelength: the conformal quantile of the photos' [`band_z`]
/// rows `z`, the scale of the band of that level.
pub fn quantile_scales(z: &[Vec<f64>], levels: &[f64]) -> Vec<Vec<f64>> {
    let d = z.first().map_or(0, Vec::len);
    levels
        .iter()
        .map(|&q| {
            (0..d)
                .map(|k| conformal_quantile(&mut z.iter().map(|r| r[k]).collect::<Vec<_>>(), q))
                .collect()
        })
        .collect()
}

/// Spearman's rank correlation (Spearman 1904), ties given their mean rank.
pub fn spearman(a: &[f64], b: &[f64]) -> f64 {
    fn ranks(v: &[f64]) -> Vec<f64> {
        let mut idx: Vec<usize> = (0..v.len()).collect();
        idx.sort_by(|&i, &j| v[i].total_cmp(&v[j]));
        let mut r = vec![0.0; v.len()];
        let mut s = 0;
        while s < idx.len() {
            let mut e = s;
            while e + 1 < idx.len() && v[idx[e + 1]] == v[idx[s]] {
                e += 1;
            }
            for &i in &idx[s..=e] {
                r[i] = (s + e) as f64 / 2.0;
            }
            s = e + 1;
        }
        r
    }
    let (ra, rb) = (ranks(a), ranks(b));
    let n = a.len() as f64;
    let (ma, mb) = (ra.iter().sum::<f64>() / n, rb.iter().sum::<f64>() / n);
    let cov: f64 = ra.iter().zip(&rb).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let va: f64 = ra.iter().map(|x| (x - ma).powi(2)).sum();
    let vb: f64 = rb.iter().map(|y| (y - mb).powi(2)).sum();
    if va == 0.0 || vb == 0.0 {
        return 0.0;
    }
    cov / (va * vb).sqrt()
}

/// Judged photos made to order, for the tests of the calibration and its measurement.
#[cfg(test)]
pub(crate) mod fixtures {
    use super::Judged;
    use std::collections::BTreeMap;

    /// A judged photo whose estimate `spd` has the GFC `gfc` against its truth and whose
    /// perturbed estimates spread by `spread` at every wavelength.
    pub(crate) fn judged(spd: &[f64], gfc: f64, spread: f64) -> Judged {
        let norm = spd.iter().map(|v| v * v).sum::<f64>().sqrt();
        let u: Vec<f64> = spd.iter().map(|v| v / norm).collect();
        // A unit vector orthogonal to u (Gram–Schmidt on (1, −1, 1, −1, …)).
        let a: Vec<f64> = (0..spd.len()).map(|k| [1.0, -1.0][k % 2]).collect();
        let along: f64 = a.iter().zip(&u).map(|(x, y)| x * y).sum();
        let v: Vec<f64> = a.iter().zip(&u).map(|(x, y)| x - along * y).collect();
        let vn = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let sin = (1.0 - gfc * gfc).sqrt();
        Judged {
            spd: spd.to_vec(),
            truth: Some(
                u.iter()
                    .zip(&v)
                    .map(|(x, y)| gfc * x + sin * y / vn)
                    .collect(),
            ),
            spread: vec![spread; spd.len()],
            self_check: None,
            metric_spread: BTreeMap::new(),
            metric_error: BTreeMap::new(),
            metric_value: BTreeMap::new(),
        }
    }
}
