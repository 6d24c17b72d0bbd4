//! Ridge regression for the sim-to-real experiments: rows of inputs to rows of targets in
//! closed form, the penalty relative to the mean diagonal of XᵀX, shrinking either towards
//! zero or towards a prior model's weights (a virtual-trained model that a few real photos
//! correct), with the penalty chosen by k-fold cross-validation on the training rows.

use anyhow::{bail, Result};
use nalgebra::DMatrix;
use spdcam_core::metrics;

/// Penalties (relative) that [`Ridge::fit_cv`] chooses among.
pub const PENALTIES: [f64; 8] = [1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1, 1.0, 10.0];

/// A fitted linear map; predictions are clipped at zero (spectra are not negative).
#[derive(Debug, Clone)]
pub struct Ridge {
    /// targets × inputs.
    weights: DMatrix<f64>,
}

/// XᵀX and XᵀY of a set of rows, reused for every penalty.
struct Gram {
    xtx: DMatrix<f64>,
    xty: DMatrix<f64>,
    scale: f64,
}

impl Gram {
    fn new(x: &[&[f64]], y: &[&[f64]]) -> Result<Gram> {
        let (Some(x0), Some(y0)) = (x.first(), y.first()) else {
            bail!("ridge regression needs at least one row");
        };
        let (d, m) = (x0.len(), y0.len());
        let xs = DMatrix::from_row_iterator(x.len(), d, x.iter().flat_map(|r| r.iter().copied()));
        let ys = DMatrix::from_row_iterator(y.len(), m, y.iter().flat_map(|r| r.iter().copied()));
        let xtx = xs.transpose() * &xs;
        let xty = xs.transpose() * ys;
        let scale = xtx.diagonal().mean().max(f64::MIN_POSITIVE);
        Ok(Gram { xtx, xty, scale })
    }

    /// `(XᵀX + λsI)⁻¹ (XᵀY + λs·W₀ᵀ)`, `s` the mean diagonal of XᵀX, W₀ the prior's
    /// weights (zero without a prior).
    fn solve(&self, penalty: f64, prior: Option<&Ridge>) -> Result<Ridge> {
        let d = self.xtx.nrows();
        let shift = penalty * self.scale;
        let a = &self.xtx + DMatrix::identity(d, d) * shift;
        let mut b = self.xty.clone();
        if let Some(p) = prior {
            if p.weights.ncols() != d || p.weights.nrows() != b.ncols() {
                bail!(
                    "the prior model maps {} inputs to {} targets; the rows have {d} and {}",
                    p.weights.ncols(),
                    p.weights.nrows(),
                    b.ncols()
                );
            }
            b += p.weights.transpose() * shift;
        }
        let Some(cholesky) = a.cholesky() else {
            bail!("the ridge system is not positive definite (penalty {penalty})");
        };
        Ok(Ridge {
            weights: cholesky.solve(&b).transpose(),
        })
    }
}

impl Ridge {
    /// Fits rows `x` → `y` with the relative `penalty`, shrinking towards `prior` if given.
    pub fn fit(
        x: &[Vec<f64>],
        y: &[Vec<f64>],
        penalty: f64,
        prior: Option<&Ridge>,
    ) -> Result<Ridge> {
        let (x, y) = (borrow(x), borrow(y));
        Gram::new(&x, &y)?.solve(penalty, prior)
    }

    /// Fits with the penalty among [`PENALTIES`] whose `folds`-fold cross-validated mean GFC
    /// on the rows is best (folds: rows `i % folds`), then refits on every row.
    pub fn fit_cv<'a>(
        x: &'a [Vec<f64>],
        y: &'a [Vec<f64>],
        folds: usize,
        prior: Option<&Ridge>,
    ) -> Result<Ridge> {
        let n = x.len();
        let folds = folds.clamp(2, n.max(2));
        if n < 2 {
            return Ridge::fit(x, y, PENALTIES[PENALTIES.len() / 2], prior);
        }
        let mut totals = [0.0; PENALTIES.len()];
        for f in 0..folds {
            let (test, train): (Vec<usize>, Vec<usize>) = (0..n).partition(|i| i % folds == f);
            let pick = |rows: &'a [Vec<f64>]| -> Vec<&'a [f64]> {
                train.iter().map(|&i| rows[i].as_slice()).collect()
            };
            let gram = Gram::new(&pick(x), &pick(y))?;
            for (total, &penalty) in totals.iter_mut().zip(&PENALTIES) {
                let model = gram.solve(penalty, prior)?;
                *total += test
                    .iter()
                    .map(|&i| metrics::gfc(&y[i], &model.predict(&x[i])).unwrap_or(0.0))
                    .sum::<f64>();
            }
        }
        // The first (smallest) penalty of the best score.
        let best = (0..PENALTIES.len()).fold(0, |b, k| if totals[k] > totals[b] { k } else { b });
        Ridge::fit(x, y, PENALTIES[best], prior)
    }

    /// The prediction for one input row.
    pub fn predict(&self, x: &[f64]) -> Vec<f64> {
        self.weights
            .row_iter()
            .map(|w| w.iter().zip(x).map(|(a, b)| a * b).sum::<f64>().max(0.0))
            .collect()
    }
}

fn borrow(rows: &[Vec<f64>]) -> Vec<&[f64]> {
    rows.iter().map(Vec::as_slice).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y = (2·x₀ − x₁ + 3, x₀ + 1) (bias input 1), exactly: a tiny penalty recovers it.
    fn line() -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
        let x: Vec<Vec<f64>> = (0..20)
            .map(|i| vec![i as f64 * 0.1, (i * i % 7) as f64 * 0.2, 1.0])
            .collect();
        let y = x
            .iter()
            .map(|r| vec![2.0 * r[0] - r[1] + 3.0, r[0] + 1.0])
            .collect();
        (x, y)
    }

    #[test]
    fn recovers_a_linear_map_and_shrinks_towards_the_prior() {
        let (x, y) = line();
        let fit = Ridge::fit(&x, &y, 1e-9, None).unwrap();
        assert!((fit.predict(&[1.0, 0.5, 1.0])[0] - 4.5).abs() < 1e-5);
        // A huge penalty gives the prior back; towards zero it gives (almost) zero.
        let prior = Ridge {
            weights: DMatrix::from_row_slice(2, 3, &[1.0, 1.0, 1.0, 0.0, 0.0, 2.0]),
        };
        let held = Ridge::fit(&x, &y, 1e9, Some(&prior)).unwrap();
        assert!((held.predict(&[1.0, 2.0, 1.0])[0] - 4.0).abs() < 1e-6);
        assert!((held.predict(&[1.0, 2.0, 1.0])[1] - 2.0).abs() < 1e-6);
        let zero = Ridge::fit(&x, &y, 1e9, None).unwrap();
        assert!(zero.predict(&[1.0, 2.0, 1.0])[0] < 1e-6);
        assert!(Ridge::fit(&[], &[], 1.0, None).is_err());
        let wrong = Ridge {
            weights: DMatrix::from_row_slice(1, 2, &[1.0, 1.0]),
        };
        assert!(Ridge::fit(&x, &y, 1.0, Some(&wrong)).is_err());
    }

    #[test]
    fn cross_validation_prefers_a_small_penalty_for_clean_data() {
        let (x, y) = line();
        let fit = Ridge::fit_cv(&x, &y, 5, None).unwrap();
        assert!((fit.predict(&[1.0, 0.5, 1.0])[0] - 4.5).abs() < 1e-2);
    }
}

#[cfg(test)]
mod reference {
    use super::*;

    /// A small noisy problem: 12 rows of 2 inputs and a bias to 3 non-negative targets.
    fn problem() -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
        let x: Vec<Vec<f64>> = (0..12)
            .map(|i| {
                let t = i as f64;
                vec![0.3 + 0.1 * t, 1.0 + (0.7 * t).sin(), 1.0]
            })
            .collect();
        let y = x
            .iter()
            .enumerate()
            .map(|(i, r)| {
                let e = 0.05 * (1.3 * i as f64).cos();
                vec![
                    (r[0] + 0.5 * r[1] + e).max(0.0),
                    (0.2 + 0.3 * r[0] * r[1] - e).max(0.0),
                    (1.0 - 0.4 * r[0] + 0.1 * r[1] + 2.0 * e).max(0.0),
                ]
            })
            .collect();
        (x, y)
    }

    #[test]
    fn print_reference() {
        let (x, y) = problem();
        let prior = Ridge {
            weights: DMatrix::from_row_slice(3, 3, &[1.0, 0.4, 0.0, 0.0, 0.5, 0.1, -0.3, 0.0, 0.9]),
        };
        let newprior = spdcam_learn::ridge::Ridge::from_weights(&[
            vec![1.0, 0.4, 0.0],
            vec![0.0, 0.5, 0.1],
            vec![-0.3, 0.0, 0.9],
        ])
        .unwrap();
        use spdcam_learn::ridge::Ridge as New;
        let cases = [
            (
                "fit",
                Ridge::fit(&x, &y, 1e-3, None).unwrap(),
                New::fit(&x, &y, 1e-3, None).unwrap(),
            ),
            (
                "fit_prior",
                Ridge::fit(&x, &y, 0.1, Some(&prior)).unwrap(),
                New::fit(&x, &y, 0.1, Some(&newprior)).unwrap(),
            ),
            (
                "cv",
                Ridge::fit_cv(&x, &y, 4, None).unwrap(),
                New::fit_cv(&x, &y, 4, None).unwrap(),
            ),
            (
                "cv_prior",
                Ridge::fit_cv(&x, &y, 4, Some(&prior)).unwrap(),
                New::fit_cv(&x, &y, 4, Some(&newprior)).unwrap(),
            ),
        ];
        let mut worst = 0.0f64;
        for (name, old, new) in cases {
            let w: Vec<f64> = (0..3)
                .flat_map(|t| (0..3).map(move |j| (t, j)))
                .map(|(t, j)| old.weights[(t, j)])
                .collect();
            println!("{name}: {w:?}");
            for t in 0..3 {
                for j in 0..3 {
                    let (a, b) = (old.weights[(t, j)], new.weight(t, j));
                    worst = worst.max((a - b).abs() / a.abs().max(1e-300));
                }
            }
        }
        println!("worst relative difference {worst:e}");
        // The penalties CV picks: the scores of each.
        assert!(worst < 1e-9);
    }
}
