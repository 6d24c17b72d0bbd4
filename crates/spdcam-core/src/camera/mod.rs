//! The virtual camera (thesis chapter 3, and the JPEG camera beyond it), one module per box
//! of the chain, each switchable, then the patch features by the sampler photos use too
//! ([`crate::sampler`]):
//!
//! ```text
//! light × chart ─► scene ─► optics ─► sensor ─────────────────► ISP ───────────────────────────► features
//!  (sensor:        (uneven   (veiling  (exposure, clipping,      (demosaic, white_balance
//!   spectral        lighting) glare)    mosaic, noise)            with adaptation, aberration,
//!   response)                                                     colour matrix, tone, JPEG)
//! ```
//!
//! `scene.rs`, `optics.rs`, `sensor.rs` + `noise.rs`, `demosaic.rs`, `white_balance.rs`,
//! `aberration.rs` (lateral chromatic aberration, an optical effect the thesis applies to the
//! white-balanced image), `colour.rs`, `tone.rs`. The per-shot settings of the stages beyond
//! the thesis come as one record, [`in_camera::InCamera`], which each stage reads its part of.
//!
//! [`Camera::render`] runs the whole image pipeline; [`Camera::features_fast`] gives the
//! noise-free features straight from patch-level values, without an image, for very large
//! datasets; [`Camera::exposed_chart`] and [`Camera::develop`] let a scene photo
//! ([`crate::photo::scene`]) run the same stages on a chart placed in a scene.

pub mod aberration;
pub mod colour;
pub mod demosaic;
mod dng_profile;
pub mod in_camera;
pub mod noise;
pub mod optics;
pub mod scene;
pub mod sensor;
pub mod tone;
pub mod white_balance;

use crate::chart::Chart;
use crate::cie_illuminant::StandardIlluminant;
use crate::colorimetry::Observer;
use crate::error::{short_number, Error, Result};
use crate::raster::{Mosaic, RgbImage};
use crate::sampler::{self, SampleBuffers};
use crate::seed;
use crate::spectral::{Grid, Spd};
use aberration::LateralAberration;
use colour::{ColourConfig, ColourTransform};
use demosaic::DemosaicMethod;
use in_camera::InCamera;
use noise::NoiseParams;
use optics::{ChartGlow, VeilingGlare};
use scene::UnevenLighting;
use sensor::{AutoExposure, Sensitivities, SensorConfig, SensorMode, SpectralResponse};
use serde::{Deserialize, Serialize};
use tone::ToneRendering;
use white_balance::{RegionGeometry, WhiteBalance};

/// The largest exposure (fraction of full scale the brightest raw value is scaled to):
/// above 1 the brightest patches clip; at 100 every patch brighter than 1 % of the
/// brightest does, beyond which a photo holds nothing more.
pub const MAX_EXPOSURE: f64 = 100.0;

/// The smallest exposure: the brightest raw value (a chart's white patch) at 1 % of full
/// scale, 2.6 levels of an 8-bit photo, about what the thesis's noise preset leaves of a
/// signal (its read noise is 0.4 % of full scale). Below it the photo holds no signal: the
/// patches are noise and quantisation steps, and the white balance divides by them.
pub const MIN_EXPOSURE: f64 = 0.01;

/// Every setting of the camera, one field per stage; `None` switches a stage off.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CameraConfig {
    /// Sensor layout (single Bayer sensor or three sensors) and exposure.
    pub sensor: SensorConfig,
    /// Sensor noise; `None`: noise-free.
    pub noise: Option<NoiseParams>,
    /// Used with a single sensor only.
    pub demosaic: DemosaicMethod,
    /// How the white-balance gains are estimated.
    pub white_balance: WhiteBalance,
    /// Which image the white-balance statistics are taken from.
    pub white_balance_statistics: WhiteBalanceStatistics,
    /// Lateral chromatic aberration; `None`: none.
    pub aberration: Option<LateralAberration>,
    /// Colour correction to sRGB and the output bit depth.
    pub colour: ColourConfig,
    /// The JPEG camera's own rendering (auto exposure, partial white balance, tone curve…);
    /// `None` (the default) renders as the thesis did.
    #[serde(default)]
    pub in_camera: Option<InCamera>,
}

/// The image white balance estimates the light from; the gains are always applied to the
/// demosaiced image.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum WhiteBalanceStatistics {
    /// The raw mosaic binned into 2×2 cells (R, mean of the two G, B), as camera ISPs
    /// gather AWB statistics: free of demosaicing overshoot, so the patch-level path gives
    /// the same gains.
    #[default]
    BinnedRaw,
    /// The demosaiced image, as the thesis did: Menon's overshoot at sharp patch edges
    /// enters the estimate.
    Demosaiced,
}

impl std::str::FromStr for WhiteBalanceStatistics {
    type Err = Error;

    /// Parses `raw` ([`WhiteBalanceStatistics::BinnedRaw`]) or `demosaiced`.
    fn from_str(text: &str) -> Result<WhiteBalanceStatistics> {
        match text.to_ascii_lowercase().as_str() {
            "raw" => Ok(WhiteBalanceStatistics::BinnedRaw),
            "demosaiced" => Ok(WhiteBalanceStatistics::Demosaiced),
            _ => Err(Error::UnknownName {
                kind: "white-balance statistics",
                name: text.to_string(),
                valid: "raw, demosaiced".into(),
            }),
        }
    }
}

impl Default for CameraConfig {
    /// The thesis's camera: RGGB, thesis noise, Menon 2007, shades of grey (p = 6),
    /// aberration 20/4000, D65-fitted colour matrix, 8-bit sRGB.
    fn default() -> Self {
        CameraConfig {
            sensor: SensorConfig::default(),
            noise: Some(NoiseParams::THESIS),
            demosaic: DemosaicMethod::Menon2007,
            white_balance: WhiteBalance::default(),
            white_balance_statistics: WhiteBalanceStatistics::default(),
            aberration: Some(LateralAberration::THESIS),
            colour: ColourConfig::default(),
            in_camera: None,
        }
    }
}

/// A camera looking at one chart: everything that does not depend on the light is
/// precomputed here (spectral response, region map, D65 colour matrix).
#[derive(Debug, Clone)]
pub struct Camera {
    config: CameraConfig,
    grid: Grid,
    camera_name: String,
    chart: Chart,
    response: SpectralResponse,
    /// The raw response of a perfect white diffuser per unit of light in each band:
    /// `white[channel·bands + band] = S_channel(λ)·Δλ`.
    white: Vec<f32>,
    region_map: Vec<u16>,
    /// Each region's centre across the chart, for the lighting gradient.
    region_centres: Vec<[f32; 2]>,
    geometry: RegionGeometry,
    camera_to_xyz: Option<nalgebra::Matrix3<f64>>,
    colour: ColourTransform,
}

/// Reusable buffers for rendering, so a loop over many lights allocates nothing per sample.
#[derive(Debug, Clone)]
pub struct RenderBuffers {
    raw: Vec<[f32; 3]>,
    mosaic: Mosaic,
    /// The final image after [`Camera::render_into`]: encoded sRGB, quantised, on 0…1.
    pub image: RgbImage,
    scratch: Vec<f32>,
    binned: RgbImage,
    region: aberration::RegionPlanes,
    samples: SampleBuffers,
}

/// The intermediate images of one render, for inspection (`--stages`).
#[derive(Debug, Clone, Default)]
pub struct Stages {
    /// The mosaic after noise (single sensor only), normalised raw.
    pub cfa: Option<Mosaic>,
    /// The image after demosaicing (linear camera RGB).
    pub demosaiced: Option<RgbImage>,
    /// The image after white balance (linear camera RGB).
    pub white_balanced: Option<RgbImage>,
    /// The image after lateral chromatic aberration, when that stage is on.
    pub aberrated: Option<RgbImage>,
}

/// One rendered chart: the final sRGB image (0…1, quantised), its features, its stages.
#[derive(Debug, Clone)]
pub struct Rendering {
    /// The final image: encoded sRGB, quantised, on 0…1.
    pub image: RgbImage,
    /// The features of the image ([`Camera::features`]): robust mean encoded sRGB, 0–255.
    pub features: Vec<f32>,
    /// The intermediate images, when asked for.
    pub stages: Stages,
    /// The gains (R, G, B) white balance applied to the camera signal.
    pub white_balance_gains: [f32; 3],
}

/// A scene photographed by [`Camera::develop`].
#[derive(Debug, Clone)]
pub struct Developed {
    /// The final image: encoded sRGB, quantised, on 0…1.
    pub image: RgbImage,
    /// The sensor's mosaic with its noise, before any processing (normalised raw, 1 = full
    /// scale): what a raw file holds. A three-sensor camera has none.
    pub mosaic: Option<Mosaic>,
    /// The gains (R, G, B) white balance applied to the camera signal.
    pub white_balance_gains: [f32; 3],
}

impl Camera {
    /// Builds a camera for `chart` (reflectances on `grid`) from `sensitivities` (on `grid`).
    /// Fits the colour matrix under CIE D65 on the chart's patches (noise-free, patch level).
    pub fn new(
        sensitivities: &Sensitivities,
        chart: Chart,
        config: CameraConfig,
        grid: &Grid,
    ) -> Result<Camera> {
        if let Some(noise) = &config.noise {
            noise.validate()?;
        }
        let exposure = config.sensor.exposure;
        if !(exposure > 0.0 && exposure <= MAX_EXPOSURE) {
            return Err(Error::invalid(format!(
                "exposure {} is outside (0, {MAX_EXPOSURE}]: a fraction of full scale, above \
                 1 the brightest patches clip",
                crate::error::short_number(exposure)
            )));
        }
        if exposure < MIN_EXPOSURE {
            return Err(Error::invalid(too_low_exposure(exposure)));
        }
        if let Some(ic) = &config.in_camera {
            ic.validate()?;
        }
        if chart.reflectances.len() >= u16::MAX as usize {
            return Err(Error::invalid("a chart may have at most 65534 patches"));
        }
        let response = SpectralResponse::new(sensitivities, &chart, grid)?;
        let white: Vec<f32> = (0..3)
            .flat_map(|c| sensitivities.curves.item(c).iter())
            .map(|&s| (s * grid.step_nm) as f32)
            .collect();
        let region_map = chart.layout.region_map();
        let region_centres = chart.layout.region_centres();
        let geometry =
            RegionGeometry::from_region_map(&region_map, chart.layout.width, response.regions());
        let mut camera = Camera {
            config,
            grid: *grid,
            camera_name: sensitivities.name.clone(),
            chart,
            response,
            white,
            region_map,
            region_centres,
            geometry,
            camera_to_xyz: None,
            colour: ColourTransform::new(None, config.colour.bit_depth)?,
        };
        if config.colour.correction {
            let t = camera.fit_d65_matrix()?;
            camera.camera_to_xyz = Some(t);
            camera.colour = ColourTransform::new(Some(t), config.colour.bit_depth)?;
        }
        Ok(camera)
    }

    /// The stages' settings of a shot with the in-camera record `ic` ([`Shot::of`]); without
    /// one, the thesis's camera, which puts its brightest value at the configured exposure
    /// of full scale and so clips only an exposure above 1.
    fn shot(&self, ic: Option<&InCamera>) -> Shot {
        let mut shot = Shot::of(ic);
        if ic.is_none() && self.config.sensor.exposure > 1.0 {
            shot.full_scale = 1.0;
        }
        shot
    }

    /// Thesis 3.1.6: white-balanced camera RGB of every patch under D65 against the
    /// patches' XYZ under D65 (perfect white Y = 1).
    fn fit_d65_matrix(&self) -> Result<nalgebra::Matrix3<f64>> {
        let d65 = StandardIlluminant::D65.spd(&self.grid)?;
        let light = self.light(&d65)?;
        let mut balanced = Vec::new();
        // The matrix is the factory calibration: fitted without the in-camera rendering.
        self.balanced_regions(&Shot::of(None), &light, &mut balanced);
        let observer = Observer::cie1931(&self.grid)?;
        let patches = self.chart.reflectances.len();
        let rgb: Vec<[f64; 3]> = balanced[..patches]
            .iter()
            .map(|v| v.map(|x| x as f64))
            .collect();
        let xyz: Vec<[f64; 3]> = (0..patches)
            .map(|p| observer.reflectance_to_xyz(self.chart.reflectances.item(p), &d65))
            .collect();
        colour::fit_correction_matrix(&rgb, &xyz)
    }

    /// The settings.
    pub fn config(&self) -> &CameraConfig {
        &self.config
    }

    /// The chart.
    pub fn chart(&self) -> &Chart {
        &self.chart
    }

    /// The simulation grid.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The camera's name.
    pub fn camera_name(&self) -> &str {
        &self.camera_name
    }

    /// About how many bytes this camera holds (its chart's pixel map, geometry and
    /// reflectances, its spectral response), to bound a pool of many cameras before it is
    /// built ([`crate::limits::CAMERA_POOL_BYTES`]).
    pub fn held_bytes(&self) -> u64 {
        let bands = self.grid.count;
        let regions = self.region_centres.len();
        let patches = self.chart.reflectances.len();
        let bytes = std::mem::size_of::<Camera>()
            + self.region_map.len() * std::mem::size_of::<u16>()
            + regions * std::mem::size_of::<[f32; 2]>()
            + self.geometry.areas.len() * std::mem::size_of::<f64>()
            + self.geometry.boundaries.len() * std::mem::size_of::<(usize, usize, f64)>()
            + patches * (bands * std::mem::size_of::<f64>() + std::mem::size_of::<String>())
            + self.chart.feature_patches.len() * std::mem::size_of::<usize>()
            + (regions + 1) * 3 * bands * std::mem::size_of::<f32>();
        bytes as u64
    }

    /// The D65-fitted camera RGB → XYZ matrix, if colour correction is on.
    pub fn correction_matrix(&self) -> Option<nalgebra::Matrix3<f64>> {
        self.camera_to_xyz
    }

    /// Checks an SPD and converts it for rendering: it must be on the simulation grid,
    /// finite, non-negative and give the camera a signal.
    pub fn light(&self, spd: &Spd) -> Result<Vec<f32>> {
        let spd = spd.on(&self.grid, "the camera")?;
        if let Some((i, v)) = spd
            .iter()
            .enumerate()
            .find(|(_, v)| !v.is_finite() || **v < 0.0)
        {
            return Err(Error::invalid(format!(
                "the SPD is {} at {} nm; it must be finite and non-negative",
                short_number(*v),
                self.grid.wavelength(i)
            )));
        }
        if spd.iter().all(|&v| v == 0.0) {
            return Err(Error::invalid(
                "the SPD is zero everywhere: there is no light",
            ));
        }
        let light: Vec<f32> = spd.iter().map(|&v| v as f32).collect();
        let mut raw = Vec::new();
        self.response.raw_into(&light, &mut raw);
        if raw.iter().flatten().all(|&v| v <= 0.0) {
            return Err(Error::invalid(
                "the light gives this camera no signal (no power where the camera is sensitive)",
            ));
        }
        Ok(light)
    }

    /// Fresh buffers sized for this camera's images.
    pub fn buffers(&self) -> RenderBuffers {
        let l = &self.chart.layout;
        self.buffers_sized(l.width, l.height)
    }

    /// Fresh buffers for images of `width × height` pixels.
    fn buffers_sized(&self, width: usize, height: usize) -> RenderBuffers {
        let pattern = match self.config.sensor.mode {
            SensorMode::SingleSensor(p) => p,
            SensorMode::ThreeSensor => crate::raster::CfaPattern::Rggb,
        };
        RenderBuffers {
            raw: Vec::new(),
            mosaic: Mosaic::new(width, height, pattern),
            image: RgbImage::new(width, height),
            scratch: Vec::new(),
            binned: RgbImage::new(width / 2, height / 2),
            region: aberration::RegionPlanes::default(),
            samples: SampleBuffers::default(),
        }
    }

    /// Exposed raw values of every region under `light` (into `raw`): the spectral
    /// response, the scene's uneven lighting, the optics' glare, and the sensor's exposure
    /// (with clipping at full scale when the shot meters automatically).
    fn exposed_regions(&self, shot: &Shot, light: &[f32], raw: &mut Vec<[f32; 3]>) {
        self.lit_regions(shot, light, raw);
        let scale = self.exposure_scale(shot, raw);
        expose(raw, scale, shot.full_scale);
    }

    /// Raw values of every region under `light` before exposure (into `raw`): the
    /// spectral response, the scene's uneven lighting and the optics' glare.
    fn lit_regions(&self, shot: &Shot, light: &[f32], raw: &mut Vec<[f32; 3]>) {
        self.response.raw_into(light, raw);
        let patches = self.chart.reflectances.len();
        shot.lighting.apply(raw, &self.region_centres);
        shot.glare.apply(raw, patches, &self.region_centres);
    }

    /// The exposure's scale for lit region values: the shot's metering, or the camera's
    /// fixed exposure of the brightest value.
    fn exposure_scale(&self, shot: &Shot, raw: &[[f32; 3]]) -> f32 {
        let patches = self.chart.reflectances.len();
        shot.auto_exposure
            .and_then(|exposure| exposure.scale(raw, patches))
            .unwrap_or_else(|| {
                sensor::exposure_scale(
                    raw,
                    self.chart.layout.shows_background(),
                    self.config.sensor.exposure,
                )
            })
    }

    /// The chart's exposed raw values per region (patches, then the background; 1 = full
    /// scale) under each of `spds`, all at the exposure the first light gives: the scene a
    /// photo of the chart is composed from ([`crate::photo::scene`]), a second light lighting
    /// part of the chart as the camera metered the first.
    pub fn exposed_chart(&self, spds: &[&Spd]) -> Result<Vec<Vec<[f32; 3]>>> {
        Ok(self.exposed_chart_at(spds, None)?.0)
    }

    /// [`Camera::exposed_chart`] at the exposure `scale` another chart of the same photo
    /// was metered at (`None`: metered on the first light here), and that scale: the
    /// charts of one photo share its exposure, so their levels compare.
    pub fn exposed_chart_at(
        &self,
        spds: &[&Spd],
        scale: Option<f32>,
    ) -> Result<(Vec<Vec<[f32; 3]>>, f32)> {
        let shot = self.shot(self.config.in_camera.as_ref());
        let mut out: Vec<Vec<[f32; 3]>> = Vec::with_capacity(spds.len());
        for spd in spds {
            let light = self.light(spd)?;
            let mut raw = Vec::new();
            self.lit_regions(&shot, &light, &mut raw);
            out.push(raw);
        }
        let scale = match (scale, out.first()) {
            (Some(scale), _) => scale,
            (None, Some(first)) => self.exposure_scale(&shot, first),
            (None, None) => 1.0,
        };
        out.iter_mut()
            .for_each(|raw| expose(raw, scale, shot.full_scale));
        Ok((out, scale))
    }

    /// The raw camera RGB (1 = full scale, unclipped) a perfect white diffuser square to
    /// `spd` reads at the exposure `scale` ([`Camera::exposed_chart_at`] gives a photo's):
    /// the light as the sensor sees it at that exposure, before the shot's uneven lighting
    /// and glare. The virtual camera's absolute exposure rests on it
    /// ([`crate::photo::raw::dng::virtual_exposure`]).
    pub fn exposed_white(&self, spd: &Spd, scale: f32) -> Result<[f64; 3]> {
        let light = self.light(spd)?;
        let bands = light.len();
        let mut rgb = [0.0f64; 3];
        for (c, row) in self.white.chunks_exact(bands).enumerate() {
            rgb[c] = f64::from(scale)
                * row
                    .iter()
                    .zip(&light)
                    .map(|(&s, &l)| f64::from(s) * f64::from(l))
                    .sum::<f64>();
        }
        Ok(rgb)
    }

    /// Photographs a scene given as linear raw camera RGB at the sensor (exposed, 1 = full
    /// scale; any size): the sensor (mosaic and noise), demosaicing, white balance from the
    /// whole image with the shot's adaptation, aberration, the colour matrix and tone
    /// rendering, quantised at the camera's bit depth. The stages are those of
    /// [`Camera::render`]; the patch-level JPEG model is left out, for a scene photo is
    /// encoded by a real JPEG encoder afterwards.
    pub fn develop(&self, scene: &RgbImage, seed: u64) -> Developed {
        let shot = self.scene_shot();
        let mut buffers = self.buffers_sized(scene.width, scene.height);
        let full_scale = shot.full_scale;
        match self.config.sensor.mode {
            SensorMode::SingleSensor(_) => {
                sensor::sample_mosaic(scene, full_scale, &mut buffers.mosaic)
            }
            SensorMode::ThreeSensor => {
                for (plane, src) in buffers.image.planes.iter_mut().zip(&scene.planes) {
                    plane
                        .iter_mut()
                        .zip(src)
                        .for_each(|(v, &s)| *v = s.min(full_scale));
                }
            }
        }
        let gains = self.sense_and_balance(&shot, seed, &mut buffers, None);
        self.finish_image(&shot, &mut buffers, None);
        // Demosaicing read the noisy mosaic and left it in place.
        let mosaic = matches!(self.config.sensor.mode, SensorMode::SingleSensor(_))
            .then_some(buffers.mosaic);
        Developed {
            image: buffers.image,
            mosaic,
            white_balance_gains: gains,
        }
    }

    /// An exposed raw value as [`Camera::develop`] encodes it with white-balance `gains`
    /// (clipped at full scale, balanced, encoded sRGB on 0…1, unquantised): what a flat,
    /// noise-free patch of a scene photo shows.
    pub fn encode_exposed(&self, raw: [f32; 3], gains: [f32; 3]) -> [f32; 3] {
        let shot = self.scene_shot();
        let balanced = std::array::from_fn(|c| raw[c].min(shot.full_scale) * gains[c]);
        self.finish_pixel(&shot, balanced)
    }

    /// The configured shot without the patch-level JPEG model (scene photos are encoded by
    /// a real encoder).
    fn scene_shot(&self) -> Shot {
        let mut shot = self.shot(self.config.in_camera.as_ref());
        if let Some(rendering) = &mut shot.rendering {
            rendering.jpeg_quality = None;
        }
        shot
    }

    /// Patch-level white-balanced values (noise-free) into `raw`, used by the D65 fit and
    /// the fast path.
    fn balanced_regions(&self, shot: &Shot, light: &[f32], raw: &mut Vec<[f32; 3]>) {
        self.exposed_regions(shot, light, raw);
        self.balance_regions(shot, raw);
    }

    /// White balance of exposed region values in place: the gains the camera estimates from
    /// them, adapted as the shot adapts.
    fn balance_regions(&self, shot: &Shot, raw: &mut [[f32; 3]]) {
        let estimated = self
            .config
            .white_balance
            .gains_for_regions(raw, &self.geometry);
        let gains = white_balance::adapt(estimated, shot.adaptation);
        raw.iter_mut()
            .for_each(|v| *v = std::array::from_fn(|c| v[c] * gains[c]));
    }

    /// White-balanced camera RGB → encoded sRGB (0…1, unquantised): the colour matrix and
    /// the sRGB curve, through the shot's tone rendering when it has one.
    #[inline]
    fn finish_pixel(&self, shot: &Shot, rgb: [f32; 3]) -> [f32; 3] {
        match &shot.rendering {
            None => self.colour.encode_pixel(rgb),
            Some(tone) => tone.encode(&self.colour, self.colour.to_linear_srgb(rgb)),
        }
    }

    /// Runs the full pipeline for one light and returns the image, features and stages.
    pub fn render(&self, spd: &Spd, seed: u64, keep_stages: bool) -> Result<Rendering> {
        let light = self.light(spd)?;
        let mut buffers = self.buffers();
        let mut stages = Stages::default();
        let gains = self.render_into(
            &light,
            seed,
            &mut buffers,
            keep_stages.then_some(&mut stages),
        );
        let features = self.features(&buffers.image);
        Ok(Rendering {
            image: buffers.image,
            features,
            stages,
            white_balance_gains: gains,
        })
    }

    /// The full pipeline into reusable buffers (the final image lands in `buffers.image`);
    /// `light` must come from [`Camera::light`]. Returns the white-balance gains.
    pub fn render_into(
        &self,
        light: &[f32],
        seed: u64,
        buffers: &mut RenderBuffers,
        mut stages: Option<&mut Stages>,
    ) -> [f32; 3] {
        let shot = self.shot(self.config.in_camera.as_ref());
        let gains = self.capture_balanced(&shot, light, seed, buffers, stages.as_deref_mut());
        self.finish_image(&shot, buffers, stages);
        gains
    }

    /// The white-balanced image in `buffers.image` → aberration, the colour matrix and tone
    /// rendering, quantised.
    fn finish_image(&self, shot: &Shot, buffers: &mut RenderBuffers, stages: Option<&mut Stages>) {
        if let Some(ab) = &self.config.aberration {
            ab.apply(&mut buffers.image, &mut buffers.scratch);
        }
        if let Some(s) = stages {
            s.aberrated = Some(buffers.image.clone());
        }
        match shot.rendering {
            None => self.colour.apply(&mut buffers.image),
            Some(_) => {
                let [r, g, b] = &mut buffers.image.planes;
                for ((r, g), b) in r.iter_mut().zip(g.iter_mut()).zip(b.iter_mut()) {
                    let v = self
                        .finish_pixel(shot, [*r, *g, *b])
                        .map(|v| self.colour.quantise(v));
                    (*r, *g, *b) = (v[0], v[1], v[2]);
                }
            }
        }
    }

    /// The features [`Camera::render_into`] followed by [`Camera::features`] give, computed
    /// without aberrating and colour-transforming the pixels no feature samples (the stages
    /// after white balance act pixel by pixel). Appends to `out`.
    pub fn render_features_into(
        &self,
        light: &[f32],
        seed: u64,
        buffers: &mut RenderBuffers,
        out: &mut Vec<f32>,
    ) {
        self.render_features_with(self.config.in_camera.as_ref(), light, seed, buffers, out);
    }

    /// [`Camera::render_features_into`] with the in-camera stage `ic` in place of the
    /// configured one (domain randomisation draws one per sample).
    pub fn render_features_with(
        &self,
        ic: Option<&InCamera>,
        light: &[f32],
        seed: u64,
        buffers: &mut RenderBuffers,
        out: &mut Vec<f32>,
    ) {
        let shot = self.shot(ic);
        self.capture_balanced(&shot, light, seed, buffers, None);
        let RenderBuffers {
            image,
            region,
            samples,
            ..
        } = buffers;
        let layout = &self.chart.layout;
        for &p in &self.chart.feature_patches {
            let (x, y, side) = layout.sampling_region(p);
            let area = aberration::Region {
                x,
                y,
                width: side,
                height: side,
            };
            match &self.config.aberration {
                Some(ab) => ab.region(image, area, region),
                None => {
                    for (plane, src) in region.planes.iter_mut().zip(&image.planes) {
                        plane.clear();
                        for row in y..y + side {
                            let start = row * image.width + x;
                            plane.extend_from_slice(&src[start..start + side]);
                        }
                    }
                }
            }
            let [r, g, b] = &region.planes;
            samples.pixels.clear();
            samples
                .pixels
                .extend(r.iter().zip(g).zip(b).map(|((&r, &g), &b)| {
                    self.finish_pixel(&shot, [r, g, b])
                        .map(|v| self.colour.quantise(v))
                }));
            let (mean, _) = sampler::robust_mean(samples);
            out.extend(mean.map(|m| (255.0 * m) as f32));
        }
    }

    /// Sensor, noise, demosaicing and white balance into `buffers.image`; returns the gains.
    fn capture_balanced(
        &self,
        shot: &Shot,
        light: &[f32],
        seed: u64,
        buffers: &mut RenderBuffers,
        stages: Option<&mut Stages>,
    ) -> [f32; 3] {
        self.exposed_regions(shot, light, &mut buffers.raw);
        match self.config.sensor.mode {
            SensorMode::SingleSensor(_) => {
                sensor::form_mosaic(&self.region_map, &buffers.raw, &mut buffers.mosaic)
            }
            SensorMode::ThreeSensor => {
                sensor::form_three_sensor(&self.region_map, &buffers.raw, &mut buffers.image)
            }
        }
        self.sense_and_balance(shot, seed, buffers, stages)
    }

    /// The exposed signal in `buffers.mosaic` (one sensor) or `buffers.image` (three) →
    /// noise, demosaicing and white balance into `buffers.image`; returns the gains.
    fn sense_and_balance(
        &self,
        shot: &Shot,
        seed: u64,
        buffers: &mut RenderBuffers,
        mut stages: Option<&mut Stages>,
    ) -> [f32; 3] {
        let RenderBuffers {
            mosaic,
            image,
            binned,
            ..
        } = buffers;
        let mut from_raw = false;
        match self.config.sensor.mode {
            SensorMode::SingleSensor(_) => {
                if let Some(noise) = &self.config.noise {
                    noise::add_noise(&mut mosaic.data, mosaic.width, noise, seed);
                }
                if let Some(s) = stages.as_deref_mut() {
                    s.cfa = Some(mosaic.clone());
                }
                if self.config.white_balance_statistics == WhiteBalanceStatistics::BinnedRaw {
                    bin_mosaic(mosaic, binned);
                    from_raw = true;
                }
                demosaic::demosaic_into(mosaic, self.config.demosaic, image);
            }
            SensorMode::ThreeSensor => {
                if let Some(noise) = &self.config.noise {
                    for (c, plane) in image.planes.iter_mut().enumerate() {
                        noise::add_noise(plane, mosaic.width, noise, seed::derive(seed, c as u64));
                    }
                }
            }
        }
        if let Some(s) = stages.as_deref_mut() {
            s.demosaiced = Some(image.clone());
        }
        let estimated = self
            .config
            .white_balance
            .gains(if from_raw { binned } else { image });
        let gains = white_balance::adapt(estimated, shot.adaptation);
        white_balance::apply_gains(image, gains);
        if let Some(s) = stages {
            s.white_balanced = Some(image.clone());
        }
        gains
    }

    /// Features of a final image: the robust mean encoded sRGB (0–255) of each feature
    /// patch's central sampling region, by the sampler photos use ([`sampler`]),
    /// `p01_r, p01_g, p01_b, p02_r, …`.
    pub fn features(&self, image: &RgbImage) -> Vec<f32> {
        let layout = &self.chart.layout;
        let mut out = Vec::with_capacity(self.chart.feature_patches.len() * 3);
        let mut samples = SampleBuffers::default();
        let [r, g, b] = &image.planes;
        for &p in &self.chart.feature_patches {
            let (x0, y0, side) = layout.sampling_region(p);
            samples.pixels.clear();
            for y in y0..y0 + side {
                let row = y * image.width + x0..y * image.width + x0 + side;
                samples.pixels.extend(
                    r[row.clone()]
                        .iter()
                        .zip(&g[row.clone()])
                        .zip(&b[row])
                        .map(|((&r, &g), &b)| [r, g, b]),
                );
            }
            let (mean, _) = sampler::robust_mean(&mut samples);
            out.extend(mean.map(|m| (255.0 * m) as f32));
        }
        out
    }

    /// Noise-free features straight from patch-level values (no image, no demosaicing, no
    /// aberration, no quantisation): what [`Camera::render`] gives with noise off, up to
    /// quantisation, at a fraction of the cost. Appends to `out`.
    ///
    /// ```
    /// use spdcam_core::builtin;
    /// use spdcam_core::camera::sensor::Sensitivities;
    /// use spdcam_core::camera::{Camera, CameraConfig};
    /// use spdcam_core::chart::Chart;
    /// use spdcam_core::cie_illuminant::StandardIlluminant;
    /// use spdcam_core::spectral::Grid;
    ///
    /// let grid = Grid::SIMULATION;
    /// let table = &builtin::CAMERAS[0];
    /// let sensitivities = Sensitivities::new(table.name, &table.load()?, &grid)?;
    /// let chart = Chart::colorchecker24(&grid)?;
    /// let camera = Camera::new(&sensitivities, chart, CameraConfig::default(), &grid)?;
    /// let (mut raw, mut warm, mut cool) = (Vec::new(), Vec::new(), Vec::new());
    /// camera.features_fast(&camera.light(&StandardIlluminant::A.spd(&grid)?)?, &mut raw, &mut warm);
    /// camera.features_fast(&camera.light(&StandardIlluminant::D65.spd(&grid)?)?, &mut raw, &mut cool);
    /// assert_eq!(warm.len(), 72);
    /// // White balanced: the white patch (19) is near neutral under both lights, while the
    /// // blue patch (13) changes with the light.
    /// let white = |f: &[f32]| (f[54] - f[56]).abs();
    /// assert!(white(&warm) < 12.0 && white(&cool) < 12.0);
    /// assert_ne!(warm[36..39], cool[36..39]);
    /// # Ok::<(), spdcam_core::Error>(())
    /// ```
    pub fn features_fast(&self, light: &[f32], raw: &mut Vec<[f32; 3]>, out: &mut Vec<f32>) {
        self.features_fast_with(self.config.in_camera.as_ref(), light, raw, out);
    }

    /// The exposed raw camera RGB of every region under `light` (patches, then the
    /// background; 1 = full scale): what a raw file of the chart holds under the in-camera
    /// stage `ic`'s uneven lighting, glare and exposure, before any white balance, colour
    /// matrix or tone. Exposed as one who shoots raw for the light exposes: the stage's
    /// exposure, but never above [`RAW_BRIGHTEST`] for the chart's brightest patch value, so
    /// that no patch clips.
    pub fn raw_regions_with(&self, ic: Option<&InCamera>, light: &[f32], raw: &mut Vec<[f32; 3]>) {
        let shot = self.shot(ic);
        self.lit_regions(&shot, light, raw);
        let patches = self.chart.reflectances.len().min(raw.len());
        let brightest = raw[..patches]
            .iter()
            .flatten()
            .fold(0.0f32, |m, &v| m.max(v));
        let mut scale = self.exposure_scale(&shot, raw);
        if brightest > 0.0 {
            scale = scale.min(RAW_BRIGHTEST / brightest);
        }
        expose(raw, scale, shot.full_scale);
    }

    /// [`Camera::features_fast`] with the in-camera stage `ic` in place of the configured
    /// one (calibration and domain randomisation vary it per call).
    pub fn features_fast_with(
        &self,
        ic: Option<&InCamera>,
        light: &[f32],
        raw: &mut Vec<[f32; 3]>,
        out: &mut Vec<f32>,
    ) {
        let shot = self.shot(ic);
        self.balanced_regions(&shot, light, raw);
        self.finish_features(&shot, raw, out);
    }

    /// [`Camera::features_fast_with`] for a chart lit by `light` and, on the regions
    /// `second` marks (the chart's patches in its order; unmarked and later regions keep
    /// `light`), by `other`: one exposure, metered under the first light as in
    /// [`Camera::exposed_chart`], and one white balance from the chart as lit. Two lights
    /// in one photo, at patch level.
    pub fn features_fast_two_lights(
        &self,
        ic: Option<&InCamera>,
        light: &[f32],
        other: &[f32],
        second: &[bool],
        raw: &mut Vec<[f32; 3]>,
        out: &mut Vec<f32>,
    ) {
        let shot = self.shot(ic);
        self.lit_regions(&shot, light, raw);
        let scale = self.exposure_scale(&shot, raw);
        let mut by_other = Vec::new();
        self.lit_regions(&shot, other, &mut by_other);
        for ((v, o), &marked) in raw.iter_mut().zip(&by_other).zip(second) {
            if marked {
                *v = *o;
            }
        }
        expose(raw, scale, shot.full_scale);
        self.balance_regions(&shot, raw);
        self.finish_features(&shot, raw, out);
    }

    /// The feature patches of white-balanced region values, encoded on 0–255, appended to
    /// `out`.
    fn finish_features(&self, shot: &Shot, raw: &[[f32; 3]], out: &mut Vec<f32>) {
        for &p in &self.chart.feature_patches {
            let encoded = self.finish_pixel(shot, raw[p]);
            out.extend(encoded.map(|v| 255.0 * v));
        }
    }
}

/// The stages' settings for one shot, resolved from the camera's in-camera record (or one
/// drawn for this sample); without a record, the thesis's camera.
#[derive(Debug, Clone, Copy)]
struct Shot {
    lighting: UnevenLighting,
    glare: VeilingGlare,
    auto_exposure: Option<AutoExposure>,
    /// Raw values clip here: full scale (1) for a metering JPEG camera; the thesis's camera
    /// normalises to the brightest value and clips only an exposure above 1
    /// ([`Camera::shot`]).
    full_scale: f32,
    adaptation: f64,
    rendering: Option<ToneRendering>,
}

impl Shot {
    fn of(in_camera: Option<&InCamera>) -> Shot {
        match in_camera {
            None => Shot {
                lighting: UnevenLighting {
                    gradient: [0.0, 0.0],
                },
                glare: VeilingGlare {
                    share: 0.0,
                    glow: ChartGlow::OFF,
                },
                auto_exposure: None,
                full_scale: f32::INFINITY,
                adaptation: 1.0,
                rendering: None,
            },
            Some(ic) => Shot {
                lighting: ic.uneven_lighting(),
                glare: ic.glare(),
                auto_exposure: ic.auto_exposure(),
                full_scale: 1.0,
                adaptation: ic.adaptation,
                rendering: Some(ic.rendering()),
            },
        }
    }
}

/// The highest raw value (share of full scale) [`Camera::raw_regions_with`] exposes a
/// chart's patch to: below clipping with room for the sensor's noise.
pub const RAW_BRIGHTEST: f32 = 0.9;

/// Scales raw values by the exposure's `scale` and clips them at `full_scale`.
/// Why an exposure under [`MIN_EXPOSURE`] is refused, for a message that names the option
/// it came from: "exposure 1e-10 puts the white patch …".
pub fn too_low_exposure(exposure: f64) -> String {
    let percent = 100.0 * exposure;
    // Three significant digits: 1e-8 %, not 1.0000000000000001e-8 %.
    let digits = 10f64.powi(2 - percent.abs().log10().floor() as i32);
    let percent = if digits.is_finite() {
        (percent * digits).round() / digits
    } else {
        percent
    };
    format!(
        "exposure {} puts the chart's white patch (its brightest) at {}% of full scale, \
         under the {}% a photo needs to hold a signal above the noise and the quantisation \
         steps; use {MIN_EXPOSURE}–{MAX_EXPOSURE} (e.g. 0.8; above 1 the brightest patches \
         clip)",
        crate::error::short_number(exposure),
        crate::error::short_number(percent),
        crate::error::short_number(100.0 * MIN_EXPOSURE),
    )
}

fn expose(raw: &mut [[f32; 3]], scale: f32, full_scale: f32) {
    raw.iter_mut()
        .for_each(|v| *v = v.map(|x| (x * scale).min(full_scale)));
}

/// Mean raw value of the first `patches` regions (the chart's patches, before the
/// background).
pub(crate) fn patch_mean(raw: &[[f32; 3]], patches: usize) -> [f32; 3] {
    let n = patches.min(raw.len()).max(1);
    std::array::from_fn(|c| raw[..n].iter().map(|v| v[c]).sum::<f32>() / n as f32)
}

/// Bins a mosaic into 2×2 cells, each giving (R, mean of the two G, B); odd edges dropped.
fn bin_mosaic(mosaic: &Mosaic, out: &mut RgbImage) {
    let (w, h) = (mosaic.width / 2, mosaic.height / 2);
    if (out.width, out.height) != (w, h) {
        *out = RgbImage::new(w, h);
    }
    let p = mosaic.pattern;
    for y in 0..h {
        for x in 0..w {
            let mut rgb = [0.0f32; 3];
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let (mx, my) = (2 * x + dx, 2 * y + dy);
                rgb[p.channel_at(mx, my)] += mosaic.get(mx, my);
            }
            let i = y * w + x;
            out.planes[0][i] = rgb[0];
            out.planes[1][i] = rgb[1] / 2.0;
            out.planes[2][i] = rgb[2];
        }
    }
}
