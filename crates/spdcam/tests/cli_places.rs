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
