//! The colour protocol on small inputs: one validation lamp, one test lamp and the white
//! references, one held-out camera, a few photos; needs the measured data (the lamp library
//! and the cameras).
#![cfg(feature = "measured-data")]

mod common;

use common::data_dir;
use spdcam_core::builtin::DataDir;
use spdcam_core::light_families::ValidationSplit;
use spdcam_core::spectral::{Grid, Spd};
use spdcam_eval::colour::lights::{references, LightSet};
use spdcam_eval::colour::{ColourOptions, ColourReport, ColourScore, Group, Summary};
use spdcam_eval::held_out::{HeldOutPhotos, LampFiles, GRID};
use spdcam_eval::lamp_validation::average_spd;
use std::path::PathBuf;

/// Every number of a summary is finite and in its range.
fn check(s: &Summary, what: &str) {
    assert!(s.photos > 0, "{what}");
    for share in [s.refused, s.ok] {
        assert!((0.0..=1.0).contains(&share), "{what}: {s:?}");
    }
    assert!(s.refused < 1.0, "{what}: every photo refused");
    assert!(s.gfc > 0.5 && s.gfc <= 1.0 + 1e-12, "{what}: {s:?}");
    assert!(
        s.delta_uv_prime >= 0.0 && s.delta_uv_prime < 0.1,
        "{what}: {s:?}"
    );
    let c = s
        .cct
        .unwrap_or_else(|| panic!("{what}: white lights without a CCT score"));
    assert!(c.median_error.abs() < 0.5, "{what}: {c:?}");
    assert!((0.0..=1.0).contains(&c.too_high), "{what}: {c:?}");
    assert!(c.median_abs_error >= 0.0, "{what}: {c:?}");
}

#[test]
fn one_camera_a_few_photos() {
    let root = data_dir();
    let data = DataDir::new(Some(root.clone()));
    let repo = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut split = ValidationSplit::read(&repo.join("docs/validation-split.json")).unwrap();
    split.lamps.validation.truncate(1);
    split.lamps.test.truncate(1);
    split.cameras.held_out.truncate(1);
    let dir = std::env::temp_dir().join(format!("spdcam-colour-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let split_path = dir.join("split.json");
    split.write(&split_path).unwrap();
    let options = ColourOptions {
        held_out: HeldOutPhotos {
            models: vec![repo.join("models/colorchecker24.spdm")],
            split: split_path,
            library: LampFiles::default(),
            cameras: None,
            shots: 1,
            seed: 3,
        },
        reference_photos: 1,
        patch_photos: 2,
        light_named: true,
        light_priors: Vec::new(),
        raw: false,
        raw_models: Vec::new(),
    };
    let report = ColourReport::measure(&options, &data, &mut |_| {}).unwrap();
    assert_eq!(report.cameras, 1);
    // The model, then the model told each light's kind, on the same photos.
    assert_eq!(report.models.len(), 2);
    let model = &report.models[0];
    assert!(model.calibrated, "the shipped model has a calibration");
    assert!(!model.light_named && report.models[1].light_named);
    for m in &report.models {
        for row in &m.rows {
            for (k, s) in row.scores.iter().enumerate() {
                check(s, &format!("{:?} {:?} path {k}", row.set, row.group));
            }
        }
    }
    // Told "daylight" or "incandescent", the white references' shapes come closer.
    let reference_gfc = |m: &spdcam_eval::colour::ModelColour| {
        m.rows
            .iter()
            .find(|r| r.set == LightSet::References && r.group == Group::All)
            .unwrap()
            .scores[1]
            .gfc
    };
    let (plain, told) = (reference_gfc(model), reference_gfc(&report.models[1]));
    assert!(told > plain, "told {told}, plain {plain}");
    assert!(report.markdown().contains("told the kind of light"));
    // The references: 8 lights, 1 scene photo and 2 patch-level photos each, and the
    // shipped model's intervals.
    let refs = model
        .rows
        .iter()
        .find(|r| r.set == LightSet::References && r.group == Group::All)
        .unwrap();
    assert_eq!(refs.lights, 8);
    assert_eq!([refs.scores[0].photos, refs.scores[1].photos], [8, 16]);
    let (width, holds) = refs.scores[1].cct.unwrap().interval.unwrap();
    assert!(width > 0.0 && width < 1.0, "{width}");
    assert!((0.0..=1.0).contains(&holds));

    // The truth over 400–700 nm keeps the shape and nearly the colour of the whole light.
    for row in &report.baselines {
        let truth = &row.scores[1];
        assert!((truth.gfc - 1.0).abs() < 1e-12, "{row:?}");
        assert!(truth.delta_uv_prime < 1e-3, "{row:?}");
        assert!(truth.cct.unwrap().median_abs_error < 0.005, "{row:?}");
    }
    // The constant's score of D65 is its colour against D65's, computed here directly.
    let library = LampFiles::default().read(&data, &GRID).unwrap();
    let fit = library.positions(&split.lamps.fit, "fit").unwrap();
    let spds: Vec<Vec<f64>> = library
        .spds
        .iter()
        .map(|s| s.resampled(&Grid::ESTIMATION).unwrap().into_values())
        .collect();
    let constant = Spd::new(Grid::ESTIMATION, average_spd(&spds, &fit)).unwrap();
    let d65 = references()
        .unwrap()
        .into_iter()
        .find(|l| l.name == "CIE D65")
        .unwrap();
    let direct = ColourScore::of(&d65.spd, &constant).unwrap();
    let row = report
        .baselines
        .iter()
        .find(|r| r.group == Group::Light("CIE D65".into()))
        .unwrap();
    assert_eq!(row.scores[0].delta_uv_prime, direct.delta_uv_prime);
    assert_eq!(
        row.scores[0].cct.unwrap().median_error,
        direct.cct_error().unwrap()
    );

    // The same seed gives the same report.
    let again = ColourReport::measure(&options, &data, &mut |_| {}).unwrap();
    assert_eq!(again.markdown(), report.markdown());
    std::fs::remove_dir_all(&dir).unwrap();
}
