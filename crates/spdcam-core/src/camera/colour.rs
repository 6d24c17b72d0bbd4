//! Colour (thesis 3.1.6): a 3×3 colour-correction matrix from white-balanced camera RGB to
//! CIE XYZ, fitted once under D65 on the chart and applied under every light; then XYZ →
//! linear sRGB (IEC 61966-2-1), the sRGB transfer curve, and quantisation.

use crate::colorimetry;
use crate::error::{Error, Result};
use crate::raster::RgbImage;
use nalgebra::Matrix3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::sync::OnceLock;

/// Output settings of the colour stage.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct ColourConfig {
    /// Apply the D65-fitted colour-correction matrix; off, the white-balanced camera RGB is
    /// encoded as if it were linear sRGB.
    pub correction: bool,
    /// Output bits per channel: 8 or 16.
    pub bit_depth: u32,
}

impl Default for ColourConfig {
    fn default() -> Self {
        ColourConfig {
            correction: true,
            bit_depth: 8,
        }
    }
}

/// Least-squares colour-correction matrix `T = XYZ·RGBᵀ(RGB·RGBᵀ)⁻¹` (thesis 3.1.6) mapping
/// camera RGB to XYZ over the given patch pairs.
pub fn fit_correction_matrix(rgb: &[[f64; 3]], xyz: &[[f64; 3]]) -> Result<Matrix3<f64>> {
    if rgb.len() != xyz.len() || rgb.len() < 3 {
        return Err(Error::invalid(format!(
            "a colour-correction fit needs at least 3 patch pairs, got {} RGB and {} XYZ",
            rgb.len(),
            xyz.len()
        )));
    }
    let mut rrt = Matrix3::<f64>::zeros();
    let mut xrt = Matrix3::<f64>::zeros();
    for (r, x) in rgb.iter().zip(xyz) {
        for i in 0..3 {
            for j in 0..3 {
                rrt[(i, j)] += r[i] * r[j];
                xrt[(i, j)] += x[i] * r[j];
            }
        }
    }
    let inv = rrt.try_inverse().ok_or_else(|| {
        Error::invalid(
            "the chart's camera responses under D65 are degenerate; cannot fit a colour matrix",
        )
    })?;
    Ok(xrt * inv)
}

/// The XYZ → linear sRGB matrix, read off the colorimetry module's conversion.
pub fn xyz_to_srgb_matrix() -> Matrix3<f64> {
    let mut m = Matrix3::<f64>::zeros();
    for j in 0..3 {
        let mut unit = [0.0; 3];
        unit[j] = 1.0;
        let col = colorimetry::xyz_to_linear_srgb(unit);
        for i in 0..3 {
            m[(i, j)] = col[i];
        }
    }
    m
}

/// Entries of the sRGB encoding table: linear values 0…1 in steps of 1/16384. Linear
/// interpolation in it is within 1e-6 of the exact curve, far below a 16-bit step.
const ENCODE_TABLE_STEPS: usize = 16384;

/// The sRGB encoding table, made once and shared by every camera: a camera pool of
/// thousands (`generate --randomise camera`) would otherwise hold 64 kB of it per camera.
fn encode_table() -> &'static [f32] {
    static TABLE: OnceLock<Vec<f32>> = OnceLock::new();
    TABLE.get_or_init(|| {
        (0..=ENCODE_TABLE_STEPS)
            .map(|k| colorimetry::srgb_encode(k as f64 / ENCODE_TABLE_STEPS as f64) as f32)
            .collect()
    })
}

/// The sRGB transfer curve on a linear value clipped to 0…1, interpolated in the shared
/// table (within 1e-6 of [`colorimetry::srgb_encode`]): for image loops.
#[inline]
pub fn srgb_encode_fast(linear: f32) -> f32 {
    encode_from_table(encode_table(), linear)
}

#[inline]
fn encode_from_table(table: &[f32], linear: f32) -> f32 {
    let x = linear.clamp(0.0, 1.0) * ENCODE_TABLE_STEPS as f32;
    let i = (x as usize).min(ENCODE_TABLE_STEPS - 1);
    let f = x - i as f32;
    table[i] + f * (table[i + 1] - table[i])
}

/// Steps of the sRGB decoding table over encoded values 0…1: linear interpolation in it is
/// within 1e-5 of the curve, and a power per pixel and channel made the 24 MP photo bench
/// about 0.1 s slower.
const DECODE_TABLE_STEPS: usize = 4096;

/// The sRGB decoding (IEC 61966-2-1) of `encoded`, clipped to 0…1, interpolated in a table
/// made once (within 1e-5 of [`colorimetry::srgb_decode`]): for loops over pixels or
/// feature rows.
#[inline]
pub fn srgb_decode_fast(encoded: f32) -> f32 {
    static TABLE: OnceLock<Vec<f32>> = OnceLock::new();
    let table = TABLE.get_or_init(|| {
        (0..=DECODE_TABLE_STEPS)
            .map(|k| colorimetry::srgb_decode_f32(k as f32 / DECODE_TABLE_STEPS as f32))
            .collect()
    });
    let x = encoded.clamp(0.0, 1.0) * DECODE_TABLE_STEPS as f32;
    let i = (x as usize).min(DECODE_TABLE_STEPS - 1);
    table[i] + (x - i as f32) * (table[i + 1] - table[i])
}

/// Camera RGB → encoded, quantised sRGB, as one matrix, a table and a number of levels.
#[derive(Debug, Clone)]
pub struct ColourTransform {
    matrix: [[f32; 3]; 3],
    table: &'static [f32],
    levels: f32,
}

impl ColourTransform {
    /// Builds the transform: `camera_to_xyz` (None when correction is off) then XYZ → sRGB.
    pub fn new(camera_to_xyz: Option<Matrix3<f64>>, bit_depth: u32) -> Result<ColourTransform> {
        if bit_depth != 8 && bit_depth != 16 {
            return Err(Error::invalid(format!(
                "output bit depth {bit_depth} is not 8 or 16"
            )));
        }
        let m = match camera_to_xyz {
            Some(t) => xyz_to_srgb_matrix() * t,
            None => Matrix3::identity(),
        };
        let matrix = std::array::from_fn(|i| std::array::from_fn(|j| m[(i, j)] as f32));
        Ok(ColourTransform {
            matrix,
            table: encode_table(),
            levels: ((1u32 << bit_depth) - 1) as f32,
        })
    }

    /// Linear sRGB of a camera RGB triple (unclipped).
    #[inline]
    pub fn to_linear_srgb(&self, rgb: [f32; 3]) -> [f32; 3] {
        let m = &self.matrix;
        std::array::from_fn(|i| m[i][0] * rgb[0] + m[i][1] * rgb[1] + m[i][2] * rgb[2])
    }

    /// The sRGB transfer curve on a clipped linear value, from the table.
    #[inline]
    pub fn encode(&self, linear: f32) -> f32 {
        encode_from_table(self.table, linear)
    }

    /// Quantises an encoded value to the output bit depth (result still on 0…1).
    #[inline(always)]
    pub fn quantise(&self, encoded: f32) -> f32 {
        // `encoded` is on 0…1: adding ½ and truncating rounds without a libm call (through
        // i32, which vector instructions convert to directly; the same for these values).
        ((encoded * self.levels + 0.5) as i32) as f32 / self.levels
    }

    /// Camera RGB → encoded sRGB, unquantised (the patch-level path).
    #[inline]
    pub fn encode_pixel(&self, rgb: [f32; 3]) -> [f32; 3] {
        self.to_linear_srgb(rgb).map(|v| self.encode(v))
    }

    /// Transforms a white-balanced camera image in place into quantised encoded sRGB (0…1).
    pub fn apply(&self, image: &mut RgbImage) {
        let [r, g, b] = &mut image.planes;
        const CHUNK: usize = 16384;
        if r.len() > 200_000 {
            r.par_chunks_mut(CHUNK)
                .zip(g.par_chunks_mut(CHUNK))
                .zip(b.par_chunks_mut(CHUNK))
                .for_each(|((r, g), b)| self.apply_planes_widest(r, g, b));
        } else {
            self.apply_planes_widest(r, g, b);
        }
    }

    /// [`ColourTransform::apply_planes`] compiled for AVX2 where the CPU has it (eight pixels
    /// per instruction, table reads gathered). Both builds do the same IEEE operations, so
    /// their results are identical.
    fn apply_planes_widest(&self, r: &mut [f32], g: &mut [f32], b: &mut [f32]) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            #[target_feature(enable = "avx2")]
            fn avx2(t: &ColourTransform, r: &mut [f32], g: &mut [f32], b: &mut [f32]) {
                t.apply_planes(r, g, b)
            }
            // SAFETY: the CPU supports AVX2, as checked just above.
            return unsafe { avx2(self, r, g, b) };
        }
        self.apply_planes(r, g, b)
    }

    /// The per-pixel work of [`ColourTransform::apply`] on three equally long plane slices,
    /// [`COLOUR_BLOCK`] pixels at a time in separate passes: the matrix, the table position,
    /// the table reads, the interpolation and quantisation. Every pass but the reads is plain
    /// arithmetic over arrays, which the compiler vectorises; the result is the same, bit for
    /// bit, as [`ColourTransform::encode_pixel`] followed by [`ColourTransform::quantise`].
    #[inline(always)]
    fn apply_planes(&self, r: &mut [f32], g: &mut [f32], b: &mut [f32]) {
        let n = r.len().min(g.len()).min(b.len());
        let m = &self.matrix;
        let steps = ENCODE_TABLE_STEPS as f32;
        let mut position = [[0.0f32; COLOUR_BLOCK]; 3];
        let mut index = [[0i32; COLOUR_BLOCK]; 3];
        let mut low = [[0.0f32; COLOUR_BLOCK]; 3];
        let mut high = [[0.0f32; COLOUR_BLOCK]; 3];
        for start in (0..n).step_by(COLOUR_BLOCK) {
            let len = COLOUR_BLOCK.min(n - start);
            let planes = [
                &mut r[start..start + len],
                &mut g[start..start + len],
                &mut b[start..start + len],
            ];
            for c in 0..3 {
                for i in 0..len {
                    let rgb = [planes[0][i], planes[1][i], planes[2][i]];
                    let linear = m[c][0] * rgb[0] + m[c][1] * rgb[1] + m[c][2] * rgb[2];
                    position[c][i] = linear.clamp(0.0, 1.0) * steps;
                    // Non-negative, so truncating to i32 is the table index `encode` takes.
                    index[c][i] = (position[c][i] as i32).min(ENCODE_TABLE_STEPS as i32 - 1);
                }
            }
            for c in 0..3 {
                for i in 0..len {
                    let k = index[c][i] as usize;
                    low[c][i] = self.table[k];
                    high[c][i] = self.table[k + 1];
                }
            }
            for (c, plane) in planes.into_iter().enumerate() {
                for (i, v) in plane.iter_mut().enumerate() {
                    let f = position[c][i] - index[c][i] as f32;
                    *v = self.quantise(low[c][i] + f * (high[c][i] - low[c][i]));
                }
            }
        }
    }
}

/// Pixels the colour stage transforms per pass.
const COLOUR_BLOCK: usize = 256;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_recovers_an_exact_linear_map() {
        let t = Matrix3::new(0.5, 0.3, 0.1, 0.2, 0.7, 0.1, 0.0, 0.1, 0.9);
        let rgb: Vec<[f64; 3]> = (0..10)
            .map(|i| {
                [
                    0.1 * i as f64,
                    0.05 * (i * i % 7) as f64,
                    0.3 + 0.02 * i as f64,
                ]
            })
            .collect();
        let xyz: Vec<[f64; 3]> = rgb
            .iter()
            .map(|r| {
                let v = t * nalgebra::Vector3::from(*r);
                [v[0], v[1], v[2]]
            })
            .collect();
        let fit = fit_correction_matrix(&rgb, &xyz).unwrap();
        assert!((fit - t).abs().max() < 1e-12);
        assert!(fit_correction_matrix(&rgb[..2], &xyz[..2]).is_err());
    }

    #[test]
    fn table_encoding_matches_the_curve() {
        let ct = ColourTransform::new(None, 16).unwrap();
        for k in 0..=1000 {
            let x = k as f64 / 1000.0;
            let exact = colorimetry::srgb_encode(x);
            assert!((ct.encode(x as f32) as f64 - exact).abs() < 2e-6, "{x}");
        }
        assert_eq!(ct.encode(-0.5), 0.0);
        assert_eq!(ct.encode(2.0), 1.0);
        assert!(ColourTransform::new(None, 12).is_err());
    }

    #[test]
    fn image_transform_is_the_pixel_transform_bit_for_bit() {
        let m = Matrix3::new(1.6, -0.4, -0.1, -0.2, 1.3, -0.1, 0.0, -0.3, 1.4);
        for depth in [8, 16] {
            let ct = ColourTransform::new(Some(m), depth).unwrap();
            // 300,000 pixels (the parallel path) over and beyond 0…1, with exact table nodes.
            let mut image = RgbImage::new(600, 500);
            for (c, plane) in image.planes.iter_mut().enumerate() {
                for (i, v) in plane.iter_mut().enumerate() {
                    let k = (i * (7 + 2 * c) + 3 * c) % 20_011;
                    *v = if k.is_multiple_of(97) {
                        (k % 16_385) as f32 / ENCODE_TABLE_STEPS as f32
                    } else {
                        k as f32 / 16_000.0 - 0.1
                    };
                }
            }
            let expected: Vec<[f32; 3]> = (0..image.planes[0].len())
                .map(|i| {
                    let rgb = [image.planes[0][i], image.planes[1][i], image.planes[2][i]];
                    ct.encode_pixel(rgb).map(|v| ct.quantise(v))
                })
                .collect();
            ct.apply(&mut image);
            for (i, e) in expected.iter().enumerate() {
                let got = [image.planes[0][i], image.planes[1][i], image.planes[2][i]];
                assert_eq!(got.map(f32::to_bits), e.map(f32::to_bits), "pixel {i}");
            }
        }
    }
}
