//! A raw photo's light colour, measured through the file's own colour matrices
//! ([`spdcam_core::raw::RawReading::light_xy`]), given to the model's spectrum: the model
//! reads the shape from the developed patches, the chromaticity comes from the sensor.
//!
//! Why: after white balance (the camera's, or the raw development's) a light's colour lives
//! only in small shifts of the coloured patches, which the model reads to about Δu′v′ 0.01;
//! the raw values of the chart's grey patches are the camera's reading of the light itself,
//! which a 3×3 calibration takes to XYZ far more closely. The spectrum is moved to that
//! chromaticity by the smallest change in the model's PCA coefficients
//! ([`ColourHead::conform`]), so its shape changes as little as the colour needs.

use crate::colour_head::ColourHead;
use crate::model::Model;
use spdcam_core::colorimetry::xy_to_xyz;
use spdcam_core::quality::uv::xyz_to_uv1976;

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
