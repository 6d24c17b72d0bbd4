//! Spectral error metrics of the thesis (section 4.3): RMSE, GFC, SAM and SID between a true
//! and an estimated SPD, and their summary over a set.
//!
//! [`compare`] first divides each spectrum by its own maximum (so both lie in [0, 1]), clips
//! negative values to 0, then computes
//!
//! - RMSE = √(Σ (f_p − f_i)² / n) (Eq. 4.1),
//! - GFC = Σ f_i f_p / (‖f_i‖ ‖f_p‖), the cosine of the angle between the spectra (Eq. 4.2),
//! - SAM = arccos GFC, in radians (Eq. 4.3),
//! - SID = D(p‖q) + D(q‖p), the symmetric relative entropy of the spectra read as probability
//!   distributions (Eq. 4.4). A band where one spectrum is 0 would make it infinite, so
//!   [`SID_EPSILON`] is added to every band of the max-normalised spectra before they are
//!   divided by their sums: p = (f_i + ε) / Σ (f_i + ε).
//!
//! A spectrum that is zero everywhere has no direction: its GFC with anything is 0 (SAM π/2).
//!
//! Each metric comes in two forms: the typed one ([`gfc_spd`], [`rmse_spd`],
//! [`compare_spd`]) takes two [`Spd`]s and refuses spectra on different grids, for scoring an
//! estimate against its truth; the row-level one ([`gfc`], [`rmse`], [`compare`]) takes bare
//! slices of the same length, for inner loops over rows of model output that share one grid.

use crate::error::{Error, Result};
use crate::spectral::{normalise_by_max, Spd};
use serde::{Deserialize, Serialize};

/// Added to every band of a max-normalised spectrum before SID turns it into a distribution.
pub const SID_EPSILON: f64 = 1e-6;

/// The four metrics between one true and one estimated SPD.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SpectralMetrics {
    /// Root mean square error of the max-normalised spectra.
    pub rmse: f64,
    /// Goodness-of-fit coefficient, 1 for spectra of the same shape.
    pub gfc: f64,
    /// Spectral angle in radians, 0 for spectra of the same shape.
    pub sam: f64,
    /// Spectral information divergence, 0 for spectra of the same shape.
    pub sid: f64,
}

/// Mean, standard deviation (population) and median of one metric over a set.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// The arithmetic mean.
    pub mean: f64,
    /// The population standard deviation.
    pub std: f64,
    /// The median (mean of the two middle values for an even count).
    pub median: f64,
    /// The smallest value.
    pub min: f64,
    /// The largest value.
    pub max: f64,
}

fn check_pair(truth: &[f64], estimate: &[f64]) -> Result<()> {
    if truth.len() != estimate.len() {
        return Err(Error::invalid(format!(
            "cannot compare spectra of {} and {} bands",
            truth.len(),
            estimate.len()
        )));
    }
    if truth.is_empty() {
        return Err(Error::invalid("cannot compare empty spectra"));
    }
    if let Some(v) = truth.iter().chain(estimate).find(|v| !v.is_finite()) {
        return Err(Error::invalid(format!(
            "cannot compare spectra holding the non-finite value {v}"
        )));
    }
    Ok(())
}

/// Checks that `truth` and `estimate` are sampled on the same grid: comparing spectra
/// value by value means nothing otherwise.
fn check_same_grid(truth: &Spd, estimate: &Spd) -> Result<()> {
    if truth.grid() != estimate.grid() {
        return Err(Error::invalid(format!(
            "cannot compare spectra on different grids: the truth is on {}, the estimate on {}; \
             resample one onto the other's grid",
            truth.grid(),
            estimate.grid()
        )));
    }
    Ok(())
}

/// RMSE of two spectra as they are (no normalisation): the row-level form over bare values
/// of one grid, for inner loops over model output rows; [`rmse_spd`] is the typed form that
/// checks the grids.
pub fn rmse(truth: &[f64], estimate: &[f64]) -> Result<f64> {
    check_pair(truth, estimate)?;
    let sum: f64 = truth
        .iter()
        .zip(estimate)
        .map(|(a, b)| (b - a) * (b - a))
        .sum();
    Ok((sum / truth.len() as f64).sqrt())
}

/// GFC of two spectra as they are (no normalisation; scale does not change it): the
/// row-level form over bare values of one grid, for inner loops over model output rows;
/// [`gfc_spd`] is the typed form that checks the grids.
///
/// ```
/// use spdcam_core::spectral_error::gfc;
///
/// assert_eq!(gfc(&[1.0, 2.0, 3.0], &[2.0, 4.0, 6.0])?, 1.0); // the same shape
/// assert!(gfc(&[1.0, 0.0], &[0.0, 1.0])?.abs() < 1e-12); // nothing in common
/// assert!(gfc(&[1.0, 2.0], &[1.0]).is_err());
/// # Ok::<(), spdcam_core::Error>(())
/// ```
pub fn gfc(truth: &[f64], estimate: &[f64]) -> Result<f64> {
    check_pair(truth, estimate)?;
    let dot: f64 = truth.iter().zip(estimate).map(|(a, b)| a * b).sum();
    let na = truth.iter().map(|a| a * a).sum::<f64>().sqrt();
    let nb = estimate.iter().map(|b| b * b).sum::<f64>().sqrt();
    if na == 0.0 || nb == 0.0 {
        return Ok(0.0);
    }
    Ok((dot / (na * nb)).clamp(-1.0, 1.0))
}

/// SAM (radians) of two spectra: arccos of their GFC.
pub fn sam(truth: &[f64], estimate: &[f64]) -> Result<f64> {
    Ok(gfc(truth, estimate)?.acos())
}

/// SID of two non-negative spectra, with [`SID_EPSILON`] added to every band.
pub fn sid(truth: &[f64], estimate: &[f64]) -> Result<f64> {
    check_pair(truth, estimate)?;
    let distribution = |f: &[f64]| -> Vec<f64> {
        let shifted: Vec<f64> = f.iter().map(|v| v.max(0.0) + SID_EPSILON).collect();
        let sum: f64 = shifted.iter().sum();
        shifted.into_iter().map(|v| v / sum).collect()
    };
    let p = distribution(truth);
    let q = distribution(estimate);
    let d: f64 = p
        .iter()
        .zip(&q)
        .map(|(pi, qi)| pi * (pi / qi).ln() + qi * (qi / pi).ln())
        .sum();
    Ok(d.max(0.0))
}

/// All four metrics, each spectrum normalised by its own maximum first (thesis section
/// 4.3): the row-level form over bare values of one grid; [`compare_spd`] is the typed form
/// that checks the grids.
///
/// ```
/// use spdcam_core::cie_illuminant::StandardIlluminant;
/// use spdcam_core::spectral_error::compare;
/// use spdcam_core::spectral::Grid;
///
/// let grid = Grid::ESTIMATION;
/// let (a, d65) = (StandardIlluminant::A.spd(&grid)?, StandardIlluminant::D65.spd(&grid)?);
/// let same = compare(&a, &a)?;
/// assert_eq!((same.gfc, same.rmse), (1.0, 0.0));
/// let apart = compare(&a, &d65)?;
/// assert!(apart.gfc < 0.95 && apart.sam > 0.0 && apart.sid > 0.0);
/// # Ok::<(), spdcam_core::Error>(())
/// ```
pub fn compare(truth: &[f64], estimate: &[f64]) -> Result<SpectralMetrics> {
    check_pair(truth, estimate)?;
    let t = normalise_by_max(truth);
    let e = normalise_by_max(estimate);
    Ok(SpectralMetrics {
        rmse: rmse(&t, &e)?,
        gfc: gfc(&t, &e)?,
        sam: sam(&t, &e)?,
        sid: sid(&t, &e)?,
    })
}

/// [`rmse`] of two spectra on the same grid; an error, not a panic, when their grids differ.
///
/// ```
/// use spdcam_core::spectral_error::rmse_spd;
/// use spdcam_core::spectral::{Grid, Spd};
///
/// let grid = Grid::parse("400-700:100")?;
/// let truth = Spd::new(grid, vec![0.0, 1.0, 1.0, 0.0])?;
/// let estimate = Spd::new(grid, vec![0.0, 1.0, 0.0, 0.0])?;
/// assert_eq!(rmse_spd(&truth, &estimate)?, 0.5);
/// let coarse = Spd::new(Grid::parse("400-700:150")?, vec![0.0, 1.0, 0.0])?;
/// assert!(rmse_spd(&truth, &coarse).is_err());
/// # Ok::<(), spdcam_core::Error>(())
/// ```
pub fn rmse_spd(truth: &Spd, estimate: &Spd) -> Result<f64> {
    check_same_grid(truth, estimate)?;
    rmse(truth.values(), estimate.values())
}

/// [`gfc`] of two spectra on the same grid; an error, not a panic, when their grids differ.
///
/// ```
/// use spdcam_core::cie_illuminant::StandardIlluminant;
/// use spdcam_core::spectral_error::gfc_spd;
/// use spdcam_core::spectral::Grid;
///
/// let a = StandardIlluminant::A.spd(&Grid::ESTIMATION)?;
/// assert!((gfc_spd(&a, &a)? - 1.0).abs() < 1e-12);
/// let d65 = StandardIlluminant::D65.spd(&Grid::SIMULATION)?;
/// assert!(gfc_spd(&a, &d65).is_err()); // 400–700 nm against 380–780 nm
/// # Ok::<(), spdcam_core::Error>(())
/// ```
pub fn gfc_spd(truth: &Spd, estimate: &Spd) -> Result<f64> {
    check_same_grid(truth, estimate)?;
    gfc(truth.values(), estimate.values())
}

/// [`compare`] of two spectra on the same grid (each normalised by its own maximum first);
/// an error, not a panic, when their grids differ.
pub fn compare_spd(truth: &Spd, estimate: &Spd) -> Result<SpectralMetrics> {
    check_same_grid(truth, estimate)?;
    compare(truth.values(), estimate.values())
}

/// Mean, standard deviation, median, minimum and maximum of `values`; an error when empty
/// or when a value is not finite.
///
/// ```
/// use spdcam_core::spectral_error::summarise;
///
/// let s = summarise(&[0.99, 0.97, 0.95, 0.93])?;
/// assert!((s.mean - 0.96).abs() < 1e-12 && (s.median - 0.96).abs() < 1e-12);
/// assert_eq!((s.min, s.max), (0.93, 0.99));
/// assert!(summarise(&[]).is_err());
/// # Ok::<(), spdcam_core::Error>(())
/// ```
pub fn summarise(values: &[f64]) -> Result<Summary> {
    if values.is_empty() {
        return Err(Error::invalid("cannot summarise an empty set of values"));
    }
    if let Some(v) = values.iter().find(|v| !v.is_finite()) {
        return Err(Error::invalid(format!(
            "cannot summarise a set holding the non-finite value {v}"
        )));
    }
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let std = (values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n).sqrt();
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let mid = sorted.len() / 2;
    let median = if sorted.len().is_multiple_of(2) {
        0.5 * (sorted[mid - 1] + sorted[mid])
    } else {
        sorted[mid]
    };
    Ok(Summary {
        mean,
        std,
        median,
        min: sorted[0],
        max: sorted[sorted.len() - 1],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gaussian(mu: f64, sigma: f64) -> Vec<f64> {
        (0..61)
            .map(|i| {
                let l = 400.0 + 5.0 * i as f64;
                (-(l - mu) * (l - mu) / (2.0 * sigma * sigma)).exp()
            })
            .collect()
    }

    #[test]
    fn identical_spectra_are_a_perfect_match() {
        let a = gaussian(550.0, 40.0);
        // A different scale is the same spectrum after normalisation.
        let b: Vec<f64> = a.iter().map(|v| 3.5 * v).collect();
        let m = compare(&a, &b).unwrap();
        assert!(m.rmse.abs() < 1e-15, "{m:?}");
        assert!((m.gfc - 1.0).abs() < 1e-15, "{m:?}");
        assert!(m.sam.abs() < 1e-6, "{m:?}");
        assert!(m.sid.abs() < 1e-15, "{m:?}");
    }

    #[test]
    fn rmse_of_a_known_offset() {
        let a = [0.2, 0.4, 0.6, 0.8];
        let b = [0.3, 0.5, 0.7, 0.9];
        assert!((rmse(&a, &b).unwrap() - 0.1).abs() < 1e-12);
        // Same maxima (1), two bands off by 0.1: √((0.01 + 0.01) / 4).
        let t = [1.0, 0.5, 0.2, 0.8];
        let e = [1.0, 0.6, 0.1, 0.8];
        let m = compare(&t, &e).unwrap();
        assert!((m.rmse - 0.005f64.sqrt()).abs() < 1e-12, "{m:?}");
    }

    #[test]
    fn gfc_and_sam_by_hand() {
        // Orthogonal spectra: GFC 0, SAM π/2.
        let m = compare(&[1.0, 0.0], &[0.0, 1.0]).unwrap();
        assert!(m.gfc.abs() < 1e-15);
        assert!((m.sam - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        // [1, 1] against [1, 0]: cos 45°.
        let m = compare(&[1.0, 1.0], &[1.0, 0.0]).unwrap();
        assert!((m.gfc - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-12);
        assert!((m.sam - std::f64::consts::FRAC_PI_4).abs() < 1e-12);
    }

    #[test]
    fn sam_is_arccos_gfc() {
        let a = gaussian(500.0, 30.0);
        let b = gaussian(530.0, 50.0);
        let m = compare(&a, &b).unwrap();
        assert!(m.gfc < 0.99 && m.gfc > 0.5, "{m:?}");
        assert!((m.sam - m.gfc.acos()).abs() < 1e-15);
    }

    #[test]
    fn sid_by_hand_and_symmetric() {
        // Two-band distributions p = (0.5, 0.5) and q = (0.25, 0.75) (ε is negligible here).
        let p = [1.0, 1.0];
        let q = [1.0 / 3.0, 1.0];
        let expected = 0.5 * (0.5f64 / 0.25).ln()
            + 0.5 * (0.5f64 / 0.75).ln()
            + 0.25 * (0.25f64 / 0.5).ln()
            + 0.75 * (0.75f64 / 0.5).ln();
        let m = compare(&p, &q).unwrap();
        assert!((m.sid - expected).abs() < 1e-5, "{} vs {expected}", m.sid);
        let r = compare(&q, &p).unwrap();
        assert!((m.sid - r.sid).abs() < 1e-15);
        // A zero band stays finite thanks to ε.
        assert!(compare(&[1.0, 0.0], &[1.0, 1.0]).unwrap().sid.is_finite());
    }

    #[test]
    fn bad_input_is_an_error() {
        assert!(compare(&[1.0, 2.0], &[1.0]).is_err());
        assert!(compare(&[], &[]).is_err());
        assert!(compare(&[1.0, f64::NAN], &[1.0, 1.0]).is_err());
        // A zero spectrum is no error; it has GFC 0.
        assert_eq!(compare(&[0.0, 0.0], &[1.0, 1.0]).unwrap().gfc, 0.0);
    }

    #[test]
    fn summary_statistics() {
        let s = summarise(&[1.0, 2.0, 3.0, 4.0]).unwrap();
        assert_eq!(s.mean, 2.5);
        assert_eq!(s.median, 2.5);
        assert!((s.std - 1.25f64.sqrt()).abs() < 1e-15);
        assert_eq!((s.min, s.max), (1.0, 4.0));
        assert_eq!(summarise(&[3.0, 1.0, 2.0]).unwrap().median, 2.0);
        assert!(summarise(&[]).is_err());
    }

    #[test]
    fn typed_metrics_equal_the_row_level_ones_on_one_grid() {
        let grid = crate::spectral::Grid::ESTIMATION;
        let (t, e) = (gaussian(550.0, 40.0), gaussian(580.0, 60.0));
        let (ts, es) = (
            Spd::new(grid, t.clone()).unwrap(),
            Spd::new(grid, e.clone()).unwrap(),
        );
        assert_eq!(gfc_spd(&ts, &es).unwrap(), gfc(&t, &e).unwrap());
        assert_eq!(rmse_spd(&ts, &es).unwrap(), rmse(&t, &e).unwrap());
        assert_eq!(compare_spd(&ts, &es).unwrap(), compare(&t, &e).unwrap());
    }

    #[test]
    fn typed_metrics_refuse_spectra_on_different_grids_of_one_length() {
        let grid = crate::spectral::Grid::ESTIMATION;
        // As many values, shifted by one step: the slices would compare, the spectra must not.
        let shifted = crate::spectral::Grid::from_parts(405.0, 5.0, grid.count).unwrap();
        let truth = Spd::new(grid, gaussian(550.0, 40.0)).unwrap();
        let estimate = Spd::new(shifted, gaussian(550.0, 40.0)).unwrap();
        for err in [
            gfc_spd(&truth, &estimate).unwrap_err(),
            rmse_spd(&truth, &estimate).unwrap_err(),
            compare_spd(&truth, &estimate).unwrap_err(),
        ] {
            let message = err.to_string();
            assert!(message.contains("different grids"), "{message}");
            assert!(message.contains(&grid.to_string()), "{message}");
            assert!(message.contains(&shifted.to_string()), "{message}");
        }
    }
}
