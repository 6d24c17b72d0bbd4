//! `spdcam metrics`: lighting-quality numbers of measured SPDs (every column of a spectral CSV)
//! or named lights.

use crate::outln;
use anyhow::Result;
use clap::Args;
use serde::Serialize;
use spdcam_core::builtin::DataDir;
use spdcam_core::fsio;
use spdcam_core::named_light::resolve_spd;
use spdcam_core::quality::registry::{Metric, Source, METRICS};
use spdcam_core::quality::{LightSpectrum, LightingMetrics, QUALITY_GRID};
use spdcam_core::spectral::SpectralSet;
use std::path::Path;

/// Options of `spdcam metrics`.
#[derive(Debug, Args)]
pub struct MetricsArgs {
    /// Spectral CSVs (every column is one light; FILE.csv:COLUMN picks one) or named lights
    /// (D65, A, D50, daylight:CCT, planck:CCT, cct:CCT).
    #[arg(required = true, value_name = "SPD")]
    spds: Vec<String>,
    /// Print a JSON list with one object per light (every number; undefined ones null, with
    /// the reason under `reasons`).
    #[arg(long)]
    json: bool,
}

/// One light's metrics as printed: its name, then every number.
#[derive(Debug, Serialize)]
struct Row {
    name: String,
    #[serde(flatten)]
    metrics: LightingMetrics,
}

/// Runs `spdcam metrics`.
pub fn run(args: MetricsArgs, data_dir: &DataDir) -> Result<()> {
    let mut rows = Vec::new();
    for spec in &args.spds {
        rows.extend(lights(spec, data_dir)?);
    }
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&rows)?)?;
    } else {
        print_table(&rows)?;
    }
    Ok(())
}

/// The lights `spec` names, with their metrics: every column of a CSV file, or one light.
fn lights(spec: &str, data_dir: &DataDir) -> Result<Vec<Row>> {
    let path = Path::new(spec);
    if fsio::is_input(path) {
        let set = SpectralSet::read_csv(path)?;
        return Ok((0..set.len())
            .map(|i| Row {
                name: set.names()[i].clone(),
                metrics: match LightSpectrum::from_set(&set, i) {
                    Ok(light) => LightingMetrics::of(&light),
                    Err(e) => LightingMetrics::undefined(&e.to_string()),
                },
            })
            .collect());
    }
    let spd = resolve_spd(spec, data_dir, &QUALITY_GRID)?;
    let metrics = LightingMetrics::of_spd(&spd.spd);
    Ok(vec![Row {
        name: spd.name,
        metrics,
    }])
}

/// The metrics of the table: every registry row read from a light's metrics.
fn table_metrics() -> impl Iterator<Item = &'static Metric> {
    METRICS
        .iter()
        .filter(|m| matches!(m.source, Source::Lighting(_)))
}

/// The main numbers ([`METRICS`] read from the light), one light per line, each to its
/// `lab_decimals`; then the reasons and warnings.
fn print_table(rows: &[Row]) -> Result<()> {
    let width = rows
        .iter()
        .map(|r| r.name.chars().count())
        .max()
        .unwrap_or(4)
        .max(4);
    let column = |m: &Metric| m.symbol.chars().count().max(7);
    let mut header = format!("{:<width$} ", "name");
    for m in table_metrics() {
        header += &format!(" {:>w$}", m.symbol, w = column(m));
    }
    outln!("{header}")?;
    for r in rows {
        let pad = width - r.name.chars().count();
        let mut line = format!("{}{:pad$} ", r.name, "");
        for m in table_metrics() {
            let value = m.value(&r.metrics).map_or_else(
                || "—".into(),
                |v| format!("{:.d$}", m.shown_scale * v, d = m.lab_decimals),
            );
            line += &format!(" {value:>w$}", w = column(m));
        }
        outln!("{line}")?;
    }
    let units: Vec<String> = table_metrics()
        .filter(|m| !m.unit.is_empty())
        .map(|m| format!("{} in {}", m.symbol, m.unit))
        .collect();
    outln!(
        "({}; `--json` gives every number: R1–R14, TM-30 hue bins, all five α-opic ratios, \
         chromaticities)",
        units.join(", ")
    )?;
    for r in rows {
        let mut seen = Vec::new();
        for reason in r.metrics.reasons.values() {
            if !seen.contains(&reason) {
                outln!("{}: undefined values: {reason}", r.name)?;
                seen.push(reason);
            }
        }
        for w in &r.metrics.warnings {
            outln!("{}: note: {w}", r.name)?;
        }
    }
    Ok(())
}
