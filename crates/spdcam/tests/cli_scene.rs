//! `spdcam render --scene` with the chart placed as asked (size, centre, rotation, tilt,
//! shadow), found by `spdcam estimate`, and its `--debug` image announced and written at
//! the photo's full resolution.

mod common;

use common::{fails, s, scratch, spdcam};

/// The corners `render --scene` prints: eight numbers after "chart corners ".
fn printed_corners(out: &str) -> Vec<f64> {
    let at = out.find("chart corners ").expect(out) + "chart corners ".len();
    out[at..]
        .trim_end()
        .trim_end_matches(')')
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect()
}

#[test]
fn a_tilted_shadowed_chart_is_placed_as_asked_and_found_with_a_full_size_debug_image() {
    let dir = scratch("tilted");
    let photo = dir.join("tilted.jpg");
    let out = spdcam(&[
        "render",
        "--spd",
        "D65",
        "--scene",
        "4000x3000",
        "--chart-width",
        "1/8",
        "--chart-centre",
        "0.5,0.5",
        "--chart-rotation",
        "0",
        "--tilt",
        "65",
        "--shadow",
        "0.4,0.4,0",
        "--noise",
        "off",
        "--demosaic",
        "bilinear",
        "--seed",
        "2",
        "-o",
        &s(&photo),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}");
    let c = printed_corners(&stdout);
    // Face-on 1/8 of 4000 px wide, centred; tilted 65° about the horizontal axis: the
    // chart's height is foreshortened to about cos 65° ≈ 0.42 of its face-on 1/8 × 4000
    // × 3.84/5.84 px.
    let width = c[2] - c[0];
    assert!((width - 500.0).abs() < 60.0, "width {width}: {stdout}");
    let height = 0.5 * ((c[5] - c[3]) + (c[7] - c[1]));
    let face_on = 500.0 * 3.84 / 5.84;
    assert!(
        (height / face_on - 0.42).abs() < 0.06,
        "height {height} of {face_on}: {stdout}"
    );
    let centre = [
        (c[0] + c[2] + c[4] + c[6]) / 4.0,
        (c[1] + c[3] + c[5] + c[7]) / 4.0,
    ];
    assert!((centre[0] - 2000.0).abs() < 30.0 && (centre[1] - 1500.0).abs() < 60.0);

    let debug = dir.join("found.png");
    let out = spdcam(&[
        "estimate",
        &s(&photo),
        "--chart",
        "colorchecker24",
        "--debug",
        &s(&debug),
    ]);
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert!(out.status.success(), "{stdout}\n{stderr}");
    assert!(stdout.contains("ColorChecker 24 detected"), "{stdout}");
    assert!(
        stderr.contains(&format!("debug → {}", debug.display())),
        "{stderr}"
    );
    let overlay = image::open(&debug).unwrap();
    assert_eq!((overlay.width(), overlay.height()), (4000, 3000));
}

#[test]
fn scene_placements_out_of_range_are_refused_by_name() {
    let dir = scratch("refused");
    let photo = s(&dir.join("x.jpg"));
    let base = ["render", "--spd", "D65", "--scene", "640x480", "-o", &photo];
    for (extra, expected) in [
        (vec!["--tilt", "89"], "a tilt of 89° is out of range"),
        (
            vec!["--shadow", "1.5"],
            "a shadow's factor 1.5 must lie between 0 and 1",
        ),
        (
            vec!["--chart-width", "2"],
            "--chart-width '2' must be a share between 0 and 1",
        ),
        (
            vec!["--chart-centre", "0.5"],
            "--chart-centre '0.5' needs two shares X,Y",
        ),
        (
            vec![
                "--chart-width",
                "0.9",
                "--chart-centre",
                "0.1,0.1",
                "--chart-rotation",
                "0",
                "--tilt",
                "10",
            ],
            "does not fit a 640×480 scene at the centre given",
        ),
    ] {
        let args: Vec<&str> = base.iter().copied().chain(extra.iter().copied()).collect();
        let err = fails(&args);
        assert!(err.contains(expected), "{extra:?}: {err}");
    }
    let err = fails(&["render", "--spd", "D65", "-o", &photo, "--tilt", "30"]);
    assert!(err.contains("--scene"), "{err}");
}

#[test]
fn detection_rates_of_one_difficulty_keep_the_missed_photos_to_look_at() {
    let dir = scratch("detection");
    let md = dir.join("detection.md");
    let misses = dir.join("misses");
    let out = common::ok(&[
        "detection",
        "--photos",
        "2",
        "--size",
        "400x300",
        "--charts",
        "colorchecker24",
        "--difficulty",
        "size",
        "--misses",
        &s(&misses),
        "-o",
        &s(&md),
    ]);
    assert!(out.contains("detection rates:"), "{out}");
    let text = std::fs::read_to_string(&md).unwrap();
    for bucket in ["| size | 1/4 |", "| size | 1/15 |"] {
        assert!(text.contains(bucket), "{bucket} missing:\n{text}");
    }
    assert!(!text.contains("| tilt |"), "only sizes asked for:\n{text}");
    assert!(text.contains("--difficulty size -o"), "{text}");
    // A 1/15 chart is 27 px wide in a 400 px photo: every photo missed is kept as a file.
    let listed = text
        .lines()
        .filter(|l| l.starts_with("- colorchecker24"))
        .count();
    assert!(listed > 0, "{text}");
    let kept = std::fs::read_dir(&misses).unwrap().count();
    assert_eq!(kept, listed, "{text}");
    let e = fails(&[
        "detection",
        "--difficulty",
        "colour",
        "-o",
        &s(&dir.join("x.md")),
    ]);
    assert!(
        e.contains("'colour'") && e.contains("rotation, shadow, size, tilt"),
        "{e}"
    );
    let e = fails(&[
        "detection",
        "--charts",
        "colorchecker24",
        "--photograph",
        "colorchecker_sg140",
        "-o",
        &s(&dir.join("x.md")),
    ]);
    assert!(e.contains("--photograph 'colorchecker_sg140'"), "{e}");
    assert!(!dir.join("x.md").exists());
}
