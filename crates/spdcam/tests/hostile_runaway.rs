//! Runaway resources, standard output and silently odd outputs (issue 39): option values
//! that asked for gigabytes are refused before any work, a full standard output is an
//! error (not a panic), `estimate --features` streams what it prints, odd lighting weights
//! and exposures are handled or refused. First tier: no measured data.

mod common;

use common::{fails_fast, fresh_clone_command, ok, s, scratch};
use std::fs::File;
use std::path::Path;
use std::process::{Output, Stdio};

/// A features CSV of `rows` copies of the row of a ColorChecker 24 rendered under D65.
fn features_csv(dir: &Path, rows: usize) -> String {
    let one = dir.join("one.csv");
    ok(&[
        "render",
        "--spd",
        "D65",
        "--noise",
        "off",
        "-o",
        &s(&dir.join("one.png")),
        "--features",
        &s(&one),
    ]);
    let text = std::fs::read_to_string(&one).unwrap();
    let (header, row) = text.trim_end().split_once('\n').unwrap();
    let mut csv = format!("{header}\n");
    for _ in 0..rows {
        csv.push_str(row);
        csv.push('\n');
    }
    let path = dir.join(format!("rows{rows}.csv"));
    std::fs::write(&path, csv).unwrap();
    s(&path)
}

#[test]
fn counts_and_sizes_that_ask_for_gigabytes_are_refused_before_any_work() {
    // Item 8: 1,000,000 camera variants aborted on a 40 GB allocation, a billion detection
    // photos on 64 GB, and `render --size 5000x5000 --stages` peaked at 2.66 GB.
    let dir = scratch("counts");
    let data = s(&dir.join("d"));
    let e = fails_fast(&[
        "generate",
        "--lighting",
        "planck",
        "--count",
        "5",
        "--fast",
        "--randomise",
        "camera",
        "--cameras",
        "nikon_d5100_npl",
        "--camera-variants",
        "1000000",
        "-o",
        &data,
    ]);
    assert!(
        e.contains("--camera-variants 1000000")
            && e.contains("bytes of a camera pool exceed the limit")
            && e.contains("SPDCAM_MAX_CAMERA_POOL_BYTES="),
        "{e}"
    );
    let e = fails_fast(&[
        "detection",
        "--photos",
        "1000000000",
        "--size",
        "64x64",
        "-o",
        &s(&dir.join("d.md")),
    ]);
    assert!(
        e.contains("--photos: 1,000,000,000 scene photos per bucket and chart exceed")
            && e.contains("SPDCAM_MAX_DETECTION_PHOTOS=1000000000"),
        "{e}"
    );
    let stages = dir.join("stages");
    let e = fails_fast(&[
        "render",
        "--spd",
        "D65",
        "--size",
        "5000x5000",
        "--stages",
        &s(&stages),
        "-o",
        &s(&dir.join("big.png")),
    ]);
    assert!(
        e.contains("--stages with a 5000×5000 chart") && e.contains("SPDCAM_MAX_RENDER_PIXELS"),
        "{e}"
    );
    assert!(
        !stages.exists(),
        "the refused run made {}",
        stages.display()
    );
    // A pool within the limit still generates.
    ok(&[
        "generate",
        "--lighting",
        "planck",
        "--count",
        "5",
        "--fast",
        "--randomise",
        "camera",
        "--cameras",
        "nikon_d5100_npl",
        "--camera-variants",
        "2",
        "-o",
        &data,
    ]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Runs spdcam with its standard output on a full disk (`/dev/full`).
fn to_full_disk(args: &[&str]) -> Output {
    fresh_clone_command(args)
        .stdout(Stdio::from(File::create("/dev/full").unwrap()))
        .output()
        .unwrap()
}

#[test]
fn a_full_standard_output_is_a_clear_error_not_a_panic() {
    // Item 10: "failed printing to stdout" panics (exit 101) on a full disk.
    if !Path::new("/dev/full").exists() {
        return;
    }
    let dir = scratch("full");
    let rows3 = features_csv(&dir, 3);
    let rows25 = features_csv(&dir, 25);
    let png = s(&dir.join("r.png"));
    let commands: Vec<Vec<&str>> = vec![
        vec!["list"],
        vec!["metrics", "D65"],
        vec!["metrics", "--json", "D65"],
        vec!["estimate", "--features", &rows3],
        vec!["estimate", "--features", &rows25],
        vec!["estimate", "--features", &rows3, "--json"],
        vec!["estimate", "--features", &rows3, "-o", "-"],
        vec!["render", "--spd", "D65", "--noise", "off", "-o", &png],
    ];
    for args in &commands {
        let out = to_full_disk(args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(
            stderr.contains("error: could not write to standard output: No space left on device"),
            "{args:?}: {stderr}"
        );
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_reader_that_stops_ends_spdcam_quietly() {
    // Item 10 keeps `spdcam … | head` quiet: the closed pipe ends spdcam without a word.
    let dir = scratch("pipe");
    let rows = features_csv(&dir, 40);
    let mut child = fresh_clone_command(&["estimate", "--features", &rows, "--json"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        !stderr.contains("error") && !stderr.contains("panicked"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn features_as_json_are_json_lines_written_row_by_row() {
    // Item 9: `--features F --json` held every row's JSON in one list till the end.
    let dir = scratch("jsonl");
    let rows = features_csv(&dir, 30);
    let stdout = ok(&["estimate", "--features", &rows, "--json"]);
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 30, "{stdout}");
    for (i, line) in lines.iter().enumerate() {
        let value: serde_json::Value = serde_json::from_str(line).unwrap();
        assert_eq!(value["name"], format!("estimate_{}", i + 1), "{line}");
        assert!(value["verdict"].is_string(), "{line}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn many_feature_rows_without_an_output_print_a_line_each() {
    // Item 17: 21 rows and no `-o` printed only "21 estimates with …".
    let dir = scratch("summary");
    let rows = features_csv(&dir, 23);
    let stdout = ok(&["estimate", "--features", &rows]);
    for i in 1..=23 {
        let line = stdout
            .lines()
            .find(|l| l.starts_with(&format!("estimate_{i}: ")))
            .unwrap_or_else(|| panic!("no line of row {i}:\n{stdout}"));
        assert!(
            line.contains("xy (") && line.contains("CCT ") && line.contains("verdict: "),
            "{line}"
        );
    }
    assert!(
        stdout.contains("one line per estimate as it is made (CIE xy, CCT, Duv, verdict)"),
        "{stdout}"
    );
    assert!(stdout.contains("23 estimates with"), "{stdout}");
    assert!(
        stdout.contains("-o FILE.csv writes them as CSV") && stdout.contains("JSON Lines"),
        "{stdout}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn mixture_proportions_near_the_largest_number_share_the_draws() {
    // Item 14: `mix:daylight=1e308,planck=1e308` drew 1,000 planck and 0 daylight.
    let dir = scratch("mix");
    let data = dir.join("d");
    ok(&[
        "generate",
        "--lighting",
        "mix:daylight=1e308,planck=1e308",
        "--count",
        "400",
        "--fast",
        "-o",
        &s(&data),
    ]);
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(data.join("manifest.json")).unwrap())
            .unwrap();
    let families = manifest["families"].as_object().expect("families");
    let count = |prefix: &str| -> u64 {
        families
            .iter()
            .filter(|(name, _)| name.contains(prefix))
            .map(|(_, n)| n.as_u64().unwrap())
            .sum()
    };
    let (daylight, planck) = (count("daylight"), count("planck"));
    assert!(
        (120..=280).contains(&daylight) && (120..=280).contains(&planck),
        "{families:?}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_exposure_too_low_to_hold_a_signal_is_fails_fast() {
    // Item 15: `--exposure 1e-10 --noise off` gave a white patch of (255, 255, 108).
    let dir = scratch("exposure");
    let png = s(&dir.join("c.png"));
    let e = fails_fast(&[
        "render",
        "--spd",
        "D65",
        "--exposure",
        "1e-10",
        "--noise",
        "off",
        "-o",
        &png,
    ]);
    assert!(
        e.contains("--exposure 1e-10") && e.contains("white patch") && e.contains("0.01"),
        "{e}"
    );
    assert!(!Path::new(&png).exists());
    let e = fails_fast(&[
        "generate",
        "--lighting",
        "planck",
        "--count",
        "5",
        "--exposure",
        "1e-10",
        "-o",
        &s(&dir.join("d")),
    ]);
    assert!(
        e.contains("--exposure 1e-10") && e.contains("white patch"),
        "{e}"
    );
    // A dim photo that still holds a signal renders.
    ok(&[
        "render",
        "--spd",
        "D65",
        "--exposure",
        "0.05",
        "--noise",
        "off",
        "-o",
        &png,
    ]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn stages_of_a_scene_are_refused_clearly() {
    // Item 16: `render --scene … --stages DIR` wrote nothing.
    let dir = scratch("scene-stages");
    let stages = dir.join("stages");
    let e = fails_fast(&[
        "render",
        "--spd",
        "D65",
        "--scene",
        "400x300",
        "--stages",
        &s(&stages),
        "-o",
        &s(&dir.join("p.jpg")),
    ]);
    assert!(e.contains("--stages") && e.contains("--scene"), "{e}");
    assert!(!stages.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
