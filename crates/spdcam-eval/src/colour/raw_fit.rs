//! Fitting the correction of raw files' colour matrices (`spdcam colour-map raw`,
//! [`RawColourCorrection`]): each of the split's *fit* lamps, and the smooth lights the
//! training recipes also draw (Planckian radiators and CIE daylight, [`smooth_lights`]),
//! seen by each of its *training* cameras as that camera's DNG gives it to a reader — the
//! neutral under the light through the camera's matrices fitted under A and D65 — against
//! the light's true chromaticity, and the bias fitted as a linear function of the light's
//! shape — or, given the raw models, of the shape each raw model reads from that camera's
//! raw patches, the shape the correction is handed when a photo is read. Its validation and
//! test lamps and
//! its held-out cameras stay unseen: the fit is scored on the validation lamps through the
//! training cameras here, and `spdcam experiment colour --raw` measures it on the held-out
//! cameras.

use crate::error::{EvalError, Result};
use crate::held_out::{training_cameras, LampFiles, SkippedCamera, GRID};
use rayon::prelude::*;
use spdcam_core::builtin::DataDir;
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::{Camera, CameraConfig};
use spdcam_core::chart::Chart;
use spdcam_core::cie_illuminant::{daylight, planck};
use spdcam_core::colorimetry::Observer;
use spdcam_core::dataset::raw_features;
use spdcam_core::light_families::validation_split::LampPart;
use spdcam_core::light_families::ValidationSplit;
use spdcam_core::photo::raw::dng::virtual_raw_colour;
use spdcam_core::quality::uv::xy_to_uv1976;
use spdcam_core::spectral::Spd;
use spdcam_infer::measured_colour::RawColourCorrection;
use spdcam_infer::Model;
use std::path::PathBuf;

/// The relative ridge penalty the correction is fitted with by default.
pub const PENALTY: f64 = 1e-3;

/// What the correction is fitted on.
#[derive(Debug, Clone)]
pub struct RawFitOptions {
    /// The validation split: its fit and validation lamps and training cameras.
    pub split: PathBuf,
    /// The lamp library.
    pub library: LampFiles,
    /// Directory of camera sensitivity CSVs holding the split's training cameras; `None`:
    /// the data directory's cameras/.
    pub cameras: Option<PathBuf>,
    /// The ridge penalty, relative to the mean diagonal of XᵀX.
    pub penalty: f64,
    /// Raw models (`spdcam generate --raw`): when given, each reading's shape is each raw
    /// model's estimate from that camera's raw patches of its chart, every model's readings
    /// pooled; none: the light's true shape.
    pub raw_models: Vec<PathBuf>,
}

/// A fitted correction and what it does.
#[derive(Debug, Clone)]
pub struct RawFit {
    /// The correction.
    pub correction: RawColourCorrection,
    /// Median Δu′v′ of the matrices' reading before and after the correction, on the fit
    /// lights (what it was fitted on) and on the validation lamps (unseen lamps, the same
    /// cameras): `[[fit before, fit after], [validation before, validation after]]`.
    pub median_delta_uv: [[f64; 2]; 2],
    /// Training cameras left out (unreadable curves), for the caller to report.
    pub skipped: Vec<SkippedCamera>,
}

/// The smooth lights beside the fit lamps: Planckian radiators at 2,000–7,000 K every
/// 250 K and CIE daylight at 4,000–10,000 K every 500 K, where a 3×3 calibration is nearly
/// exact, so that the correction learns to leave them alone.
pub fn smooth_lights() -> Result<Vec<Spd>> {
    let planckian = (0..=20).map(|k| planck(2000.0 + 250.0 * k as f64, &GRID));
    let daylights = (0..=12).map(|k| daylight(4000.0 + 500.0 * k as f64, &GRID));
    Ok(planckian
        .chain(daylights)
        .collect::<std::result::Result<Vec<_>, _>>()?)
}

/// One lamp through one camera: the lamp's shape, and the matrices' read and the true u′v′.
struct Reading {
    shape: Vec<f64>,
    read: [f64; 2],
    truth: [f64; 2],
}

/// Every lamp of `lamps` through every camera of `cameras` (each lamp's shape and true
/// colour worked out once, not once per camera).
fn readings(cameras: &[Camera], lamps: &[Spd], observer: &Observer) -> Result<Vec<Reading>> {
    let lights: Vec<(Vec<f64>, [f64; 2])> = lamps
        .iter()
        .map(|spd| {
            let truth = xy_to_uv1976(observer.spd_to_xy(spd.values()));
            Ok((RawColourCorrection::shape(spd)?, truth))
        })
        .collect::<Result<_>>()?;
    let per_camera: Vec<Vec<Reading>> = cameras
        .par_iter()
        .map(|camera| {
            let colour = virtual_raw_colour(camera)?;
            lamps
                .iter()
                .zip(&lights)
                .map(|(spd, (shape, truth))| {
                    let xy = colour.light_xy(camera.neutral_under(spd)?)?;
                    Ok(Reading {
                        shape: shape.clone(),
                        read: xy_to_uv1976(xy),
                        truth: *truth,
                    })
                })
                .collect::<Result<Vec<_>>>()
        })
        .collect::<Result<_>>()?;
    Ok(per_camera.into_iter().flatten().collect())
}

/// Each of `lights` through each of `cameras` (camera-major, as [`readings`] orders them)
/// read by the raw model `model`: the shape ([`RawColourCorrection::shape`]) of its
/// estimate from the camera's raw patches of the model's chart, without lighting gradient
/// or glare ([`raw_features`]).
fn estimated_shapes(
    model: &Model,
    cameras: &[Sensitivities],
    lights: &[Spd],
    data_dir: &DataDir,
) -> Result<Vec<Vec<f64>>> {
    let name = model
        .header()
        .chart
        .clone()
        .ok_or_else(|| EvalError::invalid("a raw model that names no chart"))?;
    let chart = Chart::resolve(&name, None, data_dir, &GRID)?;
    let d = model.grid().count;
    let per_camera: Vec<Vec<Vec<f64>>> = cameras
        .par_iter()
        .map(|s| {
            let camera = Camera::new(s, chart.clone(), CameraConfig::default(), &GRID)?;
            let colour = virtual_raw_colour(&camera)?;
            let (mut raw, mut row) = (Vec::new(), Vec::new());
            for spd in lights {
                raw_features(
                    &camera,
                    &colour,
                    None,
                    &camera.light(spd)?,
                    &mut raw,
                    &mut row,
                )?;
            }
            let rows: Vec<f64> = row.iter().map(|&v| f64::from(v)).collect();
            model
                .estimate_rows(&rows)?
                .chunks_exact(d)
                .map(|spd| {
                    Ok(RawColourCorrection::shape(&Spd::new(
                        model.grid(),
                        spd.to_vec(),
                    )?)?)
                })
                .collect()
        })
        .collect::<Result<_>>()?;
    Ok(per_camera.into_iter().flatten().collect())
}

/// `readings` once per raw model of `models`, each reading's shape the model's estimate
/// ([`estimated_shapes`]); `readings` as they are without models.
fn as_estimated(
    readings: Vec<Reading>,
    models: &[Model],
    cameras: &[Sensitivities],
    lights: &[Spd],
    data_dir: &DataDir,
) -> Result<Vec<Reading>> {
    if models.is_empty() {
        return Ok(readings);
    }
    let mut out = Vec::with_capacity(readings.len() * models.len());
    for model in models {
        let shapes = estimated_shapes(model, cameras, lights, data_dir)?;
        out.extend(readings.iter().zip(shapes).map(|(r, shape)| Reading {
            shape,
            read: r.read,
            truth: r.truth,
        }));
    }
    Ok(out)
}

/// The median Δu′v′ of `readings` as read and as `correction` corrects them.
fn medians(readings: &[Reading], correction: &RawColourCorrection) -> [f64; 2] {
    let distance = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    let before = readings.iter().map(|r| distance(r.read, r.truth)).collect();
    let after = readings
        .iter()
        .map(|r| {
            let bias = correction.bias(&r.shape);
            distance([r.read[0] - bias[0], r.read[1] - bias[1]], r.truth)
        })
        .collect();
    [super::median(before), super::median(after)]
}

impl RawFit {
    /// Fits the correction of `options` (see the module's documentation); `progress` hears
    /// what is being done.
    pub fn fit(
        options: &RawFitOptions,
        data_dir: &DataDir,
        progress: &mut dyn FnMut(&str),
    ) -> Result<RawFit> {
        let split = ValidationSplit::read(&options.split)?;
        let library = options.library.read(data_dir, &GRID)?;
        let held = training_cameras(&split, options.cameras.as_deref(), data_dir)?;
        let chart = Chart::colorchecker24(&GRID)?;
        let cameras: Vec<Camera> = held
            .cameras
            .iter()
            .map(|s| Camera::new(s, chart.clone(), CameraConfig::default(), &GRID))
            .collect::<std::result::Result<_, _>>()?;
        let lamps = |part: LampPart, what: &str| -> Result<Vec<Spd>> {
            let ids = library.positions(split.lamps(part), what)?;
            Ok(ids.into_iter().map(|i| library.spds[i].clone()).collect())
        };
        let (fit_lamps, validation_lamps) = (
            lamps(LampPart::Fit, "the split's fit lamps")?,
            lamps(LampPart::Validation, "the split's validation lamps")?,
        );
        let smooth = smooth_lights()?;
        let fit_lights: Vec<Spd> = fit_lamps.iter().chain(&smooth).cloned().collect();
        let observer = Observer::cie1931(&GRID)?;
        let models: Vec<Model> = options
            .raw_models
            .iter()
            .map(|path| {
                let model = Model::load(path)?;
                model.require_raw_xyz(&path.display().to_string())?;
                Ok(model)
            })
            .collect::<Result<_>>()?;
        progress("the fit lights through the training cameras");
        let fit_readings = as_estimated(
            readings(&cameras, &fit_lights, &observer)?,
            &models,
            &held.cameras,
            &fit_lights,
            data_dir,
        )?;
        let samples: Vec<(Vec<f64>, [f64; 2])> = fit_readings
            .iter()
            .map(|r| {
                let bias = [r.read[0] - r.truth[0], r.read[1] - r.truth[1]];
                (r.shape.clone(), bias)
            })
            .collect();
        let shapes = if models.is_empty() {
            String::new()
        } else {
            format!(
                "; the shapes {} raw model(s) read from each camera's raw patches ({})",
                models.len(),
                options
                    .raw_models
                    .iter()
                    .map(|p| p
                        .file_name()
                        .map_or(String::new(), |n| n.to_string_lossy().into_owned()))
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        };
        let fitted_on = format!(
            "{} readings: the {} fit lamps of {} and {} Planckian and daylight lights through \
             its {} training cameras' DNG matrices (fitted under A and D65 on the \
             ColorChecker 24){shapes}",
            samples.len(),
            fit_lamps.len(),
            options
                .split
                .file_name()
                .map_or(String::new(), |n| n.to_string_lossy().into_owned()),
            smooth.len(),
            cameras.len()
        );
        let correction = RawColourCorrection::fit(&samples, options.penalty, fitted_on)?;
        progress("the validation lamps through the training cameras");
        let validation_readings = as_estimated(
            readings(&cameras, &validation_lamps, &observer)?,
            &models,
            &held.cameras,
            &validation_lamps,
            data_dir,
        )?;
        Ok(RawFit {
            median_delta_uv: [
                medians(&fit_readings, &correction),
                medians(&validation_readings, &correction),
            ],
            correction,
            skipped: held.skipped,
        })
    }
}
