//! Least-squares fitting of a lamp model to a measured SPD: the shapes' heights enter
//! linearly and must not be negative (non-negative least squares, Lawson & Hanson 1974),
//! their positions and widths non-linearly (Levenberg–Marquardt, Marquardt 1963, within
//! bounds); the heights are solved for each trial of the positions (variable projection,
//! Golub & Pereyra 1973), so the search runs over the few non-linear parameters only.

use nalgebra::{DMatrix, DVector};

/// Non-negative least squares, min ‖A x − b‖ subject to x ≥ 0, by the active-set algorithm of
/// C. L. Lawson and R. J. Hanson, *Solving Least Squares Problems*, Prentice-Hall 1974,
/// ch. 23 (the NNLS algorithm).
pub fn nnls(a: &DMatrix<f64>, b: &DVector<f64>) -> DVector<f64> {
    let n = a.ncols();
    let mut x = DVector::zeros(n);
    let mut passive = vec![false; n];
    let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
    let tol = 1e-12 * scale * scale * (a.nrows().max(1) as f64) * b.amax().max(1e-300);
    for _ in 0..3 * n + 3 {
        let w = a.transpose() * (b - a * &x);
        let candidate = (0..n)
            .filter(|&j| !passive[j])
            .max_by(|&i, &j| w[i].total_cmp(&w[j]));
        let Some(t) = candidate.filter(|&t| w[t] > tol) else {
            break;
        };
        passive[t] = true;
        loop {
            let z = solve_on(a, b, &passive);
            if (0..n).all(|j| !passive[j] || z[j] > 0.0) {
                x = z;
                break;
            }
            let alpha = (0..n)
                .filter(|&j| passive[j] && z[j] <= 0.0)
                .map(|j| x[j] / (x[j] - z[j]))
                .fold(f64::INFINITY, f64::min);
            x += (z - &x) * alpha;
            for j in 0..n {
                if passive[j] && x[j] <= 1e-15 {
                    passive[j] = false;
                    x[j] = 0.0;
                }
            }
            if !passive.iter().any(|&p| p) {
                break;
            }
        }
    }
    x
}

/// Unconstrained least squares on the passive columns (others zero), by SVD so that nearly
/// collinear columns (two lines closer than the grid step) stay solvable.
fn solve_on(a: &DMatrix<f64>, b: &DVector<f64>, passive: &[bool]) -> DVector<f64> {
    let cols: Vec<usize> = (0..a.ncols()).filter(|&j| passive[j]).collect();
    let sub = a.select_columns(&cols);
    let solved = sub
        .svd(true, true)
        .solve(b, 1e-12)
        .unwrap_or_else(|_| DVector::zeros(cols.len()));
    let mut z = DVector::zeros(a.ncols());
    for (k, &j) in cols.iter().enumerate() {
        z[j] = solved[k];
    }
    z
}

/// The result of a bounded least-squares search.
#[derive(Debug, Clone, PartialEq)]
pub struct Minimum {
    /// The parameters at the minimum found (within their bounds).
    pub x: Vec<f64>,
    /// Sum of squared residuals at `x`.
    pub cost: f64,
}

/// Minimises ‖r(x)‖² within `lower ≤ x ≤ upper` from `start` by Levenberg–Marquardt
/// (D. W. Marquardt, "An algorithm for least-squares estimation of nonlinear parameters",
/// J. SIAM 11(2), 431–441, 1963: steps (JᵀJ + μ diag JᵀJ) δ = −Jᵀr, μ lowered after a step
/// that reduces the cost and raised otherwise), with forward-difference Jacobians and every
/// trial point clamped into the bounds.
pub fn levenberg_marquardt(
    residuals: &dyn Fn(&[f64]) -> Vec<f64>,
    start: &[f64],
    lower: &[f64],
    upper: &[f64],
    max_iterations: usize,
) -> Minimum {
    let clamp = |x: &mut [f64]| {
        for (k, v) in x.iter_mut().enumerate() {
            *v = v.clamp(lower[k], upper[k]);
        }
    };
    let cost_of = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>();
    let mut x = start.to_vec();
    clamp(&mut x);
    let mut r = residuals(&x);
    let mut cost = cost_of(&r);
    let d = x.len();
    let mut mu = 1e-3;
    for _ in 0..max_iterations {
        let m = r.len();
        let mut jac = DMatrix::zeros(m, d);
        for k in 0..d {
            let h = 1e-5 * (upper[k] - lower[k]).max(1e-9);
            let mut probe = x.clone();
            let step = if x[k] + h <= upper[k] { h } else { -h };
            probe[k] += step;
            let rp = residuals(&probe);
            for i in 0..m {
                jac[(i, k)] = (rp[i] - r[i]) / step;
            }
        }
        let jt = jac.transpose();
        let jtj = &jt * &jac;
        let g = &jt * DVector::from_column_slice(&r);
        let mut improved = false;
        while mu < 1e12 {
            let mut a = jtj.clone();
            for k in 0..d {
                a[(k, k)] += mu * jtj[(k, k)].max(1e-12);
            }
            let Some(delta) = a.cholesky().map(|c| c.solve(&(-&g))) else {
                mu *= 4.0;
                continue;
            };
            let mut trial: Vec<f64> = x.iter().zip(delta.iter()).map(|(a, b)| a + b).collect();
            clamp(&mut trial);
            let rt = residuals(&trial);
            let ct = cost_of(&rt);
            if ct < cost {
                let gain = (cost - ct) / cost.max(1e-300);
                x = trial;
                r = rt;
                cost = ct;
                mu = (mu / 3.0).max(1e-12);
                improved = gain > 1e-10;
                break;
            }
            mu *= 4.0;
        }
        if !improved {
            break;
        }
    }
    Minimum { x, cost }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nnls_matches_a_hand_solved_case() {
        // b = 2·a₀ + 3·a₁ exactly, a₂ would need a negative weight: x = (2, 3, 0).
        let a = DMatrix::from_row_slice(4, 3, &[1., 0., 1., 0., 1., -1., 1., 1., 0., 1., 2., 0.]);
        let b = DVector::from_row_slice(&[2., 3., 5., 8.]);
        let x = nnls(&a, &b);
        assert!(
            (x[0] - 2.0).abs() < 1e-10 && (x[1] - 3.0).abs() < 1e-10,
            "{x}"
        );
        assert!(x[2].abs() < 1e-10, "{x}");
        // The unconstrained optimum of min ‖x − (1, −1)‖ clips at zero.
        let id = DMatrix::identity(2, 2);
        let x = nnls(&id, &DVector::from_row_slice(&[1.0, -1.0]));
        assert_eq!((x[0], x[1]), (1.0, 0.0));
    }

    #[test]
    fn levenberg_marquardt_fits_a_gaussian_within_bounds() {
        let xs: Vec<f64> = (0..60).map(|k| 400.0 + 5.0 * k as f64).collect();
        let truth = |c: f64, w: f64| -> Vec<f64> {
            xs.iter()
                .map(|x| (-(x - c).powi(2) / (2.0 * w * w)).exp())
                .collect()
        };
        let data = truth(512.0, 23.0);
        let r = |p: &[f64]| -> Vec<f64> {
            truth(p[0], p[1])
                .iter()
                .zip(&data)
                .map(|(a, b)| a - b)
                .collect()
        };
        let m = levenberg_marquardt(&r, &[480.0, 10.0], &[400.0, 2.0], &[700.0, 80.0], 200);
        assert!((m.x[0] - 512.0).abs() < 1e-4, "{:?}", m.x);
        assert!((m.x[1] - 23.0).abs() < 1e-4, "{:?}", m.x);
        // With the width capped below the truth, the fit stops at the bound.
        let m = levenberg_marquardt(&r, &[480.0, 10.0], &[400.0, 2.0], &[700.0, 15.0], 200);
        assert!((m.x[1] - 15.0).abs() < 1e-12 && (m.x[0] - 512.0).abs() < 1.0);
    }
}
