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

/// The example's estimate as the library makes it (what the CLI estimates and reports).
fn example_estimate() -> spdcam_infer::Estimate {
    spdcam_infer::Estimator::shipped(
        spdcam_core::builtin::DataDir::new(None),
        spdcam_core::spectral::Grid::parse("400-700:5").unwrap(),
    )
    .unwrap()
    .estimate_photo(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join(EXAMPLE),
        &spdcam_infer::PhotoOptions::default(),
    )
    .unwrap()
}

/// The significant digits of a number's text: `0.00007` → 1, `11` → 2, `800` → 1.
fn significant_digits(text: &str) -> usize {
    let digits: String = text.chars().filter(char::is_ascii_digit).collect();
    let digits = digits.trim_start_matches('0');
    if text.contains('.') {
        digits.len()
    } else {
        digits.trim_end_matches('0').len()
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
    // Every metric as the presentation gives it: rounded with its interval, or '—' and why.
    let presentation = spdcam_present::presentation::Presentation::of(&example_estimate());
    let mut greyed = 0;
    for line in presentation.groups.iter().flat_map(|g| &g.metrics) {
        match &line.value {
            Some(value) => {
                let unit = if line.unit.is_empty() {
                    String::new()
                } else {
                    format!(" {}", line.unit)
                };
                let cell = format!("data-key=\"{}\">{value}{unit}</td>", line.key);
                assert!(html.contains(&cell), "no {cell} in the report");
                // The half-width keeps one or two significant digits.
                if let Some((_, half)) = value.split_once(" ± ") {
                    let n = significant_digits(half);
                    assert!((1..=2).contains(&n), "{}: {value}", line.key);
                }
            }
            None => {
                greyed += 1;
                let why = line.not_meaningful.as_deref().unwrap();
                let cell = format!(
                    "<tr class=\"metric not-meaningful\"><th>{}</th><td data-key=\"{}\">—</td>\
                     <td class=\"explain reason\">{}</td>",
                    line.label,
                    line.key,
                    why.replace('\'', "&#39;")
                );
                assert!(html.contains(&cell), "no {cell} in the report");
            }
        }
    }
    // This LED mix lies far from the Planckian locus: no CCT, no Ra anywhere in the report.
    assert!(greyed >= 2, "{greyed} metrics greyed");
    let m = &e["metrics"];
    for key in ["cct_k", "cri_ra"] {
        let raw = m[key].as_f64().unwrap();
        for text in [format!("{raw:.0}"), format!("{raw:.1}")] {
            for cell in [format!(">{text}<"), format!(">{text} ±")] {
                assert!(!html.contains(&cell), "{key} {text} is shown");
            }
        }
    }
    // No R1–R15 bars, SSI or filter corrections for a light without a colour temperature;
    // its chromaticity on the u′v′ diagram.
    assert!(!html.contains("class=\"r-bars\"") && !html.contains("SSI (own CCT)"));
    assert!(html.contains("class=\"uv-diagram\"") && html.contains("class=\"estimate-point\""));
    let gfc = format!("{:.4}", e["truth"]["gfc"].as_f64().unwrap());
    assert!(
        html.contains(&format!("data-key=\"gfc\">GFC {gfc}, RMSE ")),
        "GFC {gfc}"
    );
    let x = format!("{:.4}", e["colorimetry"]["xy"][0].as_f64().unwrap());
    assert!(html.contains(&x), "x {x}");
    let confidence = format!(
        "(confidence {:.2})",
        e["photo"]["confidence"].as_f64().unwrap()
    );
    assert!(html.contains(&confidence), "{confidence}");
    // The summary and the verdict in plain words at the top.
    let summary = html.find(&format!(
        "<p class=\"summary\">{}",
        presentation.summary.replace('\'', "&#39;")
    ));
    let verdict = html.find(&format!(
        "data-verdict=\"{}\"",
        e["verdict"].as_str().unwrap()
    ));
    let plot = html.find("<svg class=\"spd-plot\"");
    assert!(
        summary.is_some() && summary < verdict && verdict < plot,
        "the order"
    );
    // The plots inline, the truth and the bands drawn and in the legend, the photo as a data URI.
    assert!(html.contains("<polyline class=\"spd\""));
    assert!(html.contains("<polyline class=\"truth\""));
    assert!(
        html.contains("<polygon class=\"band68\"") && html.contains("<polygon class=\"band95\"")
    );
    for label in ["estimate", "true spectrum", "68 % band", "95 % band"] {
        assert!(
            html.contains(&format!(">{label}</text></g>")),
            "no legend entry {label}"
        );
    }
    assert!(html.contains("src=\"data:image/jpeg;base64,/9j/"));
    // The metrics' warnings, but those that a metric is not meaningful: its greyed row says
    // that, without repeating the raw value.
    for w in e["metrics"]["warnings"].as_array().unwrap() {
        let w = w.as_str().unwrap().replace('\'', "&#39;");
        assert_eq!(
            html.contains(&w),
            !w.contains("not meaningful"),
            "warning {w}"
        );
    }
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
    assert!(html.contains("<h1>The light in sg-telelumen.jpg</h1>"));
    assert!(html.contains("<h1>The light in again.jpg</h1>"));
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
    // The example's light is too far from white for TM-30: the reason, not the graphic.
    assert!(html.contains(
        "<p class=\"undefined\" data-key=\"tm30_bins\">TM-30 colour vector graphic: not meaningful"
    ));
    assert!(!html.contains("<svg class=\"tm30-cvg\""));
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
