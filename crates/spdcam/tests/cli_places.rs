//! The light at several places from the command line: `render --scene --place` writes a
//! photo of several charts with one truth column per place, and `estimate` gives one
//! estimate per chart, numbered from left to right, scored against its own truth, with the
//! comparison across places printed and in `--json`.

mod common;

use common::{fails, ok, s, scratch};

/// The example photo: a ColorChecker 24 under CIE A at the left; two under D65 at the
/// right, the lower one in shade at 0.4 of the light (`examples/cc24-two-lights.jpg`, made
/// by the command in the README).
const EXAMPLE: &str = "../../examples/cc24-two-lights.jpg";

#[test]
fn every_chart_of_the_example_is_estimated_and_the_lights_are_told_apart() {
    let out = ok(&["estimate", EXAMPLE]);
    for k in 1..=3 {
        assert!(
            out.contains(&format!("cc24-two-lights.jpg place {k}: xy")),
            "{out}"
        );
    }
    // Each place scored against its own column of the truth beside the photo.
    let scores: Vec<f64> = out
        .lines()
        .filter_map(|l| l.split("against the true SPD: GFC ").nth(1))
        .map(|t| t.split(',').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(scores.len(), 3, "{out}");
    assert!(scores.iter().all(|&g| g > 0.95), "{scores:?}");
    assert!(out.contains("the light across the 3 places"), "{out}");
    assert!(
        out.contains("the lights differ: the greys of places 1 and"),
        "{out}"
    );
    assert!(out.contains("place 1 differs most"), "{out}");
    // The report shows each place on one drawing of the photo with every place numbered.
    let dir = scratch("places-report");
    let report = dir.join("places.html");
    ok(&["estimate", EXAMPLE, "--report", &s(&report)]);
    let html = std::fs::read_to_string(&report).unwrap();
    let photos: Vec<&str> = html
        .split("data:image/jpeg;base64,")
        .skip(1)
        .map(|t| t.split('"').next().unwrap())
        .collect();
    assert_eq!(photos.len(), 3, "one photo per place");
    assert!(
        photos.iter().all(|p| *p == photos[0]),
        "one drawing of every place"
    );
}

#[test]
fn the_json_says_where_each_chart_is_and_how_the_places_compare() {
    let json: serde_json::Value =
        serde_json::from_str(&ok(&["estimate", EXAMPLE, "--json"])).unwrap();
    let estimates = json.as_array().unwrap();
    assert_eq!(estimates.len(), 3);
    let mut last_x = 0.0;
    for (k, e) in estimates.iter().enumerate() {
        let place = &e["photo"]["place"];
        assert_eq!(place["number"], k + 1);
        assert_eq!(place["of"], 3);
        let x = place["centre"][0].as_f64().unwrap();
        assert!(x > last_x, "numbered from left to right");
        last_x = x;
        assert!(e["light_level"]["level"].as_f64().unwrap() > 0.0);
    }
    let across = &estimates[0]["across_places"];
    assert_eq!(across, &estimates[2]["across_places"]);
    assert_eq!(across["lights_differ"], true);
    assert_eq!(across["most_different"], 1);
    // The render's true levels: 1, 0.979 and 0.392 of the first place (the brightest is
    // place 2): each within 5 % of the truth.
    let levels: Vec<f64> = across["places"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["relative_illuminance"].as_f64().unwrap())
        .collect();
    for (got, want) in levels.iter().zip([1.0 / 0.979, 1.0, 0.392 / 0.979]) {
        assert!((got / want - 1.0).abs() < 0.05, "{levels:?}");
    }
    // Places 2 and 3 share D65: their greys agree far within the threshold.
    let grey = |k: usize| {
        let g = &across["places"][k]["grey_uv_prime"];
        [g[0].as_f64().unwrap(), g[1].as_f64().unwrap()]
    };
    let (a, b) = (grey(1), grey(2));
    assert!((a[0] - b[0]).hypot(a[1] - b[1]) < 0.003);
}

#[test]
fn render_places_charts_writes_one_truth_per_place_and_refuses_overlaps() {
    let dir = scratch("places");
    let photo = dir.join("one-light.jpg");
    let truth = dir.join("one-light.truth.csv");
    let out = ok(&[
        "render",
        "--spd",
        "D50",
        "--scene",
        "1200x800",
        "--place",
        "centre=0.7,0.5 width=0.25",
        "--place",
        "centre=0.25,0.5 width=0.25 level=0.5",
        "-o",
        &s(&photo),
        "--spd-out",
        &s(&truth),
    ]);
    // Numbered from left to right: the second --place is place 1.
    assert!(out.contains("place 1: colorchecker24 under D50"), "{out}");
    assert!(out.contains("light level 0.500"), "{out}");
    let header = std::fs::read_to_string(&truth).unwrap();
    assert!(
        header.starts_with("wavelength_nm,place 1,place 2\n"),
        "{header}"
    );
    let estimated = ok(&["estimate", &s(&photo)]);
    assert!(
        estimated.contains("one light in colour: the greys agree"),
        "{estimated}"
    );
    // The shaded place 1 at half the light of place 2.
    let level = estimated
        .split("light level against the brightest place: place 1 ")
        .nth(1)
        .and_then(|t| t.split(" %").next())
        .and_then(|t| t.parse::<f64>().ok())
        .expect(&estimated);
    assert!((level - 50.0).abs() <= 2.5, "{estimated}");
    // Refusals, each naming what is wrong, with no photo written.
    let refused = |places: &[&str], name: &str| {
        let out = dir.join(name);
        let out_text = s(&out);
        let mut args = vec!["render", "--spd", "D50", "--scene", "1200x800"];
        for &p in places {
            args.extend(["--place", p]);
        }
        args.extend(["-o", out_text.as_str()]);
        let e = fails(&args);
        assert!(!out.exists(), "{name} was written");
        e
    };
    let e = refused(
        &["centre=0.45,0.5 width=0.3", "centre=0.55,0.5 width=0.3"],
        "overlap.jpg",
    );
    assert!(e.contains("charts 1 and 2 of the scene overlap"), "{e}");
    let e = refused(&["width=0.3"], "bad.jpg");
    assert!(e.contains("needs centre=X,Y"), "{e}");
}

#[test]
fn a_passport_in_its_case_is_one_chart_and_its_other_page_none() {
    let dir = scratch("passport");
    for (page, rotation) in [("creative", "8"), ("white-balance", "190")] {
        let photo = dir.join(format!("passport-{page}.jpg"));
        let truth = dir.join(format!("passport-{page}.truth.csv"));
        let centre = if rotation == "8" {
            "0.3,0.5"
        } else {
            "0.7,0.5"
        };
        ok(&[
            "render",
            "--spd",
            "cct:4000",
            "--scene",
            "1600x1000",
            "--place",
            &format!("centre={centre} width=0.28 rotation={rotation} passport={page}"),
            "-o",
            &s(&photo),
            "--spd-out",
            &s(&truth),
        ]);
        let out = ok(&["estimate", &s(&photo)]);
        // One chart: no place numbers, no comparison across places, scored as good.
        assert!(out.contains("ColorChecker 24 detected"), "{page}: {out}");
        assert!(!out.contains(" place "), "{page}: {out}");
        let gfc: f64 = out
            .split("against the true SPD: GFC ")
            .nth(1)
            .and_then(|t| t.split(',').next())
            .and_then(|t| t.parse().ok())
            .expect(&out);
        assert!(gfc > 0.95, "{page}: GFC {gfc}");
    }
    let e = fails(&[
        "render",
        "--spd",
        "D50",
        "--scene",
        "1200x800",
        "--place",
        "centre=0.3,0.5 width=0.25 passport=cover",
        "-o",
        &s(&dir.join("cover.jpg")),
    ]);
    assert!(
        e.contains("passport=creative or passport=white-balance"),
        "{e}"
    );
}

#[test]
fn corners_given_once_per_chart_place_each_chart() {
    // The example's three charts: their corners from the detection, given back by hand.
    let json: serde_json::Value =
        serde_json::from_str(&ok(&["estimate", EXAMPLE, "--json"])).unwrap();
    let corners: Vec<String> = json
        .as_array()
        .unwrap()
        .iter()
        .map(|e| {
            e["photo"]["corners"]
                .as_array()
                .unwrap()
                .iter()
                .flat_map(|p| p.as_array().unwrap().iter().map(|v| v.as_f64().unwrap()))
                .map(|v| format!("{v:.1}"))
                .collect::<Vec<_>>()
                .join(",")
        })
        .collect();
    assert_eq!(corners.len(), 3);
    // Given right to left, numbered left to right all the same.
    let mut args = vec!["estimate", EXAMPLE, "--json"];
    for c in corners.iter().rev() {
        args.extend(["--corners", c.as_str()]);
    }
    let placed: serde_json::Value = serde_json::from_str(&ok(&args)).unwrap();
    let placed = placed.as_array().unwrap();
    assert_eq!(placed.len(), 3);
    for (k, (by_hand, found)) in placed.iter().zip(json.as_array().unwrap()).enumerate() {
        assert_eq!(by_hand["photo"]["place"]["number"], k + 1);
        assert_eq!(by_hand["photo"]["method"], "corners");
        let (a, b) = (&by_hand["colorimetry"]["xy"], &found["colorimetry"]["xy"]);
        let d = (a[0].as_f64().unwrap() - b[0].as_f64().unwrap())
            .hypot(a[1].as_f64().unwrap() - b[1].as_f64().unwrap());
        assert!(d < 0.005, "place {}: {a} against {b}", k + 1);
    }
    assert_eq!(placed[0]["across_places"]["lights_differ"], true);
    // A set of corners short of four points is refused, naming the option.
    let e = fails(&[
        "estimate",
        EXAMPLE,
        "--corners",
        &corners[0],
        "--corners",
        "1,2,3,4",
    ]);
    assert!(e.contains("--corners needs eight numbers"), "{e}");
}

/// The example ColorChecker 24 photo with, on a canvas as wide again to its right, a dark
/// board of six by four squares: the chart's grey row in its place, the other eighteen
/// six saturated colours in turn. Detection takes it for a second chart; its colours say
/// it is not one (as the white-balance page of a ColorChecker Passport opened above its
/// ColorChecker 24 was read in a public raw photo).
fn chart_beside_a_grid_that_is_not_one(path: &std::path::Path) {
    let photo = image::open("../../examples/cc24-led.jpg")
        .unwrap()
        .to_rgb8();
    let (w, h) = photo.dimensions();
    let mut canvas = image::RgbImage::from_pixel(2 * w, h, image::Rgb([128, 120, 110]));
    image::imageops::replace(&mut canvas, &photo, 0, 0);
    let board_w = f64::from(w) * 0.8;
    let (x0, y0) = (
        f64::from(w) * 1.1,
        (f64::from(h) - board_w * 4.0 / 6.0) / 2.0,
    );
    let pitch = board_w / 6.4;
    let fill = |canvas: &mut image::RgbImage, x: f64, y: f64, side_x: f64, side_y: f64, c| {
        for py in y as u32..(y + side_y) as u32 {
            for px in x as u32..(x + side_x) as u32 {
                canvas.put_pixel(px, py, image::Rgb(c));
            }
        }
    };
    fill(
        &mut canvas,
        x0,
        y0,
        board_w,
        board_w * 4.0 / 6.0,
        [25, 25, 25],
    );
    let greys = [243, 200, 160, 122, 85, 52];
    let colours = [
        [200, 40, 40],
        [40, 170, 60],
        [50, 60, 190],
        [40, 170, 180],
        [180, 50, 170],
        [220, 200, 40],
    ];
    for r in 0..4 {
        for c in 0..6 {
            let colour = if r == 3 {
                [greys[c]; 3]
            } else {
                colours[(r * 6 + c) % 6]
            };
            let x = x0 + pitch * (0.3 + c as f64);
            let y = y0 + pitch * (0.25 + r as f64);
            fill(&mut canvas, x, y, pitch * 0.8, pitch * 0.8, colour);
        }
    }
    canvas.save(path).unwrap();
}

#[test]
fn a_grid_beside_the_chart_that_is_not_a_chart_is_left_out_with_a_note() {
    let dir = scratch("places-not-a-chart");
    let photo = dir.join("chart-and-grid.png");
    chart_beside_a_grid_that_is_not_one(&photo);
    let run = common::spdcam(&["estimate", &s(&photo)]);
    let (out, said) = (
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr),
    );
    assert!(run.status.success(), "{out}\n{said}");
    assert!(
        said.contains("chart-and-grid.png: a grid of patches at")
            && said.contains("was left out: it is not a ColorChecker 24 (the patches' colours"),
        "{said}"
    );
    // One estimate, of the chart, not numbered as a place; the command succeeds.
    assert!(out.contains("chart-and-grid.png: xy"), "{out}");
    assert!(!out.contains(" place "), "{out}");
    let json: serde_json::Value =
        serde_json::from_str(&ok(&["estimate", &s(&photo), "--json"])).unwrap();
    assert_eq!(json.as_array().unwrap().len(), 1, "{json}");
}
