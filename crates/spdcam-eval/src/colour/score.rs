//! How far an estimate's light colour lies from the true light's, as a colour meter reads
//! it: the distance in CIE 1976 u′v′ and the error of the correlated colour temperature.

use crate::error::Result;
use spdcam_core::colorimetry::uv_to_cct_duv;
use spdcam_core::quality::uv::{xyz_to_uv1960, xyz_to_uv1976};
use spdcam_core::quality::LightSpectrum;
use spdcam_core::spectral::Spd;

/// The CCT of a light farther than this from the Planckian locus (|Duv|, CIE 1960 uv) is not
/// scored: its colour temperature says little of its colour. ANSI C78.377 bins white lamps
/// within about ±0.006 of the locus; 0.02 keeps every lamp a person would call white and
/// leaves out the coloured ones.
pub const CCT_MAX_DUV: f64 = 0.02;

/// The colour of one light: CIE 1976 (u′, v′) and, where it has one (Ohno 2014, within
/// 1,000–100,000 K), its CCT and Duv.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightColour {
    /// CIE 1976 UCS (u′, v′) of the CIE 1931 2° observer (CIE 015:2018 §8.1).
    pub uv_prime: [f64; 2],
    /// Correlated colour temperature (K) and Duv (Ohno 2014); `None` outside the table.
    pub cct_duv: Option<(f64, f64)>,
}

impl LightColour {
    /// The colour of `spd` on its own grid, through the lighting-quality metrics' spectrum
    /// (resampled to 360–780 nm at 1 nm, zero where `spd` has no samples): the same route
    /// as an estimate's `metrics`. Errors on a spectrum without visible light.
    pub fn of(spd: &Spd) -> Result<LightColour> {
        let light = LightSpectrum::from_samples(&spd.grid().wavelengths(), spd.values())?;
        let xyz = light.xyz();
        Ok(LightColour {
            uv_prime: xyz_to_uv1976(xyz),
            cct_duv: uv_to_cct_duv(xyz_to_uv1960(xyz)).ok(),
        })
    }
}

/// An estimate's light colour against the truth's: what a colour meter beside the chart
/// would have shown as the difference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ColourScore {
    /// Δu′v′: the Euclidean distance of the two (u′, v′) (CIE 015:2018 §8.1).
    pub delta_uv_prime: f64,
    /// The true light's (u′, v′).
    pub true_uv_prime: [f64; 2],
    /// The estimate's (u′, v′).
    pub estimate_uv_prime: [f64; 2],
    /// The true light's CCT (K), where it lies within [`CCT_MAX_DUV`] of the locus.
    pub true_cct: Option<f64>,
    /// The estimate's CCT (K), where the truth's is scored and the estimate has one.
    pub estimate_cct: Option<f64>,
    /// The true light's Duv, where its CCT is scored.
    pub true_duv: Option<f64>,
    /// The estimate's Duv, where the truth's CCT is scored and the estimate has one.
    pub estimate_duv: Option<f64>,
}

impl ColourScore {
    /// The score of `estimate` against `truth`, each on its own grid (an estimate over
    /// 400–700 nm against a light measured over 380–780 nm is scored as such). Errors on a
    /// spectrum without visible light.
    ///
    /// ```
    /// use spdcam_core::cie_illuminant::planck;
    /// use spdcam_core::spectral::Grid;
    /// use spdcam_eval::colour::ColourScore;
    ///
    /// let truth = planck(3000.0, &Grid::SIMULATION)?;
    /// let estimate = planck(3300.0, &Grid::ESTIMATION)?;
    /// let s = ColourScore::of(&truth, &estimate)?;
    /// // 3,300 K read for 3,000 K: 10 % too high.
    /// assert!((s.cct_error().unwrap() - 0.10).abs() < 0.005);
    /// assert!(s.delta_uv_prime > 0.005);
    /// # Ok::<(), spdcam_eval::EvalError>(())
    /// ```
    pub fn of(truth: &Spd, estimate: &Spd) -> Result<ColourScore> {
        let t = LightColour::of(truth)?;
        let e = LightColour::of(estimate)?;
        Ok(ColourScore::between(&t, &e))
    }

    /// The score of colour `estimate` against colour `truth`.
    pub fn between(truth: &LightColour, estimate: &LightColour) -> ColourScore {
        let [a, b] = truth.uv_prime;
        let [c, d] = estimate.uv_prime;
        let scored = truth.cct_duv.filter(|(_, duv)| duv.abs() <= CCT_MAX_DUV);
        let estimated = scored.and(estimate.cct_duv);
        ColourScore {
            delta_uv_prime: (a - c).hypot(b - d),
            true_uv_prime: truth.uv_prime,
            estimate_uv_prime: estimate.uv_prime,
            true_cct: scored.map(|(cct, _)| cct),
            estimate_cct: estimated.map(|(cct, _)| cct),
            true_duv: scored.map(|(_, duv)| duv),
            estimate_duv: estimated.map(|(_, duv)| duv),
        }
    }

    /// The signed relative CCT error, (estimate − truth) / truth (0.01 = 1 % too high);
    /// `None` where either CCT is not scored.
    pub fn cct_error(&self) -> Option<f64> {
        Some((self.estimate_cct? - self.true_cct?) / self.true_cct?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use spdcam_core::cie_illuminant::{daylight, planck, StandardIlluminant};
    use spdcam_core::colorimetry::cct_to_uv_planck;
    use spdcam_core::spectral::Grid;

    #[test]
    fn a_light_against_itself_scores_zero() {
        for spd in [
            daylight(6500.0, &Grid::SIMULATION).unwrap(),
            StandardIlluminant::A.spd(&Grid::ESTIMATION).unwrap(),
        ] {
            let s = ColourScore::of(&spd, &spd).unwrap();
            assert_eq!(s.delta_uv_prime, 0.0);
            assert_eq!(s.cct_error(), Some(0.0));
        }
    }

    #[test]
    fn illuminant_a_is_a_planckian_of_2856_k() {
        // CIE 015:2018: A is Planck's law at 2,856 K (c2 = 1.4388e-2 m·K).
        let a = StandardIlluminant::A.spd(&Grid::SIMULATION).unwrap();
        let p = planck(2856.0, &Grid::SIMULATION).unwrap();
        let s = ColourScore::of(&a, &p).unwrap();
        assert!(s.delta_uv_prime < 5e-4, "{}", s.delta_uv_prime);
        let e = s.cct_error().unwrap();
        assert!(e.abs() < 0.002, "{e}");
    }

    #[test]
    fn two_planckians_differ_as_their_chromaticities_do() {
        let grid = Grid::parse("360-830:1").unwrap();
        let truth = planck(3000.0, &grid).unwrap();
        let estimate = planck(3300.0, &grid).unwrap();
        let s = ColourScore::of(&truth, &estimate).unwrap();
        let e = s.cct_error().unwrap();
        assert!((e - 0.1).abs() < 0.001, "{e}");
        // u′ = u, v′ = 1.5 v of each locus point, from Planck's law on the observer's own
        // 1 nm table (CIE 015:2018 §8.1).
        let [u1, v1] = cct_to_uv_planck(3000.0).unwrap();
        let [u2, v2] = cct_to_uv_planck(3300.0).unwrap();
        let expected = (u1 - u2).hypot(1.5 * (v1 - v2));
        assert!(
            (s.delta_uv_prime - expected).abs() < 2e-5,
            "{} vs {expected}",
            s.delta_uv_prime
        );
        assert!(expected > 0.01, "{expected}");
    }

    #[test]
    fn a_coloured_light_has_no_cct_score() {
        // A green narrow band lies far above the locus.
        let grid = Grid::SIMULATION;
        let values = grid
            .wavelengths()
            .iter()
            .map(|&w| (-((w - 530.0) / 15.0).powi(2)).exp())
            .collect();
        let green = Spd::new(grid, values).unwrap();
        let d65 = StandardIlluminant::D65.spd(&grid).unwrap();
        let s = ColourScore::of(&green, &d65).unwrap();
        assert_eq!(s.true_cct, None);
        assert_eq!(s.cct_error(), None);
        assert!(s.delta_uv_prime > 0.1, "{}", s.delta_uv_prime);
        // The other way round the truth is white and both CCTs are scored.
        assert!(ColourScore::of(&d65, &green).unwrap().true_cct.is_some());
    }
}
