//! Image buffers that pass between the camera stages: a Bayer mosaic and a planar RGB image.

use serde::{Deserialize, Serialize};

/// Bayer colour-filter layouts, named by the top-left 2×2 block read row by row.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum CfaPattern {
    /// Red, green / green, blue.
    Rggb,
    /// Blue, green / green, red.
    Bggr,
    /// Green, red / blue, green.
    Grbg,
    /// Green, blue / red, green.
    Gbrg,
}

impl CfaPattern {
    /// All four layouts.
    pub const ALL: [CfaPattern; 4] = [
        CfaPattern::Rggb,
        CfaPattern::Bggr,
        CfaPattern::Grbg,
        CfaPattern::Gbrg,
    ];

    /// The channel (0 = R, 1 = G, 2 = B) the filter at pixel (`x`, `y`) passes.
    #[inline]
    pub fn channel_at(self, x: usize, y: usize) -> usize {
        let block = match self {
            CfaPattern::Rggb => [0, 1, 1, 2],
            CfaPattern::Bggr => [2, 1, 1, 0],
            CfaPattern::Grbg => [1, 0, 2, 1],
            CfaPattern::Gbrg => [1, 2, 0, 1],
        };
        block[(y & 1) * 2 + (x & 1)]
    }
}

impl std::str::FromStr for CfaPattern {
    type Err = crate::Error;

    /// Parses `RGGB`, `BGGR`, `GRBG` or `GBRG` (any case).
    fn from_str(text: &str) -> crate::Result<CfaPattern> {
        match text.to_ascii_uppercase().as_str() {
            "RGGB" => Ok(CfaPattern::Rggb),
            "BGGR" => Ok(CfaPattern::Bggr),
            "GRBG" => Ok(CfaPattern::Grbg),
            "GBRG" => Ok(CfaPattern::Gbrg),
            _ => Err(crate::Error::UnknownName {
                kind: "Bayer pattern",
                name: text.to_string(),
                valid: "rggb, bggr, grbg, gbrg".into(),
            }),
        }
    }
}

/// A single-channel raw image behind a Bayer filter, row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct Mosaic {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// The colour filter array: which channel each pixel sees.
    pub pattern: CfaPattern,
    /// `width × height` values, row-major (normalised raw signal, about 0…1).
    pub data: Vec<f32>,
}

impl Mosaic {
    /// A mosaic of zeros.
    pub fn new(width: usize, height: usize, pattern: CfaPattern) -> Mosaic {
        Mosaic {
            width,
            height,
            pattern,
            data: vec![0.0; width * height],
        }
    }

    /// The value at (`x`, `y`).
    #[inline]
    pub fn get(&self, x: usize, y: usize) -> f32 {
        self.data[y * self.width + x]
    }

    /// The mosaic a three-channel image gives behind this filter (each pixel keeps one channel).
    pub fn from_rgb(image: &RgbImage, pattern: CfaPattern) -> Mosaic {
        let mut m = Mosaic::new(image.width, image.height, pattern);
        for y in 0..image.height {
            for x in 0..image.width {
                let i = y * image.width + x;
                m.data[i] = image.planes[pattern.channel_at(x, y)][i];
            }
        }
        m
    }
}

/// A three-channel image stored as three row-major planes (R, G, B).
#[derive(Debug, Clone, PartialEq)]
pub struct RgbImage {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// R, G and B, each `width × height` values row-major (about 0…1: linear camera
    /// signal before the colour stage, encoded sRGB after it).
    pub planes: [Vec<f32>; 3],
}

impl RgbImage {
    /// An image of zeros.
    pub fn new(width: usize, height: usize) -> RgbImage {
        let n = width * height;
        RgbImage {
            width,
            height,
            planes: [vec![0.0; n], vec![0.0; n], vec![0.0; n]],
        }
    }

    /// The (R, G, B) value at (`x`, `y`).
    #[inline]
    pub fn pixel(&self, x: usize, y: usize) -> [f32; 3] {
        let i = y * self.width + x;
        [self.planes[0][i], self.planes[1][i], self.planes[2][i]]
    }

    /// Number of pixels.
    pub fn len(&self) -> usize {
        self.width * self.height
    }

    /// Whether the image has no pixels.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Separable Gaussian blur of one plane (row-major, `width` wide) in place, edges clamped,
/// the kernel truncated at ⌈3σ⌉ (at least 1) and normalised to sum 1; `scratch` is reused
/// between calls. Used by the lens's point spread and by edge-based white balance.
pub fn gaussian_blur(
    plane: &mut [f32],
    width: usize,
    height: usize,
    sigma: f64,
    scratch: &mut Vec<f32>,
) {
    let radius = (3.0 * sigma).ceil().max(1.0) as isize;
    let kernel: Vec<f32> = (-radius..=radius)
        .map(|i| (-(i * i) as f64 / (2.0 * sigma * sigma)).exp() as f32)
        .collect();
    let sum: f32 = kernel.iter().sum();
    let kernel: Vec<f32> = kernel.iter().map(|k| k / sum).collect();
    let clamp = |v: isize, n: usize| v.clamp(0, n as isize - 1) as usize;
    scratch.clear();
    scratch.resize(plane.len(), 0.0);
    for y in 0..height {
        for x in 0..width {
            scratch[y * width + x] = kernel
                .iter()
                .enumerate()
                .map(|(k, w)| w * plane[y * width + clamp(x as isize + k as isize - radius, width)])
                .sum();
        }
    }
    for y in 0..height {
        for x in 0..width {
            plane[y * width + x] = kernel
                .iter()
                .enumerate()
                .map(|(k, w)| {
                    w * scratch[clamp(y as isize + k as isize - radius, height) * width + x]
                })
                .sum();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_pattern_has_two_greens_per_block() {
        for p in CfaPattern::ALL {
            let block: Vec<usize> = (0..4).map(|k| p.channel_at(k % 2, k / 2)).collect();
            assert_eq!(block.iter().filter(|&&c| c == 1).count(), 2, "{p:?}");
            assert_eq!(block.iter().filter(|&&c| c == 0).count(), 1);
            assert_eq!(format!("{p:?}").parse::<CfaPattern>().unwrap(), p);
        }
        assert_eq!(CfaPattern::Rggb.channel_at(0, 0), 0);
        assert_eq!(CfaPattern::Rggb.channel_at(1, 1), 2);
        assert_eq!(CfaPattern::Gbrg.channel_at(1, 0), 2);
    }
}
