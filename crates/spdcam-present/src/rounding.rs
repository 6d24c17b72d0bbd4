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
//!   Δuv beyond 0.0125, a quarter of the ±0.05 within which a CCT means anything (Ohno 2014),
//!   unless the whole interval lies beyond ±0.05 (the photo then shows a coloured light, and
//!   by about how much);
//!   for ratios (melanopic DER, S/P, blue-light hazard, PPF per lux) a half-width beyond
//!   half the value (the interval then spans more than a factor of three); for a filter's
//!   mired shift beyond 25 mired (about an eighth CTO, the smallest correction gel). In
//!   place of the number, the interval itself ([`undetermined_words`]).
//! - One unit per quantity: PPF per lux in µmol s⁻¹ m⁻² per 1000 lx ([`scale`]).
//!
//! Each metric's unit, scale, precision, limit and range are columns of its row in the
//! metric registry ([`registry::METRICS`]); the rules above are what those columns hold.

use spdcam_core::quality::registry::{self, Determined, Metric, Precision};

/// What follows a number that has no interval beside numbers that carry theirs: the trust
/// calibration gives it none ([`registry::Metric::calibrated`]), or none for this model.
pub const UNCALIBRATED: &str = "uncalibrated: no interval";

/// `text`, a number as shown, followed by [`UNCALIBRATED`] where the estimate's other
/// numbers carry intervals (`calibrated`) and this one has none (`half95` is `None`).
pub fn marked_uncalibrated(text: String, half95: Option<f64>, calibrated: bool) -> String {
    if calibrated && half95.is_none() {
        format!("{text} ({UNCALIBRATED})")
    } else {
        text
    }
}

/// The words that stand in place of a number its photo does not determine.
pub const NOT_DETERMINABLE: &str = "not determinable from this photo";

/// The registry's row of `key` ([`registry::METRICS`]); a key it does not hold is written
/// as a plain number of three significant digits, determined within ±25.
fn row(key: &str) -> Metric {
    registry::metric(key).copied().unwrap_or(Metric {
        key: "",
        reason_key: "",
        symbol: "",
        label: "",
        explanation: "",
        unit: "",
        shown_scale: 1.0,
        group: registry::Group::FilmTv,
        precision: Precision::Significant3,
        lab_decimals: 3,
        determined: Determined::Within(25.0),
        at_most_100: false,
        may_be_negative: true,
        meaningful_for: registry::MeaningfulFor::AnyLight,
        calibrated: false,
        interval_in_per_cent: false,
        source: registry::Source::Meter,
    })
}

/// What the metric of `key` is multiplied by before it is shown: PPF per lux (stored per
/// lux) is shown per 1000 lx, all else as stored ([`Metric::shown_scale`]).
pub fn scale(key: &str) -> f64 {
    row(key).shown_scale
}

/// The unit shown after the metric of `key` (empty for none): one unit per quantity
/// everywhere ([`Metric::unit`]).
pub fn unit(key: &str) -> &'static str {
    row(key).unit
}

/// Whether a value `value` with 95 % half-width `half` (both as shown, after [`scale`]) is
/// determined by the photo, by the rules of the module's documentation
/// ([`Metric::determined`]).
pub fn determinable(key: &str, value: f64, half: f64) -> bool {
    match row(key).determined {
        Determined::WithinShare(share) => half <= share * value.abs(),
        Determined::Within(limit) => half <= limit,
        // Or, far from white, an interval wholly beyond the ±0.05 within which a CCT means
        // anything: the photo then shows the light is coloured, and by about how much.
        Determined::WithinOrColoured(limit) => {
            half <= limit || value.abs() - half > spdcam_infer::estimate::MAX_CCT_DUV
        }
    }
}

/// The metric of `key` as every front end shows it, without its unit: `6480 ± 310`,
/// `+0.0031 ± 0.0012`, `82` (no interval: the metric's usual precision), or `Err` with
/// [`NOT_DETERMINABLE`] when the interval is too wide ([`determinable`]). `value` and
/// `half95` are as stored; [`scale`] is applied here.
pub fn shown(key: &str, value: f64, half95: Option<f64>) -> Result<String, &'static str> {
    let metric = row(key);
    let k = metric.shown_scale;
    let value = k * value;
    let sign = if metric.precision.signed() && value >= 0.0 {
        "+"
    } else {
        ""
    };
    match half95.map(|h| k * h).filter(|h| *h > 0.0 && h.is_finite()) {
        Some(half) if !determinable(key, value, half) => Err(NOT_DETERMINABLE),
        Some(half) => {
            let (v, h) = round_with_uncertainty(value, half);
            Ok(format!("{sign}{v} ± {h}"))
        }
        None => Ok(match metric.precision {
            Precision::Signed4 => format!("{value:+.4}"),
            Precision::SignedWhole => format!("{value:+.0}"),
            Precision::Whole => format!("{value:.0}"),
            Precision::Significant3 => round_sig(value, 3),
        }),
    }
}

/// [`shown`] with the unit, and the words in place of an undeterminable number
/// ([`undetermined_words`]): what a line of text prints, e.g. `6480 ± 310 K`.
pub fn shown_with_unit(key: &str, value: f64, half95: Option<f64>) -> String {
    match shown(key, value, half95) {
        Ok(v) if unit(key).is_empty() => v,
        Ok(v) => format!("{v} {}", unit(key)),
        Err(_) => undetermined_words(key, value, half95),
    }
}

/// The 95 % interval `value ± half95` of the metric of `key` (both as stored), cut to the
/// values the quantity can take ([`Metric::at_most_100`], [`Metric::may_be_negative`]):
/// indices on the 0–100 scale (CIE 13.3 Ra and R1–R15, TM-30 Rf, SSI) never exceed 100, and
/// quantities that cannot be negative (CCT, TM-30 Rg, the ratios and efficacies) never fall
/// below 0.
pub fn interval_bounds(key: &str, value: f64, half95: f64) -> (f64, f64) {
    let metric = row(key);
    let (mut lo, mut hi) = (value - half95, value + half95);
    if metric.at_most_100 {
        hi = hi.min(100.0);
        lo = lo.min(hi);
    }
    if !metric.may_be_negative {
        lo = lo.max(0.0);
        hi = hi.max(lo);
    }
    (lo, hi)
}

/// What stands in place of a number whose 95 % interval is too wide to round to one
/// ([`determinable`]): [`NOT_DETERMINABLE`] and, when the interval is known, what the photo
/// does say, e.g. `not determinable from this photo (between 2400 and 4200 K, 95 %)`. A
/// person can still act on a range ("warmer than 2400 K"); a rounded middle would claim more.
pub fn undetermined_words(key: &str, value: f64, half95: Option<f64>) -> String {
    let k = scale(key);
    match half95.filter(|h| *h > 0.0 && h.is_finite()) {
        Some(half) if value.is_finite() => {
            let (lo, hi) = interval_bounds(key, k * value, k * half);
            let rounded = |x: f64| round_with_uncertainty(x, k * half).0;
            let unit = match unit(key) {
                "" => String::new(),
                u => format!(" {u}"),
            };
            format!(
                "{NOT_DETERMINABLE} (between {} and {}{unit}, 95 %)",
                rounded(lo),
                rounded(hi)
            )
        }
        _ => NOT_DETERMINABLE.to_string(),
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
            format!("{NOT_DETERMINABLE} (between 4100 and 5900 K, 95 %)")
        );
    }

    #[test]
    fn an_undetermined_number_gives_the_interval_the_photo_supports() {
        // R9 20 ± 44: −24 to 64, rounded at the half-width's place (one digit of 44: tens).
        assert_eq!(
            undetermined_words("cri_r9", 20.0, Some(44.0)),
            format!("{NOT_DETERMINABLE} (between -20 and 60, 95 %)")
        );
        // Ra 90 ± 30 cannot exceed 100; a CCT cannot fall below 0 K.
        assert_eq!(interval_bounds("cri_ra", 90.0, 30.0), (60.0, 100.0));
        assert_eq!(interval_bounds("cct_k", 3000.0, 4000.0), (0.0, 7000.0));
        // A mired shift and Δuv keep their sign.
        assert_eq!(interval_bounds("mired_5600", -10.0, 40.0), (-50.0, 30.0));
        // PPF per lux in its shown unit (per 1000 lx).
        assert_eq!(
            undetermined_words("ppf_per_lux", 0.0296, Some(0.02)),
            format!("{NOT_DETERMINABLE} (between 10 and 50 µmol s⁻¹ m⁻² per 1000 lx, 95 %)")
        );
        // Without an interval, the words alone.
        assert_eq!(undetermined_words("cri_r9", 20.0, None), NOT_DETERMINABLE);
    }

    #[test]
    fn a_duv_wholly_beyond_the_white_limit_is_shown() {
        // The SG example: |Duv| 0.090 ± 0.025 lies wholly beyond 0.05, so the photo says the
        // light is coloured and by about how much.
        assert_eq!(shown("duv", 0.090, Some(0.025)).unwrap(), "+0.090 ± 0.025");
        assert_eq!(shown("duv", -0.090, Some(0.025)).unwrap(), "-0.090 ± 0.025");
        // 0.06 ± 0.025 reaches back inside ±0.05: not determinable.
        assert_eq!(shown("duv", 0.06, Some(0.025)), Err(NOT_DETERMINABLE));
    }
}
