//! The per-shot settings of a JPEG camera, beyond the thesis's pipeline, in one record:
//! uneven lighting across the chart, veiling glare and a glow on part of it, automatic
//! exposure with sensor saturation, auto white balance with incomplete adaptation, colour saturation, a
//! highlight shoulder, a tone curve beyond the sRGB gamma, and JPEG-like quantisation.
//! Each setting belongs to one stage of the chain and is carried out there:
//!
//! | settings | stage | module |
//! |---|---|---|
//! | `gradient` | scene: uneven lighting | [`super::scene`] |
//! | `flare`, `glow` | optics: veiling glare | [`super::optics`] |
//! | `exposure_target` (+ clipping at full scale) | sensor: auto exposure | [`super::sensor`] |
//! | `adaptation` | ISP: white balance | [`super::white_balance`] |
//! | `saturation`, `shoulder`, `gamma`, `contrast`, `jpeg_quality` | ISP: rendering | [`super::tone`] |
//!
//! The record is what a fit to real photos finds ([`fit_to_photos`]), domain randomisation draws per
//! sample and dataset manifests store. Every setting's neutral value leaves the image
//! unchanged; the whole record is off unless [`crate::camera::CameraConfig::in_camera`] is
//! set.

use super::optics::{ChartGlow, VeilingGlare};
use super::scene::UnevenLighting;
use super::sensor::AutoExposure;
use super::tone::ToneRendering;
use super::Camera;
use crate::error::{short_number, Error, Result};
use crate::minimise::nelder_mead;
use crate::spectral::Spd;
use serde::{Deserialize, Serialize};

/// The in-camera settings. [`InCamera::NEUTRAL`] changes nothing but the sensor clipping.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct InCamera {
    /// Veiling glare: each region's raw value gains `flare` × the mean raw value of the
    /// chart's patches (0 = none; sensible 0–0.5).
    pub flare: f64,
    /// Automatic exposure: the mean green raw value of the chart's patches is scaled to this
    /// fraction of full scale (sensible 0.05–0.6), replacing the sensor's normalisation to
    /// the maximum; raw values above full scale clip. `None` keeps the sensor's exposure.
    pub exposure_target: Option<f64>,
    /// Fraction of the white-balance correction applied, as a power of the gains (1 = full
    /// correction, 0 = none: the light's cast stays; sensible 0.5–1).
    pub adaptation: f64,
    /// Colour saturation in linear sRGB about the luminance (1 = unchanged; sensible 0.5–1.5).
    pub saturation: f64,
    /// Highlight shoulder: linear values above `1 − shoulder` roll off smoothly towards 1
    /// instead of clipping (0 = hard clip; sensible 0–0.5).
    pub shoulder: f64,
    /// Power on linear values before encoding (1 = the sRGB curve alone; below 1 brightens
    /// mid-tones; sensible 0.6–1.4).
    pub gamma: f64,
    /// S-curve on encoded values `y + contrast·y(1−y)(2y−1)` (0 = none; −1…1).
    pub contrast: f64,
    /// JPEG quality (1–100) whose DC quantisation steps (libjpeg's tables) round each
    /// pixel's Y, Cb, Cr: what JPEG does to flat patches. `None` = no JPEG quantisation.
    pub jpeg_quality: Option<u8>,
    /// Uneven lighting (a scene effect): the light's relative gain on a patch is
    /// `1 + gradient[0]·x + gradient[1]·y`, with x, y the patch centre's position across
    /// the chart's patch grid from −½ (left, top) to +½ (right, bottom); [0, 0] = even
    /// lighting (sensible magnitudes up to 0.5).
    #[serde(default)]
    pub gradient: [f64; 2],
    /// Black floor of the rendered values (0 = none; sensible 0–0.2): each encoded value
    /// becomes `floor + (1 − floor)·value`, as a real camera's black offset, noise and
    /// residual flare keep its darkest channels above 0 where the colour matrix pushes a
    /// saturated patch's channel below black (`docs/real-cameras.md`).
    #[serde(default)]
    pub floor: f64,
    /// A glow on part of the chart (a bright light beside it, scattered by the lens onto the
    /// patches near it); off when its level is 0, and then left unwritten, so that records
    /// made before it existed read the same.
    #[serde(default, skip_serializing_if = "ChartGlow::is_off")]
    pub glow: ChartGlow,
}

/// Largest glow level: the patches' mean raw value at the glow's centre.
const MAX_GLOW_LEVEL: f64 = 1.0;
/// Largest glow width: twice the chart's extent (wider is a veiling glare).
const MAX_GLOW_WIDTH: f64 = 2.0;
/// Farthest glow centre from the chart's centre, along each axis, in chart extents.
const MAX_GLOW_OFFSET: f64 = 1.5;

/// Largest black floor: half of full scale.
const MAX_FLOOR: f64 = 0.5;

impl Default for InCamera {
    fn default() -> Self {
        InCamera::NEUTRAL
    }
}

/// Largest lighting-gradient magnitude: the gain stays positive over the whole chart.
const MAX_GRADIENT: f64 = 1.5;

/// Parameter names and ranges, for messages and for the fit's bounds.
const RANGES: [(&str, f64, f64); 7] = [
    ("exposure_target", 0.01, 1.0),
    ("flare", 0.0, 1.0),
    ("adaptation", 0.0, 1.5),
    ("saturation", 0.0, 2.0),
    ("shoulder", 0.0, 0.9),
    ("gamma", 0.3, 3.0),
    ("contrast", -1.0, 1.0),
];

impl InCamera {
    /// Every stage neutral: no flare, the sensor's exposure, full white balance, no
    /// saturation change, hard clip, sRGB curve alone, no JPEG.
    pub const NEUTRAL: InCamera = InCamera {
        flare: 0.0,
        exposure_target: None,
        adaptation: 1.0,
        saturation: 1.0,
        shoulder: 0.0,
        gamma: 1.0,
        contrast: 0.0,
        jpeg_quality: None,
        gradient: [0.0, 0.0],
        floor: 0.0,
        glow: ChartGlow::OFF,
    };

    /// The fitted parameters as a vector in [`RANGES`] order (exposure target 0 when off).
    fn to_vector(self) -> [f64; 7] {
        [
            self.exposure_target.unwrap_or(0.0),
            self.flare,
            self.adaptation,
            self.saturation,
            self.shoulder,
            self.gamma,
            self.contrast,
        ]
    }

    /// The inverse of [`InCamera::to_vector`], keeping `self`'s JPEG quality and lighting gradient.
    fn with_vector(self, v: [f64; 7]) -> InCamera {
        InCamera {
            exposure_target: Some(v[0]),
            flare: v[1],
            adaptation: v[2],
            saturation: v[3],
            shoulder: v[4],
            gamma: v[5],
            contrast: v[6],
            ..self
        }
    }

    /// Checks every parameter against its range.
    pub fn validate(&self) -> Result<()> {
        let v = self.to_vector();
        for (k, &(name, lo, hi)) in RANGES.iter().enumerate() {
            let x = v[k];
            if k == 0 && self.exposure_target.is_none() {
                continue;
            }
            if !(x.is_finite() && x >= lo && x <= hi) {
                return Err(Error::invalid(format!(
                    "in-camera {name} {} is outside [{lo}, {hi}]",
                    short_number(x)
                )));
            }
        }
        if self
            .gradient
            .iter()
            .any(|g| !(g.is_finite() && g.abs() <= MAX_GRADIENT))
        {
            return Err(Error::invalid(format!(
                "in-camera lighting gradient {:?} is outside ±{MAX_GRADIENT}",
                self.gradient
            )));
        }
        if !(self.floor.is_finite() && (0.0..=MAX_FLOOR).contains(&self.floor)) {
            return Err(Error::invalid(format!(
                "in-camera black floor {} is outside [0, {MAX_FLOOR}]",
                self.floor
            )));
        }
        let g = self.glow;
        let glow_in_range = (0.0..=MAX_GLOW_LEVEL).contains(&g.level)
            && g.width > 0.0
            && g.width <= MAX_GLOW_WIDTH
            && g.at.iter().all(|a| a.abs() <= MAX_GLOW_OFFSET);
        if !g.is_off() && !glow_in_range {
            return Err(Error::invalid(format!(
                "in-camera glow (level {}, width {}, at {:?}) is outside level [0, \
                 {MAX_GLOW_LEVEL}], width (0, {MAX_GLOW_WIDTH}], centre within \
                 ±{MAX_GLOW_OFFSET} chart extents",
                short_number(g.level),
                short_number(g.width),
                g.at
            )));
        }
        if let Some(q) = self.jpeg_quality {
            if !(1..=100).contains(&q) {
                return Err(Error::invalid(format!(
                    "in-camera JPEG quality {q} is outside 1–100"
                )));
            }
        }
        Ok(())
    }

    /// The scene stage's setting: the lighting gradient across the chart.
    pub fn uneven_lighting(&self) -> UnevenLighting {
        UnevenLighting {
            gradient: self.gradient,
        }
    }

    /// The optics stage's setting: the veiling glare and the glow.
    pub fn glare(&self) -> VeilingGlare {
        VeilingGlare {
            share: self.flare,
            glow: self.glow,
        }
    }

    /// The sensor stage's automatic exposure, when it is on.
    pub fn auto_exposure(&self) -> Option<AutoExposure> {
        self.exposure_target.map(|target| AutoExposure { target })
    }

    /// The ISP's rendering after the colour matrix.
    pub fn rendering(&self) -> ToneRendering {
        ToneRendering {
            saturation: self.saturation,
            shoulder: self.shoulder,
            gamma: self.gamma,
            contrast: self.contrast,
            jpeg_quality: self.jpeg_quality,
            floor: self.floor,
        }
    }
}

/// One real photo of the chart: its features (0–255, the camera's feature order) and the
/// measured SPD of its light on the camera's simulation grid.
#[derive(Debug, Clone)]
pub struct ReferencePhoto {
    /// The photo's chart features (0–255).
    pub features: Vec<f64>,
    /// The light's measured SPD on the camera's simulation grid.
    pub spd: Spd,
}

/// The result of [`fit_to_photos`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct InCameraFit {
    /// The fitted in-camera rendering.
    pub in_camera: InCamera,
    /// Root-mean-square feature error (0–255) over the photos, before (neutral in-camera
    /// stage with auto exposure at the photos' level) and after the fit.
    pub rms_before: f64,
    /// The same error with the fitted stage.
    pub rms_after: f64,
    /// Objective evaluations used.
    pub evaluations: usize,
}

/// Fits the in-camera parameters (all but the JPEG quality, kept from `start`) of `camera`
/// to `photos` by least squares on the features, with Nelder–Mead inside the parameter
/// ranges, from `start`.
pub fn fit_to_photos(
    camera: &Camera,
    photos: &[ReferencePhoto],
    start: InCamera,
    max_evaluations: usize,
) -> Result<InCameraFit> {
    if photos.is_empty() {
        return Err(Error::invalid(
            "fitting the in-camera stage needs at least one photo",
        ));
    }
    let expected = camera.chart().feature_patches.len() * 3;
    let mut lights = Vec::with_capacity(photos.len());
    for (i, p) in photos.iter().enumerate() {
        if p.features.len() != expected {
            return Err(Error::invalid(format!(
                "reference photo {i} has {} features; the chart needs {expected}",
                p.features.len()
            )));
        }
        if p.features.iter().any(|v| !v.is_finite()) {
            return Err(Error::invalid(format!(
                "reference photo {i} has a feature that is not a number"
            )));
        }
        lights.push(
            camera
                .light(&p.spd)
                .map_err(|e| Error::invalid(format!("reference photo {i}: {e}")))?,
        );
    }
    start.validate()?;
    let mut raw = Vec::new();
    let mut out = Vec::new();
    let mut objective = |ic: &InCamera| -> f64 {
        let mut sum = 0.0;
        for (light, photo) in lights.iter().zip(photos) {
            out.clear();
            camera.features_fast_with(Some(ic), light, &mut raw, &mut out);
            sum += out
                .iter()
                .zip(&photo.features)
                .map(|(&a, &b)| (f64::from(a) - b).powi(2))
                .sum::<f64>();
        }
        (sum / (photos.len() * expected) as f64).sqrt()
    };
    let start = InCamera {
        exposure_target: Some(start.exposure_target.unwrap_or(0.18)),
        ..start
    };
    let rms_before = objective(&InCamera {
        jpeg_quality: None,
        ..start
    });
    let clamp =
        |v: [f64; 7]| -> [f64; 7] { std::array::from_fn(|k| v[k].clamp(RANGES[k].1, RANGES[k].2)) };
    let mut evaluations = 0;
    let mut f = |v: &[f64; 7]| {
        evaluations += 1;
        objective(&start.with_vector(clamp(*v)))
    };
    let best = nelder_mead(&mut f, start.to_vector(), 0.1, max_evaluations);
    let in_camera = start.with_vector(clamp(best.0));
    Ok(InCameraFit {
        in_camera,
        rms_before,
        rms_after: best.1,
        evaluations,
    })
}
