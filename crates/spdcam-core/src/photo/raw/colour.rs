//! A raw file's own colour calibration, read the DNG way (Adobe, *Digital Negative
//! Specification* 1.6, chapter 6, "Mapping Camera Color Space to CIE XYZ Space"): one or two
//! `ColorMatrix` tags, each mapping CIE XYZ to the camera's raw RGB under its calibration
//! illuminant, interpolated linearly in inverse colour temperature (mired) at the colour
//! temperature of the photo's own neutral, found by iteration.
//!
//! spdcam uses it twice: the light's chromaticity is the camera's reading of a spectrally
//! flat patch taken back to XYZ ([`RawColour::light_xy`]), and the patches are developed to
//! white-balanced sRGB as a raw converter does ([`RawColour::development`]).

use crate::colorimetry;
use crate::error::{Error, Result};
use nalgebra::{Matrix3, Vector3};
use serde::Serialize;

/// One `ColorMatrix` of a raw file: XYZ → camera raw RGB under its calibration illuminant.
#[derive(Debug, Clone, PartialEq)]
pub struct CalibratedMatrix {
    /// The calibration illuminant as the file names it (`A`, `D65`, …).
    pub illuminant: String,
    /// Its correlated colour temperature, kelvin.
    pub cct_k: f64,
    /// XYZ → camera RGB.
    pub xyz_to_camera: Matrix3<f64>,
}

/// The colour calibration a raw file carries: its matrices (one or two, by calibration
/// illuminant) and the camera's neutral as shot, when the file gives one.
#[derive(Debug, Clone, PartialEq)]
pub struct RawColour {
    /// The matrices, ordered by colour temperature (warmest first).
    pub matrices: Vec<CalibratedMatrix>,
    /// The camera's own estimate of a neutral's raw RGB (`AsShotNeutral`), G = 1.
    pub as_shot_neutral: Option<[f64; 3]>,
}

/// What was used to take a photo's raw values to colour, for `--json` and the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RawColourUse {
    /// The calibration illuminants of the file's matrices, e.g. `["A", "D65"]`.
    pub matrices: Vec<String>,
    /// The weight of the warmest matrix in the interpolation (1 with a single matrix).
    pub warm_weight: f64,
    /// The neutral's colour temperature the matrices were interpolated at, kelvin.
    pub neutral_cct_k: f64,
}

/// Iterations of the neutral ↔ matrix fixed point (the DNG SDK stops within a few).
const NEUTRAL_ITERATIONS: usize = 30;
/// Colour-temperature range the interpolation is evaluated in (the DNG SDK's limits).
const CCT_RANGE_K: (f64, f64) = (2000.0, 50_000.0);

/// Bradford cone response matrix (Lam 1985, as tabulated by Lindbloom and in CIE 160:2004):
/// XYZ → the sharpened cone space where white balance is a diagonal scaling.
const BRADFORD: [[f64; 3]; 3] = [
    [0.8951, 0.2664, -0.1614],
    [-0.7502, 1.7135, 0.0367],
    [0.0389, -0.0685, 1.0296],
];

impl RawColour {
    /// The calibration from `matrices` (XYZ → camera, with their illuminants' names and
    /// colour temperatures); refused when there is none or one cannot be inverted.
    pub fn new(
        mut matrices: Vec<CalibratedMatrix>,
        as_shot_neutral: Option<[f64; 3]>,
    ) -> Result<RawColour> {
        if matrices.is_empty() {
            return Err(Error::invalid(
                "the raw file carries no colour matrix, so its values cannot be taken to \
                 colour; develop it to a JPEG or TIFF in a raw converter and give spdcam that",
            ));
        }
        if let Some(m) = matrices
            .iter()
            .find(|m| m.xyz_to_camera.try_inverse().is_none() || !m.cct_k.is_finite())
        {
            return Err(Error::invalid(format!(
                "the raw file's colour matrix for illuminant {} cannot be inverted",
                m.illuminant
            )));
        }
        matrices.sort_by(|a, b| a.cct_k.total_cmp(&b.cct_k));
        let as_shot_neutral =
            as_shot_neutral.filter(|n| n.iter().all(|v| v.is_finite() && *v > 0.0));
        Ok(RawColour {
            matrices,
            as_shot_neutral,
        })
    }

    /// The XYZ → camera matrix at colour temperature `cct_k` (DNG 1.6 ch. 6: linear in
    /// mired between the two calibration illuminants, the nearer one beyond them) and the
    /// warmest matrix's weight.
    fn xyz_to_camera_at(&self, cct_k: f64) -> (Matrix3<f64>, f64) {
        let first = &self.matrices[0];
        let Some(second) = self.matrices.last().filter(|m| m.cct_k > first.cct_k) else {
            return (first.xyz_to_camera, 1.0);
        };
        let mired = 1e6 / cct_k.clamp(CCT_RANGE_K.0, CCT_RANGE_K.1);
        let (m1, m2) = (1e6 / first.cct_k, 1e6 / second.cct_k);
        let g = ((mired - m2) / (m1 - m2)).clamp(0.0, 1.0);
        (
            first.xyz_to_camera * g + second.xyz_to_camera * (1.0 - g),
            g,
        )
    }

    /// The camera → XYZ matrix for a photo whose neutral (a spectrally flat surface's raw
    /// RGB, any scale) is `neutral`, with how it was made. The neutral's chromaticity and
    /// the matrix depend on each other; both are found by fixed-point iteration from D50,
    /// as the DNG SDK does.
    pub fn camera_to_xyz(&self, neutral: [f64; 3]) -> Result<(Matrix3<f64>, RawColourUse)> {
        if !neutral.iter().all(|v| v.is_finite() && *v > 0.0) {
            return Err(Error::invalid(
                "the photo's neutral has a channel at or below zero; no patch holds a \
                 usable grey",
            ));
        }
        let n = Vector3::from(neutral);
        let mut cct_k = 5003.0;
        let mut used = self.xyz_to_camera_at(cct_k);
        for _ in 0..NEUTRAL_ITERATIONS {
            let inverse = used.0.try_inverse().ok_or_else(|| {
                Error::invalid("the interpolated colour matrix cannot be inverted")
            })?;
            let xyz = inverse * n;
            let xy = colorimetry::xyz_to_xy([xyz[0], xyz[1], xyz[2]]);
            let next = match colorimetry::uv_to_cct_duv(colorimetry::xy_to_uv1960(xy)) {
                Ok((t, _)) if t.is_finite() => t.clamp(CCT_RANGE_K.0, CCT_RANGE_K.1),
                _ => break,
            };
            let settled = (1e6 / next - 1e6 / cct_k).abs() < 0.01;
            cct_k = next;
            used = self.xyz_to_camera_at(cct_k);
            if settled {
                break;
            }
        }
        let inverse = used
            .0
            .try_inverse()
            .ok_or_else(|| Error::invalid("the interpolated colour matrix cannot be inverted"))?;
        Ok((
            inverse,
            RawColourUse {
                matrices: self.matrices.iter().map(|m| m.illuminant.clone()).collect(),
                warm_weight: used.1,
                neutral_cct_k: cct_k,
            },
        ))
    }

    /// The CIE 1931 xy chromaticity of the light that made a spectrally flat surface read
    /// `neutral` (raw RGB), through the file's own matrices.
    pub fn light_xy(&self, neutral: [f64; 3]) -> Result<[f64; 2]> {
        let (to_xyz, _) = self.camera_to_xyz(neutral)?;
        let xyz = to_xyz * Vector3::from(neutral);
        if !(xyz[1] > 0.0 && xyz.iter().all(|v| v.is_finite())) {
            return Err(Error::invalid(
                "the file's colour matrix takes the photo's neutral to no colour",
            ));
        }
        Ok(colorimetry::xyz_to_xy([xyz[0], xyz[1], xyz[2]]))
    }

    /// Camera raw RGB → linear sRGB (D65) white-balanced for the light whose neutral is
    /// `neutral`: the file's matrix to XYZ, Bradford adaptation from the neutral's white to
    /// D65, then IEC 61966-2-1's XYZ → linear sRGB. Scaled so that the neutral itself maps
    /// to equal channels of its own green value: what a raw converter's "as shot" rendering
    /// does before its tone curve.
    pub fn development(&self, neutral: [f64; 3]) -> Result<(Matrix3<f64>, RawColourUse)> {
        let (to_xyz, used) = self.camera_to_xyz(neutral)?;
        let white = to_xyz * Vector3::from(neutral);
        let d65 = colorimetry::xy_to_xyz(D65_XY, 1.0);
        let bradford = Matrix3::from_row_slice(&BRADFORD.concat());
        let inverse_bradford = bradford
            .try_inverse()
            .expect("the Bradford matrix is invertible");
        let source = bradford * white;
        let target = bradford * Vector3::from(d65);
        if !source.iter().all(|v| v.is_finite() && *v > 0.0) {
            return Err(Error::invalid(
                "the photo's neutral lies outside the colours a light can have",
            ));
        }
        let scale = Matrix3::from_diagonal(&target.component_div(&source));
        let to_srgb = crate::camera::colour::xyz_to_srgb_matrix();
        let m = to_srgb * inverse_bradford * scale * bradford * to_xyz;
        // The neutral keeps its green level, so exposure reads the same before and after.
        let grey = m * Vector3::from(neutral);
        let norm = neutral[1] / grey[1];
        Ok((m * norm, used))
    }
}

/// CIE D65's chromaticity (CIE 15:2018, table 11.3, 2° observer).
const D65_XY: [f64; 2] = [0.31272, 0.32903];

/// The colour temperature (kelvin) of a DNG/EXIF `LightSource` code (DNG 1.6 table
/// "CalibrationIlluminant"; EXIF 2.32 `LightSource`), for the codes whose illuminant has
/// one; `None` for "unknown" and "other".
pub fn illuminant_cct(code: u16) -> Option<(&'static str, f64)> {
    Some(match code {
        1 | 9 | 18 => ("daylight", 5500.0),
        2 | 14 => ("cool white fluorescent", 4150.0),
        3 | 17 | 24 => ("A", 2856.0),
        4 => ("flash", 5500.0),
        10 => ("cloudy", 6500.0),
        11 => ("shade", 7500.0),
        12 => ("daylight fluorescent", 6430.0),
        13 => ("day white fluorescent", 5000.0),
        15 => ("white fluorescent", 3450.0),
        16 => ("warm white fluorescent", 2940.0),
        19 => ("C", 6774.0),
        20 => ("D55", 5503.0),
        21 => ("D65", 6504.0),
        22 => ("D75", 7504.0),
        23 => ("D50", 5003.0),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A made-up camera whose raw RGB is linear sRGB under A (matrix 1) and a slightly
    /// different mix under D65 (matrix 2).
    fn two_matrices() -> RawColour {
        let srgb_to_xyz = crate::camera::colour::xyz_to_srgb_matrix()
            .try_inverse()
            .unwrap();
        let xyz_to_srgb = srgb_to_xyz.try_inverse().unwrap();
        let other = Matrix3::new(1.1, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.9) * xyz_to_srgb;
        RawColour::new(
            vec![
                CalibratedMatrix {
                    illuminant: "D65".into(),
                    cct_k: 6504.0,
                    xyz_to_camera: other,
                },
                CalibratedMatrix {
                    illuminant: "A".into(),
                    cct_k: 2856.0,
                    xyz_to_camera: xyz_to_srgb,
                },
            ],
            None,
        )
        .unwrap()
    }

    #[test]
    fn the_interpolation_is_linear_in_mired_and_clamped_beyond_the_illuminants() {
        let colour = two_matrices();
        assert_eq!(colour.matrices[0].illuminant, "A");
        // Halfway in mired between 2856 K (350.1) and 6504 K (153.8): 251.9 mired.
        let halfway = 1e6 / ((1e6 / 2856.0 + 1e6 / 6504.0) / 2.0);
        let (m, g) = colour.xyz_to_camera_at(halfway);
        assert!((g - 0.5).abs() < 1e-12, "{g}");
        let expected = (colour.matrices[0].xyz_to_camera + colour.matrices[1].xyz_to_camera) / 2.0;
        assert!((m - expected).abs().max() < 1e-12);
        assert_eq!(colour.xyz_to_camera_at(2000.0).1, 1.0);
        assert_eq!(colour.xyz_to_camera_at(20_000.0).1, 0.0);
    }

    #[test]
    fn a_neutral_under_a_reads_as_a_and_develops_to_grey() {
        let colour = two_matrices();
        // Under A the camera is linear sRGB: the neutral is A's XYZ in linear sRGB.
        let a_xy = [0.44757, 0.40745];
        let a = colorimetry::xyz_to_linear_srgb(colorimetry::xy_to_xyz(a_xy, 1.0));
        let xy = colour.light_xy(a).unwrap();
        assert!(
            (xy[0] - a_xy[0]).abs() < 1e-4 && (xy[1] - a_xy[1]).abs() < 1e-4,
            "{xy:?}"
        );
        let (m, used) = colour.development(a).unwrap();
        assert!((used.neutral_cct_k - 2856.0).abs() < 15.0, "{used:?}");
        assert!(used.warm_weight > 0.99, "{used:?}");
        let grey = m * Vector3::from(a);
        // Neutral up to the rounding of D65's chromaticity in the sRGB matrix.
        assert!((grey[0] / grey[1] - 1.0).abs() < 1e-3 && (grey[2] / grey[1] - 1.0).abs() < 1e-3);
        assert!((grey[1] - a[1]).abs() < 1e-12);
    }

    #[test]
    fn a_file_without_matrices_or_with_a_singular_one_is_refused() {
        let e = RawColour::new(Vec::new(), None).unwrap_err().to_string();
        assert!(
            e.contains("no colour matrix") && e.contains("raw converter"),
            "{e}"
        );
        let singular = CalibratedMatrix {
            illuminant: "D65".into(),
            cct_k: 6504.0,
            xyz_to_camera: Matrix3::zeros(),
        };
        let e = RawColour::new(vec![singular], None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("cannot be inverted"), "{e}");
        let e = two_matrices()
            .light_xy([1.0, 0.0, 1.0])
            .unwrap_err()
            .to_string();
        assert!(e.contains("neutral"), "{e}");
    }

    #[test]
    fn calibration_illuminant_codes_have_their_colour_temperatures() {
        assert_eq!(illuminant_cct(17), Some(("A", 2856.0)));
        assert_eq!(illuminant_cct(21), Some(("D65", 6504.0)));
        assert_eq!(illuminant_cct(0), None);
        assert_eq!(illuminant_cct(255), None);
    }
}
