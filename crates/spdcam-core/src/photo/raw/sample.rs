//! The patches of a chart read on a raw photo's mosaic: each colour-filter tile inside a
//! patch's sampled square is one camera-RGB value (its channels' photosites averaged, no
//! demosaicing), the same robust statistic as for encoded photos ([`crate::sampler`]).
//!
//! Then the chart's own neutral patches give the light: their camera RGB per unit of
//! reflectance is the camera's reading of the light itself, which the file's matrices take
//! to its chromaticity ([`super::RawColour::light_xy`]); and every patch is developed as a raw
//! converter's "as shot" rendering would (white-balanced to that neutral, the file's
//! matrix, sRGB), so that the feature row has the meaning and scale of a JPEG's.

use super::colour::{chart_neutral, RawColourUse};
use super::RawMosaic;
use crate::colorimetry::{srgb_decode, srgb_encode};
use crate::error::{Error, Result};
use crate::photo::{ChartTemplate, Homography, PatchSample};
use crate::sampler::{robust_mean, SampleBuffers, SAMPLING_FRACTION};
use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;
use serde::Serialize;

/// Most cells read per patch (an even subsample beyond), as for encoded photos.
const MAX_CELLS: usize = 40_000;
/// Fewest cells a sampled square must cover.
const MIN_CELLS: usize = 4;
/// A patch is clipped when more than this share of its cells has a clipped photosite.
const CLIPPED_SHARE: f64 = 0.25;
/// A perfect white reflector is developed to this linear level, where a JPEG camera's
/// exposure puts it (the ColorChecker's white, reflectance 0.9, then encodes near 240/255).
const WHITE_LEVEL: f64 = 0.97;

/// What a raw photo's chart says beyond its feature row.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RawReading {
    /// The camera as the file names it.
    pub camera: String,
    /// The light's CIE 1931 xy chromaticity: the chart's neutral patches through the
    /// file's own colour matrices.
    pub light_xy: [f64; 2],
    /// The neutral patches it was read from (row-major index from 0).
    pub neutral_patches: Vec<usize>,
    /// How the file's matrices were used.
    pub colour: RawColourUse,
    /// Every patch's XYZ through the file's matrices at the chart's neutral, a perfect
    /// white at Y = 100 ([`super::RawColour::relative_xyz`]): a raw model's features.
    #[serde(skip)]
    pub patch_xyz: Vec<[f32; 3]>,
    /// The raw model whose spectrum the estimate is, when one read these patches
    /// (`spdcam_infer::Estimator::with_raw_models`); `None`: the chart's model read the
    /// developed patches.
    pub spectrum_model: Option<String>,
    /// The DNG's lens-shading gain maps applied before the patches were read.
    pub gain_maps_applied: usize,
    /// The opcodes of the DNG's `OpcodeList2` not applied, by name.
    pub opcodes_skipped: Vec<String>,
}

impl RawReading {
    /// One line for a person: "raw file (camera …): patches read on the sensor's mosaic,
    /// the light's colour from N grey patches through the file's A and D65 matrices".
    pub fn describe(&self) -> String {
        let mut line = format!(
            "raw file ({}): patches read on the sensor's mosaic, the light's colour from {} \
             grey patches through the file's {} colour matri{}",
            self.camera,
            self.neutral_patches.len(),
            self.colour.matrices.join(" and "),
            if self.colour.matrices.len() == 1 {
                "x"
            } else {
                "ces"
            }
        );
        if self.colour.forward_matrix {
            line.push_str(", developed through its forward matrices");
        }
        if let Some(model) = &self.spectrum_model {
            line.push_str(&format!(", the spectrum from {model}"));
        }
        if self.gain_maps_applied > 0 {
            line.push_str(&format!(
                "; its {} lens-shading gain map{} applied",
                self.gain_maps_applied,
                if self.gain_maps_applied == 1 { "" } else { "s" }
            ));
        }
        if !self.opcodes_skipped.is_empty() {
            line.push_str(&format!(
                "; not applied: {}",
                self.opcodes_skipped.join(", ")
            ));
        }
        line
    }
}

/// One patch's cells: camera RGB (share of full scale) and whether each is clipped.
struct PatchCells {
    cells: Vec<[f32; 3]>,
    clipped: Vec<bool>,
    centre: [f64; 2],
}

/// Samples every patch of `template` placed by `homography` (chart → the preview's upright
/// pixels) on `raw`'s mosaic, reads the light's chromaticity from its neutral patches and
/// develops the patches to encoded sRGB (0–255, the feature scale).
pub fn sample(
    raw: &RawMosaic,
    source: &str,
    template: &ChartTemplate,
    homography: &Homography,
) -> Result<(Vec<PatchSample>, RawReading)> {
    let to_sensor = Homography::from_rows(&raw.preview_to_sensor());
    let chart_to_sensor = Homography(to_sensor.0 * homography.0);
    let inverse = chart_to_sensor
        .inverse()
        .ok_or_else(|| Error::invalid("the chart's homography is singular"))?;
    let sensor_to_preview = to_sensor
        .inverse()
        .ok_or_else(|| Error::invalid("the raw preview's scale is singular"))?;
    let patches: Vec<PatchCells> = (0..template.patch_count())
        .into_par_iter()
        .map(|p| {
            patch_cells(raw, source, template, &chart_to_sensor, &inverse, p).map(|mut c| {
                c.centre = sensor_to_preview.apply(c.centre);
                c
            })
        })
        .collect::<Result<_>>()?;
    let means: Vec<([f32; 3], bool, f32)> = patches
        .iter()
        .map(|p| {
            let clipped = p.clipped.iter().filter(|&&c| c).count();
            let share = clipped as f32 / p.cells.len().max(1) as f32;
            let values = kept(p, share as f64 > CLIPPED_SHARE, |v| v);
            let (mean, _) = robust_mean(&mut SampleBuffers::with_pixels(values));
            (mean.map(|v| v as f32), share as f64 > CLIPPED_SHARE, share)
        })
        .collect();
    let dark_level = srgb_decode(crate::photo::DARK_LEVEL as f64) as f32;
    let usable: Vec<(usize, f64)> = template
        .neutrals
        .iter()
        .copied()
        .filter(|&(p, _)| {
            let (rgb, clipped, _) = means[p];
            !clipped && rgb.iter().all(|&v| v > dark_level)
        })
        .collect();
    if usable.is_empty() {
        return Err(Error::invalid(format!(
            "{source}: every grey patch of the chart is clipped or nearly black in the raw \
             values, so the light's colour cannot be read; expose so that the white patch \
             is below full scale and the dark greys above black"
        )));
    }
    let greys: Vec<([f32; 3], f64)> = usable.iter().map(|&(p, r)| (means[p].0, r)).collect();
    let neutral = chart_neutral(&greys)
        .ok_or_else(|| Error::invalid(format!("{source}: the chart's greys reflect nothing")))?;
    let light_xy = raw.colour.light_xy(neutral)?;
    let camera_means: Vec<[f32; 3]> = means.iter().map(|m| m.0).collect();
    let patch_xyz = raw.colour.relative_xyz(neutral, &camera_means)?;
    let (development, colour) = raw.colour.development(neutral)?;
    let gain = WHITE_LEVEL / neutral[1];
    let develop = develop_with(&development, gain);
    let samples = patches
        .into_iter()
        .zip(&means)
        .enumerate()
        .map(|(p, (cells, &(camera, clipped, share)))| {
            let values = kept(&cells, clipped, &develop);
            let (mean, std) = robust_mean(&mut SampleBuffers::with_pixels(values));
            PatchSample {
                patch: p,
                centre: cells.centre,
                rgb: mean.map(|v| (255.0 * v) as f32),
                std: std.map(|v| (255.0 * v) as f32),
                pixels: cells.cells.len(),
                clipped_share: share,
                clipped,
                dark: camera.iter().all(|&v| v < dark_level),
                camera_rgb: Some(camera),
            }
        })
        .collect();
    Ok((
        samples,
        RawReading {
            camera: raw.camera.clone(),
            light_xy,
            neutral_patches: usable.iter().map(|u| u.0).collect(),
            colour,
            patch_xyz,
            spectrum_model: None,
            gain_maps_applied: raw.gain_maps_applied,
            opcodes_skipped: raw.opcodes_skipped.clone(),
        },
    ))
}

/// Camera RGB → encoded sRGB (0…1) by the development matrix and exposure gain.
fn develop_with(m: &Matrix3<f64>, gain: f64) -> impl Fn([f32; 3]) -> [f32; 3] + '_ {
    move |v| {
        let out = m * Vector3::new(v[0] as f64, v[1] as f64, v[2] as f64) * gain;
        [0, 1, 2].map(|c| srgb_encode(out[c].clamp(0.0, 1.0)) as f32)
    }
}

/// The cells a patch's value is made of, mapped by `f`: the unclipped ones, or all where the
/// patch is mostly clipped (or too few are left), as for encoded photos.
fn kept(p: &PatchCells, mostly_clipped: bool, f: impl Fn([f32; 3]) -> [f32; 3]) -> Vec<[f32; 3]> {
    let unclipped = p.clipped.iter().filter(|&&c| !c).count();
    let all = mostly_clipped || unclipped < MIN_CELLS;
    p.cells
        .iter()
        .zip(&p.clipped)
        .filter(|&(_, &c)| all || !c)
        .map(|(&v, _)| f(v))
        .collect()
}

/// The cells inside patch `p`'s sampled square, read on the mosaic.
fn patch_cells(
    raw: &RawMosaic,
    source: &str,
    template: &ChartTemplate,
    chart_to_sensor: &Homography,
    inverse: &Homography,
    p: usize,
) -> Result<PatchCells> {
    let square = template.patch_square(p, SAMPLING_FRACTION);
    let corners: Vec<[f64; 2]> = square.iter().map(|&c| chart_to_sensor.apply(c)).collect();
    let centre = chart_to_sensor.apply(template.patch_centre(p));
    let lo = |i: usize| corners.iter().map(|q| q[i]).fold(f64::INFINITY, f64::min);
    let hi = |i: usize| {
        corners
            .iter()
            .map(|q| q[i])
            .fold(f64::NEG_INFINITY, f64::max)
    };
    if !(lo(0) >= 0.0 && lo(1) >= 0.0 && hi(0) <= raw.width as f64 && hi(1) <= raw.height as f64) {
        return Err(Error::invalid(format!(
            "{source}: patch {} lies outside the photo; is the whole chart in view?",
            p + 1
        )));
    }
    let (cw, ch) = raw.cell_size();
    let (cells_x, cells_y) = raw.cells();
    let (x0, x1) = (
        (lo(0) / cw as f64) as usize,
        ((hi(0) / cw as f64).ceil() as usize).min(cells_x),
    );
    let (y0, y1) = (
        (lo(1) / ch as f64) as usize,
        ((hi(1) / ch as f64).ceil() as usize).min(cells_y),
    );
    let boxed = (x1.saturating_sub(x0)) * (y1.saturating_sub(y0));
    let stride = ((boxed as f64 / MAX_CELLS as f64).sqrt().ceil() as usize).max(1);
    let [[sx0, sy0], _, [sx1, sy1], _] = square;
    let mut cells = Vec::new();
    let mut clipped = Vec::new();
    let reader = raw.cell_reader();
    for cy in (y0..y1).step_by(stride) {
        for cx in (x0..x1).step_by(stride) {
            let q = inverse.apply([(cx as f64 + 0.5) * cw as f64, (cy as f64 + 0.5) * ch as f64]);
            if q[0] < sx0 || q[0] > sx1 || q[1] < sy0 || q[1] > sy1 {
                continue;
            }
            let (v, c) = reader.cell(cx, cy);
            cells.push(v);
            clipped.push(c);
        }
    }
    if cells.len() < MIN_CELLS {
        return Err(Error::invalid(format!(
            "{source}: patch {} covers only {} colour-filter cells; the chart is too small in \
             this photo",
            p + 1,
            cells.len()
        )));
    }
    Ok(PatchCells {
        cells,
        clipped,
        centre,
    })
}
