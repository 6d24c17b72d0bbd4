//! The true SPDs beside estimates: `--truth`, or `<photo stem>.truth.csv` beside each photo.

use anyhow::{bail, Context, Result};
use spdcam_core::error::short_number;
use spdcam_core::named_light::SPD_NEGATIVE_TOLERANCE;
use spdcam_core::photo::Place;
use spdcam_core::spectral::{Extrapolation, Grid, Interpolation, Spd, SpectralSet};
use std::path::Path;

/// Truth files found beside a photo: `<photo stem>` + this.
pub(super) const TRUTH_SUFFIX: &str = ".truth.csv";

/// The part of the scored range a truth may miss at its ends, in all (held at its edge
/// values there, with a warning): 5 %, 15 nm of 400–700 nm. A truth missing more would be
/// scored on values it does not have.
const TRUTH_MISSING_MAX: f64 = 0.05;

/// Reads a spectral CSV of true SPDs, resampled to `grid`; a truth that is negative, holds
/// no light on `grid` or misses more than [`TRUTH_MISSING_MAX`] of it is refused (a GFC
/// against it means nothing).
pub(super) fn read_truths(path: &Path, grid: &Grid) -> Result<SpectralSet> {
    let set = SpectralSet::read_csv(path)
        .and_then(|s| s.require_non_negative("true SPD", SPD_NEGATIVE_TOLERANCE))
        .with_context(|| {
            format!(
                "reading the true SPDs {} (a spectral CSV: wavelength_nm, then one column per \
                 SPD)",
                path.display()
            )
        })?;
    check_coverage(path, set.wavelengths(), grid)?;
    // Only the shape is scored (GFC, and RMSE between peak-normalised SPDs): each truth is
    // divided by its peak first, so that a file in any units (1e300 W/nm or 1e-300) is
    // resampled without overflowing or vanishing. A truth with no light keeps its zeros and
    // is refused below.
    let set = set.normalised_by_max().unwrap_or(set);
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

/// Refuses a truth sampled at `wavelengths` that misses more than [`TRUTH_MISSING_MAX`]
/// of `grid`'s range, and warns of a smaller miss (held at the truth's edge values).
fn check_coverage(path: &Path, wavelengths: &[f64], grid: &Grid) -> Result<()> {
    let (lo, hi) = (wavelengths[0], wavelengths[wavelengths.len() - 1]);
    let (start, end) = (grid.start_nm, grid.end_nm());
    let span = end - start;
    let covered = (hi.min(end) - lo.max(start)).max(0.0);
    let missing = span - covered;
    if missing <= 1e-9 * span.max(1.0) {
        return Ok(());
    }
    let ranges = format!(
        "{} covers {}–{} nm, the estimates are scored over {}–{} nm",
        path.display(),
        short_number(lo),
        short_number(hi),
        short_number(start),
        short_number(end)
    );
    if missing > TRUTH_MISSING_MAX * span {
        bail!(
            "{ranges}: the truth misses {} nm of it, so no GFC or RMSE can be given; give a \
             truth covering the scored range, or score a range the truth covers (--range)",
            short_number(missing)
        );
    }
    eprintln!(
        "warning: {ranges}; the {} nm it misses are held at its edge values",
        short_number(missing)
    );
    Ok(())
}

/// The truth for each estimate: from `--truth` (one column for all, or one per estimate),
/// else from `<stem>.truth.csv` beside each photo (`photos`, one per estimate, with its
/// place among several charts in `places`: one column for the photo, or one per place in
/// their numbered order); resampled to `grid`.
pub(super) fn truths(
    truth: Option<&Path>,
    photos: &[&Path],
    places: &[Option<Place>],
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
        .zip(places)
        .map(|(photo, place)| {
            let Some(stem) = photo.file_stem() else {
                return Ok(None);
            };
            let path = photo.with_file_name(format!("{}{TRUTH_SUFFIX}", stem.to_string_lossy()));
            if !path.is_file() {
                return Ok(None);
            }
            let set = read_truths(&path, grid)?;
            match (set.len(), place) {
                (1, _) => Ok(Some(item(&set, 0)?)),
                (n, Some(place)) if n == place.of => Ok(Some(item(&set, place.number - 1)?)),
                (n, Some(place)) => bail!(
                    "{}: {n} true SPDs for a photo of {} charts; give one, or one per chart \
                     from left to right",
                    path.display(),
                    place.of
                ),
                (n, None) => bail!("{}: one true SPD expected, found {n}", path.display()),
            }
        })
        .collect()
}
