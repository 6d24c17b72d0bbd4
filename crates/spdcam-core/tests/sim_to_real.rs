//! Does the virtual camera explain real photos? The thesis's measured Telelumen set (640
//! JPEGs by a Canon EOS 5D Mark IV, each with the spectroradiometer SPD of its light) against
//! the patch-level virtual camera fed with those SPDs.
//!
//! The correspondence of the 96 SG reflectances to the features of the photos: the
//! reflectance file lists the chart's centre patches column by column (B2…B9, C2…C9, …),
//! the photos' features run row by row. Ranking the patches by lightness, real against
//! rendered, tells the two orders apart: only the chart's physical order
//! (`colorchecker_sg96`) makes the real and the virtual ranks agree.

#![cfg(feature = "measured-data")]

mod shared_data;

use spdcam_core::builtin::{self, DataDir};
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::{Camera, CameraConfig};
use spdcam_core::chart::Chart;
use spdcam_core::spectral::{Extrapolation, Grid, Interpolation, SpectralSet};

const GRID: Grid = Grid::SIMULATION;

/// Rows of a numeric CSV with a header (features or SPDs of the measured sets).
fn read_rows(path: &std::path::Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(|c| c.trim().parse().unwrap()).collect())
        .collect();
    (header, rows)
}

fn ranks(values: &[f64]) -> Vec<f64> {
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
    let mut r = vec![0.0; values.len()];
    for (rank, &i) in order.iter().enumerate() {
        r[i] = rank as f64;
    }
    r
}

/// Spearman's rank correlation (no ties expected in continuous data).
fn spearman(a: &[f64], b: &[f64]) -> f64 {
    let (ra, rb) = (ranks(a), ranks(b));
    let n = a.len() as f64;
    let mean = (n - 1.0) / 2.0;
    let cov: f64 = ra
        .iter()
        .zip(&rb)
        .map(|(x, y)| (x - mean) * (y - mean))
        .sum();
    let var: f64 = ra.iter().map(|x| (x - mean).powi(2)).sum();
    cov / var
}

/// Mean rank correlation of the green features, real against rendered, over the photos.
fn agreement(chart_name: &str) -> f64 {
    let root = shared_data::data_dir();
    let data_dir = DataDir::new(Some(root.clone()));
    let (_, set) = builtin::resolve_table(
        "canon_eos_5d_mark_ii",
        "camera",
        &[],
        &data_dir,
        &["thesis"],
    )
    .unwrap();
    let sensitivities = Sensitivities::new("canon_eos_5d_mark_ii", &set, &GRID).unwrap();
    let chart = Chart::resolve(chart_name, None, &data_dir, &GRID).unwrap();
    let config = CameraConfig {
        noise: None,
        ..CameraConfig::default()
    };
    let camera = Camera::new(&sensitivities, chart, config, &GRID).unwrap();
    let dev = root.join("thesis/measured/telelumen_canon5d4_dev");
    let (_, features) = read_rows(&dev.join("features.csv"));
    let (header, spds) = read_rows(&dev.join("spds.csv"));
    let wavelengths: Vec<f64> = header.iter().map(|h| h.parse().unwrap()).collect();
    let names: Vec<String> = (0..spds.len()).map(|i| format!("s{i}")).collect();
    let columns: Vec<Vec<f64>> = spds.clone();
    let set = SpectralSet::new(wavelengths, names, columns).unwrap();
    let (set, _) = set
        .resample(&GRID, Interpolation::Linear, Extrapolation::Zero)
        .unwrap();
    let mut raw = Vec::new();
    let mut rendered = Vec::new();
    let photos = 160;
    let total: f64 = (0..photos)
        .map(|i| {
            rendered.clear();
            let light = camera.light(&set.spd(i).unwrap()).unwrap();
            camera.features_fast(&light, &mut raw, &mut rendered);
            let green = |v: &[f32]| {
                v.iter()
                    .skip(1)
                    .step_by(3)
                    .map(|&x| f64::from(x))
                    .collect::<Vec<_>>()
            };
            let real: Vec<f64> = features[i].iter().skip(1).step_by(3).copied().collect();
            spearman(&real, &green(&rendered))
        })
        .sum();
    total / photos as f64
}

#[test]
fn real_photos_follow_the_charts_physical_patch_order() {
    let physical = agreement("colorchecker_sg96");
    let file_order = agreement("colorchecker_sg96_thesis");
    println!("rank agreement of real and rendered patches: physical order {physical:.3}, file order {file_order:.3}");
    assert!(physical > 0.7, "physical order: {physical}");
    assert!(file_order.abs() < 0.2, "file order: {file_order}");
}

#[test]
fn sg96_features_are_the_centre_patches_of_the_full_sg() {
    // Two independent measurements of the same chart: the thesis's 96 centre patches
    // (i1Pro2) and the full 140-patch SG. Feature k of both must be the same surface.
    let data_dir = DataDir::new(Some(shared_data::data_dir()));
    let sg96 = Chart::resolve("colorchecker_sg96", None, &data_dir, &GRID).unwrap();
    let sg140 = Chart::resolve("colorchecker_sg140", None, &data_dir, &GRID).unwrap();
    let rms = |a: &[f64], b: &[f64]| {
        (a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / a.len() as f64).sqrt()
    };
    let mut nearest_at_same_position = 0;
    let mut differences = Vec::new();
    for (k, &p) in sg140.feature_patches.iter().enumerate() {
        let ours = sg96.reflectances.item(sg96.feature_patches[k]);
        let same = rms(ours, sg140.reflectances.item(p));
        let closest = sg140
            .feature_patches
            .iter()
            .map(|&q| rms(ours, sg140.reflectances.item(q)))
            .fold(f64::INFINITY, f64::min);
        nearest_at_same_position += usize::from(same <= closest + 1e-12);
        differences.push(same);
    }
    differences.sort_by(f64::total_cmp);
    let median = differences[differences.len() / 2];
    println!(
        "same surface at the same position: {nearest_at_same_position} of 96 nearest, median RMS difference {median:.4}"
    );
    assert!(nearest_at_same_position >= 85, "{nearest_at_same_position}");
    assert!(median < 0.015, "{median}");
    let template =
        spdcam_core::photo::ChartTemplate::for_chart("colorchecker_sg96", &data_dir, &GRID)
            .unwrap();
    assert_eq!((template.rows, template.cols), (10, 14));
    assert_eq!(template.feature_patches, sg140.feature_patches);
    assert!(spdcam_core::photo::ChartTemplate::for_chart(
        "colorchecker_sg96_thesis",
        &data_dir,
        &GRID
    )
    .is_none());
}
