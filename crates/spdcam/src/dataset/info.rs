//! `spdcam dataset info`: a dataset's counts, families, columns and settings; optionally its
//! files checked against the manifest, and a plot of some of its SPDs.

use crate::generate::progress_bar;
use crate::plot_file::{plot_is_png, write_plot};
use anyhow::{anyhow, bail, Result};
use clap::Args;
use spdcam_core::dataset::{self, Dataset, Manifest, Origin};
use spdcam_core::fsio;
use spdcam_core::spectral::Grid;
use std::path::{Path, PathBuf};

#[derive(Debug, Args)]
pub(super) struct InfoArgs {
    /// The dataset directory.
    dataset: PathBuf,
    /// Also plot 20 SPDs spread over the dataset into this file: SVG for .svg, PNG for .png.
    #[arg(long, value_name = "FILE.svg|FILE.png")]
    plot: Option<PathBuf>,
    /// Read every sample file and check it against the manifest (SHA-256, columns, finite
    /// values, row and family counts) and for samples held twice; exits non-zero when
    /// anything is wrong.
    #[arg(long)]
    verify: bool,
    /// After rewriting sample files on purpose (e.g. with pandas, same columns): re-read
    /// them and record their new row counts and checksums in the manifest.
    #[arg(long, conflicts_with = "verify")]
    update_checksums: bool,
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

/// Runs `spdcam dataset info`.
pub(super) fn run(args: InfoArgs) -> Result<()> {
    if let Some(path) = &args.plot {
        plot_is_png(path)?;
        fsio::check_parent_dir(path)?;
    }
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
        if let Some(why) = &report.duplicates_unchecked {
            eprintln!("  note:     samples not checked for duplicates: {why}");
        }
        if !report.problems.is_empty() {
            bail!(
                "{} failed verification: {} of {} sample files read correctly; problems: {}",
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
        let n = dataset.len();
        let shown = n.min(20);
        let positions: Vec<u64> = (0..shown).map(|k| k * n / shown.max(1)).collect();
        let rows = dataset.rows_at(&positions)?;
        let svg = plot_spds(&rows, &dataset.columns().spd_grid)?;
        write_plot(path, &svg)?;
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
