//! Grouping patch candidates into a lattice: integer grid positions for blobs that sit on
//! one projected grid of similar squares.
//!
//! From a seed blob and two of its neighbours (an approximately orthogonal pair), the grid
//! grows: every blob whose position, mapped back through the current grid-to-image map,
//! lies close to an integer grid point next to those already taken joins, and the map is
//! refitted (affine while few points are known, then a homography by least squares). A
//! blob far from every grid point never enters, so outliers do not bend the fit.

use super::geometry::Homography;
use super::segment::{principal_variances, Blob};
use nalgebra::Matrix3;

/// Blobs on one grid.
#[derive(Debug, Clone)]
pub struct Lattice {
    /// (blob index, integer grid position), grid positions shifted to start at (0, 0).
    pub members: Vec<(usize, [i32; 2])>,
    /// Grid position → level coordinates. The grid's first axis points along the image's
    /// x axis as seen from the second, as (x, y) do on screen: the grid is never mirrored.
    pub map: Homography,
}

/// Largest distance (in grid units) from a blob to its grid point.
const SNAP: f64 = 0.22;
/// How many grid steps (in each direction) a blob may lie from the lattice's members and
/// still join it: 2 bridges one missing patch, which small, blurred charts have between
/// every few found ones.
const REACH: i32 = 2;
/// Most seeds tried.
const MAX_SEEDS: usize = 40;

/// Pixels the lens's blur and the segmentation's edge threshold take off each side of a
/// patch: a small chart's patches segment as blobs well under their pitch (a third to a
/// half of it at 7 px a patch), so sizes are compared with the pitch as if restored.
const EROSION_PX: f64 = 1.0;

/// `blob` grown by [`EROSION_PX`] on each side along its own axes (the eigenvectors of its
/// second moments: a rectangle of sides l has variances l²/12 along them).
fn restored(blob: &Blob) -> Blob {
    let [a, b, c] = blob.moments;
    let (large, small) = principal_variances(blob.moments);
    let small = small.max(1e-9);
    let grow = |variance: f64| ((12.0 * variance).sqrt() + 2.0 * EROSION_PX).powi(2) / 12.0;
    let (g_large, g_small) = (grow(large), grow(small));
    // Σ = small·I + (large − small)·e eᵀ with e the major axis; the same with grown values.
    let scale = if large - small > 1e-12 {
        (g_large - g_small) / (large - small)
    } else {
        0.0
    };
    let moments = [
        g_small + scale * (a - small),
        scale * b,
        g_small + scale * (c - small),
    ];
    Blob {
        area: blob.area * (g_large * g_small / (large * small)).sqrt(),
        moments,
        ..blob.clone()
    }
}

/// Lattices of at least `min_members` blobs, largest first.
pub fn find_lattices(blobs: &[Blob], min_members: usize) -> Vec<Lattice> {
    let restored: Vec<Blob> = blobs.iter().map(restored).collect();
    let blobs = &restored[..];
    let neighbours = neighbour_lists(blobs);
    let mut order: Vec<usize> = (0..blobs.len())
        .filter(|&i| neighbours[i].len() >= 2)
        .collect();
    order.sort_by_key(|&i| std::cmp::Reverse(neighbours[i].len()));
    let mut taken = vec![false; blobs.len()];
    let mut out: Vec<Lattice> = Vec::new();
    for &seed in order.iter() {
        if out.len() >= MAX_SEEDS {
            break;
        }
        if taken[seed] {
            continue;
        }
        let Some(lattice) = grow(blobs, &neighbours[seed], seed) else {
            continue;
        };
        if lattice.members.len() >= min_members {
            for &(b, _) in &lattice.members {
                taken[b] = true;
            }
            out.push(lattice);
        }
    }
    out.sort_by_key(|l| std::cmp::Reverse(l.members.len()));
    out
}

/// Grid neighbours measured in a blob's own metric ([`Blob::metric_length`]): a square
/// patch's side measures √12 ≈ 3.46, so its neighbours one pitch away (patch over pitch
/// 0.86) measure about 4.0, or more when edges trim the blob; diagonal ones 5.7.
const NEIGHBOUR_METRIC: (f64, f64) = (2.8, 6.4);

/// For each blob, the blobs of similar size at about one patch pitch, measured in the
/// blob's own metric so that foreshortened patches find their neighbours as square ones do.
fn neighbour_lists(blobs: &[Blob]) -> Vec<Vec<usize>> {
    let mut idx: Vec<usize> = (0..blobs.len()).collect();
    idx.sort_by(|&a, &b| blobs[a].centre[0].total_cmp(&blobs[b].centre[0]));
    let xs: Vec<f64> = idx.iter().map(|&i| blobs[i].centre[0]).collect();
    let mut out = vec![Vec::new(); blobs.len()];
    for &i in &idx {
        let bi = &blobs[i];
        let (largest, _) = principal_variances(bi.moments);
        let reach = NEIGHBOUR_METRIC.1 * largest.max(0.0).sqrt();
        let lo = xs.partition_point(|&x| x < bi.centre[0] - reach);
        for &j in &idx[lo..] {
            let bj = &blobs[j];
            if bj.centre[0] > bi.centre[0] + reach {
                break;
            }
            if j == i {
                continue;
            }
            let d = bi.metric_length([bj.centre[0] - bi.centre[0], bj.centre[1] - bi.centre[1]]);
            let ratio = bj.area / bi.area;
            if (NEIGHBOUR_METRIC.0..=NEIGHBOUR_METRIC.1).contains(&d)
                && (0.4..=2.5).contains(&ratio)
            {
                out[i].push(j);
            }
        }
    }
    out
}

/// An affine grid map from a seed and its neighbours, or `None` without an orthogonal pair.
/// Lengths and angles are those of the seed's own metric, in which a foreshortened grid is
/// square again.
fn seed_map(blobs: &[Blob], neighbours: &[usize], seed: usize) -> Option<Homography> {
    let b = &blobs[seed];
    let c = b.centre;
    let mut vecs: Vec<[f64; 2]> = neighbours
        .iter()
        .map(|&j| [blobs[j].centre[0] - c[0], blobs[j].centre[1] - c[1]])
        .collect();
    vecs.sort_by(|p, q| b.metric_length(*p).total_cmp(&b.metric_length(*q)));
    let u = *vecs.first()?;
    let lu = b.metric_length(u);
    let v = vecs.iter().skip(1).find(|v| {
        let lv = b.metric_length(**v);
        let cos = b.metric_dot(u, **v) / (lu * lv);
        cos.abs() < 0.45 && (lv / lu) < 1.6
    })?;
    // Keep the grid unmirrored: (u, v) turn like the screen's (x, y).
    let v = if u[0] * v[1] - u[1] * v[0] > 0.0 {
        *v
    } else {
        [-v[0], -v[1]]
    };
    Some(Homography(Matrix3::new(
        u[0], v[0], c[0], u[1], v[1], c[1], 0.0, 0.0, 1.0,
    )))
}

/// Grows a lattice from `seed`.
fn grow(blobs: &[Blob], neighbours: &[usize], seed: usize) -> Option<Lattice> {
    let mut map = seed_map(blobs, neighbours, seed)?;
    let seed_area = blobs[seed].area;
    let candidates: Vec<usize> = (0..blobs.len())
        .filter(|&j| (0.25..=4.0).contains(&(blobs[j].area / seed_area)))
        .collect();
    let mut members: Vec<(usize, [i32; 2])> = vec![(seed, [0, 0])];
    for _ in 0..40 {
        let inverse = map.inverse()?;
        let mut claims: std::collections::HashMap<[i32; 2], (f64, usize)> =
            std::collections::HashMap::new();
        let known: std::collections::HashSet<[i32; 2]> = members.iter().map(|m| m.1).collect();
        for &j in &candidates {
            let q = inverse.apply(blobs[j].centre);
            if !q[0].is_finite() || !q[1].is_finite() {
                continue;
            }
            let n = [q[0].round() as i32, q[1].round() as i32];
            let r = (q[0] - n[0] as f64).hypot(q[1] - n[1] as f64);
            if r > SNAP {
                continue;
            }
            let near = (-REACH..=REACH)
                .any(|di| (-REACH..=REACH).any(|dj| known.contains(&[n[0] + di, n[1] + dj])));
            if !near {
                continue;
            }
            // The blob's size must agree with the local grid pitch.
            let p0 = map.apply([n[0] as f64, n[1] as f64]);
            let px = map.apply([n[0] as f64 + 1.0, n[1] as f64]);
            let py = map.apply([n[0] as f64, n[1] as f64 + 1.0]);
            let cell =
                ((px[0] - p0[0]) * (py[1] - p0[1]) - (px[1] - p0[1]) * (py[0] - p0[0])).abs();
            let fill = blobs[j].area / cell.max(1e-9);
            if !(0.3..=1.05).contains(&fill) {
                continue;
            }
            let e = claims.entry(n).or_insert((r, j));
            if r < e.0 {
                *e = (r, j);
            }
        }
        let mut next: Vec<(usize, [i32; 2])> =
            claims.into_iter().map(|(n, (_, j))| (j, n)).collect();
        next.sort_by_key(|m| (m.1[1], m.1[0]));
        // A blob may claim only one grid point.
        let mut seen = std::collections::HashSet::new();
        next.retain(|m| seen.insert(m.0));
        if next.iter().all(|m| m.0 != seed) {
            return None;
        }
        let from: Vec<[f64; 2]> = next
            .iter()
            .map(|m| [m.1[0] as f64, m.1[1] as f64])
            .collect();
        let to: Vec<[f64; 2]> = next.iter().map(|m| blobs[m.0].centre).collect();
        let new_map = fit_map(&from, &to).unwrap_or(map);
        let unchanged = next == members;
        members = next;
        map = new_map;
        if unchanged {
            break;
        }
    }
    // Shift the grid to start at (0, 0).
    let i0 = members.iter().map(|m| m.1[0]).min()?;
    let j0 = members.iter().map(|m| m.1[1]).min()?;
    for m in &mut members {
        m.1 = [m.1[0] - i0, m.1[1] - j0];
    }
    let shift = Matrix3::new(1.0, 0.0, i0 as f64, 0.0, 1.0, j0 as f64, 0.0, 0.0, 1.0);
    Some(Lattice {
        members,
        map: Homography(map.0 * shift),
    })
}

/// Least-squares grid map: a homography when the points span at least 3 × 3 grid
/// positions (enough to pin perspective), else an affine map, else `None`.
pub(crate) fn fit_map(from: &[[f64; 2]], to: &[[f64; 2]]) -> Option<Homography> {
    let span = |k: usize| {
        let lo = from.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min);
        let hi = from.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max);
        hi - lo
    };
    if from.len() >= 6 && span(0) >= 2.0 && span(1) >= 2.0 {
        if let Ok(h) = Homography::fit(from, to) {
            return Some(h);
        }
    }
    fit_affine(from, to)
}

/// Least-squares affine map, `None` for fewer than three non-collinear points.
fn fit_affine(from: &[[f64; 2]], to: &[[f64; 2]]) -> Option<Homography> {
    if from.len() < 3 {
        return None;
    }
    let mut ata = nalgebra::Matrix3::<f64>::zeros();
    let mut atx = nalgebra::Vector3::<f64>::zeros();
    let mut aty = nalgebra::Vector3::<f64>::zeros();
    for (f, t) in from.iter().zip(to) {
        let a = nalgebra::Vector3::new(f[0], f[1], 1.0);
        ata += a * a.transpose();
        atx += a * t[0];
        aty += a * t[1];
    }
    let inv = ata.try_inverse()?;
    if ata.determinant().abs() < 1e-9 {
        return None;
    }
    let px = inv * atx;
    let py = inv * aty;
    Some(Homography(Matrix3::new(
        px[0], px[1], px[2], py[0], py[1], py[2], 0.0, 0.0, 1.0,
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A blob of a `w` × `h` rectangle turned by `angle` radians.
    fn rectangle(w: f64, h: f64, angle: f64) -> Blob {
        let (s, c) = angle.sin_cos();
        let (vw, vh) = (w * w / 12.0, h * h / 12.0);
        Blob {
            centre: [50.0, 40.0],
            area: w * h,
            colour: [0.5; 3],
            moments: [
                vw * c * c + vh * s * s,
                (vw - vh) * s * c,
                vw * s * s + vh * c * c,
            ],
        }
    }

    #[test]
    fn a_restored_blob_is_the_rectangle_grown_on_every_side() {
        for (w, h, angle) in [
            (6.0, 6.0, 0.0),
            (9.0, 4.0, 0.0),
            (9.0, 4.0, 0.7),
            (3.0, 12.0, -1.2),
        ] {
            let got = restored(&rectangle(w, h, angle));
            let want = rectangle(w + 2.0 * EROSION_PX, h + 2.0 * EROSION_PX, angle);
            assert!(
                (got.area - want.area).abs() < 1e-9,
                "{w}×{h}: area {}",
                got.area
            );
            for k in 0..3 {
                assert!(
                    (got.moments[k] - want.moments[k]).abs() < 1e-9,
                    "{w}×{h} at {angle}: {:?} against {:?}",
                    got.moments,
                    want.moments
                );
            }
            assert_eq!(got.centre, want.centre);
        }
    }

    #[test]
    fn a_small_blurred_grid_is_found_as_one_lattice() {
        // Patches 7 px apart that segment as 3.5 px blobs (a chart a fifteenth of the
        // frame wide, blurred): unrestored they are neither neighbours nor fill their cell.
        let blobs: Vec<Blob> = (0..10)
            .flat_map(|r| (0..14).map(move |c| (c, r)))
            .map(|(c, r)| Blob {
                centre: [100.0 + 7.0 * f64::from(c), 60.0 + 7.0 * f64::from(r)],
                ..rectangle(3.5, 3.5, 0.0)
            })
            .collect();
        let lattices = find_lattices(&blobs, 6);
        assert_eq!(lattices.len(), 1);
        assert_eq!(lattices[0].members.len(), 140);
    }
}
