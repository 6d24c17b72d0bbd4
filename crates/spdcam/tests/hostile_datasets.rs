//! Datasets and training input that would have given a confident wrong answer (issue 39):
//! samples merged twice, manifests that name some of the features, constant features,
//! empty imports, exports outside the SPDs' wavelengths, plots in the wrong format.

mod common;

use common::{fails, ok, s, scratch};
use std::path::Path;

/// A generated dataset of `count` samples (fast pipeline) in `dir`.
fn generate(dir: &Path, count: &str) {
    ok(&[
        "generate",
        "--lighting",
        "gaussian:4",
        "--count",
        count,
        "--fast",
        "-o",
        &s(dir),
    ]);
}

/// The number of samples `dataset info` reports.
fn samples(dir: &Path) -> u64 {
    let info = ok(&["dataset", "info", &s(dir)]);
    info.lines()
        .find_map(|l| l.trim().strip_prefix("samples:"))
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no sample count in {info}"))
}

/// CSV files of `rows` (features, SPD at 380–780 nm in 5 nm steps) for `dataset import`.
fn write_csv(dir: &Path, feature_names: &[&str], rows: &[(Vec<f64>, Vec<f64>)]) {
    let line = |values: &[f64]| {
        values
            .iter()
            .map(|v| v.to_string())
            .collect::<Vec<_>>()
            .join(",")
    };
    let mut features = feature_names.join(",") + "\n";
    let wavelengths: Vec<String> = (0..81).map(|i| (380 + 5 * i).to_string()).collect();
    let mut spds = wavelengths.join(",") + "\n";
    for (f, spd) in rows {
        features += &(line(f) + "\n");
        spds += &(line(spd) + "\n");
    }
    std::fs::write(dir.join("features.csv"), features).unwrap();
    std::fs::write(dir.join("spds.csv"), spds).unwrap();
}

/// An SPD on 380–780 nm that peaks at `peak_nm`.
fn spd(peak_nm: f64) -> Vec<f64> {
    (0..81)
        .map(|i| {
            let nm = 380.0 + 5.0 * i as f64;
            (-((nm - peak_nm) / 60.0).powi(2)).exp()
        })
        .collect()
}

/// Imports the CSV files of `dir` as the dataset `out`.
fn import(dir: &Path, out: &Path) -> String {
    ok(&[
        "dataset",
        "import",
        "--features",
        &s(&dir.join("features.csv")),
        "--spds",
        &s(&dir.join("spds.csv")),
        "-o",
        &s(out),
    ])
}

#[test]
fn merge_refuses_samples_it_already_holds_whatever_path_they_came_by() {
    // Issue 39, item 3: `merge DS SPLIT/train` gave 340 samples, 140 of them twice.
    let dir = scratch("merge-twice");
    let ds = dir.join("ds");
    generate(&ds, "200");
    ok(&["dataset", "split", &s(&ds), "-o", &s(&dir.join("parts"))]);
    let train = dir.join("parts/train");
    let held = samples(&train);
    let merged = dir.join("merged");
    let e = fails(&["dataset", "merge", &s(&ds), &s(&train), "-o", &s(&merged)]);
    assert!(
        e.contains(&format!("{held} samples would be held twice")),
        "{e}"
    );
    assert!(
        e.contains(&format!(
            "{held} of {} are already in {}",
            s(&train),
            s(&ds)
        )),
        "{e}"
    );
    assert!(e.contains("--drop-duplicates"), "{e}");
    assert!(!merged.exists(), "a refused merge leaves nothing");

    let out = ok(&[
        "dataset",
        "merge",
        &s(&ds),
        &s(&train),
        "--drop-duplicates",
        "-o",
        &s(&merged),
    ]);
    assert!(
        out.contains(&format!(
            "200 samples ({held} samples already held left out)"
        )),
        "{out}"
    );
    ok(&["dataset", "info", &s(&merged), "--verify"]);

    // The same samples exported and imported again have new numbers and family, and
    // features that went through text: still recognised.
    let csv = dir.join("csv");
    ok(&["dataset", "export", &s(&ds), "--csv", "-o", &s(&csv)]);
    let again = dir.join("again");
    ok(&[
        "dataset",
        "import",
        "--features",
        &s(&csv.join("features.csv")),
        "--weights",
        &s(&csv.join("weights.csv")),
        "--lighting",
        "gaussian:4",
        "-o",
        &s(&again),
    ]);
    let e = fails(&[
        "dataset",
        "merge",
        &s(&ds),
        &s(&again),
        "-o",
        &s(&merged),
        "--force",
    ]);
    assert!(e.contains("200 samples would be held twice"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn verify_reports_samples_held_twice_and_merge_keeps_one_of_each() {
    // Issue 39, item 3: `--verify` passed a dataset holding samples twice.
    let dir = scratch("verify-twice");
    let names = ["p01_r", "p01_g", "p01_b"];
    let rows = vec![
        (vec![10.0, 20.0, 30.0], spd(450.0)),
        (vec![11.0, 21.0, 31.0], spd(550.0)),
        (vec![10.0, 20.0, 30.0], spd(450.0)),
        (vec![12.0, 22.0, 32.0], spd(650.0)),
    ];
    write_csv(&dir, &names, &rows);
    let twice = dir.join("twice");
    import(&dir, &twice);
    let e = fails(&["dataset", "info", &s(&twice), "--verify"]);
    assert!(
        e.contains("1 samples repeat earlier samples of the dataset"),
        "{e}"
    );
    let once = dir.join("once");
    let out = ok(&[
        "dataset",
        "merge",
        &s(&twice),
        "--drop-duplicates",
        "-o",
        &s(&once),
    ]);
    assert!(
        out.contains("3 samples (1 samples already held left out)"),
        "{out}"
    );
    let info = ok(&["dataset", "info", &s(&once), "--verify"]);
    assert!(info.contains("verified: 1 files, 3 samples"), "{info}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Keeps the first `n` feature names of the manifest in `dir`.
fn cut_feature_names(dir: &Path, n: usize) {
    let path = dir.join("manifest.json");
    let mut manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let names = manifest["columns"]["feature_names"].as_array_mut().unwrap();
    names.truncate(n);
    std::fs::write(&path, serde_json::to_string_pretty(&manifest).unwrap()).unwrap();
}

#[test]
fn a_manifest_naming_some_of_the_features_is_refused() {
    // Issue 39, item 18: a manifest naming 10 of 72 features passed `--verify`, and
    // `export` wrote 10 columns.
    let dir = scratch("cut-features");
    let ds = dir.join("ds");
    generate(&ds, "20");
    cut_feature_names(&ds, 10);
    let e = fails(&["dataset", "info", &s(&ds), "--verify"]);
    assert!(
        e.contains("names 10 feature columns (p01_r … p04_r)")
            && e.contains("gives 72 (p01_r … p24_b)"),
        "{e}"
    );
    let e = fails(&[
        "dataset",
        "export",
        &s(&ds),
        "--csv",
        "-o",
        &s(&dir.join("csv")),
    ]);
    assert!(e.contains("names 10 feature columns"), "{e}");
    assert!(!dir.join("csv").exists());

    // Imported samples name no chart: their files show the columns left out.
    let names = ["p01_r", "p01_g", "p01_b", "p02_r", "p02_g", "p02_b"];
    let rows = vec![
        (vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0], spd(450.0)),
        (vec![6.0, 5.0, 4.0, 3.0, 2.0, 1.0], spd(550.0)),
    ];
    write_csv(&dir, &names, &rows);
    let imported = dir.join("imported");
    import(&dir, &imported);
    cut_feature_names(&imported, 3);
    let e = fails(&["dataset", "info", &s(&imported), "--verify"]);
    assert!(
        e.contains("holds 6 feature columns (p01_r … p02_b) but the manifest names 3"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn importing_files_without_samples_is_refused_and_writes_nothing() {
    // Issue 39, item 19: header-only files made a 0-sample dataset with exit 0.
    let dir = scratch("import-empty");
    write_csv(&dir, &["p01_r", "p01_g", "p01_b"], &[]);
    let out = dir.join("out");
    let e = fails(&[
        "dataset",
        "import",
        "--features",
        &s(&dir.join("features.csv")),
        "--spds",
        &s(&dir.join("spds.csv")),
        "-o",
        &s(&out),
    ]);
    assert!(e.contains("hold no samples"), "{e}");
    assert!(!out.exists(), "nothing is written");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn export_refuses_wavelengths_the_dataset_does_not_hold() {
    // Issue 39, item 19: `export --spd-grid 300-900` padded the SPDs with zeros.
    let dir = scratch("export-grid");
    let ds = dir.join("ds");
    generate(&ds, "10");
    let csv = dir.join("csv");
    let e = fails(&[
        "dataset",
        "export",
        &s(&ds),
        "--csv",
        "--spd-grid",
        "300-900",
        "-o",
        &s(&csv),
    ]);
    assert!(
        e.contains("reaches outside the dataset's SPDs, 380–780 nm")
            && e.contains("give a grid within 380–780 nm"),
        "{e}"
    );
    assert!(!csv.exists());
    ok(&[
        "dataset",
        "export",
        &s(&ds),
        "--csv",
        "--spd-grid",
        "400-700:10",
        "-o",
        &s(&csv),
    ]);
    let spds = std::fs::read_to_string(csv.join("spds.csv")).unwrap();
    assert!(spds.starts_with("400,410,"), "{}", &spds[..40]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn info_plots_png_for_png_and_refuses_other_names() {
    // Issue 39, item 19: `info --plot x.png` wrote SVG into a .png.
    let dir = scratch("info-plot");
    let ds = dir.join("ds");
    generate(&ds, "10");
    let png = dir.join("x.png");
    ok(&["dataset", "info", &s(&ds), "--plot", &s(&png)]);
    let bytes = std::fs::read(&png).unwrap();
    assert!(bytes.starts_with(b"\x89PNG\r\n\x1a\n"), "not a PNG");
    let svg = dir.join("x.svg");
    ok(&["dataset", "info", &s(&ds), "--plot", &s(&svg)]);
    assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
    let pdf = dir.join("x.pdf");
    let e = fails(&["dataset", "info", &s(&ds), "--plot", &s(&pdf)]);
    assert!(e.contains("x.pdf") && e.contains(".svg or .png"), "{e}");
    assert!(!pdf.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(feature = "train")]
#[test]
fn train_refuses_features_that_never_change() {
    // Issue 39, item 19: `train` on constant features gave a model with no warning.
    let dir = scratch("train-constant");
    let names = ["p01_r", "p01_g", "p01_b", "p02_r", "p02_g", "p02_b"];
    let rows: Vec<(Vec<f64>, Vec<f64>)> = (0..40)
        .map(|i| {
            (
                vec![50.0, 60.0, 70.0, 80.0, 90.0, 100.0],
                spd(420.0 + 5.0 * i as f64),
            )
        })
        .collect();
    write_csv(&dir, &names, &rows);
    let data = dir.join("constant");
    import(&dir, &data);
    let model = dir.join("m.spdm");
    let e = fails(&[
        "train",
        "--data",
        &s(&data),
        "--model",
        "linear",
        "-o",
        &s(&model),
    ]);
    assert!(
        e.contains("every feature is the same in all") && e.contains("could not learn"),
        "{e}"
    );
    assert!(!model.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
