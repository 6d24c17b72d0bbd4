//! Training: one loop for the networks (Adam, MSE, seeded shuffling, validation every epoch,
//! early stopping keeping the best epoch, learning rate halved on plateaus), the closed-form
//! ridge fit for `linear`, and transfer learning on a new dataset.

use crate::burn_net::{dropout_masks, prepare, BurnNet};
use crate::error::{LearnError, Result};
use burn::optim::{AdamConfig, GradientsParams};
use burn::tensor::{Device, Tensor, TensorData};
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use spdcam_core::builtin::DataDir;
use spdcam_core::dataset::{Columns, Dataset, SampleBatch};
use spdcam_core::photo::ChartTemplate;
use spdcam_core::spectral::Grid;
use spdcam_core::spectral_error;
use spdcam_infer::colour_head::ColourHead;
use spdcam_infer::model::Model;
use spdcam_infer::network::{Architecture, Network, Parameter};
use spdcam_infer::pca::Pca;
pub use spdcam_infer::record::{Backend, Schedule, TrainOptions};
use spdcam_infer::record::{DataInfo, TrainingRecord};
use spdcam_infer::ridge::Gram;
use spdcam_infer::scale::{FeatureScaler, TargetScaler};
use spdcam_infer::target::{Channels, PcaColour, Target, TargetKind};
use std::ops::Range;
use std::path::Path;
use std::time::Instant;

/// The burn device of `backend`, with autodiff; an error when this build lacks the backend.
fn device(backend: Backend) -> Result<Device> {
    let device = match backend {
        Backend::Cpu => Device::flex(),
        #[cfg(feature = "cuda")]
        Backend::Cuda => Device::cuda(0),
        #[cfg(feature = "wgpu")]
        Backend::Wgpu => Device::wgpu(Default::default()),
        #[allow(unreachable_patterns)]
        other => {
            return Err(LearnError::invalid(format!(
            "this build has no {other:?} backend; rebuild spdcam-learn with the cargo feature {}",
            format!("{other:?}").to_lowercase()
        )))
        }
    };
    Ok(device.autodiff())
}

/// A dataset in memory with what the model file records about it.
#[derive(Debug, Clone)]
pub struct TrainingSet {
    /// The samples.
    pub samples: SampleBatch,
    /// Their columns (feature names, SPD grid, weight names).
    pub columns: Columns,
    /// Where they came from.
    pub info: DataInfo,
}

impl TrainingSet {
    /// Reads the dataset directory `dir` (from `spdcam generate` or `spdcam dataset
    /// import`) into memory.
    pub fn load(dir: &Path) -> Result<TrainingSet> {
        let failed = |action| {
            move |source| LearnError::Dataset {
                action,
                path: dir.to_path_buf(),
                source,
            }
        };
        let dataset = Dataset::open(dir).map_err(failed("opening"))?;
        let samples = dataset.load().map_err(failed("reading"))?;
        Ok(TrainingSet {
            samples,
            columns: dataset.columns().clone(),
            info: DataInfo::from_dataset(&dataset, &dir.display().to_string()),
        })
    }
}

/// Records in `model` the template of the chart it was trained on, so that it estimates
/// from photos of that chart on its own; nothing for a chart no photo shows.
pub fn add_photo_chart(model: &mut Model, data_dir: &DataDir) -> Result<()> {
    let template = model
        .header()
        .chart
        .as_deref()
        .and_then(|chart| ChartTemplate::for_chart(chart, data_dir, &Grid::SIMULATION));
    if let Some(template) = template {
        model.set_photo_chart(template)?;
    }
    Ok(())
}

/// One epoch of a training log.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EpochRecord {
    /// 1-based epoch number.
    pub epoch: usize,
    /// Mean training loss (MSE of the scaled targets).
    pub train_loss: f64,
    /// Validation loss.
    pub val_loss: f64,
    /// Mean validation GFC of the SPDs.
    pub val_gfc: f64,
    /// The learning rate used.
    pub lr: f64,
    /// Seconds the epoch's training steps took.
    pub seconds: f64,
}

/// What the training loop reports while it runs.
#[derive(Debug, Clone, Copy)]
pub enum Progress {
    /// Steps done of an epoch.
    Step {
        /// 1-based epoch.
        epoch: usize,
        /// Steps done.
        done: usize,
        /// Steps in the epoch.
        total: usize,
    },
    /// An epoch finished.
    Epoch(EpochRecord),
}

/// A trained model and its log.
#[derive(Debug, Clone)]
pub struct Trained {
    /// The model (best validation epoch).
    pub model: Model,
    /// One record per epoch run (empty for `linear`).
    pub log: Vec<EpochRecord>,
}

/// Features, scaled targets and true SPDs of a set of rows, ready for the loop.
struct Prepared {
    x: Vec<f32>,
    y: Vec<f32>,
    spds: Vec<f64>,
    rows: usize,
}

/// The SPDs of `batch` on `grid` (a sub-grid of `columns.spd_grid`), each max-normalised.
pub fn spds_on_grid(batch: &SampleBatch, columns: &Columns, grid: &Grid) -> Result<Vec<f64>> {
    let source = &columns.spd_grid;
    let indices: Option<Vec<usize>> = grid
        .wavelengths()
        .iter()
        .map(|&nm| source.index_of(nm))
        .collect();
    let indices = indices.ok_or_else(|| {
        LearnError::invalid(format!(
            "the model grid {} is not part of the dataset's SPD grid {}",
            grid.label(),
            source.label()
        ))
    })?;
    let mut out = Vec::with_capacity(batch.len() * indices.len());
    let mut spd = vec![0.0; indices.len()];
    for i in 0..batch.len() {
        let row = batch.spd_of(i);
        for (v, &j) in spd.iter_mut().zip(&indices) {
            *v = row[j];
        }
        spdcam_core::spectral::clip_normalise(&mut spd);
        out.extend_from_slice(&spd);
    }
    Ok(out)
}

/// Rows `idx` of a row-major array of width `w`.
fn take_rows(data: &[f64], w: usize, idx: &[usize]) -> Vec<f64> {
    let mut out = Vec::with_capacity(idx.len() * w);
    for &i in idx {
        out.extend_from_slice(&data[i * w..(i + 1) * w]);
    }
    out
}

/// The targets (unscaled) of rows of SPDs (and weights).
fn targets_of(target: &Target, spds: &[f64], weights: &[f64]) -> Vec<f64> {
    match target {
        Target::Weights(_) => weights.to_vec(),
        _ => spds
            .chunks_exact(target.spd_len())
            .flat_map(|s| target.encode(s).unwrap_or_default())
            .collect(),
    }
}

/// The target scaling fitted on `raw` targets; the colour outputs of a [`Target::PcaColour`]
/// scaled to a range of √weight instead of 1, so that each weighs `weight` PCA coefficients
/// in the mean squared error the networks are trained on.
fn fit_target_scaler(target: &Target, raw: &[f64]) -> Result<TargetScaler> {
    let mut scaler = TargetScaler::fit(raw, target.len())?;
    if let Target::PcaColour(p) = target {
        let root = p.colour.weight.sqrt();
        for j in p.pca.len()..target.len() {
            scaler.max[j] = scaler.min[j] + (scaler.max[j] - scaler.min[j]) / root;
        }
    }
    Ok(scaler)
}

/// Model-independent pieces fitted on the training rows.
struct Fitted {
    features: FeatureScaler,
    target: Target,
    targets: TargetScaler,
}

/// Decodes network outputs to SPDs and scores them against `spds`: (MSE of the outputs
/// against `y`, mean GFC).
fn score(fitted: &Fitted, outputs: &[f32], y: &[f32], spds: &[f64]) -> Result<(f64, f64)> {
    let k = fitted.target.len();
    let d = fitted.target.spd_len();
    let rows = outputs.len() / k;
    let mse = outputs
        .iter()
        .zip(y)
        .map(|(a, b)| f64::from(a - b).powi(2))
        .sum::<f64>()
        / outputs.len().max(1) as f64;
    let mut t = vec![0.0; k];
    let mut spd = vec![0.0; d];
    let mut gfc = 0.0;
    let decoder = fitted.target.decoder(None);
    for r in 0..rows {
        fitted
            .targets
            .unscale_into(&outputs[r * k..(r + 1) * k], &mut t);
        decoder.decode_into(&t, &mut spd);
        gfc += spectral_error::gfc(&spds[r * d..(r + 1) * d], &spd)?;
    }
    Ok((mse, gfc / rows.max(1) as f64))
}

fn prepare_rows(
    fitted: &Fitted,
    set: &TrainingSet,
    spds: &[f64],
    idx: &[usize],
) -> Result<Prepared> {
    let f = set.samples.feature_count;
    let d = fitted.target.spd_len();
    let features = take_rows(&set.samples.features, f, idx);
    let spd_rows = take_rows(spds, d, idx);
    let weights = take_rows(&set.samples.weights, set.samples.weight_count, idx);
    let raw = targets_of(&fitted.target, &spd_rows, &weights);
    Ok(Prepared {
        x: fitted.features.transform(&features)?,
        y: fitted.targets.scale(&raw),
        spds: spd_rows,
        rows: idx.len(),
    })
}

/// Checks a dataset can train or be scored by a model with these columns.
fn check_set(set: &TrainingSet) -> Result<()> {
    if set.samples.is_empty() {
        return Err(LearnError::invalid(format!(
            "{}: the dataset has no samples",
            set.info.path
        )));
    }
    if let Some(v) = set.samples.features.iter().find(|v| !v.is_finite()) {
        return Err(LearnError::invalid(format!(
            "{}: a feature is {v}",
            set.info.path
        )));
    }
    Ok(())
}

/// Refuses training rows whose features, each row divided by its own scale as the model
/// sees them, are the same in every row (every feature constant, or all rows identical):
/// every input would scale to zero and a model could learn nothing from them.
fn check_features_vary(scaler: &FeatureScaler, set: &TrainingSet, rows: usize) -> Result<()> {
    if scaler.min.iter().zip(&scaler.max).any(|(lo, hi)| hi > lo) {
        return Ok(());
    }
    Err(LearnError::invalid(format!(
        "{}: every feature is the same in all {rows} training samples (each row divided by \
         its {}): a model could not learn anything from them. The features must differ \
         between samples; check how the dataset was generated or imported",
        set.info.path,
        match scaler.row_scale {
            spdcam_infer::scale::RowScale::Max => "maximum",
            spdcam_infer::scale::RowScale::Mean => "mean",
        }
    )))
}

/// What training and fine-tuning both start from: the SPDs of `data` on the grid, the row
/// indices of training and validation, the set the validation rows index and its SPDs, and
/// the training rows' SPDs.
struct TrainValSplit<'a> {
    spds: Vec<f64>,
    train_idx: Vec<usize>,
    val_idx: Vec<usize>,
    val_set: &'a TrainingSet,
    val_spds: Vec<f64>,
    train_spds: Vec<f64>,
}

/// The set-up [`train`] and [`finetune`] share: the SPDs of `data` on `grid`, and training
/// and validation rows: all of `data` against `validation` (checked by `check_columns`), or
/// without one a seeded `(share, seed)` split of `data`.
fn split_train_val<'a>(
    data: &'a TrainingSet,
    validation: Option<&'a TrainingSet>,
    grid: &Grid,
    (share, seed): (f64, u64),
    check_columns: impl Fn(&TrainingSet) -> Result<()>,
) -> Result<TrainValSplit<'a>> {
    let spds = spds_on_grid(&data.samples, &data.columns, grid)?;
    let (train_idx, val_idx, val_set, val_spds) = match validation {
        Some(v) => {
            check_set(v)?;
            check_columns(v)?;
            let vs = spds_on_grid(&v.samples, &v.columns, grid)?;
            (
                (0..data.samples.len()).collect(),
                (0..v.samples.len()).collect(),
                v,
                vs,
            )
        }
        None => {
            let (train_idx, val_idx) = split_indices(data.samples.len(), share, seed)?;
            (train_idx, val_idx, data, spds.clone())
        }
    };
    let train_spds = take_rows(&spds, grid.count, &train_idx);
    Ok(TrainValSplit {
        spds,
        train_idx,
        val_idx,
        val_set,
        val_spds,
        train_spds,
    })
}

/// A seeded split of `n` rows into (train, validation) indices.
fn split_indices(n: usize, val_split: f64, seed: u64) -> Result<(Vec<usize>, Vec<usize>)> {
    if !(val_split > 0.0 && val_split < 1.0) {
        return Err(LearnError::invalid(format!(
            "the validation split {val_split} must lie strictly between 0 and 1"
        )));
    }
    if n < 2 {
        return Err(LearnError::invalid(format!(
            "at least 2 samples are needed to hold some out for validation, got {n}"
        )));
    }
    let mut idx: Vec<usize> = (0..n).collect();
    idx.shuffle(&mut rand::rngs::SmallRng::seed_from_u64(seed ^ 0x5eed_5711));
    let n_val = ((n as f64 * val_split).round() as usize).clamp(1, n - 1);
    let val = idx[..n_val].to_vec();
    let mut train = idx[n_val..].to_vec();
    train.sort_unstable();
    Ok((train, val))
}

/// Parts each training batch is split into: each part's gradient is computed on its own
/// thread (in its own autodiff graph) and the parts' gradients are summed, so that one step
/// keeps two cores busy (data parallelism within the batch). A fixed number rather than the
/// thread count, so that the sums, and so the trained weights, are the same on any machine.
pub const BATCH_PARTS: usize = 2;

/// Trains a model on `data`, validating on `validation` or, without one, on a seeded
/// `val_split` share of `data`. Each batch is computed in [`BATCH_PARTS`] parallel parts.
pub fn train(
    data: &TrainingSet,
    validation: Option<&TrainingSet>,
    options: &TrainOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<Trained> {
    train_in_parts(data, validation, options, BATCH_PARTS, progress)
}

/// [`train`] with each batch computed in `parts` parallel parts (1: one graph on one
/// thread, the loop before data parallelism; the learning benchmark compares the two).
/// The same gradient up to rounding, whatever `parts`.
pub fn train_in_parts(
    data: &TrainingSet,
    validation: Option<&TrainingSet>,
    options: &TrainOptions,
    parts: usize,
    progress: &mut dyn FnMut(Progress),
) -> Result<Trained> {
    let started = Instant::now();
    options.architecture.validate()?;
    options.schedule.validate()?;
    check_set(data)?;
    let d = options.grid.count;
    let TrainValSplit {
        spds,
        train_idx,
        val_idx,
        val_set,
        val_spds,
        train_spds,
    } = split_train_val(
        data,
        validation,
        &options.grid,
        (options.val_split, options.seed),
        |v| {
            if v.columns.feature_names == data.columns.feature_names {
                Ok(())
            } else {
                Err(LearnError::invalid(format!(
                    "{} and {} have different feature columns",
                    data.info.path, v.info.path
                )))
            }
        },
    )?;
    let f = data.samples.feature_count;
    let train_features = take_rows(&data.samples.features, f, &train_idx);
    let target = match options.target {
        TargetKind::Pca(components) => Target::Pca(Pca::fit(&train_spds, d, components)?),
        TargetKind::PcaColour {
            components,
            colour_weight,
        } => Target::PcaColour(PcaColour {
            pca: Pca::fit(&train_spds, d, components)?,
            colour: ColourHead::on_grid(&options.grid, colour_weight)?,
        }),
        TargetKind::Weights => {
            let k = data.samples.weight_count;
            if k == 0 {
                return Err(LearnError::invalid(format!(
                    "{}: the dataset has no weight columns; train on PCA targets instead",
                    data.info.path
                )));
            }
            let weights = take_rows(&data.samples.weights, k, &train_idx);
            let channels =
                Channels::fit(data.columns.weight_names.clone(), &weights, &train_spds, d)?;
            if channels.fit_rmse > 0.02 {
                return Err(LearnError::invalid(format!(
                    "{}: the SPDs are not weighted sums of fixed channels (fit RMSE {:.4}); \
                     train on PCA targets instead",
                    data.info.path, channels.fit_rmse
                )));
            }
            Target::Weights(channels)
        }
    };
    let weights = take_rows(&data.samples.weights, data.samples.weight_count, &train_idx);
    let raw_targets = targets_of(&target, &train_spds, &weights);
    let fitted = Fitted {
        features: FeatureScaler::fit(&train_features, f, Some(options.row_scale))?,
        targets: fit_target_scaler(&target, &raw_targets)?,
        target,
    };
    check_features_vary(&fitted.features, data, train_idx.len())?;
    let train_rows = prepare_rows(&fitted, data, &spds, &train_idx)?;
    let val_rows = prepare_rows(&fitted, val_set, &val_spds, &val_idx)?;
    let k = fitted.target.len();
    let (network, log, best) = match &options.architecture {
        Architecture::Linear { ridge } => {
            let net = fit_ridge(&train_rows, &val_rows, f, k, *ridge, &fitted)?;
            (net, Vec::new(), 0)
        }
        arch => {
            let init = Network::init(arch.clone(), f, k, options.seed)?;
            fit_network(
                init,
                &train_rows,
                &val_rows,
                &fitted,
                &options.schedule,
                options.seed,
                false,
                (options.backend, parts),
                progress,
            )?
        }
    };
    let outputs = network.forward(&val_rows.x)?;
    let (val_loss, val_gfc) = score(&fitted, &outputs, &val_rows.y, &val_rows.spds)?;
    let record = TrainingRecord {
        data: data.info.clone(),
        validation: validation.map(|v| v.info.clone()),
        train_samples: train_rows.rows,
        val_samples: val_rows.rows,
        options: options.clone(),
        epochs_run: log.len(),
        best_epoch: best,
        val_loss,
        val_gfc,
        seconds: started.elapsed().as_secs_f64(),
        finetuned_from: None,
    };
    let model = Model::assemble(
        network,
        fitted.features,
        fitted.target,
        fitted.targets,
        options.grid,
        data.columns.feature_names.clone(),
        record,
    )?;
    Ok(Trained { model, log })
}

/// Closed-form ridge regression ([`spdcam_infer::ridge`]) from normalised features (plus a bias) to
/// scaled targets, the feature weights penalised by λ·n (n rows) and the bias by 10⁻¹²·n;
/// with `ridge` 0, λ is chosen on the validation rows among 10⁻⁸…10⁰.
fn fit_ridge(
    train: &Prepared,
    val: &Prepared,
    f: usize,
    k: usize,
    ridge: f64,
    fitted: &Fitted,
) -> Result<Network> {
    let n = train.rows;
    let gram = Gram::from_fn(
        n,
        f + 1,
        k,
        |i, j| {
            if j < f {
                f64::from(train.x[i * f + j])
            } else {
                1.0
            }
        },
        |i, j| f64::from(train.y[i * k + j]),
    )?;
    let candidates: Vec<f64> = if ridge > 0.0 {
        vec![ridge]
    } else {
        (-8..=0).map(|e| 10f64.powi(e)).collect()
    };
    let mut best: Option<(f64, Network)> = None;
    for lambda in candidates {
        let mut diagonal = vec![lambda * n as f64; f + 1];
        diagonal[f] = 1e-12 * n as f64;
        let b = gram.solve(&diagonal, None)?;
        let weight: Vec<f32> = (0..f)
            .flat_map(|i| (0..k).map(move |j| (i, j)))
            .map(|(i, j)| b.weight(j, i) as f32)
            .collect();
        let bias: Vec<f32> = (0..k).map(|j| b.weight(j, f) as f32).collect();
        let net = Network::new(
            Architecture::Linear { ridge: lambda },
            f,
            k,
            vec![
                Parameter {
                    name: "output.weight".into(),
                    shape: vec![f, k],
                    data: weight,
                },
                Parameter {
                    name: "output.bias".into(),
                    shape: vec![k],
                    data: bias,
                },
            ],
        )?;
        let (loss, _) = score(fitted, &net.forward(&val.x)?, &val.y, &val.spds)?;
        if best.as_ref().is_none_or(|(l, _)| loss < *l) {
            best = Some((loss, net));
        }
    }
    best.map(|(_, net)| net)
        .ok_or_else(|| LearnError::invalid("no ridge penalty to try"))
}

/// Keeps freed memory in the process: glibc otherwise hands each large freed block back to
/// the system at once, so every training step page-faults its temporaries in anew (about a
/// third of a CNN step on 2 cores).
fn keep_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        static ONCE: std::sync::Once = std::sync::Once::new();
        // SAFETY: mallopt only changes allocator thresholds; it is called once, before the
        // training allocates.
        ONCE.call_once(|| unsafe {
            libc::mallopt(libc::M_MMAP_THRESHOLD, 1 << 30);
            libc::mallopt(libc::M_TRIM_THRESHOLD, i32::MAX);
        });
    }
}

/// `rows` cut into at most `parts` contiguous, nearly equal, non-empty ranges.
fn part_ranges(rows: usize, parts: usize) -> Vec<Range<usize>> {
    let parts = parts.clamp(1, rows.max(1));
    (0..parts)
        .map(|p| rows * p / parts..rows * (p + 1) / parts)
        .filter(|r| !r.is_empty())
        .collect()
}

/// One optimiser step's gradient on rows `xb`/`yb` (`rows` of them) of `net`, computed in
/// `parts` parts on parallel threads, each on a replica of `net` with its own autodiff graph;
/// the parts' losses are scaled so that they add up to the batch's mean squared error.
/// Returns the summed gradients and that loss.
#[allow(clippy::too_many_arguments)]
fn batch_gradient(
    net: &BurnNet,
    architecture: &Architecture,
    (xb, yb): (&[f32], &[f32]),
    (rows, f, k): (usize, usize, usize),
    masks: Vec<Tensor<2>>,
    parts: usize,
    device: &Device,
) -> Result<(GradientsParams, f64)> {
    let ranges = part_ranges(rows, parts);
    let replicas: Vec<BurnNet> = (1..ranges.len()).map(|_| net.replica()).collect();
    let scale = 1.0 / (rows * k) as f32;
    let part = |p: usize| -> Result<(GradientsParams, f64)> {
        let model = if p == 0 { net } else { &replicas[p - 1] };
        let r = ranges[p].clone();
        let n = r.len();
        let input = prepare(architecture, &xb[r.start * f..r.end * f], n, f, device)?;
        let target = Tensor::<2>::from_data(
            TensorData::new(yb[r.start * k..r.end * k].to_vec(), [n, k]),
            device,
        );
        let masks = masks
            .iter()
            .map(|m| m.clone().narrow(0, r.start, n))
            .collect();
        let output = model.forward(architecture, input, masks)?;
        let loss = (output - target).square().sum().mul_scalar(scale);
        let grads = loss.backward();
        let value = f64::from(loss.into_scalar::<f32>());
        Ok((GradientsParams::from_grads(grads, model), value))
    };
    let results = (0..ranges.len())
        .into_par_iter()
        .map(part)
        .collect::<Result<Vec<_>>>()?;
    let loss = results.iter().map(|(_, l)| l).sum();
    let grads = net.sum_gradients(results.into_iter().map(|(g, _)| g).collect());
    Ok((grads, loss))
}

/// The gradient loop: returns the best-validation network, the log and the best epoch.
/// Each batch is computed in `parts` parallel parts (see [`batch_gradient`]).
#[allow(clippy::too_many_arguments)]
fn fit_network(
    init: Network,
    train: &Prepared,
    val: &Prepared,
    fitted: &Fitted,
    schedule: &Schedule,
    seed: u64,
    freeze_features: bool,
    (backend, parts): (Backend, usize),
    progress: &mut dyn FnMut(Progress),
) -> Result<(Network, Vec<EpochRecord>, usize)> {
    keep_freed_memory();
    let device = device(backend)?;
    device.seed(seed);
    let architecture = init.architecture().clone();
    let f = init.inputs();
    let k = init.outputs();
    let mut net = BurnNet::from_network(&init, &device)?;
    if freeze_features {
        net = net.freeze_features();
    }
    let mut optimizer = AdamConfig::new().with_epsilon(1e-7).init();
    let mut rng = rand::rngs::SmallRng::seed_from_u64(seed.wrapping_add(1));
    let mut order: Vec<usize> = (0..train.rows).collect();
    let batch = schedule.batch.min(train.rows.max(1));
    let steps = train.rows.div_ceil(batch);
    let mut lr = schedule.lr;
    let mut best: Option<(f64, Network, usize)> = None;
    let mut since_best = 0;
    let mut since_decay = 0;
    let mut log = Vec::new();
    let mut xb = Vec::with_capacity(batch * f);
    let mut yb = Vec::with_capacity(batch * k);
    for epoch in 1..=schedule.epochs {
        let t0 = Instant::now();
        order.shuffle(&mut rng);
        let mut loss_sum = 0.0;
        for (step, chunk) in order.chunks(batch).enumerate() {
            xb.clear();
            yb.clear();
            for &i in chunk {
                xb.extend_from_slice(&train.x[i * f..(i + 1) * f]);
                yb.extend_from_slice(&train.y[i * k..(i + 1) * k]);
            }
            let rows = chunk.len();
            let masks = dropout_masks(&architecture, rows, f, &mut rng, &device)?;
            let (grads, loss) = batch_gradient(
                &net,
                &architecture,
                (&xb, &yb),
                (rows, f, k),
                masks,
                parts,
                &device,
            )?;
            loss_sum += loss * rows as f64;
            net = optimizer.step(lr, net, grads);
            progress(Progress::Step {
                epoch,
                done: step + 1,
                total: steps,
            });
        }
        let seconds = t0.elapsed().as_secs_f64();
        if !loss_sum.is_finite() {
            return Err(diverged(epoch, "the training loss", lr));
        }
        // The network is built from its own architecture, so the only way its parameters
        // fail the model's checks is by holding non-finite values.
        let snapshot = net
            .to_network(&init)
            .map_err(|e| diverged(epoch, &format!("the parameters ({e})"), lr))?;
        let outputs = snapshot.forward(&val.x)?;
        let (val_loss, val_gfc) = score(fitted, &outputs, &val.y, &val.spds)?;
        if !val_loss.is_finite() {
            return Err(diverged(epoch, "the validation loss", lr));
        }
        let record = EpochRecord {
            epoch,
            train_loss: loss_sum / train.rows as f64,
            val_loss,
            val_gfc,
            lr,
            seconds,
        };
        log.push(record);
        progress(Progress::Epoch(record));
        if best.as_ref().is_none_or(|(l, _, _)| val_loss < *l) {
            best = Some((val_loss, snapshot, epoch));
            since_best = 0;
            since_decay = 0;
        } else {
            since_best += 1;
            since_decay += 1;
        }
        if schedule.patience.is_some_and(|p| since_best >= p) {
            break;
        }
        if schedule.plateau.is_some_and(|p| since_decay >= p) {
            lr *= 0.5;
            since_decay = 0;
        }
    }
    let (_, network, epoch) = best.ok_or_else(|| LearnError::invalid("no epoch was run"))?;
    Ok((network, log, epoch))
}

/// The error of a training whose loss or parameters became non-finite (`what`) at `epoch`.
fn diverged(epoch: usize, what: &str, lr: f64) -> LearnError {
    LearnError::Numerical(format!(
        "training diverged at epoch {epoch}: {what} became non-finite (NaN or infinite); \
         try a smaller learning rate than {} (--lr)",
        spdcam_core::error::short_number(lr)
    ))
}

/// How to fine-tune a model on new data (the thesis's transfer learning, section 6.4).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FinetuneOptions {
    /// The optimisation schedule.
    pub schedule: Schedule,
    /// Train only the new output layer, keeping the others fixed.
    pub freeze_features: bool,
    /// Fit a new PCA (and target scaling) on the new data instead of keeping the model's.
    pub refit_pca: bool,
    /// Keep the trained output layer instead of starting a new one: for a handful of
    /// samples of the same kind of target, where a new layer would be fitted to too little.
    pub keep_output: bool,
    /// Seed of the split, the new layer, the shuffling and the dropout.
    pub seed: u64,
    /// The share of the data held out for validation when no validation set is given.
    pub val_split: f64,
    /// Where to train.
    pub backend: Backend,
}

impl FinetuneOptions {
    /// The thesis's transfer learning: 100 epochs, batch 64, learning rate 1e-3, all layers.
    pub fn thesis() -> FinetuneOptions {
        FinetuneOptions {
            schedule: Schedule {
                epochs: 100,
                ..Schedule::thesis()
            },
            freeze_features: false,
            refit_pca: false,
            keep_output: false,
            seed: 1,
            val_split: 0.2,
            backend: Backend::Cpu,
        }
    }
}

/// Fine-tunes `model` on `data`: a new output layer, then all layers (or only the new one)
/// trained on the new samples. The input scaling of the model is kept.
pub fn finetune(
    model: &Model,
    data: &TrainingSet,
    validation: Option<&TrainingSet>,
    options: &FinetuneOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<Trained> {
    let started = Instant::now();
    options.schedule.validate()?;
    check_set(data)?;
    model.check_features(&data.columns.feature_names, &data.info.path)?;
    match model.network().architecture() {
        Architecture::Linear { .. } => {
            return Err(LearnError::invalid(
                "a linear model has no layers to transfer; train a new one on the data instead",
            ))
        }
        Architecture::Average { .. } => {
            return Err(LearnError::invalid(
                "an average of models has no one network to fine-tune; fine-tune a member, or \
                 fit ridge on the photos (finetune without recipe flags weighs it)",
            ))
        }
        _ => {}
    }
    if options.keep_output && options.refit_pca {
        return Err(LearnError::invalid(
            "a refitted PCA needs a new output layer; drop keeping the output layer",
        ));
    }
    let grid = model.grid();
    let d = grid.count;
    let TrainValSplit {
        spds,
        train_idx,
        val_idx,
        val_set,
        val_spds,
        train_spds,
    } = split_train_val(
        data,
        validation,
        &grid,
        (options.val_split, options.seed),
        |v| Ok(model.check_features(&v.columns.feature_names, &v.info.path)?),
    )?;
    let (target, targets) = match (model.target(), options.refit_pca) {
        (Target::Pca(pca), true) => {
            let pca = Pca::fit(
                &train_spds,
                d,
                spdcam_infer::pca::Components::Count(pca.len()),
            )?;
            let target = Target::Pca(pca);
            let raw = targets_of(&target, &train_spds, &[]);
            let scaler = fit_target_scaler(&target, &raw)?;
            (target, scaler)
        }
        (Target::PcaColour(p), true) => {
            let pca = Pca::fit(
                &train_spds,
                d,
                spdcam_infer::pca::Components::Count(p.pca.len()),
            )?;
            let target = Target::PcaColour(PcaColour {
                pca,
                colour: p.colour.clone(),
            });
            let raw = targets_of(&target, &train_spds, &[]);
            let scaler = fit_target_scaler(&target, &raw)?;
            (target, scaler)
        }
        (Target::Weights(_), true) => {
            return Err(LearnError::invalid(
                "the model predicts channel weights; there is no PCA to refit",
            ))
        }
        (t, false) => {
            if let Target::Weights(c) = t {
                if data.columns.weight_names != c.names {
                    return Err(LearnError::invalid(format!(
                        "{}: the weight columns {:?} differ from the model's channels {:?}",
                        data.info.path, data.columns.weight_names, c.names
                    )));
                }
            }
            (t.clone(), model.target_scaler().clone())
        }
    };
    let fitted = Fitted {
        features: model.feature_scaler().clone(),
        target,
        targets,
    };
    let train_rows = prepare_rows(&fitted, data, &spds, &train_idx)?;
    let val_rows = prepare_rows(&fitted, val_set, &val_spds, &val_idx)?;
    let init = if options.keep_output {
        model.network().clone()
    } else {
        model
            .network()
            .with_new_output(fitted.target.len(), options.seed)?
    };
    let (network, log, best) = fit_network(
        init,
        &train_rows,
        &val_rows,
        &fitted,
        &options.schedule,
        options.seed,
        options.freeze_features,
        (options.backend, BATCH_PARTS),
        progress,
    )?;
    let outputs = network.forward(&val_rows.x)?;
    let (val_loss, val_gfc) = score(&fitted, &outputs, &val_rows.y, &val_rows.spds)?;
    let previous = model.training().clone();
    let mut train_options = previous.options.clone();
    train_options.schedule = options.schedule.clone();
    train_options.seed = options.seed;
    train_options.val_split = options.val_split;
    train_options.backend = options.backend;
    let record = TrainingRecord {
        data: data.info.clone(),
        validation: validation.map(|v| v.info.clone()),
        train_samples: train_rows.rows,
        val_samples: val_rows.rows,
        options: train_options,
        epochs_run: log.len(),
        best_epoch: best,
        val_loss,
        val_gfc,
        seconds: started.elapsed().as_secs_f64(),
        finetuned_from: Some(Box::new(previous)),
    };
    let mut tuned = Model::assemble(
        network,
        fitted.features,
        fitted.target,
        fitted.targets,
        grid,
        data.columns.feature_names.clone(),
        record,
    )?;
    if let Some(template) = model.photo_chart() {
        tuned.set_photo_chart(template.clone())?;
    }
    Ok(Trained { model: tuned, log })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::gaussian_set;
    use spdcam_infer::network::{Architecture, CnnSpec};
    use spdcam_infer::pca::Components;
    use spdcam_infer::scale::RowScale;

    #[test]
    fn part_ranges_tile_the_batch() {
        assert_eq!(part_ranges(7, 2), vec![0..3, 3..7]);
        assert_eq!(part_ranges(64, 2), vec![0..32, 32..64]);
        assert_eq!(part_ranges(1, 2), vec![0..1]);
        assert_eq!(part_ranges(5, 1), vec![0..5]);
    }

    #[test]
    fn batch_parts_give_the_one_graph_weights() {
        let data = gaussian_set(300, 24, 3, 4);
        let options = TrainOptions {
            row_scale: RowScale::Max,
            architecture: Architecture::Cnn1d(CnnSpec::thesis()),
            target: TargetKind::Pca(Components::default()),
            grid: Grid::ESTIMATION,
            schedule: Schedule {
                epochs: 1,
                batch: 37,
                ..Schedule::thesis()
            },
            seed: 5,
            val_split: 0.2,
            backend: Backend::Cpu,
        };
        let one = train_in_parts(&data, None, &options, 1, &mut |_| {}).unwrap();
        let two = train_in_parts(&data, None, &options, 2, &mut |_| {}).unwrap();
        let three = train_in_parts(&data, None, &options, 3, &mut |_| {}).unwrap();
        let (a, b, c) = (
            one.model.network(),
            two.model.network(),
            three.model.network(),
        );
        let mut largest = 0.0f32;
        let mut moved = 0.0f32;
        let init = Network::init(a.architecture().clone(), a.inputs(), a.outputs(), 5).unwrap();
        for (((pa, pb), pc), p0) in a
            .parameters()
            .iter()
            .zip(b.parameters())
            .zip(c.parameters())
            .zip(init.parameters())
        {
            for (((x, y), z), w) in pa.data.iter().zip(&pb.data).zip(&pc.data).zip(&p0.data) {
                largest = largest.max((x - y).abs()).max((x - z).abs());
                moved = moved.max((x - w).abs());
            }
        }
        // Training moved the weights; splitting the batches changed them by rounding only.
        assert!(moved > 1e-3, "{moved}");
        assert!(
            largest < 1e-4 * moved.max(1.0),
            "{largest} vs moved {moved}"
        );
        for (x, y) in one.log.iter().zip(&two.log) {
            assert!(
                (x.train_loss - y.train_loss).abs() < 1e-5 * x.train_loss,
                "{x:?} {y:?}"
            );
        }
    }
}
