//! Plane geometry: homographies fitted by normalised least squares (DLT), and checks on the
//! four corners a user gives.

use crate::error::{short_number, Error, Result};
use nalgebra::{DMatrix, Matrix3, Vector3};

/// A plane projective map `p' ~ H p`, stored row-major with `h[2][2] = 1` where possible.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Homography(pub Matrix3<f64>);

impl Homography {
    /// The map of `p`; non-finite when `p` lies on the horizon line.
    #[inline]
    pub fn apply(&self, p: [f64; 2]) -> [f64; 2] {
        let m = &self.0;
        let w = m[(2, 0)] * p[0] + m[(2, 1)] * p[1] + m[(2, 2)];
        [
            (m[(0, 0)] * p[0] + m[(0, 1)] * p[1] + m[(0, 2)]) / w,
            (m[(1, 0)] * p[0] + m[(1, 1)] * p[1] + m[(1, 2)]) / w,
        ]
    }

    /// The inverse map, if the matrix is invertible.
    pub fn inverse(&self) -> Option<Homography> {
        self.0.try_inverse().map(|m| Homography(normalise(m)))
    }

    /// The map followed by a uniform scale of the output by `s` (e.g. from a pyramid level
    /// to full resolution).
    pub fn scaled_output(&self, s: f64) -> Homography {
        let scale = Matrix3::new(s, 0.0, 0.0, 0.0, s, 0.0, 0.0, 0.0, 1.0);
        Homography(normalise(scale * self.0))
    }

    /// The map of row-major entries (the inverse of [`Homography::to_rows`]).
    pub fn from_rows(rows: &[[f64; 3]; 3]) -> Homography {
        Homography(Matrix3::from_fn(|r, c| rows[r][c]))
    }

    /// Row-major entries.
    pub fn to_rows(&self) -> [[f64; 3]; 3] {
        std::array::from_fn(|r| std::array::from_fn(|c| self.0[(r, c)]))
    }

    /// Least-squares fit (normalised DLT, Hartley & Zisserman alg. 4.2) of the map taking
    /// each `from[i]` to `to[i]`; at least four pairs, not all on one line.
    pub fn fit(from: &[[f64; 2]], to: &[[f64; 2]]) -> Result<Homography> {
        let n = from.len();
        if n < 4 || to.len() != n {
            return Err(Error::invalid(format!(
                "a homography needs at least four point pairs, got {n}"
            )));
        }
        let (tf, nf) = conditioner(from);
        let (tt, nt) = conditioner(to);
        if collinear(&nf) || collinear(&nt) {
            return Err(Error::invalid("homography fit: the points lie on one line"));
        }
        let mut a = DMatrix::<f64>::zeros(2 * n, 9);
        for i in 0..n {
            let [x, y] = nf[i];
            let [u, v] = nt[i];
            let r = 2 * i;
            a.row_mut(r)
                .copy_from_slice(&[-x, -y, -1.0, 0.0, 0.0, 0.0, u * x, u * y, u]);
            a.row_mut(r + 1)
                .copy_from_slice(&[0.0, 0.0, 0.0, -x, -y, -1.0, v * x, v * y, v]);
        }
        let ata = a.transpose() * &a;
        let eig = ata.symmetric_eigen();
        let (k, _) = eig
            .eigenvalues
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(b.1))
            .ok_or_else(|| Error::invalid("homography fit failed"))?;
        let h = eig.eigenvectors.column(k);
        let hn = Matrix3::from_row_slice(h.as_slice());
        let tt_inv = tt
            .try_inverse()
            .ok_or_else(|| Error::invalid("homography fit: degenerate target points"))?;
        let m = tt_inv * hn * tf;
        if !m.iter().all(|v| v.is_finite()) || m[(2, 2)].abs() < 1e-12 {
            return Err(Error::invalid(
                "homography fit: the points are degenerate (collinear or coincident)",
            ));
        }
        let hm = Homography(normalise(m));
        // Reject maps that fold the plane between the given points (a point pair on the
        // wrong side of the horizon line).
        let sign = |p: [f64; 2]| {
            let w = hm.0[(2, 0)] * p[0] + hm.0[(2, 1)] * p[1] + hm.0[(2, 2)];
            w > 0.0
        };
        let first = sign(from[0]);
        if from.iter().any(|&p| sign(p) != first) {
            return Err(Error::invalid(
                "homography fit: the points do not come from one view of a plane",
            ));
        }
        Ok(hm)
    }

    /// Root-mean-square distance between `H from[i]` and `to[i]`.
    pub fn rms_error(&self, from: &[[f64; 2]], to: &[[f64; 2]]) -> f64 {
        let s: f64 = from
            .iter()
            .zip(to)
            .map(|(&f, t)| {
                let p = self.apply(f);
                (p[0] - t[0]).powi(2) + (p[1] - t[1]).powi(2)
            })
            .sum();
        (s / from.len().max(1) as f64).sqrt()
    }
}

/// Scales a matrix so that `m[2][2] = 1` (or unit norm when that entry is ~0).
fn normalise(m: Matrix3<f64>) -> Matrix3<f64> {
    let d = m[(2, 2)];
    if d.abs() > 1e-12 {
        m / d
    } else {
        m / m.norm()
    }
}

/// Whether conditioned points (centred, mean distance √2) lie on one line: their scatter
/// matrix has a near-zero eigenvalue.
fn collinear(points: &[[f64; 2]]) -> bool {
    let n = points.len() as f64;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for p in points {
        sxx += p[0] * p[0] / n;
        sxy += p[0] * p[1] / n;
        syy += p[1] * p[1] / n;
    }
    let det = sxx * syy - sxy * sxy;
    det < 1e-8 * (sxx + syy).powi(2).max(1e-300)
}

/// Similarity moving the points' centroid to the origin and their mean distance to √2.
fn conditioner(points: &[[f64; 2]]) -> (Matrix3<f64>, Vec<[f64; 2]>) {
    let n = points.len() as f64;
    let cx = points.iter().map(|p| p[0]).sum::<f64>() / n;
    let cy = points.iter().map(|p| p[1]).sum::<f64>() / n;
    let mean_d = points
        .iter()
        .map(|p| ((p[0] - cx).powi(2) + (p[1] - cy).powi(2)).sqrt())
        .sum::<f64>()
        / n;
    let s = if mean_d > 0.0 {
        std::f64::consts::SQRT_2 / mean_d
    } else {
        1.0
    };
    let t = Matrix3::new(s, 0.0, -s * cx, 0.0, s, -s * cy, 0.0, 0.0, 1.0);
    let moved = points
        .iter()
        .map(|p| {
            let v = t * Vector3::new(p[0], p[1], 1.0);
            [v[0], v[1]]
        })
        .collect();
    (t, moved)
}

/// z-component of `(b − a) × (c − b)`.
fn turn(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0])
}

/// Puts four corners given in any order into clockwise order as seen on screen (y down),
/// starting from the one nearest the image's top-left; checks that they lie inside a
/// `width × height` image and form a convex quadrilateral of non-trivial size.
pub fn sort_corners(corners: &[[f64; 2]], width: usize, height: usize) -> Result<[[f64; 2]; 4]> {
    if corners.len() != 4 {
        return Err(Error::invalid(format!(
            "--corners needs four points (eight numbers x1,y1,…,x4,y4), got {}",
            corners.len()
        )));
    }
    for (i, p) in corners.iter().enumerate() {
        if !(p[0].is_finite()
            && p[1].is_finite()
            && (0.0..=width as f64).contains(&p[0])
            && (0.0..=height as f64).contains(&p[1]))
        {
            return Err(Error::invalid(format!(
                "corner {} ({}, {}) lies outside the {width}×{height} image",
                i + 1,
                short_number(p[0]),
                short_number(p[1])
            )));
        }
    }
    let cx = corners.iter().map(|p| p[0]).sum::<f64>() / 4.0;
    let cy = corners.iter().map(|p| p[1]).sum::<f64>() / 4.0;
    let mut sorted: Vec<[f64; 2]> = corners.to_vec();
    // Clockwise on screen with y down = increasing atan2(y, x).
    sorted.sort_by(|a, b| {
        (a[1] - cy)
            .atan2(a[0] - cx)
            .total_cmp(&(b[1] - cy).atan2(b[0] - cx))
    });
    let start = (0..4)
        .min_by(|&i, &j| (sorted[i][0] + sorted[i][1]).total_cmp(&(sorted[j][0] + sorted[j][1])))
        .unwrap_or(0);
    let out: [[f64; 2]; 4] = std::array::from_fn(|k| sorted[(start + k) % 4]);
    let turns: Vec<f64> = (0..4)
        .map(|k| turn(out[k], out[(k + 1) % 4], out[(k + 2) % 4]))
        .collect();
    let area = 0.5
        * (0..4)
            .map(|k| out[k][0] * out[(k + 1) % 4][1] - out[(k + 1) % 4][0] * out[k][1])
            .sum::<f64>()
            .abs();
    let min_side = (0..4)
        .map(|k| (out[k][0] - out[(k + 1) % 4][0]).hypot(out[k][1] - out[(k + 1) % 4][1]))
        .fold(f64::INFINITY, f64::min);
    if turns.iter().any(|&t| t <= 1e-9 * (area + 1.0)) || min_side < 4.0 {
        return Err(Error::invalid(format!(
            "corners {} do not form a convex quadrilateral with sides of at least 4 px",
            corners
                .iter()
                .map(|p| format!("({}, {})", short_number(p[0]), short_number(p[1])))
                .collect::<Vec<_>>()
                .join(" ")
        )));
    }
    Ok(out)
}

/// Whether two convex quadrilaterals come nearer than `gap` (photo pixels; 0: whether they
/// overlap): they are apart when the projections on the normal of some side of one of them
/// lie more than `gap` apart (the separating axis theorem, Gottschalk, Lin & Manocha 1996,
/// "OBBTree", SIGGRAPH '96).
pub fn quads_near(a: &[[f64; 2]; 4], b: &[[f64; 2]; 4], gap: f64) -> bool {
    let separated_by = |poly: &[[f64; 2]; 4], other: &[[f64; 2]; 4]| {
        (0..4).any(|k| {
            let (p, q) = (poly[k], poly[(k + 1) % 4]);
            let normal = [q[1] - p[1], p[0] - q[0]];
            let norm = normal[0].hypot(normal[1]).max(1e-12);
            let range = |points: &[[f64; 2]; 4]| {
                points
                    .iter()
                    .map(|v| (v[0] * normal[0] + v[1] * normal[1]) / norm)
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                        (lo.min(x), hi.max(x))
                    })
            };
            let (own_lo, own_hi) = range(poly);
            let (lo, hi) = range(other);
            lo > own_hi + gap || hi < own_lo - gap
        })
    };
    !(separated_by(a, b) || separated_by(b, a))
}

/// The centre of a quadrilateral: the mean of its corners.
pub fn quad_centre(corners: &[[f64; 2]; 4]) -> [f64; 2] {
    let n = corners.len() as f64;
    [
        corners.iter().map(|p| p[0]).sum::<f64>() / n,
        corners.iter().map(|p| p[1]).sum::<f64>() / n,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_recovers_a_known_homography() {
        let h = Homography(Matrix3::new(
            2.0, 0.3, 10.0, -0.2, 1.5, 20.0, 0.001, 0.002, 1.0,
        ));
        let from: Vec<[f64; 2]> = (0..20)
            .map(|i| [(i % 5) as f64 * 10.0, (i / 5) as f64 * 7.0])
            .collect();
        let to: Vec<[f64; 2]> = from.iter().map(|&p| h.apply(p)).collect();
        let fit = Homography::fit(&from, &to).unwrap();
        for (a, b) in fit.0.iter().zip(h.0.iter()) {
            assert!((a - b).abs() < 1e-8 * (1.0 + b.abs()), "{a} vs {b}");
        }
        assert!(fit.rms_error(&from, &to) < 1e-8);
        let inv = fit.inverse().unwrap();
        let p = inv.apply(h.apply([3.0, 4.0]));
        assert!((p[0] - 3.0).abs() < 1e-9 && (p[1] - 4.0).abs() < 1e-9);
    }

    #[test]
    fn collinear_points_are_rejected() {
        let from = [[0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [3.0, 3.0]];
        assert!(Homography::fit(&from, &from).is_err());
    }

    #[test]
    fn corners_are_sorted_clockwise_from_top_left() {
        let c = sort_corners(
            &[[90.0, 80.0], [10.0, 12.0], [12.0, 70.0], [95.0, 10.0]],
            100,
            100,
        )
        .unwrap();
        assert_eq!(c, [[10.0, 12.0], [95.0, 10.0], [90.0, 80.0], [12.0, 70.0]]);
    }

    #[test]
    fn bad_corners_are_rejected() {
        let outside = sort_corners(
            &[[0.0, 0.0], [200.0, 0.0], [10.0, 10.0], [0.0, 10.0]],
            100,
            100,
        );
        assert!(outside.unwrap_err().to_string().contains("outside"));
        // A dart: one corner inside the triangle of the other three.
        let dart = sort_corners(
            &[[0.0, 0.0], [90.0, 0.0], [20.0, 30.0], [0.0, 90.0]],
            100,
            100,
        );
        assert!(dart.unwrap_err().to_string().contains("convex"));
        let three = sort_corners(&[[0.0, 0.0], [90.0, 0.0], [30.0, 30.0]], 100, 100);
        assert!(three.is_err());
    }

    #[test]
    fn quadrilaterals_apart_touching_and_overlapping() {
        let square = |x: f64, y: f64, side: f64| {
            [[x, y], [x + side, y], [x + side, y + side], [x, y + side]]
        };
        let a = square(0.0, 0.0, 10.0);
        // 5 px apart: near within a gap of 6, apart within 4.
        let b = square(15.0, 0.0, 10.0);
        assert!(quads_near(&a, &b, 6.0));
        assert!(!quads_near(&a, &b, 4.0));
        assert!(quads_near(&a, &square(5.0, 5.0, 10.0), 0.0));
        // One inside the other.
        assert!(quads_near(&a, &square(2.0, 2.0, 3.0), 0.0));
        // A diamond whose side faces the square's corner 3/√2 px away: apart though their
        // bounding boxes overlap.
        let diamond = [[9.0, 14.0], [14.0, 9.0], [19.0, 14.0], [14.0, 19.0]];
        assert!(!quads_near(&a, &diamond, 0.0));
        assert!(quads_near(&a, &diamond, 2.5));
        assert_eq!(quad_centre(&a), [5.0, 5.0]);
    }
}
