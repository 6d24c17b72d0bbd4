//! The NIST Colour Quality Scale, version 9.0: Qa, Qf, Qg and the 15 per-sample scores.
//!
//! W. Davis and Y. Ohno, "Color quality scale", Optical Engineering 49(3), 033602 (2010), in
//! the form of the NIST CQS 9.0 spreadsheet. The 15 saturated Munsell samples VS1–VS15
//! (`data/nist_cqs90_vs15.csv`) are computed under the test light and under the reference
//! illuminant of its CCT ([`cie1995`]: Planckian below 5000 K, CIE daylight from 5000 K) with
//! the CIE 1931 2° observer at 1 nm over 360–780 nm (the samples Sprague-interpolated, CIE
//! 167:2005). The test colours are adapted to the reference white by a von Kries transform in
//! the CMCCAT2000 cone space (Li et al. 2002) and all colours are taken to CIE 1976 L\*a\*b\*
//! relative to the reference white. For each sample, ΔE\*ab is the CIELAB
//! difference and ΔC\*ab = C\*test − C\*ref; the saturation factor forgives a gain in chroma:
//! ΔE_p = √(ΔE² − ΔC²) when ΔC > 0, else ΔE. A difference becomes a 0–100 score by
//! Q = 10 ln(1 + exp((100 − s·ΔE)/10)) (the scaling to 0–100 of Davis & Ohno, which keeps
//! scores of poor lights above zero); the CCT factor that CQS 7.x applied to very warm lights
//! is 1 in version 9.0.
//!
//! - [`ColourQualityScale::qa`], the general Colour Quality Scale: the score of the RMS ΔE_p of
//!   the 15 samples with s = 3.2; 100 means the samples look as under the reference, while
//!   extra saturation is not counted against the light.
//! - [`ColourQualityScale::qf`], colour fidelity: the score of the RMS ΔE (every shift counts)
//!   with s = 2.93 × 1.0343.
//! - [`ColourQualityScale::qg`], relative gamut: the area of the polygon of the 15 test
//!   (a\*, b\*) in percent of that of CIE D65 (8210); above 100 the light saturates colours.
//! - [`ColourQualityScale::q_samples`]: each sample's score of its ΔE_p, s = 3.2.
//!
//! The colour preference scale Qp and the relative gamut Qd of CQS 7.x (Davis & Ohno 2010)
//! are not part of CQS 9.0 and are not computed (colour-science gives `None` for them).
//!
//! The computation follows colour-science 0.4.7's `colour_quality_scale(sd,
//! method="NIST CQS 9.0")` step by step. On 221 measured lamps the scores agree with it within
//! 1e-9 at its CCT, and within 3e-3 at the CCT of [`crate::colorimetry::uv_to_cct_duv`],
//! which lies within 0.1 K of colour-science's (`tests/quality_reference.rs`).
//!
//! [`cie1995`]: super::reference::ReferenceIlluminants::cie1995

use super::cri::{references, sample_weights_of};
use super::spectrum::{observer_2deg, BandWeights, LightSpectrum, QUALITY_GRID};
use crate::builtin;
use crate::colorimetry::{xy_to_xyz, xyz_to_lab, xyz_to_xy};
use crate::error::Result;
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};
use std::sync::OnceLock;

/// Number of NIST CQS 9.0 reflectance samples.
pub const VS_COUNT: usize = 15;

/// The CMCCAT2000 cone-response matrix (C. Li, M. R. Luo, B. Rigg, R. W. G. Hunt, "CMC 2000
/// chromatic adaptation transform: CMCCAT2000", Color Res. Appl. 27(1), 49–58, 2002), the
/// adaptation space of NIST CQS 9.0 as colour-science applies it.
const M_CMCCAT2000: [[f64; 3]; 3] = [
    [0.7982, 0.3389, -0.1371],
    [-0.5918, 1.5512, 0.0406],
    [0.0008, 0.0239, 0.9753],
];

/// The scale factor s of Qa and of the per-sample scores (NIST CQS 9.0).
const SCALE_QA: f64 = 3.2;
/// The scale factor s of Qf (NIST CQS 9.0: 2.93 × 1.0343).
const SCALE_QF: f64 = 2.93 * 1.0343;
/// Gamut area of the 15 samples under CIE D65 in CIELAB (a\*, b\*), the 100 of Qg (NIST CQS;
/// colour-science's `GAMUT_AREA_D65`).
const GAMUT_AREA_D65: f64 = 8210.0;

/// The NIST CQS 9.0 scores of a light.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ColourQualityScale {
    /// General Colour Quality Scale Qa (0–100): RMS colour shift of the 15 samples with gains
    /// in chroma forgiven.
    pub qa: f64,
    /// Colour fidelity scale Qf (0–100): RMS colour shift, every shift counted.
    pub qf: f64,
    /// Gamut area scale Qg: the samples' (a\*, b\*) gamut under the light, in percent of
    /// that under CIE D65.
    pub qg: f64,
    /// Per-sample scores Q1–Q15 (index 0 is VS1), each from its chroma-forgiving shift.
    pub q_samples: [f64; VS_COUNT],
}

/// The samples VS1–VS15 times each CIE 1931 CMF on [`QUALITY_GRID`], built once.
fn sample_weights() -> &'static BandWeights {
    static W: OnceLock<BandWeights> = OnceLock::new();
    W.get_or_init(|| sample_weights_of(&builtin::NIST_CQS90_VS15))
}

/// The white of a light (XYZ, Y = 1) and the XYZ of each sample under it on the same scale,
/// as colour-science's `vs_colorimetry_data` computes them before any adaptation.
fn sample_xyz(spd: &[f64]) -> ([f64; 3], Vec<[f64; 3]>) {
    let white = observer_2deg().spd_to_xyz(spd);
    // The samples' sums lack the Δλ that spd_to_xyz includes.
    let k = QUALITY_GRID.step_nm / white[1];
    let mut sums = vec![0.0; 3 * VS_COUNT];
    sample_weights().apply(spd, &mut sums);
    let samples = sums
        .chunks_exact(3)
        .map(|s| [k * s[0], k * s[1], k * s[2]])
        .collect();
    (white.map(|v| v / white[1]), samples)
}

/// The von Kries adaptation from white `from` to white `to` in the CMCCAT2000 cone space:
/// M⁻¹ · diag(M·to / M·from) · M (colour-science's `matrix_chromatic_adaptation_VonKries`,
/// full adaptation).
fn von_kries_cmccat2000(from: [f64; 3], to: [f64; 3]) -> Matrix3<f64> {
    let m = Matrix3::from_fn(|i, j| M_CMCCAT2000[i][j]);
    let inverse = m
        .try_inverse()
        .expect("the CMCCAT2000 matrix is invertible");
    let gains = (m * Vector3::from(to)).component_div(&(m * Vector3::from(from)));
    inverse * Matrix3::from_diagonal(&gains) * m
}

/// The 0–100 score of a colour difference `delta_e` with scale factor `s`:
/// 10 ln(1 + exp((100 − s·ΔE)/10)) (Davis & Ohno 2010, the conversion to a 0–100 scale).
fn score(delta_e: f64, s: f64) -> f64 {
    10.0 * ((100.0 - s * delta_e) / 10.0).exp().ln_1p()
}

/// ΔE\*ab and the saturation-corrected ΔE_p between a test and a reference L\*a\*b\*: ΔE_p
/// removes the chroma difference ΔC\*ab when the test is the more chromatic (Davis & Ohno 2010).
fn differences(test: [f64; 3], reference: [f64; 3]) -> (f64, f64) {
    let delta_e = ((test[0] - reference[0]).powi(2)
        + (test[1] - reference[1]).powi(2)
        + (test[2] - reference[2]).powi(2))
    .sqrt();
    let delta_c = test[1].hypot(test[2]) - reference[1].hypot(reference[2]);
    let delta_e_p = if delta_c > 0.0 {
        // ΔC ≤ ΔE; the clamp only absorbs rounding where they are equal.
        (delta_e * delta_e - delta_c * delta_c).max(0.0).sqrt()
    } else {
        delta_e
    };
    (delta_e, delta_e_p)
}

/// Area of the polygon through the (a\*, b\*) of `lab` in order, as the sum of the triangles
/// it makes with the origin (colour-science's `gamut_area`, there by Heron's formula, here by
/// the equal |a_i b_(i+1) − a_(i+1) b_i| / 2).
fn gamut_area(lab: &[[f64; 3]]) -> f64 {
    let n = lab.len();
    (0..n)
        .map(|i| {
            let (p, q) = (lab[i], lab[(i + 1) % n]);
            (p[1] * q[2] - q[1] * p[2]).abs() / 2.0
        })
        .sum()
}

/// Root mean square of `values`.
fn rms(values: &[f64]) -> f64 {
    (values.iter().map(|v| v * v).sum::<f64>() / values.len() as f64).sqrt()
}

/// NIST CQS 9.0 of `light` at correlated colour temperature `cct_k` (kelvin, from
/// [`crate::colorimetry::uv_to_cct_duv`]), by the method described at the top of this module.
/// Errors where the reference illuminant is not defined (CCT above 25,000 K).
///
/// ```
/// use spdcam_core::cie_illuminant::StandardIlluminant;
/// use spdcam_core::colorimetry::uv_to_cct_duv;
/// use spdcam_core::quality::uv::xyz_to_uv1960;
/// use spdcam_core::quality::{colour_quality_scale_nist_cqs90, LightSpectrum};
/// use spdcam_core::spectral::Grid;
///
/// let a = StandardIlluminant::A.spd(&Grid::SIMULATION)?;
/// let light = LightSpectrum::on_grid(&Grid::SIMULATION, &a)?;
/// let (cct, _) = uv_to_cct_duv(xyz_to_uv1960(light.xyz()))?;
/// let cqs = colour_quality_scale_nist_cqs90(&light, cct)?;
/// // Illuminant A is a Planckian radiator, its own reference: Qa 100.
/// assert!((cqs.qa - 100.0).abs() < 0.01);
/// # Ok::<(), spdcam_core::Error>(())
/// ```
pub fn colour_quality_scale_nist_cqs90(
    light: &LightSpectrum,
    cct_k: f64,
) -> Result<ColourQualityScale> {
    let reference = references().cie1995(cct_k)?;
    let (white_t, test) = sample_xyz(light.values());
    let (white_r, refr) = sample_xyz(&reference);
    // CIELAB relative to the reference white from its chromaticity, Y = 1 (colour-science's
    // XYZ_to_Lab(…, illuminant=xy_r)).
    let lab_white = xy_to_xyz(xyz_to_xy(white_r), 1.0);
    let adapt = von_kries_cmccat2000(white_t, white_r);
    let lab_t: Vec<[f64; 3]> = test
        .iter()
        .map(|&xyz| xyz_to_lab((adapt * Vector3::from(xyz)).into(), lab_white))
        .collect();
    let lab_r: Vec<[f64; 3]> = refr.iter().map(|&xyz| xyz_to_lab(xyz, lab_white)).collect();
    let (delta_e, delta_e_p): (Vec<f64>, Vec<f64>) = lab_t
        .iter()
        .zip(&lab_r)
        .map(|(&t, &r)| differences(t, r))
        .unzip();
    Ok(ColourQualityScale {
        qa: score(rms(&delta_e_p), SCALE_QA),
        qf: score(rms(&delta_e), SCALE_QF),
        qg: 100.0 * gamut_area(&lab_t) / GAMUT_AREA_D65,
        q_samples: std::array::from_fn(|i| score(delta_e_p[i], SCALE_QA)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colorimetry::uv_to_cct_duv;
    use crate::quality::uv::xyz_to_uv1960;

    #[test]
    fn scores_differences_and_areas_by_hand() {
        // No difference scores 10 ln(1 + e^10) ≈ 100.00045; at s·ΔE = 100, 10 ln 2.
        assert!((score(0.0, SCALE_QA) - 10.0 * (1.0 + 10f64.exp()).ln()).abs() < 1e-12);
        assert!((score(100.0 / SCALE_QA, SCALE_QA) - 10.0 * 2f64.ln()).abs() < 1e-12);
        // A pure gain in chroma (a* 30 → 40) is forgiven; a loss (40 → 30) counts in full.
        let (de, dep) = differences([50.0, 40.0, 0.0], [50.0, 30.0, 0.0]);
        assert_eq!((de, dep), (10.0, 0.0));
        let (de, dep) = differences([50.0, 30.0, 0.0], [50.0, 40.0, 0.0]);
        assert_eq!((de, dep), (10.0, 10.0));
        // A hue shift at equal chroma (3-4-5 triangle turned) counts in full.
        let (de, dep) = differences([50.0, 4.0, 3.0], [50.0, 3.0, 4.0]);
        assert!((de - 2f64.sqrt()).abs() < 1e-12 && de == dep);
        // The square of side 2 centred on the origin, as four triangles.
        let square = [
            [0.0, 1.0, 1.0],
            [0.0, -1.0, 1.0],
            [0.0, -1.0, -1.0],
            [0.0, 1.0, -1.0],
        ];
        assert!((gamut_area(&square) - 4.0).abs() < 1e-15);
    }

    #[test]
    fn a_reference_illuminant_scores_full_marks() {
        // A Planckian radiator at 3000 K is its own reference: every ΔE = 0, so Qa, Qf and
        // every Q_i are 10 ln(1 + e^10); Qg is its own gamut, smaller than D65's.
        let spd = crate::cie_illuminant::planck(3000.0, &QUALITY_GRID).unwrap();
        let light = LightSpectrum::on_grid(&QUALITY_GRID, &spd).unwrap();
        let full = score(0.0, SCALE_QA);
        let cqs = colour_quality_scale_nist_cqs90(&light, 3000.0).unwrap();
        assert!((cqs.qa - full).abs() < 1e-9, "{cqs:?}");
        assert!((cqs.qf - full).abs() < 1e-9, "{cqs:?}");
        for q in cqs.q_samples {
            assert!((q - full).abs() < 1e-9, "{cqs:?}");
        }
        assert!(cqs.qg > 90.0 && cqs.qg < 100.0, "{}", cqs.qg);
        // At the CCT computed from its chromaticity (within a fraction of a kelvin of 3000 K)
        // the reference is all but the same radiator.
        let (cct, _) = uv_to_cct_duv(xyz_to_uv1960(light.xyz())).unwrap();
        let near = colour_quality_scale_nist_cqs90(&light, cct).unwrap();
        assert!(
            (near.qa - full).abs() < 0.01 && (near.qg - cqs.qg).abs() < 0.01,
            "{near:?}"
        );
        assert!(colour_quality_scale_nist_cqs90(&light, 30_000.0).is_err());
    }
}
