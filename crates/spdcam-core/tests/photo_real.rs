//! Real photos of a ColorChecker 24 (shared data, `photos/`) and bad input.

#![cfg(feature = "measured-data")]

mod shared_data;

use spdcam_core::chart::Chart;
use spdcam_core::cie_illuminant::StandardIlluminant;
use spdcam_core::colorimetry::Observer;
use spdcam_core::photo::{
    analyse, analyse_photo, decode_photo, AnalyseOptions, ChartTemplate, Photo, PhotoAnalysis,
};
use spdcam_core::spectral::Grid;
use std::path::PathBuf;

const GRID: Grid = Grid::SIMULATION;

fn cc24() -> (Chart, ChartTemplate) {
    let chart = Chart::colorchecker24(&GRID).unwrap();
    let t = ChartTemplate::from_chart(&chart).unwrap();
    (chart, t)
}

fn options() -> AnalyseOptions {
    AnalyseOptions {
        templates: vec![cc24().1],
        corners: None,
        debug: None,
    }
}

fn photo_path(name: &str) -> PathBuf {
    shared_data::data_dir().join("photos").join(name)
}

fn scratch_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("spdcam-photo-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Spearman rank correlation.
fn spearman(a: &[f64], b: &[f64]) -> f64 {
    let rank = |v: &[f64]| {
        let mut idx: Vec<usize> = (0..v.len()).collect();
        idx.sort_by(|&i, &j| v[i].total_cmp(&v[j]));
        let mut r = vec![0.0; v.len()];
        for (k, &i) in idx.iter().enumerate() {
            r[i] = k as f64;
        }
        r
    };
    let (ra, rb) = (rank(a), rank(b));
    let n = a.len() as f64;
    let d2: f64 = ra.iter().zip(&rb).map(|(x, y)| (x - y).powi(2)).sum();
    1.0 - 6.0 * d2 / (n * (n * n - 1.0))
}

/// The photo's patches must follow the chart's own lightness: the neutral row strictly
/// darker from white to black, and all 24 patches ranked by lightness more like their
/// luminance under D65 than the same photo read upside down (the only other placement of a
/// 4 × 6 grid).
fn check_order(a: &PhotoAnalysis) {
    let (chart, _) = cc24();
    let obs = Observer::cie1931(&GRID).unwrap();
    let d65 = StandardIlluminant::D65.spd(&GRID).unwrap();
    let truth: Vec<f64> = (0..24)
        .map(|p| obs.reflectance_to_xyz(chart.reflectances.item(p), &d65)[1])
        .collect();
    let light: Vec<f64> = (0..24)
        .map(|p| a.features[3 * p..3 * p + 3].iter().map(|&v| v as f64).sum())
        .collect();
    for p in 18..23 {
        assert!(
            light[p] > light[p + 1] || a.patches[p].clipped,
            "{}: neutral patch {} ({:.1}) is not lighter than patch {} ({:.1})",
            a.source,
            p + 1,
            light[p],
            p + 2,
            light[p + 1]
        );
    }
    let rho = spearman(&light, &truth);
    let turned: Vec<f64> = light.iter().rev().copied().collect();
    let rho_turned = spearman(&turned, &truth);
    println!(
        "{}: lightness rank correlation with the chart {rho:.3}, upside down {rho_turned:.3}",
        a.source
    );
    assert!(
        rho > 0.5 && rho > rho_turned + 0.5,
        "{}: lightness order correlation {rho:.3}, upside down {rho_turned:.3}",
        a.source
    );
}

#[test]
fn real_photos_are_found_in_the_right_orientation() {
    for name in ["IMG_0903_025p-crop.png", "IMG_20140613_203438.jpg"] {
        let dir = scratch_dir("real");
        let mut opts = options();
        opts.debug = Some(dir.join(format!("{name}.png")));
        let a = analyse_photo(&photo_path(name), &opts).unwrap();
        println!(
            "{name}: confidence {:.2}, corners {:?}, warnings {:?}",
            a.confidence, a.corners, a.warnings
        );
        assert_eq!(a.chart, "colorchecker24");
        assert!(a.confidence >= 0.5);
        assert_eq!(a.features.len(), 72);
        check_order(&a);
        assert!(opts.debug.as_ref().unwrap().is_file());
        std::fs::remove_dir_all(dir).ok();
    }
}

#[test]
fn corners_in_any_order_give_the_detected_placement() {
    let path = photo_path("IMG_0903_025p-crop.png");
    let detected = analyse_photo(&path, &options()).unwrap();
    let mut shuffled = detected.corners.to_vec();
    shuffled.swap(0, 2);
    shuffled.swap(1, 3);
    shuffled.swap(0, 1);
    let opts = AnalyseOptions {
        corners: Some(shuffled),
        ..options()
    };
    let given = analyse_photo(&path, &opts).unwrap();
    assert_eq!(given.method, "corners");
    for k in 0..4 {
        let d = (given.corners[k][0] - detected.corners[k][0])
            .hypot(given.corners[k][1] - detected.corners[k][1]);
        assert!(d < 1e-6, "corner {k} moved by {d}");
    }
    for (a, b) in given.features.iter().zip(&detected.features) {
        assert!((a - b).abs() < 1e-3);
    }
    check_order(&given);
}

#[test]
fn bad_corners_are_clear_errors() {
    let path = photo_path("IMG_0903_025p-crop.png");
    let cases: [(&[[f64; 2]], &str); 3] = [
        (
            &[[10.0, 10.0], [300.0, 10.0], [300.0, 1000.0], [10.0, 300.0]],
            "outside",
        ),
        (
            &[[10.0, 10.0], [300.0, 10.0], [60.0, 60.0], [10.0, 300.0]],
            "convex",
        ),
        (
            &[[10.0, 10.0], [300.0, 10.0], [300.0, 300.0]],
            "four points",
        ),
    ];
    for (corners, expected) in cases {
        let opts = AnalyseOptions {
            corners: Some(corners.to_vec()),
            ..options()
        };
        let e = analyse_photo(&path, &opts).unwrap_err().to_string();
        assert!(e.contains(expected), "{e}");
    }
}

fn png_bytes(img: image::RgbImage) -> Vec<u8> {
    let mut bytes = Vec::new();
    image::DynamicImage::ImageRgb8(img)
        .write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )
        .unwrap();
    bytes
}

#[test]
fn bad_input_is_a_clear_error_and_writes_no_features() {
    let dir = scratch_dir("bad");
    // Not an image.
    let text = dir.join("notes.jpg");
    std::fs::write(&text, b"these are notes, not a photo").unwrap();
    let e = analyse_photo(&text, &options()).unwrap_err().to_string();
    assert!(
        e.contains("notes.jpg") && e.contains("not a JPEG, PNG, TIFF or camera raw image"),
        "{e}"
    );
    // A truncated JPEG.
    let full = std::fs::read(photo_path("IMG_20140613_203438.jpg")).unwrap();
    let cut = dir.join("cut.jpg");
    std::fs::write(&cut, &full[..full.len() / 3]).unwrap();
    let e = analyse_photo(&cut, &options()).unwrap_err().to_string();
    assert!(e.contains("cut.jpg"), "{e}");
    // A 1×1 image.
    let dot = dir.join("dot.png");
    std::fs::write(&dot, png_bytes(image::RgbImage::new(1, 1))).unwrap();
    let e = analyse_photo(&dot, &options()).unwrap_err().to_string();
    assert!(e.contains("1×1"), "{e}");
    // A missing file.
    let e = analyse_photo(&dir.join("missing.jpg"), &options())
        .unwrap_err()
        .to_string();
    assert!(e.contains("missing.jpg"), "{e}");
    // A photo without a chart: a failure that says so, and the debug image is written.
    let noise = image::RgbImage::from_fn(400, 300, |x, y| {
        let v = ((x * 7919 + y * 104729) % 251) as u8;
        image::Rgb([v, v / 2 + 40, 255 - v])
    });
    let photo: Photo = decode_photo(&png_bytes(noise), "no-chart.png").unwrap();
    let debug = dir.join("no-chart-debug.png");
    let opts = AnalyseOptions {
        debug: Some(debug.clone()),
        ..options()
    };
    let e = analyse(&photo, &opts).unwrap_err().to_string();
    assert!(e.contains("no chart found"), "{e}");
    assert!(
        debug.is_file(),
        "the debug image must be written when no chart is found"
    );
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains("partial"))
        .collect();
    assert!(leftovers.is_empty());
    std::fs::remove_dir_all(&dir).ok();
}
