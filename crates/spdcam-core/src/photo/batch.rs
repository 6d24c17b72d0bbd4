//! One call from a photo file to its feature row: decode ─► find (or place) the chart ─►
//! sample ─► features, confidence, flags and warnings; several photos in parallel. A photo
//! may show several charts ([`analyse_places_telling_debug`]): one analysis per chart, each
//! with its [`Place`].

use super::detect::{detect_all, detect_traced, from_corners, from_corners_any, no_chart};
use super::exposure::Exposure;
use super::geometry::quad_centre;
use super::load::{load_photo, Photo};
use super::overlay::{debug_overlay_full, write_overlay, Found};
use super::raw::RawReading;
use super::sample::{sample, PatchSample};
use super::{ChartTemplate, Detection};
use crate::advice::Advice;
use crate::chart::patch_name;
use crate::error::{Error, Result};
use crate::fsio;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// A warning is given when more than this share of the feature patches is clipped.
const CLIPPED_WARNING_SHARE: f64 = 0.1;
/// A warning is given below this confidence (results above [`super::MIN_CONFIDENCE`]).
const LOW_CONFIDENCE: f64 = 0.8;

/// How to analyse photos.
#[derive(Debug, Clone, Default)]
pub struct AnalyseOptions {
    /// The charts to look for; with [`AnalyseOptions::corners`], the one whose patches fit
    /// the photo inside those corners best.
    pub templates: Vec<ChartTemplate>,
    /// The chart's four outer corners in photo pixels, any order; `None` to detect. For
    /// [`analyse_places_telling_debug`], four for each chart of several, chart after chart.
    pub corners: Option<Vec<[f64; 2]>>,
    /// Where to write the debug image (written also when no chart is found). With several
    /// photos, each gets its own file, see [`debug_path`].
    pub debug: Option<PathBuf>,
}

/// What a photo gave.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PhotoAnalysis {
    /// The photo's file (or name).
    pub source: String,
    /// Photo width in pixels (after EXIF orientation).
    pub width: usize,
    /// Photo height in pixels.
    pub height: usize,
    /// `"detected"` or `"corners"`.
    pub method: &'static str,
    /// The chart found.
    pub chart: String,
    /// 0…1: how sure the chart's placement and orientation are.
    pub confidence: f64,
    /// Outer corners of the patch grid (photo pixels): the chart's TL, TR, BR, BL.
    pub corners: [[f64; 2]; 4],
    /// Chart coordinates (patch pitch units) → photo pixels, row-major.
    pub homography: [[f64; 3]; 3],
    /// Feature column names, `p01_r, p01_g, …`.
    pub feature_names: Vec<String>,
    /// Mean encoded sRGB (0–255) of each feature patch, in feature order: the model's input.
    pub features: Vec<f32>,
    /// Every patch of the chart, row-major, with its statistics and flags.
    pub patches: Vec<PatchSample>,
    /// What the user should know (clipping, low confidence, dark patches).
    pub warnings: Vec<String>,
    /// The camera's exposure from the photo's EXIF, when it gives aperture, time and ISO.
    pub exposure: Option<Exposure>,
    /// For a raw photo, what its mosaic said beyond the features (the light's chromaticity
    /// through the file's matrices); `None` for an encoded photo.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub raw: Option<RawReading>,
    /// Where the chart lies among several in the photo; `None` when the photo shows one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub place: Option<Place>,
}

/// Where one chart of several lies in a photo: the light at that place.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Place {
    /// 1-based, numbered from left to right by the charts' centres (the number the debug
    /// image draws on the chart).
    pub number: usize,
    /// How many charts the photo shows.
    pub of: usize,
    /// The centre of the chart's patch grid, photo pixels.
    pub centre: [f64; 2],
}

impl Place {
    /// "place 2 of 3 (at 1200, 640 px)".
    pub fn label(&self) -> String {
        format!(
            "place {} of {} (at {:.0}, {:.0} px)",
            self.number, self.of, self.centre[0], self.centre[1]
        )
    }
}

impl PhotoAnalysis {
    /// The chart found, as detection gave it (what the overlay draws).
    pub fn detection(&self) -> Detection {
        Detection {
            chart: self.chart.clone(),
            corners: self.corners,
            homography: self.homography,
            confidence: self.confidence,
        }
    }
}

/// Decodes, finds the chart, samples it. Writes the debug image when asked, also when no
/// chart is found (then the error says so).
pub fn analyse_photo(path: &Path, options: &AnalyseOptions) -> Result<PhotoAnalysis> {
    let photo = load_photo(path)?;
    analyse(&photo, options)
}

/// [`analyse_photo`] for a decoded photo. When it fails, the error tells what the decoder
/// noticed too (a truncated or corrupt file explains a chart not found).
pub fn analyse(photo: &Photo, options: &AnalyseOptions) -> Result<PhotoAnalysis> {
    analyse_telling_debug(photo, options).0
}

/// [`analyse`], also giving the debug image it wrote (`options.debug`, when it was written:
/// with the chart found, or with none found), so that a front end announces what is on disk
/// without looking there.
pub fn analyse_telling_debug(
    photo: &Photo,
    options: &AnalyseOptions,
) -> (Result<PhotoAnalysis>, Option<PathBuf>) {
    let mut written = None;
    let result = analyse_decoded(photo, options, &mut written).map_err(|e| noted(photo, e));
    (result, written)
}

/// [`analyse_telling_debug`] for every chart the photo shows ([`detect_all`]): one analysis
/// per chart, numbered from left to right, each with its [`Place`] when there are several;
/// the debug image draws them all with their numbers. With corners given, the one chart
/// they hold.
pub fn analyse_places_telling_debug(
    photo: &Photo,
    options: &AnalyseOptions,
) -> (Result<Vec<PhotoAnalysis>>, Option<PathBuf>) {
    let mut written = None;
    let result = analyse_places(photo, options, &mut written).map_err(|e| noted(photo, e));
    (result, written)
}

/// An error about `photo` with what its decoder noticed.
fn noted(photo: &Photo, e: Error) -> Error {
    if photo.warnings.is_empty() {
        e
    } else {
        Error::invalid(format!("{e}; note: {}", photo.warnings.join("; ")))
    }
}

fn analyse_places(
    photo: &Photo,
    options: &AnalyseOptions,
    written: &mut Option<PathBuf>,
) -> Result<Vec<PhotoAnalysis>> {
    let templates = &options.templates;
    if templates.is_empty() {
        return Err(Error::invalid("no chart to look for"));
    }
    let (detections, method) = match &options.corners {
        Some(corners) if corners.len() <= 4 => {
            return Ok(vec![analyse_decoded(photo, options, written)?])
        }
        Some(corners) => (placed_by_corners(photo, templates, corners)?, "corners"),
        None => {
            let (detections, trace) = detect_all(photo, templates)?;
            if detections.is_empty() {
                if let Some(path) = &options.debug {
                    write_overlay(path, &debug_overlay_full(photo, &[], Some(&trace)))?;
                    *written = Some(path.clone());
                }
                return Err(no_chart(photo, templates));
            }
            (detections, "detected")
        }
    };
    let mut sampled = Vec::with_capacity(detections.len());
    for detection in detections {
        let template = template_of(templates, &detection)?;
        let (patches, raw) = sample(photo, template, &detection.map())?;
        sampled.push((template, detection, patches, raw));
    }
    if let Some(path) = &options.debug {
        let found: Vec<Found<'_>> = sampled
            .iter()
            .map(|(t, d, p, _)| (*t, d, p.as_slice()))
            .collect();
        write_overlay(path, &debug_overlay_full(photo, &found, None))?;
        *written = Some(path.clone());
    }
    let of = sampled.len();
    Ok(sampled
        .into_iter()
        .enumerate()
        .map(|(k, (template, detection, patches, raw))| {
            let place = (of > 1).then(|| Place {
                number: k + 1,
                of,
                centre: quad_centre(&detection.corners),
            });
            let mut analysis = assemble(photo, template, detection, method, patches, raw);
            analysis.place = place;
            analysis
        })
        .collect())
}

/// The charts placed by `corners`, four for each (chart after chart), numbered from left
/// to right as detection numbers the charts it finds.
fn placed_by_corners(
    photo: &Photo,
    templates: &[ChartTemplate],
    corners: &[[f64; 2]],
) -> Result<Vec<Detection>> {
    if !corners.len().is_multiple_of(4) {
        return Err(Error::invalid(format!(
            "corners come four for each chart (eight numbers x1,y1,…,x4,y4 per --corners); \
             {} points were given",
            corners.len()
        )));
    }
    let mut placed = corners
        .chunks(4)
        .map(|one| match templates {
            [only] => from_corners(photo, only, one),
            _ => Ok(from_corners_any(photo, templates, one)?.0),
        })
        .collect::<Result<Vec<Detection>>>()?;
    placed.sort_by(|a, b| {
        let (ca, cb) = (quad_centre(&a.corners), quad_centre(&b.corners));
        ca[0].total_cmp(&cb[0]).then(ca[1].total_cmp(&cb[1]))
    });
    Ok(placed)
}

/// The template of the chart `detection` found.
fn template_of<'a>(
    templates: &'a [ChartTemplate],
    detection: &Detection,
) -> Result<&'a ChartTemplate> {
    templates
        .iter()
        .find(|t| t.name == detection.chart)
        .ok_or_else(|| Error::invalid("detected chart has no template"))
}

fn analyse_decoded(
    photo: &Photo,
    options: &AnalyseOptions,
    written: &mut Option<PathBuf>,
) -> Result<PhotoAnalysis> {
    let templates = &options.templates;
    if templates.is_empty() {
        return Err(Error::invalid("no chart to look for"));
    }
    let (detection, trace, method) = match &options.corners {
        Some(corners) if corners.len() > 4 => {
            return Err(Error::invalid(format!(
                "corners of {} charts were given: several charts are read one estimate per \
                 chart (each photo's places), not as one",
                corners.len().div_ceil(4)
            )))
        }
        Some(corners) => {
            let detection = match templates.as_slice() {
                [only] => from_corners(photo, only, corners)?,
                _ => from_corners_any(photo, templates, corners)?.0,
            };
            (Some(detection), None, "corners")
        }
        None => {
            let (d, trace) = detect_traced(photo, templates)?;
            (d, Some(trace), "detected")
        }
    };
    let Some(detection) = detection else {
        if let Some(path) = &options.debug {
            write_overlay(path, &debug_overlay_full(photo, &[], trace.as_ref()))?;
            *written = Some(path.clone());
        }
        return Err(no_chart(photo, templates));
    };
    let template = template_of(templates, &detection)?;
    let h = detection.map();
    let (patches, raw) = sample(photo, template, &h)?;
    if let Some(path) = &options.debug {
        let image = debug_overlay_full(photo, &[(template, &detection, &patches)], None);
        write_overlay(path, &image)?;
        *written = Some(path.clone());
    }
    Ok(assemble(photo, template, detection, method, patches, raw))
}

fn assemble(
    photo: &Photo,
    template: &ChartTemplate,
    detection: Detection,
    method: &'static str,
    patches: Vec<PatchSample>,
    raw: Option<RawReading>,
) -> PhotoAnalysis {
    let features: Vec<f32> = template
        .feature_patches
        .iter()
        .flat_map(|&p| patches[p].rgb)
        .collect();
    let mut warnings = photo.warnings.clone();
    let n = template.feature_patches.len();
    // The feature patches flagged by `flag`, by the names the chart prints.
    let flagged = |flag: fn(&PatchSample) -> bool| -> Vec<String> {
        template
            .feature_patches
            .iter()
            .filter(|&&p| flag(&patches[p]))
            .map(|&p| patch_name(&template.name, p))
            .collect()
    };
    let clipped = flagged(|p| p.clipped);
    if clipped.len() as f64 > CLIPPED_WARNING_SHARE * n as f64 {
        warnings.push(
            Advice::Clipped {
                count: clipped.len(),
                of: n,
                names: clipped,
                calibration_most: None,
            }
            .to_string(),
        );
    }
    let dark = flagged(|p| p.dark);
    if !dark.is_empty() {
        warnings.push(
            Advice::Dark {
                count: dark.len(),
                of: n,
                names: dark,
            }
            .to_string(),
        );
    }
    if detection.confidence < LOW_CONFIDENCE {
        warnings.push(
            Advice::LowConfidence {
                confidence: detection.confidence,
                placed: method == "corners",
            }
            .to_string(),
        );
    }
    PhotoAnalysis {
        source: photo.source.clone(),
        width: photo.width,
        height: photo.height,
        method,
        chart: detection.chart,
        confidence: detection.confidence,
        corners: detection.corners,
        homography: detection.homography,
        feature_names: template.feature_names.clone(),
        features,
        patches,
        warnings,
        exposure: photo.exposure,
        raw,
        place: None,
    }
}

/// The debug image of each of `photos`, all different: [`debug_path`], and where two photos
/// share a file stem (`d1/p.jpg`, `d2/p.jpg`), their directories' names join the stem
/// (`dbg-d1-p.png`, `dbg-d2-p.png`), then their position in the list.
pub fn debug_paths(base: &Path, photos: &[PathBuf]) -> Vec<PathBuf> {
    let count = photos.len();
    let mut paths: Vec<PathBuf> = photos.iter().map(|p| debug_path(base, p, count)).collect();
    let duplicated =
        |paths: &[PathBuf], i: usize| paths.iter().filter(|p| **p == paths[i]).count() > 1;
    let clashing: Vec<usize> = (0..count).filter(|&i| duplicated(&paths, i)).collect();
    for &i in &clashing {
        let parent = photos[i]
            .parent()
            .and_then(Path::file_name)
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let stem = photos[i]
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        paths[i] = debug_path(base, Path::new(&format!("{parent}-{stem}")), count);
    }
    let clashing: Vec<usize> = (0..count).filter(|&i| duplicated(&paths, i)).collect();
    for &i in &clashing {
        let stem = paths[i]
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let ext = paths[i]
            .extension()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        paths[i] = paths[i].with_file_name(format!("{stem}-{}.{ext}", i + 1));
    }
    paths
}

/// The debug image of `photo` when `count` photos share the base name `base`:
/// `base` itself for one photo, else `<base stem>-<photo stem>.<base extension>`.
pub fn debug_path(base: &Path, photo: &Path, count: usize) -> PathBuf {
    if count <= 1 {
        return base.to_path_buf();
    }
    let stem = base
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "debug".into());
    let ext = base
        .extension()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "png".into());
    let photo_stem = photo
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    base.with_file_name(format!("{stem}-{photo_stem}.{ext}"))
}

/// The feature rows as CSV: a header of feature names and one row per analysis (the
/// layout of a dataset's `features.csv`). All analyses must be of the same chart.
pub fn features_csv(analyses: &[PhotoAnalysis]) -> Result<String> {
    let Some(first) = analyses.first() else {
        return Err(Error::invalid("no photo analysed: no features to write"));
    };
    if let Some(other) = analyses
        .iter()
        .find(|a| a.feature_names != first.feature_names)
    {
        return Err(Error::invalid(format!(
            "{} shows {} and {} shows {}: their features cannot share one table",
            first.source, first.chart, other.source, other.chart
        )));
    }
    let mut out = first.feature_names.join(",");
    out.push('\n');
    for a in analyses {
        let row: Vec<String> = a.features.iter().map(|v| format!("{v:.4}")).collect();
        let _ = writeln!(out, "{}", row.join(","));
    }
    Ok(out)
}

/// Writes [`features_csv`] to `path` atomically.
pub fn write_features_csv(path: &Path, analyses: &[PhotoAnalysis]) -> Result<()> {
    fsio::write_atomic(path, features_csv(analyses)?.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn debug_images_of_photos_with_one_name_do_not_overwrite_each_other() {
        // Issue 15: `--debug dbg.png` with `d1/p.jpg` and `d2/p.jpg` wrote one `dbg-p.png`.
        let photos: Vec<PathBuf> = ["d1/p.jpg", "d2/p.jpg", "d2/q.jpg", "x/d1/p.png", "d1/p.png"]
            .iter()
            .map(PathBuf::from)
            .collect();
        let paths = debug_paths(Path::new("out/dbg.png"), &photos);
        let names: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
        assert_eq!(
            names,
            [
                "out/dbg-d1-p-1.png",
                "out/dbg-d2-p.png",
                "out/dbg-q.png",
                "out/dbg-d1-p-4.png",
                "out/dbg-d1-p-5.png"
            ]
        );
        let one = debug_paths(Path::new("dbg.png"), &photos[..1]);
        assert_eq!(one, [PathBuf::from("dbg.png")]);
    }
}
