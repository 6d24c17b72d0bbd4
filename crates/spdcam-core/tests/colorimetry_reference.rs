//! Colorimetry, illuminants and resampling against reference values computed with
//! colour-science 0.4.7 (`tools/export_reference.py` → `tests/reference/*.json`; each JSON
//! section's `description` says exactly how its numbers were made).

use serde_json::Value;
use spdcam_core::cie_illuminant::{
    daylight, daylight_from_xy, daylight_xy, planck, StandardIlluminant,
};
use spdcam_core::colorimetry::{
    cct_duv_to_uv, delta_e_2000, lab_to_xyz, linear_srgb_to_xyz, srgb_decode, srgb_encode,
    srgb_encode_f32, uv_to_cct_duv, xy_to_uv1960, xy_to_xyz, xyz_to_lab, xyz_to_linear_srgb,
    Observer,
};
use spdcam_core::spectral::{Extrapolation, Grid, Interpolation, SpectralSet};

fn load(name: &str) -> Value {
    let path = format!("{}/tests/reference/{name}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn vec(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap_or_else(|| panic!("not an array: {v}"))
        .iter()
        .map(|x| x.as_f64().unwrap_or_else(|| panic!("not a number: {x}")))
        .collect()
}

fn arr<const N: usize>(v: &Value) -> [f64; N] {
    vec(v)
        .try_into()
        .unwrap_or_else(|_| panic!("not {N} numbers: {v}"))
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// Largest absolute difference, element by element.
fn max_abs(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Largest relative difference, element by element.
fn max_rel(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| ((x - y) / y).abs())
        .fold(0.0, f64::max)
}

fn observer() -> Observer {
    Observer::cie1931(&Grid::SIMULATION).unwrap()
}

#[test]
fn illuminant_chromaticities() {
    let reference = load("colorimetry.json");
    let obs = observer();
    let mut worst = 0.0f64;
    for ill in StandardIlluminant::ALL {
        let spd = ill.spd(&Grid::SIMULATION).unwrap();
        let xy = obs.spd_to_xy(&spd);
        let d = max_abs(&xy, &vec(&reference[format!("xy_{}", ill.name())]));
        assert!(d <= 1e-5, "{ill}: xy {xy:?} differs by {d}");
        worst = worst.max(d);
        let xyz = obs.spd_to_xyz(&spd);
        let normalised = xyz.map(|c| 100.0 * c / xyz[1]);
        let dn = max_abs(
            &normalised,
            &vec(&reference[format!("XYZ_{}_normalised", ill.name())]),
        );
        assert!(dn <= 1e-6, "{ill}: XYZ {normalised:?} differs by {dn}");
        let published = match ill {
            StandardIlluminant::D65 => Some([0.31271, 0.32902]),
            StandardIlluminant::A => Some([0.44757, 0.40745]),
            StandardIlluminant::D50 => None,
        };
        if let Some(p) = published {
            let dp = max_abs(&xy, &p);
            assert!(
                dp <= 2e-5,
                "{ill}: xy {xy:?} is {dp} from the CIE value {p:?}"
            );
        }
    }
    println!("illuminant xy: max |Δ| vs colour-science {worst:.2e}");
}

#[test]
fn colorchecker_under_d65() {
    let reference = load("colorimetry.json");
    let section = &reference["colorchecker24_under_D65"];
    let csv_path = format!(
        "{}/../../data/colorchecker24.csv",
        env!("CARGO_MANIFEST_DIR")
    );
    let chart = SpectralSet::read_csv(std::path::Path::new(&csv_path)).unwrap();
    chart
        .require_grid(&Grid::SIMULATION, "colorchecker24")
        .unwrap();
    let obs = observer();
    let d65 = StandardIlluminant::D65.spd(&Grid::SIMULATION).unwrap();
    let white = obs.white_xyz(&d65);
    assert!(max_abs(&white, &vec(&section["white_XYZ"])) <= 1e-12);
    let matrix = section["matrix_XYZ_to_sRGB"].as_array().unwrap();
    for (row, ours) in matrix
        .iter()
        .zip(spdcam_core::colorimetry::MATRIX_XYZ_TO_SRGB)
    {
        assert_eq!(vec(row), ours);
    }

    let patches = section["patches"].as_array().unwrap();
    assert_eq!(patches.len(), 24);
    let (mut d_xyz, mut d_lin, mut d_enc, mut de_lab, mut de_srgb) =
        (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for p in patches {
        let name = p["patch"].as_str().unwrap();
        let i = chart
            .position(name)
            .unwrap_or_else(|| panic!("no patch {name}"));
        let xyz = obs.reflectance_to_xyz(chart.item(i), &d65);
        let lin = xyz_to_linear_srgb(xyz);
        let enc = lin.map(srgb_encode);
        let lab = xyz_to_lab(xyz, white);

        let e_xyz = max_abs(&xyz, &vec(&p["XYZ"]));
        assert!(e_xyz <= 1e-4, "{name}: XYZ {xyz:?} differs by {e_xyz}");
        let e_lin = max_abs(&lin, &vec(&p["srgb_linear"]));
        let e_enc = max_abs(&enc, &vec(&p["srgb_encoded"]));
        assert!(
            e_lin <= 1e-6 && e_enc <= 1e-6,
            "{name}: sRGB {enc:?} ({e_lin}, {e_enc})"
        );
        let e_lab = delta_e_2000(lab, arr(&p["lab"]));
        assert!(e_lab <= 0.1, "{name}: ΔE2000 of Lab {e_lab}");
        // The displayed colour: our encoded sRGB and the reference's, both decoded back to
        // XYZ through the published sRGB → XYZ matrix, compared in CIELAB.
        let shown = |rgb: [f64; 3]| xyz_to_lab(linear_srgb_to_xyz(rgb.map(srgb_decode)), white);
        let e_srgb = delta_e_2000(shown(enc), shown(arr(&p["srgb_encoded"])));
        assert!(e_srgb <= 0.1, "{name}: ΔE2000 of sRGB {e_srgb}");

        d_xyz = d_xyz.max(e_xyz);
        d_lin = d_lin.max(e_lin);
        d_enc = d_enc.max(e_enc);
        de_lab = de_lab.max(e_lab);
        de_srgb = de_srgb.max(e_srgb);
    }
    println!(
        "colorchecker: max |ΔXYZ| {d_xyz:.2e}, |Δ linear sRGB| {d_lin:.2e}, |Δ encoded sRGB| \
         {d_enc:.2e}, ΔE2000 Lab {de_lab:.2e}, ΔE2000 sRGB {de_srgb:.2e}"
    );
}

#[test]
fn srgb_transfer_pairs() {
    let reference = load("colorimetry.json");
    let mut worst = 0.0f64;
    for pair in reference["srgb_transfer"]["pairs"].as_array().unwrap() {
        let (l, e) = (num(&pair["linear"]), num(&pair["encoded"]));
        let d = (srgb_encode(l) - e).abs().max((srgb_decode(e) - l).abs());
        assert!(
            d <= 1e-12,
            "linear {l}: encode {} decode {}",
            srgb_encode(l),
            srgb_decode(e)
        );
        assert!(
            (srgb_encode_f32(l as f32) as f64 - e).abs() <= 1e-6,
            "f32 at {l}"
        );
        worst = worst.max(d);
    }
    println!("sRGB transfer: max |Δ| {worst:.2e}");
}

#[test]
fn cielab_cases() {
    let reference = load("colorimetry.json");
    let mut worst = 0.0f64;
    for case in reference["xyz_to_lab"]["cases"].as_array().unwrap() {
        let white = xy_to_xyz(arr(&case["white_xy"]), 1.0);
        assert!(max_abs(&white, &vec(&case["white_XYZ"])) <= 1e-15);
        let xyz = arr(&case["XYZ"]);
        let lab = xyz_to_lab(xyz, white);
        let d = max_abs(&lab, &vec(&case["lab"]));
        assert!(d <= 1e-9, "{xyz:?}: Lab {lab:?} differs by {d}");
        let back = lab_to_xyz(lab, white);
        assert!(max_abs(&back, &xyz) <= 1e-12, "{xyz:?} -> {back:?}");
        worst = worst.max(d);
    }
    println!("CIELAB: max |ΔLab| {worst:.2e}");
}

#[test]
fn delta_e_2000_sharma_pairs() {
    let reference = load("colorimetry.json");
    let pairs = reference["delta_e_2000"]["pairs"].as_array().unwrap();
    assert_eq!(pairs.len(), 34);
    let (mut vs_colour, mut vs_published) = (0.0f64, 0.0f64);
    for p in pairs {
        let de = delta_e_2000(arr(&p["lab1"]), arr(&p["lab2"]));
        let n = p["pair"].as_u64().unwrap();
        if p["ill_conditioned"].as_bool().unwrap() {
            // Two mean-hue candidates exactly 180° apart: the last bit of atan2 decides.
            assert!(
                (de - 4.8045).abs() <= 1e-4 || (de - 4.7461).abs() <= 1e-4,
                "pair {n}: {de}"
            );
            continue;
        }
        let dc = (de - num(&p["delta_e_colour"])).abs();
        let dp = (de - num(&p["delta_e_published"])).abs();
        assert!(
            dc <= 1e-4,
            "pair {n}: {de} vs colour-science {}",
            p["delta_e_colour"]
        );
        assert!(
            dp <= 5e-5 + 1e-12,
            "pair {n}: {de} vs published {}",
            p["delta_e_published"]
        );
        vs_colour = vs_colour.max(dc);
        vs_published = vs_published.max(dp);
    }
    println!(
        "ΔE2000: max |Δ| vs colour-science {vs_colour:.2e}, vs published (4 dp) {vs_published:.2e}"
    );
}

#[test]
fn cct_and_duv_ohno() {
    let reference = load("colorimetry.json");
    let (mut d_cct, mut d_rel, mut d_duv, mut d_min, mut d_uv) =
        (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for case in reference["cct_duv"]["cases"].as_array().unwrap() {
        let source = case["source"].as_str().unwrap();
        let uv_ref = arr::<2>(&case["uv"]);
        assert!(
            max_abs(&xy_to_uv1960(arr(&case["xy"])), &uv_ref) <= 1e-12,
            "{source}"
        );
        let (cct, duv) = uv_to_cct_duv(uv_ref).unwrap();
        let (cct_ref, duv_ref) = (num(&case["CCT"]), num(&case["Duv"]));
        let dc = (cct - cct_ref).abs();
        assert!(
            dc <= 1.0 || dc <= 1e-4 * cct_ref,
            "{source}: CCT {cct} vs {cct_ref}"
        );
        assert!(
            (duv - duv_ref).abs() <= 1e-4,
            "{source}: Duv {duv} vs {duv_ref}"
        );
        let dm = (cct - num(&case["CCT_min_distance"])).abs();
        assert!(
            dm <= 1.0,
            "{source}: CCT {cct} vs exact {}",
            case["CCT_min_distance"]
        );
        d_cct = d_cct.max(dc);
        d_rel = d_rel.max(dc / cct_ref);
        d_duv = d_duv.max((duv - duv_ref).abs());
        d_min = d_min.max(dm);
        if let Some(gen) = case.get("generated_from_CCT_Duv") {
            let [t, duv] = arr(gen);
            let uv = cct_duv_to_uv(t, duv).unwrap();
            let du = max_abs(&uv, &uv_ref);
            assert!(du <= 1e-8, "{source}: uv {uv:?} vs {uv_ref:?}");
            d_uv = d_uv.max(du);
        }
    }
    println!(
        "CCT: max |ΔT| vs colour-science {d_cct:.2e} K (relative {d_rel:.2e}), |ΔDuv| {d_duv:.2e}, \
         |ΔT| vs exact minimum distance {d_min:.2e} K; cct_duv_to_uv max |Δuv| {d_uv:.2e}"
    );
}

#[test]
fn planck_radiance() {
    let reference = load("colorimetry.json");
    let section = &reference["planck"];
    assert_eq!(num(&section["c1"]), spdcam_core::cie_illuminant::PLANCK_C1);
    assert_eq!(num(&section["c2"]), spdcam_core::cie_illuminant::PLANCK_C2);
    let grid = Grid::new(400.0, 700.0, 20.0).unwrap();
    let idx: Vec<usize> = vec(&section["wavelengths_nm"])
        .iter()
        .map(|&w| grid.index_of(w).unwrap())
        .collect();
    let (mut d_abs, mut d_rel) = (0.0f64, 0.0f64);
    for case in section["cases"].as_array().unwrap() {
        let t = num(&case["T"]);
        let spd = planck(t, &grid).unwrap();
        let ours: Vec<f64> = idx.iter().map(|&i| spd[i]).collect();
        let relative: Vec<f64> = ours.iter().map(|v| v / ours[2]).collect();
        let da = max_rel(&ours, &vec(&case["radiance"]));
        let dr = max_rel(&relative, &vec(&case["relative_to_560nm"]));
        assert!(da <= 1e-4 && dr <= 1e-4, "{t} K: {ours:?} ({da}, {dr})");
        d_abs = d_abs.max(da);
        d_rel = d_rel.max(dr);
    }
    println!(
        "Planck: max relative Δ radiance {d_abs:.2e}, of values relative to 560 nm {d_rel:.2e}"
    );
}

#[test]
fn daylight_d_series() {
    let reference = load("colorimetry.json");
    let section = &reference["daylight"];
    assert_eq!(
        vec(&section["wavelengths_nm"]),
        Grid::SIMULATION.wavelengths()
    );
    let (mut d_xy, mut d_spd) = (0.0f64, 0.0f64);
    for case in section["cases"].as_array().unwrap() {
        let cct = num(&case["CCT"]);
        let xy_ref = arr::<2>(&case["xy"]);
        let spd_ref = vec(&case["spd"]);
        let spd = if cct <= 25000.0 {
            let xy = daylight_xy(cct).unwrap();
            let dx = max_abs(&xy, &xy_ref);
            assert!(dx <= 1e-12, "{cct} K: xy {xy:?} vs {xy_ref:?}");
            d_xy = d_xy.max(dx);
            daylight(cct, &Grid::SIMULATION).unwrap()
        } else {
            // 25000 × 1.4388/1.4380 lies just outside the formula's 4,000–25,000 K, which
            // `daylight` enforces; the SPD of the reference chromaticity is still checked.
            assert!(daylight(cct, &Grid::SIMULATION).is_err());
            daylight_from_xy(xy_ref, &Grid::SIMULATION).unwrap()
        };
        let d = max_rel(&spd, &spd_ref);
        assert!(d <= 1e-4, "{cct} K: SPD differs by {d} (relative)");
        d_spd = d_spd.max(d);
    }
    println!("daylight: max |Δxy| {d_xy:.2e}, max relative ΔSPD {d_spd:.2e}");
}

#[test]
fn resampling_sprague_and_linear() {
    let reference = load("resampling.json");
    let (mut d_sprague, mut d_linear) = (0.0f64, 0.0f64);
    for case in reference["cases"].as_array().unwrap() {
        let name = case["name"].as_str().unwrap();
        let set =
            SpectralSet::new(vec(&case["x"]), vec![name.into()], vec![vec(&case["y"])]).unwrap();
        let x_out = vec(&case["x_out"]);
        let grid = Grid::new(x_out[0], x_out[x_out.len() - 1], x_out[1] - x_out[0]).unwrap();
        assert_eq!(grid.wavelengths(), x_out, "{name}");
        for (method, key) in [
            (Interpolation::Sprague1880, "sprague"),
            (Interpolation::Linear, "linear"),
        ] {
            let (out, report) = set.resample(&grid, method, Extrapolation::Zero).unwrap();
            assert!(!report.extrapolated(), "{name}");
            let d = max_abs(out.item(0), &vec(&case[key]));
            assert!(d <= 1e-6, "{name} {key}: differs by {d}");
            match method {
                Interpolation::Sprague1880 => d_sprague = d_sprague.max(d),
                _ => d_linear = d_linear.max(d),
            }
        }
    }
    println!("resampling: max |Δ| Sprague {d_sprague:.2e}, linear {d_linear:.2e}");
}
