//! Scene photos in the trust report: the chart in a cluttered scene, found, sampled and
//! estimated like a user's photo, clean and made bad four ways.

use crate::error::{EvalError, Result};
use crate::held_out::{Setup, GRID};
use crate::trust::shots::{GLARE_LEVEL, GLARE_WIDTH};
use rand::rngs::SmallRng;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use spdcam_core::builtin::DataDir;
use spdcam_core::camera::optics::Glow;
use spdcam_core::camera::CameraConfig;
use spdcam_core::chart::{Chart, KnownChart};
use spdcam_core::dataset::randomise::camera_pool;
use spdcam_core::light_families::validation_split::LampPart;
use spdcam_core::photo::scene::{self, SceneLight, SceneOptions};
use spdcam_core::photo::ChartTemplate;
use spdcam_core::seed;
use spdcam_core::spectral::SpectralSet;
use spdcam_infer::trust::{TrustCalibration, Verdict};
use spdcam_infer::PhotoOptions;
use spdcam_infer::{Estimator, Model, ModelSet, NamedModel};

/// Scene photos per kind in [`scene_verdicts`].
pub const SCENES: usize = 20;

/// The chart as photos show it for `model_chart` (the SG's 96 patches are read from the
/// whole 140-patch chart).
pub(crate) fn photo_chart(model_chart: &str) -> &str {
    match KnownChart::from_name(model_chart).and_then(KnownChart::physical) {
        Some(physical) => physical.name(),
        None => model_chart,
    }
}

/// `model` as a user's photo meets it, looking for `photo_chart` only: its estimator (judged
/// by `calibration` when given, else by the shipped calibration made for the model, if any)
/// and the options of every photo.
fn user_estimator(
    model: &Model,
    photo_chart: &str,
    data_dir: &DataDir,
    calibration: Option<&TrustCalibration>,
) -> Result<(Estimator, PhotoOptions)> {
    let estimator = match calibration {
        Some(cal) => Estimator::calibrated(
            NamedModel {
                name: "model".to_string(),
                model: model.clone(),
            },
            cal.clone(),
            data_dir.clone(),
            model.grid(),
        )?,
        None => Estimator::new(
            ModelSet::single(model.clone(), "model"),
            data_dir.clone(),
            model.grid(),
        )?,
    };
    let options = PhotoOptions {
        chart: Some(photo_chart.to_string()),
        ..PhotoOptions::default()
    };
    Ok((estimator, options))
}

/// The scenes of the trust protocols: 1200×900 pixels, everything else as `spdcam render
/// --scene` draws it.
pub(crate) fn scene_options() -> SceneOptions {
    SceneOptions {
        width: 1200,
        height: 900,
        ..SceneOptions::default()
    }
}

/// Scene photos (the code of `spdcam render --scene`: the chart placed in a cluttered scene
/// with perspective, blur, vignetting, noise and JPEG) of [`SCENES`] test lamps, each by a
/// held-out camera, found, sampled and estimated like a user's photo: clean, of another
/// chart (the non-grey patches in another order), the right half of the chart lit by
/// another lamp (one exposure and white balance, or each half its own), and with glare.
/// Per kind: the share not `ok` (or refused: no chart found), and the share the self-check
/// flags.
pub fn scene_verdicts(
    model: &Model,
    cal: &TrustCalibration,
    model_chart: &str,
    setup: &Setup,
    data_dir: &DataDir,
    seed: u64,
) -> Result<[(f64, f64); 5]> {
    let name = photo_chart(model_chart);
    let chart = Chart::resolve(name, None, data_dir, &GRID)?;
    let template = ChartTemplate::from_chart(&chart)?;
    let chart = chart.with_layout(scene::scene_layout(&template))?;
    let mut wrong = chart.clone();
    let movable: Vec<usize> = chart
        .feature_patches
        .iter()
        .copied()
        .filter(|p| template.neutrals.iter().all(|n| n.0 != *p))
        .collect();
    let mut order = movable.clone();
    order.shuffle(&mut SmallRng::seed_from_u64(seed));
    let mut items: Vec<Vec<f64>> = chart.reflectances.items().to_vec();
    for (&to, &from) in movable.iter().zip(&order) {
        items[to] = chart.reflectances.item(from).to_vec();
    }
    wrong.reflectances = SpectralSet::on_grid(&GRID, chart.reflectances.names().to_vec(), items)?;
    let config = CameraConfig::default();
    let pool = camera_pool(&setup.cameras, 0, seed, &chart, config, &GRID)?;
    let wrong_pool = camera_pool(&setup.cameras, 0, seed, &wrong, config, &GRID)?;
    let ids = setup
        .library
        .positions(setup.split.lamps(LampPart::Test), "the split's test lamps")?;
    let (estimator, options) = user_estimator(model, name, data_dir, Some(cal))?;
    let plain = scene_options();
    let balanced = SceneOptions {
        balance_halves: true,
        ..plain.clone()
    };
    let glare = SceneOptions {
        glow: Some(Glow {
            level: GLARE_LEVEL,
            width: GLARE_WIDTH,
        }),
        ..plain.clone()
    };
    let mut counts = [(0usize, 0usize); 5];
    for i in 0..SCENES {
        let lamp = ids[i * ids.len() / SCENES];
        let other = ids[(i * ids.len() / SCENES + ids.len() / 2) % ids.len()];
        let k = i % pool.len();
        let shot_seed = seed::derive(seed, i as u64);
        let (spd, other_spd) = (&setup.library.spds[lamp], &setup.library.spds[other]);
        let half = SceneLight {
            spd,
            right_half: Some(other_spd),
        };
        let shots = [
            (&pool[k], SceneLight::single(spd), &plain),
            (&wrong_pool[k], SceneLight::single(spd), &plain),
            (&pool[k], half, &plain),
            (&pool[k], SceneLight::single(spd), &glare),
            (&pool[k], half, &balanced),
        ];
        for (kind, (camera, light, scene_options)) in shots.into_iter().enumerate() {
            let shot = scene::photograph(camera, light, shot_seed, scene_options)?;
            match estimator.estimate_photo_bytes(&shot.jpeg, "scene.jpg", &options) {
                Ok(e) => {
                    let t = e
                        .trust
                        .ok_or_else(|| EvalError::invalid("an estimate without a verdict"))?;
                    counts[kind].0 += usize::from(t.verdict != Verdict::Ok);
                    let flagged = t.self_check.as_ref().is_some_and(|s| cal.flags(s));
                    counts[kind].1 += usize::from(flagged);
                }
                Err(_) => {
                    counts[kind].0 += 1;
                    counts[kind].1 += 1;
                }
            }
        }
    }
    Ok(counts.map(|(n, f)| (n as f64 / SCENES as f64, f as f64 / SCENES as f64)))
}

/// Scene photos of one part's lamps, found and sampled like a user's photo.
pub struct SceneRows {
    /// Per photo found: the lamp's position among the part's lamps and its feature row
    /// (encoded sRGB, 0–255, the model's feature order).
    pub rows: Vec<(usize, Vec<f64>)>,
    /// Photos whose chart was not found (left out).
    pub refused: usize,
}

/// `per_lamp` scene photos of each of the lamps `part` of the split (the code of `spdcam
/// render --scene`: 1200×900 pixels, the chart in a cluttered scene with perspective,
/// blur, vignetting and the default camera stage — Bayer mosaic, noise, demosaicing, white
/// balance over the whole scene, colour matrix, tone, JPEG), each by the split's held-out
/// cameras in turn, then found and sampled as `model`'s estimator finds and samples a
/// user's photo. In parallel; each photo seeded from `seed` and its number.
pub fn scene_rows(
    model: &Model,
    model_chart: &str,
    setup: &Setup,
    part: LampPart,
    per_lamp: usize,
    data_dir: &DataDir,
    seed: u64,
) -> Result<SceneRows> {
    use rayon::prelude::*;
    let name = photo_chart(model_chart);
    let chart = Chart::resolve(name, None, data_dir, &GRID)?;
    let template = ChartTemplate::from_chart(&chart)?;
    let chart = chart.with_layout(scene::scene_layout(&template))?;
    let pool = camera_pool(
        &setup.cameras,
        0,
        seed,
        &chart,
        CameraConfig::default(),
        &GRID,
    )?;
    let ids = setup
        .library
        .positions(setup.split.lamps(part), "the split's lamps")?;
    let (estimator, options) = user_estimator(model, name, data_dir, None)?;
    let scene_options = scene_options();
    let found: Vec<Option<(usize, Vec<f64>)>> = (0..ids.len() * per_lamp)
        .into_par_iter()
        .map(|g| {
            let lamp = g / per_lamp;
            let spd = &setup.library.spds[ids[lamp]];
            let shot = scene::photograph(
                &pool[g % pool.len()],
                SceneLight::single(spd),
                seed::derive(seed, g as u64),
                &scene_options,
            )?;
            let photo = spdcam_core::photo::decode_photo(&shot.jpeg, "scene.jpg")?;
            Ok(estimator.analyse_decoded(&photo, &options).ok().map(|a| {
                (
                    lamp,
                    a.analysis.features.iter().map(|&v| f64::from(v)).collect(),
                )
            }))
        })
        .collect::<Result<_>>()?;
    let refused = found.iter().filter(|f| f.is_none()).count();
    Ok(SceneRows {
        rows: found.into_iter().flatten().collect(),
        refused,
    })
}
