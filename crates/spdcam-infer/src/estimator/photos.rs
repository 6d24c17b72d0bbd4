//! Photos into estimates: a photo file, its bytes or its decoded pixels analysed (the chart
//! found and sampled), its patches checked for being the chart, and each chart of it
//! estimated, with its place when the photo shows several.

use super::{Estimator, ModelSpds};
use crate::error::{InferError, Result};
use crate::estimate::Estimate;
use crate::feature_rows::FeatureRows;
use crate::photo_options::PhotoOptions;
use crate::places;
use crate::trust::{self, feature_scale, Identity, PhotoFlags};
use rayon::prelude::*;
use spdcam_core::advice::{place_left_out, Mismatch, Sampled};
use spdcam_core::chart::shown_chart_name;
use spdcam_core::photo::{
    self, analysis_overlay_jpeg, debug_paths, AnalyseOptions, ChartTemplate, Photo, PhotoAnalysis,
};
use std::path::{Path, PathBuf};

impl Estimator {
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
        let checked: Vec<Checked> = analyses
            .into_iter()
            .map(|analysis| {
                let (found, mismatches) = self.check_chart(&analysis);
                (analysis, found, mismatches)
            })
            .collect();
        let checked = leave_out_places_not_the_chart(checked);
        // One drawing of every place, numbered, shared by their reports.
        let overlay = match options.overlay_width {
            Some(width) => {
                let all: Vec<&PhotoAnalysis> = checked.iter().map(|(a, _)| a).collect();
                Some(overlay_of(photo, &analyse.templates, &all, width).map_err(|e| e.to_string()))
            }
            None => None,
        };
        let mut debug = debug;
        checked
            .into_iter()
            .map(|(analysis, found)| {
                let mut identified = None;
                let analysed = found.and_then(|found| {
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
    /// ([`InferError::NotTheChart`]; see [`crate::trust::chart_identity`]): no number is made of
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
            model_spds.raw_row.as_deref(),
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
        self.check_chart(analysis).0
    }

    /// [`Estimator::refuse_not_the_chart`], with what was found against the chart (empty
    /// where nothing was, or the photo could not be identified).
    fn check_chart(&self, analysis: &PhotoAnalysis) -> (Result<Option<Identified>>, Vec<Mismatch>) {
        match self.identify(analysis) {
            Ok(found) => {
                let mismatches = found.identity.mismatches();
                let required = self.prepared.trust[found.index].identity.require(
                    &found.identity,
                    sampled(analysis),
                    &analysis.source,
                );
                (required.map(|()| Some(found)), mismatches)
            }
            Err(_) => (Ok(None), Vec::new()),
        }
    }

    /// Whether an analysed photo shows the chart it is said to: the statistics of
    /// [`crate::trust::chart_identity`], the shuffled one under the model's estimate (or, where the
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
                analysis.raw.as_ref().map(|r| (r, feature_patches)),
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
}

/// The picture of the charts found on `photo` (as `--debug` draws it), `width` pixels wide,
/// as JPEG.
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

/// An analysed place, whether it is the chart ([`Estimator::refuse_not_the_chart`]) and what
/// was found against it.
type Checked = (PhotoAnalysis, Result<Option<Identified>>, Vec<Mismatch>);

/// The places of one photo with those whose patches are not the chart left out, where
/// another place is the chart: a grid detection found beside a chart (the white-balance
/// page of a ColorChecker Passport opened above its ColorChecker 24) is no failed photo.
/// What was left out, and why, is a warning on each place kept, and the kept places are
/// numbered again (none when one is left). Where no place is the chart, every refusal
/// stands.
fn leave_out_places_not_the_chart(
    checked: Vec<Checked>,
) -> Vec<(PhotoAnalysis, Result<Option<Identified>>)> {
    let refused =
        |found: &Result<Option<Identified>>| matches!(found, Err(InferError::NotTheChart(_)));
    if checked.len() < 2 || checked.iter().all(|(_, found, _)| refused(found)) {
        return checked
            .into_iter()
            .map(|(a, found, _)| (a, found))
            .collect();
    }
    let (kept, left_out): (Vec<_>, Vec<_>) = checked
        .into_iter()
        .partition(|(_, found, _)| !refused(found));
    let notes: Vec<String> = left_out
        .iter()
        .map(|(analysis, _, mismatches)| {
            let centre = analysis.place.as_ref().map(|p| p.centre);
            place_left_out(&shown_chart_name(&analysis.chart), centre, mismatches)
        })
        .collect();
    let of = kept.len();
    kept.into_iter()
        .enumerate()
        .map(|(k, (mut analysis, found, _))| {
            analysis.place = match analysis.place.take() {
                Some(place) if of > 1 => Some(photo::Place {
                    number: k + 1,
                    of,
                    ..place
                }),
                _ => None,
            };
            analysis.warnings.extend(notes.iter().cloned());
            (analysis, found)
        })
        .collect()
}
