//! Fitting a colour map on small inputs: the split's validation lamps through three of its
//! training cameras, one scene photo each; needs the measured data (the lamp library and the
//! cameras).
#![cfg(feature = "measured-data")]

mod common;

use common::data_dir;
use spdcam_core::builtin::DataDir;
use spdcam_core::light_families::ValidationSplit;
use spdcam_eval::colour::map_fit::{MapFit, MapFitOptions};
use spdcam_eval::held_out::LampFiles;
use std::path::PathBuf;

#[test]
fn a_map_is_fitted_from_the_model_without_one_and_reads_its_photos_better() {
    let data = DataDir::new(Some(data_dir()));
    let repo = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut split = ValidationSplit::read(&repo.join("docs/validation-split.json")).unwrap();
    split.cameras.training.truncate(3);
    let dir = std::env::temp_dir().join(format!("spdcam-colour-map-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let split_path = dir.join("split.json");
    split.write(&split_path).unwrap();
    let options = |model: PathBuf| MapFitOptions {
        model,
        split: split_path.clone(),
        library: LampFiles::default(),
        cameras: None,
        scene_photos: 1,
        patch_photos: 0,
        seed: 5,
    };
    let fit = MapFit::fit(
        &options(repo.join("models/colorchecker24.spdm")),
        &data,
        &mut |_| {},
    )
    .unwrap();
    // Every scene photo's chart is found.
    assert_eq!(fit.photos, split.lamps.validation.len());
    // Scene photos through the training cameras read the ColorChecker 24's CCT about 6 %
    // low: the map takes that out.
    let [before, after] = fit.median_delta_uv;
    assert!(after < before, "median Δu′v′ {before} → {after}");
    let map = fit.model.header().colour_map.clone().unwrap();
    // Mired stays mired: a slope near one, an offset of tens of mired at most.
    assert!((0.5..2.0).contains(&map.mired.slope), "{:?}", map.mired);
    assert!(map.mired.offset.abs() < 200.0, "{:?}", map.mired);
    assert!(
        map.fitted_on.contains("3 training cameras"),
        "{}",
        map.fitted_on
    );
    // Fitted again from the mapped model, the fit starts from the model without a map.
    let path = dir.join("mapped.spdm");
    fit.model.save(&path).unwrap();
    let again = MapFit::fit(&options(path), &data, &mut |_| {}).unwrap();
    assert_eq!(again.model.header().colour_map, Some(map));
    assert_eq!(again.median_delta_uv, fit.median_delta_uv);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_raw_correction_fitted_on_the_fit_lamps_reads_unseen_lamps_closer_and_is_the_shipped_one() {
    use spdcam_eval::colour::raw_fit::{RawFit, RawFitOptions};
    use spdcam_infer::measured_colour::RawColourCorrection;
    let data = DataDir::new(Some(data_dir()));
    let repo = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let options = RawFitOptions {
        split: repo.join("docs/validation-split.json"),
        library: LampFiles::default(),
        cameras: None,
        penalty: RawColourCorrection::shipped().unwrap().penalty,
        // The shipped correction is fitted on the shapes the shipped raw models read.
        raw_models: vec![
            repo.join("models/colorchecker_sg96.raw.spdm"),
            repo.join("models/colorchecker24.raw.spdm"),
        ],
    };
    let fit = RawFit::fit(&options, &data, &mut |_| {}).unwrap();
    let [[fit_before, fit_after], [val_before, val_after]] = fit.median_delta_uv;
    // The matrices' bias on lamps is most of their error: unseen lamps through the same
    // cameras come at least 40 % closer.
    assert!(fit_after < 0.6 * fit_before, "{fit_before} → {fit_after}");
    assert!(val_after < 0.6 * val_before, "{val_before} → {val_after}");
    // The committed models/raw-colour.json is what the fit gives (up to the last digits
    // another CPU's arithmetic may change).
    let shipped = RawColourCorrection::shipped().unwrap();
    assert_eq!(shipped.fitted_on, fit.correction.fitted_on);
    for t in 0..2 {
        assert!((shipped.intercept[t] - fit.correction.intercept[t]).abs() < 1e-9);
        for (a, b) in shipped.weights[t].iter().zip(&fit.correction.weights[t]) {
            assert!((a - b).abs() < 1e-9 * (1.0 + a.abs()), "{a} vs {b}");
        }
    }
}
