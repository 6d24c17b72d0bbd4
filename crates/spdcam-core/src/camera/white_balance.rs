//! White balance (thesis 3.1.4): estimate the light's colour from image statistics and
//! divide it out with per-channel gains (green keeps gain 1).

use crate::error::{Error, Result};
use crate::limits;
use crate::raster::RgbImage;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// White-balance algorithms.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum WhiteBalance {
    /// No white balance.
    None,
    /// Grey world (Buchsbaum 1980): the mean of each channel is grey.
    GreyWorld,
    /// White patch / max-RGB (Land & McCann 1971): the maximum of each channel is white.
    WhitePatch,
    /// Shades of grey (Finlayson & Trezzi 2004): the Minkowski p-norm of each channel is grey;
    /// p = 6 is the paper's best and the thesis's choice.
    ShadesOfGrey {
        /// The norm's exponent (≥ 1; 1 is grey world, ∞ white patch).
        p: f64,
    },
    /// Grey edge (van de Weijer, Gevers & Gijsenij 2007): the Minkowski p-norm of the
    /// gradient magnitude, after Gaussian smoothing with `sigma` px, is grey.
    GreyEdge {
        /// The norm's exponent (≥ 1).
        p: f64,
        /// The Gaussian smoothing's standard deviation (pixels).
        sigma: f64,
    },
}

impl Default for WhiteBalance {
    fn default() -> Self {
        WhiteBalance::ShadesOfGrey { p: 6.0 }
    }
}

/// Region statistics a chart gives, for white balance without an image: each region's
/// area in pixels and the length of the boundary between each pair of touching regions.
#[derive(Debug, Clone, Default)]
pub struct RegionGeometry {
    /// Each region's area (pixels).
    pub areas: Vec<f64>,
    /// (region a, region b, length of their boundary in pixels) for each touching pair.
    pub boundaries: Vec<(usize, usize, f64)>,
}

impl RegionGeometry {
    /// Counts areas and boundary lengths from a per-pixel region map.
    pub fn from_region_map(map: &[u16], width: usize, regions: usize) -> RegionGeometry {
        let mut areas = vec![0.0; regions];
        let mut pairs = std::collections::BTreeMap::new();
        let height = map.len() / width;
        for y in 0..height {
            for x in 0..width {
                let r = map[y * width + x] as usize;
                areas[r] += 1.0;
                let mut touch = |o: usize| {
                    if o != r {
                        *pairs.entry((r.min(o), r.max(o))).or_insert(0.0) += 1.0;
                    }
                };
                if x + 1 < width {
                    touch(map[y * width + x + 1] as usize);
                }
                if y + 1 < height {
                    touch(map[(y + 1) * width + x] as usize);
                }
            }
        }
        RegionGeometry {
            areas,
            boundaries: pairs.into_iter().map(|((a, b), l)| (a, b, l)).collect(),
        }
    }
}

impl std::str::FromStr for WhiteBalance {
    type Err = Error;

    /// Parses `none`, `grey-world`, `white-patch`, `shades-of-grey[:p]`, `grey-edge[:p[:sigma]]`.
    fn from_str(text: &str) -> Result<WhiteBalance> {
        let mut parts = text.split(':');
        let name = parts
            .next()
            .unwrap_or("")
            .to_ascii_lowercase()
            .replace('_', "-");
        let mut number = |default: f64| -> Result<f64> {
            match parts.next() {
                None => Ok(default),
                Some(s) => s.parse::<f64>().ok().filter(|v| *v > 0.0).ok_or_else(|| {
                    Error::invalid(format!(
                        "white balance '{text}': '{s}' is not a positive number"
                    ))
                }),
            }
        };
        let wb = match name.as_str() {
            "none" | "off" => WhiteBalance::None,
            "grey-world" | "gray-world" => WhiteBalance::GreyWorld,
            "white-patch" | "max-rgb" => WhiteBalance::WhitePatch,
            "shades-of-grey" | "shades-of-gray" => WhiteBalance::ShadesOfGrey { p: number(6.0)? },
            "grey-edge" | "gray-edge" => {
                let p = number(6.0)?;
                let sigma = number(1.0)?;
                limits::FILTER_SIGMA_PX
                    .check_f64(sigma, &format!("white balance '{text}': sigma"))?;
                WhiteBalance::GreyEdge { p, sigma }
            }
            _ => {
                return Err(Error::UnknownName {
                    kind: "white balance",
                    name: text.to_string(),
                    valid:
                        "none, grey-world, white-patch, shades-of-grey[:p], grey-edge[:p[:sigma]]"
                            .into(),
                })
            }
        };
        Ok(wb)
    }
}

impl WhiteBalance {
    /// Gains that turn the estimated light colour `estimate` grey, green fixed.
    fn gains_from_estimate(estimate: [f64; 3]) -> [f32; 3] {
        let g = estimate[1];
        estimate.map(|e| {
            if e > 0.0 && g > 0.0 {
                (g / e) as f32
            } else {
                1.0
            }
        })
    }

    /// The per-channel gains this algorithm finds for `image`.
    pub fn gains(&self, image: &RgbImage) -> [f32; 3] {
        let estimate = match *self {
            WhiteBalance::None => return [1.0; 3],
            WhiteBalance::GreyWorld => image.planes.each_ref().map(|p| minkowski(p, 1.0)),
            WhiteBalance::WhitePatch => image
                .planes
                .each_ref()
                .map(|p| p.iter().cloned().fold(0.0f32, f32::max) as f64),
            WhiteBalance::ShadesOfGrey { p } => image.planes.each_ref().map(|c| minkowski(c, p)),
            WhiteBalance::GreyEdge { p, sigma } => image.planes.each_ref().map(|c| {
                let grad = gradient_magnitude(c, image.width, image.height, sigma);
                minkowski(&grad, p)
            }),
        };
        Self::gains_from_estimate(estimate)
    }

    /// The gains for an image made of flat regions with `values`, without rendering it.
    /// Grey edge uses the boundary lengths: on a straight edge the smoothed gradient of each
    /// channel is the step times one common profile, so the Minkowski sums differ between
    /// channels only through `Σ length·|step|^p` (corners aside).
    pub fn gains_for_regions(&self, values: &[[f32; 3]], geometry: &RegionGeometry) -> [f32; 3] {
        let area_norm = |p: f64| -> [f64; 3] {
            let total: f64 = geometry.areas.iter().sum();
            std::array::from_fn(|c| {
                let s: f64 = values
                    .iter()
                    .zip(&geometry.areas)
                    .map(|(v, a)| a * power(v[c].max(0.0) as f64, p))
                    .sum();
                (s / total).powf(1.0 / p)
            })
        };
        let estimate = match *self {
            WhiteBalance::None => return [1.0; 3],
            WhiteBalance::GreyWorld => area_norm(1.0),
            WhiteBalance::ShadesOfGrey { p } => area_norm(p),
            WhiteBalance::WhitePatch => std::array::from_fn(|c| {
                values
                    .iter()
                    .zip(&geometry.areas)
                    .filter(|(_, a)| **a > 0.0)
                    .map(|(v, _)| v[c] as f64)
                    .fold(0.0, f64::max)
            }),
            WhiteBalance::GreyEdge { p, .. } => std::array::from_fn(|c| {
                geometry
                    .boundaries
                    .iter()
                    .map(|&(a, b, len)| len * power((values[a][c] - values[b][c]).abs() as f64, p))
                    .sum::<f64>()
                    .powf(1.0 / p)
            }),
        };
        Self::gains_from_estimate(estimate)
    }
}

/// `x^p`, spelled out as multiplications for the usual whole powers (no libm call).
#[inline]
fn power(x: f64, p: f64) -> f64 {
    match p {
        1.0 => x,
        2.0 => x * x,
        4.0 => (x * x) * (x * x),
        6.0 => {
            let x2 = x * x;
            x2 * x2 * x2
        }
        _ => x.powf(p),
    }
}

/// Incomplete adaptation (a camera that keeps some of the light's cast, as people prefer
/// under warm light): each gain raised to the power `adaptation` (1 = full correction,
/// 0 = none).
pub fn adapt(gains: [f32; 3], adaptation: f64) -> [f32; 3] {
    if adaptation == 1.0 {
        return gains;
    }
    let a = adaptation as f32;
    gains.map(|g| if g > 0.0 { g.powf(a) } else { g })
}

/// Multiplies each channel by its gain.
pub fn apply_gains(image: &mut RgbImage, gains: [f32; 3]) {
    for (plane, g) in image.planes.iter_mut().zip(gains) {
        if g != 1.0 {
            plane.iter_mut().for_each(|v| *v *= g);
        }
    }
}

/// The Minkowski p-mean `(mean |v|^p)^(1/p)` of a channel (negative noise counts as zero).
/// Powers are taken in f32 and summed per block of 4,096 values in f64, which keeps the
/// sum exact to f32 precision and lets the compiler vectorise the inner loop.
///
/// A channel whose largest value is under 1/2 is first scaled by the power of two that
/// brings it to [1/2, 1): `v^6` of a dim image (v = 1e-8, an exposure of 1e-8) is below
/// f32's smallest number, and every channel's mean came out 0, so the white balance left
/// the image unbalanced while the colour matrix expects it balanced (a white patch of
/// 255, 255, 108). Scaling by a power of two is exact, so brighter images keep every bit.
fn minkowski(values: &[f32], p: f64) -> f64 {
    let largest = if values.len() > 200_000 {
        values.par_iter().copied().reduce(|| 0.0, f32::max)
    } else {
        values.iter().copied().fold(0.0, f32::max)
    };
    if largest > 0.0 && largest < 0.5 {
        // 2^k with largest·2^k in [1/2, 1), k at most 126 (f32's largest power of two).
        let k = (-largest.log2().floor() - 1.0).clamp(1.0, 126.0) as i32;
        let scale = 2f32.powi(k);
        let scaled: Vec<f32> = values.iter().map(|&v| v * scale).collect();
        return minkowski(&scaled, p) / scale as f64;
    }
    let n = values.len().max(1) as f64;
    let block_sum = |block: &[f32]| -> f64 {
        // Whole powers spelled out so they compile to multiplications, not a libm call.
        let s: f32 = match p {
            1.0 => block.iter().map(|&v| v.max(0.0)).sum(),
            2.0 => block.iter().map(|&v| v.max(0.0) * v.max(0.0)).sum(),
            4.0 => block
                .iter()
                .map(|&v| {
                    let x2 = v.max(0.0) * v.max(0.0);
                    x2 * x2
                })
                .sum(),
            6.0 => block
                .iter()
                .map(|&v| {
                    let x = v.max(0.0);
                    let x2 = x * x;
                    x2 * x2 * x2
                })
                .sum(),
            _ => {
                let pf = p as f32;
                block.iter().map(|&v| v.max(0.0).powf(pf)).sum()
            }
        };
        s as f64
    };
    let sum: f64 = if values.len() > 200_000 {
        values.par_chunks(4096).map(block_sum).sum()
    } else {
        values.chunks(4096).map(block_sum).sum()
    };
    (sum / n).powf(1.0 / p)
}

/// |∇(G_σ * f)| with a separable Gaussian and central differences, edges clamped.
fn gradient_magnitude(plane: &[f32], width: usize, height: usize, sigma: f64) -> Vec<f32> {
    let mut smooth = plane.to_vec();
    crate::raster::gaussian_blur(&mut smooth, width, height, sigma, &mut Vec::new());
    let clamp = |v: isize, n: usize| v.clamp(0, n as isize - 1) as usize;
    let mut out = vec![0.0f32; plane.len()];
    for y in 0..height {
        for x in 0..width {
            let at = |xx: usize, yy: usize| smooth[yy * width + xx];
            let gx =
                (at(clamp(x as isize + 1, width), y) - at(clamp(x as isize - 1, width), y)) / 2.0;
            let gy =
                (at(x, clamp(y as isize + 1, height)) - at(x, clamp(y as isize - 1, height))) / 2.0;
            out[y * width + x] = (gx * gx + gy * gy).sqrt();
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::str::FromStr;

    /// A 2×2 image: pixels (R,G,B) = (1,2,4), (3,2,0), (1,1,1), (3,3,3).
    fn tiny() -> RgbImage {
        RgbImage {
            width: 2,
            height: 2,
            planes: [
                vec![1.0, 3.0, 1.0, 3.0],
                vec![2.0, 2.0, 1.0, 3.0],
                vec![4.0, 0.0, 1.0, 3.0],
            ],
        }
    }

    fn close(a: [f32; 3], b: [f64; 3]) {
        for c in 0..3 {
            assert!((a[c] as f64 - b[c]).abs() < 1e-5, "{a:?} vs {b:?}");
        }
    }

    #[test]
    fn gains_on_a_hand_computed_image() {
        let img = tiny();
        // Means: R 2, G 2, B 2 → no correction.
        close(WhiteBalance::GreyWorld.gains(&img), [1.0, 1.0, 1.0]);
        // Maxima: R 3, G 3, B 4.
        close(WhiteBalance::WhitePatch.gains(&img), [1.0, 1.0, 0.75]);
        // p = 2: R sqrt(20/4), G sqrt(18/4), B sqrt(26/4).
        let (r, g, b) = (
            (20.0f64 / 4.0).sqrt(),
            (18.0f64 / 4.0).sqrt(),
            (26.0f64 / 4.0).sqrt(),
        );
        close(
            WhiteBalance::ShadesOfGrey { p: 2.0 }.gains(&img),
            [g / r, 1.0, g / b],
        );
        close(WhiteBalance::None.gains(&img), [1.0, 1.0, 1.0]);
    }

    #[test]
    fn a_dim_image_gets_the_gains_of_a_bright_one() {
        // Issue 39, item 15: at 1e-8 of full scale v^6 underflowed f32, every estimate was
        // 0, and the gains fell back to 1 (an unbalanced image, a yellow white patch).
        let scaled = |k: f32| {
            let mut img = tiny();
            img.planes
                .iter_mut()
                .for_each(|p| p.iter_mut().for_each(|v| *v *= k / 4.0));
            img
        };
        for wb in [
            WhiteBalance::ShadesOfGrey { p: 6.0 },
            WhiteBalance::ShadesOfGrey { p: 2.5 },
        ] {
            let bright = wb.gains(&scaled(1.0));
            assert_ne!(bright, [1.0; 3], "{wb:?}");
            for k in [0.1, 1e-8, 1e-10, 1e-30] {
                let dim = wb.gains(&scaled(k)).map(f64::from);
                close(bright, dim);
            }
        }
    }

    #[test]
    fn a_grey_scene_under_coloured_light_comes_out_grey() {
        let light = [0.8f32, 0.5, 0.2];
        let mut img = RgbImage::new(32, 32);
        for y in 0..32usize {
            for x in 0..32 {
                let grey = if (x / 8 + y / 8).is_multiple_of(2) {
                    0.3
                } else {
                    0.9
                };
                for (plane, tint) in img.planes.iter_mut().zip(light) {
                    plane[y * 32 + x] = grey * tint;
                }
            }
        }
        for wb in [
            WhiteBalance::GreyWorld,
            WhiteBalance::WhitePatch,
            WhiteBalance::ShadesOfGrey { p: 6.0 },
            WhiteBalance::GreyEdge { p: 6.0, sigma: 1.0 },
        ] {
            let gains = wb.gains(&img);
            for c in 0..3 {
                let balanced = light[c] * gains[c];
                assert!((balanced - light[1]).abs() < 1e-4, "{wb:?}: {gains:?}");
            }
        }
    }

    #[test]
    fn region_gains_match_image_gains() {
        let layout = crate::chart::Layout::grid(2, 2, 6, 2, 2);
        let map = layout.region_map();
        let values = [
            [0.2f32, 0.4, 0.1],
            [0.6, 0.5, 0.9],
            [0.3, 0.3, 0.3],
            [0.9, 0.2, 0.5],
            [0.04, 0.05, 0.03],
        ];
        let geometry = RegionGeometry::from_region_map(&map, layout.width, 5);
        let mut img = RgbImage::new(layout.width, layout.height);
        for (i, &r) in map.iter().enumerate() {
            for (plane, value) in img.planes.iter_mut().zip(values[r as usize]) {
                plane[i] = value;
            }
        }
        for wb in [
            WhiteBalance::GreyWorld,
            WhiteBalance::WhitePatch,
            WhiteBalance::ShadesOfGrey { p: 6.0 },
        ] {
            let a = wb.gains(&img);
            let b = wb.gains_for_regions(&values, &geometry);
            for c in 0..3 {
                assert!((a[c] - b[c]).abs() < 1e-4, "{wb:?}: {a:?} vs {b:?}");
            }
        }
        let a = WhiteBalance::GreyEdge { p: 6.0, sigma: 1.0 }.gains(&img);
        let b = WhiteBalance::GreyEdge { p: 6.0, sigma: 1.0 }.gains_for_regions(&values, &geometry);
        for c in 0..3 {
            assert!((a[c] / b[c] - 1.0).abs() < 0.05, "grey edge {a:?} vs {b:?}");
        }
    }

    #[test]
    fn parse_names_and_errors() {
        assert_eq!(
            WhiteBalance::from_str("shades-of-grey:4").unwrap(),
            WhiteBalance::ShadesOfGrey { p: 4.0 }
        );
        assert_eq!(
            WhiteBalance::from_str("grey-world").unwrap(),
            WhiteBalance::GreyWorld
        );
        assert!(WhiteBalance::from_str("magic").is_err());
        assert!(WhiteBalance::from_str("shades-of-grey:-1").is_err());
        // Issue 15: `grey-edge:1:1e9` ran for minutes with gigabytes.
        let e = WhiteBalance::from_str("grey-edge:1:1e9")
            .unwrap_err()
            .to_string();
        assert!(e.contains("SPDCAM_MAX_FILTER_SIGMA"), "{e}");
        assert!(WhiteBalance::from_str("grey-edge:1:2").is_ok());
    }
}
