//! Detection where charts are hard to find, on the program's own scene photos
//! (`spdcam_core::photo::detection_rate`): tilted to 70°, a fifteenth of the frame wide,
//! partly shadowed; and with corners given, the chart whose patches fit them is chosen.
//! A few photos per bucket at 1600×1200 by the default camera (docs/detection.md has more).

#[cfg(feature = "measured-data")]
mod shared_data;

use spdcam_core::builtin::{self, DataDir};
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::{Camera, CameraConfig};
use spdcam_core::chart::Chart;
use spdcam_core::cie_illuminant;
use spdcam_core::photo::detection_rate::{self, BucketRate, Difficulty};
use spdcam_core::photo::scene::{self, SceneLight};
use spdcam_core::photo::{analyse, decode_photo, AnalyseOptions, ChartTemplate};
use spdcam_core::spectral::Grid;

const GRID: Grid = Grid::SIMULATION;
const SIZE: (usize, usize) = (1600, 1200);
/// Photos per bucket here.
const PHOTOS: usize = 3;

/// The default camera photographing `chart` laid out for scenes, and its template.
fn camera(chart: Chart) -> (Camera, ChartTemplate) {
    let template = ChartTemplate::from_chart(&chart).unwrap();
    let chart = chart.with_layout(scene::scene_layout(&template)).unwrap();
    let set = builtin::CAMERAS[0].load().unwrap();
    let sens = Sensitivities::new("nikon_d5100_npl", &set, &GRID).unwrap();
    let camera = Camera::new(&sens, chart, CameraConfig::default(), &GRID).unwrap();
    (camera, template)
}

/// Every bucket for `camera`, searched for among `templates`: each must be found in every
/// photo but the misses `tolerated` (per bucket label), with a mean corner error within
/// 2 % of a patch side (3 % at 1/12 of the width and under 25 % light, 4 % at 1/15).
/// (The goals are 99 % found and 2 %; docs/detection.md says how far they are met.)
fn every_bucket_found(camera: &Camera, templates: &[ChartTemplate], tolerated: &[(&str, usize)]) {
    let rates: Vec<BucketRate> = detection_rate::buckets()
        .iter()
        .map(|b| detection_rate::measure(camera, templates, b, PHOTOS, 7, SIZE).unwrap())
        .collect();
    println!("{}", detection_rate::markdown_table(&rates));
    for r in &rates {
        let may_miss = tolerated
            .iter()
            .find(|(label, _)| *label == r.bucket.label)
            .map_or(0, |t| t.1);
        assert!(
            r.found + may_miss >= r.photos,
            "{} {} {}: {:?}",
            r.chart,
            r.bucket.difficulty.label(),
            r.bucket.label,
            r.misses
        );
        // The smallest charts' patches are 18 px apart (the ColorChecker 24 at 1/15) or 7.6
        // (the SG): seed 7's photos there are placed 2.2 and 1.9 % of a patch side off on
        // average (the SG's at 1/12, 9.5 px apart, 1.5 %; before the last refinement pass
        // read the edges' gradient, 3.4 %); docs/detection.md has 20 photos each.
        // Under 25 % light, where the shadow's soft edge crosses the chart the refinement
        // can settle a few pixels off: seed 7's three ColorChecker 24 photos are 3.3, 0.6 and
        // 2.7 % off (docs/detection.md's 20 photos 0.9 % on average).
        let bound = match r.bucket.label.as_str() {
            "1/15" => 0.04,
            "1/12" | "25 % light" => 0.03,
            _ => 0.02,
        };
        assert!(
            r.mean_corner_error <= bound,
            "{} {} {}: corner error {:.3} of a patch side",
            r.chart,
            r.bucket.difficulty.label(),
            r.bucket.label,
            r.mean_corner_error
        );
    }
    for d in [Difficulty::Size, Difficulty::Tilt, Difficulty::Shadow] {
        assert!(rates.iter().any(|r| r.bucket.difficulty == d));
    }
}

#[test]
fn colorchecker24_is_found_tilted_small_and_shadowed() {
    let (camera, template) = camera(Chart::colorchecker24(&GRID).unwrap());
    every_bucket_found(&camera, &[template], &[]);
}

#[cfg(feature = "measured-data")]
#[test]
fn both_charts_are_found_tilted_small_and_shadowed_among_each_other() {
    let data = DataDir::new(Some(shared_data::data_dir()));
    let (cc24, t24) = camera(Chart::colorchecker24(&GRID).unwrap());
    let (sg, tsg) = camera(Chart::resolve("colorchecker_sg140", None, &data, &GRID).unwrap());
    let templates = [tsg, t24];
    // The SG at 1/15 of the width (patches 7 px apart) is found in 132 of 140 photos of
    // seeds 1–7 (94 %): the misses lie in the frame's corners, where the lens's colour
    // fringes are half a patch wide. One of seed 7's three is among them.
    every_bucket_found(&sg, &templates, &[("1/15", 1)]);
    every_bucket_found(&cc24, &templates, &[]);
}

/// A scene of `camera`'s chart at 1/8 of the width tilted 60°, and its true corners.
fn tilted_scene(camera: &Camera, seed: u64) -> (spdcam_core::photo::Photo, [[f64; 2]; 4]) {
    let bucket = &detection_rate::buckets()[7];
    let (mut options, cct) = bucket.scene(seed, SIZE.0, SIZE.1);
    options.width_share = (0.2, 0.2);
    let spd = cie_illuminant::planck(cct, &GRID).unwrap();
    let shot = scene::photograph(camera, SceneLight::single(&spd), seed, &options).unwrap();
    let photo = decode_photo(&shot.jpeg, "tilted.jpg").unwrap();
    (photo, shot.corners)
}

#[cfg(feature = "measured-data")]
#[test]
fn with_corners_the_chart_whose_patches_fit_them_is_chosen() {
    // Issue 28: a foreshortened ColorChecker 24 with --corners alone was read as the SG
    // (the first chart), confidence 0.00.
    let data = DataDir::new(Some(shared_data::data_dir()));
    let (cc24, t24) = camera(Chart::colorchecker24(&GRID).unwrap());
    let (sg, tsg) = camera(Chart::resolve("colorchecker_sg140", None, &data, &GRID).unwrap());
    for (camera, name) in [(&cc24, "colorchecker24"), (&sg, "colorchecker_sg140")] {
        for order in [[&tsg, &t24], [&t24, &tsg]] {
            let (photo, corners) = tilted_scene(camera, 11);
            // Corners given in another order than the chart's, rounded as a person clicks.
            let given: Vec<[f64; 2]> = [2, 0, 3, 1]
                .iter()
                .map(|&k| corners[k].map(f64::round))
                .collect();
            let options = AnalyseOptions {
                templates: order.iter().map(|t| (*t).clone()).collect(),
                corners: Some(given),
                debug: None,
            };
            let a = analyse(&photo, &options).unwrap();
            assert_eq!(a.chart, name, "templates {:?}", order.map(|t| &t.name));
            assert_eq!(a.method, "corners");
            // The SG's fine grid fits the corners of this scene less tightly (0.34).
            assert!(a.confidence > 0.3, "{name}: confidence {}", a.confidence);
            for (k, (got, want)) in a.corners.iter().zip(&corners).enumerate() {
                let d = (got[0] - want[0]).hypot(got[1] - want[1]);
                assert!(
                    d < 2.0,
                    "{name}: corner {k} {d:.1} px off: oriented wrongly"
                );
            }
        }
    }
}

#[test]
fn corners_of_a_colorchecker24_choose_it_over_a_chart_with_another_grid() {
    // Without the measured data: the ColorChecker 24 against itself laid as a 4 × 6 grid
    // (a chart of another shape) must not be read as that grid.
    let (cc24, t24) = camera(Chart::colorchecker24(&GRID).unwrap());
    let mut other = t24.clone();
    other.name = "another_grid".into();
    other.rows = 8;
    other.cols = 12;
    other.feature_patches = (0..96).collect();
    other.neutrals = vec![(0, 0.9), (1, 0.5), (2, 0.1)];
    let (photo, corners) = tilted_scene(&cc24, 5);
    let options = AnalyseOptions {
        templates: vec![other, t24],
        corners: Some(corners.to_vec()),
        debug: None,
    };
    let a = analyse(&photo, &options).unwrap();
    assert_eq!(a.chart, "colorchecker24");
    let _ = DataDir::new(None);
}

/// The part of scene photo `seed` (a ColorChecker 24 at 1/8 of the width, anywhere) beside
/// the chart, at least a third of the photo's width: cluttered background and no chart.
fn background_only(camera: &Camera, seed: u64) -> spdcam_core::photo::Photo {
    let bucket = &detection_rate::buckets()[1];
    let shot = bucket.photograph(camera, seed, SIZE).unwrap();
    let image = image::load_from_memory(&shot.jpeg).unwrap().to_rgb8();
    let xs = shot.corners.map(|c| c[0]);
    let (lo, hi) = (
        xs.iter().copied().fold(f64::INFINITY, f64::min),
        xs.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    );
    let margin = 10.0;
    let (x0, x1) = if SIZE.0 as f64 - hi > lo {
        ((hi + margin) as u32, SIZE.0 as u32)
    } else {
        (0, (lo - margin).max(0.0) as u32)
    };
    assert!(x1 - x0 >= SIZE.0 as u32 / 3, "seed {seed}: {x0}..{x1}");
    let part = image::imageops::crop_imm(&image, x0, 0, x1 - x0, SIZE.1 as u32).to_image();
    let mut png = std::io::Cursor::new(Vec::new());
    part.write_to(&mut png, image::ImageFormat::Png).unwrap();
    decode_photo(png.get_ref(), &format!("background-{seed}.png")).unwrap()
}

/// No chart is found in any of `photos` background-only photos.
fn nothing_found_beside_the_chart(camera: &Camera, templates: &[ChartTemplate], photos: u64) {
    for seed in 0..photos {
        let photo = background_only(camera, seed);
        if let Ok(d) = spdcam_core::photo::detect(&photo, templates) {
            panic!(
                "{}: {} found at {:?} (confidence {:.2})",
                photo.source, d.chart, d.corners, d.confidence
            );
        }
    }
}

#[test]
fn no_chart_is_found_in_a_photo_without_one() {
    // Issue 28: placements found by the photo's support for their grid (few patches
    // segmented) must not turn clutter into a chart.
    let (cc24, t24) = camera(Chart::colorchecker24(&GRID).unwrap());
    nothing_found_beside_the_chart(&cc24, &[t24], 6);
}

#[cfg(feature = "measured-data")]
#[test]
fn neither_chart_is_found_in_a_photo_without_one() {
    let data = DataDir::new(Some(shared_data::data_dir()));
    let (cc24, t24) = camera(Chart::colorchecker24(&GRID).unwrap());
    let (_, tsg) = camera(Chart::resolve("colorchecker_sg140", None, &data, &GRID).unwrap());
    nothing_found_beside_the_chart(&cc24, &[tsg, t24], 12);
}
