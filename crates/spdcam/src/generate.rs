//! `spdcam generate`: a dataset of (features, SPD) samples from the virtual camera.

use crate::outln;
use crate::render::CameraArgs;
use anyhow::Result;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use spdcam_core::builtin::DataDir;
use spdcam_core::dataset::randomise::{RandomiseRequest, DEFAULT_CAMERA_VARIANTS};
use spdcam_core::dataset::{
    GenerateEvent, GenerateOptions, GenerateRequest, Pipeline, Plan, Shard, DEFAULT_CHUNK_SIZE,
};
use spdcam_core::spectral::Grid;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::Instant;

/// Options of `spdcam generate`.
#[derive(Debug, Args)]
pub struct GenerateArgs {
    /// Lighting recipe (`spdcam list lighting` shows the forms).
    #[arg(long)]
    lighting: String,
    /// Number of samples of the whole run (all shards together).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_count)]
    count: u64,
    /// Seed: sample i depends only on (seed, i).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Output dataset directory (manifest.json + samples/part-NNNNN.parquet).
    #[arg(short, long)]
    output: PathBuf,
    /// Also write each rendered chart as images/sample-NNNNNNNN.png.
    #[arg(long)]
    images: bool,
    /// Generate only part K of N (K = 0…N-1), e.g. on N machines; join the parts with
    /// `spdcam dataset merge`.
    #[arg(long, value_name = "K/N", value_parser = parse_shard)]
    shard: Option<Shard>,
    /// Noise-free patch-level features without an image, for very large sets.
    #[arg(long)]
    fast: bool,
    /// Noise-free patch-level features as a raw file is read, for a raw model: each patch's
    /// exposed camera RGB (no white balance, tone or JPEG) taken to XYZ by the camera's DNG
    /// colour matrices (fitted under A and D65) at the chart's neutral, a perfect white at
    /// Y = 100.
    #[arg(long, conflicts_with_all = ["fast", "images"])]
    raw: bool,
    /// Wavelengths the SPDs are stored at, START-END[:STEP] in nm (inside 380-780).
    #[arg(long, default_value = "380-780:5", value_name = "START-END[:STEP]")]
    spd_grid: String,
    /// Samples per Parquet file (shards of one run must use the same).
    #[arg(long, default_value_t = DEFAULT_CHUNK_SIZE)]
    chunk_size: u64,
    /// Replace what the output directory holds instead of refusing or resuming.
    #[arg(long)]
    force: bool,
    /// The camera's in-camera rendering, as written by `spdcam fit-in-camera` (JSON).
    #[arg(long, value_name = "FILE.json")]
    in_camera: Option<PathBuf>,
    /// Domain randomisation per sample, comma-separated: camera (draw the camera from
    /// --cameras), exposure, wb (or wb-wide), tone, jpeg, floor (draw those in-camera
    /// parameters; floor: a black floor under the rendered values), gradient (uneven
    /// lighting across the chart), glow (a glow of random place, size and strength on the
    /// chart in half the photos, as a lamp beside it gives).
    #[arg(long, value_delimiter = ',', value_name = "GROUPS")]
    randomise: Vec<String>,
    /// Cameras to draw from with --randomise camera, comma-separated: directories of
    /// sensitivity CSVs, camera names or files.
    #[arg(long, value_name = "DIR|LIST")]
    cameras: Option<String>,
    /// A validation split (`spdcam lamps split`): its held-out cameras are left out of the pool.
    #[arg(long, value_name = "SPLIT.json")]
    camera_split: Option<PathBuf>,
    /// Perturbed copies of each camera in the pool (shift ±5 nm, gain ±10 %).
    #[arg(long, default_value_t = DEFAULT_CAMERA_VARIANTS)]
    camera_variants: usize,
    #[command(flatten)]
    camera: CameraArgs,
}

fn parse_count(text: &str) -> Result<u64, String> {
    match text.trim().parse::<i128>() {
        Ok(n) if n >= 1 && n <= u64::MAX as i128 => Ok(n as u64),
        Ok(_) => Err("the sample count must be at least 1".into()),
        Err(_) => Err("the sample count must be a whole number, e.g. 10000".into()),
    }
}

fn parse_shard(text: &str) -> Result<Shard, String> {
    Shard::parse(text).map_err(|e| e.to_string())
}

/// A progress bar with rate and ETA on a terminal; nothing when stderr is piped.
pub fn progress_bar(total: u64, unit: &str) -> Option<ProgressBar> {
    if !std::io::stderr().is_terminal() {
        return None;
    }
    let style = ProgressStyle::with_template(&format!(
        "{{elapsed_precise}} [{{wide_bar}}] {{human_pos}}/{{human_len}} {unit}, {{rate}}, ETA {{eta}}"
    ))
    .unwrap_or_else(|_| ProgressStyle::default_bar())
    .with_key(
        "rate",
        |state: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
            let _ = write!(w, "{:.0}/s", state.per_sec());
        },
    );
    Some(ProgressBar::new(total).with_style(style))
}

/// Tells what a prepared run will do when it is not simply all of it: no samples in this
/// shard, all of them already written, or a resumed run.
fn report_plan(plan: &Plan, output: &Path, chunk_size: u64) {
    if plan.total() == 0 {
        eprintln!(
            "warning: this shard holds no samples: the run has fewer files of {chunk_size} samples than shards"
        );
    } else if plan.done() == plan.total() {
        eprintln!(
            "{} already holds all {} samples of this run",
            output.display(),
            plan.total()
        );
    } else if plan.done() > 0 {
        eprintln!(
            "resuming: {} of {} samples were already written",
            plan.done(),
            plan.total()
        );
    }
}

/// The files and directories the run reads that the options name: the in-camera
/// rendering, the camera split, and a camera, camera pool or lighting file given as a path
/// (`leds:FILE`); the output must lie apart from them.
fn input_files(args: &GenerateArgs) -> Vec<PathBuf> {
    let named = [
        Some(args.camera.camera.as_str()),
        args.cameras.as_deref(),
        args.lighting.split_once(':').map(|(_, rest)| rest),
    ];
    args.in_camera
        .iter()
        .chain(&args.camera_split)
        .cloned()
        .chain(named.into_iter().flatten().map(PathBuf::from))
        .filter(|p| p.exists())
        .collect()
}

/// Runs `spdcam generate`.
pub fn run(args: GenerateArgs, data_dir: &DataDir) -> Result<()> {
    let grid = Grid::SIMULATION;
    let inputs = input_files(&args);
    let inputs: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
    spdcam_core::fsio::check_output_apart(&args.output, &inputs)?;
    let options = GenerateOptions {
        count: args.count,
        seed: args.seed,
        shard: args.shard,
        pipeline: if args.raw {
            Pipeline::Raw
        } else if args.fast {
            Pipeline::Fast
        } else {
            Pipeline::Full
        },
        spd_grid: Grid::parse(&args.spd_grid)?,
        images: args.images,
        chunk_size: args.chunk_size,
    };
    let mut config = args.camera.config()?;
    if let Some(path) = &args.in_camera {
        config.in_camera = Some(crate::fit_in_camera::read_in_camera(path)?);
    }
    let request = GenerateRequest {
        lighting: args.lighting,
        camera: args.camera.camera.clone(),
        chart: args.camera.chart(data_dir, &grid)?,
        config,
        randomise: RandomiseRequest {
            groups: args.randomise,
            cameras: args.cameras,
            camera_split: args.camera_split,
            camera_variants: args.camera_variants,
        },
        options,
    };
    let bar = OnceLock::new();
    let mut new = 0;
    let mut started = Instant::now();
    let manifest = request.run(
        &args.output,
        args.force,
        data_dir,
        &mut |event| match event {
            GenerateEvent::Skipped(path, e) => crate::fit_in_camera::warn_skipped(path, e),
            GenerateEvent::Planned(plan) => {
                report_plan(plan, &args.output, args.chunk_size);
                new = plan.total() - plan.done();
                started = Instant::now();
                if let Some(b) = progress_bar(new, "samples") {
                    let _ = bar.set(b);
                }
            }
        },
        &|n| {
            if let Some(bar) = bar.get() {
                bar.inc(n);
            }
        },
    )?;
    if let Some(bar) = bar.get() {
        bar.finish_and_clear();
    }
    let seconds = started.elapsed().as_secs_f64();
    outln!(
        "{} samples in {} ({new} new in {seconds:.1} s, {:.0} samples/s)",
        manifest.samples,
        args.output.display(),
        new as f64 / seconds.max(1e-9)
    )?;
    if let Some(ratio) = manifest.valid_ratio {
        outln!(
            "valid ratio {ratio:.4} ({} lights drawn), families: {}",
            manifest.attempts,
            manifest
                .families
                .iter()
                .map(|(f, n)| format!("{f} {n}"))
                .collect::<Vec<_>>()
                .join(", ")
        )?;
    }
    Ok(())
}
