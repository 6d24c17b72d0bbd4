//! Inputs read the wrong way or answered silently wrong (issue 39): lamp tables with a zero
//! end and noise, pipes and devices as inputs, spectra not in nanometres, limits written
//! as spdcam prints them, truths that miss the scored range, `--range` and the colorimetry,
//! huge and tiny numbers in messages, and messages that say what to do. First tier: every
//! run goes through `common::fresh_clone_command` and reads no measured data.

mod common;

use common::{fails_fast, fresh_clone_command, refusal, s, scratch, spdcam};
use spdcam_core::builtin::DATA_DIR_ENV;
use std::path::{Path, PathBuf};
use std::process::Output;
use std::time::Instant;

/// The example photo of the repository and its truth.
fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(name)
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Runs spdcam, which must succeed; its standard output and standard error.
fn succeeds(args: &[&str]) -> (String, String) {
    let out = spdcam(args);
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert!(
        out.status.success(),
        "spdcam {args:?} failed:\n{stdout}\n{stderr}"
    );
    (stdout, stderr)
}

/// Runs `script` in bash with `$SPDCAM` the built spdcam, as a user's shell would (for
/// process substitution, `<(…)`).
fn shell(script: &str) -> Output {
    std::process::Command::new("bash")
        .args(["-c", script])
        .env("SPDCAM", env!("CARGO_BIN_EXE_spdcam"))
        .env_remove(DATA_DIR_ENV)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("bash runs")
}

/// A fluorescent-like lamp as colour-science and ISETCam tabulate them: 380–780 nm at 5 nm,
/// a low continuum, narrow mercury and phosphor lines, and 0 at 780 nm (a synthetic
/// spectrum, not any library's data). `noise` is added at the two ends.
fn lamp_csv(noise: [f64; 2]) -> String {
    let lines = [(405.0, 0.3), (435.0, 0.8), (545.0, 1.0), (610.0, 0.9)];
    let mut out = String::from("wavelength_nm,tl841\n");
    for i in 0..81 {
        let w = 380.0 + 5.0 * i as f64;
        let mut v = 0.03 + 0.04 * (-((w - 600.0) / 80.0).powi(2)).exp();
        for (centre, height) in lines {
            if (w - centre).abs() < 1e-9 {
                v += height;
            }
        }
        if i == 0 {
            v = noise[0];
        }
        if i == 80 {
            v = noise[1];
        }
        out.push_str(&format!("{w},{v}\n"));
    }
    out
}

#[test]
fn a_lamp_table_ending_in_zero_renders_as_a_chart_and_a_scene() {
    // Issue 39, item 5: Sprague's undershoot beside the 0 at 780 nm was blamed on the file.
    let dir = scratch("lamp");
    let lamp = dir.join("tl841.csv");
    std::fs::write(&lamp, lamp_csv([0.03, 0.0])).unwrap();
    let lamp = s(&lamp);
    let (_, stderr) = succeeds(&["render", "--spd", &lamp, "-o", &s(&dir.join("c.png"))]);
    assert!(!stderr.contains("negative"), "{stderr}");
    assert!(dir.join("c.png").is_file());
    succeeds(&[
        "render",
        "--spd",
        &lamp,
        "--scene",
        "640x480",
        "-o",
        &s(&dir.join("s.jpg")),
    ]);
    assert!(dir.join("s.jpg").is_file());
}

#[test]
fn small_negative_noise_is_set_to_zero_with_a_note_and_large_is_refusal() {
    // Issue 39, item 5: the tolerance is 1 % of the peak (README, named_light::SPD_NEGATIVE_TOLERANCE).
    let dir = scratch("noise");
    let noisy = dir.join("noisy.csv");
    std::fs::write(&noisy, lamp_csv([-0.004, -0.002])).unwrap();
    let (_, stderr) = succeeds(&["render", "--spd", &s(&noisy), "-o", &s(&dir.join("c.png"))]);
    assert!(
        stderr.contains("note:")
            && stderr.contains("column 'tl841'")
            && stderr.contains("set to 0")
            && stderr.contains("1 %"),
        "{stderr}"
    );
    let bad = dir.join("bad.csv");
    std::fs::write(&bad, lamp_csv([0.03, -0.2])).unwrap();
    let e = fails_fast(&["render", "--spd", &s(&bad), "-o", &s(&dir.join("d.png"))]);
    for part in ["bad.csv", "column 'tl841'", "780 nm", "-0.2", "1 %"] {
        assert!(e.contains(part), "{part}: {e}");
    }
    assert!(!dir.join("d.png").exists());
}

#[test]
fn pipes_and_devices_are_read_as_files_are() {
    // Issue 39, item 6: `<(…)` and /dev/zero were said not to exist.
    let dir = scratch("pipes");
    let lamp = dir.join("lamp.csv");
    std::fs::write(&lamp, lamp_csv([0.03, 0.0])).unwrap();
    let (from_file, _) = succeeds(&["metrics", &s(&lamp), "--json"]);
    let piped = shell(&format!("\"$SPDCAM\" metrics <(cat '{}') --json", s(&lamp)));
    assert!(piped.status.success(), "{}", text(&piped.stderr));
    assert_eq!(text(&piped.stdout), from_file);
    let piped = shell(&format!(
        "\"$SPDCAM\" render --spd <(cat '{}') -o '{}'",
        s(&lamp),
        s(&dir.join("p.png"))
    ));
    assert!(piped.status.success(), "{}", text(&piped.stderr));
    assert!(dir.join("p.png").is_file());
    let png = s(&dir.join("z.png"));
    for args in [
        vec!["metrics", "/dev/zero"],
        vec!["render", "--spd", "/dev/zero", "-o", &png],
    ] {
        let e = fails_fast(&args);
        assert!(
            e.contains("/dev/zero") && e.contains("not a text file") && !e.contains("not exist"),
            "{args:?}: {e}"
        );
    }
    let e = fails_fast(&["metrics", &s(&dir.join("missing.csv"))]);
    assert!(e.contains("does not exist"), "{e}");
}

#[test]
fn a_photo_that_is_no_image_is_refused_from_its_first_bytes() {
    // Issue 39, item 11: `estimate /dev/zero` read 1 GiB before refusing.
    let started = Instant::now();
    let out = fresh_clone_command(&["estimate", "/dev/zero"])
        .output()
        .unwrap();
    let e = refusal(&out, started, 10, "estimate /dev/zero");
    assert!(
        e.contains("/dev/zero")
            && e.contains("JPEG, PNG, TIFF or camera raw")
            && e.contains("00 00"),
        "{e}"
    );
    let dir = scratch("notimage");
    let csv = dir.join("photo.jpg");
    std::fs::write(&csv, "wavelength_nm,a\n400,1\n410,1\n").unwrap();
    let e = fails_fast(&["estimate", &s(&csv)]);
    assert!(
        e.contains("not a JPEG, PNG, TIFF or camera raw image"),
        "{e}"
    );
}

#[test]
fn wavelengths_not_in_nanometres_are_refusal() {
    // Issue 39, item 6: a spectral CSV in µm gave exit 0 and "no visible light".
    let dir = scratch("micrometres");
    let um = dir.join("um.csv");
    let rows: String = (0..=40)
        .map(|i| format!("{},1\n", 0.38 + 0.01 * i as f64))
        .collect();
    std::fs::write(&um, format!("wavelength_nm,lamp\n{rows}")).unwrap();
    let png = s(&dir.join("um.png"));
    for args in [
        vec!["metrics", &s(&um)],
        vec!["render", "--spd", &s(&um), "-o", &png],
    ] {
        let e = fails_fast(&args);
        assert!(
            e.contains("micrometres") && e.contains("nm") && e.contains("0.38"),
            "{args:?}: {e}"
        );
    }
}

#[test]
fn limits_are_read_as_spdcam_prints_them_and_a_bad_value_is_named() {
    // Issue 39, item 7: `1e6` and `1,000,000` were silently ignored.
    let dir = scratch("limits");
    let png = s(&dir.join("c.png"));
    for value in ["1e3", "1,000", "1_000"] {
        let out = fresh_clone_command(&["render", "--spd", "D65", "-o", &png])
            .env("SPDCAM_MAX_RENDER_PIXELS", value)
            .output()
            .unwrap();
        let e = refusal(&out, Instant::now(), 20, value);
        assert!(
            e.contains("SPDCAM_MAX_RENDER_PIXELS") && e.contains("exceed the limit of 1,000"),
            "{value}: {e}"
        );
    }
    let out = fresh_clone_command(&["render", "--spd", "D65", "-o", &png])
        .env("SPDCAM_MAX_RENDER_PIXELS", "lots")
        .output()
        .unwrap();
    let e = refusal(&out, Instant::now(), 20, "lots");
    assert!(
        e.contains("SPDCAM_MAX_RENDER_PIXELS") && e.contains("\"lots\""),
        "{e}"
    );
    assert!(!dir.join("c.png").exists());
}

#[test]
fn a_truth_that_misses_the_scored_range_gives_no_score() {
    // Issue 39, item 12: truths in µm, at 200–245 nm and at 480–495 nm were scored.
    let dir = scratch("truth");
    let photo = s(&example("sg-telelumen.jpg"));
    let write = |name: &str, wavelengths: &[f64]| {
        let path = dir.join(name);
        let rows: String = wavelengths.iter().map(|w| format!("{w},1\n")).collect();
        std::fs::write(&path, format!("wavelength_nm,t\n{rows}")).unwrap();
        s(&path)
    };
    let steps = |a: f64, b: f64, step: f64| -> Vec<f64> {
        (0..=((b - a) / step).round() as usize)
            .map(|i| a + step * i as f64)
            .collect()
    };
    for (truth, expected) in [
        (write("uv.csv", &steps(200.0, 245.0, 5.0)), "misses"),
        (write("narrow.csv", &steps(480.0, 495.0, 5.0)), "480–495 nm"),
        (write("um.csv", &steps(0.38, 0.78, 0.01)), "micrometres"),
    ] {
        let e = fails_fast(&["estimate", &photo, "--truth", &truth]);
        assert!(
            e.contains(expected) && !e.contains("GFC 0."),
            "{truth}: {e}"
        );
    }
    // A truth that misses a few nm is scored, with a warning naming the ranges.
    let close = write("close.csv", &steps(405.0, 700.0, 5.0));
    let (stdout, stderr) = succeeds(&["estimate", &photo, "--truth", &close]);
    assert!(stdout.contains("GFC"), "{stdout}");
    assert!(
        stderr.contains("405–700 nm") && stderr.contains("400–700 nm"),
        "{stderr}"
    );
}

/// The first estimate's `key` (an object) in `estimate --json` output.
fn json_field(stdout: &str, key: &str) -> serde_json::Value {
    let v: serde_json::Value = serde_json::from_str(stdout).unwrap();
    v[0][key].clone()
}

#[test]
fn the_range_changes_what_is_shown_not_the_colorimetry() {
    // Issue 39, item 13: `--range 500-600` moved xy; `--range 550-550` gave the locus.
    let photo = s(&example("sg-telelumen.jpg"));
    let (full, _) = succeeds(&["estimate", &photo, "--json"]);
    let (narrow, _) = succeeds(&["estimate", &photo, "--json", "--range", "500-600"]);
    for key in ["colorimetry", "metrics", "verdict"] {
        assert_eq!(
            json_field(&full, key),
            json_field(&narrow, key),
            "{key} moved with --range"
        );
    }
    for (range, expected) in [
        ("550-550", "single wavelength"),
        // Issue 55: two wavelengths 5 nm apart were estimated and scored.
        ("550-555", "too few to be a spectrum"),
        ("500-540:1", "too few to be a spectrum"),
        ("300-400", "the model estimates"),
    ] {
        let e = fails_fast(&["estimate", &photo, "--range", range]);
        assert!(e.contains(expected), "{range}: {e}");
    }
}

#[test]
fn huge_and_tiny_numbers_are_short_in_messages() {
    // Issue 39, item 20: 300-digit numbers.
    let photo = s(&example("sg-telelumen.jpg"));
    let tiny = ["1e-300"; 8].join(",");
    let dir = scratch("numbers");
    let png = s(&dir.join("c.png"));
    let features = dir.join("features.csv");
    // The ColorChecker 24's features, every one 1e-300 (a black chart).
    let names: Vec<String> = (1..=24)
        .flat_map(|k| ["r", "g", "b"].map(|c| format!("p{k:02}_{c}")))
        .collect();
    std::fs::write(
        &features,
        format!("{}\n{}\n", names.join(","), vec!["1e-300"; 72].join(",")),
    )
    .unwrap();
    for args in [
        vec!["estimate", &photo, "--corners", &tiny],
        vec![
            "render",
            "--lighting",
            "lamp:phosphor-led:spread=1e300",
            "--draw",
            "0",
            "-o",
            &png,
        ],
        vec!["render", "--spd", "daylight:1e300", "-o", &png],
        vec!["estimate", &photo, "--range", "400-700:1e-300"],
        vec!["estimate", "--features", &s(&features)],
    ] {
        let e = fails_fast(&args);
        assert!(
            e.lines().all(|l| l.chars().count() < 400) && !e.contains("0000000000"),
            "{args:?}: {e}"
        );
        assert!(
            e.contains("e300") || e.contains("e-300") || e.contains("e302"),
            "{args:?}: {e}"
        );
    }
}

#[test]
fn messages_say_what_is_wrong_and_what_to_do() {
    // Issue 39, item 21.
    let dir = scratch("messages");
    let photo = s(&example("sg-telelumen.jpg"));
    let spectral = dir.join("spectral.csv");
    std::fs::write(&spectral, lamp_csv([0.03, 0.0])).unwrap();
    let features = dir.join("features.csv");
    std::fs::write(&features, "p01_r,p01_g,p01_b\n10,20,30\n").unwrap();
    let e = fails_fast(&[
        "dataset",
        "import",
        "--features",
        &s(&features),
        "--spds",
        &s(&spectral),
        "-o",
        &s(&dir.join("ds")),
    ]);
    assert!(
        e.contains("spectral CSV") && e.contains("one per row") && e.contains("transpose"),
        "{e}"
    );
    let e = fails_fast(&[
        "fit-in-camera",
        "--features",
        &s(&features),
        "--spds",
        &s(&spectral),
        "-o",
        &s(&dir.join("cal.json")),
    ]);
    assert!(e.contains("spectral CSV") && e.contains("transpose"), "{e}");
    // SPDs in units the camera's single precision cannot hold: only the shape matters, so
    // they are divided by their peak (with a note) and render as the unscaled file does; a
    // truth so scaled scores as the unscaled one.
    let unscaled = dir.join("x1.csv");
    std::fs::write(&unscaled, lamp_csv([0.03, 0.0])).unwrap();
    // The chart's patches as rendered (mean sRGB 0–255 each).
    let patches = |spd: &Path, name: &str| -> (Vec<f64>, String) {
        let features = dir.join(format!("{name}.features.csv"));
        let (_, err) = succeeds(&[
            "render",
            "--spd",
            &s(spd),
            "-o",
            &s(&dir.join(format!("{name}.png"))),
            "--features",
            &s(&features),
        ]);
        let text = std::fs::read_to_string(&features).unwrap();
        let row = text.lines().nth(1).unwrap();
        (row.split(',').map(|v| v.parse().unwrap()).collect(), err)
    };
    let (reference, plain_err) = patches(&unscaled, "x1");
    assert!(!plain_err.contains("divided by its peak"), "{plain_err}");
    let score = |truth: &Path| {
        let (out, _) = succeeds(&[
            "estimate",
            &s(&example("cc24-led.jpg")),
            "--truth",
            &s(truth),
            "--json",
        ]);
        json_field(&out, "truth")["gfc"].as_f64().unwrap()
    };
    let reference_gfc = score(&unscaled);
    for factor in ["1e308", "1e-320"] {
        let scaled = dir.join(format!("x{factor}.csv"));
        let rows: String = lamp_csv([0.03, 0.0])
            .lines()
            .skip(1)
            .map(|l| {
                let (w, v) = l.split_once(',').unwrap();
                format!(
                    "{w},{}\n",
                    v.parse::<f64>().unwrap() * factor.parse::<f64>().unwrap()
                )
            })
            .collect();
        std::fs::write(&scaled, format!("wavelength_nm,tl841\n{rows}")).unwrap();
        let (rendered, e) = patches(&scaled, factor);
        assert!(
            e.contains("divided by its peak") && e.contains("column 'tl841'"),
            "{factor}: {e}"
        );
        // The same chart but for the last bits (subnormal values carry fewer digits).
        assert!(
            rendered
                .iter()
                .zip(&reference)
                .all(|(a, b)| (a - b).abs() <= 1.0),
            "{factor}: {rendered:?} against {reference:?}"
        );
        // The same score, to the digits a subnormal file holds (1e-320 is a multiple of
        // 4.9e-324: about three significant digits).
        let gfc = score(&scaled);
        assert!(
            (gfc - reference_gfc).abs() < 1e-3,
            "{factor}: GFC {gfc} against {reference_gfc}"
        );
    }
    let e = fails_fast(&["estimate", &photo, "--truth", &photo]);
    assert!(
        e.contains("JPEG image") && e.contains("spectral CSV") && !e.contains("UTF-8"),
        "{e}"
    );
}

#[cfg(feature = "train")]
#[test]
fn a_ridge_too_large_for_the_solver_is_refused_with_the_usable_range() {
    // Issue 39, item 21: `train --ridge 1e308` ended in "NonPositivePivot { index: 0 }".
    let dir = scratch("ridge");
    let e = fails_fast(&[
        "train",
        "--data",
        &s(&dir.join("no-data")),
        "--model",
        "linear",
        "--ridge",
        "1e308",
        "-o",
        &s(&dir.join("m.spdm")),
    ]);
    assert!(
        e.contains("--ridge 1e308") && e.contains("too large") && e.contains("up to 1e6"),
        "{e}"
    );
    assert!(!e.contains("Pivot"), "{e}");
}
