//! The thesis's virtual sets (Gaussian G1–G4 and the 24-channel Telelumen set, ColorChecker
//! 24): their names, channel spectra and parts, read with SPDs made from their weights.

use crate::error::{LearnError, Result};
use crate::train::TrainingSet;
use spdcam_core::dataset::{Columns, Precision, SampleBatch};
use spdcam_core::light_families::Channels;
use spdcam_core::spectral::{Extrapolation, Grid, Interpolation, SpectralSet};
use spdcam_infer::record::DataInfo;
use spdcam_infer::FeatureRows;
use std::collections::BTreeMap;
use std::path::Path;

/// One of the thesis's virtual sets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SetName {
    /// Gaussian, 4 channels.
    G1,
    /// Gaussian, 5 channels.
    G2,
    /// Gaussian, 6 channels.
    G3,
    /// Gaussian, 7 channels.
    G4,
    /// All 24 Telelumen channels (the thesis's H2 used the SG chart; this set uses CC24).
    T24,
}

impl SetName {
    /// Every set, in the thesis's order.
    pub const ALL: [SetName; 5] = [
        SetName::G1,
        SetName::G2,
        SetName::G3,
        SetName::G4,
        SetName::T24,
    ];

    fn dir(self) -> &'static str {
        match self {
            SetName::G1 => "gaussian_4ch_cc24",
            SetName::G2 => "gaussian_5ch_cc24",
            SetName::G3 => "gaussian_6ch_cc24",
            SetName::G4 => "gaussian_7ch_cc24",
            SetName::T24 => "telelumen_24ch_cc24",
        }
    }

    /// The set's name in the tables (`G1`…`T24`).
    pub fn label(self) -> &'static str {
        match self {
            SetName::G1 => "G1",
            SetName::G2 => "G2",
            SetName::G3 => "G3",
            SetName::G4 => "G4",
            SetName::T24 => "T24",
        }
    }

    /// The number of the thesis's Gaussian channels ([`Channels::gaussian`]); `None` for
    /// the Telelumen set.
    fn gaussian_channels(self) -> Option<usize> {
        match self {
            SetName::G1 => Some(4),
            SetName::G2 => Some(5),
            SetName::G3 => Some(6),
            SetName::G4 => Some(7),
            SetName::T24 => None,
        }
    }

    /// Mean GFC the thesis published: (1D CNN, DNN) where it has them.
    pub fn thesis_gfc(self) -> (Option<f64>, Option<f64>) {
        match self {
            SetName::G1 => (Some(0.9997), Some(0.9989)),
            SetName::G2 => (Some(0.9994), Some(0.9988)),
            SetName::G3 => (Some(0.9992), Some(0.9982)),
            SetName::G4 => (Some(0.9990), Some(0.9972)),
            SetName::T24 => (None, None),
        }
    }
}

impl std::str::FromStr for SetName {
    type Err = LearnError;

    /// A set by its label, in any case (`g1`, `T24`).
    fn from_str(name: &str) -> Result<SetName> {
        SetName::ALL
            .into_iter()
            .find(|set| set.label().eq_ignore_ascii_case(name))
            .ok_or_else(|| {
                LearnError::invalid(format!(
                    "unknown thesis set '{name}' (known: {})",
                    SetName::ALL
                        .map(|set| set.label().to_lowercase())
                        .join(", ")
                ))
            })
    }
}

/// Channel spectra of a set on the simulation grid (`root`: the thesis's data, holding
/// `telelumen_24_channels.csv`).
pub fn channels(set: SetName, root: &Path) -> Result<Vec<Vec<f64>>> {
    let grid = Grid::SIMULATION;
    if let Some(n) = set.gaussian_channels() {
        return Ok(Channels::gaussian(n, &grid)?.spds);
    }
    let path = root.join("telelumen_24_channels.csv");
    let raw = SpectralSet::read_csv(&path)
        .map_err(|e| LearnError::invalid(format!("reading {}: {e}", path.display())))?;
    let (set, _) = raw.resample(&grid, Interpolation::Linear, Extrapolation::Zero)?;
    // The thesis's code set the channels to 0 above 700 nm.
    Ok((0..set.len())
        .map(|i| {
            set.item(i)
                .iter()
                .enumerate()
                .map(|(k, v)| {
                    if grid.wavelength(k) > 700.0 {
                        0.0
                    } else {
                        v.max(0.0)
                    }
                })
                .collect()
        })
        .collect())
}

/// One part (`train` or `val`) of a set under `root`'s `virtual/`, with SPDs made from its
/// weights and the channels `ch` ([`channels`]), normalised to a maximum of 1.
pub fn load_part(set: SetName, part: &str, root: &Path, ch: &[Vec<f64>]) -> Result<TrainingSet> {
    let dir = root.join("virtual").join(format!("{}_{part}", set.dir()));
    let features = FeatureRows::read_csv(&dir.join("features.csv"))?;
    let weights = FeatureRows::read_csv(&dir.join("weights.csv"))?;
    if weights.rows != features.rows || weights.names.len() != ch.len() {
        return Err(LearnError::invalid(format!(
            "{}: {} feature rows, {} weight rows of {} channels (expected {})",
            dir.display(),
            features.rows,
            weights.rows,
            weights.names.len(),
            ch.len()
        )));
    }
    let grid = Grid::SIMULATION;
    let k = ch.len();
    let mut samples = SampleBatch {
        feature_count: features.names.len(),
        spd_len: grid.count,
        weight_count: k,
        features: features.values.clone(),
        weights: weights.values.clone(),
        ..SampleBatch::default()
    };
    for (i, w) in weights.values.chunks_exact(k).enumerate() {
        let mut spd: Vec<f64> = (0..grid.count)
            .map(|j| w.iter().zip(ch).map(|(wi, c)| wi * c[j]).sum())
            .collect();
        let max = spd.iter().copied().fold(0.0, f64::max);
        if max > 0.0 {
            spd.iter_mut().for_each(|v| *v /= max);
        }
        samples.spds.extend(spd);
        samples.samples.push(i as u64);
        samples.families.push(set.label().into());
        samples.attempts.push(1);
    }
    Ok(TrainingSet {
        samples,
        columns: Columns {
            feature_names: features.names,
            feature_precision: Precision::Float64,
            spd_grid: grid,
            weight_names: weights.names,
        },
        info: DataInfo {
            path: format!("thesis virtual/{}_{part}", set.dir()),
            samples: features.rows,
            chart: Some("colorchecker-24".into()),
            camera: Some("canon-eos-5d-mark-ii (thesis)".into()),
            families: BTreeMap::from([(set.label().to_string(), features.rows as u64)]),
            origin: None,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sets_are_named_by_their_labels_in_any_case() {
        for set in SetName::ALL {
            assert_eq!(set.label().to_lowercase().parse::<SetName>().unwrap(), set);
            assert_eq!(set.label().parse::<SetName>().unwrap(), set);
        }
        let err = "h2".parse::<SetName>().unwrap_err().to_string();
        assert!(
            err.contains("'h2'") && err.contains("g1, g2, g3, g4, t24"),
            "{err}"
        );
    }
}
