//! One self-contained HTML page of estimates (`spdcam estimate --report`): for each, the
//! photo with the chart found, the SPD plot, colorimetry, every lighting metric, the TM-30
//! colour vector graphic, the detection and the score against a truth, and a details table.
//!
//! The page is driven by the estimate's JSON ([`crate::Estimate::to_json`]), not by the
//! Rust types, so that keys added to the JSON later are shown without changes here: the
//! keys this module knows get their own sections, every other value goes to the details
//! table. Everything is inline (CSS, SVG, the photo as a data URI): the page loads nothing.

use serde_json::{Map, Value};
use std::collections::BTreeSet;
use std::fmt::Write as _;

/// Widest photo embedded in a report, in pixels.
pub const REPORT_IMAGE_WIDTH: u32 = 1200;

/// An image embedded in a report as a data URI.
#[derive(Debug, Clone, PartialEq)]
pub struct ReportImage {
    /// Its media type, e.g. `image/jpeg`.
    pub mime: &'static str,
    /// The encoded image.
    pub bytes: Vec<u8>,
}

/// One estimate of a report.
#[derive(Debug, Clone, PartialEq)]
pub struct ReportItem {
    /// The estimate as JSON (`Estimate::to_json`), with whatever keys it has.
    pub estimate: Value,
    /// The photo with the chart's outline and sampled patches, for estimates of photos.
    pub image: Option<ReportImage>,
    /// The true SPD on the estimate's wavelengths, when known (any scale).
    pub truth_spd: Option<Vec<f64>>,
}

/// Keys of the estimate's JSON shown in their own sections (dotted paths); the details
/// table shows every other value.
const SHOWN: [&str; 20] = [
    "name",
    "model",
    "wavelength_nm",
    "spd",
    "colorimetry",
    "metrics",
    "metric_uncertainty",
    "truth",
    "verdict",
    "reasons",
    "photo.source",
    "photo.width",
    "photo.height",
    "photo.method",
    "photo.chart",
    "photo.confidence",
    "photo.corners",
    "photo.patches",
    "photo.warnings",
    "photo.features_by_name",
];

/// Arrays longer than this are summarised in the details table, not listed.
const LISTED_MAX: usize = 16;

/// The colours of the TM-30 hue bins 1–16 (as the standard's graphics draw them).
const BIN_COLOURS: [&str; 16] = [
    "#e62828", "#e74b4b", "#fb812e", "#ffb529", "#cbca46", "#7eb94c", "#41c06d", "#009c7c",
    "#16bcb0", "#00a4bf", "#0085c3", "#3b62aa", "#4568ae", "#6a4e85", "#9d69a1", "#a74f81",
];

const STYLE: &str = "body{font:13px/1.35 system-ui,sans-serif;color:#1d2330;max-width:1200px;\
margin:16px auto;padding:0 12px}h1{font-size:20px}h2{font-size:17px;margin:4px 0 8px}\
h3{font-size:14px;margin:12px 0 4px}section{border-top:2px solid #1d2330;padding-top:8px;\
margin-bottom:24px}.grid{display:grid;grid-template-columns:minmax(0,1fr) minmax(0,1fr);gap:12px;align-items:start}\
figure{margin:0}figcaption{font-size:11px;color:#555}img.photo{max-width:100%;height:auto;\
display:block}svg{width:100%;height:auto;display:block}svg.tm30-cvg{max-width:340px}table{border-collapse:collapse;\
margin-bottom:6px}th,td{text-align:left;padding:1px 8px 1px 0;border-bottom:1px solid #ddd;\
vertical-align:top}td.num{font-variant-numeric:tabular-nums}.cri-r,.tm30-bins{font-size:11px}\
.cri-r th,.cri-r td,.tm30-bins th,.tm30-bins td{padding:1px 3px 1px 0}.undefined{color:#777}\
.verdict{font-size:16px;font-weight:600;border:2px solid #1d2330;background:#f3f1e8;\
padding:8px 12px;margin:6px 0}.warnings li{color:#8a5a00}.small{font-size:11px;color:#555}\
@media print{body{margin:0;max-width:none;font-size:8pt}h3{margin:4px 0 2px}\
img.photo{max-height:70mm;width:auto}svg.tm30-cvg{max-width:60mm}.tm30-bins,.small{font-size:7pt}section{break-after:page;\
border:none}section:last-of-type{break-after:auto}.details{font-size:8pt}}";

/// The HTML page of `items` under the heading `title`.
pub fn report_html(title: &str, items: &[ReportItem]) -> String {
    let mut out = String::new();
    let _ = write!(
        out,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <meta name=\"viewport\" content=\"width=device-width,initial-scale=1\">\
         <title>{t}</title><style>{STYLE}</style></head>\n<body>\n<h1>{t}</h1>\n",
        t = esc(title)
    );
    for (i, item) in items.iter().enumerate() {
        section(&mut out, i + 1, item);
    }
    out.push_str(
        "<p class=\"small\">Made by spdcam. The SPD is relative (peak 1) and estimated on its \
         wavelength range only; the metrics are computed on that range.</p>\n</body></html>\n",
    );
    out
}

/// One estimate's section.
fn section(out: &mut String, index: usize, item: &ReportItem) {
    let e = &item.estimate;
    let name = e["name"]
        .as_str()
        .map_or_else(|| format!("estimate {index}"), str::to_string);
    let _ = write!(
        out,
        "<section class=\"estimate\" id=\"estimate-{index}\">\n<h2>{}</h2>\n",
        esc(&name)
    );
    verdict(out, e);
    let mut shown: BTreeSet<String> = SHOWN.iter().map(|s| s.to_string()).collect();
    out.push_str("<div class=\"grid\">\n");
    match &item.image {
        Some(image) => {
            let _ = writeln!(
                out,
                "<figure><img class=\"photo\" alt=\"the photo with the chart found\" \
                 src=\"data:{};base64,{}\"><figcaption>The chart found (green outline, yellow: \
                 the corner of patch 1) and the squares sampled (white; red: clipped).\
                 </figcaption></figure>",
                image.mime,
                base64(&image.bytes)
            );
        }
        None => {
            out.push_str("<div class=\"small\">No photo: estimated from chart features.</div>\n")
        }
    }
    let bands = ["band95", "band68"].map(|k| band(e, k));
    for (key, band) in ["band95", "band68"].iter().zip(&bands) {
        if band.is_some() {
            shown.insert(key.to_string());
        }
    }
    let _ = writeln!(
        out,
        "<figure>{}<figcaption>The estimated SPD (relative, peak 1){}{}.</figcaption></figure>",
        spd_svg(e, item.truth_spd.as_deref(), &bands),
        if item.truth_spd.is_some() {
            ", the true SPD dashed (peak 1)"
        } else {
            ""
        },
        match (&bands[0], &bands[1]) {
            (Some(_), Some(_)) => ", the 68 % and 95 % uncertainty bands shaded",
            (Some(_), None) => ", the 95 % uncertainty band shaded",
            (None, Some(_)) => ", the 68 % uncertainty band shaded",
            (None, None) => "",
        }
    );
    out.push_str("</div>\n<div class=\"grid\">\n<div>\n<h3>Colour and source</h3>\n");
    summary_table(out, e);
    tm30(out, &e["metrics"]);
    out.push_str("</div>\n<div>\n");
    metrics_tables(out, &e["metrics"], &e["metric_uncertainty"]);
    warnings(out, e);
    let mut rows = Vec::new();
    details(e, "", &shown, &mut rows);
    if !rows.is_empty() {
        out.push_str(
            "<h3>Details</h3>\n<table class=\"details\"><tr><th>key</th><th>value</th></tr>\n",
        );
        for (key, value) in rows {
            let _ = writeln!(
                out,
                "<tr data-key=\"{k}\"><th>{k}</th><td class=\"num\">{}</td></tr>",
                esc(&value),
                k = esc(&key)
            );
        }
        out.push_str("</table>\n");
    }
    out.push_str("</div>\n</div>\n</section>\n");
}

/// The verdict at the top of the section, with its reasons, when the estimate has one.
fn verdict(out: &mut String, e: &Value) {
    let text = match &e["verdict"] {
        Value::Null => None,
        Value::String(s) => Some(s.clone()),
        other => Some(scalar_or_json(other)),
    };
    if let Some(text) = text {
        let _ = writeln!(out, "<p class=\"verdict\">Verdict: {}</p>", esc(&text));
    }
    let reasons = strings(&e["reasons"]);
    if !reasons.is_empty() {
        out.push_str("<ul class=\"reasons\">");
        for r in reasons {
            let _ = write!(out, "<li>{}</li>", esc(&r));
        }
        out.push_str("</ul>\n");
    }
}

/// The strings of a JSON array (other values as JSON text).
fn strings(v: &Value) -> Vec<String> {
    v.as_array()
        .map(|a| a.iter().map(scalar_or_json).collect())
        .unwrap_or_default()
}

/// A string as it is, anything else as compact JSON.
fn scalar_or_json(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        Value::Number(_) => number(v),
        other => other.to_string(),
    }
}

/// The numbers of a JSON array, when every element is a finite number.
fn numbers(v: &Value) -> Option<Vec<f64>> {
    v.as_array()?
        .iter()
        .map(|x| x.as_f64().filter(|f| f.is_finite()))
        .collect()
}

/// `{lower, upper}` of the band `key`, when both have one value per wavelength.
fn band(e: &Value, key: &str) -> Option<(Vec<f64>, Vec<f64>)> {
    let n = e["wavelength_nm"].as_array()?.len();
    let lower = numbers(&e[key]["lower"])?;
    let upper = numbers(&e[key]["upper"])?;
    (lower.len() == n && upper.len() == n).then_some((lower, upper))
}

/// The SPD plot: the estimate, the truth (peak 1) when known, the bands when present.
fn spd_svg(e: &Value, truth: Option<&[f64]>, bands: &[Option<(Vec<f64>, Vec<f64>)>; 2]) -> String {
    let (Some(w), Some(spd)) = (numbers(&e["wavelength_nm"]), numbers(&e["spd"])) else {
        return "<p class=\"small\">No SPD to plot.</p>".into();
    };
    if w.len() < 2 || spd.len() != w.len() {
        return "<p class=\"small\">No SPD to plot.</p>".into();
    }
    let truth: Option<Vec<f64>> = truth.filter(|t| t.len() == w.len()).and_then(|t| {
        let peak = t.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (peak > 0.0).then(|| t.iter().map(|v| v / peak).collect())
    });
    let top = spd
        .iter()
        .chain(truth.iter().flatten())
        .chain(bands.iter().flatten().flat_map(|(_, u)| u))
        .copied()
        .fold(1.0_f64, f64::max);
    let y_max = (top * 1.05 * 4.0).ceil() / 4.0;
    let (w0, w1) = (w[0], w[w.len() - 1]);
    let (left, right, top_px, bottom) = (52.0, 624.0, 14.0, 326.0);
    let x = |v: f64| left + (v - w0) / (w1 - w0) * (right - left);
    let y = |v: f64| bottom - v.clamp(0.0, y_max) / y_max * (bottom - top_px);
    let mut s = String::new();
    let _ = write!(
        s,
        "<svg class=\"spd-plot\" viewBox=\"0 0 640 370\" \
         role=\"img\" aria-label=\"estimated SPD\" font-size=\"12\" font-family=\"sans-serif\">\
         <rect x=\"{left}\" y=\"{top_px}\" width=\"{}\" height=\"{}\" fill=\"#fff\" stroke=\"#888\"/>",
        right - left,
        bottom - top_px
    );
    let mut tick = (w0 / 50.0).ceil() * 50.0;
    while tick <= w1 + 1e-9 {
        let _ = write!(
            s,
            "<line x1=\"{0:.1}\" x2=\"{0:.1}\" y1=\"{top_px}\" y2=\"{bottom}\" stroke=\"#eee\"/>\
             <text x=\"{0:.1}\" y=\"{1}\" text-anchor=\"middle\">{tick:.0}</text>",
            x(tick),
            bottom + 16.0
        );
        tick += 50.0;
    }
    let mut level = 0.0;
    while level <= y_max + 1e-9 {
        let _ = write!(
            s,
            "<line x1=\"{left}\" x2=\"{right}\" y1=\"{0:.1}\" y2=\"{0:.1}\" stroke=\"#eee\"/>\
             <text x=\"{1}\" y=\"{2:.1}\" text-anchor=\"end\">{level:.2}</text>",
            y(level),
            left - 6.0,
            y(level) + 4.0
        );
        level += 0.25;
    }
    let _ = write!(
        s,
        "<text x=\"{:.1}\" y=\"362\" text-anchor=\"middle\">wavelength (nm)</text>\
         <text transform=\"translate(14 {:.1}) rotate(-90)\" text-anchor=\"middle\">relative power</text>",
        (left + right) / 2.0,
        (top_px + bottom) / 2.0
    );
    for ((lower, upper), (class, opacity)) in bands
        .iter()
        .zip([("band95", 0.18), ("band68", 0.32)])
        .filter_map(|(b, style)| b.as_ref().map(|b| (b, style)))
    {
        let mut points: Vec<String> = w
            .iter()
            .zip(upper)
            .map(|(&l, &v)| format!("{:.1},{:.1}", x(l), y(v)))
            .collect();
        points.extend(
            w.iter()
                .zip(lower)
                .rev()
                .map(|(&l, &v)| format!("{:.1},{:.1}", x(l), y(v))),
        );
        let _ = write!(
            s,
            "<polygon class=\"{class}\" points=\"{}\" fill=\"#1f5fbf\" fill-opacity=\"{opacity}\" \
             stroke=\"none\"/>",
            points.join(" ")
        );
    }
    let line = |values: &[f64]| {
        w.iter()
            .zip(values)
            .map(|(&l, &v)| format!("{:.1},{:.1}", x(l), y(v)))
            .collect::<Vec<_>>()
            .join(" ")
    };
    if let Some(t) = &truth {
        let _ = write!(
            s,
            "<polyline class=\"truth\" points=\"{}\" fill=\"none\" stroke=\"#222\" \
             stroke-width=\"1.5\" stroke-dasharray=\"6 4\"/>",
            line(t)
        );
    }
    let _ = write!(
        s,
        "<polyline class=\"spd\" points=\"{}\" fill=\"none\" stroke=\"#1f5fbf\" stroke-width=\"2.5\"/>",
        line(&spd)
    );
    let mut legend = vec![("estimate", "#1f5fbf", " stroke-width=\"2\"")];
    if truth.is_some() {
        legend.push((
            "true SPD",
            "#222",
            " stroke-width=\"2\" stroke-dasharray=\"6 4\"",
        ));
    }
    if bands[1].is_some() {
        legend.push((
            "68 % band",
            "#1f5fbf",
            " stroke-width=\"10\" stroke-opacity=\"0.32\"",
        ));
    }
    if bands[0].is_some() {
        legend.push((
            "95 % band",
            "#1f5fbf",
            " stroke-width=\"10\" stroke-opacity=\"0.18\"",
        ));
    }
    for (k, (label, colour, style)) in legend.iter().enumerate() {
        let ly = top_px + 14.0 + 16.0 * k as f64;
        let _ = write!(
            s,
            "<line x1=\"{0}\" x2=\"{1}\" y1=\"{ly}\" y2=\"{ly}\" stroke=\"{colour}\"{style}/>\
             <text x=\"{2}\" y=\"{3}\">{label}</text>",
            right - 120.0,
            right - 96.0,
            right - 90.0,
            ly + 4.0
        );
    }
    s.push_str("</svg>");
    s
}

/// Colorimetry, source and score: the numbers one reads first.
fn summary_table(out: &mut String, e: &Value) {
    let c = &e["colorimetry"];
    out.push_str("<table class=\"summary\">\n");
    if let Some(xy) = numbers(&c["xy"]).filter(|xy| xy.len() == 2) {
        row(
            out,
            "xy",
            "CIE 1931 x, y",
            &format!("{:.4}, {:.4}", xy[0], xy[1]),
        );
    }
    match (c["cct"].as_f64(), c["duv"].as_f64()) {
        (Some(cct), Some(duv)) => {
            row(out, "cct", "CCT", &format!("{cct:.0} K"));
            row(out, "duv", "Duv (CIE 1960 uv)", &format!("{duv:+.4}"));
        }
        _ => row(
            out,
            "cct",
            "CCT",
            "none: farther than |Duv| 0.05 from the Planckian locus",
        ),
    }
    let truth = &e["truth"];
    if let (Some(gfc), Some(rmse)) = (truth["gfc"].as_f64(), truth["rmse"].as_f64()) {
        row(out, "gfc", "GFC against the true SPD", &format!("{gfc:.4}"));
        row(
            out,
            "rmse",
            "RMSE against the true SPD (peak 1)",
            &format!("{rmse:.4}"),
        );
    }
    let p = &e["photo"];
    if p.is_object() {
        if let Some(conf) = p["confidence"].as_f64() {
            row(
                out,
                "confidence",
                "detection confidence (0–1)",
                &format!(
                    "{conf:.2}{}",
                    if conf < 0.8 {
                        " (low: check the photo)"
                    } else {
                        ""
                    }
                ),
            );
        }
        let method = match p["method"].as_str() {
            Some("corners") => "the corners given",
            Some("detected") => "detection",
            Some(other) => other,
            None => "—",
        };
        row(
            out,
            "chart",
            "chart",
            &format!("{} (found by {method})", p["chart"].as_str().unwrap_or("—")),
        );
        if let (Some(width), Some(height)) = (p["width"].as_u64(), p["height"].as_u64()) {
            row(
                out,
                "photo-size",
                "photo",
                &format!("{width} × {height} px"),
            );
        }
        if let Some(corners) = p["corners"].as_array() {
            let text: Vec<String> = corners
                .iter()
                .filter_map(numbers)
                .filter(|c| c.len() == 2)
                .map(|c| format!("({:.0}, {:.0})", c[0], c[1]))
                .collect();
            row(
                out,
                "corners",
                "chart corners (px; TL, TR, BR, BL)",
                &text.join(" "),
            );
        }
        if let Some(patches) = p["patches"].as_array() {
            let flagged = |flag: &str| -> Vec<String> {
                patches
                    .iter()
                    .filter(|q| q[flag].as_bool() == Some(true))
                    .filter_map(|q| q["patch"].as_u64().map(|n| (n + 1).to_string()))
                    .collect()
            };
            let list = |v: Vec<String>| {
                if v.is_empty() {
                    "none".to_string()
                } else {
                    v.join(", ")
                }
            };
            row(
                out,
                "patches",
                "patches sampled",
                &format!(
                    "{}; clipped: {}; dark: {}",
                    patches.len(),
                    list(flagged("clipped")),
                    list(flagged("dark"))
                ),
            );
        }
    }
    if let Some(model) = e["model"].as_str() {
        row(out, "model", "model", model);
    }
    out.push_str("</table>\n");
}

/// One labelled row, its value cell marked with `key`.
fn row(out: &mut String, key: &str, label: &str, value: &str) {
    let _ = writeln!(
        out,
        "<tr><th>{}</th><td class=\"num\" data-key=\"{}\">{}</td></tr>",
        esc(label),
        esc(key),
        esc(value)
    );
}

/// The label and unit of a lighting metric's key; unknown keys are shown as they are.
fn metric_label(key: &str) -> (String, &'static str) {
    let (label, unit) = match key {
        "xy" => ("CIE 1931 x, y", ""),
        "uv_1960" => ("CIE 1960 u, v", ""),
        "uv_prime_1976" => ("CIE 1976 u′, v′", ""),
        "cct_k" => ("CCT", "K"),
        "duv" => ("Duv", ""),
        "cri_ra" => ("CIE 13.3 colour rendering index Ra", ""),
        "tm30_rf" => ("TM-30 fidelity Rf", ""),
        "tm30_rg" => ("TM-30 gamut Rg", ""),
        "mel_der" => ("melanopic DER (M-EDER, CIE S 026)", ""),
        "sp_ratio" => ("scotopic/photopic ratio S/P", ""),
        "ppf_per_lux" => (
            "photosynthetic photon flux PPF per lux",
            "µmol s⁻¹ m⁻² lx⁻¹",
        ),
        "blh_efficacy_w_per_lm" => ("blue-light hazard efficacy K_B,v (IEC TR 62778)", "W/lm"),
        "alpha_opic_elr_mw_per_lm" => ("α-opic ELR (CIE S 026)", "mW/lm"),
        "alpha_opic_der" => ("α-opic DER (CIE S 026)", ""),
        other => return (other.replace('_', " "), ""),
    };
    (label.to_string(), unit)
}

/// The lighting metrics' order in the table; keys not named here follow.
const METRIC_ORDER: [&str; 14] = [
    "cct_k",
    "duv",
    "cri_ra",
    "tm30_rf",
    "tm30_rg",
    "xy",
    "uv_1960",
    "uv_prime_1976",
    "mel_der",
    "sp_ratio",
    "ppf_per_lux",
    "blh_efficacy_w_per_lm",
    "alpha_opic_der",
    "alpha_opic_elr_mw_per_lm",
];

/// The α-opic quantities' names.
fn alpha_label(key: &str) -> &str {
    match key {
        "sc" => "S-cone-opic",
        "mc" => "M-cone-opic",
        "lc" => "L-cone-opic",
        "rh" => "rhodopic",
        "mel" => "melanopic",
        other => other,
    }
}

/// A lighting metric's value as the report shows it.
fn metric_value(key: &str, v: &Value) -> String {
    match (key, v.as_f64()) {
        ("cct_k", Some(f)) => format!("{f:.0}"),
        ("duv", Some(f)) => format!("{f:+.4}"),
        ("cri_ra" | "tm30_rf" | "tm30_rg", Some(f)) => format!("{f:.1}"),
        _ => match numbers(v) {
            Some(list) if !list.is_empty() && list.len() <= LISTED_MAX => list
                .iter()
                .map(|&f| {
                    if key.contains("uv") || key == "xy" {
                        format!("{f:.4}")
                    } else {
                        fmt(f)
                    }
                })
                .collect::<Vec<_>>()
                .join(", "),
            _ => scalar_or_json(v),
        },
    }
}

/// A metric's 95 % half-width as the report shows it (no sign, the value's decimals).
fn interval_value(key: &str, half95: f64) -> String {
    match key {
        "cct_k" => format!("± {half95:.0}"),
        "duv" => format!("± {half95:.4}"),
        "cri_ra" | "cri_r9" | "tm30_rf" | "tm30_rg" => format!("± {half95:.1}"),
        _ => format!("± {}", fmt(half95)),
    }
}

/// Every lighting metric (undefined ones with their reason) with its 95 % interval from
/// `intervals` (the estimate's `metric_uncertainty`) when there is one; R1–R14 in a table of
/// their own.
fn metrics_tables(out: &mut String, m: &Value, intervals: &Value) {
    let Some(obj) = m.as_object() else {
        return;
    };
    let reasons = &m["reasons"];
    out.push_str(
        "<h3>Lighting metrics</h3>\n<table class=\"metrics\"><tr><th>metric</th><th>value</th>\
         <th>95 %</th><th>unit</th></tr>\n",
    );
    let mut keys: Vec<&String> = obj.keys().collect();
    let rank = |k: &str| {
        METRIC_ORDER
            .iter()
            .position(|o| *o == k)
            .unwrap_or(METRIC_ORDER.len())
    };
    keys.sort_by_key(|k| rank(k));
    for key in keys {
        let v = &obj[key.as_str()];
        if matches!(
            key.as_str(),
            "reasons" | "warnings" | "cri_r" | "tm30_bins" | "tm30_rf_ces"
        ) {
            continue;
        }
        let (label, unit) = metric_label(key);
        match v {
            Value::Null => {
                let why = reasons[key.as_str()].as_str().unwrap_or("undefined");
                let _ = writeln!(
                    out,
                    "<tr><th>{}</th><td class=\"undefined\" data-key=\"{}\" colspan=\"3\">— ({})</td></tr>",
                    esc(&label),
                    esc(key),
                    esc(why)
                );
            }
            Value::Object(parts) => {
                for (part, value) in parts {
                    let _ = writeln!(
                        out,
                        "<tr><th>{} {}</th><td class=\"num\" data-key=\"{}.{}\">{}</td><td></td><td>{}</td></tr>",
                        esc(&label),
                        esc(alpha_label(part)),
                        esc(key),
                        esc(part),
                        esc(&metric_value(part, value)),
                        unit
                    );
                }
            }
            _ => {
                let interval = intervals[key.as_str()]["half95"]
                    .as_f64()
                    .map(|h| interval_value(key, h))
                    .unwrap_or_default();
                let _ = writeln!(
                    out,
                    "<tr><th>{}</th><td class=\"num\" data-key=\"{}\">{}</td>\
                     <td class=\"num\" data-key=\"{}.half95\">{}</td><td>{}</td></tr>",
                    esc(&label),
                    esc(key),
                    esc(&metric_value(key, v)),
                    esc(key),
                    esc(&interval),
                    unit
                );
            }
        }
    }
    if let Some(ces) = numbers(&m["tm30_rf_ces"]).filter(|c| !c.is_empty()) {
        let (lo, hi) = ces.iter().enumerate().fold(
            ((0, f64::INFINITY), (0, f64::NEG_INFINITY)),
            |(lo, hi), (i, &v)| {
                (
                    if v < lo.1 { (i, v) } else { lo },
                    if v > hi.1 { (i, v) } else { hi },
                )
            },
        );
        let _ = writeln!(
            out,
            "<tr><th>TM-30 fidelity of the {} colour samples</th><td class=\"num\" \
             data-key=\"tm30_rf_ces\">lowest {:.1} (CES {}), highest {:.1} (CES {})</td><td></td><td></td></tr>",
            ces.len(),
            lo.1,
            lo.0 + 1,
            hi.1,
            hi.0 + 1
        );
    }
    out.push_str("</table>\n");
    match numbers(&m["cri_r"]) {
        Some(r) if !r.is_empty() => {
            out.push_str("<table class=\"cri-r\"><tr><th>CIE 13.3</th>");
            for i in 1..=r.len() {
                let _ = write!(out, "<th>R{i}</th>");
            }
            out.push_str("</tr><tr><th>special index</th>");
            for (i, v) in r.iter().enumerate() {
                let _ = write!(
                    out,
                    "<td class=\"num\" data-key=\"cri_r.{}\">{v:.1}</td>",
                    i + 1
                );
            }
            out.push_str("</tr>");
            if let Some(h) = intervals["cri_r9"]["half95"].as_f64() {
                let _ = write!(
                    out,
                    "<tr><th>95 %</th>{}<td class=\"num\" data-key=\"cri_r9.half95\">{}</td></tr>",
                    "<td></td>".repeat(8),
                    esc(&interval_value("cri_r9", h))
                );
            }
            out.push_str("</table>\n");
        }
        _ => {
            if let Some(why) = reasons["cri_r"].as_str() {
                let _ = writeln!(out, "<p class=\"undefined\">R1–R14: — ({})</p>", esc(why));
            }
        }
    }
}

/// The warnings of the photo and of the metrics.
fn warnings(out: &mut String, e: &Value) {
    let all: Vec<String> = strings(&e["photo"]["warnings"])
        .into_iter()
        .chain(strings(&e["metrics"]["warnings"]))
        .collect();
    if all.is_empty() {
        return;
    }
    out.push_str("<h3>Warnings</h3>\n<ul class=\"warnings\">");
    for w in all {
        let _ = write!(out, "<li>{}</li>", esc(&w));
    }
    out.push_str("</ul>\n");
}

/// The TM-30 colour vector graphic and the hue bins' table, or why there are none.
fn tm30(out: &mut String, m: &Value) {
    out.push_str("<h3>TM-30 colour vector graphic</h3>\n");
    let bins: Option<Vec<[f64; 7]>> = m["tm30_bins"].as_array().and_then(|a| {
        a.iter()
            .map(|b| {
                let r = numbers(&b["reference_ab"]).filter(|v| v.len() == 2)?;
                let t = numbers(&b["test_ab"]).filter(|v| v.len() == 2)?;
                Some([
                    r[0],
                    r[1],
                    t[0],
                    t[1],
                    b["rf"].as_f64()?,
                    b["chroma_shift"].as_f64()?,
                    b["hue_shift"].as_f64()?,
                ])
            })
            .collect()
    });
    let Some(bins) = bins.filter(|b| b.len() == 16) else {
        let why = m["reasons"]["tm30_bins"]
            .as_str()
            .unwrap_or("no TM-30 hue bins");
        let _ = writeln!(out, "<p class=\"undefined\">— ({})</p>", esc(why));
        return;
    };
    out.push_str(&tm30_svg(
        &bins,
        m["tm30_rf"].as_f64(),
        m["tm30_rg"].as_f64(),
    ));
    out.push_str(
        "<p class=\"small\">After ANSI/IES TM-30-20, Annex (colour vector graphic): each hue \
         bin's average (a′, b′) under the reference illuminant is put on the unit circle (black) \
         and the test light's average is drawn at the same offset, scaled by the reference \
         chroma (red); lines join each reference to its test point (dots). Outside the circle: more saturated.\
         </p>\n<table class=\"tm30-bins\"><tr><th>hue bin</th>",
    );
    for j in 1..=16 {
        let _ = write!(out, "<th>{j}</th>");
    }
    for (label, k, scale, digits) in [
        ("R<sub>f,h</sub>", 4, 1.0, 0),
        ("R<sub>cs,h</sub> %", 5, 100.0, 0),
        ("R<sub>hs,h</sub> rad", 6, 1.0, 2),
    ] {
        let _ = write!(out, "</tr><tr><th>{label}</th>");
        for b in &bins {
            let _ = write!(out, "<td class=\"num\">{:.digits$}</td>", b[k] * scale);
        }
    }
    out.push_str("</tr></table>\n");
}

/// The graphic of the 16 bins `[a_ref, b_ref, a_test, b_test, …]`.
fn tm30_svg(bins: &[[f64; 7]], rf: Option<f64>, rg: Option<f64>) -> String {
    let normalised: Vec<([f64; 2], [f64; 2])> = bins
        .iter()
        .map(|b| {
            let chroma = b[0].hypot(b[1]).max(1e-9);
            let unit = [b[0] / chroma, b[1] / chroma];
            let test = [
                unit[0] + (b[2] - b[0]) / chroma,
                unit[1] + (b[3] - b[1]) / chroma,
            ];
            (unit, test)
        })
        .collect();
    // The reference circle 140 px, smaller when a test point would fall outside.
    let reach = normalised
        .iter()
        .map(|(_, t)| t[0].hypot(t[1]))
        .filter(|v| v.is_finite())
        .fold(1.35_f64, f64::max);
    // The radius of the hue bins' background, in px.
    const OUTER: f64 = 195.0;
    let (c, r) = (200.0, 140.0 * 1.35 / reach);
    let px = |p: [f64; 2]| [c + r * p[0], c - r * p[1]];
    let points: Vec<([f64; 2], [f64; 2])> =
        normalised.iter().map(|(u, t)| (px(*u), px(*t))).collect();
    let mut s = String::new();
    let _ = write!(
        s,
        "<svg class=\"tm30-cvg\" viewBox=\"0 0 400 400\" \
         role=\"img\" aria-label=\"TM-30 colour vector graphic\" font-family=\"sans-serif\" \
         font-size=\"12\">"
    );
    for (j, colour) in BIN_COLOURS.iter().enumerate() {
        let a0 = std::f64::consts::TAU * j as f64 / 16.0;
        let a1 = std::f64::consts::TAU * (j + 1) as f64 / 16.0;
        let p0 = [c + OUTER * a0.cos(), c - OUTER * a0.sin()];
        let p1 = [c + OUTER * a1.cos(), c - OUTER * a1.sin()];
        let _ = write!(
            s,
            "<path d=\"M{c},{c}L{:.1},{:.1}A{outer},{outer} 0 0 0 {:.1},{:.1}z\" fill=\"{}\" \
             fill-opacity=\"0.22\" stroke=\"#fff\"/>",
            p0[0],
            p0[1],
            p1[0],
            p1[1],
            colour,
            outer = OUTER,
        );
    }
    for radius in [0.8, 1.2] {
        let _ = write!(
            s,
            "<circle cx=\"{c}\" cy=\"{c}\" r=\"{:.1}\" fill=\"none\" stroke=\"#888\" \
             stroke-dasharray=\"3 3\"/>",
            radius * r
        );
    }
    let _ = write!(
        s,
        "<circle class=\"reference\" cx=\"{c}\" cy=\"{c}\" r=\"{r}\" fill=\"none\" \
         stroke=\"#000\" stroke-width=\"2\"/>"
    );
    let polygon: Vec<String> = points
        .iter()
        .map(|(_, t)| format!("{:.1},{:.1}", t[0], t[1]))
        .collect();
    let _ = write!(
        s,
        "<polygon class=\"test\" points=\"{}\" fill=\"none\" stroke=\"#d00\" stroke-width=\"2.5\"/>",
        polygon.join(" ")
    );
    for (j, (reference, test)) in points.iter().enumerate() {
        let _ = write!(
            s,
            "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"#333\" \
             stroke-width=\"1.5\"/><circle cx=\"{:.1}\" cy=\"{:.1}\" \
             r=\"3.5\" fill=\"{}\" stroke=\"#000\" stroke-width=\"0.5\"/>",
            reference[0], reference[1], test[0], test[1], test[0], test[1], BIN_COLOURS[j]
        );
        let mid = std::f64::consts::TAU * (j as f64 + 0.5) / 16.0;
        let at = [c + 0.93 * OUTER * mid.cos(), c - 0.93 * OUTER * mid.sin()];
        let _ = write!(
            s,
            "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\" font-size=\"10\" fill=\"#444\">{}</text>",
            at[0],
            at[1] + 3.0,
            j + 1
        );
    }
    let label = |v: Option<f64>| v.map_or_else(|| "—".to_string(), |v| format!("{v:.0}"));
    let _ = write!(
        s,
        "<text x=\"{c}\" y=\"{:.0}\" text-anchor=\"middle\" font-size=\"15\">Rf {}</text>\
         <text x=\"{c}\" y=\"{:.0}\" text-anchor=\"middle\" font-size=\"15\">Rg {}</text></svg>",
        c - 4.0,
        label(rf),
        c + 16.0,
        label(rg)
    );
    s
}

/// The details table's rows: every value of `v` below `path` not in `shown`.
fn details(v: &Value, path: &str, shown: &BTreeSet<String>, rows: &mut Vec<(String, String)>) {
    if shown.contains(path) {
        return;
    }
    let join = |key: &str| {
        if path.is_empty() {
            key.to_string()
        } else {
            format!("{path}.{key}")
        }
    };
    match v {
        Value::Object(map) => object_details(map, &join, shown, rows),
        Value::Array(items) => {
            if let Some(list) = numbers(v) {
                let text = if list.len() <= LISTED_MAX {
                    list.iter().map(|&f| fmt(f)).collect::<Vec<_>>().join(", ")
                } else {
                    format!(
                        "{} values from {} to {} (all in the JSON)",
                        list.len(),
                        fmt(list.iter().copied().fold(f64::INFINITY, f64::min)),
                        fmt(list.iter().copied().fold(f64::NEG_INFINITY, f64::max))
                    )
                };
                rows.push((path.to_string(), text));
            } else if items.len() <= LISTED_MAX {
                for (i, item) in items.iter().enumerate() {
                    details(item, &format!("{path}[{i}]"), shown, rows);
                }
            } else {
                rows.push((
                    path.to_string(),
                    format!("{} items (all in the JSON)", items.len()),
                ));
            }
        }
        Value::Null => rows.push((path.to_string(), "—".into())),
        other => rows.push((path.to_string(), scalar_or_json(other))),
    }
}

fn object_details(
    map: &Map<String, Value>,
    join: &dyn Fn(&str) -> String,
    shown: &BTreeSet<String>,
    rows: &mut Vec<(String, String)>,
) {
    for (key, value) in map {
        details(value, &join(key), shown, rows);
    }
}

/// A JSON number readably: integers as they are, others to 4 significant digits.
fn number(v: &Value) -> String {
    if let Some(i) = v.as_i64() {
        return i.to_string();
    }
    v.as_f64().map_or_else(|| v.to_string(), fmt)
}

/// `f` to 4 significant digits, in scientific notation only when very large or small.
fn fmt(f: f64) -> String {
    if !f.is_finite() {
        return f.to_string();
    }
    if f == 0.0 {
        return "0".into();
    }
    let magnitude = f.abs().log10().floor() as i32;
    if !(-4..6).contains(&magnitude) {
        return format!("{f:.3e}");
    }
    let digits = (3 - magnitude).max(0) as usize;
    format!("{f:.digits$}")
}

/// Text escaped for HTML (element content and quoted attributes).
fn esc(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for ch in s.chars() {
        match ch {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// Standard base64 (RFC 4648, padded), for data URIs.
fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    /// A hand-made estimate with the keys a later version adds (verdict, bands, a new number).
    fn estimate_with_verdict() -> Value {
        let w: Vec<f64> = (0..7).map(|i| 400.0 + 50.0 * f64::from(i)).collect();
        let spd = vec![0.2, 0.5, 0.8, 1.0, 0.9, 0.7, 0.4];
        let shift = |d: f64| spd.iter().map(|v| v + d).collect::<Vec<f64>>();
        let (low68, high68, low95, high95) = (shift(-0.05), shift(0.05), shift(-0.1), shift(0.1));
        json!({
            "name": "room <1>.jpg",
            "model": "shipped",
            "wavelength_nm": w,
            "spd": spd,
            "colorimetry": {"xy": [0.4476, 0.4074], "cct": 2856.0, "duv": 0.0001},
            "metrics": {"cri_ra": 81.26, "tm30_rf": null,
                        "cri_r": [80.0, 81.0, 82.0, 83.0, 84.0, 85.0, 86.0, 87.0, 20.5, 60.0, 70.0,
                                  71.0, 72.0, 73.0],
                        "reasons": {"tm30_rf": "the SPD does not cover 380–780 nm"},
                        "warnings": []},
            "truth": null,
            "verdict": "usable with care",
            "reasons": ["the chart is small in the photo"],
            "band68": {"lower": low68, "upper": high68},
            "band95": {"lower": low95, "upper": high95},
            "expected_gfc": 0.9912,
            "metric_uncertainty": {"cri_ra": {"half68": 1.9, "half95": 4.04},
                                   "cri_r9": {"half68": 7.0, "half95": 15.26}},
            "self_check": {"passed": true, "residual": 0.0123}
        })
    }

    #[test]
    fn the_verdict_bands_and_new_keys_are_shown() {
        let item = ReportItem {
            estimate: estimate_with_verdict(),
            image: None,
            truth_spd: None,
        };
        let html = report_html("spdcam estimate", &[item]);
        let verdict = html.find("class=\"verdict\"").expect("no verdict");
        assert!(
            verdict < html.find("class=\"spd-plot\"").unwrap(),
            "verdict not at the top"
        );
        assert!(html.contains("Verdict: usable with care"));
        assert!(html.contains("<li>the chart is small in the photo</li>"));
        assert!(html.contains("<polygon class=\"band95\""));
        assert!(html.contains("<polygon class=\"band68\""));
        assert!(html.contains("68 % and 95 % uncertainty bands"));
        assert!(html.contains(">68 % band</text>") && html.contains(">95 % band</text>"));
        // Keys the report does not know go to the details table; the plotted bands do not.
        assert!(html.contains(
            "<tr data-key=\"expected_gfc\"><th>expected_gfc</th><td class=\"num\">0.9912</td>"
        ));
        assert!(html.contains("data-key=\"self_check.passed\""));
        assert!(html.contains("<td class=\"num\">0.01230</td>"));
        assert!(!html.contains("data-key=\"band68"));
        // Undefined metrics carry their reason; text is escaped.
        assert!(html.contains("— (the SPD does not cover 380–780 nm)"));
        assert!(html.contains("<h2>room &lt;1&gt;.jpg</h2>"));
        assert!(html.contains("data-key=\"cri_ra\">81.3</td>"));
        // Metric intervals stand beside their values, not in the details.
        assert!(html.contains("data-key=\"cri_ra.half95\">± 4.0</td>"));
        assert!(html.contains("data-key=\"cri_r9.half95\">± 15.3</td>"));
        assert!(!html.contains("data-key=\"metric_uncertainty"));
    }

    #[test]
    fn malformed_bands_and_a_missing_verdict_are_left_out() {
        let mut e = estimate_with_verdict();
        e["band95"] = json!({"lower": [0.1], "upper": [0.2]});
        e.as_object_mut().unwrap().remove("verdict");
        e.as_object_mut().unwrap().remove("band68");
        let html = report_html(
            "t",
            &[ReportItem {
                estimate: e,
                image: None,
                truth_spd: None,
            }],
        );
        assert!(!html.contains("class=\"verdict\""));
        assert!(!html.contains("<polygon class=\"band"));
        assert!(html.contains("data-key=\"band95.lower\""));
    }

    #[test]
    fn numbers_and_base64_are_formatted() {
        assert_eq!(fmt(0.012346), "0.01235");
        assert_eq!(fmt(1234.4), "1234");
        assert_eq!(fmt(12.3456), "12.35");
        assert_eq!(fmt(1.5e-7), "1.500e-7");
        assert_eq!(base64(b""), "");
        assert_eq!(base64(b"f"), "Zg==");
        assert_eq!(base64(b"fo"), "Zm8=");
        assert_eq!(base64(b"foobar"), "Zm9vYmFy");
    }
}
