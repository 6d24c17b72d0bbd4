//! `spdcam metrics` as a user runs it: JSON with every key, a readable table, named lights, and
//! clear errors on bad input.

mod common;

use common::{scratch, spdcam};
use std::path::PathBuf;

/// The CIE 015 lamps the library's reference tests use (FL2, FL7, FL11, LED-B3, LED-RGB1, HP1).
fn lamps_csv() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../spdcam-core/tests/reference/quality_spds.csv")
}

/// colour-science's Ra of FL2 from the committed reference numbers.
fn reference_ra(name: &str) -> f64 {
    let path = lamps_csv().with_file_name("quality_shipped.csv");
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "cri_ra").unwrap();
    let row = lines.find(|l| l.starts_with(&format!("{name},"))).unwrap();
    row.split(',').nth(col).unwrap().parse().unwrap()
}

const REQUIRED_KEYS: [&str; 10] = [
    "name",
    "cct_k",
    "duv",
    "cri_ra",
    "cri_r",
    "tm30_rf",
    "tm30_rg",
    "mel_der",
    "sp_ratio",
    "ppf_per_lux",
];

#[test]
fn json_has_one_object_per_column_with_every_key() {
    let o = spdcam(&["metrics", lamps_csv().to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let list = v.as_array().unwrap();
    let names: Vec<&str> = list.iter().map(|o| o["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["FL2", "FL7", "FL11", "LED-B3", "LED-RGB1", "HP1"]);
    for o in list {
        for key in REQUIRED_KEYS {
            assert!(o.get(key).is_some(), "{}: no key {key}", o["name"]);
        }
        assert_eq!(o["cri_r"].as_array().unwrap().len(), 14);
    }
    let fl2 = &list[0];
    let ra = fl2["cri_ra"].as_f64().unwrap();
    assert!((ra - reference_ra("FL2")).abs() < 0.1, "Ra {ra}");
    assert!((fl2["cct_k"].as_f64().unwrap() - 4224.5).abs() < 1.0);
    assert_eq!(fl2["tm30_bins"].as_array().unwrap().len(), 16);
    assert!(fl2["reasons"].as_object().unwrap().is_empty());
}

#[test]
fn undefined_values_are_null_with_a_reason() {
    let dir = scratch("metrics-null");
    let csv = dir.join("odd.csv");
    // A dark column, a strongly negative one, and a deep-red line with no CCT.
    let mut text = String::from("wavelength_nm,dark,negative,red\n");
    for w in (380..=780).step_by(5) {
        let red = if w == 650 { 1.0 } else { 0.0 };
        let neg = if w == 500 { -0.5 } else { 1.0 };
        text.push_str(&format!("{w},0,{neg},{red}\n"));
    }
    std::fs::write(&csv, text).unwrap();
    let o = spdcam(&["metrics", csv.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let [dark, negative, red] = [&v[0], &v[1], &v[2]];
    for o in [dark, negative] {
        for key in &REQUIRED_KEYS[1..] {
            assert!(o[key].is_null(), "{}: {key} = {}", o["name"], o[key]);
            assert!(
                o["reasons"][key].is_string(),
                "{}: no reason for {key}",
                o["name"]
            );
        }
    }
    assert!(dark["reasons"]["cri_ra"]
        .as_str()
        .unwrap()
        .contains("no visible light"));
    assert!(negative["reasons"]["cct_k"]
        .as_str()
        .unwrap()
        .contains("negative (-0.5) at 500 nm"));
    assert!(red["cct_k"].is_null() && red["tm30_rf"].is_null());
    assert!(red["reasons"]["tm30_rf"]
        .as_str()
        .unwrap()
        .contains("colour temperature"));
    assert!(red["sp_ratio"].as_f64().unwrap() > 0.0 && red["mel_der"].as_f64().unwrap() > 0.0);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn text_table_and_named_lights() {
    let o = spdcam(&["metrics", "D65", "cct:2700", lamps_csv().to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8(o.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert!(lines[0].contains("CCT") && lines[0].contains("Ra") && lines[0].contains("M-EDER"));
    let d65 = lines.iter().find(|l| l.starts_with("D65 ")).unwrap();
    // D65: CCT 6504 K, Ra 100.0 (to one decimal), M-EDER 1.000.
    assert!(
        d65.contains("6504") && d65.contains("100.0") && d65.contains("1.000"),
        "{d65}"
    );
    let warm = lines.iter().find(|l| l.starts_with("cct:2700")).unwrap();
    assert!(warm.contains("2700"), "{warm}");
    // FL2: CCT 4225 K, Ra 64.15 (colour-science), Rf 70.1.
    let fl2: Vec<&str> = lines
        .iter()
        .find(|l| l.starts_with("FL2 "))
        .unwrap()
        .split_whitespace()
        .collect();
    assert_eq!(fl2[1], "4225", "{fl2:?}");
    let ra: f64 = fl2[3].parse().unwrap();
    assert!((ra - reference_ra("FL2")).abs() <= 0.06, "{fl2:?}");
    assert_eq!(fl2[5], "70.1", "{fl2:?}");
    // HP1 (high-pressure sodium) lies off the locus far enough for a note, or has none; every
    // light has its row.
    assert!(lines.iter().any(|l| l.starts_with("HP1 ")));
}

#[test]
fn bad_input_is_a_one_line_error() {
    let dir = scratch("metrics-bad");
    let missing = dir.join("missing.csv");
    let o = spdcam(&["metrics", missing.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(!o.status.success());
    assert!(
        err.contains("missing.csv") && err.contains("does not exist"),
        "{err}"
    );
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");

    let bad = dir.join("bad.csv");
    std::fs::write(&bad, "wavelength_nm,a\n400,1\n410,x\n").unwrap();
    let o = spdcam(&["metrics", bad.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(!o.status.success());
    assert!(
        err.contains("bad.csv") && err.contains("line 3") && err.contains("'x'"),
        "{err}"
    );

    let o = spdcam(&["metrics", "moonlight"]);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(
        !o.status.success() && err.contains("moonlight") && err.contains("D65"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
