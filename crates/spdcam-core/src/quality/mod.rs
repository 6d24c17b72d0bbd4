//! Lighting-quality metrics of a light's spectrum: what the light does for colour, for the
//! eye's five photoreceptors, for plants and for the retina.
//!
//! Each metric cites its standard and works on any SPD on any grid, resampled once into a
//! [`LightSpectrum`] (360–780 nm at 1 nm):
//!
//! - chromaticity: CIE 1931 xy, CIE 1960 uv, CIE 1976 u′v′ ([`uv`]); CCT and Duv by Ohno (2014)
//!   ([`crate::colorimetry::uv_to_cct_duv`]);
//! - colour rendering: CIE 13.3-1995 Ra and R1–R14 ([`cri`]);
//! - colour fidelity and gamut: CIE 224:2017 / ANSI/IES TM-30-20 Rf, Rg and the 16 hue bins
//!   ([`tm30`], with CIECAM02/CAM02-UCS in [`cam02`]); the NIST Colour Quality Scale 9.0
//!   Qa ([`cqs`]);
//! - CIE S 026:2018 α-opic efficacies and daylight efficacy ratios, M-EDER ([`alpha_opic`]);
//! - S/P ratio, photosynthetic photon flux per lumen, blue-light hazard efficacy
//!   ([`photobiology`]);
//! - for coloured light, the dominant or complementary wavelength and excitation purity
//!   (CIE 015:2018), and the peak wavelength ([`dominant`]);
//! - for film and television, R15 (JIS Z 8726) beside R1–R14, the Academy Spectral
//!   Similarity Index and the mired and green–magenta correction to a target CCT
//!   ([`film_tv`]).
//!
//! [`LightingMetrics`] gathers every number; a value that is not defined for a light is `None`
//! with the reason in [`LightingMetrics::reasons`]. The single numbers a person reads, with
//! their names, units, rounding and groups, are the rows of one table,
//! [`registry::METRICS`]. The results match colour-science 0.4.7 (CRI, CIE 2017/TM-30, NIST
//! CQS 9.0, CCT) and luxpy 1.12.5 (α-opic) on 221 measured lamps
//! (`tests/quality_reference.rs`).

pub mod alpha_opic;
pub mod cam02;
pub mod cqs;
pub mod cri;
pub mod dominant;
pub mod film_tv;
pub mod photobiology;
pub mod reference;
pub mod registry;
mod spectrum;
pub mod tm30;
pub mod uv;

pub use alpha_opic::{alpha_opic_cie_s026, AlphaOpic, AlphaValues};
pub use cqs::{colour_quality_scale_nist_cqs90, ColourQualityScale};
pub use cri::{colour_rendering_cie1995, ColourRendering};
pub use dominant::{
    dominant_wavelength, dominant_wavelength_of, peak_wavelength_nm, DominantWavelength,
    ILLUMINANT_E_XY,
};
pub use film_tv::{
    cct_correction, cct_correction_of, special_rendering_index_r15,
    special_rendering_indices_r1_r15, spectral_similarity_index, CctCorrection, SsiReference,
};
pub use photobiology::{blue_light_hazard_efficacy, ppf_per_lumen, scotopic_photopic_ratio};
pub use spectrum::{LightSpectrum, QUALITY_GRID};
pub use tm30::{colour_fidelity_cie2017, ColourFidelity, HueBin};

use crate::colorimetry::{uv_to_cct_duv, xyz_to_xy};
use crate::spectral::Spd;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// CIE 13.3-1995 §5.2: Ra is not meaningful for a light farther than this from the Planckian
/// locus (ΔC in CIE 1960 uv).
pub const CRI_MAX_DUV: f64 = 5.4e-3;

/// Every lighting-quality number of one light. Keys are stable (they are the JSON output of
/// `spdcam metrics`); a `None` value has its reason in `reasons` under the same key.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LightingMetrics {
    /// CIE 1931 (x, y).
    pub xy: Option<[f64; 2]>,
    /// CIE 1960 UCS (u, v).
    pub uv_1960: Option<[f64; 2]>,
    /// CIE 1976 UCS (u′, v′).
    pub uv_prime_1976: Option<[f64; 2]>,
    /// Correlated colour temperature, kelvin (Ohno 2014).
    pub cct_k: Option<f64>,
    /// Distance from the Planckian locus in CIE 1960 uv, positive above it.
    pub duv: Option<f64>,
    /// CIE 13.3 general colour rendering index Ra.
    pub cri_ra: Option<f64>,
    /// CIE 13.3 special colour rendering indices R1–R14.
    pub cri_r: Option<[f64; 14]>,
    /// CIE 224:2017 / TM-30-20 fidelity index Rf.
    pub tm30_rf: Option<f64>,
    /// TM-30-20 gamut index Rg.
    pub tm30_rg: Option<f64>,
    /// TM-30-20 hue bins 1–16: local fidelity, chroma and hue shift, bin averages.
    pub tm30_bins: Option<Vec<HueBin>>,
    /// CIE 224:2017 fidelity of each of the 99 colour evaluation samples.
    pub tm30_rf_ces: Option<Vec<f64>>,
    /// NIST Colour Quality Scale 9.0 general index Qa ([`cqs`]).
    pub cqs_qa: Option<f64>,
    /// CIE S 026 α-opic efficacies of luminous radiation, mW/lm.
    pub alpha_opic_elr_mw_per_lm: Option<AlphaValues>,
    /// CIE S 026 α-opic daylight (D65) efficacy ratios.
    pub alpha_opic_der: Option<AlphaValues>,
    /// Melanopic daylight efficacy ratio (M-EDER), CIE S 026.
    pub mel_der: Option<f64>,
    /// Scotopic/photopic ratio.
    pub sp_ratio: Option<f64>,
    /// Photosynthetic photon flux per lumen, µmol·s⁻¹·lm⁻¹ (= µmol·m⁻²·s⁻¹ per lux).
    pub ppf_per_lux: Option<f64>,
    /// Blue-light hazard efficacy K_B,v, W/lm (IEC TR 62778).
    pub blh_efficacy_w_per_lm: Option<f64>,
    /// Why each `None` value is undefined, by key.
    pub reasons: BTreeMap<String, String>,
    /// Caveats about defined values (e.g. Ra of a light far from the Planckian locus).
    pub warnings: Vec<String>,
}

/// The keys of [`LightingMetrics`] that hold numbers, in output order.
pub const METRIC_KEYS: [&str; 19] = [
    "xy",
    "uv_1960",
    "uv_prime_1976",
    "cct_k",
    "duv",
    "cri_ra",
    "cri_r",
    "tm30_rf",
    "tm30_rg",
    "tm30_bins",
    "tm30_rf_ces",
    "cqs_qa",
    "alpha_opic_elr_mw_per_lm",
    "alpha_opic_der",
    "mel_der",
    "sp_ratio",
    "ppf_per_lux",
    "blh_efficacy_w_per_lm",
    "reasons",
];

/// The CCT-dependent keys.
const CCT_KEYS: [&str; 9] = [
    "cct_k",
    "duv",
    "cri_ra",
    "cri_r",
    "tm30_rf",
    "tm30_rg",
    "tm30_bins",
    "tm30_rf_ces",
    "cqs_qa",
];

impl LightingMetrics {
    /// Every metric undefined for `reason` (e.g. a spectrum with no visible light).
    pub fn undefined(reason: &str) -> LightingMetrics {
        let mut m = LightingMetrics::empty();
        m.set_reason(&METRIC_KEYS[..METRIC_KEYS.len() - 1], reason);
        m
    }

    /// No value and no reason yet.
    fn empty() -> LightingMetrics {
        LightingMetrics {
            xy: None,
            uv_1960: None,
            uv_prime_1976: None,
            cct_k: None,
            duv: None,
            cri_ra: None,
            cri_r: None,
            tm30_rf: None,
            tm30_rg: None,
            tm30_bins: None,
            tm30_rf_ces: None,
            cqs_qa: None,
            alpha_opic_elr_mw_per_lm: None,
            alpha_opic_der: None,
            mel_der: None,
            sp_ratio: None,
            ppf_per_lux: None,
            blh_efficacy_w_per_lm: None,
            reasons: BTreeMap::new(),
            warnings: Vec::new(),
        }
    }

    /// The metrics of `spd` on its wavelengths (see [`LightingMetrics::from_samples`]).
    ///
    /// ```
    /// use spdcam_core::cie_illuminant::StandardIlluminant;
    /// use spdcam_core::quality::LightingMetrics;
    /// use spdcam_core::spectral::Grid;
    ///
    /// let a = StandardIlluminant::A.spd(&Grid::SIMULATION)?;
    /// let m = LightingMetrics::of_spd(&a);
    /// // Illuminant A is the CRI's own reference at its CCT: Ra 100.
    /// assert!((m.cri_ra.unwrap() - 100.0).abs() < 0.5);
    /// assert!(m.scalar("tm30_rf").unwrap() > 99.0);
    /// # Ok::<(), spdcam_core::Error>(())
    /// ```
    pub fn of_spd(spd: &Spd) -> LightingMetrics {
        LightingMetrics::from_samples(&spd.grid().wavelengths(), spd)
    }

    /// The metrics of a spectrum sampled at `wavelengths`; a spectrum the metrics cannot take
    /// (no visible light, malformed) gives every value undefined with the error as reason.
    /// The row-level form, for rows of model output sharing one set of wavelengths;
    /// [`LightingMetrics::of_spd`] is the typed form that takes the wavelengths from the
    /// spectrum's grid.
    pub fn from_samples(wavelengths: &[f64], values: &[f64]) -> LightingMetrics {
        match LightSpectrum::from_samples(wavelengths, values) {
            Ok(light) => LightingMetrics::of(&light),
            Err(e) => LightingMetrics::undefined(&e.to_string()),
        }
    }

    /// Every metric of `light`.
    pub fn of(light: &LightSpectrum) -> LightingMetrics {
        let mut m = LightingMetrics::empty();
        let xyz = light.xyz();
        let uv = uv::xyz_to_uv1960(xyz);
        m.xy = Some(xyz_to_xy(xyz));
        m.uv_1960 = Some(uv);
        m.uv_prime_1976 = Some(uv::xyz_to_uv1976(xyz));
        let (lo, hi) = light.source_range_nm();
        if lo > 380.0 || hi < 780.0 {
            m.warnings.push(format!(
                "the spectrum covers {lo}–{hi} nm only; it is taken as zero elsewhere in 380–780 nm"
            ));
        }

        match uv_to_cct_duv(uv) {
            Ok((cct, duv)) => {
                m.cct_k = Some(cct);
                m.duv = Some(duv);
                match colour_rendering_cie1995(light, cct) {
                    Ok(c) => {
                        m.cri_ra = Some(c.ra);
                        m.cri_r = Some(c.r);
                        if duv.abs() > CRI_MAX_DUV {
                            m.warnings.push(format!(
                                "Duv {duv:.4} is beyond CIE 13.3's ±{CRI_MAX_DUV}: Ra and R1–R14 are not meaningful"
                            ));
                        }
                    }
                    Err(e) => m.set_reason(&["cri_ra", "cri_r"], &e.to_string()),
                }
                match colour_fidelity_cie2017(light, cct) {
                    Ok(f) => {
                        m.tm30_rf = Some(f.rf);
                        m.tm30_rg = Some(f.rg);
                        m.tm30_bins = Some(f.bins);
                        m.tm30_rf_ces = Some(f.rf_ces);
                    }
                    Err(e) => m.set_reason(
                        &["tm30_rf", "tm30_rg", "tm30_bins", "tm30_rf_ces"],
                        &e.to_string(),
                    ),
                }
                match colour_quality_scale_nist_cqs90(light, cct) {
                    Ok(q) => m.cqs_qa = Some(q.qa),
                    Err(e) => m.set_reason(&["cqs_qa"], &e.to_string()),
                }
            }
            Err(e) => m.set_reason(&CCT_KEYS, &format!("no correlated colour temperature: {e}")),
        }

        match alpha_opic_cie_s026(light) {
            Ok(a) => {
                m.alpha_opic_elr_mw_per_lm = Some(a.elr_mw_per_lm);
                m.alpha_opic_der = Some(a.der);
                m.mel_der = Some(a.der.mel);
            }
            Err(e) => m.set_reason(
                &["alpha_opic_elr_mw_per_lm", "alpha_opic_der", "mel_der"],
                &e.to_string(),
            ),
        }
        m.sp_ratio = Some(scotopic_photopic_ratio(light));
        m.ppf_per_lux = Some(ppf_per_lumen(light));
        m.blh_efficacy_w_per_lm = Some(blue_light_hazard_efficacy(light));
        m.drop_non_finite();
        m
    }

    /// Makes a value that came out non-finite undefined, with a reason: no `NaN` (JSON
    /// `null`) is ever left without saying why.
    fn drop_non_finite(&mut self) {
        let mut dropped = Vec::new();
        for (key, value) in [
            ("cct_k", &mut self.cct_k),
            ("duv", &mut self.duv),
            ("cri_ra", &mut self.cri_ra),
            ("tm30_rf", &mut self.tm30_rf),
            ("tm30_rg", &mut self.tm30_rg),
            ("cqs_qa", &mut self.cqs_qa),
            ("mel_der", &mut self.mel_der),
            ("sp_ratio", &mut self.sp_ratio),
            ("ppf_per_lux", &mut self.ppf_per_lux),
            ("blh_efficacy_w_per_lm", &mut self.blh_efficacy_w_per_lm),
        ] {
            if value.is_some_and(|v| !v.is_finite()) {
                *value = None;
                dropped.push(key);
            }
        }
        if self.cri_r.is_some_and(|r| r.iter().any(|v| !v.is_finite())) {
            self.cri_r = None;
            dropped.push("cri_r");
        }
        self.set_reason(
            &dropped,
            "the computation gave a non-finite number (the spectrum is beyond what double \
             precision holds)",
        );
    }

    /// The value of the single-number metric `key` (a row of [`registry::METRICS`] read from
    /// these metrics), `None` when it is undefined or `key` is not one of them.
    pub fn scalar(&self, key: &str) -> Option<f64> {
        registry::metric(key)?.value(self)
    }

    fn set_reason(&mut self, keys: &[&str], reason: &str) {
        for k in keys {
            self.reasons.insert(k.to_string(), reason.to_string());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cie_illuminant::StandardIlluminant;
    use crate::spectral::Grid;

    #[test]
    fn d65_has_every_metric() {
        let grid = Grid::new(300.0, 780.0, 5.0).unwrap();
        let d65 = StandardIlluminant::D65.spd(&grid).unwrap();
        let m = LightingMetrics::from_samples(&grid.wavelengths(), &d65);
        assert!(m.reasons.is_empty(), "{:?}", m.reasons);
        assert!((m.cct_k.unwrap() - 6504.0).abs() < 2.0, "{:?}", m.cct_k);
        assert!((m.mel_der.unwrap() - 1.0).abs() < 1e-12);
        assert!(m.cri_ra.unwrap() > 99.0 && m.tm30_rf.unwrap() > 99.0);
        assert!(m.warnings.is_empty(), "{:?}", m.warnings);
        for metric in registry::calibrated() {
            assert!(
                m.scalar(metric.key).is_some_and(f64::is_finite),
                "{}",
                metric.key
            );
        }
        assert_eq!(m.scalar("cri_r9"), Some(m.cri_r.unwrap()[8]));
        assert_eq!(m.scalar("cri_ra"), m.cri_ra);
        assert_eq!(m.scalar("no such metric"), None);
    }

    #[test]
    fn undefined_values_carry_reasons_under_their_keys() {
        let m = LightingMetrics::from_samples(&[400.0, 500.0], &[0.0, 0.0]);
        assert!(m.cri_ra.is_none() && m.sp_ratio.is_none());
        assert!(
            m.reasons["cri_ra"].contains("no visible light"),
            "{:?}",
            m.reasons
        );
        let json = serde_json::to_value(&m).unwrap();
        for key in METRIC_KEYS {
            assert!(json.get(key).is_some(), "missing key {key}");
        }
        // And the other way: every field but the warnings is a key of the list.
        for key in json.as_object().unwrap().keys() {
            assert!(
                key == "warnings" || METRIC_KEYS.contains(&key.as_str()),
                "{key} is not in METRIC_KEYS"
            );
        }
        assert!(json["cri_ra"].is_null());
        // A deep red line has a CCT below 1000 K: CCT, CRI and TM-30 are undefined, the
        // photobiological ratios are not.
        let mut v = vec![0.0; QUALITY_GRID.count];
        v[650 - 360] = 1.0;
        let m = LightingMetrics::from_samples(&QUALITY_GRID.wavelengths(), &v);
        assert!(m.cct_k.is_none() && m.tm30_rf.is_none());
        assert!(m.reasons["tm30_rf"].contains("correlated colour temperature"));
        assert!(m.sp_ratio.is_some() && m.mel_der.is_some());
    }
}
