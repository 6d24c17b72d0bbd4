//! CIE 1976 L*a*b* and the CIEDE2000 colour difference.

/// CIE ε = 216/24389: below it Y/Yn lies on the linear segment of L*.
const EPSILON: f64 = 216.0 / 24389.0;
/// CIE κ = 24389/27, the slope of that segment.
const KAPPA: f64 = 24389.0 / 27.0;

fn f(t: f64) -> f64 {
    if t > EPSILON {
        t.cbrt()
    } else {
        (KAPPA * t + 16.0) / 116.0
    }
}

/// CIE 1976 L\*a\*b\* of `xyz` relative to the white `white_xyz` (same scale, e.g. both with
/// the white at Y = 1): L\* = 116 f(Y/Yn) − 16, a\* = 500 (f(X/Xn) − f(Y/Yn)),
/// b\* = 200 (f(Y/Yn) − f(Z/Zn)), f(t) = t^(1/3) above ε = 216/24389 and (κt + 16)/116 below,
/// κ = 24389/27 (CIE 015:2018, with the exact rational constants as in colour-science).
pub fn xyz_to_lab(xyz: [f64; 3], white_xyz: [f64; 3]) -> [f64; 3] {
    let [fx, fy, fz] = [0, 1, 2].map(|i| f(xyz[i] / white_xyz[i]));
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// XYZ of CIE 1976 L\*a\*b\* `lab` relative to `white_xyz`, the exact inverse of
/// [`xyz_to_lab`] (CIE 015:2018).
pub fn lab_to_xyz(lab: [f64; 3], white_xyz: [f64; 3]) -> [f64; 3] {
    let [l, a, b] = lab;
    let fy = (l + 16.0) / 116.0;
    let fx = fy + a / 500.0;
    let fz = fy - b / 200.0;
    let inv = |f: f64| {
        let f3 = f * f * f;
        if f3 > EPSILON {
            f3
        } else {
            (116.0 * f - 16.0) / KAPPA
        }
    };
    let yr = if l > KAPPA * EPSILON {
        fy * fy * fy
    } else {
        l / KAPPA
    };
    [
        inv(fx) * white_xyz[0],
        yr * white_xyz[1],
        inv(fz) * white_xyz[2],
    ]
}

/// The CIEDE2000 colour difference ΔE₀₀ between two L\*a\*b\* colours with kL = kC = kH = 1
/// (CIE 142:2001), implemented as written out by Sharma, Wu & Dalal (2005), "The CIEDE2000
/// color-difference formula: implementation notes, supplementary test data, and mathematical
/// observations", Color Res. Appl. 30(1), 21–30 (eqs. 1–22; mean hue and hue difference by
/// their eqs. 10 and 14, which resolve the ±180° cases).
pub fn delta_e_2000(lab1: [f64; 3], lab2: [f64; 3]) -> f64 {
    let [l1, a1, b1] = lab1;
    let [l2, a2, b2] = lab2;
    let pow7 = |c: f64| c.powi(7);
    let c_bar = (a1.hypot(b1) + a2.hypot(b2)) / 2.0;
    let g = 0.5 * (1.0 - (pow7(c_bar) / (pow7(c_bar) + pow7(25.0))).sqrt());
    let (a1p, a2p) = ((1.0 + g) * a1, (1.0 + g) * a2);
    let (c1p, c2p) = (a1p.hypot(b1), a2p.hypot(b2));
    let hue = |b: f64, ap: f64| {
        if b == 0.0 && ap == 0.0 {
            0.0
        } else {
            b.atan2(ap).to_degrees().rem_euclid(360.0)
        }
    };
    let (h1p, h2p) = (hue(b1, a1p), hue(b2, a2p));

    let dl = l2 - l1;
    let dc = c2p - c1p;
    let chroma_zero = c1p * c2p == 0.0;
    let dh_angle = if chroma_zero {
        0.0
    } else {
        let d = h2p - h1p;
        if d > 180.0 {
            d - 360.0
        } else if d < -180.0 {
            d + 360.0
        } else {
            d
        }
    };
    let dh = 2.0 * (c1p * c2p).sqrt() * (dh_angle / 2.0).to_radians().sin();

    let l_bar = (l1 + l2) / 2.0;
    let c_bar_p = (c1p + c2p) / 2.0;
    let h_bar = if chroma_zero {
        h1p + h2p
    } else if (h1p - h2p).abs() <= 180.0 {
        (h1p + h2p) / 2.0
    } else if h1p + h2p < 360.0 {
        (h1p + h2p + 360.0) / 2.0
    } else {
        (h1p + h2p - 360.0) / 2.0
    };
    let cosd = |deg: f64| deg.to_radians().cos();
    let t =
        1.0 - 0.17 * cosd(h_bar - 30.0) + 0.24 * cosd(2.0 * h_bar) + 0.32 * cosd(3.0 * h_bar + 6.0)
            - 0.20 * cosd(4.0 * h_bar - 63.0);
    let d_theta = 30.0 * (-((h_bar - 275.0) / 25.0).powi(2)).exp();
    let r_c = 2.0 * (pow7(c_bar_p) / (pow7(c_bar_p) + pow7(25.0))).sqrt();
    let l50 = (l_bar - 50.0).powi(2);
    let s_l = 1.0 + 0.015 * l50 / (20.0 + l50).sqrt();
    let s_c = 1.0 + 0.045 * c_bar_p;
    let s_h = 1.0 + 0.015 * c_bar_p * t;
    let r_t = -(2.0 * d_theta).to_radians().sin() * r_c;
    let (tl, tc, th) = (dl / s_l, dc / s_c, dh / s_h);
    (tl * tl + tc * tc + th * th + r_t * tc * th).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    const D65: [f64; 3] = [0.95047, 1.0, 1.08883];

    #[test]
    fn white_is_l100_and_black_is_zero() {
        let lab = xyz_to_lab(D65, D65);
        assert_eq!(lab, [100.0, 0.0, 0.0]);
        assert_eq!(xyz_to_lab([0.0; 3], D65), [0.0, 0.0, 0.0]);
        // Y = 0.18 gives L* ≈ 49.496 (on the cube-root branch).
        let l = xyz_to_lab([0.18 * D65[0], 0.18, 0.18 * D65[2]], D65)[0];
        assert!((l - 49.49611).abs() < 1e-4, "{l}");
    }

    #[test]
    fn lab_round_trip_on_both_branches() {
        for xyz in [
            [0.2, 0.3, 0.1],
            [0.004, 0.005, 0.006],
            [0.0005, 0.02, 0.9],
            [1.2, 1.0, 0.3],
        ] {
            let back = lab_to_xyz(xyz_to_lab(xyz, D65), D65);
            for (a, b) in back.iter().zip(xyz) {
                assert!((a - b).abs() < 1e-14, "{xyz:?} -> {back:?}");
            }
        }
    }

    #[test]
    fn delta_e_2000_basic_properties() {
        let a = [50.0, 2.6772, -79.7751];
        let b = [50.0, 0.0, -82.7485];
        assert_eq!(delta_e_2000(a, a), 0.0);
        assert_eq!(delta_e_2000([0.0; 3], [0.0; 3]), 0.0);
        // Sharma et al. (2005) Table 1, pair 1.
        assert!((delta_e_2000(a, b) - 2.0425).abs() < 5e-5);
        assert!((delta_e_2000(a, b) - delta_e_2000(b, a)).abs() < 1e-12);
        // A pure lightness difference at L̄ = 50 is ΔL (S_L = 1).
        assert!((delta_e_2000([49.0, 0.0, 0.0], [51.0, 0.0, 0.0]) - 2.0).abs() < 1e-12);
    }
}
