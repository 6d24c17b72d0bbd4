//! The report's colour-meter parts ([`crate::meter`] as HTML): the headline readings, the
//! R1–R15 bar chart and the film and TV numbers.

use crate::html::esc;
use crate::meter::Meter;
use std::fmt::Write as _;

/// Approximate sRGB colours of CIE 13.3's test colour samples 1–14 and JIS Z 8726's No. 15,
/// for the bars (as colour meters draw them; only a visual aid).
const TCS_COLOURS: [&str; 15] = [
    "#b78e86", "#9c9354", "#7fa04a", "#6ba28b", "#6e9db4", "#857fb8", "#a97eae", "#b7788b",
    "#c4132b", "#e8c300", "#2f7d4a", "#1d3d8f", "#e9c6ad", "#4d5a32", "#d5a283",
];

/// The headline readings (and the illuminance) as one block.
pub(crate) fn headline_html(out: &mut String, m: &Meter) {
    let _ = write!(out, "<div class=\"meter {}\">", m.kind);
    for r in &m.headline {
        let _ = write!(
            out,
            "<span class=\"reading\"><span class=\"label\">{}</span> \
             <span class=\"value\" data-key=\"{}\">{}</span></span>",
            esc(r.label),
            r.key,
            esc(&r.value)
        );
    }
    if let Some(lux) = &m.illuminance {
        let _ = write!(
            out,
            "<span class=\"reading\"><span class=\"label\">Illuminance</span> \
             <span class=\"value\" data-key=\"illuminance\">{}</span></span>",
            esc(lux)
        );
    }
    out.push_str("</div>\n");
}

/// R1–R15 as bars (0–100; negative values below the axis), with their values; one not
/// determinable has no bar and `—`.
pub(crate) fn r_bars_svg(r: &[Option<f64>]) -> String {
    let (w, h, top, axis) = (300.0, 96.0, 12.0, 78.0);
    let low = r
        .iter()
        .flatten()
        .copied()
        .fold(0.0_f64, f64::min)
        .max(-100.0);
    // 0 at `axis`, 100 at `top`; negative values go below down to `low`.
    let scale = (axis - top) / (100.0 - low.min(0.0) * 0.3);
    let step = w / r.len() as f64;
    let mut s = format!(
        "<svg class=\"r-bars\" viewBox=\"0 0 {w} {h}\" \
         role=\"img\" aria-label=\"Special colour rendering indices R1 to R15\" \
         font-family=\"sans-serif\"><line x1=\"0\" x2=\"{w}\" y1=\"{axis}\" y2=\"{axis}\" stroke=\"#888\"/>"
    );
    for (i, v) in r.iter().enumerate() {
        let x = i as f64 * step + 2.0;
        let Some(v) = v else {
            let _ = write!(
                s,
                "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"8\" text-anchor=\"middle\">—</text>\
                 <text x=\"{:.1}\" y=\"{h}\" font-size=\"8\" text-anchor=\"middle\" fill=\"#555\">R{}</text>",
                x + (step - 4.0) / 2.0,
                axis - 2.0,
                x + (step - 4.0) / 2.0,
                i + 1
            );
            continue;
        };
        let len = v.clamp(low, 100.0) * scale;
        let (y, height) = if len >= 0.0 {
            (axis - len, len)
        } else {
            (axis, (-len).min(h - axis - 10.0))
        };
        let _ = write!(
            s,
            "<rect data-key=\"r{}\" x=\"{x:.1}\" y=\"{y:.1}\" width=\"{:.1}\" height=\"{height:.1}\" fill=\"{}\"/>\
             <text x=\"{:.1}\" y=\"{:.1}\" font-size=\"8\" text-anchor=\"middle\">{}</text>\
             <text x=\"{:.1}\" y=\"{h}\" font-size=\"8\" text-anchor=\"middle\" fill=\"#555\">R{}</text>",
            i + 1,
            step - 4.0,
            TCS_COLOURS[i % TCS_COLOURS.len()],
            x + (step - 4.0) / 2.0,
            (axis - len.max(0.0) - 2.0).max(8.0),
            crate::rounding::shown_with_unit("cri_r", *v, None),
            x + (step - 4.0) / 2.0,
            i + 1
        );
    }
    s.push_str("</svg>");
    s
}

/// The film and TV numbers: R1–R15 bars, SSI and the filter corrections, or nothing for a
/// light without a meaningful CCT.
pub(crate) fn film_tv_html(out: &mut String, m: &Meter) {
    if m.r1_r15.is_none() && m.film_tv.is_empty() {
        return;
    }
    out.push_str("<div class=\"row film-tv\">\n<div>");
    if let Some(r) = &m.r1_r15 {
        let _ = write!(
            out,
            "<figure>{}<figcaption>R1–R15: how true each test colour looks (CIE 13.3; R15 \
             Japanese skin, JIS Z 8726); R9 is the saturated red{}.</figcaption></figure>",
            r_bars_svg(r),
            m.r9_note
                .as_ref()
                .map_or_else(String::new, |note| format!("; no bar: {}", esc(note)))
        );
    }
    out.push_str("</div>\n<div><table class=\"film-tv small\">");
    for r in &m.film_tv {
        let _ = write!(
            out,
            "<tr><th>{}</th><td data-key=\"{}\">{}</td></tr>",
            esc(r.label),
            r.key,
            esc(&r.value)
        );
    }
    out.push_str(
        "</table><p class=\"small\">SSI: the Academy's spectral similarity to a reference \
         (100 = the same). Filter: the mired shift 10⁶/T<sub>target</sub> − 10⁶/T<sub>light</sub> \
         and the Δuv a green–magenta filter removes.</p></div>\n</div>\n",
    );
}
