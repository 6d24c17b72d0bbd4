//! `spdcam detection`: how often the charts are found in the program's own scene photos,
//! per difficulty (`spdcam_core::photo::detection_rate`), written as Markdown.

use crate::outln;
use anyhow::{bail, Context, Result};
use clap::Args;
use spdcam_core::builtin::DataDir;
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::{Camera, CameraConfig};
use spdcam_core::chart::{Chart, KnownChart};
use spdcam_core::fsio;
use spdcam_core::limits;
use spdcam_core::photo::detection_rate::{self, BucketRate};
use spdcam_core::photo::scene;
use spdcam_core::photo::ChartTemplate;
use spdcam_core::spectral::Grid;
use std::fmt::Write as _;
use std::path::PathBuf;

/// Options of `spdcam detection`.
#[derive(Debug, Args)]
pub struct DetectionArgs {
    /// Scene photos per bucket and chart.
    #[arg(long, default_value_t = 20)]
    photos: usize,
    /// Photo size WxH.
    #[arg(long, default_value = "1600x1200", value_name = "WxH")]
    size: String,
    /// Seed of the photos.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// The charts photographed (each searched for among all of them).
    #[arg(
        long,
        value_delimiter = ',',
        default_values_t = KnownChart::photographed().iter().map(|c| c.name().to_string())
    )]
    charts: Vec<String>,
    /// Photograph only these of --charts (each photo is still searched for all of them);
    /// default: every chart of --charts.
    #[arg(long, value_delimiter = ',', value_name = "CHARTS")]
    photograph: Vec<String>,
    /// Only the buckets of these difficulties: size, tilt, rotation, shadow; default: all.
    #[arg(long, value_delimiter = ',', value_name = "DIFFICULTIES")]
    difficulty: Vec<String>,
    /// Also write every photo whose chart was not found into this directory, as
    /// `CHART-DIFFICULTY-BUCKET-SEED.jpg`, to look at.
    #[arg(long, value_name = "DIR")]
    misses: Option<PathBuf>,
    /// Camera sensitivities (a built-in name, a data-directory name or FILE.csv).
    #[arg(long, default_value = "nikon_d5100_npl")]
    camera: String,
    /// The Markdown file to write.
    #[arg(short, long, value_name = "FILE.md")]
    output: PathBuf,
}

/// Runs `spdcam detection`.
pub fn run(args: DetectionArgs, data_dir: &DataDir) -> Result<()> {
    fsio::check_parent_dir(&args.output)?;
    if args.photos == 0 {
        bail!("--photos must be at least 1");
    }
    limits::DETECTION_PHOTOS.check(args.photos as u64, "--photos")?;
    let (w, h) = args
        .size
        .split_once(['x', 'X', '×'])
        .and_then(|(w, h)| Some((w.trim().parse().ok()?, h.trim().parse().ok()?)))
        .with_context(|| format!("--size '{}' is not of the form WxH", args.size))?;
    scene::check_scene_size(w, h)?;
    let known: Vec<&str> = detection_rate::buckets()
        .iter()
        .map(|b| b.difficulty.label())
        .collect();
    if let Some(d) = args
        .difficulty
        .iter()
        .find(|d| !known.contains(&d.as_str()))
    {
        bail!(
            "--difficulty '{d}' is not one of {}",
            known
                .iter()
                .copied()
                .collect::<std::collections::BTreeSet<_>>()
                .into_iter()
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    if let Some(c) = args.photograph.iter().find(|c| !args.charts.contains(c)) {
        bail!(
            "--photograph '{c}' is not one of --charts ({})",
            args.charts.join(", ")
        );
    }
    if let Some(dir) = &args.misses {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create --misses directory {}", dir.display()))?;
    }
    let grid = Grid::SIMULATION;
    let sensitivities = Sensitivities::resolve(&args.camera, data_dir, &grid)?;
    let mut cameras = Vec::new();
    let mut templates = Vec::new();
    for name in &args.charts {
        let chart = Chart::resolve(name, None, data_dir, &grid)?;
        let template = ChartTemplate::from_chart(&chart)?;
        let chart = chart.with_layout(scene::scene_layout(&template))?;
        cameras.push(Camera::new(
            &sensitivities,
            chart,
            CameraConfig::default(),
            &grid,
        )?);
        templates.push(template);
    }
    let started = std::time::Instant::now();
    let mut rates: Vec<BucketRate> = Vec::new();
    let buckets = detection_rate::buckets().into_iter().filter(|b| {
        args.difficulty.is_empty() || args.difficulty.iter().any(|d| d == b.difficulty.label())
    });
    for bucket in buckets {
        let photographed = cameras
            .iter()
            .zip(&args.charts)
            .filter(|(_, name)| args.photograph.is_empty() || args.photograph.contains(name));
        for (camera, _) in photographed {
            let r = detection_rate::measure(
                camera,
                &templates,
                &bucket,
                args.photos,
                args.seed,
                (w, h),
            )?;
            let error = if r.found == 0 {
                "–".to_string()
            } else {
                format!("{:.1} %", 100.0 * r.mean_corner_error)
            };
            eprintln!(
                "{} {} {}: found {}/{}, corner error {error}",
                r.chart,
                bucket.difficulty.label(),
                bucket.label,
                r.found,
                r.photos,
            );
            for (seed, why) in &r.misses {
                eprintln!("  missed seed {seed}: {why}");
                if let Some(dir) = &args.misses {
                    let shot = bucket.photograph(camera, *seed, (w, h))?;
                    let label: String = bucket
                        .label
                        .chars()
                        .filter(|c| c.is_ascii_alphanumeric())
                        .collect();
                    let file = dir.join(format!(
                        "{}-{}-{label}-{seed}.jpg",
                        r.chart,
                        bucket.difficulty.label()
                    ));
                    fsio::write_atomic(&file, &shot.jpeg)?;
                }
            }
            rates.push(r);
        }
    }
    let md = document(&args, (w, h), &rates, started.elapsed().as_secs_f64());
    fsio::write_atomic(&args.output, md.as_bytes())?;
    outln!("detection rates: {}", args.output.display())?;
    Ok(())
}

/// The Markdown document.
fn document(
    args: &DetectionArgs,
    (w, h): (usize, usize),
    rates: &[BucketRate],
    seconds: f64,
) -> String {
    let mut md = String::from("# How often the chart is found\n\n");
    let _ = write!(
        md,
        "Regenerated by the command at the end. Scene photos made by the code of `spdcam render \
         --scene` ({w}×{h}, {} per bucket and chart, seed {}): the chart (laid out as the \
         physical chart, gaps included) under a Planckian light of 2700–6500 K, photographed by \
         the default camera ({}: Bayer mosaic, sensor noise, Menon demosaicing, white balance \
         over the whole frame, lateral aberration, JPEG 80–95) on a cluttered background, with \
         the lens's blur (σ 0–1.2 px) and vignetting, anywhere in the frame. Each bucket varies \
         one difficulty; the rest is drawn per photo: the rotation in the chart's plane within \
         ±10° (any in the rotation bucket), the side the tilted chart turns away and the axis \
         (the photo's horizontal or vertical), and, without tilt, corners displaced by up to 5 % \
         of the chart's side for a little perspective. Size: the patch grid's width as a share \
         of the photo's width, face-on. Tilt: the chart's plane turned away by that angle, \
         seen by a pinhole camera of focal length 0.9 × the photo's width, at 1/4 of the width. \
         Shadow: 30–60 % of the chart, from any side, darker by that factor (soft edge), at 1/6 \
         of the width.\n\n\
         Each photo is searched for all the charts ({}) as `spdcam estimate` searches one. \
         Found: the right chart, every corner within half a patch side of its true place (so \
         also the right way round). Corner error: the mean distance of the four corners of \
         the patch grid from the true ones, in % of a patch side (the square root of a \
         patch's area in the photo), over the photos found. The search runs on the photo with \
         the lens's colour fringes taken out in the camera's own RGB (a typical camera's \
         colour matrix undone, then red's and blue's magnification against green measured \
         on the strongest edges and undone). The patch candidates (regions of nearly constant \
         colour) are grouped into grids, their sizes compared with the grid's pitch as if \
         the pixel that blur takes off each side were restored; a grid is laid on the chart \
         the way round in which its neutral patches are grey and in the chart's order of \
         lightness. The corners are those of the grid fitted to the patch candidates, \
         refined where the patches are at least 7 px apart: moved to \
         where the patch edges are sharpest in the camera's green (a Nelder–Mead search on \
         pairs of points across every patch edge, ending a fiftieth of a patch either side \
         of it, where each pair reads the brightness gradient across the edge). Where too \
         few patches are \
         segmented for the chart to be found by them (a small or steep chart), the grid \
         extrapolated from those found is accepted when the photo supports it: flat inside \
         the patches, not so when moved by half a patch, and no patches continuing outside \
         the chart; such a grid is refined at any size. Goals: at least 99 % found down to \
         1/15 of the width and 70° tilt, mean corner error at most 2 %.\n\n",
        args.photos,
        args.seed,
        args.camera,
        args.charts.join(", ")
    );
    md += &detection_rate::markdown_table(rates);
    let found: usize = rates.iter().map(|r| r.found).sum();
    let photos: usize = rates.iter().map(|r| r.photos).sum();
    let _ = write!(
        md,
        "\nAll buckets: {found} of {photos} found ({:.1} %); {seconds:.0} s on this machine.\n",
        100.0 * found as f64 / photos.max(1) as f64
    );
    let misses: Vec<String> = rates
        .iter()
        .flat_map(|r| {
            r.misses.iter().map(move |(s, why)| {
                format!(
                    "- {} {} {}, seed {s}: {why}",
                    r.chart,
                    r.bucket.difficulty.label(),
                    r.bucket.label
                )
            })
        })
        .collect();
    if !misses.is_empty() {
        md += "\nPhotos not found:\n\n";
        md += &misses.join("\n");
        md.push('\n');
    }
    let mut filters = String::new();
    if !args.photograph.is_empty() {
        let _ = write!(filters, " --photograph {}", args.photograph.join(","));
    }
    if !args.difficulty.is_empty() {
        let _ = write!(filters, " --difficulty {}", args.difficulty.join(","));
    }
    let _ = write!(
        md,
        "\n```sh\nspdcam detection --photos {} --size {w}x{h} --seed {} --charts {}{filters} -o docs/detection.md\n```\n",
        args.photos,
        args.seed,
        args.charts.join(",")
    );
    md
}
