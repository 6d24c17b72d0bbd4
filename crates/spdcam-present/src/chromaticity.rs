//! The CIE 1976 u′v′ chromaticity diagram of an estimate, as SVG: one drawing for the
//! report and the web page.
//!
//! - The spectral locus is the CIE 1931 2° observer's (360–700 nm, 5 nm, as the core ships
//!   it), closed by the line of purples; u′ = 4X/(X + 15Y + 3Z), v′ = 9Y/(X + 15Y + 3Z)
//!   (CIE 015:2018 §8.1; u′ = u, v′ = 1.5 v of CIE 1960 uv).
//! - The Planckian locus (1000–20,000 K, Planck's law through the same observer) with
//!   isotemperature lines at 2000, 3000, 6500 and 10,000 K, each drawn
//!   ±0.05 along the locus normal in CIE 1960 uv (the range in which a CCT means anything,
//!   Ohno 2014; isotemperature lines are normal to the locus in uv, CIE 015:2018 §9.5).
//! - The estimate's point and, when its CCT and Δuv have calibrated 95 % intervals, the 95 %
//!   region: the ellipse with those half-widths as semi-axes in the (CCT, Δuv) plane, mapped
//!   into u′v′ (an approximation: the two intervals are treated as independent). The truth's
//!   point when known. An inset enlarges the neighbourhood of the estimate, where the region
//!   is seen.

use spdcam_core::colorimetry::{cct_duv_to_uv, cct_to_uv_planck, Observer};
use spdcam_core::quality::uv::{uv1960_to_uv1976, xy_to_uv1976};
use spdcam_core::spectral::Grid;
use spdcam_infer::estimate::Estimate;
use std::fmt::Write as _;

/// The isotemperature lines drawn, kelvin, and at which end each is labelled: `true` at
/// Duv +0.05 (above the locus), `false` at −0.05. Above 3000 K the locus is short in u′v′
/// and the lines crowd: few lines, labelled at alternate ends, keep every label readable
/// (4000 and 5000 K would sit on the 560 nm label or on their neighbours' labels).
pub const ISOTEMPERATURE_K: [(f64, bool); 4] = [
    (2000.0, true),
    (3000.0, false),
    (6500.0, false),
    (10000.0, true),
];

/// The SVG's size, in its own units.
const SIZE: (f64, f64) = (400.0, 400.0);

/// The size of the drawing's text, in its units: the drawing is shown no narrower than
/// about 300 px (a phone's column), where this is 11 px.
pub const FONT: f64 = 15.0;

/// The main panel: pixel box (left, top, right, bottom) and the u′, v′ ranges it shows.
const MAIN: View = View {
    px: (44.0, 8.0, 392.0, 362.0),
    u: (0.0, 0.63),
    v: (0.0, 0.64),
};

/// The inset's pixel box (left, top, right, bottom).
const INSET_PX: (f64, f64, f64, f64) = (232.0, 200.0, 388.0, 340.0);

/// How far inside the inset's edge (a share of its half-width) the region and the truth are
/// kept, so that the truth's × is never cut at the edge.
const INSET_MARGIN: f64 = 0.2;

/// A window of u′v′ drawn into a pixel box.
#[derive(Debug, Clone, Copy)]
struct View {
    px: (f64, f64, f64, f64),
    u: (f64, f64),
    v: (f64, f64),
}

impl View {
    /// The pixel position of `uv` (u′, v′).
    fn at(&self, uv: [f64; 2]) -> (f64, f64) {
        let (l, t, r, b) = self.px;
        (
            l + (uv[0] - self.u.0) / (self.u.1 - self.u.0) * (r - l),
            b - (uv[1] - self.v.0) / (self.v.1 - self.v.0) * (b - t),
        )
    }

    /// `points` as an SVG `points` attribute.
    fn points(&self, points: &[[f64; 2]]) -> String {
        points
            .iter()
            .map(|p| {
                let (x, y) = self.at(*p);
                format!("{x:.2},{y:.2}")
            })
            .collect::<Vec<_>>()
            .join(" ")
    }
}

/// The spectral locus in u′v′ with its wavelengths, 360–700 nm every 5 nm.
fn spectral_locus() -> Vec<(f64, [f64; 2])> {
    let Ok(grid) = Grid::new(360.0, 700.0, 5.0) else {
        return Vec::new();
    };
    let Ok(observer) = Observer::cie1931(&grid) else {
        return Vec::new();
    };
    let (x, y, z) = (observer.cmf(0), observer.cmf(1), observer.cmf(2));
    grid.wavelengths()
        .into_iter()
        .enumerate()
        .filter_map(|(i, nm)| {
            let d = x[i] + 15.0 * y[i] + 3.0 * z[i];
            (d > 0.0).then(|| (nm, [4.0 * x[i] / d, 9.0 * y[i] / d]))
        })
        .collect()
}

/// The Planckian locus in u′v′, 1000–20,000 K in 2 % steps.
fn planckian_locus() -> Vec<[f64; 2]> {
    let mut out = Vec::new();
    let mut t = 1000.0_f64;
    while t <= 20000.0 {
        if let Ok(uv) = cct_to_uv_planck(t) {
            out.push(uv1960_to_uv1976(uv));
        }
        t *= 1.02;
    }
    out
}

/// The estimate's 95 % region in u′v′ (see the module's documentation), when its CCT is
/// meaningful (near the Planckian locus) and its CCT and Δuv have calibrated intervals.
pub fn region95(e: &Estimate) -> Option<Vec<[f64; 2]>> {
    crate::meaningful::cct_meaningful(e).ok()?;
    let (cct, duv) = (e.metrics.cct_k?, e.metrics.duv?);
    let u = e.trust.as_ref()?.uncertainty.as_ref()?;
    let (ht, hd) = (u.metrics.get("cct_k")?.half95, u.metrics.get("duv")?.half95);
    (0..48)
        .map(|i| {
            let a = std::f64::consts::TAU * f64::from(i) / 48.0;
            let t = (cct + ht * a.cos()).max(1000.0);
            cct_duv_to_uv(t, duv + hd * a.sin())
                .ok()
                .map(uv1960_to_uv1976)
        })
        .collect()
}

/// The u′v′ diagram of estimate `e` (and of its truth's chromaticity `truth_xy` when known)
/// as a self-contained SVG element.
pub fn uv_diagram_svg(e: &Estimate, truth_xy: Option<[f64; 2]>) -> String {
    let point = xy_to_uv1976(e.colorimetry.xy);
    let truth = truth_xy.map(xy_to_uv1976);
    let region = region95(e);
    let mut s = String::new();
    let _ = write!(
        s,
        "<svg class=\"uv-diagram\" viewBox=\"0 0 {} {}\" \
         role=\"img\" aria-label=\"CIE 1976 u′v′ chromaticity diagram with the estimate\" \
         font-family=\"sans-serif\">",
        SIZE.0, SIZE.1
    );
    let _ = write!(
        s,
        "<rect width=\"{}\" height=\"{}\" fill=\"#fff\"/>",
        SIZE.0, SIZE.1
    );
    let (l, t, r, b) = MAIN.px;
    for i in 0..=6 {
        let g = 0.1 * f64::from(i);
        let (x, _) = MAIN.at([g, 0.0]);
        let (_, y) = MAIN.at([0.0, g]);
        let _ = write!(
            s,
            "<line x1=\"{x:.1}\" x2=\"{x:.1}\" y1=\"{t}\" y2=\"{b}\" stroke=\"#eceef2\"/>\
             <text class=\"tick\" x=\"{x:.1}\" y=\"{:.1}\" font-size=\"{FONT}\" text-anchor=\"middle\" fill=\"#5b6475\">{g:.1}</text>\
             <line x1=\"{l}\" x2=\"{r}\" y1=\"{y:.1}\" y2=\"{y:.1}\" stroke=\"#eceef2\"/>",
            b + FONT + 1.0,
        );
        // The origin's 0.0 once, under the u′ axis.
        if i > 0 {
            let _ = write!(
                s,
                "<text class=\"tick\" x=\"{:.1}\" y=\"{:.1}\" font-size=\"{FONT}\" text-anchor=\"end\" fill=\"#5b6475\">{g:.1}</text>",
                l - 4.0,
                y + 5.0
            );
        }
    }
    let _ = write!(
        s,
        "<text x=\"{:.0}\" y=\"{:.0}\" font-size=\"{FONT}\" text-anchor=\"middle\">u′</text>\
         <text x=\"2\" y=\"{:.0}\" font-size=\"{FONT}\">v′</text>",
        MAIN.at([0.35, 0.0]).0,
        SIZE.1 - 2.0,
        MAIN.at([0.0, 0.35]).1 + 5.0
    );
    draw_view(&mut s, &MAIN, point, truth, region.as_deref(), true);
    // The inset: 0.06 × 0.06 around the estimate, wider when the region or the truth needs
    // it, so that each lies at least INSET_MARGIN of the inset's half-width inside it.
    let mut half = 0.03_f64;
    for p in region.iter().flatten().chain(truth.iter()) {
        half = half
            .max((p[0] - point[0]).abs() / (1.0 - INSET_MARGIN))
            .max((p[1] - point[1]).abs() / (1.0 - INSET_MARGIN));
    }
    let inset = View {
        px: INSET_PX,
        u: (point[0] - half, point[0] + half),
        v: (point[1] - half, point[1] + half),
    };
    let (il, it, ir, ib) = inset.px;
    let _ = write!(
        s,
        "<defs><clipPath id=\"uv-inset-clip\"><rect x=\"{il}\" y=\"{it}\" width=\"{}\" height=\"{}\"/></clipPath></defs>\
         <rect x=\"{il}\" y=\"{it}\" width=\"{}\" height=\"{}\" fill=\"#fff\" stroke=\"#1d2330\"/>\
         <g class=\"inset\" clip-path=\"url(#uv-inset-clip)\">",
        ir - il,
        ib - it,
        ir - il,
        ib - it
    );
    draw_view(&mut s, &inset, point, truth, region.as_deref(), false);
    let _ = write!(
        s,
        "</g><text x=\"{:.0}\" y=\"{:.0}\" font-size=\"{FONT}\" fill=\"#5b6475\">enlarged ±{}</text></svg>",
        il + 4.0,
        ib - 4.0,
        crate::rounding::round_sig(half, 1)
    );
    s
}

/// The loci, the isotemperature lines, the region, the truth and the point, in `view`;
/// wavelength and temperature labels when `labels`.
fn draw_view(
    s: &mut String,
    view: &View,
    point: [f64; 2],
    truth: Option<[f64; 2]>,
    region: Option<&[[f64; 2]]>,
    labels: bool,
) {
    let locus = spectral_locus();
    let pts: Vec<[f64; 2]> = locus.iter().map(|(_, p)| *p).collect();
    let _ = write!(
        s,
        "<polygon class=\"spectral-locus\" points=\"{}\" fill=\"#f7f3ea\" stroke=\"#1d2330\"/>",
        view.points(&pts)
    );
    if labels {
        for (nm, p) in locus
            .iter()
            .filter(|(nm, _)| [460.0, 480.0, 500.0, 520.0, 560.0, 600.0].contains(nm))
        {
            let (x, y) = view.at(*p);
            // Left of the locus where there is room; 500 and 520 nm lie by the v′ axis, so
            // their labels go inside the locus, clear of the axis's numbers.
            let (dx, anchor) = match p[0] {
                u if u < 0.05 => (7.0, "start"),
                u if u < 0.15 => (-7.0, "end"),
                _ => (7.0, "start"),
            };
            let _ = write!(
                s,
                "<text class=\"wavelength\" x=\"{:.1}\" y=\"{:.1}\" font-size=\"{FONT}\" fill=\"#5b6475\" text-anchor=\"{anchor}\">{nm:.0}</text>",
                x + dx,
                y + 5.0,
            );
        }
    }
    let _ = write!(
        s,
        "<polyline class=\"planckian\" points=\"{}\" fill=\"none\" stroke=\"#8a5a00\"/>",
        view.points(&planckian_locus())
    );
    for (k, above) in ISOTEMPERATURE_K {
        let (Ok(a), Ok(c)) = (cct_duv_to_uv(k, -0.05), cct_duv_to_uv(k, 0.05)) else {
            continue;
        };
        let (a, c) = (view.at(uv1960_to_uv1976(a)), view.at(uv1960_to_uv1976(c)));
        let _ = write!(
            s,
            "<line class=\"isotemperature\" data-k=\"{k:.0}\" x1=\"{:.2}\" y1=\"{:.2}\" x2=\"{:.2}\" y2=\"{:.2}\" stroke=\"#c9a34a\" stroke-width=\"0.8\"/>",
            a.0, a.1, c.0, c.1
        );
        if labels {
            // Beyond the line's labelled end, away from the locus.
            let (x, y) = if above {
                (c.0, c.1 - 4.0)
            } else {
                (a.0, a.1 + FONT)
            };
            let _ = write!(
                s,
                "<text class=\"cct-label\" x=\"{x:.1}\" y=\"{y:.1}\" font-size=\"{FONT}\" fill=\"#8a5a00\" text-anchor=\"middle\">{}</text>",
                k as u32
            );
        }
    }
    if let Some(region) = region {
        let _ = write!(
            s,
            "<polygon class=\"region95\" points=\"{}\" fill=\"#1f5fbf\" fill-opacity=\"0.18\" stroke=\"#1f5fbf\"/>",
            view.points(region)
        );
    }
    if let Some(t) = truth {
        let (x, y) = view.at(t);
        let _ = write!(
            s,
            "<path class=\"truth\" d=\"M{:.2} {:.2}l8 8m0 -8l-8 8\" stroke=\"#1d2330\" stroke-width=\"1.6\"/>",
            x - 4.0,
            y - 4.0
        );
    }
    let (x, y) = view.at(point);
    let _ = write!(
        s,
        "<circle class=\"estimate-point\" data-u=\"{:.4}\" data-v=\"{:.4}\" cx=\"{x:.2}\" cy=\"{y:.2}\" r=\"3.5\" fill=\"#1f5fbf\" stroke=\"#fff\"/>",
        point[0], point[1]
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The pixel positions of attribute `name` pairs in elements of `class`.
    fn attr(svg: &str, class: &str, name: &str) -> Vec<f64> {
        svg.split(&format!("class=\"{class}\""))
            .skip(1)
            .filter_map(|rest| {
                let at = rest.find(&format!(" {name}=\""))? + name.len() + 3;
                rest[at..].split('"').next()?.parse().ok()
            })
            .collect()
    }

    #[test]
    fn d65_sits_at_its_published_u_v_and_the_locus_passes_520_nm() {
        // D65: x 0.31271, y 0.32902 → u′ 0.1978, v′ 0.4683 (CIE 015:2018 Table T.3).
        let uv = xy_to_uv1976([0.31271, 0.32902]);
        assert!(
            (uv[0] - 0.1978).abs() < 1e-4 && (uv[1] - 0.4683).abs() < 1e-4,
            "{uv:?}"
        );
        let e = crate::test_support::estimate_of_d65();
        let svg = uv_diagram_svg(&e, Some([0.31271, 0.32902]));
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>"));
        // The point on the main panel, back from its pixels.
        let (cx, cy) = (
            attr(&svg, "estimate-point", "cx")[0],
            attr(&svg, "estimate-point", "cy")[0],
        );
        let (px, py) = MAIN.at([0.1978, 0.4683]);
        assert!(
            (cx - px).abs() < 1.0 && (cy - py).abs() < 1.0,
            "{cx} {cy} vs {px} {py}"
        );
        // D65 cut to 400–700 nm moves by less than 5·10⁻⁴.
        assert!((attr(&svg, "estimate-point", "data-u")[0] - 0.1978).abs() < 5e-4);
        assert!((attr(&svg, "estimate-point", "data-v")[0] - 0.4683).abs() < 5e-4);
        // The spectral locus passes 520 nm at x 0.0743, y 0.8338 (CIE 1931 table).
        let at520 = MAIN.at(xy_to_uv1976([0.0743, 0.8338]));
        let polygon = svg
            .split("class=\"spectral-locus\" points=\"")
            .nth(1)
            .unwrap();
        let near = polygon.split('"').next().unwrap().split(' ').any(|p| {
            let mut xy = p.split(',').map(|v| v.parse::<f64>().unwrap());
            let (x, y) = (xy.next().unwrap(), xy.next().unwrap());
            (x - at520.0).hypot(y - at520.1) < 1.5
        });
        assert!(near, "no locus point near 520 nm at {at520:?}");
        // Four isotemperature lines on each panel, and the truth drawn.
        assert_eq!(svg.matches("class=\"isotemperature\"").count(), 8);
        assert!(svg.contains("class=\"truth\""));
    }

    /// Each `<text>` of `svg` as (its estimated box left, top, right, bottom; its text): a
    /// sans-serif digit is about 0.56 em wide, a line from 0.75 em above the baseline to
    /// 0.2 em below it.
    fn text_boxes(svg: &str) -> Vec<([f64; 4], String)> {
        svg.split("<text ")
            .skip(1)
            .map(|rest| {
                let (attrs, after) = rest.split_once('>').unwrap();
                let content = after.split("</text>").next().unwrap().to_string();
                let get = |name: &str| -> String {
                    let at = attrs.find(&format!("{name}=\"")).unwrap() + name.len() + 2;
                    attrs[at..].split('"').next().unwrap().to_string()
                };
                let (x, y): (f64, f64) = (get("x").parse().unwrap(), get("y").parse().unwrap());
                let size: f64 = get("font-size").parse().unwrap();
                let w = 0.56 * size * content.chars().count() as f64;
                let anchor = if attrs.contains("text-anchor=") {
                    get("text-anchor")
                } else {
                    "start".into()
                };
                let left = match anchor.as_str() {
                    "middle" => x - w / 2.0,
                    "end" => x - w,
                    _ => x,
                };
                ([left, y - 0.75 * size, left + w, y + 0.2 * size], content)
            })
            .collect()
    }

    #[test]
    fn no_label_covers_another_and_the_truth_is_never_cut_by_the_inset() {
        let e = crate::test_support::estimate_of_d65();
        // A truth far off (the SG report's case): it widens the inset, not leaves it.
        let truth_xy = [0.36, 0.30];
        let svg = uv_diagram_svg(&e, Some(truth_xy));
        let boxes = text_boxes(&svg);
        assert!(boxes.len() > 20, "{}", boxes.len());
        for (i, (a, ta)) in boxes.iter().enumerate() {
            for (b, tb) in &boxes[i + 1..] {
                let apart = a[2] <= b[0] || b[2] <= a[0] || a[3] <= b[1] || b[3] <= a[1];
                assert!(apart, "'{ta}' {a:?} overlaps '{tb}' {b:?}");
            }
            // Nothing of the main panel hides under the inset but the inset's own label.
            let (l, t, r, bottom) = INSET_PX;
            let under = a[0] < r && a[2] > l && a[1] < bottom && a[3] > t;
            assert!(
                !under || ta.starts_with("enlarged"),
                "'{ta}' under the inset"
            );
        }
        assert!(svg
            .split("<text ")
            .skip(1)
            .all(|t| t.contains(&format!("font-size=\"{FONT}\""))));
        // The truth's × (8 units across) lies wholly inside the inset.
        let inset = svg.split("class=\"inset\"").nth(1).unwrap();
        let d = inset.split("class=\"truth\" d=\"M").nth(1).unwrap();
        let mut xy = d
            .split(['l', ' '])
            .take(2)
            .map(|v| v.parse::<f64>().unwrap());
        let (x, y) = (xy.next().unwrap(), xy.next().unwrap());
        let (l, t, r, b) = INSET_PX;
        assert!(
            x >= l && x + 8.0 <= r && y >= t && y + 8.0 <= b,
            "× at {x},{y} in {INSET_PX:?}"
        );
    }
}
