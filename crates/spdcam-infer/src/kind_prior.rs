//! The kind of light, when the person knows it: a model's estimate moved to the lights of that
//! kind. Each kind carries a sample of its lights (particles, drawn from the kind's lighting
//! recipe) and how the model errs on photos of them (the mean and covariance of its residuals
//! in a common PCA basis). The estimate for a named kind is the posterior mean given the
//! model's estimate, by Bayes' rule with a Gaussian likelihood of the residuals and, as the
//! prior, a kernel density estimate of the kind's lights: a Gaussian of covariance H = h²·Σ
//! around each particle (Σ the particles' covariance, h by Scott's rule n^(−1/(k+4)); Scott,
//! *Multivariate Density Estimation*, 1992, §6.3). Each kernel's posterior is the Kalman
//! update `p + H(H + R)⁻¹(y − p)`, weighted by `N(y; p, H + R)` (a Gaussian-sum filter:
//! Alspach & Sorenson 1972, *IEEE Trans. Autom. Control* 17, 439). A daylight estimate is
//! then a mixture of daylights (the kernels span only the family's directions), a
//! fluorescent one keeps its mercury lines.
//!
//! `spdcam light-kinds fit` makes a model's priors; the shipped models' are built in.

use crate::colour_map::ColourMap;
use crate::error::{InferError, Result};
use crate::model::Model;
use crate::pca::Pca;
use faer::linalg::solvers::DenseSolveCore;
use faer::{Mat, Side};
use serde::{Deserialize, Serialize};
use spdcam_core::light_families::LightKind;
use spdcam_core::spectral::normalise_by_max;

/// The `format` field of a priors file.
pub const FORMAT: &str = "spdcam-light-kinds";
/// The version of the format this program reads and writes.
pub const VERSION: u32 = 1;

/// The shrinkage of a residual covariance towards its mean variance (a fraction of the
/// mean diagonal added to the diagonal), so that a direction the residual photos barely
/// explored is not taken as certain (Ledoit & Wolf 2004, *J. Multivariate Anal.* 88, 365).
pub const SHRINKAGE: f64 = 0.05;

/// One model's priors for every kind it can be told of.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KindPriors {
    /// Always [`FORMAT`].
    pub format: String,
    /// [`VERSION`].
    pub version: u32,
    /// The fingerprint of the model the residuals were measured on.
    pub model: String,
    /// How the priors were made.
    pub method: String,
    /// The common basis on the model's wavelengths: a PCA of every kind's particles.
    pub basis: Pca,
    /// One prior per kind, `Unknown` excepted.
    pub kinds: Vec<KindPrior>,
}

/// One kind's prior.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KindPrior {
    /// The kind.
    pub kind: LightKind,
    /// The lighting recipe the particles and residual photos were drawn from.
    pub recipe: String,
    /// The particles: lights of the kind as coefficients of the basis.
    pub particles: Vec<Vec<f64>>,
    /// The model's mean residual (estimate − truth) in the basis.
    pub bias: Vec<f64>,
    /// `(H + R)⁻¹`: the inverse of the kernel covariance plus the residuals' covariance
    /// (shrunk by [`SHRINKAGE`]); it weighs the kernels.
    pub precision: Vec<Vec<f64>>,
    /// `H (H + R)⁻¹`: how far each kernel's mean moves towards the estimate.
    pub gain: Vec<Vec<f64>>,
    /// How many photos the residuals were measured on.
    pub residual_photos: usize,
    /// The distance ([`KindPrior::distance`]) 99 % of those photos stay within: an
    /// estimate farther from every light of the kind is unlike the kind.
    pub unlike_level: f64,
}

/// The share of the kind's own photos [`KindPrior::unlike_level`] keeps within.
pub const UNLIKE_QUANTILE: f64 = 0.99;

impl KindPrior {
    /// The prior of `kind` from its particles and the model's estimates of photos of other
    /// lights of the kind with their truths (in the basis, one pair per photo): the kernel
    /// covariance from the particles' own, the likelihood from the residuals `estimate −
    /// truth`, the unlike level from the estimates' distances.
    pub fn from_photos(
        kind: LightKind,
        recipe: &str,
        particles: Vec<Vec<f64>>,
        estimates: &[Vec<f64>],
        truths: &[Vec<f64>],
    ) -> Result<KindPrior> {
        let k = particles.first().map_or(0, Vec::len);
        let residuals: Vec<Vec<f64>> = estimates
            .iter()
            .zip(truths)
            .map(|(e, t)| e.iter().zip(t).map(|(a, b)| a - b).collect())
            .collect();
        if k == 0 || residuals.len() < 2 * k {
            return Err(InferError::invalid(format!(
                "{}: {} residual photos for {k} coefficients; at least twice as many are needed",
                kind.name(),
                residuals.len()
            )));
        }
        let (bias, mut residual) = mean_and_covariance(&residuals, k);
        let mean_variance = (0..k).map(|j| residual[(j, j)]).sum::<f64>() / k as f64;
        for j in 0..k {
            residual[(j, j)] += SHRINKAGE * mean_variance;
        }
        let h2 = (particles.len() as f64).powf(-2.0 / (k as f64 + 4.0));
        let kernel = mean_and_covariance(&particles, k).1 * h2;
        let total = &kernel + &residual;
        let llt = total.llt(Side::Lower).map_err(|e| {
            InferError::Numerical(format!("{}: the residual covariance: {e:?}", kind.name()))
        })?;
        let precision = llt.inverse();
        let gain = &kernel * &precision;
        let rows = |m: &Mat<f64>| -> Vec<Vec<f64>> {
            (0..k)
                .map(|a| (0..k).map(|b| m[(a, b)]).collect())
                .collect()
        };
        let mut prior = KindPrior {
            kind,
            recipe: recipe.to_string(),
            particles,
            bias,
            precision: rows(&precision),
            gain: rows(&gain),
            residual_photos: residuals.len(),
            unlike_level: f64::INFINITY,
        };
        let mut distances: Vec<f64> = estimates.iter().map(|e| prior.distance(e)).collect();
        distances.sort_by(f64::total_cmp);
        let at = ((distances.len() as f64 * UNLIKE_QUANTILE).ceil() as usize).max(1);
        prior.unlike_level = distances[at.min(distances.len()) - 1];
        Ok(prior)
    }

    /// How far the model's estimate `coefficients` lies from the kind's lights: the smallest
    /// squared Mahalanobis distance (under `H + R`) of its bias-corrected coefficients to a
    /// particle.
    pub fn distance(&self, coefficients: &[f64]) -> f64 {
        self.quadratics(coefficients)
            .into_iter()
            .fold(f64::INFINITY, f64::min)
    }

    /// `(y − pᵢ)ᵀ (H + R)⁻¹ (y − pᵢ)` for each particle, `y` the estimate less the bias.
    fn quadratics(&self, coefficients: &[f64]) -> Vec<f64> {
        let k = self.bias.len();
        let y: Vec<f64> = (0..k).map(|j| coefficients[j] - self.bias[j]).collect();
        self.particles
            .iter()
            .map(|p| {
                let d: Vec<f64> = (0..k).map(|j| y[j] - p[j]).collect();
                (0..k)
                    .map(|a| d[a] * (0..k).map(|b| self.precision[a][b] * d[b]).sum::<f64>())
                    .sum()
            })
            .collect()
    }

    /// The posterior mean for the model's estimate `coefficients` (in the basis): each
    /// kernel's updated mean, weighed by how likely the estimate is under it.
    pub fn posterior(&self, coefficients: &[f64]) -> Vec<f64> {
        let k = self.bias.len();
        let y: Vec<f64> = (0..k).map(|j| coefficients[j] - self.bias[j]).collect();
        let log_weights: Vec<f64> = self
            .quadratics(coefficients)
            .into_iter()
            .map(|q| -0.5 * q)
            .collect();
        let top = log_weights
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max);
        let weights: Vec<f64> = log_weights.iter().map(|l| (l - top).exp()).collect();
        let total: f64 = weights.iter().sum();
        // Σ wᵢ (pᵢ + G (y − pᵢ)) = p̄ + G (y − p̄), p̄ the weighted mean of the particles.
        let mean: Vec<f64> = (0..k)
            .map(|j| {
                self.particles
                    .iter()
                    .zip(&weights)
                    .map(|(p, w)| p[j] * w)
                    .sum::<f64>()
                    / total
            })
            .collect();
        (0..k)
            .map(|a| {
                mean[a]
                    + (0..k)
                        .map(|b| self.gain[a][b] * (y[b] - mean[b]))
                        .sum::<f64>()
            })
            .collect()
    }
}

/// The mean and the sample covariance (n − 1) of `rows`, each of `k` values.
fn mean_and_covariance(rows: &[Vec<f64>], k: usize) -> (Vec<f64>, Mat<f64>) {
    let n = rows.len() as f64;
    let mean: Vec<f64> = (0..k)
        .map(|j| rows.iter().map(|r| r[j]).sum::<f64>() / n)
        .collect();
    let cov = Mat::<f64>::from_fn(k, k, |a, b| {
        rows.iter()
            .map(|r| (r[a] - mean[a]) * (r[b] - mean[b]))
            .sum::<f64>()
            / (n - 1.0).max(1.0)
    });
    (mean, cov)
}

impl KindPriors {
    /// Reads priors from JSON, `source` naming the text in errors; every kind's sizes are
    /// checked against the basis.
    pub fn from_json(text: &str, source: &str) -> Result<KindPriors> {
        let priors: KindPriors = serde_json::from_str(text)
            .map_err(|e| InferError::invalid(format!("{source}: not light-kind priors: {e}")))?;
        if priors.format != FORMAT || priors.version != VERSION {
            return Err(InferError::invalid(format!(
                "{source}: format '{}' version {}; this program reads {FORMAT} version {VERSION}",
                priors.format, priors.version
            )));
        }
        priors.basis.validate()?;
        let k = priors.basis.len();
        for prior in &priors.kinds {
            let square = |m: &[Vec<f64>]| m.len() == k && m.iter().all(|r| r.len() == k);
            if prior.particles.is_empty()
                || prior.particles.iter().any(|p| p.len() != k)
                || prior.bias.len() != k
                || !square(&prior.precision)
                || !square(&prior.gain)
            {
                return Err(InferError::invalid(format!(
                    "{source}: the prior of {} does not match the basis of {k} components",
                    prior.kind.name()
                )));
            }
        }
        Ok(priors)
    }

    /// The priors as the JSON `spdcam light-kinds fit` writes.
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string(self)
            .map_err(|e| InferError::invalid(format!("light-kind priors: {e}")))
    }

    /// The prior of `kind`, if these priors hold one.
    pub fn prior(&self, kind: LightKind) -> Option<&KindPrior> {
        self.kinds.iter().find(|p| p.kind == kind)
    }

    /// The kinds these priors can be told of, `Unknown` first.
    pub fn kinds(&self) -> Vec<LightKind> {
        LightKind::ALL
            .into_iter()
            .filter(|&k| k == LightKind::Unknown || self.prior(k).is_some())
            .collect()
    }

    /// The model's estimate `spd` (on the model's grid) moved to the lights of `kind`, peak
    /// 1; `Unknown` gives it back unchanged.
    ///
    /// ```
    /// use spdcam_core::light_families::LightKind;
    /// use spdcam_infer::kind_prior::{KindPrior, KindPriors, FORMAT, VERSION};
    /// use spdcam_infer::pca::{Components, Pca};
    ///
    /// // Two-sample spectra; the basis keeps both directions.
    /// let basis = Pca::fit(&[1.0, 0.0, 0.0, 1.0, 0.5, 0.5], 2, Components::Count(2))?;
    /// let lights = [[1.0, 0.2], [1.0, 0.9]].map(|s| basis.project(&s));
    /// // Photos of the lights, estimated a little off.
    /// let truths: Vec<Vec<f64>> = (0..8).map(|i| lights[i % 2].clone()).collect();
    /// let estimates: Vec<Vec<f64>> = truths
    ///     .iter()
    ///     .enumerate()
    ///     .map(|(i, t)| vec![t[0] + 0.01 * (i % 3) as f64, t[1] + 0.01 * (i / 4) as f64])
    ///     .collect();
    /// let prior =
    ///     KindPrior::from_photos(LightKind::Daylight, "test", lights.to_vec(), &estimates, &truths)?;
    /// let priors = KindPriors {
    ///     format: FORMAT.into(), version: VERSION, model: "m".into(), method: "test".into(),
    ///     basis, kinds: vec![prior],
    /// };
    /// // An estimate among the kind's lights is moved (peak 1) and is like the kind; one far
    /// // from both lights is unlike it; `Unknown` leaves an estimate as it is.
    /// let moved = priors.apply(LightKind::Daylight, &[1.0, 0.25])?;
    /// assert_eq!(moved.iter().copied().fold(0.0, f64::max), 1.0);
    /// assert!(!priors.unlike(LightKind::Daylight, &[1.0, 0.25])?);
    /// assert!(priors.unlike(LightKind::Daylight, &[0.1, 1.0])?);
    /// assert_eq!(priors.apply(LightKind::Unknown, &[1.0, 0.25])?, [1.0, 0.25]);
    /// # Ok::<(), spdcam_infer::InferError>(())
    /// ```
    pub fn apply(&self, kind: LightKind, spd: &[f64]) -> Result<Vec<f64>> {
        if kind == LightKind::Unknown {
            return Ok(spd.to_vec());
        }
        let (prior, coefficients) = self.coefficients(kind, spd)?;
        let moved: Vec<f64> = self
            .basis
            .reconstruct(&prior.posterior(&coefficients))
            .into_iter()
            .map(|v| v.max(0.0))
            .collect();
        if moved.iter().all(|&v| v <= 0.0) {
            return Err(InferError::Numerical(format!(
                "the {} prior left no light",
                kind.name()
            )));
        }
        Ok(normalise_by_max(&moved))
    }

    /// [`KindPriors::apply`], then, for a model with a colour map, the estimate's corrected
    /// colour given back ([`ColourMap::keep_colour`]): what `estimate --light` gives.
    pub fn told(&self, kind: LightKind, spd: &[f64], map: Option<&ColourMap>) -> Result<Vec<f64>> {
        let moved = self.apply(kind, spd)?;
        Ok(match map {
            Some(map) if kind != LightKind::Unknown => map.keep_colour(&self.basis, spd, &moved),
            _ => moved,
        })
    }

    /// Whether the model's estimate `spd` lies farther from every light of `kind` than 99 %
    /// of the kind's own photos do ([`KindPrior::unlike_level`]): the light in the photo is
    /// then unlikely to be of that kind. Never for `Unknown`.
    pub fn unlike(&self, kind: LightKind, spd: &[f64]) -> Result<bool> {
        if kind == LightKind::Unknown {
            return Ok(false);
        }
        let (prior, coefficients) = self.coefficients(kind, spd)?;
        Ok(prior.distance(&coefficients) > prior.unlike_level)
    }

    /// The prior of `kind` and the coefficients of `spd` (peak-normalised) in the basis.
    fn coefficients(&self, kind: LightKind, spd: &[f64]) -> Result<(&KindPrior, Vec<f64>)> {
        let prior = self.prior(kind).ok_or_else(|| {
            InferError::invalid(format!("no prior for the kind of light '{}'", kind.name()))
        })?;
        if spd.len() != self.basis.dim() {
            return Err(InferError::invalid(format!(
                "an SPD of {} samples for light-kind priors of {}",
                spd.len(),
                self.basis.dim()
            )));
        }
        Ok((prior, self.basis.project(&normalise_by_max(spd))))
    }
}

/// The priors built into the program per shipped model (`models/<chart>.kinds.json`): those of
/// `model` (matched by its fingerprint), if any.
pub fn priors_for(model: &Model) -> Result<Option<KindPriors>> {
    let fingerprint = model.fingerprint();
    for shipped in &crate::shipped::SHIPPED {
        let name = format!("{}'s light-kind priors", shipped.name());
        let priors = KindPriors::from_json(shipped.kinds, &name)?;
        if priors.model == fingerprint {
            return Ok(Some(priors));
        }
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pca::Components;

    fn identity_basis() -> Pca {
        // Orthonormal basis of R², mean 0.5: coefficients are the samples minus 0.5.
        Pca {
            mean: vec![0.5, 0.5],
            components: vec![vec![1.0, 0.0], vec![0.0, 1.0]],
            explained_ratio: vec![0.5, 0.5],
            total_variance: 1.0,
        }
    }

    fn prior_with(particles: Vec<Vec<f64>>, precision: f64) -> KindPrior {
        KindPrior {
            kind: LightKind::Fluorescent,
            recipe: "test".into(),
            particles,
            bias: vec![0.0, 0.0],
            precision: vec![vec![precision, 0.0], vec![0.0, precision]],
            gain: vec![vec![0.0; 2]; 2],
            residual_photos: 4,
            unlike_level: 1.0,
        }
    }

    #[test]
    fn the_posterior_weighs_particles_by_their_gaussian_likelihood() {
        // Particles at 0 and 1 on the first axis, the estimate at 0.25, unit precision:
        // weights exp(−0.25²/2) and exp(−0.75²/2); their ratio exp(0.25) by hand.
        let prior = prior_with(vec![vec![0.0, 0.0], vec![1.0, 0.0]], 1.0);
        let w1 = 1.0 / (1.0 + 0.25f64.exp());
        let mean = prior.posterior(&[0.25, 0.0]);
        assert!((mean[0] - w1).abs() < 1e-12, "{mean:?} against {w1}");
        assert_eq!(mean[1], 0.0);
        // A sharp likelihood picks the nearer particle.
        let sharp = prior_with(vec![vec![0.0, 0.0], vec![1.0, 0.0]], 1e4);
        assert!(sharp.posterior(&[0.25, 0.0])[0] < 1e-12);
        // A kernel's mean moves towards the estimate by the gain: halfway on the first axis.
        let mut kernel = prior_with(vec![vec![0.0, 0.0]], 1.0);
        kernel.gain[0][0] = 0.5;
        assert_eq!(kernel.posterior(&[1.0, 1.0]), [0.5, 0.0]);
        // Far from every particle, no weight underflows to a division by zero.
        let far = sharp.posterior(&[1e3, 0.0]);
        assert!((far[0] - 1.0).abs() < 1e-12);
    }

    #[test]
    fn the_bias_is_taken_off_before_weighing() {
        let mut prior = prior_with(vec![vec![0.0, 0.0], vec![1.0, 0.0]], 1e4);
        // The model reads 0.8 too high: an estimate at 0.9 is the particle at 0.1 → 0.
        prior.bias = vec![0.8, 0.0];
        assert!(prior.posterior(&[0.9, 0.0])[0] < 1e-6);
    }

    #[test]
    fn residual_statistics_are_the_sample_mean_and_shrunk_covariance() {
        // Residuals ±1 on the first axis about 0.5, ±2 on the second about 0: sample
        // variances 4/3 and 16/3 (n − 1 = 3), mean variance 10/3, shrinkage 0.05 of it.
        let residuals = vec![
            vec![1.5, 2.0],
            vec![-0.5, -2.0],
            vec![1.5, -2.0],
            vec![-0.5, 2.0],
        ];
        let zeros = vec![vec![0.0; 2]; residuals.len()];
        let prior = KindPrior::from_photos(
            LightKind::Hid,
            "t",
            vec![vec![0.0, 0.0]],
            &residuals,
            &zeros,
        )
        .unwrap();
        assert_eq!(prior.bias, [0.5, 0.0]);
        let shrink = SHRINKAGE * 10.0 / 3.0;
        assert!((prior.precision[0][0] - 1.0 / (4.0 / 3.0 + shrink)).abs() < 1e-12);
        assert!((prior.precision[1][1] - 1.0 / (16.0 / 3.0 + shrink)).abs() < 1e-12);
        assert!(prior.precision[0][1].abs() < 1e-12);
        // Two particles 2 apart on the first axis: their variance 2 there, 0 on the second;
        // the kernel h²·2 with h² = 2^(−2/6) (Scott, n = 2, k = 2) moves the first axis only.
        let two = KindPrior::from_photos(
            LightKind::Hid,
            "t",
            vec![vec![0.0, 0.0], vec![2.0, 0.0]],
            &residuals,
            &zeros,
        )
        .unwrap();
        let kernel = 2.0 * 2f64.powf(-1.0 / 3.0);
        let total = kernel + 4.0 / 3.0 + shrink;
        assert!((two.precision[0][0] - 1.0 / total).abs() < 1e-12);
        assert!((two.gain[0][0] - kernel / total).abs() < 1e-12);
        assert!(two.gain[1][1].abs() < 1e-12 && two.gain[0][1].abs() < 1e-12);
        // Too few photos for the coefficients is refused.
        let err = KindPrior::from_photos(
            LightKind::Hid,
            "t",
            vec![vec![0.0, 0.0]],
            &residuals[..3],
            &zeros[..3],
        )
        .unwrap_err();
        assert!(err.to_string().contains("residual photos"), "{err}");
    }

    #[test]
    fn a_round_trip_through_json_keeps_the_priors_and_sizes_are_checked() {
        let priors = KindPriors {
            format: FORMAT.into(),
            version: VERSION,
            model: "abc".into(),
            method: "test".into(),
            basis: identity_basis(),
            kinds: vec![prior_with(vec![vec![0.5, -0.5]], 2.0)],
        };
        let text = priors.to_json().unwrap();
        assert_eq!(KindPriors::from_json(&text, "t").unwrap(), priors);
        assert_eq!(priors.kinds(), [LightKind::Unknown, LightKind::Fluorescent]);
        let broken = text.replace("[0.5,-0.5]", "[0.5]");
        let err = KindPriors::from_json(&broken, "the file").unwrap_err();
        assert!(err.to_string().contains("fluorescent"), "{err}");
        let err = priors.apply(LightKind::Daylight, &[1.0, 0.0]).unwrap_err();
        assert!(err.to_string().contains("daylight"), "{err}");
        // A one-particle prior gives that particle's spectrum (peak 1).
        let moved = priors.apply(LightKind::Fluorescent, &[0.3, 1.0]).unwrap();
        assert_eq!(moved, [1.0, 0.0]);
    }

    #[test]
    fn a_fitted_basis_projects_and_reconstructs_the_particles() {
        let basis = Pca::fit(&[1.0, 0.0, 0.0, 1.0, 0.5, 0.5], 2, Components::Count(2)).unwrap();
        let p = basis.project(&[1.0, 0.2]);
        let back = basis.reconstruct(&p);
        assert!((back[0] - 1.0).abs() < 1e-12 && (back[1] - 0.2).abs() < 1e-12);
    }
}
