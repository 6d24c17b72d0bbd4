//! The HTML report of estimates (`spdcam estimate --report`, and the web page's "Report"
//! download): for each estimate one page with the plain-words summary, the colour meter's
//! headline ([`crate::meter`]) and the verdict, the photo with the chart found, the SPD with
//! its labelled 68/95 % bands (and the true SPD when known), the CIE 1976 u′v′ diagram
//! ([`crate::chromaticity`]), the metrics grouped and rounded as [`Presentation`] gives them
//! (those not meaningful for the light greyed with the reason), the TM-30 colour vector
//! graphic, R1–R15 as bars with SSI and the filter corrections, and the detection. Everything is inline (CSS, SVG, the photo as a data URI): the page loads
//! nothing. Each estimate prints on one A4 or Letter page.

use crate::chromaticity::uv_diagram_svg;
use crate::html::esc;
use crate::meaningful::cct_meaningful;
use crate::presentation::Presentation;
use crate::report_meter::{film_tv_html, headline_html};
use spdcam_core::quality::HueBin;
use spdcam_core::spectral::Spd;
use spdcam_infer::estimate::Colorimetry;
use spdcam_infer::estimate::Estimate;
use spdcam_infer::trust::Band;
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

/// One estimate of a report: the estimate, what it means, the photo and the truth.
#[derive(Debug, Clone)]
pub struct ReportItem {
    /// The estimate.
    pub estimate: Estimate,
    /// Its words and rounded numbers.
    pub presentation: Presentation,
    /// The photo with the chart's outline and sampled patches, for estimates of photos.
    pub image: Option<ReportImage>,
    /// The true SPD on the estimate's wavelengths, when known (any scale).
    pub truth_spd: Option<Vec<f64>>,
}

impl ReportItem {
    /// The report item of `estimate`, with its photo drawn and its truth when known.
    pub fn new(
        estimate: Estimate,
        image: Option<ReportImage>,
        truth_spd: Option<Vec<f64>>,
    ) -> ReportItem {
        ReportItem::presented(Presentation::of(&estimate), estimate, image, truth_spd)
    }

    /// [`ReportItem::new`] with the estimate's presentation made already (for the page's
    /// JSON, say): not made again.
    pub fn presented(
        presentation: Presentation,
        estimate: Estimate,
        image: Option<ReportImage>,
        truth_spd: Option<Vec<f64>>,
    ) -> ReportItem {
        ReportItem {
            presentation,
            estimate,
            image,
            truth_spd,
        }
    }
}

/// The colours of the TM-30 hue bins 1–16 (as the standard's graphics draw them).
const BIN_COLOURS: [&str; 16] = [
    "#e62828", "#e74b4b", "#fb812e", "#ffb529", "#cbca46", "#7eb94c", "#41c06d", "#009c7c",
    "#16bcb0", "#00a4bf", "#0085c3", "#3b62aa", "#4568ae", "#6a4e85", "#9d69a1", "#a74f81",
];

/// The colour of the estimate and its bands.
const ESTIMATE_COLOUR: &str = "#1f5fbf";

const STYLE: &str = "\
body{font:13px/1.35 system-ui,sans-serif;color:#1d2330;max-width:1000px;margin:16px auto;padding:0 12px}\
h1{font-size:19px;margin:0 0 4px}h3{font-size:13px;margin:8px 0 3px}\
p{margin:3px 0}section{margin-bottom:28px}\
.summary{font-size:14px}\
.verdict{border:2px solid #1d2330;background:#f3f1e8;padding:5px 10px;margin:6px 0}\
.verdict.doubtful{border-color:#8a5a00;background:#fbf3df}.verdict.unusable{border-color:#b3261e;background:#fbe6e4}\
.verdict strong{font-size:14px}.verdict ul{margin:2px 0 0;padding-left:18px}\
.row{display:grid;grid-template-columns:minmax(0,1fr) minmax(0,1fr);gap:12px;align-items:start;margin-top:6px}\
.row.three{grid-template-columns:minmax(0,1fr) minmax(0,1.2fr) minmax(0,0.9fr)}.row.with-tm30{grid-template-columns:minmax(0,3fr) minmax(0,2fr)}\
.meter{display:flex;flex-wrap:wrap;gap:4px 18px;margin:4px 0}.meter .reading .label{color:#555;font-size:11px;display:block}.meter .reading .value{font-size:17px;font-weight:600;font-variant-numeric:tabular-nums}\
svg.uv-diagram{max-width:300px;margin:auto}svg.r-bars{max-width:420px}.row.single{grid-template-columns:minmax(0,1fr)}\
figure{margin:0}figcaption,.small{font-size:11px;color:#555}\
img.photo{max-width:100%;max-height:320px;height:auto;display:block;margin:auto}\
svg{width:100%;height:auto;display:block}svg.tm30-cvg{max-width:250px;margin:auto}\
table{border-collapse:collapse;width:100%}th,td{text-align:left;padding:1px 6px 1px 0;border-bottom:1px solid #ddd;vertical-align:top}\
td.num{font-variant-numeric:tabular-nums;white-space:nowrap}\
table.metrics th.group{padding-top:5px;border-bottom:1px solid #888;font-size:12px}\
table.metrics td.explain{color:#555;font-size:11px}\
tr.not-meaningful th,tr.not-meaningful td{color:#888}tr.not-meaningful .reason{font-style:italic}\
table.grid-table{table-layout:fixed;font-size:11px}table.grid-table th,table.grid-table td{padding:1px 2px;text-align:center}\
table.grid-table th:first-child{text-align:left;width:22%}table.metrics th{white-space:nowrap}\
.undefined{color:#888;font-style:italic}.warnings li{color:#8a5a00}\
@page{margin:9mm}\
@media print{body{margin:0;max-width:none;padding:0;font-size:7.5pt}h1{font-size:13pt}h3{font-size:8.5pt;margin:4px 0 2px}\
.summary{font-size:9pt}.verdict{padding:3px 8px;margin:3px 0}.verdict strong{font-size:9pt}\
img.photo{max-height:32mm;width:auto}svg.spd-plot{max-height:32mm}svg.uv-diagram{max-height:33mm}svg.r-bars{max-height:19mm}.meter .reading .value{font-size:10pt}.meter .reading .label{font-size:6.5pt}svg.tm30-cvg{max-width:44mm}\
figcaption,.small,table.metrics td.explain{font-size:6.5pt}tr.metric:not(.not-meaningful) td.explain{display:none}.film-tv td,.film-tv th{padding:0 4px 0 0}table.grid-table{font-size:6.5pt}\
section{break-after:page;margin:0}section:last-of-type{break-after:auto}\
.row{gap:8px;margin-top:3px}}";

/// The HTML page of `items` under the heading `title`; each item is a section (a page in
/// print) headed by its own name.
pub fn report_html(title: &str, items: &[ReportItem]) -> String {
    let mut out = String::new();
    let _ = write!(
        out,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <meta name=\"viewport\" content=\"width=device-width,initial-scale=1\">\
         <title>{}</title><style>{STYLE}</style></head>\n<body>\n",
        esc(title)
    );
    for (i, item) in items.iter().enumerate() {
        section(&mut out, i + 1, item);
    }
    out.push_str("</body></html>\n");
    out
}

/// One estimate's section.
fn section(out: &mut String, index: usize, item: &ReportItem) {
    let e = &item.estimate;
    let p = &item.presentation;
    let _ = write!(
        out,
        "<section class=\"estimate\" id=\"estimate-{index}\">\n<h1>The light in {}</h1>\n\
         <p class=\"summary\">{}</p>\n",
        esc(&e.name),
        esc(&p.summary)
    );
    headline_html(out, &p.meter);
    if let Some(v) = &p.verdict {
        let _ = write!(
            out,
            "<div class=\"verdict {}\" data-verdict=\"{}\"><strong>Verdict: {}</strong> {}",
            v.label,
            v.label,
            esc(v.headline),
            esc(v.explanation)
        );
        if let Some(glare) = &v.glare {
            let _ = write!(out, " {}", esc(glare));
        }
        if !v.reasons.is_empty() {
            out.push_str("<ul class=\"reasons\">");
            for r in &v.reasons {
                let _ = write!(out, "<li>{}</li>", esc(r));
            }
            out.push_str("</ul>");
        }
        out.push_str("</div>\n");
    }
    out.push_str("<div class=\"row three\">\n");
    match &item.image {
        Some(image) => {
            let _ = writeln!(
                out,
                "<figure><img class=\"photo\" alt=\"the photo with the chart found\" \
                 src=\"data:{};base64,{}\"><figcaption>{}: the chart found (green outline, \
                 yellow: the corner of patch 1) and the squares sampled (white; red: clipped).\
                 </figcaption></figure>",
                image.mime,
                base64(&image.bytes),
                esc(&e.name)
            );
        }
        None => out.push_str("<p class=\"small\">No photo: estimated from chart features.</p>\n"),
    }
    let truth = item
        .truth_spd
        .as_deref()
        .and_then(|t| peak_one(t, e.spd.len()));
    let bands = e
        .trust
        .as_ref()
        .and_then(|t| t.uncertainty.as_ref())
        .map(|u| (&u.band68, &u.band95));
    let _ = writeln!(
        out,
        "<figure>{}<figcaption>The estimated spectrum (relative, peak 1){}{}.</figcaption></figure>",
        spd_svg(&e.spd.grid().wavelengths(), &e.spd, truth.as_deref(), bands),
        if truth.is_some() {
            ", the true spectrum dashed (peak 1)"
        } else {
            ""
        },
        if bands.is_some() {
            "; the true spectrum lies in the dark band with 68 % and in the light band with \
             95 % probability"
        } else {
            ""
        }
    );
    let truth_xy = truth
        .as_ref()
        .and_then(|t| Spd::new(*e.spd.grid(), t.clone()).ok())
        .and_then(|t| Colorimetry::of(&t).ok())
        .map(|c| c.xy);
    let _ = writeln!(
        out,
        "<figure>{}<figcaption>CIE 1976 u′v′: the estimate (blue dot){}{}, the Planckian \
         locus with isotemperature lines; the inset enlarges its neighbourhood.</figcaption></figure>",
        uv_diagram_svg(e, truth_xy),
        if crate::chromaticity::region95(e).is_some() {
            " with its 95 % region (from the CCT and Δuv intervals)"
        } else {
            ""
        },
        if truth_xy.is_some() {
            ", the truth (×)"
        } else {
            ""
        }
    );
    out.push_str("</div>\n");
    let bins = tm30_bins(e);
    let _ = writeln!(
        out,
        "<div class=\"row{}\">\n<div>",
        if bins.is_ok() {
            " with-tm30"
        } else {
            " single"
        }
    );
    metrics_table(out, p);
    out.push_str("</div>\n");
    match bins {
        Ok(bins) => {
            out.push_str("<div>\n");
            tm30_graphic(out, bins, e);
            out.push_str("</div>\n</div>\n");
            tm30_table(out, bins);
        }
        Err(why) => {
            out.push_str("</div>\n");
            let _ = writeln!(
                out,
                "<p class=\"undefined\" data-key=\"tm30_bins\">TM-30 colour vector graphic: {}</p>",
                esc(&why)
            );
        }
    }
    film_tv_html(out, &p.meter);
    facts(out, e);
    let warnings = &p.warnings;
    if !warnings.is_empty() {
        out.push_str("<ul class=\"warnings small\">");
        for w in warnings {
            let _ = write!(out, "<li>{}</li>", esc(w));
        }
        out.push_str("</ul>\n");
    }
    let _ = writeln!(
        out,
        "<p class=\"small\">{} The spectrum is relative (peak 1) and estimated on {}–{} nm only; \
         the metrics are computed on that range. Made by spdcam ({}).</p>\n</section>",
        esc(&p.gfc),
        e.spd.grid().start_nm,
        e.spd.grid().end_nm(),
        esc(&e.model)
    );
}

/// `t` scaled to peak 1, when it has `n` values and a positive peak.
fn peak_one(t: &[f64], n: usize) -> Option<Vec<f64>> {
    let peak = t.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (t.len() == n && peak > 0.0).then(|| t.iter().map(|v| v / peak).collect())
}

/// The grouped metrics: a rounded value with its 95 % interval, or greyed with the reason.
fn metrics_table(out: &mut String, p: &Presentation) {
    out.push_str("<table class=\"metrics\">\n");
    for group in &p.groups {
        let _ = writeln!(
            out,
            "<tr><th class=\"group\" colspan=\"3\">{}</th></tr>",
            esc(group.title)
        );
        for m in &group.metrics {
            let unit = if m.unit.is_empty() {
                String::new()
            } else {
                format!(" {}", m.unit)
            };
            match (&m.value, &m.not_meaningful) {
                (Some(value), _) => {
                    let _ = writeln!(
                        out,
                        "<tr class=\"metric\"><th>{}</th><td class=\"num\" data-key=\"{}\">{}{}</td>\
                         <td class=\"explain\">{}</td></tr>",
                        esc(m.label),
                        m.key,
                        esc(value),
                        esc(&unit),
                        esc(m.explanation)
                    );
                }
                (None, why) => {
                    let _ = writeln!(
                        out,
                        "<tr class=\"metric not-meaningful\"><th>{}</th><td data-key=\"{}\">—</td>\
                         <td class=\"explain reason\">{}</td></tr>",
                        esc(m.label),
                        m.key,
                        esc(why.as_deref().unwrap_or("not defined"))
                    );
                }
            }
        }
    }
    out.push_str(
        "</table>\n<p class=\"small\">±: the 95 % interval, calibrated on photos held out from training.</p>\n",
    );
}

/// The photo, the detection and the score against the truth, in one small table.
fn facts(out: &mut String, e: &Estimate) {
    let mut rows: Vec<(&str, &str, String)> = Vec::new();
    let xy = e.colorimetry.xy;
    rows.push(("xy", "CIE 1931 x, y", format!("{:.4}, {:.4}", xy[0], xy[1])));
    if let Some(t) = &e.truth {
        rows.push((
            "gfc",
            "against the true spectrum",
            format!("GFC {:.4}, RMSE {:.4}", t.gfc, t.rmse),
        ));
    }
    if let Some(a) = &e.photo {
        let method = if a.method == "corners" {
            "the corners given"
        } else {
            "detection"
        };
        let clipped = a.patches.iter().filter(|p| p.clipped).count();
        let dark = a.patches.iter().filter(|p| p.dark).count();
        rows.push((
            "chart",
            "chart",
            format!(
                "{} found by {method} (confidence {:.2}) in a {} × {} px photo; {} patches \
                 sampled, {clipped} clipped, {dark} dark",
                spdcam_core::chart::shown_chart_name(&a.chart),
                a.confidence,
                a.width,
                a.height,
                a.patches.len()
            ),
        ));
        if let Some(raw) = &a.raw {
            rows.push(("raw", "raw", raw.describe()));
        }
    }
    if let Some(w) = e
        .trust
        .as_ref()
        .and_then(|t| t.uncertainty.as_ref())
        .map(|u| u.widening)
        .filter(|w| *w > 1.0)
    {
        rows.push((
            "widening",
            "bands widened",
            format!("{w:.1}× (the light explains this photo less well than usual)"),
        ));
    }
    out.push_str("<table class=\"facts small\">");
    for (key, label, value) in rows {
        let _ = write!(
            out,
            "<tr><th>{}</th><td data-key=\"{key}\">{}</td></tr>",
            esc(label),
            esc(&value)
        );
    }
    out.push_str("</table>\n");
}

/// The SPD plot: the estimate, the truth (peak 1) when known, the 68 % and 95 % bands when
/// present, with a legend above the frame so it covers no curve.
fn spd_svg(w: &[f64], spd: &[f64], truth: Option<&[f64]>, bands: Option<(&Band, &Band)>) -> String {
    if w.len() < 2 || spd.len() != w.len() {
        return "<p class=\"small\">No spectrum to plot.</p>".into();
    }
    let bands = bands.filter(|(b68, b95)| {
        [b68, b95]
            .iter()
            .all(|b| b.lower.len() == w.len() && b.upper.len() == w.len())
    });
    let top = spd
        .iter()
        .chain(truth.into_iter().flatten())
        .chain(bands.iter().flat_map(|(_, b95)| b95.upper.iter()))
        .copied()
        .filter(|v| v.is_finite())
        .fold(1.0_f64, f64::max);
    let y_max = (top * 1.02 * 4.0).ceil() / 4.0;
    let (w0, w1) = (w[0], w[w.len() - 1]);
    let (left, right, top_px, bottom) = (46.0, 630.0, 30.0, 300.0);
    let x = |v: f64| left + (v - w0) / (w1 - w0) * (right - left);
    let y = |v: f64| bottom - v.clamp(0.0, y_max) / y_max * (bottom - top_px);
    let mut s = String::new();
    let _ = write!(
        s,
        "<svg class=\"spd-plot\" viewBox=\"0 0 640 340\" role=\"img\" aria-label=\"estimated \
         spectrum\" font-size=\"12\" font-family=\"sans-serif\"><rect x=\"{left}\" y=\"{top_px}\" \
         width=\"{}\" height=\"{}\" fill=\"#fff\" stroke=\"#888\"/>",
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
            bottom + 15.0
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
            left - 5.0,
            y(level) + 4.0
        );
        level += 0.25;
    }
    let _ = write!(
        s,
        "<text x=\"{:.1}\" y=\"334\" text-anchor=\"middle\">wavelength (nm)</text>\
         <text transform=\"translate(12 {:.1}) rotate(-90)\" text-anchor=\"middle\">relative power</text>",
        (left + right) / 2.0,
        (top_px + bottom) / 2.0
    );
    let points = |values: &mut dyn Iterator<Item = (f64, f64)>| {
        values
            .map(|(l, v)| format!("{:.1},{:.1}", x(l), y(v)))
            .collect::<Vec<_>>()
            .join(" ")
    };
    if let Some((b68, b95)) = bands {
        for (class, band, opacity) in [("band95", b95, 0.16), ("band68", b68, 0.34)] {
            let outline = points(
                &mut w
                    .iter()
                    .copied()
                    .zip(band.upper.iter().copied())
                    .chain(w.iter().copied().zip(band.lower.iter().copied()).rev()),
            );
            let _ = write!(
                s,
                "<polygon class=\"{class}\" points=\"{outline}\" fill=\"{ESTIMATE_COLOUR}\" \
                 fill-opacity=\"{opacity}\" stroke=\"none\"/>"
            );
        }
    }
    if let Some(t) = truth {
        let _ = write!(
            s,
            "<polyline class=\"truth\" points=\"{}\" fill=\"none\" stroke=\"#222\" \
             stroke-width=\"1.5\" stroke-dasharray=\"6 4\"/>",
            points(&mut w.iter().copied().zip(t.iter().copied()))
        );
    }
    let _ = write!(
        s,
        "<polyline class=\"spd\" points=\"{}\" fill=\"none\" stroke=\"{ESTIMATE_COLOUR}\" \
         stroke-width=\"2.5\"/>",
        points(&mut w.iter().copied().zip(spd.iter().copied()))
    );
    // The legend in a row above the frame.
    let mut legend: Vec<(&str, String)> = vec![(
        "estimate",
        format!("stroke=\"{ESTIMATE_COLOUR}\" stroke-width=\"2.5\""),
    )];
    if truth.is_some() {
        legend.push((
            "true spectrum",
            "stroke=\"#222\" stroke-width=\"1.5\" stroke-dasharray=\"6 4\"".into(),
        ));
    }
    if bands.is_some() {
        legend.push((
            "68 % band",
            format!("stroke=\"{ESTIMATE_COLOUR}\" stroke-width=\"10\" stroke-opacity=\"0.34\""),
        ));
        legend.push((
            "95 % band",
            format!("stroke=\"{ESTIMATE_COLOUR}\" stroke-width=\"10\" stroke-opacity=\"0.16\""),
        ));
    }
    let mut lx = left;
    for (label, style) in legend {
        let _ = write!(
            s,
            "<g class=\"legend\"><line x1=\"{lx}\" x2=\"{}\" y1=\"14\" y2=\"14\" {style}/>\
             <text x=\"{}\" y=\"18\">{label}</text></g>",
            lx + 22.0,
            lx + 27.0
        );
        lx += 40.0 + 7.0 * label.len() as f64;
    }
    s.push_str("</svg>");
    s
}

/// The TM-30 hue bins when they are meaningful for the light, else why not.
fn tm30_bins(e: &Estimate) -> Result<&[HueBin], String> {
    cct_meaningful(e)?;
    e.metrics
        .tm30_bins
        .as_deref()
        .filter(|b| b.len() == 16)
        .ok_or_else(|| {
            e.metrics
                .reasons
                .get("tm30_bins")
                .cloned()
                .unwrap_or_else(|| "no TM-30 hue bins".into())
        })
}

/// The TM-30 colour vector graphic with a line of how to read it.
fn tm30_graphic(out: &mut String, bins: &[HueBin], e: &Estimate) {
    out.push_str("<h3>TM-30 colour vector graphic</h3>\n");
    out.push_str(&tm30_svg(bins, e.metrics.tm30_rf, e.metrics.tm30_rg));
    out.push_str(
        "<p class=\"small\">After ANSI/IES TM-30-20: each hue bin's average under the \
         reference light on the black circle, under this light the red line; outside the \
         circle colours look more saturated, inside duller.</p>\n",
    );
}

/// A row of the hue-bin table: its label and how a bin's value is written.
type BinRow = (&'static str, fn(&HueBin) -> String);

/// The hue bins' local fidelity, chroma shift and hue shift, 16 columns across the page.
fn tm30_table(out: &mut String, bins: &[HueBin]) {
    out.push_str("<table class=\"grid-table tm30-bins\"><tr><th>TM-30 hue bin</th>");
    for j in 1..=16 {
        let _ = write!(out, "<th>{j}</th>");
    }
    let rows: [BinRow; 3] = [
        ("local fidelity R<sub>f,h</sub>", |b| format!("{:.0}", b.rf)),
        ("chroma shift R<sub>cs,h</sub> %", |b| {
            format!("{:.0}", 100.0 * b.chroma_shift)
        }),
        ("hue shift R<sub>hs,h</sub> rad", |b| {
            // No "-0.00".
            format!("{:.2}", b.hue_shift + 0.0).replace("-0.00", "0.00")
        }),
    ];
    for (label, value) in rows {
        let _ = write!(out, "</tr><tr><th>{label}</th>");
        for b in bins {
            let _ = write!(out, "<td class=\"num\">{}</td>", value(b));
        }
    }
    out.push_str("</tr></table>\n");
}

/// The graphic of the 16 hue bins.
fn tm30_svg(bins: &[HueBin], rf: Option<f64>, rg: Option<f64>) -> String {
    let normalised: Vec<([f64; 2], [f64; 2])> = bins
        .iter()
        .map(|b| {
            let [ra, rb] = b.reference_ab;
            let chroma = ra.hypot(rb).max(1e-9);
            let unit = [ra / chroma, rb / chroma];
            let test = [
                unit[0] + (b.test_ab[0] - ra) / chroma,
                unit[1] + (b.test_ab[1] - rb) / chroma,
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
        "<svg class=\"tm30-cvg\" viewBox=\"0 0 400 400\" role=\"img\" aria-label=\"TM-30 colour \
         vector graphic\" font-family=\"sans-serif\" font-size=\"12\">"
    );
    for (j, colour) in BIN_COLOURS.iter().enumerate() {
        let a0 = std::f64::consts::TAU * j as f64 / 16.0;
        let a1 = std::f64::consts::TAU * (j + 1) as f64 / 16.0;
        let p0 = [c + OUTER * a0.cos(), c - OUTER * a0.sin()];
        let p1 = [c + OUTER * a1.cos(), c - OUTER * a1.sin()];
        let _ = write!(
            s,
            "<path d=\"M{c},{c}L{:.1},{:.1}A{OUTER},{OUTER} 0 0 0 {:.1},{:.1}z\" fill=\"{colour}\" \
             fill-opacity=\"0.22\" stroke=\"#fff\"/>",
            p0[0], p0[1], p1[0], p1[1]
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
             stroke-width=\"1.5\"/><circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"3.5\" fill=\"{}\" \
             stroke=\"#000\" stroke-width=\"0.5\"/>",
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
