//! The in-camera rendering stage against hand-computed cases, its identity when neutral,
//! calibration on photos rendered with known parameters, and deterministic domain
//! randomisation.

use spdcam_core::builtin::{self, DataDir};
use spdcam_core::camera::colour::ColourTransform;
use spdcam_core::camera::in_camera::{fit_to_photos, InCamera, ReferencePhoto};
use spdcam_core::camera::optics::ChartGlow;
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::tone::jpeg_quantise;
use spdcam_core::camera::white_balance;
use spdcam_core::camera::{Camera, CameraConfig};
use spdcam_core::chart::Chart;
use spdcam_core::cie_illuminant::StandardIlluminant;
use spdcam_core::colorimetry;
use spdcam_core::dataset::randomise::{
    camera_pool, GlowRange, InCameraRanges, Randomisation, GLOW_WIDTHS,
    IN_CAMERA_AND_GRADIENT_GROUPS, IN_CAMERA_GROUPS,
};
use spdcam_core::dataset::{GenerateOptions, Generator, Pipeline};
use spdcam_core::light_families::Lighting;
use spdcam_core::spectral::{Grid, Spd};

const GRID: Grid = Grid::SIMULATION;

fn nikon() -> Sensitivities {
    let set = builtin::CAMERAS[0].load().unwrap();
    Sensitivities::new("nikon_d5100_npl", &set, &GRID).unwrap()
}

fn camera(in_camera: Option<InCamera>) -> Camera {
    let config = CameraConfig {
        noise: None,
        in_camera,
        ..CameraConfig::default()
    };
    Camera::new(
        &nikon(),
        Chart::colorchecker24(&GRID).unwrap(),
        config,
        &GRID,
    )
    .unwrap()
}

fn fast(camera: &Camera, ic: Option<&InCamera>, spd: &Spd) -> Vec<f32> {
    let light = camera.light(spd).unwrap();
    let (mut raw, mut out) = (Vec::new(), Vec::new());
    camera.features_fast_with(ic, &light, &mut raw, &mut out);
    out
}

#[test]
fn neutral_stage_changes_nothing() {
    let off = camera(None);
    let neutral = camera(Some(InCamera::NEUTRAL));
    for ill in [StandardIlluminant::A, StandardIlluminant::D65] {
        let spd = ill.spd(&GRID).unwrap();
        let a = off.render(&spd, 1, false).unwrap().features;
        let b = neutral.render(&spd, 1, false).unwrap().features;
        assert_eq!(a, b);
        let mut raw = Vec::new();
        let (mut fa, mut fb) = (Vec::new(), Vec::new());
        off.features_fast(&off.light(&spd).unwrap(), &mut raw, &mut fa);
        neutral.features_fast(&neutral.light(&spd).unwrap(), &mut raw, &mut fb);
        assert_eq!(fa, fb);
    }
    assert_eq!(
        off.correction_matrix(),
        camera(Some(InCamera {
            gamma: 0.5,
            ..InCamera::NEUTRAL
        }))
        .correction_matrix(),
        "the colour matrix is fitted without the in-camera stage"
    );
}

#[test]
fn tone_stages_match_hand_computed_values() {
    let ct = ColourTransform::new(None, 16).unwrap();
    let enc = |x: f64| colorimetry::srgb_encode(x) as f32;
    // Contrast: y + c·y(1−y)(2y−1) on the encoded value.
    let ic = InCamera {
        contrast: 0.5,
        ..InCamera::NEUTRAL
    };
    let y = enc(0.1);
    let want = y + 0.5 * y * (1.0 - y) * (2.0 * y - 1.0);
    assert!((ic.rendering().encode(&ct, [0.1; 3])[0] - want).abs() < 1e-5);
    // Shoulder 0.4: 1.2 rolls off to 0.6 + 0.4·(1 − e^−1.5); 0.5 is below the knee.
    let ic = InCamera {
        shoulder: 0.4,
        ..InCamera::NEUTRAL
    };
    let rolled = 0.6 + 0.4 * (1.0 - (-1.5f64).exp());
    assert!((ic.rendering().encode(&ct, [1.2, 0.5, 0.0])[0] - enc(rolled)).abs() < 1e-5);
    assert!((ic.rendering().encode(&ct, [1.2, 0.5, 0.0])[1] - enc(0.5)).abs() < 1e-5);
    // Black floor 0.1: a channel pushed below black reads 0.1, white stays 1, and the
    // rest is scaled between them.
    let ic = InCamera {
        floor: 0.1,
        ..InCamera::NEUTRAL
    };
    let out = ic.rendering().encode(&ct, [-0.2, 1.0, 0.1]);
    assert!(
        (out[0] - 0.1).abs() < 1e-6 && (out[1] - 1.0).abs() < 1e-6,
        "{out:?}"
    );
    assert!((out[2] - (0.1 + 0.9 * enc(0.1))).abs() < 1e-5, "{out:?}");
    assert!(InCamera {
        floor: 0.6,
        ..InCamera::NEUTRAL
    }
    .validate()
    .is_err());
    // Gamma 2 on linear 0.3 → 0.09.
    let ic = InCamera {
        gamma: 2.0,
        ..InCamera::NEUTRAL
    };
    assert!((ic.rendering().encode(&ct, [0.3; 3])[2] - enc(0.09)).abs() < 1e-5);
    // Saturation 0 turns a colour into its luminance; greys are kept at any saturation.
    let ic = InCamera {
        saturation: 0.0,
        ..InCamera::NEUTRAL
    };
    let lum = 0.2126 * 0.8 + 0.7152 * 0.2 + 0.0722 * 0.1;
    for v in ic.rendering().encode(&ct, [0.8, 0.2, 0.1]) {
        assert!((v - enc(lum)).abs() < 1e-5);
    }
    // Incomplete adaptation: gains^a.
    let ic = InCamera {
        adaptation: 0.5,
        ..InCamera::NEUTRAL
    };
    let g = white_balance::adapt([2.0, 1.0, 0.25], ic.adaptation);
    assert!((g[0] - 2f32.sqrt()).abs() < 1e-6 && g[1] == 1.0 && (g[2] - 0.5).abs() < 1e-6);
    // Flare adds flare × the patch mean; auto exposure brings the mean green to the target.
    let ic = InCamera {
        flare: 0.5,
        exposure_target: Some(0.2),
        ..InCamera::NEUTRAL
    };
    let mut raw = vec![[1.0, 2.0, 3.0], [3.0, 4.0, 5.0], [100.0, 100.0, 100.0]];
    ic.glare().apply(&mut raw, 2, &[[0.0, 0.0]; 3]);
    assert_eq!(raw[0], [2.0, 3.5, 5.0]);
    assert_eq!(raw[2], [101.0, 101.5, 102.0]);
    // Patch means were (2, 3, 4): patch 2 becomes (4, 5.5, 7), so the mean green is 4.5.
    assert_eq!(
        ic.auto_exposure().and_then(|e| e.scale(&raw, 2)),
        Some(0.2 / 4.5)
    );
    // JPEG at quality 50: DC steps 16/8 = 2 (luma) and 17/8 (chroma) levels; a grey of
    // 101 levels has Y = 101 → 102 (nearest multiple of 2), Cb = Cr = 0.
    let q = jpeg_quantise([101.0 / 255.0; 3], 50);
    for v in q {
        assert!((v * 255.0 - 102.0).abs() < 1e-3, "{q:?}");
    }
    assert!(InCamera {
        contrast: 2.0,
        ..InCamera::NEUTRAL
    }
    .validate()
    .is_err());
    assert!(InCamera {
        jpeg_quality: Some(0),
        ..InCamera::NEUTRAL
    }
    .validate()
    .is_err());
}

#[test]
fn auto_exposure_brightens_and_saturates_bright_patches() {
    let cam = camera(None);
    let spd = StandardIlluminant::D65.spd(&GRID).unwrap();
    let base = fast(&cam, None, &spd);
    let bright = InCamera {
        exposure_target: Some(0.6),
        ..InCamera::NEUTRAL
    };
    let out = fast(&cam, Some(&bright), &spd);
    let mean = |v: &[f32]| v.iter().sum::<f32>() / v.len() as f32;
    assert!(mean(&out) > mean(&base) + 20.0);
    // Bright patches saturate: more values at full scale than at the thesis's exposure.
    let saturated = |v: &[f32]| v.iter().filter(|&&x| x > 254.5).count();
    assert!(saturated(&out) > saturated(&base) + 3, "{out:?}");
}

#[test]
fn calibration_recovers_known_parameters() {
    let truth = InCamera {
        flare: 0.05,
        exposure_target: Some(0.3),
        adaptation: 0.7,
        saturation: 0.85,
        shoulder: 0.2,
        gamma: 0.9,
        contrast: 0.2,
        jpeg_quality: None,
        gradient: [0.0, 0.0],
        floor: 0.0,
        glow: ChartGlow::OFF,
    };
    let cam = camera(None);
    let lights = [
        StandardIlluminant::A,
        StandardIlluminant::D65,
        StandardIlluminant::D50,
    ];
    let mut photos: Vec<ReferencePhoto> = lights
        .iter()
        .map(|l| {
            let spd = l.spd(&GRID).unwrap();
            let features = fast(&cam, Some(&truth), &spd)
                .iter()
                .map(|&v| f64::from(v))
                .collect();
            ReferencePhoto { features, spd }
        })
        .collect();
    // A bluish light too: D65 with its red end attenuated.
    let mut blue = StandardIlluminant::D65.spd(&GRID).unwrap().into_values();
    for (k, v) in blue.iter_mut().enumerate() {
        *v *= 1.5 - k as f64 / GRID.count as f64;
    }
    let blue = Spd::new(GRID, blue).unwrap();
    photos.push(ReferencePhoto {
        features: fast(&cam, Some(&truth), &blue)
            .iter()
            .map(|&v| f64::from(v))
            .collect(),
        spd: blue,
    });
    let fit = fit_to_photos(&cam, &photos, InCamera::NEUTRAL, 6000).unwrap();
    println!("{fit:?}");
    assert!(fit.rms_before > 5.0, "{}", fit.rms_before);
    assert!(fit.rms_after < 0.3, "{}", fit.rms_after);
    let ic = fit.in_camera;
    assert!((ic.exposure_target.unwrap() - 0.3).abs() < 0.03, "{ic:?}");
    assert!((ic.adaptation - 0.7).abs() < 0.05, "{ic:?}");
    assert!((ic.saturation - 0.85).abs() < 0.05, "{ic:?}");
    // Bad input is an error, not a panic.
    let bad = [ReferencePhoto {
        features: vec![1.0; 5],
        spd: photos[0].spd.clone(),
    }];
    assert!(fit_to_photos(&cam, &bad, InCamera::NEUTRAL, 100).is_err());
    assert!(fit_to_photos(&cam, &[], InCamera::NEUTRAL, 100).is_err());
}

#[test]
fn randomised_generation_is_deterministic_per_seed_and_sample() {
    let chart = Chart::colorchecker24(&GRID).unwrap();
    let config = CameraConfig {
        noise: None,
        ..CameraConfig::default()
    };
    let base = Camera::new(&nikon(), chart.clone(), config, &GRID).unwrap();
    let sens: Vec<Sensitivities> = builtin::CAMERAS
        .iter()
        .map(|t| Sensitivities::new(t.name, &t.load().unwrap(), &GRID).unwrap())
        .collect();
    let pool = camera_pool(&sens, 2, 7, &chart, config, &GRID).unwrap();
    assert_eq!(pool.len(), sens.len() * 3);
    let ranges = InCameraRanges::for_groups(&IN_CAMERA_GROUPS).unwrap();
    assert!(InCameraRanges::for_groups(&["nonsense"]).is_err());
    let randomisation = Randomisation::new(pool, ranges).unwrap();
    let lighting =
        Lighting::parse("gaussian:4", &DataDir::new(None), &GRID).unwrap_or_else(|e| panic!("{e}"));
    let mut options = GenerateOptions::new(40, 3);
    options.pipeline = Pipeline::Fast;
    let run = |r: Option<&Randomisation>, range: std::ops::Range<u64>| {
        let mut g = Generator::new(&base, &lighting, options.clone()).unwrap();
        if let Some(r) = r {
            g = g.with_randomisation(r).unwrap();
        }
        g.samples(range, None, &|_| {}).unwrap()
    };
    let a = run(Some(&randomisation), 0..40);
    let b = run(Some(&randomisation), 20..40);
    assert_eq!(&a.features[20 * 72..], &b.features[..]);
    let plain = run(None, 0..40);
    assert_eq!(a.spds, plain.spds, "randomisation leaves the lights alone");
    assert_ne!(a.features, plain.features);
    let (c1, p1) = randomisation.draw(3, 5);
    let (c2, p2) = randomisation.draw(3, 5);
    assert_eq!(c1.camera_name(), c2.camera_name());
    assert_eq!(p1, p2);
}

#[test]
fn lighting_gradient_scales_patches_by_their_position() {
    // CC24 is 4 × 6: patch 0's centre sits at x = 0.5/6 − 0.5 = −5/12, y = 0.5/4 − 0.5 = −3/8.
    let centres = Chart::colorchecker24(&GRID)
        .unwrap()
        .layout
        .region_centres();
    assert_eq!(centres.len(), 25, "24 patches and the background");
    let near = |a: [f32; 2], b: [f32; 2]| (a[0] - b[0]).abs() < 1e-6 && (a[1] - b[1]).abs() < 1e-6;
    assert!(
        near(centres[0], [-5.0 / 12.0, -3.0 / 8.0]),
        "{:?}",
        centres[0]
    );
    assert!(
        near(centres[23], [5.0 / 12.0, 3.0 / 8.0]),
        "{:?}",
        centres[23]
    );
    assert_eq!(centres[24], [0.0, 0.0]);
    let ic = InCamera {
        gradient: [0.4, -0.2],
        ..InCamera::NEUTRAL
    };
    let mut raw = vec![[1.0f32, 2.0, 4.0]; 25];
    ic.uneven_lighting().apply(&mut raw, &centres);
    // Patch 0: 1 + 0.4·(−5/12) − 0.2·(−3/8) = 1 − 1/6 + 0.075.
    let g0 = 1.0 - 1.0 / 6.0 + 0.075;
    let g23 = 1.0 + 1.0 / 6.0 - 0.075;
    for (c, base) in [1.0f32, 2.0, 4.0].into_iter().enumerate() {
        assert!((raw[0][c] - base * g0 as f32).abs() < 1e-6);
        assert!((raw[23][c] - base * g23 as f32).abs() < 1e-6);
        assert_eq!(raw[24][c], base, "the background is at the centre");
    }
    // Through the camera: a left-to-right gradient brightens the right column relative to
    // the left one; no gradient is the neutral stage.
    let spd = StandardIlluminant::D65.spd(&GRID).unwrap();
    let flat = fast(&camera(None), Some(&InCamera::NEUTRAL), &spd);
    let zero = InCamera {
        gradient: [0.0, 0.0],
        ..InCamera::NEUTRAL
    };
    assert_eq!(fast(&camera(None), Some(&zero), &spd), flat);
    let tilted = InCamera {
        gradient: [0.5, 0.0],
        ..InCamera::NEUTRAL
    };
    let lit = fast(&camera(None), Some(&tilted), &spd);
    let green = |f: &[f32], patch: usize| f[patch * 3 + 1];
    // Patches 18 (white, left) and 23 (black, right) on the bottom row: the exposure is
    // normalised again, so compare the change of one against the other's.
    let change = |p: usize| green(&lit, p) / green(&flat, p);
    assert!(
        change(23) > 1.2 * change(18),
        "right {} left {}",
        change(23),
        change(18)
    );
    assert!(InCamera {
        gradient: [2.0, 0.0],
        ..InCamera::NEUTRAL
    }
    .validate()
    .is_err());
}

#[test]
fn randomised_gradient_stays_in_its_range() {
    // One camera: the Nikon, noise-free, photographing the ColorChecker 24.
    let pool = vec![camera(None)];
    let ranges = InCameraRanges::for_groups(&["gradient"]).unwrap();
    let max = ranges.gradient.unwrap();
    let randomisation = Randomisation::new(pool, ranges).unwrap();
    let draws: Vec<[f64; 2]> = (0..200)
        .map(|i| randomisation.draw(9, i).1.unwrap().gradient)
        .collect();
    assert!(draws.iter().flatten().all(|g| g.abs() <= max));
    let spread = draws
        .iter()
        .map(|g| g[0])
        .fold(0.0f64, |m, g| m.max(g.abs()));
    assert!(
        spread > 0.8 * max,
        "draws cover the range: largest {spread}"
    );
    assert_eq!(draws[7], randomisation.draw(9, 7).1.unwrap().gradient);
}

#[test]
fn two_lights_meet_at_one_exposure_and_one_white_balance() {
    let cam = camera(None);
    let a = StandardIlluminant::D65.spd(&GRID).unwrap();
    let b = StandardIlluminant::A.spd(&GRID).unwrap();
    let (la, lb) = (cam.light(&a).unwrap(), cam.light(&b).unwrap());
    let ic = InCamera {
        exposure_target: Some(0.3),
        ..InCamera::NEUTRAL
    };
    let two = |other: &[f32], second: &[bool]| {
        let (mut raw, mut out) = (Vec::new(), Vec::new());
        cam.features_fast_two_lights(Some(&ic), &la, other, second, &mut raw, &mut out);
        out
    };
    let patches = 24;
    let right: Vec<bool> = (0..patches).map(|p| p % 6 >= 3).collect();
    let one = fast(&cam, Some(&ic), &a);
    // The same light twice, or the second light nowhere, is the photo of one light.
    assert_eq!(two(&la, &right), one);
    assert_eq!(two(&lb, &vec![false; patches]), one);
    // Tungsten on the right half: its patches warm against the daylit left, where a photo
    // of each light alone balances each to neutral.
    let mixed = two(&lb, &right);
    let red_over_blue = |f: &[f32], p: usize| f[3 * p] / f[3 * p + 2].max(1.0);
    // The neutral row: white (p18) on the left, neutral 3.5 (p22) on the right.
    let (left, right_grey) = (red_over_blue(&mixed, 19), red_over_blue(&mixed, 22));
    assert!(
        right_grey > 1.3 * left,
        "right {right_grey}, left {left}: {mixed:?}"
    );
    let alone = fast(&cam, Some(&ic), &b);
    assert!(red_over_blue(&alone, 22) < 1.2 * red_over_blue(&alone, 19));
}

#[test]
fn ranges_record_the_floor_only_when_it_is_drawn() {
    // Records of runs without the floor read as before it existed (a model's header holds
    // them, and a rebuilt model must match the committed one in every setting).
    let without = InCameraRanges::for_groups(&["exposure", "wb"]).unwrap();
    let json = serde_json::to_string(&without).unwrap();
    assert!(!json.contains("floor"), "{json}");
    let read: InCameraRanges = serde_json::from_str(&json).unwrap();
    assert_eq!(read, without);
    let with = InCameraRanges::for_groups(&["floor"]).unwrap();
    let json = serde_json::to_string(&with).unwrap();
    assert!(json.contains(r#""floor":[0.0,0.15]"#), "{json}");
    assert_eq!(serde_json::from_str::<InCameraRanges>(&json).unwrap(), with);
}

#[test]
fn the_named_group_lists_differ_by_the_gradient_alone() {
    let stage = InCameraRanges::for_groups(&IN_CAMERA_GROUPS).unwrap();
    let with_gradient = InCameraRanges::for_groups(&IN_CAMERA_AND_GRADIENT_GROUPS).unwrap();
    assert!(stage.gradient.is_none() && with_gradient.gradient.is_some());
    assert_eq!(
        InCameraRanges {
            gradient: None,
            ..with_gradient
        },
        stage
    );
    assert_eq!(IN_CAMERA_AND_GRADIENT_GROUPS[..4], IN_CAMERA_GROUPS);
}

#[test]
fn a_glow_lifts_the_dark_patches_near_it_and_is_refused_outside_its_ranges() {
    // A glow on the black patch (p23, bottom right of the 4 × 6 chart, at x = 5/12,
    // y = 3/8) lifts it far more than the patch at the opposite corner (p0, dark skin).
    let spd = StandardIlluminant::D65.spd(&GRID).unwrap();
    let cam = camera(None);
    let ic = |level: f64| InCamera {
        exposure_target: Some(0.3),
        glow: ChartGlow {
            level,
            at: [5.0 / 12.0, 3.0 / 8.0],
            width: 0.15,
        },
        ..InCamera::NEUTRAL
    };
    let clean = fast(&cam, Some(&ic(0.0)), &spd);
    let glowing = fast(&cam, Some(&ic(0.5)), &spd);
    let green = |f: &[f32], p: usize| f[3 * p + 1];
    assert!(
        green(&glowing, 23) > green(&clean, 23) + 40.0,
        "black patch {} → {}",
        green(&clean, 23),
        green(&glowing, 23)
    );
    assert!(
        (green(&glowing, 0) - green(&clean, 0)).abs() < 3.0,
        "far patch {} → {}",
        green(&clean, 0),
        green(&glowing, 0)
    );
    // Level 0 is the stage without a glow, whatever its place and width.
    let plain = InCamera {
        exposure_target: Some(0.3),
        ..InCamera::NEUTRAL
    };
    assert_eq!(clean, fast(&cam, Some(&plain), &spd));
    for bad in [
        ChartGlow {
            level: 1.5,
            at: [0.0, 0.0],
            width: 0.3,
        },
        ChartGlow {
            level: 0.3,
            at: [0.0, 0.0],
            width: 0.0,
        },
        ChartGlow {
            level: 0.3,
            at: [2.0, 0.0],
            width: 0.3,
        },
        ChartGlow {
            level: f64::NAN,
            at: [0.0, 0.0],
            width: 0.3,
        },
    ] {
        let err = InCamera {
            glow: bad,
            ..InCamera::NEUTRAL
        }
        .validate()
        .unwrap_err();
        assert!(err.to_string().contains("glow"), "{err}");
    }
}

#[test]
fn randomised_glows_cover_their_ranges_and_are_recorded_only_when_drawn() {
    // One camera: the Nikon, noise-free, photographing the ColorChecker 24.
    let pool = vec![camera(None)];
    let ranges = InCameraRanges::for_groups(&["glow"]).unwrap();
    let GlowRange {
        share,
        level: [lo, hi],
    } = ranges.glow.unwrap();
    let randomisation = Randomisation::new(pool.clone(), ranges).unwrap();
    let all: Vec<ChartGlow> = (0..400)
        .map(|i| randomisation.draw(4, i).1.unwrap().glow)
        .collect();
    let glows: Vec<ChartGlow> = all.iter().copied().filter(|g| !g.is_off()).collect();
    let drawn = glows.len() as f64 / all.len() as f64;
    assert!(
        (drawn - share).abs() < 0.08,
        "{drawn} of the photos with a glow"
    );
    for g in &glows {
        assert!((lo..=hi).contains(&g.level), "{g:?}");
        assert!(
            (GLOW_WIDTHS[0]..=GLOW_WIDTHS[1]).contains(&g.width),
            "{g:?}"
        );
        assert!(g.at.iter().all(|a| a.abs() <= 0.5), "{g:?}");
    }
    let largest = glows.iter().map(|g| g.level).fold(0.0, f64::max);
    assert!(
        largest > 0.9 * hi,
        "the draws reach the top of the range: {largest}"
    );
    let corners = [[-1.0, -1.0], [1.0, -1.0], [-1.0, 1.0], [1.0, 1.0]];
    for [sx, sy] in corners {
        assert!(
            glows
                .iter()
                .any(|g| g.at[0] * sx > 0.3 && g.at[1] * sy > 0.3),
            "some glow near the corner ({sx}, {sy})"
        );
    }
    // Without the group the glow is off and the record does not name it.
    let without = InCameraRanges::for_groups(&IN_CAMERA_AND_GRADIENT_GROUPS).unwrap();
    assert!(!serde_json::to_string(&without).unwrap().contains("glow"));
    let plain = Randomisation::new(pool, without).unwrap();
    assert!((0..50).all(|i| plain.draw(4, i).1.unwrap().glow.is_off()));
    let json = serde_json::to_string(&InCamera::NEUTRAL).unwrap();
    assert!(!json.contains("glow"), "{json}");
    let with = InCameraRanges::for_groups(&["glow"]).unwrap();
    let json = serde_json::to_string(&with).unwrap();
    assert_eq!(serde_json::from_str::<InCameraRanges>(&json).unwrap(), with);
}
