//! A correction of a white light's colour learnt on validation photos: the estimate's
//! colour temperature and Duv mapped, each by a straight line, to the true light's, fitted by
//! least squares on photos of lamps the model was not trained on, through the split's
//! training cameras and the full camera chain of a user's photo (`spdcam colour-map fit`).
//! The spectrum is then made to have the corrected colour by the smallest change of its PCA
//! coefficients in the training spectra's own spread ([`ColourHead::conform`]).
//!
//! Why: a model trained on virtual photos reads the colour temperature of white light as
//! regressions do, pulled towards the middle of its training lights (the Digital SG model
//! reads 2,700 K as about 3,200 K and daylight slightly low), and its Duv with much noise.
//! Regressing the true reciprocal colour temperature (mired, in which equal steps are about
//! equal colour differences; Wyszecki & Stiles, *Color Science*, 2nd ed., §3.11) and Duv on
//! the estimated ones takes out the part of that error which is linear in the estimate — the
//! idea of corrected-moment illuminant estimation (Finlayson, "Corrected-moment illuminant
//! estimation", ICCV 2013), where a least-squares correction is learnt on top of a simpler
//! estimator.
//!
//! Only white light is corrected, where the map was fitted: in full where the estimate's
//! |Duv| is at most [`FULL_DUV`], fading linearly to nothing at [`NO_DUV`], so that coloured
//! light (an RGB lamp set to green) is left as the model reads it and the estimate stays
//! continuous in the features.

use crate::colour_head::{ColourHead, Conformer};
use crate::error::{InferError, Result};
use crate::pca::Pca;
use serde::{Deserialize, Serialize};
use spdcam_core::colorimetry::{cct_duv_to_uv, uv_to_cct_duv};
use spdcam_core::quality::uv::{uv1960_to_uv1976, uv1976_to_uv1960};
use spdcam_core::spectral::Grid;

/// The fewest white photos a map is fitted on: four parameters need many more pairs than
/// four to be estimated rather than interpolated.
pub const MIN_PHOTOS: usize = 30;
/// Up to this |Duv| (CIE 1960 uv) of the estimate the map applies in full: about twice the
/// range ANSI C78.377 allows white lamps.
pub const FULL_DUV: f64 = 0.015;
/// From this |Duv| of the estimate on the map does not apply; only estimates within it are
/// fitted on.
pub const NO_DUV: f64 = 0.03;
/// A true light is white (fitted on) within this |Duv| of the locus: the colour protocol's
/// limit for scoring a CCT.
pub const WHITE_DUV: f64 = 0.02;

/// One straight line, `slope · x + offset`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Line {
    /// The slope.
    pub slope: f64,
    /// The offset.
    pub offset: f64,
}

impl Line {
    /// The least-squares line through `(x, y)` pairs; `None` where the x are all alike.
    fn fit(pairs: impl Iterator<Item = (f64, f64)> + Clone) -> Option<Line> {
        let n = pairs.clone().count() as f64;
        let (mx, my) = pairs
            .clone()
            .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
        let (sxx, sxy) = pairs.fold((0.0, 0.0), |(a, b), (x, y)| {
            (a + (x - mx) * (x - mx), b + (x - mx) * (y - my))
        });
        (sxx / n > 1e-12 && sxy.is_finite()).then(|| Line {
            slope: sxy / sxx,
            offset: my - sxy / sxx * mx,
        })
    }

    fn at(&self, x: f64) -> f64 {
        self.slope * x + self.offset
    }
}

/// A correction of white light's colour and the colour head that moves a spectrum to it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ColourMap {
    /// Corrected mired (10⁶ / CCT) from the estimate's.
    pub mired: Line,
    /// Corrected Duv from the estimate's.
    pub duv: Line,
    /// The observer on the model's grid, pulling the whole way.
    pub head: ColourHead,
    /// What it was fitted on, in words (photos, lamps, cameras, seed).
    pub fitted_on: String,
}

/// The estimate's mired and Duv where it has a CCT.
fn mired_duv(uv_prime: [f64; 2]) -> Option<(f64, f64)> {
    uv_to_cct_duv(uv1976_to_uv1960(uv_prime))
        .ok()
        .map(|(cct, duv)| (1e6 / cct, duv))
}

impl ColourMap {
    /// The least-squares lines taking each `(estimated, true)` u′v′ pair's mired and Duv to
    /// the truth's, over the pairs whose truth is white (|Duv| ≤ [`WHITE_DUV`]) and whose
    /// estimate lies where the map applies (|Duv| < [`NO_DUV`]), for a model on `grid`.
    /// Errors on fewer than [`MIN_PHOTOS`] such pairs or estimates all of one colour.
    pub fn fit(pairs: &[([f64; 2], [f64; 2])], grid: &Grid, fitted_on: String) -> Result<Self> {
        let used: Vec<((f64, f64), (f64, f64))> = pairs
            .iter()
            .filter_map(|(e, t)| Some((mired_duv(*e)?, mired_duv(*t)?)))
            .filter(|((_, de), (_, dt))| de.abs() < NO_DUV && dt.abs() <= WHITE_DUV)
            .collect();
        if used.len() < MIN_PHOTOS {
            return Err(InferError::invalid(format!(
                "a colour map needs at least {MIN_PHOTOS} photos of white light read as \
                 white, got {} of {}",
                used.len(),
                pairs.len()
            )));
        }
        let alike =
            || InferError::invalid("a colour map's photos are too alike in colour to fit a map to");
        let mired = Line::fit(used.iter().map(|((m, _), (t, _))| (*m, *t))).ok_or_else(alike)?;
        let duv = Line::fit(used.iter().map(|((_, d), (_, t))| (*d, *t))).ok_or_else(alike)?;
        Ok(ColourMap {
            mired,
            duv,
            head: ColourHead::on_grid(grid, 1.0)?,
            fitted_on,
        })
    }

    /// How much of the map applies to an estimate of Duv `duv`: 1 up to [`FULL_DUV`], 0 from
    /// [`NO_DUV`], linear between.
    pub fn weight(duv: f64) -> f64 {
        ((NO_DUV - duv.abs()) / (NO_DUV - FULL_DUV)).clamp(0.0, 1.0)
    }

    /// The corrected u′v′ of an estimate read as `uv_prime` (unchanged where it has no CCT or
    /// is not white).
    pub fn apply(&self, uv_prime: [f64; 2]) -> [f64; 2] {
        let Some((mired, duv)) = mired_duv(uv_prime) else {
            return uv_prime;
        };
        let w = Self::weight(duv);
        let corrected_mired = self.mired.at(mired);
        if w == 0.0 || corrected_mired <= 0.0 || !corrected_mired.is_finite() {
            return uv_prime;
        }
        let Ok(uv) = cct_duv_to_uv(1e6 / corrected_mired, self.duv.at(duv)) else {
            return uv_prime;
        };
        let mapped = uv1960_to_uv1976(uv);
        [0, 1].map(|i| uv_prime[i] + w * (mapped[i] - uv_prime[i]))
    }

    /// Moves `coefficients` (of `pca`) so that their spectrum has the corrected colour of its
    /// own; leaves them where the spectrum has none (black) or the map does not apply.
    pub fn correct(&self, pca: &Pca, coefficients: &mut [f64]) {
        self.correct_with(&self.head.conformer(pca), coefficients);
    }

    /// [`ColourMap::correct`] with this map's head made ready for the PCA once
    /// ([`ColourHead::conformer`]), for many spectra.
    pub fn correct_with(&self, conformer: &Conformer, coefficients: &mut [f64]) {
        let mut own = conformer.pca().reconstruct(coefficients);
        own.iter_mut().for_each(|v| *v = v.max(0.0));
        if let Some(uv) = self.head.uv(&own) {
            let target = self.apply(uv);
            if target != uv {
                conformer.conform_from(coefficients, own, uv, target);
            }
        }
    }

    /// `moved` — the model's estimate `estimate` moved by a light-kind prior of PCA `basis`
    /// ([`crate::kind_prior`]) — given back the estimate's corrected colour as far as the map
    /// applies to it, its shape the prior's: the prior keeps a daylight a daylight, the map
    /// says which (the prior's colour comes from lights like the training ones, the map's
    /// from photos like a user's). Peak 1, nothing below 0.
    pub fn keep_colour(&self, basis: &Pca, estimate: &[f64], moved: &[f64]) -> Vec<f64> {
        let (Some(own), Some(now)) = (self.head.uv(estimate), self.head.uv(moved)) else {
            return moved.to_vec();
        };
        let Some((_, duv)) = mired_duv(own) else {
            return moved.to_vec();
        };
        let w = Self::weight(duv);
        if w == 0.0 {
            return moved.to_vec();
        }
        let mut coefficients = basis.project(moved);
        let target = [0, 1].map(|i| now[i] + w * (own[i] - now[i]));
        self.head.conform(basis, &mut coefficients, target);
        let mut out = basis.reconstruct(&coefficients);
        spdcam_core::spectral::clip_normalise(&mut out);
        out
    }

    /// Checks the stored numbers (for a map read from a file) against the model's SPD length.
    pub fn validate(&self, spd_len: usize) -> Result<()> {
        let numbers = [
            self.mired.slope,
            self.mired.offset,
            self.duv.slope,
            self.duv.offset,
        ];
        if numbers.iter().any(|v| !v.is_finite()) {
            return Err(InferError::invalid(
                "the colour map holds non-finite numbers",
            ));
        }
        if self.head.pull != 1.0 {
            return Err(InferError::invalid(
                "the colour map's head must pull the whole way (1)",
            ));
        }
        self.head.validate(spd_len)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pca::Components;
    use spdcam_core::cie_illuminant::planck;

    fn grid() -> Grid {
        Grid::new(400.0, 700.0, 5.0).unwrap()
    }

    /// Planckian spectra of 2,500–8,000 K (peak 1, rows of 61 on [`grid`]) and a PCA of them.
    fn planckians() -> (Vec<f64>, Pca) {
        let g = grid();
        let data: Vec<f64> = (0..40)
            .flat_map(|i| {
                let s = planck(2500.0 + 140.0 * i as f64, &g).unwrap();
                let m = s.values().iter().cloned().fold(0.0, f64::max);
                s.values().iter().map(|v| v / m).collect::<Vec<_>>()
            })
            .collect();
        let pca = Pca::fit(&data, 61, Components::Count(4)).unwrap();
        (data, pca)
    }

    /// u′v′ of a CCT and Duv.
    fn uv_prime(cct: f64, duv: f64) -> [f64; 2] {
        uv1960_to_uv1976(cct_duv_to_uv(cct, duv).unwrap())
    }

    /// Estimates on a lattice of 2,500–7,000 K and Duv −0.012…0.012, truths by the lines
    /// mired 1.1·m − 20 and Duv 0.5·d + 0.001.
    fn lattice() -> Vec<([f64; 2], [f64; 2])> {
        let mut pairs = Vec::new();
        for i in 0..10 {
            for j in 0..5 {
                let mired = 1e6 / (2500.0 + 500.0 * i as f64);
                let duv = -0.012 + 0.006 * j as f64;
                pairs.push((
                    uv_prime(1e6 / mired, duv),
                    uv_prime(1e6 / (1.1 * mired - 20.0), 0.5 * duv + 0.001),
                ));
            }
        }
        pairs
    }

    #[test]
    fn known_lines_are_recovered() {
        let map = ColourMap::fit(&lattice(), &grid(), "lattice".into()).unwrap();
        // Through Ohno's (2014) CCT and Duv, good to a fraction of a kelvin and 1e-5.
        assert!((map.mired.slope - 1.1).abs() < 2e-3, "{:?}", map.mired);
        assert!((map.mired.offset + 20.0).abs() < 0.5, "{:?}", map.mired);
        assert!((map.duv.slope - 0.5).abs() < 2e-3, "{:?}", map.duv);
        assert!((map.duv.offset - 0.001).abs() < 2e-5, "{:?}", map.duv);
        // 4,000 K (250 mired) on the locus → 1.1·250 − 20 = 255 mired (3,922 K), Duv 0.001.
        let (cct, duv) = uv_to_cct_duv(uv1976_to_uv1960(map.apply(uv_prime(4000.0, 0.0)))).unwrap();
        assert!((cct - 1e6 / 255.0).abs() < 3.0, "{cct}");
        assert!((duv - 0.001).abs() < 2e-5, "{duv}");
    }

    #[test]
    fn coloured_light_is_left_and_the_edge_fades() {
        let map = ColourMap::fit(&lattice(), &grid(), "lattice".into()).unwrap();
        let green = uv_prime(4000.0, 0.04);
        assert_eq!(map.apply(green), green);
        // A blue narrow band (no CCT) is left too.
        let blue = [0.17, 0.15];
        assert_eq!(map.apply(blue), blue);
        assert_eq!(ColourMap::weight(0.0), 1.0);
        assert_eq!(ColourMap::weight(-FULL_DUV), 1.0);
        assert!((ColourMap::weight(0.0225) - 0.5).abs() < 1e-12);
        assert_eq!(ColourMap::weight(NO_DUV), 0.0);
        // Half-way out the estimate moves half as far as the full map would move it.
        let edge = uv_prime(4000.0, 0.0225);
        let moved = map.apply(edge);
        let full = {
            let m = map.mired.at(250.0);
            uv_prime(1e6 / m, map.duv.at(0.0225))
        };
        for i in 0..2 {
            let half = 0.5 * (edge[i] + full[i]);
            assert!((moved[i] - half).abs() < 1e-4, "{moved:?} vs {half}");
        }
    }

    #[test]
    fn too_few_or_alike_photos_are_refused() {
        let g = grid();
        let few: Vec<_> = lattice().into_iter().take(10).collect();
        assert!(ColourMap::fit(&few, &g, String::new()).is_err());
        // All of one colour: no line to fit.
        let alike: Vec<_> = (0..40)
            .map(|_| (uv_prime(3000.0, 0.0), uv_prime(3100.0, 0.0)))
            .collect();
        assert!(ColourMap::fit(&alike, &g, String::new()).is_err());
        // Coloured truths are not fitted on: too few white ones remain.
        let coloured: Vec<_> = lattice()
            .into_iter()
            .map(|(e, _)| (e, uv_prime(4000.0, 0.05)))
            .collect();
        assert!(ColourMap::fit(&coloured, &g, String::new()).is_err());
    }

    #[test]
    fn a_corrected_spectrum_has_the_mapped_colour() {
        let (data, pca) = planckians();
        let map = ColourMap::fit(&lattice(), &grid(), "lattice".into()).unwrap();
        map.validate(61).unwrap();
        let start = &data[61 * 10..61 * 11];
        let before = map.head.uv(start).unwrap();
        let mut c = pca.project(start);
        map.correct(&pca, &mut c);
        let mut spd = pca.reconstruct(&c);
        spd.iter_mut().for_each(|v| *v = v.max(0.0));
        let after = map.head.uv(&spd).unwrap();
        let want = map.apply(before);
        assert!(
            (after[0] - want[0]).hypot(after[1] - want[1]) < 1e-5,
            "{before:?} → {after:?}, want {want:?}"
        );
        assert!((after[0] - before[0]).hypot(after[1] - before[1]) > 1e-3);
    }

    #[test]
    fn a_prior_keeps_its_shape_and_white_light_the_estimate_colour() {
        let g = grid();
        let (data, basis) = planckians();
        let map = ColourMap::fit(&lattice(), &g, "lattice".into()).unwrap();
        // The estimate a 3,900 K spectrum, the prior's a 4,460 K one: the result has the
        // estimate's colour.
        let (estimate, moved) = (&data[61 * 10..61 * 11], &data[61 * 14..61 * 15]);
        let kept = map.keep_colour(&basis, estimate, moved);
        let (want, got) = (map.head.uv(estimate).unwrap(), map.head.uv(&kept).unwrap());
        assert!(
            (want[0] - got[0]).hypot(want[1] - got[1]) < 1e-5,
            "{want:?} {got:?}"
        );
        assert_eq!(kept.iter().cloned().fold(0.0, f64::max), 1.0);
        // A coloured estimate (a green band far above the locus) leaves the prior's as it is.
        let green: Vec<f64> = g
            .wavelengths()
            .iter()
            .map(|&w| (-((w - 530.0) / 20.0).powi(2)).exp())
            .collect();
        assert_eq!(map.keep_colour(&basis, &green, moved), moved.to_vec());
    }
}
