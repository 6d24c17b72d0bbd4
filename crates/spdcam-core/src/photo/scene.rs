//! Synthetic photos: a chart photographed in a scene the way a person photographs it. The
//! chart's exposed raw values under the light (the camera's scene and sensor response) are
//! warped by a random homography onto a cluttered, textured background lit by the same
//! light; the lens blurs and vignettes the image (and a bright light outside the frame may
//! glow into it); then the camera develops it through the same stages as a rendered chart
//! — mosaic, sensor noise, demosaicing, white balance, aberration, colour matrix, tone — and
//! a real JPEG encoder writes it. Every random choice comes from the seed. Used to make
//! example photos, to test detection against known truth and to test the self-check.

use super::geometry::Homography;
use super::ChartTemplate;
use crate::camera::optics::{Glow, LensBlur, Vignetting};
use crate::camera::{self, Camera};
use crate::chart::Layout;
use crate::error::{short_number, Error, Result};
use crate::imageio;
use crate::limits;
use crate::raster::RgbImage;
use crate::seed;
use crate::spectral::Spd;
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};

/// Pixels per patch pitch a chart is rendered at before it is placed in a scene.
pub const SCENE_PITCH_PX: usize = 50;

/// How a scene is photographed; each range is drawn uniformly per scene. The sensor's noise
/// is the camera's.
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
    /// The lens's Gaussian blur σ in pixels.
    pub blur_sigma: (f64, f64),
    /// Light fall-off at the photo's corners (0 = none).
    pub vignetting: (f64, f64),
    /// JPEG quality, 1–100.
    pub jpeg_quality: (u8, u8),
    /// A bright light just outside the frame glowing into the lens at the chart's first
    /// corner (top left of its patch grid), its width a share of the grid's width; `None`:
    /// none.
    pub glow: Option<Glow>,
    /// The chart's centre as a share of the photo's width and height; `None`: anywhere the
    /// chart fits, drawn at random.
    pub centre: Option<[f64; 2]>,
    /// The chart's rotation in its own plane, degrees clockwise; `None`: drawn at random.
    pub rotation_deg: Option<f64>,
    /// The chart's plane seen at an angle (a perspective view, replacing the random corner
    /// displacement of [`SceneOptions::perspective`]); `None`: seen face-on up to that
    /// displacement.
    pub tilt: Option<Tilt>,
    /// A shadow over part of the chart; `None`: evenly lit.
    pub shadow: Option<Shadow>,
    /// With a second light on the right half ([`SceneLight::right_half`]): each half
    /// exposed and white-balanced for its own light, as two photos of the scene joined at
    /// the chart's middle; else one exposure (metered under the first light) and one white
    /// balance over the whole frame.
    pub balance_halves: bool,
}

/// The axis of the photo about which the chart's plane is turned away from the camera.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TiltAxis {
    /// The photo's horizontal axis: the chart is foreshortened vertically (a chart lying on
    /// a table).
    Horizontal,
    /// The photo's vertical axis: the chart is foreshortened horizontally (a chart on a
    /// side wall).
    Vertical,
}

/// A chart whose plane is turned by `degrees` about `axis`, photographed by a pinhole
/// camera of focal length [`TILT_FOCAL_SHARE`] × the photo's width: the chart's outline is
/// the perspective projection of the turned plane (Hartley & Zisserman 2004, "Multiple View
/// Geometry", section 6.1), foreshortened by about cos(degrees) and larger on its near side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tilt {
    /// The angle between the chart's normal and the line of sight, degrees (−85…85; the
    /// sign says which side comes nearer).
    pub degrees: f64,
    /// The axis turned about.
    pub axis: TiltAxis,
}

/// Focal length of the pinhole camera that views a tilted chart, as a share of the photo's
/// width (a 26 mm-equivalent phone lens is 0.72 of the width, a 50 mm lens 1.39).
pub const TILT_FOCAL_SHARE: f64 = 0.9;

/// Largest tilt, degrees: beyond it the chart is seen nearly edge-on.
pub const MAX_TILT_DEG: f64 = 85.0;

/// A shadow on the chart: every point of the chart beyond a straight edge is darker by
/// `factor`, with a soft edge (penumbra) a twentieth of the chart's width wide.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shadow {
    /// The light left in the shadow (0 < factor < 1).
    pub factor: f64,
    /// The share of the chart's width (along the shadow's direction) the shadow covers, 0…1.
    pub cover: f64,
    /// The direction the shadow comes from, degrees clockwise from the chart's right side:
    /// 0 shades its right part, 90 its bottom part.
    pub direction_deg: f64,
}

impl Shadow {
    /// The light left at chart-canvas point `(u, v)` (shares of the canvas's width and
    /// height, 0…1): 1 in the light, `factor` deep in the shadow.
    pub fn light_at(&self, u: f64, v: f64) -> f64 {
        let (s, c) = self.direction_deg.to_radians().sin_cos();
        // Position along the shadow's direction, 0…1 across the chart's extent that way.
        let reach = 0.5 * (c.abs() + s.abs());
        let along = ((u - 0.5) * c + (v - 0.5) * s) / reach.max(1e-9) * 0.5 + 0.5;
        let edge = 1.0 - self.cover;
        let penumbra = 0.05;
        let t = ((along - edge) / penumbra + 0.5).clamp(0.0, 1.0);
        let shaded = t * t * (3.0 - 2.0 * t);
        1.0 - shaded * (1.0 - self.factor)
    }
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
            jpeg_quality: (80, 95),
            glow: None,
            centre: None,
            rotation_deg: None,
            tilt: None,
            shadow: None,
            balance_halves: false,
        }
    }
}

/// The light on the chart: one spectrum, or a second one lighting the right half of the
/// chart (mixed light, which a photo must not be trusted with).
#[derive(Debug, Clone, Copy)]
pub struct SceneLight<'a> {
    /// The light on the chart (on the whole chart without `right_half`).
    pub spd: &'a Spd,
    /// The light on the right half of the chart, at the exposure of the first.
    pub right_half: Option<&'a Spd>,
}

impl<'a> SceneLight<'a> {
    /// One light on the whole chart.
    pub fn single(spd: &'a Spd) -> SceneLight<'a> {
        SceneLight {
            spd,
            right_half: None,
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
    /// Each feature patch as a flat, noise-free, unblurred patch would show at its centre,
    /// vignetting and glow included (encoded sRGB, 0–255, `p01_r, p01_g, …`): the features
    /// a perfect sampler would read.
    pub expected_features: Vec<f32>,
    /// The sensor's mosaic before any processing, for a raw file (`None` for a
    /// three-sensor camera or two halves developed apart).
    pub mosaic: Option<crate::raster::Mosaic>,
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

/// Photographs `camera`'s chart (laid out by [`scene_layout`]) under `light` in scene
/// `seed`.
pub fn photograph(
    camera: &Camera,
    light: SceneLight,
    seed: u64,
    options: &SceneOptions,
) -> Result<ScenePhoto> {
    let shot = match (light.right_half, options.balance_halves) {
        (Some(right), true) => {
            // Two photos of one scene, each exposed and balanced for its own light, joined
            // at the chart's middle.
            let mut left = develop_scene(camera, SceneLight::single(light.spd), seed, options)?;
            let right = develop_scene(camera, SceneLight::single(right), seed, options)?;
            let w = left.image.width;
            for y in 0..left.image.height {
                for x in 0..w {
                    let q = left.inverse.apply([x as f64 + 0.5, y as f64 + 0.5]);
                    let (cw, ch) = left.canvas;
                    if q[0] >= cw / 2.0 && q[0] <= cw && q[1] >= 0.0 && q[1] <= ch {
                        for (l, r) in left.image.planes.iter_mut().zip(&right.image.planes) {
                            l[y * w + x] = r[y * w + x];
                        }
                    }
                }
            }
            for (k, right_lit) in left.right_lit.iter().enumerate() {
                if *right_lit {
                    left.expected_features[3 * k..3 * k + 3]
                        .copy_from_slice(&right.expected_features[3 * k..3 * k + 3]);
                }
            }
            left.mosaic = None;
            left
        }
        _ => develop_scene(camera, light, seed, options)?,
    };
    Ok(ScenePhoto {
        jpeg: imageio::encode_jpeg(&shot.image, shot.quality)?,
        corners: shot.corners,
        patch_px: shot.patch_px,
        expected_features: shot.expected_features,
        mosaic: shot.mosaic,
    })
}

/// A scene photo before JPEG encoding, with what is true about it.
struct DevelopedScene {
    image: RgbImage,
    quality: u8,
    corners: [[f64; 2]; 4],
    patch_px: f64,
    expected_features: Vec<f32>,
    mosaic: Option<crate::raster::Mosaic>,
    /// Photo → chart canvas.
    inverse: Homography,
    /// The chart canvas's width and height: canvas points right of its middle are the
    /// right half.
    canvas: (f64, f64),
    /// Per feature patch: on the right half.
    right_lit: Vec<bool>,
}

/// [`photograph`] up to the developed image.
fn develop_scene(
    camera: &Camera,
    light: SceneLight,
    seed: u64,
    options: &SceneOptions,
) -> Result<DevelopedScene> {
    check_scene_size(options.width, options.height)?;
    check_width_share(options.width_share)?;
    check_placement(options)?;
    let mut rng = SmallRng::seed_from_u64(seed);
    let laid = lay(camera, &mut rng, options)?;
    let spds: Vec<&Spd> = std::iter::once(light.spd).chain(light.right_half).collect();
    let exposed = camera.exposed_chart(&spds)?;
    let mut scene = RgbImage::new(options.width, options.height);
    scene.planes = background(
        &mut rng,
        options.width,
        options.height,
        chart_white(camera, &exposed[0]),
    );
    paint(&mut scene, camera, &laid, &exposed, options.shadow);
    let patch_mean = camera::patch_mean(&exposed[0], camera.chart().reflectances.len());
    let glow = options
        .glow
        .map(|g| (g, laid.corners[0], laid.grid_width_px(), patch_mean));
    let (developed, vignetting, quality) =
        develop_whole(camera, &mut scene, &mut rng, seed, options, glow)?;
    let seen = Seen {
        developer: camera,
        vignetting,
        glow,
        gains: developed.white_balance_gains,
        size: (options.width, options.height),
    };
    let expected_features = seen.features(camera, &laid, &exposed, options.shadow);
    let right_lit = laid.right_lit(camera);
    Ok(DevelopedScene {
        image: developed.image,
        mosaic: developed.mosaic,
        quality,
        corners: laid.corners,
        patch_px: laid.patch_px,
        expected_features,
        inverse: laid.inverse,
        canvas: (laid.canvas.0 as f64, laid.canvas.1 as f64),
        right_lit,
    })
}

/// A glow into the lens: the glow, its centre (photo px), its reference length (px) and the
/// mean raw level it is a share of.
pub(super) type GlowAt = (Glow, [f64; 2], f64, [f32; 3]);

/// A chart's canvas laid into the photo.
pub(super) struct Laid {
    /// Chart canvas → photo.
    pub(super) homography: Homography,
    /// Photo → chart canvas.
    pub(super) inverse: Homography,
    /// Outer corners of the patch grid in the photo: TL, TR, BR, BL.
    pub(super) corners: [[f64; 2]; 4],
    /// Mean patch side in photo pixels.
    pub(super) patch_px: f64,
    /// The canvas's width and height in its own pixels.
    pub(super) canvas: (usize, usize),
    /// The outer outline of what is laid in the photo (the canvas, or the case holding
    /// it): TL, TR, BR, BL.
    pub(super) outline: [[f64; 2]; 4],
}

impl Laid {
    /// The outline of a `canvas` (width, height) mapped by `homography`: TL, TR, BR, BL.
    pub(super) fn canvas_outline(
        homography: &Homography,
        (cw, ch): (usize, usize),
    ) -> [[f64; 2]; 4] {
        let (cw, ch) = (cw as f64, ch as f64);
        [[0.0, 0.0], [cw, 0.0], [cw, ch], [0.0, ch]].map(|p| homography.apply(p))
    }

    /// The patch grid's top side in photo pixels.
    pub(super) fn grid_width_px(&self) -> f64 {
        let [a, b, ..] = self.corners;
        (b[0] - a[0]).hypot(b[1] - a[1])
    }

    /// Per feature patch of `camera`'s chart: whether it lies on the canvas's right half.
    fn right_lit(&self, camera: &Camera) -> Vec<bool> {
        let layout = &camera.chart().layout;
        let half = self.canvas.0 as f64 / 2.0;
        camera
            .chart()
            .feature_patches
            .iter()
            .map(|&p| layout.patch_origin(p).0 as f64 + layout.patch_px as f64 / 2.0 >= half)
            .collect()
    }
}

/// Checks a drawn share of the photo's width a chart's patch grid spans.
pub(super) fn check_width_share(share: (f64, f64)) -> Result<()> {
    if share.0 > 0.0 && share.0 <= share.1 && share.1 < 1.0 {
        Ok(())
    } else {
        Err(Error::invalid(format!(
            "the chart's share of the scene width {share:?} must lie in (0, 1)"
        )))
    }
}

/// `camera`'s chart laid into the photo as `options` place it ([`placement`]).
pub(super) fn lay(camera: &Camera, rng: &mut SmallRng, options: &SceneOptions) -> Result<Laid> {
    let chart = camera.chart();
    let template = ChartTemplate::from_chart(chart)?;
    let layout = &chart.layout;
    let (cw, ch) = (layout.width, layout.height);
    let grid_w = (layout.cols * layout.patch_px + (layout.cols - 1) * layout.gap_px) as f64;
    let grid_h = (layout.rows * layout.patch_px + (layout.rows - 1) * layout.gap_px) as f64;
    let placed = placement(rng, (cw as f64, ch as f64), grid_w, options)?;
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
    let (tw, th) = template.size();
    let patch_px = template.patch_fraction * (quad_area(&corners) / (tw * th)).sqrt();
    Ok(Laid {
        homography,
        inverse,
        corners,
        patch_px,
        canvas: (cw, ch),
        outline: Laid::canvas_outline(&homography, (cw, ch)),
    })
}

/// The area of a simple quadrilateral (shoelace formula).
pub(super) fn quad_area(corners: &[[f64; 2]; 4]) -> f64 {
    0.5 * (0..4)
        .map(|k| corners[k][0] * corners[(k + 1) % 4][1] - corners[(k + 1) % 4][0] * corners[k][1])
        .sum::<f64>()
        .abs()
}

/// The raw value of the chart's whitest surface under its light (`exposed`, per region),
/// which tints the background.
pub(super) fn chart_white(camera: &Camera, exposed: &[[f32; 3]]) -> [f32; 3] {
    let patches = camera.chart().reflectances.len();
    [0, 1, 2].map(|c| exposed[..patches].iter().map(|v| v[c]).fold(0.0, f32::max))
}

/// Paints `camera`'s chart, laid by `laid`, into the raw `scene`: each canvas pixel the
/// exposed value of its region (`exposed[0]`, or the last light on the canvas's right
/// half), bilinear between canvas pixels, dimmed by `shadow`.
pub(super) fn paint(
    scene: &mut RgbImage,
    camera: &Camera,
    laid: &Laid,
    exposed: &[Vec<[f32; 3]>],
    shadow: Option<Shadow>,
) {
    let (w, h) = (scene.width, scene.height);
    let (cw, ch) = laid.canvas;
    let region_map = camera.chart().layout.region_map();
    let half = cw as f64 / 2.0;
    let shade =
        |u: f64, v: f64| shadow.map_or(1.0, |sh| sh.light_at(u / cw as f64, v / ch as f64) as f32);
    // Only the photo pixels inside the canvas's outline are visited.
    let xs = pixel_bounds(&Laid::canvas_outline(&laid.homography, laid.canvas), w, h);
    for y in xs.1.clone() {
        for x in xs.0.clone() {
            let q = laid.inverse.apply([x as f64 + 0.5, y as f64 + 0.5]);
            let (u, v) = (q[0] - 0.5, q[1] - 0.5);
            if !(u >= 0.0 && v >= 0.0 && u <= (cw - 1) as f64 && v <= (ch - 1) as f64) {
                continue;
            }
            let (x0, y0) = (u as usize, v as usize);
            let (x1, y1) = ((x0 + 1).min(cw - 1), (y0 + 1).min(ch - 1));
            let (fx, fy) = ((u - x0 as f64) as f32, (v - y0 as f64) as f32);
            let at = |cx: usize, cy: usize| {
                let lit = if cx as f64 + 0.5 >= half {
                    exposed.len() - 1
                } else {
                    0
                };
                exposed[lit][usize::from(region_map[cy * cw + cx])]
            };
            let (a, b, c, d) = (at(x0, y0), at(x1, y0), at(x0, y1), at(x1, y1));
            let light = shade(u + 0.5, v + 0.5);
            for (k, plane) in scene.planes.iter_mut().enumerate() {
                let top = a[k] * (1.0 - fx) + b[k] * fx;
                let bottom = c[k] * (1.0 - fx) + d[k] * fx;
                plane[y * w + x] = (top * (1.0 - fy) + bottom * fy) * light;
            }
        }
    }
}

/// The photo's pixel columns and rows an `outline` (photo pixels) covers, a pixel of margin
/// around it, clipped to a `w × h` photo.
pub(super) fn pixel_bounds(
    outline: &[[f64; 2]; 4],
    w: usize,
    h: usize,
) -> (std::ops::Range<usize>, std::ops::Range<usize>) {
    let span = |axis: usize, size: usize| {
        let lo = outline
            .iter()
            .map(|p| p[axis])
            .fold(f64::INFINITY, f64::min);
        let hi = outline
            .iter()
            .map(|p| p[axis])
            .fold(f64::NEG_INFINITY, f64::max);
        let lo = (lo.floor() - 1.0).clamp(0.0, size as f64) as usize;
        let hi = (hi.ceil() + 1.0).clamp(0.0, size as f64) as usize;
        lo..hi
    };
    (span(0, w), span(1, h))
}

/// The lens and the camera over the painted scene: the glow (if any), blur and vignetting
/// drawn from `rng`, development by `camera`, then the JPEG quality drawn; the developed
/// photo, its vignetting and the quality.
pub(super) fn develop_whole(
    camera: &Camera,
    scene: &mut RgbImage,
    rng: &mut SmallRng,
    seed: u64,
    options: &SceneOptions,
    glow: Option<GlowAt>,
) -> Result<(camera::Developed, Vignetting, u8)> {
    if let Some((g, centre, length, mean)) = glow {
        g.apply(scene, centre, mean, length);
    }
    let blur = LensBlur {
        sigma: draw(rng, options.blur_sigma),
    };
    blur.apply(scene);
    let vignetting = Vignetting {
        strength: draw(rng, options.vignetting),
    };
    vignetting.apply(scene);
    let developed = camera.develop(scene, seed::derive(seed, 1));
    let (q0, q1) = options.jpeg_quality;
    let quality = rng.random_range(q0.clamp(1, 100)..=q1.clamp(q0.clamp(1, 100), 100));
    Ok((developed, vignetting, quality))
}

/// How the developed photo shows a flat patch: the camera that developed it, its
/// vignetting and glow, its white balance and the photo's size.
pub(super) struct Seen<'a> {
    pub(super) developer: &'a Camera,
    pub(super) vignetting: Vignetting,
    pub(super) glow: Option<GlowAt>,
    pub(super) gains: [f32; 3],
    pub(super) size: (usize, usize),
}

impl Seen<'_> {
    /// Each feature patch of `camera`'s chart (laid by `laid`, exposed as `exposed`,
    /// shaded by `shadow`) as a flat, noise-free, unblurred patch shows at its centre
    /// (encoded sRGB, 0–255).
    pub(super) fn features(
        &self,
        camera: &Camera,
        laid: &Laid,
        exposed: &[Vec<[f32; 3]>],
        shadow: Option<Shadow>,
    ) -> Vec<f32> {
        let chart = camera.chart();
        let layout = &chart.layout;
        let (cw, ch) = laid.canvas;
        let half = cw as f64 / 2.0;
        chart
            .feature_patches
            .iter()
            .flat_map(|&p| {
                let (px, py) = layout.patch_origin(p);
                let centre = layout.patch_px as f64 / 2.0;
                let canvas_centre = [px as f64 + centre, py as f64 + centre];
                let at = laid.homography.apply(canvas_centre);
                let lit = if canvas_centre[0] >= half {
                    exposed.len() - 1
                } else {
                    0
                };
                let g = self.vignetting.gain(at, self.size.0, self.size.1) as f32;
                let (glow, mean) = match self.glow {
                    Some((glow, c, length, mean)) => (glow.share_at(at, c, length) as f32, mean),
                    None => (0.0, [0.0; 3]),
                };
                let light = shadow.map_or(1.0, |sh| {
                    sh.light_at(canvas_centre[0] / cw as f64, canvas_centre[1] / ch as f64) as f32
                });
                let raw: [f32; 3] =
                    std::array::from_fn(|c| (exposed[lit][p][c] * light + glow * mean[c]) * g);
                self.developer
                    .encode_exposed(raw, self.gains)
                    .map(|v| 255.0 * v)
            })
            .collect()
    }
}

fn draw(rng: &mut SmallRng, (lo, hi): (f64, f64)) -> f64 {
    if hi > lo {
        rng.random_range(lo..hi)
    } else {
        lo
    }
}

/// A placement of the chart canvas inside the photo: scaled so the patch grid spans the
/// drawn share of the width (face-on), rotated in its plane, then either turned away by the
/// tilt and projected or each corner displaced at random for perspective; centred where
/// given, else anywhere it fits (drawn again until it does).
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
        let angle = match options.rotation_deg {
            Some(deg) => deg.to_radians(),
            None => rng.random_range(0.0..std::f64::consts::TAU),
        };
        let (s, c) = angle.sin_cos();
        let (cw, ch) = (canvas.0 * scale, canvas.1 * scale);
        let (cx, cy) = match options.centre {
            Some([x, y]) => (x * w, y * h),
            None => (rng.random_range(0.0..w), rng.random_range(0.0..h)),
        };
        let unit = [[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]];
        let corners = match options.tilt {
            Some(tilt) => {
                let focal = TILT_FOCAL_SHARE * w;
                let (ts, tc) = tilt.degrees.to_radians().sin_cos();
                unit.map(|[u, v]| {
                    let (x, y) = (u * cw, v * ch);
                    let (x, y) = (c * x - s * y, s * x + c * y);
                    let (x, y, z) = match tilt.axis {
                        TiltAxis::Vertical => (x * tc, y, x * ts),
                        TiltAxis::Horizontal => (x, y * tc, y * ts),
                    };
                    let depth = (focal + z).max(1e-9);
                    [cx + focal * x / depth, cy + focal * y / depth]
                })
            }
            None => {
                let jitter = (options.perspective * cw.min(ch)).max(1e-9);
                unit.map(|[u, v]| {
                    let (x, y) = (u * cw, v * ch);
                    [
                        cx + c * x - s * y + rng.random_range(-jitter..jitter),
                        cy + s * x + c * y + rng.random_range(-jitter..jitter),
                    ]
                })
            }
        };
        let margin = 4.0;
        if corners
            .iter()
            .all(|p| p[0] > margin && p[1] > margin && p[0] < w - margin && p[1] < h - margin)
        {
            return Ok(corners);
        }
        if options.centre.is_some()
            && options.rotation_deg.is_some()
            && options.width_share.0 == options.width_share.1
            && (options.tilt.is_some() || options.perspective == 0.0)
        {
            break;
        }
    }
    Err(Error::invalid(format!(
        "a chart spanning {:?} of the width does not fit a {}×{} scene{}",
        options.width_share,
        options.width,
        options.height,
        if options.centre.is_some() {
            " at the centre given"
        } else {
            ""
        }
    )))
}

/// Checks the placement options: the centre inside the photo, the rotation finite, the tilt
/// within ±[`MAX_TILT_DEG`], the shadow's factor in (0, 1) and cover in [0, 1].
pub(super) fn check_placement(options: &SceneOptions) -> Result<()> {
    if let Some([x, y]) = options.centre {
        if !((0.0..=1.0).contains(&x) && (0.0..=1.0).contains(&y)) {
            return Err(Error::invalid(format!(
                "the chart's centre {},{} must lie in the photo: shares of its width and \
                 height, 0…1",
                short_number(x),
                short_number(y)
            )));
        }
    }
    if let Some(r) = options.rotation_deg.filter(|r| !r.is_finite()) {
        return Err(Error::invalid(format!(
            "the chart's rotation {r} is not an angle in degrees"
        )));
    }
    if let Some(t) = options.tilt {
        if t.degrees.is_nan() || t.degrees.abs() > MAX_TILT_DEG {
            return Err(Error::invalid(format!(
                "a tilt of {}° is out of range: give −{MAX_TILT_DEG}…{MAX_TILT_DEG}°",
                t.degrees
            )));
        }
    }
    if let Some(sh) = options.shadow {
        if !(sh.factor > 0.0 && sh.factor < 1.0) {
            return Err(Error::invalid(format!(
                "a shadow's factor {} must lie between 0 and 1 (the light left in it)",
                sh.factor
            )));
        }
        if !((0.0..=1.0).contains(&sh.cover) && sh.direction_deg.is_finite()) {
            return Err(Error::invalid(format!(
                "a shadow covering {} of the chart from {}° is out of range: give a cover 0…1",
                sh.cover, sh.direction_deg
            )));
        }
    }
    Ok(())
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

/// Raw background: two octaves of value noise in colour, with clutter (random rectangles,
/// some of them square tiles, and discs), reflecting 1–70 % of `white`, the raw value of a
/// white surface under the scene's light.
pub(super) fn background(rng: &mut SmallRng, w: usize, h: usize, white: [f32; 3]) -> [Vec<f32>; 3] {
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
    for (plane, t) in planes.iter_mut().zip(white) {
        plane.iter_mut().for_each(|v| *v *= t);
    }
    planes
}
