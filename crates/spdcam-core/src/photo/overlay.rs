//! The debug image: the photo (at full resolution up to [`DEBUG_MAX_PIXELS`], else reduced
//! by [`debug_factor`]; for a report reduced to at most [`OVERLAY_SIZE`] px), the chart's
//! outline with its first corner marked, every sampled region with its patch number, each
//! chart's place number where a photo shows several, and, when no chart was found, the
//! patch candidates the search saw.

use super::detect::SearchTrace;
use super::geometry::quad_centre;
use super::load::Photo;
use super::pyramid::Level;
use super::sample::PatchSample;
use super::{ChartTemplate, Detection};
use crate::error::{Error, Result};
use crate::fsio;
use crate::sampler::SAMPLING_FRACTION;
use image::ImageEncoder;
use std::path::Path;

/// Longest side of the overlay embedded in a report.
pub const OVERLAY_SIZE: usize = 1600;
/// Most pixels of a debug image written at the photo's full resolution (150 MB of RGB);
/// larger photos are reduced by [`debug_factor`].
pub const DEBUG_MAX_PIXELS: usize = 50_000_000;

/// The integer factor by which the debug image of a `width × height` photo is reduced: 1
/// (full resolution) up to [`DEBUG_MAX_PIXELS`].
pub fn debug_factor(width: usize, height: usize) -> usize {
    let pixels = width as f64 * height as f64;
    (pixels / DEBUG_MAX_PIXELS as f64).sqrt().ceil().max(1.0) as usize
}

const GREEN: [u8; 3] = [0, 255, 64];
const RED: [u8; 3] = [255, 32, 32];
const WHITE: [u8; 3] = [255, 255, 255];
const BLACK: [u8; 3] = [0, 0, 0];
const YELLOW: [u8; 3] = [255, 220, 0];
const CYAN: [u8; 3] = [0, 230, 255];

/// A chart found and sampled: its template, its placement and its sampled patches.
pub type Found<'a> = (&'a ChartTemplate, &'a Detection, &'a [PatchSample]);

/// 3×5 bitmaps of the digits 0–9, one row per 3 bits (MSB left).
const DIGITS: [[u8; 5]; 10] = [
    [7, 5, 5, 5, 7],
    [2, 6, 2, 2, 7],
    [7, 1, 7, 4, 7],
    [7, 1, 7, 1, 7],
    [5, 5, 7, 1, 1],
    [7, 4, 7, 1, 7],
    [7, 4, 7, 5, 7],
    [7, 1, 2, 2, 2],
    [7, 5, 7, 5, 7],
    [7, 5, 7, 1, 7],
];

struct Canvas {
    width: usize,
    height: usize,
    rgb: Vec<u8>,
}

impl Canvas {
    fn dot(&mut self, x: i64, y: i64, r: i64, colour: [u8; 3]) {
        for yy in y - r..=y + r {
            for xx in x - r..=x + r {
                if xx >= 0 && yy >= 0 && (xx as usize) < self.width && (yy as usize) < self.height {
                    let i = 3 * (yy as usize * self.width + xx as usize);
                    self.rgb[i..i + 3].copy_from_slice(&colour);
                }
            }
        }
    }

    fn line(&mut self, a: [f64; 2], b: [f64; 2], r: i64, colour: [u8; 3]) {
        if !(a.iter().chain(&b).all(|v| v.is_finite())) {
            return;
        }
        let steps = ((b[0] - a[0]).abs().max((b[1] - a[1]).abs()).ceil() as usize).clamp(1, 20_000);
        for s in 0..=steps {
            let t = s as f64 / steps as f64;
            let x = a[0] + t * (b[0] - a[0]);
            let y = a[1] + t * (b[1] - a[1]);
            self.dot(x.floor() as i64, y.floor() as i64, r, colour);
        }
    }

    fn polygon(&mut self, points: &[[f64; 2]], r: i64, colour: [u8; 3]) {
        for k in 0..points.len() {
            self.line(points[k], points[(k + 1) % points.len()], r, colour);
        }
    }

    /// Writes `n` centred on `at` in digits of `scale` px per bitmap cell, on a black box.
    fn number(&mut self, n: usize, at: [f64; 2], scale: i64, colour: [u8; 3]) {
        let text: Vec<usize> = n.to_string().bytes().map(|b| (b - b'0') as usize).collect();
        let w = text.len() as i64 * 4 * scale - scale;
        let h = 5 * scale;
        let (x0, y0) = (at[0] as i64 - w / 2, at[1] as i64 - h / 2);
        for yy in y0 - 1..y0 + h + 1 {
            for xx in x0 - 1..x0 + w + 1 {
                self.dot(xx, yy, 0, BLACK);
            }
        }
        for (k, &d) in text.iter().enumerate() {
            for (row, bits) in DIGITS[d].iter().enumerate() {
                for col in 0..3 {
                    if bits & (4 >> col) != 0 {
                        for sy in 0..scale {
                            for sx in 0..scale {
                                self.dot(
                                    x0 + k as i64 * 4 * scale + col * scale + sx,
                                    y0 + row as i64 * scale + sy,
                                    0,
                                    colour,
                                );
                            }
                        }
                    }
                }
            }
        }
    }
}

/// Draws the debug image reduced to about [`OVERLAY_SIZE`] px (for a report). For each
/// chart found: its outline (green, first corner marked yellow), each sampled square
/// (white; red when clipped) with its 1-based patch number and, where there are several,
/// its place number (1, 2, … as the output numbers them; large, cyan, at its centre).
/// Without one: the candidates in `trace` (red squares) and the best rejected outline.
pub fn debug_overlay(
    photo: &Photo,
    found: &[Found<'_>],
    trace: Option<&SearchTrace>,
) -> image::RgbImage {
    let factor = Level::factor_for(photo.width, photo.height, OVERLAY_SIZE);
    draw_overlay(photo, found, trace, factor)
}

/// [`debug_overlay`] at the photo's full resolution (reduced by [`debug_factor`] beyond
/// [`DEBUG_MAX_PIXELS`]): the `--debug` image, in which a small chart's patches can be
/// told apart.
pub fn debug_overlay_full(
    photo: &Photo,
    found: &[Found<'_>],
    trace: Option<&SearchTrace>,
) -> image::RgbImage {
    draw_overlay(photo, found, trace, debug_factor(photo.width, photo.height))
}

fn draw_overlay(
    photo: &Photo,
    found: &[Found<'_>],
    trace: Option<&SearchTrace>,
    factor: usize,
) -> image::RgbImage {
    let level = Level::new(photo, factor);
    let s = 1.0 / factor as f64;
    let mut canvas = Canvas {
        width: level.width,
        height: level.height,
        rgb: (0..level.width * level.height)
            .flat_map(|i| {
                [0, 1, 2].map(|c| (level.planes[c][i].clamp(0.0, 1.0) * 255.0).round() as u8)
            })
            .collect(),
    };
    let down = |p: [f64; 2]| [p[0] * s, p[1] * s];
    let thick = (level.width.max(level.height) / 600) as i64;
    if let Some(trace) = trace {
        for &(c, side) in &trace.blobs {
            let h = 0.5 * side * s;
            let c = down(c);
            canvas.polygon(
                &[
                    [c[0] - h, c[1] - h],
                    [c[0] + h, c[1] - h],
                    [c[0] + h, c[1] + h],
                    [c[0] - h, c[1] + h],
                ],
                0,
                RED,
            );
        }
        if let Some((corners, _)) = &trace.best {
            canvas.polygon(&corners.map(down), thick, YELLOW);
        }
    }
    for (k, &(template, detection, samples)) in found.iter().enumerate() {
        let h = detection.map();
        let pitch = {
            let a = down(h.apply([0.0, 0.0]));
            let b = down(h.apply([1.0, 0.0]));
            (a[0] - b[0]).hypot(a[1] - b[1])
        };
        let digit = ((pitch / 16.0) as i64).clamp(1, 6);
        canvas.polygon(&detection.corners.map(down), thick + 1, GREEN);
        let c0 = down(detection.corners[0]);
        canvas.dot(c0[0] as i64, c0[1] as i64, 3 * (thick + 1), YELLOW);
        for sample in samples {
            let square = template
                .patch_square(sample.patch, SAMPLING_FRACTION)
                .map(|p| down(h.apply(p)));
            let colour = if sample.clipped { RED } else { WHITE };
            canvas.polygon(&square, 0, colour);
            canvas.number(sample.patch + 1, down(sample.centre), digit, colour);
        }
        if found.len() > 1 {
            let centre = down(quad_centre(&detection.corners));
            canvas.number(k + 1, centre, (pitch / 5.0).max(3.0) as i64, CYAN);
        }
    }
    image::RgbImage::from_raw(canvas.width as u32, canvas.height as u32, canvas.rgb)
        .unwrap_or_default()
}

/// The debug image of an analysed photo (the charts `found` with their sampled patches, as
/// [`debug_overlay`] draws them, numbered by place when there are several), reduced to at
/// most `max_width` px wide and encoded as JPEG: small enough to embed in a report.
pub fn analysis_overlay_jpeg(
    photo: &Photo,
    found: &[Found<'_>],
    max_width: u32,
) -> Result<Vec<u8>> {
    let mut image = debug_overlay(photo, found, None);
    if image.width() > max_width && max_width > 0 {
        let height = (u64::from(image.height()) * u64::from(max_width) / u64::from(image.width()))
            .max(1) as u32;
        image = image::imageops::resize(
            &image,
            max_width,
            height,
            image::imageops::FilterType::Triangle,
        );
    }
    let mut bytes = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut bytes, 85)
        .write_image(
            image.as_raw(),
            image.width(),
            image.height(),
            image::ExtendedColorType::Rgb8,
        )
        .map_err(|e| Error::Image {
            context: photo.source.clone(),
            message: e.to_string(),
        })?;
    Ok(bytes)
}

/// Encodes the debug image as PNG and writes it to `path` atomically.
pub fn write_overlay(path: &Path, image: &image::RgbImage) -> Result<()> {
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(
            image.as_raw(),
            image.width(),
            image.height(),
            image::ExtendedColorType::Rgb8,
        )
        .map_err(|e| Error::Image {
            context: path.display().to_string(),
            message: e.to_string(),
        })?;
    fsio::write_atomic(path, &bytes)
}
