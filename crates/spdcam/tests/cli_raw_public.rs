//! Raw files that spdcam did not write (`tests/raw-files/`, their sources and licences in
//! its README): a camera's DNG of a ColorChecker Passport is found, read on its mosaic and
//! estimated, the Passport's other page left out with a note; cut files of three formats
//! are refused by name as damaged, quickly, without a panic.

mod common;

use common::{s, spdcam};
use std::path::PathBuf;
use std::time::Instant;

fn raw_file(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/raw-files")
        .join(name)
}

#[test]
fn a_cameras_dng_of_a_passport_is_estimated_from_its_mosaic() {
    let photo = raw_file("passport-eos-550d.dng");
    let run = spdcam(&["estimate", &s(&photo), "--json"]);
    let said = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{said}");
    // The white-balance page above the ColorChecker 24 is found as a grid and left out.
    assert!(
        said.contains("a grid of patches at") && said.contains("it is not a ColorChecker 24"),
        "{said}"
    );
    let json: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
    let estimates = json.as_array().unwrap();
    assert_eq!(estimates.len(), 1, "{json}");
    let e = &estimates[0];
    assert_eq!(e["photo"]["chart"], "colorchecker24", "{e}");
    assert!(e["photo"]["place"].is_null(), "one chart, no place: {e}");
    let raw = &e["photo"]["raw"];
    assert_eq!(raw["camera"], "Canon EOS Kiss X4", "{raw}");
    // The file has one colour matrix, for D65, and no forward matrix or gain map.
    assert_eq!(
        raw["colour"]["matrices"],
        serde_json::json!(["D65"]),
        "{raw}"
    );
    assert_eq!(raw["colour"]["forward_matrix"], false, "{raw}");
    assert_eq!(raw["gain_maps_applied"], 0, "{raw}");
    // The ColorChecker 24's six greys in the photo's bottom row, the darkest too dark.
    let greys: Vec<u64> = raw["neutral_patches"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p.as_u64().unwrap())
        .collect();
    assert!(
        greys.len() >= 4 && greys.iter().all(|p| (18..24).contains(p)),
        "{raw}"
    );
    // The light is not documented; the scene is a room at dusk. Its greys read a warm light
    // near the Planckian locus, and the estimate's own CCT agrees with them.
    let neutral_cct = raw["colour"]["neutral_cct_k"].as_f64().unwrap();
    assert!((2000.0..4500.0).contains(&neutral_cct), "{raw}");
    let cct = e["colorimetry"]["cct"].as_f64().unwrap();
    assert!(
        (cct / neutral_cct - 1.0).abs() < 0.05,
        "{cct} against {neutral_cct}"
    );
    let duv = e["colorimetry"]["duv"].as_f64().unwrap();
    assert!(duv.abs() < 0.02, "{duv}");
}

#[test]
fn cut_raw_files_of_three_formats_are_refused_by_name() {
    for name in [
        "cut-leica-m10.dng",
        "cut-sony-zv-e10.arw",
        "cut-canon-eos-r.cr3",
    ] {
        let started = Instant::now();
        let run = spdcam(&["estimate", &s(&raw_file(name))]);
        let said = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(1), "{name}: {said}");
        assert!(!said.contains("panicked"), "{name}: {said}");
        assert!(said.contains(&format!("{name}: unusable photo")), "{said}");
        assert!(said.contains("damaged or truncated"), "{said}");
        assert!(said.contains("raw converter"), "{said}");
        assert!(run.stdout.is_empty(), "{name}: no estimate");
        assert!(started.elapsed().as_secs() < 20, "{name}: quickly");
    }
}
