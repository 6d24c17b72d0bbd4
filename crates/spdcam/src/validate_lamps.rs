//! `spdcam lamps validate`: the validation protocol for real lamps. (a) The split's held-out
//! lamps photographed (patch level) by the split's held-out cameras with the randomised
//! in-camera stage; (b) the same lamps photographed by an independent simple camera model
//! (`spdcam_core::simple_camera`); both scored per lamp type (mean GFC, 400–700 nm) beside
//! the average-SPD baseline, for the validation lamps (choose on these) and the test lamps
//! (report only). (c) The real photo sets of the thesis (SG 96 models only).

use crate::held_out_args::HeldOutArgs;
use anyhow::{bail, Context, Result};
use clap::Args;
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};
use spdcam_core::builtin::DataDir;
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::{Camera, CameraConfig};
use spdcam_core::chart::{Chart, KnownChart};
use spdcam_core::dataset::randomise::{camera_pool, InCameraRanges, Randomisation};
use spdcam_core::dataset::REAL_PHOTO_SETS;
use spdcam_core::fsio::write_atomic;
use spdcam_core::lighting::validation_split::LampPart;
use spdcam_core::lighting::{LampLibrary, LampType, ValidationSplit};
use spdcam_core::simple_camera::{Shot, SimpleCamera};
use spdcam_core::spectral::{Extrapolation, Grid, Interpolation, SpectralSet};
use spdcam_core::{metrics, seed};
use spdcam_eval::held_out::{held_out_cameras, in_data_dir, on_grid};
use spdcam_infer::Model;
use std::path::PathBuf;

/// Options of `spdcam lamps validate`.
#[derive(Debug, Args)]
pub struct ValidateArgs {
    #[command(flatten)]
    photos: HeldOutArgs,
    /// The thesis's data (holding measured/…); default: the data directory's thesis/.
    #[arg(long)]
    thesis_data: Option<PathBuf>,
    /// Leave out (c), the real photo sets.
    #[arg(long)]
    no_real: bool,
    /// Output Markdown table (printed too).
    #[arg(short, long)]
    output: PathBuf,
}

const GRID: Grid = Grid::SIMULATION;
/// Random stream of the simple camera's draws.
const SIMPLE_STREAM: u64 = 0x5349_4D50_4C45_0001;

/// Feature rows of the held-out lamps under one camera model: `shots` rows per lamp.
struct Photos {
    /// Row-major features, `lamps × shots` rows.
    features: Vec<f64>,
    width: usize,
}

/// The scores of one model on one part of the lamps: mean GFC per lamp.
type LampScores = Vec<f64>;

/// Runs `spdcam lamps validate`.
pub fn run(args: ValidateArgs, data_dir: &DataDir) -> Result<()> {
    if args.photos.shots == 0 {
        bail!("--shots must be at least 1");
    }
    let library = args.photos.library.read(data_dir, &GRID)?;
    let split = ValidationSplit::read(&args.photos.split)?;
    let held_out = held_out_cameras(&split, args.photos.cameras.as_deref(), data_dir)?;
    let parts = [
        ("validation", LampPart::Validation),
        ("test", LampPart::Test),
    ];
    let lamps: Vec<Vec<usize>> = parts
        .iter()
        .map(|(name, p)| library.positions(split.lamps(*p), &format!("the split's {name} lamps")))
        .collect::<spdcam_core::Result<_>>()?;
    let fit_lamps = library.positions(split.lamps(LampPart::Fit), "the split's fit lamps")?;
    let models = args
        .photos
        .model
        .iter()
        .map(|p| Ok((p.clone(), Model::load(p)?)))
        .collect::<Result<Vec<_>>>()?;

    let mut md = String::new();
    let mut real_rows = Vec::new();
    for (path, model) in &models {
        let chart_name = model
            .header()
            .chart
            .clone()
            .with_context(|| format!("{}: the model names no chart", path.display()))?;
        let chart = Chart::resolve(&chart_name, None, data_dir, &GRID)?;
        model.check_features(&chart.feature_names(), &chart_name)?;
        let truth = on_grid(&library, &model.grid())?;
        let average = average_spd(&truth, &fit_lamps);
        md += &format!("### `{}` ({chart_name})\n\n", file_name(path));
        md += "| lamp type | lamps (val / test) | average SPD (val) | (a) randomised in-camera (val) | (b) simple camera (val) | average SPD (test) | (a) test | (b) test |\n|---|---:|---:|---:|---:|---:|---:|---:|\n";
        let mut cells: Vec<[LampScores; 3]> = Vec::new();
        for (k, ids) in lamps.iter().enumerate() {
            let stream = seed::derive(args.photos.seed, k as u64);
            let a = pipeline_photos(&held_out, &chart, &library, ids, args.photos.shots, stream)?;
            let b = simple_photos(&held_out, &chart, &library, ids, args.photos.shots, stream)?;
            let baseline: LampScores = ids
                .iter()
                .map(|&i| metrics::gfc(&truth[i], &average).unwrap_or(0.0))
                .collect();
            cells.push([
                baseline,
                score(model, &a, &truth, ids, args.photos.shots)?,
                score(model, &b, &truth, ids, args.photos.shots)?,
            ]);
        }
        let kinds: Vec<Option<LampType>> = LampType::ALL
            .iter()
            .filter(|t| lamps.iter().flatten().any(|&i| library.types[i] == **t))
            .map(|&t| Some(t))
            .chain([None])
            .collect();
        for kind in kinds {
            let label = kind.map_or("**all**", LampType::label);
            let select = |part: usize| -> Vec<usize> {
                (0..lamps[part].len())
                    .filter(|&j| kind.is_none_or(|t| library.types[lamps[part][j]] == t))
                    .collect()
            };
            let (sv, st) = (select(0), select(1));
            let mean = |part: usize, col: usize, rows: &[usize]| -> String {
                if rows.is_empty() {
                    return "–".into();
                }
                let v = rows.iter().map(|&j| cells[part][col][j]).sum::<f64>() / rows.len() as f64;
                format!("{v:.4}")
            };
            md += &format!(
                "| {label} | {} / {} | {} | {} | {} | {} | {} | {} |\n",
                sv.len(),
                st.len(),
                mean(0, 0, &sv),
                mean(0, 1, &sv),
                mean(0, 2, &sv),
                mean(1, 0, &st),
                mean(1, 1, &st),
                mean(1, 2, &st)
            );
        }
        md.push('\n');
        if !args.no_real && KnownChart::from_name(&chart_name) == Some(KnownChart::Sg96) {
            real_rows.push((path.clone(), real_scores(&args, model, data_dir)?));
        }
        eprintln!("{}: done", path.display());
    }
    if !real_rows.is_empty() {
        md += "### (c) the real photo sets (virtual-only models)\n\n| model | Telelumen, Canon 5D IV (dev) | Hue, Canon 5D IV | Telelumen, Galaxy Tab S7 |\n|---|---:|---:|---:|\n";
        for (path, scores) in &real_rows {
            md += &format!(
                "| `{}` | {:.4} | {:.4} | {:.4} |\n",
                file_name(path),
                scores[0],
                scores[1],
                scores[2]
            );
        }
        md.push('\n');
    }
    md += &format!(
        "Mean GFC (400–700 nm) per lamp (over {} photos each), then over the lamps of a type. \
         (a): each photo by a held-out camera of the split ({} cameras) with the randomised \
         in-camera stage (exposure, white balance, tone, JPEG, lighting gradient), patch level, \
         noise-free; (b): by the independent simple camera (grey-world white balance partly \
         applied, D65-fitted colour matrix, auto exposure, a little flare and gradient, sRGB, \
         8 bit) with the same cameras. Average SPD: the mean of the split's fit lamps, the \
         estimate of a model that knows nothing. Seed {}.\n",
        args.photos.shots,
        held_out.len(),
        args.photos.seed
    );
    write_atomic(&args.output, md.as_bytes())?;
    print!("{md}");
    Ok(())
}

/// A model's file name, for the tables (directories differ between machines).
fn file_name(path: &std::path::Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into(),
    )
}

/// The mean of the lamps `ids`, normalised by its maximum.
fn average_spd(spds: &[Vec<f64>], ids: &[usize]) -> Vec<f64> {
    let d = spds[0].len();
    let sum: Vec<f64> = (0..d)
        .map(|k| ids.iter().map(|&i| spds[i][k]).sum::<f64>())
        .collect();
    metrics::normalise_by_max(&sum)
}

/// (a): each lamp `shots` times through a held-out camera with the randomised in-camera stage.
fn pipeline_photos(
    cameras: &[Sensitivities],
    chart: &Chart,
    library: &LampLibrary,
    ids: &[usize],
    shots: u64,
    seed: u64,
) -> Result<Photos> {
    let config = CameraConfig {
        noise: None,
        ..CameraConfig::default()
    };
    let pool = camera_pool(cameras, 0, seed, chart, config, &GRID)?;
    let randomisation = Randomisation::new(
        pool,
        InCameraRanges::for_groups(&["exposure", "wb", "tone", "jpeg", "gradient"])?,
    )?;
    let width = chart.feature_names().len();
    let mut features = Vec::with_capacity(ids.len() * shots as usize * width);
    let (mut raw, mut out) = (Vec::new(), Vec::new());
    for (j, &i) in ids.iter().enumerate() {
        for k in 0..shots {
            let (camera, ic): (&Camera, _) = randomisation.draw(seed, j as u64 * shots + k);
            let light = camera.light(&library.spds[i])?;
            out.clear();
            camera.features_fast_with(ic.as_ref(), &light, &mut raw, &mut out);
            features.extend(out.iter().map(|&v| f64::from(v)));
        }
    }
    Ok(Photos { features, width })
}

/// (b): each lamp `shots` times through the simple camera, camera and shot drawn at random.
fn simple_photos(
    cameras: &[Sensitivities],
    chart: &Chart,
    library: &LampLibrary,
    ids: &[usize],
    shots: u64,
    seed: u64,
) -> Result<Photos> {
    let simple = cameras
        .iter()
        .map(|s| Ok(SimpleCamera::new(s, chart, &GRID)?))
        .collect::<Result<Vec<_>>>()?;
    let width = chart.feature_names().len();
    let mut features = Vec::with_capacity(ids.len() * shots as usize * width);
    for (j, &i) in ids.iter().enumerate() {
        for k in 0..shots {
            let mut rng = SmallRng::seed_from_u64(seed::derive(
                seed::derive(seed, j as u64 * shots + k),
                SIMPLE_STREAM,
            ));
            let camera = &simple[rng.random_range(0..simple.len())];
            let shot = Shot::draw(&mut rng);
            features.extend(camera.photograph(&library.spds[i], &shot)?);
        }
    }
    Ok(Photos { features, width })
}

/// Mean GFC per lamp of `model` on `photos` (rows `shots` per lamp of `ids`).
fn score(
    model: &Model,
    photos: &Photos,
    truth: &[Vec<f64>],
    ids: &[usize],
    shots: u64,
) -> Result<LampScores> {
    let estimates = model.estimate_rows(&photos.features)?;
    let d = model.grid().count;
    debug_assert_eq!(
        photos.features.len() / photos.width,
        ids.len() * shots as usize
    );
    Ok(ids
        .iter()
        .enumerate()
        .map(|(j, &i)| {
            (0..shots as usize)
                .map(|k| {
                    let row = j * shots as usize + k;
                    metrics::gfc(&truth[i], &estimates[row * d..(row + 1) * d]).unwrap_or(0.0)
                })
                .sum::<f64>()
                / shots as f64
        })
        .collect())
}

/// (c): mean GFC of `model` on each real photo set (dev; Hue train + val; tablet train + val).
fn real_scores(args: &ValidateArgs, model: &Model, data_dir: &DataDir) -> Result<[f64; 3]> {
    let thesis = match &args.thesis_data {
        Some(p) => p.clone(),
        None => in_data_dir(None, "thesis", data_dir)?,
    };
    let sets = REAL_PHOTO_SETS
        .iter()
        .map(|set| set.load(&thesis, &GRID))
        .collect::<spdcam_core::Result<Vec<_>>>()?;
    let grid = model.grid();
    let mut out = [0.0; 3];
    for (k, set) in sets.iter().enumerate() {
        let rows: Vec<f64> = set.features.iter().flatten().copied().collect();
        let estimates = model.estimate_rows(&rows)?;
        let names = (0..set.spds.len()).map(|i| format!("s{i}")).collect();
        let truth = SpectralSet::from_spds(names, &set.spds)?
            .resample(&grid, Interpolation::Linear, Extrapolation::Zero)?
            .0;
        let d = grid.count;
        out[k] = (0..set.spds.len())
            .map(|i| {
                metrics::gfc(
                    &metrics::normalise_by_max(truth.item(i)),
                    &estimates[i * d..(i + 1) * d],
                )
                .unwrap_or(0.0)
            })
            .sum::<f64>()
            / set.spds.len() as f64;
    }
    Ok(out)
}
