//! The trust calibration of a raw model (`spdcam trust calibrate --raw-model`): fitted on
//! raw scene photos (DNGs of the whole camera chain) of the split's validation lamps and of
//! smooth lights (Planckian radiators and CIE daylight) by its held-out cameras, each
//! estimated as a user's raw photo is (the chart's model finds and
//! checks the chart, the raw model reads the spectrum from the patches' XYZ through the
//! file's matrices). Its bands, expected GFC, metric intervals (the CCT and Duv among them,
//! of the light's colour as the matrices read it) and the self-check's levels on the
//! developed colours are all of raw photos.

use crate::colour::photos::raw_scene;
use crate::error::{EvalError, Result};
use crate::held_out::{on_grid, HeldOutPhotos, GRID};
use crate::trust::fit::{fit_calibration, Calibrated, CalibrationPhotos, Calibrations, PhotoKind};
use crate::trust::judged::Judged;
use crate::trust::scenes::{photo_chart, scene_options};
use rayon::prelude::*;
use spdcam_core::builtin::DataDir;
use spdcam_core::camera::CameraConfig;
use spdcam_core::chart::Chart;
use spdcam_core::cie_illuminant::{daylight, planck};
use spdcam_core::dataset::randomise::camera_pool;
use spdcam_core::light_families::validation_split::LampPart;
use spdcam_core::photo::scene::{self, SceneLight};
use spdcam_core::photo::ChartTemplate;
use spdcam_core::seed;
use spdcam_core::spectral::Spd;
use spdcam_infer::estimator::raw_row;
use spdcam_infer::trust::{self, Perturbed};
use spdcam_infer::{Estimate, Estimator, Model, ModelSet, NamedModel, PhotoOptions};
use std::path::PathBuf;

/// One raw scene photo estimated: its light (position among the calibration's lights), its
/// clipped patches as the verdict counts them and its judgement.
type RawScene = (usize, usize, Judged);

/// The smooth lights a raw model is calibrated on beside the validation lamps: Planckian
/// radiators at 2,125–6,875 K every 250 K and CIE daylight at 4,250–9,750 K every 500 K,
/// between the CCTs of the white references `spdcam experiment colour` checks on and of the
/// colour correction's fit lights ([`crate::colour::raw_fit::smooth_lights`]). Without
/// them the calibration knows lamps only and expects daylight to be read poorly (a raw
/// photo of D65 expected at GFC 0.925 and read at 0.9995).
pub fn calibration_smooth_lights() -> Result<Vec<(String, Spd)>> {
    let planckian = (0..20).map(|k| {
        let cct = 2125.0 + 250.0 * f64::from(k);
        Ok((format!("Planckian {cct} K"), planck(cct, &GRID)?))
    });
    let daylights = (0..12).map(|k| {
        let cct = 4250.0 + 500.0 * f64::from(k);
        Ok((format!("CIE daylight {cct} K"), daylight(cct, &GRID)?))
    });
    planckian.chain(daylights).collect()
}

/// Fits the calibration of each raw model of `raw_models` (files) on `per_lamp` raw scene
/// photos of each of the split's validation lamps and of each smooth light
/// ([`calibration_smooth_lights`]), estimated by the estimator of the model
/// of its chart among `photos`' models with the raw model beside it. Each photo is seeded
/// from `photos`' seed and its number, as the scene photos of [`crate::trust::fit::calibrate`].
pub fn calibrate_raw(
    photos: &HeldOutPhotos,
    raw_models: &[PathBuf],
    per_lamp: usize,
    data_dir: &DataDir,
) -> Result<Calibrations> {
    if per_lamp == 0 {
        return Err(EvalError::invalid(
            "a raw model is calibrated on raw scene photos: give --scenes 1 or more",
        ));
    }
    let setup = photos.setup(data_dir)?;
    let lamps = setup
        .library
        .positions(setup.split.lamps(LampPart::Validation), "the split's lamps")?;
    let models = photos.models()?;
    let smooth = calibration_smooth_lights()?;
    let mut out = Vec::new();
    for path in raw_models {
        let raw = Model::load(path)?;
        raw.require_raw_xyz(&path.display().to_string())?;
        let chart_name = raw.header().chart.clone().ok_or_else(|| {
            EvalError::invalid(format!("{}: the model names no chart", path.display()))
        })?;
        let (_, model, _) = models
            .iter()
            .find(|(_, _, chart)| *chart == chart_name)
            .ok_or_else(|| {
                EvalError::invalid(format!(
                    "{}: give the model of its chart ({chart_name}) with --model, which finds \
                     and checks the chart on the raw photos",
                    path.display()
                ))
            })?;
        let estimator = Estimator::new(
            ModelSet::single(model.clone(), "model"),
            data_dir.clone(),
            model.grid(),
        )?
        .with_raw_models(vec![NamedModel {
            name: path.display().to_string(),
            model: raw.clone(),
        }])?;
        // Every light with its truth on the model's grid, its kind of photo and its type.
        let lamp_truths = on_grid(&setup.library, &model.grid())?;
        let mut lights: Vec<(Spd, Vec<f64>, PhotoKind, String)> = lamps
            .iter()
            .map(|&l| {
                let label = setup.library.types.get(l).map_or("other", |t| t.label());
                (
                    setup.library.spds[l].clone(),
                    lamp_truths[l].clone(),
                    PhotoKind::Scene,
                    label.to_string(),
                )
            })
            .collect();
        for (_, spd) in &smooth {
            let truth = spd.resampled(&model.grid())?.normalised_by_max();
            lights.push((
                spd.clone(),
                truth.into_values(),
                PhotoKind::Smooth,
                "smooth".to_string(),
            ));
        }
        let name = photo_chart(&chart_name);
        let chart = Chart::resolve(name, None, data_dir, &GRID)?;
        let template = ChartTemplate::from_chart(&chart)?;
        let chart = chart.with_layout(scene::scene_layout(&template))?;
        let pool = camera_pool(
            &setup.cameras,
            0,
            photos.seed,
            &chart,
            CameraConfig::default(),
            &GRID,
        )?;
        let feature_patches = model
            .photo_chart()
            .map(|t| t.feature_patches.clone())
            .ok_or_else(|| EvalError::invalid(format!("{chart_name}: no photo template")))?;
        let options = PhotoOptions {
            chart: Some(name.to_string()),
            ..PhotoOptions::default()
        };
        let shot_options = scene_options();
        let found: Vec<Option<RawScene>> = (0..lights.len() * per_lamp)
            .into_par_iter()
            .map(|g| {
                let light = g / per_lamp;
                let (spd, truth, ..) = &lights[light];
                let camera = &pool[g % pool.len()];
                let shot = scene::photograph(
                    camera,
                    SceneLight::single(spd),
                    seed::derive(photos.seed, g as u64),
                    &shot_options,
                )?;
                let bytes = raw_scene(camera, spd, &shot)?;
                let Ok(estimate) = estimator.estimate_photo_bytes(&bytes, "scene.dng", &options)
                else {
                    return Ok(None);
                };
                let (clipped, judged) =
                    judge_raw(&estimate, &raw, &feature_patches, truth.clone())?;
                Ok(Some((light, clipped, judged)))
            })
            .collect::<Result<_>>()?;
        let refused = found.iter().filter(|f| f.is_none()).count();
        let (mut clipped, mut judged, mut kinds, mut groups, mut sources) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for (light, clipped_patches, j) in found.into_iter().flatten() {
            let (_, _, kind, label) = &lights[light];
            clipped.push(clipped_patches);
            judged.push(j);
            kinds.push(*kind);
            groups.push(light);
            sources.push((kind.label().to_string(), label.clone()));
        }
        let method = format!(
            "raw scene photos (DNGs of the whole camera chain, found and sampled as a user's \
             raw photo is) of the split's {} validation lamps and {} smooth lights (Planckian \
             2,125–6,875 K, CIE daylight 4,250–9,750 K), {per_lamp} each by its held-out \
             cameras, seed {}; {refused} refused (no chart found); read by the raw model, the \
             chart found and checked by the chart's model; spread of the raw model over \
             perturbed copies of the patches' XYZ",
            lamps.len(),
            smooth.len(),
            photos.seed
        );
        let photos =
            CalibrationPhotos::scenes_only(clipped, judged, kinds, groups, sources, per_lamp);
        let (calibration, records) = fit_calibration(&raw, &chart_name, &photos, method)?;
        out.push(Calibrated {
            model: path.clone(),
            chart: chart_name,
            calibration,
            records,
        });
    }
    Ok(Calibrations {
        models: out,
        skipped: setup.skipped,
    })
}

/// A raw photo's estimate judged as the estimator judges it with the raw model `raw`: the
/// estimate (on the model's grid), its truth, the raw model's spread over perturbed copies
/// of the patches' XYZ (`feature_patches` of the photo's chart), the self-check on the
/// developed colours; beside it, how many of its patches the verdict counts as clipped.
fn judge_raw(
    estimate: &Estimate,
    raw: &Model,
    feature_patches: &[usize],
    truth: Vec<f64>,
) -> Result<(usize, Judged)> {
    let analysis = estimate
        .photo
        .as_ref()
        .ok_or_else(|| EvalError::invalid("a photo's estimate without its analysis"))?;
    let reading = analysis
        .raw
        .as_ref()
        .ok_or_else(|| EvalError::invalid("a raw photo's estimate without its raw reading"))?;
    let xyz = raw_row(reading, feature_patches, &analysis.source)?;
    let perturbed = Perturbed::of(raw, &xyz)?;
    let spd = spdcam_core::spectral::normalise_by_max(estimate.spd.values());
    let self_check = estimate.trust.as_ref().and_then(|t| t.self_check.clone());
    let judged = Judged::of(
        spd,
        Some(truth),
        &perturbed,
        self_check,
        &raw.grid().wavelengths(),
    )?;
    let row: Vec<f64> = analysis.features.iter().map(|&v| f64::from(v)).collect();
    let flags = trust::photo_flags(analysis, Some(feature_patches));
    Ok((trust::clipped_features(&row, &flags).len(), judged))
}
