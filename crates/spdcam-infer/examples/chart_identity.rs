//! Measures the chart identity test (`spdcam_infer::trust::chart_identity`) on charts and on
//! images that hold none, as `docs/chart-identity.md` reports it; `tools/chart_identity.sh`
//! makes the inputs and runs it.
//!
//! ```text
//! chart_identity DATA_DIR SCENES.tsv NAME=FEATURES.csv…
//! ```
//!
//! `SCENES.tsv` lists scene photos of a chart, one a line: `path<TAB>x1,y1,…,x4,y4` (the
//! chart's true corners, as `spdcam render --scene` prints them). Each is estimated with its
//! detected corners and with the true ones; each also gives a crop where the chart is not.
//! The images with no chart (noise, gradients, flat, stripes, the crops) are made here,
//! seeded, each with five corner sets and both charts. Every row of each `FEATURES.csv` is
//! tested as a feature row. Prints per group the share accepted and each statistic's range;
//! writes every item's statistics to `chart-identity-items.tsv` in the working directory.

use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};
use spdcam_core::builtin::DataDir;
use spdcam_core::photo::{analyse as analyse_decoded, load_photo, AnalyseOptions, Photo};
use spdcam_core::spectral::Grid;
use spdcam_infer::trust::chart_identity::{
    MAX_SHUFFLED, MAX_TEXTURE, MIN_CONTRAST, MIN_NEUTRAL_ORDER,
};
use spdcam_infer::trust::Identity;
use spdcam_infer::{Estimator, FeatureRows, InferError, PhotoOptions};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Side of the generated no-chart images.
const SIZE: (usize, usize) = (640, 480);
/// The charts corners are placed for.
const CHARTS: [&str; 2] = ["colorchecker24", "colorchecker_sg96"];

/// One item measured: its group, name, whether a number came out, and its statistics.
struct Item {
    group: String,
    name: String,
    /// `accepted`, `refused` (not the chart) or `other: …` (refused for another reason).
    outcome: String,
    identity: Option<Identity>,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [data_dir, scenes, rows @ ..] = args.as_slice() else {
        return Err("usage: chart_identity DATA_DIR SCENES.tsv NAME=FEATURES.csv…".into());
    };
    let estimator = Estimator::shipped(
        DataDir::new(Some(PathBuf::from(data_dir))),
        Grid::ESTIMATION,
    )?;
    let mut items = Vec::new();
    for spec in rows {
        let (name, path) = spec.split_once('=').ok_or("rows are NAME=FEATURES.csv")?;
        let features = FeatureRows::read_csv(Path::new(path))?;
        for (k, identity) in estimator
            .row_identities(&features, path)?
            .into_iter()
            .enumerate()
        {
            let outcome = if identity.mismatches().is_empty() {
                "accepted"
            } else {
                "refused"
            };
            items.push(Item {
                group: format!("rows: {name}"),
                name: format!("row {}", k + 1),
                outcome: outcome.into(),
                identity: Some(identity),
            });
        }
    }
    let mut crops = Vec::new();
    for line in std::fs::read_to_string(scenes)?.lines() {
        let (path, corners) = line.split_once('\t').ok_or("scenes are PATH<TAB>CORNERS")?;
        let photo = load_photo(Path::new(path))?;
        let corners = parse_corners(corners)?;
        let name = Path::new(path).file_name().unwrap().to_string_lossy();
        for (how, options) in [
            ("detected", PhotoOptions::default()),
            (
                "true corners",
                PhotoOptions {
                    corners: Some(corners.clone()),
                    ..PhotoOptions::default()
                },
            ),
        ] {
            items.push(measure(
                &estimator,
                &photo,
                &options,
                &format!("scenes, {how}"),
                &name,
            ));
        }
        crops.push(crop_without_chart(&photo, &corners)?);
    }
    let mut no_chart = generated()?;
    no_chart.extend(crops.into_iter().map(|p| ("scene crops".to_string(), p)));
    for (group, photo) in &no_chart {
        for (k, corners) in corner_sets(photo.width, photo.height)
            .into_iter()
            .enumerate()
        {
            for chart in CHARTS {
                let options = PhotoOptions {
                    chart: Some(chart.into()),
                    corners: Some(corners.clone()),
                    ..PhotoOptions::default()
                };
                let name = format!("{} corners {} {chart}", photo.source, k + 1);
                items.push(measure(&estimator, photo, &options, group, &name));
            }
        }
    }
    print!("{}", summary(&items));
    let mut tsv =
        String::from("group\tname\toutcome\tcontrast\tneutral_order\tshuffled\ttexture\n");
    for item in &items {
        let id = item.identity.as_ref();
        let f = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.4}"));
        writeln!(
            tsv,
            "{}\t{}\t{}\t{}\t{}\t{}\t{}",
            item.group,
            item.name,
            item.outcome,
            f(id.map(|i| i.contrast)),
            f(id.and_then(|i| i.neutral_order)),
            f(id.and_then(|i| i.shuffled)),
            f(id.and_then(|i| i.texture)),
        )?;
    }
    std::fs::write("chart-identity-items.tsv", tsv)?;
    Ok(())
}

/// `x1,y1,…,x4,y4` as four points.
fn parse_corners(text: &str) -> Result<Vec<[f64; 2]>, Box<dyn std::error::Error>> {
    let v: Vec<f64> = text
        .split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<Result<_, _>>()?;
    if v.len() != 8 {
        return Err(format!("corners need eight numbers: {text}").into());
    }
    Ok(v.chunks(2).map(|p| [p[0], p[1]]).collect())
}

/// The photo estimated with `options`: what came out, and its identity when it was analysed.
fn measure(
    estimator: &Estimator,
    photo: &Photo,
    options: &PhotoOptions,
    group: &str,
    name: &str,
) -> Item {
    // Estimated as the estimator estimates; the statistics of what it took for the chart,
    // or, where it refused the patches, of the analysis it refused.
    let (outcome, identity) = match estimator.analyse_decoded(photo, options) {
        Ok(analysed) => {
            let identity = estimator.photo_identity(&analysed.analysis).ok();
            match estimator.estimate_analysis(analysed.analysis, name.into()) {
                Ok(_) => ("accepted".to_string(), identity),
                Err(e) => (format!("other: {e}"), identity),
            }
        }
        Err(InferError::NotTheChart(_)) => {
            let analysis = estimator
                .templates(options.chart.as_deref())
                .and_then(|templates| {
                    let analyse = AnalyseOptions {
                        templates,
                        corners: options.corners.clone(),
                        debug: None,
                    };
                    Ok(analyse_decoded(photo, &analyse)?)
                });
            let identity = analysis.and_then(|a| estimator.photo_identity(&a)).ok();
            ("refused".to_string(), identity)
        }
        Err(e) => (format!("other: {e}"), None),
    };
    Item {
        group: group.into(),
        name: name.into(),
        outcome,
        identity,
    }
}

/// A photo of `width × height` whose pixel (x, y) is `colour(x, y)` (0–1 per channel).
fn image(name: &str, colour: impl Fn(f64, f64) -> [f64; 3]) -> Result<Photo, InferError> {
    let (w, h) = SIZE;
    let mut data = Vec::with_capacity(w * h * 3);
    for y in 0..h {
        for x in 0..w {
            let c = colour(x as f64 / w as f64, y as f64 / h as f64);
            data.extend(c.map(|v| (255.0 * v.clamp(0.0, 1.0)).round() as u8));
        }
    }
    Ok(Photo::from_rgb8(name, w, h, data)?)
}

/// The generated images with no chart, by group, seeded.
fn generated() -> Result<Vec<(String, Photo)>, InferError> {
    let mut out = Vec::new();
    let mut rng = SmallRng::seed_from_u64(41);
    let colour = |rng: &mut SmallRng| -> [f64; 3] { std::array::from_fn(|_| rng.random()) };
    for seed in 0..3u64 {
        let mut r = SmallRng::seed_from_u64(seed);
        // Noise: per pixel, in 16-pixel blocks, and smooth (bilinear over an 8 × 6 grid).
        let pixels: Vec<[f64; 3]> = (0..SIZE.0 * SIZE.1).map(|_| colour(&mut r)).collect();
        out.push((
            "noise".into(),
            image(&format!("noise-{seed}"), |x, y| {
                pixels[(y * SIZE.1 as f64) as usize * SIZE.0 + (x * SIZE.0 as f64) as usize]
            })?,
        ));
        let blocks: Vec<[f64; 3]> = (0..40 * 30).map(|_| colour(&mut r)).collect();
        out.push((
            "noise".into(),
            image(&format!("blocks-{seed}"), |x, y| {
                blocks[(y * 30.0) as usize * 40 + (x * 40.0) as usize]
            })?,
        ));
        let knots: Vec<[f64; 3]> = (0..9 * 7).map(|_| colour(&mut r)).collect();
        out.push((
            "noise".into(),
            image(&format!("smooth-noise-{seed}"), |x, y| {
                let (gx, gy) = (x * 8.0, y * 6.0);
                let (i, j) = (gx.floor() as usize, gy.floor() as usize);
                let (fx, fy) = (gx.fract(), gy.fract());
                let k = |i: usize, j: usize| knots[j.min(6) * 9 + i.min(8)];
                std::array::from_fn(|c| {
                    (1.0 - fy) * ((1.0 - fx) * k(i, j)[c] + fx * k(i + 1, j)[c])
                        + fy * ((1.0 - fx) * k(i, j + 1)[c] + fx * k(i + 1, j + 1)[c])
                })
            })?,
        ));
        // Smooth gradients: linear between two colours, radial, and grey.
        let (a, b) = (colour(&mut rng), colour(&mut rng));
        let angle: f64 = rng.random_range(0.0..std::f64::consts::TAU);
        out.push((
            "gradients".into(),
            image(&format!("linear-{seed}"), |x, y| {
                let t = (0.5 + (x - 0.5) * angle.cos() + (y - 0.5) * angle.sin()).clamp(0.0, 1.0);
                std::array::from_fn(|c| a[c] + t * (b[c] - a[c]))
            })?,
        ));
        let (centre, edge) = (colour(&mut rng), colour(&mut rng));
        out.push((
            "gradients".into(),
            image(&format!("radial-{seed}"), |x, y| {
                let t = (2.0 * ((x - 0.5).powi(2) + (y - 0.5).powi(2)).sqrt()).min(1.0);
                std::array::from_fn(|c| centre[c] + t * (edge[c] - centre[c]))
            })?,
        ));
        let (lo, hi) = (rng.random_range(0.0..0.3), rng.random_range(0.6..1.0));
        out.push((
            "gradients".into(),
            image(&format!("grey-ramp-{seed}"), |x, y| {
                let v = lo + (hi - lo) * (if seed == 1 { y } else { x });
                [v; 3]
            })?,
        ));
        // Flat: a colour and a grey.
        let flat = colour(&mut rng);
        out.push(("flat".into(), image(&format!("flat-{seed}"), |_, _| flat)?));
        let grey: f64 = rng.random();
        out.push((
            "flat".into(),
            image(&format!("grey-{seed}"), |_, _| [grey; 3])?,
        ));
        // Stripes: vertical, horizontal and diagonal, of random colours and width.
        let colours: Vec<[f64; 3]> = (0..12).map(|_| colour(&mut rng)).collect();
        let period: f64 = rng.random_range(0.03..0.2);
        for (kind, along) in [("vertical", 0), ("horizontal", 1), ("diagonal", 2)] {
            let colours = colours.clone();
            out.push((
                "stripes".into(),
                image(&format!("stripes-{kind}-{seed}"), move |x, y| {
                    let t = match along {
                        0 => x,
                        1 => y,
                        _ => (x + y) / 2.0,
                    };
                    colours[(t / period) as usize % colours.len()]
                })?,
            ));
        }
    }
    Ok(out)
}

/// The widest band of `photo` (left, right, above or below the chart) that holds no part of
/// the chart with corners `corners`, as a photo of its own.
fn crop_without_chart(photo: &Photo, corners: &[[f64; 2]]) -> Result<Photo, InferError> {
    let xs = corners.iter().map(|p| p[0]);
    let ys = corners.iter().map(|p| p[1]);
    let margin = 8.0;
    let (x0, x1) = (
        xs.clone().fold(f64::INFINITY, f64::min) - margin,
        xs.fold(0.0, f64::max) + margin,
    );
    let (y0, y1) = (
        ys.clone().fold(f64::INFINITY, f64::min) - margin,
        ys.fold(0.0, f64::max) + margin,
    );
    let (w, h) = (photo.width as f64, photo.height as f64);
    // (x, y, width, height) of the four bands, the largest taken.
    let bands = [
        (0.0, 0.0, x0.max(0.0), h),
        (x1.min(w), 0.0, w - x1.min(w), h),
        (0.0, 0.0, w, y0.max(0.0)),
        (0.0, y1.min(h), w, h - y1.min(h)),
    ];
    let (bx, by, bw, bh) = bands
        .into_iter()
        .max_by(|a, b| (a.2 * a.3).total_cmp(&(b.2 * b.3)))
        .unwrap();
    let (bx, by, bw, bh) = (bx as usize, by as usize, bw as usize, bh as usize);
    let mut data = Vec::with_capacity(bw * bh * 3);
    for y in by..by + bh {
        for x in bx..bx + bw {
            data.extend(photo.pixel(x, y).map(|v| (255.0 * v).round() as u8));
        }
    }
    let name = format!(
        "crop of {}",
        Path::new(&photo.source)
            .file_name()
            .unwrap()
            .to_string_lossy()
    );
    Ok(Photo::from_rgb8(&name, bw, bh, data)?)
}

/// Five corner sets inside a `width × height` image: an inset rectangle, a near-square, a
/// skewed quadrilateral, a small rectangle of a chart's shape, and a rotated rectangle.
fn corner_sets(width: usize, height: usize) -> Vec<Vec<[f64; 2]>> {
    let (w, h) = (width as f64, height as f64);
    let at = |pts: [[f64; 2]; 4]| pts.iter().map(|p| [p[0] * w, p[1] * h]).collect::<Vec<_>>();
    let side = 0.6 * w.min(h);
    let square = {
        let (cx, cy) = (w / 2.0, h / 2.0);
        let s = side / 2.0;
        vec![
            [cx - s, cy - s * 0.95],
            [cx + s, cy - s],
            [cx + s * 0.97, cy + s],
            [cx - s, cy + s],
        ]
    };
    let rotated = {
        let (cx, cy, a) = (w / 2.0, h / 2.0, 20f64.to_radians());
        // Half sides, shrunk until the turned rectangle lies inside the image.
        let (hw, hh) = (0.3 * w, 0.2 * h);
        let fit = (0.45 * h / (hw * a.sin() + hh * a.cos()))
            .min(0.45 * w / (hw * a.cos() + hh * a.sin()))
            .min(1.0);
        let (hw, hh) = (hw * fit, hh * fit);
        [[-hw, -hh], [hw, -hh], [hw, hh], [-hw, hh]]
            .iter()
            .map(|p| {
                [
                    cx + p[0] * a.cos() - p[1] * a.sin(),
                    cy + p[0] * a.sin() + p[1] * a.cos(),
                ]
            })
            .collect()
    };
    vec![
        at([[0.1, 0.1], [0.9, 0.1], [0.9, 0.9], [0.1, 0.9]]),
        square,
        at([[0.15, 0.2], [0.85, 0.1], [0.9, 0.85], [0.1, 0.75]]),
        at([[0.05, 0.55], [0.45, 0.55], [0.45, 0.82], [0.05, 0.82]]),
        rotated,
    ]
}

/// Per group: items, the share accepted, refused as not the chart, refused otherwise, and
/// each statistic's range; then each statistic's threshold.
fn summary(items: &[Item]) -> String {
    let mut groups: BTreeMap<&str, Vec<&Item>> = BTreeMap::new();
    for item in items {
        groups.entry(&item.group).or_default().push(item);
    }
    let mut out = String::from(
        "| group | items | accepted | refused: not the chart | refused otherwise | contrast | neutral order | shuffled | texture |\n\
         | --- | --: | --: | --: | --: | --- | --- | --- | --- |\n",
    );
    for (group, members) in &groups {
        let n = members.len();
        let share = |what: &dyn Fn(&str) -> bool| {
            let k = members.iter().filter(|i| what(&i.outcome)).count();
            format!("{k} ({:.0} %)", 100.0 * k as f64 / n as f64)
        };
        let range = |get: &dyn Fn(&Identity) -> Option<f64>| {
            let values: Vec<f64> = members
                .iter()
                .filter_map(|i| i.identity.as_ref().and_then(get))
                .collect();
            if values.is_empty() {
                return "–".to_string();
            }
            let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            format!("{lo:.3}–{hi:.3}")
        };
        let _ = writeln!(
            out,
            "| {group} | {n} | {} | {} | {} | {} | {} | {} | {} |",
            share(&|o| o == "accepted"),
            share(&|o| o == "refused"),
            share(&|o| o.starts_with("other")),
            range(&|i| Some(i.contrast)),
            range(&|i| i.neutral_order),
            range(&|i| i.shuffled),
            range(&|i| i.texture),
        );
    }
    // Per statistic: the charts' worst value, the no-chart items it refuses and, of them,
    // the value nearest to the threshold.
    let chart = |i: &&Item| i.group.starts_with("rows") || i.group.starts_with("scenes");
    let no_chart = items.iter().filter(|i| !chart(i)).count();
    out.push_str(
        "\n| statistic | threshold | charts: worst | no chart refused by it | of those, nearest |\n\
         | --- | --- | --: | --: | --: |\n",
    );
    type Get = fn(&Identity) -> Option<f64>;
    let stats: [(&str, &str, f64, bool, Get); 4] = [
        ("contrast", "≥", MIN_CONTRAST, false, |i| Some(i.contrast)),
        ("neutral order", "≥", MIN_NEUTRAL_ORDER, false, |i| {
            i.neutral_order
        }),
        ("shuffled", "≤", MAX_SHUFFLED, true, |i| i.shuffled),
        ("texture", "≤", MAX_TEXTURE, true, |i| i.texture),
    ];
    for (name, sign, level, high_is_bad, get) in stats {
        let values = |want: bool| -> Vec<f64> {
            items
                .iter()
                .filter(|i| chart(i) == want)
                .filter_map(|i| i.identity.as_ref().and_then(get))
                .collect()
        };
        let bad = |v: f64| if high_is_bad { v > level } else { v < level };
        let refused: Vec<f64> = values(false).into_iter().filter(|&v| bad(v)).collect();
        // The worst of `v`: the largest where high is bad, else the smallest.
        let worst = |v: &[f64], high: bool| {
            v.iter().copied().fold(None, |a: Option<f64>, x| {
                Some(a.map_or(x, |a| if high { a.max(x) } else { a.min(x) }))
            })
        };
        let shown = |v: Option<f64>| v.map_or("–".to_string(), |v| format!("{v:.3}"));
        let _ = writeln!(
            out,
            "| {name} | {sign} {level} | {} | {} of {no_chart} | {} |",
            shown(worst(&values(true), high_is_bad)),
            refused.len(),
            shown(worst(&refused, !high_is_bad)),
        );
    }
    let _ = writeln!(
        out,
        "\nThresholds: contrast ≥ {MIN_CONTRAST}, neutral order ≥ {MIN_NEUTRAL_ORDER}, shuffled ≤ {MAX_SHUFFLED}, texture ≤ {MAX_TEXTURE}."
    );
    out
}
