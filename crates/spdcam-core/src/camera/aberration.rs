//! Lateral chromatic aberration (thesis 3.1.5): the red channel is magnified and the blue
//! one shrunk about the image centre, so colour fringes grow towards the corners.

use crate::raster::RgbImage;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Lateral chromatic aberration: red scaled by `1 + strength`, blue by `1 − strength`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LateralAberration {
    pub strength: f64,
}

impl LateralAberration {
    /// The thesis's strength: 20/4000.
    pub const THESIS: LateralAberration = LateralAberration {
        strength: 20.0 / 4000.0,
    };

    /// Applies the aberration in place; `scratch` is reused between calls.
    pub fn apply(&self, image: &mut RgbImage, scratch: &mut Vec<f32>) {
        let (w, h) = (image.width, image.height);
        for (channel, scale) in [(0usize, 1.0 + self.strength), (2, 1.0 - self.strength)] {
            scratch.clear();
            scratch.extend_from_slice(&image.planes[channel]);
            scale_about_centre(scratch, &mut image.planes[channel], w, h, scale);
        }
    }
}

/// `dst(x) = src(c + (x − c)/scale)` with bilinear interpolation, edges clamped.
fn scale_about_centre(src: &[f32], dst: &mut [f32], w: usize, h: usize, scale: f64) {
    let (cx, cy) = ((w as f64 - 1.0) / 2.0, (h as f64 - 1.0) / 2.0);
    let inv = 1.0 / scale;
    let max_x = (w - 1) as f64;
    let max_y = (h - 1) as f64;
    // Source column positions are the same for every row: compute them once.
    let columns: Vec<(usize, usize, f32)> = (0..w)
        .map(|x| {
            let sx = (cx + (x as f64 - cx) * inv).clamp(0.0, max_x);
            let x0 = sx.floor() as usize;
            (x0, (x0 + 1).min(w - 1), (sx - x0 as f64) as f32)
        })
        .collect();
    let row = |(y, out): (usize, &mut [f32])| {
        let sy = (cy + (y as f64 - cy) * inv).clamp(0.0, max_y);
        let y0 = sy.floor() as usize;
        let y1 = (y0 + 1).min(h - 1);
        let fy = (sy - y0 as f64) as f32;
        let (r0, r1) = (&src[y0 * w..y0 * w + w], &src[y1 * w..y1 * w + w]);
        for (o, &(x0, x1, fx)) in out.iter_mut().zip(&columns) {
            let top = r0[x0] + fx * (r0[x1] - r0[x0]);
            let bottom = r1[x0] + fx * (r1[x1] - r1[x0]);
            *o = top + fy * (bottom - top);
        }
    };
    if w * h > 200_000 {
        dst.par_chunks_mut(w).enumerate().for_each(row);
    } else {
        dst.chunks_mut(w).enumerate().for_each(row);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_stays_and_edges_move_outward_for_red() {
        let (w, h) = (101, 51);
        let mut img = RgbImage::new(w, h);
        for y in 0..h {
            for x in 0..w {
                for c in 0..3 {
                    img.planes[c][y * w + x] = x as f32;
                }
            }
        }
        let mut scratch = Vec::new();
        LateralAberration { strength: 0.1 }.apply(&mut img, &mut scratch);
        let at = |c: usize, x: usize| img.planes[c][25 * w + x];
        assert_eq!(at(0, 50), 50.0);
        // red at x = 100 samples source 50 + 50/1.1
        assert!((at(0, 100) - (50.0 + 50.0 / 1.1)).abs() < 1e-3);
        // blue shrinks: x = 60 samples 50 + 10/0.9, green untouched
        assert!((at(2, 60) - (50.0 + 10.0 / 0.9)).abs() < 1e-3);
        assert_eq!(at(1, 100), 100.0);
    }

    #[test]
    fn zero_strength_is_identity() {
        let mut img = RgbImage::new(8, 6);
        for (i, v) in img.planes[0].iter_mut().enumerate() {
            *v = i as f32 * 0.1;
        }
        let before = img.clone();
        LateralAberration { strength: 0.0 }.apply(&mut img, &mut Vec::new());
        assert_eq!(img, before);
    }
}
