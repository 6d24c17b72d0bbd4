//! `spdcam estimate --report`: the HTML page of the example photo, of several photos and of
//! feature rows, with the shipped models and no data directory; unwritable paths.

mod common;

use common::{ok, s, scratch, spdcam};
use serde_json::Value;
use std::path::Path;

/// The example photo, with its true SPD beside it.
const EXAMPLE: &str = "../../examples/sg-telelumen.jpg";

/// The files in `dir`, by name.
fn files(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// The page loads nothing: no resource from the network, no stylesheet import.
fn assert_self_contained(html: &str) {
    for pattern in [
        "src=\"http",
        "href=\"http",
        "src='http",
        "href='http",
        "@import",
        "url(http",
        "http://",
        "https://",
    ] {
        assert!(!html.contains(pattern), "the report holds '{pattern}'");
    }
}

#[test]
fn the_report_of_the_example_photo_shows_its_numbers_as_json_gives_them() {
    let dir = scratch("example");
    let report = dir.join("report.html");
    let out = ok(&["estimate", EXAMPLE, "--report", &s(&report)]);
    assert!(
        out.contains(&format!("report → {}", report.display())),
        "{out}"
    );
    assert_eq!(files(&dir), ["report.html"], "a temporary file was left");
    let html = std::fs::read_to_string(&report).unwrap();
    assert!(html.starts_with("<!DOCTYPE html>"));
    assert!(html.trim_end().ends_with("</html>"));
    assert_self_contained(&html);

    let json: Value = serde_json::from_str(&ok(&["estimate", EXAMPLE, "--json"])).unwrap();
    let e = &json[0];
    let m = &e["metrics"];
    let ra = format!("{:.1}", m["cri_ra"].as_f64().unwrap());
    let rf = format!("{:.1}", m["tm30_rf"].as_f64().unwrap());
    let rg = format!("{:.1}", m["tm30_rg"].as_f64().unwrap());
    let cct = format!("{:.0}", m["cct_k"].as_f64().unwrap());
    for (key, value) in [
        ("cri_ra", &ra),
        ("tm30_rf", &rf),
        ("tm30_rg", &rg),
        ("cct_k", &cct),
    ] {
        let cell = format!("data-key=\"{key}\">{value}</td>");
        assert!(html.contains(&cell), "no {cell} in the report");
    }
    let gfc = format!("{:.4}", e["truth"]["gfc"].as_f64().unwrap());
    assert!(
        html.contains(&format!("data-key=\"gfc\">{gfc}</td>")),
        "GFC {gfc}"
    );
    let x = format!("{:.4}", e["colorimetry"]["xy"][0].as_f64().unwrap());
    assert!(html.contains(&x), "x {x}");
    let confidence = format!("{:.2}", e["photo"]["confidence"].as_f64().unwrap());
    assert!(
        html.contains(&format!("data-key=\"confidence\">{confidence}")),
        "confidence {confidence}"
    );
    // The plots inline, the truth drawn, the photo as a data URI.
    assert!(html.contains("<svg class=\"spd-plot\""));
    assert!(html.contains("<polyline class=\"spd\""));
    assert!(html.contains("<polyline class=\"truth\""));
    assert!(html.contains("<svg class=\"tm30-cvg\""));
    assert!(html.contains("ANSI/IES TM-30-20"));
    assert!(html.contains("src=\"data:image/jpeg;base64,/9j/"));
    // Every warning, and the numbers no section shows in the details table.
    for w in e["metrics"]["warnings"].as_array().unwrap() {
        let w = w.as_str().unwrap().replace('\'', "&#39;");
        assert!(html.contains(&w), "warning {w}");
    }
    assert!(html.contains("data-key=\"photo.homography[0]\""));
    assert_eq!(html.matches("<section class=\"estimate\"").count(), 1);
}

#[test]
fn several_photos_and_feature_rows_share_one_page() {
    let dir = scratch("several");
    let other = dir.join("again.jpg");
    std::fs::copy(Path::new(env!("CARGO_MANIFEST_DIR")).join(EXAMPLE), &other).unwrap();
    let report = dir.join("photos.html");
    let features = dir.join("features.csv");
    ok(&[
        "estimate",
        EXAMPLE,
        &s(&other),
        "--report",
        &s(&report),
        "--features-out",
        &s(&features),
    ]);
    let html = std::fs::read_to_string(&report).unwrap();
    assert_eq!(html.matches("<section class=\"estimate\"").count(), 2);
    assert_eq!(html.matches("src=\"data:image/jpeg;base64,").count(), 2);
    assert!(html.contains("<h2>sg-telelumen.jpg</h2>"));
    assert!(html.contains("<h2>again.jpg</h2>"));
    // The copy has no truth beside it: one truth line only.
    assert_eq!(html.matches("<polyline class=\"truth\"").count(), 1);

    let rows = dir.join("rows.html");
    ok(&[
        "estimate",
        "--features",
        &s(&features),
        "--report",
        &s(&rows),
    ]);
    let html = std::fs::read_to_string(&rows).unwrap();
    assert_self_contained(&html);
    assert_eq!(html.matches("<section class=\"estimate\"").count(), 2);
    assert!(!html.contains("data:image"));
    assert!(html.contains("estimated from chart features"));
    assert!(html.contains("<svg class=\"tm30-cvg\""));
}

#[test]
fn an_unwritable_report_is_named_and_nothing_is_written() {
    let dir = scratch("unwritable");
    let missing = dir.join("no-such-dir").join("report.html");
    let out = spdcam(&["estimate", EXAMPLE, "--report", &s(&missing)]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains(&s(&missing)), "{err}");
    let out = spdcam(&["estimate", EXAMPLE, "--report", &s(&dir)]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("is a directory"), "{err}");
    assert!(files(&dir).is_empty(), "{:?}", files(&dir));
}
