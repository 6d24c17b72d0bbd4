//! Hostile and careless input on the command line (issue 15): every case gets a clear
//! error at once — no abort, no minutes of work, no lost output, no silent overwrite.
//! First tier: it reads no measured data (every run goes through
//! `common::fresh_clone_command`, which takes the data directory out of the environment, so
//! that the cases meet the program as a fresh clone has it).

mod common;

use common::{fails_fast, fresh_clone_command, s, scratch, spdcam};
use spdcam_core::builtin::DATA_DIR_ENV;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

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
    let out = fresh_clone_command(&["render", "--spd", "D65", "--noise", "off", "-o", "-"])
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
    let features = fresh_clone_command(&[
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

#[test]
fn a_colour_map_without_photos_or_a_place_to_go_is_refused_before_any_work() {
    let dir = scratch("colour-map");
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let model = s(&repo.join("models/colorchecker24.spdm"));
    let split = s(&repo.join("docs/validation-split.json"));
    let base = ["colour-map", "fit", "--model", &model, "--split", &split];
    let out = s(&dir.join("m.spdm"));
    let none = [&base[..], &["--photos", "0", "-o", &out]].concat();
    let e = fails_fast(&none);
    assert!(e.contains("a colour map needs photos"), "{e}");
    let nowhere = s(&dir.join("missing/m.spdm"));
    let e = fails_fast(&[&base[..], &["-o", &nowhere]].concat());
    assert!(e.contains("does not exist"), "{e}");
    assert!(!dir.join("m.spdm").exists());
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
        &s(&dir.join("data")),
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
    let out = fresh_clone_command(&["estimate", &s(&example_photo()), "-o", "-"])
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

/// spdcam (no data directory) with extra environment variables and, when given, a file as
/// its standard input.
fn spdcam_with(args: &[&str], env: &[(&str, &str)], stdin: Option<&Path>) -> std::process::Output {
    let mut command = fresh_clone_command(args);
    for (k, v) in env {
        command.env(k, v);
    }
    if let Some(path) = stdin {
        command.stdin(std::fs::File::open(path).unwrap());
    }
    command.output().expect("spdcam runs")
}

/// As [`fails_fast`], with extra environment variables.
fn fails_fast_with(args: &[&str], env: &[(&str, &str)]) -> String {
    let started = Instant::now();
    let out = spdcam_with(args, env, None);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    // 1: refused while running; 2: refused by the argument parser (a usage error).
    assert!(
        matches!(out.status.code(), Some(1) | Some(2)),
        "spdcam {args:?} {env:?}: {stderr}"
    );
    assert!(
        started.elapsed() < Duration::from_secs(20),
        "spdcam {args:?} took {:?}",
        started.elapsed()
    );
    assert!(stderr.lines().any(|l| l.starts_with("error: ")), "{stderr}");
    stderr
}

/// A small generated dataset (fast pipeline) in `dir`.
fn small_dataset(dir: &Path, count: &str, seed: &str) {
    let out = spdcam(&[
        "generate",
        "--lighting",
        "gaussian:4",
        "--count",
        count,
        "--seed",
        seed,
        "--chunk-size",
        "8",
        "--fast",
        "-o",
        &s(dir),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `dataset info --verify` of `dir` passes with `samples` samples.
fn verifies(dir: &Path, samples: u64) {
    let out = spdcam(&["dataset", "info", &s(dir), "--verify"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && text.contains(&format!("{samples} samples match")),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn an_output_that_is_holds_or_lies_inside_an_input_is_refused_before_anything_is_deleted() {
    // Issue 29, item 1: `dataset split DS -o DS --force` and `dataset export --csv DS -o DS
    // --force` emptied DS, then failed.
    let dir = scratch("apart");
    let data = dir.join("ds");
    small_dataset(&data, "20", "1");
    let d = s(&data);
    let nested = s(&data.join("parts"));
    let roundabout = s(&dir.join("new/../ds"));
    let whole = s(&dir);
    let cases: [(Vec<&str>, &str); 7] = [
        (vec!["dataset", "split", &d, "-o", &d, "--force"], "is"),
        (
            vec!["dataset", "export", &d, "--csv", "-o", &d, "--force"],
            "is",
        ),
        (
            vec!["dataset", "split", &d, "-o", &roundabout, "--force"],
            "is",
        ),
        (
            vec!["dataset", "split", &d, "-o", &nested, "--force"],
            "lies inside",
        ),
        (
            vec!["dataset", "split", &d, "-o", &whole, "--force"],
            "contains",
        ),
        (vec!["dataset", "merge", &d, "-o", &d, "--force"], "is"),
        (
            vec!["dataset", "export", &d, "--csv", "-o", &whole, "--force"],
            "contains",
        ),
    ];
    for (args, relation) in cases {
        let e = fails_fast(&args);
        assert!(
            e.contains(&format!(
                "the output -o {} {relation} the input",
                args[args.len() - 2]
            )) && e.contains(&format!("{d}: writing it would destroy what is read")),
            "{args:?}: {e}"
        );
        verifies(&data, 20);
    }
    assert!(!data.join("parts").exists() && !dir.join("new").exists());
    // Importing from a dataset's own export into that directory would remove the files read.
    let out = spdcam(&["dataset", "export", &d, "--csv", "-o", &s(&dir.join("csv"))]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = dir.join("csv");
    let (f, spds) = (s(&csv.join("features.csv")), s(&csv.join("spds.csv")));
    let e = fails_fast(&[
        "dataset",
        "import",
        "--features",
        &f,
        "--spds",
        &spds,
        "-o",
        &s(&csv),
        "--force",
    ]);
    assert!(e.contains("contains the input"), "{e}");
    assert!(csv.join("features.csv").is_file() && csv.join("spds.csv").is_file());
    // generate refuses a directory holding a file it reads.
    std::fs::write(dir.join("in.json"), "{}").unwrap();
    let e = fails_fast(&[
        "generate",
        "--lighting",
        "gaussian:4",
        "--count",
        "5",
        "--in-camera",
        &s(&dir.join("in.json")),
        "-o",
        &whole,
        "--force",
    ]);
    assert!(e.contains("contains the input"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_same_samples_twice_are_not_merged() {
    // Issue 29, item 9: `dataset merge ds ds -o m` (or ds and a copy) gave every sample
    // twice, without a word.
    let dir = scratch("merge-twice");
    let (a, b, c) = (dir.join("a"), dir.join("b"), dir.join("c"));
    small_dataset(&a, "16", "1");
    small_dataset(&c, "16", "2");
    std::fs::create_dir_all(b.join("samples")).unwrap();
    for name in [
        "manifest.json",
        "samples/part-00000.parquet",
        "samples/part-00001.parquet",
    ] {
        std::fs::copy(a.join(name), b.join(name)).unwrap();
    }
    let merged = s(&dir.join("m"));
    for second in [&a, &b] {
        let e = fails_fast(&["dataset", "merge", &s(&a), &s(second), "-o", &merged]);
        assert!(
            e.contains("hold the same samples: numbers 0–15 of one generate run")
                && e.contains("seed 1"),
            "{e}"
        );
        assert!(!dir.join("m").exists());
    }
    // A larger run with the same seed holds the same first samples.
    let longer = dir.join("longer");
    small_dataset(&longer, "24", "1");
    let e = fails_fast(&[
        "dataset",
        "merge",
        &s(&longer),
        &s(&c),
        &s(&a),
        "-o",
        &merged,
    ]);
    assert!(e.contains("numbers 0–15"), "{e}");
    // Different seeds are different samples.
    let out = spdcam(&["dataset", "merge", &s(&a), &s(&c), "-o", &merged]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && text.contains("32 samples"),
        "{text}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn pipes_and_devices_are_read_through_the_byte_cap() {
    // Issue 29, item 4: `estimate /dev/zero` reached 15.7 GB in 10 s. Since issue 39 its
    // first bytes refuse it (hostile_inputs.rs); a stream that starts as a JPEG does and
    // goes on for ever meets the cap.
    let cap = [("SPDCAM_MAX_PHOTO_BYTES", "100000")];
    let started = Instant::now();
    let mut child = fresh_clone_command(&["estimate", "/dev/stdin"])
        .envs(cap)
        .stdin(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || {
        use std::io::Write;
        // Written until spdcam stops reading (a broken pipe ends it).
        let _ = stdin.write_all(&[0xFF, 0xD8, 0xFF]);
        while stdin.write_all(&[0u8; 1 << 16]).is_ok() {}
    });
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap();
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.code() == Some(1) && started.elapsed() < Duration::from_secs(20),
        "{e}"
    );
    assert!(
        e.contains("/dev/stdin: unusable photo: more than 100,000 bytes of a photo")
            && e.contains("set SPDCAM_MAX_PHOTO_BYTES=N"),
        "{e}"
    );
    // A photo through a pipe is read as a file is, and capped the same way.
    let photo = example_photo();
    let out = spdcam_with(
        &["estimate", "/dev/stdin", "-o", "-"],
        &[],
        Some(photo.as_path()),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).starts_with("wavelength_nm,stdin"));
    let out = spdcam_with(&["estimate", "/dev/stdin"], &cap, Some(photo.as_path()));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.code() == Some(1) && e.contains("bytes of a photo") && e.contains("100,000"),
        "{e}"
    );
    // A features file without line breaks is refused at the line cap.
    let e = fails_fast_with(
        &["estimate", "--features", "/dev/zero"],
        &[("SPDCAM_MAX_TEXT_FILE_BYTES", "1000000")],
    );
    assert!(
        e.contains("/dev/zero line 1 (one line): more than 1,000,000 bytes of a text file"),
        "{e}"
    );
}

/// A spectral CSV of smooth SPDs on 380–780 nm at 5 nm (peak 1), one multiplied by each of
/// `factors`.
fn spectral_csv(path: &Path, factors: &[f64]) {
    let mut text = String::from("wavelength_nm");
    for k in 0..factors.len() {
        text += &format!(",s{k}");
    }
    text.push('\n');
    for i in 0..81 {
        let w = 380.0 + 5.0 * i as f64;
        // A warm-white-like smooth SPD: a Planckian-shaped rise with a blue bump.
        let base = ((w / 780.0).powi(4) + 0.4 * (-((w - 450.0) / 20.0).powi(2)).exp()) / 1.01;
        text += &format!("{w}");
        for f in factors {
            text += &format!(",{:e}", base * f);
        }
        text.push('\n');
    }
    std::fs::write(path, text).unwrap();
}

#[test]
fn extreme_but_finite_spds_give_the_metrics_of_the_unscaled_spd() {
    // Issue 29, item 11: scaled by 1e-320 Ra/R9/Rf/Rg were NaN (null, no reason); scaled by
    // 1e308 the SPD was refused as non-finite.
    let dir = scratch("extreme-spd");
    let csv = dir.join("s.csv");
    spectral_csv(&csv, &[1.0, 1e-300, 1e-320, 1e300, 1e308]);
    let out = spdcam(&["metrics", &s(&csv), "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = rows.as_array().unwrap();
    let value = |row: usize, key: &str| rows[row][key].as_f64();
    #[allow(clippy::needless_range_loop)] // `row` also picks the tolerance and the values
    for row in 1..rows.len() {
        assert!(
            rows[row]["reasons"].as_object().unwrap().is_empty(),
            "{}",
            rows[row]
        );
        // 1e-320 is subnormal: the file keeps only about 11 bits of each value.
        let tolerance = if row == 2 { 0.05 } else { 1e-9 };
        for key in [
            "cct_k", "cri_ra", "tm30_rf", "tm30_rg", "mel_der", "sp_ratio",
        ] {
            let (a, b) = (value(0, key).unwrap(), value(row, key).unwrap());
            assert!(
                (a - b).abs() <= tolerance * a.abs().max(1.0),
                "row {row} {key}: {a} vs {b}"
            );
        }
    }
    // A light whose metrics are undefined says why for each of them.
    let mut line = String::from("wavelength_nm,line\n");
    for i in 0..81 {
        let w = 380 + 5 * i;
        line += &format!("{w},{}\n", if w == 650 { "1e-320" } else { "0" });
    }
    std::fs::write(&csv, line).unwrap();
    let out = spdcam(&["metrics", &s(&csv), "--json"]);
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let m = &rows[0];
    for key in ["cct_k", "cri_ra", "tm30_rf", "tm30_rg"] {
        assert!(m[key].is_null(), "{m}");
        assert!(
            m["reasons"][key].as_str().is_some_and(|r| !r.is_empty()),
            "{m}"
        );
    }
    assert!(m["sp_ratio"].as_f64().is_some_and(f64::is_finite), "{m}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn coverage_draws_are_capped() {
    // Issue 29, item 5: `coverage --draws 100000000` reached 17.7 GB.
    let dir = scratch("coverage-draws");
    let csv = dir.join("s.csv");
    spectral_csv(&csv, &[1.0]);
    let e = fails_fast(&[
        "coverage",
        &s(&csv),
        "--lighting",
        "gaussian:4",
        "--draws",
        "100000000",
        "--no-fit",
    ]);
    assert!(
        e.contains("100,000,000 draws exceed the limit of 1,000,000")
            && e.contains("SPDCAM_MAX_DRAWS=100000000"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn exposure_above_one_clips_as_documented() {
    // Issue 29, item 6: `--exposure 1.5` was refused though the help says "above 1 clips".
    let dir = scratch("exposure-clips");
    let png = s(&dir.join("c.png"));
    // The ColorChecker 24's features; patches 19 and 20 are its white and lightest grey.
    let features = |exposure: &str| -> Vec<f64> {
        let out = spdcam(&[
            "render",
            "--spd",
            "D65",
            "--noise",
            "off",
            "--exposure",
            exposure,
            "-o",
            &png,
            "--features",
            "-",
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let text = String::from_utf8_lossy(&out.stdout).into_owned();
        text.lines()
            .nth(1)
            .unwrap()
            .split(',')
            .map(|v| v.parse().unwrap())
            .collect()
    };
    let patch = |f: &[f64], p: usize| f[3 * (p - 1)..3 * p].to_vec();
    let spread = |rgb: &[f64]| {
        rgb.iter().cloned().fold(f64::MIN, f64::max) - rgb.iter().cloned().fold(f64::MAX, f64::min)
    };
    let (under, normal, over, far) = (
        features("0.5"),
        features("1"),
        features("1.5"),
        features("3"),
    );
    // Up to 1 nothing clips: the exposure drops out with the white balance, and the white
    // stays white.
    assert_eq!(under, normal);
    assert!(
        spread(&patch(&normal, 19)) <= 3.0,
        "{:?}",
        patch(&normal, 19)
    );
    // Above 1 the brightest raw channel clips: the white takes a cast, and at 3 the white
    // and the lightest grey clip to one colour.
    assert_ne!(over, normal);
    assert!(spread(&patch(&over, 19)) > 10.0, "{:?}", patch(&over, 19));
    assert_eq!(patch(&far, 19), patch(&far, 20));
    assert_ne!(patch(&normal, 19), patch(&normal, 20));
    let help = String::from_utf8_lossy(&spdcam(&["render", "--help"]).stdout).into_owned();
    assert!(help.contains("above 1 clips"), "{help}");
    for (value, shown) in [("1e300", "1e300"), ("-1e300", "-1e300"), ("0", "0")] {
        let e = fails_fast(&["render", "--spd", "D65", "--exposure", value, "-o", &png]);
        assert!(
            e.contains(&format!("--exposure {shown} is not a positive fraction"))
                && e.contains("1.5 to clip")
                && !e.contains("00000000"),
            "{e}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn standard_output_carries_only_the_data() {
    // Issue 29, item 7: `render --features -` printed "rendered …" after the CSV.
    let dir = scratch("stdout-clean");
    let png = s(&dir.join("c.png"));
    let spd = s(&dir.join("spd.csv"));
    let out = spdcam(&[
        "render",
        "--spd",
        "D65",
        "--noise",
        "off",
        "-o",
        &png,
        "--features",
        "-",
        "--spd-out",
        &spd,
    ]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(text.lines().count(), 2, "{text}");
    assert!(
        text.starts_with("p01_r,") && !text.contains("rendered"),
        "{text}"
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("rendered colorchecker24 under D65") && stderr.contains("light SPD:"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_verdict_goes_to_standard_error_when_the_estimate_goes_to_standard_output() {
    // Issue 29, item 8: with `-o -` the verdict ("UNUSABLE" for a bad photo) was not shown.
    let out = spdcam(&["estimate", &s(&example_photo()), "-o", "-"]);
    assert!(out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr
            .lines()
            .any(|l| l.starts_with("sg-telelumen.jpg: verdict: ")
                || l.starts_with("sg-telelumen.jpg: UNUSABLE")),
        "{stderr}"
    );
    assert!(!String::from_utf8_lossy(&out.stdout).contains("verdict"));
    // An unusable estimate says so: features of the example photo with red and blue
    // swapped describe no light a camera sees.
    let dir = scratch("verdict-stderr");
    let features = dir.join("f.csv");
    let out = spdcam(&[
        "estimate",
        &s(&example_photo()),
        "--features-out",
        &s(&features),
    ]);
    assert!(out.status.success());
    let text = std::fs::read_to_string(&features).unwrap();
    let (header, row) = text.trim().split_once('\n').unwrap();
    let swapped: Vec<&str> = row
        .split(',')
        .collect::<Vec<_>>()
        .chunks(3)
        .flat_map(|p| [p[2], p[1], p[0]])
        .collect();
    std::fs::write(&features, format!("{header}\n{}\n", swapped.join(","))).unwrap();
    let quiet = spdcam(&["estimate", "--features", &s(&features), "-o", "-"]);
    let told = spdcam(&["estimate", "--features", &s(&features)]);
    let verdict = |o: &std::process::Output, from_stdout: bool| {
        let text = String::from_utf8_lossy(if from_stdout { &o.stdout } else { &o.stderr });
        text.lines()
            .find_map(|l| l.split_once("verdict: ").map(|(_, v)| v.to_string()))
            .unwrap_or_else(|| panic!("no verdict in {text}"))
    };
    assert_eq!(verdict(&quiet, false), verdict(&told, true));
    assert!(String::from_utf8_lossy(&quiet.stdout).starts_with("wavelength_nm,"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_cut_jpeg_is_called_truncated_and_a_flipped_bit_is_not() {
    // Issue 29, item 10: a JPEG cut in half said only "no chart found"; one flipped bit
    // in a complete file was called truncated.
    let dir = scratch("jpeg-ends");
    let bytes = std::fs::read(example_photo()).unwrap();
    let half = dir.join("half.jpg");
    std::fs::write(&half, &bytes[..bytes.len() / 2]).unwrap();
    let out = spdcam(&["estimate", &s(&half)]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("half.jpg") && stderr.contains("the JPEG file is truncated"),
        "{stderr}"
    );
    let flipped = dir.join("flipped.jpg");
    for k in 1..8 {
        let mut damaged = bytes.clone();
        let at = damaged.len() * k / 8;
        damaged[at] ^= 0x04;
        assert!(damaged.ends_with(&[0xFF, 0xD9]));
        std::fs::write(&flipped, &damaged).unwrap();
        let out = spdcam(&["estimate", &s(&flipped)]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!stderr.contains("truncated"), "bit at {at}: {stderr}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn errors_name_what_the_user_typed_and_how_to_go_on() {
    // Issue 29, item 12.
    let dir = scratch("clear-errors");
    let png = s(&dir.join("c.png"));
    let e = fails_fast(&[
        "render",
        "--spd",
        "D65",
        "--chart",
        "colorchecker_sg96",
        "-o",
        &png,
    ]);
    assert!(
        e.contains("chart colorchecker_sg96 needs its measured reflectances")
            && e.contains("no data directory is set")
            && e.contains("charts available without data: colorchecker24")
            && e.contains(&format!("--data-dir DIR or {DATA_DIR_ENV}"))
            && !e.contains("i1pro2"),
        "{e}"
    );
    // Huge numbers are written short.
    let corners = "1e300,0,100,0,100,100,0,100";
    let e = fails_fast(&["estimate", &s(&example_photo()), "--corners", corners]);
    assert!(e.contains("corner 1 (1e300, 0) lies outside"), "{e}");
    let features = dir.join("f.csv");
    let header: Vec<String> = (1..=24)
        .flat_map(|p| ["r", "g", "b"].map(|c| format!("p{p:02}_{c}")))
        .collect();
    let row: Vec<&str> = (0..72)
        .map(|i| if i == 4 { "1e300" } else { "50" })
        .collect();
    std::fs::write(
        &features,
        format!("{}\n{}\n", header.join(","), row.join(",")),
    )
    .unwrap();
    let e = fails_fast(&["estimate", "--features", &s(&features)]);
    assert!(e.contains("p02_g: 1e300 is outside 0–255"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(feature = "train")]
#[test]
fn a_diverging_training_says_so() {
    // Issue 29, item 12: `train --lr 1e30` said "parameter hidden0.weight holds non-finite
    // values".
    let dir = scratch("diverge");
    let data = dir.join("d");
    small_dataset(&data, "64", "1");
    let e = fails_fast(&[
        "train",
        "--model",
        "mlp",
        "--data",
        &s(&data),
        "--lr",
        "1e30",
        "--epochs",
        "3",
        "-o",
        &s(&dir.join("m.spdm")),
    ]);
    assert!(
        e.contains("training diverged at epoch 1")
            && e.contains("became non-finite")
            && e.contains("try a smaller learning rate than 1e30"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn every_limit_is_set_by_its_environment_variable() {
    // Issue 29: one place states every input limit; each can be lowered (or raised) for a
    // run, and the refusal names it.
    let dir = scratch("limits");
    let csv = dir.join("s.csv");
    spectral_csv(&csv, &[1.0, 2.0, 3.0]);
    let (csv, png, out) = (s(&csv), s(&dir.join("c.png")), s(&dir.join("d")));
    let photo = s(&example_photo());
    let model = s(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/colorchecker24.spdm"));
    let generate = |extra: &[&'static str]| -> Vec<String> {
        let mut args: Vec<String> = ["generate", "--lighting", "gaussian:4", "--fast", "-o", &out]
            .map(String::from)
            .to_vec();
        args.extend(extra.iter().map(|a| a.to_string()));
        args
    };
    let six = s(&dir.join("six"));
    let made = spdcam(&[
        "generate",
        "--lighting",
        "gaussian:4",
        "--count",
        "6",
        "--fast",
        "-o",
        &six,
    ]);
    assert!(made.status.success(), "{made:?}");
    let cases: Vec<(&str, &str, Vec<String>, &str)> = vec![
        (
            "SPDCAM_MAX_PHOTO_BYTES",
            "1000",
            vec!["estimate".into(), photo.clone()],
            "bytes of a photo exceed the limit of 1,000",
        ),
        (
            "SPDCAM_MAX_TEXT_FILE_BYTES",
            "100",
            vec!["metrics".into(), csv.clone()],
            "bytes of a text file exceed the limit of 100",
        ),
        (
            "SPDCAM_MAX_MODEL_BYTES",
            "1000",
            vec!["estimate".into(), photo.clone(), "--model".into(), model],
            "bytes of a model file exceed the limit of 1,000",
        ),
        (
            "SPDCAM_MAX_IMAGE_PIXELS",
            "1000",
            vec!["estimate".into(), photo.clone()],
            "image pixels exceed the limit of 1,000",
        ),
        (
            "SPDCAM_MAX_RENDER_PIXELS",
            "100",
            vec![
                "render".into(),
                "--spd".into(),
                "D65".into(),
                "-o".into(),
                png.clone(),
            ],
            "rendered pixels exceed the limit of 100",
        ),
        (
            "SPDCAM_MAX_CSV_COLUMNS",
            "3",
            vec!["metrics".into(), csv.clone()],
            "4 CSV columns exceed the limit of 3",
        ),
        (
            "SPDCAM_MAX_CSV_ROWS",
            "10",
            vec!["metrics".into(), csv.clone()],
            "more than 10 CSV rows",
        ),
        (
            "SPDCAM_MAX_GRID_BANDS",
            "10",
            generate(&["--count", "5", "--spd-grid", "380-780:5"]),
            "wavelength bands exceed the limit of 10",
        ),
        (
            "SPDCAM_MAX_SAMPLES",
            "10",
            generate(&["--count", "11"]),
            "11 samples of one run exceed the limit of 10",
        ),
        (
            "SPDCAM_MAX_DRAWS",
            "10",
            vec![
                "coverage".into(),
                csv.clone(),
                "--lighting".into(),
                "gaussian:4".into(),
                "--draws".into(),
                "11".into(),
                "--no-fit".into(),
            ],
            "11 draws exceed the limit of 10",
        ),
        (
            "SPDCAM_MAX_DISTINCT_SAMPLES",
            "5",
            vec![
                "dataset".into(),
                "merge".into(),
                six.clone(),
                "-o".into(),
                s(&dir.join("merged")),
            ],
            "6 samples checked for duplicates exceed the limit of 5",
        ),
        (
            "SPDCAM_MAX_CHUNK_BYTES",
            "1000",
            generate(&["--count", "5"]),
            "bytes of one sample file exceed the limit of 1,000",
        ),
        (
            "SPDCAM_MAX_FILTER_SIGMA",
            "2",
            vec![
                "render".into(),
                "--spd".into(),
                "D65".into(),
                "--white-balance".into(),
                "grey-edge:1:3".into(),
                "-o".into(),
                png.clone(),
            ],
            "3 filter sigma in pixels exceed the limit of 2",
        ),
        (
            "SPDCAM_MAX_DETECTION_PHOTOS",
            "10",
            vec![
                "detection".into(),
                "--photos".into(),
                "11".into(),
                "-o".into(),
                s(&dir.join("d.md")),
            ],
            "11 scene photos per bucket and chart exceed the limit of 10",
        ),
        (
            "SPDCAM_MAX_CAMERA_POOL_BYTES",
            "1000",
            generate(&[
                "--count",
                "5",
                "--randomise",
                "camera",
                "--cameras",
                "nikon_d5100_npl",
            ]),
            "bytes of a camera pool exceed the limit of 1,000",
        ),
    ];
    for limit in spdcam_core::limits::ALL {
        assert!(
            cases.iter().any(|c| c.0 == limit.env),
            "no test of {}",
            limit.env
        );
    }
    for (env, value, args, expected) in &cases {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let e = fails_fast_with(&args, &[(*env, *value)]);
        assert!(
            e.contains(expected) && e.contains(env),
            "{env}={value} {args:?}: {e}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn ten_million_columns_are_refused_at_once() {
    // Issue 29: a 149 MB CSV of 10 million uniquely named columns ran 60 s at 3.4 GB.
    let dir = scratch("ten-million-columns");
    let wide = dir.join("wide.csv");
    let mut text = String::with_capacity(120 << 20);
    text.push_str("wavelength_nm");
    for i in 0..10_000_000u32 {
        text.push_str(",c");
        text.push_str(&i.to_string());
    }
    text.push_str("\n380");
    text.push_str(&",1".repeat(10_000_000));
    text.push('\n');
    std::fs::write(&wide, text).unwrap();
    for args in [
        vec!["metrics", "WIDE"],
        vec!["estimate", "--features", "WIDE"],
        vec!["coverage", "WIDE", "--lighting", "gaussian:4"],
    ] {
        let args: Vec<String> = args.iter().map(|a| a.replace("WIDE", &s(&wide))).collect();
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let started = Instant::now();
        let e = fails_fast(&args);
        assert!(
            e.contains("CSV columns")
                && e.contains("100,000")
                && e.contains("the limit")
                && e.contains("SPDCAM_MAX_CSV_COLUMNS"),
            "{args:?}: {e}"
        );
        assert!(
            started.elapsed() < Duration::from_secs(10),
            "{args:?}: {:?}",
            started.elapsed()
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
