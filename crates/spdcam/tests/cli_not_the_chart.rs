//! Images that hold no chart, with four corners placed in them anyway (issue 41): each is
//! refused with a message that names what is wrong and what to do, and no number is
//! printed; the chart itself, with its corners given or detected, is estimated. First tier:
//! no measured data (the ColorChecker SG is tested by its grey patches' order and the
//! patches' texture alone, as a fresh clone has no SG reflectances).

mod common;

use common::{ok, s, scratch, spdcam};
use std::path::{Path, PathBuf};

/// Seeded values in 0–1 (a 64-bit linear congruential generator, Knuth's MMIX constants).
struct Seeded(u64);

impl Seeded {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    fn colour(&mut self) -> [f64; 3] {
        [self.next(), self.next(), self.next()]
    }
}

/// Writes a `w × h` PNG whose pixel at (x, y) (both 0–1 across the image) is `colour`.
fn png(path: &Path, (w, h): (u32, u32), colour: impl Fn(f64, f64) -> [f64; 3]) {
    let image = image::RgbImage::from_fn(w, h, |x, y| {
        let c = colour(f64::from(x) / f64::from(w), f64::from(y) / f64::from(h));
        image::Rgb(c.map(|v| (255.0 * v.clamp(0.0, 1.0)).round() as u8))
    });
    image.save(path).unwrap();
}

/// Images with no chart, generated here (seeds apart from the measurement's): pixel noise,
/// blocky noise, a smooth colour gradient, a flat colour, and stripes each way.
fn no_chart_images(dir: &Path) -> Vec<PathBuf> {
    let size = (600, 400);
    let mut seeded = Seeded(2024);
    let pixels: Vec<[f64; 3]> = (0..600 * 400).map(|_| seeded.colour()).collect();
    let blocks: Vec<[f64; 3]> = (0..30 * 20).map(|_| seeded.colour()).collect();
    let (a, b) = (seeded.colour(), seeded.colour());
    let flat = seeded.colour();
    let stripes: Vec<[f64; 3]> = (0..9).map(|_| seeded.colour()).collect();
    let paths: Vec<PathBuf> = [
        "noise",
        "blocks",
        "gradient",
        "flat",
        "vertical",
        "horizontal",
    ]
    .iter()
    .map(|n| dir.join(format!("{n}.png")))
    .collect();
    png(&paths[0], size, |x, y| {
        pixels[(y * 400.0) as usize * 600 + (x * 600.0) as usize]
    });
    png(&paths[1], size, |x, y| {
        blocks[(y * 20.0) as usize * 30 + (x * 30.0) as usize]
    });
    png(&paths[2], size, |x, y| {
        let t = 0.6 * x + 0.4 * y;
        std::array::from_fn(|c| a[c] + t * (b[c] - a[c]))
    });
    png(&paths[3], size, |_, _| flat);
    png(&paths[4], size, |x, _| stripes[(x * 13.0) as usize % 9]);
    png(&paths[5], size, |_, y| stripes[(y * 7.0) as usize % 9]);
    paths
}

/// A scene photo with the chart on its right, and the left part of it, where the chart is
/// not, as a PNG; the scene's file and the chart's corners as `render` printed them.
fn scene_and_crop(dir: &Path) -> (PathBuf, String, PathBuf) {
    let scene = dir.join("scene.jpg");
    let said = ok(&[
        "render",
        "--lighting",
        "lamp:phosphor-led",
        "--draw",
        "2",
        "--scene",
        "900x600",
        "--seed",
        "9",
        "--chart-width",
        "0.3",
        "--chart-centre",
        "0.75,0.5",
        "-o",
        &s(&scene),
    ]);
    let corners = said
        .rsplit_once("(chart corners ")
        .and_then(|(_, rest)| rest.trim().strip_suffix(')'))
        .unwrap_or_else(|| panic!("no corners in: {said}"))
        .to_string();
    let crop = dir.join("scene-left.png");
    image::open(&scene)
        .unwrap()
        .crop_imm(0, 0, 450, 600)
        .save(&crop)
        .unwrap();
    (scene, corners, crop)
}

/// Corner sets inside a `w × h` image: an inset rectangle, a near-square and a skewed
/// quadrilateral, as `--corners` takes them.
fn corner_sets(w: f64, h: f64) -> Vec<String> {
    let at = |p: [[f64; 2]; 4]| {
        p.iter()
            .map(|q| format!("{:.0},{:.0}", q[0] * w, q[1] * h))
            .collect::<Vec<_>>()
            .join(",")
    };
    let side = 0.7 * h / w;
    vec![
        at([[0.08, 0.1], [0.92, 0.1], [0.92, 0.9], [0.08, 0.9]]),
        at([
            [0.5 - side / 2.0, 0.15],
            [0.5 + side / 2.0, 0.16],
            [0.5 + side / 2.0, 0.85],
            [0.5 - side / 2.0, 0.85],
        ]),
        at([[0.12, 0.2], [0.88, 0.08], [0.92, 0.86], [0.1, 0.74]]),
    ]
}

#[test]
fn images_without_a_chart_are_refused_with_what_to_do_and_no_number() {
    let dir = scratch("no-chart");
    let mut images: Vec<(PathBuf, f64, f64)> = no_chart_images(&dir)
        .into_iter()
        .map(|p| (p, 600.0, 400.0))
        .collect();
    let (_, _, crop) = scene_and_crop(&dir);
    images.push((crop, 450.0, 600.0));
    for (image, w, h) in &images {
        for corners in corner_sets(*w, *h) {
            for (chart, shown) in [
                ("colorchecker24", "ColorChecker 24"),
                ("colorchecker_sg96", "ColorChecker Digital SG"),
            ] {
                let args = [
                    "estimate",
                    &s(image),
                    "--chart",
                    chart,
                    "--corners",
                    &corners,
                ];
                let out = spdcam(&args);
                let stdout = String::from_utf8_lossy(&out.stdout);
                let stderr = String::from_utf8_lossy(&out.stderr);
                assert!(!out.status.success(), "{args:?} was estimated:\n{stdout}");
                let want = format!(
                    "these corners do not hold a {shown}: place them on the chart's four \
                     outer corners ("
                );
                assert!(stderr.contains(&want), "{args:?}:\n{stderr}");
                assert!(!stderr.contains("panicked"), "{stderr}");
                // No number of the light: nothing on standard output at all.
                assert!(stdout.trim().is_empty(), "{args:?} printed:\n{stdout}");
            }
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_chart_is_estimated_with_its_corners_given_and_detected() {
    let dir = scratch("the-chart");
    let (scene, corners, _) = scene_and_crop(&dir);
    for extra in [vec![], vec!["--corners", corners.as_str()]] {
        let mut args = vec!["estimate".to_string(), s(&scene)];
        args.extend(extra.iter().map(|a| a.to_string()));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = ok(&args);
        assert!(out.contains("CCT") && out.contains("relative SPD"), "{out}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Every row of the five real measured sets (ColorChecker SG photos with strong veiling
/// glare and hot spots) is taken for the chart: streamed through the model, an SPD each.
#[cfg(feature = "measured-data")]
#[test]
fn every_real_measured_row_is_the_chart() {
    let data = common::data_dir();
    let dir = scratch("measured");
    for set in [
        "telelumen_canon5d4_dev",
        "hue_canon5d4_train",
        "hue_canon5d4_val",
        "telelumen_galaxy_tab_s7_train",
        "telelumen_galaxy_tab_s7_val",
    ] {
        let features = data.join("thesis/measured").join(set).join("features.csv");
        let rows = std::fs::read_to_string(&features).unwrap().lines().count() - 1;
        let out = dir.join(format!("{set}.csv"));
        let args = [
            "--data-dir",
            &s(&data),
            "estimate",
            "--features",
            &s(&features),
            "--layout",
            "long",
            "-o",
            &s(&out),
        ];
        let run = spdcam(&args);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(run.status.success(), "{set}: {stderr}");
        let written = std::fs::read_to_string(&out).unwrap().lines().count() - 1;
        assert_eq!(written, rows, "{set}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// With the SG's reflectances at hand the no-chart images meet the full test (the chart's
/// fit against shuffled patches) for both charts, and are refused all the same.
#[cfg(feature = "measured-data")]
#[test]
fn with_the_measured_data_no_chart_is_refused_for_either_chart() {
    let data = s(&common::data_dir());
    let dir = scratch("no-chart-data");
    let images = no_chart_images(&dir);
    for image in [&images[1], &images[2], &images[5]] {
        for chart in ["colorchecker24", "colorchecker_sg96"] {
            let corners = &corner_sets(600.0, 400.0)[2];
            let args = [
                "--data-dir",
                &data,
                "estimate",
                &s(image),
                "--chart",
                chart,
                "--corners",
                corners,
            ];
            let out = spdcam(&args);
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert!(!out.status.success(), "{args:?}");
            assert!(stderr.contains("these corners do not hold a "), "{stderr}");
            assert!(String::from_utf8_lossy(&out.stdout).trim().is_empty());
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}
