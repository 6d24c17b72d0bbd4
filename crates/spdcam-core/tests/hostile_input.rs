//! Hostile and careless input to datasets (issue 15): two writers of one directory, damaged
//! part files on resume and on reading, failed imports, nonsense SPD files, sizes past the
//! limits. Needs no data directory.

use spdcam_core::builtin::{self, DataDir};
use spdcam_core::camera::sensor::Sensitivities;
use spdcam_core::camera::{Camera, CameraConfig};
use spdcam_core::chart::Chart;
use spdcam_core::dataset::{
    self, Dataset, Duplicates, ExportOptions, GenerateOptions, Generator, ImportOptions, Pipeline,
    LOCK_FILE,
};
use spdcam_core::light_families::Lighting;
use spdcam_core::spectral::Grid;
use std::path::{Path, PathBuf};

const GRID: Grid = Grid::SIMULATION;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("spdcam-hostile-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn camera() -> Camera {
    let set = builtin::CAMERAS[0].load().unwrap();
    let sensitivities = Sensitivities::new("nikon_d5100_npl", &set, &GRID).unwrap();
    Camera::new(
        &sensitivities,
        Chart::colorchecker24(&GRID).unwrap(),
        CameraConfig::default(),
        &GRID,
    )
    .unwrap()
}

fn lighting() -> Lighting {
    Lighting::parse("gaussian:4", &DataDir::default(), &GRID).unwrap()
}

fn options(count: u64, seed: u64) -> GenerateOptions {
    GenerateOptions {
        chunk_size: 8,
        pipeline: Pipeline::Fast,
        ..GenerateOptions::new(count, seed)
    }
}

fn generate(dir: &Path, count: u64, seed: u64) {
    let (cam, light) = (camera(), lighting());
    let generator = Generator::new(&cam, &light, options(count, seed)).unwrap();
    let plan = generator.prepare(dir, false).unwrap();
    generator.run(&plan, &|_| {}).unwrap();
}

/// Flips one bit in the middle of `path`.
fn flip_a_bit(path: &Path) {
    let mut bytes = std::fs::read(path).unwrap();
    let at = bytes.len() / 2;
    bytes[at] ^= 0x10;
    std::fs::write(path, bytes).unwrap();
}

#[test]
fn a_second_writer_of_a_directory_refuses_at_once() {
    // Issue 15, item 1: run A (seed 7) reported success while the directory ended with
    // run B's (seed 9) parts and manifest.
    let dir = scratch("two-writers");
    let (cam, light) = (camera(), lighting());
    let a = Generator::new(&cam, &light, options(24, 7)).unwrap();
    let b = Generator::new(&cam, &light, options(24, 9)).unwrap();
    let plan_a = a.prepare(&dir, false).unwrap();
    assert!(dir.join(LOCK_FILE).is_file());
    for overwrite in [false, true] {
        let e = b.prepare(&dir, overwrite).unwrap_err().to_string();
        assert!(e.contains("in use") && e.contains(LOCK_FILE), "{e}");
    }
    // The same holds for every other writer of the directory.
    let csv = scratch("two-writers-csv");
    std::fs::create_dir_all(&csv).unwrap();
    std::fs::write(csv.join("f.csv"), FEATURES).unwrap();
    std::fs::write(csv.join("s.csv"), "400,700\n1,1\n1,1\n").unwrap();
    let e = dataset::import_csv(
        &csv.join("f.csv"),
        &csv.join("s.csv"),
        &dir,
        &import_options(),
        true,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("in use"), "{e}");
    let m = a.run(&plan_a, &|_| {}).unwrap();
    assert_eq!(m.samples, 24);
    assert!(
        !dir.join(LOCK_FILE).exists(),
        "the lock goes when the run ends"
    );
    std::fs::remove_dir_all(&csv).unwrap();
    let data = Dataset::open(&dir).unwrap();
    assert_eq!(data.manifest().origin.generated().unwrap().seed, 7);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_stale_lock_of_a_dead_process_does_not_block() {
    let dir = scratch("stale");
    std::fs::create_dir_all(&dir).unwrap();
    let mut child = std::process::Command::new("true").spawn().unwrap();
    let pid = child.id();
    child.wait().unwrap();
    let host = std::fs::read_to_string("/proc/sys/kernel/hostname")
        .map(|h| h.trim().to_string())
        .unwrap_or_else(|_| "unknown".into());
    let owner = dataset::LockOwner {
        pid,
        host,
        process_start: Some(1),
        since_unix_s: 0,
    };
    std::fs::write(dir.join(LOCK_FILE), serde_json::to_string(&owner).unwrap()).unwrap();
    if cfg!(target_os = "linux") {
        generate(&dir, 8, 1);
        assert_eq!(Dataset::open(&dir).unwrap().len(), 8);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_damaged_part_is_rendered_again_on_resume_and_noticed_when_read() {
    // Issue 15, item 7: a part file with one flipped byte was kept on resume; the manifest
    // had no checksums; `dataset info`/`export` did not notice.
    let whole = scratch("flip-whole");
    generate(&whole, 24, 3);
    let data = Dataset::open(&whole).unwrap();
    assert!(data.manifest().files.iter().all(|f| f.sha256.is_some()));
    let report = data.verify(&|_| {});
    assert!(report.problems.is_empty(), "{:?}", report.problems);
    assert_eq!((report.files_ok, report.without_checksum), (3, 0));

    let damaged = scratch("flip-damaged");
    generate(&damaged, 24, 3);
    let part = damaged.join(&data.manifest().files[1].name);
    flip_a_bit(&part);
    let opened = Dataset::open(&damaged).unwrap();
    let report = opened.verify(&|_| {});
    assert_eq!(report.files_ok, 2);
    assert!(
        report.problems[0].contains("part-00001") && report.problems[0].contains("checksum"),
        "{:?}",
        report.problems
    );
    let e = opened.load().unwrap_err().to_string();
    assert!(e.contains("checksum"), "{e}");
    let csv = scratch("flip-export");
    let export = ExportOptions {
        feature_scale: 255.0,
        spd_grid: None,
    };
    let e = dataset::export_csv(&opened, &csv, &export, false).unwrap_err();
    assert!(e.to_string().contains("checksum"), "{e}");
    assert!(!csv.exists(), "a failed export leaves nothing");

    // Running the same command again renders the damaged part again: the files equal a
    // clean run's.
    let (cam, light) = (camera(), lighting());
    let generator = Generator::new(&cam, &light, options(24, 3)).unwrap();
    let plan = generator.prepare(&damaged, false).unwrap();
    assert_eq!(
        plan.done(),
        16,
        "the two intact parts are kept, the damaged one is not"
    );
    generator.run(&plan, &|_| {}).unwrap();
    for f in &data.manifest().files {
        assert_eq!(
            std::fs::read(whole.join(&f.name)).unwrap(),
            std::fs::read(damaged.join(&f.name)).unwrap(),
            "{}",
            f.name
        );
    }
    for d in [&whole, &damaged] {
        std::fs::remove_dir_all(d).unwrap();
    }
}

#[test]
fn files_rewritten_on_purpose_are_taken_in_with_update_checksums() {
    let dir = scratch("rewritten");
    generate(&dir, 16, 2);
    let data = Dataset::open(&dir).unwrap();
    let name = &data.manifest().files[0].name;
    let batch = data.read_file(0).unwrap();
    let mut fewer = data.columns().batch();
    for i in 0..3 {
        fewer.push(batch.row(i)).unwrap();
    }
    let bytes = dataset::encode_parquet(data.columns(), &fewer).unwrap();
    std::fs::write(dir.join(name), bytes).unwrap();
    assert!(data.read_file(0).is_err());
    let m = Dataset::update_checksums(&dir).unwrap();
    assert_eq!((m.samples, m.files[0].rows), (11, 3));
    let again = Dataset::open(&dir).unwrap();
    assert!(again.verify(&|_| {}).problems.is_empty());
    assert_eq!(again.load().unwrap().len(), 11);
    std::fs::remove_dir_all(&dir).unwrap();
}

fn import_options() -> ImportOptions {
    ImportOptions {
        feature_scale: 255.0,
        spd_grid: Grid::ESTIMATION,
        family: "x".into(),
        chunk_size: 4096,
        weights_of: None,
    }
}

/// Imports features `f` and SPDs `s` (CSV text) into `dir/data`; the error text if it fails.
fn import(dir: &Path, f: &str, s: &str) -> Result<dataset::ImportReport, String> {
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(dir.join("f.csv"), f).unwrap();
    std::fs::write(dir.join("s.csv"), s).unwrap();
    dataset::import_csv(
        &dir.join("f.csv"),
        &dir.join("s.csv"),
        &dir.join("data"),
        &import_options(),
        false,
    )
    .map_err(|e| e.to_string())
}

const FEATURES: &str = "p01_r,p01_g,p01_b\n200,120,40\n30,90,180\n";

#[test]
fn nonsense_spd_files_are_refused_like_render_refuses_them() {
    // Issue 15, items 3 and 5: one wavelength panicked; negative, all-zero and µm SPDs were
    // stored (all zero) with a warning and exit 0.
    let dir = scratch("spd-files");
    let cases = [
        ("550\n1\n2\n", "at least two"),
        ("400,500,600\n1,-0.5,1\n1,1,1\n", "negative"),
        ("400,500,600\n0,0,0\n1,1,1\n", "zero everywhere"),
        ("0.4,0.5,0.6\n1,1,1\n1,1,1\n", "not in nm"),
        ("100,200,300\n1,1,1\n1,1,1\n", "zero everywhere"),
    ];
    for (spds, expected) in cases {
        let e = import(&dir, FEATURES, spds).unwrap_err();
        assert!(e.contains(expected) && e.contains("s.csv"), "{spds:?}: {e}");
        // Item 9: a failed import leaves no `samples/` behind, and the same command runs
        // again.
        assert!(!dir.join("data").exists(), "{spds:?} left output behind");
    }
    let ok = import(
        &dir,
        FEATURES,
        "400,500,600,700\n1,0.5,0.25,0\n0.2,1,0.3,0.1\n",
    )
    .unwrap();
    assert_eq!(ok.manifest.samples, 2);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_failed_import_into_an_existing_directory_keeps_what_was_there() {
    let dir = scratch("import-existing");
    let out = dir.join("data");
    std::fs::create_dir_all(&out).unwrap();
    let bad_features = "p01_r,p01_g,p01_b\n200,120,40\n30,x,180\n";
    std::fs::write(dir.join("f.csv"), bad_features).unwrap();
    std::fs::write(dir.join("s.csv"), "400,500\n1,1\n1,1\n").unwrap();
    let e = dataset::import_csv(
        &dir.join("f.csv"),
        &dir.join("s.csv"),
        &out,
        &import_options(),
        false,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("'x' is not a number"), "{e}");
    assert!(out.is_dir(), "a directory the user made stays");
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), 0);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn counts_chunks_and_grids_past_the_limits_are_refused_before_work() {
    // Issue 15, item 4: `generate --count 1e12` spent minutes planning chunk paths;
    // `--spd-grid 380-780:0.00001` ran for minutes with gigabytes.
    let (cam, light) = (camera(), lighting());
    let e = Generator::new(&cam, &light, options(1_000_000_000_000, 1))
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("SPDCAM_MAX_SAMPLES"), "{e}");
    let huge_chunks = GenerateOptions {
        chunk_size: 1 << 40,
        ..options(10, 1)
    };
    let e = Generator::new(&cam, &light, huge_chunks)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("SPDCAM_MAX_CHUNK_BYTES"), "{e}");
    let e = Grid::parse("380-780:0.00001").unwrap_err().to_string();
    assert!(e.contains("SPDCAM_MAX_GRID_BANDS"), "{e}");
}

#[test]
fn manifests_naming_files_outside_the_dataset_are_refused() {
    let dir = scratch("escape");
    generate(&dir, 8, 1);
    let path = dir.join("manifest.json");
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(
        &path,
        text.replace("samples/part-00000.parquet", "../../etc/passwd"),
    )
    .unwrap();
    let e = Dataset::open(&dir).unwrap_err().to_string();
    assert!(e.contains("not a path inside"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn writers_refuse_an_output_that_is_holds_or_lies_inside_an_input() {
    // Issue 29, item 1: split and export with --force emptied their input first.
    let dir = scratch("apart");
    let data = dir.join("ds");
    generate(&data, 16, 3);
    let input = Dataset::open(&data).unwrap();
    let export = ExportOptions {
        feature_scale: 255.0,
        spd_grid: None,
    };
    for (out, relation) in [
        (data.clone(), "is"),
        (data.join("samples"), "lies inside"),
        (dir.clone(), "contains"),
    ] {
        let errors = [
            dataset::split(&input, &out, [0.5, 0.25, 0.25], 1, true, &|_| {}).map(|_| ()),
            dataset::export_csv(&input, &out, &export, true).map(|_| ()),
            dataset::merge(
                std::slice::from_ref(&input),
                &out,
                true,
                Duplicates::Refuse,
                &|_| {},
            )
            .map(|_| ()),
        ];
        for e in errors {
            let e = e.unwrap_err().to_string();
            assert!(
                e.contains(&format!("{relation} the input {}", data.display())),
                "{}: {e}",
                out.display()
            );
        }
        let again = Dataset::open(&data).unwrap();
        assert!(again.verify(&|_| {}).problems.is_empty());
        assert_eq!(again.len(), 16);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_dataset_and_its_copy_are_not_merged() {
    // Issue 29, item 9.
    let dir = scratch("merge-copy");
    let (a, b) = (dir.join("a"), dir.join("b"));
    generate(&a, 16, 4);
    std::fs::create_dir_all(b.join("samples")).unwrap();
    for name in [
        "manifest.json",
        "samples/part-00000.parquet",
        "samples/part-00001.parquet",
    ] {
        std::fs::copy(a.join(name), b.join(name)).unwrap();
    }
    let inputs = [Dataset::open(&a).unwrap(), Dataset::open(&b).unwrap()];
    let e = dataset::merge(&inputs, &dir.join("m"), false, Duplicates::Refuse, &|_| {})
        .unwrap_err()
        .to_string();
    assert!(e.contains("hold the same samples"), "{e}");
    assert!(!dir.join("m").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn endless_streams_are_read_only_up_to_the_limit() {
    // Issue 29, item 4: `estimate /dev/zero` reached 15.7 GB.
    let limit = spdcam_core::limits::Limit {
        what: "bytes of a test stream",
        env: "SPDCAM_TEST_UNSET_LIMIT",
        default: 4096,
    };
    let e = spdcam_core::fsio::read_limited(Path::new("/dev/zero"), &limit)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("/dev/zero: more than 4,096 bytes of a test stream"),
        "{e}"
    );
    let dir = scratch("limited-read");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("exact"), vec![7u8; 4096]).unwrap();
    std::fs::write(dir.join("over"), vec![7u8; 4097]).unwrap();
    let read = spdcam_core::fsio::read_limited(&dir.join("exact"), &limit).unwrap();
    assert_eq!(read.len(), 4096);
    let e = spdcam_core::fsio::read_limited(&dir.join("over"), &limit)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("4,097 bytes of a test stream exceed the limit of 4,096"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_cut_jpeg_is_truncated_and_a_flipped_bit_is_corrupt() {
    // Issue 29, item 10.
    use spdcam_core::photo::{decode_photo, jpeg_end, JpegEnd};
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/sg-telelumen.jpg");
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(jpeg_end(&bytes), JpegEnd::Complete);
    let half = &bytes[..bytes.len() / 2];
    assert_eq!(jpeg_end(half), JpegEnd::Truncated);
    match decode_photo(half, "half.jpg") {
        Ok(p) => assert!(
            p.warnings.iter().any(|w| w.contains("truncated")),
            "{:?}",
            p.warnings
        ),
        Err(e) => assert!(e.to_string().contains("truncated"), "{e}"),
    }
    let mut corrupt = 0;
    for k in 1..16 {
        let mut damaged = bytes.clone();
        let at = damaged.len() * k / 16;
        damaged[at] ^= 0x04;
        let end = jpeg_end(&damaged);
        assert_ne!(end, JpegEnd::Truncated, "bit at {at}");
        corrupt += usize::from(end == JpegEnd::Corrupt);
        let said = match decode_photo(&damaged, "flipped.jpg") {
            Ok(p) => p.warnings.join("; "),
            Err(e) => e.to_string(),
        };
        assert!(!said.contains("truncated"), "bit at {at}: {said}");
        if end == JpegEnd::Corrupt {
            assert!(said.contains("corrupt"), "bit at {at}: {said}");
        }
    }
    // A bit that makes a marker out of entropy-coded data: FF followed by a marker code.
    let mut marker = bytes.clone();
    let at = (bytes.len() / 2..bytes.len() - 4)
        .find(|&i| bytes[i] == 0xFE && !matches!(bytes[i + 1], 0x00 | 0xD0..=0xD9 | 0xFF))
        .unwrap();
    marker[at] = 0xFF;
    assert_eq!(jpeg_end(&marker), JpegEnd::Corrupt);
    assert!(corrupt > 0 || jpeg_end(&marker) == JpegEnd::Corrupt);
}

#[test]
fn spds_at_the_ends_of_double_precision_give_the_unscaled_metrics() {
    // Issue 29, item 11.
    use spdcam_core::quality::LightingMetrics;
    let grid = Grid::new(380.0, 780.0, 5.0).unwrap();
    let base: Vec<f64> = grid
        .wavelengths()
        .iter()
        .map(|w| ((w / 780.0).powi(4) + 0.4 * (-((w - 450.0) / 20.0).powi(2)).exp()) / 1.01)
        .collect();
    let reference = LightingMetrics::from_samples(&grid.wavelengths(), &base);
    assert!(reference.reasons.is_empty(), "{:?}", reference.reasons);
    for scale in [1e-300, 1e300, 1e308, f64::MAX / 2.0] {
        let scaled: Vec<f64> = base.iter().map(|v| v * scale).collect();
        let m = LightingMetrics::from_samples(&grid.wavelengths(), &scaled);
        assert!(m.reasons.is_empty(), "{scale:e}: {:?}", m.reasons);
        for key in [
            "cct_k", "cri_ra", "cri_r9", "tm30_rf", "tm30_rg", "mel_der", "sp_ratio",
        ] {
            let (a, b) = (reference.scalar(key).unwrap(), m.scalar(key).unwrap());
            assert!(
                (a - b).abs() <= 1e-9 * a.abs().max(1.0),
                "{scale:e} {key}: {a} vs {b}"
            );
        }
    }
}
