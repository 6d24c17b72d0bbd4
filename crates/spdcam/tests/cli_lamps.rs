//! Real lamps from the command line: `spdcam coverage` on SPDs a test writes, the `lamp:` and
//! `blend:` recipes, and (with the measured data) the validation split and protocol.

mod common;

use common::{fails, ok, s, scratch};
use std::path::{Path, PathBuf};

/// The cells of the table row whose first cell starts with `label`.
fn row<'a>(table: &'a str, label: &str) -> Vec<&'a str> {
    let line = table
        .lines()
        .find(|l| l.trim_start_matches("| ").starts_with(label))
        .unwrap_or_else(|| panic!("no row {label} in\n{table}"));
    line.split('|')
        .map(str::trim)
        .filter(|c| !c.is_empty())
        .collect()
}

/// The mean of a `mean (worst)` cell.
fn mean(cell: &str) -> f64 {
    cell.split_whitespace().next().unwrap().parse().unwrap()
}

/// Two Planckian lamps (2,700 K and 3,000 K, by Planck's law) and a narrow green line.
fn write_lamps(dir: &Path) -> (PathBuf, PathBuf) {
    let planck = |nm: f64, t: f64| {
        let l = nm * 1e-9;
        1.0 / (l.powi(5) * ((1.4388e-2 / (l * t)).exp() - 1.0))
    };
    let mut csv = String::from("wavelength_nm,warm,warmer,green line\n");
    for k in 0..81 {
        let nm = 380.0 + 5.0 * k as f64;
        let line = (-((nm - 530.0) / 4.0).powi(2)).exp();
        csv += &format!(
            "{nm},{},{},{line}\n",
            planck(nm, 3000.0),
            planck(nm, 2700.0)
        );
    }
    let spds = dir.join("lamps.csv");
    std::fs::write(&spds, csv).unwrap();
    let info = dir.join("info.csv");
    std::fs::write(
        &info,
        "column,type,category\nwarm,Incandescent/Filament,Commercial\nwarmer,Incandescent/Filament,Commercial\ngreen line,LED Mixed,Experimental\n",
    )
    .unwrap();
    (spds, info)
}

#[test]
fn coverage_finds_planckian_lamps_in_planck_and_not_in_a_narrow_range() {
    let dir = scratch("coverage");
    let (spds, info) = write_lamps(&dir);
    let table = dir.join("coverage.md");
    let per_lamp = dir.join("per-lamp.csv");
    let out = ok(&[
        "coverage",
        &s(&spds),
        "--types",
        &s(&info),
        "--lighting",
        "planck:2000-4000",
        "--lighting",
        "planck:8000-10000",
        "--draws",
        "2000",
        "-o",
        &s(&table),
        "--per-lamp",
        &s(&per_lamp),
    ]);
    assert_eq!(std::fs::read_to_string(&table).unwrap(), out);
    // Columns: the types in report order (mixed-colour LED: the line; incandescent: the two
    // Planckians), then all.
    let header = row(&out, "recipe");
    assert!(header[1].starts_with("mixed-colour LED (1)"), "{out}");
    assert!(header[2].starts_with("incandescent/halogen (2)"), "{out}");
    // Planckian lamps inside the drawn range are met almost exactly; a 8,000–10,000 K
    // radiator is far from a 2,700–3,000 K one.
    let near = row(&out, "`planck:2000-4000`");
    let far = row(&out, "`planck:8000-10000`");
    assert!(mean(near[2]) > 0.9999, "{out}");
    assert!(mean(far[2]) < 0.95, "{out}");
    // A narrow line is covered by neither.
    assert!(mean(near[1]) < 0.6 && mean(far[1]) < 0.6, "{out}");
    // The family model of each lamp's type, fitted: the mixed-LED family reaches a narrow
    // line, the filament family a Planckian.
    let fitted = row(&out, "family model");
    assert!(mean(fitted[1]) > 0.99 && mean(fitted[2]) > 0.999, "{out}");
    let csv = std::fs::read_to_string(&per_lamp).unwrap();
    assert_eq!(csv.lines().count(), 4, "{csv}");
    assert!(csv.starts_with("lamp,type,"), "{csv}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn lamp_recipes_are_listed_and_bad_ones_named() {
    let list = ok(&["list", "lighting"]);
    for family in [
        "lamp:phosphor-led",
        "lamp:hybrid-led",
        "lamp:mixed-led",
        "lamp:fluorescent",
        "lamp:hid",
        "lamp:incandescent",
        "blend:",
    ] {
        assert!(list.contains(family), "{family} missing:\n{list}");
    }
    let dir = scratch("recipes");
    let (spds, _) = write_lamps(&dir);
    let err = fails(&["coverage", &s(&spds), "--lighting", "lamp:candle"]);
    assert!(
        err.contains("lamp family 'candle'") && err.contains("phosphor-led"),
        "{err}"
    );
    let err = fails(&["coverage", &s(&spds), "--lighting", "lamp:hid:spread=wide"]);
    assert!(err.contains("spread 'wide'"), "{err}");
    // A lamp family and a blend with daylight draw (the built-in fits need no data).
    let out = ok(&[
        "coverage",
        &s(&spds),
        "--lighting",
        "blend:daylight+lamp:phosphor-led",
        "--draws",
        "200",
        "--no-fit",
    ]);
    assert!(out.contains("`blend:daylight+lamp:phosphor-led`"), "{out}");
    std::fs::remove_dir_all(&dir).ok();
}

#[cfg(feature = "measured-data")]
#[test]
fn the_committed_split_is_what_the_command_makes() {
    let dir = scratch("split");
    let out = dir.join("split.json");
    ok(&[
        "--data-dir",
        &s(&common::data_dir()),
        "lamps",
        "split",
        "--seed",
        "1",
        "-o",
        &s(&out),
    ]);
    let made = std::fs::read_to_string(&out).unwrap();
    let committed = std::fs::read_to_string("../../docs/validation-split.json").unwrap();
    assert_eq!(made, committed);
    std::fs::remove_dir_all(&dir).ok();
}

#[cfg(feature = "measured-data")]
#[test]
fn the_shipped_models_beat_the_average_spd_on_held_out_lamps() {
    let dir = scratch("validate");
    let table = dir.join("validation.md");
    let out = ok(&[
        "--data-dir",
        &s(&common::data_dir()),
        "lamps",
        "validate",
        "--split",
        "../../docs/validation-split.json",
        "--model",
        "../../models/colorchecker_sg96.spdm",
        "--model",
        "../../models/colorchecker24.spdm",
        "--shots",
        "2",
        "--no-real",
        "-o",
        &s(&table),
    ]);
    // Per model: the **all** row, validation (average SPD, (a), (b)) then test.
    let rows: Vec<Vec<f64>> = out
        .lines()
        .filter(|l| l.starts_with("| **all**"))
        .map(|l| {
            l.split('|')
                .map(str::trim)
                .skip(3)
                .filter_map(|c| c.parse().ok())
                .collect()
        })
        .collect();
    assert_eq!(rows.len(), 2, "{out}");
    for r in rows {
        assert_eq!(r.len(), 6, "{out}");
        assert!(r[1] > r[0] + 0.02 && r[2] > r[0] + 0.02, "{out}");
        assert!(r[4] > r[3] + 0.02 && r[5] > r[3] + 0.02, "{out}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
