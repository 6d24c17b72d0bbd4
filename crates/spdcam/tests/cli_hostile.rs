//! Hostile and careless input on the command line (issue 15): every case gets a clear
//! error at once — no abort, no minutes of work, no lost output, no silent overwrite.

mod common;

use common::{s, scratch, spdcam};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// Runs spdcam, expects it to fail within a few seconds with an error (not a signal or a
/// panic), and returns its stderr.
fn fails_fast(args: &[&str]) -> String {
    let started = Instant::now();
    let out = spdcam(args);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "spdcam {args:?} succeeded");
    // 1: the work was refused; 2: an option's value was (a usage error, clap's convention).
    assert!(
        matches!(out.status.code(), Some(1 | 2)),
        "spdcam {args:?} died: {stderr}"
    );
    assert!(
        started.elapsed() < Duration::from_secs(20),
        "spdcam {args:?} took {:?}",
        started.elapsed()
    );
    assert!(stderr.lines().any(|l| l.starts_with("error: ")), "{stderr}");
    stderr
}

#[test]
fn sizes_from_options_are_capped_with_a_clear_error() {
    // Issue 15, item 4: these aborted on allocation or ran for minutes with gigabytes.
    let dir = scratch("caps");
    let png = dir.join("c.png");
    let jpg = dir.join("c.jpg");
    for (args, limit) in [
        (vec!["--patch-px", "100000"], "SPDCAM_MAX_RENDER_PIXELS"),
        (vec!["--size", "200000x200000"], "SPDCAM_MAX_RENDER_PIXELS"),
        (
            vec!["--white-balance", "grey-edge:1:1e9"],
            "SPDCAM_MAX_FILTER_SIGMA",
        ),
    ] {
        let png = s(&png);
        let mut all = vec!["render", "--spd", "D65", "-o", &png];
        all.extend(args.iter().copied());
        let e = fails_fast(&all);
        assert!(e.contains(limit), "{args:?}: {e}");
    }
    let e = fails_fast(&[
        "render",
        "--spd",
        "D65",
        "--scene",
        "100000x100000",
        "-o",
        &s(&jpg),
    ]);
    assert!(e.contains("SPDCAM_MAX_RENDER_PIXELS"), "{e}");
    let out = dir.join("d");
    let e = fails_fast(&[
        "generate",
        "--lighting",
        "gaussian:4",
        "--count",
        "1000000000000",
        "-o",
        &s(&out),
    ]);
    assert!(e.contains("SPDCAM_MAX_SAMPLES"), "{e}");
    let e = fails_fast(&[
        "generate",
        "--lighting",
        "gaussian:4",
        "--count",
        "10",
        "--spd-grid",
        "380-780:0.00001",
        "-o",
        &s(&out),
    ]);
    assert!(e.contains("SPDCAM_MAX_GRID_BANDS"), "{e}");
    assert!(!out.exists() || std::fs::read_dir(&out).unwrap().count() == 0);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_negative_exposure_is_named_not_mistaken_for_an_option() {
    // Issue 15, item 13: `--exposure -1` was rejected by the argument parser.
    let dir = scratch("exposure");
    let e = fails_fast(&[
        "render",
        "--spd",
        "D65",
        "--exposure",
        "-1",
        "-o",
        &s(&dir.join("c.png")),
    ]);
    assert!(e.contains("--exposure -1") && e.contains("positive"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn help_names_the_files_generate_writes() {
    let out = spdcam(&["generate", "--help"]);
    let help = String::from_utf8_lossy(&out.stdout);
    assert!(help.contains("samples/part-NNNNN.parquet"), "{help}");
    assert!(!help.contains("samples-NNNNN"), "{help}");
}

#[test]
fn dash_writes_to_standard_output() {
    // Issue 15, item 13: `-o -` wrote a file named `-`.
    let dir = scratch("stdout");
    let out = Command::new(env!("CARGO_BIN_EXE_spdcam"))
        .args(["render", "--spd", "D65", "--noise", "off", "-o", "-"])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.stdout.starts_with(b"\x89PNG"), "stdout is the PNG");
    let png = dir.join("c.png");
    let features = Command::new(env!("CARGO_BIN_EXE_spdcam"))
        .args([
            "render",
            "--spd",
            "D65",
            "--noise",
            "off",
            "-o",
            &s(&png),
            "--features",
            "-",
        ])
        .current_dir(&dir)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&features.stdout);
    assert!(text.starts_with("p01_r,p01_g,p01_b,"), "{text}");
    assert!(!dir.join("-").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(feature = "train")]
#[test]
fn train_refuses_an_unwritable_model_path_before_training() {
    // Issue 15, item 6: `train -o DIR` failed only after training finished.
    let dir = scratch("train-out");
    let e = fails_fast(&[
        "train",
        "--model",
        "mlp",
        "--data",
        &s(&dir.join("no-such-data")),
        "-o",
        &s(&dir),
    ]);
    assert!(e.contains("is a directory"), "{e}");
    let e = fails_fast(&[
        "train",
        "--model",
        "mlp",
        "--data",
        &s(&dir.join("no-such-data")),
        "-o",
        &s(&dir.join("missing/m.spdm")),
    ]);
    assert!(e.contains("does not exist"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(feature = "train")]
#[test]
fn evaluate_refuses_to_overwrite_a_directory_of_user_files() {
    // Issue 15, item 10: `evaluate -o` overwrote a user's files while export/split refuse.
    let dir = scratch("evaluate-out");
    std::fs::write(dir.join("samples.csv"), "my own file").unwrap();
    let e = fails_fast(&[
        "evaluate",
        "--model",
        &s(&dir.join("m.spdm")),
        "--data",
        &s(&dir),
        "-o",
        &s(&dir),
    ]);
    assert!(e.contains("not empty") && e.contains("--force"), "{e}");
    assert_eq!(
        std::fs::read_to_string(dir.join("samples.csv")).unwrap(),
        "my own file"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_damaged_dataset_fails_verification_and_a_failed_import_leaves_nothing() {
    // Issue 15, items 7 and 9.
    let dir = scratch("verify");
    let data = dir.join("d");
    let out = spdcam(&[
        "generate",
        "--lighting",
        "gaussian:4",
        "--count",
        "20",
        "--chunk-size",
        "8",
        "--fast",
        "-o",
        &s(&data),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let ok = spdcam(&["dataset", "info", &s(&data), "--verify"]);
    let text = String::from_utf8_lossy(&ok.stdout);
    assert!(
        ok.status.success() && text.contains("verified: 3 files, 20 samples"),
        "{text}"
    );
    let part = data.join("samples/part-00001.parquet");
    let mut bytes = std::fs::read(&part).unwrap();
    let at = bytes.len() / 2;
    bytes[at] ^= 1;
    std::fs::write(&part, bytes).unwrap();
    let e = fails_fast(&["dataset", "info", &s(&data), "--verify"]);
    assert!(
        e.contains("part-00001.parquet") && e.contains("checksum"),
        "{e}"
    );
    let e = fails_fast(&[
        "dataset",
        "export",
        &s(&data),
        "--csv",
        "-o",
        &s(&dir.join("csv")),
    ]);
    assert!(e.contains("checksum"), "{e}");

    std::fs::write(dir.join("f.csv"), "p01_r,p01_g,p01_b\n1,2,3\n").unwrap();
    std::fs::write(dir.join("s.csv"), "400,500\n-1,1\n").unwrap();
    let (f, spds, imported) = (dir.join("f.csv"), dir.join("s.csv"), dir.join("imported"));
    let import = [
        "dataset",
        "import",
        "--features",
        &s(&f),
        "--spds",
        &s(&spds),
        "-o",
        &s(&imported),
    ];
    let e = fails_fast(&import);
    assert!(e.contains("negative"), "{e}");
    assert!(!dir.join("imported").exists());
    std::fs::write(dir.join("s.csv"), "400,500\n1,1\n").unwrap();
    let again = spdcam(&import);
    assert!(
        again.status.success(),
        "{}",
        String::from_utf8_lossy(&again.stderr)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The example photo committed with the repository (a ColorChecker Digital SG).
fn example_photo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/sg-telelumen.jpg")
}

#[test]
fn nonsense_features_and_truths_get_no_spd() {
    // Issue 15, item 5: all-zero features printed "CCT 6744 K", negative features were
    // accepted, a greyscale photo got an SPD, an all-zero truth printed GFC 0.0000.
    let dir = scratch("nonsense");
    let features = dir.join("f.csv");
    let out = spdcam(&[
        "estimate",
        &s(&example_photo()),
        "--features-out",
        &s(&features),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&features).unwrap();
    let (header, row) = text.trim().split_once('\n').unwrap();
    let values: Vec<f64> = row.split(',').map(|v| v.parse().unwrap()).collect();
    let write = |name: &str, values: &[f64]| {
        let path = dir.join(name);
        let cells: Vec<String> = values.iter().map(|v| v.to_string()).collect();
        std::fs::write(&path, format!("{header}\n{}\n", cells.join(","))).unwrap();
        path
    };
    let zero = write("zero.csv", &vec![0.0; values.len()]);
    let e = fails_fast(&["estimate", "--features", &s(&zero)]);
    assert!(e.contains("black") && !e.contains("CCT"), "{e}");
    let mut negative = values.clone();
    negative[4] = -3.0;
    let e = fails_fast(&["estimate", "--features", &s(&write("neg.csv", &negative))]);
    assert!(e.contains("p02_g") && e.contains("-3"), "{e}");
    let grey: Vec<f64> = values
        .chunks(3)
        .flat_map(|p| {
            let mean = p.iter().sum::<f64>() / 3.0;
            [mean; 3]
        })
        .collect();
    let e = fails_fast(&["estimate", "--features", &s(&write("grey.csv", &grey))]);
    assert!(e.contains("greyscale"), "{e}");

    let truth = dir.join("zero-truth.csv");
    std::fs::write(&truth, "wavelength_nm,t\n380,0\n780,0\n").unwrap();
    let e = fails_fast(&[
        "estimate",
        "--features",
        &s(&features),
        "--truth",
        &s(&truth),
    ]);
    assert!(e.contains("zero everywhere"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_greyscale_photo_gets_no_spd() {
    let dir = scratch("greyscale");
    let grey = dir.join("grey.png");
    image::open(example_photo())
        .unwrap()
        .grayscale()
        .save(&grey)
        .unwrap();
    let e = fails_fast(&["estimate", &s(&grey)]);
    assert!(e.contains("grey.png"), "{e}");
    assert!(e.contains("greyscale"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_truncated_jpeg_is_estimated_with_a_warning() {
    // Issue 15, item 11: JPEGs cut at 90 % and 99 % decoded without a word.
    let dir = scratch("truncated");
    let bytes = std::fs::read(example_photo()).unwrap();
    let cut = dir.join("cut.jpg");
    std::fs::write(&cut, &bytes[..bytes.len() * 99 / 100]).unwrap();
    let out = spdcam(&["estimate", &s(&cut)]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("cut.jpg") && stderr.contains("truncated"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn estimates_go_to_standard_output_with_dash() {
    let dir = scratch("estimate-stdout");
    let out = Command::new(env!("CARGO_BIN_EXE_spdcam"))
        .args(["estimate", &s(&example_photo()), "-o", "-"])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.starts_with("wavelength_nm,sg-telelumen.jpg,sg-telelumen.jpg_lower68,"),
        "{text}"
    );
    assert_eq!(text.lines().count(), 62, "the CSV and nothing else: {text}");
    assert!(!dir.join("-").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_version_0_model_is_called_damaged_not_newer() {
    let dir = scratch("model-v0");
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/colorchecker_sg96.spdm");
    let mut bytes = std::fs::read(shipped).unwrap();
    bytes[8..12].copy_from_slice(&0u32.to_le_bytes());
    let model = dir.join("v0.spdm");
    std::fs::write(&model, bytes).unwrap();
    let e = fails_fast(&["estimate", &s(&example_photo()), "--model", &s(&model)]);
    assert!(
        e.contains("version 0") && e.contains("damaged") && !e.contains("newer"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn errors_about_wide_files_and_bad_cells_stay_short_and_precise() {
    // Issue 15, item 13: a 2000-column CSV error listed every column (a 13 kB line); "a
    // feature is NaN" named no row or column.
    let dir = scratch("wide");
    let wide = dir.join("wide.csv");
    let names: Vec<String> = (0..2000).map(|i| format!("channel_{i}")).collect();
    let row = |w: u32| {
        std::iter::once(w.to_string())
            .chain((0..2000).map(|_| "0.5".to_string()))
            .collect::<Vec<_>>()
            .join(",")
    };
    std::fs::write(
        &wide,
        format!(
            "wavelength_nm,{}\n{}\n{}\n",
            names.join(","),
            row(400),
            row(700)
        ),
    )
    .unwrap();
    let png = dir.join("c.png");
    let e = fails_fast(&[
        "render",
        "--spd",
        "D65",
        "--camera",
        &s(&wide),
        "-o",
        &s(&png),
    ]);
    assert!(e.len() < 600, "{} bytes: {e}", e.len());
    assert!(e.contains("2000 in all"), "{e}");

    let features = dir.join("nan.csv");
    // ColorChecker 24 features (72 columns, a shipped model reads them), p01_g of the
    // second row NaN.
    let header: Vec<String> = (1..=24)
        .flat_map(|p| ["r", "g", "b"].map(|c| format!("p{p:02}_{c}")))
        .collect();
    let row = |second: &str| {
        (0..72)
            .map(|i| {
                if i == 1 {
                    second.to_string()
                } else {
                    "50".to_string()
                }
            })
            .collect::<Vec<_>>()
            .join(",")
    };
    std::fs::write(
        &features,
        format!("{}\n{}\n{}\n", header.join(","), row("50"), row("nan")),
    )
    .unwrap();
    let e = fails_fast(&["estimate", "--features", &s(&features)]);
    assert!(
        e.contains("line 3") && e.contains("p01_g") && e.contains("NaN"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
