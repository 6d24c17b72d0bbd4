//! sRGB (IEC 61966-2-1:1999): the XYZ ↔ linear RGB matrices and the transfer function.

/// CIE XYZ (D65 white, Y = 1) → linear sRGB, the 4-decimal matrix published in
/// IEC 61966-2-1:1999. colour-science 0.4.7 uses these exact values (`MATRIX_XYZ_TO_sRGB`),
/// so results agree with it bit for bit rather than with the inverse of the primaries.
pub const MATRIX_XYZ_TO_SRGB: [[f64; 3]; 3] = [
    [3.2406, -1.5372, -0.4986],
    [-0.9689, 1.8758, 0.0415],
    [0.0557, -0.2040, 1.0570],
];

/// Linear sRGB → CIE XYZ (D65 white, Y = 1), the 4-decimal matrix published in
/// IEC 61966-2-1:1999 (colour-science 0.4.7's `MATRIX_sRGB_TO_XYZ`). It is the inverse of
/// [`MATRIX_XYZ_TO_SRGB`] only to about 1e-4, as published.
pub const MATRIX_SRGB_TO_XYZ: [[f64; 3]; 3] = [
    [0.4124, 0.3576, 0.1805],
    [0.2126, 0.7152, 0.0722],
    [0.0193, 0.1192, 0.9505],
];

fn mul(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    m.map(|row| row[0] * v[0] + row[1] * v[1] + row[2] * v[2])
}

/// Linear sRGB of XYZ (Y = 1 for the D65 white) by [`MATRIX_XYZ_TO_SRGB`], without chromatic
/// adaptation or clipping: XYZ of another white must be adapted to D65 first.
pub fn xyz_to_linear_srgb(xyz: [f64; 3]) -> [f64; 3] {
    mul(&MATRIX_XYZ_TO_SRGB, xyz)
}

/// XYZ (Y = 1 for the D65 white) of linear sRGB by [`MATRIX_SRGB_TO_XYZ`].
pub fn linear_srgb_to_xyz(rgb: [f64; 3]) -> [f64; 3] {
    mul(&MATRIX_SRGB_TO_XYZ, rgb)
}

/// The sRGB encoding (IEC 61966-2-1 inverse EOTF) of a linear value: 12.92·L for
/// L ≤ 0.0031308, 1.055·L^(1/2.4) − 0.055 above. Unclipped: negatives stay on the linear
/// segment and values above 1 follow the power law, as in colour-science.
pub fn srgb_encode(linear: f64) -> f64 {
    if linear <= 0.0031308 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

/// The sRGB decoding (IEC 61966-2-1 EOTF) of an encoded value: V/12.92 for V ≤ 0.04045,
/// ((V + 0.055)/1.055)^2.4 above; unclipped, the inverse of [`srgb_encode`].
pub fn srgb_decode(encoded: f64) -> f64 {
    if encoded <= 0.04045 {
        encoded / 12.92
    } else {
        ((encoded + 0.055) / 1.055).powf(2.4)
    }
}

/// [`srgb_encode`] in single precision, for image loops.
pub fn srgb_encode_f32(linear: f32) -> f32 {
    if linear <= 0.003_130_8 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

/// [`srgb_decode`] in single precision, for image loops.
pub fn srgb_decode_f32(encoded: f32) -> f32 {
    if encoded <= 0.040_45 {
        encoded / 12.92
    } else {
        ((encoded + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encode_fixed_points_and_boundary_continuity() {
        assert_eq!(srgb_encode(0.0), 0.0);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-15);
        assert_eq!(srgb_decode(0.0), 0.0);
        assert!((srgb_decode(1.0) - 1.0).abs() < 1e-15);
        // Both segments meet at 0.0031308 to within the standard's rounding (≈ 1e-8).
        let b = 0.0031308;
        let linear_side = 12.92 * b;
        let power_side = 1.055 * f64::powf(b, 1.0 / 2.4) - 0.055;
        assert!(
            (linear_side - power_side).abs() < 1e-7,
            "{linear_side} {power_side}"
        );
        assert!((srgb_encode(b) - srgb_encode(b + 1e-12)).abs() < 1e-7);
        // The 18 % grey encodes to 0.4614.
        assert!((srgb_encode(0.18) - 0.461356).abs() < 1e-6);
        // Negatives stay on the linear segment.
        assert_eq!(srgb_encode(-0.01), -0.1292);
    }

    #[test]
    fn decode_inverts_encode() {
        for i in -10..=1100 {
            let l = i as f64 / 1000.0;
            assert!((srgb_decode(srgb_encode(l)) - l).abs() < 1e-12, "{l}");
            let lf = l as f32;
            assert!(
                (srgb_decode_f32(srgb_encode_f32(lf)) - lf).abs() < 2e-6,
                "{l}"
            );
            assert!(
                (srgb_encode_f32(lf) as f64 - srgb_encode(l)).abs() < 1e-6,
                "{l}"
            );
        }
    }

    #[test]
    fn d65_white_maps_to_rgb_one() {
        // XYZ of the D65 white (x, y) = (0.3127, 0.3290), Y = 1.
        let white = [0.3127 / 0.3290, 1.0, (1.0 - 0.3127 - 0.3290) / 0.3290];
        for c in xyz_to_linear_srgb(white) {
            assert!((c - 1.0).abs() < 1e-3, "{c}");
        }
        let back = linear_srgb_to_xyz(xyz_to_linear_srgb(white));
        for (a, b) in back.iter().zip(white) {
            assert!((a - b).abs() < 5e-4, "{back:?}");
        }
    }
}
