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

use crate::absolute::{absolute_level, chart_level};
use crate::error::{InferError, Result};
use crate::estimate::{Colorimetry, Estimate};
use crate::feature_rows::FeatureRows;
use crate::kind_prior::{self, KindPriors};
use crate::measured_colour;
use crate::photo_options::{chart_templates, PhotoOptions};
use crate::places;
use crate::shipped::{ModelSet, NamedModel};
use crate::stream::{check_feature_rows, row_name, FeatureStream, GridMap};
use crate::trust::{
    self, feature_scale, ChartCheck, ChartIdentity, Identity, PhotoFlags, Trust, TrustCalibration,
    Verdict,
};
use rayon::prelude::*;
use spdcam_core::advice::{Advice, Sampled};
use spdcam_core::builtin::DataDir;
use spdcam_core::chart::{shown_chart_name, Chart};
use spdcam_core::light_families::LightKind;
use spdcam_core::photo::{
    self, analysis_overlay_jpeg, debug_paths, AnalyseOptions, ChartTemplate, Photo, PhotoAnalysis,
};
use spdcam_core::quality::LightingMetrics;
use spdcam_core::spectral::{Grid, Spd};
use std::ops::Range;
use std::path::{Path, PathBuf};
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

    /// The estimator of the shipped models (see [`ModelSet::shipped`]).
    pub fn shipped(data_dir: DataDir, grid: Grid) -> Result<Estimator> {
        Estimator::new(ModelSet::shipped()?, data_dir, grid)
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
        Estimator::with(self.prepared.clone(), self.priors.clone(), self.light, grid)
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

    /// The estimate for the photo file at `path`, labelled with its file name.
    pub fn estimate_photo(&self, path: &Path, options: &PhotoOptions) -> Result<Estimate> {
        self.estimate_photos(&[path.to_path_buf()], options, |_| Ok::<(), InferError>(()))?
            .pop()
            .ok_or_else(|| InferError::invalid("no photo analysed"))?
            .into_estimate()
    }

    /// Photo files the whole way, in one call: each analysed (in parallel; one bad photo
    /// does not cost the others), then estimated by the model for its chart, labelled with
    /// its file name (its path where names repeat). One [`PhotoEstimate`] per chart found
    /// (every chart of a photo that shows several, each labelled `NAME place K` and compared
    /// with the others, [`crate::places`]), or per photo that could not be used, in order:
    /// the analysis, the debug image written for it and the estimate. `progress`
    /// hears of each step ([`PhotoProgress`]) so that a front end prints between them; an
    /// error it returns stops the work.
    pub fn estimate_photos<E: From<InferError>>(
        &self,
        paths: &[PathBuf],
        options: &PhotoOptions,
        mut progress: impl FnMut(PhotoProgress<'_>) -> std::result::Result<(), E>,
    ) -> std::result::Result<Vec<PhotoEstimate>, E> {
        if options.corners.is_some() && paths.len() > 1 {
            return Err(InferError::invalid(format!(
                "corners apply to one photo; {} were given",
                paths.len()
            ))
            .into());
        }
        let templates = self.templates(options.chart.as_deref())?;
        let debug = options.debug.as_ref().map(|d| debug_paths(d, paths));
        let per_photo: Vec<Vec<PhotoEstimate>> = paths
            .par_iter()
            .enumerate()
            .map(|(i, path)| {
                let debug = debug.as_ref().map(|d| d[i].clone());
                let mut found = match photo::load_photo(path) {
                    Ok(decoded) => {
                        self.analyse_places_with(&decoded, options, templates.clone(), debug)
                    }
                    Err(e) => vec![PhotoEstimate::unusable(e.into())],
                };
                found.iter_mut().for_each(|p| p.photo = i);
                found
            })
            .collect();
        let mut photos: Vec<PhotoEstimate> = per_photo.into_iter().flatten().collect();
        progress(PhotoProgress::Analysed(&photos))?;
        let labels = photo_labels(paths);
        for photo in &mut photos {
            if let Ok(analysed) = &photo.analysed {
                progress(PhotoProgress::Estimating(&analysed.analysis))?;
                let label = place_label(&labels[photo.photo], &analysed.analysis);
                self.estimate_analysed(photo, label);
            }
        }
        compare_photo_places(&mut photos);
        Ok(photos)
    }

    /// The estimate for a photo held in memory (an upload, never written to disk), decoded
    /// with the same limits as a file and labelled `name`.
    ///
    /// ```
    /// use spdcam_core::builtin::DataDir;
    /// use spdcam_core::chart::KnownChart;
    /// use spdcam_core::spectral::Grid;
    /// use spdcam_infer::{Estimator, PhotoOptions};
    ///
    /// let estimator = Estimator::shipped(DataDir::new(None), Grid::ESTIMATION)?;
    /// let jpeg = std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/sg-telelumen.jpg"))?;
    /// let estimate = estimator.estimate_photo_bytes(&jpeg, "upload.jpg", &PhotoOptions::default())?;
    /// assert_eq!(estimate.photo.unwrap().chart, KnownChart::Sg140.name());
    /// let err = estimator.estimate_photo_bytes(b"not a photo", "notes.txt", &PhotoOptions::default());
    /// assert!(err.unwrap_err().to_string().contains("notes.txt"));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn estimate_photo_bytes(
        &self,
        bytes: &[u8],
        name: &str,
        options: &PhotoOptions,
    ) -> Result<Estimate> {
        self.photo_bytes(bytes, name, options).into_estimate()
    }

    /// A photo held in memory the whole way, in one call: its analysis (with the picture of
    /// the chart found when `options.overlay_width` asks for it), the debug image written
    /// and its estimate, labelled `name`.
    pub fn photo_bytes(&self, bytes: &[u8], name: &str, options: &PhotoOptions) -> PhotoEstimate {
        let decoded = match photo::decode_photo(bytes, name) {
            Ok(decoded) => decoded,
            Err(e) => return PhotoEstimate::unusable(e.into()),
        };
        let mut photo = match self.templates(options.chart.as_deref()) {
            Ok(templates) => self.analyse_with(&decoded, options, templates, options.debug.clone()),
            Err(e) => PhotoEstimate::unusable(e),
        };
        self.estimate_analysed(&mut photo, name.into());
        photo
    }

    /// A photo held in memory the whole way, every chart it shows: one [`PhotoEstimate`] per
    /// chart (as [`Estimator::estimate_photos`] gives them, labelled `name`, or `name place
    /// K` where there are several, and compared across places), or one with why the photo
    /// could not be used.
    pub fn photo_bytes_places(
        &self,
        bytes: &[u8],
        name: &str,
        options: &PhotoOptions,
    ) -> Vec<PhotoEstimate> {
        match photo::decode_photo(bytes, name) {
            Ok(decoded) => self.photo_places(&decoded, name, options),
            Err(e) => vec![PhotoEstimate::unusable(e.into())],
        }
    }

    /// [`Estimator::photo_bytes_places`] for a photo already decoded (a file read, or a
    /// pixel array in Python).
    pub fn photo_places(
        &self,
        photo: &Photo,
        name: &str,
        options: &PhotoOptions,
    ) -> Vec<PhotoEstimate> {
        let mut photos = match self.templates(options.chart.as_deref()) {
            Ok(templates) => {
                self.analyse_places_with(photo, options, templates, options.debug.clone())
            }
            Err(e) => vec![PhotoEstimate::unusable(e)],
        };
        for one in &mut photos {
            if let Ok(analysed) = &one.analysed {
                let label = place_label(name, &analysed.analysis);
                self.estimate_analysed(one, label);
            }
        }
        compare_photo_places(&mut photos);
        photos
    }

    /// The estimate for a photo already decoded (from bytes, or a pixel array in Python),
    /// labelled with the photo's source.
    pub fn estimate_decoded(&self, photo: &Photo, options: &PhotoOptions) -> Result<Estimate> {
        let analysed = self.analyse_decoded(photo, options)?;
        self.estimate_analysis(analysed.analysis, photo.source.clone())
    }

    /// Analyses a decoded photo with `options` (the chart found among the charts
    /// [`Estimator::templates`] gives, or placed by `options.corners`, and sampled); patches
    /// that are not the chart are refused ([`InferError::NotTheChart`]).
    pub fn analyse_decoded(&self, photo: &Photo, options: &PhotoOptions) -> Result<AnalysedPhoto> {
        let templates = self.templates(options.chart.as_deref())?;
        self.analyse_with(photo, options, templates, options.debug.clone())
            .analysed
    }

    /// One decoded photo analysed with `options` among `templates`, its debug image (if
    /// any) written to `debug`; no estimate yet.
    fn analyse_with(
        &self,
        photo: &Photo,
        options: &PhotoOptions,
        templates: Vec<ChartTemplate>,
        debug: Option<PathBuf>,
    ) -> PhotoEstimate {
        let analyse = AnalyseOptions {
            templates,
            corners: options.corners.clone(),
            debug,
        };
        let (analysis, debug) = photo::analyse_telling_debug(photo, &analyse);
        let mut identified = None;
        let analysed = analysis.map_err(InferError::from).and_then(|analysis| {
            let (analysis, found) = self.the_chart_placed(photo, &analyse, analysis)?;
            identified = found.map(Carried);
            let overlay = match options.overlay_width {
                Some(width) => Some(overlay_of(photo, &analyse.templates, &[&analysis], width)?),
                None => None,
            };
            Ok(AnalysedPhoto { analysis, overlay })
        });
        PhotoEstimate {
            debug,
            analysed,
            estimate: None,
            identified,
            photo: 0,
        }
    }

    /// [`Estimator::analyse_with`] for every chart the photo shows (`options.corners`: the
    /// one or several they hold, four corners each): one [`PhotoEstimate`] per chart, the
    /// debug image (drawing them all) on the first. A chart whose patches are refused as not
    /// the chart keeps its refusal.
    fn analyse_places_with(
        &self,
        photo: &Photo,
        options: &PhotoOptions,
        templates: Vec<ChartTemplate>,
        debug: Option<PathBuf>,
    ) -> Vec<PhotoEstimate> {
        if options.corners.as_ref().is_some_and(|c| c.len() <= 4) {
            return vec![self.analyse_with(photo, options, templates, debug)];
        }
        let analyse = AnalyseOptions {
            templates,
            corners: options.corners.clone(),
            debug,
        };
        let (analyses, debug) = photo::analyse_places_telling_debug(photo, &analyse);
        let analyses = match analyses {
            Ok(analyses) => analyses,
            Err(e) => {
                let mut unusable = PhotoEstimate::unusable(e.into());
                unusable.debug = debug;
                return vec![unusable];
            }
        };
        // One drawing of every place, numbered, shared by their reports.
        let overlay = match options.overlay_width {
            Some(width) => {
                let all: Vec<&PhotoAnalysis> = analyses.iter().collect();
                Some(overlay_of(photo, &analyse.templates, &all, width).map_err(|e| e.to_string()))
            }
            None => None,
        };
        let mut debug = debug;
        analyses
            .into_iter()
            .map(|analysis| {
                let mut identified = None;
                let analysed = self.refuse_not_the_chart(&analysis).and_then(|found| {
                    identified = found.map(Carried);
                    let overlay = overlay.clone().transpose().map_err(InferError::invalid)?;
                    Ok(AnalysedPhoto { analysis, overlay })
                });
                PhotoEstimate {
                    debug: debug.take(),
                    analysed,
                    estimate: None,
                    identified,
                    photo: 0,
                }
            })
            .collect()
    }

    /// The estimate for an analysed photo, by the model for the chart it shows, labelled
    /// `name`, judged with what the analysis found (detection, clipped and dark patches).
    /// Patches that do not behave like the chart are refused first
    /// ([`InferError::NotTheChart`]; see [`trust::chart_identity`]): no number is made of
    /// them, whether the chart was detected or its corners given.
    pub fn estimate_analysis(&self, analysis: PhotoAnalysis, name: String) -> Result<Estimate> {
        let identified = self.identify(&analysis)?;
        self.estimate_identified(analysis, identified, name)
    }

    /// [`Estimator::estimate_analysis`] of a photo already identified: the model's SPD made
    /// when the analysis was checked is the estimate's, not made again.
    fn estimate_identified(
        &self,
        analysis: PhotoAnalysis,
        identified: Identified,
        name: String,
    ) -> Result<Estimate> {
        self.prepared.trust[identified.index].identity.require(
            &identified.identity,
            sampled(&analysis),
            &analysis.source,
        )?;
        let model_spds = identified.model_spds?;
        let own = model_spds.own().to_vec();
        self.judged(
            identified.index,
            name,
            model_spds.told,
            &own,
            &identified.rows.values,
            &identified.flags,
            Some(analysis),
        )
    }

    /// The estimate of a photo analysed by [`Estimator::analyse_with`], from what its check
    /// identified when there is that (else identified now), labelled `name`.
    fn estimate_analysed(&self, photo: &mut PhotoEstimate, name: String) {
        let Ok(analysed) = &photo.analysed else {
            return;
        };
        let analysis = analysed.analysis.clone();
        photo.estimate = Some(match photo.identified.take() {
            Some(identified) => self.estimate_identified(analysis, identified.0, name),
            None => self.estimate_analysis(analysis, name),
        });
    }

    /// `analysis` when its patches are the chart; else, with corners given and several
    /// charts looked for, the first other chart those corners hold (the patches of one chart
    /// can fit the grid of another better: the ColorChecker 24's six columns and the SG's
    /// twelve), its debug image written again; else the refusal.
    fn the_chart_placed(
        &self,
        photo: &Photo,
        analyse: &AnalyseOptions,
        analysis: PhotoAnalysis,
    ) -> Result<(PhotoAnalysis, Option<Identified>)> {
        let refusal = match self.refuse_not_the_chart(&analysis) {
            Ok(identified) => return Ok((analysis, identified)),
            Err(refusal) => refusal,
        };
        if analyse.corners.is_none() {
            return Err(refusal);
        }
        analyse
            .templates
            .iter()
            .filter(|t| t.name != analysis.chart)
            .find_map(|t| {
                let one = AnalyseOptions {
                    templates: vec![t.clone()],
                    ..analyse.clone()
                };
                let other = photo::analyse(photo, &one).ok()?;
                self.refuse_not_the_chart(&other)
                    .ok()
                    .map(|identified| (other, identified))
            })
            .ok_or(refusal)
    }

    /// Refuses an analysed photo whose patches are not the chart ([`InferError::NotTheChart`]),
    /// so that it is told with the photos that cannot be used, before any estimate; other
    /// errors are left for the estimate to give. What was identified is kept for the
    /// estimate, so that the model runs once per photo.
    fn refuse_not_the_chart(&self, analysis: &PhotoAnalysis) -> Result<Option<Identified>> {
        match self.identify(analysis) {
            Ok(found) => {
                self.prepared.trust[found.index].identity.require(
                    &found.identity,
                    sampled(analysis),
                    &analysis.source,
                )?;
                Ok(Some(found))
            }
            Err(_) => Ok(None),
        }
    }

    /// Whether an analysed photo shows the chart it is said to: the statistics of
    /// [`trust::chart_identity`], the shuffled one under the model's estimate (or, where the
    /// model refuses the features, under an equal-energy light) when the chart's
    /// reflectances are at hand. [`Estimator::estimate_photo`] refuses the photo when they
    /// find anything against the chart (`Identity::mismatches`).
    pub fn photo_identity(&self, analysis: &PhotoAnalysis) -> Result<Identity> {
        Ok(self.identify(analysis)?.identity)
    }

    /// The model for `analysis`, its features and flags, its identity and the model's SPDs
    /// (or why the model made none). What needs no light is measured first, and the model
    /// is not run when it finds anything against the chart.
    fn identify(&self, analysis: &PhotoAnalysis) -> Result<Identified> {
        let rows = FeatureRows::of_analyses(&[analysis])?;
        let index = self.choose(&rows.names, &analysis.source).map_err(|_| {
            InferError::invalid(format!(
                "{}: no model for chart {}; the models are for {}",
                analysis.source,
                shown_chart_name(&analysis.chart),
                self.charts()
            ))
        })?;
        let chosen = self.named(index);
        let feature_patches = chosen
            .model
            .photo_chart()
            .filter(|t| t.name == analysis.chart)
            .map(|t| t.feature_patches.as_slice());
        let flags = trust::photo_flags(analysis, feature_patches);
        let judge = &self.prepared.trust[index];
        let scale = feature_scale(&rows.values);
        let mut identity = judge.identity.of_photo(analysis, scale);
        let model_spds = if identity.mismatches().is_empty() {
            self.run_model_measured(
                index,
                &rows,
                &analysis.source,
                analysis.raw.as_ref().map(|r| r.light_xy),
            )
        } else {
            Err(InferError::invalid("the patches are not the chart"))
        };
        if let Some(check) = &judge.check {
            let light = match &model_spds {
                Ok(spds) => spds.told.clone(),
                Err(_) => vec![1.0; chosen.model.grid().count],
            };
            judge.identity.add_shuffled(
                &mut identity,
                &rows.values,
                scale,
                &flags.clipped,
                (check, &light),
            )?;
        }
        Ok(Identified {
            index,
            rows,
            flags,
            identity,
            model_spds,
        })
    }

    /// Whether each of the feature rows `features` holds the patches of the model's chart:
    /// the statistics of [`trust::chart_identity`], the shuffled one under the model's
    /// estimate when the chart's reflectances are at hand. [`Estimator::estimate_rows`] and
    /// [`Estimator::stream`] refuse a row when they find anything against the chart.
    pub fn row_identities(&self, features: &FeatureRows, source: &str) -> Result<Vec<Identity>> {
        let index = self.choose(&features.names, source)?;
        let model_spds = self.run_model(index, features, source)?.told;
        let width = features.names.len().max(1);
        let d = self.named(index).model.grid().count.max(1);
        features
            .values
            .par_chunks(width)
            .zip(model_spds.par_chunks(d))
            .map(|(row, spd)| self.row_identity(index, row, spd))
            .collect()
    }

    /// The identity of one feature row whose SPD under model `index` is `spd`.
    fn row_identity(&self, index: usize, row: &[f64], spd: &[f64]) -> Result<Identity> {
        let judge = &self.prepared.trust[index];
        let scale = feature_scale(row);
        let mut identity = judge.identity.of_row(row, scale);
        if let Some(check) = &judge.check {
            judge
                .identity
                .add_shuffled(&mut identity, row, scale, &[], (check, spd))?;
        }
        Ok(identity)
    }

    /// Refuses the first of feature rows `values` (row-major, the first being row
    /// `first_row`, 0-based) that does not behave like model `index`'s chart, with the SPDs
    /// `model_spds` the model made of them (see [`trust::chart_identity`]).
    fn require_chart_rows(
        &self,
        index: usize,
        values: &[f64],
        model_spds: &[f64],
        source: &str,
        first_row: usize,
    ) -> Result<()> {
        let identity = &self.prepared.trust[index].identity;
        let width = self.named(index).model.feature_names().len().max(1);
        let d = self.named(index).model.grid().count.max(1);
        let failed = values
            .par_chunks(width)
            .zip(model_spds.par_chunks(d))
            .enumerate()
            .find_map_first(|(k, (row, spd))| {
                self.row_identity(index, row, spd)
                    .and_then(|found| {
                        identity.require(&found, Sampled::Row(first_row + k + 1), source)
                    })
                    .err()
            });
        failed.map_or(Ok(()), Err)
    }

    /// Judged estimates for feature rows, each labelled `estimate_N` (1-based), by the
    /// model for their columns; `source` names the rows in errors. The rows are judged in
    /// parallel.
    ///
    /// ```
    /// use spdcam_core::builtin::{self, DataDir};
    /// use spdcam_core::camera::sensor::Sensitivities;
    /// use spdcam_core::camera::{Camera, CameraConfig};
    /// use spdcam_core::chart::Chart;
    /// use spdcam_core::cie_illuminant::StandardIlluminant;
    /// use spdcam_core::spectral::Grid;
    /// use spdcam_infer::{Estimator, FeatureRows};
    ///
    /// // The ColorChecker 24 under illuminant A, through the virtual camera.
    /// let grid = Grid::SIMULATION;
    /// let table = &builtin::CAMERAS[0];
    /// let sensitivities = Sensitivities::new(table.name, &table.load()?, &grid)?;
    /// let chart = Chart::colorchecker24(&grid)?;
    /// let names = chart.feature_names();
    /// let camera = Camera::new(&sensitivities, chart, CameraConfig::default(), &grid)?;
    /// let a = StandardIlluminant::A.spd(&grid)?;
    /// let (mut raw, mut row) = (Vec::new(), Vec::new());
    /// camera.features_fast(&camera.light(&a)?, &mut raw, &mut row);
    /// let values = row.iter().map(|&v| f64::from(v)).collect();
    ///
    /// let estimator = Estimator::shipped(DataDir::new(None), Grid::ESTIMATION)?;
    /// let rows = FeatureRows::from_values(names, values, "rendered")?;
    /// let estimate = &estimator.estimate_rows(&rows, "rendered")?[0];
    /// assert_eq!(estimate.name, "estimate_1");
    /// // A warm light: a CCT near illuminant A's 2856 K.
    /// let cct = estimate.colorimetry.cct.unwrap();
    /// assert!((2300.0..3500.0).contains(&cct), "{cct}");
    /// assert!(estimate.trust.is_some());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn estimate_rows(&self, features: &FeatureRows, source: &str) -> Result<Vec<Estimate>> {
        let index = self.choose(&features.names, source)?;
        let model_spds = self.run_model(index, features, source)?;
        self.require_chart_rows(index, &features.values, &model_spds.told, source, 0)?;
        let width = features.names.len();
        let d = self.named(index).model.grid().count;
        features
            .values
            .par_chunks(width)
            .zip(model_spds.told.par_chunks(d))
            .zip(model_spds.own().par_chunks(d))
            .enumerate()
            .map(|(i, ((row, spd), own))| {
                self.judged(
                    index,
                    row_name(i),
                    spd.to_vec(),
                    own,
                    row,
                    &PhotoFlags::default(),
                    None,
                )
            })
            .collect()
    }

    /// Feature rows from `stream`, estimated a block at a time (see [`RowStream`]); the
    /// model is the one for the stream's columns.
    ///
    /// ```
    /// use spdcam_core::builtin::{self, DataDir};
    /// use spdcam_core::camera::sensor::Sensitivities;
    /// use spdcam_core::camera::{Camera, CameraConfig};
    /// use spdcam_core::chart::Chart;
    /// use spdcam_core::cie_illuminant::StandardIlluminant;
    /// use spdcam_core::spectral::Grid;
    /// use spdcam_infer::stream::FeatureStream;
    /// use spdcam_infer::Estimator;
    ///
    /// // Two rows of the ColorChecker 24 through the virtual camera, under A and D65.
    /// let grid = Grid::SIMULATION;
    /// let table = &builtin::CAMERAS[0];
    /// let sensitivities = Sensitivities::new(table.name, &table.load()?, &grid)?;
    /// let chart = Chart::colorchecker24(&grid)?;
    /// let names = chart.feature_names();
    /// let camera = Camera::new(&sensitivities, chart, CameraConfig::default(), &grid)?;
    /// let mut text = names.join(",") + "\n";
    /// for light in [StandardIlluminant::A, StandardIlluminant::D65] {
    ///     let (mut raw, mut row) = (Vec::new(), Vec::new());
    ///     camera.features_fast(&camera.light(&light.spd(&grid)?)?, &mut raw, &mut row);
    ///     let cells: Vec<String> = row.iter().map(|v| v.to_string()).collect();
    ///     text.push_str(&(cells.join(",") + "\n"));
    /// }
    ///
    /// let estimator = Estimator::shipped(DataDir::new(None), Grid::ESTIMATION)?;
    /// let file = FeatureStream::new(Box::new(std::io::Cursor::new(text)), "rows.csv")?;
    /// let mut stream = estimator.stream(file, "rows.csv")?;
    /// let block = stream.next_block()?.unwrap();
    /// assert_eq!((block.rows, block.spds.len()), (2, 2 * 61));
    /// // The full judged estimate of a row, only when it is wanted.
    /// let second = stream.estimate(&block, 1)?;
    /// assert_eq!(second.name, "estimate_2");
    /// assert_eq!(second.spd.values(), &block.spds[61..]);
    /// assert!(stream.next_block()?.is_none());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn stream(&self, stream: FeatureStream, source: &str) -> Result<RowStream<'_>> {
        let index = self.choose(stream.names(), source)?;
        self.map(index)?;
        Ok(RowStream {
            estimator: self,
            stream,
            index,
            source: source.to_string(),
            rows: 0,
        })
    }

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
        measured: Option<[f64; 2]>,
    ) -> Result<ModelSpds> {
        let model = &self.named(index).model;
        model.check_features(&features.names, source)?;
        self.map(index)?;
        check_feature_rows(
            &features.values,
            &features.names,
            source,
            0,
            features.rows > 1,
        )?;
        let mut spds = model.estimate_rows(&features.values)?;
        if let Some(xy) = measured {
            measured_colour::conform(model, &mut spds, xy);
        }
        self.told_of_light(index, spds)
    }

    /// THE constructor of every estimate: the model's SPD `model_spd` (on its grid, peak 1)
    /// for `row`, judged (the self-check, the perturbed spread, the calibration; `flags`
    /// what a photo analysis found), and everything read from it on the output grid.
    /// `own` is the model's output before a kind of light moved it (`model_spd` itself
    /// when none was named), which the kind's check weighs.
    #[allow(clippy::too_many_arguments)]
    fn judged(
        &self,
        index: usize,
        name: String,
        model_spd: Vec<f64>,
        own: &[f64],
        row: &[f64],
        flags: &PhotoFlags,
        photo: Option<PhotoAnalysis>,
    ) -> Result<Estimate> {
        let chosen = self.named(index);
        let map = self.map(index)?;
        let judge = &self.prepared.trust[index];
        let mut trust = trust::assess(
            &chosen.model,
            judge.calibration.as_ref(),
            judge.check.as_ref(),
            row,
            &model_spd,
            flags,
        )?;
        self.bands_on_grid(&mut trust, map)?;
        self.check_kind(index, own, &mut trust)?;
        // The colorimetry, the metrics and the absolute level are of the model's whole
        // estimate, whatever part of it the output grid shows.
        let full = Spd::new(chosen.model.grid(), model_spd.clone())?;
        let spd = Spd::new(self.grid, map.apply(model_spd))?;
        let metrics = LightingMetrics::of_spd(&full);
        let colorimetry = Colorimetry::of_metrics(&metrics)?;
        if photo.as_ref().is_some_and(|a| a.raw.is_some()) {
            if let (Some(u), Some(cct)) = (&mut trust.uncertainty, colorimetry.cct) {
                measured_colour::set_intervals(&mut u.metrics, cct);
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

/// The picture of the chart found on `photo` (as `--debug` draws it), `width` pixels wide,
/// as JPEG.
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

fn overlay_of(
    photo: &Photo,
    templates: &[ChartTemplate],
    analyses: &[&PhotoAnalysis],
    width: u32,
) -> Result<Vec<u8>> {
    let detections: Vec<_> = analyses.iter().map(|a| a.detection()).collect();
    let found = analyses
        .iter()
        .zip(&detections)
        .map(|(analysis, detection)| {
            let template = templates
                .iter()
                .find(|t| t.name == analysis.chart)
                .ok_or_else(|| {
                    InferError::invalid(format!(
                        "{}: no template of chart {}",
                        analysis.source, analysis.chart
                    ))
                })?;
            Ok((template, detection, analysis.patches.as_slice()))
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(analysis_overlay_jpeg(photo, &found, width)?)
}

/// An estimate's label: the photo's, with the place where the photo shows several charts.
fn place_label(photo: &str, analysis: &PhotoAnalysis) -> String {
    match analysis.place {
        Some(place) => format!("{photo} place {}", place.number),
        None => photo.to_string(),
    }
}

/// Sets [`Estimate::across_places`] on every estimate made of a photo with several charts,
/// the estimates grouped by their photo's source.
fn compare_photo_places(photos: &mut [PhotoEstimate]) {
    let mut sources: Vec<String> = photos
        .iter()
        .filter_map(made)
        .filter_map(|e| e.photo.as_ref().filter(|p| p.place.is_some()))
        .map(|p| p.source.clone())
        .collect();
    sources.sort();
    sources.dedup();
    for source in sources {
        let readings: Vec<places::PlaceReading> = photos
            .iter()
            .filter_map(made)
            .filter_map(|e| place_reading(e, &source))
            .collect();
        let across = places::LightAcrossPlaces::of(&readings);
        for p in photos.iter_mut() {
            if let Some(Ok(e)) = &mut p.estimate {
                if place_reading(e, &source).is_some() {
                    e.across_places = across.clone();
                }
            }
        }
    }
}

/// The estimate made of `photo`, when one was.
fn made(photo: &PhotoEstimate) -> Option<&Estimate> {
    photo.estimate.as_ref().and_then(|e| e.as_ref().ok())
}

/// What `estimate` gave at its place, when it is one of several charts in the photo
/// `source`.
fn place_reading<'a>(estimate: &'a Estimate, source: &str) -> Option<places::PlaceReading<'a>> {
    let photo = estimate.photo.as_ref().filter(|p| p.source == source)?;
    let place = photo.place?;
    Some(places::PlaceReading {
        number: place.number,
        centre: place.centre,
        xy: estimate.colorimetry.xy,
        cct: estimate.colorimetry.cct,
        duv: estimate.colorimetry.duv,
        level: estimate.light_level.as_ref(),
    })
}

/// Where the patches of `analysis` came from: corners placed by hand, or detection.
fn sampled(analysis: &PhotoAnalysis) -> Sampled {
    match analysis.method {
        "corners" => Sampled::Corners,
        _ => Sampled::Detected,
    }
}

/// Column labels for photos: their file names, or their paths where names repeat.
fn photo_labels(photos: &[PathBuf]) -> Vec<String> {
    let names: Vec<String> = photos
        .iter()
        .map(|p| {
            p.file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_else(|| p.display().to_string())
        })
        .collect();
    names
        .iter()
        .zip(photos)
        .map(|(n, p)| {
            if names.iter().filter(|m| *m == n).count() > 1 {
                p.display().to_string()
            } else {
                n.clone()
            }
        })
        .collect()
}

/// What [`Estimator::identify`] found of an analysed photo.
struct Identified {
    /// The index of the model for its chart.
    index: usize,
    /// Its feature row.
    rows: FeatureRows,
    /// What the analysis found that bears on trust.
    flags: PhotoFlags,
    /// Whether it is the chart.
    identity: Identity,
    /// The model's SPD (on its grid), or why there is none.
    model_spds: Result<ModelSpds>,
}

/// The model's SPDs for some rows (on its grid, peak 1, row-major): as a named kind of
/// light moved them, and the model's own output when a kind moved them.
struct ModelSpds {
    /// The SPDs the estimates are made of.
    told: Vec<f64>,
    /// The model's own output, when a kind of light moved it to `told`.
    own: Option<Vec<f64>>,
}

impl ModelSpds {
    /// The model's own output (before a kind of light moved it).
    fn own(&self) -> &[f64] {
        self.own.as_deref().unwrap_or(&self.told)
    }
}

/// What [`Estimator::identify`] found of a photo, carried from its analysis to its estimate
/// (opaque: the printed form says only that it is there).
struct Carried(Identified);

impl std::fmt::Debug for Carried {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Carried(identified)")
    }
}

/// One photo's way through the [`Estimator`] ([`Estimator::estimate_photos`],
/// [`Estimator::photo_bytes`]): its analysis, the debug image written for it and its
/// estimate.
#[derive(Debug)]
pub struct PhotoEstimate {
    /// The debug image written for the photo (`PhotoOptions::debug`), also when no chart
    /// was found in it; `None` when none was written.
    pub debug: Option<PathBuf>,
    /// What the photo gave, or why it could not be used (unreadable, no chart found, not
    /// the chart).
    pub analysed: Result<AnalysedPhoto>,
    /// The estimate, or why the model gave none; `None` while not made (the photo could
    /// not be used, or [`PhotoProgress::Analysed`] reports before any estimate).
    pub estimate: Option<Result<Estimate>>,
    /// What checking the analysis identified (the model's SPD among it), for the estimate.
    identified: Option<Carried>,
    /// The photo's position (0-based) among the paths given to
    /// [`Estimator::estimate_photos`] (0 for a single photo): several charts of one photo
    /// share it.
    pub photo: usize,
}

impl PhotoEstimate {
    fn unusable(error: InferError) -> PhotoEstimate {
        PhotoEstimate {
            debug: None,
            analysed: Err(error),
            estimate: None,
            identified: None,
            photo: 0,
        }
    }

    /// The estimate, or why there is none (the photo's error first).
    pub fn into_estimate(self) -> Result<Estimate> {
        self.analysed?;
        self.estimate
            .unwrap_or_else(|| Err(InferError::invalid("no estimate was made")))
    }
}

/// The steps [`Estimator::estimate_photos`] reports, so that a front end prints between
/// them.
#[derive(Debug)]
pub enum PhotoProgress<'a> {
    /// Every photo analysed (in order), before any estimate is made.
    Analysed(&'a [PhotoEstimate]),
    /// The estimate of this analysed photo is about to be made.
    Estimating(&'a PhotoAnalysis),
}

/// A photo analysed by the [`Estimator`].
#[derive(Debug, Clone)]
pub struct AnalysedPhoto {
    /// What the photo gave.
    pub analysis: PhotoAnalysis,
    /// The photo with the chart found drawn on it (as `--debug` draws it), reduced to
    /// `PhotoOptions::overlay_width` and encoded as JPEG, when asked for.
    pub overlay: Option<Vec<u8>>,
}

/// Feature rows read a block at a time and estimated by one model (see
/// [`Estimator::stream`]): time linear in the rows, memory bounded whatever their number.
/// The SPDs of a block come cheap; [`RowStream::estimate`] makes the full judged estimate
/// of any row of it.
pub struct RowStream<'a> {
    estimator: &'a Estimator,
    stream: FeatureStream,
    index: usize,
    source: String,
    rows: usize,
}

/// One block of a [`RowStream`]: the rows' features and their SPDs.
#[derive(Debug, Clone)]
pub struct EstimatedBlock {
    /// The number (0-based) of the block's first row among all rows.
    pub first_row: usize,
    /// Number of rows.
    pub rows: usize,
    /// The features, row-major.
    pub features: Vec<f64>,
    /// The SPDs on the estimator's grid, peak 1, row-major.
    pub spds: Vec<f64>,
    /// The SPDs on the model's grid, as the judge takes them.
    model_spds: Vec<f64>,
    /// The model's own SPDs before a named kind of light moved them (`None` when none was
    /// named: they are `model_spds`).
    own_spds: Option<Vec<f64>>,
}

impl RowStream<'_> {
    /// The name of the model estimating the rows.
    pub fn model_name(&self) -> &str {
        &self.estimator.named(self.index).name
    }

    /// The next block of rows with their SPDs, or `None` after the last. Rows that say
    /// nothing about the light, or that are not the model's chart
    /// ([`trust::chart_identity`]), are refused, naming the row (1-based in the file).
    pub fn next_block(&mut self) -> Result<Option<EstimatedBlock>> {
        let Some(block) = self.stream.next_block(self.rows)? else {
            return Ok(None);
        };
        let names = self.stream.names();
        check_feature_rows(&block.values, names, &self.source, block.first_row, true)?;
        let ModelSpds {
            told: model_spds,
            own,
        } = self.estimator.told_of_light(
            self.index,
            self.estimator
                .named(self.index)
                .model
                .estimate_rows(&block.values)?,
        )?;
        self.estimator.require_chart_rows(
            self.index,
            &block.values,
            &model_spds,
            &self.source,
            block.first_row,
        )?;
        let spds = self.estimator.map(self.index)?.apply(model_spds.clone());
        self.rows += block.rows;
        Ok(Some(EstimatedBlock {
            first_row: block.first_row,
            rows: block.rows,
            features: block.values,
            spds,
            model_spds,
            own_spds: own,
        }))
    }

    /// The full judged estimate of row `k` of `block`, named `estimate_N` after its place
    /// among all rows: the SPD the block holds, not estimated again.
    pub fn estimate(&self, block: &EstimatedBlock, k: usize) -> Result<Estimate> {
        Ok(self.estimates(block, k..k + 1)?.remove(0))
    }

    /// The full judged estimates of rows `rows` of `block`, in order, as
    /// [`RowStream::estimate`] makes each: judged in parallel, since judging (the self-check,
    /// the perturbed spread, the lighting metrics) costs far more than the SPD.
    pub fn estimates(&self, block: &EstimatedBlock, rows: Range<usize>) -> Result<Vec<Estimate>> {
        if rows.start >= rows.end || rows.end > block.rows {
            return Err(InferError::invalid(format!(
                "rows {}..{} of a block of {} rows",
                rows.start, rows.end, block.rows
            )));
        }
        let width = self.stream.names().len();
        let d = self.estimator.named(self.index).model.grid().count;
        let (estimator, index) = (self.estimator, self.index);
        rows.into_par_iter()
            .map(|k| {
                let own = block.own_spds.as_ref().unwrap_or(&block.model_spds);
                estimator.judged(
                    index,
                    row_name(block.first_row + k),
                    block.model_spds[k * d..(k + 1) * d].to_vec(),
                    &own[k * d..(k + 1) * d],
                    &block.features[k * width..(k + 1) * width],
                    &PhotoFlags::default(),
                    None,
                )
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use spdcam_core::chart::KnownChart;
    use spdcam_core::photo::decode_photo;

    fn example_photo() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/sg-telelumen.jpg")
    }

    fn shipped() -> Estimator {
        Estimator::shipped(DataDir::new(None), Grid::ESTIMATION).unwrap()
    }

    /// The ColorChecker 24 features of `spd` through the first built-in camera.
    fn colorchecker24_row(spd: &Spd) -> FeatureRows {
        use spdcam_core::builtin;
        use spdcam_core::camera::sensor::Sensitivities;
        use spdcam_core::camera::{Camera, CameraConfig};
        let grid = Grid::SIMULATION;
        let table = &builtin::CAMERAS[0];
        let sensitivities = Sensitivities::new(table.name, &table.load().unwrap(), &grid).unwrap();
        let chart = Chart::colorchecker24(&grid).unwrap();
        let names = chart.feature_names();
        let camera = Camera::new(&sensitivities, chart, CameraConfig::default(), &grid).unwrap();
        let (mut raw, mut row) = (Vec::new(), Vec::new());
        camera.features_fast(&camera.light(spd).unwrap(), &mut raw, &mut row);
        let values = row.iter().map(|&v| f64::from(v)).collect();
        FeatureRows::from_values(names, values, "rendered").unwrap()
    }

    #[test]
    fn told_the_kind_an_estimate_keeps_to_such_lights_and_a_wrong_kind_is_named() {
        use spdcam_core::cie_illuminant::{planck, StandardIlluminant};
        let estimator = shipped();
        let a = StandardIlluminant::A.spd(&Grid::SIMULATION).unwrap();
        let truth = planck(2856.0, &Grid::ESTIMATION).unwrap();
        let row = colorchecker24_row(&a);
        let gfc = |e: &Estimate| {
            spdcam_core::spectral_error::gfc(truth.values(), e.spd.values()).unwrap()
        };
        let plain = &estimator.estimate_rows(&row, "A").unwrap()[0];
        let told = estimator.for_light(LightKind::Incandescent).unwrap();
        let incandescent = &told.estimate_rows(&row, "A").unwrap()[0];
        assert_eq!(
            (plain.light, incandescent.light),
            (LightKind::Unknown, LightKind::Incandescent)
        );
        assert!(
            gfc(incandescent) > gfc(plain).max(0.995),
            "told {} against {}",
            gfc(incandescent),
            gfc(plain)
        );
        let json = incandescent.to_json().unwrap();
        assert_eq!(json["light"], "incandescent");
        assert!(plain.to_json().unwrap().get("light").is_none());
        let said = |e: &Estimate| e.trust.as_ref().unwrap().reasons.join(" ");
        assert!(!said(incandescent).contains("does not look like"));
        // Told the light is a colour-mixing LED lamp, the filament's photo is named unlike it
        // and never ok.
        let rgb = &estimator
            .for_light(LightKind::RgbLed)
            .unwrap()
            .estimate_rows(&row, "A")
            .unwrap()[0];
        assert!(
            said(rgb).contains("does not look like colour-mixing LED light"),
            "{}",
            said(rgb)
        );
        assert_ne!(rgb.trust.as_ref().unwrap().verdict, Verdict::Ok);
        // A kind is carried to other grids, and every shipped model knows every kind.
        assert_eq!(
            told.on_grid(Grid::parse("420-680:20").unwrap())
                .unwrap()
                .light(),
            LightKind::Incandescent
        );
        assert_eq!(estimator.light_kinds().unwrap(), LightKind::ALL);
    }

    #[test]
    fn a_candidate_is_judged_by_the_calibration_given_and_refuses_another_models() {
        use spdcam_core::cie_illuminant::StandardIlluminant;
        let shipped_set = ModelSet::shipped().unwrap();
        let cc24 = shipped_set
            .for_known(KnownChart::ColorChecker24)
            .unwrap()
            .clone();
        let sg = shipped_set.for_known(KnownChart::Sg96).unwrap().clone();
        let own = trust::calibration_for(&cc24.model).unwrap().unwrap();
        let row = colorchecker24_row(&StandardIlluminant::D65.spd(&Grid::SIMULATION).unwrap());
        let judge = |cal: TrustCalibration| {
            let e = Estimator::calibrated(cc24.clone(), cal, DataDir::new(None), Grid::ESTIMATION)
                .unwrap();
            e.estimate_rows(&row, "D65")
                .unwrap()
                .remove(0)
                .trust
                .unwrap()
        };
        // With its own calibration, exactly as the shipped estimator judges it.
        let as_shipped = shipped()
            .estimate_rows(&row, "D65")
            .unwrap()
            .remove(0)
            .trust
            .unwrap();
        let given = judge(own.clone());
        assert_eq!(given.verdict, as_shipped.verdict);
        assert_eq!(given.reasons, as_shipped.reasons);
        // A calibration that calls every spread too large is the one that judges.
        let strict = TrustCalibration {
            difficulty_doubtful: 0.0,
            ..own
        };
        let judged = judge(strict);
        assert_ne!(judged.verdict, Verdict::Ok);
        assert!(
            judged.reasons.len() > as_shipped.reasons.len(),
            "{:?}",
            judged.reasons
        );
        // The SG's calibration is not this model's.
        let other = trust::calibration_for(&sg.model).unwrap().unwrap();
        let err = Estimator::calibrated(cc24, other, DataDir::new(None), Grid::ESTIMATION)
            .err()
            .unwrap()
            .to_string();
        assert!(err.contains("made for another model"), "{err}");
    }

    #[test]
    fn a_model_without_priors_cannot_be_told_the_kind() {
        let shipped = ModelSet::shipped().unwrap();
        let model = shipped.models()[0].model.clone();
        let estimator = Estimator::new(
            ModelSet::single(model.clone(), "mine.spdm".to_string()),
            DataDir::new(None),
            Grid::ESTIMATION,
        )
        .unwrap()
        .with_priors(Vec::new())
        .unwrap();
        // The shipped model keeps its built-in priors; priors of another model are refused.
        assert!(estimator.for_light(LightKind::Daylight).is_ok());
        let mut other = kind_prior::priors_for(&model).unwrap().unwrap();
        other.model = "another model".into();
        let err = estimator.with_priors(vec![other]).err().unwrap();
        assert!(err.to_string().contains("no model of the set"), "{err}");
        let mut bare = estimator.clone();
        bare.priors = Arc::new(OnceLock::from(vec![None]));
        let err = bare.for_light(LightKind::Daylight).err().unwrap();
        assert!(
            err.to_string().contains("mine.spdm") && err.to_string().contains("none"),
            "{err}"
        );
        assert_eq!(bare.light_kinds().unwrap(), [LightKind::Unknown]);
        assert!(bare.for_light(LightKind::Unknown).is_ok());
    }

    #[test]
    fn a_photo_runs_the_model_once_for_its_estimate_and_once_for_its_spread() {
        // Issue 52: the chart check and the estimate each ran the model, and a named kind of
        // light ran it a third time. Now: once for the estimate (whose SPD the chart check
        // also uses) and once for the perturbed copies the bands need, by design.
        let bytes = std::fs::read(example_photo()).unwrap();
        for estimator in [
            shipped(),
            shipped().for_light(LightKind::Luminaire).unwrap(),
        ] {
            let before = crate::model::RUNS.with(|r| r.get());
            let photo = estimator.photo_bytes(&bytes, "example.jpg", &PhotoOptions::default());
            let runs = crate::model::RUNS.with(|r| r.get()) - before;
            assert!(photo.into_estimate().is_ok());
            assert_eq!(runs, 2, "{:?}", estimator.light());
        }
    }

    #[test]
    fn a_photo_its_bytes_its_pixels_and_its_row_give_one_estimate() {
        let estimator = shipped();
        let options = PhotoOptions::default();
        let path = example_photo();
        let from_file = estimator.estimate_photo(&path, &options).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let from_bytes = estimator
            .estimate_photo_bytes(&bytes, "in memory", &options)
            .unwrap();
        let decoded = decode_photo(&bytes, "decoded").unwrap();
        let from_pixels = estimator.estimate_decoded(&decoded, &options).unwrap();
        assert_eq!(from_bytes.name, "in memory");
        assert_eq!(from_pixels.name, "decoded");
        let analysis = from_file.photo.as_ref().unwrap();
        let rows = FeatureRows::of_analyses(&[analysis]).unwrap();
        let from_row = estimator.estimate_rows(&rows, "row").unwrap().remove(0);
        assert_eq!(from_row.name, "estimate_1");
        for other in [&from_bytes, &from_pixels, &from_row] {
            assert_eq!(other.spd, from_file.spd);
            assert_eq!(other.colorimetry, from_file.colorimetry);
        }
        // The row carries no photo flags; the photo's own judgement is the same here, as
        // the example photo has no clipped or dark feature patch and a sure detection.
        let verdicts: Vec<_> = [&from_file, &from_bytes, &from_pixels, &from_row]
            .iter()
            .map(|e| e.trust.as_ref().unwrap().clone())
            .collect();
        assert!(verdicts.iter().all(|t| t.verdict == verdicts[0].verdict));
        assert_eq!(verdicts[0].uncertainty, verdicts[3].uncertainty);
        assert_eq!(verdicts[0].self_check, verdicts[3].self_check);
    }

    #[test]
    fn another_grid_shares_the_models_and_resamples_spd_and_bands() {
        let estimator = shipped();
        let coarse = estimator
            .on_grid(Grid::parse("400-700:10").unwrap())
            .unwrap();
        assert!(Arc::ptr_eq(&estimator.prepared, &coarse.prepared));
        let path = example_photo();
        let fine = estimator
            .estimate_photo(&path, &PhotoOptions::default())
            .unwrap();
        let e = coarse
            .estimate_photo(&path, &PhotoOptions::default())
            .unwrap();
        assert_eq!(e.spd.grid(), coarse.grid());
        // Every other 5 nm sample is a 10 nm sample.
        for (k, v) in e.spd.iter().enumerate() {
            assert!((v - fine.spd[2 * k]).abs() < 1e-12, "at {k}");
        }
        let u = e.trust.as_ref().unwrap().uncertainty.as_ref().unwrap();
        assert_eq!(u.band95.lower.grid(), coarse.grid());
        assert_eq!(u.band68.upper.len(), 31);
        // Issue 39: the colorimetry, the metrics and the verdict are the whole estimate's,
        // whatever range is shown.
        let narrow = estimator
            .on_grid(Grid::parse("500-600:5").unwrap())
            .unwrap()
            .estimate_photo(&path, &PhotoOptions::default())
            .unwrap();
        for other in [&e, &narrow] {
            assert_eq!(other.colorimetry, fine.colorimetry);
            assert_eq!(other.metrics, fine.metrics);
            assert_eq!(
                other.trust.as_ref().unwrap().verdict,
                fine.trust.as_ref().unwrap().verdict
            );
        }
    }

    #[test]
    fn a_range_beyond_the_model_or_of_one_wavelength_is_refused() {
        for (range, expected) in [
            ("380-780:5", "the model estimates"),
            ("550-550", "single wavelength"),
        ] {
            let err = shipped()
                .on_grid(Grid::parse(range).unwrap())
                .err()
                .unwrap_or_else(|| panic!("{range} was taken"))
                .to_string();
            assert!(err.contains(expected), "{err}");
        }
    }

    #[test]
    fn a_stream_gives_the_rows_estimates_and_judges_any_row_of_a_block() {
        let estimator = shipped();
        let photo = estimator
            .estimate_photo(&example_photo(), &PhotoOptions::default())
            .unwrap();
        let analysis = photo.photo.as_ref().unwrap();
        let mut text = analysis.feature_names.join(",") + "\n";
        for scale in [1.0f32, 0.5, 0.25] {
            let row: Vec<String> = analysis
                .features
                .iter()
                .map(|v| format!("{}", v * scale))
                .collect();
            text.push_str(&row.join(","));
            text.push('\n');
        }
        let rows = FeatureRows::from_csv_str(&text, "f.csv").unwrap();
        let all = estimator.estimate_rows(&rows, "f.csv").unwrap();
        let source =
            FeatureStream::new(Box::new(std::io::Cursor::new(text.into_bytes())), "f.csv").unwrap();
        let mut stream = estimator.stream(source, "f.csv").unwrap();
        assert_eq!(
            stream.model_name(),
            "the shipped ColorChecker Digital SG model"
        );
        let block = stream.next_block().unwrap().unwrap();
        assert_eq!((block.first_row, block.rows), (0, 3));
        assert!(stream.next_block().unwrap().is_none());
        for (k, e) in all.iter().enumerate() {
            let streamed = stream.estimate(&block, k).unwrap();
            assert_eq!(streamed.name, e.name);
            assert_eq!(streamed.spd.values(), &block.spds[k * 61..(k + 1) * 61]);
            assert_eq!(streamed.trust, e.trust);
        }
        assert!(stream.estimate(&block, 3).is_err());
    }

    #[test]
    fn a_photo_without_a_chart_names_itself() {
        let photo = Photo::from_rgb8("grey.png", 200, 150, vec![128; 200 * 150 * 3]).unwrap();
        let err = shipped()
            .estimate_decoded(&photo, &PhotoOptions::default())
            .unwrap_err()
            .to_string();
        assert!(err.contains("grey.png"), "{err}");
    }

    #[test]
    fn one_call_gives_the_analysis_the_estimate_and_the_debug_image_written() {
        let debug = std::env::temp_dir().join(format!("spdcam-debug-{}.png", std::process::id()));
        let options = PhotoOptions {
            debug: Some(debug.clone()),
            ..PhotoOptions::default()
        };
        let missing = PathBuf::from("no-such-photo.jpg");
        let mut steps = Vec::new();
        let photos = shipped()
            .estimate_photos(&[example_photo(), missing], &options, |step| {
                steps.push(match step {
                    PhotoProgress::Analysed(all) => format!("analysed {}", all.len()),
                    PhotoProgress::Estimating(a) => format!("estimating {}", a.chart),
                });
                Ok::<(), InferError>(())
            })
            .unwrap();
        assert_eq!(steps, ["analysed 2", "estimating colorchecker_sg140"]);
        let written = photos[0].debug.clone().unwrap();
        assert!(written.is_file(), "{}", written.display());
        std::fs::remove_file(&written).unwrap();
        assert!(photos[0].analysed.is_ok());
        assert!(matches!(photos[0].estimate, Some(Ok(_))));
        // The photo that cannot be read writes no debug image and has no estimate.
        assert!(photos[1].debug.is_none() && photos[1].estimate.is_none());
        assert!(photos[1]
            .analysed
            .as_ref()
            .unwrap_err()
            .to_string()
            .contains("no-such-photo"));
    }

    #[test]
    fn the_report_picture_is_drawn_from_the_one_decoding() {
        let options = PhotoOptions {
            overlay_width: Some(320),
            ..PhotoOptions::default()
        };
        let analysed = shipped()
            .estimate_photos(&[example_photo()], &options, |_| Ok::<(), InferError>(()))
            .unwrap()
            .pop()
            .unwrap()
            .analysed
            .unwrap();
        let jpeg = analysed.overlay.unwrap();
        let picture = decode_photo(&jpeg, "overlay.jpg").unwrap();
        assert_eq!(picture.width, 320);
        let plain = shipped()
            .estimate_photos(&[example_photo()], &PhotoOptions::default(), |_| {
                Ok::<(), InferError>(())
            })
            .unwrap()
            .pop()
            .unwrap()
            .analysed
            .unwrap();
        assert!(plain.overlay.is_none());
        assert_eq!(plain.analysis, analysed.analysis);
    }
}
