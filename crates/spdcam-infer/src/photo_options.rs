//! How photos are analysed before an estimate: the options ([`PhotoOptions`]) and the
//! charts looked for ([`chart_templates`]).

use crate::error::{InferError, Result};
use crate::shipped::ModelSet;
use spdcam_core::builtin::DataDir;
use spdcam_core::chart::{Chart, KnownChart};
use spdcam_core::photo::ChartTemplate;
use spdcam_core::spectral::Grid;
use std::path::PathBuf;

/// How photos are analysed: which charts to look for, and optional corners or debug image.
#[derive(Debug, Clone, Default)]
pub struct PhotoOptions {
    /// Look only for this chart (a name or a reflectance CSV); default: every chart a model
    /// of the set was trained for.
    pub chart: Option<String>,
    /// The chart's four outer corners in pixels, any order (one photo only); four for each
    /// chart of several, chart after chart, where every chart is estimated.
    pub corners: Option<Vec<[f64; 2]>>,
    /// Where to write a debug image of each photo (see `spdcam_core::photo::debug_path`).
    pub debug: Option<PathBuf>,
    /// Also draw the chart found on each photo, reduced to at most this many pixels wide
    /// (a JPEG for a report; [`crate::AnalysedPhoto::overlay`]), while the
    /// photo is decoded anyway.
    pub overlay_width: Option<u32>,
}

/// The charts to look for in photos. With `chart`: that chart as photos show it (from a
/// model's file when a model was trained for it) and as `spdcam render` draws it. Without:
/// every model's chart, the same two ways; when no model names its chart, the chart
/// registry's charts that a shipped model reads, as photos show them (those whose
/// reflectances are at hand: the ColorChecker 24 and, when the data directory holds it, the
/// Digital SG).
pub fn chart_templates(
    models: &ModelSet,
    chart: Option<&str>,
    data_dir: &DataDir,
) -> Result<Vec<ChartTemplate>> {
    let grid = Grid::SIMULATION;
    let names: Vec<String> = match chart {
        Some(name) => vec![name.to_string()],
        None => models
            .models()
            .iter()
            .filter_map(|m| m.model.header().chart.clone())
            .collect(),
    };
    if names.is_empty() {
        return Ok(KnownChart::with_shipped_model()
            .into_iter()
            .filter_map(|c| ChartTemplate::of_known(c, data_dir, &grid))
            .collect());
    }
    let mut out: Vec<ChartTemplate> = Vec::new();
    let mut push = |t: ChartTemplate| {
        if out.iter().all(|o| o.name != t.name) {
            out.push(t);
        }
    };
    for name in &names {
        let physical = match models.for_chart(name).and_then(|m| m.model.photo_chart()) {
            Some(t) => Some(t.clone()),
            None => ChartTemplate::for_chart(name, data_dir, &grid),
        };
        physical.into_iter().for_each(&mut push);
        if let Some(rendered) = Chart::resolve(name, None, data_dir, &grid)
            .ok()
            .and_then(|c| ChartTemplate::from_chart(&c).ok())
        {
            push(rendered);
        }
    }
    if out.is_empty() {
        // Name the reason: an unknown chart, or one with too few neutral patches.
        let name = &names[0];
        let chart = Chart::resolve(name, None, data_dir, &grid)?;
        ChartTemplate::from_chart(&chart)?;
        return Err(InferError::invalid(format!(
            "chart '{name}' cannot be found in photos"
        )));
    }
    Ok(out)
}
