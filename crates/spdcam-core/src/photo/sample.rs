//! Sampling the patches of a rectified chart with the one sampler ([`crate::sampler`]: the
//! centred square of each patch, the same share and the same robust statistic as the
//! virtual camera), clipped pixels set aside as glare, and flags for clipped or very dark
//! patches.

use super::geometry::Homography;
use super::load::Photo;
use super::raw::RawReading;
use super::ChartTemplate;
use crate::error::{Error, Result};
use crate::sampler::{robust_mean, SampleBuffers, SAMPLING_FRACTION};
use rayon::prelude::*;
use serde::Serialize;

/// Most pixels read per patch (an even subsample beyond), which keeps large photos fast.
const MAX_PIXELS: usize = 40_000;
/// A patch is clipped when more than this share of its pixels has a clipped channel.
const CLIPPED_SHARE: f64 = 0.25;
/// A patch is dark when its brightest channel's mean is below this (encoded, 0…1).
pub(crate) const DARK_LEVEL: f32 = 8.0 / 255.0;
/// Fewest pixels a sampled square must cover.
const MIN_PIXELS: usize = 4;

/// One sampled patch.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PatchSample {
    /// Patch index in the chart, row-major from 0.
    pub patch: usize,
    /// Centre of the patch in photo pixels.
    pub centre: [f64; 2],
    /// Robust mean encoded sRGB, 0–255 (the feature scale).
    pub rgb: [f32; 3],
    /// Standard deviation of the pixels kept, 0–255.
    pub std: [f32; 3],
    /// Pixels read.
    pub pixels: usize,
    /// Share of the pixels read with a clipped channel.
    pub clipped_share: f32,
    /// More than a quarter of the pixels are clipped: the value is a lower bound.
    pub clipped: bool,
    /// The patch is nearly black in every channel: its colour is mostly noise.
    pub dark: bool,
    /// For a raw photo, the patch's linear camera RGB (share of full scale, black
    /// subtracted) before development: the values `rgb` was made from.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub camera_rgb: Option<[f32; 3]>,
}

/// Samples every patch of `template` placed by `homography` (chart → photo pixels); a raw
/// photo on its mosaic ([`super::raw::sample`]), which also reads the light's chromaticity.
pub fn sample(
    photo: &Photo,
    template: &ChartTemplate,
    homography: &Homography,
) -> Result<(Vec<PatchSample>, Option<RawReading>)> {
    if let Some(raw) = photo.raw() {
        let (patches, reading) = super::raw::sample(raw, &photo.source, template, homography)?;
        return Ok((patches, Some(reading)));
    }
    sample_encoded(photo, template, homography).map(|patches| (patches, None))
}

/// Samples the encoded pixels of a photo.
fn sample_encoded(
    photo: &Photo,
    template: &ChartTemplate,
    homography: &Homography,
) -> Result<Vec<PatchSample>> {
    let inverse = homography
        .inverse()
        .ok_or_else(|| Error::invalid("the chart's homography is singular"))?;
    (0..template.patch_count())
        .into_par_iter()
        .map(|p| sample_patch(photo, template, homography, &inverse, p))
        .collect()
}

fn sample_patch(
    photo: &Photo,
    template: &ChartTemplate,
    homography: &Homography,
    inverse: &Homography,
    p: usize,
) -> Result<PatchSample> {
    let square = template.patch_square(p, SAMPLING_FRACTION);
    let image: Vec<[f64; 2]> = square.iter().map(|&c| homography.apply(c)).collect();
    let centre = homography.apply(template.patch_centre(p));
    let (x_lo, x_hi) = image
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), q| {
            (lo.min(q[0]), hi.max(q[0]))
        });
    let (y_lo, y_hi) = image
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), q| {
            (lo.min(q[1]), hi.max(q[1]))
        });
    if !(x_lo >= 0.0 && y_lo >= 0.0 && x_hi <= photo.width as f64 && y_hi <= photo.height as f64) {
        return Err(Error::invalid(format!(
            "{}: patch {} lies outside the photo (around ({:.0}, {:.0})); is the whole chart in view?",
            photo.source,
            p + 1,
            centre[0],
            centre[1]
        )));
    }
    let (x0, x1) = (
        x_lo.floor() as usize,
        (x_hi.ceil() as usize).min(photo.width),
    );
    let (y0, y1) = (
        y_lo.floor() as usize,
        (y_hi.ceil() as usize).min(photo.height),
    );
    let box_pixels = (x1 - x0) * (y1 - y0);
    let stride = ((box_pixels as f64 / MAX_PIXELS as f64).sqrt().ceil() as usize).max(1);
    let [[sx0, sy0], _, [sx1, sy1], _] = square;
    let clip = photo.clip_level();
    let mut kept: Vec<[f32; 3]> = Vec::new();
    let mut clipped = Vec::new();
    for y in (y0..y1).step_by(stride) {
        for x in (x0..x1).step_by(stride) {
            let q = inverse.apply([x as f64 + 0.5, y as f64 + 0.5]);
            if q[0] < sx0 || q[0] > sx1 || q[1] < sy0 || q[1] > sy1 {
                continue;
            }
            let v = photo.pixel(x, y);
            if v.iter().any(|&c| c >= clip) {
                clipped.push(v);
            } else {
                kept.push(v);
            }
        }
    }
    let read = kept.len() + clipped.len();
    if read < MIN_PIXELS {
        return Err(Error::invalid(format!(
            "{}: patch {} covers only {read} pixels; the chart is too small in this photo",
            photo.source,
            p + 1
        )));
    }
    let clipped_share = clipped.len() as f64 / read as f64;
    let is_clipped = clipped_share > CLIPPED_SHARE;
    // A mostly clipped patch is reported as read; otherwise clipped pixels are glare.
    let values = if is_clipped || kept.len() < MIN_PIXELS {
        kept.extend_from_slice(&clipped);
        kept
    } else {
        kept
    };
    let (mean, std) = robust_mean(&mut SampleBuffers::with_pixels(values));
    Ok(PatchSample {
        patch: p,
        centre,
        rgb: mean.map(|v| (255.0 * v) as f32),
        std: std.map(|v| (255.0 * v) as f32),
        pixels: read,
        clipped_share: clipped_share as f32,
        clipped: is_clipped,
        dark: mean.iter().all(|&v| v < DARK_LEVEL as f64),
        camera_rgb: None,
    })
}
