//! The colour protocol's photos, each estimated and scored: (a) scene photos (the code of
//! `spdcam render --scene`) found, sampled and estimated like a user's photo, and (b) the
//! patch-level photos of the randomised in-camera stage, estimated as feature rows.

use super::lights::Light;
use super::score::ColourScore;
use crate::error::{EvalError, Result};
use crate::held_out::{randomised_cameras, GRID};
use crate::trust::scenes::photo_chart;
use rayon::prelude::*;
use spdcam_core::builtin::DataDir;
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::{Camera, CameraConfig};
use spdcam_core::chart::Chart;
use spdcam_core::dataset::randomise::camera_pool;
use spdcam_core::photo::raw::dng::virtual_camera_dng;
use spdcam_core::photo::scene::{self, SceneLight, SceneOptions};
use spdcam_core::photo::ChartTemplate;
use spdcam_core::seed;
use spdcam_core::spectral::Spd;
use spdcam_core::spectral_error;
use spdcam_infer::measured_colour::RawColourCorrection;
use spdcam_infer::photo_options::PhotoOptions;
use spdcam_infer::trust::Verdict;
use spdcam_infer::{Estimate, Estimator, FeatureRows};

/// The DNG of a scene photo `shot` by `camera` under `spd`, as `spdcam render --scene -o
/// x.dng` writes it.
pub(crate) fn raw_scene(camera: &Camera, spd: &Spd, shot: &scene::ScenePhoto) -> Result<Vec<u8>> {
    let mosaic = shot
        .mosaic
        .as_ref()
        .ok_or_else(|| EvalError::invalid("a scene photo without a sensor mosaic"))?;
    Ok(virtual_camera_dng(camera, spd, mosaic, None)?)
}

/// Width and height of the scene photos: the trust report's scenes.
pub const SCENE_SIZE: (usize, usize) = (1200, 900);

/// One photo scored: refused, or the estimate's shape and colour against the truth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhotoScore {
    /// Which of the protocol's lights it shows.
    pub light: usize,
    /// Which of the held-out cameras took it (`None` for a baseline, which no camera takes).
    pub camera: Option<usize>,
    /// The scoring of the estimate; `None`: refused (no chart found).
    pub estimate: Option<Scored>,
}

/// One estimate scored against the truth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scored {
    /// GFC of the peak-normalised estimate against the truth on the model's wavelengths.
    pub gfc: f64,
    /// The light's colour against the truth's.
    pub colour: ColourScore,
    /// Judged `ok`.
    pub ok: bool,
    /// The estimate's CCT (K) and the half-width (K) of its calibrated 95 % interval, where
    /// the model has a calibration and the estimate a CCT.
    pub cct_interval: Option<(f64, f64)>,
    /// The estimate's own colour fidelity index (ANSI/IES TM-30 Rf), where it has one.
    pub rf: Option<f64>,
    /// The GFC the trust calibration expects of the estimate, where the model has one.
    pub expected_gfc: Option<f64>,
    /// The size (Δu′v′) of the bias a raw file's matrices have for a light of the estimate's
    /// shape ([`RawColourCorrection::bias`]): what the raw colour correction takes off.
    pub raw_bias: Option<f64>,
    /// The share of the model's wavelengths where the true SPD (peak 1) lies inside the
    /// estimate's calibrated 95 % band, where it has one.
    pub band95_held: Option<f64>,
}

impl Scored {
    /// Scores `estimate` of `light`: its SPD, its verdict and its CCT interval.
    pub fn of(estimate: &Estimate, light: &Light) -> Result<Scored> {
        let trust = estimate.trust.as_ref();
        let correction = RawColourCorrection::shipped()?;
        let uncertainty = trust.and_then(|t| t.uncertainty.as_ref());
        let band95_held = match uncertainty {
            Some(u) => {
                let truth = light
                    .spd
                    .resampled(estimate.spd.grid())?
                    .normalised_by_max();
                let (lower, upper) = (u.band95.lower.values(), u.band95.upper.values());
                let held = truth
                    .values()
                    .iter()
                    .enumerate()
                    .filter(|&(k, t)| lower[k] <= *t && *t <= upper[k])
                    .count();
                Some(held as f64 / truth.values().len().max(1) as f64)
            }
            None => None,
        };
        let half95 = uncertainty
            .and_then(|u| u.metrics.get("cct_k"))
            .map(|m| m.half95);
        Ok(Scored {
            ok: trust.is_some_and(|t| t.verdict == Verdict::Ok),
            cct_interval: estimate.metrics.cct_k.zip(half95),
            rf: estimate.metrics.tm30_rf,
            expected_gfc: uncertainty.map(|u| u.expected_gfc),
            raw_bias: RawColourCorrection::shape(&estimate.spd).ok().map(|shape| {
                let [u, v] = correction.bias(&shape);
                u.hypot(v)
            }),
            band95_held,
            ..Scored::spd(&estimate.spd, light)?
        })
    }

    /// Scores an SPD estimated for `light` without a verdict or intervals (a baseline).
    pub fn spd(spd: &Spd, light: &Light) -> Result<Scored> {
        let truth = light.spd.resampled(spd.grid())?.normalised_by_max();
        Ok(Scored {
            gfc: spectral_error::gfc_spd(&truth, &spd.normalised_by_max())?,
            colour: ColourScore::of(&light.spd, spd)?,
            ok: false,
            cct_interval: None,
            rf: None,
            expected_gfc: None,
            raw_bias: None,
            band95_held: None,
        })
    }
}

/// What a set of photos is taken with: the held-out cameras, the seed of the draws, and how
/// many photos of each light.
pub struct Shoot<'a> {
    /// The held-out cameras.
    pub cameras: &'a [Sensitivities],
    /// The lights, each with how many photos to take of it.
    pub lights: &'a [(Light, u64)],
    /// Seed of this set's draws.
    pub seed: u64,
    /// Scene photos are raw DNGs of the sensor's mosaic (the camera's matrices fitted under
    /// A and D65, its neutral under the light as shot), not JPEGs.
    pub raw: bool,
}

/// The estimator a light's photos are estimated by (the same for every light, or one told
/// the light's kind).
pub type EstimatorFor<'a> = dyn Fn(&Light) -> Result<Estimator> + Sync + 'a;

impl Shoot<'_> {
    /// The light of every photo, in order: each light as many times as it is photographed.
    fn jobs(&self) -> Vec<usize> {
        self.lights
            .iter()
            .enumerate()
            .flat_map(|(j, (_, n))| std::iter::repeat_n(j, *n as usize))
            .collect()
    }

    /// (a): each light photographed in a cluttered scene by a held-out camera (each camera
    /// in turn) with the default camera stage, then found, sampled and estimated by
    /// the estimator `estimator_for` gives for the light, like a user's photo of
    /// `model_chart`; in parallel, the same for a seed.
    pub fn scenes(
        &self,
        estimator_for: &EstimatorFor<'_>,
        model_chart: &str,
        data_dir: &DataDir,
    ) -> Result<Vec<PhotoScore>> {
        let name = photo_chart(model_chart);
        let chart = Chart::resolve(name, None, data_dir, &GRID)?;
        let template = ChartTemplate::from_chart(&chart)?;
        let chart = chart.with_layout(scene::scene_layout(&template))?;
        let config = CameraConfig::default();
        let pool = camera_pool(self.cameras, 0, self.seed, &chart, config, &GRID)?;
        let options = PhotoOptions {
            chart: Some(name.to_string()),
            ..PhotoOptions::default()
        };
        let scene_options = SceneOptions {
            width: SCENE_SIZE.0,
            height: SCENE_SIZE.1,
            ..SceneOptions::default()
        };
        self.jobs()
            .into_par_iter()
            .enumerate()
            .map(|(g, j)| {
                let light = &self.lights[j].0;
                let camera = &pool[g % pool.len()];
                let camera_index = g % pool.len();
                let shot_seed = seed::derive(self.seed, g as u64);
                let shot = scene::photograph(
                    camera,
                    SceneLight::single(&light.spd),
                    shot_seed,
                    &scene_options,
                )?;
                let estimator = estimator_for(light)?;
                let (bytes, name) = if self.raw {
                    (raw_scene(camera, &light.spd, &shot)?, "scene.dng")
                } else {
                    (shot.jpeg, "scene.jpg")
                };
                let estimate = match estimator.estimate_photo_bytes(&bytes, name, &options) {
                    Ok(e) => Some(Scored::of(&e, light)?),
                    Err(_) => None,
                };
                Ok(PhotoScore {
                    light: j,
                    camera: Some(camera_index),
                    estimate,
                })
            })
            .collect()
    }

    /// (b): each light through a held-out camera with the randomised in-camera stage
    /// (exposure, white balance, tone, JPEG, gradient; `lamps validate`'s (a)), patch level
    /// on `chart`, estimated as feature rows by the estimator `estimator_for` gives for each
    /// light (in parallel, all the photos of a light at once).
    pub fn patches(
        &self,
        estimator_for: &EstimatorFor<'_>,
        chart: &Chart,
    ) -> Result<Vec<PhotoScore>> {
        let randomisation = randomised_cameras(self.cameras, self.seed, chart)?;
        let names = chart.feature_names();
        let jobs = self.jobs();
        let mut values = Vec::with_capacity(jobs.len() * names.len());
        let (mut raw, mut out) = (Vec::new(), Vec::new());
        let mut taken_by = Vec::with_capacity(jobs.len());
        for (g, &j) in jobs.iter().enumerate() {
            let (camera, ic) = randomisation.draw(self.seed, g as u64);
            taken_by.push(
                self.cameras
                    .iter()
                    .position(|c| c.name == camera.camera_name()),
            );
            let light = camera.light(&self.lights[j].0.spd)?;
            out.clear();
            camera.features_fast_with(ic.as_ref(), &light, &mut raw, &mut out);
            values.extend(out.iter().map(|&v| f64::from(v)));
        }
        // The photos of a light are consecutive (see `jobs`): one block of rows per light.
        let width = names.len();
        let mut starts = Vec::with_capacity(self.lights.len());
        let mut first = 0;
        for (_, n) in self.lights {
            starts.push((first, *n as usize));
            first += *n as usize;
        }
        let scored = starts
            .par_iter()
            .enumerate()
            .map(|(j, &(first, n))| {
                let light = &self.lights[j].0;
                let block = values[first * width..(first + n) * width].to_vec();
                let rows =
                    FeatureRows::from_values(names.clone(), block, "the patch-level photos")?;
                let estimates =
                    estimator_for(light)?.estimate_rows(&rows, "the patch-level photos")?;
                if estimates.len() != n {
                    return Err(EvalError::invalid(format!(
                        "{} estimates for {n} patch-level photos",
                        estimates.len()
                    )));
                }
                estimates
                    .iter()
                    .zip(&taken_by[first..first + n])
                    .map(|(e, &camera)| {
                        Ok(PhotoScore {
                            light: j,
                            camera,
                            estimate: Some(Scored::of(e, light)?),
                        })
                    })
                    .collect::<Result<Vec<_>>>()
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(scored.concat())
    }
}
