//! Several charts in one photo: every chart found where it lies, none invented, none taken
//! twice, numbered from left to right; a photo of one chart found as before. The scenes are
//! seeded synthetic photos ([`spdcam_core::photo::scene_places`]).

mod photo_support;

use photo_support::{colorchecker24, wide_photo_options, ChartSetup};
use spdcam_core::builtin::DataDir;
use spdcam_core::named_light;
use spdcam_core::photo::scene::{SceneOptions, Tilt, TiltAxis};
use spdcam_core::photo::scene_places::{photograph_places, PlacesPhoto, ScenePlace};
use spdcam_core::photo::{
    analyse_places_telling_debug, decode_photo, detect, detect_all, quad_centre, AnalyseOptions,
    Detection,
};
use spdcam_core::spectral::{Grid, Spd};

fn light(spec: &str) -> Spd {
    named_light::resolve_spd(spec, &DataDir::new(None), &Grid::SIMULATION)
        .unwrap()
        .spd
}

/// A chart of `setup` at `centre` spanning `share` of the width, turned by `rotation`.
fn placing(share: f64, centre: [f64; 2], rotation: f64, tilt: Option<Tilt>) -> SceneOptions {
    SceneOptions {
        width_share: (share, share),
        centre: Some(centre),
        rotation_deg: Some(rotation),
        tilt,
        perspective: 0.0,
        ..SceneOptions::default()
    }
}

/// The mean distance of found corners from the true ones, in patch sides.
fn corner_error(found: &Detection, truth: &[[f64; 2]; 4], patch_px: f64) -> f64 {
    (0..4)
        .map(|k| (found.corners[k][0] - truth[k][0]).hypot(found.corners[k][1] - truth[k][1]))
        .sum::<f64>()
        / 4.0
        / patch_px
}

/// Checks that `found` holds exactly the charts of `shot`, each within a third of a patch.
fn assert_found(found: &[Detection], shot: &PlacesPhoto, what: &str) {
    assert_eq!(found.len(), shot.places.len(), "{what}: {found:#?}");
    for truth in &shot.places {
        let centre = quad_centre(&truth.corners);
        let nearest = found
            .iter()
            .min_by(|a, b| {
                let d = |d: &Detection| {
                    let c = quad_centre(&d.corners);
                    (c[0] - centre[0]).hypot(c[1] - centre[1])
                };
                d(a).total_cmp(&d(b))
            })
            .unwrap();
        assert_eq!(nearest.chart, truth.chart, "{what}");
        let e = corner_error(nearest, &truth.corners, truth.patch_px);
        assert!(e < 0.35, "{what}: corners off by {e:.2} patch sides");
    }
    // Numbered from left to right.
    for pair in found.windows(2) {
        assert!(quad_centre(&pair[0].corners)[0] <= quad_centre(&pair[1].corners)[0]);
    }
}

fn shoot(places: &[ScenePlace], seed: u64) -> (PlacesPhoto, spdcam_core::photo::Photo) {
    let shot = photograph_places(places, seed, &wide_photo_options()).unwrap();
    let photo = decode_photo(&shot.jpeg, &format!("places-{seed}.jpg")).unwrap();
    (shot, photo)
}

#[test]
fn two_charts_under_two_lights_are_both_found() {
    let cc = colorchecker24();
    let (warm, cool) = (light("A"), light("D65"));
    let places = [
        ScenePlace {
            camera: cc.camera(),
            light: &warm,
            level: 1.0,
            placing: placing(0.3, [0.25, 0.5], 10.0, None),
            case: None,
        },
        ScenePlace {
            camera: cc.camera(),
            light: &cool,
            level: 0.8,
            placing: placing(0.25, [0.72, 0.45], -20.0, None),
            case: None,
        },
    ];
    let (shot, photo) = shoot(&places, 1);
    let (found, _) = detect_all(&photo, std::slice::from_ref(&cc.template)).unwrap();
    assert_found(&found, &shot, "two charts");
}

#[test]
fn small_and_tilted_charts_are_found_beside_a_large_one() {
    let cc = colorchecker24();
    let d50 = light("D50");
    let places = [
        ScenePlace {
            camera: cc.camera(),
            light: &d50,
            level: 1.0,
            placing: placing(0.35, [0.3, 0.5], 0.0, None),
            case: None,
        },
        ScenePlace {
            camera: cc.camera(),
            light: &d50,
            level: 0.5,
            placing: placing(0.1, [0.72, 0.25], 30.0, None),
            case: None,
        },
        ScenePlace {
            camera: cc.camera(),
            light: &d50,
            level: 1.0,
            placing: placing(
                0.18,
                [0.75, 0.72],
                0.0,
                Some(Tilt {
                    degrees: 60.0,
                    axis: TiltAxis::Vertical,
                }),
            ),
            case: None,
        },
    ];
    let (shot, photo) = shoot(&places, 2);
    let (found, _) = detect_all(&photo, std::slice::from_ref(&cc.template)).unwrap();
    assert_found(&found, &shot, "three charts");
    // One light at two levels: the second chart's light is half the first's.
    assert!((shot.places[1].relative_illuminance - 0.5).abs() < 1e-9);
}

#[test]
fn one_chart_is_found_as_the_single_search_finds_it() {
    let cc = colorchecker24();
    let d65 = light("D65");
    let places = [ScenePlace {
        camera: cc.camera(),
        light: &d65,
        level: 1.0,
        placing: placing(0.4, [0.45, 0.55], 15.0, None),
        case: None,
    }];
    let (_, photo) = shoot(&places, 3);
    let templates = [cc.template.clone()];
    let (all, _) = detect_all(&photo, &templates).unwrap();
    let one = detect(&photo, &templates).unwrap();
    assert_eq!(all, vec![one]);
    // And the analysis of one chart carries no place.
    let options = AnalyseOptions {
        templates: templates.to_vec(),
        ..AnalyseOptions::default()
    };
    let analyses = analyse_places_telling_debug(&photo, &options).0.unwrap();
    assert_eq!(analyses.len(), 1);
    assert_eq!(analyses[0].place, None);
}

#[test]
fn each_chart_of_several_is_analysed_with_its_place() {
    let cc = colorchecker24();
    let d65 = light("D65");
    let places: Vec<ScenePlace> = [[0.2, 0.3], [0.5, 0.7], [0.8, 0.3]]
        .iter()
        .map(|&centre| ScenePlace {
            camera: cc.camera(),
            light: &d65,
            level: 1.0,
            placing: placing(0.2, centre, 0.0, None),
            case: None,
        })
        .collect();
    let (shot, photo) = shoot(&places, 4);
    let options = AnalyseOptions {
        templates: vec![cc.template.clone()],
        ..AnalyseOptions::default()
    };
    let analyses = analyse_places_telling_debug(&photo, &options).0.unwrap();
    assert_eq!(analyses.len(), 3);
    for (k, (a, truth)) in analyses.iter().zip(&shot.places).enumerate() {
        let place = a.place.unwrap();
        assert_eq!((place.number, place.of), (k + 1, 3));
        let c = quad_centre(&truth.corners);
        assert!((place.centre[0] - c[0]).hypot(place.centre[1] - c[1]) < 5.0);
    }
}

#[test]
fn charts_placed_over_each_other_are_refused() {
    let cc: ChartSetup = colorchecker24();
    let d65 = light("D65");
    let places: Vec<ScenePlace> = [[0.4, 0.5], [0.5, 0.5]]
        .iter()
        .map(|&centre| ScenePlace {
            camera: cc.camera(),
            light: &d65,
            level: 1.0,
            placing: placing(0.3, centre, 0.0, None),
            case: None,
        })
        .collect();
    let e = photograph_places(&places, 5, &wide_photo_options()).unwrap_err();
    assert!(e.to_string().contains("charts 1 and 2"), "{e}");
}
