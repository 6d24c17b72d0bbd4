//! Speed of training and estimating, against baselines measured in the same run:
//!
//! - training: one epoch of the thesis's 1D CNN on 10,000 samples with our loop (im2col
//!   convolutions, reshape max-pool, each batch computed in two data-parallel parts on two
//!   threads) against the same loop on one graph and one thread (the loop before data
//!   parallelism) and against the straightforward burn model (burn's `Conv1d` and
//!   `MaxPool1d` modules, batch 64, the same Adam) on the same flex backend;
//! - estimating: features → SPD with the plain-Rust forward pass against burn's flex forward
//!   pass (no autodiff) of the straightforward model.
//!
//! `cargo bench -p spdcam-learn --bench speed [-- --quick]`; `--quick` measures fewer samples.
//! Goals (issues 4 and 16, 2-core CPU): ≤ 4 s per 10,000-sample CNN epoch on the 96-patch
//! chart, ≤ 1 ms per estimate, ≤ 1 s for 10,000 estimates.

use burn::module::Module;
use burn::nn::conv::{Conv1d, Conv1dConfig};
use burn::nn::pool::{MaxPool1d, MaxPool1dConfig};
use burn::nn::{Dropout, DropoutConfig, Linear, LinearConfig};
use burn::optim::{AdamConfig, GradientsParams};
use burn::tensor::activation::{relu, sigmoid};
use burn::tensor::{Device, Tensor, TensorData};
use spdcam_infer::network::{Architecture, CnnSpec};
use spdcam_infer::pca::Components;
use spdcam_infer::scale::RowScale;
use spdcam_infer::target::TargetKind;
use spdcam_learn::synthetic::gaussian_set;
use spdcam_learn::train::{train_in_parts, Backend, Schedule, TrainOptions, BATCH_PARTS};
use std::time::Instant;

/// The thesis CNN written the straightforward way with burn's layers (NCL layout).
#[derive(Module, Debug)]
struct Straightforward {
    conv1: Conv1d,
    conv2: Conv1d,
    pool: MaxPool1d,
    dropout: Dropout,
    dense: Linear,
    output: Linear,
}

impl Straightforward {
    fn new(inputs: usize, outputs: usize, device: &Device) -> Straightforward {
        let l3 = (inputs - 6 - 4) / 2;
        Straightforward {
            conv1: Conv1dConfig::new(1, 32, 7).init(device),
            conv2: Conv1dConfig::new(32, 64, 5).init(device),
            pool: MaxPool1dConfig::new(2).init(),
            dropout: DropoutConfig::new(0.2).init(),
            dense: LinearConfig::new(64 * l3, 64).init(device),
            output: LinearConfig::new(64, outputs).init(device),
        }
    }

    fn forward(&self, x: Tensor<3>) -> Tensor<2> {
        let h = relu(self.conv1.forward(x));
        let h = relu(self.conv2.forward(h));
        let h = self.dropout.forward(self.pool.forward(h));
        let [b, c, l] = h.dims();
        let h = relu(self.dense.forward(h.reshape([b, c * l])));
        sigmoid(self.output.forward(h))
    }
}

fn straightforward_epoch(x: &[f32], y: &[f32], f: usize, k: usize, rows: usize) -> f64 {
    let device = Device::flex().autodiff();
    device.seed(1);
    let mut net = Straightforward::new(f, k, &device);
    let mut optim = AdamConfig::new().init();
    let batch = 64;
    let t0 = Instant::now();
    for start in (0..rows).step_by(batch) {
        let n = batch.min(rows - start);
        let xb = Tensor::<3>::from_data(
            TensorData::new(x[start * f..(start + n) * f].to_vec(), [n, 1, f]),
            &device,
        );
        let yb = Tensor::<2>::from_data(
            TensorData::new(y[start * k..(start + n) * k].to_vec(), [n, k]),
            &device,
        );
        let loss = (net.forward(xb) - yb).square().mean();
        let grads = GradientsParams::from_grads(loss.backward(), &net);
        net = optim.step(1e-3, net, grads);
    }
    t0.elapsed().as_secs_f64()
}

fn options(schedule: Schedule) -> TrainOptions {
    TrainOptions {
        row_scale: RowScale::Max,
        architecture: Architecture::Cnn1d(CnnSpec::thesis()),
        target: TargetKind::Pca(Components::default()),
        grid: spdcam_core::spectral::Grid::ESTIMATION,
        schedule,
        seed: 1,
        val_split: 0.1,
        backend: Backend::Cpu,
    }
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let rows = if quick { 2_000 } else { 10_000 };
    println!("spdcam-learn benchmark ({rows} training samples; times scaled to 10,000)");
    for patches in [24usize, 96] {
        let f = patches * 3;
        // 10 % more rows: the validation split.
        let data = gaussian_set(rows * 10 / 9, patches, 1, 2);
        let scale = 10_000.0 / rows as f64;
        println!("\n{patches} patches ({f} features), thesis 1D CNN:");
        let mut ours = Vec::new();
        let mut model = None;
        for batch in [64, 128, 256] {
            let schedule = Schedule {
                epochs: 1,
                batch,
                ..Schedule::thesis()
            };
            let epoch = |parts: usize| {
                let trained =
                    train_in_parts(&data, None, &options(schedule.clone()), parts, &mut |_| {})
                        .expect("training");
                (trained.log[0].seconds * scale, trained.model)
            };
            let (one, _) = epoch(1);
            let (parts, trained) = epoch(BATCH_PARTS);
            println!(
                "  our loop,        batch {batch:>3}: {parts:6.2} s per 10,000-sample epoch \
                 ({BATCH_PARTS} parts; one graph {one:6.2} s, ratio {:.2}×)",
                one / parts
            );
            ours.push(parts);
            model = Some(trained);
        }
        let model = model.expect("a model");
        // The baseline on the same normalised inputs (values do not matter for speed).
        let k = model.network().outputs();
        let x: Vec<f32> = (0..rows * f)
            .map(|i| ((i * 31 % 97) as f32) / 97.0)
            .collect();
        let y: Vec<f32> = (0..rows * k)
            .map(|i| ((i * 17 % 89) as f32) / 89.0)
            .collect();
        let base = straightforward_epoch(&x, &y, f, k, rows) * scale;
        println!("  straightforward, batch  64: {base:6.2} s per 10,000-sample epoch");
        println!(
            "  ratio straightforward / ours: batch 64 {:.2}×, batch 128 {:.2}×, batch 256 {:.2}×",
            base / ours[0],
            base / ours[1],
            base / ours[2]
        );

        // Estimates.
        let features = &data.samples.features;
        let one = &features[..f];
        let reps = 2_000;
        let t0 = Instant::now();
        for _ in 0..reps {
            std::hint::black_box(model.estimate(std::hint::black_box(one)).expect("estimate"));
        }
        let single = t0.elapsed().as_secs_f64() / reps as f64;
        let n = 10_000.min(data.samples.len());
        let t0 = Instant::now();
        let spds = model.estimate_rows(&features[..n * f]).expect("estimates");
        let many = t0.elapsed().as_secs_f64() * 10_000.0 / n as f64;
        std::hint::black_box(spds);
        let device = Device::flex();
        let net = Straightforward::new(f, k, &device);
        let xs = model
            .feature_scaler()
            .transform(&features[..n * f])
            .expect("scale");
        let t0 = Instant::now();
        for _ in 0..200 {
            let xb = Tensor::<3>::from_data(TensorData::new(xs[..f].to_vec(), [1, 1, f]), &device);
            std::hint::black_box(net.forward(xb).into_data());
        }
        let burn_single = t0.elapsed().as_secs_f64() / 200.0;
        let t0 = Instant::now();
        let xb = Tensor::<3>::from_data(TensorData::new(xs, [n, 1, f]), &device);
        std::hint::black_box(net.forward(xb).into_data());
        let burn_many = t0.elapsed().as_secs_f64() * 10_000.0 / n as f64;
        println!(
            "  one estimate: {:8.1} µs (burn flex forward {:8.1} µs, ratio {:.1}×)",
            single * 1e6,
            burn_single * 1e6,
            burn_single / single
        );
        println!(
            "  10,000 estimates: {many:6.3} s (burn flex forward {burn_many:6.3} s, ratio {:.1}×)",
            burn_many / many
        );
    }
}
