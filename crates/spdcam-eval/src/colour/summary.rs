//! The colour protocol's numbers for a group of photos: how many were refused and judged
//! `ok`, the mean GFC, the median Δu′v′, the CCT error and, where the estimates carry
//! calibrated intervals, how wide the CCT's 95 % interval is and how often it holds the
//! truth.

use super::photos::{PhotoScore, Scored};

/// The CCT numbers of a group: over the photos whose true light lies within
/// [`CCT_MAX_DUV`](super::score::CCT_MAX_DUV) of the Planckian locus.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CctSummary {
    /// Photos scored on CCT.
    pub photos: usize,
    /// Median signed relative CCT error, (estimate − truth) / truth.
    pub median_error: f64,
    /// Share of those photos whose CCT is read too high.
    pub too_high: f64,
    /// Median absolute relative CCT error.
    pub median_abs_error: f64,
    /// Median half-width of the 95 % interval relative to the estimated CCT (over the photos
    /// with one), and the share of the photos scored on CCT whose interval holds the true
    /// CCT (a photo without an interval does not); `None` where no photo has an interval.
    pub interval: Option<(f64, f64)>,
}

/// The numbers of one group of photos.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Summary {
    /// Photos taken.
    pub photos: usize,
    /// Share refused (no chart found).
    pub refused: f64,
    /// Share judged `ok` (a refused photo is not).
    pub ok: f64,
    /// Mean GFC (400–700 nm) over the photos estimated.
    pub gfc: f64,
    /// Median Δu′v′ over the photos estimated.
    pub delta_uv_prime: f64,
    /// The CCT numbers; `None` where no photo is scored on CCT.
    pub cct: Option<CctSummary>,
}

/// The median of `values` (the mean of the middle two for an even count); NaN when empty.
///
/// ```
/// use spdcam_eval::colour::median;
///
/// assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
/// assert_eq!(median(vec![4.0, 1.0, 2.0, 3.0]), 2.5);
/// assert!(median(Vec::new()).is_nan());
/// ```
pub fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    match n {
        0 => f64::NAN,
        _ if n % 2 == 1 => values[n / 2],
        _ => 0.5 * (values[n / 2 - 1] + values[n / 2]),
    }
}

/// The share of `items` for which `test` holds; 0 for none.
fn share<T>(items: &[T], test: impl Fn(&T) -> bool) -> f64 {
    if items.is_empty() {
        return 0.0;
    }
    items.iter().filter(|x| test(x)).count() as f64 / items.len() as f64
}

impl Summary {
    /// The numbers of the photos of `scores` that `select` picks (by light); `None` when
    /// it picks none.
    pub fn of(scores: &[PhotoScore], select: impl Fn(usize) -> bool) -> Option<Summary> {
        let photos: Vec<&PhotoScore> = scores.iter().filter(|s| select(s.light)).collect();
        if photos.is_empty() {
            return None;
        }
        let estimated: Vec<&Scored> = photos.iter().filter_map(|s| s.estimate.as_ref()).collect();
        let gfc = if estimated.is_empty() {
            f64::NAN
        } else {
            estimated.iter().map(|s| s.gfc).sum::<f64>() / estimated.len() as f64
        };
        Some(Summary {
            photos: photos.len(),
            refused: share(&photos, |s| s.estimate.is_none()),
            ok: share(&photos, |s| s.estimate.is_some_and(|e| e.ok)),
            gfc,
            delta_uv_prime: median(estimated.iter().map(|s| s.colour.delta_uv_prime).collect()),
            cct: cct_summary(&estimated),
        })
    }
}

/// The CCT numbers of the estimates whose truth is scored on CCT.
fn cct_summary(estimated: &[&Scored]) -> Option<CctSummary> {
    let scored: Vec<(&Scored, f64)> = estimated
        .iter()
        .filter_map(|s| s.colour.cct_error().map(|e| (*s, e)))
        .collect();
    if scored.is_empty() {
        return None;
    }
    let errors: Vec<f64> = scored.iter().map(|(_, e)| *e).collect();
    // Half-widths over the photos with an interval; a photo without one (its perturbed
    // copies define no CCT) does not hold the truth.
    let intervals: Vec<(f64, bool)> = scored
        .iter()
        .filter_map(|(s, _)| {
            let (cct, half) = s.cct_interval?;
            let truth = s.colour.true_cct?;
            Some((half / cct, (cct - truth).abs() <= half))
        })
        .collect();
    Some(CctSummary {
        photos: scored.len(),
        median_error: median(errors.clone()),
        too_high: share(&errors, |e| *e > 0.0),
        median_abs_error: median(errors.iter().map(|e| e.abs()).collect()),
        interval: (!intervals.is_empty()).then(|| {
            let held = intervals.iter().filter(|(_, holds)| *holds).count();
            (
                median(intervals.iter().map(|(w, _)| *w).collect()),
                held as f64 / scored.len() as f64,
            )
        }),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colour::score::ColourScore;

    fn scored(truth: f64, estimate: f64, half: Option<f64>) -> Scored {
        Scored {
            gfc: 0.9,
            colour: ColourScore {
                delta_uv_prime: 0.01,
                true_uv_prime: [0.2, 0.5],
                estimate_uv_prime: [0.21, 0.5],
                true_cct: Some(truth),
                estimate_cct: Some(estimate),
                true_duv: Some(0.0),
                estimate_duv: Some(0.001),
            },
            ok: true,
            cct_interval: half.map(|h| (estimate, h)),
            rf: None,
            expected_gfc: None,
            raw_bias: None,
            band95_held: None,
        }
    }

    #[test]
    fn refused_photos_count_against_ok_but_not_in_the_errors() {
        let scores = [
            PhotoScore {
                light: 0,
                camera: None,
                estimate: Some(scored(3000.0, 3300.0, Some(330.0))),
            },
            PhotoScore {
                light: 0,
                camera: None,
                estimate: Some(scored(4000.0, 3800.0, Some(100.0))),
            },
            PhotoScore {
                light: 0,
                camera: None,
                estimate: None,
            },
            PhotoScore {
                light: 1,
                camera: None,
                estimate: Some(scored(5000.0, 9000.0, None)),
            },
        ];
        let s = Summary::of(&scores, |l| l == 0).unwrap();
        assert_eq!(s.photos, 3);
        assert!((s.refused - 1.0 / 3.0).abs() < 1e-12);
        assert!((s.ok - 2.0 / 3.0).abs() < 1e-12);
        assert!((s.gfc - 0.9).abs() < 1e-12);
        let c = s.cct.unwrap();
        assert_eq!(c.photos, 2);
        // +10 % and −5 %: median +2.5 %, one of two too high, median |error| 7.5 %.
        assert!((c.median_error - 0.025).abs() < 1e-12);
        assert_eq!(c.too_high, 0.5);
        assert!((c.median_abs_error - 0.075).abs() < 1e-12);
        // Half-widths 10 % and 100/3800; the first holds (330 ≥ 300), the second not.
        let (width, holds) = c.interval.unwrap();
        assert!((width - 0.5 * (0.1 + 100.0 / 3800.0)).abs() < 1e-12);
        assert_eq!(holds, 0.5);
        // No photo of light 2; light 1 without intervals.
        assert!(Summary::of(&scores, |l| l == 2).is_none());
        assert_eq!(
            Summary::of(&scores, |l| l == 1)
                .unwrap()
                .cct
                .unwrap()
                .interval,
            None
        );
    }
}
