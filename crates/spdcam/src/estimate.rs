//! `spdcam estimate`: the light's SPD from photos of a chart, or from chart features, with a
//! trained model (by default the one shipped inside the program).
//!
//! Every source of features ends in [`estimate_rows`] (features → SPDs): a features CSV, or
//! photos analysed by [`crate::photo_args`].

use crate::photo_args::{self, PhotoArgs};
use crate::plot_file::{plot_is_png, write_plot};
use anyhow::{bail, Context, Result};
use clap::Args;
use spdcam_core::builtin::DataDir;
use spdcam_core::colorimetry::{uv_to_cct_duv, xy_to_uv1960, Observer};
use spdcam_core::fsio;
use spdcam_core::metrics;
use spdcam_core::photo::PhotoAnalysis;
use spdcam_core::spectral::{Extrapolation, Grid, Interpolation, SpectralSet};
use spdcam_learn::evaluate::spds_svg;
use spdcam_learn::model::Model;
use std::path::{Path, PathBuf};

/// The model used when `--model` is not given: a 1D CNN for the ColorChecker Digital SG,
/// trained on virtual photos (see the README for the command that made it).
const DEFAULT_MODEL: &[u8] = include_bytes!("../../../models/default.spdm");
/// What `--model` shows for the shipped model.
const DEFAULT_MODEL_NAME: &str = "the shipped default model";
/// CCT is defined only this near the Planckian locus (|Duv| in CIE 1960 uv).
const MAX_CCT_DUV: f64 = 0.05;
/// Truth files found beside a photo: `<photo stem>` + this.
const TRUTH_SUFFIX: &str = ".truth.csv";

/// Options of `spdcam estimate`.
#[derive(Debug, Args)]
pub struct EstimateArgs {
    /// Photos of a colour chart (JPEG, PNG, TIFF), or chart images from `spdcam render`;
    /// one estimate each.
    #[arg(value_name = "PHOTO", required_unless_present = "features")]
    photos: Vec<PathBuf>,
    /// The model file (.spdm); default: the model shipped inside spdcam.
    #[arg(long)]
    model: Option<PathBuf>,
    /// Estimate from a features CSV instead of photos: a header naming the columns (p01_r,
    /// p01_g, …), one row per estimate; values on any scale (0–255 or 0–1).
    #[arg(long, value_name = "FILE.csv", conflicts_with = "photos")]
    features: Option<PathBuf>,
    /// Spectral CSV to write: wavelength_nm, then one column per photo (or feature row).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Wavelength grid of the output, START-END[:STEP] in nm (within the model's grid).
    #[arg(long, default_value = "400-700:5", value_name = "START-END[:STEP]")]
    range: String,
    /// Also plot the estimates (SVG or PNG, by the name's extension), with CIE xy, CCT and
    /// Duv in the title.
    #[arg(long, value_name = "SPD.svg|png")]
    plot: Option<PathBuf>,
    /// The true SPDs as spectral CSV (one column, or one per estimate), to print each
    /// estimate's GFC and RMSE. Default for a photo: `<photo stem>.truth.csv` beside it,
    /// when it exists.
    #[arg(long, value_name = "FILE.csv")]
    truth: Option<PathBuf>,
    #[command(flatten)]
    photo: PhotoArgs,
}

/// Feature rows read from a CSV file: column names and row-major values.
pub struct FeatureRows {
    /// Column names from the header.
    pub names: Vec<String>,
    /// Values, row-major.
    pub values: Vec<f64>,
    /// Number of rows.
    pub rows: usize,
}

/// Reads a features CSV (header + numeric rows).
pub fn read_features(path: &Path) -> Result<FeatureRows> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((_, header)) = lines.next() else {
        bail!("{}: the file is empty", path.display());
    };
    let names: Vec<String> = header
        .split(',')
        .map(|s| s.trim().trim_matches('"').to_string())
        .collect();
    let mut values = Vec::new();
    let mut rows = 0;
    for (i, line) in lines {
        let cells: Vec<&str> = line.split(',').collect();
        if cells.len() != names.len() {
            bail!(
                "{} line {}: {} values, the header names {} columns",
                path.display(),
                i + 1,
                cells.len(),
                names.len()
            );
        }
        for (cell, name) in cells.iter().zip(&names) {
            let v: f64 = cell.trim().parse().map_err(|_| {
                anyhow::anyhow!(
                    "{} line {}, column {name}: '{}' is not a number",
                    path.display(),
                    i + 1,
                    cell.trim()
                )
            })?;
            if !v.is_finite() {
                bail!(
                    "{} line {}, column {name}: {v} is not a finite number",
                    path.display(),
                    i + 1
                );
            }
            values.push(v);
        }
        rows += 1;
    }
    if rows == 0 {
        bail!("{}: no rows of features below the header", path.display());
    }
    Ok(FeatureRows {
        names,
        values,
        rows,
    })
}

/// SPD estimates for feature rows (checked against the model's columns), one set item per
/// row named by `labels`, resampled to `grid`.
pub fn estimate_rows(
    model: &Model,
    features: &FeatureRows,
    labels: Vec<String>,
    source: &str,
    grid: &Grid,
) -> Result<SpectralSet> {
    model.check_features(&features.names, source)?;
    let mg = model.grid();
    if grid.start_nm < mg.start_nm - 1e-9 || grid.end_nm() > mg.end_nm() + 1e-9 {
        bail!(
            "--range {}: the model estimates {} nm only",
            grid.label(),
            mg.label()
        );
    }
    let spds = model.estimate_rows(&features.values)?;
    let values = spds.chunks_exact(mg.count).map(<[f64]>::to_vec).collect();
    let set = SpectralSet::on_grid(&mg, labels, values)?;
    if *grid == mg {
        return Ok(set);
    }
    let (resampled, _) = set.resample(grid, Interpolation::Auto, Extrapolation::HoldEdge)?;
    Ok(resampled)
}

/// CIE 1931 xy, and CCT and Duv where the chromaticity is near enough the Planckian locus.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Colorimetry {
    /// CIE 1931 chromaticity.
    pub xy: [f64; 2],
    /// Correlated colour temperature (K); `None` farther than |Duv| 0.05 from the locus.
    pub cct: Option<f64>,
    /// Distance from the Planckian locus in CIE 1960 uv.
    pub duv: Option<f64>,
}

impl Colorimetry {
    /// The colorimetry of `spd` on `grid`.
    pub fn of(spd: &[f64], grid: &Grid) -> Result<Colorimetry> {
        let xy = Observer::cie1931(grid)?.spd_to_xy(spd);
        let (cct, duv) = match uv_to_cct_duv(xy_to_uv1960(xy)) {
            Ok((cct, duv)) if duv.abs() <= MAX_CCT_DUV => (Some(cct), Some(duv)),
            _ => (None, None),
        };
        Ok(Colorimetry { xy, cct, duv })
    }

    /// `xy (0.3127, 0.3290), CCT 6504 K, Duv +0.0032`.
    pub fn label(&self) -> String {
        let mut s = format!("xy ({:.4}, {:.4})", self.xy[0], self.xy[1]);
        match (self.cct, self.duv) {
            (Some(cct), Some(duv)) => s.push_str(&format!(", CCT {cct:.0} K, Duv {duv:+.4}")),
            _ => s.push_str(", no CCT (far from the Planckian locus)"),
        }
        s
    }
}

/// An estimate compared with its truth.
#[derive(Debug, Clone, Copy, serde::Serialize)]
struct Score {
    gfc: f64,
    rmse: f64,
}

/// The model `--model` names, or the shipped one; with its name for messages.
fn load_model(path: Option<&Path>) -> Result<(Model, String)> {
    match path {
        Some(p) => Ok((Model::load(p)?, p.display().to_string())),
        None => Ok((
            Model::from_bytes(DEFAULT_MODEL).context("the shipped default model is damaged")?,
            DEFAULT_MODEL_NAME.to_string(),
        )),
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

/// The truth for each estimate: from `--truth` (one column for all, or one per estimate),
/// else from `<stem>.truth.csv` beside each photo; resampled to `grid`.
fn truths(args: &EstimateArgs, count: usize, grid: &Grid) -> Result<Vec<Option<Vec<f64>>>> {
    let read = |path: &Path| -> Result<SpectralSet> {
        let set = SpectralSet::read_csv(path)
            .with_context(|| format!("reading the true SPDs {}", path.display()))?;
        let (set, _) = set.resample(grid, Interpolation::Auto, Extrapolation::HoldEdge)?;
        Ok(set)
    };
    if let Some(path) = &args.truth {
        let set = read(path)?;
        return match set.len() {
            1 => Ok(vec![Some(set.item(0).to_vec()); count]),
            n if n == count => Ok((0..n).map(|i| Some(set.item(i).to_vec())).collect()),
            n => bail!(
                "{}: {n} true SPDs for {count} estimates; give one, or one per estimate",
                path.display()
            ),
        };
    }
    if args.photos.is_empty() {
        return Ok(vec![None; count]);
    }
    args.photos
        .iter()
        .map(|photo| {
            let Some(stem) = photo.file_stem() else {
                return Ok(None);
            };
            let path = photo.with_file_name(format!("{}{TRUTH_SUFFIX}", stem.to_string_lossy()));
            if !path.is_file() {
                return Ok(None);
            }
            let set = read(&path)?;
            if set.len() != 1 {
                bail!(
                    "{}: one true SPD expected, found {}",
                    path.display(),
                    set.len()
                );
            }
            Ok(Some(set.item(0).to_vec()))
        })
        .collect()
}

/// Runs `spdcam estimate`.
pub fn run(args: EstimateArgs, data_dir: &DataDir) -> Result<()> {
    for path in [&args.output, &args.plot, &args.photo.features_out]
        .into_iter()
        .flatten()
    {
        fsio::check_parent_dir(path)?;
    }
    if let Some(plot) = &args.plot {
        plot_is_png(plot)?;
    }
    let (model, model_name) = load_model(args.model.as_deref())?;
    let grid = Grid::parse(&args.range)?;
    let (features, labels, analyses, source) = match &args.features {
        Some(path) => {
            let f = read_features(path)?;
            let labels = (1..=f.rows).map(|i| format!("estimate_{i}")).collect();
            (f, labels, Vec::new(), path.display().to_string())
        }
        None => {
            let templates = photo_args::templates(&args.photo, &model, data_dir)?;
            let analyses = photo_args::analyse_photos(&args.photos, &args.photo, &templates)?;
            photo_args::write_outputs(&analyses, &args.photo)?;
            let f = photo_features(&analyses)?;
            if !args.photo.json {
                for a in &analyses {
                    println!("{}", photo_args::describe(a));
                }
            }
            if let Some(out) = &args.photo.features_out {
                if model.check_features(&f.names, "").is_err() {
                    println!(
                        "features → {}; no estimate: {model_name} is for chart {}",
                        out.display(),
                        model.header().chart.as_deref().unwrap_or("unknown")
                    );
                    return Ok(());
                }
            }
            let source = match args.photos.as_slice() {
                [one] => one.display().to_string(),
                _ => "the photos".into(),
            };
            (f, photo_labels(&args.photos), analyses, source)
        }
    };
    let set = estimate_rows(&model, &features, labels, &source, &grid)?;
    let truths = truths(&args, set.len(), &grid)?;
    let mut scores = Vec::with_capacity(set.len());
    let mut colorimetry = Vec::with_capacity(set.len());
    for (i, truth) in truths.iter().enumerate() {
        colorimetry.push(Colorimetry::of(set.item(i), &grid)?);
        scores.push(
            truth
                .as_ref()
                .map(|t| -> Result<Score> {
                    let t = metrics::normalise_by_max(t);
                    let e = metrics::normalise_by_max(set.item(i));
                    Ok(Score {
                        gfc: metrics::gfc(&t, &e)?,
                        rmse: metrics::rmse(&t, &e)?,
                    })
                })
                .transpose()?,
        );
    }
    if let Some(out) = &args.output {
        set.write_csv(out)?;
    }
    if let Some(plot) = &args.plot {
        let shown = set.len().min(20);
        let series: Vec<(String, Vec<f64>)> = (0..shown)
            .map(|i| (set.names()[i].clone(), set.item(i).to_vec()))
            .collect();
        let title = if set.len() == 1 {
            format!("Estimated SPD: {}", colorimetry[0].label())
        } else {
            format!("Estimated SPDs ({shown} of {})", set.len())
        };
        write_plot(plot, &spds_svg(&title, &grid, &series)?)?;
    }
    if args.photo.json {
        let json = estimates_json(&set, &grid, &colorimetry, &scores, &analyses)?;
        println!("{}", serde_json::to_string_pretty(&json)?);
        return Ok(());
    }
    println!("{} estimate(s) with {model_name}", set.len());
    let detailed = set.len() <= 20;
    for i in 0..set.len() {
        if detailed {
            println!("{}: {}", set.names()[i], colorimetry[i].label());
            println!("  relative SPD: {}", spd_line(set.item(i), &grid));
        }
        if let Some(s) = scores[i] {
            println!(
                "  against the true SPD: GFC {:.4}, RMSE {:.4} (both peak-normalised)",
                s.gfc, s.rmse
            );
        }
    }
    if let Some(out) = &args.output {
        println!(
            "SPD{} → {}",
            if set.len() > 1 { "s" } else { "" },
            out.display()
        );
    }
    if let Some(plot) = &args.plot {
        println!("plot → {}", plot.display());
    }
    Ok(())
}

/// The feature rows of analysed photos; all must come from the same chart.
fn photo_features(analyses: &[PhotoAnalysis]) -> Result<FeatureRows> {
    let first = &analyses[0];
    if let Some(other) = analyses
        .iter()
        .find(|a| a.feature_names != first.feature_names)
    {
        bail!(
            "{} shows chart {} and {} chart {}: estimate them in separate calls",
            first.source,
            first.chart,
            other.source,
            other.chart
        );
    }
    Ok(FeatureRows {
        names: first.feature_names.clone(),
        values: analyses
            .iter()
            .flat_map(|a| a.features.iter().map(|&v| f64::from(v)))
            .collect(),
        rows: analyses.len(),
    })
}

/// The SPD every 25 nm, peak-normalised, on one terminal line: `400:0.12 425:0.40 …`.
fn spd_line(spd: &[f64], grid: &Grid) -> String {
    let spd = metrics::normalise_by_max(spd);
    grid.wavelengths()
        .iter()
        .zip(&spd)
        .filter(|(w, _)| (*w % 25.0).abs() < 1e-9)
        .map(|(w, v)| format!("{w:.0}:{v:.2}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Everything about the estimates as JSON: per estimate its name, SPD, colorimetry, score
/// against the truth, and (from photos) the chart analysis.
fn estimates_json(
    set: &SpectralSet,
    grid: &Grid,
    colorimetry: &[Colorimetry],
    scores: &[Option<Score>],
    analyses: &[PhotoAnalysis],
) -> Result<serde_json::Value> {
    let items = (0..set.len())
        .map(|i| {
            let mut v = serde_json::json!({
                "name": set.names()[i],
                "wavelength_nm": grid.wavelengths(),
                "spd": set.item(i),
                "colorimetry": colorimetry[i],
                "truth": scores[i],
            });
            if let Some(a) = analyses.get(i) {
                v["photo"] = photo_args::analysis_json(a)?;
            }
            Ok(v)
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(serde_json::Value::Array(items))
}
