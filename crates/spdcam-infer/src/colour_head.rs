//! The light's colour as a model predicts it beside the spectrum's shape: two more network
//! outputs, the CIE 1976 u′v′ chromaticity of the light (CIE 1931 2° observer on the model's
//! grid), trained together with the PCA coefficients (`--target pca-colour`), and the
//! spectrum then made to have exactly that colour.
//!
//! Why: a model trained on PCA coefficients alone weighs every coefficient's error alike,
//! whatever it does to the colour, so a spectrum close in shape can be off by Δu′v′ 0.01 —
//! five times what a colour meter allows. Two numbers are easier to learn than forty, and
//! learning the chromaticity directly is what recent illuminant-estimation work does.
//!
//! Making the spectrum agree ([`ColourHead::conform`]): the smallest change of the PCA
//! coefficients, measured in the training spectra's own spread (each coefficient's change
//! divided by the standard deviation of that coefficient over the training spectra), that
//! gives the spectrum the predicted u′v′. u′v′ is a ratio of linear functions of the
//! coefficients, so the minimum-norm Gauss–Newton step `Δc = Λ Jᵀ (J Λ Jᵀ)⁻¹ r` (Λ the
//! coefficients' variances, J the 2 × k Jacobian of u′v′, r the chromaticity residual;
//! Nocedal & Wright, *Numerical Optimization*, 2nd ed., §10.3 and the minimum-norm solution
//! of an under-determined linear system, §A.2) reaches it in two or three steps. In the
//! Bayesian reading it is the most probable spectrum, under a Gaussian prior with the
//! training spectra's principal variances, among those of the predicted colour (Bishop,
//! *Pattern Recognition and Machine Learning*, 2006, §2.3.3).

use crate::error::{InferError, Result};
use crate::pca::Pca;
use serde::{Deserialize, Serialize};
use spdcam_core::colorimetry::Observer;
use spdcam_core::quality::uv::xyz_to_uv1976;
use spdcam_core::spectral::Grid;

/// Gauss–Newton steps of [`ColourHead::conform`] at most.
const CONFORM_STEPS: usize = 6;
/// The chromaticity residual (u′v′ units) below which [`ColourHead::conform`] stops.
const CONFORM_TOLERANCE: f64 = 1e-6;

/// The colour outputs of a model: the observer on the model's grid and the weight the colour
/// had in training.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ColourHead {
    /// x̄, ȳ, z̄ of the CIE 1931 2° observer on the model's grid.
    pub observer: [Vec<f64>; 3],
    /// How much each colour output weighed in the training loss against one PCA coefficient
    /// (the colour targets' scaled range is √weight instead of 1).
    pub weight: f64,
    /// The share of the way from the spectrum's own chromaticity to the predicted one that
    /// the spectrum is moved (1: all the way; 0: the colour outputs are not used). Chosen on
    /// validation photos, real ones among them: a colour learnt from virtual photos alone
    /// may transfer to real cameras worse than the spectrum it corrects.
    #[serde(default = "all_the_way")]
    pub pull: f64,
}

/// The default [`ColourHead::pull`].
fn all_the_way() -> f64 {
    1.0
}

impl ColourHead {
    /// The colour head of a model on `grid`, trained with `weight`.
    pub fn on_grid(grid: &Grid, weight: f64) -> Result<ColourHead> {
        if !(weight.is_finite() && weight > 0.0) {
            return Err(InferError::invalid(format!(
                "the colour weight must be a positive number, got {weight}"
            )));
        }
        let observer = Observer::cie1931(grid)
            .map_err(|e| InferError::invalid(format!("the colour head's observer: {e}")))?;
        Ok(ColourHead {
            observer: [0, 1, 2].map(|c| observer.cmf(c).to_vec()),
            weight,
            pull: 1.0,
        })
    }

    /// The same head moving the spectrum `pull` of the way to the predicted colour.
    pub fn with_pull(mut self, pull: f64) -> Result<ColourHead> {
        if !(0.0..=1.0).contains(&pull) {
            return Err(InferError::invalid(format!(
                "the colour pull must lie between 0 and 1, got {pull}"
            )));
        }
        self.pull = pull;
        Ok(self)
    }

    /// The spectrum's length.
    pub fn spd_len(&self) -> usize {
        self.observer[0].len()
    }

    /// CIE XYZ (unscaled) of a spectrum on the model's grid.
    fn xyz(&self, spd: &[f64]) -> [f64; 3] {
        self.observer
            .each_ref()
            .map(|cmf| cmf.iter().zip(spd).map(|(c, s)| c * s).sum())
    }

    /// The CIE 1976 u′v′ of a spectrum on the model's grid; `None` for a black one.
    pub fn uv(&self, spd: &[f64]) -> Option<[f64; 2]> {
        uv_of(self.xyz(spd))
    }

    /// Changes `coefficients` (of `pca`) as little as the training spectra's spread allows so
    /// that the spectrum they stand for, its negatives set to 0, moves [`ColourHead::pull`]
    /// of the way from its own chromaticity to `predicted` (see the module's
    /// documentation). Leaves them as they are where no step can be made (a black spectrum,
    /// a non-finite prediction). For many spectra of one PCA, [`ColourHead::conformer`].
    pub fn conform(&self, pca: &Pca, coefficients: &mut [f64], predicted: [f64; 2]) {
        self.conformer(pca).conform(coefficients, predicted);
    }

    /// This head ready to conform spectra of `pca`: what does not depend on the spectrum
    /// (the coefficients' variances, the components' XYZ) computed once.
    pub fn conformer<'a>(&'a self, pca: &'a Pca) -> Conformer<'a> {
        Conformer {
            head: self,
            pca,
            variance: pca
                .explained_ratio
                .iter()
                .map(|r| (r * pca.total_variance).max(f64::MIN_POSITIVE))
                .collect(),
            component_xyz: pca.components.iter().map(|c| self.xyz(c)).collect(),
        }
    }

    /// Checks the stored numbers (for a head read from a file).
    pub fn validate(&self, spd_len: usize) -> Result<()> {
        if self.observer.iter().any(|c| c.len() != spd_len) {
            return Err(InferError::invalid(format!(
                "the colour head's observer does not lie on the model's grid of {spd_len} values"
            )));
        }
        if self.observer.iter().flatten().any(|v| !v.is_finite())
            || !(self.weight.is_finite() && self.weight > 0.0)
            || !(0.0..=1.0).contains(&self.pull)
        {
            return Err(InferError::invalid(
                "the colour head holds non-finite or non-positive numbers",
            ));
        }
        Ok(())
    }
}

/// A [`ColourHead`] with one PCA's numbers computed once ([`ColourHead::conformer`]), for
/// conforming many spectra of that PCA.
pub struct Conformer<'a> {
    head: &'a ColourHead,
    pca: &'a Pca,
    /// Each coefficient's variance over the training spectra (Λ).
    variance: Vec<f64>,
    /// Each component's XYZ.
    component_xyz: Vec<[f64; 3]>,
}

impl<'a> Conformer<'a> {
    /// The PCA whose spectra it conforms.
    pub fn pca(&self) -> &'a Pca {
        self.pca
    }

    /// [`ColourHead::conform`] with this conformer's head and PCA.
    pub fn conform(&self, coefficients: &mut [f64], predicted: [f64; 2]) {
        if !predicted.iter().all(|t| t.is_finite()) || self.head.pull == 0.0 {
            return;
        }
        let mut spd = self.pca.reconstruct(coefficients);
        spd.iter_mut().for_each(|v| *v = v.max(0.0));
        let Some(own) = self.head.uv(&spd) else {
            return;
        };
        self.conform_from(coefficients, spd, own, predicted);
    }

    /// [`Conformer::conform`] of coefficients whose spectrum, negatives set to 0, is `spd`
    /// of chromaticity `own`: for a caller that has just computed them.
    pub fn conform_from(
        &self,
        coefficients: &mut [f64],
        mut spd: Vec<f64>,
        own: [f64; 2],
        predicted: [f64; 2],
    ) {
        if !predicted.iter().all(|t| t.is_finite()) || self.head.pull == 0.0 {
            return;
        }
        let pull = self.head.pull;
        let target = [0, 1].map(|i| own[i] + pull * (predicted[i] - own[i]));
        let k = coefficients.len().min(self.pca.len());
        let (variance, component_xyz) = (&self.variance[..k], &self.component_xyz[..k]);
        let mut jacobian = vec![[0.0; 2]; k];
        for step in 0..CONFORM_STEPS {
            if step > 0 {
                self.pca.reconstruct_into(coefficients, &mut spd);
                spd.iter_mut().for_each(|v| *v = v.max(0.0));
            }
            let xyz = self.head.xyz(&spd);
            let Some(uv) = uv_of(xyz) else { return };
            let r = [target[0] - uv[0], target[1] - uv[1]];
            if r[0].hypot(r[1]) < CONFORM_TOLERANCE {
                return;
            }
            for (j, b) in jacobian.iter_mut().zip(component_xyz) {
                *j = uv_slope(xyz, *b);
            }
            // J Λ Jᵀ, 2 × 2.
            let mut m = [[0.0; 2]; 2];
            for (j, l) in jacobian.iter().zip(variance) {
                for a in 0..2 {
                    for b in 0..2 {
                        m[a][b] += j[a] * l * j[b];
                    }
                }
            }
            let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
            if !(det.is_finite() && det.abs() > 1e-300) {
                return;
            }
            let y = [
                (m[1][1] * r[0] - m[0][1] * r[1]) / det,
                (m[0][0] * r[1] - m[1][0] * r[0]) / det,
            ];
            for ((c, j), l) in coefficients.iter_mut().zip(&jacobian).zip(variance) {
                *c += l * (j[0] * y[0] + j[1] * y[1]);
            }
        }
    }
}

/// CIE 1976 u′v′ of XYZ ([`xyz_to_uv1976`]); `None` for black or a spectrum whose X + 15Y +
/// 3Z is not positive (negative coefficients can make one).
fn uv_of(xyz: [f64; 3]) -> Option<[f64; 2]> {
    let d = xyz[0] + 15.0 * xyz[1] + 3.0 * xyz[2];
    (d > 0.0 && d.is_finite()).then(|| xyz_to_uv1976(xyz))
}

/// How u′ and v′ change per unit of a component whose XYZ is `b`, at the spectrum of XYZ
/// `xyz` (the quotient rule on u′ = 4X/D, v′ = 9Y/D, D = X + 15Y + 3Z).
fn uv_slope([x, y, z]: [f64; 3], [bx, by, bz]: [f64; 3]) -> [f64; 2] {
    let d = x + 15.0 * y + 3.0 * z;
    let bd = bx + 15.0 * by + 3.0 * bz;
    [
        4.0 * (bx * d - x * bd) / (d * d),
        9.0 * (by * d - y * bd) / (d * d),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pca::Components;
    use spdcam_core::cie_illuminant::planck;

    fn grid() -> Grid {
        Grid::new(400.0, 700.0, 5.0).unwrap()
    }

    /// Planckian spectra of 2500–8000 K, peak 1, as rows.
    fn planckians() -> Vec<f64> {
        let g = grid();
        (0..40)
            .flat_map(|i| {
                let t = 2500.0 + 140.0 * i as f64;
                let mut s = planck(t, &g).unwrap().values().to_vec();
                let m = s.iter().cloned().fold(0.0, f64::max);
                s.iter_mut().for_each(|v| *v /= m);
                s
            })
            .collect()
    }

    #[test]
    fn uv_of_equal_energy_is_published() {
        // CIE 015:2018: the equal-energy stimulus E has u′v′ (0.2105, 0.4737).
        let head = ColourHead::on_grid(&Grid::new(380.0, 780.0, 1.0).unwrap(), 1.0).unwrap();
        let uv = head.uv(&[1.0; 401]).unwrap();
        assert!(
            (uv[0] - 0.2105).abs() < 5e-4 && (uv[1] - 0.4737).abs() < 5e-4,
            "{uv:?}"
        );
    }

    #[test]
    fn conform_reaches_the_target_with_a_small_change() {
        let data = planckians();
        let pca = Pca::fit(&data, 61, Components::Count(4)).unwrap();
        let head = ColourHead::on_grid(&grid(), 1.0).unwrap();
        // Start at the 3000 K spectrum and ask for the colour of the 3300 K one.
        let start = &data[61 * 4..61 * 5];
        let goal = &data[61 * 6..61 * 7];
        let target = head.uv(goal).unwrap();
        let mut c = pca.project(start);
        head.conform(&pca, &mut c, target);
        let mut spd = pca.reconstruct(&c);
        spd.iter_mut().for_each(|v| *v = v.max(0.0));
        let uv = head.uv(&spd).unwrap();
        assert!(
            (uv[0] - target[0]).hypot(uv[1] - target[1]) < 1e-5,
            "{uv:?} vs {target:?}"
        );
        // The change follows the Planckian family: the result is close to the goal's shape.
        let peak = spd.iter().cloned().fold(0.0, f64::max);
        let err: f64 = spd
            .iter()
            .zip(goal)
            .map(|(a, b)| (a / peak - b).abs())
            .fold(0.0, f64::max);
        assert!(
            err < 0.02,
            "largest difference to the 3300 K spectrum {err}"
        );
    }

    #[test]
    fn a_pull_of_a_half_goes_half_way() {
        let data = planckians();
        let pca = Pca::fit(&data, 61, Components::Count(4)).unwrap();
        let head = ColourHead::on_grid(&grid(), 1.0)
            .unwrap()
            .with_pull(0.5)
            .unwrap();
        let start = &data[61 * 4..61 * 5];
        let (own, goal) = (
            head.uv(start).unwrap(),
            head.uv(&data[61 * 8..61 * 9]).unwrap(),
        );
        let mut c = pca.project(start);
        head.conform(&pca, &mut c, goal);
        let mut spd = pca.reconstruct(&c);
        spd.iter_mut().for_each(|v| *v = v.max(0.0));
        let uv = head.uv(&spd).unwrap();
        for i in 0..2 {
            let half = 0.5 * (own[i] + goal[i]);
            assert!((uv[i] - half).abs() < 2e-4, "{uv:?}: half way is {half}");
        }
        // A pull of 0 leaves the coefficients as they are.
        let none = head.with_pull(0.0).unwrap();
        let mut c0 = pca.project(start);
        let before = c0.clone();
        none.conform(&pca, &mut c0, goal);
        assert_eq!(c0, before);
    }

    #[test]
    fn bad_settings_are_refused() {
        assert!(ColourHead::on_grid(&grid(), 0.0).is_err());
        assert!(ColourHead::on_grid(&grid(), f64::NAN).is_err());
        let head = ColourHead::on_grid(&grid(), 1.0).unwrap();
        assert!(head.clone().with_pull(1.5).is_err());
        assert!(head.with_pull(-0.1).is_err());
    }
}
