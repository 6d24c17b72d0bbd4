//! Ratios of a light's effect on rods, plants and the retina to its luminous flux: the
//! scotopic/photopic (S/P) ratio, photosynthetic photon flux per lumen, and the blue-light
//! hazard efficacy.

use super::alpha_opic::K_M;
use super::spectrum::{LightSpectrum, QUALITY_GRID};
use crate::builtin;
use crate::spectral::{Extrapolation, Interpolation};
use std::sync::OnceLock;

/// Maximum luminous efficacy of scotopic vision K′_m, lm/W, and the photopic K_m of the S/P
/// ratio convention (IES TM-12-12; CIE 015:2018 rounds them to 1700 and 683 lm/W).
const K_M_SCOTOPIC: f64 = 1700.0;
const K_M_SP: f64 = 683.0;
/// Planck constant (J·s), speed of light (m/s) and Avogadro constant (1/mol), exact SI values.
const PLANCK_H: f64 = 6.626_070_15e-34;
const LIGHT_C: f64 = 299_792_458.0;
const AVOGADRO: f64 = 6.022_140_76e23;
/// The photosynthetically active range, nm (ANSI/ASABE S640:2017).
const PAR_NM: (f64, f64) = (400.0, 700.0);

/// V′(λ), the photon weights of the PAR range and B(λ) on [`QUALITY_GRID`], built once.
struct Tables {
    v_prime: Vec<f64>,
    /// µmol of photons per joule at each wavelength inside 400–700 nm, 0 outside.
    par_umol_per_j: Vec<f64>,
    blue_hazard: Vec<f64>,
}

fn tables() -> &'static Tables {
    static T: OnceLock<Tables> = OnceLock::new();
    T.get_or_init(|| {
        let on_grid = |t: &builtin::BuiltinTable| {
            t.load()
                .and_then(|s| s.resample(&QUALITY_GRID, Interpolation::Auto, Extrapolation::Zero))
                .map(|(s, _)| s.item(0).to_vec())
                .expect("a shipped photobiology table resamples")
        };
        let par_umol_per_j = QUALITY_GRID
            .wavelengths()
            .iter()
            .map(|&w| {
                if (PAR_NM.0..=PAR_NM.1).contains(&w) {
                    w * 1e-9 / (PLANCK_H * LIGHT_C * AVOGADRO) * 1e6
                } else {
                    0.0
                }
            })
            .collect();
        Tables {
            v_prime: on_grid(&builtin::CIE1951_SCOTOPIC),
            par_umol_per_j,
            blue_hazard: on_grid(&builtin::BLUE_LIGHT_HAZARD),
        }
    })
}

/// The S/P ratio: scotopic over photopic luminous flux,
/// K′_m Σ S V′ Δλ / (K_m Σ S V Δλ) with K′_m = 1700 lm/W, K_m = 683 lm/W, V′ the CIE 1951
/// scotopic function (CIE S 010/ISO 23539:2005) and V the CIE 1931 ȳ (IES TM-12-12).
pub fn scotopic_photopic_ratio(light: &LightSpectrum) -> f64 {
    K_M_SCOTOPIC * light.weighted_sum(&tables().v_prime) / (K_M_SP * light.xyz()[1])
}

/// Photosynthetic photon flux per lumen, µmol·s⁻¹·lm⁻¹ (equal to PPFD in µmol·m⁻²·s⁻¹ per
/// lux): the photons of 400–700 nm, Σ S λ/(h c N_A) Δλ (ANSI/ASABE S640:2017), over the
/// luminous flux K_m Σ S V Δλ with K_m = 683.002 lm/W.
pub fn ppf_per_lumen(light: &LightSpectrum) -> f64 {
    light.weighted_sum(&tables().par_umol_per_j) / (K_M * light.xyz()[1])
}

/// Blue-light hazard efficacy of luminous radiation K_B,v = Σ S B Δλ / (K_m Σ S V Δλ), in W/lm
/// (IEC TR 62778:2014 §4.3; B(λ) of IEC 62471:2006 / ICNIRP 2013, 0 above 700 nm): the
/// blue-light weighted radiance per unit luminance, from which the hazard of a source of
/// known luminance follows.
pub fn blue_light_hazard_efficacy(light: &LightSpectrum) -> f64 {
    light.weighted_sum(&tables().blue_hazard) / (K_M * light.xyz()[1])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line_at(nm: usize) -> LightSpectrum {
        let mut v = vec![0.0; QUALITY_GRID.count];
        v[nm - 360] = 1.0;
        LightSpectrum::on_grid(&QUALITY_GRID, &v).unwrap()
    }

    #[test]
    fn monochromatic_lines_match_hand_computation() {
        // 555 nm: V = ȳ(555) = 1, V′(555) = 0.402 (CIE 1951 table), so S/P = 1700·0.402/683.
        let l555 = line_at(555);
        let sp = scotopic_photopic_ratio(&l555);
        assert!((sp - 1700.0 * 0.402 / 683.0).abs() < 1e-3, "{sp}");
        // 1 W at 555 nm is 683.002 lm and 555e-9/(h c) photons/s = 4.6394 µmol/s.
        let ppf = ppf_per_lumen(&l555);
        let photons = 555e-9 / (PLANCK_H * LIGHT_C) / AVOGADRO * 1e6;
        assert!((photons - 4.6394).abs() < 1e-4, "{photons}");
        assert!((ppf - photons / 683.002).abs() < 1e-12, "{ppf}");
        // 440 nm: B = 1, V = ȳ(440) = 0.023, so K_B,v = 1/(683.002 · 0.023) W/lm.
        let kb = blue_light_hazard_efficacy(&line_at(440));
        assert!((kb - 1.0 / (683.002 * 0.023)).abs() < 1e-9, "{kb}");
        // Outside 400–700 nm no photon counts; above 700 nm no blue-light hazard.
        assert_eq!(ppf_per_lumen(&line_at(720)), 0.0);
        assert_eq!(blue_light_hazard_efficacy(&line_at(720)), 0.0);
        assert!(ppf_per_lumen(&line_at(700)) > 0.0);
    }
}
