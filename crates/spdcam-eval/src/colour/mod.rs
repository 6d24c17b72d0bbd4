//! The colour protocol (`spdcam experiment colour`): every model judged on the light's
//! colour as a colour meter reads it (Δu′v′, CCT), beside its shape (GFC).
//!
//! Lights: the split's validation lamps (choose on these), its test lamps (report only) and
//! eight white references ([`lights::references`]). Photos, all by the split's held-out
//! cameras (cameras outside the training pool):
//!
//! - (a) scene photos ([`photos::Shoot::scenes`]): the chart in a cluttered scene, the full
//!   camera chain and a JPEG, then found, sampled and estimated by the [`Estimator`] a
//!   user's photo goes through;
//! - (b) patch-level photos ([`photos::Shoot::patches`]) with the randomised in-camera
//!   stage, as `spdcam lamps validate` (a) takes them, estimated as feature rows.
//!
//! Beside the models: the constant (the mean SPD of the split's fit lamps) and the truth seen
//! over 400–700 nm only (the nearest an estimate on those wavelengths can come). Scores per
//! lamp type or reference and per set ([`summary::Summary`]); [`ColourReport::markdown`]
//! writes them.

pub mod lights;
pub mod map_fit;
pub mod photos;
pub mod raw_fit;
mod report;
pub mod score;
pub mod summary;

pub use score::{ColourScore, LightColour, CCT_MAX_DUV};
pub use summary::{median, CctSummary, Summary};

use crate::error::{EvalError, Result};
use crate::held_out::{HeldOutPhotos, SkippedCamera, GRID};
use crate::lamp_validation::average_spd;
use lights::{Light, LightSet};
use photos::{EstimatorFor, PhotoScore, Scored, Shoot};
use spdcam_core::builtin::DataDir;
use spdcam_core::chart::Chart;
use spdcam_core::light_families::validation_split::LampPart;
use spdcam_core::light_families::LampType;
use spdcam_core::seed;
use spdcam_core::spectral::{Grid, Spd};
use spdcam_infer::kind_prior::KindPriors;
use spdcam_infer::{Estimator, Model, ModelSet, NamedModel};
use std::path::PathBuf;

/// The options of the colour protocol.
#[derive(Debug, Clone)]
pub struct ColourOptions {
    /// The models, split, lamp library, cameras and seed; `shots`: scene photos of each lamp.
    pub held_out: HeldOutPhotos,
    /// Scene photos of each white reference.
    pub reference_photos: u64,
    /// Patch-level photos of each light.
    pub patch_photos: u64,
    /// Also measure each model told each light's kind (`estimate --light`), on the same
    /// photos.
    pub light_named: bool,
    /// Light-kind priors (`spdcam light-kinds fit`) for models without built-in ones, each
    /// used for the model whose fingerprint it names.
    pub light_priors: Vec<KindPriors>,
    /// (a) is taken as raw DNGs of the same scenes instead of JPEGs.
    pub raw: bool,
    /// Models that read raw patches, each for the model of its chart
    /// ([`Estimator::with_raw_models`]).
    pub raw_models: Vec<PathBuf>,
}

/// What a row of a table groups.
#[derive(Debug, Clone, PartialEq)]
pub enum Group {
    /// The lamps of one type.
    Type(LampType),
    /// One white reference.
    Light(String),
    /// Every light of the set.
    All,
}

impl Group {
    /// Whether `light` belongs to the group.
    fn holds(&self, light: &Light) -> bool {
        match self {
            Group::Type(t) => light.kind == *t,
            Group::Light(name) => light.name == *name,
            Group::All => true,
        }
    }
}

/// The scores of one group of lights.
#[derive(Debug, Clone, PartialEq)]
pub struct Row<T> {
    /// The set the lights belong to.
    pub set: LightSet,
    /// Which of its lights.
    pub group: Group,
    /// How many lights.
    pub lights: usize,
    /// The scores.
    pub scores: T,
}

/// A model's scores on one group: (a) scene photos and (b) patch-level photos.
pub type ModelRow = Row<[Summary; 2]>;
/// The baselines' scores on one group: the constant and the truth over 400–700 nm.
pub type BaselineRow = Row<[Summary; 2]>;

/// One model measured.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelColour {
    /// The model's file.
    pub model: PathBuf,
    /// The chart it names.
    pub chart: String,
    /// Whether it was told each light's kind.
    pub light_named: bool,
    /// Whether the program holds a trust calibration for it (CCT intervals).
    pub calibrated: bool,
    /// Per group of lights.
    pub rows: Vec<ModelRow>,
    /// Every photo scored: (a) scene photos, (b) patch-level photos.
    pub photos: [Vec<PhotoScore>; 2],
}

/// The colour protocol's results.
#[derive(Debug, Clone, PartialEq)]
pub struct ColourReport {
    /// Each model, in the order given.
    pub models: Vec<ModelColour>,
    /// The constant and the truncated truth, per group, on [`Grid::ESTIMATION`].
    pub baselines: Vec<BaselineRow>,
    /// The lights photographed, as [`PhotoScore::light`] counts them.
    pub lights: Vec<Light>,
    /// The held-out cameras' names, as [`PhotoScore::camera`] counts them.
    pub camera_names: Vec<String>,
    /// Scene photos of each lamp, of each reference, and patch-level photos of each light.
    pub photos: [u64; 3],
    /// How many held-out cameras took them.
    pub cameras: usize,
    /// The seed.
    pub seed: u64,
    /// The held-out cameras left out (unreadable curves), for the caller to report.
    pub skipped: Vec<SkippedCamera>,
    /// Whether (a) was raw DNGs.
    pub raw: bool,
}

/// Every group of `lights` with a light: per lamp set its lamp types (in [`LampType::ALL`]'s
/// order), per reference the light, then the whole set.
fn groups(lights: &[Light]) -> Vec<(LightSet, Group)> {
    let mut out = Vec::new();
    for set in LightSet::ALL {
        let members: Vec<&Light> = lights.iter().filter(|l| l.set == set).collect();
        if members.is_empty() {
            continue;
        }
        if set == LightSet::References {
            out.extend(members.iter().map(|l| (set, Group::Light(l.name.clone()))));
        } else {
            out.extend(
                LampType::ALL
                    .into_iter()
                    .filter(|t| members.iter().any(|l| l.kind == *t))
                    .map(|t| (set, Group::Type(t))),
            );
        }
        out.push((set, Group::All));
    }
    out
}

/// The rows of `groups` over `lights`, each summarising every score list of `scores`.
fn rows<const N: usize>(
    groups: &[(LightSet, Group)],
    lights: &[Light],
    scores: [&[PhotoScore]; N],
) -> Result<Vec<Row<[Summary; N]>>> {
    groups
        .iter()
        .map(|(set, group)| {
            let select = |j: usize| lights[j].set == *set && group.holds(&lights[j]);
            let summaries = scores.map(|s| Summary::of(s, select));
            let summaries = summaries
                .into_iter()
                .collect::<Option<Vec<Summary>>>()
                .and_then(|v| <[Summary; N]>::try_from(v).ok())
                .ok_or_else(|| EvalError::invalid("a group of lights without a photo"))?;
            Ok(Row {
                set: *set,
                group: group.clone(),
                lights: (0..lights.len()).filter(|&j| select(j)).count(),
                scores: summaries,
            })
        })
        .collect()
}

impl ColourReport {
    /// Measures every model of `options` (see the module's documentation); `progress` hears
    /// what is being done.
    pub fn measure(
        options: &ColourOptions,
        data_dir: &DataDir,
        progress: &mut dyn FnMut(&str),
    ) -> Result<ColourReport> {
        let held_out = &options.held_out;
        for (value, option) in [
            (held_out.shots, "--photos"),
            (options.reference_photos, "--reference-photos"),
            (options.patch_photos, "--patch-photos"),
        ] {
            if value == 0 {
                return Err(EvalError::invalid(format!("{option} must be at least 1")));
            }
        }
        let setup = held_out.setup(data_dir)?;
        let mut lights = Vec::new();
        for set in LightSet::ALL {
            lights.extend(lights::lights(&setup.library, &setup.split, set)?);
        }
        let groups = groups(&lights);
        let count = |l: &Light, lamps: u64, references: u64| {
            if l.set == LightSet::References {
                references
            } else {
                lamps
            }
        };
        let scene_lights: Vec<(Light, u64)> = lights
            .iter()
            .map(|l| {
                (
                    l.clone(),
                    count(l, held_out.shots, options.reference_photos),
                )
            })
            .collect();
        let patch_lights: Vec<(Light, u64)> = lights
            .iter()
            .map(|l| (l.clone(), options.patch_photos))
            .collect();
        let scenes = Shoot {
            cameras: &setup.cameras,
            lights: &scene_lights,
            seed: seed::derive(held_out.seed, 1),
            raw: options.raw,
        };
        let patches = Shoot {
            cameras: &setup.cameras,
            lights: &patch_lights,
            seed: seed::derive(held_out.seed, 2),
            raw: false,
        };

        let raw_models = options
            .raw_models
            .iter()
            .map(|p| {
                Ok(NamedModel {
                    name: crate::held_out::file_name(p),
                    model: Model::load(p)?,
                })
            })
            .collect::<Result<Vec<NamedModel>>>()?;
        let mut models = Vec::new();
        for (path, model, chart_name) in held_out.models()? {
            let chart = Chart::resolve(&chart_name, None, data_dir, &GRID)?;
            model.check_features(&chart.feature_names(), &chart_name)?;
            let calibrated = spdcam_infer::trust::calibration_for(&model)?.is_some();
            let name = crate::held_out::file_name(&path);
            let fingerprint = model.fingerprint();
            let estimator = Estimator::new(
                ModelSet::single(model.clone(), name.clone()),
                data_dir.clone(),
                model.grid(),
            )?
            .with_priors(
                options
                    .light_priors
                    .iter()
                    .filter(|p| p.model == fingerprint)
                    .cloned()
                    .collect(),
            )?
            .with_raw_models(
                raw_models
                    .iter()
                    .filter(|r| r.model.header().chart.as_deref() == Some(chart_name.as_str()))
                    .cloned()
                    .collect(),
            )?;
            let same = |_: &Light| Ok(estimator.clone());
            let told = |l: &Light| Ok(estimator.for_light(l.light_kind())?);
            let ways: [(&EstimatorFor<'_>, bool); 2] = [(&same, false), (&told, true)];
            for (estimator_for, light_named) in ways {
                if light_named && !options.light_named {
                    continue;
                }
                let told = if light_named { ", told the kind" } else { "" };
                progress(&format!("{name}{told}: scene photos"));
                let a = scenes.scenes(estimator_for, &chart_name, data_dir)?;
                progress(&format!("{name}{told}: patch-level photos"));
                let b = patches.patches(estimator_for, &chart)?;
                models.push(ModelColour {
                    model: path.clone(),
                    chart: chart_name.clone(),
                    light_named,
                    calibrated,
                    rows: rows(&groups, &lights, [&a, &b])?,
                    photos: [a, b],
                });
            }
        }
        let fit = setup
            .library
            .positions(setup.split.lamps(LampPart::Fit), "the split's fit lamps")?;
        let baselines = baselines(&setup.library.spds, &fit, &lights)?;
        Ok(ColourReport {
            models,
            baselines: rows(&groups, &lights, [&baselines[0], &baselines[1]])?,
            camera_names: setup.cameras.iter().map(|c| c.name.clone()).collect(),
            lights,
            photos: [
                held_out.shots,
                options.reference_photos,
                options.patch_photos,
            ],
            cameras: setup.cameras.len(),
            seed: held_out.seed,
            skipped: setup.skipped,
            raw: options.raw,
        })
    }
}

/// Per light, on [`Grid::ESTIMATION`]: the constant (the mean of the fit lamps `fit` of
/// `spds`) and the truth cut to those wavelengths, each scored as one estimate.
fn baselines(spds: &[Spd], fit: &[usize], lights: &[Light]) -> Result<[Vec<PhotoScore>; 2]> {
    let grid = Grid::ESTIMATION;
    let on_grid = spds
        .iter()
        .map(|s| Ok(s.resampled(&grid)?.into_values()))
        .collect::<Result<Vec<_>>>()?;
    let constant = Spd::new(grid, average_spd(&on_grid, fit))?;
    let mut out = [Vec::new(), Vec::new()];
    for (j, light) in lights.iter().enumerate() {
        let truncated = light.spd.resampled(&grid)?;
        for (k, spd) in [&constant, &truncated].into_iter().enumerate() {
            out[k].push(PhotoScore {
                light: j,
                camera: None,
                estimate: Some(Scored::spd(spd, light)?),
            });
        }
    }
    Ok(out)
}
