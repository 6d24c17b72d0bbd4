//! A small synthetic dataset for tests and benchmarks, made in memory in milliseconds: lights
//! that are random mixtures of the thesis's four Gaussian channels (G1), seen by a fixed
//! random "camera" — smooth random patch reflectances times three Gaussian sensitivities,
//! summed over wavelength, then a 1/2.2 gamma — so that learning has a real, non-linear
//! inverse problem to solve.

use crate::train::TrainingSet;
use rand::{Rng, SeedableRng};
use spdcam_core::dataset::{Columns, Precision, SampleBatch};
use spdcam_core::spectral::Grid;
use spdcam_infer::record::DataInfo;
use std::collections::BTreeMap;

/// The thesis's 4-channel Gaussian lights: (centre, width) in nm.
pub const G1_CHANNELS: [(f64, f64); 4] =
    [(430.0, 15.0), (510.0, 20.0), (590.0, 20.0), (670.0, 15.0)];

fn gaussian(l: f64, mu: f64, sigma: f64) -> f64 {
    (-(l - mu) * (l - mu) / (2.0 * sigma * sigma)).exp()
}

/// `rows` samples of a chart of `patches` patches (3 features each) under random G1 lights;
/// the camera and chart depend on `camera_seed` only, the lights on `seed`.
pub fn gaussian_set(rows: usize, patches: usize, seed: u64, camera_seed: u64) -> TrainingSet {
    let grid = Grid {
        start_nm: 380.0,
        step_nm: 5.0,
        count: 81,
    };
    let wl = grid.wavelengths();
    let mut cam = rand::rngs::SmallRng::seed_from_u64(camera_seed);
    // Smooth reflectances: sums of 3 broad bumps with random centres and heights.
    let reflectances: Vec<Vec<f64>> = (0..patches)
        .map(|_| {
            let bumps: Vec<(f64, f64, f64)> = (0..3)
                .map(|_| {
                    (
                        cam.random_range(380.0..780.0),
                        cam.random_range(30.0..90.0),
                        cam.random_range(0.05..0.6),
                    )
                })
                .collect();
            wl.iter()
                .map(|&l| {
                    let v: f64 = bumps.iter().map(|&(m, s, h)| h * gaussian(l, m, s)).sum();
                    (0.03 + v).min(1.0)
                })
                .collect()
        })
        .collect();
    let sensitivities: Vec<Vec<f64>> = [(600.0, 40.0), (540.0, 40.0), (460.0, 35.0)]
        .iter()
        .map(|&(m, s)| wl.iter().map(|&l| gaussian(l, m, s)).collect())
        .collect();
    let mut rng = rand::rngs::SmallRng::seed_from_u64(seed);
    let mut samples = SampleBatch {
        feature_count: patches * 3,
        spd_len: grid.count,
        weight_count: G1_CHANNELS.len(),
        ..SampleBatch::default()
    };
    for i in 0..rows {
        let w: Vec<f64> = G1_CHANNELS
            .iter()
            .map(|_| (rng.random_range(0.0..1.0f64) * 100.0).round() / 100.0 + 0.01)
            .collect();
        let mut spd: Vec<f64> = wl
            .iter()
            .map(|&l| {
                G1_CHANNELS
                    .iter()
                    .zip(&w)
                    .map(|(&(m, s), wi)| wi * gaussian(l, m, s))
                    .sum()
            })
            .collect();
        let max = spd.iter().copied().fold(0.0, f64::max);
        spd.iter_mut().for_each(|v| *v /= max);
        let mut raw = Vec::with_capacity(patches * 3);
        for r in &reflectances {
            for s in &sensitivities {
                raw.push(
                    spd.iter()
                        .zip(r)
                        .zip(s)
                        .map(|((a, b), c)| a * b * c)
                        .sum::<f64>(),
                );
            }
        }
        let peak = raw.iter().copied().fold(0.0, f64::max);
        samples
            .features
            .extend(raw.iter().map(|v| 255.0 * (v / peak).powf(1.0 / 2.2)));
        samples.spds.extend(spd);
        samples.weights.extend(w);
        samples.samples.push(i as u64);
        samples.families.push("gaussian".into());
        samples.attempts.push(1);
    }
    let feature_names = (1..=patches)
        .flat_map(|p| ["r", "g", "b"].map(|c| format!("p{p:02}_{c}")))
        .collect();
    TrainingSet {
        samples,
        columns: Columns {
            feature_names,
            feature_precision: Precision::Float64,
            spd_grid: grid,
            weight_names: (1..=G1_CHANNELS.len()).map(|i| format!("ch{i}")).collect(),
        },
        info: DataInfo {
            path: format!("synthetic gaussian set ({rows} samples, seed {seed})"),
            samples: rows,
            chart: Some(format!("synthetic-{patches}")),
            camera: Some("synthetic".into()),
            families: BTreeMap::from([("gaussian".to_string(), rows as u64)]),
            origin: None,
        },
    }
}
