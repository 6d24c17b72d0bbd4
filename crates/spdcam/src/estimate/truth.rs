//! The true SPDs beside estimates: `--truth`, or `<photo stem>.truth.csv` beside each photo.

use anyhow::{bail, Context, Result};
use spdcam_core::spectral::{Extrapolation, Grid, Interpolation, Spd, SpectralSet};
use std::path::Path;

/// Truth files found beside a photo: `<photo stem>` + this.
pub(super) const TRUTH_SUFFIX: &str = ".truth.csv";

/// Reads a spectral CSV of true SPDs, resampled to `grid`; a truth that is negative or
/// holds no light on `grid` is refused (a GFC against it means nothing).
pub(super) fn read_truths(path: &Path, grid: &Grid) -> Result<SpectralSet> {
    let set = SpectralSet::read_csv(path)
        .and_then(|s| s.require_non_negative("true SPD", 0.01))
        .with_context(|| format!("reading the true SPDs {}", path.display()))?;
    let (set, _) = set.resample(grid, Interpolation::Auto, Extrapolation::HoldEdge)?;
    if let Some(i) = (0..set.len()).find(|&i| set.item(i).iter().all(|&v| v <= 0.0)) {
        bail!(
            "{}: the true SPD '{}' is zero everywhere on {grid}; a truth must hold light",
            path.display(),
            set.names()[i]
        );
    }
    Ok(set)
}

/// The truth for each estimate: from `--truth` (one column for all, or one per estimate),
/// else from `<stem>.truth.csv` beside each photo (`photos`, one per estimate); resampled
/// to `grid`.
pub(super) fn truths(
    truth: Option<&Path>,
    photos: &[&Path],
    count: usize,
    grid: &Grid,
) -> Result<Vec<Option<Spd>>> {
    let item = |set: &SpectralSet, i: usize| Spd::new(*grid, set.item(i).to_vec());
    if let Some(path) = truth {
        let set = read_truths(path, grid)?;
        return match set.len() {
            1 => Ok(vec![Some(item(&set, 0)?); count]),
            n if n == count => (0..n).map(|i| Ok(Some(item(&set, i)?))).collect(),
            n => bail!(
                "{}: {n} true SPDs for {count} estimates; give one, or one per estimate",
                path.display()
            ),
        };
    }
    if photos.is_empty() {
        return Ok(vec![None; count]);
    }
    photos
        .iter()
        .map(|photo| {
            let Some(stem) = photo.file_stem() else {
                return Ok(None);
            };
            let path = photo.with_file_name(format!("{}{TRUTH_SUFFIX}", stem.to_string_lossy()));
            if !path.is_file() {
                return Ok(None);
            }
            let set = read_truths(&path, grid)?;
            if set.len() != 1 {
                bail!(
                    "{}: one true SPD expected, found {}",
                    path.display(),
                    set.len()
                );
            }
            Ok(Some(item(&set, 0)?))
        })
        .collect()
}
