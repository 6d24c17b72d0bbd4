//! `spdcam generate` and `spdcam dataset` as a user runs them: reproducible files, shards
//! that merge into one run, features that `spdcam render` reproduces, lossless import, and
//! clear errors.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn spdcam(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_spdcam"))
        .args(args)
        .env_remove("SPDCAM_DATA")
        .output()
        .expect("spdcam runs")
}

fn ok(args: &[&str]) -> Output {
    let out = spdcam(args);
    assert!(
        out.status.success(),
        "spdcam {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("spdcam-cli-ds-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn files(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let bytes = std::fs::read(&p).unwrap();
                out.insert(p.strip_prefix(dir).unwrap().to_path_buf(), bytes);
            }
        }
    }
    out
}

const LIGHTING: &str = "gaussian:4";

fn generate(out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "generate",
        "--lighting",
        LIGHTING,
        "--count",
        "40",
        "--seed",
        "3",
        "--chunk-size",
        "16",
        "-o",
        s(out),
    ];
    args.extend_from_slice(extra);
    ok(&args)
}

fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    (header, rows)
}

#[test]
fn generate_is_reproducible_and_shards_merge_into_one_run() {
    let dir = scratch("shards");
    let (a, b) = (dir.join("a"), dir.join("b"));
    let out = generate(&a, &[]);
    assert!(
        out.stderr.is_empty(),
        "quiet when piped: {:?}",
        String::from_utf8_lossy(&out.stderr)
    );
    generate(&b, &[]);
    let whole = files(&a);
    assert!(whole.contains_key(Path::new("manifest.json")));
    assert!(whole.contains_key(Path::new("samples/part-00002.parquet")));
    assert_eq!(whole, files(&b));

    let mut shards = Vec::new();
    for k in ["1/3", "2/3", "0/3"] {
        let shard = dir.join(format!("shard{}", &k[..1]));
        generate(&shard, &["--shard", k]);
        shards.push(shard);
    }
    let merged = dir.join("merged");
    let mut args = vec!["dataset", "merge", "-o", s(&merged)];
    args.extend(shards.iter().map(|p| s(p)));
    ok(&args);
    assert_eq!(whole, files(&merged));

    // Running the same command again changes nothing.
    let again = generate(&a, &[]);
    assert!(String::from_utf8_lossy(&again.stderr).contains("already"));
    assert_eq!(whole, files(&a));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The local scale-out recipe (`tools/generate_shards.sh`, docs/scale-out.md): N shard
/// processes running at once, then `dataset merge`, give the files of one run.
#[cfg(unix)]
#[test]
fn shards_as_parallel_processes_merge_into_one_run() {
    let dir = scratch("processes");
    let common = [
        "--lighting",
        "mix:daylight=0.5,phosphor=0.3,planck=0.2",
        "--count",
        "1000",
        "--fast",
        "--seed",
        "9",
        "--chunk-size",
        "64",
    ];
    let single = dir.join("single");
    let mut args = vec!["generate", "-o", s(&single)];
    args.extend_from_slice(&common);
    ok(&args);
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tools/generate_shards.sh"
    );
    let out = Command::new("sh")
        .arg(script)
        .arg("5")
        .arg(dir.join("sharded"))
        .args(common)
        .env("SPDCAM", env!("CARGO_BIN_EXE_spdcam"))
        .env_remove("SPDCAM_DATA")
        .output()
        .expect("sh runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let whole = files(&single);
    assert_eq!(
        whole.keys().filter(|p| p.starts_with("samples")).count(),
        16,
        "1000 samples in files of 64"
    );
    for k in 0..5 {
        let shard = files(&dir.join("sharded").join(format!("shard-{k}")));
        assert!(shard.len() < whole.len(), "shard {k} holds a part");
    }
    assert_eq!(whole, files(&dir.join("sharded").join("merged")));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn generated_features_equal_spdcam_render_of_their_spd() {
    let dir = scratch("render");
    let data = dir.join("data");
    let seed = 9u64;
    ok(&[
        "generate",
        "--lighting",
        LIGHTING,
        "--count",
        "5",
        "--seed",
        "9",
        "-o",
        s(&data),
    ]);
    let csv = dir.join("csv");
    ok(&["dataset", "export", s(&data), "--csv", "-o", s(&csv)]);
    let (wavelengths, spds) = read_csv(&csv.join("spds.csv"));
    let (names, features) = read_csv(&csv.join("features.csv"));
    assert_eq!(names.len(), 72);
    for i in [0usize, 3] {
        let mut light = String::from("wavelength_nm,spd\n");
        for (w, v) in wavelengths.iter().zip(&spds[i]) {
            light.push_str(&format!("{w},{v}\n"));
        }
        let light_file = dir.join(format!("light{i}.csv"));
        std::fs::write(&light_file, light).unwrap();
        let rendered = dir.join(format!("render{i}.csv"));
        let noise_seed = spdcam_core::seed::derive(seed, i as u64).to_string();
        ok(&[
            "render",
            "--spd",
            s(&light_file),
            "--seed",
            &noise_seed,
            "--features",
            s(&rendered),
            "-o",
            s(&dir.join(format!("render{i}.png"))),
        ]);
        let (rendered_names, rendered_rows) = read_csv(&rendered);
        assert_eq!(rendered_names, names);
        let parse = |row: &[String]| {
            row.iter()
                .map(|v| v.parse::<f32>().unwrap())
                .collect::<Vec<_>>()
        };
        assert_eq!(parse(&rendered_rows[0]), parse(&features[i]), "sample {i}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(feature = "measured-data")]
#[test]
fn thesis_dev_set_imports_without_losing_a_number() {
    let root = spdcam_test_data::measured_data_dir();
    let src = root.join("thesis/measured/telelumen_canon5d4_dev");
    assert!(src.is_dir(), "shared data not found at {}", root.display());
    let dir = scratch("import");
    let data = dir.join("dev");
    let out = ok(&[
        "dataset",
        "import",
        "--features",
        s(&src.join("features.csv")),
        "--spds",
        s(&src.join("spds.csv")),
        "-o",
        s(&data),
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("640 samples") && text.contains("telelumen_canon5d4_dev"),
        "{text}"
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("735–780 nm set to zero"));
    let csv = dir.join("csv");
    ok(&[
        "dataset",
        "export",
        s(&data),
        "--csv",
        "--spd-grid",
        "380-730:10",
        "-o",
        s(&csv),
    ]);
    for name in ["features.csv", "spds.csv"] {
        let (h0, r0) = read_csv(&src.join(name));
        let (h1, r1) = read_csv(&csv.join(name));
        let num = |rows: Vec<Vec<String>>| -> Vec<Vec<f64>> {
            rows.iter()
                .map(|r| r.iter().map(|v| v.parse().unwrap()).collect())
                .collect()
        };
        let head = |h: Vec<String>| -> Vec<String> {
            h.iter()
                .map(|v| v.parse::<f64>().map_or(v.clone(), |x| x.to_string()))
                .collect()
        };
        assert_eq!(head(h0), head(h1), "{name} header");
        assert_eq!(num(r0), num(r1), "{name} values");
    }

    let plot = dir.join("preview.svg");
    let out = ok(&["dataset", "info", s(&data), "--plot", s(&plot)]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("640") && text.contains("telelumen_canon5d4_dev"),
        "{text}"
    );
    let svg = std::fs::read_to_string(&plot).unwrap();
    assert!(
        svg.starts_with("<svg") && svg.matches("<polyline").count() >= 20,
        "{}",
        &svg[..200.min(svg.len())]
    );

    let parts = dir.join("parts");
    let out = ok(&["dataset", "split", s(&data), "-o", s(&parts), "--seed", "2"]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("train 448, val 64, test 128"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Runs a command expected to fail; checks the exit code and that stderr names `expect`.
fn fails<S: AsRef<str>>(args: &[S], expect: &str) {
    let args: Vec<&str> = args.iter().map(AsRef::as_ref).collect();
    let out = spdcam(&args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} succeeded");
    assert!(
        err.contains(expect),
        "{args:?}: expected '{expect}' in: {err}"
    );
    assert!(err.starts_with("error"), "{err}");
}

#[test]
fn bad_input_gives_clear_errors() {
    let dir = scratch("errors");
    let out = dir.join("out");
    let generate = |count: &str, extra: &[&str]| -> Vec<String> {
        let mut args = vec![
            "generate",
            "--lighting",
            LIGHTING,
            "--count",
            count,
            "-o",
            s(&out),
        ];
        args.extend_from_slice(extra);
        args.into_iter().map(String::from).collect()
    };
    fails(&generate("-5", &[]), "the sample count must be at least 1");
    fails(&generate("0", &[]), "the sample count must be at least 1");
    fails(&generate("ten", &[]), "whole number");
    fails(
        &generate("10", &["--shard", "3/3"]),
        "shard '3/3' is not K/N",
    );
    fails(
        &generate("10", &["--shard", "1:3"]),
        "shard '1:3' is not K/N",
    );
    fails(&generate("10", &["--fast", "--images"]), "full pipeline");
    fails(
        &[
            "generate",
            "--lighting",
            "moonbeams",
            "--count",
            "10",
            "-o",
            s(&out),
        ],
        "moonbeams",
    );
    assert!(!out.exists(), "no output for bad settings");

    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("notes.txt"), "keep me").unwrap();
    fails(&generate("10", &[]), "not empty; use --force");
    ok(&generate("10", &["--force"])
        .iter()
        .map(String::as_str)
        .collect::<Vec<_>>());
    assert!(out.join("manifest.json").is_file());
    assert_eq!(
        std::fs::read_to_string(out.join("notes.txt")).unwrap(),
        "keep me"
    );
    fails(&generate("10", &["--seed", "4"]), "other settings (seed)");

    let o = s(&out);
    fails(&["dataset", "info", s(&dir)], "no manifest.json");
    fails(
        &["dataset", "export", o, "-o", s(&dir.join("csv"))],
        "--csv",
    );
    let split = |fractions: &str| -> Vec<String> {
        [
            "dataset",
            "split",
            o,
            "-o",
            s(&dir.join("split")),
            "--fractions",
            fractions,
        ]
        .map(String::from)
        .to_vec()
    };
    fails(&split("0.5,0.5"), "three numbers");
    fails(&split("0.5,0.5,0.5"), "add up to 1");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn list_shows_the_lighting_recipes() {
    let out = ok(&["list", "lighting"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("gaussian"), "{text}");
}

/// A camera sensitivity CSV of three Gaussian channels (peaks 600, 540, 460 nm), shifted by
/// `shift` nm: a valid camera of its own for each shift.
fn camera_csv(path: &Path, shift: f64) {
    let mut text = String::from("wavelength_nm,r,g,b\n");
    for w in (400..=700).step_by(10) {
        let g = |peak: f64| (-((f64::from(w) - peak - shift) / 40.0).powi(2) / 2.0).exp();
        text.push_str(&format!("{w},{},{},{}\n", g(600.0), g(540.0), g(460.0)));
    }
    std::fs::write(path, text).unwrap();
}

#[test]
fn the_camera_pool_joins_several_directories_and_names() {
    let dir = scratch("pool");
    let (a, b) = (dir.join("measured"), dir.join("predicted"));
    for d in [&a, &b] {
        std::fs::create_dir_all(d).unwrap();
    }
    camera_csv(&a.join("alpha__lab.csv"), 0.0);
    camera_csv(&b.join("beta.csv"), 6.0);
    let pool = format!("{},{},nikon_d5100_npl", s(&a), s(&b));
    let out = dir.join("out");
    generate(
        &out,
        &[
            "--fast",
            "--randomise",
            "camera",
            "--cameras",
            &pool,
            "--camera-variants",
            "0",
        ],
    );
    let manifest = std::fs::read_to_string(out.join("manifest.json")).unwrap();
    let manifest: serde_json::Value = serde_json::from_str(&manifest).unwrap();
    let cameras = &manifest["origin"]["randomisation"]["cameras"];
    let names: Vec<&str> = cameras
        .as_array()
        .expect("the manifest lists the pool")
        .iter()
        .filter_map(|c| c.as_str())
        .collect();
    for name in ["alpha__lab", "beta", "nikon_d5100_npl"] {
        assert!(names.contains(&name), "{name} missing from {names:?}");
    }
    // The same directory twice would draw its cameras twice as often.
    let twice = format!("{},{}", s(&a), s(&a));
    fails(
        &[
            "generate",
            "--lighting",
            LIGHTING,
            "--count",
            "4",
            "--fast",
            "--randomise",
            "camera",
            "--cameras",
            &twice,
            "-o",
            s(&dir.join("twice")),
        ],
        "camera 'alpha__lab' is in the camera pool twice",
    );
}
