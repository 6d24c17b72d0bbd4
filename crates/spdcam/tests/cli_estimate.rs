//! `spdcam estimate PHOTO`: the main job, end to end, with the shipped model and no data
//! directory; features of charts no model knows; bad photos.

mod common;

use common::{fails, ok, s, scratch, spdcam};
use std::path::Path;

/// The example photo the README's first command estimates, and its true SPD beside it.
const EXAMPLE: &str = "../../examples/sg-telelumen.jpg";

/// The number after `key` in `text`.
fn number_after(text: &str, key: &str) -> f64 {
    let at = text
        .find(key)
        .unwrap_or_else(|| panic!("no '{key}' in:\n{text}"))
        + key.len();
    text[at..]
        .trim_start()
        .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
        .next()
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no number after '{key}' in:\n{text}"))
}

#[test]
fn the_example_photo_is_estimated_with_the_shipped_model() {
    let dir = scratch("example");
    let csv = dir.join("spd.csv");
    let plot = dir.join("spd.svg");
    let debug = dir.join("debug.png");
    let out = ok(&[
        "estimate",
        EXAMPLE,
        "-o",
        &s(&csv),
        "--plot",
        &s(&plot),
        "--debug",
        &s(&debug),
    ]);
    assert!(out.contains("ColorChecker Digital SG detected"), "{out}");
    assert!(
        out.contains("the shipped ColorChecker Digital SG model"),
        "{out}"
    );
    // One name for one chart: no identifier of the chart in what a person reads.
    assert!(
        !out.contains("colorchecker_sg96") && !out.contains("colorchecker_sg140"),
        "{out}"
    );
    // The glossary is printed on request only.
    assert!(!out.contains("GFC: goodness-of-fit"), "{out}");
    assert!(out.contains("--explain"), "{out}");
    let explained = ok(&["estimate", EXAMPLE, "--explain"]);
    assert!(
        explained.contains("GFC: goodness-of-fit"),
        "--explain explains GFC:\n{explained}"
    );
    // The lighting-quality line and its legend. This purple LED mix is far from white
    // (|Duv| ≈ 0.1): CRI and TM-30 are not meaningful and shown as "—", as the report does;
    // the circadian and plant numbers are, PPF per 1000 lx. A meter leads with its
    // complementary or dominant wavelength.
    assert!(
        out.contains(" wavelength ") && out.contains("Excitation purity"),
        "{out}"
    );
    assert!(
        out.contains("  Ra —, R9 —, Rf —, Rg —, Qa —, M-EDER ")
            && out.contains("PPF ")
            && out.contains("µmol s⁻¹ m⁻² per 1000 lx"),
        "{out}"
    );
    // The truth file beside the photo is found and scored.
    let gfc = number_after(&out, "against the true SPD: GFC");
    assert!(gfc > 0.9 && gfc <= 1.0, "GFC {gfc}:\n{out}");
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(
        text.starts_with("wavelength_nm,sg-telelumen.jpg,sg-telelumen.jpg_lower68,sg-telelumen.jpg_upper68,sg-telelumen.jpg_lower95,sg-telelumen.jpg_upper95\n400,"),
        "{text}"
    );
    assert_eq!(text.lines().count(), 62);
    let svg = std::fs::read_to_string(&plot).unwrap();
    assert!(svg.contains("<svg") && svg.contains("xy ("));
    let overlay = image::open(&debug).unwrap();
    assert_eq!((overlay.width(), overlay.height()), (2000, 1500));

    // JSON: the SPD, colorimetry, score and the photo's analysis.
    let json: serde_json::Value = serde_json::from_str(&ok(&["estimate", EXAMPLE, "--json"]))
        .expect("--json prints JSON alone");
    let item = &json[0];
    assert_eq!(item["spd"].as_array().unwrap().len(), 61);
    assert_eq!(item["wavelength_nm"][0].as_f64(), Some(400.0));
    assert!((item["truth"]["gfc"].as_f64().unwrap() - gfc).abs() < 1e-4);
    assert!(item["photo"]["confidence"].as_f64().unwrap() > 0.8);
    assert_eq!(item["photo"]["features"].as_array().unwrap().len(), 288);
    assert_eq!(item["photo"]["patches"].as_array().unwrap().len(), 140);
    let xy = item["colorimetry"]["xy"].as_array().unwrap();
    assert!(xy.iter().all(|v| (0.0..1.0).contains(&v.as_f64().unwrap())));
    // Lighting-quality metrics of the estimated SPD: every key, the chromaticity of the
    // colorimetry (1 nm resampling moves it a little), and the caveat of the 400–700 nm range.
    let m = &item["metrics"];
    for key in [
        "cct_k", "duv", "cri_ra", "cri_r", "tm30_rf", "tm30_rg", "mel_der", "sp_ratio",
    ] {
        assert!(
            m[key].is_number() || m[key].is_array(),
            "metrics.{key} = {}",
            m[key]
        );
    }
    for (a, b) in m["xy"]
        .as_array()
        .unwrap()
        .iter()
        .zip(item["colorimetry"]["xy"].as_array().unwrap())
    {
        assert!(
            (a.as_f64().unwrap() - b.as_f64().unwrap()).abs() < 2e-3,
            "{m}"
        );
    }
    assert!(
        m["warnings"][0].as_str().unwrap().contains("400–700 nm"),
        "{m}"
    );

    // An explicit truth file that does not match the photo scores worse.
    let flat = dir.join("flat.csv");
    let mut text = String::from("wavelength_nm,equal energy\n");
    for w in (380..=780).step_by(5) {
        text.push_str(&format!("{w},1\n"));
    }
    std::fs::write(&flat, text).unwrap();
    let out = ok(&["estimate", EXAMPLE, "--truth", &s(&flat)]);
    assert!(
        number_after(&out, "against the true SPD: GFC") < gfc,
        "{out}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_kind_of_light_can_be_named() {
    let told = ok(&["estimate", EXAMPLE, "--light", "luminaire", "--json"]);
    let told: serde_json::Value = serde_json::from_str(&told).unwrap();
    assert_eq!(told[0]["light"], "luminaire", "{told}");
    let plain = ok(&["estimate", EXAMPLE, "--json"]);
    let plain: serde_json::Value = serde_json::from_str(&plain).unwrap();
    assert!(plain[0].get("light").is_none());
    assert_ne!(told[0]["spd"], plain[0]["spd"]);
    // Told the wrong kind, the estimate says the photo does not look like it.
    let wrong = ok(&["estimate", EXAMPLE, "--light", "daylight"]);
    assert!(wrong.contains("told the light is daylight"), "{wrong}");
    assert!(wrong.contains("does not look like daylight"), "{wrong}");
    let err = fails(&["estimate", EXAMPLE, "--light", "candle"]);
    assert!(
        err.contains("'candle' is not a kind of light") && err.contains("white-led"),
        "{err}"
    );
    let list = ok(&["light-kinds", "list"]);
    for kind in spdcam_core::light_families::LightKind::ALL {
        assert!(list.contains(kind.name()), "{list}");
    }
}

#[test]
fn a_colorchecker24_photo_is_estimated_with_its_own_model() {
    let dir = scratch("cc24");
    let photo = dir.join("cc24.jpg");
    let truth = dir.join("truth.csv");
    ok(&[
        "render",
        "--spd",
        "A",
        "--scene",
        "1200x900",
        "-o",
        &s(&photo),
        "--spd-out",
        &s(&truth),
    ]);
    // No options: the chart is detected and the ColorChecker 24 model chosen.
    let csv = dir.join("spd.csv");
    let out = ok(&[
        "estimate",
        &s(&photo),
        "--truth",
        &s(&truth),
        "-o",
        &s(&csv),
    ]);
    assert!(out.contains("ColorChecker 24 detected"), "{out}");
    assert!(out.contains("the shipped ColorChecker 24 model"), "{out}");
    let gfc = number_after(&out, "against the true SPD: GFC");
    assert!(gfc > 0.95, "CIE A through the CC24 model: GFC {gfc}\n{out}");
    // A clean rendered photo: trusted, with its expected GFC and band.
    assert!(out.contains("verdict: ok"), "{out}");
    let expected = number_after(&out, "expected GFC");
    assert!((0.9..=1.0).contains(&expected), "{out}");
    assert!(out.contains("95 % band"), "{out}");
    // The metrics with their calibrated 95 % intervals, or the words that say the interval
    // is too wide for a number.
    assert!(out.contains(", Δuv ") && out.contains("CCT "), "{out}");
    let cct_line = out.lines().find(|l| l.contains("CCT ")).unwrap();
    assert!(
        cct_line.contains(" K ± ")
            || cct_line.contains(" ± ")
            || cct_line.contains("CCT not determinable from this photo"),
        "CCT with its interval: {cct_line}"
    );
    let line = out.lines().find(|l| l.contains("Ra ")).unwrap();
    let (ra, rest) = line.split_once("Ra ").unwrap().1.split_once(" ± ").unwrap();
    assert!(ra.parse::<f64>().is_ok(), "{line}");
    assert!(number_after(rest, "") > 0.0, "{line}");
    assert!(std::fs::read_to_string(&csv).unwrap().starts_with(
        "wavelength_nm,cc24.jpg,cc24.jpg_lower68,cc24.jpg_upper68,cc24.jpg_lower95,cc24.jpg_upper95\n"
    ));
    let json: serde_json::Value =
        serde_json::from_str(&ok(&["estimate", &s(&photo), "--json"])).unwrap();
    let e = &json[0];
    assert_eq!(e["verdict"], "ok", "{}", e["reasons"]);
    let spd = e["spd"].as_array().unwrap();
    for band in ["band68", "band95"] {
        let lower = e[band]["lower"].as_array().unwrap();
        let upper = e[band]["upper"].as_array().unwrap();
        assert_eq!((lower.len(), upper.len()), (spd.len(), spd.len()));
        for ((l, u), v) in lower.iter().zip(upper).zip(spd) {
            let (l, u, v) = (
                l.as_f64().unwrap(),
                u.as_f64().unwrap(),
                v.as_f64().unwrap(),
            );
            assert!(l <= v + 1e-9 && v <= u + 1e-9, "{band}: {l} {v} {u}");
        }
    }
    // Every single-number metric the estimate defines has an interval, 68 % inside 95 %.
    let intervals = &e["metric_uncertainty"];
    for key in [
        "cct_k", "duv", "cri_ra", "cri_r9", "tm30_rf", "mel_der", "sp_ratio",
    ] {
        let (h68, h95) = (
            intervals[key]["half68"].as_f64().unwrap(),
            intervals[key]["half95"].as_f64().unwrap(),
        );
        assert!(0.0 < h68 && h68 <= h95, "{key}: {intervals}");
    }
    let check = &e["self_check"];
    assert!(check["mean"].as_f64().unwrap() < 0.1, "{check}");
    assert_eq!(check["worst_patches"].as_array().unwrap().len(), 3);

    // Features are written for any chart; with a model for another chart there is no
    // estimate, and the run says so and fails, leaving no SPD file.
    let features = dir.join("f.csv");
    let never = dir.join("never.csv");
    let err = fails(&[
        "estimate",
        &s(&photo),
        "--chart",
        "colorchecker24",
        "--model",
        "../../models/colorchecker_sg96.spdm",
        "--features-out",
        &s(&features),
        "-o",
        &s(&never),
    ]);
    assert!(err.contains("no model for chart ColorChecker 24"), "{err}");
    assert!(!never.exists(), "no SPD file without an estimate");
    let text = std::fs::read_to_string(&features).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header.len(), 72);
    assert_eq!((header[0], header[71]), ("p01_r", "p24_b"));
    let row: Vec<f64> = lines
        .next()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    // Patch 19 (white) is the lightest of the neutral row in every channel, and near
    // neutral: the camera balances the whole scene, so the chart's white keeps only a
    // slight cast.
    let white = &row[54..57];
    assert!(white.iter().all(|&v| v > 150.0), "{white:?}");
    for grey in 20..24 {
        let g = &row[3 * (grey - 1)..3 * grey];
        assert!((0..3).all(|c| white[c] > g[c]), "{white:?} {g:?}");
    }
    let (lo, hi) = (
        white.iter().fold(255.0f64, |m, &v| m.min(v)),
        white.iter().fold(0.0f64, |m, &v| m.max(v)),
    );
    assert!(lo > 0.75 * hi, "{white:?}");

    // Feature rows are matched to the model for their columns (JSON Lines: a row a line).
    let out = ok(&["estimate", "--features", &s(&features), "--json"]);
    let json: serde_json::Value = serde_json::from_str(out.lines().next().unwrap()).unwrap();
    assert_eq!(json["model"], "the shipped ColorChecker 24 model");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_photos_give_clear_errors_and_no_output() {
    let dir = scratch("bad");
    let csv = dir.join("out.csv");
    let text = dir.join("notes.jpg");
    std::fs::write(&text, "not a photo").unwrap();
    let err = fails(&["estimate", &s(&text), "-o", &s(&csv)]);
    assert!(err.contains("notes.jpg"), "{err}");

    let bytes = std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join(EXAMPLE)).unwrap();
    let truncated = dir.join("truncated.jpg");
    std::fs::write(&truncated, &bytes[..bytes.len() / 3]).unwrap();
    let err = fails(&["estimate", &s(&truncated), "-o", &s(&csv)]);
    assert!(err.contains("truncated.jpg"), "{err}");

    let err = fails(&["estimate", &s(&dir.join("missing.jpg")), "-o", &s(&csv)]);
    assert!(err.contains("missing.jpg"), "{err}");
    // Issue 55: "No such file or directory (os error 2)"; now what to do, the photo named
    // once and called unusable.
    assert!(
        err.contains("unusable photo: no such file or folder: check the path"),
        "{err}"
    );
    assert_eq!(err.matches("missing.jpg").count(), 1, "{err}");

    let err = fails(&[
        "estimate",
        EXAMPLE,
        "--corners",
        "0,0,10,0,10,10,0,10,5",
        "-o",
        &s(&csv),
    ]);
    assert!(err.contains("eight numbers"), "{err}");
    let err = fails(&[
        "estimate",
        EXAMPLE,
        "--corners",
        "-50,-50,5000,0,5000,4000,0,4000",
        "-o",
        &s(&csv),
    ]);
    assert!(err.contains("outside"), "{err}");

    let err = fails(&["estimate", EXAMPLE, "--features", &s(&text)]);
    assert!(err.contains("cannot be used with"), "{err}");
    let err = fails(&["estimate", EXAMPLE, "--model", &s(&text)]);
    assert!(err.contains("not a spdcam model"), "{err}");
    assert!(!csv.exists(), "no partial output");

    // One bad photo in a batch: the others are still estimated, the bad one is named, and
    // the run fails.
    let out = spdcam(&["estimate", EXAMPLE, &s(&text), "-o", &s(&csv)]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("notes.jpg") && stderr.contains("1 of 2 photo(s)"),
        "{stderr}"
    );
    let written = std::fs::read_to_string(&csv).unwrap();
    assert!(
        written.starts_with("wavelength_nm,sg-telelumen.jpg,sg-telelumen.jpg_lower68,"),
        "{written}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[cfg(feature = "measured-data")]
#[test]
fn a_chart_image_from_render_is_estimated() {
    let dir = scratch("render");
    let data = s(&common::data_dir());
    let chart = dir.join("chart.png");
    let truth = dir.join("chart.truth.csv");
    ok(&[
        "--data-dir",
        &data,
        "render",
        "--chart",
        "colorchecker_sg96",
        "--camera",
        "canon_eos_5d_mark_ii_mod_bw486",
        "--spd",
        "D65",
        "--border-px",
        "24",
        "-o",
        &s(&chart),
        "--spd-out",
        &s(&truth),
    ]);
    // The chart with a margin around it, as a photo shows it (detection looks for a chart
    // inside the photo, not for one that is the whole image), found among every chart.
    let out = ok(&["--data-dir", &data, "estimate", &s(&chart)]);
    assert!(out.contains("ColorChecker Digital SG detected"), "{out}");
    let gfc = number_after(&out, "against the true SPD: GFC");
    assert!(gfc > 0.99, "GFC {gfc}:\n{out}");
    // The text withholds a CCT whose interval is too wide; the JSON has every number.
    let json = ok(&["--data-dir", &data, "estimate", &s(&chart), "--json"]);
    let parsed: serde_json::Value = serde_json::from_str(&json).unwrap();
    let cct = parsed[0]["metrics"]["cct_k"].as_f64().unwrap();
    assert!((5800.0..7200.0).contains(&cct), "CCT {cct}:\n{json}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Cells of a CSV file, line by line.
fn csv_cells(path: &Path) -> Vec<Vec<String>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| l.split(',').map(String::from).collect())
        .collect()
}

/// Many feature rows: streamed, laid out long above 256 rows (or as asked), the same
/// numbers as the wide layout, in row order; colorimetry only for what is printed.
#[test]
fn many_feature_rows_stream_to_the_long_layout() {
    let dir = scratch("long");
    let one = dir.join("one.csv");
    ok(&["estimate", EXAMPLE, "--features-out", &s(&one)]);
    let text = std::fs::read_to_string(&one).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let row: Vec<f64> = lines
        .next()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    let many = dir.join("many.csv");
    let mut body = format!("{header}\n");
    for r in 0..300 {
        let scaled: Vec<String> = row
            .iter()
            .map(|v| format!("{:.3}", v * (0.8 + 0.001 * r as f64)))
            .collect();
        body.push_str(&scaled.join(","));
        body.push_str(if r == 150 { "\r\n\n" } else { "\n" });
    }
    std::fs::write(&many, body).unwrap();

    let (long, wide) = (dir.join("long.csv"), dir.join("wide.csv"));
    let out = ok(&["estimate", "--features", &s(&many), "-o", &s(&long)]);
    assert!(out.starts_with("300 estimates with"), "{out}");
    assert!(
        !out.contains("CCT"),
        "no colorimetry for rows not printed: {out}"
    );
    assert!(out.contains("long layout"), "{out}");
    ok(&[
        "estimate",
        "--features",
        &s(&many),
        "-o",
        &s(&wide),
        "--layout",
        "wide",
    ]);
    let (long, wide) = (csv_cells(&long), csv_cells(&wide));
    assert_eq!(long.len(), 301);
    assert_eq!(long[0][0], "name");
    assert_eq!((long[0][1].as_str(), long[0][61].as_str()), ("400", "700"));
    assert_eq!(wide.len(), 62);
    assert_eq!(wide[0].len(), 301);
    for r in 0..300 {
        assert_eq!(long[r + 1][0], format!("estimate_{}", r + 1));
        assert_eq!(wide[0][r + 1], long[r + 1][0]);
        for k in 0..61 {
            assert_eq!(long[r + 1][k + 1], wide[k + 1][r + 1], "row {r}, band {k}");
        }
    }

    // A few rows: wide by default, printed in full; --layout long writes them long.
    let few = dir.join("few.csv");
    let text = std::fs::read_to_string(&many).unwrap();
    std::fs::write(&few, text.lines().take(4).collect::<Vec<_>>().join("\n")).unwrap();
    let small = dir.join("small.csv");
    let out = ok(&["estimate", "--features", &s(&few), "-o", &s(&small)]);
    let printed = out.lines().filter(|l| l.starts_with("estimate_")).count();
    assert_eq!(printed, 3, "{out}");
    assert!(std::fs::read_to_string(&small)
        .unwrap()
        .starts_with("wavelength_nm,estimate_1,estimate_2,estimate_3\n"));
    ok(&[
        "estimate",
        "--features",
        &s(&few),
        "-o",
        &s(&small),
        "--layout",
        "long",
    ]);
    assert_eq!(csv_cells(&small).len(), 4);
    let err = fails(&["estimate", EXAMPLE, "-o", &s(&small), "--layout", "long"]);
    assert!(err.contains("--layout long is for --features"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A scene photo of another chart that the detector takes for a ColorChecker 24 (its grey
/// row in place, the other 18 patches in another order): its patches are not the
/// ColorChecker 24's (issue 41), so it is refused with what to do and no number, and a batch
/// goes on with the next photo.
#[test]
fn a_photo_of_another_chart_is_refused_and_the_batch_goes_on() {
    let dir = scratch("wrong-chart");
    let table = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/colorchecker24.csv"),
    )
    .unwrap();
    let order = [
        8, 3, 6, 5, 15, 16, 2, 12, 0, 1, 13, 10, 17, 9, 14, 11, 4, 7, 18, 19, 20, 21, 22, 23,
    ];
    let shuffled: String = table
        .lines()
        .map(|line| {
            let cells: Vec<&str> = line.split(',').collect();
            let mut out = vec![cells[0]];
            out.extend(order.iter().map(|&p| cells[1 + p]));
            out.join(",") + "\n"
        })
        .collect();
    let chart = dir.join("other.csv");
    std::fs::write(&chart, shuffled).unwrap();
    let photo = dir.join("other.jpg");
    ok(&[
        "render",
        "--spd",
        "A",
        "--chart",
        &s(&chart),
        "--layout",
        "4x6",
        "--scene",
        "1200x900",
        "-o",
        &s(&photo),
    ]);
    let out = spdcam(&["estimate", &s(&photo), EXAMPLE]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("other.jpg: unusable photo: what was found is not a ColorChecker 24: show where the chart is by its four outer corners (")
            && stderr.contains("give its corners with --corners")
            && stderr.contains("1 of 2 photo(s)"),
        "{stderr}"
    );
    // The next photo is estimated; the refused one printed nothing.
    assert!(stdout.contains("sg-telelumen.jpg"), "{stdout}");
    assert!(!stdout.contains("other.jpg"), "{stdout}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A chart lit half by daylight and half by a bulb, each half exposed and white-balanced for
/// its own light (every grey patch stays grey): the reasons name two lights; the same scene
/// under daylight alone does not.
#[test]
fn a_chart_lit_by_two_lights_each_half_balanced_is_named_so() {
    let dir = scratch("two-lights");
    let second: [&[&str]; 2] = [&[], &["--right-light", "A", "--balance-halves"]];
    for (lights, extra) in second.iter().enumerate() {
        let photo = dir.join(format!("lights-{lights}.jpg"));
        let mut args = vec![
            "render", "--spd", "D65", "--scene", "1200x900", "--seed", "2", "-o",
        ];
        let shown = s(&photo);
        args.push(&shown);
        args.extend_from_slice(extra);
        ok(&args);
        let json: serde_json::Value =
            serde_json::from_str(&ok(&["estimate", &s(&photo), "--json"])).unwrap();
        let names_two = json[0]["reasons"]
            .as_array()
            .unwrap()
            .iter()
            .any(|r| r.as_str().unwrap().contains("two different lights"));
        assert_eq!(names_two, lights == 1, "{}", json[0]["reasons"]);
        assert!(json[0]["self_check"]["two_lights"].as_f64().is_some());
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `jpeg` with an EXIF segment (APP1, CIPA DC-008) right after its start-of-image marker
/// giving aperture `f_number`, exposure time 1/`per_second` s and `iso`.
fn with_exif(jpeg: &[u8], f_number: u32, per_second: u32, iso: u16) -> Vec<u8> {
    use exif::experimental::Writer;
    use exif::{Field, In, Rational, Tag, Value};
    let fields = [
        (
            Tag::FNumber,
            Value::Rational(vec![Rational {
                num: f_number,
                denom: 1,
            }]),
        ),
        (
            Tag::ExposureTime,
            Value::Rational(vec![Rational {
                num: 1,
                denom: per_second,
            }]),
        ),
        (Tag::PhotographicSensitivity, Value::Short(vec![iso])),
    ]
    .map(|(tag, value)| Field {
        tag,
        ifd_num: In::PRIMARY,
        value,
    });
    let mut writer = Writer::new();
    for f in &fields {
        writer.push_field(f);
    }
    let mut tiff = std::io::Cursor::new(Vec::new());
    writer.write(&mut tiff, false).unwrap();
    let tiff = tiff.into_inner();
    let mut out = jpeg[..2].to_vec();
    out.extend_from_slice(&[0xFF, 0xE1]);
    out.extend_from_slice(&u16::try_from(2 + 6 + tiff.len()).unwrap().to_be_bytes());
    out.extend_from_slice(b"Exif\0\0");
    out.extend_from_slice(&tiff);
    out.extend_from_slice(&jpeg[2..]);
    out
}

#[test]
fn the_exif_exposure_gives_approximate_absolute_levels() {
    let dir = scratch("exif");
    let plain = dir.join("plain.jpg");
    ok(&[
        "render",
        "--spd",
        "D50",
        "--scene",
        "1200x900",
        "-o",
        &s(&plain),
    ]);
    let bytes = std::fs::read(&plain).unwrap();
    let json = |name: &str, f: u32, per_second: u32, iso: u16| -> serde_json::Value {
        let path = dir.join(name);
        std::fs::write(&path, with_exif(&bytes, f, per_second, iso)).unwrap();
        let v: serde_json::Value =
            serde_json::from_str(&ok(&["estimate", &s(&path), "--json"])).unwrap();
        v[0].clone()
    };
    let e = json("f4.jpg", 4, 100, 100);
    assert_eq!(e["photo"]["exposure"]["iso"], 100.0, "{}", e["photo"]);
    let a = &e["absolute"];
    let lux = a["illuminance_lux"]
        .as_f64()
        .unwrap_or_else(|| panic!("{e}"));
    // Each neutral patch used: its luminance from the exposure (ISO 12232 SOS, q = 0.65)
    // equals the illuminance times its luminance factor / π. The factors of the ColorChecker
    // 24's neutrals (white … black) from X-Rite's published CIELAB L* (D50, charts made
    // after November 2014) agree with the chart's spectra to a few per cent.
    let published_y =
        [96.54f64, 81.26, 66.77, 50.87, 35.66, 20.46].map(|l| ((l + 16.0) / 116.0).powi(3));
    let patches = a["patches"].as_array().unwrap();
    assert!(!patches.is_empty(), "{a}");
    for p in patches {
        let feature = p[0].as_u64().unwrap() as usize;
        assert!((19..=24).contains(&feature), "a neutral patch: {feature}");
        let rgb: Vec<f64> = (0..3)
            .map(|c| {
                e["photo"]["features"][3 * (feature - 1) + c]
                    .as_f64()
                    .unwrap()
                    / 255.0
            })
            .collect();
        let decode = |v: f64| {
            if v <= 0.04045 {
                v / 12.92
            } else {
                ((v + 0.055) / 1.055).powf(2.4)
            }
        };
        let y = 0.2126 * decode(rgb[0]) + 0.7152 * decode(rgb[1]) + 0.0722 * decode(rgb[2]);
        let luminance = (y / 0.18) * (10.0 / 100.0) * 16.0 / (0.65 * 0.01);
        let from_patch = p[1].as_f64().unwrap() * published_y[feature - 19] / std::f64::consts::PI;
        assert!(
            (from_patch / luminance - 1.0).abs() < 0.08,
            "patch {feature}: {from_patch} vs {luminance} cd/m²"
        );
    }
    // PPFD and melanopic EDI scale the illuminance by the estimate's own ratios.
    let m = &e["metrics"];
    let close = |a: f64, b: f64| (a / b - 1.0).abs() < 1e-9;
    assert!(close(
        a["ppfd_umol_m2_s"].as_f64().unwrap(),
        lux * m["ppf_per_lux"].as_f64().unwrap()
    ));
    assert!(close(
        a["melanopic_edi_lux"].as_f64().unwrap(),
        lux * m["mel_der"].as_f64().unwrap()
    ));
    assert!(a["note"].as_str().unwrap().starts_with("approximate"));
    // The same pixels taken with twice the time, or one stop more open, saw half the light.
    let slower = json("slower.jpg", 4, 50, 100)["absolute"]["illuminance_lux"]
        .as_f64()
        .unwrap();
    assert!(close(slower, lux / 2.0), "{slower} vs {lux}");
    let wider = json("iso.jpg", 4, 100, 200)["absolute"]["illuminance_lux"]
        .as_f64()
        .unwrap();
    assert!(close(wider, lux / 2.0), "{wider} vs {lux}");
    // Text output names the exposure; a photo without EXIF has none and says nothing.
    let text = ok(&["estimate", &s(&dir.join("f4.jpg"))]);
    assert!(
        text.contains("absolute (approximate, from f/4, 1/100 s, ISO 100):"),
        "{text}"
    );
    let plain_json: serde_json::Value =
        serde_json::from_str(&ok(&["estimate", &s(&plain), "--json"])).unwrap();
    assert!(plain_json[0]["absolute"].is_null());
    assert!(plain_json[0]["absolute_reason"]
        .as_str()
        .unwrap()
        .contains("EXIF"));
    assert!(!ok(&["estimate", &s(&plain)]).contains("absolute"));
}

#[test]
fn help_lines_fit_a_terminal() {
    // Issue 55: `estimate --help` had lines of up to 374 characters.
    for command in [
        &["estimate", "--help"][..],
        &["render", "--help"],
        &["--help"],
    ] {
        let help = ok(command);
        let longest = help.lines().map(|l| l.chars().count()).max().unwrap();
        assert!(
            longest <= 100,
            "{command:?}: a line of {longest} characters"
        );
    }
}

#[test]
fn corners_in_any_order_give_the_same_estimate() {
    // Issue 55: corners given in a crossed (bow-tie) order were refused. Every order of the
    // example's four corners (the README: "any order") finds the same chart and light.
    let photo = "../../examples/cc24-led.jpg";
    let corners = [[1644, 791], [889, 1187], [752, 717], [1380, 405]];
    let mut xy = Vec::new();
    for order in [
        [0, 1, 2, 3],
        [0, 2, 1, 3],
        [0, 1, 3, 2],
        [2, 0, 3, 1],
        [3, 1, 0, 2],
    ] {
        let text = order
            .iter()
            .map(|&k| format!("{},{}", corners[k][0], corners[k][1]))
            .collect::<Vec<_>>()
            .join(",");
        let out = ok(&["estimate", photo, "--corners", &text, "--json"]);
        let json: serde_json::Value = serde_json::from_str(&out).unwrap();
        assert_eq!(json[0]["verdict"], "ok", "{order:?}");
        xy.push(json[0]["colorimetry"]["xy"].to_string());
    }
    assert!(xy.windows(2).all(|w| w[0] == w[1]), "{xy:?}");
}

#[test]
fn a_photo_with_nearly_black_patches_is_never_ok_nor_well_exposed() {
    // Issue 53: the example darkened to 6 % of its brightness warned "nearly black … expose
    // more" and, beside it, said "verdict: ok" and "its patches are well exposed".
    use spdcam_core::colorimetry::{srgb_decode, srgb_encode};
    let dir = scratch("dark");
    let photo = image::open("../../examples/cc24-led.jpg")
        .unwrap()
        .to_rgb8();
    let mut dark = photo.clone();
    for p in dark.pixels_mut() {
        for v in &mut p.0 {
            let linear = srgb_decode(f64::from(*v) / 255.0) * 0.06;
            *v = (srgb_encode(linear) * 255.0).round() as u8;
        }
    }
    let path = dir.join("dark.png");
    dark.save(&path).unwrap();
    let report = dir.join("dark.html");
    let out = ok(&["estimate", &s(&path), "--report", &s(&report)]);
    assert!(out.contains("nearly black"), "{out}");
    assert!(out.contains("verdict: doubtful"), "{out}");
    let page = std::fs::read_to_string(&report).unwrap();
    assert!(
        !page.contains("well exposed"),
        "the report says well exposed"
    );
    // The example as it is: ok, and the same words never claim what was not checked.
    let out = ok(&["estimate", "../../examples/cc24-led.jpg"]);
    assert!(out.contains("verdict: ok"), "{out}");
    // With the glare read on its darkest patches (the ColorChecker 24 has two: black and
    // blue), in words and in the JSON.
    assert!(out.contains("Glare on the chart: none seen"), "{out}");
    let json: serde_json::Value =
        serde_json::from_str(&ok(&["estimate", "../../examples/cc24-led.jpg", "--json"])).unwrap();
    let veil = &json[0]["self_check"]["veil"];
    assert_eq!(veil["patches"], 2, "{veil}");
    assert!(veil["share"].as_f64().unwrap().abs() < 0.2, "{veil}");
}
