//! The lighting recipes against the thesis's rules and its luminaire, and their errors.

#![cfg(feature = "measured-data")]

mod shared_data;

use spdcam_core::builtin::DataDir;
use spdcam_core::light_families::{catalogue, Lighting};
use spdcam_core::spectral::Grid;

const GRID: Grid = Grid::SIMULATION;

fn data_dir() -> DataDir {
    DataDir::new(Some(shared_data::data_dir()))
}

fn parse(spec: &str) -> spdcam_core::Result<Lighting> {
    Lighting::parse(spec, &data_dir(), &GRID)
}

#[test]
fn telelumen_valid_ratios_match_the_thesis() {
    // Table 5.1 of the thesis: valid settings of 3170 per configuration.
    for (preset, thesis) in [
        ("config1", 2167.0),
        ("config2", 2395.0),
        ("config3", 2631.0),
    ] {
        let lighting = parse(&format!("telelumen:{preset}")).unwrap();
        let draws = 6000u64;
        let attempts: u64 = (0..draws)
            .map(|i| u64::from(lighting.draw(11, i).unwrap().attempts))
            .sum();
        let ratio = draws as f64 / attempts as f64;
        let expected = thesis / 3170.0;
        println!("{preset}: valid ratio {ratio:.4} (thesis {expected:.4})");
        assert!(
            (ratio - expected).abs() < 0.02,
            "{preset}: {ratio} against {expected}"
        );
    }
}

#[test]
fn seven_of_seventeen_leaves_uv_and_ir_dark() {
    let lighting = parse("telelumen:config1").unwrap();
    assert_eq!(lighting.weight_names().unwrap().len(), 24);
    for i in 0..300 {
        let draw = lighting.draw(5, i).unwrap();
        let w = draw.weights.unwrap();
        assert_eq!(w.len(), 24);
        assert!(w[..2].iter().chain(&w[19..]).all(|&x| x == 0.0), "{w:?}");
        assert_eq!(w[2..19].iter().filter(|&&x| x > 0.0).count(), 7);
        assert!(w.iter().all(|&x| x <= 1.0));
        assert_eq!(draw.family, "leds");
        let max = draw.spd.iter().cloned().fold(0.0, f64::max);
        assert!((max - 1.0).abs() < 1e-12);
        // The SPD is the weighted sum of the channels, normalised.
        let channels = lighting.channels().unwrap();
        assert_eq!(channels.combine(&w).unwrap(), draw.spd.values());
    }
}

#[test]
fn same_seed_same_lights() {
    let lighting =
        parse("mix:telelumen:config2=0.5,daylight=0.2,planck=0.1,phosphor=0.1,fluorescent=0.1")
            .unwrap();
    let a: Vec<_> = (0..50).map(|i| lighting.draw(3, i).unwrap()).collect();
    let b: Vec<_> = (0..50)
        .rev()
        .map(|i| lighting.draw(3, i).unwrap())
        .collect();
    assert!(a.iter().zip(b.iter().rev()).all(|(x, y)| x == y));
    assert_ne!(lighting.draw(4, 0).unwrap(), a[0]);
    // Every member shows up, and weights are recorded for every draw of a mixture with a
    // weighted member (zeros for the others).
    let families: std::collections::BTreeSet<_> = (0..400)
        .map(|i| lighting.draw(3, i).unwrap().family)
        .collect();
    assert_eq!(families.len(), 5, "{families:?}");
    assert!(a
        .iter()
        .all(|d| d.weights.as_ref().is_some_and(|w| w.len() == 24)));
}

#[test]
fn every_catalogue_family_draws_normalised_lights() {
    let dir = std::env::temp_dir().join("spdcam-lighting-spds");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("two.csv");
    std::fs::write(&file, "wavelength_nm,a,b\n380,1,0\n580,0.5,0.5\n780,0,1\n").unwrap();
    let specs = [
        "gaussian:4".to_string(),
        "gaussian:9".to_string(),
        "telelumen:h1".to_string(),
        "telelumen:h2".to_string(),
        "daylight".to_string(),
        "planck:2000-3000".to_string(),
        "phosphor".to_string(),
        "fluorescent".to_string(),
        format!("spds:{}", file.display()),
        format!("spds:{}:mix", file.display()),
    ];
    assert!(catalogue().len() >= 9);
    for spec in &specs {
        let lighting = parse(spec).unwrap();
        for i in 0..20 {
            let draw = lighting.draw(1, i).unwrap();
            assert_eq!(draw.spd.len(), GRID.count, "{spec}");
            let max = draw.spd.iter().cloned().fold(0.0, f64::max);
            assert!((max - 1.0).abs() < 1e-9, "{spec}: max {max}");
            assert!(draw.spd.iter().all(|&v| v >= 0.0), "{spec}");
        }
    }
    let h1 = parse("telelumen:h1").unwrap().draw(2, 0).unwrap();
    assert_eq!(h1.weights.unwrap().iter().filter(|&&w| w > 0.0).count(), 7);
}

#[test]
fn bad_recipes_are_named() {
    let dir = std::env::temp_dir().join("spdcam-lighting-bad");
    std::fs::create_dir_all(&dir).unwrap();
    let ragged = dir.join("ragged.csv");
    std::fs::write(&ragged, "wavelength_nm,a,b\n400,1,0\n500,0.5\n600,0,1\n").unwrap();
    let ragged = ragged.display().to_string();
    let cases = [
        ("candle:3".to_string(), "unknown lighting family 'candle'"),
        ("gaussian:x".to_string(), "whole number"),
        ("telelumen:config1:k=30".to_string(), "Telelumen preset"),
        (format!("leds:{ragged}"), "ragged.csv"),
        ("telelumen:config9".to_string(), "config1, config2"),
        ("daylight:3000-9000".to_string(), "within 4000–25000 K"),
        ("mix:daylight=0.5,planck".to_string(), "needs a proportion"),
        ("mix:daylight=-1".to_string(), "positive number"),
    ];
    for (spec, expected) in &cases {
        let err = parse(spec).unwrap_err().to_string();
        assert!(err.contains(expected), "{spec}: {err}");
    }
    let channels = shared_data::data_dir().join("thesis/telelumen_24_channels.csv");
    let leds = channels.display();
    for (options, expected) in [
        ("k=30", "k = 30"),
        ("max=1.5", "max = 1.5"),
        ("max=0", "outside (0, 1]"),
        ("lit=3-30", "channel 25 does not exist"),
        ("budget=-2", "positive"),
        ("colour=red", "unknown option 'colour'"),
    ] {
        let err = parse(&format!("leds:{leds}:{options}"))
            .unwrap_err()
            .to_string();
        assert!(err.contains(expected), "{options}: {err}");
    }
}
