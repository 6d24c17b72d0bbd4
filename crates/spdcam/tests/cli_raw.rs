//! Camera raw files on the command line: `render --scene … -o x.dng` writes one, `estimate`
//! reads it on its mosaic, says so, reads the light's colour through the file's matrices and
//! gives the raw intervals; a cut file is refused by name.

mod common;

use common::{s, scratch, spdcam};

#[test]
fn a_rendered_dng_is_estimated_from_its_mosaic_with_the_lights_colour() {
    let dir = scratch("raw");
    let photo = dir.join("warm.dng");
    let out = spdcam(&[
        "render",
        "--spd",
        "planck:3000",
        "--scene",
        "1200x900",
        "--seed",
        "6",
        "-o",
        &s(&photo),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = spdcam(&["estimate", &s(&photo), "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let e = &json[0];
    let raw = &e["photo"]["raw"];
    assert_eq!(
        raw["colour"]["matrices"],
        serde_json::json!(["A", "D65"]),
        "{raw}"
    );
    // Planckian 3000 K: CIE 1931 xy (0.4369, 0.4041) (CIE 015:2018, Planck's law).
    let xy = [
        raw["light_xy"][0].as_f64().unwrap(),
        raw["light_xy"][1].as_f64().unwrap(),
    ];
    assert!(
        (xy[0] - 0.4369).abs() < 0.003 && (xy[1] - 0.4041).abs() < 0.003,
        "{xy:?}"
    );
    let cct = e["colorimetry"]["cct"].as_f64().unwrap();
    assert!((cct / 3000.0 - 1.0).abs() < 0.03, "{cct}");
    // The raw intervals: 8.6 % of the CCT at 95 %.
    let half = e["metric_uncertainty"]["cct_k"]["half95"].as_f64().unwrap();
    assert!((half / cct - 0.0859).abs() < 1e-6, "{half} of {cct}");
    // Without an EXIF exposure the DNG gets no absolute levels, and says why.
    assert!(e["absolute"].is_null(), "{e}");
    assert!(
        e["absolute_reason"].as_str().unwrap().contains("EXIF"),
        "{e}"
    );
    let out = spdcam(&["estimate", &s(&photo)]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("raw file (spdcam") && stdout.contains("sensor's mosaic"),
        "{stdout}"
    );

    let cut = dir.join("cut.dng");
    let bytes = std::fs::read(&photo).unwrap();
    std::fs::write(&cut, &bytes[..bytes.len() / 4]).unwrap();
    let out = spdcam(&["estimate", &s(&cut)]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("cut.dng"),
        "{stderr}"
    );
}
