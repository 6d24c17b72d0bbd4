//! Closed-form ridge regression (Tikhonov regularisation; Hoerl & Kennard, "Ridge
//! regression: biased estimation for nonorthogonal problems", Technometrics 12, 1970) from
//! rows of inputs to rows of targets: the weights `B` minimise
//! `‖Y − XB‖² + Σⱼ λⱼ ‖Bⱼ − B₀ⱼ‖²`, i.e. `B = (XᵀX + Λ)⁻¹ (XᵀY + Λ B₀)`, solved by a Cholesky
//! factorisation. `Λ` is a diagonal of per-input penalties and `B₀` an optional prior model
//! (zero without one): a large penalty gives the prior back, so a model trained on virtual
//! data can be corrected by a few real photos.
//!
//! [`Gram`] holds `XᵀX` and `XᵀY` once for many penalties: the `linear` model
//! (`spdcam_learn::train`) penalises the feature weights by λ·n and leaves the bias (almost) free;
//! [`Ridge::fit`] and [`Ridge::fit_cv`] (the sim-to-real experiment) use one penalty relative
//! to the mean diagonal of `XᵀX` on every input, chosen by k-fold cross-validation in
//! [`Ridge::fit_cv`].

use crate::error::{InferError, Result};
use faer::{linalg::solvers::Solve, Mat, Side};
use spdcam_core::spectral_error;

/// Relative penalties (times the mean diagonal of `XᵀX`) that [`Ridge::fit_cv`] chooses
/// among.
pub const PENALTIES: [f64; 8] = [1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1, 1.0, 10.0];

/// A fitted linear map from an input row to a target row (no intercept of its own: add a
/// constant 1 input for one).
#[derive(Debug, Clone)]
pub struct Ridge {
    /// targets × inputs.
    weights: Mat<f64>,
}

/// `XᵀX` and `XᵀY` of a set of rows, computed once and solved for any penalties.
#[derive(Debug, Clone)]
pub struct Gram {
    xtx: Mat<f64>,
    xty: Mat<f64>,
    rows: usize,
}

impl Gram {
    /// The Gram matrices of `rows` rows of `inputs` inputs (`x(row, input)`) and `targets`
    /// targets (`y(row, target)`); an error without rows, inputs or targets.
    pub fn from_fn(
        rows: usize,
        inputs: usize,
        targets: usize,
        x: impl Fn(usize, usize) -> f64,
        y: impl Fn(usize, usize) -> f64,
    ) -> Result<Gram> {
        if rows == 0 || inputs == 0 || targets == 0 {
            return Err(InferError::invalid(format!(
                "ridge regression needs rows, inputs and targets ({rows} rows of {inputs} \
                 inputs and {targets} targets)"
            )));
        }
        let x = Mat::<f64>::from_fn(rows, inputs, x);
        let y = Mat::<f64>::from_fn(rows, targets, y);
        Ok(Gram {
            xtx: x.transpose() * &x,
            xty: x.transpose() * &y,
            rows,
        })
    }

    /// The Gram matrices of input rows `x` and target rows `y` (as many, each of one length).
    pub fn from_rows(x: &[&[f64]], y: &[&[f64]]) -> Result<Gram> {
        let (Some(x0), Some(y0)) = (x.first(), y.first()) else {
            return Err(InferError::invalid(
                "ridge regression needs at least one row",
            ));
        };
        let (d, m) = (x0.len(), y0.len());
        if x.len() != y.len() || x.iter().any(|r| r.len() != d) || y.iter().any(|r| r.len() != m) {
            return Err(InferError::invalid(format!(
                "ridge regression needs as many input rows as target rows, each of one length \
                 ({} input rows, {} target rows)",
                x.len(),
                y.len()
            )));
        }
        Gram::from_fn(x.len(), d, m, |i, j| x[i][j], |i, j| y[i][j])
    }

    /// The number of rows.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// The mean diagonal of `XᵀX` (the mean squared input), at least the smallest positive
    /// number: the scale of [`Gram::solve_relative`]'s penalty.
    pub fn mean_diagonal(&self) -> f64 {
        let d = self.xtx.nrows();
        let sum: f64 = (0..d).map(|j| self.xtx[(j, j)]).sum();
        (sum / d as f64).max(f64::MIN_POSITIVE)
    }

    /// `(XᵀX + Λ)⁻¹ (XᵀY + Λ B₀)` with `Λ` = `diagonal` (one penalty per input, ≥ 0) and
    /// `B₀` the `prior`'s weights (zero without a prior).
    pub fn solve(&self, diagonal: &[f64], prior: Option<&Ridge>) -> Result<Ridge> {
        let d = self.xtx.nrows();
        if diagonal.len() != d {
            return Err(InferError::invalid(format!(
                "{} ridge penalties for {d} inputs",
                diagonal.len()
            )));
        }
        if let Some(bad) = diagonal.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
            return Err(InferError::invalid(format!(
                "ridge penalty {} is not a finite number ≥ 0 (too large a penalty overflows); \
                 use a smaller one",
                spdcam_core::error::short_number(*bad)
            )));
        }
        let mut a = self.xtx.clone();
        for (j, &shift) in diagonal.iter().enumerate() {
            a[(j, j)] += shift;
        }
        let mut b = self.xty.clone();
        if let Some(p) = prior {
            if p.inputs() != d || p.targets() != b.ncols() {
                return Err(InferError::invalid(format!(
                    "the prior model maps {} inputs to {} targets; the rows have {d} and {}",
                    p.inputs(),
                    p.targets(),
                    b.ncols()
                )));
            }
            for (j, &shift) in diagonal.iter().enumerate() {
                for t in 0..b.ncols() {
                    b[(j, t)] += p.weights[(t, j)] * shift;
                }
            }
        }
        let solved = a
            .llt(Side::Lower)
            .map_err(|e| {
                InferError::Numerical(format!(
                    "ridge regression: XᵀX + Λ is not positive definite ({e:?}): the inputs are \
                     not finite, too large, or linearly dependent without a penalty; scale the \
                     inputs or give a positive penalty"
                ))
            })?
            .solve(&b);
        Ok(Ridge {
            weights: solved.transpose().to_owned(),
        })
    }

    /// [`Gram::solve`] with the same penalty, `penalty` × [`Gram::mean_diagonal`], on every
    /// input.
    pub fn solve_relative(&self, penalty: f64, prior: Option<&Ridge>) -> Result<Ridge> {
        let shift = penalty * self.mean_diagonal();
        self.solve(&vec![shift; self.xtx.nrows()], prior)
    }
}

impl Ridge {
    /// A map with the given weights, one row per target of one weight per input.
    pub fn from_weights(weights: &[Vec<f64>]) -> Result<Ridge> {
        let d = weights.first().map_or(0, Vec::len);
        if d == 0 || weights.iter().any(|w| w.len() != d) {
            return Err(InferError::invalid(
                "a linear map needs at least one target row, all of one non-zero length",
            ));
        }
        Ok(Ridge {
            weights: Mat::from_fn(weights.len(), d, |t, j| weights[t][j]),
        })
    }

    /// Fits rows `x` → `y` with the relative `penalty` (see [`Gram::solve_relative`]),
    /// shrinking towards `prior` if given.
    pub fn fit(
        x: &[Vec<f64>],
        y: &[Vec<f64>],
        penalty: f64,
        prior: Option<&Ridge>,
    ) -> Result<Ridge> {
        Gram::from_rows(&borrow(x), &borrow(y))?.solve_relative(penalty, prior)
    }

    /// Fits with the penalty among [`PENALTIES`] whose `folds`-fold cross-validated mean GFC
    /// (goodness-of-fit coefficient, [`spectral_error::gfc`]) of [`Ridge::predict_non_negative`] on
    /// the rows is best, then refits on every row. Fold `f` holds rows `i % folds == f`; ties
    /// go to the smaller penalty. For non-negative targets such as spectra.
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
            let gram = Gram::from_rows(&pick(x), &pick(y))?;
            for (total, &penalty) in totals.iter_mut().zip(&PENALTIES) {
                let model = gram.solve_relative(penalty, prior)?;
                *total += test
                    .iter()
                    .map(|&i| {
                        spectral_error::gfc(&y[i], &model.predict_non_negative(&x[i]))
                            .unwrap_or(0.0)
                    })
                    .sum::<f64>();
            }
        }
        let best = (0..PENALTIES.len()).fold(0, |b, k| if totals[k] > totals[b] { k } else { b });
        Ridge::fit(x, y, PENALTIES[best], prior)
    }

    /// The number of inputs.
    pub fn inputs(&self) -> usize {
        self.weights.ncols()
    }

    /// The number of targets.
    pub fn targets(&self) -> usize {
        self.weights.nrows()
    }

    /// The weight of `input` in `target`.
    pub fn weight(&self, target: usize, input: usize) -> f64 {
        self.weights[(target, input)]
    }

    /// The prediction `Bᵀx` for one input row.
    pub fn predict(&self, x: &[f64]) -> Vec<f64> {
        (0..self.targets())
            .map(|t| {
                (0..self.inputs())
                    .zip(x)
                    .map(|(j, v)| self.weights[(t, j)] * v)
                    .sum()
            })
            .collect()
    }

    /// [`Ridge::predict`] clipped at zero, for targets that cannot be negative (spectra).
    pub fn predict_non_negative(&self, x: &[f64]) -> Vec<f64> {
        self.predict(x)
            .into_iter()
            .map(|v: f64| v.max(0.0))
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
        let prior = Ridge::from_weights(&[vec![1.0, 1.0, 1.0], vec![0.0, 0.0, 2.0]]).unwrap();
        let held = Ridge::fit(&x, &y, 1e9, Some(&prior)).unwrap();
        assert!((held.predict(&[1.0, 2.0, 1.0])[0] - 4.0).abs() < 1e-6);
        assert!((held.predict(&[1.0, 2.0, 1.0])[1] - 2.0).abs() < 1e-6);
        let zero = Ridge::fit(&x, &y, 1e9, None).unwrap();
        assert!(zero.predict(&[1.0, 2.0, 1.0])[0] < 1e-6);
        assert!(Ridge::fit(&[], &[], 1.0, None).is_err());
        let wrong = Ridge::from_weights(&[vec![1.0, 1.0]]).unwrap();
        assert!(Ridge::fit(&x, &y, 1.0, Some(&wrong)).is_err());
        assert!(Ridge::fit(&x, &y[1..], 1.0, None).is_err());
    }

    #[test]
    fn cross_validation_prefers_a_small_penalty_for_clean_data() {
        let (x, y) = line();
        let fit = Ridge::fit_cv(&x, &y, 5, None).unwrap();
        assert!((fit.predict(&[1.0, 0.5, 1.0])[0] - 4.5).abs() < 1e-2);
    }

    /// 12 noisy rows of 2 inputs and a bias to 3 non-negative targets.
    fn noisy() -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
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

    /// The weights (targets × inputs, row-major) the earlier nalgebra implementation of the
    /// sim-to-real experiment gave on [`noisy`]: fixed penalties with and without a prior,
    /// and 4-fold cross-validation with and without it.
    #[test]
    fn matches_the_earlier_implementation() {
        let (x, y) = noisy();
        let prior = Ridge::from_weights(&[
            vec![1.0, 0.4, 0.0],
            vec![0.0, 0.5, 0.1],
            vec![-0.3, 0.0, 0.9],
        ])
        .unwrap();
        let cases: [(Ridge, [f64; 9]); 4] = [
            (
                Ridge::fit(&x, &y, 1e-3, None).unwrap(),
                [
                    0.9882761293926465,
                    0.4984497344577603,
                    0.016159597864615762,
                    0.4450942565464521,
                    0.2805999157457793,
                    -0.22131810496360307,
                    -0.38931640192555106,
                    0.10428647870659476,
                    0.9937459847722709,
                ],
            ),
            (
                Ridge::fit(&x, &y, 0.1, Some(&prior)).unwrap(),
                [
                    1.004299999929651,
                    0.48418978524464246,
                    0.01676694205827816,
                    0.18405246196811983,
                    0.2893892701612391,
                    0.0020797494981027943,
                    -0.33081225595820757,
                    0.09558398247041332,
                    0.9491966367090119,
                ],
            ),
            (
                Ridge::fit_cv(&x, &y, 4, None).unwrap(),
                [
                    0.9975808338986046,
                    0.500181480430187,
                    0.006298877322412227,
                    0.4512782805045743,
                    0.28223934666148853,
                    -0.22867861446397938,
                    -0.401360160013817,
                    0.10111782289457331,
                    1.0086625960261568,
                ],
            ),
            (
                Ridge::fit_cv(&x, &y, 4, Some(&prior)).unwrap(),
                [
                    0.9986316567277683,
                    0.5001395682927601,
                    0.005447570714820821,
                    0.44449257454615043,
                    0.2815384062528339,
                    -0.22175368410781812,
                    -0.40072975503699826,
                    0.1009511548968377,
                    1.0083074375240224,
                ],
            ),
        ];
        for (k, (model, expected)) in cases.iter().enumerate() {
            for (i, want) in expected.iter().enumerate() {
                let got = model.weight(i / 3, i % 3);
                assert!(
                    (got - want).abs() <= 1e-9 * want.abs(),
                    "case {k}, weight {i}: {got} against {want}"
                );
            }
        }
    }

    /// One input, one target, by hand: rows x = (1, 2), y = (2, 4) give XᵀX = 5, XᵀY = 10;
    /// with λ = 5 the weight is 10 / (5 + 5) = 1, towards a prior of 3 it is
    /// (10 + 5·3) / (5 + 5) = 2.5.
    #[test]
    fn a_hand_computed_one_dimensional_case() {
        let gram = Gram::from_rows(&[&[1.0], &[2.0]], &[&[2.0], &[4.0]]).unwrap();
        assert_eq!(gram.rows(), 2);
        assert_eq!(gram.mean_diagonal(), 5.0);
        let w = gram.solve(&[5.0], None).unwrap();
        assert!((w.weight(0, 0) - 1.0).abs() < 1e-15);
        let prior = Ridge::from_weights(&[vec![3.0]]).unwrap();
        assert!((gram.solve_relative(1.0, Some(&prior)).unwrap().weight(0, 0) - 2.5).abs() < 1e-15);
        assert_eq!(w.predict_non_negative(&[-1.0]), vec![0.0]);
        assert!(gram.solve(&[1.0, 1.0], None).is_err());
    }
}
