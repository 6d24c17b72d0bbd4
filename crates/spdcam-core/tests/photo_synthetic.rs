//! Chart detection, rectification and sampling on seeded synthetic photos (see
//! `photo_support`): the chart must be found, its corners placed within a small share of a
//! patch, its orientation right, and its features equal to what an ideal camera shows of
//! the chart's flat patches; and photos by the full camera (mosaic, noise, aberration) must
//! be found and sampled close to it.

mod photo_support;
#[cfg(feature = "measured-data")]
mod shared_data;

use image::ImageEncoder;
#[cfg(feature = "measured-data")]
use photo_support::colorchecker_sg;
use photo_support::{colorchecker24, delta_e, scene, ChartSetup, SceneSize};
use rayon::prelude::*;
#[cfg(feature = "measured-data")]
use spdcam_core::builtin::DataDir;
use spdcam_core::photo::{analyse, decode_photo, AnalyseOptions, ChartTemplate};

const SIZE: SceneSize = SceneSize {
    width: 960,
    height: 720,
};

/// What one photo gave.
#[derive(Debug, Clone)]
struct Outcome {
    seed: u64,
    found: bool,
    /// Mean corner distance over the patch side.
    corner_error: f64,
    oriented: bool,
    mean_de: f64,
    max_de: f64,
    light: String,
    message: String,
}

fn run(
    setup: &ChartSetup,
    templates: &[ChartTemplate],
    seeds: std::ops::Range<u64>,
) -> Vec<Outcome> {
    let options = AnalyseOptions {
        templates: templates.to_vec(),
        corners: None,
        debug: std::env::var_os("SPDCAM_PHOTO_DEBUG")
            .map(|d| std::path::PathBuf::from(d).join(format!("{}.png", setup.template.name))),
    };
    seeds
        .into_par_iter()
        .map(|seed| {
            let s = scene(setup, seed, SIZE);
            let mut opts = options.clone();
            opts.debug = opts
                .debug
                .map(|d| d.with_file_name(format!("{}-{seed}.png", setup.template.name)));
            let r = analyse(&s.photo, &opts);
            match r {
                Ok(a) => {
                    let errs: Vec<f64> = (0..4)
                        .map(|k| {
                            (a.corners[k][0] - s.corners[k][0])
                                .hypot(a.corners[k][1] - s.corners[k][1])
                        })
                        .collect();
                    let corner_error = errs.iter().sum::<f64>() / 4.0 / s.patch_px;
                    // Right orientation: every corner is nearest its own true corner.
                    let oriented = (0..4).all(|k| {
                        (0..4).all(|j| {
                            let d = |c: [f64; 2]| {
                                (a.corners[k][0] - c[0]).hypot(a.corners[k][1] - c[1])
                            };
                            j == k || d(s.corners[k]) < d(s.corners[j])
                        })
                    });
                    let des: Vec<f64> = (0..a.features.len() / 3)
                        .map(|p| {
                            let f = |v: &[f32]| [v[3 * p], v[3 * p + 1], v[3 * p + 2]];
                            delta_e(f(&a.features), f(&s.features))
                        })
                        .collect();
                    Outcome {
                        seed,
                        found: a.chart == setup.template.name,
                        corner_error,
                        oriented,
                        mean_de: des.iter().sum::<f64>() / des.len() as f64,
                        max_de: des.iter().cloned().fold(0.0, f64::max),
                        light: s.light,
                        message: format!("confidence {:.2}", a.confidence),
                    }
                }
                Err(e) => Outcome {
                    seed,
                    found: false,
                    corner_error: f64::NAN,
                    oriented: false,
                    mean_de: f64::NAN,
                    max_de: f64::NAN,
                    light: s.light,
                    message: e.to_string(),
                },
            }
        })
        .collect()
}

fn report(name: &str, outcomes: &[Outcome]) -> (f64, f64, f64, usize) {
    let found: Vec<&Outcome> = outcomes.iter().filter(|o| o.found).collect();
    let rate = found.len() as f64 / outcomes.len() as f64;
    let corner = found.iter().map(|o| o.corner_error).sum::<f64>() / found.len().max(1) as f64;
    let de = found.iter().map(|o| o.mean_de).sum::<f64>() / found.len().max(1) as f64;
    let max_de = found.iter().map(|o| o.max_de).fold(0.0, f64::max);
    let misoriented = found.iter().filter(|o| !o.oriented).count();
    println!(
        "{name}: {} photos, found {:.1} %, mean corner error {:.2} % of a patch side, \
         mean ΔE2000 {de:.3} (worst patch {max_de:.2}), misoriented {misoriented}",
        outcomes.len(),
        100.0 * rate,
        100.0 * corner
    );
    for o in outcomes {
        if !o.found || !o.oriented || o.corner_error > 0.03 || o.mean_de > 1.0 {
            println!(
                "  seed {}: found {} oriented {} corner {:.3} ΔE {:.2}/{:.2} light {} — {}",
                o.seed,
                o.found,
                o.oriented,
                o.corner_error,
                o.mean_de,
                o.max_de,
                o.light,
                o.message
            );
        }
    }
    (rate, corner, de, misoriented)
}

fn scene_count(default: u64) -> u64 {
    std::env::var("SPDCAM_PHOTO_SCENES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// Checks the outcomes of a batch of synthetic photos: found, placed, oriented, sampled.
fn check(outcomes: &[Outcome]) {
    let (rate, corner, de, misoriented) = report("all", outcomes);
    assert!(
        rate >= 0.98,
        "chart found in only {:.1} % of the photos",
        100.0 * rate
    );
    assert!(corner < 0.03, "mean corner error {:.3} patch sides", corner);
    assert!(de < 1.0, "mean ΔE2000 {de:.3}");
    let off: Vec<u64> = outcomes
        .iter()
        .filter(|o| o.found && o.mean_de >= 1.0)
        .map(|o| o.seed)
        .collect();
    assert!(
        off.is_empty(),
        "photos whose features are ΔE2000 ≥ 1 off: {off:?}"
    );
    assert_eq!(misoriented, 0, "charts found upside down or turned");
}

#[test]
fn colorchecker24_photos_are_found_rectified_and_sampled() {
    let cc24 = colorchecker24();
    let templates = vec![cc24.template.clone()];
    let start = std::time::Instant::now();
    let outcomes = run(&cc24, &templates, 0..scene_count(150));
    println!(
        "{} photos in {:.1} s",
        outcomes.len(),
        start.elapsed().as_secs_f64()
    );
    check(&outcomes);
}

/// Both charts looked for in every photo, so neither is taken for the other; the Digital
/// SG's reflectances come from the measured data.
#[cfg(feature = "measured-data")]
#[test]
fn synthetic_photos_of_both_charts_are_found_rectified_and_sampled() {
    let data = DataDir::new(Some(shared_data::data_dir()));
    let cc24 = colorchecker24();
    let sg = colorchecker_sg(&data);
    let templates = vec![cc24.template.clone(), sg.template.clone()];
    let n = scene_count(200);
    let n_sg = n / 4;
    let mut outcomes = run(&cc24, &templates, 0..n - n_sg);
    report("ColorChecker 24", &outcomes);
    let sg_outcomes = run(&sg, &templates, 10_000..10_000 + n_sg);
    report("ColorChecker SG", &sg_outcomes);
    outcomes.extend(sg_outcomes);
    check(&outcomes);
}

/// A minimal big-endian EXIF (TIFF) block holding only the orientation tag.
fn exif_orientation(value: u16) -> Vec<u8> {
    let mut e = b"MM\0\x2a".to_vec();
    e.extend_from_slice(&8u32.to_be_bytes());
    e.extend_from_slice(&1u16.to_be_bytes());
    e.extend_from_slice(&0x0112u16.to_be_bytes());
    e.extend_from_slice(&3u16.to_be_bytes());
    e.extend_from_slice(&1u32.to_be_bytes());
    e.extend_from_slice(&value.to_be_bytes());
    e.extend_from_slice(&[0, 0, 0, 0, 0, 0]);
    e
}

#[test]
fn exif_orientation_is_honoured() {
    let cc24 = colorchecker24();
    let s = scene(&cc24, 7, SIZE);
    // Store the photo turned a quarter left, tagged "rotate 90° clockwise to display".
    let stored = image::load_from_memory(&s.jpeg)
        .unwrap()
        .rotate270()
        .to_rgb8();
    let mut jpeg = Vec::new();
    let mut encoder = image::codecs::jpeg::JpegEncoder::new_with_quality(&mut jpeg, 95);
    encoder.set_exif_metadata(exif_orientation(6)).unwrap();
    encoder
        .write_image(
            stored.as_raw(),
            stored.width(),
            stored.height(),
            image::ExtendedColorType::Rgb8,
        )
        .unwrap();
    let photo = decode_photo(&jpeg, "turned.jpg").unwrap();
    assert_eq!((photo.width, photo.height), (SIZE.width, SIZE.height));
    let options = AnalyseOptions {
        templates: vec![cc24.template.clone()],
        ..AnalyseOptions::default()
    };
    let a = analyse(&photo, &options).unwrap();
    for k in 0..4 {
        let d = (a.corners[k][0] - s.corners[k][0]).hypot(a.corners[k][1] - s.corners[k][1]);
        assert!(d < 0.1 * s.patch_px, "corner {k} is {d:.1} px off");
    }
}

/// The full camera chain (Bayer mosaic, thesis noise, Menon demosaicing, aberration) under
/// daylight and tungsten: every chart is found and its features stay close to the
/// noise-free flat-patch truth (demosaicing and noise move them a little, never far).
#[test]
fn photos_by_the_full_camera_are_found_and_sampled_close_to_the_truth() {
    use spdcam_core::camera::{Camera, CameraConfig};
    use spdcam_core::chart::Chart;
    use spdcam_core::cie_illuminant::StandardIlluminant;
    use spdcam_core::photo::scene::{self, SceneLight, SceneOptions};
    use spdcam_core::spectral::Grid;
    let grid = Grid::SIMULATION;
    let chart = Chart::colorchecker24(&grid).unwrap();
    let template = ChartTemplate::from_chart(&chart).unwrap();
    let chart = chart.with_layout(scene::scene_layout(&template)).unwrap();
    let set = spdcam_core::builtin::CAMERAS[0].load().unwrap();
    let sens =
        spdcam_core::camera::sensor::Sensitivities::new("nikon_d5100_npl", &set, &grid).unwrap();
    let camera = Camera::new(&sens, chart, CameraConfig::default(), &grid).unwrap();
    let options = SceneOptions {
        width: SIZE.width,
        height: SIZE.height,
        width_share: (0.3, 0.6),
        ..SceneOptions::default()
    };
    let analyse_options = AnalyseOptions {
        templates: vec![template],
        ..AnalyseOptions::default()
    };
    let lights = [StandardIlluminant::D65, StandardIlluminant::A].map(|l| l.spd(&grid).unwrap());
    let errors: Vec<f64> = (0..8u64)
        .into_par_iter()
        .map(|seed| {
            let spd = &lights[seed as usize % 2];
            let shot = scene::photograph(&camera, SceneLight::single(spd), seed, &options).unwrap();
            let photo = decode_photo(&shot.jpeg, "full.jpg").unwrap();
            let a = analyse(&photo, &analyse_options).unwrap();
            let f = |v: &[f32], p: usize| [v[3 * p], v[3 * p + 1], v[3 * p + 2]];
            (0..a.features.len() / 3)
                .map(|p| delta_e(f(&a.features, p), f(&shot.expected_features, p)))
                .sum::<f64>()
                / (a.features.len() / 3) as f64
        })
        .collect();
    println!("mean ΔE2000 per photo: {errors:.2?}");
    assert!(errors.iter().all(|&e| e < 1.5), "{errors:.2?}");
}
