//! Colorimetry: from spectra to tristimulus values, chromaticities, CCT/Duv, sRGB and CIELAB.
//!
//! The virtual camera and the estimators work on spectra; judging their output means
//! expressing spectra the way a human observer (and a display) sees them. This module does
//! that with the standard CIE machinery:
//!
//! - [`Observer`]: the CIE 1931 2° standard observer (CIE 015:2018, tabulated CMFs shipped in
//!   `data/cie_1931_2deg_cmf.csv`) on a working [`Grid`](crate::spectral::Grid), with
//!   spectrum → XYZ by plain summation (CIE 015:2018).
//! - Chromaticity coordinates: CIE 1931 xy and CIE 1960 UCS uv (CIE 015:2018).
//! - Correlated colour temperature and Duv by Ohno (2014), "Practical use and calculation of
//!   CCT and Duv", LEUKOS 10(1), 47–55 — the method colour-science calls
//!   `uv_to_CCT_Ohno2013`.
//! - sRGB per IEC 61966-2-1:1999 (matrices and transfer function).
//! - CIE 1976 L\*a\*b\* (CIE 015:2018) and the CIEDE2000 colour difference as written
//!   out by Sharma, Wu & Dalal (2005), Color Res. Appl. 30(1), 21–30.
//!
//! The results match colour-science 0.4.7 (see `tests/colorimetry_reference.rs`).

mod cct;
mod cielab;
mod observer;
mod srgb;

pub use cct::{cct_duv_to_uv, cct_to_uv_planck, uv_to_cct_duv, CCT_MAX_K, CCT_MIN_K};
pub use cielab::{delta_e_2000, lab_to_xyz, xyz_to_lab};
pub use observer::Observer;
pub use srgb::{
    linear_srgb_to_xyz, srgb_decode, srgb_decode_f32, srgb_encode, srgb_encode_f32,
    xyz_to_linear_srgb, MATRIX_SRGB_TO_XYZ, MATRIX_XYZ_TO_SRGB,
};

/// CIE 1931 chromaticity (x, y) of tristimulus values: x = X/(X+Y+Z), y = Y/(X+Y+Z)
/// (CIE 015:2018). Black (X+Y+Z = 0) has no chromaticity and gives NaN.
pub fn xyz_to_xy(xyz: [f64; 3]) -> [f64; 2] {
    let sum = xyz[0] + xyz[1] + xyz[2];
    [xyz[0] / sum, xyz[1] / sum]
}

/// Tristimulus values of chromaticity `xy` at luminance `y_lum`: X = x·Y/y, Z = (1−x−y)·Y/y
/// (the inverse of the CIE 015 definition). `xy[1]` must be non-zero.
pub fn xy_to_xyz(xy: [f64; 2], y_lum: f64) -> [f64; 3] {
    let [x, y] = xy;
    [x * y_lum / y, y_lum, (1.0 - x - y) * y_lum / y]
}

/// CIE 1960 UCS (u, v) of an xy chromaticity: u = 4x/(−2x+12y+3), v = 6y/(−2x+12y+3)
/// (CIE 015:2018; the space CCT and Duv are defined in).
pub fn xy_to_uv1960(xy: [f64; 2]) -> [f64; 2] {
    let [x, y] = xy;
    let d = -2.0 * x + 12.0 * y + 3.0;
    [4.0 * x / d, 6.0 * y / d]
}

/// xy chromaticity of CIE 1960 UCS (u, v): x = 3u/(2u−8v+4), y = 2v/(2u−8v+4), the inverse of
/// [`xy_to_uv1960`].
pub fn uv1960_to_xy(uv: [f64; 2]) -> [f64; 2] {
    let [u, v] = uv;
    let d = 2.0 * u - 8.0 * v + 4.0;
    [3.0 * u / d, 2.0 * v / d]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn xy_xyz_round_trip() {
        let xyz = [0.2, 0.3, 0.4];
        let xy = xyz_to_xy(xyz);
        assert!((xy[0] - 2.0 / 9.0).abs() < 1e-15 && (xy[1] - 3.0 / 9.0).abs() < 1e-15);
        let back = xy_to_xyz(xy, 0.3);
        for (a, b) in back.iter().zip(xyz) {
            assert!((a - b).abs() < 1e-15, "{back:?}");
        }
        assert!(xyz_to_xy([0.0; 3])[0].is_nan());
    }

    #[test]
    fn uv1960_round_trip_and_equal_energy_point() {
        // The equal-energy point x = y = 1/3 has u = 4/19, v = 6/19.
        let uv = xy_to_uv1960([1.0 / 3.0, 1.0 / 3.0]);
        assert!((uv[0] - 4.0 / 19.0).abs() < 1e-15 && (uv[1] - 6.0 / 19.0).abs() < 1e-15);
        for xy in [
            [0.3127, 0.329],
            [0.44757, 0.40745],
            [0.15, 0.06],
            [0.64, 0.33],
        ] {
            let back = uv1960_to_xy(xy_to_uv1960(xy));
            assert!((back[0] - xy[0]).abs() < 1e-14 && (back[1] - xy[1]).abs() < 1e-14);
        }
    }
}
