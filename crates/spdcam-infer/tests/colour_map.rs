//! The shipped Digital SG model's colour map: it moves white estimates to the colour the map
//! gives, is part of the model's identity, survives the file, and keeps averages honest.

use spdcam_core::chart::KnownChart;
use spdcam_infer::colour_head::ColourHead;
use spdcam_infer::{Model, ModelSet};

fn shipped_sg() -> Model {
    let set = ModelSet::shipped().unwrap();
    set.for_known(KnownChart::Sg140).unwrap().model.clone()
}

/// A plausible feature row: a grey chart with a warm cast rising along the patches.
fn warm_row(model: &Model) -> Vec<f64> {
    (0..model.feature_names().len())
        .map(|i| {
            let base = 60.0 + 1.5 * (i / 3) as f64;
            base * [1.15, 1.0, 0.8][i % 3]
        })
        .collect()
}

#[test]
fn the_map_moves_the_estimate_to_the_colour_it_gives() {
    let mapped = shipped_sg();
    let map = mapped
        .header()
        .colour_map
        .clone()
        .expect("the shipped SG model carries a colour map");
    let mut plain = mapped.clone();
    plain.set_colour_map(None).unwrap();
    let head = ColourHead::on_grid(&mapped.grid(), 1.0).unwrap();
    let row = warm_row(&mapped);
    let before = head.uv(&plain.estimate(&row).unwrap()).unwrap();
    let after = head.uv(&mapped.estimate(&row).unwrap()).unwrap();
    let want = map.apply(before);
    assert!(
        (after[0] - want[0]).hypot(after[1] - want[1]) < 1e-5,
        "{before:?} → {after:?}, the map gives {want:?}"
    );
    assert_ne!(mapped.fingerprint(), plain.fingerprint());
    assert!(mapped
        .describe()
        .ends_with("white light's colour mapped (`spdcam colour-map fit`)"));
    assert!(!plain.describe().contains("colour mapped"));
}

#[test]
fn the_map_survives_the_file_and_a_model_without_one_is_written_as_before() {
    let mapped = shipped_sg();
    let back = Model::from_bytes(&mapped.to_bytes().unwrap()).unwrap();
    assert_eq!(back.header().colour_map, mapped.header().colour_map);
    assert_eq!(back.fingerprint(), mapped.fingerprint());
    let mut plain = mapped;
    plain.set_colour_map(None).unwrap();
    let bytes = plain.to_bytes().unwrap();
    let text = String::from_utf8_lossy(&bytes);
    assert!(
        !text.contains("colour_map"),
        "a model without a map names none"
    );
    assert_eq!(Model::from_bytes(&bytes).unwrap().header().colour_map, None);
}

#[test]
fn an_average_of_mapped_members_is_refused() {
    let mapped = shipped_sg();
    let e = Model::average(&[mapped.clone(), mapped])
        .unwrap_err()
        .to_string();
    assert!(e.contains("colour map"), "{e}");
}
