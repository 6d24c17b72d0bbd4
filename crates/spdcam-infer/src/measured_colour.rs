//! A raw photo's light colour, measured through the file's own colour matrices
//! ([`spdcam_core::photo::raw::RawReading::light_xy`]), given to the model's spectrum: the model
//! reads the shape from the developed patches, the chromaticity comes from the sensor.
//!
//! Why: after white balance (the camera's, or the raw development's) a light's colour lives
//! only in small shifts of the coloured patches, which the model reads to about Δu′v′ 0.01;
//! the raw values of the chart's grey patches are the camera's reading of the light itself,
//! which a 3×3 calibration takes to XYZ far more closely. The spectrum is moved to that
//! chromaticity by the smallest change in the model's PCA coefficients
//! ([`ColourHead::conform`]), so its shape changes as little as the colour needs; its CCT
//! and Duv intervals are those of the measured chromaticity's own calibrated error
//! ([`cct_duv_intervals`]), not the model's.

use crate::colour_head::ColourHead;
use crate::model::Model;
use crate::trust::MetricInterval;
use spdcam_core::colorimetry::xy_to_xyz;
use spdcam_core::quality::uv::xyz_to_uv1976;
use std::collections::BTreeMap;

/// `spds` (the model's SPDs on its grid, peak 1, row-major) each moved to chromaticity `xy`
/// (CIE 1931); `false` and unchanged where the model has no PCA basis to move them in.
pub fn conform(model: &Model, spds: &mut [f64], xy: [f64; 2]) -> bool {
    let Some(pca) = model.target().pca() else {
        return false;
    };
    let Ok(head) = ColourHead::on_grid(&model.grid(), 1.0) else {
        return false;
    };
    let target = xyz_to_uv1976(xy_to_xyz(xy, 1.0));
    let d = model.grid().count;
    for spd in spds.chunks_mut(d) {
        let mut coefficients = pca.project(spd);
        head.conform(pca, &mut coefficients, target);
        let mut moved = pca.reconstruct(&coefficients);
        spdcam_core::spectral::clip_normalise(&mut moved);
        spd.copy_from_slice(&moved);
    }
    true
}

/// Relative CCT errors (|estimate − truth| / truth) a raw photo's light is read within with
/// 68 % and 95 % probability, and the same for Duv (absolute): the 68th and 95th
/// percentiles of those errors on raw scene photos of the validation split's validation
/// lamps through its held-out cameras, both charts pooled (`spdcam experiment colour --raw
/// --photos-csv`, `docs/raw.md`); their coverage is reported on its test lamps. A split
/// conformal interval (Vovk, Gammerman & Shafer, *Algorithmic Learning in a Random World*,
/// 2005; Lei et al., JASA 2018): one calibration set, the empirical quantile as half-width.
pub const RAW_CCT_RELATIVE: [f64; 2] = [0.0343, 0.0859];
/// See [`RAW_CCT_RELATIVE`].
pub const RAW_DUV: [f64; 2] = [0.0051, 0.0094];

/// The CCT and Duv intervals (half-widths at 68 % and 95 %) of a light a raw photo read at
/// CCT `cct_k`.
pub fn cct_duv_intervals(cct_k: f64) -> [MetricInterval; 2] {
    [
        MetricInterval {
            half68: RAW_CCT_RELATIVE[0] * cct_k,
            half95: RAW_CCT_RELATIVE[1] * cct_k,
        },
        MetricInterval {
            half68: RAW_DUV[0],
            half95: RAW_DUV[1],
        },
    ]
}

/// Sets the CCT and Duv intervals of `metrics` (where they are there) for an estimate of
/// CCT `cct_k` from a raw photo ([`cct_duv_intervals`]).
pub fn set_intervals(metrics: &mut BTreeMap<String, MetricInterval>, cct_k: f64) {
    let [cct, duv] = cct_duv_intervals(cct_k);
    for (key, interval) in [("cct_k", cct), ("duv", duv)] {
        if let Some(slot) = metrics.get_mut(key) {
            *slot = interval;
        }
    }
}
