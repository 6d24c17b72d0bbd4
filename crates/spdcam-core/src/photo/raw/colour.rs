//! A raw file's own colour calibration, read the DNG way (Adobe, *Digital Negative
//! Specification* 1.6, chapter 6, "Mapping Camera Color Space to CIE XYZ Space"): one or two
//! `ColorMatrix` tags, each mapping CIE XYZ to the camera's raw RGB under its calibration
//! illuminant, interpolated linearly in inverse colour temperature (mired) at the colour
//! temperature of the photo's own neutral, found by iteration; with the camera's own
//! `CameraCalibration` and `AnalogBalance` where the file gives them
//! (XYZ → camera = AnalogBalance · CameraCalibration · ColorMatrix), and its
//! `ForwardMatrix` for developing white-balanced colours where it gives one.
//!
//! spdcam uses it twice: the light's chromaticity is the camera's reading of a spectrally
//! flat patch taken back to XYZ ([`RawColour::light_xy`]; the DNG way finds the white from
//! the colour matrices, forward matrices or not), and the patches are developed to
//! white-balanced sRGB as a raw converter does ([`RawColour::development`]).

use crate::colorimetry;
use crate::error::{Error, Result};
use nalgebra::{Matrix3, Vector3};
use serde::Serialize;

/// One calibration illuminant's matrices of a raw file.
#[derive(Debug, Clone, PartialEq)]
pub struct CalibratedMatrix {
    /// The calibration illuminant as the file names it (`A`, `D65`, …).
    pub illuminant: String,
    /// Its correlated colour temperature, kelvin.
    pub cct_k: f64,
    /// `ColorMatrix`: XYZ → the reference camera's RGB.
    pub xyz_to_camera: Matrix3<f64>,
    /// `CameraCalibration`: the reference camera's RGB → this camera's (identity when the
    /// file gives none).
    pub camera_calibration: Matrix3<f64>,
    /// `ForwardMatrix`: white-balanced reference camera RGB → XYZ adapted to D50, when the
    /// file gives one.
    pub forward: Option<Matrix3<f64>>,
}

impl CalibratedMatrix {
    /// A `ColorMatrix` alone (no camera calibration, no forward matrix).
    pub fn new(illuminant: &str, cct_k: f64, xyz_to_camera: Matrix3<f64>) -> CalibratedMatrix {
        CalibratedMatrix {
            illuminant: illuminant.to_string(),
            cct_k,
            xyz_to_camera,
            camera_calibration: Matrix3::identity(),
            forward: None,
        }
    }
}

/// The colour calibration a raw file carries: its matrices (one or two, by calibration
/// illuminant), its analog balance and the camera's neutral as shot, when the file gives
/// them.
#[derive(Debug, Clone, PartialEq)]
pub struct RawColour {
    /// The matrices, ordered by colour temperature (warmest first).
    pub matrices: Vec<CalibratedMatrix>,
    /// `AnalogBalance`: the gains applied to each channel before the values were stored
    /// (1, 1, 1 when the file gives none).
    pub analog_balance: [f64; 3],
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
    /// Whether the patches were developed through the file's forward matrices.
    pub forward_matrix: bool,
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
        if let Some(m) = matrices.iter().find(|m| {
            m.camera_calibration.try_inverse().is_none()
                || m.forward.is_some_and(|f| f.try_inverse().is_none())
        }) {
            return Err(Error::invalid(format!(
                "the raw file's camera calibration or forward matrix for illuminant {} \
                 cannot be inverted",
                m.illuminant
            )));
        }
        // The DNG specification asks for forward matrices with every colour matrix or none.
        if !matrices.iter().all(|m| m.forward.is_some()) {
            matrices.iter_mut().for_each(|m| m.forward = None);
        }
        matrices.sort_by(|a, b| a.cct_k.total_cmp(&b.cct_k));
        let as_shot_neutral =
            as_shot_neutral.filter(|n| n.iter().all(|v| v.is_finite() && *v > 0.0));
        Ok(RawColour {
            matrices,
            analog_balance: [1.0; 3],
            as_shot_neutral,
        })
    }

    /// The same calibration with the file's `AnalogBalance` (ignored unless every gain is
    /// finite and positive).
    pub fn with_analog_balance(mut self, gains: [f64; 3]) -> RawColour {
        if gains.iter().all(|g| g.is_finite() && *g > 0.0) {
            self.analog_balance = gains;
        }
        self
    }

    /// Linear interpolation in mired at `cct_k` of one matrix of each illuminant (DNG 1.6
    /// ch. 6: the nearer one beyond them), with the warmest one's weight.
    fn interpolate(
        &self,
        cct_k: f64,
        pick: impl Fn(&CalibratedMatrix) -> Matrix3<f64>,
    ) -> (Matrix3<f64>, f64) {
        let first = &self.matrices[0];
        let Some(second) = self.matrices.last().filter(|m| m.cct_k > first.cct_k) else {
            return (pick(first), 1.0);
        };
        let mired = 1e6 / cct_k.clamp(CCT_RANGE_K.0, CCT_RANGE_K.1);
        let (m1, m2) = (1e6 / first.cct_k, 1e6 / second.cct_k);
        let g = ((mired - m2) / (m1 - m2)).clamp(0.0, 1.0);
        (pick(first) * g + pick(second) * (1.0 - g), g)
    }

    /// AnalogBalance · CameraCalibration at `cct_k`: the reference camera's RGB → the
    /// values as stored.
    fn reference_to_stored(&self, cct_k: f64) -> Matrix3<f64> {
        let balance = Matrix3::from_diagonal(&Vector3::from(self.analog_balance));
        balance * self.interpolate(cct_k, |m| m.camera_calibration).0
    }

    /// The XYZ → stored camera RGB matrix at colour temperature `cct_k` (DNG 1.6 ch. 6:
    /// AnalogBalance · CameraCalibration · ColorMatrix, each interpolated linearly in mired
    /// between the two calibration illuminants, the nearer one beyond them) and the warmest
    /// matrix's weight.
    fn xyz_to_camera_at(&self, cct_k: f64) -> (Matrix3<f64>, f64) {
        let (colour, g) = self.interpolate(cct_k, |m| m.xyz_to_camera);
        (self.reference_to_stored(cct_k) * colour, g)
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
                forward_matrix: false,
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

    /// Each of `rgb` (camera raw RGB, on the scale of `neutral`) as CIE 1931 XYZ through the
    /// file's matrices at `neutral` ([`RawColour::camera_to_xyz`]), scaled so that the
    /// neutral itself (a perfect white's reading) has Y = 100: the patches' colours as a
    /// colorimeter would read them under this light, relative to the white. The feature
    /// row a raw model reads ([`crate::dataset::Pipeline::Raw`]): the light's colour stays
    /// in it, where a white-balanced development takes it out.
    pub fn relative_xyz(&self, neutral: [f64; 3], rgb: &[[f32; 3]]) -> Result<Vec<[f32; 3]>> {
        let (to_xyz, _) = self.camera_to_xyz(neutral)?;
        let white = (to_xyz * Vector3::from(neutral))[1];
        if !(white.is_finite() && white > 0.0) {
            return Err(Error::invalid(
                "the file's colour matrix gives the photo's neutral no luminance",
            ));
        }
        let m = to_xyz * (100.0 / white);
        Ok(rgb
            .iter()
            .map(|v| {
                let xyz = m * Vector3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2]));
                [xyz[0] as f32, xyz[1] as f32, xyz[2] as f32]
            })
            .collect())
    }

    /// Camera raw RGB → linear sRGB (D65) white-balanced for the light whose neutral is
    /// `neutral`, then IEC 61966-2-1's XYZ → linear sRGB. With forward matrices, the DNG
    /// way (1.6 ch. 6): the stored values → the reference camera's, divided by the
    /// neutral's reference RGB, the interpolated `ForwardMatrix` to XYZ at D50, Bradford to
    /// D65. Without them: the colour matrix to XYZ, Bradford from the neutral's white to
    /// D65. Scaled so that the neutral itself maps to equal channels of its own green
    /// value: what a raw converter's "as shot" rendering does before its tone curve.
    pub fn development(&self, neutral: [f64; 3]) -> Result<(Matrix3<f64>, RawColourUse)> {
        let (to_xyz, mut used) = self.camera_to_xyz(neutral)?;
        let bradford = Matrix3::from_row_slice(&BRADFORD.concat());
        let inverse_bradford = bradford
            .try_inverse()
            .expect("the Bradford matrix is invertible");
        let adapt = |from: Vector3<f64>, to: Vector3<f64>| -> Result<Matrix3<f64>> {
            let (source, target) = (bradford * from, bradford * to);
            if !source.iter().all(|v| v.is_finite() && *v > 0.0) {
                return Err(Error::invalid(
                    "the photo's neutral lies outside the colours a light can have",
                ));
            }
            let scale = Matrix3::from_diagonal(&target.component_div(&source));
            Ok(inverse_bradford * scale * bradford)
        };
        let d65 = Vector3::from(colorimetry::xy_to_xyz(D65_XY, 1.0));
        let to_adapted_xyz = if self.matrices[0].forward.is_some() {
            let cct_k = used.neutral_cct_k;
            let stored_to_reference = self
                .reference_to_stored(cct_k)
                .try_inverse()
                .ok_or_else(|| Error::invalid("the camera calibration cannot be inverted"))?;
            let reference = stored_to_reference * Vector3::from(neutral);
            if !reference.iter().all(|v| v.is_finite() && *v > 0.0) {
                return Err(Error::invalid(
                    "the photo's neutral has a channel at or below zero in the reference \
                     camera's values",
                ));
            }
            let balance = Matrix3::from_diagonal(&reference.map(|v| 1.0 / v));
            let (forward, _) = self.interpolate(cct_k, |m| m.forward.expect("all or none"));
            let d50 = Vector3::from(colorimetry::xy_to_xyz(D50_XY, 1.0));
            used.forward_matrix = true;
            adapt(d50, d65)? * forward * balance * stored_to_reference
        } else {
            let white = to_xyz * Vector3::from(neutral);
            adapt(white, d65)? * to_xyz
        };
        let to_srgb = crate::camera::colour::xyz_to_srgb_matrix();
        let m = to_srgb * to_adapted_xyz;
        // The neutral keeps its green level, so exposure reads the same before and after.
        let grey = m * Vector3::from(neutral);
        let norm = neutral[1] / grey[1];
        Ok((m * norm, used))
    }
}

/// A chart's neutral: the camera RGB per unit reflectance of its grey patches, each given
/// as (its camera RGB, its mean reflectance), summed over all of them (brighter greys weigh
/// more, as their values are less noisy); `None` without a grey of positive reflectance.
pub fn chart_neutral(greys: &[([f32; 3], f64)]) -> Option<[f64; 3]> {
    let reflectance: f64 = greys.iter().map(|g| g.1).sum();
    (reflectance > 0.0).then(|| {
        std::array::from_fn(|c| greys.iter().map(|g| f64::from(g.0[c])).sum::<f64>() / reflectance)
    })
}

/// CIE D50's chromaticity, the profile connection space's white that forward matrices map
/// a neutral to (ICC.1:2010 D50 XYZ 0.9642, 1, 0.8249).
const D50_XY: [f64; 2] = [0.34570, 0.35854];

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
                CalibratedMatrix::new("D65", 6504.0, other),
                CalibratedMatrix::new("A", 2856.0, xyz_to_srgb),
            ],
            None,
        )
        .unwrap()
    }

    #[test]
    fn patches_read_as_xyz_relative_to_the_white_through_the_matrix_at_the_neutral() {
        // One matrix: the camera's raw RGB is XYZ itself (identity), so the neutral of a
        // D65 white at half scale reads D65's XYZ with Y = 100, and a 20 % grey Y = 20.
        let colour = RawColour::new(
            vec![CalibratedMatrix::new("D65", 6504.0, Matrix3::identity())],
            None,
        )
        .unwrap();
        let d65 = colorimetry::xy_to_xyz(D65_XY, 0.5);
        let neutral = d65;
        let grey = d65.map(|v| (0.2 * v) as f32);
        let red = [0.3f32, 0.1, 0.05];
        let xyz = colour.relative_xyz(neutral, &[grey, red]).unwrap();
        let white = colorimetry::xy_to_xyz(D65_XY, 100.0);
        for c in 0..3 {
            assert!(
                (f64::from(xyz[0][c]) - 0.2 * white[c]).abs() < 1e-4,
                "{xyz:?}"
            );
            assert!((f64::from(xyz[1][c]) - 200.0 * f64::from(red[c])).abs() < 1e-4);
        }
        // The neutral's scale does not matter; a neutral the matrix gives no light is an
        // error, not a row of infinities.
        let doubled = colour.relative_xyz(d65.map(|v| 2.0 * v), &[grey]).unwrap();
        assert!(
            (f64::from(doubled[0][1]) - 10.0).abs() < 1e-4,
            "{doubled:?}"
        );
        assert!(colour.relative_xyz([0.0, 1.0, 1.0], &[grey]).is_err());
    }

    #[test]
    fn a_charts_neutral_is_its_greys_light_per_unit_reflectance() {
        // Greys of reflectance 0.9 and 0.3 reading 0.45 and 0.15 in green: 0.5 per unit.
        let greys = [([0.36f32, 0.45, 0.27], 0.9), ([0.12f32, 0.15, 0.09], 0.3)];
        let n = chart_neutral(&greys).unwrap();
        let expected = [0.4, 0.5, 0.3];
        for c in 0..3 {
            assert!((n[c] - expected[c]).abs() < 1e-6, "{n:?}");
        }
        assert_eq!(chart_neutral(&[]), None);
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
        let singular = CalibratedMatrix::new("D65", 6504.0, Matrix3::zeros());
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

    /// CIE A's chromaticity (CIE 15:2018, table 11.3).
    const A_XY: [f64; 2] = [0.44757, 0.40745];

    /// A camera whose raw RGB is linear sRGB (a single D65 matrix), with `forward` as its
    /// forward matrix.
    fn srgb_camera(forward: Option<Matrix3<f64>>) -> RawColour {
        let xyz_to_srgb = crate::camera::colour::xyz_to_srgb_matrix();
        let mut matrix = CalibratedMatrix::new("D65", 6504.0, xyz_to_srgb);
        matrix.forward = forward;
        RawColour::new(vec![matrix], None).unwrap()
    }

    /// The Bradford adaptation from white `from` to white `to` (xy).
    fn bradford(from: [f64; 2], to: [f64; 2]) -> Matrix3<f64> {
        let b = Matrix3::from_row_slice(&BRADFORD.concat());
        let (s, t) = (
            b * Vector3::from(colorimetry::xy_to_xyz(from, 1.0)),
            b * Vector3::from(colorimetry::xy_to_xyz(to, 1.0)),
        );
        b.try_inverse().unwrap() * Matrix3::from_diagonal(&t.component_div(&s)) * b
    }

    #[test]
    fn an_analog_balance_is_undone_before_the_matrices() {
        // The same sensor with its red amplified 2× before storing: its values and its
        // AnalogBalance tag say so, and the light and the development read the same.
        let plain = two_matrices();
        let amplified = two_matrices().with_analog_balance([2.0, 1.0, 1.0]);
        let a = colorimetry::xyz_to_linear_srgb(colorimetry::xy_to_xyz(A_XY, 1.0));
        let stored = [2.0 * a[0], a[1], a[2]];
        let (x, y) = (
            plain.light_xy(a).unwrap(),
            amplified.light_xy(stored).unwrap(),
        );
        assert!(
            (x[0] - y[0]).abs() < 1e-9 && (x[1] - y[1]).abs() < 1e-9,
            "{x:?} {y:?}"
        );
        let (m, _) = plain.development(a).unwrap();
        let (n, _) = amplified.development(stored).unwrap();
        let gain = Matrix3::from_diagonal(&Vector3::new(2.0, 1.0, 1.0));
        assert!((m - n * gain).abs().max() < 1e-9, "{m} {n}");
        // Gains that are not positive are ignored.
        assert_eq!(
            two_matrices()
                .with_analog_balance([0.0, 1.0, 1.0])
                .analog_balance,
            [1.0; 3]
        );
    }

    #[test]
    fn a_forward_matrix_develops_white_balanced_colours_and_leaves_the_light_alone() {
        let srgb_to_xyz = crate::camera::colour::xyz_to_srgb_matrix()
            .try_inverse()
            .unwrap();
        // The sRGB camera's forward matrix: white-balanced RGB under D65 is its own RGB;
        // to XYZ, then adapted D65 → D50.
        let forward = bradford(D65_XY, D50_XY) * srgb_to_xyz;
        let (with, without) = (srgb_camera(Some(forward)), srgb_camera(None));
        // Under D65 both ways develop alike.
        let d65 = colorimetry::xyz_to_linear_srgb(colorimetry::xy_to_xyz(D65_XY, 1.0));
        let (m, used) = with.development(d65).unwrap();
        let (n, plain) = without.development(d65).unwrap();
        assert!(used.forward_matrix && !plain.forward_matrix);
        assert!((m - n).abs().max() < 2e-3, "{m} {n}");
        // Under A the forward matrix white-balances in the camera's RGB (here sRGB, a von
        // Kries scaling of its channels) where the colour matrix adapts by Bradford: the
        // development is diag(1 / neutral), scaled to keep the green.
        let a = colorimetry::xyz_to_linear_srgb(colorimetry::xy_to_xyz(A_XY, 1.0));
        let (m, _) = with.development(a).unwrap();
        let expected = Matrix3::from_diagonal(&Vector3::from(a.map(|v| a[1] / v)));
        assert!((m - expected).abs().max() < 1e-4, "{m} {expected}");
        let (n, _) = without.development(a).unwrap();
        assert!((m - n).abs().max() > 1e-2, "Bradford and von Kries differ");
        // The light's colour comes from the colour matrices either way.
        let (x, y) = (with.light_xy(a).unwrap(), without.light_xy(a).unwrap());
        assert!((x[0] - y[0]).abs() < 1e-12 && (x[1] - y[1]).abs() < 1e-12);
        assert!(
            (x[0] - A_XY[0]).abs() < 5e-4 && (x[1] - A_XY[1]).abs() < 5e-4,
            "{x:?}"
        );
    }

    #[test]
    fn forward_matrices_are_used_only_when_every_illuminant_has_one() {
        let xyz_to_srgb = crate::camera::colour::xyz_to_srgb_matrix();
        let mut first = CalibratedMatrix::new("A", 2856.0, xyz_to_srgb);
        first.forward = Some(Matrix3::identity());
        let second = CalibratedMatrix::new("D65", 6504.0, xyz_to_srgb);
        let colour = RawColour::new(vec![first, second], None).unwrap();
        assert!(colour.matrices.iter().all(|m| m.forward.is_none()));
        let mut singular = CalibratedMatrix::new("D65", 6504.0, xyz_to_srgb);
        singular.forward = Some(Matrix3::zeros());
        let e = RawColour::new(vec![singular], None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("forward matrix"), "{e}");
    }
}
