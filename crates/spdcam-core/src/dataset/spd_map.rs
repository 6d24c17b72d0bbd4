//! Moving SPDs onto a dataset's wavelength grid without touching the numbers it already has.

use crate::error::Result;
use crate::spectral::{Extrapolation, Grid, Interpolation, ResampleReport, SpectralSet};

/// Maps SPDs sampled at fixed source wavelengths onto a target grid. Target wavelengths that
/// are source wavelengths get the source value exactly; the others are interpolated
/// (Sprague 1880 on regular sources, linear otherwise) and set to zero outside the source.
#[derive(Debug, Clone)]
pub(crate) struct SpdMap {
    from: Vec<f64>,
    to: Grid,
    /// `(target index, source index)` of the wavelengths both share.
    shared: Vec<(usize, usize)>,
    /// How the other wavelengths are filled; `None` when every target is a source sample.
    report: Option<ResampleReport>,
}

impl SpdMap {
    /// A map from SPDs at `from` (nm, increasing) onto `to`.
    pub(crate) fn new(from: &[f64], to: &Grid) -> Result<SpdMap> {
        let shared: Vec<(usize, usize)> = to
            .wavelengths()
            .iter()
            .enumerate()
            .filter_map(|(k, &t)| {
                let s = from.partition_point(|&w| w < t - 1e-9);
                (s < from.len() && (from[s] - t).abs() <= 1e-9).then_some((k, s))
            })
            .collect();
        let report = if shared.len() == to.count {
            None
        } else {
            let probe = SpectralSet::new(
                from.to_vec(),
                vec!["spd".into()],
                vec![vec![0.0; from.len()]],
            )?;
            Some(
                probe
                    .resample(to, Interpolation::Auto, Extrapolation::Zero)?
                    .1,
            )
        };
        Ok(SpdMap {
            from: from.to_vec(),
            to: *to,
            shared,
            report,
        })
    }

    /// How wavelengths the source lacks were filled, if there were any.
    pub(crate) fn report(&self) -> Option<&ResampleReport> {
        self.report.as_ref()
    }

    /// Appends the SPD `values` (one per source wavelength) on the target grid to `out`.
    pub(crate) fn apply(&self, values: &[f64], out: &mut Vec<f64>) -> Result<()> {
        let start = out.len();
        if self.report.is_none() {
            out.extend(self.shared.iter().map(|&(_, s)| values[s]));
            return Ok(());
        }
        let set = SpectralSet::new(self.from.clone(), vec!["spd".into()], vec![values.to_vec()])?;
        let (resampled, _) = set.resample(&self.to, Interpolation::Auto, Extrapolation::Zero)?;
        out.extend_from_slice(resampled.item(0));
        for &(k, s) in &self.shared {
            out[start + k] = values[s];
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shared_wavelengths_keep_their_values() {
        let from: Vec<f64> = (0..36).map(|i| 380.0 + 10.0 * i as f64).collect();
        let values: Vec<f64> = from.iter().map(|w| (w / 37.0).sin() + 1.3).collect();
        let map = SpdMap::new(&from, &Grid::SIMULATION).unwrap();
        let report = map.report().unwrap();
        assert_eq!((report.filled_below, report.filled_above), (0, 10));
        let mut out = Vec::new();
        map.apply(&values, &mut out).unwrap();
        assert_eq!(out.len(), 81);
        for (i, v) in values.iter().enumerate() {
            assert_eq!(out[2 * i], *v, "{} nm", from[i]);
        }
        assert!(out[71..].iter().all(|&v| v == 0.0));
        let back = SpdMap::new(
            &Grid::SIMULATION.wavelengths(),
            &Grid::new(380.0, 730.0, 10.0).unwrap(),
        )
        .unwrap();
        assert!(back.report().is_none());
        let mut again = Vec::new();
        back.apply(&out, &mut again).unwrap();
        assert_eq!(again, values);
    }
}
