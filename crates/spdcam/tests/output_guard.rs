//! No input destroyed (issue 39, defects 1, 2 and 4): every command's outputs are checked
//! against its inputs and against each other before anything is written, and outputs that
//! are links, pipes or devices are written through, never replaced by a file.
//! First tier: it reads no measured data.

mod common;

use common::{fresh_clone_command, ok, s, scratch, spdcam};
use std::path::{Path, PathBuf};

/// The example photo, copied to `dir`, with its truth beside it.
fn photo_in(dir: &Path) -> (PathBuf, PathBuf) {
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let photo = dir.join("p.jpg");
    let truth = dir.join("p.truth.csv");
    std::fs::copy(examples.join("sg-telelumen.jpg"), &photo).unwrap();
    std::fs::copy(examples.join("sg-telelumen.truth.csv"), &truth).unwrap();
    (photo, truth)
}

/// A small dataset of 20 samples made by `generate` in `dir`.
fn dataset_in(dir: &Path) -> PathBuf {
    let ds = dir.join("ds");
    ok(&[
        "generate",
        "--lighting",
        "gaussian:4",
        "--count",
        "20",
        "--fast",
        "-o",
        &s(&ds),
    ]);
    ds
}

/// Runs spdcam, which must refuse at once naming `names`, leaving every file of `dir`
/// byte for byte as it was.
fn refused_and_nothing_touched(dir: &Path, args: &[&str], names: &[&str]) {
    let before = files(dir);
    let out = spdcam(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "spdcam {args:?}: {stderr}");
    assert!(stderr.starts_with("error: "), "spdcam {args:?}: {stderr}");
    for name in names {
        assert!(
            stderr.contains(name),
            "spdcam {args:?} should name {name}: {stderr}"
        );
    }
    assert_eq!(files(dir), before, "spdcam {args:?} changed the files");
}

/// Every file under `dir` (links not followed) with its bytes, sorted.
fn files(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut all = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            let meta = std::fs::symlink_metadata(&path).unwrap();
            if meta.is_dir() {
                stack.push(path);
            } else if meta.is_file() {
                all.push((path.clone(), std::fs::read(&path).unwrap()));
            } else {
                all.push((path.clone(), Vec::new()));
            }
        }
    }
    all.sort();
    all
}

#[test]
fn estimate_outputs_onto_its_inputs_are_refused() {
    let dir = scratch("estimate");
    let (photo, truth) = photo_in(&dir);
    let (p, t) = (s(&photo), s(&truth));
    let features = dir.join("f.csv");
    std::fs::write(&features, "r,g,b\n1,2,3\n").unwrap();
    let f = s(&features);
    let model = dir.join("m.spdm");
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/colorchecker24.spdm"),
        &model,
    )
    .unwrap();
    let m = s(&model);
    for option in ["-o", "--report", "--debug", "--features-out", "--plot"] {
        refused_and_nothing_touched(&dir, &["estimate", &p, option, &p], &[option, "PHOTO"]);
    }
    refused_and_nothing_touched(
        &dir,
        &["estimate", &p, "--truth", &t, "-o", &t],
        &["--truth", "-o"],
    );
    // The truth read beside the photo without --truth is an input too.
    refused_and_nothing_touched(
        &dir,
        &["estimate", &p, "-o", &t],
        &["the truth beside the photo"],
    );
    refused_and_nothing_touched(
        &dir,
        &["estimate", "--features", &f, "-o", &f],
        &["--features", "-o"],
    );
    refused_and_nothing_touched(
        &dir,
        &["estimate", &p, "--model", &m, "-o", &m],
        &["--model"],
    );
    // Spelt another way: through `..`, a symbolic link and a hard link.
    let dotted = dir.join("sub/../p.jpg");
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    let soft = dir.join("soft.jpg");
    std::os::unix::fs::symlink(&photo, &soft).unwrap();
    let hard = dir.join("hard.jpg");
    std::fs::hard_link(&photo, &hard).unwrap();
    for out in [&dotted, &soft, &hard] {
        refused_and_nothing_touched(&dir, &["estimate", &p, "--report", &s(out)], &["PHOTO"]);
    }
}

#[test]
fn render_outputs_onto_inputs_or_each_other_are_refused() {
    let dir = scratch("render");
    let spds = dir.join("F.csv");
    std::fs::write(&spds, "wavelength_nm,a,b\n380,1,0.5\n500,1,1\n780,1,0.2\n").unwrap();
    let f = s(&spds);
    let column = format!("{f}:b");
    let png = s(&dir.join("a.png"));
    refused_and_nothing_touched(
        &dir,
        &["render", "--spd", &column, "-o", &png, "--spd-out", &f],
        &["--spd-out", "--spd "],
    );
    refused_and_nothing_touched(
        &dir,
        &["render", "--spd", &f, "-o", &png, "--features", &f],
        &["--features", "--spd "],
    );
    for option in ["--features", "--spd-out"] {
        refused_and_nothing_touched(
            &dir,
            &["render", "--spd", "D65", "-o", &png, option, &png],
            &["-o", option, "same file"],
        );
    }
    refused_and_nothing_touched(
        &dir,
        &["render", "--spd", "D65", "-o", "-", "--spd-out", "-"],
        &["standard output"],
    );
    assert!(!dir.join("a.png").exists());
}

#[test]
fn a_colour_map_written_onto_its_model_is_refused() {
    let dir = scratch("colour-map");
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let model = dir.join("m.spdm");
    let split = dir.join("split.json");
    std::fs::copy(repo.join("models/colorchecker24.spdm"), &model).unwrap();
    std::fs::copy(repo.join("docs/validation-split.json"), &split).unwrap();
    let (m, sp) = (s(&model), s(&split));
    refused_and_nothing_touched(
        &dir,
        &["colour-map", "fit", "--model", &m, "--split", &sp, "-o", &m],
        &["--model"],
    );
    refused_and_nothing_touched(
        &dir,
        &[
            "colour-map",
            "fit",
            "--model",
            &m,
            "--split",
            &sp,
            "-o",
            &sp,
        ],
        &["--split"],
    );
}

#[test]
fn spd_out_dash_is_standard_output_and_outputs_that_cannot_be_are_refused() {
    let dir = scratch("dash");
    let png = s(&dir.join("a.png"));
    let out = fresh_clone_command(&["render", "--spd", "D65", "-o", &png, "--spd-out", "-"])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.starts_with("wavelength_nm,D65\n380,"), "{stdout}");
    assert!(!dir.join("-").exists(), "a file named - was written");
    assert!(dir.join("a.png").exists());
    let (photo, _) = photo_in(&dir);
    let out = fresh_clone_command(&["estimate", &s(&photo), "--report", "-"])
        .current_dir(&dir)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("--report cannot go to standard output"),
        "{stderr}"
    );
    assert!(!dir.join("-").exists());
}

#[test]
fn dataset_and_coverage_outputs_inside_their_inputs_are_refused() {
    let dir = scratch("dataset");
    let ds = dataset_in(&dir);
    let manifest = s(&ds.join("manifest.json"));
    refused_and_nothing_touched(
        &dir,
        &["dataset", "info", &s(&ds), "--plot", &manifest],
        &["--plot", "lies inside"],
    );
    refused_and_nothing_touched(
        &dir,
        &["dataset", "split", &s(&ds), "-o", &s(&dir)],
        &["contains"],
    );
    let spds = dir.join("S.csv");
    std::fs::write(&spds, "wavelength_nm,a\n380,1\n780,1\n").unwrap();
    for option in ["-o", "--per-lamp"] {
        refused_and_nothing_touched(
            &dir,
            &[
                "coverage",
                &s(&spds),
                "--lighting",
                "planck",
                option,
                &s(&spds),
            ],
            &[option],
        );
    }
}

#[cfg(feature = "train")]
#[test]
fn training_outputs_onto_their_dataset_or_model_are_refused() {
    let dir = scratch("train");
    let ds = dataset_in(&dir);
    let d = s(&ds);
    let manifest = s(&ds.join("manifest.json"));
    let part = s(&ds.join("samples/part-00000.parquet"));
    let model = s(&dir.join("m.spdm"));
    refused_and_nothing_touched(
        &dir,
        &["train", "--data", &d, "--model", "mlp", "-o", &manifest],
        &["--data"],
    );
    for option in ["--log", "--plot"] {
        let target = if option == "--log" { &part } else { &manifest };
        refused_and_nothing_touched(
            &dir,
            &[
                "train", "--data", &d, "--model", "mlp", "-o", &model, option, target,
            ],
            &[option, "--data"],
        );
    }
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/colorchecker24.spdm"),
        &model,
    )
    .unwrap();
    refused_and_nothing_touched(
        &dir,
        &["finetune", "--model", &model, "--data", &d, "-o", &model],
        &["--model", "-o"],
    );
}

#[test]
fn links_pipes_and_devices_as_outputs_are_written_through() {
    let dir = scratch("kinds");
    let (photo, _) = photo_in(&dir);
    let p = s(&photo);
    // A symbolic link stays a link; its target gets the estimate.
    let target = dir.join("target.csv");
    std::fs::write(&target, "old").unwrap();
    let link = dir.join("link.csv");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let out = spdcam(&["estimate", &p, "-o", &s(&link)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    let written = std::fs::read_to_string(&target).unwrap();
    assert!(written.starts_with("wavelength_nm,"), "{written}");
    // A named pipe's reader gets the estimate; the pipe stays a pipe.
    let fifo = dir.join("fifo.csv");
    assert!(std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read_to_string(&fifo).unwrap())
    };
    let out = spdcam(&["estimate", &p, "-o", &s(&fifo)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(reader.join().unwrap().starts_with("wavelength_nm,"));
    use std::os::unix::fs::FileTypeExt;
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    // A full device is an error that names it, and stays a device.
    let out = spdcam(&["estimate", &p, "-o", "/dev/full"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("/dev/full") && stderr.contains("space"),
        "{stderr}"
    );
    assert!(std::fs::metadata("/dev/full")
        .unwrap()
        .file_type()
        .is_char_device());
}
