//! Synthetic photos: a rendered chart placed in a scene the way a person photographs it —
//! warped by a random homography onto a cluttered, textured background lit by the same
//! light, then blurred, vignetted, made noisy and JPEG-compressed. Every random choice comes
//! from the seed. Used to make example photos and to test detection against known truth.

use super::geometry::Homography;
use super::ChartTemplate;
use crate::chart::Layout;
use crate::colorimetry::{srgb_decode, srgb_encode};
use crate::error::{Error, Result};
use crate::limits;
use crate::raster::RgbImage;
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use std::io::Cursor;

/// Pixels per patch pitch a chart is rendered at before it is placed in a scene.
pub const SCENE_PITCH_PX: usize = 50;

/// How a scene is photographed; each range is drawn uniformly per scene.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneOptions {
    /// Photo width in pixels.
    pub width: usize,
    /// Photo height in pixels.
    pub height: usize,
    /// Width of the patch grid as a share of the photo's width.
    pub width_share: (f64, f64),
    /// Random displacement of each chart corner, as a share of the chart's smaller side
    /// (perspective).
    pub perspective: f64,
    /// Gaussian blur σ in pixels.
    pub blur_sigma: (f64, f64),
    /// Light fall-off at the photo's corners (0 = none).
    pub vignetting: (f64, f64),
    /// Noise σ in 8-bit levels.
    pub noise_sigma: (f64, f64),
    /// JPEG quality, 1–100.
    pub jpeg_quality: (u8, u8),
}

impl Default for SceneOptions {
    fn default() -> SceneOptions {
        SceneOptions {
            width: 1600,
            height: 1200,
            width_share: (0.3, 0.6),
            perspective: 0.12,
            blur_sigma: (0.0, 1.2),
            vignetting: (0.0, 0.25),
            noise_sigma: (0.0, 2.0),
            jpeg_quality: (80, 95),
        }
    }
}

/// The layout a chart is rendered with for a scene: [`SCENE_PITCH_PX`] per patch pitch, the
/// gaps of the physical chart (the template's patch fraction) and a border of a third of a
/// pitch.
pub fn scene_layout(template: &ChartTemplate) -> Layout {
    let patch = (SCENE_PITCH_PX as f64 * template.patch_fraction).round() as usize;
    Layout::grid(
        template.rows,
        template.cols,
        patch,
        SCENE_PITCH_PX - patch,
        SCENE_PITCH_PX / 3,
    )
}

/// A synthetic photo and what is true about it.
#[derive(Debug, Clone)]
pub struct ScenePhoto {
    /// The JPEG file's bytes.
    pub jpeg: Vec<u8>,
    /// Outer corners of the patch grid in the photo: the chart's TL, TR, BR, BL.
    pub corners: [[f64; 2]; 4],
    /// Patch side in photo pixels (the mean over the chart).
    pub patch_px: f64,
    /// The vignetting gain (≤ 1, linear light) at each feature patch's centre.
    pub vignetting_at_features: Vec<f64>,
}

/// Checks that a scene of `width × height` px is large enough to show a chart and within
/// [`limits::RENDER_PIXELS`].
pub fn check_scene_size(width: usize, height: usize) -> Result<()> {
    if width < 64 || height < 64 {
        return Err(Error::invalid(format!(
            "a scene of {width}×{height} px is too small; give at least 64×64"
        )));
    }
    limits::RENDER_PIXELS.check(
        limits::product(&[width as u64, height as u64]),
        &format!("a scene of {width}×{height} px"),
    )
}

/// Places `chart` (encoded sRGB on 0…1, rendered with `layout`) into scene `seed`.
pub fn photograph(
    chart: &RgbImage,
    layout: &Layout,
    template: &ChartTemplate,
    feature_patches: &[usize],
    seed: u64,
    options: &SceneOptions,
) -> Result<ScenePhoto> {
    let (w, h) = (options.width, options.height);
    check_scene_size(w, h)?;
    if !(options.width_share.0 > 0.0
        && options.width_share.0 <= options.width_share.1
        && options.width_share.1 < 1.0)
    {
        return Err(Error::invalid(format!(
            "the chart's share of the scene width {:?} must lie in (0, 1)",
            options.width_share
        )));
    }
    let mut rng = SmallRng::seed_from_u64(seed);
    let (cw, ch) = (chart.width, chart.height);
    let grid_w = (layout.cols * layout.patch_px + (layout.cols - 1) * layout.gap_px) as f64;
    let grid_h = (layout.rows * layout.patch_px + (layout.rows - 1) * layout.gap_px) as f64;
    let placed = placement(&mut rng, (cw as f64, ch as f64), grid_w, options)?;
    let canvas = [
        [0.0, 0.0],
        [cw as f64, 0.0],
        [cw as f64, ch as f64],
        [0.0, ch as f64],
    ];
    let homography = Homography::fit(&canvas, &placed)?;
    let inverse = homography
        .inverse()
        .ok_or_else(|| Error::invalid("the chart's placement is degenerate"))?;
    let (gx, gy) = (layout.margin_x as f64, layout.margin_y as f64);
    let corners = [
        [gx, gy],
        [gx + grid_w, gy],
        [gx + grid_w, gy + grid_h],
        [gx, gy + grid_h],
    ]
    .map(|p| homography.apply(p));
    let area = 0.5
        * (0..4)
            .map(|k| {
                corners[k][0] * corners[(k + 1) % 4][1] - corners[(k + 1) % 4][0] * corners[k][1]
            })
            .sum::<f64>()
            .abs();
    let (tw, th) = template.size();
    let patch_px = template.patch_fraction * (area / (tw * th)).sqrt();

    // The light's colour on the chart's whitest surface tints the background.
    let white = [0, 1, 2].map(|c| {
        let best = chart.planes[c].iter().cloned().fold(0.0f32, f32::max);
        srgb_decode(f64::from(best)) as f32
    });
    let brightest = white.iter().cloned().fold(1e-6, f32::max);
    let mut planes = background(&mut rng, w, h, white.map(|v| v / brightest));
    let chart_linear: [Vec<f32>; 3] = std::array::from_fn(|c| {
        chart.planes[c]
            .iter()
            .map(|&v| srgb_decode(f64::from(v)) as f32)
            .collect()
    });
    for y in 0..h {
        for x in 0..w {
            let q = inverse.apply([x as f64 + 0.5, y as f64 + 0.5]);
            let (u, v) = (q[0] - 0.5, q[1] - 0.5);
            if !(u >= 0.0 && v >= 0.0 && u <= (cw - 1) as f64 && v <= (ch - 1) as f64) {
                continue;
            }
            let (x0, y0) = (u as usize, v as usize);
            let (x1, y1) = ((x0 + 1).min(cw - 1), (y0 + 1).min(ch - 1));
            let (fx, fy) = ((u - x0 as f64) as f32, (v - y0 as f64) as f32);
            for (plane, p) in planes.iter_mut().zip(&chart_linear) {
                let top = p[y0 * cw + x0] * (1.0 - fx) + p[y0 * cw + x1] * fx;
                let bottom = p[y1 * cw + x0] * (1.0 - fx) + p[y1 * cw + x1] * fx;
                plane[y * w + x] = top * (1.0 - fy) + bottom * fy;
            }
        }
    }
    let sigma = draw(&mut rng, options.blur_sigma);
    let mut scratch = Vec::new();
    for p in planes.iter_mut() {
        gaussian_blur(p, w, h, sigma, &mut scratch);
    }
    let strength = draw(&mut rng, options.vignetting);
    let (mx, my) = (w as f64 / 2.0, h as f64 / 2.0);
    let vignette = |x: f64, y: f64| {
        1.0 - strength * ((x - mx).powi(2) + (y - my).powi(2)) / (mx * mx + my * my)
    };
    let noise = Normal::new(0.0, draw(&mut rng, options.noise_sigma).max(1e-9))
        .map_err(|e| Error::invalid(format!("noise: {e}")))?;
    let mut rgb8 = vec![0u8; w * h * 3];
    for y in 0..h {
        for x in 0..w {
            let g = vignette(x as f64 + 0.5, y as f64 + 0.5);
            for (c, plane) in planes.iter().enumerate() {
                let linear = f64::from(plane[y * w + x]) * g;
                let encoded = 255.0 * srgb_encode(linear.clamp(0.0, 1.0)) + noise.sample(&mut rng);
                rgb8[3 * (y * w + x) + c] = encoded.round().clamp(0.0, 255.0) as u8;
            }
        }
    }
    let (q0, q1) = options.jpeg_quality;
    let quality = rng.random_range(q0.clamp(1, 100)..=q1.clamp(q0.clamp(1, 100), 100));
    let mut jpeg = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(Cursor::new(&mut jpeg), quality)
        .encode(&rgb8, w as u32, h as u32, image::ExtendedColorType::Rgb8)
        .map_err(|e| Error::Image {
            context: "synthetic photo".into(),
            message: e.to_string(),
        })?;
    let vignetting_at_features = feature_patches
        .iter()
        .map(|&p| {
            let (px, py) = layout.patch_origin(p);
            let half = layout.patch_px as f64 / 2.0;
            let [x, y] = homography.apply([px as f64 + half, py as f64 + half]);
            vignette(x, y)
        })
        .collect();
    Ok(ScenePhoto {
        jpeg,
        corners,
        patch_px,
        vignetting_at_features,
    })
}

fn draw(rng: &mut SmallRng, (lo, hi): (f64, f64)) -> f64 {
    if hi > lo {
        rng.random_range(lo..hi)
    } else {
        lo
    }
}

/// A random placement of the chart canvas inside the photo: scaled so the patch grid spans
/// the drawn share of the width, rotated at random, each corner displaced for perspective.
fn placement(
    rng: &mut SmallRng,
    canvas: (f64, f64),
    grid_w: f64,
    options: &SceneOptions,
) -> Result<[[f64; 2]; 4]> {
    let (w, h) = (options.width as f64, options.height as f64);
    for _ in 0..10_000 {
        let share = draw(rng, options.width_share);
        let scale = share * w / grid_w;
        let (s, c) = rng.random_range(0.0..std::f64::consts::TAU).sin_cos();
        let (cw, ch) = (canvas.0 * scale, canvas.1 * scale);
        let (cx, cy) = (rng.random_range(0.0..w), rng.random_range(0.0..h));
        let jitter = (options.perspective * cw.min(ch)).max(1e-9);
        let corners = [[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]].map(|[u, v]| {
            let (x, y) = (u * cw, v * ch);
            [
                cx + c * x - s * y + rng.random_range(-jitter..jitter),
                cy + s * x + c * y + rng.random_range(-jitter..jitter),
            ]
        });
        let margin = 4.0;
        if corners
            .iter()
            .all(|p| p[0] > margin && p[1] > margin && p[0] < w - margin && p[1] < h - margin)
        {
            return Ok(corners);
        }
    }
    Err(Error::invalid(format!(
        "a chart spanning {:?} of the width does not fit a {}×{} scene",
        options.width_share, options.width, options.height
    )))
}

/// Smooth value noise on 0…1 with cells of `cell` pixels.
fn value_noise(rng: &mut SmallRng, w: usize, h: usize, cell: usize) -> Vec<f32> {
    let (gw, gh) = (w / cell + 2, h / cell + 2);
    let grid: Vec<f32> = (0..gw * gh).map(|_| rng.random::<f32>()).collect();
    let smooth = |t: f32| t * t * (3.0 - 2.0 * t);
    let mut out = vec![0.0; w * h];
    for y in 0..h {
        let gy = y as f32 / cell as f32;
        let (y0, fy) = (gy as usize, smooth(gy.fract()));
        for x in 0..w {
            let gx = x as f32 / cell as f32;
            let (x0, fx) = (gx as usize, smooth(gx.fract()));
            let g = |i: usize, j: usize| grid[j * gw + i];
            let top = g(x0, y0) * (1.0 - fx) + g(x0 + 1, y0) * fx;
            let bottom = g(x0, y0 + 1) * (1.0 - fx) + g(x0 + 1, y0 + 1) * fx;
            out[y * w + x] = top * (1.0 - fy) + bottom * fy;
        }
    }
    out
}

/// Linear-light background: two octaves of value noise in colour, with clutter (random
/// rectangles, some of them square tiles, and discs), all tinted by `tint`.
fn background(rng: &mut SmallRng, w: usize, h: usize, tint: [f32; 3]) -> [Vec<f32>; 3] {
    let mut planes: [Vec<f32>; 3] = std::array::from_fn(|_| {
        let (coarse, fine) = (rng.random_range(40..200), rng.random_range(5..20));
        let a = value_noise(rng, w, h, coarse);
        let b = value_noise(rng, w, h, fine);
        a.iter()
            .zip(&b)
            .map(|(x, y)| 0.05 + 0.3 * x + 0.1 * y)
            .collect()
    });
    for _ in 0..rng.random_range(5..40) {
        let colour: [f32; 3] = std::array::from_fn(|_| rng.random_range(0.01..0.7f32));
        let (cx, cy) = (rng.random_range(0..w) as f32, rng.random_range(0..h) as f32);
        let size = rng.random_range(8.0..(w as f32 / 6.0).max(9.0));
        let aspect = if rng.random_bool(0.3) {
            1.0
        } else {
            rng.random_range(0.3..3.0f32)
        };
        let disc = rng.random_bool(0.3);
        let (s, c) = rng.random_range(0.0..std::f32::consts::PI).sin_cos();
        let (hw, hh) = (size / 2.0, size * aspect / 2.0);
        let r = hw.max(hh) as usize + 2;
        for y in (cy as usize).saturating_sub(r)..((cy as usize) + r).min(h) {
            for x in (cx as usize).saturating_sub(r)..((cx as usize) + r).min(w) {
                let (dx, dy) = (x as f32 - cx, y as f32 - cy);
                let (u, v) = (c * dx + s * dy, -s * dx + c * dy);
                let inside = if disc {
                    (u / hw).powi(2) + (v / hh).powi(2) <= 1.0
                } else {
                    u.abs() <= hw && v.abs() <= hh
                };
                if inside {
                    for (plane, value) in planes.iter_mut().zip(colour) {
                        plane[y * w + x] = value;
                    }
                }
            }
        }
    }
    for (plane, t) in planes.iter_mut().zip(tint) {
        plane.iter_mut().for_each(|v| *v *= t);
    }
    planes
}

/// Separable Gaussian blur with clamped edges; no-op below σ = 0.2.
fn gaussian_blur(plane: &mut [f32], w: usize, h: usize, sigma: f64, scratch: &mut Vec<f32>) {
    if sigma < 0.2 {
        return;
    }
    let r = (3.0 * sigma).ceil() as isize;
    let kernel: Vec<f32> = (-r..=r)
        .map(|i| (-0.5 * (i as f64 / sigma).powi(2)).exp() as f32)
        .collect();
    let sum: f32 = kernel.iter().sum();
    let kernel: Vec<f32> = kernel.iter().map(|k| k / sum).collect();
    scratch.resize(w * h, 0.0);
    let at = |i: isize, n: usize| i.clamp(0, n as isize - 1) as usize;
    for y in 0..h {
        for x in 0..w {
            scratch[y * w + x] = kernel
                .iter()
                .enumerate()
                .map(|(k, kv)| kv * plane[y * w + at(x as isize + k as isize - r, w)])
                .sum();
        }
    }
    for y in 0..h {
        for x in 0..w {
            plane[y * w + x] = kernel
                .iter()
                .enumerate()
                .map(|(k, kv)| kv * scratch[at(y as isize + k as isize - r, h) * w + x])
                .sum();
        }
    }
}
