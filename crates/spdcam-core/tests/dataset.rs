//! Datasets end to end: generation is a pure function of (seed, sample), shards and resumed
//! runs give the files of one run, generated features are the camera's, and imports keep
//! every number of the thesis's data.

#[cfg(feature = "measured-data")]
mod shared_data;

use spdcam_core::builtin::{self, DataDir};
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::{Camera, CameraConfig};
use spdcam_core::chart::Chart;
use spdcam_core::dataset::{
    self, Dataset, Duplicates, ExportOptions, FileFormat, GenerateOptions, Generator,
    ImportOptions, Origin, Pipeline, Shard,
};
use spdcam_core::light_families::Lighting;
use spdcam_core::seed;
use spdcam_core::spectral::{Grid, Spd};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

const GRID: Grid = Grid::SIMULATION;
const LIGHTING: &str = "gaussian:4";

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("spdcam-dataset-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// Every file under `dir` (relative path → bytes).
fn files(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.insert(
                    p.strip_prefix(dir).unwrap().to_path_buf(),
                    std::fs::read(&p).unwrap(),
                );
            }
        }
    }
    out
}

fn assert_same_files(a: &Path, b: &Path) {
    let (fa, fb) = (files(a), files(b));
    assert_eq!(
        fa.keys().collect::<Vec<_>>(),
        fb.keys().collect::<Vec<_>>(),
        "{} and {} hold different files",
        a.display(),
        b.display()
    );
    for (name, bytes) in &fa {
        assert!(bytes == &fb[name], "{} differs", name.display());
    }
}

/// The thesis camera on the ColorChecker 24 with the built-in Nikon: small and quick.
fn camera(config: CameraConfig) -> Camera {
    let set = builtin::CAMERAS[0].load().unwrap();
    let sensitivities = Sensitivities::new("nikon_d5100_npl", &set, &GRID).unwrap();
    Camera::new(
        &sensitivities,
        Chart::colorchecker24(&GRID).unwrap(),
        config,
        &GRID,
    )
    .unwrap()
}

fn lighting() -> Lighting {
    Lighting::parse(LIGHTING, &DataDir::default(), &GRID).unwrap()
}

fn options(count: u64, seed: u64) -> GenerateOptions {
    GenerateOptions {
        chunk_size: 16,
        ..GenerateOptions::new(count, seed)
    }
}

fn generate(camera: &Camera, lighting: &Lighting, options: GenerateOptions, dir: &Path) {
    let generator = Generator::new(camera, lighting, options).unwrap();
    let plan = generator.prepare(dir, false).unwrap();
    generator.run(&plan, &|_| {}).unwrap();
}

#[test]
fn same_seed_gives_identical_files_and_another_seed_other_samples() {
    let (cam, light) = (camera(CameraConfig::default()), lighting());
    let (a, b, c) = (scratch("same-a"), scratch("same-b"), scratch("same-c"));
    generate(&cam, &light, options(40, 7), &a);
    generate(&cam, &light, options(40, 7), &b);
    generate(&cam, &light, options(40, 8), &c);
    assert_same_files(&a, &b);
    let (da, dc) = (Dataset::open(&a).unwrap(), Dataset::open(&c).unwrap());
    assert_eq!(da.len(), 40);
    assert_eq!(da.manifest().files.len(), 3);
    let (ra, rc) = (da.load().unwrap(), dc.load().unwrap());
    assert_eq!(ra.samples, (0..40).collect::<Vec<u64>>());
    assert_ne!(ra.features, rc.features);
    for d in [&a, &b, &c] {
        std::fs::remove_dir_all(d).unwrap();
    }
}

#[test]
fn shards_merge_into_the_single_run() {
    let (cam, light) = (camera(CameraConfig::default()), lighting());
    let whole = scratch("shards-whole");
    generate(&cam, &light, options(70, 3), &whole);
    let mut shards = Vec::new();
    for k in [2, 0, 1] {
        let dir = scratch(&format!("shards-{k}"));
        let shard = Some(Shard { index: k, count: 3 });
        generate(
            &cam,
            &light,
            GenerateOptions {
                shard,
                ..options(70, 3)
            },
            &dir,
        );
        shards.push(Dataset::open(&dir).unwrap());
    }
    let merged = scratch("shards-merged");
    let manifest = dataset::merge(&shards, &merged, false, Duplicates::Refuse, &|_| {})
        .unwrap()
        .manifest;
    assert!(matches!(manifest.origin, Origin::Generated(ref s) if s.shard.is_none()));
    assert_same_files(&whole, &merged);

    let missing = scratch("shards-missing");
    let e = dataset::merge(&shards[..2], &missing, false, Duplicates::Refuse, &|_| {})
        .unwrap_err()
        .to_string();
    assert!(e.contains("missing"), "{e}");
    for d in shards
        .iter()
        .map(Dataset::dir)
        .chain([whole.as_path(), merged.as_path()])
    {
        std::fs::remove_dir_all(d).unwrap();
    }
    let _ = std::fs::remove_dir_all(&missing);
}

#[test]
fn generated_samples_are_the_camera_renders_of_their_lights() {
    let light = lighting();
    let seed = 11;
    for (pipeline, config) in [
        (Pipeline::Full, CameraConfig::default()),
        (Pipeline::Fast, CameraConfig::default()),
    ] {
        let cam = camera(config);
        let generator = Generator::new(
            &cam,
            &light,
            GenerateOptions {
                pipeline,
                ..options(12, seed)
            },
        )
        .unwrap();
        let batch = generator.samples(0..12, None, &|_| {}).unwrap();
        for i in [0usize, 5, 11] {
            let draw = light.draw(seed, i as u64).unwrap();
            assert_eq!(batch.spd_of(i), draw.spd.values());
            assert_eq!(batch.families[i], draw.family);
            assert_eq!(batch.attempts[i], draw.attempts);
            assert_eq!(
                batch.weights_of(i),
                draw.weights.as_deref().unwrap_or_default()
            );
            let expected: Vec<f64> = match pipeline {
                Pipeline::Full => cam
                    .render(&draw.spd, seed::derive(seed, i as u64), false)
                    .unwrap()
                    .features
                    .iter()
                    .map(|&v| v as f64)
                    .collect(),
                Pipeline::Fast => {
                    let (mut raw, mut out) = (Vec::new(), Vec::new());
                    cam.features_fast(&cam.light(&draw.spd).unwrap(), &mut raw, &mut out);
                    out.iter().map(|&v| v as f64).collect()
                }
                Pipeline::Raw => unreachable!("raw samples have a test of their own"),
            };
            assert_eq!(
                batch.features_of(i),
                expected.as_slice(),
                "{pipeline:?} sample {i}"
            );
        }
    }
}

#[test]
fn spd_grid_keeps_the_drawn_values() {
    let (cam, light) = (camera(CameraConfig::default()), lighting());
    let grid = Grid::parse("400-700:10").unwrap();
    let generator = Generator::new(
        &cam,
        &light,
        GenerateOptions {
            spd_grid: grid,
            pipeline: Pipeline::Fast,
            ..options(3, 1)
        },
    )
    .unwrap();
    let batch = generator.samples(0..3, None, &|_| {}).unwrap();
    let draw = light.draw(1, 2).unwrap();
    let picked: Vec<f64> = (0..grid.count).map(|k| draw.spd[4 + 2 * k]).collect();
    assert_eq!(batch.spd_of(2), picked.as_slice());
    assert_eq!(generator.columns().column_names()[2 + 72], "spd_400");
}

#[test]
fn interrupted_run_resumes_to_the_same_files() {
    let (cam, light) = (camera(CameraConfig::default()), lighting());
    let whole = scratch("resume-whole");
    generate(&cam, &light, options(64, 5), &whole);

    let dir = scratch("resume-cut");
    let generator = Generator::new(&cam, &light, options(64, 5)).unwrap();
    let plan = generator.prepare(&dir, false).unwrap();
    let done = std::sync::atomic::AtomicU64::new(0);
    let interrupted = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        generator.run(&plan, &|n| {
            if done.fetch_add(n, std::sync::atomic::Ordering::SeqCst) + n > 40 {
                panic!("interrupt");
            }
        })
    }));
    assert!(interrupted.is_err());
    // The interrupted run's plan holds the directory's lock until it is dropped.
    let e = Generator::new(&cam, &light, options(64, 5))
        .unwrap()
        .prepare(&dir, false)
        .unwrap_err()
        .to_string();
    assert!(e.contains("in use"), "{e}");
    drop(plan);
    assert!(!dir.join("manifest.json").exists());
    assert!(Dataset::open(&dir).is_err());
    std::fs::write(dir.join(".samples-00003.parquet.999.partial"), b"PAR1 junk").unwrap();

    let again = Generator::new(&cam, &light, options(64, 5)).unwrap();
    let plan = again.prepare(&dir, false).unwrap();
    assert_eq!((plan.total(), plan.done()), (64, 32));
    again.run(&plan, &|_| {}).unwrap();
    assert_same_files(&whole, &dir);

    // A finished run asked again is left as it is.
    generate(&cam, &light, options(64, 5), &dir);
    assert_same_files(&whole, &dir);
    std::fs::remove_dir_all(&whole).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_settings_give_clear_errors() {
    let (cam, light) = (camera(CameraConfig::default()), lighting());
    let e = Generator::new(&cam, &light, options(0, 1))
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("at least 1"), "{e}");
    let fast_images = GenerateOptions {
        pipeline: Pipeline::Fast,
        images: true,
        ..options(4, 1)
    };
    let e = Generator::new(&cam, &light, fast_images)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("full pipeline"), "{e}");
    let wide = GenerateOptions {
        spd_grid: Grid::parse("300-800:5").unwrap(),
        ..options(4, 1)
    };
    assert!(Generator::new(&cam, &light, wide).is_err());
    assert!(Shard::parse("3/3").is_err());
    assert!(Shard::parse("1-3").is_err());
    assert_eq!(Shard::parse("1/3").unwrap(), Shard { index: 1, count: 3 });

    let dir = scratch("errors");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("notes.txt"), "mine").unwrap();
    let generator = Generator::new(&cam, &light, options(4, 1)).unwrap();
    let e = generator.prepare(&dir, false).unwrap_err().to_string();
    assert!(e.contains("not empty") && e.contains("--force"), "{e}");
    std::fs::remove_file(dir.join("notes.txt")).unwrap();
    generate(&cam, &light, options(4, 1), &dir);
    let other = Generator::new(&cam, &light, options(4, 2)).unwrap();
    let e = other.prepare(&dir, false).unwrap_err().to_string();
    assert!(e.contains("other settings") && e.contains("seed"), "{e}");
    let plan = other.prepare(&dir, true).unwrap();
    assert_eq!(plan.done(), 0);
    other.run(&plan, &|_| {}).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
}

fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let mut r = csv::Reader::from_path(path).unwrap();
    let header = r.headers().unwrap().iter().map(str::to_string).collect();
    let rows = r
        .records()
        .map(|rec| rec.unwrap().iter().map(|c| c.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

#[cfg(feature = "measured-data")]
#[test]
fn import_of_the_measured_dev_set_keeps_every_number() {
    let src = shared_data::data_dir().join("thesis/measured/telelumen_canon5d4_dev");
    let (feature_names, features) = read_csv(&src.join("features.csv"));
    let (wavelengths, spds) = read_csv(&src.join("spds.csv"));
    let dir = scratch("import-dev");
    let report = dataset::import_csv(
        &src.join("features.csv"),
        &src.join("spds.csv"),
        &dir,
        &ImportOptions {
            feature_scale: 255.0,
            spd_grid: GRID,
            family: "telelumen_dev".into(),
            chunk_size: 100,
            weights_of: None,
        },
        false,
    )
    .unwrap();
    assert_eq!(report.manifest.samples, 640);
    assert_eq!(report.largest_feature, 255.0);
    let data = Dataset::open(&dir).unwrap();
    assert_eq!(data.columns().feature_names, feature_names);
    let all = data.load().unwrap();
    assert_eq!(all.len(), 640);
    for (i, (f, s)) in features.iter().zip(&spds).enumerate() {
        assert_eq!(all.features_of(i), f.as_slice(), "features of row {i}");
        let spd = all.spd_of(i);
        for (k, v) in s.iter().enumerate() {
            assert_eq!(spd[2 * k], *v, "row {i} at {} nm", wavelengths[k]);
        }
        assert!(spd[71..].iter().all(|&v| v == 0.0), "beyond 730 nm is zero");
    }

    let out = scratch("import-dev-export");
    dataset::export_csv(
        &data,
        &out,
        &ExportOptions {
            feature_scale: 255.0,
            spd_grid: Some(Grid::new(380.0, 730.0, 10.0).unwrap()),
        },
        false,
    )
    .unwrap();
    assert_eq!(
        read_csv(&out.join("features.csv")),
        (feature_names, features)
    );
    let (exported_wavelengths, exported_spds) = read_csv(&out.join("spds.csv"));
    let as_numbers = |h: &[String]| {
        h.iter()
            .map(|w| w.parse::<f64>().unwrap())
            .collect::<Vec<_>>()
    };
    assert_eq!(as_numbers(&exported_wavelengths), as_numbers(&wavelengths));
    assert_eq!(exported_spds, spds);
    std::fs::remove_dir_all(&dir).unwrap();
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn unit_scale_features_are_stored_on_0_255_and_bad_files_are_named() {
    let dir = scratch("import-unit");
    std::fs::create_dir_all(&dir).unwrap();
    let (f, s) = (dir.join("f.csv"), dir.join("s.csv"));
    std::fs::write(&f, "p01_r,p01_g,p01_b\n0.313515,0.5,1\n0.1,0.2,0.3\n").unwrap();
    std::fs::write(&s, "400,500,600,700\n1,0.5,0.25,0\n0.2,1,0.3,0.1\n").unwrap();
    let opts = |scale: f64| ImportOptions {
        feature_scale: scale,
        spd_grid: Grid::ESTIMATION,
        family: "x".into(),
        chunk_size: 4096,
        weights_of: None,
    };
    let out = dir.join("data");
    dataset::import_csv(&f, &s, &out, &opts(1.0), false).unwrap();
    let data = Dataset::open(&out).unwrap();
    let all = data.load().unwrap();
    assert_eq!(all.features_of(0), &[0.313515 * 255.0, 127.5, 255.0]);
    let e = dataset::import_csv(&f, &s, &out, &opts(1.0), false)
        .unwrap_err()
        .to_string();
    assert!(e.contains("not empty"), "{e}");
    let csv_out = dir.join("csv");
    let unit = ExportOptions {
        feature_scale: 1.0,
        spd_grid: None,
    };
    dataset::export_csv(&data, &csv_out, &unit, false).unwrap();
    let (_, back) = read_csv(&csv_out.join("features.csv"));
    for (a, b) in back[0].iter().zip([0.313515, 0.5, 1.0]) {
        assert!((a - b).abs() <= f64::EPSILON * b, "{a} vs {b}");
    }

    std::fs::write(&f, "p01_r,p01_g,p01_b\n200,0.5,1\n0.1,0.2,0.3\n").unwrap();
    let e = dataset::import_csv(&f, &s, &dir.join("bad"), &opts(1.0), false)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("line 2") && e.contains("p01_r") && e.contains("f.csv"),
        "{e}"
    );
    std::fs::write(&f, "p01_r,p01_g,p01_b\n1,2,3\n").unwrap();
    let e = dataset::import_csv(&f, &s, &dir.join("bad2"), &opts(255.0), false)
        .unwrap_err()
        .to_string();
    assert!(e.contains("more rows"), "{e}");
    std::fs::write(&f, "p01_r,p01_g,p01_b\n1,x,3\n4,5,6\n").unwrap();
    let e = dataset::import_csv(&f, &s, &dir.join("bad3"), &opts(255.0), false)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("'x' is not a number") && e.contains("p01_g"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(feature = "measured-data")]
#[test]
fn split_is_seeded_complete_and_merges_back() {
    let src = shared_data::data_dir().join("thesis/measured/telelumen_canon5d4_dev");
    let dir = scratch("split");
    let data_dir = dir.join("dev");
    std::fs::create_dir_all(&dir).unwrap();
    dataset::import_csv(
        &src.join("features.csv"),
        &src.join("spds.csv"),
        &data_dir,
        &ImportOptions {
            feature_scale: 255.0,
            spd_grid: GRID,
            family: "dev".into(),
            chunk_size: 4096,
            weights_of: None,
        },
        false,
    )
    .unwrap();
    let data = Dataset::open(&data_dir).unwrap();
    let parts = dataset::split(&data, &dir.join("a"), [0.7, 0.1, 0.2], 4, false, &|_| {}).unwrap();
    assert_eq!(parts.each_ref().map(|m| m.samples), [448, 64, 128]);
    dataset::split(&data, &dir.join("b"), [0.7, 0.1, 0.2], 4, false, &|_| {}).unwrap();
    assert_same_files(&dir.join("a"), &dir.join("b"));
    let other = dataset::assign_parts(640, [0.7, 0.1, 0.2], 5).unwrap();
    assert_ne!(
        other,
        dataset::assign_parts(640, [0.7, 0.1, 0.2], 4).unwrap()
    );
    assert!(dataset::assign_parts(10, [0.7, 0.1, 0.1], 1).is_err());

    let opened: Vec<Dataset> = ["train", "val", "test"]
        .iter()
        .map(|p| Dataset::open(&dir.join("a").join(p)).unwrap())
        .collect();
    let joined = dir.join("joined");
    let m = dataset::merge(&opened, &joined, false, Duplicates::Refuse, &|_| {})
        .unwrap()
        .manifest;
    assert!(matches!(m.origin, Origin::Merged { .. }));
    let mut samples = Dataset::open(&joined).unwrap().load().unwrap().samples;
    samples.sort_unstable();
    assert_eq!(samples, (0..640).collect::<Vec<u64>>());
    let rows = data.rows_at(&[639, 3]).unwrap();
    assert_eq!(rows.samples, vec![3, 639]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(feature = "measured-data")]
#[test]
fn import_of_thesis_weights_makes_the_thesis_spds() {
    let src = shared_data::data_dir().join("thesis/virtual/gaussian_5ch_cc24_val");
    let dir = scratch("weights");
    let lighting = Lighting::parse("gaussian:5", &DataDir::default(), &GRID).unwrap();
    dataset::import_csv(
        &src.join("features.csv"),
        &src.join("weights.csv"),
        &dir,
        &ImportOptions {
            feature_scale: 1.0,
            spd_grid: Grid::ESTIMATION,
            family: "g2".into(),
            chunk_size: 4096,
            weights_of: Some(lighting.clone()),
        },
        false,
    )
    .unwrap();
    let batch = Dataset::open(&dir).unwrap().load().unwrap();
    assert_eq!(batch.len(), 889);
    // Row 0 by hand: Σ wᵢ·exp(−(λ−μᵢ)²/2σᵢ²) with the thesis's 5-channel centres and
    // widths, divided by its maximum over 380–780 nm.
    let text = std::fs::read_to_string(src.join("weights.csv")).unwrap();
    let w: Vec<f64> = text
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .map(|c| c.parse().unwrap())
        .collect();
    assert_eq!(batch.weights_of(0), w.as_slice());
    let shapes = [
        (430.0, 15.0),
        (490.0, 20.0),
        (550.0, 20.0),
        (610.0, 20.0),
        (670.0, 15.0),
    ];
    let spd = |l: f64| -> f64 {
        w.iter()
            .zip(shapes)
            .map(|(w, (mu, s)): (&f64, (f64, f64))| {
                w * (-(l - mu) * (l - mu) / (2.0 * s * s)).exp()
            })
            .sum()
    };
    let max = (0..81)
        .map(|i| spd(380.0 + 5.0 * i as f64))
        .fold(0.0, f64::max);
    for (k, &value) in batch.spd_of(0).iter().enumerate() {
        let expected = spd(400.0 + 5.0 * k as f64) / max;
        assert!(
            (value - expected).abs() < 1e-12,
            "{k}: {value} vs {expected}"
        );
    }
    let wrong = Lighting::parse("gaussian:4", &DataDir::default(), &GRID).unwrap();
    let err = dataset::import_csv(
        &src.join("features.csv"),
        &src.join("weights.csv"),
        &scratch("weights-wrong"),
        &ImportOptions {
            feature_scale: 1.0,
            spd_grid: Grid::ESTIMATION,
            family: "g2".into(),
            chunk_size: 4096,
            weights_of: Some(wrong),
        },
        false,
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("5 weight columns, but lighting 'gaussian:4' has 4 channels"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

fn samples_bytes(dir: &Path) -> usize {
    files(&dir.join("samples")).values().map(Vec::len).sum()
}

#[test]
fn generated_sets_are_compressed_float32_and_old_float64_files_still_read() {
    let (cam, light) = (camera(CameraConfig::default()), lighting());
    let generator = Generator::new(
        &cam,
        &light,
        GenerateOptions {
            pipeline: Pipeline::Fast,
            chunk_size: 500,
            ..GenerateOptions::new(2000, 4)
        },
    )
    .unwrap();
    let exact = generator.samples(0..2000, None, &|_| {}).unwrap();
    let dir = scratch("float32");
    generator
        .run(&generator.prepare(&dir, false).unwrap(), &|_| {})
        .unwrap();
    let stored = Dataset::open(&dir).unwrap().load().unwrap();
    // Features are computed in f32 and kept exactly; SPDs and weights are rounded to f32.
    assert_eq!(stored.features, exact.features);
    assert_eq!(stored.samples, exact.samples);
    assert_eq!(stored.families, exact.families);
    let relative = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .map(|(x, y)| {
                if *y == 0.0 {
                    x.abs()
                } else {
                    (x / y - 1.0).abs()
                }
            })
            .fold(0.0f64, f64::max)
    };
    let spd_error = relative(&stored.spds, &exact.spds);
    let weight_error = relative(&stored.weights, &exact.weights);
    assert!(spd_error > 0.0, "SPDs are stored as FLOAT");
    // Half an f32 ulp: 2⁻²⁴ ≈ 6e-8, some 65,000 times below one step of 8-bit features.
    assert!(
        spd_error <= 6e-8 && weight_error <= 6e-8,
        "{spd_error} {weight_error}"
    );
    for (a, b) in stored.spds.iter().zip(&exact.spds) {
        assert_eq!(*a, f64::from(*b as f32));
    }
    // What that rounding does to the features the stored SPDs render: far below one level.
    let (mut raw, mut features) = (Vec::new(), Vec::new());
    let mut feature_shift = 0.0f64;
    for i in 0..stored.len() {
        features.clear();
        cam.features_fast(
            &cam.light(&Spd::new(GRID, stored.spd_of(i).to_vec()).unwrap())
                .unwrap(),
            &mut raw,
            &mut features,
        );
        for (a, b) in features.iter().zip(exact.features_of(i)) {
            feature_shift = feature_shift.max((f64::from(*a) - b).abs());
        }
    }
    assert!(feature_shift < 1e-3, "{feature_shift} of an 8-bit level");
    let compressed = samples_bytes(&dir);

    // The first datasets' files (uncompressed, SPDs and weights as DOUBLE) read as written.
    let old = scratch("float64");
    dataset::merge(
        &[Dataset::open(&dir).unwrap()],
        &old,
        false,
        Duplicates::Refuse,
        &|_| {},
    )
    .unwrap();
    let columns = generator.columns();
    let legacy = FileFormat::uncompressed_float64_values(columns);
    let mut first = 0;
    for entry in &Dataset::open(&old).unwrap().manifest().files {
        let mut batch = columns.batch();
        for i in first..first + entry.rows as usize {
            batch.push(exact.row(i)).unwrap();
        }
        first += entry.rows as usize;
        let bytes = dataset::encode_parquet_as(columns, &batch, &legacy).unwrap();
        std::fs::write(old.join(&entry.name), bytes).unwrap();
    }
    let uncompressed = samples_bytes(&old);
    // The files were rewritten on purpose: their new checksums go into the manifest.
    Dataset::update_checksums(&old).unwrap();
    assert_eq!(Dataset::open(&old).unwrap().load().unwrap(), exact);
    println!(
        "2,000 fast samples: {compressed} bytes zstd + float32, {uncompressed} bytes \
         uncompressed + float64 values ({:.2}×); SPD relative error {spd_error:.1e}, \
         features of the stored SPDs within {feature_shift:.1e} of an 8-bit level",
        uncompressed as f64 / compressed as f64
    );
    // Lossless: float32 mantissas are close to random, so about half the bytes go.
    assert!(
        compressed * 5 < uncompressed * 3,
        "{compressed} vs {uncompressed}"
    );
    for d in [&dir, &old] {
        std::fs::remove_dir_all(d).unwrap();
    }
}

/// A dataset spdcam generated, read and written back by pandas (pyarrow): one file snappy
/// (pandas' default), one gzip, columns nullable (`tools/export_pandas_dataset.py`).
#[test]
fn files_written_by_pandas_read_back() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/reference/pandas-dataset");
    let data = Dataset::open(&dir).unwrap();
    let read = data.load().unwrap();
    let (cam, light) = (camera(CameraConfig::default()), lighting());
    let generator = Generator::new(
        &cam,
        &light,
        GenerateOptions {
            pipeline: Pipeline::Fast,
            chunk_size: 6,
            spd_grid: Grid::parse("400-700:50").unwrap(),
            ..GenerateOptions::new(12, 5)
        },
    )
    .unwrap();
    assert_eq!(data.columns(), generator.columns());
    let mut expected = generator.samples(0..12, None, &|_| {}).unwrap();
    for v in expected.spds.iter_mut().chain(expected.weights.iter_mut()) {
        *v = f64::from(*v as f32);
    }
    assert_eq!(read, expected);
}

#[test]
fn measured_photos_are_read_and_their_spds_resampled_linearly() {
    let dir = scratch("measured-photos");
    std::fs::create_dir_all(&dir).unwrap();
    let (f, s) = (dir.join("features.csv"), dir.join("spds.csv"));
    std::fs::write(&f, "p01_r,p01_g\n10,20\n\n30.5, 40\n").unwrap();
    std::fs::write(&s, "400,410nm,420\n1,3,5\n2,2,0\n").unwrap();
    let grid = Grid::new(395.0, 425.0, 5.0).unwrap();
    let m = dataset::MeasuredPhotos::read(&f, &s, &grid).unwrap();
    assert_eq!(m.features, vec![vec![10.0, 20.0], vec![30.5, 40.0]]);
    // Linear between the file's wavelengths, zero outside 400–420 nm.
    assert_eq!(m.spds[0].values(), &[0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 0.0]);
    assert_eq!(m.spds[1].values(), &[0.0, 2.0, 2.0, 2.0, 1.0, 0.0, 0.0]);
    assert_eq!(m.spds[1].grid(), &grid);
    // One SPD short, and a cell that is not a number: errors name the files and line.
    std::fs::write(&s, "400,410,420\n1,3,5\n").unwrap();
    let e = dataset::MeasuredPhotos::read(&f, &s, &grid)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("has 2 photos but") && e.contains("has 1 SPDs"),
        "{e}"
    );
    std::fs::write(&f, "p01_r,p01_g\n10,x\n").unwrap();
    let e = dataset::MeasuredPhotos::read(&f, &s, &grid)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("features.csv") && e.contains("line 2") && e.contains("'x'"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The real photo sets load from the data directory, each folder's photos joined: 640
/// Telelumen photos by the Canon, 800 of the Hue lamps, 61 by the tablet, 96 SG features
/// each, one measured SPD per photo.
#[cfg(feature = "measured-data")]
#[test]
fn the_real_photo_sets_load_and_join_their_folders() {
    let thesis = shared_data::data_dir().join("thesis");
    let grid = Grid::SIMULATION;
    let counts: Vec<usize> = dataset::REAL_PHOTO_SETS
        .iter()
        .map(|set| {
            let m = set.load(&thesis, &grid).unwrap();
            assert_eq!(m.features.len(), m.spds.len(), "{}", set.label);
            assert!(
                m.features.iter().all(|f| f.len() == 3 * 96),
                "{}",
                set.label
            );
            m.features.len()
        })
        .collect();
    assert_eq!(counts, [640, 800, 61]);
    let missing = dataset::REAL_PHOTO_SETS[0]
        .load(Path::new("no-such-dir"), &grid)
        .unwrap_err();
    assert!(
        missing.to_string().contains("telelumen_canon5d4_dev"),
        "{missing}"
    );
}

#[test]
fn raw_samples_read_each_patch_as_xyz_under_the_light_itself() {
    use spdcam_core::colorimetry::{xyz_to_xy, Observer};
    let cam = camera(CameraConfig::default());
    // White lights, which the raw reading reads (no light is drawn again).
    let light = Lighting::parse("mix:planck=0.5,daylight=0.5", &DataDir::default(), &GRID).unwrap();
    let seed = 5;
    let generator = Generator::new(
        &cam,
        &light,
        GenerateOptions {
            pipeline: Pipeline::Raw,
            ..options(8, seed)
        },
    )
    .unwrap();
    let batch = generator.samples(0..8, None, &|_| {}).unwrap();
    let observer = Observer::cie1931(&GRID).unwrap();
    let chart = cam.chart();
    // The ColorChecker 24's white (feature 19) and its blue (feature 13).
    let white = chart.feature_patches[18];
    let mut whites = Vec::new();
    for i in 0..8 {
        let draw = light.draw(seed, i as u64).unwrap();
        let row = batch.features_of(i);
        assert_eq!(row.len(), 72);
        let read = [row[54], row[55], row[56]];
        // The white patch's colorimetry under the light, a perfect white at Y = 1.
        let truth = observer.reflectance_to_xyz(chart.reflectances.item(white), draw.spd.values());
        let (xy_read, xy_true) = (xyz_to_xy(read), xyz_to_xy(truth));
        assert!(
            (xy_read[0] - xy_true[0]).abs() < 0.006 && (xy_read[1] - xy_true[1]).abs() < 0.006,
            "sample {i}: white read at {xy_read:?}, truly {xy_true:?}"
        );
        let y_true = 100.0 * truth[1];
        assert!(
            (read[1] / y_true - 1.0).abs() < 0.03,
            "sample {i}: Y {} vs {y_true}",
            read[1]
        );
        whites.push(xy_read);
    }
    // Not white-balanced: the white follows the light's colour from sample to sample.
    let spread = whites
        .iter()
        .map(|w| w[0])
        .fold(f64::NEG_INFINITY, f64::max)
        - whites.iter().map(|w| w[0]).fold(f64::INFINITY, f64::min);
    assert!(spread > 0.01, "{whites:?}");
}
