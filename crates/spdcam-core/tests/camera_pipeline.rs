//! The whole virtual camera against independent expectations.

#[cfg(feature = "measured-data")]
mod shared_data;

use spdcam_core::builtin::{self, DataDir};
use spdcam_core::camera::demosaic::{demosaic, DemosaicMethod};
use spdcam_core::camera::sensor::{Sensitivities, SensorMode};
use spdcam_core::camera::{Camera, CameraConfig};
use spdcam_core::chart::Chart;
use spdcam_core::cie_illuminant::StandardIlluminant;
use spdcam_core::colorimetry::{self, Observer};
use spdcam_core::raster::{CfaPattern, Mosaic, RgbImage};
use spdcam_core::spectral::Grid;

const GRID: Grid = Grid::SIMULATION;

fn nikon() -> Sensitivities {
    let set = builtin::CAMERAS[0].load().unwrap();
    Sensitivities::new("nikon_d5100_npl", &set, &GRID).unwrap()
}

fn noise_free() -> CameraConfig {
    CameraConfig {
        noise: None,
        ..CameraConfig::default()
    }
}

/// The chart's true sRGB (0–1, encoded) under D65 from its reflectances.
fn true_srgb(chart: &Chart) -> Vec<[f64; 3]> {
    let obs = Observer::cie1931(&GRID).unwrap();
    let d65 = StandardIlluminant::D65.spd(&GRID).unwrap();
    chart
        .feature_patches
        .iter()
        .map(|&p| {
            let xyz = obs.reflectance_to_xyz(chart.reflectances.item(p), &d65);
            colorimetry::xyz_to_linear_srgb(xyz)
                .map(|v| colorimetry::srgb_encode(v.clamp(0.0, 1.0)))
        })
        .collect()
}

fn lab_of_srgb(rgb: [f64; 3], white: [f64; 3]) -> [f64; 3] {
    let lin = rgb.map(colorimetry::srgb_decode);
    colorimetry::xyz_to_lab(colorimetry::linear_srgb_to_xyz(lin), white)
}

fn mean_delta_e(features: &[f32], truth: &[[f64; 3]]) -> (f64, f64) {
    let white = colorimetry::linear_srgb_to_xyz([1.0, 1.0, 1.0]);
    let des: Vec<f64> = truth
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let r = [0, 1, 2].map(|c| features[3 * i + c] as f64 / 255.0);
            colorimetry::delta_e_2000(lab_of_srgb(r, white), lab_of_srgb(*t, white))
        })
        .collect();
    let max = des.iter().cloned().fold(0.0, f64::max);
    (des.iter().sum::<f64>() / des.len() as f64, max)
}

#[test]
fn d65_render_reproduces_the_chart_colours() {
    let chart = Chart::colorchecker24(&GRID).unwrap();
    let truth = true_srgb(&chart);
    let camera = Camera::new(&nikon(), chart, noise_free(), &GRID).unwrap();
    let d65 = StandardIlluminant::D65.spd(&GRID).unwrap();
    let rendering = camera.render(&d65, 0, false).unwrap();
    let (mean, max) = mean_delta_e(&rendering.features, &truth);
    println!(
        "ColorChecker 24 under D65, Nikon D5100, noise off: mean ΔE2000 {mean:.3}, max {max:.3}"
    );
    assert!(mean <= 2.0, "mean ΔE2000 {mean}");
}

#[cfg(feature = "measured-data")]
#[test]
fn d65_render_with_the_thesis_camera_and_sg() {
    let data = DataDir::new(Some(shared_data::data_dir()));
    let (name, set) = builtin::resolve_table(
        "canon_eos_5d_mark_ii_mod_bw486",
        "camera",
        &[],
        &data,
        &["thesis"],
    )
    .unwrap();
    let canon = Sensitivities::new(&name, &set, &GRID).unwrap();
    for chart_name in ["colorchecker24", "colorchecker_sg96", "colorchecker_sg140"] {
        let chart = Chart::resolve(chart_name, None, &data, &GRID).unwrap();
        let truth = true_srgb(&chart);
        let camera = Camera::new(&canon, chart, noise_free(), &GRID).unwrap();
        let d65 = StandardIlluminant::D65.spd(&GRID).unwrap();
        let rendering = camera.render(&d65, 0, false).unwrap();
        let (mean, max) = mean_delta_e(&rendering.features, &truth);
        println!("{chart_name} under D65, Canon 5D Mark II BW486, noise off: mean ΔE2000 {mean:.3}, max {max:.3}");
        assert!(mean <= 2.0, "{chart_name}: mean ΔE2000 {mean}");
    }
}

#[test]
fn fast_features_match_the_noise_free_image_pipeline() {
    use spdcam_core::camera::white_balance::WhiteBalance;
    // The paths differ by 8-bit quantisation only (and the aberration's sub-pixel shift,
    // which stays far inside the sampled region), white balance included: its statistics
    // come from the binned raw mosaic, which the patch-level path reproduces exactly.
    let plain = CameraConfig {
        white_balance: WhiteBalance::None,
        aberration: None,
        ..noise_free()
    };
    for (config, max_tolerance, mean_tolerance) in
        [(plain, 0.51f32, 0.3f32), (noise_free(), 0.75, 0.35)]
    {
        let chart = Chart::colorchecker24(&GRID).unwrap();
        let camera = Camera::new(&nikon(), chart, config, &GRID).unwrap();
        for spd in ["A", "cct:9000", "D50"] {
            let spd =
                spdcam_core::named_light::resolve_spd(spd, &DataDir::default(), &GRID).unwrap();
            let full = camera.render(&spd.spd, 0, false).unwrap().features;
            let light = camera.light(&spd.spd).unwrap();
            let mut fast = Vec::new();
            camera.features_fast(&light, &mut Vec::new(), &mut fast);
            assert_eq!(full.len(), fast.len());
            let diffs: Vec<f32> = full.iter().zip(&fast).map(|(a, b)| (a - b).abs()).collect();
            let max = diffs.iter().cloned().fold(0.0, f32::max);
            let mean = diffs.iter().sum::<f32>() / diffs.len() as f32;
            println!(
                "fast vs full, {}, {:?}: mean {mean:.2}, max {max:.2} levels",
                spd.name, config.white_balance
            );
            assert!(
                max <= max_tolerance && mean <= mean_tolerance,
                "{}: mean {mean}, max {max}",
                spd.name
            );
        }
    }
}

#[test]
fn noisy_renders_are_reproducible_and_seed_dependent() {
    let chart = Chart::colorchecker24(&GRID).unwrap();
    let camera = Camera::new(&nikon(), chart, CameraConfig::default(), &GRID).unwrap();
    let a_spd = StandardIlluminant::A.spd(&GRID).unwrap();
    let one = camera.render(&a_spd, 5, false).unwrap();
    let two = camera.render(&a_spd, 5, false).unwrap();
    let other = camera.render(&a_spd, 6, false).unwrap();
    assert_eq!(one.image, two.image);
    assert_ne!(one.image, other.image);
    // The features-only path gives exactly the features of the full render.
    let light = camera.light(&a_spd).unwrap();
    let mut buffers = camera.buffers();
    let mut features = Vec::new();
    camera.render_features_into(&light, 5, &mut buffers, &mut features);
    assert_eq!(features, one.features);
}

#[test]
fn white_balance_neutralises_the_light() {
    let chart = Chart::colorchecker24(&GRID).unwrap();
    let camera = Camera::new(&nikon(), chart, noise_free(), &GRID).unwrap();
    let a_spd = StandardIlluminant::A.spd(&GRID).unwrap();
    let features = camera.render(&a_spd, 0, false).unwrap().features;
    // Patch 22 (neutral 5): R, G, B within a few levels after shades-of-grey balance.
    let n5 = &features[21 * 3..21 * 3 + 3];
    let spread =
        n5.iter().cloned().fold(f32::MIN, f32::max) - n5.iter().cloned().fold(f32::MAX, f32::min);
    assert!(spread < 12.0, "neutral 5 under A: {n5:?}");
}

fn psnr(a: &RgbImage, b: &RgbImage, border: usize) -> f64 {
    let mut se = 0.0;
    let mut n = 0usize;
    for c in 0..3 {
        for y in border..a.height - border {
            for x in border..a.width - border {
                let i = y * a.width + x;
                se += ((a.planes[c][i] - b.planes[c][i]) as f64).powi(2);
                n += 1;
            }
        }
    }
    10.0 * (1.0 / (se / n as f64)).log10()
}

#[test]
fn demosaicing_quality_on_a_rendered_chart() {
    // A ColorChecker as it is built: patches on a black body with gaps between them.
    let chart = Chart::colorchecker24(&GRID)
        .unwrap()
        .with_layout(spdcam_core::chart::Layout::grid(4, 6, 24, 4, 8))
        .unwrap();
    let config = CameraConfig {
        noise: None,
        aberration: None,
        white_balance: spdcam_core::camera::white_balance::WhiteBalance::None,
        colour: spdcam_core::camera::colour::ColourConfig {
            correction: false,
            bit_depth: 16,
        },
        ..CameraConfig::default()
    };
    let mut three = config;
    three.sensor.mode = SensorMode::ThreeSensor;
    let camera = Camera::new(&nikon(), chart, three, &GRID).unwrap();
    let d65 = StandardIlluminant::D65.spd(&GRID).unwrap();
    let truth = camera
        .render(&d65, 0, true)
        .unwrap()
        .stages
        .demosaiced
        .unwrap();
    let mosaic = Mosaic::from_rgb(&truth, CfaPattern::Rggb);
    let scores: Vec<(DemosaicMethod, f64)> = DemosaicMethod::ALL
        .iter()
        .map(|&m| (m, psnr(&demosaic(&mosaic, m), &truth, 4)))
        .collect();
    println!("demosaicing PSNR on a ColorChecker 24 render: {scores:?}");
    let get = |m| scores.iter().find(|(k, _)| *k == m).unwrap().1;
    assert!(get(DemosaicMethod::Menon2007) >= get(DemosaicMethod::Malvar2004));
    assert!(get(DemosaicMethod::Malvar2004) > get(DemosaicMethod::Bilinear));
}

#[test]
fn thesis_white_balance_statistics_see_demosaicing_overshoot() {
    use spdcam_core::camera::WhiteBalanceStatistics;
    let chart = Chart::colorchecker24(&GRID).unwrap();
    let thesis = CameraConfig {
        white_balance_statistics: WhiteBalanceStatistics::Demosaiced,
        aberration: None,
        ..noise_free()
    };
    let a_spd = StandardIlluminant::A.spd(&GRID).unwrap();
    let gains = |config: CameraConfig| {
        let camera = Camera::new(&nikon(), chart.clone(), config, &GRID).unwrap();
        camera.render(&a_spd, 0, false).unwrap().white_balance_gains
    };
    let raw = gains(CameraConfig {
        aberration: None,
        ..noise_free()
    });
    let demosaiced = gains(thesis);
    // Menon's blue overshoot at edges under A raises the blue estimate: a smaller blue gain.
    assert!(demosaiced[2] < raw[2] * 0.97, "{demosaiced:?} vs {raw:?}");
    assert_eq!(raw[1], 1.0);
}

/// The typical camera colour matrix with which detection undoes the lens's colour fringes
/// (`spdcam_core::photo::TYPICAL_CAMERA_TO_SRGB`) is the element-wise median of the D65-fitted
/// matrices of the measured cameras, each row scaled to sum to 1 (white stays white).
#[cfg(feature = "measured-data")]
#[test]
fn the_typical_camera_matrix_is_the_median_of_the_measured_cameras() {
    use spdcam_core::camera::colour::xyz_to_srgb_matrix;
    use spdcam_core::photo::TYPICAL_CAMERA_TO_SRGB;
    let dir = shared_data::data_dir().join("cameras");
    let data = DataDir::new(Some(shared_data::data_dir()));
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "csv"))
        .collect();
    names.sort();
    let mut matrices = Vec::new();
    for path in &names {
        // Tables the camera cannot use (too few bands) are left out, as training does.
        let Ok(s) = Sensitivities::resolve(&path.to_string_lossy(), &data, &GRID) else {
            continue;
        };
        let chart = Chart::colorchecker24(&GRID).unwrap();
        let camera = Camera::new(&s, chart, noise_free(), &GRID).unwrap();
        let m = xyz_to_srgb_matrix() * camera.correction_matrix().unwrap();
        let rows: [[f64; 3]; 3] = std::array::from_fn(|i| {
            let sum: f64 = (0..3).map(|j| m[(i, j)]).sum();
            std::array::from_fn(|j| m[(i, j)] / sum)
        });
        matrices.push(rows);
    }
    assert!(matrices.len() >= 40, "{} cameras", matrices.len());
    for i in 0..3 {
        for j in 0..3 {
            let mut v: Vec<f64> = matrices.iter().map(|m| m[i][j]).collect();
            v.sort_by(f64::total_cmp);
            let median = 0.5 * (v[(v.len() - 1) / 2] + v[v.len() / 2]);
            println!("({i}, {j}): median {median:.3} over {} cameras", v.len());
            assert!(
                (TYPICAL_CAMERA_TO_SRGB[i][j] - median).abs() < 0.0015,
                "({i}, {j}): {} against the median {median:.4}",
                TYPICAL_CAMERA_TO_SRGB[i][j]
            );
        }
    }
}
