//! What a colour meter's screen shows for an estimate (a Sekonic C-800 class meter leads
//! with these): for white light the CCT and Δuv with their 95 % intervals, for coloured light
//! the dominant (or complementary) wavelength, the excitation purity and the peak
//! wavelength (CIE 015:2018 §9.1, [`spdcam_core::quality::dominant`]); the illuminance when
//! the photo's EXIF allows it; and the film and TV numbers: R1–R15 (JIS Z 8726's R15), the
//! Academy SSI and the filter correction to 3200 K and 5600 K
//! ([`spdcam_core::quality::film_tv`]). Every number is written by [`crate::rounding`].

use crate::meaningful::{cct_meaningful, cri_meaningful};
use crate::rounding::{
    marked_uncalibrated, round_sig, shown, shown_with_unit, undetermined_words, NOT_DETERMINABLE,
};
use serde::Serialize;
use spdcam_core::quality::dominant::{dominant_wavelength, peak_wavelength_nm, ILLUMINANT_E_XY};
use spdcam_core::quality::film_tv::{
    cct_correction, special_rendering_indices_r1_r15, spectral_similarity_index, SsiReference,
    DAYLIGHT_K, TUNGSTEN_K,
};
use spdcam_core::quality::{registry, LightSpectrum};
use spdcam_infer::estimate::Estimate;
use spdcam_infer::estimate::MAX_CCT_DUV;

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
    /// Why R9 has no bar, with the interval the photo supports
    /// ([`crate::rounding::undetermined_words`]): `R9 not determinable from this photo
    /// (between -20 and 60, 95 %)`; `None` when R9 is shown.
    pub r9_note: Option<String>,
    /// SSI and the filter corrections to 3200 K and 5600 K, for white light.
    pub film_tv: Vec<Reading>,
}

/// The name of metric `key` in the registry ([`registry::Metric::label`]).
fn label(key: &'static str) -> &'static str {
    registry::metric(key).map_or(key, |m| m.label)
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
                    let hue = spectral_hue(d.wavelength_nm);
                    headline.push(Reading {
                        key: "dominant_nm",
                        label: "Dominant wavelength",
                        value: if d.complementary {
                            format!(
                                "none: a purple light, a mix of red and blue that no single \
                                 wavelength matches; it lies opposite {:.0} nm ({hue}), its \
                                 complementary wavelength",
                                d.wavelength_nm
                            )
                        } else {
                            format!("{:.0} nm ({hue})", d.wavelength_nm)
                        },
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
            // How far from white, where the photo says so: a calibrated interval wholly
            // beyond the ±0.05 of white light (`crate::rounding::determinable`).
            if let (Some(duv), Some(half)) = (duv, half95(e, "duv")) {
                if shown("duv", duv, Some(half)).is_ok() {
                    headline.push(Reading {
                        key: "duv",
                        label: "Δuv",
                        value: shown_with_unit("duv", duv, Some(half)),
                    });
                }
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
        let mut r9_note = None;
        let r1_r15 = match (&light, cct_duv) {
            (Some(light), Some((cct, _))) if cri_meaningful(e).is_ok() => {
                special_rendering_indices_r1_r15(light, cct).ok().map(|r| {
                    let r9_half = half95(e, "cri_r9");
                    let r9_shown = shown("cri_r9", r[8], r9_half).is_ok();
                    if !r9_shown {
                        r9_note = Some(format!(
                            "R9 {}",
                            undetermined_words("cri_r9", r[8], r9_half)
                        ));
                    }
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
            r9_note,
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
    let cct_half = half95(e, "cct_k");
    let cct_undetermined = shown("cct_k", cct, cct_half).is_err();
    let calibrated = e.trust.as_ref().is_some_and(|t| t.uncertainty.is_some());
    let mut out = Vec::new();
    for (key, reference) in [
        ("ssi", SsiReference::CctMatched),
        ("ssi_3200", SsiReference::Planckian(TUNGSTEN_K)),
        ("ssi_5600", SsiReference::Daylight(DAYLIGHT_K)),
    ] {
        let label = label(key);
        if let Ok(v) = spectral_similarity_index(light, &reference) {
            let value = if key == "ssi" && cct_undetermined {
                // Its reference is a light of the estimate's own CCT, which the photo does not
                // determine.
                format!("{NOT_DETERMINABLE} (its reference needs the CCT)")
            } else {
                // SSI has no calibrated interval (`registry::Metric::calibrated`): said so
                // rather than a bare number beside numbers that carry theirs.
                marked_uncalibrated(format!("{v:.0}"), None, calibrated)
            };
            out.push(Reading { key, label, value });
        }
    }
    // The mired shift's 95 % half-width from the CCT's: d(10⁶/T) = 10⁶·dT/T² (first order).
    let mired_half = cct_half.map(|h| 1e6 * h / (cct * cct));
    for (key, target) in [("mired_3200", TUNGSTEN_K), ("mired_5600", DAYLIGHT_K)] {
        let label = label(key);
        let Ok(c) = cct_correction(cct, duv, target) else {
            continue;
        };
        let shift = c.mired_shift;
        let value = match (shown(key, shift, mired_half), mired_half) {
            (Ok(v), _) if !cct_undetermined => {
                format!("{v} mired ({})", gel_words(shift))
            }
            // Too wide for one number: the interval, and the gels it spans.
            (_, Some(h)) => mired_range_words(key, shift, h),
            (_, None) => NOT_DETERMINABLE.to_string(),
        };
        out.push(Reading { key, label, value });
    }
    out.push(Reading {
        key: "green_magenta_duv",
        label: "Green–magenta",
        value: green_magenta_words(duv, half95(e, "duv")),
    });
    out
}

/// The green–magenta correction in words: a filter only where the 95 % interval of Δuv
/// excludes zero ("no filter"); otherwise none is called for within what the photo can tell.
fn green_magenta_words(duv: f64, half95: Option<f64>) -> String {
    match shown("duv", duv, half95) {
        Ok(v) if half95.is_some_and(|h| duv.abs() <= h) => format!(
            "no correction needed within what this photo can tell (Δuv {v}: the interval \
             holds 0)"
        ),
        Ok(v) if duv > 0.0 => format!("Δuv {v}: a magenta (minus-green) filter"),
        Ok(v) => format!("Δuv {v}: a green (plus-green) filter"),
        Err(_) => undetermined_words("duv", duv, half95),
    }
}

/// LEE Filters' colour-temperature gels and their mired shifts (LEE Filters, "Colour
/// correction" technical data: 204 full, 205 ½, 206 ¼, 223 ⅛ CT Orange; 201 full, 202 ½,
/// 203 ¼, 218 ⅛ CT Blue); other makers' are within a few mired.
const GELS: [(f64, &str); 8] = [
    (159.0, "a full CTO"),
    (109.0, "a ½ CTO"),
    (64.0, "a ¼ CTO"),
    (26.0, "an ⅛ CTO"),
    (-18.0, "an ⅛ CTB"),
    (-35.0, "a ¼ CTB"),
    (-78.0, "a ½ CTB"),
    (-137.0, "a full CTB"),
];

/// The gel nearest a mired shift, in a filter's words: `warming: about a ¼ CTO`; `no gel`
/// within half the smallest gel's shift (Wyszecki & Stiles 1982 §3.11: positive warms,
/// negative cools).
fn gel_words(mired: f64) -> String {
    let smallest = if mired > 0.0 { 26.0 } else { 18.0 };
    if mired.abs() < smallest / 2.0 {
        return "no gel: less than half an ⅛".to_string();
    }
    let side: Vec<&(f64, &str)> = GELS
        .iter()
        .filter(|(m, _)| (*m > 0.0) == (mired > 0.0))
        .collect();
    let strongest = side
        .iter()
        .max_by(|a, b| a.0.abs().total_cmp(&b.0.abs()))
        .expect("gels on both sides");
    let way = if mired > 0.0 {
        "warming: amber, CTO"
    } else {
        "cooling: blue, CTB"
    };
    if mired.abs() > 1.25 * strongest.0.abs() {
        return format!("{way}; more than {}", strongest.1);
    }
    let nearest = side
        .iter()
        .min_by(|a, b| (a.0 - mired).abs().total_cmp(&(b.0 - mired).abs()))
        .expect("gels on both sides");
    format!("{way}; about {}", nearest.1)
}

/// A mired shift whose 95 % interval is too wide for one number: the interval and the gels
/// at its ends, or that the photo cannot tell which way the light needs correcting.
fn mired_range_words(key: &str, shift: f64, half95: f64) -> String {
    let (lo, hi) = crate::rounding::interval_bounds(key, shift, half95);
    let r = |x: f64| {
        let (v, _) = crate::rounding::round_with_uncertainty(x, half95);
        if x >= 0.0 {
            format!("+{v}")
        } else {
            v
        }
    };
    let span = format!("between {} and {} mired (95 %)", r(lo), r(hi));
    if lo < 0.0 && hi > 0.0 {
        format!("{span}: the photo cannot tell whether it needs warming or cooling")
    } else {
        let end = |m: f64| {
            gel_words(m).split_once("; ").map_or_else(
                || "no gel".to_string(),
                |(_, g)| g.trim_start_matches("about ").to_string(),
            )
        };
        let way = if shift > 0.0 { "warming" } else { "cooling" };
        let (weak, strong) = if shift > 0.0 { (lo, hi) } else { (hi, lo) };
        format!("{span}: {way}, between {} and {}", end(weak), end(strong))
    }
}

/// The hue name of a spectral colour of wavelength `nm` (coarsened from Kelly 1943, "Color
/// designations for lights", J. Opt. Soc. Am. 33, 627–632).
fn spectral_hue(nm: f64) -> &'static str {
    match nm {
        n if n < 450.0 => "violet",
        n if n < 485.0 => "blue",
        n if n < 500.0 => "blue-green",
        n if n < 530.0 => "green",
        n if n < 565.0 => "yellowish green",
        n if n < 580.0 => "yellow",
        n if n < 600.0 => "orange",
        n if n < 620.0 => "reddish orange",
        _ => "red",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rounding::UNCALIBRATED;
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
            .split_once(" nm (")
            .unwrap()
            .0
            .parse()
            .unwrap();
        assert!((nm - 610.0).abs() < 3.0, "{nm}");
        assert!(red.headline[0].value.ends_with("(reddish orange)"));
        assert_eq!(red.headline[2].value, "610 nm");
        assert!(red.film_tv.is_empty() && red.r1_r15.is_none());
        // Red and blue together: a purple, which has no dominant wavelength; the words say
        // so and name the complementary one.
        let purple: Vec<f64> = grid
            .wavelengths()
            .iter()
            .map(|w| (-((w - 450.0) / 10.0).powi(2)).exp() + (-((w - 640.0) / 10.0).powi(2)).exp())
            .collect();
        let purple = Meter::of(&estimate_of(Spd::new(grid, purple).unwrap(), &[]));
        let words = &purple.headline[0].value;
        assert!(
            words.starts_with("none: a purple light") && words.contains("complementary wavelength"),
            "{words}"
        );
        assert!(
            words.contains("nm (green") || words.contains("nm (yellowish green"),
            "{words}"
        );
    }

    #[test]
    fn a_filter_is_advised_only_where_its_interval_excludes_no_filter() {
        // The example: Δuv +0.002 ± 0.008 holds 0 (the true light needed the other
        // filter): no advice.
        let none = green_magenta_words(0.002, Some(0.008));
        assert!(none.starts_with("no correction needed"), "{none}");
        assert!(none.contains("+0.002 ± 0.008"), "{none}");
        assert_eq!(
            green_magenta_words(0.006, Some(0.002)),
            "Δuv +0.0060 ± 0.0020: a magenta (minus-green) filter"
        );
        assert_eq!(
            green_magenta_words(-0.006, Some(0.002)),
            "Δuv -0.0060 ± 0.0020: a green (plus-green) filter"
        );
        // Too wide to say anything: the interval, not advice.
        assert!(green_magenta_words(0.01, Some(0.02)).starts_with(NOT_DETERMINABLE));
    }

    #[test]
    fn a_mired_shift_names_the_nearest_gel_and_a_wide_interval_the_gels_it_spans() {
        // LEE's gels: +64 is a ¼ CTO, −137 a full CTB, +5 no gel, +250 more than a full CTO.
        assert_eq!(gel_words(60.0), "warming: amber, CTO; about a ¼ CTO");
        assert_eq!(gel_words(-130.0), "cooling: blue, CTB; about a full CTB");
        assert!(gel_words(5.0).starts_with("no gel"));
        assert_eq!(
            gel_words(250.0),
            "warming: amber, CTO; more than a full CTO"
        );
        // +90 ± 30 mired: from +60 to +120, a ¼ to a ½ CTO (the issue's "between a ¼ and a ½
        // CTO").
        assert_eq!(
            mired_range_words("mired_5600", 90.0, 30.0),
            "between +60 and +120 mired (95 %): warming, between a ¼ CTO and a ½ CTO"
        );
        // An interval across zero cannot tell the way.
        assert!(mired_range_words("mired_3200", -10.0, 40.0).ends_with("warming or cooling"));
    }

    #[test]
    fn ssi_says_it_has_no_interval_and_follows_an_undetermined_cct() {
        let mut e = estimate_of_d65();
        let m = Meter::of(&e);
        let ssi = m.film_tv.iter().find(|r| r.key == "ssi").unwrap();
        assert!(ssi.value.contains(UNCALIBRATED), "{ssi:?}");
        // A CCT the photo does not determine leaves the SSI against the light's own CCT
        // undetermined too, and the filter corrections give their intervals.
        let u = e.trust.as_mut().unwrap().uncertainty.as_mut().unwrap();
        u.metrics.get_mut("cct_k").unwrap().half95 = 2000.0;
        let m = Meter::of(&e);
        let ssi = m.film_tv.iter().find(|r| r.key == "ssi").unwrap();
        assert!(ssi.value.starts_with(NOT_DETERMINABLE), "{ssi:?}");
        let to3200 = m.film_tv.iter().find(|r| r.key == "mired_3200").unwrap();
        assert!(to3200.value.starts_with("between "), "{to3200:?}");
    }
}
