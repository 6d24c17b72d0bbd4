//! A raw model's trust calibration (`spdcam trust calibrate --raw-model`) on a few raw scene
//! photos: two validation lamps and the smooth lights, one photo each by one held-out
//! camera; needs the measured data (the lamp library and the cameras).
#![cfg(feature = "measured-data")]

mod common;

use common::data_dir;
use spdcam_core::builtin::DataDir;
use spdcam_core::light_families::ValidationSplit;
use spdcam_eval::held_out::{HeldOutPhotos, LampFiles};
use spdcam_eval::trust::raw::{calibrate_raw, calibration_smooth_lights};
use spdcam_infer::Model;
use std::path::PathBuf;

#[test]
fn a_raw_model_is_calibrated_on_raw_scene_photos_of_its_chart() {
    let data = DataDir::new(Some(data_dir()));
    let repo = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut split = ValidationSplit::read(&repo.join("docs/validation-split.json")).unwrap();
    split.lamps.validation.truncate(2);
    split.cameras.held_out.truncate(1);
    let dir = std::env::temp_dir().join(format!("spdcam-raw-calibration-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let split_path = dir.join("split.json");
    split.write(&split_path).unwrap();
    let photos = |models: Vec<PathBuf>| HeldOutPhotos {
        models,
        split: split_path.clone(),
        library: LampFiles::default(),
        cameras: None,
        shots: 1,
        seed: 5,
    };
    let chart_model = repo.join("models/colorchecker24.spdm");
    let raw_model = repo.join("models/colorchecker24.raw.spdm");
    let fitted = calibrate_raw(
        &photos(vec![chart_model.clone()]),
        std::slice::from_ref(&raw_model),
        1,
        &data,
    )
    .unwrap();
    assert_eq!(fitted.models.len(), 1);
    let c = &fitted.models[0];
    let raw = Model::load(&raw_model).unwrap();
    // Made for the raw model, on its wavelengths, from scene photos of the two lamps and
    // the smooth lights.
    let smooth = calibration_smooth_lights().unwrap().len();
    assert_eq!(smooth, 32);
    assert_eq!(c.calibration.model, raw.fingerprint());
    assert_eq!(c.chart, "colorchecker24");
    assert_eq!(c.calibration.wavelength_nm, raw.grid().wavelengths());
    assert_eq!(c.calibration.scenes_per_lamp, 1);
    assert_eq!(c.calibration.real_photos, 0);
    assert!(c.calibration.method.starts_with("raw scene photos"));
    assert!(c.records.len() > smooth && c.records.len() <= 2 + smooth);
    for r in &c.records {
        // The lamps' photos are groups 0 and 1, each smooth light a group of its own.
        match r.source.as_str() {
            "scene" => assert!(r.group < 2, "{}", r.group),
            "smooth" => assert!((2..2 + smooth).contains(&r.group), "{}", r.group),
            other => panic!("a calibration photo of source {other}"),
        }
        assert!(r.gfc > 0.5 && r.gfc <= 1.0, "GFC {}", r.gfc);
        // The self-check on the developed colours was made on every photo.
        assert!(r.self_check.is_some());
    }
    // A smooth light is read closely: the expected GFC of most of them is high.
    let smooth_expected: Vec<f64> = c
        .records
        .iter()
        .filter(|r| r.source == "smooth")
        .map(|r| r.expected_gfc)
        .collect();
    let high = smooth_expected.iter().filter(|&&e| e > 0.97).count();
    assert!(2 * high > smooth_expected.len(), "{smooth_expected:?}");
    // The bands are wider at 95 % than at 68 %, everywhere.
    assert!(c
        .calibration
        .scale68
        .iter()
        .zip(&c.calibration.scale95)
        .all(|(a, b)| a <= b));

    // Without scene photos, without the chart's model, or with a model that reads no raw
    // patches: refused, naming what to give.
    let none = calibrate_raw(
        &photos(vec![chart_model.clone()]),
        std::slice::from_ref(&raw_model),
        0,
        &data,
    )
    .err()
    .unwrap()
    .to_string();
    assert!(none.contains("--scenes 1 or more"), "{none}");
    let sg = repo.join("models/colorchecker_sg96.spdm");
    let alone = calibrate_raw(
        &photos(vec![sg]),
        std::slice::from_ref(&raw_model),
        1,
        &data,
    )
    .err()
    .unwrap()
    .to_string();
    assert!(
        alone.contains("give the model of its chart (colorchecker24)"),
        "{alone}"
    );
    let not_raw = calibrate_raw(&photos(vec![chart_model.clone()]), &[chart_model], 1, &data)
        .err()
        .unwrap()
        .to_string();
    assert!(not_raw.contains("does not read raw patches"), "{not_raw}");
    std::fs::remove_dir_all(&dir).unwrap();
}
