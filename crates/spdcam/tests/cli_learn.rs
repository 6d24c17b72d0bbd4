//! `spdcam train / estimate / evaluate / finetune` end to end on a small synthetic dataset
//! brought in with `spdcam dataset import`.

#![cfg(feature = "train")]

use spdcam_learn::synthetic::gaussian_set;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn spdcam(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_spdcam"))
        .args(args)
        .output()
        .expect("running spdcam")
}

fn ok(args: &[&str]) -> String {
    let out = spdcam(args);
    assert!(
        out.status.success(),
        "spdcam {args:?} failed:\n{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn fails(args: &[&str]) -> String {
    let out = spdcam(args);
    assert!(!out.status.success(), "spdcam {args:?} should fail");
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("spdcam-cli-learn-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes features.csv and spds.csv of a synthetic set and imports them as a dataset.
fn dataset(dir: &Path, name: &str, rows: usize, patches: usize, seed: u64) -> (PathBuf, PathBuf) {
    let set = gaussian_set(rows, patches, seed, 2);
    let f = set.samples.feature_count;
    let mut features = set.columns.feature_names.join(",") + "\n";
    for row in set.samples.features.chunks_exact(f) {
        let cells: Vec<String> = row.iter().map(|v| format!("{v:.4}")).collect();
        features.push_str(&(cells.join(",") + "\n"));
    }
    let grid = set.columns.spd_grid;
    let header: Vec<String> = grid.wavelengths().iter().map(|w| format!("{w}")).collect();
    let mut spds = header.join(",") + "\n";
    for row in set.samples.spds.chunks_exact(grid.count) {
        let cells: Vec<String> = row.iter().map(|v| format!("{v:.6}")).collect();
        spds.push_str(&(cells.join(",") + "\n"));
    }
    let fp = dir.join(format!("{name}-features.csv"));
    let sp = dir.join(format!("{name}-spds.csv"));
    std::fs::write(&fp, features).unwrap();
    std::fs::write(&sp, spds).unwrap();
    let out = dir.join(name);
    ok(&[
        "dataset",
        "import",
        "--features",
        fp.to_str().unwrap(),
        "--spds",
        sp.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    (out, fp)
}

/// Trains the ridge baseline on `data` into `model`.
fn train_linear(data: &Path, model: &Path) -> String {
    ok(&[
        "train",
        "--data",
        data.to_str().unwrap(),
        "--model",
        "linear",
        "-o",
        model.to_str().unwrap(),
    ])
}

/// `spdcam train` arguments with a fixed ridge penalty.
fn with_ridge<'a>(data: &'a str, model: &'a str, ridge: &'a str, out: &'a str) -> [&'a str; 9] {
    [
        "train", "--data", data, "--model", model, "--ridge", ridge, "-o", out,
    ]
}

#[test]
fn train_estimate_evaluate_finetune() {
    let dir = scratch("all");
    let (data, features) = dataset(&dir, "train", 800, 24, 1);
    let (small, _) = dataset(&dir, "small", 200, 24, 2);
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let model = dir.join("m.spdm");
    let out = ok(&[
        "train",
        "--data",
        &s(&data),
        "--model",
        "cnn1d",
        "-o",
        &s(&model),
        "--epochs",
        "3",
        "--batch",
        "64",
        "--seed",
        "3",
    ]);
    assert!(out.contains("validation GFC"), "{out}");
    assert!(model.is_file());
    let log = std::fs::read_to_string(dir.join("m.log.csv")).unwrap();
    assert_eq!(log.lines().count(), 4, "{log}");
    assert!(std::fs::read_to_string(dir.join("m.loss.svg"))
        .unwrap()
        .contains("<svg"));

    // The baseline.
    let linear = dir.join("lin.spdm");
    train_linear(&data, &linear);
    // A fixed penalty is recorded in the model; it applies to linear models only.
    let (data_arg, strong) = (s(&data), s(&dir.join("strong.spdm")));
    let out = ok(&with_ridge(&data_arg, "linear", "0.1", &strong));
    assert!(out.contains("validation GFC"), "{out}");
    let err = fails(&with_ridge(&data_arg, "cnn1d", "0.1", &strong));
    assert!(err.contains("--ridge applies to --model linear"), "{err}");
    let err = fails(&with_ridge(&data_arg, "linear", "0", &strong));
    assert!(err.contains("positive"), "{err}");

    // One row: colorimetry is printed; the CSV has one estimate column.
    let one = dir.join("one.csv");
    let text = std::fs::read_to_string(&features).unwrap();
    let mut lines = text.lines();
    std::fs::write(
        &one,
        format!("{}\n{}\n", lines.next().unwrap(), lines.next().unwrap()),
    )
    .unwrap();
    let spd = dir.join("spd.csv");
    let plot = dir.join("spd.svg");
    let out = ok(&[
        "estimate",
        "--model",
        &s(&linear),
        "--features",
        &s(&one),
        "-o",
        &s(&spd),
        "--plot",
        &s(&plot),
    ]);
    // The meter's headline: CCT and Δuv for white light, a wavelength for coloured light.
    assert!(
        out.contains("xy (") && (out.contains("CCT") || out.contains("wavelength")),
        "{out}"
    );
    let csv = std::fs::read_to_string(&spd).unwrap();
    assert!(csv.starts_with("wavelength_nm,estimate_1\n400,"), "{csv}");
    assert_eq!(csv.lines().count(), 62);
    assert!(plot.is_file());

    // Many rows, another range.
    let out = ok(&[
        "estimate",
        "--model",
        &s(&model),
        "--features",
        &s(&features),
        "-o",
        &s(&spd),
        "--range",
        "420-680:10",
        "--layout",
        "wide",
    ]);
    assert!(out.contains("800 estimates"), "{out}");
    let csv = std::fs::read_to_string(&spd).unwrap();
    assert!(csv.starts_with("wavelength_nm,estimate_1,estimate_2,"));
    assert_eq!(csv.lines().count(), 28);

    // Evaluate writes the report.
    let report = dir.join("report");
    let out = ok(&[
        "evaluate",
        "--model",
        &s(&linear),
        "--data",
        &s(&data),
        "-o",
        &s(&report),
    ]);
    assert!(out.contains("| GFC |"), "{out}");
    for f in [
        "samples.csv",
        "metrics.json",
        "metrics.md",
        "band_mae.csv",
        "boxplots.svg",
        "band_mae.svg",
        "best_median_worst.svg",
    ] {
        assert!(report.join(f).is_file(), "{f}");
    }
    // Imported features name no chart or camera: nothing to render the worst case with.
    assert!(!report.join("worst_case.png").exists());
    let metrics: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(report.join("metrics.json")).unwrap())
            .unwrap();
    let gfc = metrics["metrics"]["gfc"]["mean"].as_f64().unwrap();
    assert!(gfc > 0.95 && gfc <= 1.0, "linear GFC {gfc}");

    // Fine-tuning writes a new model.
    let tuned = dir.join("tuned.spdm");
    ok(&[
        "finetune",
        "--model",
        &s(&model),
        "--data",
        &s(&small),
        "-o",
        &s(&tuned),
        "--epochs",
        "2",
        "--freeze",
    ]);
    assert!(tuned.is_file());

    // With no recipe flags, the recipe is chosen by cross-validation: every candidate scored
    // (the model unchanged among them), the best one named and written.
    let chosen = dir.join("chosen.spdm");
    let out = ok(&[
        "finetune",
        "--model",
        &s(&model),
        "--data",
        &s(&small),
        "-o",
        &s(&chosen),
    ]);
    assert!(out.contains("5-fold cross-validation"), "{out}");
    for name in [
        "the model unchanged",
        "all layers, about 150 steps",
        "output layer only",
        "ridge on the photos alone, penalty 1e-4",
        "ridge on the photos alone, penalty 1",
    ] {
        assert!(out.contains(name), "{name}: {out}");
    }
    let scores: Vec<f64> = out
        .lines()
        .filter_map(|l| l.split("cross-validated GFC ").nth(1))
        .map(|v| v.split([' ', ')']).next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(scores.len(), 8, "seven candidates and the choice: {out}");
    assert!(
        scores[..7].windows(2).all(|w| w[0] >= w[1]),
        "best first: {out}"
    );
    assert_eq!(scores[7], scores[0], "the best is chosen: {out}");
    assert!(chosen.is_file());

    // Features of another chart, and a file that is not a model: clear errors.
    let (_, other) = dataset(&dir, "other", 20, 30, 4);
    let err = fails(&[
        "estimate",
        "--model",
        &s(&model),
        "--features",
        &s(&other),
        "-o",
        &s(&spd),
    ]);
    assert!(
        err.contains("90 feature columns") && err.contains("72"),
        "{err}"
    );
    let err = fails(&[
        "estimate",
        "--model",
        &s(&one),
        "--features",
        &s(&one),
        "-o",
        &s(&spd),
    ]);
    assert!(err.contains("not a spdcam model"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Thesis Fig. 6.7: a model trained on generated data (chart and camera known) gets the
/// chart rendered under the worst case's true and estimated SPD, and their difference.
#[test]
fn evaluate_renders_the_worst_case() {
    let dir = scratch("worst");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let data = dir.join("data");
    ok(&[
        "generate",
        "--count",
        "300",
        "--seed",
        "5",
        "--fast",
        "--chart",
        "colorchecker24",
        "--camera",
        "nikon_d5100_npl",
        "--lighting",
        "gaussian:4",
        "-o",
        &s(&data),
    ]);
    let model = dir.join("lin.spdm");
    train_linear(&data, &model);
    let report = dir.join("report");
    ok(&[
        "evaluate",
        "--model",
        &s(&model),
        "--data",
        &s(&data),
        "-o",
        &s(&report),
    ]);
    let image = image::open(report.join("worst_case.png"))
        .expect("worst_case.png")
        .to_rgb8();
    // Three panels of the chart's width and an 8-pixel gap between them.
    let (w, h) = (image.width(), image.height());
    assert_eq!((w - 16) % 3, 0, "width {w}");
    let panel = (w - 16) / 3;
    let pixel = |x: u32, y: u32| image.get_pixel(x, y).0;
    let (mut differ, mut lit) = (0, 0);
    for y in 0..h {
        for x in 0..panel {
            if pixel(x, y) != pixel(x + panel + 8, y) {
                differ += 1;
            }
            if pixel(x + 2 * (panel + 8), y).iter().any(|&v| v > 8) {
                lit += 1;
            }
        }
    }
    assert!(differ > 0, "the estimate's render equals the truth's");
    assert!(lit > 0, "the difference panel is black");
    assert_eq!(pixel(panel + 2, h / 2), [255, 255, 255], "a white gap");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn an_average_of_a_network_and_a_ridge_estimates_between_them() {
    let dir = scratch("average");
    let (data, features) = dataset(&dir, "train", 600, 24, 4);
    let (few, _) = dataset(&dir, "few", 40, 24, 5);
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let (network, ridge, average) = (
        dir.join("network.spdm"),
        dir.join("ridge.spdm"),
        dir.join("average.spdm"),
    );
    for (model, out) in [("mlp", &network), ("linear", &ridge)] {
        ok(&[
            "train",
            "--data",
            &s(&data),
            "--model",
            model,
            "--row-scale",
            "mean",
            "--epochs",
            "2",
            "--seed",
            "1",
            "-o",
            &s(out),
        ]);
    }
    let out = ok(&["average", &s(&network), &s(&ridge), "-o", &s(&average)]);
    assert!(out.contains("average of mlp and linear"), "{out}");
    // Its estimate of each row is the mean of the members' (before peak normalisation,
    // which the members' similar scale keeps close to the mean of the normalised SPDs).
    let estimate = |model: &Path| -> Vec<Vec<f64>> {
        let csv = dir.join("estimate.csv");
        ok(&[
            "estimate",
            "--model",
            &s(model),
            "--features",
            &s(&features),
            "-o",
            &s(&csv),
        ]);
        let text = std::fs::read_to_string(&csv).unwrap();
        text.lines()
            .skip(1)
            .map(|l| l.split(',').skip(1).map(|v| v.parse().unwrap()).collect())
            .collect()
    };
    let (a, b, mean) = (estimate(&network), estimate(&ridge), estimate(&average));
    assert_eq!(mean.len(), a.len());
    let (mut between, mut cells) = (0, 0);
    for ((ra, rb), rm) in a.iter().zip(&b).zip(&mean) {
        for ((x, y), m) in ra.iter().zip(rb).zip(rm) {
            cells += 1;
            between += usize::from(x.min(*y) - 0.05 <= *m && *m <= x.max(*y) + 0.05);
        }
    }
    assert!(
        between * 100 >= cells * 95,
        "{between} of {cells} between the members"
    );
    // A member cannot be overwritten, and members must share their scaling.
    let err = fails(&["average", &s(&network), &s(&ridge), "-o", &s(&ridge)]);
    assert!(err.contains("is the input MODELS"), "{err}");
    let max_scaled = dir.join("max.spdm");
    ok(&[
        "train",
        "--data",
        &s(&data),
        "--model",
        "linear",
        "-o",
        &s(&max_scaled),
    ]);
    let err = fails(&["average", &s(&network), &s(&max_scaled), "-o", &s(&average)]);
    assert!(err.contains("feature scaling"), "{err}");
    // Fine-tuning an average weighs the model unchanged and ridge on the photos only.
    let out = ok(&[
        "finetune",
        "--model",
        &s(&average),
        "--data",
        &s(&few),
        "-o",
        &s(&dir.join("tuned.spdm")),
    ]);
    let scores = out.matches("cross-validated GFC ").count();
    assert_eq!(scores, 5, "four candidates and the choice: {out}");
    assert!(!out.contains("all layers"), "{out}");
    std::fs::remove_dir_all(&dir).ok();
}
