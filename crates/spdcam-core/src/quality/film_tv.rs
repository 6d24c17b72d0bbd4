//! The numbers a cinematographer reads off a colour meter: R1–R15 (R15 the Japanese skin
//! sample of JIS Z 8726), the Academy Spectral Similarity Index (SSI), and the filter
//! correction to a target colour temperature as a mired shift and a green–magenta shift.

use super::cri::{colour_rendering_cie1995, sample_weights_of, special_indices, TCS_COUNT};
use super::spectrum::{BandWeights, LightSpectrum, QUALITY_GRID};
use super::uv::xyz_to_uv1960;
use crate::builtin;
use crate::cie_illuminant::{daylight, planck};
use crate::colorimetry::{uv_to_cct_duv, CCT_MAX_K, CCT_MIN_K};
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::sync::OnceLock;

/// Tungsten studio light, the usual target of a warm correction, in kelvin.
pub const TUNGSTEN_K: f64 = 3200.0;
/// Photographic daylight (HMI, daylight-balanced film), the usual cool target, in kelvin.
pub const DAYLIGHT_K: f64 = 5600.0;

/// Beyond this distance from the Planckian locus (|Δuv| in CIE 1960 uv) a correlated colour
/// temperature is not meaningful (Ohno 2014, LEUKOS 10(1), 47–55, §1), so neither is a
/// reference or a filter correction based on it.
pub const CCT_MAX_ABS_DUV: f64 = 0.05;

/// The CCT and Δuv of `light` (Ohno 2014) for `what`; errors where they are not defined or
/// |Δuv| exceeds [`CCT_MAX_ABS_DUV`].
fn meaningful_cct(light: &LightSpectrum, what: &str) -> Result<(f64, f64)> {
    let (cct, duv) = uv_to_cct_duv(xyz_to_uv1960(light.xyz()))
        .map_err(|e| Error::invalid(format!("no {what}: {e}")))?;
    if duv.abs() > CCT_MAX_ABS_DUV {
        return Err(Error::invalid(format!(
            "no {what}: the light is Δuv {duv:.4} from the Planckian locus, beyond the \
             ±{CCT_MAX_ABS_DUV} within which a colour temperature means anything; it is a \
             coloured light, described by its dominant wavelength"
        )));
    }
    Ok((cct, duv))
}

/// The JIS Z 8726 sample No. 15 times each CIE 1931 CMF on [`QUALITY_GRID`], built once.
fn tcs15_weights() -> &'static BandWeights {
    static W: OnceLock<BandWeights> = OnceLock::new();
    W.get_or_init(|| sample_weights_of(&builtin::CIE2024_TCS15))
}

/// The special colour rendering index R15 of `light` at correlated colour temperature `cct`
/// (kelvin): test colour sample No. 15 of JIS Z 8726:1990 (Japanese skin complexion, shipped
/// as `data/cie_2024_tcs15.csv` from the CIE's 2024 publication of it) computed exactly as
/// R1–R14 are by CIE 13.3-1995 (same reference illuminant, von Kries adaptation and
/// U*V*W* difference; see [`super::cri`]), as colour-science's `colour_rendering_index` does
/// with `method="CIE 2024"`. Errors where the reference illuminant is not defined (CCT above
/// 25,000 K).
pub fn special_rendering_index_r15(light: &LightSpectrum, cct: f64) -> Result<f64> {
    Ok(special_indices(light, cct, tcs15_weights())?[0])
}

/// R1–R15 of `light` at `cct` (index 0 is R1): CIE 13.3-1995 R1–R14 and the JIS Z 8726 R15
/// of [`special_rendering_index_r15`], the bars a colour meter draws.
pub fn special_rendering_indices_r1_r15(
    light: &LightSpectrum,
    cct: f64,
) -> Result<[f64; TCS_COUNT + 1]> {
    let r = colour_rendering_cie1995(light, cct)?.r;
    let r15 = special_rendering_index_r15(light, cct)?;
    Ok(std::array::from_fn(
        |i| if i < TCS_COUNT { r[i] } else { r15 },
    ))
}

/// The reference an SSI compares a light with.
#[derive(Debug, Clone, PartialEq)]
pub enum SsiReference {
    /// The reference of the light's own CCT (Ohno 2014): a Planckian radiator below 4000 K,
    /// CIE daylight (D series, CIE 015:2018) from 4000 K to 25,000 K — the default reference of
    /// the Academy's SSI (AMPAS 2020, and `computeSSI` of the R package colorSpec).
    CctMatched,
    /// A Planckian radiator at this temperature in kelvin (3200 K for tungsten work).
    Planckian(f64),
    /// CIE daylight (D series) at this CCT in kelvin, 4000–25,000 K (5500 K ≈ D55).
    Daylight(f64),
    /// Any reference spectrum.
    Spectrum(LightSpectrum),
}

/// First and last wavelengths of the SSI's 1 nm working range, nm.
const SSI_RANGE_NM: (usize, usize) = (375, 675);
/// Number of 10 nm SSI bands, centred 380, 390, …, 670 nm.
const SSI_BANDS: usize = 30;

/// The light's power in the 30 SSI bands, each the trapezoidal integral over ±5 nm of its
/// centre, normalised to sum 1; `None` when it has no power in 375–675 nm.
fn ssi_bands(values: &[f64]) -> Option<[f64; SSI_BANDS]> {
    let start = SSI_RANGE_NM.0 - QUALITY_GRID.start_nm as usize;
    let mut bands = [0.0; SSI_BANDS];
    for (b, band) in bands.iter_mut().enumerate() {
        let s = &values[start + 10 * b..=start + 10 * b + 10];
        *band = 0.5 * (s[0] + s[10]) + s[1..10].iter().sum::<f64>();
    }
    let total: f64 = bands.iter().sum();
    if !(total > 0.0 && total.is_finite()) {
        return None;
    }
    Some(bands.map(|b| b / total))
}

/// The Academy Spectral Similarity Index of `test` against `reference`, unrounded (the
/// Academy reports it rounded to an integer; 100 = the same spectral shape).
///
/// The method of J. Holm and T. Maier, Academy Spectral Similarity Index (SSI): Overview,
/// AMPAS (2020), as implemented by colour-science's `colour.spectral_similarity_index`: both
/// spectra on 375–675 nm at 1 nm are integrated (trapezoidally) into 30 bands of 10 nm
/// centred on 380–670 nm and each normalised to sum 1; the relative differences
/// (t_i − r_i)/(r_i + 1/30) are weighted (4/15, 22/45, 32/45, 40/45, 44/45 over the first five
/// bands, 11/15 and 3/15 over the last two, 1 elsewhere), smoothed with the kernel
/// (0.22, 0.56, 0.22) (zero beyond the ends), and SSI = 100 − 32·√Σ c_i².
///
/// Errors when either spectrum has no power in 375–675 nm, and for a CCT-matched or
/// daylight reference where it is not defined (a light without a meaningful CCT: outside
/// 1000–25,000 K or beyond [`CCT_MAX_ABS_DUV`]; daylight below 4000 K).
///
/// ```
/// use spdcam_core::cie_illuminant::StandardIlluminant;
/// use spdcam_core::quality::film_tv::{spectral_similarity_index, SsiReference};
/// use spdcam_core::quality::LightSpectrum;
/// use spdcam_core::spectral::Grid;
///
/// let grid = Grid::new(300.0, 780.0, 5.0)?;
/// let a = StandardIlluminant::A.spd(&grid)?;
/// let a = LightSpectrum::on_grid(&grid, &a)?;
/// // Illuminant A is a Planckian radiator at 2856 K: its own CCT-matched reference.
/// let ssi = spectral_similarity_index(&a, &SsiReference::CctMatched)?;
/// assert!(ssi > 99.5);
/// # Ok::<(), spdcam_core::Error>(())
/// ```
pub fn spectral_similarity_index(test: &LightSpectrum, reference: &SsiReference) -> Result<f64> {
    let reference_values: Vec<f64> = match reference {
        SsiReference::CctMatched => {
            let (cct, _) = meaningful_cct(test, "CCT-matched SSI reference")?;
            if cct < 4000.0 {
                planck(cct, &QUALITY_GRID)?.to_vec()
            } else {
                daylight(cct, &QUALITY_GRID)
                    .map_err(|e| {
                        Error::invalid(format!(
                            "no CCT-matched SSI reference for a light of {cct:.0} K: {e}"
                        ))
                    })?
                    .to_vec()
            }
        }
        SsiReference::Planckian(t) => planck(*t, &QUALITY_GRID)?.to_vec(),
        SsiReference::Daylight(t) => daylight(*t, &QUALITY_GRID)?.to_vec(),
        SsiReference::Spectrum(s) => s.values().to_vec(),
    };
    let no_power = |which: &str| {
        Error::invalid(format!(
            "the {which} spectrum has no power in {}–{} nm, the range the SSI compares",
            SSI_RANGE_NM.0, SSI_RANGE_NM.1
        ))
    };
    let t = ssi_bands(test.values()).ok_or_else(|| no_power("test"))?;
    let r = ssi_bands(&reference_values).ok_or_else(|| no_power("reference"))?;
    let weight = |i: usize| match i {
        0 => 4.0 / 15.0,
        1 => 22.0 / 45.0,
        2 => 32.0 / 45.0,
        3 => 40.0 / 45.0,
        4 => 44.0 / 45.0,
        28 => 11.0 / 15.0,
        29 => 3.0 / 15.0,
        _ => 1.0,
    };
    let wdr: [f64; SSI_BANDS] =
        std::array::from_fn(|i| weight(i) * (t[i] - r[i]) / (r[i] + 1.0 / 30.0));
    let at = |i: isize| {
        usize::try_from(i)
            .ok()
            .and_then(|i| wdr.get(i))
            .copied()
            .unwrap_or(0.0)
    };
    let m: f64 = (0..SSI_BANDS as isize)
        .map(|i| (0.22 * at(i - 1) + 0.56 * at(i) + 0.22 * at(i + 1)).powi(2))
        .sum();
    Ok(100.0 - 32.0 * m.sqrt())
}

/// The filter correction that brings a light to a target colour temperature, as a colour
/// meter shows it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CctCorrection {
    /// The target colour temperature, kelvin.
    pub target_k: f64,
    /// Mired shift 10⁶/T_target − 10⁶/T_light (mired, MK⁻¹; the "LB index" of colour meters):
    /// positive = a warming (amber, CTO / Wratten 81 and 85 series) filter, negative = a
    /// cooling (blue, CTB / Wratten 80 and 82 series) filter.
    pub mired_shift: f64,
    /// The green–magenta shift, as the Δuv (CIE 1960 uv) the filter must remove: the light's
    /// own Δuv, positive = the light lies above the Planckian locus (greenish) and needs a
    /// magenta (minus-green) filter, negative = it lies below (magenta) and needs a green
    /// (plus-green) filter. (Colour meters also give a "CC index" in Kodak CC filter steps;
    /// its conversion from Δuv is not published, so it is not given here.)
    pub green_magenta_duv: f64,
}

/// The correction of a light of correlated colour temperature `cct_k` and Δuv `duv` (Ohno
/// 2014, [`crate::colorimetry::uv_to_cct_duv`]) to `target_k` (e.g. [`TUNGSTEN_K`] or
/// [`DAYLIGHT_K`]). The mired (micro-reciprocal degree) scale is the one filters are rated in
/// because a filter shifts 10⁶/T by nearly the same amount whatever the source (Wyszecki &
/// Stiles, Color Science, 2nd ed., 1982, §3.11; the LB-index/filter table of the Sekonic C-800
/// manual, Appendix 9-2, e.g. +112 MK⁻¹ = Wratten 85). Errors on a CCT or target outside
/// 1000–100,000 K (the range of the CCT method) or a non-finite Δuv.
///
/// ```
/// use spdcam_core::quality::film_tv::{cct_correction, DAYLIGHT_K};
///
/// // Tungsten (3200 K) to daylight (5600 K): a −133.9 mired (blue, full CTB) correction.
/// let c = cct_correction(3200.0, 0.0, DAYLIGHT_K)?;
/// assert!((c.mired_shift + 133.93).abs() < 0.01);
/// # Ok::<(), spdcam_core::Error>(())
/// ```
pub fn cct_correction(cct_k: f64, duv: f64, target_k: f64) -> Result<CctCorrection> {
    for (what, t) in [
        ("light's CCT", cct_k),
        ("target colour temperature", target_k),
    ] {
        if !(CCT_MIN_K..=CCT_MAX_K).contains(&t) {
            return Err(Error::invalid(format!(
                "the {what} {t} K is outside {CCT_MIN_K}–{CCT_MAX_K} K; a mired correction \
                 needs colour temperatures in that range (e.g. a target of {TUNGSTEN_K} K or \
                 {DAYLIGHT_K} K)"
            )));
        }
    }
    if !duv.is_finite() {
        return Err(Error::invalid(format!(
            "Δuv {duv} is not a finite number; no green–magenta correction"
        )));
    }
    Ok(CctCorrection {
        target_k,
        mired_shift: 1e6 / target_k - 1e6 / cct_k,
        green_magenta_duv: duv,
    })
}

/// The correction of `light` to `target_k`, from its CCT and Δuv (Ohno 2014); see
/// [`cct_correction`]. Errors where the light has no meaningful CCT (beyond 1000–100,000 K or
/// [`CCT_MAX_ABS_DUV`] from the Planckian locus).
pub fn cct_correction_of(light: &LightSpectrum, target_k: f64) -> Result<CctCorrection> {
    let (cct, duv) = meaningful_cct(light, "colour-temperature correction")?;
    cct_correction(cct, duv, target_k)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn planckian(t: f64) -> LightSpectrum {
        LightSpectrum::on_grid(&QUALITY_GRID, &planck(t, &QUALITY_GRID).unwrap()).unwrap()
    }

    #[test]
    fn a_reference_illuminant_renders_skin_perfectly_and_is_its_own_ssi_reference() {
        let light = planckian(3000.0);
        let (cct, _) = uv_to_cct_duv(xyz_to_uv1960(light.xyz())).unwrap();
        let r = special_rendering_indices_r1_r15(&light, cct).unwrap();
        for v in r {
            assert!((v - 100.0).abs() < 0.01, "{r:?}");
        }
        let ssi = spectral_similarity_index(&light, &SsiReference::CctMatched).unwrap();
        assert!(ssi > 99.9, "{ssi}");
        let same = spectral_similarity_index(&light, &SsiReference::Spectrum(light.clone()));
        assert_eq!(same.unwrap(), 100.0);
        // 3000 K against 6500 K daylight: a clearly different shape.
        let far = spectral_similarity_index(&light, &SsiReference::Daylight(6500.0)).unwrap();
        assert!(far < 80.0, "{far}");
    }

    #[test]
    fn ssi_refuses_spectra_without_power_in_its_range() {
        let mut v = vec![0.0; QUALITY_GRID.count];
        v[700 - 360] = 1.0;
        let red = LightSpectrum::on_grid(&QUALITY_GRID, &v).unwrap();
        let e = spectral_similarity_index(&red, &SsiReference::Planckian(3200.0)).unwrap_err();
        assert!(
            e.to_string()
                .contains("test spectrum has no power in 375–675 nm"),
            "{e}"
        );
        let e = spectral_similarity_index(&planckian(3200.0), &SsiReference::Spectrum(red));
        assert!(e.unwrap_err().to_string().contains("reference spectrum"));
        let e = spectral_similarity_index(&planckian(3200.0), &SsiReference::Daylight(3000.0));
        assert!(e.unwrap_err().to_string().contains("daylight CCT 3000 K"));
    }

    #[test]
    fn coloured_light_has_no_cct_based_answer() {
        // A 525 nm line is Δuv ≈ 0.2 from the Planckian locus: no CCT, so no CCT-matched
        // reference and no filter correction, with the reason.
        let mut v = vec![0.0; QUALITY_GRID.count];
        v[525 - 360] = 1.0;
        let green = LightSpectrum::on_grid(&QUALITY_GRID, &v).unwrap();
        let e = cct_correction_of(&green, DAYLIGHT_K)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("dominant wavelength") && e.contains("±0.05"),
            "{e}"
        );
        let e = spectral_similarity_index(&green, &SsiReference::CctMatched).unwrap_err();
        assert!(e.to_string().contains("CCT-matched SSI reference"), "{e}");
        // Against a fixed reference the SSI is still defined.
        assert!(spectral_similarity_index(&green, &SsiReference::Planckian(3200.0)).is_ok());
    }

    #[test]
    fn mired_and_green_magenta_shifts() {
        let c = cct_correction(3200.0, 0.0, 5600.0).unwrap();
        assert!((c.mired_shift - (1e6 / 5600.0 - 1e6 / 3200.0)).abs() < 1e-12);
        assert!((c.mired_shift + 133.928_571).abs() < 1e-5, "{c:?}");
        let back = cct_correction(5600.0, 0.0, 3200.0).unwrap();
        assert_eq!(back.mired_shift, -c.mired_shift);
        // 5500 K daylight to 3400 K: +112 mired, the Wratten 85 of the Sekonic C-800 table.
        let w85 = cct_correction(5500.0, 0.0, 3400.0).unwrap();
        assert!((w85.mired_shift - 112.3).abs() < 0.1, "{w85:?}");
        let green = cct_correction(4000.0, 0.004, 4000.0).unwrap();
        assert_eq!((green.mired_shift, green.green_magenta_duv), (0.0, 0.004));
        let e = cct_correction(3200.0, 0.0, 0.0).unwrap_err();
        assert!(
            e.to_string().contains("target colour temperature 0 K"),
            "{e}"
        );
        assert!(cct_correction(f64::NAN, 0.0, 3200.0).is_err());
        assert!(cct_correction(3200.0, f64::INFINITY, 3200.0).is_err());
        let light = planckian(3200.0);
        let c = cct_correction_of(&light, TUNGSTEN_K).unwrap();
        assert!(
            c.mired_shift.abs() < 0.1 && c.green_magenta_duv.abs() < 1e-4,
            "{c:?}"
        );
    }
}
