//! Lateral chromatic aberration measured and undone on a detection level: a lens that
//! magnifies red and blue slightly differently from green draws colour fringes along every
//! edge, growing towards the frame's corners (a few pixels there), and the fringes split a
//! small chart's patches into slivers that the segmentation cannot use.
//!
//! The model is the radial one of Mallon & Whelan 2007 ("Calibration and removal of
//! lateral chromatic aberration in images", Pattern Recognition Letters 28(1)): each of red
//! and blue is the green image magnified about the image centre by its own factor 1 + k.
//! Each k is found as the magnification that best aligns that channel's gradients with
//! green's on the strongest green edges (the magnitudes of their dot products, normalised by
//! the channel's gradient energy: an edge lines up whatever the sign of its colour
//! contrast) (the edge alignment of Kang 2007, "Automatic removal of chromatic aberration
//! from a single image", CVPR), then undone by resampling.
//! Only detection sees the corrected level; patches are sampled at their centres, where
//! the fringes do not reach.
//!
//! The lens magnifies the sensor's own channels, and the camera's colour matrix then mixes
//! them: each channel of the photo holds all three magnifications, so its fringes are no
//! single magnification (a matrix with −0.8 off the diagonal makes them stronger and
//! two-sided). Measuring and undoing them in the camera's RGB, reached by inverting a
//! typical camera's matrix ([`TYPICAL_CAMERA_TO_SRGB`]), takes this mixing out.

use super::pyramid::{bilinear_plane, Level};
use super::segment::box3;
use crate::camera::colour::{srgb_decode_fast, xyz_to_srgb_matrix, ColourTransform};
use nalgebra::Matrix3;
use rayon::prelude::*;
use std::sync::OnceLock;

/// Largest relative magnification tried, either way (a strong lens: 1 % is 10 px at the
/// corner of a 2000 px wide level).
const MOST: f64 = 0.01;
/// Magnifications tried between −[`MOST`] and +[`MOST`].
const STEPS: usize = 41;
/// Green edge pixels the alignment is measured on (the strongest).
const EDGE_SAMPLES: usize = 10_000;
/// The search tries every COARSE-th magnification, then every one around the best of those
/// (the alignment is smooth in the magnification: one peak).
const COARSE: usize = 4;
/// A magnification smaller than this (at most a fifth of a pixel at the corner of a 1000
/// px level) is left alone.
const NEGLIGIBLE: f64 = 0.0004;

/// A typical camera's colour matrix, white-balanced camera RGB → linear sRGB: the
/// element-wise median of the D65-fitted matrices (thesis 3.1.6) of the 55 usable measured
/// cameras of the data directory's cameras/, each with its rows first scaled to sum to 1
/// (white stays white); recomputed and compared by the second-tier test in
/// `tests/camera_pipeline.rs`.
pub const TYPICAL_CAMERA_TO_SRGB: [[f64; 3]; 3] = [
    [1.734, -0.692, -0.071],
    [-0.144, 1.584, -0.407],
    [0.050, -0.554, 1.497],
];

/// `level` with `f` applied to every pixel's (R, G, B).
fn map_pixels(level: &Level, f: impl Fn([f32; 3]) -> [f32; 3] + Sync) -> Level {
    let mut out = level.clone();
    let [r, g, b] = &mut out.planes;
    r.par_iter_mut()
        .zip(g.par_iter_mut())
        .zip(b.par_iter_mut())
        .for_each(|((r, g), b)| [*r, *g, *b] = f([*r, *g, *b]));
    out
}

/// `level` (encoded sRGB) in a typical camera's linear RGB: decoded, then the inverse of
/// [`TYPICAL_CAMERA_TO_SRGB`].
pub fn to_camera(level: &Level) -> Level {
    let inverse = Matrix3::from_fn(|i, j| TYPICAL_CAMERA_TO_SRGB[i][j])
        .try_inverse()
        .unwrap_or_else(Matrix3::identity);
    let m: [[f32; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| inverse[(i, j)] as f32));
    map_pixels(level, |rgb| {
        let v = rgb.map(srgb_decode_fast);
        std::array::from_fn(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
    })
}

/// A level of [`to_camera`] back in encoded sRGB (clipped to 0…1), by the camera's own
/// colour transform with [`TYPICAL_CAMERA_TO_SRGB`] as its matrix.
pub fn to_display(level: &Level) -> Level {
    static TYPICAL: OnceLock<ColourTransform> = OnceLock::new();
    let transform = TYPICAL.get_or_init(|| {
        let srgb_to_xyz = xyz_to_srgb_matrix()
            .try_inverse()
            .unwrap_or_else(Matrix3::identity);
        let typical = Matrix3::from_fn(|i, j| TYPICAL_CAMERA_TO_SRGB[i][j]);
        ColourTransform::new(Some(srgb_to_xyz * typical), 8)
            .expect("8 bits is an output depth the transform takes")
    });
    map_pixels(level, |rgb| transform.encode_pixel(rgb))
}

/// The magnifications of red and blue relative to green ([`measure`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ChannelScales {
    /// Red's magnification less 1.
    pub red: f64,
    /// Blue's magnification less 1.
    pub blue: f64,
}

impl ChannelScales {
    /// Whether undoing them changes anything.
    pub fn is_negligible(&self) -> bool {
        self.red.abs() < NEGLIGIBLE && self.blue.abs() < NEGLIGIBLE
    }
}

/// Red's and blue's magnifications relative to green in `level`, each the best aligned of
/// [`STEPS`] within ±[`MOST`] (searched coarse to fine), refined by a parabola through its
/// neighbours; 0 where the level has too few edges to tell.
pub fn measure(level: &Level) -> ChannelScales {
    let (w, h) = (level.width, level.height);
    if w < 8 || h < 8 {
        return ChannelScales::default();
    }
    // Smoothed twice by 3 × 3 boxes (about a Gaussian of σ 1.2 px): a sharp edge's gradient
    // is a pixel wide and would align only at the exact magnification.
    let smooth: Vec<Vec<f32>> = level
        .planes
        .par_iter()
        .map(|plane| box3(&box3(plane, w, h), w, h))
        .collect();
    let green = &smooth[1];
    let mut edges: Vec<(f32, usize)> = (1..h - 1)
        .into_par_iter()
        .flat_map_iter(|y| {
            (1..w - 1).map(move |x| {
                let i = y * w + x;
                let gx = green[i + 1] - green[i - 1];
                let gy = green[i + w] - green[i - w];
                (gx * gx + gy * gy, i)
            })
        })
        .collect();
    if edges.len() > EDGE_SAMPLES {
        let k = edges.len() - EDGE_SAMPLES;
        edges.select_nth_unstable_by(k, |a, b| a.0.total_cmp(&b.0));
        edges.drain(..k);
    }
    edges.retain(|e| e.0 > 0.0);
    if edges.len() < 100 {
        return ChannelScales::default();
    }
    // In pixel order, so that the samples of each magnification walk the planes forwards.
    edges.sort_unstable_by_key(|e| e.1);
    // Each edge's place (pixel centre, from the image centre) and green gradient, worked
    // out once for the many magnifications scored.
    let centre = [w as f64 / 2.0, h as f64 / 2.0];
    let edges: Vec<EdgeSample> = edges
        .iter()
        .map(|&(_, i)| EdgeSample {
            from_centre: [
                (i % w) as f64 + 0.5 - centre[0],
                (i / w) as f64 + 0.5 - centre[1],
            ],
            green: [
                f64::from(green[i + 1] - green[i - 1]),
                f64::from(green[i + w] - green[i - w]),
            ],
        })
        .collect();
    let score = |plane: &[f32], k: f64| -> f64 {
        let (dot, energy) = edges
            .iter()
            .map(|edge| {
                let p = [
                    centre[0] + edge.from_centre[0] * (1.0 + k),
                    centre[1] + edge.from_centre[1] * (1.0 + k),
                ];
                let cx = sample(plane, w, h, [p[0] + 1.0, p[1]])
                    - sample(plane, w, h, [p[0] - 1.0, p[1]]);
                let cy = sample(plane, w, h, [p[0], p[1] + 1.0])
                    - sample(plane, w, h, [p[0], p[1] - 1.0]);
                let [gx, gy] = edge.green;
                // Each edge counts by how well the gradients line up, whatever the sign of
                // its colour contrast: an edge where red falls as green rises (red against
                // green) lines up as much as a grey one, and summed with its sign it would
                // favour a magnification that moves it off.
                ((gx * cx + gy * cy).abs(), cx * cx + cy * cy)
            })
            .fold((0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1));
        // Normalised by the channel's own gradient energy there: interpolating between
        // pixels blurs, which would favour no magnification at all.
        dot / energy.max(1e-12).sqrt()
    };
    let best = |channel: usize| {
        let plane = &smooth[channel];
        // Every COARSE-th magnification first, then every one around the best of those.
        let coarse: Vec<usize> = (0..STEPS).step_by(COARSE).collect();
        let coarse_scores: Vec<f64> = coarse
            .par_iter()
            .map(|&s| score(plane, magnification(s)))
            .collect();
        let around = coarse[(0..coarse.len())
            .max_by(|&a, &b| coarse_scores[a].total_cmp(&coarse_scores[b]))
            .unwrap_or(0)];
        let lo = around.saturating_sub(COARSE);
        let hi = (around + COARSE).min(STEPS - 1);
        // The coarse scores within the range are not computed again.
        let scores: Vec<(usize, f64)> = (lo..=hi)
            .into_par_iter()
            .map(|s| match coarse.iter().position(|&c| c == s) {
                Some(j) => (s, coarse_scores[j]),
                None => (s, score(plane, magnification(s))),
            })
            .collect();
        let at = |s: usize| scores.iter().find(|v| v.0 == s).map_or(f64::MIN, |v| v.1);
        let s = scores
            .iter()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map_or(STEPS / 2, |v| v.0);
        if s == 0 || s == STEPS - 1 || s == lo || s == hi {
            return magnification(s);
        }
        // The parabola's vertex through the best and its two neighbours.
        let (a, b, c) = (at(s - 1), at(s), at(s + 1));
        let curvature = a - 2.0 * b + c;
        let offset = if curvature < 0.0 {
            (0.5 * (a - c) / curvature).clamp(-0.5, 0.5)
        } else {
            0.0
        };
        magnification(s) + offset * step()
    };
    ChannelScales {
        red: best(0),
        blue: best(2),
    }
}

/// One green edge that [`measure`] aligns the other channels on.
struct EdgeSample {
    /// The pixel's centre less the image's centre.
    from_centre: [f64; 2],
    /// Green's central-difference gradient there (x, y).
    green: [f64; 2],
}

/// `level` with red and blue brought back onto green: each resampled at the point its
/// magnification moved there.
pub fn undo(level: &Level, scales: ChannelScales) -> Level {
    let (w, h) = (level.width, level.height);
    let centre = [w as f64 / 2.0, h as f64 / 2.0];
    let mut out = level.clone();
    for (channel, k) in [(0, scales.red), (2, scales.blue)] {
        let plane = &level.planes[channel];
        out.planes[channel]
            .par_chunks_mut(w.max(1))
            .enumerate()
            .for_each(|(row, values)| {
                let y = row as f64 + 0.5;
                for (column, v) in values.iter_mut().enumerate() {
                    let x = column as f64 + 0.5;
                    *v = sample(
                        plane,
                        w,
                        h,
                        [
                            centre[0] + (x - centre[0]) * (1.0 + k),
                            centre[1] + (y - centre[1]) * (1.0 + k),
                        ],
                    ) as f32;
                }
            });
    }
    out
}

fn step() -> f64 {
    2.0 * MOST / (STEPS - 1) as f64
}

fn magnification(s: usize) -> f64 {
    -MOST + s as f64 * step()
}

/// [`bilinear_plane`] in f64.
fn sample(plane: &[f32], w: usize, h: usize, p: [f64; 2]) -> f64 {
    f64::from(bilinear_plane(plane, w, h, p))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A level of squares of random greys on a grid, the same in every channel, then red
    /// magnified by `red` and blue by `blue` about the centre.
    fn fringed(red: f64, blue: f64) -> Level {
        coloured(red, blue, 0)
    }

    /// [`fringed`] with every `opposed`-th square's red the negative of its green (red
    /// falls where green rises across its edges); 0: none.
    fn coloured(red: f64, blue: f64, opposed: i64) -> Level {
        let (w, h) = (400, 300);
        let value = |x: f64, y: f64, channel: usize| {
            let (c, r) = ((x / 20.0).floor() as i64, (y / 20.0).floor() as i64);
            let (u, v) = (x.rem_euclid(20.0), y.rem_euclid(20.0));
            let grey = if u < 3.0 || v < 3.0 {
                0.1
            } else {
                0.2 + 0.07 * ((c * 7 + r * 13).rem_euclid(11)) as f32 as f64
            };
            if channel == 0 && opposed > 0 && (c * 3 + r * 5).rem_euclid(opposed) == 0 {
                1.0 - grey
            } else {
                grey
            }
        };
        let plane = |k: f64, channel: usize| -> Vec<f32> {
            (0..w * h)
                .map(|i| {
                    let (x, y) = ((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
                    // Magnified by 1 + k: the value at p came from centre + (p − centre)/(1 + k).
                    let (sx, sy) = (
                        200.0 + (x - 200.0) / (1.0 + k),
                        150.0 + (y - 150.0) / (1.0 + k),
                    );
                    value(sx, sy, channel) as f32
                })
                .collect()
        };
        Level {
            width: w,
            height: h,
            planes: [plane(red, 0), plane(0.0, 1), plane(blue, 2)],
        }
    }

    #[test]
    fn edges_of_opposite_colour_contrast_line_up_too() {
        // A third of the squares red against green: their edges line up at the same
        // magnification as the grey ones, and must not pull the measure off it.
        let level = coloured(0.006, -0.004, 3);
        let s = measure(&level);
        assert!((s.red - 0.006).abs() < 0.0008, "{s:?}");
        assert!((s.blue + 0.004).abs() < 0.0008, "{s:?}");
    }

    #[test]
    fn a_radial_magnification_is_measured_and_undone() {
        let level = fringed(0.006, -0.004);
        let s = measure(&level);
        assert!((s.red - 0.006).abs() < 0.0008, "{s:?}");
        assert!((s.blue + 0.004).abs() < 0.0008, "{s:?}");
        let fixed = undo(&level, s);
        let error = |l: &Level| -> f64 {
            (0..l.width * l.height)
                .map(|i| f64::from((l.planes[0][i] - l.planes[1][i]).abs()))
                .sum::<f64>()
                / (l.width * l.height) as f64
        };
        assert!(
            // What is left is the blur of resampling sharp edges.
            error(&fixed) < 0.6 * error(&level),
            "{} → {}",
            error(&level),
            error(&fixed)
        );
    }

    #[test]
    fn camera_rgb_and_back_is_the_level_itself() {
        let level = fringed(0.0, 0.0);
        let back = to_display(&to_camera(&level));
        for c in 0..3 {
            for (a, b) in level.planes[c].iter().zip(&back.planes[c]) {
                assert!((a - b).abs() < 2e-3, "{a} → {b}");
            }
        }
    }

    #[test]
    fn fringes_mixed_by_the_colour_matrix_are_measured_in_camera_rgb() {
        // The lens magnifies the sensor's channels, the camera's matrix then mixes them.
        // Linear camera values of 0.23–0.47, which the matrix keeps within 0…1 (no clipping).
        let mut raw = fringed(0.006, -0.004);
        raw.planes
            .iter_mut()
            .for_each(|p| p.iter_mut().for_each(|v| *v = 0.35 + 0.3 * (*v - 0.5)));
        let photo = to_display(&raw);
        let s = measure(&to_camera(&photo));
        assert!((s.red - 0.006).abs() < 0.0008, "{s:?}");
        assert!((s.blue + 0.004).abs() < 0.0008, "{s:?}");
        // Measured on the mixed channels, the magnifications come out wrong.
        let mixed = measure(&photo);
        assert!(
            (mixed.red - 0.006).abs() > 0.0015 && (mixed.blue + 0.004).abs() > 0.0015,
            "{mixed:?}"
        );
    }

    #[test]
    fn an_aligned_level_is_left_alone() {
        let s = measure(&fringed(0.0, 0.0));
        assert!(s.is_negligible(), "{s:?}");
        let flat = Level {
            width: 50,
            height: 40,
            planes: [vec![0.5; 2000], vec![0.5; 2000], vec![0.5; 2000]],
        };
        assert_eq!(measure(&flat), ChannelScales::default());
    }
}
