//! Camera raw files on the command line: `render --scene … -o x.dng` writes one, `estimate`
//! reads it on its mosaic, says so, reads the light's colour through the file's matrices and
//! judges it by the raw model's calibration; a cut file is refused by name. Told the light's
//! illuminance (`--illuminance`), the DNG carries the EXIF exposure by ISO 12232's
//! saturation-based speed and `estimate` reads the absolute levels back.

mod common;

use common::{fails, ok, s, scratch, spdcam};

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
    // The virtual camera's DNG has neither forward matrices nor lens-shading opcodes.
    assert_eq!(raw["colour"]["forward_matrix"], false, "{raw}");
    assert_eq!(raw["gain_maps_applied"], 0, "{raw}");
    assert_eq!(raw["opcodes_skipped"], serde_json::json!([]), "{raw}");
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
    // Judged by the raw model's own calibration (fitted on raw scene photos, smooth lights
    // among them): a Planckian light is expected to be read closely, `ok`, and its CCT's
    // 95 % interval holds the truth within ±4 % (the JPEG model's calibration gave raw
    // photos ±5.1 % at best).
    assert_eq!(e["verdict"], "ok", "{}", e["reasons"]);
    let expected_gfc = e["expected_gfc"].as_f64().unwrap();
    assert!(expected_gfc > 0.98, "{expected_gfc}");
    let half = e["metric_uncertainty"]["cct_k"]["half95"].as_f64().unwrap();
    assert!(
        (cct - 3000.0).abs() <= half && half / cct < 0.04,
        "{cct} ± {half}"
    );
    // Without --illuminance the DNG has no EXIF exposure: no absolute levels, and why.
    assert!(e["absolute"].is_null(), "{e}");
    assert!(
        e["absolute_reason"].as_str().unwrap().contains("EXIF"),
        "{e}"
    );
    // The shipped ColorChecker 24 raw model made the spectrum, and both outputs say so.
    assert_eq!(
        raw["spectrum_model"], "the shipped ColorChecker 24 raw model",
        "{raw}"
    );
    let out = spdcam(&["estimate", &s(&photo)]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("raw file (spdcam") && stdout.contains("sensor's mosaic"),
        "{stdout}"
    );
    assert!(
        stdout.contains("raw photos' spectra from the shipped ColorChecker 24 raw model"),
        "{stdout}"
    );

    // A raw model reads raw patches only: refused as a photo's model, and a photo's model
    // refused as a raw model, each with what to do instead.
    let models = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models");
    let raw_model = s(&models.join("colorchecker24.raw.spdm"));
    let jpeg_model = s(&models.join("colorchecker24.spdm"));
    let err = fails(&["estimate", &s(&photo), "--model", &raw_model]);
    assert!(
        err.contains("reads raw files' patches") && err.contains("--raw-model"),
        "{err}"
    );
    let err = fails(&["estimate", &s(&photo), "--raw-model", &jpeg_model]);
    assert!(err.contains("does not read raw patches"), "{err}");
    // Given explicitly, it reads the photo as the shipped one does.
    let given = ok(&["estimate", &s(&photo), "--raw-model", &raw_model]);
    assert!(
        given.contains(&format!("raw photos' spectra from {raw_model}")),
        "{given}"
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

/// The lighting metric `key` of the named light `spd` (`spdcam metrics --json`).
fn true_metric(spd: &str, key: &str) -> f64 {
    let v: serde_json::Value = serde_json::from_str(&ok(&["metrics", spd, "--json"])).unwrap();
    v[0][key]
        .as_f64()
        .unwrap_or_else(|| panic!("{spd}: no {key}"))
}

#[test]
fn a_dng_told_its_illuminance_gives_the_absolute_levels_back() {
    // Two lights at three illuminances, each a scene DNG with the chart in the middle (the
    // lens's vignetting, up to 25 % at the corners, costs the grey row 1–2 % there).
    let dir = scratch("raw-lux");
    for (k, (spd, lux)) in [("A", 250.0), ("A", 2000.0), ("D65", 20_000.0)]
        .into_iter()
        .enumerate()
    {
        let photo = dir.join(format!("lit{k}.dng"));
        let lux_arg = lux.to_string();
        ok(&[
            "render",
            "--spd",
            spd,
            "--scene",
            "1200x900",
            "--chart-centre",
            "0.5,0.5",
            "--chart-width",
            "0.4",
            "--seed",
            &(30 + k).to_string(),
            "--illuminance",
            &lux_arg,
            "-o",
            &s(&photo),
        ]);
        let json: serde_json::Value =
            serde_json::from_str(&ok(&["estimate", &s(&photo), "--json"])).unwrap();
        let e = &json[0];
        let exposure = &e["photo"]["exposure"];
        assert_eq!(
            (exposure["f_number"].as_f64(), exposure["iso"].as_f64()),
            (Some(4.0), Some(100.0)),
            "{exposure}"
        );
        let a = &e["absolute"];
        let found = a["illuminance_lux"]
            .as_f64()
            .unwrap_or_else(|| panic!("{spd} at {lux} lx: {e}"));
        // The illuminance read back differs from the light's only by the grey patches'
        // green against their luminance factor (under 1 %), the vignetting, the sensor's
        // noise and the DNG's 14-bit steps: within 3 %.
        assert!(
            (found / lux - 1.0).abs() < 0.03,
            "{spd}: {found} lx read, {lux} lx true"
        );
        assert!(
            a["note"]
                .as_str()
                .unwrap()
                .contains("saturation-based speed"),
            "{a}"
        );
        // PPFD and melanopic EDI: the illuminance times the estimate's own PPF per lux and
        // M-EDER, so against the truth (the known SPD's ratios at the known level) they
        // are off by the illuminance's 3 % and by the estimate's error in those ratios,
        // which its calibrated 95 % interval bounds.
        for (key, ratio) in [
            ("ppfd_umol_m2_s", "ppf_per_lux"),
            ("melanopic_edi_lux", "mel_der"),
        ] {
            let value = a[key].as_f64().unwrap();
            let truth = lux * true_metric(spd, ratio);
            let estimated = e["metrics"][ratio].as_f64().unwrap();
            let half = e["metric_uncertainty"][ratio]["half95"].as_f64().unwrap();
            assert!(
                (value / (found * estimated) - 1.0).abs() < 1e-9,
                "{key}: {value}"
            );
            assert!(
                (value / truth - 1.0).abs() < 0.03 + half / estimated,
                "{spd} at {lux} lx, {key}: {value} read, {truth} true (± {half} in {ratio})"
            );
        }
        if k == 0 {
            // The command line and the report show them too.
            let text = ok(&["estimate", &s(&photo)]);
            assert!(
                text.contains("absolute (approximate, from f/4,")
                    && text.contains("ISO 100): PPFD")
                    && text.contains("illuminance about"),
                "{text}"
            );
            let report = dir.join("lit.html");
            ok(&["estimate", &s(&photo), "--report", &s(&report)]);
            let html = std::fs::read_to_string(&report).unwrap();
            assert!(
                html.contains("data-key=\"illuminance\""),
                "no illuminance in the report"
            );
        }
    }
    // The illuminance belongs to a DNG's EXIF, and must be a level.
    let png = s(&dir.join("chart.png"));
    let e = fails(&["render", "--spd", "A", "--illuminance", "100", "-o", &png]);
    assert!(e.contains("FILE.dng"), "{e}");
    let dng = s(&dir.join("chart.dng"));
    for bad in ["0", "nan", "inf"] {
        let e = fails(&["render", "--spd", "A", "--illuminance", bad, "-o", &dng]);
        assert!(e.contains("illuminance"), "{bad}: {e}");
    }
}

#[test]
fn a_dng_of_several_charts_told_the_first_ones_illuminance_gives_each_its_own() {
    // Two ColorChecker 24s under CIE A, the second in a shade at half the light: with the
    // first chart's illuminance the DNG's exposure gives each its own level back. (Under
    // different lights the sensor's green stands for luminance differently: docs/raw.md.)
    let dir = scratch("raw-places-illuminance");
    let photo = dir.join("two.dng");
    ok(&[
        "render",
        "--spd",
        "A",
        "--scene",
        "1600x1000",
        "--seed",
        "3",
        "--place",
        "centre=0.28,0.5 width=0.3",
        "--place",
        "centre=0.72,0.5 width=0.3 level=0.5",
        "--illuminance",
        "400",
        "-o",
        &s(&photo),
    ]);
    let json: serde_json::Value =
        serde_json::from_str(&ok(&["estimate", &s(&photo), "--json"])).unwrap();
    let estimates = json.as_array().unwrap();
    assert_eq!(estimates.len(), 2, "{json}");
    for (e, lux) in estimates.iter().zip([400.0, 200.0]) {
        let read = e["absolute"]["illuminance_lux"].as_f64().unwrap();
        assert!((read / lux - 1.0).abs() < 0.03, "{read} lx for {lux}: {e}");
    }
}

#[test]
fn a_raw_model_is_not_calibrated_on_the_real_photo_sets_jpegs() {
    let dir = scratch("raw-calibrate");
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let models = root.join("models");
    let err = fails(&[
        "trust",
        "calibrate",
        "--model",
        &s(&models.join("colorchecker24.spdm")),
        "--raw-model",
        &s(&models.join("colorchecker24.raw.spdm")),
        "--split",
        &s(&root.join("docs/validation-split.json")),
        "--scenes",
        "1",
        "--real",
        "-o",
        &s(&dir),
    ]);
    assert!(
        err.contains("calibrated on raw scene photos alone") && err.contains("leave out --real"),
        "{err}"
    );
}

#[test]
fn a_raw_photo_of_a_chart_lit_half_by_another_light_is_not_ok() {
    // The chart's left half under a Planckian 3000 K, its right half under D65: no one light
    // explains the patches, which the self-check on the developed colours tells, with the
    // raw model's calibration's levels.
    let dir = scratch("raw-half");
    let photo = dir.join("half.dng");
    ok(&[
        "render",
        "--spd",
        "planck:3000",
        "--right-light",
        "D65",
        "--scene",
        "1200x900",
        "--seed",
        "2",
        "-o",
        &s(&photo),
    ]);
    let out = spdcam(&["estimate", &s(&photo), "--json"]);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let e = &json[0];
    assert_eq!(e["verdict"], "unusable", "{}", e["reasons"]);
    let reasons = e["reasons"].to_string();
    assert!(reasons.contains("does not explain"), "{reasons}");
}
