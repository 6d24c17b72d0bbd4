//! Uniform chromaticity scales of light colours: CIE 1960 UCS (u, v) and CIE 1976 UCS (u′, v′).

/// CIE 1960 UCS (u, v) of tristimulus values: u = 4X/(X+15Y+3Z), v = 6Y/(X+15Y+3Z)
/// (CIE 015:2018 §8.1; the space of CCT, Duv and the CIE 13.3 adaptation). Black gives NaN.
pub fn xyz_to_uv1960(xyz: [f64; 3]) -> [f64; 2] {
    let d = xyz[0] + 15.0 * xyz[1] + 3.0 * xyz[2];
    [4.0 * xyz[0] / d, 6.0 * xyz[1] / d]
}

/// CIE 1976 UCS (u′, v′) of tristimulus values: u′ = 4X/(X+15Y+3Z), v′ = 9Y/(X+15Y+3Z)
/// (CIE 015:2018 §8.1), i.e. u′ = u and v′ = 1.5 v. Black gives NaN.
pub fn xyz_to_uv1976(xyz: [f64; 3]) -> [f64; 2] {
    let d = xyz[0] + 15.0 * xyz[1] + 3.0 * xyz[2];
    [4.0 * xyz[0] / d, 9.0 * xyz[1] / d]
}

/// CIE 1931 (x, y) → CIE 1976 UCS (u′, v′): u′ = 4x/(−2x+12y+3), v′ = 9y/(−2x+12y+3)
/// (CIE 015:2018 §8.1).
pub fn xy_to_uv1976(xy: [f64; 2]) -> [f64; 2] {
    let d = -2.0 * xy[0] + 12.0 * xy[1] + 3.0;
    [4.0 * xy[0] / d, 9.0 * xy[1] / d]
}

/// CIE 1960 (u, v) → CIE 1976 (u′, v′): u′ = u, v′ = 1.5 v (CIE 015:2018 §8.1).
pub fn uv1960_to_uv1976(uv: [f64; 2]) -> [f64; 2] {
    [uv[0], 1.5 * uv[1]]
}

/// CIE 1976 (u′, v′) → CIE 1960 (u, v), the inverse of [`uv1960_to_uv1976`].
pub fn uv1976_to_uv1960(uv_prime: [f64; 2]) -> [f64; 2] {
    [uv_prime[0], uv_prime[1] / 1.5]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colorimetry::{xy_to_uv1960, xy_to_xyz};

    #[test]
    fn equal_energy_white_and_agreement_with_xy_route() {
        // Illuminant E: u = 4/19, v = 6/19, v′ = 9/19 (CIE 015:2018).
        let e = xyz_to_uv1960([1.0, 1.0, 1.0]);
        assert!((e[0] - 4.0 / 19.0).abs() < 1e-15 && (e[1] - 6.0 / 19.0).abs() < 1e-15);
        let e76 = xyz_to_uv1976([1.0, 1.0, 1.0]);
        assert!((e76[0] - 4.0 / 19.0).abs() < 1e-15 && (e76[1] - 9.0 / 19.0).abs() < 1e-15);
        // D65 (x, y) = (0.31271, 0.32902): u′ = 0.19783, v′ = 0.46833 (CIE 015:2018 Table 11).
        let xyz = xy_to_xyz([0.31271, 0.32902], 1.0);
        let d65 = xyz_to_uv1976(xyz);
        assert!((d65[0] - 0.19783).abs() < 1e-5 && (d65[1] - 0.46833).abs() < 1e-5);
        let via_xy = xy_to_uv1960([0.31271, 0.32902]);
        let direct = xyz_to_uv1960(xyz);
        assert!((via_xy[0] - direct[0]).abs() < 1e-15 && (via_xy[1] - direct[1]).abs() < 1e-15);
        // The two scales of one light convert into each other.
        assert_eq!(uv1960_to_uv1976(e), e76);
        let back = uv1976_to_uv1960(d65);
        assert!((back[0] - direct[0]).abs() < 1e-15 && (back[1] - direct[1]).abs() < 1e-15);
        // From xy directly, as from its XYZ.
        let from_xy = xy_to_uv1976([0.31271, 0.32902]);
        assert!((from_xy[0] - d65[0]).abs() < 1e-15 && (from_xy[1] - d65[1]).abs() < 1e-15);
    }
}
