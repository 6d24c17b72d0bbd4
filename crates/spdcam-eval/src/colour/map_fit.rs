//! Fitting a model's colour map (`spdcam colour-map fit`, [`ColourMap`]): the split's
//! validation lamps (never trained on) photographed by its *training* cameras — scene photos
//! through the full camera chain and patch-level photos with the randomised in-camera stage,
//! as the colour protocol takes them — estimated by the model without a map, and the lines
//! taking their mired and Duv to the true lights' fitted by least squares (white light only). The held-out cameras stay
//! unseen, so `spdcam experiment colour` measures the mapped model on cameras, and test
//! lamps, the map never met.

use super::lights::{self, LightSet};
use super::photos::{PhotoScore, Shoot};
use crate::error::{EvalError, Result};
use crate::held_out::{file_name, training_cameras, LampFiles, SkippedCamera, GRID};
use spdcam_core::builtin::DataDir;
use spdcam_core::chart::Chart;
use spdcam_core::light_families::ValidationSplit;
use spdcam_core::seed;
use spdcam_infer::colour_map::ColourMap;
use spdcam_infer::{Estimator, Model, ModelSet};
use std::path::PathBuf;

/// What a colour map is fitted on.
#[derive(Debug, Clone)]
pub struct MapFitOptions {
    /// The model (a map it already has is replaced: the fit starts from the model without).
    pub model: PathBuf,
    /// The validation split: its validation lamps and training cameras.
    pub split: PathBuf,
    /// The lamp library.
    pub library: LampFiles,
    /// Directory of camera sensitivity CSVs holding the split's training cameras; `None`:
    /// the data directory's cameras/.
    pub cameras: Option<PathBuf>,
    /// Scene photos of each lamp.
    pub scene_photos: u64,
    /// Patch-level photos of each lamp.
    pub patch_photos: u64,
    /// Seed of the photos.
    pub seed: u64,
}

/// A fitted map and what it does on the photos it was fitted on.
#[derive(Debug, Clone)]
pub struct MapFit {
    /// The model with its new map.
    pub model: Model,
    /// Photos fitted on (estimated; refused scene photos are left out).
    pub photos: usize,
    /// Median Δu′v′ of those photos' estimates before and after the map (the map's own
    /// result, before the spectrum is moved to it).
    pub median_delta_uv: [f64; 2],
    /// Training cameras left out (unreadable curves), for the caller to report.
    pub skipped: Vec<SkippedCamera>,
}

impl MapFit {
    /// Fits the map of `options` (see the module's documentation); `progress` hears what is
    /// being done.
    pub fn fit(
        options: &MapFitOptions,
        data_dir: &DataDir,
        progress: &mut dyn FnMut(&str),
    ) -> Result<MapFit> {
        if options.scene_photos == 0 && options.patch_photos == 0 {
            return Err(EvalError::invalid(
                "a colour map needs photos: --photos or --patch-photos at least 1",
            ));
        }
        let split = ValidationSplit::read(&options.split)?;
        let library = options.library.read(data_dir, &GRID)?;
        let cameras = training_cameras(&split, options.cameras.as_deref(), data_dir)?;
        let lamps = lights::lights(&library, &split, LightSet::Validation)?;
        let mut model = Model::load(&options.model)?;
        model.set_colour_map(None)?;
        let chart_name = model.header().chart.clone().ok_or_else(|| {
            EvalError::invalid(format!(
                "{}: the model names no chart",
                options.model.display()
            ))
        })?;
        let chart = Chart::resolve(&chart_name, None, data_dir, &GRID)?;
        model.check_features(&chart.feature_names(), &chart_name)?;
        let estimator = Estimator::new(
            ModelSet::single(model.clone(), file_name(&options.model)),
            data_dir.clone(),
            model.grid(),
        )?;
        let same = |_: &lights::Light| Ok(estimator.clone());
        // The shoot of `per_lamp` photos of each lamp, its draws from stream `stream`.
        let lights_of =
            |per_lamp: u64| -> Vec<_> { lamps.iter().map(|l| (l.clone(), per_lamp)).collect() };
        let (scene_lights, patch_lights) = (
            lights_of(options.scene_photos),
            lights_of(options.patch_photos),
        );
        let shoot = |lights, stream| Shoot {
            cameras: &cameras.cameras,
            lights,
            seed: seed::derive(options.seed, stream),
            raw: false,
        };
        let mut scores: Vec<PhotoScore> = Vec::new();
        if options.scene_photos > 0 {
            progress("scene photos");
            scores.extend(shoot(&scene_lights, 1).scenes(&same, &chart_name, data_dir)?);
        }
        if options.patch_photos > 0 {
            progress("patch-level photos");
            scores.extend(shoot(&patch_lights, 2).patches(&same, &chart)?);
        }
        let pairs: Vec<([f64; 2], [f64; 2])> = scores
            .iter()
            .filter_map(|s| s.estimate.as_ref())
            .map(|e| (e.colour.estimate_uv_prime, e.colour.true_uv_prime))
            .collect();
        let fitted_on = format!(
            "{} photos ({} scene, {} patch-level per lamp) of the {} validation lamps of {}, \
             by its {} training cameras, seed {}",
            pairs.len(),
            options.scene_photos,
            options.patch_photos,
            lamps.len(),
            file_name(&options.split),
            cameras.cameras.len(),
            options.seed
        );
        let map = ColourMap::fit(&pairs, &model.grid(), fitted_on)?;
        let distance = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
        let before: Vec<f64> = pairs.iter().map(|(e, t)| distance(*e, *t)).collect();
        let after: Vec<f64> = pairs
            .iter()
            .map(|(e, t)| distance(map.apply(*e), *t))
            .collect();
        model.set_colour_map(Some(map))?;
        Ok(MapFit {
            model,
            photos: pairs.len(),
            median_delta_uv: [super::median(before), super::median(after)],
            skipped: cameras.skipped,
        })
    }
}
