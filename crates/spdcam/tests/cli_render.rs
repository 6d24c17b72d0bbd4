//! `spdcam render` and `spdcam list` as a user runs them: outputs, and clear errors on bad input.

mod common;

use common::{scratch, spdcam};
use std::path::Path;
use std::process::Output;

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Runs a render expected to fail; checks the exit code, that the message is one line
/// containing `expect`, and that no output file appeared.
fn fails(dir: &Path, extra: &[&str], expect: &str) {
    let out = dir.join("out.png");
    let mut args = vec!["render", "-o", out.to_str().unwrap()];
    args.extend_from_slice(extra);
    let o = spdcam(&args);
    let msg = stderr(&o);
    assert!(!o.status.success(), "{args:?} succeeded");
    assert!(
        msg.contains(expect),
        "{args:?}: expected '{expect}' in: {msg}"
    );
    assert_eq!(msg.trim_end().lines().count(), 1, "not one line: {msg}");
    assert!(!out.exists(), "{args:?} left {}", out.display());
    let leftovers: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains("out"))
        .collect();
    assert!(leftovers.is_empty(), "partial files: {leftovers:?}");
}

#[test]
fn render_writes_png_and_features() {
    let dir = scratch("ok");
    let png = dir.join("chart.png");
    let features = dir.join("f.csv");
    let stages = dir.join("stages");
    std::fs::create_dir(&stages).unwrap();
    let o = spdcam(&[
        "render",
        "--spd",
        "cct:3000",
        "-o",
        png.to_str().unwrap(),
        "--features",
        features.to_str().unwrap(),
        "--stages",
        stages.to_str().unwrap(),
        "--seed",
        "3",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains(png.to_str().unwrap()), "{stdout}");
    let img = image::open(&png).unwrap();
    assert_eq!((img.width(), img.height()), (144, 96));
    let text = std::fs::read_to_string(&features).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 2);
    assert!(lines[0].starts_with("p01_r,p01_g,p01_b,p02_r"));
    let values: Vec<f64> = lines[1].split(',').map(|v| v.parse().unwrap()).collect();
    assert_eq!(values.len(), 72);
    assert!(values.iter().all(|v| (0.0..=255.0).contains(v)));
    for stage in [
        "1_cfa.png",
        "2_demosaiced.png",
        "3_white_balanced.png",
        "4_aberrated.png",
    ] {
        assert!(stages.join(stage).is_file(), "{stage}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn sixteen_bit_three_sensor_render() {
    let dir = scratch("sixteen");
    let png = dir.join("c.png");
    let o = spdcam(&[
        "render",
        "--spd",
        "A",
        "--sensor",
        "three",
        "--bit-depth",
        "16",
        "--noise",
        "phone",
        "--white-balance",
        "grey-edge",
        "--size",
        "300x200",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let img = image::open(&png).unwrap();
    assert_eq!(img.color(), image::ColorType::Rgb16);
    assert_eq!((img.width(), img.height()), (300, 200));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_inputs_give_one_line_errors_and_no_file() {
    let dir = scratch("bad");
    let write = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    };
    let no_header = write("noheader.csv", "400,1\n500,1\n700,1\n");
    let bad_cell = write("badcell.csv", "wavelength_nm,lamp\n400,1\n500,x\n700,1\n");
    let unsorted = write("unsorted.csv", "wavelength_nm,lamp\n500,1\n400,1\n700,1\n");
    let duplicate = write("dup.csv", "wavelength_nm,lamp\n400,1\n400,1\n700,1\n");
    let negative = write("neg.csv", "wavelength_nm,lamp\n400,1\n500,-3\n700,1\n");
    let zero = write("zero.csv", "wavelength_nm,lamp\n400,0\n500,0\n700,0\n");
    let narrow = write(
        "narrowcam.csv",
        "wavelength_nm,r,g,b\n450,1,1,1\n550,1,1,1\n650,1,1,1\n",
    );
    fails(&dir, &["--spd", &no_header], "no header");
    fails(
        &dir,
        &["--spd", &bad_cell],
        "line 3, column 'lamp': 'x' is not a number",
    );
    fails(&dir, &["--spd", &unsorted], "unsorted wavelength");
    fails(&dir, &["--spd", &duplicate], "duplicate wavelength");
    fails(&dir, &["--spd", &negative], "negative");
    fails(&dir, &["--spd", &zero], "zero everywhere");
    fails(
        &dir,
        &["--spd", "D65", "--camera", &narrow],
        "must cover 400–700 nm",
    );
    fails(
        &dir,
        &["--spd", "D65", "--camera", "canon_nope"],
        "nikon_d5100_npl",
    );
    fails(&dir, &["--spd", "sunshine"], "unknown light 'sunshine'");
    fails(
        &dir,
        &["--spd", "D65", "--chart", "macbeth"],
        "colorchecker24",
    );
    fails(
        &dir,
        &["--spd", "D65", "--noise", "loud"],
        "unknown noise preset",
    );
    fails(&dir, &["--spd", "D65", "--bit-depth", "12"], "12");
    let missing = dir.join("missing").join("x.png");
    let o = spdcam(&["render", "--spd", "D65", "-o", missing.to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("does not exist"), "{}", stderr(&o));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn list_prints_builtins() {
    let o = spdcam(&["list"]);
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    for expected in [
        "nikon_d5100_npl",
        "sigma_sd_merrill_npl",
        "colorchecker24",
        "D65",
        "thesis",
        "phone",
    ] {
        assert!(text.contains(expected), "{expected} missing from: {text}");
    }
}

#[test]
fn scene_photos_and_drawn_lights() {
    let dir = scratch("scene");
    let photo = dir.join("scene.jpg");
    let truth = dir.join("truth.csv");
    let o = spdcam(&[
        "render",
        "--lighting",
        "phosphor",
        "--draw",
        "4",
        "--scene",
        "640x480",
        "-o",
        photo.to_str().unwrap(),
        "--spd-out",
        truth.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let decoded = image::open(&photo).unwrap();
    assert_eq!((decoded.width(), decoded.height()), (640, 480));
    let text = std::fs::read_to_string(&truth).unwrap();
    assert!(text.starts_with("wavelength_nm,phosphor draw 4 (seed 0)\n380,"));
    let max = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse::<f64>().unwrap())
        .fold(0.0, f64::max);
    assert_eq!(max, 1.0);

    let bad = dir.join("bad");
    std::fs::create_dir_all(&bad).unwrap();
    fails(
        &bad,
        &["--spd", "D65", "--scene", "640x480"],
        "name the output FILE.jpg",
    );
    fails(
        &bad,
        &["--lighting", "candle", "--draw", "0"],
        "unknown lighting family 'candle'",
    );
}
