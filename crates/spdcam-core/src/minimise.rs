//! Derivative-free minimisation for the few small fits that have no gradient at hand: the
//! in-camera stage's calibration and the refinement of a chart's corners on the photo.

/// Nelder–Mead simplex minimisation (Nelder & Mead 1965, "A simplex method for function
/// minimization", Comput. J. 7:308) from `x0` with initial steps `step` (relative to each
/// coordinate's size, at least `step` absolute); standard coefficients. Returns the best
/// point and value.
pub(crate) fn nelder_mead<const N: usize>(
    f: &mut dyn FnMut(&[f64; N]) -> f64,
    x0: [f64; N],
    step: f64,
    max_evaluations: usize,
) -> ([f64; N], f64) {
    let mut simplex: Vec<([f64; N], f64)> = Vec::with_capacity(N + 1);
    simplex.push((x0, f(&x0)));
    for k in 0..N {
        let mut x = x0;
        x[k] += step * x[k].abs().max(1.0);
        simplex.push((x, f(&x)));
    }
    let mut used = N + 1;
    let combine = |a: &[f64; N], b: &[f64; N], t: f64| -> [f64; N] {
        std::array::from_fn(|k| a[k] + t * (b[k] - a[k]))
    };
    while used < max_evaluations {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        let spread = simplex[N].1 - simplex[0].1;
        if spread.abs() < 1e-9 * simplex[0].1.abs().max(1e-12) {
            break;
        }
        let centroid: [f64; N] =
            std::array::from_fn(|k| simplex[..N].iter().map(|p| p.0[k]).sum::<f64>() / N as f64);
        let worst = simplex[N];
        let reflected = combine(&centroid, &worst.0, -1.0);
        let fr = f(&reflected);
        used += 1;
        if fr < simplex[0].1 {
            let expanded = combine(&centroid, &worst.0, -2.0);
            let fe = f(&expanded);
            used += 1;
            simplex[N] = if fe < fr {
                (expanded, fe)
            } else {
                (reflected, fr)
            };
        } else if fr < simplex[N - 1].1 {
            simplex[N] = (reflected, fr);
        } else {
            let contracted = if fr < worst.1 {
                combine(&centroid, &reflected, 0.5)
            } else {
                combine(&centroid, &worst.0, 0.5)
            };
            let fc = f(&contracted);
            used += 1;
            if fc < worst.1.min(fr) {
                simplex[N] = (contracted, fc);
            } else {
                let best = simplex[0].0;
                for p in simplex.iter_mut().skip(1) {
                    p.0 = combine(&best, &p.0, 0.5);
                    p.1 = f(&p.0);
                    used += 1;
                }
            }
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    simplex[0]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nelder_mead_finds_a_quadratic_minimum() {
        let mut f = |x: &[f64; 2]| (x[0] - 1.0).powi(2) + 3.0 * (x[1] + 2.0).powi(2);
        let (x, v) = nelder_mead(&mut f, [0.0, 0.0], 0.5, 2000);
        assert!(
            (x[0] - 1.0).abs() < 1e-3 && (x[1] + 2.0).abs() < 1e-3,
            "{x:?}"
        );
        assert!(v < 1e-6);
    }
}
