//! The light-kind priors fitted on small inputs (a few particles and photos per kind) and
//! the real photo sets estimated with their kind named; needs the measured data (the
//! training cameras, the lamp fits' luminaire, the real photo sets).
#![cfg(feature = "measured-data")]

mod common;

use common::data_dir;
use spdcam_core::builtin::DataDir;
use spdcam_core::light_families::LightKind;
use spdcam_eval::light_kinds::{real_checks, KindFit, KindFitOptions};
use spdcam_infer::kind_prior::KindPriors;
use std::path::PathBuf;

#[test]
fn priors_fitted_on_a_few_photos_move_estimates_towards_their_kind() {
    let repo = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let data = DataDir::new(Some(data_dir()));
    let options = KindFitOptions {
        model: repo.join("models/colorchecker_sg96.spdm"),
        split: repo.join("docs/validation-split.json"),
        cameras: None,
        particles: 80,
        photos: 240,
        seed: 5,
    };
    let mut heard = Vec::new();
    let fit = KindFit::fit(&options, &data, &mut |k| heard.push(k.to_string())).unwrap();
    let kinds: Vec<LightKind> = fit.priors.kinds.iter().map(|p| p.kind).collect();
    assert_eq!(kinds, &LightKind::ALL[1..]);
    assert_eq!(heard.len(), 7);
    let text = fit.priors.to_json().unwrap();
    assert_eq!(KindPriors::from_json(&text, "fitted").unwrap(), fit.priors);
    for c in &fit.checks {
        assert!(c.worst_particle_gfc > 0.95, "{c:?}");
        assert!(c.told.unlike < 0.1, "{c:?}");
        assert!(c.told.gfc.iter().all(|g| *g > 0.5 && *g <= 1.0), "{c:?}");
    }
    // A family of one parameter is recovered far better once named, in shape; its colour
    // stays the one the SG model's colour map gives (the prior's shape, the map's colour).
    assert!(fit.model.header().colour_map.is_some());
    for kind in [LightKind::Daylight, LightKind::Incandescent] {
        let c = fit.checks.iter().find(|c| c.kind == kind).unwrap();
        assert!(
            c.told.gfc[1] > c.told.gfc[0] && c.told.gfc[1] > 0.99,
            "{c:?}"
        );
        assert!(
            (c.told.delta_uv[1] - c.told.delta_uv[0]).abs() < 1e-4,
            "{c:?}"
        );
    }
    // The same seed gives the same priors; too few photos for the basis is refused.
    let again = KindFit::fit(&options, &data, &mut |_| {}).unwrap();
    assert_eq!(again.priors, fit.priors);
    let few = KindFitOptions {
        photos: 20,
        ..options.clone()
    };
    let err = KindFit::fit(&few, &data, &mut |_| {}).unwrap_err();
    assert!(err.to_string().contains("residual photos"), "{err}");

    // The real sets, each estimated with and without its kind.
    let real = real_checks(&fit.model, &fit.priors, &data).unwrap();
    let photos: Vec<usize> = real.iter().map(|c| c.photos).collect();
    assert_eq!(photos, [640, 800, 61]);
    assert_eq!(real[1].kind, LightKind::RgbLed);
    for c in &real {
        assert!(c.told.gfc.iter().all(|g| *g > 0.5 && *g <= 1.0), "{c:?}");
        assert!((0.0..=1.0).contains(&c.told.unlike), "{c:?}");
    }
}
