//! The [`Estimator`]: built once from the models, the data directory and the output grid,
//! it holds per model everything an estimate needs besides the input (the chart templates
//! photos are searched for, the trust calibration parsed once, the chart check built once,
//! the map from the model's wavelengths to the output's), and turns every kind of input into
//! the same judged [`Estimate`].
//!
//! ```text
//! photo path ─► decode ─┐
//! photo bytes ─► decode ─┼─► find the chart, sample ─► PhotoAnalysis ─┐
//! decoded photo ─────────┘                                            │
//! feature rows (FeatureRows) ──────────────────────────────────────────┼─► the model for the
//! a stream of rows (FeatureStream, a block at a time) ─────────────────┘   columns, once per
//!     row ─► SPD ─► judged (the same SPD, trust::assess) ─► Estimate (one constructor)
//! ```
//!
//! The command line, the web app and the Python package all estimate through it, so the
//! same photo or row gives the same SPD and the same verdict in each.

//! One file per way in: `photos` (photo files, bytes and decoded photos: analysed, the
//! chart checked, each chart of a photo estimated) and `rows` (feature rows in memory or
//! streamed); this file builds the estimator and holds the one constructor of every
//! estimate (`Estimator::judged`); `tests` holds their tests.

mod photos;
mod rows;
#[cfg(test)]
mod tests;

pub use photos::{AnalysedPhoto, PhotoEstimate, PhotoProgress};
pub use rows::{EstimatedBlock, RowStream};

use crate::absolute::{absolute_level, chart_level};
use crate::error::{InferError, Result};
use crate::estimate::{Colorimetry, Estimate};
use crate::feature_rows::FeatureRows;
use crate::kind_prior::{self, KindPriors};
use crate::measured_colour::{self, RawColourCorrection};
use crate::photo_options::chart_templates;
use crate::shipped::{ModelSet, NamedModel};
use crate::stream::{check_feature_rows, GridMap};
use crate::trust::{
    self, ChartCheck, ChartIdentity, PhotoFlags, ReadBy, Trust, TrustCalibration, Verdict,
};
use rayon::prelude::*;
use spdcam_core::advice::Advice;
use spdcam_core::builtin::DataDir;
use spdcam_core::chart::{shown_chart_name, Chart};
use spdcam_core::light_families::LightKind;
use spdcam_core::photo::raw::RawReading;
use spdcam_core::photo::{ChartTemplate, PhotoAnalysis};
use spdcam_core::quality::LightingMetrics;
use spdcam_core::spectral::{Grid, Spd};
use std::sync::{Arc, OnceLock};

/// The narrowest output range an estimate is given on: a sixth of 400–700 nm (a spectrum
/// over less is a few numbers, and a GFC over them says nothing of its shape).
pub const MIN_RANGE_NM: f64 = 50.0;

/// The fewest wavelengths an output range holds.
pub const MIN_RANGE_WAVELENGTHS: usize = 3;

/// What judging one model's estimates needs, made once per model.
struct ModelTrust {
    /// The shipped calibration measured on the model, parsed once.
    calibration: Option<TrustCalibration>,
    /// The chart re-rendered under an estimate (the self-check), built once.
    check: Option<ChartCheck>,
    /// The test that patches are the model's chart at all, made once.
    identity: ChartIdentity,
}

/// What does not depend on the output grid, shared by the estimators of every grid.
struct Prepared {
    models: ModelSet,
    /// Per model of `models`, in order.
    trust: Vec<ModelTrust>,
    /// The charts photos are searched for without `PhotoOptions::chart`; `None` when they
    /// cannot be made (the error is made again when a photo needs them).
    templates: Option<Vec<ChartTemplate>>,
    /// Per model of `models`, in order: its chart on the model's grid, for the absolute
    /// levels; `None` when its reflectances are not at hand.
    charts: Vec<Option<Arc<Chart>>>,
    data_dir: DataDir,
}

/// What one model needs on the output grid.
#[derive(Clone)]
struct OnGrid {
    /// The model's wavelengths to the output's; `None` when the output lies outside them
    /// (the error is made again when an estimate needs the model).
    map: Option<GridMap>,
}

/// Turns photos and feature rows into judged estimates of the light (see the module's
/// documentation). Cheap to clone; [`Estimator::on_grid`] gives one for other wavelengths
/// sharing the models.
///
/// ```
/// use spdcam_core::builtin::DataDir;
/// use spdcam_core::spectral::Grid;
/// use spdcam_infer::{Estimator, ModelSet, PhotoOptions};
/// use std::path::Path;
///
/// let estimator = Estimator::new(ModelSet::shipped()?, DataDir::new(None), Grid::ESTIMATION)?;
/// let photo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/sg-telelumen.jpg");
/// let estimate = estimator.estimate_photo(&photo, &PhotoOptions::default())?;
/// assert_eq!(estimate.name, "sg-telelumen.jpg");
/// assert_eq!(estimate.spd.grid(), &Grid::ESTIMATION);
/// // Judged: a verdict, and bands from the model's calibration.
/// let trust = estimate.trust.as_ref().unwrap();
/// println!("verdict {}", trust.verdict.label());
/// assert!(trust.uncertainty.is_some());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone)]
pub struct Estimator {
    prepared: Arc<Prepared>,
    grid: Grid,
    /// Per model of the set, in order.
    on_grid: Vec<OnGrid>,
    /// Per model of the set, in order: its light-kind priors, if it has any; read from the
    /// built-in ones when a kind is first named (most estimates never name one).
    priors: Arc<OnceLock<Vec<Option<KindPriors>>>>,
    /// The kind of light the estimates are told of.
    light: LightKind,
    /// Per model of the set, in order: the model that reads a raw photo's patches for the
    /// same chart ([`crate::Model::reads_raw_xyz`]), when one is given
    /// ([`Estimator::with_raw_models`]).
    raw_models: Arc<Vec<Option<RawReader>>>,
}

/// A model that reads raw photos' patches, and the calibration its estimates are judged by.
#[derive(Clone)]
struct RawReader {
    /// The model.
    named: NamedModel,
    /// Its trust calibration (`spdcam trust calibrate --raw-model`), shipped with it; `None`
    /// for a model without one, whose estimates have no bands and no expected GFC.
    calibration: Option<TrustCalibration>,
}

impl Estimator {
    /// The estimator of `models` (charts found in `data_dir` when not built in) whose
    /// estimates lie on `grid`: each model's calibration parsed and chart check built here,
    /// once.
    pub fn new(models: ModelSet, data_dir: DataDir, grid: Grid) -> Result<Estimator> {
        let calibrations = models
            .models()
            .iter()
            .map(|m| trust::calibration_for(&m.model))
            .collect::<Result<Vec<_>>>()?;
        Estimator::judged_by(models, calibrations, data_dir, grid)
    }

    /// The estimator of one model judged by `calibration`, a calibration made for it (`spdcam
    /// trust calibrate`) that is not among the shipped ones: how a candidate model is judged
    /// before it ships. An error when the calibration was made for another model.
    pub fn calibrated(
        model: NamedModel,
        calibration: TrustCalibration,
        data_dir: DataDir,
        grid: Grid,
    ) -> Result<Estimator> {
        if calibration.model != model.model.fingerprint() {
            return Err(InferError::invalid(format!(
                "the trust calibration was made for another model than {} (its fingerprint \
                 {}, the model's {}): calibrate this model with `spdcam trust calibrate`",
                model.name,
                calibration.model,
                model.model.fingerprint()
            )));
        }
        Estimator::judged_by(
            ModelSet::single(model.model, model.name),
            vec![Some(calibration)],
            data_dir,
            grid,
        )
    }

    /// The estimator of `models`, each judged by its calibration in `calibrations` (in
    /// order; `None`: no calibration).
    fn judged_by(
        models: ModelSet,
        calibrations: Vec<Option<TrustCalibration>>,
        data_dir: DataDir,
        grid: Grid,
    ) -> Result<Estimator> {
        if let Some(raw) = models.models().iter().find(|m| m.model.reads_raw_xyz()) {
            return Err(InferError::invalid(format!(
                "{} reads raw files' patches through their colour matrices, not a photo's \
                 colours: give it as a raw model (`estimate --raw-model`) beside a model of \
                 its chart",
                raw.name
            )));
        }
        let trust = models
            .models()
            .iter()
            .zip(calibrations)
            .map(|(m, calibration)| {
                let check = ChartCheck::for_model(&m.model, &data_dir)?;
                Ok(ModelTrust {
                    calibration,
                    identity: ChartIdentity::for_model(&m.model),
                    check,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let templates = chart_templates(&models, None, &data_dir).ok();
        let charts = models
            .models()
            .iter()
            .map(|m| {
                let name = m.model.header().chart.as_deref()?;
                let chart = Chart::resolve(name, None, &data_dir, &m.model.grid()).ok()?;
                Some(Arc::new(chart))
            })
            .collect();
        let prepared = Arc::new(Prepared {
            models,
            trust,
            templates,
            charts,
            data_dir,
        });
        Estimator::with(prepared, Arc::default(), LightKind::Unknown, grid)
    }

    /// The estimator of the shipped models (see [`ModelSet::shipped`]), raw photos of a
    /// chart read by its shipped raw model where it has one ([`ModelSet::shipped_raw`]).
    pub fn shipped(data_dir: DataDir, grid: Grid) -> Result<Estimator> {
        Estimator::new(ModelSet::shipped()?, data_dir, grid)?
            .with_raw_models(ModelSet::shipped_raw()?)
    }

    /// The estimator of `prepared` on the output grid `grid`, which must span
    /// [`MIN_RANGE_NM`] in [`MIN_RANGE_WAVELENGTHS`] wavelengths or more, within one model's
    /// at least (an SPD is not one wavelength's value nor two's, and no model says anything
    /// outside its own range).
    fn with(
        prepared: Arc<Prepared>,
        priors: Arc<OnceLock<Vec<Option<KindPriors>>>>,
        light: LightKind,
        grid: Grid,
    ) -> Result<Estimator> {
        if grid.count < 2 {
            return Err(InferError::invalid(format!(
                "the range {}: a single wavelength is not a spectrum; give START-END[:STEP] \
                 with END above START (e.g. 400-700:5)",
                grid.label()
            )));
        }
        let span = grid.end_nm() - grid.start_nm;
        if span < MIN_RANGE_NM || grid.count < MIN_RANGE_WAVELENGTHS {
            return Err(InferError::invalid(format!(
                "the range {}: {} wavelength(s) over {span} nm are too few to be a spectrum \
                 (a GFC or a plot over them says nothing); give at least {MIN_RANGE_NM} nm in \
                 {MIN_RANGE_WAVELENGTHS} or more wavelengths, e.g. 400-700:5 or 500-600:5",
                grid.label(),
                grid.count
            )));
        }
        let maps: Vec<Result<GridMap>> = prepared
            .models
            .models()
            .iter()
            .map(|m| GridMap::new(&m.model.grid(), &grid))
            .collect();
        if maps.iter().all(Result::is_err) {
            if let Some(Err(e)) = maps.into_iter().next() {
                return Err(e);
            }
            return Err(InferError::invalid("no model to estimate with"));
        }
        let on_grid = maps
            .into_iter()
            .map(|map| OnGrid { map: map.ok() })
            .collect();
        Ok(Estimator {
            prepared,
            grid,
            on_grid,
            priors,
            light,
            raw_models: Arc::default(),
        })
    }

    /// The same models (calibrations and chart checks shared, not made again) estimating
    /// on `grid`.
    ///
    /// ```
    /// use spdcam_core::builtin::DataDir;
    /// use spdcam_core::spectral::Grid;
    /// use spdcam_infer::Estimator;
    ///
    /// let estimator = Estimator::shipped(DataDir::new(None), Grid::ESTIMATION)?;
    /// let coarse = estimator.on_grid(Grid::parse("420-680:20")?)?;
    /// assert_eq!(coarse.grid().count, 14);
    /// # Ok::<(), spdcam_infer::InferError>(())
    /// ```
    pub fn on_grid(&self, grid: Grid) -> Result<Estimator> {
        if grid == self.grid {
            return Ok(self.clone());
        }
        let mut out =
            Estimator::with(self.prepared.clone(), self.priors.clone(), self.light, grid)?;
        out.raw_models = self.raw_models.clone();
        Ok(out)
    }

    /// The same models told that the light is of `kind` ([`crate::kind_prior`]): each
    /// estimate is moved to the lights of that kind. Every model of the set must hold a
    /// prior for it; `LightKind::Unknown` (the default) leaves the estimates as the models
    /// make them.
    ///
    /// ```
    /// use spdcam_core::builtin::DataDir;
    /// use spdcam_core::light_families::LightKind;
    /// use spdcam_core::spectral::Grid;
    /// use spdcam_infer::Estimator;
    ///
    /// let estimator = Estimator::shipped(DataDir::new(None), Grid::ESTIMATION)?;
    /// assert!(estimator.light_kinds()?.contains(&LightKind::Daylight));
    /// let daylight = estimator.for_light(LightKind::Daylight)?;
    /// assert_eq!(daylight.light(), LightKind::Daylight);
    /// # Ok::<(), spdcam_infer::InferError>(())
    /// ```
    pub fn for_light(&self, kind: LightKind) -> Result<Estimator> {
        if kind != LightKind::Unknown {
            for (m, priors) in self.prepared.models.models().iter().zip(self.priors()?) {
                if priors.as_ref().and_then(|p| p.prior(kind)).is_none() {
                    return Err(InferError::invalid(format!(
                        "the model {} cannot be told the kind of light ('{}'): it carries no \
                         prior for it; the kinds it knows: {}",
                        m.name,
                        kind.name(),
                        kind_names(priors.as_ref())
                    )));
                }
            }
        }
        let mut out = self.clone();
        out.light = kind;
        Ok(out)
    }

    /// The same models with light-kind priors of their own (`spdcam light-kinds fit`), each
    /// given to the model whose fingerprint it names, in place of any built in.
    pub fn with_priors(&self, given: Vec<KindPriors>) -> Result<Estimator> {
        let mut priors: Vec<Option<KindPriors>> = self.priors()?.to_vec();
        for p in given {
            let index = self
                .prepared
                .models
                .models()
                .iter()
                .position(|m| m.model.fingerprint() == p.model)
                .ok_or_else(|| {
                    InferError::invalid(format!(
                        "light-kind priors for the model {}: no model of the set is it",
                        p.model
                    ))
                })?;
            priors[index] = Some(p);
        }
        let mut out = self.clone();
        out.priors = Arc::new(OnceLock::from(priors));
        Ok(out)
    }

    /// The same models, raw photos of a chart read by the model of `raw` for it: each must
    /// read raw patches ([`crate::Model::reads_raw_xyz`]) and estimate on the wavelengths of the
    /// set's model for its chart, which keeps the chart's checks (the self-check on the
    /// photo's developed colours) and the kind priors. Its spectrum replaces that model's
    /// for raw photos, judged by the raw model's own shipped calibration where it has one
    /// ([`trust::calibration_for`]); the light's colour still comes from the file's matrices
    /// ([`crate::measured_colour`]).
    pub fn with_raw_models(&self, raw: Vec<NamedModel>) -> Result<Estimator> {
        let mut per_model: Vec<Option<RawReader>> = self.raw_models.to_vec();
        per_model.resize(self.prepared.models.models().len(), None);
        for named in raw {
            named.model.require_raw_xyz(&named.name)?;
            let chart = named.model.header().chart.clone();
            let index = self
                .prepared
                .models
                .models()
                .iter()
                .position(|m| m.model.header().chart == chart && !m.model.reads_raw_xyz())
                .ok_or_else(|| {
                    InferError::invalid(format!(
                        "the raw model {} is for chart {}, which no model of the set reads",
                        named.name,
                        chart.as_deref().unwrap_or("(unnamed)")
                    ))
                })?;
            let set_grid = self.prepared.models.models()[index].model.grid();
            if named.model.grid() != set_grid {
                return Err(InferError::invalid(format!(
                    "the raw model {} estimates on {}, the chart's model on {}: train it on \
                     the same wavelengths",
                    named.name,
                    named.model.grid().label(),
                    set_grid.label()
                )));
            }
            per_model[index] = Some(RawReader {
                calibration: trust::calibration_for(&named.model)?,
                named,
            });
        }
        let mut out = self.clone();
        out.raw_models = Arc::new(per_model);
        Ok(out)
    }

    /// The kind of light the estimates are told of.
    pub fn light(&self) -> LightKind {
        self.light
    }

    /// The kinds of light every model of the set can be told of, `Unknown` first.
    pub fn light_kinds(&self) -> Result<Vec<LightKind>> {
        let priors = self.priors()?;
        Ok(LightKind::ALL
            .into_iter()
            .filter(|&k| {
                k == LightKind::Unknown
                    || priors
                        .iter()
                        .all(|p| p.as_ref().and_then(|p| p.prior(k)).is_some())
            })
            .collect())
    }

    /// Every model's light-kind priors, the built-in ones read at the first call.
    fn priors(&self) -> Result<&[Option<KindPriors>]> {
        if let Some(priors) = self.priors.get() {
            return Ok(priors);
        }
        let built_in = self
            .prepared
            .models
            .models()
            .iter()
            .map(|m| kind_prior::priors_for(&m.model))
            .collect::<Result<Vec<_>>>()?;
        Ok(self.priors.get_or_init(|| built_in))
    }

    /// The model's SPDs `spds` (row-major on its grid) moved to the kind of light named.
    fn told_of_light(&self, index: usize, spds: Vec<f64>) -> Result<ModelSpds> {
        if self.light == LightKind::Unknown {
            return Ok(ModelSpds {
                told: spds,
                own: None,
                raw_row: None,
            });
        }
        let priors = self.priors()?[index]
            .as_ref()
            .ok_or_else(|| InferError::invalid("the model carries no light-kind priors"))?;
        let model = &self.named(index).model;
        let d = model.grid().count;
        let map = model.header().colour_map.as_ref();
        let moved = spds
            .par_chunks(d)
            .map(|spd| priors.told(self.light, spd, map))
            .collect::<Result<Vec<_>>>()?;
        Ok(ModelSpds {
            told: moved.concat(),
            own: Some(spds),
            raw_row: None,
        })
    }

    /// The wavelengths of the estimates.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The models estimates are made with.
    pub fn models(&self) -> &ModelSet {
        &self.prepared.models
    }

    /// The charts photos are searched for: those of the models (see
    /// [`chart_templates`]), or the one `chart` names.
    pub fn templates(&self, chart: Option<&str>) -> Result<Vec<ChartTemplate>> {
        match (chart, &self.prepared.templates) {
            (None, Some(templates)) => Ok(templates.clone()),
            _ => chart_templates(&self.prepared.models, chart, &self.prepared.data_dir),
        }
    }
}

impl Estimator {
    /// The index of the model for feature columns `names`.
    fn choose(&self, names: &[String], source: &str) -> Result<usize> {
        let chosen = self.prepared.models.require(names, source)?;
        self.prepared
            .models
            .models()
            .iter()
            .position(|m| std::ptr::eq(m, chosen))
            .ok_or_else(|| InferError::invalid("the chosen model is not of the set"))
    }

    fn named(&self, index: usize) -> &NamedModel {
        &self.prepared.models.models()[index]
    }

    /// Model `index`'s wavelengths to the output's, or why there is no map.
    fn map(&self, index: usize) -> Result<&GridMap> {
        match &self.on_grid[index].map {
            Some(map) => Ok(map),
            None => Err(GridMap::new(&self.named(index).model.grid(), &self.grid)
                .err()
                .unwrap_or_else(|| {
                    InferError::invalid("the output grid lies outside the model's")
                })),
        }
    }

    /// The model's SPDs (on its own grid, peak 1, row-major) for `features`, checked against
    /// its columns first (rows that say nothing about the light are refused by name).
    fn run_model(&self, index: usize, features: &FeatureRows, source: &str) -> Result<ModelSpds> {
        self.run_model_measured(index, features, source, None)
    }

    /// [`Estimator::run_model`] with the light's chromaticity a raw photo measured
    /// (`measured`), which the model's SPDs are moved to ([`measured_colour::conform`])
    /// before a kind of light moves them.
    fn run_model_measured(
        &self,
        index: usize,
        features: &FeatureRows,
        source: &str,
        raw: Option<(&RawReading, Option<&[usize]>)>,
    ) -> Result<ModelSpds> {
        let mut model = &self.named(index).model;
        model.check_features(&features.names, source)?;
        self.map(index)?;
        check_feature_rows(
            &features.values,
            &features.names,
            source,
            0,
            features.rows > 1,
        )?;
        let raw_model = self.raw_models.get(index).and_then(Option::as_ref);
        let mut raw_row_read = None;
        let mut spds = match (raw, raw_model) {
            (Some((_, None)), Some(raw_model)) => {
                return Err(InferError::invalid(format!(
                    "{source}: {} cannot find its patches on this photo's chart",
                    raw_model.named.name
                )))
            }
            (Some((reading, Some(feature_patches))), Some(raw_model)) => {
                // The raw model reads the patches' XYZ through the file's matrices.
                let row = raw_row(reading, feature_patches, source)?;
                model = &raw_model.named.model;
                let spds = model.estimate_rows(&row)?;
                raw_row_read = Some(row);
                spds
            }
            _ => model.estimate_rows(&features.values)?,
        };
        if let Some((reading, _)) = raw {
            // The matrices' bias for a light of the shape the model reads, taken off.
            let d = model.grid().count;
            let own = Spd::new(model.grid(), spds[..d.min(spds.len())].to_vec())?;
            let xy = RawColourCorrection::shipped()?.correct(reading.light_xy, &own)?;
            measured_colour::conform(model, &mut spds, xy);
        }
        let mut spds = self.told_of_light(index, spds)?;
        spds.raw_row = raw_row_read;
        Ok(spds)
    }

    /// THE constructor of every estimate: the model's SPD `model_spd` (on its grid, peak 1)
    /// for `row`, judged (the self-check, the perturbed spread, the calibration; `flags`
    /// what a photo analysis found), and everything read from it on the output grid.
    /// `own` is the model's output before a kind of light moved it (`model_spd` itself
    /// when none was named), which the kind's check weighs. `raw_row`: the raw patches' XYZ
    /// a raw model read the spectrum from ([`ModelSpds::raw_row`]), which it is judged by.
    #[allow(clippy::too_many_arguments)]
    fn judged(
        &self,
        index: usize,
        name: String,
        model_spd: Vec<f64>,
        own: &[f64],
        row: &[f64],
        raw_row: Option<&[f64]>,
        flags: &PhotoFlags,
        photo: Option<PhotoAnalysis>,
    ) -> Result<Estimate> {
        let chosen = self.named(index);
        let map = self.map(index)?;
        let judge = &self.prepared.trust[index];
        let mut photo = photo;
        let raw_reader = self.raw_models.get(index).and_then(Option::as_ref);
        if let (Some(reading), Some(reader)) =
            (photo.as_mut().and_then(|a| a.raw.as_mut()), raw_reader)
        {
            reading.spectrum_model = Some(reader.named.name.clone());
        }
        // A raw photo read by a raw model is judged by that model's calibration, its spread
        // from the raw patches; the photo's developed colours keep the chart's checks.
        let mut trust = match (raw_reader, raw_row) {
            (Some(reader), Some(raw_row)) => trust::weigh_read_by(
                ReadBy {
                    model: &reader.named.model,
                    row: raw_row,
                },
                reader.calibration.as_ref(),
                judge.check.as_ref(),
                row,
                &model_spd,
                flags,
            )?
            .into(),
            _ => trust::assess(
                &chosen.model,
                judge.calibration.as_ref(),
                judge.check.as_ref(),
                row,
                &model_spd,
                flags,
            )?,
        };
        self.bands_on_grid(&mut trust, map)?;
        self.check_kind(index, own, &mut trust)?;
        // The colorimetry, the metrics and the absolute level are of the model's whole
        // estimate, whatever part of it the output grid shows.
        let full = Spd::new(chosen.model.grid(), model_spd.clone())?;
        let spd = Spd::new(self.grid, map.apply(model_spd))?;
        let metrics = LightingMetrics::of_spd(&full);
        let colorimetry = Colorimetry::of_metrics(&metrics)?;
        // A raw photo read by the chart's own model: the CCT and Duv intervals of raw photos
        // ([`measured_colour::RAW_INTERVALS`]); a raw model's calibration has its own.
        if raw_row.is_none() && photo.as_ref().is_some_and(|a| a.raw.is_some()) {
            if let (Some(u), Some(cct)) = (&mut trust.uncertainty, colorimetry.cct) {
                measured_colour::set_intervals(&mut u.metrics, cct, u.expected_gfc);
            }
        }
        let unusable: Vec<bool> = (0..flags.clipped.len())
            .map(|k| flags.clipped[k] || flags.dark.get(k).copied().unwrap_or(false))
            .collect();
        let chart_name = chosen.model.header().chart.as_deref();
        let reflectances = self.prepared.charts[index].as_deref();
        let absolute = match &photo {
            Some(analysis) => Some(match chart_name {
                Some(chart) => {
                    absolute_level(analysis, chart, reflectances, &full, &metrics, &unusable)?
                }
                None => Err("the model names no chart".into()),
            }),
            None => None,
        };
        let light_level = match (&photo, chart_name, reflectances) {
            (Some(analysis), Some(name), Some(chart)) => {
                chart_level(analysis, name, chart, &full, &unusable)?.ok()
            }
            _ => None,
        };
        Ok(Estimate {
            name,
            model: chosen.name.clone(),
            light: self.light,
            colorimetry,
            metrics,
            spd,
            truth: None,
            photo,
            trust: Some(trust),
            absolute,
            light_level,
            across_places: None,
        })
    }

    /// With a kind of light named: whether the model's own estimate `own` (before the kind
    /// moved it) lies among the kind's lights; when it does not, `trust` says so and is at
    /// best doubtful.
    fn check_kind(&self, index: usize, own: &[f64], trust: &mut Trust) -> Result<()> {
        if self.light == LightKind::Unknown {
            return Ok(());
        }
        let Some(priors) = self.priors()?[index].as_ref() else {
            return Ok(());
        };
        if priors.unlike(self.light, own)? {
            let advice = Advice::UnlikeKind {
                kind: self.light.label().to_string(),
            };
            trust.reasons.push(advice.to_string());
            if trust.verdict == Verdict::Ok {
                trust.verdict = Verdict::Doubtful;
            }
        }
        Ok(())
    }

    /// The bands of `trust` taken from the model's wavelengths to the output's by `map`,
    /// their lower edges held at 0 or above.
    fn bands_on_grid(&self, trust: &mut Trust, map: &GridMap) -> Result<()> {
        if let Some(u) = &mut trust.uncertainty {
            for band in [&mut u.band68, &mut u.band95] {
                let lower = map.apply(band.lower.to_vec());
                band.lower = Spd::new(self.grid, lower.into_iter().map(|v| v.max(0.0)).collect())?;
                band.upper = Spd::new(self.grid, map.apply(band.upper.to_vec()))?;
            }
        }
        Ok(())
    }

    /// `ColorChecker Digital SG, ColorChecker 24`: the charts the set's models read, as
    /// people know them.
    fn charts(&self) -> String {
        self.prepared
            .models
            .models()
            .iter()
            .map(|m| {
                m.model
                    .header()
                    .chart
                    .as_deref()
                    .map_or_else(|| "unknown".to_string(), shown_chart_name)
            })
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// `daylight, fluorescent`: the kinds `priors` hold, or `none`.
fn kind_names(priors: Option<&KindPriors>) -> String {
    let names: Vec<&str> = priors
        .map(|p| p.kinds.iter().map(|k| k.kind.name()).collect())
        .unwrap_or_default();
    if names.is_empty() {
        "none".to_string()
    } else {
        names.join(", ")
    }
}

/// The model's SPDs for some rows (on its grid, peak 1, row-major): as a named kind of
/// light moved them, and the model's own output when a kind moved them.
struct ModelSpds {
    /// The SPDs the estimates are made of.
    told: Vec<f64>,
    /// The model's own output, when a kind of light moved it to `told`.
    own: Option<Vec<f64>>,
    /// The raw patches' XYZ ([`raw_row`]), when a raw model read a raw photo's spectrum.
    raw_row: Option<Vec<f64>>,
}

impl ModelSpds {
    /// The model's own output (before a kind of light moved it).
    fn own(&self) -> &[f64] {
        self.own.as_deref().unwrap_or(&self.told)
    }
}

/// A raw photo's feature row for a raw model: the XYZ of each of `feature_patches` (the
/// chart's patches the model reads, in its order) through the file's matrices, white
/// Y = 100 ([`RawReading::patch_xyz`]); `source` names the photo in an error.
pub fn raw_row(reading: &RawReading, feature_patches: &[usize], source: &str) -> Result<Vec<f64>> {
    let mut row = Vec::with_capacity(3 * feature_patches.len());
    for &p in feature_patches {
        let xyz = reading.patch_xyz.get(p).ok_or_else(|| {
            InferError::invalid(format!(
                "{source}: the raw reading holds no patch {}",
                p + 1
            ))
        })?;
        row.extend(xyz.map(f64::from));
    }
    Ok(row)
}
