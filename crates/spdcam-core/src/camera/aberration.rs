//! Lateral chromatic aberration (thesis 3.1.5): the red channel is magnified and the blue
//! one shrunk about the image centre, so colour fringes grow towards the corners.

use crate::raster::RgbImage;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Lateral chromatic aberration: red scaled by `1 + strength`, blue by `1 − strength`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LateralAberration {
    /// The relative magnification difference (the thesis: 20/4000 = 0.005).
    pub strength: f64,
}

impl LateralAberration {
    /// The thesis's strength: 20/4000.
    pub const THESIS: LateralAberration = LateralAberration {
        strength: 20.0 / 4000.0,
    };

    /// The (channel, scale) pairs the aberration changes: red magnified, blue shrunk.
    fn scaled_channels(&self) -> [(usize, f64); 2] {
        [(0, 1.0 + self.strength), (2, 1.0 - self.strength)]
    }

    /// Applies the aberration in place; `scratch` is reused between calls.
    pub fn apply(&self, image: &mut RgbImage, scratch: &mut Vec<f32>) {
        let (w, h) = (image.width, image.height);
        for (channel, scale) in self.scaled_channels() {
            scratch.clear();
            scratch.extend_from_slice(&image.planes[channel]);
            let axis = AxisMap::new(w, h, scale);
            let plane = &mut image.planes[channel];
            let row = |(y, out): (usize, &mut [f32])| axis.row(scratch, y, out);
            if w * h > 200_000 {
                plane.par_chunks_mut(w).enumerate().for_each(row);
            } else {
                plane.chunks_mut(w).enumerate().for_each(row);
            }
        }
    }

    /// The aberrated image's pixel (`x`, `y`) without aberrating the whole image: exactly
    /// what [`LateralAberration::apply`] puts there.
    pub fn pixel(&self, image: &RgbImage, x: usize, y: usize) -> [f32; 3] {
        let mut out = image.pixel(x, y);
        for (channel, scale) in self.scaled_channels() {
            let axis = AxisMap::new(image.width, image.height, scale);
            out[channel] = axis.sample(&image.planes[channel], x, y);
        }
        out
    }

    /// The aberrated image over `region` without aberrating the whole image: fills `out`
    /// with one row-major plane per channel, exactly what [`LateralAberration::apply`] puts
    /// there. The source taps of each column are worked out once per channel.
    pub fn region(&self, image: &RgbImage, region: Region, out: &mut RegionPlanes) {
        let Region {
            x,
            y,
            width,
            height,
        } = region;
        for plane in out.planes.iter_mut() {
            plane.clear();
        }
        let green = &image.planes[1];
        for row in y..y + height {
            let start = row * image.width + x;
            out.planes[1].extend_from_slice(&green[start..start + width]);
        }
        for (channel, scale) in self.scaled_channels() {
            let axis = AxisMap::new(image.width, image.height, scale);
            out.taps.clear();
            out.taps
                .extend((x..x + width).map(|c| axis.taps(c, axis.centre.0, image.width)));
            let src = &image.planes[channel];
            for row in y..y + height {
                let ty = axis.taps(row, axis.centre.1, image.height);
                for &tx in &out.taps {
                    out.planes[channel].push(AxisMap::blend(src, image.width, tx, ty));
                }
            }
        }
    }
}

/// A rectangle of pixels: top-left corner, width and height.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Region {
    /// Left column (pixels).
    pub x: usize,
    /// Top row (pixels).
    pub y: usize,
    /// Width (pixels).
    pub width: usize,
    /// Height (pixels).
    pub height: usize,
}

/// Reusable planes (R, G, B; row-major over a [`Region`]) and column taps for
/// [`LateralAberration::region`].
#[derive(Debug, Clone, Default)]
pub struct RegionPlanes {
    /// The region's R, G and B after [`LateralAberration::region`].
    pub planes: [Vec<f32>; 3],
    taps: Vec<(usize, usize, f32)>,
}

/// Where a channel scaled by `scale` about the image centre takes each output pixel from:
/// `dst(x) = src(c + (x − c)/scale)`, bilinear, edges clamped.
struct AxisMap {
    width: usize,
    height: usize,
    centre: (f64, f64),
    inverse_scale: f64,
}

impl AxisMap {
    fn new(width: usize, height: usize, scale: f64) -> AxisMap {
        AxisMap {
            width,
            height,
            centre: ((width as f64 - 1.0) / 2.0, (height as f64 - 1.0) / 2.0),
            inverse_scale: 1.0 / scale,
        }
    }

    /// Source sample of output coordinate `v` along an axis of `n` pixels centred at `c`:
    /// the lower index, the upper index and the weight of the upper one.
    #[inline]
    fn taps(&self, v: usize, c: f64, n: usize) -> (usize, usize, f32) {
        let s = (c + (v as f64 - c) * self.inverse_scale).clamp(0.0, (n - 1) as f64);
        let i0 = s as usize; // s >= 0: truncation is floor
        (i0, (i0 + 1).min(n - 1), (s - i0 as f64) as f32)
    }

    #[inline]
    fn blend(
        src: &[f32],
        w: usize,
        (x0, x1, fx): (usize, usize, f32),
        (y0, y1, fy): (usize, usize, f32),
    ) -> f32 {
        let (r0, r1) = (&src[y0 * w..y0 * w + w], &src[y1 * w..y1 * w + w]);
        let top = r0[x0] + fx * (r0[x1] - r0[x0]);
        let bottom = r1[x0] + fx * (r1[x1] - r1[x0]);
        top + fy * (bottom - top)
    }

    /// One output row.
    fn row(&self, src: &[f32], y: usize, out: &mut [f32]) {
        let ty = self.taps(y, self.centre.1, self.height);
        for (x, o) in out.iter_mut().enumerate() {
            *o = Self::blend(src, self.width, self.taps(x, self.centre.0, self.width), ty);
        }
    }

    /// One output pixel.
    fn sample(&self, src: &[f32], x: usize, y: usize) -> f32 {
        Self::blend(
            src,
            self.width,
            self.taps(x, self.centre.0, self.width),
            self.taps(y, self.centre.1, self.height),
        )
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
    fn regions_match_the_whole_image() {
        let (w, h) = (40, 30);
        let mut img = RgbImage::new(w, h);
        for c in 0..3 {
            for (i, v) in img.planes[c].iter_mut().enumerate() {
                *v = ((i * (c + 3)) % 17) as f32 * 0.05;
            }
        }
        let ab = LateralAberration { strength: 0.02 };
        let mut whole = img.clone();
        ab.apply(&mut whole, &mut Vec::new());
        let region = Region {
            x: 3,
            y: 5,
            width: 30,
            height: 24,
        };
        let mut planes = RegionPlanes::default();
        ab.region(&img, region, &mut planes);
        for c in 0..3 {
            for j in 0..region.height {
                for i in 0..region.width {
                    let expected = whole.planes[c][(region.y + j) * w + region.x + i];
                    assert_eq!(planes.planes[c][j * region.width + i], expected);
                    assert_eq!(ab.pixel(&img, region.x + i, region.y + j)[c], expected);
                }
            }
        }
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
