//! CIE 13.3-1995 colour rendering: the general index Ra and the special indices R1–R14.
//!
//! CIE 13.3-1995, "Method of measuring and specifying colour rendering properties of light
//! sources": the 14 test colour samples (shipped as `data/cie_1995_tcs14.csv`) are computed
//! under the test light and under a reference illuminant of the same CCT
//! ([`ReferenceIlluminants::cie1995`]) with the CIE 1931 2° observer; the test colours are adapted to the
//! reference white by the von Kries transform in CIE 1960 (u, v) of CIE 13.3 §5.5 (Eqs. 5–7);
//! each colour difference ΔE_i is taken in CIE 1964 U*V*W* (W* = 25 Y^(1/3) − 17,
//! U* = 13 W* (u − u_r), V* = 13 W* (v − v_r)); R_i = 100 − 4.6 ΔE_i, and Ra is the mean of
//! R1–R8. Computed at 1 nm over 360–780 nm (the samples interpolated with Sprague 1880), as
//! colour-science's `colour_rendering_index` does.

use super::reference::ReferenceIlluminants;
use super::spectrum::{observer_2deg, BandWeights, LightSpectrum, QUALITY_GRID};
use super::uv::xyz_to_uv1960;
use crate::builtin;
use crate::error::Result;
use crate::spectral::{Extrapolation, Interpolation};
use serde::{Deserialize, Serialize};
use std::sync::OnceLock;

/// Number of CIE 13.3 test colour samples.
pub const TCS_COUNT: usize = 14;

/// The CIE 13.3-1995 colour rendering indices of a light.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ColourRendering {
    /// General colour rendering index Ra, the mean of R1–R8.
    pub ra: f64,
    /// Special colour rendering indices R1–R14 (index 0 is R1).
    pub r: [f64; TCS_COUNT],
}

/// The CIE 13.3 reference illuminants on [`QUALITY_GRID`], prepared once.
pub(crate) fn references() -> &'static ReferenceIlluminants {
    static R: OnceLock<ReferenceIlluminants> = OnceLock::new();
    R.get_or_init(|| {
        ReferenceIlluminants::on_grid(&QUALITY_GRID).expect("references on 360–780 nm")
    })
}

/// The CIE 13.3 test colour samples TCS01–TCS14 times each CIE 1931 CMF on [`QUALITY_GRID`].
fn sample_weights() -> &'static BandWeights {
    static W: OnceLock<BandWeights> = OnceLock::new();
    W.get_or_init(|| sample_weights_of(&builtin::CIE1995_TCS14))
}

/// The samples of a shipped reflectance `table` times each CIE 1931 CMF on [`QUALITY_GRID`],
/// function `3·sample + channel`: the samples Sprague-interpolated to 1 nm (CIE 167:2005) and
/// held at their end values outside their range, as colour-science aligns them.
///
/// # Panics
/// If the shipped table does not parse (a build defect, caught by the crate's tests).
pub(crate) fn sample_weights_of(table: &builtin::BuiltinTable) -> BandWeights {
    let (tcs, _) = table
        .load()
        .and_then(|t| {
            t.resample(
                &QUALITY_GRID,
                Interpolation::Sprague1880,
                Extrapolation::HoldEdge,
            )
        })
        .expect("the shipped test colour samples resample to 360–780 nm");
    let obs = observer_2deg();
    let functions: Vec<Vec<f64>> = tcs
        .items()
        .iter()
        .flat_map(|r| (0..3).map(move |c| r.iter().zip(obs.cmf(c)).map(|(r, c)| r * c).collect()))
        .collect();
    BandWeights::new(&functions)
}

/// The colorimetry of the samples under one light: white (u, v) and each sample's XYZ
/// (Y of the white = 100).
struct SampleColours {
    white_uv: [f64; 2],
    samples: Vec<[f64; 3]>,
}

fn sample_colours(spd: &[f64], weights: &BandWeights) -> SampleColours {
    let obs = observer_2deg();
    let white = obs.spd_to_xyz(spd);
    // The samples' sums lack the Δλ that spd_to_xyz includes.
    let k = 100.0 / white[1] * QUALITY_GRID.step_nm;
    let mut sums = vec![0.0; weights.functions()];
    weights.apply(spd, &mut sums);
    SampleColours {
        white_uv: xyz_to_uv1960(white),
        samples: sums
            .chunks_exact(3)
            .map(|s| [k * s[0], k * s[1], k * s[2]])
            .collect(),
    }
}

/// CIE 1964 U*V*W* of a sample with CIE 1960 (u, v) and luminance factor `y` (0–100) relative
/// to the white (u_w, v_w) (CIE 13.3-1995 Eq. 8).
fn uvw(uv: [f64; 2], y: f64, white: [f64; 2]) -> [f64; 3] {
    let w = 25.0 * y.cbrt() - 17.0;
    [
        13.0 * w * (uv[0] - white[0]),
        13.0 * w * (uv[1] - white[1]),
        w,
    ]
}

/// The c and d terms of the CIE 13.3 von Kries adaptation (Eq. 6): c = (4 − u − 10v)/v,
/// d = (1.708v + 0.404 − 1.481u)/v.
fn c_d(uv: [f64; 2]) -> (f64, f64) {
    let [u, v] = uv;
    (
        (4.0 - u - 10.0 * v) / v,
        (1.708 * v + 0.404 - 1.481 * u) / v,
    )
}

/// CIE 13.3-1995 Ra and R1–R14 of `light` at correlated colour temperature `cct` (kelvin,
/// from [`crate::colorimetry::uv_to_cct_duv`]). Errors where the reference illuminant is not
/// defined (CCT above 25,000 K). CIE 13.3 deems the result meaningless when the light's
/// chromaticity lies more than 5.4e-3 from the Planckian locus; that is the caller's check.
pub fn colour_rendering_cie1995(light: &LightSpectrum, cct: f64) -> Result<ColourRendering> {
    let special = special_indices(light, cct, sample_weights())?;
    let r: [f64; TCS_COUNT] = std::array::from_fn(|i| special[i]);
    Ok(ColourRendering {
        ra: r[..8].iter().sum::<f64>() / 8.0,
        r,
    })
}

/// The CIE 13.3-1995 special colour rendering index R_i = 100 − 4.6 ΔE_i of each sample of
/// `weights` (built by [`sample_weights_of`]) under `light` at `cct`, by the method described
/// at the top of this module; errors where the reference illuminant is not defined.
pub(crate) fn special_indices(
    light: &LightSpectrum,
    cct: f64,
    weights: &BandWeights,
) -> Result<Vec<f64>> {
    let reference = references().cie1995(cct)?;
    let test = sample_colours(light.values(), weights);
    let refr = sample_colours(&reference, weights);
    let (c_k, d_k) = c_d(test.white_uv);
    let (c_r, d_r) = c_d(refr.white_uv);
    let (cr_ck, dr_dk) = (c_r / c_k, d_r / d_k);
    Ok(test
        .samples
        .iter()
        .zip(&refr.samples)
        .map(|(&xyz_t, &xyz_r)| {
            let (c_ki, d_ki) = c_d(xyz_to_uv1960(xyz_t));
            let den = 16.518 + 1.481 * cr_ck * c_ki - dr_dk * d_ki;
            let adapted = [
                (10.872 + 0.404 * cr_ck * c_ki - 4.0 * dr_dk * d_ki) / den,
                5.520 / den,
            ];
            let t = uvw(adapted, xyz_t[1], refr.white_uv);
            let q = uvw(xyz_to_uv1960(xyz_r), xyz_r[1], refr.white_uv);
            let de = ((t[0] - q[0]).powi(2) + (t[1] - q[1]).powi(2) + (t[2] - q[2]).powi(2)).sqrt();
            100.0 - 4.6 * de
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colorimetry::uv_to_cct_duv;

    #[test]
    fn a_reference_illuminant_renders_perfectly() {
        // A Planckian radiator at 3000 K is its own reference: every R_i = 100 (CIE 13.3 §5).
        let grid = QUALITY_GRID;
        let spd = crate::cie_illuminant::planck(3000.0, &grid).unwrap();
        let light = LightSpectrum::on_grid(&grid, &spd).unwrap();
        let (cct, _) = uv_to_cct_duv(xyz_to_uv1960(light.xyz())).unwrap();
        let cri = colour_rendering_cie1995(&light, cct).unwrap();
        for r in cri.r {
            assert!((r - 100.0).abs() < 0.01, "{cri:?}");
        }
    }
}
