//! Candidate patches: regions of nearly constant colour bounded by edges, kept when they are
//! convex, roughly square (up to perspective) quadrilaterals.
//!
//! The gradient (largest central difference over the three channels, after scaling the
//! image so its bright end is 1) marks edges; connected regions of low gradient are
//! measured by their moments. A region is a patch candidate when its area matches that of
//! the parallelogram its second moments describe (any parallelogram matches exactly, an
//! ellipse or an L-shape does not) and when the quadrilateral through its extreme points
//! covers it. Several gradient thresholds are tried, so that dim, low-contrast charts and
//! noisy ones both segment; duplicates are merged.

use super::pyramid::Level;
use rayon::prelude::*;

/// A candidate patch, in level pixel coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct Blob {
    /// Centroid (continuous coordinates, pixel centres at +0.5).
    pub centre: [f64; 2],
    /// Area in pixels.
    pub area: f64,
    /// Mean colour (encoded sRGB, 0…1).
    pub colour: [f32; 3],
    /// Second central moments (σxx, σxy, σyy) in pixels²: the blob's shape, from which a
    /// foreshortened patch's own frame is known.
    pub moments: [f64; 3],
}

impl Blob {
    /// Side of the square of the blob's area.
    pub fn side(&self) -> f64 {
        self.area.sqrt()
    }

    /// Whether the blob may reach the edge of a `width` × `height` image, so that it may be
    /// a shape cut by the photo's border rather than a whole patch: its extent along each
    /// axis is taken as two standard deviations either side of its centre (exact for an
    /// ellipse, 15 % more than a square's half-side).
    pub fn may_touch_border(&self, width: usize, height: usize) -> bool {
        let [sxx, _, syy] = self.moments;
        let (hx, hy) = (2.0 * sxx.max(0.0).sqrt(), 2.0 * syy.max(0.0).sqrt());
        let [x, y] = self.centre;
        x - hx <= 1.0
            || y - hy <= 1.0
            || x + hx >= width as f64 - 1.0
            || y + hy >= height as f64 - 1.0
    }

    /// The length of `v` (pixels) in the blob's own metric: √(vᵀ Σ⁻¹ v) with Σ its second
    /// moments (the Mahalanobis length). A square of side s has Σ = s²/12 · I, so a vector
    /// one side long measures √12 whatever the square's foreshortening or rotation.
    pub fn metric_length(&self, v: [f64; 2]) -> f64 {
        self.metric_dot(v, v).max(0.0).sqrt()
    }

    /// The inner product uᵀ Σ⁻¹ v of the blob's metric.
    pub fn metric_dot(&self, u: [f64; 2], v: [f64; 2]) -> f64 {
        let [a, b, c] = self.moments;
        let det = (a * c - b * b).max(1e-12);
        (u[0] * (c * v[0] - b * v[1]) + u[1] * (a * v[1] - b * v[0])) / det
    }
}

/// The variances (largest, smallest) of second moments (σxx, σxy, σyy) along their principal
/// axes: the eigenvalues of the symmetric 2 × 2 matrix, (tr/2 ± √(tr²/4 − det)).
pub fn principal_variances([a, b, c]: [f64; 3]) -> (f64, f64) {
    let half_gap = (0.25 * (a - c).powi(2) + b * b).sqrt();
    (0.5 * (a + c) + half_gap, 0.5 * (a + c) - half_gap)
}

/// Gradient thresholds (on the brightness-normalised image) tried in turn.
const THRESHOLDS: [f32; 4] = [0.02, 0.04, 0.08, 0.16];
/// Smallest area of a candidate, in level pixels.
const MIN_AREA: usize = 12;
/// Most candidates kept (the squarest first), a bound on the work of the lattice search.
const MAX_BLOBS: usize = 3000;
/// Longest axis over shortest of a candidate: a square seen at 78° from face-on (cos 78° ≈
/// 1/4.8), so that charts tilted to 70° are found with the perspective across them.
const MAX_ELONGATION: f64 = 4.8;

/// The patch candidates of a level.
pub fn find_blobs(level: &Level) -> Vec<Blob> {
    let (w, h) = (level.width, level.height);
    if w < 3 || h < 3 {
        return Vec::new();
    }
    let gradient = gradient(level);
    let max_area = (w * h / 12).max(MIN_AREA + 1);
    // Each threshold's regions on their own, in parallel, joined in the thresholds' order.
    let mut scored: Vec<(f64, Blob)> = THRESHOLDS
        .par_iter()
        .flat_map_iter(|&t| regions_below(level, &gradient, t, max_area))
        .collect();
    // Merge the same patch found at several thresholds: keep the largest region.
    scored.sort_by(|a, b| b.1.area.total_cmp(&a.1.area));
    let mut kept: Vec<(f64, Blob)> = Vec::new();
    for (q, b) in scored {
        let dup = kept.iter().any(|(_, k)| {
            let d = (k.centre[0] - b.centre[0]).hypot(k.centre[1] - b.centre[1]);
            d < 0.35 * k.side()
        });
        if !dup {
            kept.push((q, b));
        }
    }
    if kept.len() > MAX_BLOBS {
        kept.sort_by(|a, b| a.0.total_cmp(&b.0));
        kept.truncate(MAX_BLOBS);
    }
    kept.into_iter().map(|(_, b)| b).collect()
}

/// The plausible patches, each with its shape error, among the 4-connected regions of
/// `level` where `gradient` stays below `t`, of [`MIN_AREA`] to `max_area` pixels, in scan
/// order.
fn regions_below(level: &Level, gradient: &[f32], t: f32, max_area: usize) -> Vec<(f64, Blob)> {
    let (w, h) = (level.width, level.height);
    let mut scored: Vec<(f64, Blob)> = Vec::new();
    let mut visited = vec![false; w * h];
    let mut stack = Vec::new();
    let mut pixels = Vec::new();
    for start in 0..w * h {
        if visited[start] || gradient[start] >= t {
            continue;
        }
        pixels.clear();
        stack.push(start);
        visited[start] = true;
        while let Some(i) = stack.pop() {
            pixels.push(i);
            let (x, y) = (i % w, i / w);
            let mut visit = |j: usize| {
                if !visited[j] && gradient[j] < t {
                    visited[j] = true;
                    stack.push(j);
                }
            };
            if x > 0 {
                visit(i - 1);
            }
            if x + 1 < w {
                visit(i + 1);
            }
            if y > 0 {
                visit(i - w);
            }
            if y + 1 < h {
                visit(i + w);
            }
        }
        if (MIN_AREA..=max_area).contains(&pixels.len()) {
            if let Some(b) = measure(level, &pixels) {
                scored.push(b);
            }
        }
    }
    scored
}

/// Largest central difference over the channels of the 3 × 3 box-smoothed level, scaled so
/// that the 99th percentile of the brightest channel is 1; the image border gets infinity.
fn gradient(level: &Level) -> Vec<f32> {
    let (w, h) = (level.width, level.height);
    let smooth: [Vec<f32>; 3] = std::array::from_fn(|c| box3(&level.planes[c], w, h));
    let mut bright: Vec<f32> = (0..w * h)
        .step_by(7)
        .map(|i| level.planes.iter().map(|p| p[i]).fold(0.0, f32::max))
        .collect();
    let k = ((bright.len() as f64 * 0.99) as usize).min(bright.len() - 1);
    let p99 = *bright.select_nth_unstable_by(k, |a, b| a.total_cmp(b)).1;
    let gain = 1.0 / p99.max(0.02);
    let mut g = vec![f32::INFINITY; w * h];
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let i = y * w + x;
            let mut m = 0.0f32;
            for p in &smooth {
                m = m
                    .max((p[i + 1] - p[i - 1]).abs())
                    .max((p[i + w] - p[i - w]).abs());
            }
            g[i] = m * gain;
        }
    }
    g
}

/// 3 × 3 box filter (edges replicated).
pub(super) fn box3(plane: &[f32], w: usize, h: usize) -> Vec<f32> {
    let mut rows = vec![0.0f32; w * h];
    for y in 0..h {
        let r = &plane[y * w..(y + 1) * w];
        let o = &mut rows[y * w..(y + 1) * w];
        for x in 0..w {
            o[x] = r[x.saturating_sub(1)] + r[x] + r[(x + 1).min(w - 1)];
        }
    }
    let mut out = vec![0.0f32; w * h];
    for y in 0..h {
        let (a, b, c) = (y.saturating_sub(1), y, (y + 1).min(h - 1));
        for x in 0..w {
            out[y * w + x] = (rows[a * w + x] + rows[b * w + x] + rows[c * w + x]) / 9.0;
        }
    }
    out
}

/// Moments and shape tests of one region; `None` when it is not a plausible patch. The
/// first value is a shape error (0 for a perfect parallelogram).
fn measure(level: &Level, pixels: &[usize]) -> Option<(f64, Blob)> {
    let w = level.width;
    let n = pixels.len() as f64;
    let (mut sx, mut sy) = (0.0f64, 0.0f64);
    let mut colour = [0.0f64; 3];
    for &i in pixels {
        sx += (i % w) as f64;
        sy += (i / w) as f64;
        for (c, p) in level.planes.iter().enumerate() {
            colour[c] += p[i] as f64;
        }
    }
    let (cx, cy) = (sx / n, sy / n);
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for &i in pixels {
        let dx = (i % w) as f64 - cx;
        let dy = (i / w) as f64 - cy;
        sxx += dx * dx;
        sxy += dx * dy;
        syy += dy * dy;
    }
    let (sxx, sxy, syy) = (sxx / n + 1.0 / 12.0, sxy / n, syy / n + 1.0 / 12.0);
    let det = sxx * syy - sxy * sxy;
    if det <= 0.0 {
        return None;
    }
    // A parallelogram of area A has 12·sqrt(det Σ) = A.
    let squareness = n / (12.0 * det.sqrt());
    let (largest, smallest) = principal_variances([sxx, sxy, syy]);
    let elongation = (largest / smallest.max(1e-9)).sqrt();
    if !(0.88..=1.12).contains(&squareness) || elongation > MAX_ELONGATION {
        return None;
    }
    // The quadrilateral through the extreme points must cover the region.
    let at = |i: usize| [(i % w) as f64, (i / w) as f64];
    let far = |from: [f64; 2]| {
        pixels
            .iter()
            .map(|&i| at(i))
            .max_by(|a, b| {
                let da = (a[0] - from[0]).powi(2) + (a[1] - from[1]).powi(2);
                let db = (b[0] - from[0]).powi(2) + (b[1] - from[1]).powi(2);
                da.total_cmp(&db)
            })
            .unwrap_or(from)
    };
    let c1 = far([cx, cy]);
    let c3 = far(c1);
    let side_of = |p: [f64; 2]| (c3[0] - c1[0]) * (p[1] - c1[1]) - (c3[1] - c1[1]) * (p[0] - c1[0]);
    let (mut c2, mut c4) = (c1, c1);
    let (mut best2, mut best4) = (0.0, 0.0);
    for &i in pixels {
        let p = at(i);
        let s = side_of(p);
        if s > best2 {
            best2 = s;
            c2 = p;
        }
        if s < best4 {
            best4 = s;
            c4 = p;
        }
    }
    // Pixel centres → pixel outlines: push each corner half a pixel diagonal outwards.
    let grow = |p: [f64; 2]| {
        let (dx, dy) = (p[0] - cx, p[1] - cy);
        let d = dx.hypot(dy).max(1e-9);
        [p[0] + 0.7 * dx / d, p[1] + 0.7 * dy / d]
    };
    let q = [grow(c1), grow(c2), grow(c3), grow(c4)];
    let quad_area = 0.5
        * (0..4)
            .map(|k| q[k][0] * q[(k + 1) % 4][1] - q[(k + 1) % 4][0] * q[k][1])
            .sum::<f64>()
            .abs();
    let fill = n / quad_area.max(1e-9);
    if !(0.8..=1.25).contains(&fill) {
        return None;
    }
    let error = (squareness - 1.0).abs() + (fill - 1.0).abs();
    Some((
        error,
        Blob {
            centre: [cx + 0.5, cy + 0.5],
            area: n,
            colour: colour.map(|v| (v / n) as f32),
            moments: [sxx, sxy, syy],
        },
    ))
}
