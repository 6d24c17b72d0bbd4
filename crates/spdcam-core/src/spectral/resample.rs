//! Resampling spectra onto a regular grid, with explicit handling of uncovered ranges.

use crate::error::{Error, Result};
use crate::spectral::{Grid, SpectralSet};
use serde::{Deserialize, Serialize};

/// How values between the source's samples are computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Interpolation {
    /// Straight lines between neighbouring samples; works on irregular sampling.
    Linear,
    /// Sprague (1880) quintic interpolation, the method CIE 167:2005 recommends for
    /// uniformly sampled spectral data; needs a regular source grid and at least 6 samples.
    Sprague1880,
    /// Sprague when the source is regular with 6 or more samples, linear otherwise.
    Auto,
}

/// What a target wavelength outside the source's range receives.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Extrapolation {
    /// Zero (the data says nothing there; right for a sensitivity or an LED).
    Zero,
    /// The nearest edge value of the source.
    HoldEdge,
}

/// What a resampling did: which method ran and how many target samples lay outside the data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ResampleReport {
    /// The interpolation that ran (never [`Interpolation::Auto`]).
    pub method: Interpolation,
    /// The source's first and last wavelength (nm).
    pub source_range_nm: (f64, f64),
    /// Target samples below the source's range.
    pub filled_below: usize,
    /// Target samples above the source's range.
    pub filled_above: usize,
    /// What those samples received.
    pub extrapolation: Extrapolation,
}

impl ResampleReport {
    /// Whether any target sample lay outside the source data.
    pub fn extrapolated(&self) -> bool {
        self.filled_below + self.filled_above > 0
    }

    /// A one-line account for users, e.g. a warning that 380–395 nm were set to zero.
    pub fn describe(&self, what: &str, grid: &Grid) -> String {
        let fill = match self.extrapolation {
            Extrapolation::Zero => "set to zero",
            Extrapolation::HoldEdge => "held at the edge value",
        };
        let mut parts = Vec::new();
        if self.filled_below > 0 {
            parts.push(format!(
                "{}–{} nm",
                grid.start_nm,
                grid.wavelength(self.filled_below - 1)
            ));
        }
        if self.filled_above > 0 {
            parts.push(format!(
                "{}–{} nm",
                grid.wavelength(grid.count - self.filled_above),
                grid.end_nm()
            ));
        }
        format!(
            "{what} covers {}–{} nm only; {} {fill}",
            self.source_range_nm.0,
            self.source_range_nm.1,
            parts.join(" and ")
        )
    }
}

/// Sprague (1880) boundary coefficients (CIE 167:2005) for the two samples padded at each end.
const SPRAGUE_BOUNDARY: [[f64; 6]; 4] = [
    [884.0, -1960.0, 3033.0, -2648.0, 1080.0, -180.0],
    [508.0, -540.0, 488.0, -367.0, 144.0, -24.0],
    [-24.0, 144.0, -367.0, 488.0, -540.0, 508.0],
    [-180.0, 1080.0, -2648.0, 3033.0, -1960.0, 884.0],
];

impl SpectralSet {
    /// Resamples every item onto `grid`. Target wavelengths outside the source range get
    /// `extrapolation`; the report says how many did. An item with no negative value stays
    /// non-negative: Sprague's quintic overshoots below zero beside a spike or a zero end
    /// (a fluorescent lamp's lines, a table ending in 0 at 780 nm), and those undershoots,
    /// which the data never held, are set to zero.
    pub fn resample(
        &self,
        grid: &Grid,
        interpolation: Interpolation,
        extrapolation: Extrapolation,
    ) -> Result<(SpectralSet, ResampleReport)> {
        self.resample_with(grid, interpolation, extrapolation, true)
    }

    /// [`SpectralSet::resample`] without setting the undershoots of non-negative items to
    /// zero: linear in the values, so that a resampling matrix can be built from it (the
    /// resampled unit spectra are its rows). Apply [`clamp_undershoot`] to what the matrix
    /// gives to have [`SpectralSet::resample`]'s result.
    pub fn resample_unclamped(
        &self,
        grid: &Grid,
        interpolation: Interpolation,
        extrapolation: Extrapolation,
    ) -> Result<(SpectralSet, ResampleReport)> {
        self.resample_with(grid, interpolation, extrapolation, false)
    }

    fn resample_with(
        &self,
        grid: &Grid,
        interpolation: Interpolation,
        extrapolation: Extrapolation,
        clamp: bool,
    ) -> Result<(SpectralSet, ResampleReport)> {
        let x = self.wavelengths();
        if x.len() < 2 {
            return Err(Error::invalid(format!(
                "cannot resample spectra given at {} wavelength only ({} nm): interpolation \
                 needs at least two",
                x.len(),
                x[0]
            )));
        }
        let regular = self.grid();
        let method = match interpolation {
            Interpolation::Auto if regular.is_some() && x.len() >= 6 => Interpolation::Sprague1880,
            Interpolation::Auto => Interpolation::Linear,
            Interpolation::Sprague1880 if regular.is_none() || x.len() < 6 => {
                return Err(Error::invalid(format!(
                    "Sprague interpolation needs at least 6 regularly spaced samples ({} samples, {}); use linear",
                    x.len(),
                    if regular.is_some() { "regular" } else { "irregular" }
                )))
            }
            m => m,
        };
        let (lo, hi) = (x[0], x[x.len() - 1]);
        let targets = grid.wavelengths();
        let eps = 1e-9 * hi.abs().max(1.0);
        let filled_below = targets.iter().filter(|&&t| t < lo - eps).count();
        let filled_above = targets.iter().filter(|&&t| t > hi + eps).count();
        let values = self
            .items()
            .iter()
            .map(|y| {
                let padded = (method == Interpolation::Sprague1880).then(|| sprague_pad(y));
                let mut out: Vec<f64> = targets
                    .iter()
                    .map(|&t| {
                        if t < lo - eps {
                            return edge(extrapolation, y[0]);
                        }
                        if t > hi + eps {
                            return edge(extrapolation, y[y.len() - 1]);
                        }
                        let t = t.clamp(lo, hi);
                        match &padded {
                            Some(p) => sprague_at(x[0], x[1] - x[0], p, y.len(), t),
                            None => linear_at(x, y, t),
                        }
                    })
                    .collect();
                if clamp {
                    clamp_undershoot(y, &mut out);
                }
                out
            })
            .collect();
        let set = SpectralSet::on_grid(grid, self.names().to_vec(), values)?;
        Ok((
            set,
            ResampleReport {
                method,
                source_range_nm: (lo, hi),
                filled_below,
                filled_above,
                extrapolation,
            },
        ))
    }
}

/// Sets the negative values of `resampled` to zero when its `source` has none: an
/// interpolation's undershoot, not the data's.
pub fn clamp_undershoot(source: &[f64], resampled: &mut [f64]) {
    if source.iter().all(|&v| v >= 0.0) {
        // Not `max`, which would make a NaN 0: a non-finite value is left to be refused.
        resampled
            .iter_mut()
            .filter(|v| **v < 0.0)
            .for_each(|v| *v = 0.0);
    }
}

fn edge(extrapolation: Extrapolation, value: f64) -> f64 {
    match extrapolation {
        Extrapolation::Zero => 0.0,
        Extrapolation::HoldEdge => value,
    }
}

/// Index of the interval `[x[i], x[i+1]]` holding `t` (clamped to the last interval).
fn interval(x: &[f64], t: f64) -> usize {
    let i = x.partition_point(|&v| v <= t);
    i.saturating_sub(1).min(x.len() - 2)
}

fn linear_at(x: &[f64], y: &[f64], t: f64) -> f64 {
    let i = interval(x, t);
    let f = (t - x[i]) / (x[i + 1] - x[i]);
    y[i] + f * (y[i + 1] - y[i])
}

/// The samples with two extrapolated values added at each end, as CIE 167:2005 prescribes.
fn sprague_pad(y: &[f64]) -> Vec<f64> {
    let n = y.len();
    let dot = |c: &[f64; 6], v: &[f64]| c.iter().zip(v).map(|(a, b)| a * b).sum::<f64>() / 209.0;
    let mut p = Vec::with_capacity(n + 4);
    p.push(dot(&SPRAGUE_BOUNDARY[0], &y[..6]));
    p.push(dot(&SPRAGUE_BOUNDARY[1], &y[..6]));
    p.extend_from_slice(y);
    p.push(dot(&SPRAGUE_BOUNDARY[2], &y[n - 6..]));
    p.push(dot(&SPRAGUE_BOUNDARY[3], &y[n - 6..]));
    p
}

/// Sprague's quintic on the interval holding `t`; `p` is the padded sample list.
fn sprague_at(x0: f64, step: f64, p: &[f64], n: usize, t: f64) -> f64 {
    let k = ((t - x0) / step).floor().max(0.0) as usize;
    let i = k.min(n - 2);
    let xf = (t - x0) / step - i as f64;
    let j = i + 2;
    let (m2, m1, c0, p1, p2, p3) = (p[j - 2], p[j - 1], p[j], p[j + 1], p[j + 2], p[j + 3]);
    let a1 = (2.0 * m2 - 16.0 * m1 + 16.0 * p1 - 2.0 * p2) / 24.0;
    let a2 = (-m2 + 16.0 * m1 - 30.0 * c0 + 16.0 * p1 - p2) / 24.0;
    let a3 = (-9.0 * m2 + 39.0 * m1 - 70.0 * c0 + 66.0 * p1 - 33.0 * p2 + 7.0 * p3) / 24.0;
    let a4 = (13.0 * m2 - 64.0 * m1 + 126.0 * c0 - 124.0 * p1 + 61.0 * p2 - 12.0 * p3) / 24.0;
    let a5 = (-5.0 * m2 + 25.0 * m1 - 50.0 * c0 + 50.0 * p1 - 25.0 * p2 + 5.0 * p3) / 24.0;
    c0 + xf * (a1 + xf * (a2 + xf * (a3 + xf * (a4 + xf * a5))))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line_set(x: Vec<f64>) -> SpectralSet {
        let y = x.iter().map(|v| 0.3 * v - 7.0).collect();
        SpectralSet::new(x, vec!["line".into()], vec![y]).unwrap()
    }

    #[test]
    fn both_methods_are_exact_on_a_linear_function() {
        let set = line_set((0..=10).map(|i| 400.0 + 10.0 * i as f64).collect());
        let grid = Grid::new(400.0, 500.0, 1.0).unwrap();
        for method in [Interpolation::Linear, Interpolation::Sprague1880] {
            let (out, rep) = set.resample(&grid, method, Extrapolation::Zero).unwrap();
            assert!(!rep.extrapolated());
            for (w, v) in grid.wavelengths().iter().zip(out.item(0)) {
                assert!((v - (0.3 * w - 7.0)).abs() < 1e-9, "{method:?} at {w}: {v}");
            }
        }
    }

    #[test]
    fn uncovered_range_is_reported_and_filled() {
        let set = line_set(vec![400.0, 450.0, 500.0]);
        let grid = Grid::new(380.0, 520.0, 10.0).unwrap();
        let (zero, rep) = set
            .resample(&grid, Interpolation::Linear, Extrapolation::Zero)
            .unwrap();
        assert_eq!((rep.filled_below, rep.filled_above), (2, 2));
        assert_eq!(zero.item(0)[0], 0.0);
        assert_eq!(zero.item(0)[14], 0.0);
        let (held, _) = set
            .resample(&grid, Interpolation::Linear, Extrapolation::HoldEdge)
            .unwrap();
        assert_eq!(held.item(0)[0], 0.3 * 400.0 - 7.0);
        assert!(rep.describe("camera", &grid).contains("380–390 nm"));
    }

    #[test]
    fn sprague_refuses_irregular_data_and_auto_falls_back() {
        let set = line_set(vec![400.0, 401.0, 403.0, 406.0, 410.0, 415.0, 421.0]);
        let grid = Grid::new(400.0, 420.0, 5.0).unwrap();
        assert!(set
            .resample(&grid, Interpolation::Sprague1880, Extrapolation::Zero)
            .is_err());
        let (_, rep) = set
            .resample(&grid, Interpolation::Auto, Extrapolation::Zero)
            .unwrap();
        assert_eq!(rep.method, Interpolation::Linear);
    }

    #[test]
    fn a_single_wavelength_is_an_error_not_a_panic() {
        // Issue 15: one wavelength row underflowed `len - 2` in `interval`.
        let set = SpectralSet::new(vec![550.0], vec!["one".into()], vec![vec![1.0]]).unwrap();
        for method in [Interpolation::Auto, Interpolation::Linear] {
            let e = set
                .resample(&Grid::SIMULATION, method, Extrapolation::Zero)
                .unwrap_err()
                .to_string();
            assert!(e.contains("550 nm") && e.contains("at least two"), "{e}");
        }
    }

    #[test]
    fn a_non_negative_spectrum_stays_non_negative() {
        // Issue 39: a lamp at 5 nm with a spike and 0 at 780 nm rang below zero on 1 nm.
        let x: Vec<f64> = (0..81).map(|i| 380.0 + 5.0 * i as f64).collect();
        let mut y: Vec<f64> = x.iter().map(|w| 0.02 * (780.0 - w) / 400.0).collect();
        y[34] = 1.0; // 550 nm
        y[80] = 0.0;
        let set = SpectralSet::new(x, vec!["lamp".into()], vec![y]).unwrap();
        let grid = Grid::new(380.0, 780.0, 1.0).unwrap();
        let (raw, _) = set
            .resample_unclamped(&grid, Interpolation::Sprague1880, Extrapolation::Zero)
            .unwrap();
        assert!(
            raw.item(0).iter().any(|&v| v < 0.0),
            "no undershoot to test"
        );
        let (out, _) = set
            .resample(&grid, Interpolation::Sprague1880, Extrapolation::Zero)
            .unwrap();
        assert!(out.item(0).iter().all(|&v| v >= 0.0));
        for (a, b) in out.item(0).iter().zip(raw.item(0)) {
            assert!(*b < 0.0 || a == b);
        }
        // Negative data keeps its negatives (it is refused or accepted by what holds it).
        let signed = line_set((0..=10).map(|i| 10.0 + 10.0 * i as f64).collect());
        let (out, _) = signed
            .resample(
                &Grid::new(10.0, 110.0, 1.0).unwrap(),
                Interpolation::Auto,
                Extrapolation::Zero,
            )
            .unwrap();
        assert!(out.item(0)[0] < 0.0);
    }

    #[test]
    fn sprague_passes_through_samples() {
        let x: Vec<f64> = (0..12).map(|i| 380.0 + 10.0 * i as f64).collect();
        let y: Vec<f64> = x.iter().map(|v| ((v - 380.0) / 30.0).sin() + 2.0).collect();
        let set = SpectralSet::new(x.clone(), vec!["s".into()], vec![y.clone()]).unwrap();
        let grid = Grid::new(380.0, 490.0, 10.0).unwrap();
        let (out, _) = set
            .resample(&grid, Interpolation::Sprague1880, Extrapolation::Zero)
            .unwrap();
        for (a, b) in out.item(0).iter().zip(&y) {
            assert!((a - b).abs() < 1e-12);
        }
    }
}
