//! Synthetic photos of a chart for the photo tests: the chart rendered by the virtual camera
//! under a random light, warped by a random homography onto a cluttered, textured
//! background lit by the same light, then blurred, vignetted, made noisy and JPEG-compressed.
//! Every random choice comes from the seed.

#![allow(dead_code)]

use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};
use spdcam_core::builtin::{self, DataDir};
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::white_balance::WhiteBalance;
use spdcam_core::camera::{Camera, CameraConfig};
use spdcam_core::chart::{Chart, Layout};
use spdcam_core::colorimetry::{self, srgb_decode, srgb_encode};
use spdcam_core::light;
use spdcam_core::photo::{decode_photo, ChartTemplate, Homography, Photo};
use spdcam_core::spectral::Grid;
use std::io::Cursor;

const GRID: Grid = Grid::SIMULATION;

/// Pixels per patch pitch in the rendered chart.
const PITCH_PX: usize = 50;

/// One chart the generator can photograph: two cameras (automatic white balance, and none
/// so that coloured light stays coloured) and the chart's template.
pub struct ChartSetup {
    pub template: ChartTemplate,
    cameras: [Camera; 2],
    /// Smallest and largest width of the patch grid as a share of the photo's width.
    pub width_share: (f64, f64),
}

impl ChartSetup {
    /// `chart` laid out with gaps of the physical chart's patch fraction.
    pub fn new(chart: Chart, width_share: (f64, f64)) -> ChartSetup {
        let template = ChartTemplate::from_chart(&chart).unwrap();
        let patch = (PITCH_PX as f64 * template.patch_fraction).round() as usize;
        let layout = Layout::grid(
            chart.layout.rows,
            chart.layout.cols,
            patch,
            PITCH_PX - patch,
            PITCH_PX / 3,
        );
        let chart = chart.with_layout(layout).unwrap();
        let set = builtin::CAMERAS[0].load().unwrap();
        let sens = Sensitivities::new("nikon_d5100_npl", &set, &GRID).unwrap();
        let auto = Camera::new(&sens, chart.clone(), CameraConfig::default(), &GRID).unwrap();
        let fixed = Camera::new(
            &sens,
            chart,
            CameraConfig {
                white_balance: WhiteBalance::None,
                ..CameraConfig::default()
            },
            &GRID,
        )
        .unwrap();
        // The template measures patches in pitch units; the layout must agree.
        assert!((template.patch_fraction - patch as f64 / PITCH_PX as f64).abs() < 1e-9);
        ChartSetup {
            template,
            cameras: [auto, fixed],
            width_share,
        }
    }
}

/// The ColorChecker 24 (built in).
pub fn colorchecker24() -> ChartSetup {
    ChartSetup::new(Chart::colorchecker24(&GRID).unwrap(), (0.1, 0.6))
}

/// The ColorChecker Digital SG (from the data directory).
pub fn colorchecker_sg(data: &DataDir) -> ChartSetup {
    let chart = Chart::resolve("colorchecker_sg140", None, data, &GRID).unwrap();
    ChartSetup::new(chart, (0.2, 0.7))
}

/// A synthetic photo and what is true about it.
pub struct Scene {
    /// The decoded JPEG.
    pub photo: Photo,
    /// The JPEG file's bytes.
    pub jpeg: Vec<u8>,
    /// Outer corners of the patch grid in the photo: the chart's TL, TR, BR, BL.
    pub corners: [[f64; 2]; 4],
    /// Patch side in photo pixels (the mean over the chart).
    pub patch_px: f64,
    /// The unwarped render's features, darkened by the vignetting at each patch's centre.
    pub features: Vec<f32>,
    /// What the light was.
    pub light: String,
}

/// Settings of the generator.
#[derive(Debug, Clone, Copy)]
pub struct SceneSize {
    pub width: usize,
    pub height: usize,
}

/// A random light: a colour temperature, or one to three narrow bands (strongly coloured).
fn random_light(rng: &mut SmallRng) -> (String, Vec<f64>) {
    if rng.random_bool(0.5) {
        let cct = rng.random_range(2500.0..10000.0f64).round();
        let spec = format!("cct:{cct}");
        let spd = light::resolve_spd(&spec, &DataDir::new(None), &GRID)
            .unwrap()
            .values;
        (spec, spd)
    } else {
        let bands = rng.random_range(1..=3);
        let mut spd = vec![0.02; GRID.count];
        let mut name = String::from("bands");
        for _ in 0..bands {
            let centre = rng.random_range(430.0..650.0f64);
            let width = rng.random_range(12.0..40.0f64);
            let power = rng.random_range(0.3..1.0f64);
            name += &format!(":{centre:.0}/{width:.0}");
            for (i, v) in spd.iter_mut().enumerate() {
                let l = GRID.wavelength(i);
                *v += power * (-0.5 * ((l - centre) / width).powi(2)).exp();
            }
        }
        (name, spd)
    }
}

fn smoothstep_noise(rng: &mut SmallRng, w: usize, h: usize, cell: usize) -> Vec<f32> {
    let (gw, gh) = (w / cell + 2, h / cell + 2);
    let grid: Vec<f32> = (0..gw * gh).map(|_| rng.random::<f32>()).collect();
    let mut out = vec![0.0; w * h];
    for y in 0..h {
        let gy = y as f32 / cell as f32;
        let (y0, fy) = (gy as usize, gy.fract());
        let fy = fy * fy * (3.0 - 2.0 * fy);
        for x in 0..w {
            let gx = x as f32 / cell as f32;
            let (x0, fx) = (gx as usize, gx.fract());
            let fx = fx * fx * (3.0 - 2.0 * fx);
            let g = |i: usize, j: usize| grid[j * gw + i];
            let top = g(x0, y0) * (1.0 - fx) + g(x0 + 1, y0) * fx;
            let bottom = g(x0, y0 + 1) * (1.0 - fx) + g(x0 + 1, y0 + 1) * fx;
            out[y * w + x] = top * (1.0 - fy) + bottom * fy;
        }
    }
    out
}

/// Linear-light background: two octaves of value noise in colour, with clutter (random
/// rectangles, some of them square tiles, and discs) tinted by `tint`.
fn background(rng: &mut SmallRng, w: usize, h: usize, tint: [f32; 3]) -> [Vec<f32>; 3] {
    let mut planes: [Vec<f32>; 3] = std::array::from_fn(|_| {
        let (coarse, fine) = (rng.random_range(40..200), rng.random_range(5..20));
        let a = smoothstep_noise(rng, w, h, coarse);
        let b = smoothstep_noise(rng, w, h, fine);
        a.iter()
            .zip(&b)
            .map(|(x, y)| 0.05 + 0.3 * x + 0.1 * y)
            .collect()
    });
    for _ in 0..rng.random_range(5..40) {
        let colour: [f32; 3] = std::array::from_fn(|_| rng.random_range(0.01..0.7f32));
        let cx = rng.random_range(0..w) as f32;
        let cy = rng.random_range(0..h) as f32;
        let size = rng.random_range(8.0..(w as f32 / 6.0));
        let aspect = if rng.random_bool(0.3) {
            1.0
        } else {
            rng.random_range(0.3..3.0f32)
        };
        let disc = rng.random_bool(0.3);
        let angle = rng.random_range(0.0..std::f32::consts::PI);
        let (s, c) = angle.sin_cos();
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
                    for k in 0..3 {
                        planes[k][y * w + x] = colour[k];
                    }
                }
            }
        }
    }
    for (k, p) in planes.iter_mut().enumerate() {
        p.iter_mut().for_each(|v| *v *= tint[k]);
    }
    planes
}

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
    for y in 0..h {
        for x in 0..w {
            let mut s = 0.0;
            for (k, kv) in kernel.iter().enumerate() {
                let xx = (x as isize + k as isize - r).clamp(0, w as isize - 1) as usize;
                s += kv * plane[y * w + xx];
            }
            scratch[y * w + x] = s;
        }
    }
    for y in 0..h {
        for x in 0..w {
            let mut s = 0.0;
            for (k, kv) in kernel.iter().enumerate() {
                let yy = (y as isize + k as isize - r).clamp(0, h as isize - 1) as usize;
                s += kv * scratch[yy * w + x];
            }
            plane[y * w + x] = s;
        }
    }
}

/// A random chart placement: the image of the chart canvas's corners, inside the photo.
fn random_placement(
    rng: &mut SmallRng,
    setup: &ChartSetup,
    canvas: (f64, f64),
    grid_px: f64,
    size: SceneSize,
) -> [[f64; 2]; 4] {
    let (w, h) = (size.width as f64, size.height as f64);
    loop {
        let share = rng.random_range(setup.width_share.0..setup.width_share.1);
        let scale = share * w / grid_px;
        let angle = rng.random_range(0.0..std::f64::consts::TAU);
        let (s, c) = angle.sin_cos();
        let (cw, ch) = (canvas.0 * scale, canvas.1 * scale);
        let cx = rng.random_range(0.0..w);
        let cy = rng.random_range(0.0..h);
        let jitter = 0.12 * cw.min(ch);
        let corners: [[f64; 2]; 4] =
            [[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]].map(|[u, v]| {
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
            return corners;
        }
    }
}

/// Renders scene `seed` of `setup` at `size`.
pub fn scene(setup: &ChartSetup, seed: u64, size: SceneSize) -> Scene {
    let mut rng = SmallRng::seed_from_u64(seed);
    let (light_name, spd) = random_light(&mut rng);
    let camera = &setup.cameras[rng.random_range(0..2)];
    let rendering = camera.render(&spd, seed, false).unwrap();
    let chart_img = &rendering.image;
    let layout = camera.chart().layout;
    let (cw, ch) = (chart_img.width, chart_img.height);
    let grid_px = (layout.cols * layout.patch_px + (layout.cols - 1) * layout.gap_px) as f64;
    let image_corners = random_placement(&mut rng, setup, (cw as f64, ch as f64), grid_px, size);
    let canvas = [
        [0.0, 0.0],
        [cw as f64, 0.0],
        [cw as f64, ch as f64],
        [0.0, ch as f64],
    ];
    let h = Homography::fit(&canvas, &image_corners).unwrap();
    let inv = h.inverse().unwrap();
    // The patch grid's outer corners.
    let (gx0, gy0) = (layout.margin_x as f64, layout.margin_y as f64);
    let grid_h = (layout.rows * layout.patch_px + (layout.rows - 1) * layout.gap_px) as f64;
    let corners = [
        [gx0, gy0],
        [gx0 + grid_px, gy0],
        [gx0 + grid_px, gy0 + grid_h],
        [gx0, gy0 + grid_h],
    ]
    .map(|p| h.apply(p));
    let quad_area = 0.5
        * (0..4)
            .map(|k| {
                corners[k][0] * corners[(k + 1) % 4][1] - corners[(k + 1) % 4][0] * corners[k][1]
            })
            .sum::<f64>()
            .abs();
    let f = setup.template.patch_fraction;
    let (tw, th) = setup.template.size();
    let patch_px = f * (quad_area / (tw * th)).sqrt();

    // The light's colour on a white surface, for the background.
    let white = [0, 1, 2].map(|c| {
        let mut best = 0.0f32;
        for &v in &chart_img.planes[c] {
            best = best.max(v);
        }
        srgb_decode(best as f64) as f32
    });
    let wmax = white.iter().cloned().fold(1e-6, f32::max);
    let tint = white.map(|v| v / wmax);

    let (w, hgt) = (size.width, size.height);
    let mut planes = background(&mut rng, w, hgt, tint);
    let chart_lin: [Vec<f32>; 3] = std::array::from_fn(|c| {
        chart_img.planes[c]
            .iter()
            .map(|&v| srgb_decode(v as f64) as f32)
            .collect()
    });
    for y in 0..hgt {
        for x in 0..w {
            let q = inv.apply([x as f64 + 0.5, y as f64 + 0.5]);
            let (u, v) = (q[0] - 0.5, q[1] - 0.5);
            if !(u >= 0.0 && v >= 0.0 && u <= (cw - 1) as f64 && v <= (ch - 1) as f64) {
                continue;
            }
            let (x0, y0) = (u.floor() as usize, v.floor() as usize);
            let (x1, y1) = ((x0 + 1).min(cw - 1), (y0 + 1).min(ch - 1));
            let (fx, fy) = ((u - x0 as f64) as f32, (v - y0 as f64) as f32);
            for c in 0..3 {
                let p = &chart_lin[c];
                let top = p[y0 * cw + x0] * (1.0 - fx) + p[y0 * cw + x1] * fx;
                let bottom = p[y1 * cw + x0] * (1.0 - fx) + p[y1 * cw + x1] * fx;
                planes[c][y * w + x] = top * (1.0 - fy) + bottom * fy;
            }
        }
    }
    let sigma = rng.random_range(0.0..1.2);
    let mut scratch = Vec::new();
    for p in planes.iter_mut() {
        gaussian_blur(p, w, hgt, sigma, &mut scratch);
    }
    let vignette_strength = rng.random_range(0.0..0.25);
    let (mx, my) = (w as f64 / 2.0, hgt as f64 / 2.0);
    let rmax2 = mx * mx + my * my;
    let vignette =
        |x: f64, y: f64| 1.0 - vignette_strength * ((x - mx).powi(2) + (y - my).powi(2)) / rmax2;
    let noise_sigma = rng.random_range(0.0..2.0f64);
    let normal = rand_distr::Normal::new(0.0, noise_sigma.max(1e-9)).unwrap();
    let mut rgb8 = vec![0u8; w * hgt * 3];
    for y in 0..hgt {
        for x in 0..w {
            let g = vignette(x as f64 + 0.5, y as f64 + 0.5);
            for c in 0..3 {
                let lin = planes[c][y * w + x] as f64 * g;
                let enc = 255.0 * srgb_encode(lin.clamp(0.0, 1.0)) + rng.sample(normal);
                rgb8[3 * (y * w + x) + c] = enc.round().clamp(0.0, 255.0) as u8;
            }
        }
    }
    let quality = rng.random_range(80..=95u8);
    let mut jpeg = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(Cursor::new(&mut jpeg), quality)
        .encode(&rgb8, w as u32, hgt as u32, image::ExtendedColorType::Rgb8)
        .unwrap();
    let photo = decode_photo(&jpeg, &format!("synthetic-{seed}.jpg")).unwrap();

    // Reference: the unwarped render's features, with the vignetting at each patch centre.
    let features: Vec<f32> = camera
        .chart()
        .feature_patches
        .iter()
        .enumerate()
        .flat_map(|(k, &p)| {
            let (px, py) = layout.patch_origin(p);
            let centre = h.apply([
                px as f64 + layout.patch_px as f64 / 2.0,
                py as f64 + layout.patch_px as f64 / 2.0,
            ]);
            let g = vignette(centre[0], centre[1]);
            let f = &rendering.features;
            [0, 1, 2]
                .map(|c| (255.0 * srgb_encode(srgb_decode(f[3 * k + c] as f64 / 255.0) * g)) as f32)
        })
        .collect();
    Scene {
        photo,
        jpeg,
        corners,
        patch_px,
        features,
        light: light_name,
    }
}

/// ΔE2000 between two encoded sRGB colours (0–255), in CIELAB relative to sRGB white.
pub fn delta_e(a: [f32; 3], b: [f32; 3]) -> f64 {
    let white = colorimetry::linear_srgb_to_xyz([1.0, 1.0, 1.0]);
    let lab = |v: [f32; 3]| {
        let lin = v.map(|x| srgb_decode((x as f64 / 255.0).clamp(0.0, 1.0)));
        colorimetry::xyz_to_lab(colorimetry::linear_srgb_to_xyz(lin), white)
    };
    colorimetry::delta_e_2000(lab(a), lab(b))
}
