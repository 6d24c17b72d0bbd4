//! Pocket charts: the ColorChecker Passport open flat in its case, beside its other page
//! (which is never a chart), and the ColorChecker 24 at the Mini's and the Nano's sizes in a
//! photo. The scenes are seeded synthetic photos through the full camera chain
//! ([`spdcam_core::photo::scene_places`]).

mod photo_support;

use photo_support::{random_light, wide_photo_options};
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};
use spdcam_core::builtin;
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::{Camera, CameraConfig};
use spdcam_core::chart::Chart;
use spdcam_core::photo::pocket::{page_camera, PassportPage};
use spdcam_core::photo::scene::{self, SceneOptions, Tilt, TiltAxis};
use spdcam_core::photo::scene_places::{photograph_places, PlacesPhoto, ScenePlace};
use spdcam_core::photo::{decode_photo, detect_all, ChartTemplate, Detection};
use spdcam_core::spectral::Grid;

const GRID: Grid = Grid::SIMULATION;

struct Pocket {
    template: ChartTemplate,
    classic: Camera,
    pages: Vec<Camera>,
}

/// The ColorChecker 24 and the Passport's pages photographed by the full camera chain
/// (mosaic, noise, demosaicing, in-camera rendering) of the shipped Nikon D5100
/// sensitivities.
fn pocket() -> Pocket {
    let set = builtin::CAMERAS[0].load().unwrap();
    let sens = Sensitivities::new("nikon_d5100_npl", &set, &GRID).unwrap();
    let chart = Chart::colorchecker24(&GRID).unwrap();
    let template = ChartTemplate::from_chart(&chart).unwrap();
    let chart = chart.with_layout(scene::scene_layout(&template)).unwrap();
    let classic = Camera::new(&sens, chart, CameraConfig::default(), &GRID).unwrap();
    let pages = PassportPage::ALL
        .iter()
        .map(|&page| page_camera(page, &sens, &classic).unwrap())
        .collect();
    Pocket {
        classic,
        template,
        pages,
    }
}

/// The one chart of `shot`, found once, its corners within a third of a patch.
fn assert_one_chart(found: &[Detection], shot: &PlacesPhoto, what: &str) {
    assert_eq!(found.len(), 1, "{what}: {found:#?}");
    let truth = &shot.places[0];
    let error = (0..4)
        .map(|k| {
            let (f, t) = (found[0].corners[k], truth.corners[k]);
            (f[0] - t[0]).hypot(f[1] - t[1])
        })
        .sum::<f64>()
        / 4.0
        / truth.patch_px;
    assert!(
        error < 0.35,
        "{what}: corners off by {error:.2} patch sides"
    );
}

#[test]
fn the_passport_is_one_chart_beside_its_other_page() {
    let pocket = pocket();
    for seed in 0..10u64 {
        let mut rng = SmallRng::seed_from_u64(seed);
        let (light_name, light) = random_light(&mut rng);
        let page = seed as usize % pocket.pages.len();
        let tilt = (seed % 3 == 2).then(|| Tilt {
            degrees: rng.random_range(-55.0..55.0),
            axis: if rng.random_bool(0.5) {
                TiltAxis::Vertical
            } else {
                TiltAxis::Horizontal
            },
        });
        let places = [ScenePlace {
            camera: &pocket.classic,
            light: &light,
            level: 1.0,
            placing: SceneOptions {
                width_share: (0.12, 0.32),
                tilt,
                perspective: 0.05,
                ..SceneOptions::default()
            },
            case: Some(&pocket.pages[page]),
        }];
        let shot = photograph_places(&places, seed, &wide_photo_options()).unwrap();
        let photo = decode_photo(&shot.jpeg, "passport.jpg").unwrap();
        let (found, _) = detect_all(&photo, std::slice::from_ref(&pocket.template)).unwrap();
        let what = format!(
            "seed {seed}, the {} page, {light_name}, tilt {tilt:?}",
            PassportPage::ALL[page].name()
        );
        assert_one_chart(&found, &shot, &what);
    }
}

#[test]
fn the_mini_and_nano_sizes_are_found_as_a_colorchecker_24() {
    // A Mini (63.5 × 108 mm) and a Nano span a small share of a photo taken to show a
    // room: the patch grids here span 4–12 % of a 1600 px photo's width.
    let pocket = pocket();
    for seed in 0..8u64 {
        let mut rng = SmallRng::seed_from_u64(100 + seed);
        let (light_name, light) = random_light(&mut rng);
        let share = if seed % 2 == 0 { 0.12 } else { 0.06 };
        let places = [ScenePlace {
            camera: &pocket.classic,
            light: &light,
            level: 1.0,
            placing: SceneOptions {
                width_share: (share, share),
                perspective: 0.05,
                ..SceneOptions::default()
            },
            case: None,
        }];
        let shot = photograph_places(&places, 100 + seed, &wide_photo_options()).unwrap();
        let photo = decode_photo(&shot.jpeg, "small.jpg").unwrap();
        let (found, _) = detect_all(&photo, std::slice::from_ref(&pocket.template)).unwrap();
        assert_one_chart(
            &found,
            &shot,
            &format!("seed {seed}, {share} wide, {light_name}"),
        );
    }
}

#[test]
fn a_passport_whose_case_does_not_fit_is_refused() {
    let pocket = pocket();
    let (_, light) = random_light(&mut SmallRng::seed_from_u64(1));
    let places = [ScenePlace {
        camera: &pocket.classic,
        light: &light,
        level: 1.0,
        placing: SceneOptions {
            width_share: (0.3, 0.3),
            centre: Some([0.75, 0.5]),
            rotation_deg: Some(0.0),
            perspective: 0.0,
            ..SceneOptions::default()
        },
        case: Some(&pocket.pages[0]),
    }];
    let e = photograph_places(&places, 1, &wide_photo_options()).unwrap_err();
    assert!(e.to_string().contains("Passport case does not fit"), "{e}");
}
