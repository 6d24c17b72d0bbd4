//! CIECAM02 (CIE 159:2004) and its uniform colour space CAM02-UCS (Luo, Cui & Li 2006), in the
//! viewing conditions of CIE 224:2017 colour fidelity: adapting luminance L_A = 100 cd/m²,
//! background Y_b = 20, average surround, the illuminant discounted (D = 1).
//!
//! Sources: CIE 159:2004, "A colour appearance model for colour management systems:
//! CIECAM02" (forward model, steps 0–9); M. R. Luo, G. Cui, C. Li (2006), "Uniform colour
//! spaces based on CIECAM02 colour appearance model", Color Res. Appl. 31(4), 320–330
//! (CAM02-UCS: K_L = 1, c1 = 0.007, c2 = 0.0228). The implementation follows colour-science's
//! `XYZ_to_CIECAM02` and `JMh_CIECAM02_to_CAM02UCS`, including its sign-preserving powers.

use std::sync::OnceLock;

/// The CAT02 chromatic adaptation matrix (CIE 159:2004, Eq. 7).
const M_CAT02: [[f64; 3]; 3] = [
    [0.7328, 0.4296, -0.1624],
    [-0.7036, 1.6975, 0.0061],
    [0.0030, 0.0136, 0.9834],
];

/// The Hunt–Pointer–Estévez matrix to cone space (CIE 159:2004, Eq. 11).
const M_HPE: [[f64; 3]; 3] = [
    [0.38971, 0.68898, -0.07868],
    [-0.22981, 1.18340, 0.04641],
    [0.0, 0.0, 1.0],
];

/// Adapting field luminance of CIE 224:2017, cd/m².
pub const ADAPTING_LUMINANCE: f64 = 100.0;
/// Relative background luminance of CIE 224:2017.
pub const BACKGROUND_Y: f64 = 20.0;
/// Average surround (CIE 159:2004 Table 1): F, c, N_c.
const SURROUND_C: f64 = 0.69;
const SURROUND_NC: f64 = 1.0;
/// CAM02-UCS coefficients (Luo et al. 2006, Table 2).
const UCS_C1: f64 = 0.007;
const UCS_C2: f64 = 0.0228;

fn mul(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    m.map(|r| r[0] * v[0] + r[1] * v[1] + r[2] * v[2])
}

fn mat_mul(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

/// M_HPE · M_CAT02⁻¹, computed once.
fn hpe_from_cat02() -> &'static [[f64; 3]; 3] {
    static M: OnceLock<[[f64; 3]; 3]> = OnceLock::new();
    M.get_or_init(|| {
        let cat = nalgebra::Matrix3::from_fn(|i, j| M_CAT02[i][j]);
        let inv = cat.try_inverse().expect("M_CAT02 is invertible");
        mat_mul(
            &M_HPE,
            &std::array::from_fn(|i| std::array::from_fn(|j| inv[(i, j)])),
        )
    })
}

/// x^p keeping the sign of x (colour-science's `spow`).
fn spow(x: f64, p: f64) -> f64 {
    x.signum() * x.abs().powf(p)
}

/// A colour in CAM02-UCS with its CIECAM02 hue angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cam02Ucs {
    /// Lightness J′.
    pub j: f64,
    /// Red–green a′ = M′ cos h.
    pub a: f64,
    /// Yellow–blue b′ = M′ sin h.
    pub b: f64,
}

impl Cam02Ucs {
    /// The hue angle h in degrees, [0, 360) (CIECAM02 h equals the CAM02-UCS hue).
    pub fn hue_degrees(&self) -> f64 {
        self.b.atan2(self.a).to_degrees().rem_euclid(360.0)
    }
}

/// CIECAM02 set up for one adopted white in the CIE 224:2017 viewing conditions: everything of
/// the forward model that depends only on the white, so each sample costs one matrix product
/// and the nonlinear steps.
#[derive(Debug, Clone)]
pub struct Cam02Viewing {
    /// XYZ → adapted cone responses, M_HPE·M_CAT02⁻¹·diag(Y_w/RGB_w)·M_CAT02 (D = 1).
    to_cones: [[f64; 3]; 3],
    f_l: f64,
    n_bb: f64,
    cz: f64,
    a_w: f64,
    chroma_factor: f64,
    f_l_4: f64,
}

impl Cam02Viewing {
    /// The model for white `xyz_w` (Y_w on the same scale as the samples, e.g. 100), with
    /// L_A = 100 cd/m², Y_b = 20, average surround and the illuminant discounted (CIE 224:2017
    /// §4.2; CIE 159:2004 steps 0–1 with D = 1).
    pub fn cie2017(xyz_w: [f64; 3]) -> Cam02Viewing {
        let y_w = xyz_w[1];
        let rgb_w = mul(&M_CAT02, xyz_w);
        let gain = rgb_w.map(|c| y_w / c);
        let adapt: [[f64; 3]; 3] = std::array::from_fn(|i| M_CAT02[i].map(|v| v * gain[i]));
        let to_cones = mat_mul(hpe_from_cat02(), &adapt);

        let la5 = 5.0 * ADAPTING_LUMINANCE;
        let k = 1.0 / (la5 + 1.0);
        let k4 = k.powi(4);
        let f_l = 0.2 * k4 * la5 + 0.1 * (1.0 - k4).powi(2) * la5.cbrt();
        let n = BACKGROUND_Y / y_w;
        let n_bb = 0.725 * (1.0 / n).powf(0.2);
        let z = 1.48 + n.sqrt();
        let mut view = Cam02Viewing {
            to_cones,
            f_l,
            n_bb,
            cz: SURROUND_C * z,
            a_w: 1.0,
            chroma_factor: (1.64 - 0.29f64.powf(n)).powf(0.73),
            f_l_4: f_l.powf(0.25),
        };
        let white = view.post_adaptation(xyz_w);
        view.a_w = view.achromatic(&white);
        view
    }

    /// Post-adaptation cone responses R′a, G′a, B′a (CIE 159:2004 Eq. 13, signed).
    fn post_adaptation(&self, xyz: [f64; 3]) -> [f64; 3] {
        mul(&self.to_cones, xyz).map(|c| {
            let f = spow(self.f_l * c / 100.0, 0.42);
            400.0 * f / (27.13 + f.abs()) + 0.1
        })
    }

    /// Achromatic response A (CIE 159:2004 Eq. 18).
    fn achromatic(&self, rgb_a: &[f64; 3]) -> f64 {
        (2.0 * rgb_a[0] + rgb_a[1] + rgb_a[2] / 20.0 - 0.305) * self.n_bb
    }

    /// CAM02-UCS J′a′b′ of tristimulus values `xyz` (same scale as the white).
    pub fn ucs(&self, xyz: [f64; 3]) -> Cam02Ucs {
        let rgb_a = self.post_adaptation(xyz);
        let a = rgb_a[0] - 12.0 * rgb_a[1] / 11.0 + rgb_a[2] / 11.0;
        let b = (rgb_a[0] + rgb_a[1] - 2.0 * rgb_a[2]) / 9.0;
        let ab = (a * a + b * b).sqrt();
        let (cos_h, sin_h) = if ab > 0.0 {
            (a / ab, b / ab)
        } else {
            (1.0, 0.0)
        };
        // Eccentricity e_t = (cos(h + 2) + 3.8)/4 (Eq. 16), with cos(h + 2) expanded.
        let e_t = 0.25 * (cos_h * 2f64.cos() - sin_h * 2f64.sin() + 3.8);
        let j = 100.0 * spow(self.achromatic(&rgb_a) / self.a_w, self.cz);
        let t = (50000.0 / 13.0 * SURROUND_NC * self.n_bb * e_t * ab)
            / (rgb_a[0] + rgb_a[1] + 21.0 / 20.0 * rgb_a[2]);
        let root_j = (j / 100.0).signum() * (j / 100.0).abs().sqrt();
        let c = spow(t, 0.9) * root_j * self.chroma_factor;
        let m = c * self.f_l_4;
        let m_ucs = (1.0 + UCS_C2 * m).ln() / UCS_C2;
        Cam02Ucs {
            j: (1.0 + 100.0 * UCS_C1) * j / (1.0 + UCS_C1 * j),
            a: m_ucs * cos_h,
            b: m_ucs * sin_h,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_colour_science_in_the_cie_2017_viewing_conditions() {
        // Reference: colour-science 0.4.7 `XYZ_to_CIECAM02(XYZ = (19.31, 23.93, 10.14),
        // XYZ_w = (98.88, 90, 32.03), L_A = 100, Y_b = 20, Average, discount_illuminant=True)`
        // gives J = 47.520762..., M = 36.806850..., h = 191.879934...; CAM02-UCS from those.
        let (j, m, h): (f64, f64, f64) = (47.520_762_213_7, 36.806_849_827_9, 191.879_933_698_7);
        let view = Cam02Viewing::cie2017([98.88, 90.0, 32.03]);
        let ucs = view.ucs([19.31, 23.93, 10.14]);
        let jp = 1.7 * j / (1.0 + 0.007 * j);
        let mp = (1.0 + 0.0228 * m).ln() / 0.0228;
        let (ap, bp) = (mp * h.to_radians().cos(), mp * h.to_radians().sin());
        assert!((ucs.j - jp).abs() < 1e-9, "{ucs:?} vs J′ {jp}");
        assert!(
            (ucs.a - ap).abs() < 1e-9 && (ucs.b - bp).abs() < 1e-9,
            "{ucs:?}"
        );
        assert!((ucs.hue_degrees() - h).abs() < 1e-9);
    }

    #[test]
    fn white_has_lightness_100_and_almost_no_chroma() {
        // With D = 1 the white's adapted cone signals are equal up to the rounding of M_HPE
        // (its first row sums to 1.00001), so a′, b′ are nearly but not exactly 0.
        let white = [95.047, 100.0, 108.883];
        let view = Cam02Viewing::cie2017(white);
        let w = view.ucs(white);
        assert!((w.j - 100.0).abs() < 1e-9, "{w:?}");
        assert!(w.a.abs() < 0.01 && w.b.abs() < 0.01, "{w:?}");
    }
}
