//! The expected GFC's 95 % margin taken among the calibration photos most like the photo at
//! hand: in what its estimate is (the expected 1 − GFC, the CCT) and in what the photo shows
//! (how well the light found explains it, the glare on its dark patches). A real photo that
//! the light explains as real photos are explained, without glare, is judged by the real
//! photos like it; a virtual photo of a lamp the chart cannot tell from another, by those.
//!
//! Localised conformal prediction (Guan 2023, "Localized conformal prediction: a generalized
//! inference framework for conformal prediction", Biometrika 110: 33–50; with the nearest
//! neighbours as the locality, Papadopoulos, Vovk & Gammerman 2011, "Regression conformal
//! prediction with nearest neighbours", JAIR 40: 815–840): the split-conformal 95 % quantile
//! of the held-out residuals of ln(1 − GFC) among the K calibration photos nearest in the
//! standardised coordinates of [`photo_coordinates`].

use serde::{Deserialize, Serialize};

/// How many coordinates place a photo ([`photo_coordinates`]).
pub const COORDINATES: usize = 4;

/// The `q` quantile of `values` with the split-conformal finite-sample correction: the
/// ⌈(n+1)q⌉-th smallest (Lei et al. 2018, JASA 113: 1094–1111, section 2.2); the largest
/// where that lies beyond them. `values` is sorted in place.
pub fn conformal_quantile(values: &mut [f64], q: f64) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    let k = (((n + 1) as f64 * q).ceil() as usize).clamp(1, n);
    values[k - 1]
}

/// Where a photo lies among the calibration photos: ln(1 − expected GFC) (floored at 10⁻⁵),
/// ln CCT of the estimate (K), ln of the self-check's mean residual and the veil (the glare's
/// share of the chart's mean; 0 where none was read). `None` where the CCT or the self-check
/// is missing or not positive: such a photo is judged by the pooled margin.
pub fn photo_coordinates(
    expected_gfc: f64,
    cct_k: Option<f64>,
    self_check_mean: Option<f64>,
    veil: Option<f64>,
) -> Option<[f64; COORDINATES]> {
    let cct = cct_k.filter(|c| c.is_finite() && *c > 0.0)?;
    let residual = self_check_mean.filter(|r| r.is_finite() && *r > 0.0)?;
    let x = [
        (1.0 - expected_gfc).max(1e-5).ln(),
        cct.ln(),
        residual.ln(),
        veil.filter(|v| v.is_finite()).unwrap_or(0.0),
    ];
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// The calibration photos' coordinates and held-out residuals, standardised, and how many
/// neighbours a margin is taken among.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LocalMargin {
    /// The neighbours a margin is taken among (K).
    pub neighbours: usize,
    /// Each coordinate's mean over the calibration photos.
    pub centre: [f64; COORDINATES],
    /// Each coordinate's standard deviation over them (at least 10⁻⁹).
    pub spread: [f64; COORDINATES],
    /// Each calibration photo's standardised coordinates.
    pub photos: Vec<[f64; COORDINATES]>,
    /// Each photo's ln(1 − GFC) above its prediction made without its own lamp.
    pub residuals: Vec<f64>,
}

impl LocalMargin {
    /// The margin of `photos` (coordinates beside held-out residuals) with `neighbours`
    /// nearest; `None` with fewer photos than neighbours.
    pub fn fit(photos: &[([f64; COORDINATES], f64)], neighbours: usize) -> Option<LocalMargin> {
        if neighbours == 0 || photos.len() < neighbours {
            return None;
        }
        let n = photos.len() as f64;
        let mut centre = [0.0; COORDINATES];
        let mut spread = [0.0; COORDINATES];
        for c in 0..COORDINATES {
            centre[c] = photos.iter().map(|p| p.0[c]).sum::<f64>() / n;
            spread[c] = (photos
                .iter()
                .map(|p| (p.0[c] - centre[c]).powi(2))
                .sum::<f64>()
                / n)
                .sqrt()
                .max(1e-9);
        }
        let mut margin = LocalMargin {
            neighbours,
            centre,
            spread,
            photos: Vec::with_capacity(photos.len()),
            residuals: photos.iter().map(|p| p.1).collect(),
        };
        margin.photos = photos.iter().map(|p| margin.standardised(&p.0)).collect();
        Some(margin)
    }

    /// `x` in the calibration's standardised coordinates.
    fn standardised(&self, x: &[f64; COORDINATES]) -> [f64; COORDINATES] {
        std::array::from_fn(|c| (x[c] - self.centre[c]) / self.spread[c])
    }

    /// The 95 % margin of ln(1 − GFC) for a photo at `x` ([`photo_coordinates`]): the
    /// conformal quantile of the held-out residuals of its [`LocalMargin::neighbours`]
    /// nearest calibration photos (Euclidean in the standardised coordinates).
    pub fn margin95(&self, x: &[f64; COORDINATES]) -> f64 {
        let all: Vec<usize> = (0..self.photos.len()).collect();
        self.margin95_among(&self.standardised(x), &all)
    }

    /// [`LocalMargin::margin95`] of a photo at standardised coordinates `z`, its neighbours
    /// drawn from the calibration photos `among` only (indices; at least one): to judge a
    /// calibration photo by the photos of other lamps.
    pub fn margin95_among(&self, z: &[f64; COORDINATES], among: &[usize]) -> f64 {
        let mut near: Vec<(f64, f64)> = among
            .iter()
            .map(|&i| {
                let distance = self.photos[i]
                    .iter()
                    .zip(z)
                    .map(|(a, b)| (a - b).powi(2))
                    .sum();
                (distance, self.residuals[i])
            })
            .collect();
        if near.is_empty() {
            return f64::INFINITY;
        }
        let k = self.neighbours.min(near.len()).max(1);
        near.select_nth_unstable_by(k - 1, |a, b| a.0.total_cmp(&b.0));
        let mut residuals: Vec<f64> = near[..k].iter().map(|n| n.1).collect();
        conformal_quantile(&mut residuals, 0.95)
    }

    /// Whether its arrays agree and its numbers are finite.
    pub fn fits(&self) -> bool {
        self.neighbours >= 1
            && self.photos.len() == self.residuals.len()
            && self.photos.len() >= self.neighbours
            && self.spread.iter().all(|s| *s > 0.0 && s.is_finite())
            && self.centre.iter().all(|c| c.is_finite())
            && self.photos.iter().flatten().all(|v| v.is_finite())
            && self.residuals.iter().all(|v| v.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_conformal_quantile_is_the_corrected_order_statistic() {
        // n = 9, q = 0.8: ⌈10 · 0.8⌉ = 8th smallest.
        let mut v: Vec<f64> = (1..=9).rev().map(f64::from).collect();
        assert_eq!(conformal_quantile(&mut v, 0.8), 8.0);
        // n = 10, q = 0.95: ⌈11 · 0.95⌉ = 11 > 10, the largest.
        let mut v: Vec<f64> = (1..=10).map(f64::from).collect();
        assert_eq!(conformal_quantile(&mut v, 0.95), 10.0);
    }

    #[test]
    fn a_photo_takes_the_margin_of_the_photos_like_it() {
        // Two clusters: photos with a small self-check residual err little (residuals
        // 0.00…0.19), those with a large one much (residuals 2.00…2.19).
        let photo = |residual_ln: f64, k: usize, spread: f64| {
            let x = photo_coordinates(0.98, Some(5000.0), Some(residual_ln.exp()), None).unwrap();
            (x, spread + 0.01 * k as f64)
        };
        let photos: Vec<([f64; COORDINATES], f64)> = (0..20)
            .map(|k| photo(-4.0, k, 0.0))
            .chain((0..20).map(|k| photo(-1.0, k, 2.0)))
            .collect();
        let local = LocalMargin::fit(&photos, 10).unwrap();
        assert!(local.fits());
        let near_clean =
            photo_coordinates(0.98, Some(5000.0), Some((-3.9f64).exp()), None).unwrap();
        let near_poor = photo_coordinates(0.98, Some(5000.0), Some((-1.1f64).exp()), None).unwrap();
        // Ten neighbours, each of one cluster: the largest of them (⌈11 · 0.95⌉ > 10).
        let clean = local.margin95(&near_clean);
        let poor = local.margin95(&near_poor);
        assert!((0.09..=0.19).contains(&clean), "{clean}");
        assert!((2.09..=2.19).contains(&poor), "{poor}");
    }

    #[test]
    fn a_margin_among_some_photos_sees_only_those() {
        let x = |r: f64| photo_coordinates(0.98, Some(5000.0), Some(r), None).unwrap();
        let photos: Vec<_> = (0..40)
            .map(|k| {
                (
                    x(if k < 20 { 0.01 } else { 0.5 }),
                    if k < 20 { 0.1 } else { 2.0 },
                )
            })
            .collect();
        let local = LocalMargin::fit(&photos, 10).unwrap();
        let z = local.photos[0];
        assert_eq!(local.margin95(&x(0.01)), 0.1);
        // Among the poor cluster only, the nearest ten are poor.
        let poor: Vec<usize> = (20..40).collect();
        assert_eq!(local.margin95_among(&z, &poor), 2.0);
        assert_eq!(local.margin95_among(&z, &[]), f64::INFINITY);
    }

    #[test]
    fn a_photo_without_a_cct_or_self_check_has_no_place_and_too_few_photos_no_margin() {
        assert!(photo_coordinates(0.98, None, Some(0.1), Some(0.2)).is_none());
        assert!(photo_coordinates(0.98, Some(4000.0), None, None).is_none());
        assert!(photo_coordinates(0.98, Some(-1.0), Some(0.1), None).is_none());
        let x = photo_coordinates(1.0, Some(4000.0), Some(0.1), None).unwrap();
        assert_eq!(x[0], 1e-5f64.ln(), "a perfect expected GFC is floored");
        assert_eq!(x[3], 0.0, "no veil read counts as none");
        assert!(LocalMargin::fit(&[(x, 0.1); 5], 6).is_none());
    }
}
