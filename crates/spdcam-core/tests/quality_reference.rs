//! Lighting-quality metrics against independent implementations and published values.
//!
//! The reference numbers were computed by `tools/export_quality_reference.py` with
//! colour-science 0.4.7 (CCT, CIE 13.3 CRI, CIE 2017 / TM-30) and luxpy 1.12.5 (CIE S 026
//! α-opic) and are committed under `tests/reference/`. The goals of the issue: Ra and R_i
//! within 0.1, Rf and Rg within 0.1, α-opic ratios within 0.5 %, CCT within 1 K. The shipped
//! spectra (CIE A, D65, D50 and six CIE 015 lamps) form the first tier; the 221 measured lamps
//! of the data directory the second (`--features measured-data`).

mod reference_csv;
#[cfg(feature = "measured-data")]
mod shared_data;

use spdcam_core::quality::{LightSpectrum, LightingMetrics};
use spdcam_core::spectral::SpectralSet;
use std::collections::BTreeMap;
use std::path::PathBuf;

fn reference_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/reference")
}

/// Our numbers under the reference file's column names.
fn our_values(m: &LightingMetrics) -> BTreeMap<String, f64> {
    let mut v = BTreeMap::new();
    v.insert("cct_k".into(), m.cct_k.unwrap());
    v.insert("duv".into(), m.duv.unwrap());
    v.insert("cri_ra".into(), m.cri_ra.unwrap());
    for (i, r) in m.cri_r.unwrap().iter().enumerate() {
        v.insert(format!("cri_r{}", i + 1), *r);
    }
    v.insert("tm30_rf".into(), m.tm30_rf.unwrap());
    v.insert("tm30_rg".into(), m.tm30_rg.unwrap());
    for (j, b) in m.tm30_bins.as_ref().unwrap().iter().enumerate() {
        v.insert(format!("tm30_rf_h{}", j + 1), b.rf);
        v.insert(format!("tm30_rcs_h{}", j + 1), b.chroma_shift);
        v.insert(format!("tm30_rhs_h{}", j + 1), b.hue_shift);
    }
    let elr = m.alpha_opic_elr_mw_per_lm.unwrap();
    let der = m.alpha_opic_der.unwrap();
    for (name, (e, d)) in ["sc", "mc", "lc", "rh", "mel"]
        .iter()
        .zip(elr.to_array().into_iter().zip(der.to_array()))
    {
        v.insert(format!("elr_{name}"), e);
        v.insert(format!("der_{name}"), d);
    }
    v.insert("sp_ratio".into(), m.sp_ratio.unwrap());
    v.insert("ppf_per_lux".into(), m.ppf_per_lux.unwrap());
    v.insert("blh_kbv".into(), m.blh_efficacy_w_per_lm.unwrap());
    v
}

/// How far a value may be from the reference: absolute, or relative when `relative`.
struct Tolerance {
    prefix: &'static str,
    limit: f64,
    relative: bool,
}

const TOLERANCES: &[Tolerance] = &[
    Tolerance {
        prefix: "cct_k",
        limit: 1.0,
        relative: false,
    },
    Tolerance {
        prefix: "duv",
        limit: 1e-5,
        relative: false,
    },
    Tolerance {
        prefix: "cri_",
        limit: 0.1,
        relative: false,
    },
    Tolerance {
        prefix: "tm30_rf",
        limit: 0.1,
        relative: false,
    },
    Tolerance {
        prefix: "tm30_rg",
        limit: 0.1,
        relative: false,
    },
    Tolerance {
        prefix: "tm30_rcs",
        limit: 1e-3,
        relative: false,
    },
    Tolerance {
        prefix: "tm30_rhs",
        limit: 1e-3,
        relative: false,
    },
    Tolerance {
        prefix: "elr_",
        limit: 0.005,
        relative: true,
    },
    Tolerance {
        prefix: "der_",
        limit: 0.005,
        relative: true,
    },
    Tolerance {
        prefix: "sp_ratio",
        limit: 1e-3,
        relative: true,
    },
    Tolerance {
        prefix: "ppf_per_lux",
        limit: 1e-3,
        relative: true,
    },
    Tolerance {
        prefix: "blh_kbv",
        limit: 1e-3,
        relative: true,
    },
];

fn tolerance(key: &str) -> &'static Tolerance {
    TOLERANCES
        .iter()
        .find(|t| key.starts_with(t.prefix))
        .unwrap_or_else(|| panic!("no tolerance for {key}"))
}

/// Compares every light of `set` with its reference row; returns the worst deviation per
/// tolerance group (absolute or relative, as the group is judged) and the failures.
fn compare(
    set: &SpectralSet,
    reference: &BTreeMap<String, BTreeMap<String, f64>>,
) -> (BTreeMap<&'static str, (f64, String)>, Vec<String>) {
    let mut worst: BTreeMap<&'static str, (f64, String)> = BTreeMap::new();
    let mut failures = Vec::new();
    for (i, name) in set.names().iter().enumerate() {
        let expected = reference
            .get(name)
            .unwrap_or_else(|| panic!("no reference row for '{name}'"));
        let light = LightSpectrum::from_set(set, i).unwrap();
        let ours = our_values(&LightingMetrics::of(&light));
        for (key, want) in expected {
            let got = ours[key];
            let t = tolerance(key);
            let dev = if t.relative {
                (got / want - 1.0).abs()
            } else {
                (got - want).abs()
            };
            let entry = worst.entry(t.prefix).or_insert((0.0, String::new()));
            if dev > entry.0 {
                *entry = (dev, format!("{name}: {key} {got} vs {want}"));
            }
            if dev.is_nan() || dev > t.limit {
                failures.push(format!("{name}: {key} = {got}, reference {want}"));
            }
        }
    }
    (worst, failures)
}

fn assert_matches(set: &SpectralSet, reference_file: &str) {
    let reference = reference_csv::read(&reference_dir().join(reference_file));
    let (worst, failures) = compare(set, &reference);
    for (group, (dev, case)) in &worst {
        println!("{group:12} worst deviation {dev:.3e} ({case})");
    }
    assert!(
        failures.is_empty(),
        "{} deviations:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn shipped_spectra_match_colour_science_and_luxpy() {
    let illuminants = SpectralSet::read_csv(
        &PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/illuminants_cie.csv"),
    )
    .unwrap();
    assert_matches(&illuminants, "quality_shipped.csv");
    let lamps = SpectralSet::read_csv(&reference_dir().join("quality_spds.csv")).unwrap();
    assert_matches(&lamps, "quality_shipped.csv");
}

#[test]
fn published_colour_rendering_of_cie_fluorescent_lamps() {
    // CIE 015:2018 Table 10 (after CIE 13.3): Ra of FL2 = 64, FL7 = 90, FL11 = 83 (rounded).
    let lamps = SpectralSet::read_csv(&reference_dir().join("quality_spds.csv")).unwrap();
    for (name, ra) in [("FL2", 64.0), ("FL7", 90.0), ("FL11", 83.0)] {
        let i = lamps.position(name).unwrap();
        let m = LightingMetrics::of(&LightSpectrum::from_set(&lamps, i).unwrap());
        let got = m.cri_ra.unwrap();
        assert_eq!(got.round(), ra, "{name}: Ra {got}");
    }
}

#[cfg(feature = "measured-data")]
#[test]
fn the_221_measured_lamps_match_colour_science_and_luxpy() {
    let path = shared_data::data_dir().join("lamps/ies_tm30_lamps.csv");
    let lamps = SpectralSet::read_csv(&path).unwrap();
    assert_eq!(lamps.len(), 221);
    assert_matches(&lamps, "quality_lamps.csv");
}
