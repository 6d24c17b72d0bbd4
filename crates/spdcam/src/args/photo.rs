//! The photo options of `spdcam estimate` (chart, corners, debug image, features), turned
//! into the library's [`PhotoOptions`].

use anyhow::{bail, Context, Result};
use clap::Args;
use spdcam_core::chart::{shown_chart_name, KnownChart};
use spdcam_core::photo::PhotoAnalysis;
use spdcam_infer::PhotoOptions;
use std::path::{Path, PathBuf};

/// How the chart is found in each photo and what is written about it.
#[derive(Debug, Args, Clone, Default)]
pub struct PhotoArgs {
    /// The chart's four outer corners in pixels, any order: x1,y1,x2,y2,x3,y3,x4,y4
    /// (one photo only); once per chart for a photo of several, each then estimated and
    /// numbered from left to right; without it the charts are detected.
    #[arg(long, value_name = "X1,Y1,…,X4,Y4", allow_hyphen_values = true)]
    pub corners: Vec<String>,
    /// Look only for this chart (its help, from the chart registry, names the known ones).
    #[arg(long, value_name = "NAME", help = chart_help())]
    pub chart: Option<String>,
    /// Write a debug image (PNG) with the chart's outline and every sampled region; with
    /// several photos, one per photo (`NAME-<photo>.png`). Written also when no chart is found.
    #[arg(long, value_name = "FILE.png")]
    pub debug: Option<PathBuf>,
    /// Write the feature rows (`p01_r,p01_g,…`, one row per photo) as CSV.
    #[arg(long, value_name = "FILE.csv")]
    pub features_out: Option<PathBuf>,
    /// Print the result as JSON on stdout (with detection confidence, corners, per-patch
    /// features and flags): a list for photos; with --features one object per row and line
    /// (JSON Lines), written as each row is estimated.
    #[arg(long)]
    pub json: bool,
}

/// The help of `--chart`, its charts from the chart registry: `Look only for this chart:
/// colorchecker24, colorchecker_sg140 (…); default: … the ColorChecker 24 and the
/// ColorChecker Digital SG`.
fn chart_help() -> String {
    let charts = KnownChart::photographed();
    let names: Vec<&str> = charts.iter().map(|c| c.name()).collect();
    let shown: Vec<String> = charts
        .iter()
        .map(|c| format!("the {}", c.shown_name()))
        .collect();
    format!(
        "Look only for this chart: {} (or another chart name or reflectance CSV); default: \
         every chart a model is for (with the shipped models {})",
        names.join(", "),
        shown.join(" and ")
    )
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

impl PhotoArgs {
    /// The library's photo options for these arguments.
    pub fn options(&self) -> Result<PhotoOptions> {
        Ok(PhotoOptions {
            chart: self.chart.clone(),
            corners: match self.corners.as_slice() {
                [] => None,
                texts => Some(
                    texts
                        .iter()
                        .map(|t| parse_corners(t))
                        .collect::<Result<Vec<_>>>()?
                        .concat(),
                ),
            },
            debug: self.debug.clone(),
            overlay_width: None,
        })
    }
}

/// A short line about an analysis for the terminal.
pub fn describe(analysis: &PhotoAnalysis) -> String {
    let name = Path::new(&analysis.source)
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| analysis.source.clone());
    let name = match analysis.place {
        Some(place) => format!("{name} {}", place.label()),
        None => name,
    };
    let line = format!(
        "{name}: {} {} (confidence {:.2}), {} patches sampled",
        shown_chart_name(&analysis.chart),
        analysis.method,
        analysis.confidence,
        analysis.patches.len()
    );
    match &analysis.raw {
        Some(raw) => format!("{line}; {}", raw.describe()),
        None => line,
    }
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
