//! A downscaled copy of a photo for detection: box-averaged by an integer factor, planar
//! f32 (encoded sRGB, 0…1), so that a 50-megapixel photo is searched at about 1000 px.

use super::load::Photo;
use rayon::prelude::*;

/// A photo reduced by an integer `factor`: pixel (i, j) averages the photo's block
/// `[i·factor, (i+1)·factor) × [j·factor, (j+1)·factor)`; edge pixels that do not fill a
/// block are dropped.
#[derive(Debug, Clone)]
pub struct Level {
    /// Width in (block) pixels.
    pub width: usize,
    /// Height in (block) pixels.
    pub height: usize,
    /// R, G, B planes, row-major.
    pub planes: [Vec<f32>; 3],
}

impl Level {
    /// The photo reduced by `factor` (≥ 1).
    pub fn new(photo: &Photo, factor: usize) -> Level {
        let k = factor.max(1);
        Level::window(photo, k, [0, 0], [photo.width / k, photo.height / k])
    }

    /// The part of the photo reduced by `factor` (≥ 1) whose level pixels start at `origin`
    /// and span `size` (clipped to the photo): level pixel (i, j) of the window is pixel
    /// (origin + (i, j)) of [`Level::new`]. Refining a chart's corners needs only the chart.
    pub fn window(photo: &Photo, factor: usize, origin: [usize; 2], size: [usize; 2]) -> Level {
        let k = factor.max(1);
        let (full_w, full_h) = (photo.width / k, photo.height / k);
        let (x0, y0) = (origin[0].min(full_w), origin[1].min(full_h));
        let (w, h) = (size[0].min(full_w - x0), size[1].min(full_h - y0));
        let norm = 1.0 / (k * k) as f32;
        let mut interleaved = vec![[0.0f32; 3]; w * h];
        interleaved
            .par_chunks_mut(w.max(1))
            .enumerate()
            .for_each(|(y, row)| {
                for dy in 0..k {
                    let py = (y0 + y) * k + dy;
                    for (x, out) in row.iter_mut().enumerate() {
                        let px = (x0 + x) * k;
                        let s = photo.row_sum(py, px, px + k);
                        for c in 0..3 {
                            out[c] += s[c];
                        }
                    }
                }
                row.iter_mut().for_each(|v| *v = v.map(|s| s * norm));
            });
        let planes = std::array::from_fn(|c| interleaved.iter().map(|v| v[c]).collect());
        Level {
            width: w,
            height: h,
            planes,
        }
    }

    /// This level enlarged twice in each direction by bilinear interpolation: a chart whose
    /// patches are a few pixels wide keeps a low-gradient core that the segmentation can
    /// find, where the edges' gradient covers the patches at their own size.
    pub fn enlarged(&self) -> Level {
        let (w, h) = (2 * self.width, 2 * self.height);
        let mut planes: [Vec<f32>; 3] = std::array::from_fn(|_| vec![0.0; w * h]);
        for y in 0..h {
            for x in 0..w {
                let v = self.bilinear([(x as f64 + 0.5) / 2.0, (y as f64 + 0.5) / 2.0]);
                for c in 0..3 {
                    planes[c][y * w + x] = v[c];
                }
            }
        }
        Level {
            width: w,
            height: h,
            planes,
        }
    }

    /// The factor that brings a photo of `width × height` to about `target` px on its
    /// longer side (never below 1).
    pub fn factor_for(width: usize, height: usize, target: usize) -> usize {
        (width.max(height) as f64 / target as f64).round().max(1.0) as usize
    }

    /// Bilinear value of channel `c` alone at a continuous point, as [`Level::bilinear`]:
    /// a third of the work where one channel is wanted.
    pub fn bilinear_channel(&self, p: [f64; 2], c: usize) -> f32 {
        bilinear_plane(&self.planes[c], self.width, self.height, p)
    }

    /// Bilinear value at a continuous point (pixel centres at +0.5), clamped to the image.
    pub fn bilinear(&self, p: [f64; 2]) -> [f32; 3] {
        std::array::from_fn(|c| self.bilinear_channel(p, c))
    }
}

/// Bilinear value of a row-major `width × height` plane at a continuous point (pixel
/// centres at +0.5), clamped to the plane.
pub(super) fn bilinear_plane(plane: &[f32], width: usize, height: usize, p: [f64; 2]) -> f32 {
    let x = (p[0] - 0.5).clamp(0.0, (width - 1) as f64);
    let y = (p[1] - 0.5).clamp(0.0, (height - 1) as f64);
    // Truncation is the floor here (both are clamped to 0 or more), and unlike `floor` it
    // needs no call into the maths library on x86-64's baseline instruction set.
    let (x0, y0) = (x as usize, y as usize);
    let (x1, y1) = ((x0 + 1).min(width - 1), (y0 + 1).min(height - 1));
    let (fx, fy) = ((x - x0 as f64) as f32, (y - y0 as f64) as f32);
    let top = plane[y0 * width + x0] * (1.0 - fx) + plane[y0 * width + x1] * fx;
    let bottom = plane[y1 * width + x0] * (1.0 - fx) + plane[y1 * width + x1] * fx;
    top * (1.0 - fy) + bottom * fy
}
