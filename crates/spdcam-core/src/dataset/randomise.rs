//! Domain randomisation for `spdcam generate`: per sample, a camera drawn from a pool of
//! measured sensitivities (and perturbations of them) and in-camera parameters drawn from
//! ranges, so that a model learns what does not depend on one camera's processing.
//!
//! The pool is built once (each camera fits its colour matrix once); sample `i`'s draw
//! depends only on (seed, i).

use crate::builtin::DataDir;
use crate::camera::in_camera::InCamera;
use crate::camera::optics::ChartGlow;
use crate::camera::sensor::{Sensitivities, SkippedFiles};
use crate::camera::{Camera, CameraConfig};
use crate::chart::Chart;
use crate::error::{Error, Result};
use crate::light_families::ValidationSplit;
use crate::limits;
use crate::seed;
use crate::spectral::{Grid, SpectralSet};
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Stream of the per-sample randomisation draws (apart from the light's and the noise's).
const RANDOMISE_STREAM: u64 = 0x5241_4E44_0000_0001;
/// Stream of the camera perturbations.
const PERTURB_STREAM: u64 = 0x5045_5254_0000_0001;

/// The randomisation groups ([`InCameraRanges::for_groups`]) of a JPEG camera's own
/// processing: exposure, white balance, tone and JPEG.
pub const IN_CAMERA_GROUPS: [&str; 4] = ["exposure", "wb", "tone", "jpeg"];

/// [`IN_CAMERA_GROUPS`] and the light's gradient across the chart: the in-camera stage the
/// protocols over held-out lamps and the sim-to-real ablation's last rows draw from.
pub const IN_CAMERA_AND_GRADIENT_GROUPS: [&str; 5] = ["exposure", "wb", "tone", "jpeg", "gradient"];

/// Ranges `[low, high]` the in-camera parameters are drawn from, uniformly; a parameter
/// whose range is `None` keeps the base camera's value.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub struct InCameraRanges {
    /// Range of [`InCamera::exposure_target`] (fraction of full scale).
    pub exposure_target: Option<[f64; 2]>,
    /// Range of [`InCamera::flare`] (share of the patches' mean raw value).
    pub flare: Option<[f64; 2]>,
    /// Range of [`InCamera::adaptation`] (share of the white-balance correction).
    pub adaptation: Option<[f64; 2]>,
    /// Range of [`InCamera::saturation`] (1 = unchanged).
    pub saturation: Option<[f64; 2]>,
    /// Range of [`InCamera::shoulder`] (0 = hard clip).
    pub shoulder: Option<[f64; 2]>,
    /// Range of [`InCamera::gamma`] (1 = the sRGB curve alone).
    pub gamma: Option<[f64; 2]>,
    /// Range of [`InCamera::contrast`] (0 = none).
    pub contrast: Option<[f64; 2]>,
    /// Range of [`InCamera::jpeg_quality`] (1–100).
    pub jpeg_quality: Option<[u8; 2]>,
    /// Largest magnitude of each lighting-gradient component, drawn uniformly in ±it.
    #[serde(default)]
    pub gradient: Option<f64>,
    /// Range of [`InCamera::floor`] (share of full scale); left unwritten when not drawn,
    /// so that the records of runs without it read as before it existed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub floor: Option<[f64; 2]>,
    /// How often [`InCamera::glow`] is drawn and the range of its level; its centre is
    /// drawn anywhere on the chart and its width from [`GLOW_WIDTHS`]. Left unwritten when
    /// not drawn.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub glow: Option<GlowRange>,
}

/// The glows a randomised run draws: a share of the photos has one, of a level drawn
/// uniformly from `level`; the others have none (real photos either catch a lamp's glare
/// or do not).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GlowRange {
    /// Share of the photos with a glow (0–1).
    pub share: f64,
    /// Range of its level (share of the patches' mean raw value at its centre).
    pub level: [f64; 2],
}

/// The range of a drawn glow's width (share of the chart's extent): from a spot over a few
/// patches to a glow over half the chart.
pub const GLOW_WIDTHS: [f64; 2] = [0.1, 0.5];

impl InCameraRanges {
    /// Ranges for the named groups (`exposure`: exposure target and flare; `wb`:
    /// adaptation from half to full; `wb-wide`: adaptation from none to full; `tone`: saturation, shoulder, gamma, contrast; `jpeg`: JPEG quality;
    /// `gradient`: uneven lighting across the chart; `floor`: a black floor under the
    /// rendered values; `glow`: a glow of random place, size and strength on the chart),
    /// wide enough to cover the JPEG cameras
    /// and photo set-ups we know of.
    pub fn for_groups(groups: &[&str]) -> Result<InCameraRanges> {
        let mut r = InCameraRanges::default();
        for &g in groups {
            match g {
                "exposure" => {
                    r.exposure_target = Some([0.08, 0.45]);
                    r.flare = Some([0.0, 0.3]);
                }
                "wb" => r.adaptation = Some([0.5, 1.0]),
                // Real JPEG photos whose neutral patches keep most of the light's cast
                // (a white-balance adaptation near 0.3 in the Telelumen sets).
                "wb-wide" => r.adaptation = Some([0.0, 1.0]),
                "tone" => {
                    r.saturation = Some([0.6, 1.3]);
                    r.shoulder = Some([0.0, 0.4]);
                    r.gamma = Some([0.7, 1.3]);
                    r.contrast = Some([-0.4, 0.4]);
                }
                "jpeg" => r.jpeg_quality = Some([70, 98]),
                "gradient" => r.gradient = Some(0.5),
                // A black floor up to the Telelumen photos' darkest patch (about 0.15 of
                // full scale; the Hue photos' about 0.02).
                "floor" => r.floor = Some([0.0, 0.15]),
                // Up to the real Telelumen photos' glare: their blackest patch gains 0.52–0.66
                // of the chart's mean linear level (10th–90th percentile, at most 0.79) more
                // than the other dark patches (`docs/glow.md`, `tools/real_glare.py`).
                // Half the photos: the Hue photos show none.
                "glow" => {
                    r.glow = Some(GlowRange {
                        share: 0.5,
                        level: [0.0, 0.8],
                    })
                }
                other => {
                    return Err(Error::UnknownName {
                        kind: "randomisation group",
                        name: other.to_string(),
                        valid: "camera, exposure, wb, wb-wide, tone, jpeg, gradient, floor, glow"
                            .into(),
                    })
                }
            }
        }
        Ok(r)
    }

    /// Whether any parameter is drawn.
    pub fn is_empty(&self) -> bool {
        *self == InCameraRanges::default()
    }

    /// Draws the parameters, starting from `base` for those without a range.
    pub fn draw(&self, base: InCamera, rng: &mut SmallRng) -> InCamera {
        let mut u = |r: Option<[f64; 2]>, v: f64| match r {
            Some([lo, hi]) => lo + (hi - lo) * rng.random::<f64>(),
            None => v,
        };
        let exposure_target = match self.exposure_target {
            Some(r) => Some(u(Some(r), 0.0)),
            None => base.exposure_target,
        };
        let drawn = InCamera {
            exposure_target,
            flare: u(self.flare, base.flare),
            adaptation: u(self.adaptation, base.adaptation),
            saturation: u(self.saturation, base.saturation),
            shoulder: u(self.shoulder, base.shoulder),
            gamma: u(self.gamma, base.gamma),
            contrast: u(self.contrast, base.contrast),
            jpeg_quality: base.jpeg_quality,
            gradient: base.gradient,
            floor: u(self.floor, base.floor),
            glow: base.glow,
        };
        let drawn = match self.jpeg_quality {
            Some([lo, hi]) => InCamera {
                jpeg_quality: Some(rng.random_range(lo.min(hi)..=hi.max(lo))),
                ..drawn
            },
            None => drawn,
        };
        let drawn = match self.gradient {
            Some(g) => InCamera {
                gradient: [0, 1].map(|_| g * (2.0 * rng.random::<f64>() - 1.0)),
                ..drawn
            },
            None => drawn,
        };
        match self.glow {
            Some(GlowRange {
                share,
                level: [lo, hi],
            }) => {
                let on = rng.random::<f64>() < share;
                let level = lo + (hi - lo) * rng.random::<f64>();
                let at = [0, 1].map(|_| rng.random::<f64>() - 0.5);
                let [w0, w1] = GLOW_WIDTHS;
                let width = w0 + (w1 - w0) * rng.random::<f64>();
                if on {
                    InCamera {
                        glow: ChartGlow { level, at, width },
                        ..drawn
                    }
                } else {
                    drawn
                }
            }
            None => drawn,
        }
    }
}

/// A pool of cameras and the in-camera ranges one sample draws from.
#[derive(Debug, Clone)]
pub struct Randomisation {
    cameras: Vec<Camera>,
    ranges: InCameraRanges,
}

/// What the manifest records of a randomised run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RandomisationInfo {
    /// The pool's camera names (perturbed variants are named `NAME~k`).
    pub cameras: Vec<String>,
    /// The ranges the in-camera parameters were drawn from.
    pub in_camera: InCameraRanges,
    /// How each sample's camera and parameters derive from the seed, in words.
    pub seeding: String,
}

impl Randomisation {
    /// A pool of `cameras` (all photographing the same chart on the same grid) and the
    /// ranges; an empty pool is refused.
    pub fn new(cameras: Vec<Camera>, ranges: InCameraRanges) -> Result<Randomisation> {
        let first = cameras
            .first()
            .ok_or_else(|| Error::invalid("domain randomisation needs at least one camera"))?;
        for c in &cameras {
            if c.grid() != first.grid() || c.chart().name != first.chart().name {
                return Err(Error::invalid(format!(
                    "camera '{}' photographs {} on {}; the pool's first photographs {} on {}",
                    c.camera_name(),
                    c.chart().name,
                    c.grid(),
                    first.chart().name,
                    first.grid()
                )));
            }
        }
        for (name, range) in [
            ("exposure_target", ranges.exposure_target),
            ("flare", ranges.flare),
            ("adaptation", ranges.adaptation),
            ("saturation", ranges.saturation),
            ("shoulder", ranges.shoulder),
            ("gamma", ranges.gamma),
            ("contrast", ranges.contrast),
            ("floor", ranges.floor),
        ] {
            if let Some([lo, hi]) = range {
                let probe = |v: f64| {
                    let mut ic = InCamera::NEUTRAL;
                    match name {
                        "exposure_target" => ic.exposure_target = Some(v),
                        "flare" => ic.flare = v,
                        "adaptation" => ic.adaptation = v,
                        "saturation" => ic.saturation = v,
                        "shoulder" => ic.shoulder = v,
                        "gamma" => ic.gamma = v,
                        "floor" => ic.floor = v,
                        _ => ic.contrast = v,
                    }
                    ic.validate()
                };
                if lo > hi {
                    return Err(Error::invalid(format!(
                        "randomisation range of {name} [{lo}, {hi}] is empty"
                    )));
                }
                probe(lo)?;
                probe(hi)?;
            }
        }
        if let Some(GlowRange {
            share,
            level: [lo, hi],
        }) = ranges.glow
        {
            if !(0.0..=1.0).contains(&share) {
                return Err(Error::invalid(format!(
                    "randomisation share of photos with a glow {share} is outside [0, 1]"
                )));
            }
            if lo.is_nan() || hi.is_nan() || lo > hi {
                return Err(Error::invalid(format!(
                    "randomisation range of the glow's level [{lo}, {hi}] is empty"
                )));
            }
            for level in [lo, hi] {
                InCamera {
                    glow: ChartGlow {
                        level,
                        at: [0.5, 0.5],
                        width: GLOW_WIDTHS[1],
                    },
                    ..InCamera::NEUTRAL
                }
                .validate()?;
            }
        }
        if let Some(g) = ranges.gradient {
            InCamera {
                gradient: [g, g],
                ..InCamera::NEUTRAL
            }
            .validate()?;
        }
        Ok(Randomisation { cameras, ranges })
    }

    /// The pool.
    pub fn cameras(&self) -> &[Camera] {
        &self.cameras
    }

    /// The manifest's record.
    pub fn info(&self) -> RandomisationInfo {
        RandomisationInfo {
            cameras: self
                .cameras
                .iter()
                .map(|c| c.camera_name().to_string())
                .collect(),
            in_camera: self.ranges,
            seeding: "sample i: rng = SmallRng(seed::derive(seed::derive(seed, i), \
                      RANDOMISE_STREAM)); camera = pool[uniform index], then the in-camera \
                      parameters in declaration order, the lighting gradient (x, y) last"
                .to_string(),
        }
    }

    /// Sample `i`'s camera and in-camera stage (`None`: the camera's own configuration).
    pub fn draw(&self, seed: u64, i: u64) -> (&Camera, Option<InCamera>) {
        let mut rng =
            SmallRng::seed_from_u64(seed::derive(seed::derive(seed, i), RANDOMISE_STREAM));
        let camera = &self.cameras[rng.random_range(0..self.cameras.len())];
        if self.ranges.is_empty() {
            return (camera, None);
        }
        let base = camera.config().in_camera.unwrap_or(InCamera::NEUTRAL);
        (camera, Some(self.ranges.draw(base, &mut rng)))
    }
}

/// A smooth random perturbation of measured sensitivities: each channel shifted by up to
/// ±`shift_nm` and multiplied by `exp` of a sum of three Gaussian bumps of amplitude up to
/// ±`gain` (60 nm wide), deterministic in `seed`. Named `NAME~seed`.
pub fn perturb(
    camera: &Sensitivities,
    seed: u64,
    shift_nm: f64,
    gain: f64,
    grid: &Grid,
) -> Result<Sensitivities> {
    let mut rng = SmallRng::seed_from_u64(seed::derive(seed, PERTURB_STREAM));
    let w = grid.wavelengths();
    let mut curves = Vec::with_capacity(3);
    for c in 0..3 {
        let src = camera.curves.item(c);
        let shift = shift_nm * (2.0 * rng.random::<f64>() - 1.0);
        let bumps: Vec<(f64, f64)> = (0..3)
            .map(|_| {
                let centre = 400.0 + 300.0 * rng.random::<f64>();
                (centre, gain * (2.0 * rng.random::<f64>() - 1.0))
            })
            .collect();
        let curve: Vec<f64> = w
            .iter()
            .map(|&l| {
                let x = (l - shift - grid.start_nm) / grid.step_nm;
                let k = x.floor();
                let f = x - k;
                let at = |j: f64| {
                    if j < 0.0 || j as usize >= src.len() {
                        0.0
                    } else {
                        src[j as usize]
                    }
                };
                let v = (1.0 - f) * at(k) + f * at(k + 1.0);
                let m: f64 = bumps
                    .iter()
                    .map(|&(mu, a)| a * (-(l - mu).powi(2) / (2.0 * 30.0f64.powi(2))).exp())
                    .sum();
                v.max(0.0) * m.exp()
            })
            .collect();
        curves.push(curve);
    }
    let set = SpectralSet::on_grid(grid, vec!["r".into(), "g".into(), "b".into()], curves)?;
    Sensitivities::new(&format!("{}~{seed}", camera.name), &set, grid)
}

/// Builds the pool: each camera as measured and `variants` perturbed copies of it (shift up
/// to ±5 nm, gain up to ±10 %), each with `config` photographing `chart`. A camera the chart
/// cannot be fitted for (a degenerate colour matrix) is an error naming it.
pub fn camera_pool(
    sensitivities: &[Sensitivities],
    variants: usize,
    seed: u64,
    chart: &Chart,
    config: CameraConfig,
    grid: &Grid,
) -> Result<Vec<Camera>> {
    let mut pool = Vec::with_capacity(sensitivities.len() * (variants + 1));
    for (k, s) in sensitivities.iter().enumerate() {
        pool.push(Camera::new(s, chart.clone(), config, grid)?);
        for v in 0..variants {
            let p = perturb(s, seed::derive(seed, (k * 1000 + v) as u64), 5.0, 0.1, grid)?;
            pool.push(Camera::new(&p, chart.clone(), config, grid)?);
        }
    }
    Ok(pool)
}

/// The cameras `spec` names, comma-separated: each a directory (every sensitivity CSV in
/// it; the files that are not one come back as skipped, with why), a camera's name or a
/// file. A camera named twice is an error: it would be drawn twice as often.
fn pool_cameras(
    spec: &str,
    data_dir: &DataDir,
    grid: &Grid,
) -> Result<(Vec<Sensitivities>, SkippedFiles)> {
    let (mut sens, mut skipped) = (Vec::<Sensitivities>::new(), Vec::new());
    for part in spec.split(',').map(str::trim).filter(|n| !n.is_empty()) {
        let dir = Path::new(part);
        if dir.is_dir() {
            let (found, skip) = Sensitivities::in_dir(dir, data_dir, grid)?;
            sens.extend(found);
            skipped.extend(skip);
        } else {
            sens.push(Sensitivities::resolve(part, data_dir, grid)?);
        }
    }
    let mut names = std::collections::BTreeSet::new();
    if let Some(twice) = sens.iter().find(|s| !names.insert(s.name.as_str())) {
        return Err(Error::invalid(format!(
            "camera '{}' is in the camera pool twice (--cameras {spec}); name each camera and \
             directory once",
            twice.name
        )));
    }
    Ok((sens, skipped))
}

/// Perturbed copies of each camera in a pool unless a run asks for another number.
pub const DEFAULT_CAMERA_VARIANTS: usize = 3;

/// The randomisation a run asks for by name (`spdcam generate --randomise`, `--cameras`,
/// `--camera-split`, `--camera-variants`); by default none.
#[derive(Debug, Clone, PartialEq)]
pub struct RandomiseRequest {
    /// Groups: camera (draw the camera from `cameras`), exposure, wb (or wb-wide), tone,
    /// jpeg, floor (draw those in-camera parameters), gradient (uneven lighting); none: no
    /// randomisation.
    pub groups: Vec<String>,
    /// The cameras to draw from with `camera`: comma-separated directories of sensitivity
    /// CSVs, camera names or files.
    pub cameras: Option<String>,
    /// A validation split whose held-out cameras are left out of the pool.
    pub camera_split: Option<PathBuf>,
    /// Perturbed copies of each camera in the pool (with `camera`).
    pub camera_variants: usize,
}

impl Default for RandomiseRequest {
    fn default() -> Self {
        RandomiseRequest {
            groups: Vec::new(),
            cameras: None,
            camera_split: None,
            camera_variants: DEFAULT_CAMERA_VARIANTS,
        }
    }
}

/// What [`RandomiseRequest::build`] gives: the randomisation (none when no group is asked
/// for) and the camera files of the `cameras` directory skipped as invalid, with why.
pub type BuiltRandomisation = (Option<Randomisation>, SkippedFiles);

impl RandomiseRequest {
    /// The randomisation asked for around the `base` camera: its pool built once (perturbed
    /// copies seeded with `seed`) photographing `chart` with `config`, and its ranges.
    pub fn build(
        &self,
        base: &Sensitivities,
        chart: &Chart,
        config: CameraConfig,
        seed: u64,
        data_dir: &DataDir,
        grid: &Grid,
    ) -> Result<BuiltRandomisation> {
        if self.groups.is_empty() {
            if self.cameras.is_some() || self.camera_split.is_some() {
                return Err(Error::invalid(
                    "--cameras and --camera-split need --randomise camera",
                ));
            }
            return Ok((None, Vec::new()));
        }
        let groups: Vec<&str> = self.groups.iter().map(|g| g.trim()).collect();
        let with_camera = groups.contains(&"camera");
        let others: Vec<&str> = groups.iter().copied().filter(|g| *g != "camera").collect();
        let ranges = InCameraRanges::for_groups(&others)?;
        let mut sens = vec![base.clone()];
        let mut skipped = Vec::new();
        let variants = if with_camera { self.camera_variants } else { 0 };
        // Each camera of the pool holds its own chart map: the pool is bounded before the
        // cameras are read (by one camera and its copies) and before it is built.
        let copies = (variants as u64).saturating_add(1);
        let per_camera = if with_camera {
            Camera::new(base, chart.clone(), config, grid)?.held_bytes()
        } else {
            0
        };
        let pool_bytes = |cameras: usize| {
            let bytes = limits::product(&[cameras as u64, copies, per_camera]);
            limits::CAMERA_POOL_BYTES.check(
                bytes,
                &format!(
                    "--camera-variants {variants}: {cameras} camera(s) and {variants} perturbed \
                     copies of each, about {} kB each (lower --camera-variants)",
                    per_camera.div_ceil(1000)
                ),
            )
        };
        if with_camera {
            pool_bytes(1)?;
            let spec = self.cameras.as_deref().ok_or_else(|| {
                Error::invalid("--randomise camera needs --cameras DIR or a list")
            })?;
            (sens, skipped) = pool_cameras(spec, data_dir, grid)?;
        }
        if let Some(path) = &self.camera_split {
            let split = ValidationSplit::read(path)?;
            sens.retain(|s| split.allows_training_camera(&s.name));
            if sens.is_empty() {
                return Err(Error::invalid(format!(
                    "every camera of the pool is held out by {}",
                    path.display()
                )));
            }
        }
        pool_bytes(sens.len())?;
        let pool = camera_pool(&sens, variants, seed, chart, config, grid)?;
        Ok((Some(Randomisation::new(pool, ranges)?), skipped))
    }
}
