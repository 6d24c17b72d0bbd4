//! Lateral chromatic aberration measured and undone on a detection level: a lens that
//! magnifies red and blue slightly differently from green draws colour fringes along every
//! edge, growing towards the frame's corners (a few pixels there), and the fringes split a
//! small chart's patches into slivers that the segmentation cannot use.
//!
//! The model is the radial one of Mallon & Whelan 2007 ("Calibration and removal of
//! lateral chromatic aberration in images", Pattern Recognition Letters 28(1)): each of red
//! and blue is the green image magnified about the image centre by its own factor 1 + k.
//! Each k is found as the magnification that best aligns that channel's gradients with
//! green's on the strongest green edges (their normalised correlation) (the edge alignment of Kang 2007, "Automatic
//! removal of chromatic aberration from a single image", CVPR), then undone by resampling.
//! Only detection sees the corrected level; patches are sampled at their centres, where
//! the fringes do not reach.

use super::pyramid::{bilinear_plane, Level};
use super::segment::box3;
use rayon::prelude::*;

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
    let smooth: [Vec<f32>; 3] = std::array::from_fn(|c| box3(&box3(&level.planes[c], w, h), w, h));
    let green = &smooth[1];
    let mut edges: Vec<(f32, usize)> = Vec::new();
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let i = y * w + x;
            let gx = green[i + 1] - green[i - 1];
            let gy = green[i + w] - green[i - w];
            edges.push((gx * gx + gy * gy, i));
        }
    }
    if edges.len() > EDGE_SAMPLES {
        let k = edges.len() - EDGE_SAMPLES;
        edges.select_nth_unstable_by(k, |a, b| a.0.total_cmp(&b.0));
        edges.drain(..k);
    }
    edges.retain(|e| e.0 > 0.0);
    if edges.len() < 100 {
        return ChannelScales::default();
    }
    let centre = [w as f64 / 2.0, h as f64 / 2.0];
    let score = |plane: &[f32], k: f64| -> f64 {
        let (dot, energy) = edges
            .iter()
            .map(|&(_, i)| {
                let (x, y) = ((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
                let p = [
                    centre[0] + (x - centre[0]) * (1.0 + k),
                    centre[1] + (y - centre[1]) * (1.0 + k),
                ];
                let cx = sample(plane, w, h, [p[0] + 1.0, p[1]])
                    - sample(plane, w, h, [p[0] - 1.0, p[1]]);
                let cy = sample(plane, w, h, [p[0], p[1] + 1.0])
                    - sample(plane, w, h, [p[0], p[1] - 1.0]);
                let gx = f64::from(green[i + 1] - green[i - 1]);
                let gy = f64::from(green[i + w] - green[i - w]);
                (gx * cx + gy * cy, cx * cx + cy * cy)
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
        let scores: Vec<(usize, f64)> = (lo..=hi)
            .into_par_iter()
            .map(|s| (s, score(plane, magnification(s))))
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

/// `level` with red and blue brought back onto green: each resampled at the point its
/// magnification moved there.
pub fn undo(level: &Level, scales: ChannelScales) -> Level {
    let (w, h) = (level.width, level.height);
    let centre = [w as f64 / 2.0, h as f64 / 2.0];
    let mut out = level.clone();
    for (channel, k) in [(0, scales.red), (2, scales.blue)] {
        let plane = &level.planes[channel];
        for (i, v) in out.planes[channel].iter_mut().enumerate() {
            let (x, y) = ((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
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
        let (w, h) = (400, 300);
        let value = |x: f64, y: f64| {
            let (c, r) = ((x / 20.0).floor() as i64, (y / 20.0).floor() as i64);
            let (u, v) = (x.rem_euclid(20.0), y.rem_euclid(20.0));
            if u < 3.0 || v < 3.0 {
                0.1
            } else {
                0.2 + 0.07 * ((c * 7 + r * 13).rem_euclid(11)) as f32 as f64
            }
        };
        let plane = |k: f64| -> Vec<f32> {
            (0..w * h)
                .map(|i| {
                    let (x, y) = ((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
                    // Magnified by 1 + k: the value at p came from centre + (p − centre)/(1 + k).
                    let (sx, sy) = (
                        200.0 + (x - 200.0) / (1.0 + k),
                        150.0 + (y - 150.0) / (1.0 + k),
                    );
                    value(sx, sy) as f32
                })
                .collect()
        };
        Level {
            width: w,
            height: h,
            planes: [plane(red), plane(0.0), plane(blue)],
        }
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
