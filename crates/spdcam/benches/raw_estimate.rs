//! Speed of `spdcam estimate` on one 24-megapixel raw file (issue: a raw file to a judged
//! SPD in at most twice the time the decoder alone takes to read it). The virtual camera
//! photographs the ColorChecker 24 in a 6000 × 4000 scene under CIE D65 and writes the
//! sensor's mosaic as a DNG (`spdcam render --scene 6000x4000 -o x.dng`).
//!
//! Prints the median of runs of the whole estimate (decoding, the preview, detection, the
//! patches read on the mosaic, the model, the trust stage, the metrics) beside the baseline
//! run in the same process: decoding the file alone into its mosaic.
//! `cargo bench -p spdcam --bench raw_estimate`.

use spdcam_core::builtin::{self, DataDir};
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::{Camera, CameraConfig};
use spdcam_core::chart::Chart;
use spdcam_core::cie_illuminant::StandardIlluminant;
use spdcam_core::photo::raw::dng::virtual_camera_dng;
use spdcam_core::photo::scene::{self, SceneLight, SceneOptions};
use spdcam_core::photo::ChartTemplate;
use spdcam_core::spectral::Grid;
use spdcam_infer::{Estimator, PhotoOptions};
use std::hint::black_box;
use support::median;

// Only `median` and the photo size of the shared support are used here.
#[allow(dead_code)]
#[path = "../../spdcam-core/benches/support/mod.rs"]
mod support;

/// The ColorChecker 24's template, as the estimator searches for it.
fn template() -> ChartTemplate {
    let chart = Chart::colorchecker24(&Grid::SIMULATION).expect("chart");
    ChartTemplate::from_chart(&chart).expect("template")
}

/// The 24-megapixel DNG of the ColorChecker 24 in a scene under D65.
fn dng() -> Vec<u8> {
    let grid = Grid::SIMULATION;
    let table = &builtin::CAMERAS[0];
    let sensitivities =
        Sensitivities::new(table.name, &table.load().expect("camera"), &grid).expect("camera");
    let chart = Chart::colorchecker24(&grid).expect("chart");
    let template = ChartTemplate::from_chart(&chart).expect("template");
    let chart = chart
        .with_layout(scene::scene_layout(&template))
        .expect("layout");
    let camera =
        Camera::new(&sensitivities, chart, CameraConfig::default(), &grid).expect("camera");
    let d65 = StandardIlluminant::D65.spd(&grid).expect("D65");
    let options = SceneOptions {
        width: support::WIDTH as usize,
        height: support::HEIGHT as usize,
        ..SceneOptions::default()
    };
    let shot = scene::photograph(&camera, SceneLight::single(&d65), 1, &options).expect("scene");
    virtual_camera_dng(&camera, &d65, shot.mosaic.as_ref().expect("a mosaic"), None).expect("DNG")
}

fn main() {
    let bytes = dng();
    let estimator = Estimator::shipped(DataDir::default(), Grid::ESTIMATION).expect("estimator");
    let options = PhotoOptions::default();
    let estimate = estimator
        .estimate_photo_bytes(&bytes, "bench.dng", &options)
        .expect("an estimate");
    assert!(estimate
        .photo
        .as_ref()
        .and_then(|p| p.raw.as_ref())
        .is_some());
    let decoder = median(5, || {
        black_box(spdcam_core::photo::raw::decode(&bytes, "bench.dng").expect("decoded"));
    });
    let photo = spdcam_core::photo::decode_photo(&bytes, "bench.dng").expect("decoded");
    let decoded = median(5, || {
        black_box(spdcam_core::photo::decode_photo(&bytes, "bench.dng").expect("decoded"));
    });
    let templates = vec![template()];
    let detection = median(5, || {
        black_box(spdcam_core::photo::detect_all(&photo, &templates).expect("search"));
    });
    let whole = median(5, || {
        black_box(
            estimator
                .estimate_photo_bytes(&bytes, "bench.dng", &options)
                .expect("estimate"),
        );
    });
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
    println!(
        "24-megapixel DNG ({} MB) → judged SPD, median of runs:",
        bytes.len() / 1_000_000
    );
    println!(
        "  baseline: decoding the raw file     {:8.1} ms",
        ms(decoder)
    );
    println!(
        "  the decoding and its preview        {:8.1} ms",
        ms(decoded)
    );
    println!(
        "  detection on the preview            {:8.1} ms",
        ms(detection)
    );
    println!(
        "  whole estimate                      {:8.1} ms  ({:.2}× the baseline; target ≤ 2)",
        ms(whole),
        whole.as_secs_f64() / decoder.as_secs_f64()
    );
}
