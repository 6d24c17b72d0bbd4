//! The photo options of `spdcam estimate` (chart, corners, debug image, features) and the
//! step that turns photo files into analysed charts, so the command only calls
//! [`analyse_photos`] and reads [`PhotoAnalysis::features`].

use anyhow::{bail, Context, Result};
use clap::Args;
use spdcam_core::builtin::DataDir;
use spdcam_core::chart::Chart;
use spdcam_core::photo::{self, AnalyseOptions, ChartTemplate, PhotoAnalysis};
use spdcam_core::spectral::Grid;
use spdcam_learn::model::Model;
use std::path::{Path, PathBuf};

/// How the chart is found in each photo and what is written about it.
#[derive(Debug, Args, Clone, Default)]
pub struct PhotoArgs {
    /// The chart's four outer corners in pixels, any order: x1,y1,x2,y2,x3,y3,x4,y4
    /// (one photo only); without it the chart is detected.
    #[arg(long, value_name = "X1,Y1,…,X4,Y4", allow_hyphen_values = true)]
    pub corners: Option<String>,
    /// Look only for this chart: colorchecker24, colorchecker_sg140 (or another chart
    /// name or reflectance CSV); default: the ColorChecker 24, and the Digital SG when the
    /// data directory has it.
    #[arg(long, value_name = "NAME")]
    pub chart: Option<String>,
    /// Write a debug image (PNG) with the chart's outline and every sampled region; with
    /// several photos, one per photo (`NAME-<photo>.png`). Written also when no chart is found.
    #[arg(long, value_name = "FILE.png")]
    pub debug: Option<PathBuf>,
    /// Write the feature rows (`p01_r,p01_g,…`, one row per photo) as CSV.
    #[arg(long, value_name = "FILE.csv")]
    pub features_out: Option<PathBuf>,
    /// Print the result as JSON on stdout (with detection confidence, corners, per-patch
    /// features and flags; see [`analysis_json`]).
    #[arg(long)]
    pub json: bool,
}

/// Parses `x1,y1,…,x4,y4` (commas and/or spaces) into four points.
pub fn parse_corners(text: &str) -> Result<Vec<[f64; 2]>> {
    let numbers: Vec<f64> = text
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter(|s| !s.is_empty())
        .map(|s| {
            s.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .with_context(|| format!("--corners: '{s}' is not a number"))
        })
        .collect::<Result<_>>()?;
    if numbers.len() != 8 {
        bail!(
            "--corners needs eight numbers x1,y1,x2,y2,x3,y3,x4,y4; got {}",
            numbers.len()
        );
    }
    Ok(numbers.chunks(2).map(|p| [p[0], p[1]]).collect())
}

/// The charts to look for. With `--chart NAME`: that chart as photos show it (the full
/// Digital SG for `colorchecker_sg96`, from the model file when it is the model's chart) and
/// as `spdcam render` draws it. Without: the model's chart, the same two ways; for a model
/// with no photo chart, the ColorChecker 24 and, when the data directory holds it, the SG.
pub fn templates(
    args: &PhotoArgs,
    model: &Model,
    data_dir: &DataDir,
) -> Result<Vec<ChartTemplate>> {
    let grid = Grid::SIMULATION;
    let model_chart = model.header().chart.as_deref();
    let name = match (&args.chart, model_chart) {
        (Some(name), _) => name.as_str(),
        (None, Some(chart)) if model.photo_chart().is_some() => chart,
        (None, _) => {
            let mut out = vec![ChartTemplate::from_chart(&Chart::colorchecker24(&grid)?)?];
            if let Ok(sg) = Chart::resolve("colorchecker_sg140", None, data_dir, &grid) {
                out.push(ChartTemplate::from_chart(&sg)?);
            }
            return Ok(out);
        }
    };
    let physical = match model.photo_chart() {
        Some(t) if model_chart == Some(name) => Some(t.clone()),
        _ => ChartTemplate::for_chart(name, data_dir, &grid),
    };
    let rendered = Chart::resolve(name, None, data_dir, &grid)
        .ok()
        .and_then(|c| ChartTemplate::from_chart(&c).ok());
    let mut out: Vec<ChartTemplate> = physical.into_iter().collect();
    if let Some(r) = rendered {
        if out.iter().all(|t| t.name != r.name) {
            out.push(r);
        }
    }
    if out.is_empty() {
        // Name the reason: an unknown chart, or one with too few neutral patches.
        let chart = Chart::resolve(name, None, data_dir, &grid)?;
        ChartTemplate::from_chart(&chart)?;
        bail!("chart '{name}' cannot be found in photos");
    }
    Ok(out)
}

/// Decodes the photos, finds one of `templates` in each (in parallel) and samples it. Fails
/// on the first photo that cannot be analysed, naming it, before anything but debug images
/// is written; prints each analysis's warnings on stderr.
pub fn analyse_photos(
    photos: &[PathBuf],
    args: &PhotoArgs,
    templates: &[ChartTemplate],
) -> Result<Vec<PhotoAnalysis>> {
    if photos.is_empty() {
        bail!("no photo given");
    }
    let corners = args.corners.as_deref().map(parse_corners).transpose()?;
    if corners.is_some() && photos.len() > 1 {
        bail!(
            "--corners applies to one photo; {} were given",
            photos.len()
        );
    }
    let options = AnalyseOptions {
        templates: templates.to_vec(),
        corners,
        debug: args.debug.clone(),
    };
    let mut out = Vec::with_capacity(photos.len());
    for (path, result) in photos.iter().zip(photo::analyse_photos(photos, &options)) {
        let analysis = result.with_context(|| format!("cannot use photo {}", path.display()))?;
        for w in &analysis.warnings {
            eprintln!("warning: {}: {w}", analysis.source);
        }
        out.push(analysis);
    }
    Ok(out)
}

/// Writes what `--features-out` asks for (atomically); call after every photo succeeded.
pub fn write_outputs(analyses: &[PhotoAnalysis], args: &PhotoArgs) -> Result<()> {
    if let Some(path) = &args.features_out {
        photo::write_features_csv(path, analyses)?;
    }
    Ok(())
}

/// One analysis as JSON: source, chart, method, confidence, corners, homography, features
/// by name, every patch with its statistics and flags, warnings.
pub fn analysis_json(analysis: &PhotoAnalysis) -> Result<serde_json::Value> {
    let mut v = serde_json::to_value(analysis)?;
    let named: serde_json::Map<String, serde_json::Value> = analysis
        .feature_names
        .iter()
        .zip(&analysis.features)
        .map(|(n, f)| (n.clone(), serde_json::json!(f)))
        .collect();
    if let Some(obj) = v.as_object_mut() {
        obj.insert("features_by_name".into(), serde_json::Value::Object(named));
    }
    Ok(v)
}

/// A short line about an analysis for the terminal.
pub fn describe(analysis: &PhotoAnalysis) -> String {
    let name = Path::new(&analysis.source)
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| analysis.source.clone());
    format!(
        "{name}: {} {} (confidence {:.2}), {} patches sampled",
        analysis.chart,
        analysis.method,
        analysis.confidence,
        analysis.patches.len()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corners_parse_with_commas_and_spaces() {
        let c = parse_corners("1,2, 3,4 5,6,7,8").unwrap();
        assert_eq!(c, vec![[1.0, 2.0], [3.0, 4.0], [5.0, 6.0], [7.0, 8.0]]);
        assert!(parse_corners("1,2,3")
            .unwrap_err()
            .to_string()
            .contains("eight"));
        assert!(parse_corners("1,2,3,4,5,6,7,x")
            .unwrap_err()
            .to_string()
            .contains("'x'"));
    }
}
