//! CIE S 026:2018 α-opic quantities: the efficacy of a light for each of the five
//! photoreceptors of the human eye, per lumen and relative to daylight D65.
//!
//! CIE S 026/E:2018, "CIE system for metrology of optical radiation for ipRGC-influenced
//! responses to light". For each α of S-cones (sc, cyanopic), M-cones (mc, chloropic),
//! L-cones (lc, erythropic), rods (rh, rhodopic) and ipRGCs (mel, melanopic), with the action
//! spectrum s_α(λ) (peak 1; shipped as `data/cie_s026_alpha_opic.csv`):
//!
//! - α-opic irradiance E_α = Σ E(λ) s_α(λ) Δλ (§3.3),
//! - α-opic efficacy of luminous radiation K_α,v = E_α / E_v with
//!   E_v = K_m Σ E(λ) V(λ) Δλ and K_m = 683.002 lm/W (§3.6),
//! - α-opic daylight (D65) efficacy ratio γ_α,v = K_α,v / K_α,v^D65 (§3.9); the melanopic one
//!   is the M-EDER, and melanopic EDI = γ_mel,v · E_v.
//!
//! Sums run at 1 nm over 380–780 nm (the action spectra are zero below 380 nm on the
//! 360–780 nm grid; V(λ) is the CIE 1931 ȳ). K_α,v^D65 is computed the same way from the
//! shipped CIE D65 table; it reproduces S 026's Table 2 (sc 0.8173, mc 1.4558, lc 1.6289,
//! rh 1.4497, mel 1.3262 mW/lm) within 2e-4 mW/lm (S 026 used the 1 nm D65 table).

use super::spectrum::{LightSpectrum, QUALITY_GRID};
use crate::builtin;
use crate::cie_illuminant::StandardIlluminant;
use crate::error::Result;
use crate::spectral::{Extrapolation, Interpolation};
use serde::{Deserialize, Serialize};
use std::sync::OnceLock;

/// Maximum luminous efficacy of photopic vision K_m, lm/W (CIE S 026:2018; CIE 015:2018).
pub const K_M: f64 = 683.002;

/// One value per α-opic photoreceptor type of CIE S 026:2018.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AlphaValues {
    /// S-cone-opic (cyanopic).
    pub sc: f64,
    /// M-cone-opic (chloropic).
    pub mc: f64,
    /// L-cone-opic (erythropic).
    pub lc: f64,
    /// Rhodopic.
    pub rh: f64,
    /// Melanopic.
    pub mel: f64,
}

impl AlphaValues {
    fn from_array(a: [f64; 5]) -> AlphaValues {
        AlphaValues {
            sc: a[0],
            mc: a[1],
            lc: a[2],
            rh: a[3],
            mel: a[4],
        }
    }

    /// The values in the order sc, mc, lc, rh, mel.
    pub fn to_array(&self) -> [f64; 5] {
        [self.sc, self.mc, self.lc, self.rh, self.mel]
    }
}

/// The CIE S 026 α-opic ratios of a light (independent of its absolute level).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AlphaOpic {
    /// α-opic efficacy of luminous radiation K_α,v in mW/lm (α-opic irradiance in mW/m² per
    /// lux of illuminance).
    pub elr_mw_per_lm: AlphaValues,
    /// α-opic daylight (D65) efficacy ratio γ_α,v (1 for D65); `der.mel` is the M-EDER.
    pub der: AlphaValues,
}

/// The five action spectra on [`QUALITY_GRID`] and the D65 efficacies, built once.
struct Tables {
    spectra: Vec<Vec<f64>>,
    d65_elr: [f64; 5],
}

fn tables() -> &'static Tables {
    static T: OnceLock<Tables> = OnceLock::new();
    T.get_or_init(|| {
        let (set, _) = builtin::CIE_S026_ALPHA_OPIC
            .load()
            .and_then(|t| t.resample(&QUALITY_GRID, Interpolation::Auto, Extrapolation::Zero))
            .expect("the shipped α-opic table resamples");
        let spectra = set.items().to_vec();
        let d65 = StandardIlluminant::D65
            .spd(&QUALITY_GRID)
            .and_then(|v| LightSpectrum::on_grid(&QUALITY_GRID, &v))
            .expect("D65 on the quality grid");
        let d65_elr = elr(&spectra, &d65);
        Tables { spectra, d65_elr }
    })
}

/// K_α,v of `light` in W/lm for each action spectrum.
fn elr(spectra: &[Vec<f64>], light: &LightSpectrum) -> [f64; 5] {
    let e_v = K_M * light.xyz()[1];
    std::array::from_fn(|i| light.weighted_sum(&spectra[i]) / e_v)
}

/// The CIE S 026:2018 α-opic efficacies (ELR) and daylight efficacy ratios (DER) of `light`.
/// `light` has visible light by construction, so E_v > 0 and the ratios are defined.
pub fn alpha_opic_cie_s026(light: &LightSpectrum) -> Result<AlphaOpic> {
    let t = tables();
    let k = elr(&t.spectra, light);
    Ok(AlphaOpic {
        elr_mw_per_lm: AlphaValues::from_array(k.map(|v| 1000.0 * v)),
        der: AlphaValues::from_array(std::array::from_fn(|i| k[i] / t.d65_elr[i])),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn d65_reproduces_the_published_efficacies() {
        // CIE S 026:2018 Table 2: K_α,v^D65 in mW/lm for sc, mc, lc, rh, mel. S 026 integrates
        // the 1 nm CIE D65 table; the shipped one is the 5 nm table (Sprague-interpolated here),
        // which moves the cyanopic value by 1.5e-4 mW/lm.
        let published = [0.8173, 1.4558, 1.6289, 1.4497, 1.3262];
        let d65 = StandardIlluminant::D65.spd(&QUALITY_GRID).unwrap();
        let light = LightSpectrum::on_grid(&QUALITY_GRID, &d65).unwrap();
        let a = alpha_opic_cie_s026(&light).unwrap();
        for (k, p) in a.elr_mw_per_lm.to_array().iter().zip(published) {
            assert!((k - p).abs() <= 0.0002, "{k} vs {p}");
        }
        for d in a.der.to_array() {
            assert!((d - 1.0).abs() < 1e-12, "{d}");
        }
    }

    #[test]
    fn monochromatic_light_at_490_nm() {
        // A narrow line at 490 nm: K_mel,v = s_mel(490)/(K_m V(490)), with the table values
        // s_mel(490) = 1 and V(490) = ȳ(490) = 0.208020 (CIE 015:2018).
        let mut v = vec![0.0; QUALITY_GRID.count];
        v[490 - 360] = 1.0;
        let light = LightSpectrum::on_grid(&QUALITY_GRID, &v).unwrap();
        let a = alpha_opic_cie_s026(&light).unwrap();
        let expected = 1000.0 / (K_M * 0.208020);
        assert!((a.elr_mw_per_lm.mel / expected - 1.0).abs() < 1e-5, "{a:?}");
    }
}
