//! `spdcam trust`: the uncertainty calibration of a model (`calibrate`: held-out virtual
//! photos of the split's validation lamps → `<chart>.trust.json`) and its measurement
//! (`report`: the split's test lamps, the real photo sets, photos made bad on purpose →
//! docs/trust.md).

use crate::lamps::in_data_dir;
use crate::plot_file;
use crate::reliability::{self, SetReliability};
use crate::validate_lamps::{held_out_cameras, on_grid, HeldOutPhotos};
use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand};
use rand::rngs::SmallRng;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use spdcam_core::builtin::DataDir;
use spdcam_core::camera::optics::Glow;
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::CameraConfig;
use spdcam_core::chart::{Chart, KnownChart};
use spdcam_core::colorimetry::{srgb_decode, srgb_encode};
use spdcam_core::dataset::randomise::{camera_pool, InCameraRanges, Randomisation};
use spdcam_core::dataset::MeasuredPhotos;
use spdcam_core::fsio::write_atomic;
use spdcam_core::lighting::validation_split::LampPart;
use spdcam_core::lighting::{LampLibrary, ValidationSplit};
use spdcam_core::photo::scene::{self, SceneLight, SceneOptions};
use spdcam_core::photo::ChartTemplate;
use spdcam_core::quality::{LightingMetrics, SCALAR_KEYS};
use spdcam_core::spectral::{Grid, SpectralSet};
use spdcam_core::uneven_light::{Corrections, UnevenLight};
use spdcam_core::{metrics, seed};
use spdcam_infer::estimate::{estimate_photo_bytes, PhotoOptions};
use spdcam_infer::pca::{Components, Pca};
use spdcam_infer::trust::{
    self, assess, Calibration, ChartCheck, GfcModel, MetricCalibration, Perturbed, PhotoFlags,
    SelfCheck, Verdict, JITTER_COPIES, JITTER_SIGMA,
};
use spdcam_infer::{Model, ModelSet};
use spdcam_learn::real_cameras::split_sets_on;
use spdcam_learn::ridge::{Gram, Ridge};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// Options of `spdcam trust`.
#[derive(Debug, Args)]
pub struct TrustArgs {
    #[command(subcommand)]
    command: TrustCommand,
}

#[derive(Debug, Subcommand)]
enum TrustCommand {
    /// Calibrate the bands and expected GFC of models on the split's validation lamps.
    Calibrate(Box<CalibrateArgs>),
    /// Measure the calibrated models on the test lamps, the real photo sets and bad photos.
    Report(Box<ReportArgs>),
}

/// Options of `spdcam trust calibrate`.
#[derive(Debug, Args)]
struct CalibrateArgs {
    #[command(flatten)]
    photos: HeldOutPhotos,
    /// For an SG model, also calibrate on the real photo sets' validation photos (the split
    /// of `spdcam experiment real-cameras`; each set at most a third as many photos as the
    /// virtual ones, evenly spaced): they join the bands, the expected GFC, the metric
    /// intervals and the clipping and difficulty levels; the self-check's levels stay those
    /// of the virtual photos.
    #[arg(long)]
    real: bool,
    /// The thesis's data (holding measured/…); default: the data directory's thesis/.
    #[arg(long)]
    thesis_data: Option<PathBuf>,
    /// Directory to write `<chart>.trust.json` into.
    #[arg(short, long)]
    output: PathBuf,
}

/// Options of `spdcam trust report`.
#[derive(Debug, Args)]
struct ReportArgs {
    #[command(flatten)]
    photos: HeldOutPhotos,
    /// The calibrations, in the order of the models.
    #[arg(long, required = true)]
    calibration: Vec<PathBuf>,
    /// The thesis's data (holding measured/…); default: the data directory's thesis/.
    #[arg(long)]
    thesis_data: Option<PathBuf>,
    /// Output Markdown (printed too).
    #[arg(short, long)]
    output: PathBuf,
    /// Also draw the reliability diagram (.svg or .png) and show it in the Markdown.
    #[arg(long)]
    reliability: Option<PathBuf>,
}

const GRID: Grid = Grid::SIMULATION;
/// Fewer calibration photos defining a metric than this leave it without an interval.
const MIN_METRIC_PHOTOS: usize = 40;
/// Share of the chart's mean linear level the glare adds at its brightest corner.
const GLARE_LEVEL: f64 = 0.4;
/// Width (standard deviation, chart widths) of the glare's fall-off from that corner.
const GLARE_WIDTH: f64 = 0.35;

/// Runs `spdcam trust`.
pub fn run(args: TrustArgs, data_dir: &DataDir) -> Result<()> {
    match args.command {
        TrustCommand::Calibrate(a) => calibrate(*a, data_dir),
        TrustCommand::Report(a) => report(*a, data_dir),
    }
}

/// Feature rows with their true SPDs (peak 1, on the model's grid).
#[derive(Clone)]
struct Rows {
    features: Vec<Vec<f64>>,
    truths: Vec<Vec<f64>>,
}

/// Held-out virtual photos of the lamps `part` of the split: clean, and the same shots made
/// bad three ways (patches in another order, the right half lit by another lamp, glare).
struct Shots {
    clean: Rows,
    wrong_chart: Vec<Vec<f64>>,
    half_lit: Vec<Vec<f64>>,
    glare: Vec<Vec<f64>>,
}

/// Everything a model needs for both subcommands.
struct Setup {
    library: LampLibrary,
    split: ValidationSplit,
    cameras: Vec<Sensitivities>,
}

impl HeldOutPhotos {
    fn setup(&self, data_dir: &DataDir) -> Result<Setup> {
        if self.shots == 0 {
            bail!("--shots must be at least 1");
        }
        let split = ValidationSplit::read(&self.split)?;
        Ok(Setup {
            library: self.library.read(data_dir, &GRID)?,
            cameras: held_out_cameras(&split, self.cameras.as_deref(), data_dir)?,
            split,
        })
    }

    fn models(&self) -> Result<Vec<(PathBuf, Model, String)>> {
        self.model
            .iter()
            .map(|p| {
                let m = Model::load(p)?;
                let chart = m
                    .header()
                    .chart
                    .clone()
                    .with_context(|| format!("{}: the model names no chart", p.display()))?;
                Ok((p.clone(), m, chart))
            })
            .collect()
    }

    /// The lamps of `part`, `shots` photos each through the held-out cameras with the
    /// randomised in-camera stage (exposure, white balance, tone, JPEG, gradient).
    fn shots(&self, setup: &Setup, chart: &Chart, model: &Model, part: LampPart) -> Result<Shots> {
        let ids = setup
            .library
            .positions(setup.split.lamps(part), "the split's lamps")?;
        if ids.len() < 2 {
            bail!("the split names fewer than two lamps for this part");
        }
        let stream = seed::derive(self.seed, part as u64);
        let config = CameraConfig {
            noise: None,
            ..CameraConfig::default()
        };
        let pool = camera_pool(&setup.cameras, 0, stream, chart, config, &GRID)?;
        let randomisation = Randomisation::new(
            pool,
            InCameraRanges::for_groups(&["exposure", "wb", "tone", "jpeg", "gradient"])?,
        )?;
        let truth = on_grid(&setup.library, &model.grid())?;
        let cols = chart.layout.cols;
        let right: Vec<bool> = (0..chart.reflectances.len())
            .map(|p| 2 * (p % cols) >= cols)
            .collect();
        let glare_gain = glare(chart);
        let mut rng = SmallRng::seed_from_u64(seed::derive(stream, 0x5752_4f4e_4700_0001));
        let mut out = Shots {
            clean: Rows {
                features: Vec::new(),
                truths: Vec::new(),
            },
            wrong_chart: Vec::new(),
            half_lit: Vec::new(),
            glare: Vec::new(),
        };
        let (mut raw, mut a, mut b) = (Vec::new(), Vec::new(), Vec::new());
        for (j, &i) in ids.iter().enumerate() {
            let other = ids[(j + 1) % ids.len()];
            for k in 0..self.shots {
                let (camera, ic) = randomisation.draw(stream, j as u64 * self.shots + k);
                a.clear();
                b.clear();
                let light = camera.light(&setup.library.spds[i])?;
                camera.features_fast_with(ic.as_ref(), &light, &mut raw, &mut a);
                camera.features_fast_two_lights(
                    ic.as_ref(),
                    &light,
                    &camera.light(&setup.library.spds[other])?,
                    &right,
                    &mut raw,
                    &mut b,
                );
                let clean: Vec<f64> = a.iter().map(|&v| f64::from(v)).collect();
                let half: Vec<f64> = b.iter().map(|&v| f64::from(v)).collect();
                let mut order: Vec<usize> = (0..chart.feature_patches.len()).collect();
                order.shuffle(&mut rng);
                let wrong: Vec<f64> = order
                    .iter()
                    .flat_map(|&p| clean[3 * p..3 * p + 3].to_vec())
                    .collect();
                let mean_linear =
                    clean.iter().map(|&v| srgb_decode(v / 255.0)).sum::<f64>() / clean.len() as f64;
                let glared: Vec<f64> = clean
                    .iter()
                    .enumerate()
                    .map(|(f, &v)| {
                        let lin =
                            srgb_decode(v / 255.0) + GLARE_LEVEL * mean_linear * glare_gain[f / 3];
                        255.0 * srgb_encode(lin.min(1.0))
                    })
                    .collect();
                out.clean.features.push(clean);
                out.clean.truths.push(truth[i].clone());
                out.wrong_chart.push(wrong);
                out.half_lit.push(half);
                out.glare.push(glared);
            }
        }
        Ok(out)
    }
}

/// Per feature patch of `chart`: the relative glare, 1 at the top-left corner falling off
/// as a Gaussian of [`GLARE_WIDTH`] chart widths (a lamp beside the chart, out of frame).
fn glare(chart: &Chart) -> Vec<f64> {
    let (rows, cols) = (chart.layout.rows as f64, chart.layout.cols as f64);
    chart
        .feature_patches
        .iter()
        .map(|&p| {
            let x = ((p % chart.layout.cols) as f64 + 0.5) / cols;
            let y = ((p / chart.layout.cols) as f64 + 0.5) / rows * rows / cols;
            (-(x * x + y * y) / (2.0 * GLARE_WIDTH * GLARE_WIDTH)).exp()
        })
        .collect()
}

/// One feature row judged: the estimate, its spread, its GFC, its self-check, and per
/// single-number metric its spread and (with a truth) its absolute error.
struct Judged {
    spd: Vec<f64>,
    truth: Option<Vec<f64>>,
    spread: Vec<f64>,
    /// The self-check.
    self_check: Option<SelfCheck>,
    metric_spread: BTreeMap<String, f64>,
    metric_error: BTreeMap<String, f64>,
}

fn judge_rows(
    model: &Model,
    check: Option<&ChartCheck>,
    features: &[Vec<f64>],
    truths: Option<&[Vec<f64>]>,
) -> Result<Vec<Judged>> {
    let d = model.grid().count;
    let flat: Vec<f64> = features.iter().flatten().copied().collect();
    let spds = model.estimate_rows(&flat)?;
    features
        .iter()
        .enumerate()
        .map(|(r, row)| {
            let spd = metrics::normalise_by_max(&spds[r * d..(r + 1) * d]);
            let scale = trust::feature_scale(row);
            let self_check = match check {
                Some(c) => c
                    .check(&spd, row, scale, &trust::flag_patches(row, scale))
                    .ok(),
                None => None,
            };
            let perturbed = Perturbed::of(model, row)?;
            let wavelengths = model.grid().wavelengths();
            let truth = truths.map(|t| t[r].clone());
            let metric_error = match &truth {
                Some(t) => {
                    let (e, t) = (
                        LightingMetrics::from_samples(&wavelengths, &spd),
                        LightingMetrics::from_samples(&wavelengths, t),
                    );
                    SCALAR_KEYS
                        .iter()
                        .filter_map(|&k| Some((k.to_string(), (e.scalar(k)? - t.scalar(k)?).abs())))
                        .collect()
                }
                None => BTreeMap::new(),
            };
            Ok(Judged {
                spread: perturbed.spread(),
                // The metrics' spread serves the intervals, measured only against a truth.
                metric_spread: if truth.is_some() {
                    perturbed.metric_spread(&wavelengths)
                } else {
                    BTreeMap::new()
                },
                metric_error,
                truth,
                spd,
                self_check,
            })
        })
        .collect()
}

/// The `q` quantile of `values` with the split-conformal finite-sample correction: the
/// ⌈(n+1)q⌉-th smallest (Lei et al. 2018, JASA 113: 1094–1111, section 2.2).
fn conformal_quantile(values: &mut [f64], q: f64) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    let k = (((n + 1) as f64 * q).ceil() as usize).clamp(1, n);
    values[k - 1]
}

/// The median of `values`.
fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}

fn gfc(judged: &Judged) -> f64 {
    judged
        .truth
        .as_deref()
        .and_then(|t| metrics::gfc(t, &judged.spd).ok())
        .unwrap_or(0.0)
}

fn difficulty(judged: &Judged) -> f64 {
    judged.spread.iter().sum::<f64>() / judged.spread.len() as f64
}

/// The self-check residual of a judged photo ([`SelfCheck::mean`]).
fn residual(judged: &Judged) -> Option<f64> {
    judged.self_check.as_ref().map(|s| s.mean)
}

/// The calibration of `model` from judged photos with known truths, `shots` consecutive
/// photos per lamp.
/// The photos a calibration is fitted on: held-out virtual photos (`shots` consecutive ones
/// per lamp) and, with `--real`, real photos of the real sets' validation split.
struct CalibrationPhotos {
    /// Every photo's features, the virtual ones first.
    features: Vec<Vec<f64>>,
    /// Every photo judged, in the same order.
    judged: Vec<Judged>,
    /// How many of them are virtual.
    virtual_count: usize,
    /// Virtual photos per lamp.
    shots: usize,
}

impl CalibrationPhotos {
    /// The virtual photos judged.
    fn virtual_judged(&self) -> &[Judged] {
        &self.judged[..self.virtual_count]
    }

    /// The cross-validation group of each photo: a lamp's photos together (so a lamp never
    /// informs its own prediction), each real photo alone.
    fn groups(&self) -> Vec<usize> {
        let shots = self.shots.max(1);
        let lamps = self.virtual_count.div_ceil(shots);
        (0..self.judged.len())
            .map(|i| {
                if i < self.virtual_count {
                    i / shots
                } else {
                    lamps + i - self.virtual_count
                }
            })
            .collect()
    }
}

/// Fits `model`'s calibration: the self-check's levels on the virtual photos alone (clean
/// by construction, so that they tell bad photos), everything else on all of `photos`.
fn fit_calibration(
    model: &Model,
    chart: &str,
    photos: &CalibrationPhotos,
    method: String,
) -> Result<Calibration> {
    let (judged, features) = (&photos.judged, &photos.features);
    let d = model.grid().count;
    let err = |j: &Judged, k: usize| (j.spd[k] - j.truth.as_ref().map_or(0.0, |t| t[k])).abs();
    let virtual_judged = photos.virtual_judged();
    let checks_of = |value: fn(&SelfCheck) -> Option<f64>| -> Vec<f64> {
        virtual_judged
            .iter()
            .filter_map(|j| j.self_check.as_ref().and_then(value))
            .collect()
    };
    let mut checks = checks_of(|s| Some(s.mean));
    let all_checked = checks.len() == virtual_judged.len();
    let residual_reference = all_checked.then(|| median(&mut checks.clone()));
    let widenings: Vec<f64> = judged
        .iter()
        .map(|j| trust::widening(residual(j), residual_reference))
        .collect();
    let floor: Vec<f64> = (0..d)
        .map(|k| {
            median(
                &mut judged
                    .iter()
                    .zip(&widenings)
                    .map(|(j, w)| err(j, k) / w)
                    .collect::<Vec<_>>(),
            )
            .max(1e-4)
        })
        .collect();
    let z: Vec<Vec<f64>> = judged
        .iter()
        .zip(&widenings)
        .map(|(j, &w)| band_z(&floor, w, j))
        .collect();
    let [scale68, scale95]: [Vec<f64>; 2] = quantile_scales(&z, &[0.68, 0.95])
        .try_into()
        .map_err(|_| anyhow::anyhow!("two band scales"))?;
    let mut difficulties: Vec<f64> = judged.iter().map(difficulty).collect();
    let mut splits = checks_of(|s| Some(s.split));
    let mut gradients = checks_of(|s| s.colour_gradient);
    let mut glares = checks_of(|s| Some(s.glare));
    let metric_calibrations = SCALAR_KEYS
        .iter()
        .filter_map(|&key| {
            let pairs: Vec<(f64, f64)> = judged
                .iter()
                .zip(&widenings)
                .filter_map(|(j, w)| {
                    Some((*j.metric_error.get(key)? / w, *j.metric_spread.get(key)?))
                })
                .collect();
            if pairs.len() < MIN_METRIC_PHOTOS {
                return None;
            }
            let floor =
                median(&mut pairs.iter().map(|p| p.0).collect::<Vec<_>>()).max(f64::EPSILON);
            let scale = |q: f64| {
                conformal_quantile(
                    &mut pairs
                        .iter()
                        .map(|(e, s)| e / (floor + s))
                        .collect::<Vec<_>>(),
                    q,
                )
            };
            Some(MetricCalibration {
                key: key.to_string(),
                floor,
                scale68: scale(0.68),
                scale95: scale(0.95),
                photos: pairs.len(),
            })
        })
        .collect();
    let mut clipped: Vec<f64> = features
        .iter()
        .map(|row| trust::clipped_patches(row) as f64)
        .collect();
    Ok(Calibration {
        model: model.fingerprint(),
        chart: chart.to_string(),
        method,
        wavelength_nm: model.grid().wavelengths(),
        floor,
        scale68,
        scale95,
        gfc_model: fit_gfc_model(judged, &photos.groups())?,
        residual_reference,
        difficulty_doubtful: conformal_quantile(&mut difficulties, 0.99),
        self_check_doubtful: all_checked.then(|| conformal_quantile(&mut checks, 0.99)),
        split_doubtful: (splits.len() == virtual_judged.len())
            .then(|| conformal_quantile(&mut splits, 0.99)),
        // Measured where most photos had enough unclipped neutral patches.
        colour_gradient_doubtful: (10 * gradients.len() >= 9 * virtual_judged.len())
            .then(|| conformal_quantile(&mut gradients, 0.99)),
        glare_doubtful: (glares.len() == virtual_judged.len())
            .then(|| conformal_quantile(&mut glares, 0.99)),
        clipped_doubtful: conformal_quantile(&mut clipped, 0.99) as usize,
        metrics: metric_calibrations,
        real_photos: photos.judged.len() - photos.virtual_count,
    })
}

/// Numbers of principal components the expected-GFC regression chooses among.
const GFC_COMPONENTS: [usize; 7] = [0, 1, 2, 3, 5, 8, 12];
/// Penalties (× each input's centred sum of squares) it chooses among.
const GFC_PENALTIES: [f64; 7] = [1e-4, 1e-3, 1e-2, 1e-1, 1.0, 10.0, 100.0];
/// Folds of its cross-validation, whole lamps at a time.
const GFC_FOLDS: usize = 5;
/// The smallest 1 − GFC the regression's logarithm sees (GFC is printed to 4 decimals).
const GFC_GAP_FLOOR: f64 = 1e-5;

/// The expected-GFC regression ([`GfcModel`]) of the judged calibration photos: the number
/// of principal components and the penalty with the least squared error of ln(1 − GFC) in
/// cross-validation over whole groups (`groups[i]` is photo i's: a lamp's photos share one,
/// so a lamp never informs its own prediction; ties go to fewer components and the stronger
/// penalty), then refitted on every photo. The constant is not penalised.
fn fit_gfc_model(judged: &[Judged], groups: &[usize]) -> Result<GfcModel> {
    let n = judged.len();
    if groups.len() != n {
        bail!("{} photos but {} cross-validation groups", n, groups.len());
    }
    let d = judged.first().context("no calibration photos")?.spd.len();
    let most = *GFC_COMPONENTS.iter().max().unwrap_or(&0);
    let estimates: Vec<f64> = judged.iter().flat_map(|j| j.spd.iter().copied()).collect();
    let pca = Pca::fit(&estimates, d, Components::Count(most.min(d).min(n - 1)))?;
    let target: Vec<Vec<f64>> = judged
        .iter()
        .map(|j| vec![(1.0 - gfc(j)).max(GFC_GAP_FLOOR).ln()])
        .collect();
    let with = |k: usize| GfcModel {
        mean: pca.mean.clone(),
        components: pca.components[..k.min(pca.len())].to_vec(),
        weights: Vec::new(),
        low: Vec::new(),
        high: Vec::new(),
        gap_range: [0.0; 2],
    };
    let inputs = |m: &GfcModel| -> Vec<Vec<f64>> {
        judged
            .iter()
            .map(|j| m.inputs(&j.spd, difficulty(j)))
            .collect()
    };
    // Per input, the penalty's unit: its centred sum of squares, at least a millionth per
    // row so that an input without variance is shrunk to nothing (0 for the constant).
    let unit = |x: &[Vec<f64>], rows: &[usize]| -> Vec<f64> {
        let p = x[0].len();
        (0..p)
            .map(|c| {
                if c == p - 1 {
                    return 0.0;
                }
                let mean = rows.iter().map(|&i| x[i][c]).sum::<f64>() / rows.len() as f64;
                rows.iter()
                    .map(|&i| (x[i][c] - mean).powi(2))
                    .sum::<f64>()
                    .max(1e-6 * rows.len() as f64)
            })
            .collect()
    };
    // The Gram matrices of `rows` and their penalty units, solved for any penalty.
    let gram = |x: &[Vec<f64>], rows: &[usize]| -> Result<(Gram, Vec<f64>)> {
        let xs: Vec<&[f64]> = rows.iter().map(|&i| x[i].as_slice()).collect();
        let ys: Vec<&[f64]> = rows.iter().map(|&i| target[i].as_slice()).collect();
        Ok((Gram::from_rows(&xs, &ys)?, unit(x, rows)))
    };
    let solve = |(gram, unit): &(Gram, Vec<f64>), penalty: f64| -> Result<Ridge> {
        let diagonal: Vec<f64> = unit.iter().map(|u| penalty * u).collect();
        Ok(gram.solve(&diagonal, None)?)
    };
    let folds: Vec<(Vec<usize>, Vec<usize>)> = (0..GFC_FOLDS)
        .map(|f| (0..n).partition(|&i| groups[i] % GFC_FOLDS == f))
        .filter(|(test, train): &(Vec<usize>, Vec<usize>)| !test.is_empty() && !train.is_empty())
        .collect();
    let mut best: Option<(f64, usize, f64)> = None;
    for &k in GFC_COMPONENTS.iter().filter(|&&k| k <= pca.len()) {
        let x = inputs(&with(k));
        let mut sse = [0.0; GFC_PENALTIES.len()];
        for (test, train) in &folds {
            let fitted = gram(&x, train)?;
            for (total, &penalty) in sse.iter_mut().zip(&GFC_PENALTIES) {
                let ridge = solve(&fitted, penalty)?;
                *total += test
                    .iter()
                    .map(|&i| (ridge.predict(&x[i])[0] - target[i][0]).powi(2))
                    .sum::<f64>();
            }
        }
        // The strongest penalty first, so that a tie keeps it.
        for (&total, &penalty) in sse.iter().zip(&GFC_PENALTIES).rev() {
            if best.is_none_or(|b| total < b.0) {
                best = Some((total, k, penalty));
            }
        }
    }
    let (_, k, penalty) = best.context("no expected-GFC regression could be fitted")?;
    let mut model = with(k);
    let x = inputs(&model);
    let ridge = solve(&gram(&x, &(0..n).collect::<Vec<_>>())?, penalty)?;
    model.weights = (0..ridge.inputs()).map(|j| ridge.weight(0, j)).collect();
    let range = |values: &mut dyn Iterator<Item = f64>| {
        values.fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], v| {
            [lo.min(v), hi.max(v)]
        })
    };
    let input_ranges: Vec<[f64; 2]> = (0..model.weights.len())
        .map(|c| range(&mut x.iter().map(|row| row[c])))
        .collect();
    model.low = input_ranges.iter().map(|r| r[0]).collect();
    model.high = input_ranges.iter().map(|r| r[1]).collect();
    model.gap_range = range(&mut target.iter().map(|t| t[0]));
    Ok(model)
}

fn calibrate(args: CalibrateArgs, data_dir: &DataDir) -> Result<()> {
    let setup = args.photos.setup(data_dir)?;
    std::fs::create_dir_all(&args.output)
        .with_context(|| format!("creating {}", args.output.display()))?;
    for (path, model, chart_name) in args.photos.models()? {
        let chart = Chart::resolve(&chart_name, None, data_dir, &GRID)?;
        model.check_features(&chart.feature_names(), &chart_name)?;
        let check = ChartCheck::for_model(&model, data_dir)?;
        let shots = args
            .photos
            .shots(&setup, &chart, &model, LampPart::Validation)?;
        let mut judged = judge_rows(
            &model,
            check.as_ref(),
            &shots.clean.features,
            Some(&shots.clean.truths),
        )?;
        let virtual_count = judged.len();
        let real = if args.real {
            real_split(&args.thesis_data, data_dir, &model, &chart_name)?
        } else {
            Vec::new()
        };
        let real = balanced(real, virtual_count);
        let mut features = shots.clean.features;
        for set in &real {
            judged.extend(judge_rows(
                &model,
                check.as_ref(),
                &set.val.features,
                Some(&set.val.truths),
            )?);
            features.extend(set.val.features.iter().cloned());
        }
        let mut method = format!(
            "the split's {} validation lamps, {} photos each by its held-out cameras with the \
             randomised in-camera stage, patch level, seed {}; spread of {JITTER_COPIES} copies \
             perturbed by {JITTER_SIGMA}",
            setup.split.lamps(LampPart::Validation).len(),
            args.photos.shots,
            args.photos.seed
        );
        if !real.is_empty() {
            method += &format!(
                "; and {} real photos, the validation photos of {}",
                judged.len() - virtual_count,
                real.iter().map(|s| s.label).collect::<Vec<_>>().join(", ")
            );
        }
        let photos = CalibrationPhotos {
            features,
            judged,
            virtual_count,
            shots: args.photos.shots as usize,
        };
        let cal = fit_calibration(&model, &chart_name, &photos, method)?;
        let out = args.output.join(format!("{chart_name}.trust.json"));
        write_atomic(
            &out,
            format!("{}\n", serde_json::to_string_pretty(&cal)?).as_bytes(),
        )?;
        eprintln!(
            "{}: calibration → {} (expected GFC from ln(difficulty) and {} principal components; {} real photos)",
            path.display(),
            out.display(),
            cal.gfc_model.components.len(),
            cal.real_photos
        );
    }
    Ok(())
}

/// `sets` with each one's validation photos cut to at most `virtual_photos` / (number of
/// sets), evenly spaced, so that each real set weighs at most as much as a third of the
/// virtual calibration photos and the real sets together no more than those: the calibration
/// serves room lamps and the real sets' lights alike, and no large set (Hue's 711 photos)
/// sets it alone.
fn balanced(mut sets: Vec<RealSplit>, virtual_photos: usize) -> Vec<RealSplit> {
    let cap = virtual_photos / sets.len().max(1);
    for set in &mut sets {
        let n = set.val.features.len();
        if n > cap {
            let keep: Vec<usize> = (0..cap).map(|k| k * n / cap).collect();
            let pick = |rows: &[Vec<f64>]| keep.iter().map(|&i| rows[i].clone()).collect();
            set.val = Rows {
                features: pick(&set.val.features),
                truths: pick(&set.val.truths),
            };
        }
    }
    sets
}

/// One real photo set split as the real-camera study splits it, on a model's grid, the SPDs
/// peak-normalised.
#[derive(Clone)]
struct RealSplit {
    label: &'static str,
    val: Rows,
    test: Rows,
}

/// The real photo sets (SG photos) split as the real-camera study splits them
/// (`spdcam_learn::real_cameras::split_sets_on`), on `model`'s grid; none for another chart.
fn real_split(
    thesis_data: &Option<PathBuf>,
    data_dir: &DataDir,
    model: &Model,
    chart_name: &str,
) -> Result<Vec<RealSplit>> {
    if KnownChart::from_name(chart_name) != Some(KnownChart::Sg96) {
        return Ok(Vec::new());
    }
    let thesis = match thesis_data {
        Some(p) => p.clone(),
        None => in_data_dir(None, "thesis", data_dir)?,
    };
    let rows = |photos: MeasuredPhotos| Rows {
        truths: photos
            .spds
            .iter()
            .map(|s| metrics::normalise_by_max(s.values()))
            .collect(),
        features: photos.features,
    };
    Ok(split_sets_on(&thesis, &model.grid())?
        .into_iter()
        .map(|set| RealSplit {
            label: set.label,
            val: rows(set.val),
            test: rows(set.test),
        })
        .collect())
}

/// Scene photos per kind in [`scene_verdicts`].
const SCENES: usize = 20;

/// The chart as photos show it for `model_chart` (the SG's 96 patches are read from the
/// whole 140-patch chart).
fn photo_chart(model_chart: &str) -> &str {
    match KnownChart::from_name(model_chart).and_then(KnownChart::physical) {
        Some(physical) => physical.name(),
        None => model_chart,
    }
}

/// Scene photos (the code of `spdcam render --scene`: the chart placed in a cluttered scene
/// with perspective, blur, vignetting, noise and JPEG) of [`SCENES`] test lamps, each by a
/// held-out camera, found, sampled and estimated like a user's photo: clean, of another
/// chart (the non-grey patches in another order), the right half of the chart lit by
/// another lamp, and with glare. Per kind: the share not `ok` (or refused: no chart found),
/// and the share the self-check flags.
fn scene_verdicts(
    model: &Model,
    cal: &Calibration,
    model_chart: &str,
    setup: &Setup,
    data_dir: &DataDir,
    seed: u64,
) -> Result<[(f64, f64); 4]> {
    let name = photo_chart(model_chart);
    let chart = Chart::resolve(name, None, data_dir, &GRID)?;
    let template = ChartTemplate::from_chart(&chart)?;
    let chart = chart.with_layout(scene::scene_layout(&template))?;
    let mut wrong = chart.clone();
    let movable: Vec<usize> = chart
        .feature_patches
        .iter()
        .copied()
        .filter(|p| template.neutrals.iter().all(|n| n.0 != *p))
        .collect();
    let mut order = movable.clone();
    order.shuffle(&mut SmallRng::seed_from_u64(seed));
    let mut items: Vec<Vec<f64>> = chart.reflectances.items().to_vec();
    for (&to, &from) in movable.iter().zip(&order) {
        items[to] = chart.reflectances.item(from).to_vec();
    }
    wrong.reflectances = SpectralSet::on_grid(&GRID, chart.reflectances.names().to_vec(), items)?;
    let config = CameraConfig::default();
    let pool = camera_pool(&setup.cameras, 0, seed, &chart, config, &GRID)?;
    let wrong_pool = camera_pool(&setup.cameras, 0, seed, &wrong, config, &GRID)?;
    let ids = setup
        .library
        .positions(setup.split.lamps(LampPart::Test), "the split's test lamps")?;
    let models = ModelSet::single(model.clone(), "model");
    let options = PhotoOptions {
        chart: Some(name.to_string()),
        ..PhotoOptions::default()
    };
    let plain = SceneOptions {
        width: 1200,
        height: 900,
        ..SceneOptions::default()
    };
    let glare = SceneOptions {
        glow: Some(Glow {
            level: GLARE_LEVEL,
            width: GLARE_WIDTH,
        }),
        ..plain.clone()
    };
    let mut counts = [(0usize, 0usize); 4];
    for i in 0..SCENES {
        let lamp = ids[i * ids.len() / SCENES];
        let other = ids[(i * ids.len() / SCENES + ids.len() / 2) % ids.len()];
        let k = i % pool.len();
        let shot_seed = seed::derive(seed, i as u64);
        let (spd, other_spd) = (&setup.library.spds[lamp], &setup.library.spds[other]);
        let half = SceneLight {
            spd,
            right_half: Some(other_spd),
        };
        let shots = [
            (&pool[k], SceneLight::single(spd), &plain),
            (&wrong_pool[k], SceneLight::single(spd), &plain),
            (&pool[k], half, &plain),
            (&pool[k], SceneLight::single(spd), &glare),
        ];
        for (kind, (camera, light, scene_options)) in shots.into_iter().enumerate() {
            let shot = scene::photograph(camera, light, shot_seed, scene_options)?;
            match estimate_photo_bytes(
                &shot.jpeg,
                "scene.jpg",
                &models,
                &options,
                data_dir,
                &model.grid(),
            ) {
                Ok(e) => {
                    let t = e.trust.context("an estimate without a verdict")?;
                    counts[kind].0 += usize::from(t.verdict != Verdict::Ok);
                    let flagged = t.self_check.as_ref().is_some_and(|s| cal.flags(s));
                    counts[kind].1 += usize::from(flagged);
                }
                Err(_) => {
                    counts[kind].0 += 1;
                    counts[kind].1 += 1;
                }
            }
        }
    }
    Ok(counts.map(|(n, f)| (n as f64 / SCENES as f64, f as f64 / SCENES as f64)))
}

/// The options that made the photos, as a command line.
fn photo_args(p: &HeldOutPhotos) -> String {
    let mut out: String = p
        .model
        .iter()
        .map(|m| format!(" --model {}", m.display()))
        .collect();
    out += &format!(" --split {}", p.split.display());
    if let Some(l) = &p.library.lamps {
        out += &format!(" --lamps {}", l.display());
    }
    if let Some(t) = &p.library.types {
        out += &format!(" --types {}", t.display());
    }
    if let Some(c) = &p.cameras {
        out += &format!(" --cameras {}", c.display());
    }
    out += &format!(" --shots {} --seed {}", p.shots, p.seed);
    out
}

/// How the bands, the expected GFC, the self-check and the verdict are made, and the
/// thresholds (fixed before any result was seen, but for the clipping rule; see there).
const METHOD: &str = "## How it works\n\n\
- **Self-check.** The chart's reflectances × the estimated SPD × a reference camera (the \
built-in Nikon D5100) predict each patch's raw RGB; a per-photo map (3×3 matrix, offset for \
flare, linear light gradient across the chart), fitted by least squares after undoing the \
best of 25 tone curves (gamma 0.7–1.3 × S-curve contrast ±0.4), takes them to the photo's \
linear RGB. `mean`/`worst`: the patch residuals relative to the chart's mean RGB length; \
`split`: the residual when each half of the chart (left/right, top/bottom) is predicted by \
the other half's map; `colour_gradient`: how differently the three channels brighten across \
the chart on its neutral patches (a linear gain and a flare per channel fitted there, \
`spdcam_core::uneven_light`; one light falling off brightens all alike, two lights do not); \
`glare`: the share of the residual that an additive light changing linearly across the chart \
(two more columns of the map per channel) removes, a nested-model comparison: glare, a \
reflection or flare from a light beside the chart adds light to one side of it. \
The ColorChecker 24's reflectances are built in; the SG's come from the \
data directory, so without it an SG estimate has no self-check (the reasons say so).\n\
- **Bands.** The model is run on 16 copies of the features, each perturbed by 2 % \
(log-normal); the spread s(λ) of the peak-normalised SPDs plus a floor f(λ) (the median \
absolute error at λ on the calibration photos), times the photo's widening w, is scaled by \
the conformal 68 % and 95 % quantiles of |error(λ)|/((f(λ)+s(λ))·w) on the calibration \
photos. The widening w is the photo's self-check residual over the calibration photos' \
median, at least 1 (1 without a self-check): a photo the estimated light explains k times \
worse than a typical calibration photo is taken to carry k times its errors (`band_widening` \
in `--json`). Chosen on the Telelumen dev photos among no widening and the residual over the \
calibration's 50th, 75th or 90th percentile (95 % band on dev: 80.4 %, 94.5 %, about 92 % \
and 88 %); the Hue and tablet sets were looked at alongside.\n\
- **Metric intervals.** The same rule for each single-number metric (CCT, Duv, Ra, R9, Rf, Rg, \
M-EDER, S/P, PPF per lux, blue-light hazard efficacy): its standard deviation over the 16 \
copies' metrics (Monte Carlo propagation, JCGM 101:2008) plus a floor (its median absolute \
error on the calibration photos), times the widening, scaled by the conformal quantiles of \
|error|/((floor + spread)·w). Estimates print the 95 % half-width: \"Ra 82 ± 4\".\n\
- **Expected GFC.** A ridge regression of ln(1 − GFC) on ln(difficulty) and the estimate's \
coordinates on the first principal components of the calibration photos' estimates \
(`spdcam_infer::trust::GfcModel`; the number of components, 0–12, and the penalty by \
five-fold cross-validation over whole lamps of the calibration photos): the conditional \
median GFC of estimates of this shape. Spiky, narrow-band estimates come from lights that \
broadband patches resolve poorly. It replaced the median GFC of five difficulty bins \
(ρ 0.49 / 0.43 on held-out virtual photos, now 0.76 / 0.76). Scaling its 1 − GFC by the \
widening (w or w², as 1 − GFC ≈ θ²/2 for an error angle θ) made the Telelumen dev photos' \
median expected 1 − GFC 0.29 or 0.63 against an actual 0.15; without it, 0.13: not done.\n- **Verdict** (constants in `spdcam_infer::trust`, levels in the calibration file): `doubtful` \
when the detection confidence is below 0.8, more feature patches are clipped than in 99 % of \
the calibration photos, more than a quarter are nearly black, the self-check's mean or split \
residual, colour gradient or glare exceeds its 99th percentile on the calibration photos, the difficulty exceeds its \
99th percentile (many lights give nearly this photo, or it is unlike the training lights), \
or the expected GFC is below 0.95; `unusable` when more than half the patches are clipped, \
the self-check cannot be made (too few usable patches) or a self-check residual exceeds \
three times its level. An unusable estimate's numbers are not printed.\n\
- **Calibration set**, fixed before any result: the split's 54 validation lamps \
(docs/validation-split.json), 8 photos each by the split's held-out cameras with the \
randomised in-camera stage. The clipping rule was first fixed a priori at a quarter of the \
patches (doubtful at one); on the real photo sets, where saturated colours clip a channel \
under narrow-band light although the model reads them well, that marked most photos \
unusable, so it became the calibration's 99th percentile (doubtful) and half the chart \
(unusable). For the SG model (`--real`), also the real photo sets' validation photos of the \
real-camera study (`docs/real-cameras.md`: Telelumen/Canon's seeded first half, the Hue and \
tablet sets' `train` files), each set cut to at most a third as many photos as the virtual \
ones (144), evenly spaced; they join the bands, the expected GFC, the metric intervals and \
the clipping and difficulty levels, while the self-check's levels stay the virtual photos' \
(clean by construction). On the sets' test photos, against virtual photos alone: ρ(expected \
GFC, GFC) −0.14 → 0.05 (Telelumen/Canon), 0.27 → 0.51 (Hue), 0.45 → 0.68 (tablet, 7 \
photos); Hue photos `ok` 0 → 40 % (their mean GFC 0.971); the 95 % band on held-out virtual \
photos 95.3 % → 91.3 %. Uncut (1,085 real photos, 711 of them Hue's) the virtual band fell \
to 81.3 %.\n";

/// Corrections measured once and left off, with their numbers (the shipped models and
/// calibrations of this report, the same photos).
const CORRECTIONS_TRIED: &str = "\nAlso tried, and left off (measured on the SG network \
shipped before the average): the self-check's own map (3×3 \
matrix, flare, the light's gradient and an additive light changing linearly across the \
chart, fitted to the estimate after undoing the best tone curve) with its spatially varying \
parts taken out of the features, then estimated again. All of them: held-out virtual 0.9279 \
(SG) and 0.9165 (CC24), Telelumen dev 0.8175, Hue 0.8846, tablet 0.7951. The additive part \
alone (the glare): dev 0.8322, Hue 0.8769, tablet 0.8002; only where the self-check flags \
glare: dev 0.8318, Hue 0.9012, tablet 0.8002, held-out virtual 0.9347 (SG) and 0.9294 \
(CC24, at its own level). The gain alone: dev 0.7840, Hue 0.9174. Each helps one real set \
and costs another, so none is switched on.\n";

/// Spearman's rank correlation (Spearman 1904), ties given their mean rank.
fn spearman(a: &[f64], b: &[f64]) -> f64 {
    fn ranks(v: &[f64]) -> Vec<f64> {
        let mut idx: Vec<usize> = (0..v.len()).collect();
        idx.sort_by(|&i, &j| v[i].total_cmp(&v[j]));
        let mut r = vec![0.0; v.len()];
        let mut s = 0;
        while s < idx.len() {
            let mut e = s;
            while e + 1 < idx.len() && v[idx[e + 1]] == v[idx[s]] {
                e += 1;
            }
            for &i in &idx[s..=e] {
                r[i] = (s + e) as f64 / 2.0;
            }
            s = e + 1;
        }
        r
    }
    let (ra, rb) = (ranks(a), ranks(b));
    let n = a.len() as f64;
    let (ma, mb) = (ra.iter().sum::<f64>() / n, rb.iter().sum::<f64>() / n);
    let cov: f64 = ra.iter().zip(&rb).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let va: f64 = ra.iter().map(|x| (x - ma).powi(2)).sum();
    let vb: f64 = rb.iter().map(|y| (y - mb).powi(2)).sum();
    if va == 0.0 || vb == 0.0 {
        return 0.0;
    }
    cov / (va * vb).sqrt()
}

/// Per metric, on one photo set: estimates whose true value lay within the 68 % and 95 %
/// intervals, estimates with an interval, and the 95 % half-widths.
#[derive(Default)]
struct MetricCoverage {
    in68: usize,
    in95: usize,
    total: usize,
    half95: Vec<f64>,
}

/// A photo's band error in units of its calibrated scale: per wavelength
/// |error(λ)| / ((f(λ) + s(λ))·w), the quantity the calibration's conformal quantiles are
/// taken of ([`Calibration`]); `floor` is the calibration's f(λ) and `widening` the photo's w.
fn band_z(floor: &[f64], widening: f64, judged: &Judged) -> Vec<f64> {
    let truth = judged.truth.as_deref().unwrap_or_default();
    truth
        .iter()
        .enumerate()
        .map(|(k, t)| (judged.spd[k] - t).abs() / ((floor[k] + judged.spread[k]) * widening))
        .collect()
}

/// Per level of `levels`, per wavelength: the conformal quantile of the photos' [`band_z`]
/// rows `z`, the scale of the band of that level.
fn quantile_scales(z: &[Vec<f64>], levels: &[f64]) -> Vec<Vec<f64>> {
    let d = z.first().map_or(0, Vec::len);
    levels
        .iter()
        .map(|&q| {
            (0..d)
                .map(|k| conformal_quantile(&mut z.iter().map(|r| r[k]).collect::<Vec<_>>(), q))
                .collect()
        })
        .collect()
}

/// Per level of [`reliability::LEVELS`], the scales of `cal`'s bands measured on its
/// calibration photos ([`quantile_scales`]).
fn level_scales(cal: &Calibration, calibration_photos: &[Judged]) -> Vec<Vec<f64>> {
    let z: Vec<Vec<f64>> = calibration_photos
        .iter()
        .map(|j| band_z(&cal.floor, cal.widening(residual(j)), j))
        .collect();
    quantile_scales(&z, &reliability::LEVELS)
}

/// What [`measure_row`] measured on one photo set.
struct Measured {
    /// The row of the report's first table.
    row: String,
    /// The metrics' coverage.
    metrics: BTreeMap<String, MetricCoverage>,
    /// The set's points in the reliability diagram.
    reliability: SetReliability,
}

/// One row of the report's first table (coverage, rank correlation, verdicts and the mean
/// GFC under each), the metrics' coverage on the same photos, and the set's reliability
/// (coverage at every level of `level_scales`, see [`level_scales`]).
fn measure_row(
    label: &str,
    model: &Model,
    cal: &Calibration,
    check: Option<&ChartCheck>,
    level_scales: &[Vec<f64>],
    features: &[Vec<f64>],
    truths: &[Vec<f64>],
) -> Result<Measured> {
    let judged = judge_rows(model, check, features, Some(truths))?;
    let (mut in68, mut in95, mut total) = (0usize, 0usize, 0usize);
    let mut in_level = vec![0usize; level_scales.len()];
    let mut expected = Vec::new();
    let mut actual = Vec::new();
    let mut verdicts = [0usize; 3];
    let mut gfc_by_verdict = [0.0f64; 3];
    let mut coverage: BTreeMap<String, MetricCoverage> = BTreeMap::new();
    for (j, row) in judged.iter().zip(features) {
        let u = cal.uncertainty(&j.spd, &j.spread, &j.metric_spread, residual(j))?;
        for (key, &err) in &j.metric_error {
            if let Some(interval) = u.metrics.get(key) {
                let c = coverage.entry(key.clone()).or_default();
                c.in68 += usize::from(err <= interval.half68);
                c.in95 += usize::from(err <= interval.half95);
                c.total += 1;
                c.half95.push(interval.half95);
            }
        }
        let truth = j.truth.as_deref().unwrap_or_default();
        for (k, &t) in truth.iter().enumerate() {
            in68 += usize::from(u.band68.lower[k] <= t && t <= u.band68.upper[k]);
            in95 += usize::from(u.band95.lower[k] <= t && t <= u.band95.upper[k]);
            total += 1;
        }
        let z = band_z(&cal.floor, u.widening, j);
        for (count, scale) in in_level.iter_mut().zip(level_scales) {
            *count += z.iter().zip(scale).filter(|(z, s)| z <= s).count();
        }
        expected.push(u.expected_gfc);
        actual.push(gfc(j));
        let t = assess(model, Some(cal), check, row, &j.spd, &PhotoFlags::default())?;
        verdicts[t.verdict as usize] += 1;
        gfc_by_verdict[t.verdict as usize] += gfc(j);
    }
    let n = judged.len() as f64;
    let difficulty: Vec<f64> = judged.iter().map(|j| -difficulty(j)).collect();
    let mean_gfc = |v: Verdict| match verdicts[v as usize] {
        0 => "–".to_string(),
        count => format!("{:.3}", gfc_by_verdict[v as usize] / count as f64),
    };
    let row = format!(
        "| {label} | {} | {:.4} | {:.1} % | {:.1} % | {:.2} | {:.2} | {:.0} / {:.0} / {:.0} % | {} / {} |\n",
        judged.len(),
        actual.iter().sum::<f64>() / n,
        100.0 * in68 as f64 / total as f64,
        100.0 * in95 as f64 / total as f64,
        spearman(&expected, &actual),
        spearman(&difficulty, &actual),
        100.0 * verdicts[Verdict::Ok as usize] as f64 / n,
        100.0 * verdicts[Verdict::Doubtful as usize] as f64 / n,
        100.0 * verdicts[Verdict::Unusable as usize] as f64 / n,
        mean_gfc(Verdict::Ok),
        mean_gfc(Verdict::Doubtful),
    );
    let pairs: Vec<(f64, f64)> = expected.into_iter().zip(actual).collect();
    Ok(Measured {
        row,
        metrics: coverage,
        reliability: SetReliability::new(
            label.replace('`', ""),
            in_level.iter().map(|&c| c as f64 / total as f64).collect(),
            &pairs,
        ),
    })
}

/// One row of the corrections table: the mean GFC of `model` on `features` as they are and
/// with the photo's own flare and gradient corrections ([`UnevenLight`]), alone and together.
fn corrections_row(
    label: &str,
    model: &Model,
    chart: &Chart,
    features: &[Vec<f64>],
    truths: &[Vec<f64>],
) -> Result<String> {
    let fits: Vec<Option<UnevenLight>> = features
        .iter()
        .map(|row| UnevenLight::fit(chart, row, trust::feature_scale(row)).ok())
        .collect();
    let d = model.grid().count;
    let mut cells = String::new();
    for (flare, gradient) in [(false, false), (true, false), (false, true), (true, true)] {
        let which = Corrections { flare, gradient };
        let rows: Vec<f64> = features
            .iter()
            .zip(&fits)
            .flat_map(|(row, fit)| match fit {
                Some(f) => f.correct(chart, row, trust::feature_scale(row), which),
                None => row.clone(),
            })
            .collect();
        let spds = model.estimate_rows(&rows)?;
        let mean = truths
            .iter()
            .enumerate()
            .map(|(r, t)| metrics::gfc(t, &spds[r * d..(r + 1) * d]).unwrap_or(0.0))
            .sum::<f64>()
            / truths.len() as f64;
        cells += &format!(" {mean:.4} |");
    }
    let fitted = fits.iter().filter(|f| f.is_some()).count();
    let flare: Vec<f64> = fits.iter().flatten().map(|f| f.flare[1]).collect();
    let gx: Vec<f64> = fits.iter().flatten().map(|f| f.gradient[1][0]).collect();
    let median_of = |v: &[f64]| {
        if v.is_empty() {
            f64::NAN
        } else {
            median(&mut v.to_vec())
        }
    };
    Ok(format!(
        "| {label} | {} | {fitted} | {:.3} | {:+.2} |{cells}\n",
        features.len(),
        median_of(&flare),
        median_of(&gx)
    ))
}

/// The metrics' table of one model: per metric and photo set, the share of true values
/// within the 68 % and 95 % intervals and the median 95 % half-width.
fn metric_table(name: &str, sets: &[(String, BTreeMap<String, MetricCoverage>)]) -> String {
    let mut t = format!(
        "### `{name}`\n\n| metric |{}\n|---|{}\n",
        sets.iter()
            .map(|(l, _)| format!(" {l} |"))
            .collect::<String>(),
        "---:|".repeat(sets.len())
    );
    for key in SCALAR_KEYS {
        t += &format!("| `{key}` |");
        for (_, coverage) in sets {
            t += &match coverage.get(key) {
                Some(c) if c.total > 0 => format!(
                    " {:.0} / {:.0} % (± {}) |",
                    100.0 * c.in68 as f64 / c.total as f64,
                    100.0 * c.in95 as f64 / c.total as f64,
                    significant(median(&mut c.half95.clone()))
                ),
                _ => " – |".into(),
            };
        }
        t.push('\n');
    }
    t
}

/// `v` with three significant digits.
fn significant(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let decimals = (2 - v.abs().log10().floor() as i32).max(0) as usize;
    format!("{v:.decimals$}")
}

/// The real photo sets of the thesis: name, features, true SPDs on `grid` (peak 1).
fn report(args: ReportArgs, data_dir: &DataDir) -> Result<()> {
    let setup = args.photos.setup(data_dir)?;
    let models = args.photos.models()?;
    if args.calibration.len() != models.len() {
        bail!(
            "{} calibrations for {} models; give one per model, in order",
            args.calibration.len(),
            models.len()
        );
    }
    let mut md = String::from(
        "# How far an estimate can be trusted\n\n\
         Regenerated by the command at the end. Per model: the share of the true SPD's values \
         (peak 1, every wavelength of the model's grid) inside the 68 % and 95 % bands, the \
         Spearman rank correlation of the expected GFC (and of the negated difficulty, which has \
         no ties) with the actual GFC, the verdicts (ok / doubtful / unusable) and the mean \
         GFC of the ok and of the doubtful estimates. The calibration used the split's \
         validation lamps and, for the SG, the real sets' validation photos; everything here \
         is held out from it (the real rows are the sets' test photos).\n\n",
    );
    let mut flags = String::from(
        "## The self-check on clean and bad photos\n\n\
         Share of photos whose self-check residual, half-to-half residual, colour gradient or \
         glare exceeds the calibration's doubtful level \
         (flagged), and share whose verdict is not `ok`. Clean: the test lamps' photos above. \
         Wrong chart: the same photos with the patches in a random order (a chart the model \
         does not read). Half-lit: the right half of the chart lit by the next lamp of the \
         split, same camera and settings, at the exposure the first lamp gives and one white \
         balance from the chart as lit (as a camera takes two lights in one photo). Glare: veiling glare adding 40 % of the chart's mean \
         linear level at the top-left corner, falling off as a Gaussian of 0.35 chart widths. \
         All patch level (no scene photo), noise-free.\n\n\
         | model | photos | clean: flagged | clean: not ok | wrong chart: flagged | half-lit: flagged | glare: flagged | bad (all three): flagged |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    let mut scenes = format!(
        "## Scene photos\n\n\
         Photos made with the code of `spdcam render --scene` ({SCENES} test lamps, one photo each \
         per kind, 1200×900, by the held-out cameras with the default camera stage: the chart \
         placed in a cluttered scene, the lens's blur and vignetting, Bayer mosaic, sensor \
         noise, demosaicing, white balance over the whole frame, JPEG), found, sampled and \
         estimated like a user's photo. Share not `ok` (in brackets: flagged by the \
         self-check); a photo in which no chart is found counts as both. Another chart: the \
         non-grey patches in another order. Half-lit: the right half of the chart lit by \
         another test lamp in the scene, at one exposure and white balance. Glare: a bright \
         light beside the chart glowing into the lens, adding 40 % of the chart's mean raw \
         level at the grid's top-left corner and falling off as a Gaussian of 0.35 grid \
         widths.\n\n\
         | model | photos per kind | clean | another chart | half-lit | glare |\n\
         |---|---:|---:|---:|---:|---:|\n"
    );
    let mut metrics_md = String::from(
        "## Metric intervals\n\n\
         Per single-number metric (computed on the model's wavelengths for the estimate and the \
         truth alike): the share of photos whose true value lies within the estimate's 68 % and \
         95 % intervals, and in brackets the median 95 % half-width (\"Ra 82 ± 4\"). Each \
         interval is the metric's spread over the perturbed copies plus a floor, times the \
         photo's widening, scaled by the calibration's conformal quantiles.\n\n",
    );
    let mut corrections_md = String::from(
        "## The photo's own corrections\n\n\
         Flare and the light's gradient across the chart measured on the chart's neutral \
         patches of each photo (`spdcam_core::uneven_light`: per channel, a linear gain across \
         the chart and an additive flare, least squares) and taken out of its features before \
         the model; mean GFC with the features as they are, with the flare or the gradient \
         corrected, and both. Fitted: photos with enough unclipped neutral patches (the others \
         stay as they are). Median fitted flare (green, linear share of the feature scale) and \
         gradient (green, relative gain per chart width). The SG's 96 centre patches hold 14 \
         neutrals (two middle rows and a short column), the ColorChecker 24 six (one row: no \
         vertical gradient).\n\n\
         | model · photos | n | fitted | flare | gradient x | as they are | flare | gradient | both |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    md += "## Coverage and rank correlation\n\n| model · photos | n | mean GFC | in 68 % band | in 95 % band | ρ(expected GFC, GFC) | ρ(−difficulty, GFC) | ok / doubtful / unusable | mean GFC: ok / doubtful |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    let mut diagram = Vec::new();
    for ((path, model, chart_name), cal_path) in models.iter().zip(&args.calibration) {
        let text = spdcam_core::fsio::read_text(cal_path)?;
        let cal = Calibration::from_json(&text, &cal_path.display().to_string())?;
        if cal.model != model.fingerprint() {
            bail!(
                "{} is not a calibration of {}",
                cal_path.display(),
                path.display()
            );
        }
        let chart = Chart::resolve(chart_name, None, data_dir, &GRID)?;
        let check = ChartCheck::for_model(model, data_dir)?;
        let shots = args.photos.shots(&setup, &chart, model, LampPart::Test)?;
        let name = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into(),
        );
        let calibration_shots = args
            .photos
            .shots(&setup, &chart, model, LampPart::Validation)?;
        let mut calibration_photos = judge_rows(
            model,
            check.as_ref(),
            &calibration_shots.clean.features,
            Some(&calibration_shots.clean.truths),
        )?;
        let real = real_split(&args.thesis_data, data_dir, model, chart_name)?;
        if cal.real_photos > 0 {
            let calibration_real = balanced(real.clone(), calibration_shots.clean.features.len());
            for set in &calibration_real {
                calibration_photos.extend(judge_rows(
                    model,
                    check.as_ref(),
                    &set.val.features,
                    Some(&set.val.truths),
                )?);
            }
        }
        let scales = level_scales(&cal, &calibration_photos);
        let mut metric_sets = Vec::new();
        let measured = measure_row(
            &format!("`{name}` · held-out virtual (test lamps)"),
            model,
            &cal,
            check.as_ref(),
            &scales,
            &shots.clean.features,
            &shots.clean.truths,
        )?;
        md += &measured.row;
        metric_sets.push(("held-out virtual".to_string(), measured.metrics));
        diagram.push(measured.reliability);
        corrections_md += &corrections_row(
            &format!("`{name}` · held-out virtual (test lamps)"),
            model,
            &chart,
            &shots.clean.features,
            &shots.clean.truths,
        )?;
        for RealSplit {
            label, test: rows, ..
        } in &real
        {
            let measured = measure_row(
                &format!("`{name}` · real: {label} (test photos)"),
                model,
                &cal,
                check.as_ref(),
                &scales,
                &rows.features,
                &rows.truths,
            )?;
            md += &measured.row;
            metric_sets.push((format!("real: {label} (test)"), measured.metrics));
            diagram.push(measured.reliability);
            corrections_md += &corrections_row(
                &format!("`{name}` · real: {label} (test photos)"),
                model,
                &chart,
                &rows.features,
                &rows.truths,
            )?;
        }
        metrics_md += &metric_table(&name, &metric_sets);
        metrics_md.push('\n');
        if cal.self_check_doubtful.is_none() {
            flags += &format!(
                "| `{name}` | – | no self-check without the chart's reflectances | | | | | |\n"
            );
            continue;
        }
        let flagged = |rows: &[Vec<f64>]| -> Result<f64> {
            let judged = judge_rows(model, check.as_ref(), rows, None)?;
            Ok(judged
                .iter()
                .filter(|j| j.self_check.as_ref().is_none_or(|s| cal.flags(s)))
                .count() as f64
                / judged.len() as f64)
        };
        let clean = &shots.clean.features;
        let judged = judge_rows(model, check.as_ref(), clean, None)?;
        let mut not_ok = 0;
        for (j, row) in judged.iter().zip(clean) {
            let t = assess(
                model,
                Some(&cal),
                check.as_ref(),
                row,
                &j.spd,
                &PhotoFlags::default(),
            )?;
            not_ok += usize::from(t.verdict != Verdict::Ok);
        }
        let (w, h, g) = (
            flagged(&shots.wrong_chart)?,
            flagged(&shots.half_lit)?,
            flagged(&shots.glare)?,
        );
        flags += &format!(
            "| `{name}` | {} | {:.1} % | {:.1} % | {:.1} % | {:.1} % | {:.1} % | {:.1} % |\n",
            clean.len(),
            100.0 * flagged(clean)?,
            100.0 * not_ok as f64 / clean.len() as f64,
            100.0 * w,
            100.0 * h,
            100.0 * g,
            100.0 * (w + h + g) / 3.0
        );
        let [c, w, h, g] =
            scene_verdicts(model, &cal, chart_name, &setup, data_dir, args.photos.seed)?;
        scenes += &format!(
            "| `{name}` | {SCENES} | {:.0} % ({:.0} %) | {:.0} % ({:.0} %) | {:.0} % ({:.0} %) | {:.0} % ({:.0} %) |\n",
            100.0 * c.0,
            100.0 * c.1,
            100.0 * w.0,
            100.0 * w.1,
            100.0 * h.0,
            100.0 * h.1,
            100.0 * g.0,
            100.0 * g.1
        );
        eprintln!("{}: measured", path.display());
    }
    md.push('\n');
    if let Some(path) = &args.reliability {
        plot_file::write_plot(path, &reliability::diagram_svg(&diagram)?)?;
        let shown = match (path.parent(), args.output.parent()) {
            (Some(a), Some(b)) if a == b => path.file_name().map_or_else(
                || path.display().to_string(),
                |n| n.to_string_lossy().into(),
            ),
            _ => path.display().to_string(),
        };
        md += &format!(
            "![Reliability diagram]({shown})\n\n\
             The reliability diagram: left, the share of true values inside the band at each \
             nominal level (the bands of other levels scaled by the calibration photos' \
             quantiles as the 68 % and 95 % ones are); right, the photos of each set in five \
             equal-count bins of their expected GFC, the bins' median actual 1 − GFC against \
             their median expected 1 − GFC (log axes). A calibrated set follows the diagonal; \
             above it, the estimates are worse than they say.\n\n"
        );
    }
    md.push('\n');
    md += &metrics_md;
    md += &corrections_md;
    md += CORRECTIONS_TRIED;
    md.push('\n');
    md += &flags;
    md.push('\n');
    md += &scenes;
    md += &format!(
        "\nGoals: the 95 % band covers 90–97 % of the true values; ρ ≥ 0.6; the self-check flags \
         ≥ 95 % of the bad photos and < 5 % of the clean ones. Photos: {} per lamp, seed {}.\n\n",
        args.photos.shots, args.photos.seed
    );
    md += METHOD;
    md += &format!(
        "\n## Regenerating this file\n\n```sh\nspdcam trust calibrate --real{} -o models\nspdcam trust report{}{} -o {}\n```\n\n\
         (built with `--features train`; the data directory holds the lamps, the cameras, the \
         ColorChecker SG reflectances and the thesis's photo sets).\n",
        photo_args(&args.photos),
        photo_args(&args.photos),
        args.calibration
            .iter()
            .map(|c| format!(" --calibration {}", c.display()))
            .collect::<String>()
            + &args
                .reliability
                .as_ref()
                .map_or_else(String::new, |r| format!(" --reliability {}", r.display())),
        args.output.display()
    );
    write_atomic(&args.output, md.as_bytes())?;
    print!("{md}");
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A judged photo whose estimate `spd` has the GFC `gfc` against its truth and whose
    /// perturbed estimates spread by `spread` at every wavelength.
    fn judged(spd: &[f64], gfc: f64, spread: f64) -> Judged {
        let norm = spd.iter().map(|v| v * v).sum::<f64>().sqrt();
        let u: Vec<f64> = spd.iter().map(|v| v / norm).collect();
        // A unit vector orthogonal to u (Gram–Schmidt on (1, −1, 1, −1, …)).
        let a: Vec<f64> = (0..spd.len()).map(|k| [1.0, -1.0][k % 2]).collect();
        let along: f64 = a.iter().zip(&u).map(|(x, y)| x * y).sum();
        let v: Vec<f64> = a.iter().zip(&u).map(|(x, y)| x - along * y).collect();
        let vn = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let sin = (1.0 - gfc * gfc).sqrt();
        Judged {
            spd: spd.to_vec(),
            truth: Some(
                u.iter()
                    .zip(&v)
                    .map(|(x, y)| gfc * x + sin * y / vn)
                    .collect(),
            ),
            spread: vec![spread; spd.len()],
            self_check: None,
            metric_spread: BTreeMap::new(),
            metric_error: BTreeMap::new(),
        }
    }

    #[test]
    fn the_expected_gfc_regression_learns_how_the_gfc_falls_with_difficulty() {
        // 1 − GFC = 0.2 · difficulty: ln(1 − GFC) = ln 0.2 + ln(difficulty); the shapes vary
        // a little, unrelated to the GFC. 20 lamps of 4 photos.
        let rows: Vec<Judged> = (0..80)
            .map(|i| {
                let difficulty = 0.01 * (1.0 + (i * 7 % 10) as f64);
                let spd = [1.0, 0.5 + 0.02 * (i % 5) as f64, 0.6, 0.4, 0.3];
                judged(&spd, 1.0 - 0.2 * difficulty, difficulty)
            })
            .collect();
        for r in &rows {
            let want = 1.0 - 0.2 * difficulty(r);
            assert!((gfc(r) - want).abs() < 1e-9, "{} {want}", gfc(r));
        }
        let groups: Vec<usize> = (0..rows.len()).map(|i| i / 4).collect();
        let model = fit_gfc_model(&rows, &groups).unwrap();
        for r in &rows {
            let gap = 1.0 - model.expected(&r.spd, difficulty(r));
            let want = 0.2 * difficulty(r);
            assert!(
                (gap / want - 1.0).abs() < 0.05,
                "expected 1 − GFC {gap}, true {want}"
            );
        }
    }

    #[test]
    fn band_scales_grow_with_the_level_and_hold_that_share_of_the_calibration() {
        let cal_json = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../models/colorchecker24.trust.json"
        ))
        .unwrap();
        let cal = Calibration::from_json(&cal_json, "cc24").unwrap();
        let d = cal.floor.len();
        let photos: Vec<Judged> = (0..200)
            .map(|i| {
                let spd: Vec<f64> = (0..d)
                    .map(|k| 0.3 + 0.7 * ((k * 13 + i * 7) % 17) as f64 / 17.0)
                    .collect();
                judged(&spd, 0.9 + 0.0005 * i as f64, 0.02)
            })
            .collect();
        let scales = level_scales(&cal, &photos);
        assert_eq!(scales.len(), reliability::LEVELS.len());
        for pair in scales.windows(2) {
            assert!(pair[0].iter().zip(&pair[1]).all(|(a, b)| a <= b));
        }
        // The conformal quantile holds at least its level of the photos it was taken of.
        for (level, scale) in reliability::LEVELS.iter().zip(&scales) {
            let inside = photos
                .iter()
                .flat_map(|j| {
                    band_z(&cal.floor, cal.widening(residual(j)), j)
                        .into_iter()
                        .zip(scale.clone())
                })
                .filter(|(z, s)| z <= s)
                .count() as f64
                / (photos.len() * d) as f64;
            assert!(inside >= *level - 1e-9, "level {level}: {inside}");
        }
    }
}
