//! `spdcam dataset`: import, export, merge, split and inspect dataset directories.

use crate::generate::progress_bar;
use anyhow::{anyhow, bail, Context, Result};
use clap::{Args, Subcommand};
use spdcam_core::builtin::DataDir;
use spdcam_core::dataset::{
    self, Dataset, ExportOptions, ImportOptions, Manifest, Origin, DEFAULT_CHUNK_SIZE,
    FEATURE_SCALE,
};
use spdcam_core::fsio;
use spdcam_core::lighting::Lighting;
use spdcam_core::spectral::Grid;
use std::path::{Path, PathBuf};

/// Options of `spdcam dataset`.
#[derive(Debug, Args)]
pub struct DatasetArgs {
    #[command(subcommand)]
    command: DatasetCommand,
}

#[derive(Debug, Subcommand)]
enum DatasetCommand {
    /// Bring features and SPDs from CSV files (rows = samples) into a dataset.
    Import(ImportArgs),
    /// Write a dataset as CSV files: features.csv, spds.csv (header = wavelengths), ….
    Export(ExportArgs),
    /// Join the shards of one generate run, or datasets with the same columns.
    Merge(MergeArgs),
    /// Split a dataset into train, val and test parts (seeded).
    Split(SplitArgs),
    /// Counts, families, columns and settings; optionally a plot of 20 SPDs.
    Info(InfoArgs),
}

#[derive(Debug, Args)]
struct ImportArgs {
    /// Features CSV: header p01_r,p01_g,…; one row per sample.
    #[arg(long, value_name = "F.csv")]
    features: PathBuf,
    /// SPDs CSV: header = wavelengths in nm; one row per sample, same order as the features.
    #[arg(
        long,
        value_name = "S.csv",
        required_unless_present = "weights",
        conflicts_with = "weights"
    )]
    spds: Option<PathBuf>,
    /// Instead of SPDs: channel weights (one column per channel of --lighting, one row per
    /// sample); each SPD is the weighted sum of the channels, normalised by its maximum.
    #[arg(long, value_name = "W.csv", requires = "lighting")]
    weights: Option<PathBuf>,
    /// The lighting whose channels the weights drive (gaussian:N, leds:FILE, telelumen:PRESET).
    #[arg(long, value_name = "RECIPE", requires = "weights")]
    lighting: Option<String>,
    /// Scale of the features in the file: 255 (0–255) or 1 (0–1). Stored on 0–255.
    #[arg(long, default_value = "255", value_parser = ["255", "1"])]
    feature_scale: String,
    /// Wavelengths the SPDs are stored at, START-END[:STEP] in nm.
    #[arg(long, default_value = "380-780:5", value_name = "START-END[:STEP]")]
    spd_grid: String,
    /// Family name of the samples; default: the features file's directory name.
    #[arg(long)]
    family: Option<String>,
    /// Output dataset directory.
    #[arg(short, long)]
    output: PathBuf,
    /// Replace what the output directory holds.
    #[arg(long)]
    force: bool,
}

#[derive(Debug, Args)]
struct ExportArgs {
    /// The dataset directory.
    dataset: PathBuf,
    /// Write CSV (the only format so far): features.csv, spds.csv, weights.csv, samples.csv.
    #[arg(long, required = true)]
    csv: bool,
    /// Output directory.
    #[arg(short, long)]
    output: PathBuf,
    /// Scale to write the features on: 255 (0–255) or 1 (0–1).
    #[arg(long, default_value = "255", value_parser = ["255", "1"])]
    feature_scale: String,
    /// Wavelengths to write the SPDs at; default: the dataset's own.
    #[arg(long, value_name = "START-END[:STEP]")]
    spd_grid: Option<String>,
    /// Replace what the output directory holds.
    #[arg(long)]
    force: bool,
}

#[derive(Debug, Args)]
struct MergeArgs {
    /// The datasets (shard directories or datasets with the same columns).
    #[arg(required = true)]
    datasets: Vec<PathBuf>,
    /// Output dataset directory.
    #[arg(short, long)]
    output: PathBuf,
    /// Replace what the output directory holds.
    #[arg(long)]
    force: bool,
}

#[derive(Debug, Args)]
struct SplitArgs {
    /// The dataset directory.
    dataset: PathBuf,
    /// Output directory; receives train/, val/ and test/.
    #[arg(short, long)]
    output: PathBuf,
    /// Fractions of train, val and test, adding up to 1.
    #[arg(long, default_value = "0.7,0.1,0.2", value_name = "TRAIN,VAL,TEST")]
    fractions: String,
    /// Seed of the shuffle.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Replace what the output directory holds.
    #[arg(long)]
    force: bool,
}

#[derive(Debug, Args)]
struct InfoArgs {
    /// The dataset directory.
    dataset: PathBuf,
    /// Also plot 20 SPDs spread over the dataset into this SVG file.
    #[arg(long, value_name = "FILE.svg")]
    plot: Option<PathBuf>,
    /// Read every sample file and check it against the manifest (SHA-256, columns, finite
    /// values, row and family counts); exits non-zero when anything is wrong.
    #[arg(long)]
    verify: bool,
    /// After rewriting sample files on purpose (e.g. with pandas, same columns): re-read
    /// them and record their new row counts and checksums in the manifest.
    #[arg(long, conflicts_with = "verify")]
    update_checksums: bool,
}

/// Runs `spdcam dataset …`.
pub fn run(args: DatasetArgs, data_dir: &DataDir) -> Result<()> {
    match args.command {
        DatasetCommand::Import(a) => import(a, data_dir),
        DatasetCommand::Export(a) => export(a),
        DatasetCommand::Merge(a) => merge(a),
        DatasetCommand::Split(a) => split(a),
        DatasetCommand::Info(a) => info(a),
    }
}

fn import(args: ImportArgs, data_dir: &DataDir) -> Result<()> {
    let feature_scale: f64 = args.feature_scale.parse()?;
    let family = match args.family {
        Some(f) => f,
        None => args
            .features
            .canonicalize()
            .ok()
            .and_then(|p| Some(p.parent()?.file_name()?.to_string_lossy().into_owned()))
            .unwrap_or_else(|| "imported".to_string()),
    };
    let weights_of = match &args.lighting {
        Some(spec) => Some(Lighting::parse(spec, data_dir, &Grid::SIMULATION)?),
        None => None,
    };
    let options = ImportOptions {
        feature_scale,
        spd_grid: Grid::parse(&args.spd_grid)?,
        family,
        chunk_size: DEFAULT_CHUNK_SIZE,
        weights_of,
    };
    let second = args
        .spds
        .as_ref()
        .or(args.weights.as_ref())
        .context("give --spds S.csv, or --weights W.csv with --lighting")?;
    let report = dataset::import_csv(&args.features, second, &args.output, &options, args.force)?;
    let m = &report.manifest;
    if let Origin::Imported(source) = &m.origin {
        if let Some(r) = source.resampling.as_ref().filter(|r| r.extrapolated()) {
            eprintln!(
                "warning: {}",
                r.describe(&second.display().to_string(), &options.spd_grid)
            );
        }
    }
    if feature_scale == FEATURE_SCALE && report.largest_feature <= 1.0 {
        eprintln!(
            "warning: no feature exceeds 1; if the file is on 0–1, import it with --feature-scale 1"
        );
    }
    println!(
        "imported {} samples ({} features, SPDs on {}) as family '{}' into {}",
        m.samples,
        m.columns.feature_count(),
        m.columns.spd_grid,
        options.family,
        args.output.display()
    );
    Ok(())
}

fn export(args: ExportArgs) -> Result<()> {
    if !args.csv {
        bail!("name the format to export: --csv");
    }
    let dataset = Dataset::open(&args.dataset)?;
    let options = ExportOptions {
        feature_scale: args.feature_scale.parse()?,
        spd_grid: args.spd_grid.as_deref().map(Grid::parse).transpose()?,
    };
    let files = dataset::export_csv(&dataset, &args.output, &options, args.force)?;
    println!(
        "{} samples written as {}",
        dataset.len(),
        files
            .iter()
            .map(|f| f.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    Ok(())
}

fn open_all(dirs: &[PathBuf]) -> Result<Vec<Dataset>> {
    dirs.iter()
        .map(|d| Dataset::open(d).map_err(Into::into))
        .collect()
}

fn merge(args: MergeArgs) -> Result<()> {
    let inputs = open_all(&args.datasets)?;
    let total = inputs.iter().map(Dataset::len).sum();
    let bar = progress_bar(total, "rows");
    let manifest = dataset::merge(&inputs, &args.output, args.force, &|n| {
        if let Some(b) = &bar {
            b.inc(n)
        }
    })?;
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let what = match manifest.origin {
        Origin::Generated(_) => format!("the {} shards of one run", inputs.len()),
        _ => format!("{} datasets", inputs.len()),
    };
    println!(
        "merged {what} into {}: {} samples",
        args.output.display(),
        manifest.samples
    );
    Ok(())
}

fn parse_fractions(text: &str) -> Result<[f64; 3]> {
    let values: Vec<f64> = text
        .split(',')
        .map(|v| v.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .ok()
        .filter(|v: &Vec<f64>| v.len() == 3)
        .with_context(|| {
            format!("fractions '{text}' are not three numbers TRAIN,VAL,TEST, e.g. 0.7,0.1,0.2")
        })?;
    Ok([values[0], values[1], values[2]])
}

fn split(args: SplitArgs) -> Result<()> {
    let fractions = parse_fractions(&args.fractions)?;
    let input = Dataset::open(&args.dataset)?;
    let bar = progress_bar(input.len(), "rows");
    let parts = dataset::split(
        &input,
        &args.output,
        fractions,
        args.seed,
        args.force,
        &|n| {
            if let Some(b) = &bar {
                b.inc(n)
            }
        },
    )?;
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let counts: Vec<String> = ["train", "val", "test"]
        .iter()
        .zip(&parts)
        .map(|(name, m)| format!("{name} {}", m.samples))
        .collect();
    println!(
        "split {} samples into {}: {}",
        input.len(),
        args.output.display(),
        counts.join(", ")
    );
    Ok(())
}

/// A one-line account of where the samples came from.
fn describe_origin(origin: &Origin) -> String {
    match origin {
        Origin::Generated(s) => format!(
            "generated: lighting {}, camera {}, chart {}, {} pipeline, seed {}, {} of {} samples{}",
            s.lighting.spec,
            s.camera.name,
            s.chart.name,
            serde_json::to_value(s.pipeline)
                .ok()
                .and_then(|v| v.as_str().map(str::to_string))
                .unwrap_or_default(),
            s.seed,
            s.sample_range[1] - s.sample_range[0],
            s.count,
            s.shard.map(|k| format!(", shard {k}")).unwrap_or_default()
        ),
        Origin::Imported(s) => format!(
            "imported from {} and {} (features on 0–{})",
            s.features_file, s.spds_file, s.feature_scale
        ),
        Origin::Merged { sources } => format!(
            "merged from {} datasets: {}",
            sources.len(),
            sources
                .iter()
                .map(describe_origin)
                .collect::<Vec<_>>()
                .join(" | ")
        ),
        Origin::Split {
            part,
            fractions,
            seed,
            source_samples,
            source,
        } => format!(
            "{part} part of a {}/{}/{} split (seed {seed}) of {source_samples} samples, {}",
            fractions[0],
            fractions[1],
            fractions[2],
            describe_origin(source)
        ),
    }
}

fn print_info(dir: &Path, m: &Manifest) {
    let c = &m.columns;
    println!(
        "dataset {} (written by spdcam {})",
        dir.display(),
        m.spdcam_version
    );
    println!("  samples:  {} in {} files", m.samples, m.files.len());
    println!("  origin:   {}", describe_origin(&m.origin));
    if let Some(r) = m.valid_ratio.filter(|_| m.origin.generated().is_some()) {
        println!("  valid:    {r:.4} of drawn lights ({} drawn)", m.attempts);
    }
    println!("  families:");
    for (family, n) in &m.families {
        let share = 100.0 * *n as f64 / m.samples.max(1) as f64;
        println!("    {family:<32} {n:>10} ({share:.1} %)");
    }
    let precision = serde_json::to_value(c.feature_precision)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default();
    println!(
        "  features: {} ({} … {}), {precision}, mean encoded sRGB on 0–{}",
        c.feature_count(),
        c.feature_names.first().map_or("", String::as_str),
        c.feature_names.last().map_or("", String::as_str),
        m.feature_scale
    );
    println!("  SPD:      {}", c.spd_grid);
    if c.weight_names.is_empty() {
        println!("  weights:  none");
    } else {
        println!(
            "  weights:  {} ({})",
            c.weight_count(),
            c.weight_names.join(", ")
        );
    }
}

fn info(args: InfoArgs) -> Result<()> {
    if args.update_checksums {
        let m = Dataset::update_checksums(&args.dataset)?;
        println!(
            "recorded {} files ({} samples) with their checksums in {}",
            m.files.len(),
            m.samples,
            args.dataset.join(dataset::MANIFEST_FILE).display()
        );
    }
    let dataset = Dataset::open(&args.dataset)?;
    print_info(&args.dataset, dataset.manifest());
    if args.verify {
        let bar = progress_bar(dataset.len(), "rows");
        let report = dataset.verify(&|n| {
            if let Some(b) = &bar {
                b.inc(n)
            }
        });
        if let Some(b) = bar {
            b.finish_and_clear();
        }
        for problem in &report.problems {
            eprintln!("  problem:  {problem}");
        }
        let unchecked = match report.without_checksum {
            0 => String::new(),
            n => format!(" ({n} without a checksum in the manifest: contents not proven)"),
        };
        if !report.problems.is_empty() {
            bail!(
                "{} does not match its manifest: {} of {} sample files read correctly; problems: {}",
                args.dataset.display(),
                report.files_ok,
                dataset.manifest().files.len(),
                report.problems.len()
            );
        }
        println!(
            "  verified: {} files, {} samples match the manifest{unchecked}",
            report.files_ok,
            dataset.len()
        );
    }
    if let Some(path) = &args.plot {
        fsio::check_parent_dir(path)?;
        let n = dataset.len();
        let shown = n.min(20);
        let positions: Vec<u64> = (0..shown).map(|k| k * n / shown.max(1)).collect();
        let rows = dataset.rows_at(&positions)?;
        let svg = plot_spds(&rows, &dataset.columns().spd_grid)?;
        fsio::write_atomic(path, svg.as_bytes())?;
        println!("  plot:     {} ({shown} SPDs)", path.display());
    }
    Ok(())
}

/// An SVG of the SPDs of `rows`, each divided by its maximum.
fn plot_spds(rows: &dataset::SampleBatch, grid: &Grid) -> Result<String> {
    use plotters::prelude::*;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 520)).into_drawing_area();
        let err = |e: &dyn std::fmt::Display| anyhow!("drawing the plot: {e}");
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!("{} SPDs of the dataset", rows.len()),
                ("sans-serif", 22),
            )
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(56)
            .build_cartesian_2d(grid.start_nm..grid.end_nm(), 0.0..1.05)
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .x_desc("wavelength (nm)")
            .y_desc("relative power (each / its maximum)")
            .draw()
            .map_err(|e| err(&e))?;
        for i in 0..rows.len() {
            let spd = rows.spd_of(i);
            let peak = spd.iter().cloned().fold(0.0, f64::max);
            let scale = if peak > 0.0 { 1.0 / peak } else { 0.0 };
            let points = spd
                .iter()
                .enumerate()
                .map(|(k, v)| (grid.wavelength(k), v * scale));
            chart
                .draw_series(LineSeries::new(points, Palette99::pick(i).stroke_width(2)))
                .map_err(|e| err(&e))?;
        }
        root.present().map_err(|e| err(&e))?;
    }
    if svg.is_empty() {
        bail!("drawing the plot produced nothing");
    }
    Ok(svg)
}
