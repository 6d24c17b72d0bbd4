//! What a colour meter's screen shows for an estimate (a Sekonic C-800 class meter leads
//! with these): for white light the CCT and Δuv with their 95 % intervals, for coloured light
//! the dominant (or complementary) wavelength, the excitation purity and the peak
//! wavelength (CIE 015:2018 §9.1, [`spdcam_core::quality::dominant`]); the illuminance when
//! the photo's EXIF allows it; and the film and TV numbers: R1–R15 (JIS Z 8726's R15), the
//! Academy SSI and the filter correction to 3200 K and 5600 K
//! ([`spdcam_core::quality::film_tv`]). Every number is written by [`crate::rounding`].

use crate::estimate::Estimate;
use crate::estimate::MAX_CCT_DUV;
use crate::meaningful::{cct_meaningful, cri_meaningful};
use crate::rounding::{round_sig, shown, shown_with_unit, NOT_DETERMINABLE};
use serde::Serialize;
use spdcam_core::quality::dominant::{dominant_wavelength, peak_wavelength_nm, ILLUMINANT_E_XY};
use spdcam_core::quality::film_tv::{
    cct_correction, special_rendering_indices_r1_r15, spectral_similarity_index, SsiReference,
    DAYLIGHT_K, TUNGSTEN_K,
};
use spdcam_core::quality::LightSpectrum;

/// One number of the meter's screen.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Reading {
    /// A key naming it, e.g. `cct_k`, `dominant_nm`, `mired_3200`.
    pub key: &'static str,
    /// Its name as shown, e.g. `CCT`.
    pub label: &'static str,
    /// The number with its ± and unit, or the words saying why there is none.
    pub value: String,
}

/// The meter's screen: the headline readings and the film and TV numbers.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Meter {
    /// `white` (near the Planckian locus: CCT and Δuv lead) or `coloured` (dominant
    /// wavelength and purity lead).
    pub kind: &'static str,
    /// The readings that lead, in order.
    pub headline: Vec<Reading>,
    /// The illuminance on the chart in words, when the photo's EXIF gives it.
    pub illuminance: Option<String>,
    /// R1–R15 (R1 first), when CIE 13.3 is meaningful for the light; R9 `None` when its
    /// calibrated 95 % interval is too wide ([`crate::rounding::determinable`]), the others
    /// have no calibrated interval.
    pub r1_r15: Option<Vec<Option<f64>>>,
    /// SSI and the filter corrections to 3200 K and 5600 K, for white light.
    pub film_tv: Vec<Reading>,
}

/// The 95 % half-width of metric `key`, when calibrated.
fn half95(e: &Estimate, key: &str) -> Option<f64> {
    e.trust
        .as_ref()?
        .uncertainty
        .as_ref()?
        .metrics
        .get(key)
        .map(|i| i.half95)
}

impl Meter {
    /// The meter's screen for `e`.
    pub fn of(e: &Estimate) -> Meter {
        let light = LightSpectrum::on_grid(e.spd.grid(), &e.spd).ok();
        let white =
            cct_meaningful(e).is_ok() && e.metrics.duv.is_some_and(|d| d.abs() <= MAX_CCT_DUV);
        let mut headline = Vec::new();
        let (cct, duv) = (e.metrics.cct_k, e.metrics.duv);
        if let (true, Some(cct), Some(duv)) = (white, cct, duv) {
            headline.push(Reading {
                key: "cct_k",
                label: "CCT",
                value: shown_with_unit("cct_k", cct, half95(e, "cct_k")),
            });
            headline.push(Reading {
                key: "duv",
                label: "Δuv",
                value: shown_with_unit("duv", duv, half95(e, "duv")),
            });
        } else {
            match dominant_wavelength(e.colorimetry.xy, ILLUMINANT_E_XY) {
                Ok(d) => {
                    headline.push(Reading {
                        key: "dominant_nm",
                        label: if d.complementary {
                            "Complementary wavelength"
                        } else {
                            "Dominant wavelength"
                        },
                        value: format!("{:.0} nm", d.wavelength_nm),
                    });
                    headline.push(Reading {
                        key: "excitation_purity",
                        label: "Excitation purity",
                        value: format!("{:.0} %", 100.0 * d.excitation_purity),
                    });
                }
                Err(err) => headline.push(Reading {
                    key: "dominant_nm",
                    label: "Dominant wavelength",
                    value: format!("not defined: {err}"),
                }),
            }
        }
        if let (false, Some(light)) = (white, &light) {
            headline.push(Reading {
                key: "peak_nm",
                label: "Peak wavelength",
                value: format!("{:.0} nm", peak_wavelength_nm(light)),
            });
        }
        let illuminance = match &e.absolute {
            Some(Ok(level)) => Some(format!(
                "about {} lx on the chart (approximate, good to tens of per cent: from the \
                 photo's exposure settings)",
                round_sig(level.illuminance_lux, 2)
            )),
            _ => None,
        };
        let cct_duv = cct.zip(duv).filter(|_| white);
        let r1_r15 = match (&light, cct_duv) {
            (Some(light), Some((cct, _))) if cri_meaningful(e).is_ok() => {
                special_rendering_indices_r1_r15(light, cct).ok().map(|r| {
                    let r9_shown = shown("cri_r9", r[8], half95(e, "cri_r9")).is_ok();
                    r.iter()
                        .enumerate()
                        .map(|(i, v)| (i != 8 || r9_shown).then_some(*v))
                        .collect()
                })
            }
            _ => None,
        };
        Meter {
            kind: if white { "white" } else { "coloured" },
            headline,
            illuminance,
            r1_r15,
            film_tv: film_tv(e, light.as_ref(), cct_duv),
        }
    }
}

/// SSI against the light's own reference, 3200 K and 5600 K, and the filter corrections to
/// 3200 K and 5600 K; empty for a light without a meaningful CCT.
fn film_tv(
    e: &Estimate,
    light: Option<&LightSpectrum>,
    cct_duv: Option<(f64, f64)>,
) -> Vec<Reading> {
    let (Some(light), Some((cct, duv))) = (light, cct_duv) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for (key, label, reference) in [
        ("ssi", "SSI (own CCT)", SsiReference::CctMatched),
        (
            "ssi_3200",
            "SSI (3200 K tungsten)",
            SsiReference::Planckian(TUNGSTEN_K),
        ),
        (
            "ssi_5600",
            "SSI (5600 K daylight)",
            SsiReference::Daylight(DAYLIGHT_K),
        ),
    ] {
        if let Ok(v) = spectral_similarity_index(light, &reference) {
            out.push(Reading {
                key,
                label,
                value: format!("{v:.0}"),
            });
        }
    }
    // The mired shift's 95 % half-width from the CCT's: d(10⁶/T) = 10⁶·dT/T² (first order).
    let mired_half = half95(e, "cct_k").map(|h| 1e6 * h / (cct * cct));
    let cct_undetermined = shown("cct_k", cct, half95(e, "cct_k")).is_err();
    for (key, label, target) in [
        ("mired_3200", "To 3200 K", TUNGSTEN_K),
        ("mired_5600", "To 5600 K", DAYLIGHT_K),
    ] {
        let Ok(c) = cct_correction(cct, duv, target) else {
            continue;
        };
        let value = if cct_undetermined {
            NOT_DETERMINABLE.to_string()
        } else {
            match shown(key, c.mired_shift, mired_half) {
                Ok(v) => format!("{v} mired ({})", filter_words(c.mired_shift)),
                Err(words) => words.to_string(),
            }
        };
        out.push(Reading { key, label, value });
    }
    out.push(Reading {
        key: "green_magenta_duv",
        label: "Green–magenta",
        value: match shown("duv", duv, half95(e, "duv")) {
            Ok(v) if duv > 0.0 => format!("Δuv {v}: a magenta (minus-green) filter"),
            Ok(v) => format!("Δuv {v}: a green (plus-green) filter"),
            Err(words) => words.to_string(),
        },
    });
    out
}

/// Which way a mired shift goes, in a filter's words (positive warms: amber, CTO; negative
/// cools: blue, CTB; Wyszecki & Stiles 1982 §3.11).
fn filter_words(mired: f64) -> &'static str {
    if mired > 0.0 {
        "warming: amber, CTO"
    } else {
        "cooling: blue, CTB"
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::{estimate_of, estimate_of_d65};
    use spdcam_core::spectral::{Grid, Spd};

    #[test]
    fn white_light_leads_with_cct_and_duv_coloured_light_with_its_wavelength() {
        let d65 = Meter::of(&estimate_of_d65());
        assert_eq!(d65.kind, "white");
        assert_eq!(d65.headline[0].key, "cct_k");
        // D65 cut to 400–700 nm: about 6500 K, shown ± 150 K.
        assert!(
            d65.headline[0].value.ends_with(" ± 150 K"),
            "{:?}",
            d65.headline
        );
        assert_eq!(d65.headline[1].key, "duv");
        assert_eq!(d65.r1_r15.as_ref().map(Vec::len), Some(15));
        assert!(d65.r1_r15.as_ref().unwrap().iter().all(Option::is_some));
        // The mired shift to 5600 K of a 6500 K light: 10⁶/5600 − 10⁶/6500 ≈ +25 (warming).
        let to5600 = d65.film_tv.iter().find(|r| r.key == "mired_5600").unwrap();
        assert!(
            to5600.value.starts_with("+2") && to5600.value.contains("warming"),
            "{to5600:?}"
        );
        // A narrow band at 610 nm: coloured, dominant wavelength near 610 nm, purity near 1.
        let grid = Grid::ESTIMATION;
        let red: Vec<f64> = grid
            .wavelengths()
            .iter()
            .map(|w| (-((w - 610.0) / 8.0).powi(2)).exp())
            .collect();
        let red = Meter::of(&estimate_of(Spd::new(grid, red).unwrap(), &[]));
        assert_eq!(red.kind, "coloured");
        assert_eq!(red.headline[0].label, "Dominant wavelength");
        let nm: f64 = red.headline[0]
            .value
            .trim_end_matches(" nm")
            .parse()
            .unwrap();
        assert!((nm - 610.0).abs() < 3.0, "{nm}");
        assert_eq!(red.headline[2].value, "610 nm");
        assert!(red.film_tv.is_empty() && red.r1_r15.is_none());
    }
}
