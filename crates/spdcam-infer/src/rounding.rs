//! The one rule by which every front end writes a number: the command line's text, the HTML
//! report, the web page (which shows the strings the server's JSON carries) and Python's
//! `repr` all call [`shown`], so the same estimate reads with the same digits everywhere.
//!
//! - A number with an uncertainty is rounded by the Particle Data Group's rule (Review of
//!   Particle Physics, Introduction §5.3; the same practice as JCGM 100:2008 §7.2.6, which
//!   asks for at most two significant digits of an uncertainty): the 95 % half-width keeps
//!   two significant digits when its three leading digits are 100–354, one when 355–949,
//!   and is rounded up to two when 950–999; the value is rounded to the same decimal place
//!   (`154 ± 11`, `0.00025 ± 0.00007`).
//! - A number whose 95 % interval is too wide to say anything is not printed; the words
//!   [`NOT_DETERMINABLE`] stand in its place. Too wide is ([`determinable`]): for CCT a
//!   half-width beyond 15 % of the value (a ±15 % CCT spans warm to neutral white, the
//!   whole of an EN 12464-1 colour-appearance group); for indices on a 0–100 scale (CRI Ra
//!   and R1–R15, TM-30 Rf and Rg, SSI) a half-width beyond 25, a quarter of the scale; for
//!   Δuv beyond 0.0125, a quarter of the ±0.05 within which a CCT means anything (Ohno 2014);
//!   for ratios (melanopic DER, S/P, blue-light hazard, PPF per lux) a half-width beyond
//!   half the value (the interval then spans more than a factor of three); for a filter's
//!   mired shift beyond 25 mired (about a quarter CTO, the smallest correction gel).
//! - One unit per quantity: PPF per lux in µmol s⁻¹ m⁻² per 1000 lx ([`scale`]).

/// The words that stand in place of a number its photo does not determine.
pub const NOT_DETERMINABLE: &str = "not determinable from this photo";

/// What the metric of `key` is multiplied by before it is shown: PPF per lux (stored per
/// lux) is shown per 1000 lx, all else as stored.
pub fn scale(key: &str) -> f64 {
    if key == "ppf_per_lux" {
        1000.0
    } else {
        1.0
    }
}

/// The unit shown after the metric of `key` (empty for none): one unit per quantity
/// everywhere.
pub fn unit(key: &str) -> &'static str {
    match key {
        "cct_k" => "K",
        "ppf_per_lux" => "µmol s⁻¹ m⁻² per 1000 lx",
        "blh_efficacy_w_per_lm" => "W/lm",
        k if k.starts_with("mired") => "mired",
        _ => "",
    }
}

/// Whether a value `value` with 95 % half-width `half` (both as shown, after [`scale`]) is
/// determined by the photo, by the rules of the module's documentation.
pub fn determinable(key: &str, value: f64, half: f64) -> bool {
    match key {
        "cct_k" => half <= 0.15 * value.abs(),
        "duv" => half <= 0.0125,
        "mel_der" | "sp_ratio" | "ppf_per_lux" | "blh_efficacy_w_per_lm" => {
            half <= 0.5 * value.abs()
        }
        k if k.starts_with("mired") => half <= 25.0,
        _ => half <= 25.0,
    }
}

/// The metric of `key` as every front end shows it, without its unit: `6480 ± 310`,
/// `+0.0031 ± 0.0012`, `82` (no interval: the metric's usual precision), or `Err` with
/// [`NOT_DETERMINABLE`] when the interval is too wide ([`determinable`]). `value` and
/// `half95` are as stored; [`scale`] is applied here.
pub fn shown(key: &str, value: f64, half95: Option<f64>) -> Result<String, &'static str> {
    let k = scale(key);
    let value = k * value;
    let signed = key == "duv" || key.starts_with("mired");
    let sign = if signed && value >= 0.0 { "+" } else { "" };
    match half95.map(|h| k * h).filter(|h| *h > 0.0 && h.is_finite()) {
        Some(half) if !determinable(key, value, half) => Err(NOT_DETERMINABLE),
        Some(half) => {
            let (v, h) = round_with_uncertainty(value, half);
            Ok(format!("{sign}{v} ± {h}"))
        }
        None => Ok(match key {
            "duv" => format!("{value:+.4}"),
            k if k.starts_with("mired") => format!("{value:+.0}"),
            "cct_k" | "cri_ra" | "tm30_rf" | "tm30_rg" | "ssi" => format!("{value:.0}"),
            k if k.starts_with("cri_r") => format!("{value:.0}"),
            _ => round_sig(value, 3),
        }),
    }
}

/// [`shown`] with the unit, and the words in place of an undeterminable number: what a
/// line of text prints, e.g. `6480 ± 310 K`.
pub fn shown_with_unit(key: &str, value: f64, half95: Option<f64>) -> String {
    match shown(key, value, half95) {
        Ok(v) if unit(key).is_empty() => v,
        Ok(v) => format!("{v} {}", unit(key)),
        Err(words) => words.to_string(),
    }
}

/// `value` and its half-width `half` (> 0) rounded by the Particle Data Group's rule (Review
/// of Particle Physics, Introduction §5.3), as text: `(154.3, 10.83)` → `("154", "11")`.
pub fn round_with_uncertainty(value: f64, half: f64) -> (String, String) {
    let exponent = half.log10().floor() as i32;
    let leading = half / 10f64.powi(exponent - 2);
    // The decimal place (10^place) both numbers are rounded to.
    // Two significant digits for 100–354, one for 355–949; 950–999 rounds up to 1000,
    // which is two significant digits at the same place.
    let place = if leading < 354.5 {
        exponent - 1
    } else {
        exponent
    };
    let unit = 10f64.powi(place);
    let round = |x: f64| (x / unit).round() * unit;
    let decimals = (-place).max(0) as usize;
    let text = |x: f64| {
        let s = format!("{:.decimals$}", round(x));
        // No "-0".
        if s.trim_start_matches('-')
            .chars()
            .all(|c| c == '0' || c == '.')
        {
            s.trim_start_matches('-').to_string()
        } else {
            s
        }
    };
    (text(value), text(half))
}

/// `x` to `digits` significant digits, never in exponent notation: `2718` → `2700` (2).
pub fn round_sig(x: f64, digits: i32) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let place = x.abs().log10().floor() as i32 - (digits - 1);
    let unit = 10f64.powi(place);
    let decimals = (-place).max(0) as usize;
    format!("{:.decimals$}", (x / unit).round() * unit)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_rounded_to_what_their_uncertainty_supports() {
        let r = |v, h| round_with_uncertainty(v, h);
        assert_eq!(r(154.3, 10.83), ("154".into(), "11".into()));
        assert_eq!(
            r(0.0002476, 0.0000662),
            ("0.00025".into(), "0.00007".into())
        );
        assert_eq!(r(2718.0, 828.0), ("2700".into(), "800".into()));
        assert_eq!(r(40.36, 14.14), ("40".into(), "14".into()));
        assert_eq!(r(0.5, 0.0096), ("0.500".into(), "0.010".into()));
        assert_eq!(r(81.26, 4.04), ("81".into(), "4".into()));
        assert_eq!(r(-0.0004, 0.0031), ("-0.0004".into(), "0.0031".into()));
        assert_eq!(r(-0.00001, 0.004), ("0.000".into(), "0.004".into()));
        assert_eq!(round_sig(2718.0, 2), "2700");
        assert_eq!(round_sig(0.06349, 1), "0.06");
        assert_eq!(round_sig(12.3456, 3), "12.3");
    }

    #[test]
    fn an_interval_wider_than_the_quantity_is_not_a_measurement() {
        // The examples: CCT 9266 ± 23910 K, CCT ± 876 K at 5000 K, R9 −2 ± 44.
        assert_eq!(shown("cct_k", 9266.0, Some(23910.0)), Err(NOT_DETERMINABLE));
        assert_eq!(shown("cct_k", 5000.0, Some(876.0)), Err(NOT_DETERMINABLE));
        assert_eq!(shown("cri_r9", -2.0, Some(44.0)), Err(NOT_DETERMINABLE));
        assert_eq!(shown("cct_k", 5000.0, Some(740.0)).unwrap(), "5000 ± 700");
        assert_eq!(shown("cri_ra", 81.26, Some(4.04)).unwrap(), "81 ± 4");
        assert_eq!(
            shown("duv", 0.0031, Some(0.0012)).unwrap(),
            "+0.0031 ± 0.0012"
        );
        assert_eq!(shown("duv", 0.0031, Some(0.02)), Err(NOT_DETERMINABLE));
        // PPF per lux is shown per 1000 lx in every front end.
        assert_eq!(
            shown("ppf_per_lux", 0.0296, Some(0.0075)).unwrap(),
            "30 ± 8"
        );
        assert_eq!(
            shown("ppf_per_lux", 0.0296, Some(0.02)),
            Err(NOT_DETERMINABLE)
        );
        assert_eq!(
            shown_with_unit("ppf_per_lux", 0.0296, None),
            "29.6 µmol s⁻¹ m⁻² per 1000 lx"
        );
        assert_eq!(shown_with_unit("cct_k", 6504.2, None), "6504 K");
        assert_eq!(
            shown_with_unit("cct_k", 5000.0, Some(900.0)),
            NOT_DETERMINABLE
        );
    }
}
