//! `spdcam metrics`: lighting-quality numbers of measured SPDs (every column of a spectral CSV)
//! or named lights.

use crate::outln;
use anyhow::Result;
use clap::Args;
use serde::Serialize;
use spdcam_core::builtin::DataDir;
use spdcam_core::fsio;
use spdcam_core::named_light::resolve_spd;
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

fn fixed(v: Option<f64>, decimals: usize) -> String {
    v.map_or_else(|| "—".into(), |v| format!("{v:.decimals$}"))
}

/// The main numbers, one light per line, then the reasons and warnings.
fn print_table(rows: &[Row]) -> Result<()> {
    let width = rows
        .iter()
        .map(|r| r.name.chars().count())
        .max()
        .unwrap_or(4)
        .max(4);
    outln!(
        "{:<width$}  {:>7} {:>8} {:>6} {:>6} {:>6} {:>6} {:>6} {:>5} {:>7} {:>9}",
        "name",
        "CCT K",
        "Duv",
        "Ra",
        "R9",
        "Rf",
        "Rg",
        "M-EDER",
        "S/P",
        "PPF/lx",
        "BLH mW/lm"
    )?;
    for r in rows {
        let m = &r.metrics;
        let pad = width - r.name.chars().count();
        outln!(
            "{}{:pad$}  {:>7} {:>8} {:>6} {:>6} {:>6} {:>6} {:>6} {:>5} {:>7} {:>9}",
            r.name,
            "",
            fixed(m.cct_k, 0),
            fixed(m.duv, 4),
            fixed(m.cri_ra, 1),
            fixed(m.cri_r.map(|r| r[8]), 1),
            fixed(m.tm30_rf, 1),
            fixed(m.tm30_rg, 1),
            fixed(m.mel_der, 3),
            fixed(m.sp_ratio, 2),
            fixed(m.ppf_per_lux.map(|v| 1000.0 * v), 2),
            fixed(m.blh_efficacy_w_per_lm.map(|v| 1000.0 * v), 3),
        )?;
    }
    outln!(
        "(PPF/lx in µmol·s⁻¹·klm⁻¹, i.e. µmol·m⁻²·s⁻¹ per 1000 lx; `--json` gives every number: \
         R1–R14, TM-30 hue bins, all five α-opic ratios, chromaticities)"
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
