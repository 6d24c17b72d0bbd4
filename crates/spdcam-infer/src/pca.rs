//! Principal component analysis of SPDs (thesis section 4.6.3): the targets a network learns
//! are the first few PCA coefficients of the SPD, and an estimate is turned back into an SPD
//! with the inverse transform.

use crate::error::{InferError, Result};
use faer::Mat;
use serde::{Deserialize, Serialize};

/// How many principal components to keep.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Components {
    /// The fewest components whose explained variance reaches this fraction (0 < f ≤ 1).
    Variance(f64),
    /// Exactly this many components (at most the dimension of the data).
    Count(usize),
}

impl Default for Components {
    /// 99 % explained variance, as in the thesis.
    fn default() -> Self {
        Components::Variance(0.99)
    }
}

/// A fitted PCA: the mean, the kept components (orthonormal rows) and their explained
/// variance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Pca {
    /// The mean of the data, one value per dimension.
    pub mean: Vec<f64>,
    /// The kept components, each a unit vector of the data's dimension, by decreasing variance.
    pub components: Vec<Vec<f64>>,
    /// The fraction of the total variance each kept component explains.
    pub explained_ratio: Vec<f64>,
    /// The total variance of the data (sum over dimensions, divided by n − 1).
    pub total_variance: f64,
}

impl Pca {
    /// Fits the PCA of `data`: `rows` rows of `dim` values each, row-major.
    pub fn fit(data: &[f64], dim: usize, choice: Components) -> Result<Pca> {
        if dim == 0 || !data.len().is_multiple_of(dim) {
            return Err(InferError::invalid(format!(
                "PCA: {} values do not form rows of {dim}",
                data.len()
            )));
        }
        let rows = data.len() / dim;
        if rows < 2 {
            return Err(InferError::invalid(format!(
                "PCA needs at least 2 samples, got {rows}"
            )));
        }
        if let Some(v) = data.iter().find(|v| !v.is_finite()) {
            return Err(InferError::invalid(format!(
                "PCA: the data hold the non-finite value {v}"
            )));
        }
        let mut mean = vec![0.0; dim];
        for row in data.chunks_exact(dim) {
            for (m, v) in mean.iter_mut().zip(row) {
                *m += v;
            }
        }
        mean.iter_mut().for_each(|m| *m /= rows as f64);
        let centred = Mat::<f64>::from_fn(rows, dim, |i, j| data[i * dim + j] - mean[j]);
        let svd = centred
            .thin_svd()
            .map_err(|e| InferError::Numerical(format!("PCA: the SVD failed: {e:?}")))?;
        let s = svd.S().column_vector();
        let v = svd.V();
        let squares: Vec<f64> = (0..s.nrows()).map(|i| s[i] * s[i]).collect();
        let total: f64 = squares.iter().sum();
        if total <= 0.0 {
            return Err(InferError::invalid(
                "PCA: all samples are identical; there is no variance to explain",
            ));
        }
        let ratios: Vec<f64> = squares.iter().map(|q| q / total).collect();
        let keep = match choice {
            Components::Count(k) => {
                if k == 0 || k > ratios.len() {
                    return Err(InferError::invalid(format!(
                        "PCA: {k} components asked for; between 1 and {} possible",
                        ratios.len()
                    )));
                }
                k
            }
            Components::Variance(f) => {
                if !(f > 0.0 && f <= 1.0) {
                    return Err(InferError::invalid(format!(
                        "PCA: explained variance {f} must lie in (0, 1]"
                    )));
                }
                let mut sum = 0.0;
                let mut k = ratios.len();
                for (i, r) in ratios.iter().enumerate() {
                    sum += r;
                    // A hair of slack so that 1.0 is reached despite rounding.
                    if sum >= f - 1e-12 {
                        k = i + 1;
                        break;
                    }
                }
                k
            }
        };
        let components = (0..keep)
            .map(|c| (0..dim).map(|j| v[(j, c)]).collect())
            .collect();
        Ok(Pca {
            mean,
            components,
            explained_ratio: ratios[..keep].to_vec(),
            total_variance: total / (rows - 1) as f64,
        })
    }

    /// The dimension of the data.
    pub fn dim(&self) -> usize {
        self.mean.len()
    }

    /// The number of kept components.
    pub fn len(&self) -> usize {
        self.components.len()
    }

    /// Whether no component is kept (never true for a fitted PCA).
    pub fn is_empty(&self) -> bool {
        self.components.is_empty()
    }

    /// The fraction of the variance the kept components explain together.
    pub fn explained_variance(&self) -> f64 {
        self.explained_ratio.iter().sum()
    }

    /// The coefficients of one row of data.
    pub fn project(&self, row: &[f64]) -> Vec<f64> {
        self.components
            .iter()
            .map(|c| {
                c.iter()
                    .zip(row.iter().zip(&self.mean))
                    .map(|(ci, (x, m))| ci * (x - m))
                    .sum()
            })
            .collect()
    }

    /// The row of data that the coefficients stand for (the inverse transform).
    pub fn reconstruct(&self, coefficients: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.mean.len()];
        self.reconstruct_into(coefficients, &mut out);
        out
    }

    /// [`Pca::reconstruct`] into `out` (of the data's dimension), for callers that
    /// reconstruct many rows into one buffer.
    pub fn reconstruct_into(&self, coefficients: &[f64], out: &mut [f64]) {
        out.copy_from_slice(&self.mean);
        for (c, &a) in self.components.iter().zip(coefficients) {
            for (o, ci) in out.iter_mut().zip(c) {
                *o += a * ci;
            }
        }
    }

    /// Checks the fitted numbers are consistent (for a PCA read from a file).
    pub fn validate(&self) -> Result<()> {
        let dim = self.dim();
        if dim == 0 || self.components.is_empty() {
            return Err(InferError::invalid(
                "the PCA has no dimension or no component",
            ));
        }
        if self.components.iter().any(|c| c.len() != dim)
            || self.explained_ratio.len() != self.components.len()
        {
            return Err(InferError::invalid(
                "the PCA's components do not match its dimension",
            ));
        }
        let finite = self
            .mean
            .iter()
            .chain(self.components.iter().flatten())
            .all(|v| v.is_finite());
        if !finite {
            return Err(InferError::invalid("the PCA holds non-finite numbers"));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// Rows made from 3 smooth basis spectra with random weights, plus a little noise.
    fn data(rows: usize, dim: usize, seed: u64) -> Vec<f64> {
        let mut rng = rand::rngs::SmallRng::seed_from_u64(seed);
        let basis: Vec<Vec<f64>> = [0.3, 0.5, 0.7]
            .iter()
            .map(|mu| {
                (0..dim)
                    .map(|j| {
                        let x = j as f64 / dim as f64 - mu;
                        (-x * x / 0.02).exp()
                    })
                    .collect()
            })
            .collect();
        let mut out = Vec::with_capacity(rows * dim);
        for _ in 0..rows {
            let w: Vec<f64> = (0..3).map(|_| rng.random::<f64>()).collect();
            for j in 0..dim {
                let v: f64 = w.iter().zip(&basis).map(|(wk, b)| wk * b[j]).sum();
                out.push(v + 0.01 * (rng.random::<f64>() - 0.5));
            }
        }
        out
    }

    #[test]
    fn reconstruction_error_within_the_explained_variance_bound() {
        let dim = 61;
        let rows = 500;
        let x = data(rows, dim, 7);
        let pca = Pca::fit(&x, dim, Components::Variance(0.99)).unwrap();
        assert!(pca.explained_variance() >= 0.99);
        assert!(pca.len() <= 4, "{} components", pca.len());
        // Σ‖x − x̂‖² / (n − 1) = (1 − explained) · total variance, and so ≤ 1 % of it.
        let mut sq = 0.0;
        for row in x.chunks_exact(dim) {
            let r = pca.reconstruct(&pca.project(row));
            sq += row
                .iter()
                .zip(&r)
                .map(|(a, b)| (a - b) * (a - b))
                .sum::<f64>();
        }
        let residual = sq / (rows - 1) as f64;
        let bound = (1.0 - pca.explained_variance()) * pca.total_variance;
        assert!(residual <= 0.01 * pca.total_variance + 1e-12);
        assert!(
            (residual - bound).abs() <= 1e-9 * pca.total_variance,
            "{residual} vs {bound}"
        );
    }

    #[test]
    fn components_are_orthonormal_and_full_rank_reconstructs_exactly() {
        let dim = 20;
        let x = data(100, dim, 3);
        let pca = Pca::fit(&x, dim, Components::Count(dim)).unwrap();
        for a in 0..dim {
            for b in 0..dim {
                let dot: f64 = pca.components[a]
                    .iter()
                    .zip(&pca.components[b])
                    .map(|(p, q)| p * q)
                    .sum();
                let expected = if a == b { 1.0 } else { 0.0 };
                assert!((dot - expected).abs() < 1e-10);
            }
        }
        let row = &x[..dim];
        let back = pca.reconstruct(&pca.project(row));
        for (a, b) in row.iter().zip(&back) {
            assert!((a - b).abs() < 1e-10);
        }
    }

    #[test]
    fn bad_input_is_an_error() {
        assert!(Pca::fit(&[1.0, 2.0, 3.0], 2, Components::default()).is_err());
        assert!(Pca::fit(&[1.0, 2.0], 2, Components::default()).is_err());
        assert!(Pca::fit(&[1.0, 2.0, 1.0, 2.0], 2, Components::default()).is_err());
        let x = data(10, 5, 1);
        assert!(Pca::fit(&x, 5, Components::Count(6)).is_err());
        assert!(Pca::fit(&x, 5, Components::Variance(1.5)).is_err());
    }
}
