//! The real photo sets in the trust protocols: split as the real-camera study splits them,
//! their validation photos cut so that no set outweighs the virtual calibration photos.

use crate::error::Result;
use crate::held_out::in_data_dir;
use crate::real_cameras::split_sets_on;
use crate::trust::shots::Rows;
use spdcam_core::builtin::DataDir;
use spdcam_core::chart::KnownChart;
use spdcam_core::dataset::MeasuredPhotos;
use spdcam_infer::Model;
use std::path::Path;

/// `sets` with each one's validation photos cut to at most `virtual_photos` / (number of
/// sets), evenly spaced, so that each real set weighs at most as much as a third of the
/// virtual calibration photos and the real sets together no more than those: the calibration
/// serves room lamps and the real sets' lights alike, and no large set (Hue's 711 photos)
/// sets it alone.
pub fn balanced(mut sets: Vec<RealSplit>, virtual_photos: usize) -> Vec<RealSplit> {
    let cap = virtual_photos / sets.len().max(1);
    for set in &mut sets {
        let n = set.val.features.len();
        if n > cap {
            let keep: Vec<usize> = (0..cap).map(|k| k * n / cap).collect();
            let pick = |rows: &[Vec<f64>]| keep.iter().map(|&i| rows[i].clone()).collect();
            set.val = Rows {
                features: pick(&set.val.features),
                truths: pick(&set.val.truths),
            };
        }
    }
    sets
}

/// One real photo set split as the real-camera study splits it, on a model's grid, the SPDs
/// peak-normalised.
#[derive(Clone)]
pub struct RealSplit {
    /// The set's name.
    pub label: &'static str,
    /// Its validation photos (calibration may use them).
    pub val: Rows,
    /// Its test photos (only measured).
    pub test: Rows,
}

/// The real photo sets (SG photos) split as the real-camera study splits them
/// ([`split_sets_on`]), on `model`'s grid; none for another chart.
pub fn real_split(
    thesis_data: Option<&Path>,
    data_dir: &DataDir,
    model: &Model,
    chart_name: &str,
) -> Result<Vec<RealSplit>> {
    if KnownChart::from_name(chart_name) != Some(KnownChart::Sg96) {
        return Ok(Vec::new());
    }
    let thesis = match thesis_data {
        Some(p) => p.to_path_buf(),
        None => in_data_dir(None, "thesis", data_dir)?,
    };
    let rows = |photos: MeasuredPhotos| Rows {
        truths: photos
            .spds
            .iter()
            .map(|s| spdcam_core::spectral::normalise_by_max(s.values()))
            .collect(),
        features: photos.features,
    };
    Ok(split_sets_on(&thesis, &model.grid())?
        .into_iter()
        .map(|set| RealSplit {
            label: set.label,
            val: rows(set.val),
            test: rows(set.test),
        })
        .collect())
}
